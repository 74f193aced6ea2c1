"""``kind: filter`` of a ``check-design`` spec: an active filter, designed
(``filter:`` as ``design-filter`` takes it, :class:`~designer.filters.spec.FilterSpec`)
or as built (``stages:``, each ``{topology: <registry name>, parts: {R1: .., C1: ..}}``,
the parts keys the topology's designators), in every op-amp corner (``opamp:``),
with ``mask: {passband, max_loss, stopband, min_attenuation}`` as checks on the
op-amp-aware response and on SPICE's ``.ac`` (:data:`MASK_FIGURES`), besides the
spec's own ``checks:`` on :data:`designer.check.figures.FILTER`; a designed filter's
``yield: {min, samples, seed, sampler, dist}`` (with ``tolerances: {R: 1%, C: 5%}``)
counts the builds of :func:`designer.tolerance.filter.filter_spec_yield` inside the
checks on the model's figures (the mask's among them), with its Wilson interval.

A Bessel low-pass's group-delay target is ``delay: {max_error_pct: 1, to: 1k}``
beside ``mask:`` (the delay within max_error_pct % of its DC value from DC to
``to``, as design-filter's ``--max-delay-error`` and ``--delay-to``): checks on
the model's ``delay_error_pct`` (the central difference of the op-amp-aware
cascade's phase on DELAY_POINTS points from DC, :func:`designer.filters.design.central_delay`)
and on SPICE's ``spice_delay_error_pct`` (:func:`designer.filters.verify.phase_delay_error_pct`)
(:data:`DELAY_FIGURES`), and in the yield. Designed, it joins ``mask:`` in picking the
order and the joint part choice (no ``filter.order`` then), on a ``family: bessel``;
as built, any low-pass cascade.

The figures of a corner (:func:`filter_figures`): the -3 dB frequencies (where
the gain is 3 dB below the passband gain; a low-pass its last crossing, a
high-pass its first, a band-pass both), the largest loss below the passband
gain over the mask's passband and the least attenuation over its stopband, of
the cascade's analytic response with the corner's op-amp (the model of
:meth:`designer.filters.cascade.Cascade.response`) and of ngspice's ``.ac`` run of
its deck (:func:`designer.filters.deck.simulate_ac`), and SPICE's largest
deviation from the model down to 60 dB below the passband gain. The passband
gain is the design's (``filter.gain``) or, as built, the cascade's own: DC for
a low-pass, infinite frequency for a high-pass, the peak for a band-pass.
"""

from __future__ import annotations

import math
from dataclasses import dataclass, field

import numpy as np

from ..core import opamps
from ..core.errors import DesignError
from ..core.jsonio import json_safe
from ..core.units import parse_value

__all__ = ["FILTER_KEYS", "SUB_FILTER", "MASK_KEYS", "MASK_FIGURES", "DELAY_KEYS", "DELAY_FIGURES", "FilterCase",
           "filter_designs", "mask_limits", "delay_limits", "run_filter", "filter_figures", "spice_sweep",
           "corner_stages", "model_grid"]

#: the keys of ``filter:`` (design-filter's options) and ``mask:``
SUB_FILTER = ("type", "family", "order", "fc", "ripple", "bessel_norm", "chebyshev_cutoff", "f_low", "f_high",
              "bandpass_method", "topology", "stage_order", "gain", "stage_gain", "amplitude", "gbw_margin", "impedance",
              "compensate_gbw")
MASK_KEYS = ("passband", "max_loss", "stopband", "min_attenuation")
#: the keys of ``delay:``
DELAY_KEYS = ("max_error_pct", "to")
#: library parameter -> the filter spec's key (messages of FilterSpec)
FILTER_KEYS = {"filter_type": "filter.type", "family": "filter.family", "order": "filter.order",
               "fc_hz": "filter.fc", "ripple_db": "filter.ripple", "bessel_norm": "filter.bessel_norm",
               "chebyshev_cutoff": "filter.chebyshev_cutoff", "f_low_hz": "filter.f_low",
               "f_high_hz": "filter.f_high", "bandpass_method": "filter.bandpass_method",
               "topology": "filter.topology", "stage_order": "filter.stage_order", "gain": "filter.gain",
               "stage_gains": "filter.stage_gain",
               "amplitude_v": "filter.amplitude", "gbw_margin": "filter.gbw_margin",
               "impedance_ohm": "filter.impedance", "compensate_gbw": "filter.compensate_gbw",
               "passband_hz": "mask.passband", "max_loss_db": "mask.max_loss", "stopband_hz": "mask.stopband",
               "min_attenuation_db": "mask.min_attenuation", "opamp": "opamp", "r_series": "series.r",
               "c_series": "series.c", **{k: f"bounds.{k}" for k in ("r_min", "r_max", "c_min", "c_max")},
               "max_delay_error_pct": "delay.max_error_pct", "delay_to_hz": "delay.to"}
#: the mask's checks: figure -> (limit key, mask key); each on the model and on SPICE's .ac
MASK_FIGURES = {"passband_loss_db": ("max", "max_loss"), "stopband_attenuation_db": ("min", "min_attenuation"),
                "spice_passband_loss_db": ("max", "max_loss"),
                "spice_stopband_attenuation_db": ("min", "min_attenuation")}
#: the delay target's checks: figure -> (limit key, delay key); on the model and on SPICE's .ac
DELAY_FIGURES = {"delay_error_pct": ("max", "max_error_pct"), "spice_delay_error_pct": ("max", "max_error_pct")}
#: points of the model's frequency grid, per decade
POINTS_PER_DECADE = 100
#: points per decade of SPICE's .ac against a band-pass's mask
_BAND_POINTS_PER_DECADE = 400


@dataclass(frozen=True)
class FilterCase:
    """One corner's filter, as the spec gives it.

    Parameters
    ----------
    opamp : str
        The corner's op-amp.
    spec : FilterSpec or None
        Designed: what ``design-filter`` takes; None as built.
    stages : tuple
        As built: (topology name, parts dict) pairs; () when designed.
    mask : dict or None
        ``{passband, max_loss, stopband, min_attenuation}`` in Hz and dB, or None.
    delay : dict or None
        ``{max_error_pct, to}`` (%, Hz): a group-delay target, or None.
    """

    opamp: str
    spec: object = None
    stages: tuple = ()
    mask: dict | None = None
    delay: dict | None = None


@dataclass
class FilterRun:
    """A corner run: the design (None as built), the cascade, the figures.

    Parameters
    ----------
    case : FilterCase
        What was run.
    design : FilterDesign or None
        The design (designed only).
    figures : dict
        :data:`designer.check.figures.FILTER` figures.
    stages : list
        (topology name, parts) of the cascade run.
    monte_carlo : FilterMonteCarlo or None
        The spec's ``yield:`` Monte Carlo (set by check-design's yield check).
    """

    case: FilterCase
    design: object
    figures: dict
    stages: list = field(default_factory=list)
    monte_carlo: object = None

    def to_dict(self) -> dict:
        """The corner as JSON.

        Returns
        -------
        dict
            ``kind``, ``opamp``, ``as_built``, ``stages``, ``figures`` and the design's JSON when designed.
        """
        return json_safe({"kind": "filter", "opamp": self.case.opamp, "as_built": self.design is None,
                          "mask": self.case.mask, **({"delay": self.case.delay} if self.case.delay else {}),
                          "stages": [{"topology": t, "parts": {k: float(v) for k, v in p.items()}}
                                     for t, p in self.stages],
                          "figures": self.figures,
                          "design": None if self.design is None else self.design.to_dict(),
                          **({} if self.monte_carlo is None else {"monte_carlo": self.monte_carlo.to_dict()})})


def _section(doc, name: str, keys: tuple, needs: str) -> dict | None:
    """The spec's ``name:`` mapping with every one of ``keys`` (None when absent); one line naming the missing."""
    if doc.data.get(name) is None:
        return None
    m = doc.mapping((name,), keys)
    missing = [k for k in keys if k not in m]
    if missing:
        raise doc.error((name,), f"{name} needs {needs}; missing {', '.join(missing)}")
    return m


def _mask(doc) -> dict | None:
    from .sections import read_positive
    m = _section(doc, "mask", MASK_KEYS, ", ".join(MASK_KEYS))
    if m is None:
        return None
    out = {}
    for k in MASK_KEYS:
        v = m[k]
        if k in ("passband", "stopband") and isinstance(v, list):
            # a band-pass's two edges, [low, high]
            if len(v) != 2:
                raise doc.error(("mask", k), f"mask.{k} takes one edge, or a band-pass's two [low, high]; got "
                                f"{len(v)} values")
            out[k] = tuple(_positive_item(doc, k, x) for x in v)
        else:
            out[k] = read_positive(doc, ("mask", k))
    if isinstance(out["passband"], tuple) != isinstance(out["stopband"], tuple):
        raise doc.error(("mask",), "mask: a band-pass's mask gives passband and stopband both as [low, high]; a "
                        "low- or high-pass's both as one edge")
    return out


def _delay(doc) -> dict | None:
    from .sections import read_positive
    if _section(doc, "delay", DELAY_KEYS, f"{' and '.join(DELAY_KEYS)} (the delay within max_error_pct % of its DC "
                "value from DC to the frequency to)") is None:
        return None
    return {k: read_positive(doc, ("delay", k)) for k in DELAY_KEYS}


def _check_delay(doc, delay, kind: str, family: str | None = None) -> None:
    """A group-delay target on a low-pass (designed: a Bessel's)."""
    if delay is None:
        return
    if kind != "lowpass":
        raise doc.error(("delay",), f"delay: a group-delay target is for a lowpass (its delay at DC); this filter "
                        f"is a {kind}")
    if family is not None and family != "bessel":
        raise doc.error(("delay",), f"delay: a group-delay target is for a bessel filter (the flat-delay family); "
                        f"filter.family is {family}")


def _positive_item(doc, key: str, value) -> float:
    """One of a band-pass mask's two edges (``mask.<key>: [low, high]``), a positive number."""
    try:
        out = parse_value(value, f"mask.{key}") if not isinstance(value, bool) else None
    except DesignError:
        out = None
    if out is None or not out > 0:
        raise doc.error(("mask", key), f"mask.{key} must be positive numbers [low, high], got {value!r}")
    return out


def _stages(doc) -> tuple:
    from ..filters.cascade import Cascade
    from ..filters.registry import get, names
    value = doc.get(("stages",))
    if not isinstance(value, list) or not value:
        raise doc.error(("stages",), "stages must be a list of {topology: name, parts: {R1: .., C1: ..}}")
    out = []
    for i, entry in enumerate(value):
        keys = ("stages", i)
        m = doc.mapping(keys, ("topology", "parts"), entry if isinstance(entry, dict) else None)
        if not isinstance(entry, dict) or "topology" not in m or "parts" not in m:
            raise doc.error(keys, f"stages[{i}] needs topology: and parts:")
        try:
            topo = get(m["topology"]) if isinstance(m["topology"], str) else None
        except DesignError:
            topo = None
        if topo is None:
            raise doc.error(keys + ("topology",), f"stages[{i}].topology: unknown section {m['topology']!r}; "
                            f"allowed: {', '.join(names())}")
        parts = doc.mapping(keys + ("parts",), topo.designators, m["parts"])   # a list's item: given, not looked up
        missing = [r for r in topo.designators if r not in parts]
        if missing:
            raise doc.error(keys + ("parts",), f"stages[{i}].parts: {topo.name} needs {', '.join(topo.designators)}"
                            f"; missing {', '.join(missing)}")
        vals = {}
        for ref in topo.designators:
            try:
                v = parse_value(parts[ref], f"stages[{i}].parts.{ref}")
            except DesignError as exc:
                raise doc.error(keys + ("parts", ref), str(exc)) from None
            if not v > 0:
                raise doc.error(keys + ("parts", ref), f"stages[{i}].parts.{ref} must be positive")
            vals[ref] = v
        out.append((topo.name, vals))
    Cascade([(get(t), v) for t, v in out])
    return tuple(out)


def filter_designs(doc, corners) -> tuple:
    """Each corner's :class:`FilterCase` from ``filter:`` (designed) or ``stages:`` (as built), and ``mask:``.

    Parameters
    ----------
    doc : designer.check.yamldoc._Doc
        The spec document.
    corners : tuple of str
        The op-amps.

    Returns
    -------
    tuple
        (list of FilterCase, analyze: whether as built).
    """
    from ..filters.spec import FilterSpec
    from .sections import SUB, built_in_spec_words
    mask, delay = _mask(doc), _delay(doc)
    has_filter, has_stages = doc.data.get("filter") is not None, doc.data.get("stages") is not None
    if has_filter == has_stages:
        raise doc.error((), "a filter spec needs filter: {type, family, order, fc, ..} (designed) or stages: "
                        "[{topology, parts}] (as built), one of them")
    if has_stages:
        if doc.data.get("bounds") is not None:
            raise doc.error(("bounds",), "bounds: limit a design's part search; stages: are already chosen")
        stages = _stages(doc)
        _check_mask_kind(doc, mask, _kind(stages))
        _check_delay(doc, delay, _kind(stages))
        return [FilterCase(amp, None, stages, mask, delay) for amp in corners], True
    f = doc.mapping(("filter",), SUB_FILTER)
    kw = {FILTER_TO_PARAM[k]: v for k, v in f.items()}
    series = doc.mapping(("series",), SUB["series"])
    kw.update({f"{k}_series": series[k] for k in ("r", "c") if k in series})
    kw.update(doc.mapping(("bounds",), SUB["bounds"]))
    _check_mask_kind(doc, mask, str(f.get("type", "lowpass")).strip().lower())
    _check_delay(doc, delay, str(f.get("type", "lowpass")).strip().lower(),
                 str(f.get("family", "butterworth")).strip().lower())
    picks = mask is not None and not {"order", "fc", "f_low", "f_high"} & set(f)
    if delay is not None and not picks:
        raise doc.error(("delay",), "delay: a designed filter's group-delay target joins mask: in picking the order "
                        "(as design-filter's --max-delay-error); give mask: and no filter.order or filter.fc")
    if delay is not None:
        kw.update({"max_delay_error_pct": delay["max_error_pct"], "delay_to_hz": delay["to"]})
    if picks:
        # no order: the mask picks it (a band-pass's also its edges), as design-filter's --passband .. --min-attenuation
        kw.update({"passband_hz": mask["passband"], "max_loss_db": mask["max_loss"],
                   "stopband_hz": mask["stopband"], "min_attenuation_db": mask["min_attenuation"]})
    if "compensate_gbw" in kw and not isinstance(kw["compensate_gbw"], bool):
        raise doc.error(("filter", "compensate_gbw"), "filter.compensate_gbw must be true or false")
    cases = [FilterCase(amp, built_in_spec_words(doc, FILTER_KEYS, lambda amp=amp: FilterSpec(opamp=amp, **kw)), (), mask,
                        delay) for amp in corners]
    return cases, False


def _check_mask_kind(doc, mask, kind: str) -> None:
    """A mask of two edges a side for a band-pass, of one for a low- or high-pass."""
    if mask is not None and isinstance(mask["passband"], tuple) != (kind == "bandpass"):
        need = "two edges each, passband: [low, high] and stopband: [low, high]" if kind == "bandpass" else \
            "one edge each, passband: F and stopband: F"
        raise doc.error(("mask",), f"mask: a {kind}'s mask takes {need}")


#: filter: key -> FilterSpec parameter
FILTER_TO_PARAM = {v.split(".", 1)[1]: k for k, v in FILTER_KEYS.items() if v.startswith("filter.")}


def mask_limits(mask: dict | None) -> tuple:
    """The mask as :class:`~designer.check.limits.Limit` checks (:data:`MASK_FIGURES`).

    Parameters
    ----------
    mask : dict or None
        The spec's mask.

    Returns
    -------
    tuple of Limit
        None for no mask: ().
    """
    return _limits(mask, MASK_FIGURES, "mask")


def delay_limits(delay: dict | None) -> tuple:
    """The group-delay target as :class:`~designer.check.limits.Limit` checks (:data:`DELAY_FIGURES`).

    Parameters
    ----------
    delay : dict or None
        The spec's ``delay:``.

    Returns
    -------
    tuple of Limit
        None for no target: ().
    """
    return _limits(delay, DELAY_FIGURES, "delay")


def _limits(values: dict | None, table: dict, section: str) -> tuple:
    """The checks of a spec section's ``values`` by ``table`` (figure -> (limit side, key)); () without it."""
    from . import figures as F
    from .limits import limit_from
    if values is None:
        return ()
    return tuple(limit_from(fig, {side: values[key]}, f"{section}.{key}", F.unit_of("filter", fig))
                 for fig, (side, key) in table.items())


def _grid(stages, extra=()) -> np.ndarray:
    from ..filters.registry import get
    fns = [float(get(t).figures(v).fn_hz) for t, v in stages]
    lo, hi = min(fns) / 30, max(fns) * 30
    n = int(math.ceil(math.log10(hi / lo) * POINTS_PER_DECADE)) + 1
    f = np.logspace(math.log10(lo), math.log10(hi), n)
    return np.unique(np.concatenate([f, [x for x in extra if lo <= x <= hi]]))


def _kind(stages) -> str:
    from ..filters.registry import get
    kinds = {get(t).kind for t, _ in stages}
    return kinds.pop() if len(kinds) == 1 and kinds <= {"lowpass", "highpass"} else "bandpass"


def _crossings(f, g_db, level) -> list:
    """The frequencies where ``g_db`` crosses ``level`` (log-linear interpolation)."""
    above = g_db >= level
    idx = np.flatnonzero(above[1:] != above[:-1])
    out = []
    for i in idx:
        a, b = g_db[i] - level, g_db[i + 1] - level
        t = a / (a - b)
        out.append(float(math.exp(math.log(f[i]) + t * (math.log(f[i + 1]) - math.log(f[i])))))
    return out


def _response_figures(f, h, kind, ref_db, mask, prefix="") -> dict:
    from ..filters.verify import band_edge_db
    g = 20 * np.log10(np.abs(h))
    cross = _crossings(f, g, ref_db - 10 * math.log10(2))
    out = {}
    if kind == "bandpass":
        out[f"{prefix}f3_low_hz"] = cross[0] if cross else None
        out[f"{prefix}f3_high_hz"] = cross[-1] if len(cross) > 1 else None
    else:
        out[f"{prefix}f3_hz"] = (cross[-1] if kind == "lowpass" else cross[0]) if cross else None
    if mask is not None:
        pb, sb = mask["passband"], mask["stopband"]
        # the edges themselves by interpolation in log f, the points between them as they are
        at = lambda edges: np.interp(np.log(np.atleast_1d(edges)), np.log(f), g) if not isinstance(pb, tuple) \
            else band_edge_db(f, g, edges)  # noqa: E731  (a band-pass's narrow edges: a cubic, not a chord)
        g_pb, g_sb = float(np.min(at(pb))), float(np.max(at(sb)))
        if isinstance(pb, tuple):   # a band-pass's [low, high] (_mask: both or neither)
            inside = (f >= pb[0]) & (f <= pb[1])
            stop = (f <= sb[0]) | (f >= sb[1])
        else:
            inside = f <= pb if kind == "lowpass" else f >= pb
            stop = f >= sb if kind == "lowpass" else f <= sb
        out[f"{prefix}passband_loss_db"] = float(ref_db - min(g_pb, *g[inside])) if inside.any() else \
            float(ref_db - g_pb)
        out[f"{prefix}stopband_attenuation_db"] = float(ref_db - max(g_sb, *g[stop])) if stop.any() else \
            float(ref_db - g_sb)
    return out


def filter_figures(stages, opamp, ref_db: float, mask, simulator: str | None, delay=None) -> dict:
    """The :data:`designer.check.figures.FILTER` figures of a cascade with ``opamp``.

    Parameters
    ----------
    stages : list
        (topology name, parts) pairs.
    opamp : designer.core.opamps.OpAmp
        The corner's op-amp.
    ref_db : float or None
        The passband gain, dB (None: the cascade's own, see the module docstring).
    mask : dict or None
        The mask.
    simulator : str or None
        ngspice backend for the ``spice_`` figures (None: not simulated).
    delay : dict or None
        A group-delay target ``{max_error_pct, to}``: the ``delay_error_pct`` figures too.

    Returns
    -------
    dict
        Figure -> value (None where the response has none).
    """
    from ..filters.cascade import Cascade
    from ..filters.deck import simulate_ac
    from ..filters.registry import get
    cascade = Cascade([(get(t), v) for t, v in stages])
    kind = _kind(stages)
    f = model_grid(stages, mask)
    h = cascade.response(2j * math.pi * f, opamp)
    if ref_db is None:
        num, den = cascade.coefficients()
        if kind == "lowpass":
            ref = abs(num[-1] / den[-1])
        elif kind == "highpass":
            ref = abs(num[np.flatnonzero(num)[0]] / den[0]) if len(num) == len(den) else abs(num[0] / den[0])
        else:
            ref = float(np.max(np.abs(cascade.response(2j * math.pi * f))))
        ref_db = 20 * math.log10(ref)
    out = {"passband_gain_db": float(ref_db), "stages": len(stages),
           **_response_figures(f, h, kind, ref_db, mask)}
    if delay is not None:
        from ..filters.design import central_delay
        from ..filters.prototype import DELAY_POINTS, delay_error_pct
        # design-filter's grid (DC to the target, DELAY_POINTS); the half-step a 1e-4 of the target's frequency
        tau = central_delay(lambda s: cascade.response(s, opamp), np.linspace(0.0, delay["to"], DELAY_POINTS),
                            2 * math.pi * delay["to"] * 1e-4)
        out["delay_error_pct"] = delay_error_pct(tau, tau[0])
    if simulator is not None:
        netlist, f_lo, f_hi, ppd = spice_sweep(cascade, f, mask)
        fs, hs = simulate_ac(netlist, opamp, f_lo, f_hi, simulator=simulator, points_per_decade=ppd)
        out.update(_response_figures(fs, hs, kind, ref_db, mask, "spice_"))
        if delay is not None:
            from ..filters.verify import phase_delay_error_pct
            out["spice_delay_error_pct"] = phase_delay_error_pct(fs, hs, delay["to"])
        an = cascade.response(2j * math.pi * fs, opamp)
        dev = np.abs(20 * np.log10(np.abs(hs)) - 20 * np.log10(np.abs(an)))
        within = 20 * np.log10(np.abs(an)) >= ref_db - 60
        out["spice_max_deviation_db"] = float(np.max(dev[within]))
    return out


def model_grid(stages, mask) -> np.ndarray:
    """The frequency grid the figures are read on: the stages' own and the mask's edges.

    Parameters
    ----------
    stages : list
        (topology name, parts) pairs.
    mask : dict or None
        The mask.

    Returns
    -------
    numpy.ndarray
        Frequencies, Hz, ascending.
    """
    edges = () if mask is None else tuple(np.hstack([mask["passband"], mask["stopband"]]))
    return _grid(stages, edges)


def spice_sweep(cascade, f, mask) -> tuple:
    """The SPICE ``.ac`` sweep :func:`filter_figures` runs: over the model's grid
    ``f``, denser for a band-pass mask (its narrow band's edges within a few
    points otherwise).

    Parameters
    ----------
    cascade : designer.filters.cascade.Cascade
        The corner's circuit.
    f : numpy.ndarray
        The model's frequency grid, Hz.
    mask : dict or None
        The mask.

    Returns
    -------
    tuple
        (netlist, lowest Hz, highest Hz, points per decade): what
        :func:`designer.filters.deck.ac_deck` takes.
    """
    from ..filters.deck import AC_POINTS_PER_DECADE
    dense = mask is not None and isinstance(mask["passband"], tuple)
    return (cascade.netlist(), float(f[0]), float(f[-1]),
            _BAND_POINTS_PER_DECADE if dense else AC_POINTS_PER_DECADE)


def corner_stages(case: FilterCase) -> tuple:
    """A corner's stages: designed from its spec (not simulated) or as built.

    Parameters
    ----------
    case : FilterCase
        The corner.

    Returns
    -------
    tuple
        (the design or None as built, [(topology name, parts)], the passband
        gain in dB or None for the cascade's own).
    """
    from ..filters.design import design
    if case.spec is None:
        return None, list(case.stages), None
    res = design(case.spec, simulate=False)
    return res, [(st.topology, dict(st.values)) for st in res.stages], 20 * math.log10(case.spec.gain)


def run_filter(case: FilterCase, simulator: str) -> FilterRun:
    """Design (or take as built) one corner's filter and measure its figures.

    Parameters
    ----------
    case : FilterCase
        The corner.
    simulator : str
        ngspice backend.

    Returns
    -------
    FilterRun
        The run.
    """
    opamp = opamps.get(case.opamp)
    res, stages, ref_db = corner_stages(case)
    figs = filter_figures(stages, opamp, ref_db, case.mask, simulator, case.delay)
    if res is not None:
        f = res.figures
        figs.update({"passband_deviation_db": f["passband_deviation_db"], "error_joint_db": f["error_joint_db"],
                     "error_per_stage_db": f["error_per_stage_db"], "order": res.order,
                     "gbw_ratio_min": min(opamp.gbw_hz / st.gbw_needed_hz for st in res.stages)})
    return FilterRun(case, res, figs, stages)
