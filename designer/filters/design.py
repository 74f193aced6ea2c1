"""A filter from a specification (:class:`~designer.filters.spec.FilterSpec`):
the prototype's sections (:mod:`designer.filters.prototype`), each synthesised
on a registered topology, the gain split, every stage checked against its
op-amp, the parts chosen jointly from the E-series (:mod:`designer.filters.joint`)
and, on request, the cascade proven against ngspice's ``.ac``.

Sources: TI, "Op Amps for Everyone", ch. 16 (SLOA088): the cascade of
second-order sections (plus a first-order one for an odd order), stages built
in rising Q so that a high-Q stage does not clip, the rule of thumb that a
stage's op-amp needs a gain-bandwidth of 100 x fn x Q x gain; Zverev,
"Handbook of Filter Synthesis": the normalised prototypes; scipy.signal: the
poles and the order functions.

Choices made here, and why:

- each section's capacitors are series values from the start (C1 a neighbour
  of the value that puts the resistors near ``impedance_ohm``, C2 the least series
  value above the topology's ratio bound), so the synthesis stays exact with only
  the resistors continuous; then each part's two neighbouring series values are its
  candidates (a part already on the series keeps its value);
- the objective of the joint choice is the whole cascade's response with the
  op-amp's finite gain and GBW, against the ideal response, over the passband and
  the transition band, so that the choice also absorbs part of the op-amp's error;
  a Bessel's group-delay target joins it as limits (:mod:`designer.filters.joint`),
  each stage's candidates' op-amp-aware delay on the target's grid, so that
  rounding does not break a target another candidate set meets;
- the gain goes to the lowest-Q second-order stage (a Sallen-Key's Q is the more
  sensitive to its gain resistors the higher Q is; a first-order section here is a
  unity-gain buffer); if that clips a stage's output at the bench amplitude, it is
  split evenly in dB, then all put in the last stage; if every split clips, refuse.
"""

from __future__ import annotations

import itertools
import math
import time
from dataclasses import dataclass, field

import numpy as np

from ..core import opamps
from ..core.errors import DesignError
from ..core.jsonio import SCHEMA_VERSION, json_safe
from ..core.eseries import values as series_values
from ..core.units import format_eng
from .cascade import Cascade
from .deck import simulate_ac
from .joint import delay_columns, joint_search, objective, per_stage
from .prototype import (DELAY_POINTS, SectionPlan, bandpass_method, delay_error_pct, group_delay, order_from_mask,
                        plan_bandpass, plan_sections, prototype_zpk,
                        reference_bandpass, reference_response)
from .registry import get as get_topology
from .spec import FilterSpec
from .topology import SectionTarget
from .verify import proof_deck, prove

__all__ = ["StageDesign", "FilterDesign", "design", "as_built", "section_plans", "section_name", "stage_candidates", "verify_spice", "predistort",
           "analysis_grid", "with_choice", "delay_figures", "central_delay"]

#: the capacitor values (C1, nearest first) each stage offers the joint search
C_CHOICES = 3
#: the largest product of the stages' candidate counts searched (beyond it each stage keeps its best candidates)
MAX_COMBINATIONS = 500_000
#: points of the objective's frequency grid
GRID_POINTS = 160
#: how far below the passband gain the transition band ends without a mask (dB)
TRANSITION_DB = 20.0


@dataclass
class StageDesign:
    """One designed stage.

    Parameters
    ----------
    number : int
        1-based position in the cascade.
    plan : SectionPlan
        The section's kind, order, fn and Q.
    topology : str
        Registry name of its section.
    gain : float
        Its passband gain magnitude.
    continuous : dict
        Exact part values.
    candidates : list of dict
        The E-series candidate sets.
    errors : ndarray
        (n_candidates, n_f) dB error of each candidate on the objective grid.
    nearest : int
        The candidate with every part rounded to its nearest series value.
    chosen : int
        The jointly chosen candidate.
    peak_gain : float
        max |H_i| of the stage alone (V/V).
    node_peak_v : float
        The stage output's peak at the bench amplitude (the cascade up to it).
    gbw_needed_hz : float
        margin x fn x Q x noise gain.
    fn_design_hz, q_design : float or None
        The fn and Q the parts were synthesised for (the plan's, or pre-distorted for the op-amp).
    """

    number: int
    plan: SectionPlan
    topology: str
    gain: float
    continuous: dict
    candidates: list
    errors: np.ndarray
    nearest: int
    chosen: int = 0
    peak_gain: float = 1.0
    node_peak_v: float = 0.0
    gbw_needed_hz: float = 0.0
    fn_design_hz: float | None = None
    q_design: float | None = None
    delays: np.ndarray | None = None

    @property
    def values(self) -> dict:
        """The chosen E-series values."""
        return self.candidates[self.chosen]

    def to_dict(self) -> dict:
        """The stage as JSON.

        Returns
        -------
        dict
            Its figures, its continuous and its chosen part values.
        """
        return {"stage": self.number, "topology": self.topology, "kind": self.plan.kind, "order": self.plan.order,
                "fn_hz": self.plan.fn_hz, "q": self.plan.q, "gain": self.gain,
                "inverting": get_topology(self.topology).inverting, "peak_gain": self.peak_gain,
                "peak_gain_db": 20 * math.log10(self.peak_gain), "node_peak_v": self.node_peak_v,
                "gbw_needed_hz": self.gbw_needed_hz, "candidates": len(self.candidates),
                "fn_design_hz": self.fn_design_hz, "q_design": self.q_design,
                "parts_continuous": {k: float(v) for k, v in self.continuous.items()},
                "parts": {k: float(v) for k, v in self.values.items()}}


@dataclass
class FilterDesign:
    """The designed filter: its stages and every figure reported.

    Attributes
    ----------
    spec : FilterSpec
        What was asked.
    order, fc_hz : int, float
        The order and cut-off (from the mask when one was given).
    stages : list of StageDesign
        In build order.
    figures : dict
        Achieved figures against the target (see :func:`design`).
    spice : dict or None
        The SPICE proof's figures when run (:meth:`designer.filters.verify.Proof.to_dict`).
    proof : designer.filters.verify.Proof or None
        The SPICE proof itself (:func:`designer.filters.verify.prove`).
    problem : tuple or None
        The joint search's problem as :func:`~designer.filters.joint.joint_search` took it (errors per stage,
        with a delay target's columns; limits; n_dev), so that a check can enumerate the same candidates.
    """

    spec: FilterSpec
    order: int
    fc_hz: float
    stages: list
    figures: dict = field(default_factory=dict)
    spice: dict | None = None
    proof: object = None
    problem: tuple | None = None

    @property
    def opamp(self):
        """The op-amp model of every stage."""
        return opamps.get(self.spec.opamp)

    def cascade(self, which: str = "chosen") -> Cascade:
        """The cascade of ``chosen`` E-series values, or of the ``continuous`` ones.

        Parameters
        ----------
        which : str
            ``chosen`` or ``continuous``.

        Returns
        -------
        Cascade
            The circuit.
        """
        return Cascade([(get_topology(st.topology), st.values if which == "chosen" else st.continuous)
                        for st in self.stages])

    def deck(self) -> str:
        """The standalone ngspice proof deck of the chosen cascade (:func:`designer.filters.verify.proof_deck`):
        ``ngspice -b`` runs its ``.ac`` and bench ``.tran`` and prints their measurements (the passband
        gain ``passband_db`` and the -3 dB frequency ``f3db_hz``, dB relative to 1 V in, among them).

        Returns
        -------
        str
            The deck's text.
        """
        return proof_deck(self)

    def to_dict(self) -> dict:
        """Everything as JSON-ready data.

        Returns
        -------
        dict
            ``spec``, ``opamp``, ``stages``, ``figures`` and ``spice``.
        """
        s = self.spec
        spec = {"filter_type": s.filter_type, "family": s.family, "order": self.order, "fc_hz": self.fc_hz,
                "ripple_db": s.ripple_db, "bessel_norm": s.bessel_norm,
                "chebyshev_cutoff": s.chebyshev_cutoff, "gain": s.gain,
                "mask": ({"passband_hz": s.passband_hz, "max_loss_db": s.max_loss_db,
                          "stopband_hz": s.stopband_hz, "min_attenuation_db": s.min_attenuation_db}
                         if s.has_mask else None),
                "f_low_hz": s.f_low_hz, "f_high_hz": s.f_high_hz,
                "bandpass_method": (bandpass_method(s.f_low_hz, s.f_high_hz, s.bandpass_method)
                                    if s.filter_type == "bandpass" else None),
                "r_series": s.r_series, "c_series": s.c_series, "amplitude_v": s.amplitude_v,
                "gbw_margin": s.gbw_margin, "compensate_gbw": s.compensate_gbw,
                # only when given: the reference outputs of a split by the design stay as they are
                **({"stage_gains": list(s.stage_gains)} if s.stage_gains is not None else {}),
                **({"delay_target": {"max_delay_error_pct": s.max_delay_error_pct, "delay_to_hz": s.delay_to_hz}}
                   if s.has_delay_target else {})}
        return json_safe({"tool": "design-filter", "schema_version": SCHEMA_VERSION, "spec": spec,
                          "opamp": self.opamp.to_dict(), "stages": [st.to_dict() for st in self.stages],
                          "figures": dict(self.figures), "spice": self.spice})


def section_name(kind: str, order: int, family: str, gain: float) -> str:
    """The registry name of a section of ``family`` (``sallen-key`` or ``mfb``).

    Parameters
    ----------
    kind : str
        ``lowpass`` or ``highpass``.
    order : int
        1 or 2.
    family : str
        ``sallen-key`` or ``mfb``.
    gain : float
        The stage's gain (a Sallen-Key with gain above 1 is the ``-gain`` section).

    Returns
    -------
    str
        A registered name.
    """
    if kind == "bandpass":
        return "mfb-bandpass"   # the registry's one band-pass section, whatever the topology asked
    if order == 1:
        if kind == "lowpass" and (family == "mfb" or gain > 1 + 1e-12):
            return "inverting-lowpass"
        if gain > 1 + 1e-12:     # the follower's RC has unity gain; the inverting section has R2/R1
            return "inverting-highpass"
        return "rc-lowpass" if kind == "lowpass" else "rc-highpass"
    if family == "mfb":
        return f"mfb-{kind}"
    return f"sallen-key-{kind}" + ("-gain" if gain > 1 + 1e-12 else "")


def _neighbours(value: float, series: str, lo: float, hi: float) -> list:
    """The series values either side of ``value`` within [lo, hi] (itself when on the series)."""
    vals = series_values(series, lo / 10, hi * 10)
    on = np.abs(vals / value - 1) < 1e-9
    if np.any(on):
        near = [float(vals[on][0])]
    else:
        below, above = vals[vals < value], vals[vals > value]
        near = ([float(below[-1])] if below.size else []) + ([float(above[0])] if above.size else [])
    return [v for v in near if lo * (1 - 1e-9) <= v <= hi * (1 + 1e-9)]


def _bound_words(ref: str, value: float, spec: FilterSpec) -> str:
    kind = "r" if ref.startswith("R") else "c"
    unit = "Ohm" if kind == "r" else "F"
    lo, hi = getattr(spec, f"{kind}_min"), getattr(spec, f"{kind}_max")
    if value < lo:
        return f"{ref} = {format_eng(value, unit)} is below --{kind}-min {format_eng(lo, unit)}"
    return f"{ref} = {format_eng(value, unit)} is above --{kind}-max {format_eng(hi, unit)}"


def stage_candidates(topology, target: SectionTarget, spec: FilterSpec, where: str) -> tuple:
    """The continuous design and the E-series candidate sets of one stage.

    Parameters
    ----------
    topology : Topology
        The stage's section.
    target : SectionTarget
        Its fn, Q, gain (``impedance_ohm`` the resistor scale).
    spec : FilterSpec
        The series and bounds.
    where : str
        How the stage is named in a refusal ("stage 2 (sallen-key-lowpass, fn 1 kHz, Q 1.31)").

    Returns
    -------
    tuple
        (continuous values at the first capacitor choice, list of candidate dicts,
        index of the all-nearest candidate).

    Raises
    ------
    DesignError
        No candidate within the part bounds (one line naming the part and the bound).
    """
    free = topology.synthesize(target)
    # the resistors scale as 1/C at fixed ratios: move C1 so that they all sit inside the bounds when their
    # spread allows (a high-Q section spreads them by about 4 Q^2 around the impedance)
    rs = [v for r, v in free.items() if r.startswith("R") and r not in topology.choice_parts]
    k_lo, k_hi = spec.r_min / min(rs), spec.r_max / max(rs)
    k = 1.0 if k_lo <= 1.0 <= k_hi else math.sqrt(k_lo * k_hi) if k_lo <= k_hi else 1.0
    ref = topology.reference_capacitor
    c_free = min(max(free[ref] / k, spec.c_min), spec.c_max)
    # the neighbours of the free value and one more either side: the joint search's freedom per stage
    near = series_values(spec.c_series, spec.c_min, spec.c_max)
    c_choices = [float(c) for c in near[np.argsort(np.abs(np.log(near / c_free)))[:C_CHOICES]]] if near.size else []
    if not c_choices:
        raise DesignError(f"c_min: {where}: no {spec.c_series} capacitor between --c-min and --c-max", param="c_min")
    # nearest-in-log first: the continuous design shown is on it
    c_choices.sort(key=lambda c: abs(math.log(c / c_free)))
    choices = {}
    if "r3" in topology.choices:
        rs = series_values(spec.r_series, spec.r_min, spec.r_max)
        choices["r3"] = float(rs[np.argmin(np.abs(np.log(rs / target.impedance_ohm)))])
    index, cands, continuous, nearest, problem = {}, [], None, None, None
    for c1 in c_choices:
        tgt = SectionTarget(target.kind, target.fn_hz, target.q, target.gain, c_f=c1)
        ch = dict(choices)
        if "ratio" in topology.choices:
            bound = topology.limits(tgt).get("ratio_min", 1.0)
            # C2 the least series value at or above the bound: the synthesis stays exact, both capacitors standard
            c2 = series_values(spec.c_series, c1 * max(bound, 1.0) * (1 - 1e-9), c1 * max(bound, 1.0) * 20)
            if c2.size == 0 or c2[0] > spec.c_max * (1 + 1e-9):
                problem = problem or f"the capacitor ratio over {ref} (at least {bound:.4g}) puts the other at " \
                                     f"{format_eng(c1 * max(bound, 1.0), 'F')}, above --c-max " \
                                     f"{format_eng(spec.c_max, 'F')}"
                continue
            ch["ratio"] = float(c2[0]) / c1
        vals = topology.synthesize(tgt, **ch)
        per_part = {}
        for ref, v in vals.items():
            kind = "r" if ref.startswith("R") else "c"
            series = spec.r_series if kind == "r" else spec.c_series
            per_part[ref] = _neighbours(v, series, getattr(spec, f"{kind}_min"), getattr(spec, f"{kind}_max"))
            if not per_part[ref]:
                problem = problem or _bound_words(ref, v, spec)
        if any(not c for c in per_part.values()):
            continue
        if continuous is None:
            continuous = vals
            nearest = tuple(min(per_part[r], key=lambda x, v=vals[r]: abs(math.log(x / v))) for r in vals)
        for combo in itertools.product(*per_part.values()):
            if combo not in index:
                index[combo] = len(cands)
                cands.append(dict(zip(vals, combo)))
    if not cands:
        raise DesignError(f"topology: {where} is not realisable within the part bounds: {problem}; change --fc, "
                          "--impedance or the part bounds", param="topology")
    return continuous, cands, index[nearest]


def analysis_grid(spec: FilterSpec, order: int, fc_hz: float) -> dict:
    """The frequencies the design is judged on.

    Parameters
    ----------
    spec : FilterSpec
        The specification.
    order, fc_hz : int, float
        The order and cut-off (a band-pass's centre).

    Returns
    -------
    dict
        ``passband_edge_hz`` (the mask's, or the ideal's -3 dB point; a Chebyshev's ripple
        edge in the ripple convention; a band-pass's two edges), ``transition_end_hz`` (the
        mask's stopband edge, or where the ideal is 20 dB down; two for a band-pass),
        ``f3_target_hz``, ``passband_range_hz`` and ``objective_range_hz`` (Hz pairs),
        ``objective`` and ``passband`` (Hz arrays) and ``sweep_hz`` (the SPICE sweep).
    """
    kind = spec.filter_type
    wide = np.geomspace(fc_hz / 1000, fc_hz * 1000, 6001)
    db = 20 * np.log10(np.abs(_reference(spec, order, fc_hz, wide)) / spec.gain)
    level3 = -10 * math.log10(2)
    if kind == "bandpass":
        f3 = [_crossing(wide, db, level3, False), _crossing(wide, db, level3, True)]
        if spec.has_mask:
            fp, ft = list(spec.passband_edges), list(spec.stopband_edges)
        else:
            fp = [spec.f_low_hz, spec.f_high_hz]
            ft = [_crossing(wide, db, -TRANSITION_DB, False), _crossing(wide, db, -TRANSITION_DB, True)]
        pb_range, obj_range = (fp[0], fp[1]), (ft[0], ft[1])
    else:
        low = kind == "lowpass"
        f3 = _crossing(wide, db, level3, low)
        if spec.has_mask:
            fp, ft = spec.passband_hz, spec.stopband_hz
        else:
            fp = fc_hz if spec.family == "chebyshev" and spec.chebyshev_cutoff == "ripple" else f3
            ft = _crossing(wide, db, -TRANSITION_DB, low)
        pb_range = (fp / 10, fp) if low else (fp, fp * 10)
        obj_range = (fp / 10, ft) if low else (ft, fp * 10)
    return {"passband_edge_hz": fp, "transition_end_hz": ft, "f3_target_hz": f3,
            "passband_range_hz": tuple(map(float, pb_range)), "objective_range_hz": tuple(map(float, obj_range)),
            "objective": np.geomspace(*obj_range, GRID_POINTS), "passband": np.geomspace(*pb_range, GRID_POINTS // 2),
            "sweep_hz": (float(min(obj_range[0], pb_range[0]) / 30), float(max(obj_range[1], pb_range[1]) * 30))}


def _in_passband(spec: FilterSpec, f) -> np.ndarray:
    """Which of ``f`` lie in the mask's passband (its edges included)."""
    if spec.filter_type == "bandpass":
        lo, hi = spec.passband_edges
        return (f >= lo) & (f <= hi)
    return f <= spec.passband_hz if spec.filter_type == "lowpass" else f >= spec.passband_hz


def _reference(spec: FilterSpec, order: int, fc_hz: float, f) -> np.ndarray:
    """The target H(j 2 pi f): scipy's design at passband gain ``spec.gain``."""
    if spec.filter_type == "bandpass":
        return spec.gain * reference_bandpass(f, spec.family, order, spec.f_low_hz, spec.f_high_hz,
                                              spec.ripple_db or 1.0, spec.bessel_norm, spec.chebyshev_cutoff,
                                              spec.bandpass_method)
    return spec.gain * reference_response(f, spec.filter_type, spec.family, order, fc_hz, spec.ripple_db or 1.0,
                                          spec.bessel_norm, spec.chebyshev_cutoff)


def _crossing(f: np.ndarray, db: np.ndarray, level: float, low: bool) -> float:
    """Where ``db`` (relative to the passband) last stays above ``level`` coming from the passband:
    the highest such f for a low-pass, the lowest for a high-pass; linear in log f between samples."""
    above = np.flatnonzero(db >= level)
    if above.size == 0:
        return float("nan")
    i = above[-1] if low else above[0]
    j = i + 1 if low else i - 1
    if j < 0 or j >= len(f):
        return float(f[i])
    t = (db[i] - level) / (db[i] - db[j])
    return float(math.exp(math.log(f[i]) + t * (math.log(f[j]) - math.log(f[i]))))


#: the gain splits tried in turn until no stage output clips (see :func:`_split_gains`)
GAIN_STRATEGIES = ("lowest-q", "even", "last")


def _split_gains(plans: list, gain: float, strategy: str) -> list:
    """Stage gains: ``lowest-q`` (all in the lowest-Q second-order stage: a Sallen-Key's Q is
    the more sensitive to its gain resistors the higher Q is, SLOA088), ``even`` (equal dB over
    the second-order stages) or ``last`` (all in the last one)."""
    second = [i for i, p in enumerate(plans) if p.order == 2]
    gains = [1.0] * len(plans)
    if not second:
        gains[-1] = gain
    elif strategy == "even":
        for i in second:
            gains[i] = gain ** (1 / len(second))
    elif strategy == "lowest-q":
        gains[min(second, key=lambda i: plans[i].q)] = gain
    else:
        gains[second[-1]] = gain
    return gains


def _node_peaks(plans: list, gains: list, amplitude: float, fc_hz: float, at_hz=None) -> tuple:
    """Each stage's peak gain alone and its output's peak at ``amplitude`` (ideal sections); at one
    frequency ``at_hz`` instead of the peak when given."""
    f = np.geomspace(fc_hz / 1000, fc_hz * 1000, 4001) if at_hz is None else np.array([at_hz])
    s = 2j * math.pi * f
    h_cum = np.ones_like(s)
    peaks, nodes = [], []
    for p, g in zip(plans, gains):
        wn = 2 * math.pi * p.fn_hz
        if p.order == 1:
            h = wn / (s + wn) if p.kind == "lowpass" else s / (s + wn)
        else:
            den = s * s + s * wn / p.q + wn * wn
            h = {"lowpass": wn * wn, "highpass": s * s, "bandpass": s * wn / p.q}[p.kind] / den
        h = g * h
        h_cum = h_cum * h
        peaks.append(float(np.max(np.abs(h))))
        nodes.append(float(amplitude * np.max(np.abs(h_cum))))
    return peaks, nodes


def predistort(topology, target: SectionTarget, opamp) -> SectionTarget:
    """The target whose synthesis, with ``opamp``'s finite gain and GBW, best matches ``target``'s
    ideal response: fn and Q (fn alone for a first-order section) moved by least squares on the
    complex log-ratio of the responses over fn/10 .. 10 fn (gain and phase; scipy.optimize.least_squares).

    Parameters
    ----------
    topology : Topology
        The section.
    target : SectionTarget
        What the section must realise with an ideal op-amp.
    opamp : designer.core.opamps.OpAmp
        The op-amp (A0, GBW).

    Returns
    -------
    SectionTarget
        The pre-distorted target (``target`` itself when the fit cannot improve it).
    """
    from scipy.optimize import least_squares

    s = 2j * math.pi * np.geomspace(target.fn_hz / 10, target.fn_hz * 10, 61)
    ideal = topology.response(topology.synthesize(target), s)

    def moved(x):
        q = None if target.q is None else target.q * math.exp(x[1])
        return SectionTarget(target.kind, target.fn_hz * math.exp(x[0]), q, target.gain, target.impedance_ohm,
                             target.c_f)

    def residual(x):
        try:
            h = topology.response(topology.synthesize(moved(x)), s, opamp)
        except DesignError:   # outside the topology's limits: a large, smooth penalty
            return np.full(2 * s.size, 10.0)
        r = np.log(h / ideal)
        return np.concatenate([r.real, r.imag])

    x0 = np.zeros(1 if target.q is None else 2)
    fit = least_squares(residual, x0, x_scale=0.1)
    better = np.sum(residual(fit.x) ** 2) < np.sum(residual(x0) ** 2)
    return moved(fit.x) if better else target


def _noise_gain(topology, gain: float) -> float:
    return 1.0 + gain if topology.inverting else gain


def _check_gbw(number: int, plan: SectionPlan, name: str, gain: float, need: float, spec: FilterSpec,
               opamp) -> None:
    """Refuse a stage whose op-amp is too slow (one line naming the catalogue's op-amp that is fast enough)."""
    if need <= opamp.gbw_hz:
        return
    ok = opamps.fast_enough(need)
    instead = f"use {ok.name} ({format_eng(ok.gbw_hz, 'Hz')})" if ok else \
        "no catalogue op-amp is fast enough: lower fc, Q or the gain"
    q = f", Q {plan.q:.3g}" if plan.q else ""
    raise DesignError(
        f"opamp: {opamp.name} (GBW {format_eng(opamp.gbw_hz, 'Hz')}) is too slow for stage {number} ({name}, fn "
        f"{format_eng(plan.fn_hz, 'Hz')}{q}, gain {gain:.3g}): it needs GBW >= {spec.gbw_margin:g} x fn x Q x "
        f"noise gain = {format_eng(need, 'Hz')}; {instead}, or lower --gbw-margin", param="opamp")


def design(spec: FilterSpec, simulate: bool = False, simulator: str = "ngspice-cli") -> FilterDesign:
    """Design the filter ``spec`` asks for.

    Parameters
    ----------
    spec : FilterSpec
        The specification.
    simulate : bool
        Also run the SPICE proof (:func:`designer.filters.verify.prove`: ngspice ``.ac`` and ``.tran``
        of the chosen cascade against the analytic one).
    simulator : str
        ``ngspice-cli`` or ``pyspice``.

    Returns
    -------
    FilterDesign
        Stages in build order, parts chosen jointly, and the figures: ``error_joint_db``,
        ``error_per_stage_db``, ``error_nearest_db``, ``error_continuous_db`` (the worst
        deviation from the ideal over the objective grid, op-amp included, of each
        choice), ``passband_deviation_db``, ``f3_hz`` against ``f3_target_hz``, the
        search's size and time; with a mask, its margins (``mask_passband_margin_db``,
        ``mask_stopband_margin_db``) and how far each choice breaks it (``mask_violation_*_db``); with a
        group-delay target, the joint choice's delay figures (:func:`delay_figures`) and the per-stage
        rounding's and the all-nearest's beside them (``delay_error_per_stage_pct``,
        ``delay_target_met_per_stage``, ``delay_error_nearest_pct``, ``delay_target_met_nearest``).

    Raises
    ------
    DesignError
        Anything unrealisable, one line: the order a mask needs above 10, a stage no
        section realises within the bounds, an op-amp too slow, a node that clips.
    """
    opamp = opamps.get(spec.opamp)
    order, fc, plans = section_plans(spec)
    total_gain, strategies = spec.gain, GAIN_STRATEGIES
    if spec.filter_type == "bandpass":
        if plans[0].kind == "bandpass":
            # band-pass sections peak at their own fn: the product of the section gains that gives spec.gain at
            # the centre; spread evenly first (an MFB band-pass section's gain must stay below 2 Q^2)
            _, at_centre = _node_peaks(plans, [1.0] * len(plans), 1.0, fc, at_hz=fc)
            total_gain, strategies = spec.gain / at_centre[-1], ("even", "lowest-q", "last")
    n = len(plans)
    if spec.stage_order is not None:
        if sorted(spec.stage_order) != list(range(1, n + 1)):
            raise DesignError(f"stage_order must list the stages 1 to {n} (in rising Q) once each, got "
                              f"{','.join(map(str, spec.stage_order))}", param="stage_order")
        plans = [plans[i - 1] for i in spec.stage_order]
    if len(spec.topology) not in (1, n):
        raise DesignError(f"topology: give one topology or one per stage ({n} stages), got {len(spec.topology)}",
                          param="topology")
    families = list(spec.topology) * n if len(spec.topology) == 1 else list(spec.topology)
    swing = min(opamp.vout_max, -opamp.vout_min)
    if spec.stage_gains is not None:
        if plans[0].kind == "bandpass":
            raise DesignError("stage_gains: a narrow band-pass's sections peak at their own fn, their gains are "
                              "split by the design; give gain only (or bandpass_method wide)", param="stage_gains")
        if len(spec.stage_gains) != n:
            raise DesignError(f"stage_gains: give one gain per stage ({n} stages, in build order), got "
                              f"{len(spec.stage_gains)}", param="stage_gains")
        strategies = ("given",)
    for strategy in strategies:
        gains = list(spec.stage_gains) if strategy == "given" else _split_gains(plans, total_gain, strategy)
        peaks, nodes = _node_peaks(plans, gains, spec.amplitude_v, fc)
        if max(nodes) <= swing:
            break
    else:
        worst = int(np.argmax(nodes))
        change = "--stage-gain" if spec.stage_gains is not None else "--gain"
        raise DesignError(f"amplitude_v: stage {worst + 1}'s output peaks at {nodes[worst]:.3g} V at --amplitude "
                          f"{spec.amplitude_v:g} V, beyond {opamp.name}'s swing of +-{swing:.3g} V; lower "
                          f"--amplitude or {change}", param="amplitude_v")
    grid = analysis_grid(spec, order, fc)
    limits = None
    if spec.has_mask:
        # the mask's edges as two more columns of the objective, with one-sided limits (joint.py): the sum S of
        # the stages' dB errors may lower the passband edge's gain, or raise the stopband edge's, by the ideal
        # response's own margin there and no more
        # (a band-pass: both passband edges and both stopband edges)
        edges = np.array([*spec.passband_edges, *spec.stopband_edges])
        n_pass = len(spec.passband_edges)
        ideal = 20 * np.log10(np.abs(_reference(spec, order, fc, edges) / spec.gain))
        n0 = grid["objective"].size
        grid["objective"] = np.append(grid["objective"], edges)
        limits = [(n0 + i, -1.0, -(spec.max_loss_db + ideal[i])) if i < n_pass else
                  (n0 + i, 1.0, -(-ideal[i] - spec.min_attenuation_db)) for i in range(edges.size)]
        # the loss is limited over the whole passband, not at its edge only (a Chebyshev's ripple troughs
        # inside it sit at the ideal's full ripple: the parts may not deepen them past --max-loss)
        f_obj = grid["objective"][:n0]
        inside = _in_passband(spec, f_obj)
        ideal_in = 20 * np.log10(np.abs(_reference(spec, order, fc, f_obj[inside]) / spec.gain))
        limits += [(int(c), -1.0, -(spec.max_loss_db + d)) for c, d in zip(np.flatnonzero(inside), ideal_in)]
    f_obj = grid["objective"]
    s_obj = 2j * math.pi * f_obj
    stages = []
    t0 = time.perf_counter()
    for i, (p, g, fam) in enumerate(zip(plans, gains, families), 1):
        target = SectionTarget(p.kind, p.fn_hz, p.q, g, impedance_ohm=spec.impedance_ohm)
        tries = ["sallen-key", "mfb"] if fam == "auto" else [fam]
        for k, fam_try in enumerate(tries):
            name = section_name(p.kind, p.order, fam_try, g)
            topo = get_topology(name)
            q = f", Q {p.q:.4g}" if p.q else ""
            where = f"stage {i} ({name}, fn {format_eng(p.fn_hz, 'Hz')}{q}, gain {g:.4g})"
            need = spec.gbw_margin * p.fn_hz * (p.q or 1.0) * _noise_gain(topo, g)
            _check_gbw(i, p, name, g, need, spec, opamp)
            try:
                built = predistort(topo, target, opamp) if spec.compensate_gbw else target
                continuous, cands, nearest = stage_candidates(topo, built, spec, where)
                break
            except DesignError:
                if k == len(tries) - 1:
                    raise
        # the stage's ideal: the asked target's (a pre-distorted design aims its op-amp-aware response at it)
        stages.append(StageDesign(i, p, name, g, continuous, cands, _stage_errors(topo, target, cands, s_obj, opamp),
                                  nearest,
                                  peak_gain=peaks[i - 1], node_peak_v=nodes[i - 1],
                                  gbw_needed_hz=need, fn_design_hz=built.fn_hz, q_design=built.q))
    pruned = _prune(stages)
    errors = [st.errors for st in stages]
    search, all_limits, n_dev = errors, limits, None
    if spec.has_delay_target:
        # the delay target as more limit columns, read by the limits only (joint.py's rule)
        f_d, dw = _delay_grid(spec, fc)
        for st in stages:
            topo = get_topology(st.topology)
            st.delays = central_delay(lambda sv, t=topo, c=st.candidates: t.response(
                {r: np.array([v[r] for v in c])[:, None] for r in t.designators}, sv[None, :], opamp), f_d, dw)
        tau_ref = float(group_delay(prototype_zpk(spec.family, order, 1.0, spec.bessel_norm), [0.0], fc)[0])
        n_dev = errors[0].shape[1]
        cols, d_limits = delay_columns([st.delays for st in stages], spec.max_delay_error_pct, tau_ref, n_dev)
        search = [np.hstack([e, c]) for e, c in zip(errors, cols)]
        all_limits = (limits or []) + d_limits
    t_cand = time.perf_counter() - t0
    t1 = time.perf_counter()
    choice, j_joint, examined = joint_search(search, limits=all_limits, n_dev=n_dev)
    t_search = time.perf_counter() - t1
    for st, c in zip(stages, choice):
        st.chosen = c
    result = FilterDesign(spec, order, fc, stages, problem=(search, all_limits, n_dev))
    result.figures = _figures(result, grid, errors, choice, j_joint, examined, t_cand, t_search)
    result.figures["candidates_dropped"] = pruned
    if limits:
        # how far each choice breaks the mask (0: met), on the same columns
        for key, ch in (("joint", choice), ("per_stage", per_stage(errors)), ("nearest", [st.nearest for st in stages])):
            total = sum(e[c] for e, c in zip(errors, ch))
            result.figures[f"mask_violation_{key}_db"] = max(0.0, *(o + sg * total[col] for col, sg, o in limits))
    if spec.has_delay_target:
        # what the per-stage rounding (and every part's nearest value) would give for the delay, beside the joint's
        for key, ch in (("per_stage", per_stage(errors)), ("nearest", [st.nearest for st in stages])):
            tau = sum(st.delays[c] for st, c in zip(stages, ch))
            result.figures[f"delay_error_{key}_pct"] = delay_error_pct(tau, tau[0])
            result.figures[f"delay_target_met_{key}"] = bool(result.figures[f"delay_error_{key}_pct"]
                                                             <= spec.max_delay_error_pct)
    if simulate:
        result.proof = prove(result, simulator)
        result.spice = result.proof.to_dict()
    return result


def section_plans(spec: FilterSpec) -> tuple:
    """The order, cut-off (a band-pass: its centre) and sections, in rising Q, that ``spec`` asks for
    (from its mask when it has one).

    Parameters
    ----------
    spec : FilterSpec
        The specification.

    Returns
    -------
    tuple
        (order, fc in Hz, list of SectionPlan).

    Raises
    ------
    DesignError
        A mask that needs more than order 10 (one line).
    """
    if spec.has_mask and spec.filter_type != "bandpass":   # a band-pass's mask gave its order and edges
        order, fc = order_from_mask(spec.filter_type, spec.family, spec.passband_hz, spec.max_loss_db,
                                    spec.stopband_hz, spec.min_attenuation_db, spec.bessel_norm,
                                    spec.max_delay_error_pct, spec.delay_to_hz)
    else:
        order, fc = spec.order, spec.fc_hz
    conv = (spec.ripple_db or 1.0, spec.bessel_norm, spec.chebyshev_cutoff)
    if spec.filter_type == "bandpass":
        fc = math.sqrt(spec.f_low_hz * spec.f_high_hz)
        return order, fc, plan_bandpass(spec.family, order, spec.f_low_hz, spec.f_high_hz, *conv,
                                        spec.bandpass_method)
    return order, fc, plan_sections(spec.filter_type, spec.family, order, fc, *conv)


def _stage_errors(topo, target: SectionTarget, cands: list, s_obj, opamp) -> np.ndarray:
    """(candidates, f) dB error of each candidate's op-amp-aware response against the stage's ideal:
    the asked target's (a pre-distorted design aims its op-amp-aware response at it)."""
    ideal_db = 20 * np.log10(np.abs(topo.response(topo.synthesize(target), s_obj)))
    arrays = {r: np.array([c[r] for c in cands])[:, None] for r in topo.designators}
    cand_db = 20 * np.log10(np.abs(topo.response(arrays, s_obj[None, :], opamp)))
    return cand_db - ideal_db[None, :]


def as_built(spec: FilterSpec, order: int, fc_hz: float, stages: list, simulate: bool = False,
             simulator: str = "ngspice-cli") -> FilterDesign:
    """A filter of given parts (as built, or as a design-filter result lists them), judged as
    :func:`design` judges its choice: the achieved response against ``spec``'s target, its mask.

    Parameters
    ----------
    spec : FilterSpec
        What the filter should do.
    order, fc_hz : int, float
        Its order and cut-off (a band-pass: its centre).
    stages : list of tuple
        Per stage, input first: (SectionPlan, registry name, gain, part values).
    simulate : bool
        Also run the SPICE proof.
    simulator : str
        ``ngspice-cli`` or ``pyspice``.

    Returns
    -------
    FilterDesign
        One candidate per stage (its parts); the figures of :func:`design` (the joint, per-stage
        and nearest errors are this one set's).

    Raises
    ------
    DesignError
        A stage's parts not matching its topology's (one line).
    """
    opamp = opamps.get(spec.opamp)
    grid = analysis_grid(spec, order, fc_hz)
    s_obj = 2j * math.pi * grid["objective"]
    built = []
    for i, (plan, name, gain, values) in enumerate(stages, 1):
        topo = get_topology(name)
        vals = {r: float(v) for r, v in topo.values_of(values).items()}
        target = SectionTarget(plan.kind, plan.fn_hz, plan.q, gain, impedance_ohm=spec.impedance_ohm)
        errors = _stage_errors(topo, target, [vals], s_obj, opamp)
        need = spec.gbw_margin * plan.fn_hz * (plan.q or 1.0) * _noise_gain(topo, gain)
        built.append(StageDesign(i, plan, name, gain, vals, [vals], errors, 0, gbw_needed_hz=need))
    result = FilterDesign(spec, order, fc_hz, built)
    errors = [st.errors for st in built]
    result.figures = _figures(result, grid, errors, [0] * len(built), objective(errors, [0] * len(built)), 1, 0.0, 0.0)
    result.figures["candidates_dropped"] = 0
    if spec.has_mask:
        for key in ("joint", "per_stage", "nearest"):
            result.figures[f"mask_violation_{key}_db"] = max(0.0, -result.figures["mask_passband_margin_db"],
                                                             -result.figures["mask_stopband_margin_db"])
    # each stage's peak gain and its output's peak at the bench amplitude, from its own parts (op-amp-aware)
    f = np.geomspace(fc_hz / 1000, fc_hz * 1000, 4001)
    h_cum = np.ones(f.size, complex)
    for st in built:
        h = get_topology(st.topology).response(st.values, 2j * math.pi * f, opamp)
        h_cum = h_cum * h
        st.peak_gain = float(np.max(np.abs(h)))
        st.node_peak_v = float(spec.amplitude_v * np.max(np.abs(h_cum)))
    if simulate:
        result.proof = prove(result, simulator)
        result.spice = result.proof.to_dict()
    return result


def _prune(stages: list) -> int:
    """Keep the search within :data:`MAX_COMBINATIONS`: while the product of the candidate counts is
    above it, the stage with the most candidates drops its worst one by its own error (its all-nearest
    and its own best candidates are kept). Returns the number dropped."""
    dropped = 0
    while np.prod([len(st.candidates) for st in stages], dtype=float) > MAX_COMBINATIONS:
        st = max(stages, key=lambda x: len(x.candidates))
        own = np.max(np.abs(st.errors), axis=1)
        own[st.nearest] = -1.0   # never drop the all-nearest choice: the report compares with it
        worst = int(np.argmax(own))
        keep = [i for i in range(len(st.candidates)) if i != worst]
        st.candidates = [st.candidates[i] for i in keep]
        st.errors = st.errors[keep]
        st.nearest = keep.index(st.nearest)
        dropped += 1
    return dropped


def _figures(result: FilterDesign, grid: dict, errors, choice, j_joint, examined, t_cand, t_search) -> dict:
    spec, opamp, stages = result.spec, result.opamp, result.stages
    cont = result.cascade("continuous")
    chosen = result.cascade()
    f_obj = grid["objective"]
    ideal_obj = 20 * np.log10(np.abs(_reference(spec, result.order, result.fc_hz, f_obj)))
    cont_db = 20 * np.log10(np.abs(cont.response(2j * math.pi * f_obj, opamp)))
    pb = grid["passband"]
    dev_pb = np.abs(20 * np.log10(np.abs(chosen.response(2j * math.pi * pb, opamp)))
                    - 20 * np.log10(np.abs(_reference(spec, result.order, result.fc_hz, pb))))
    wide = np.geomspace(result.fc_hz / 1000, result.fc_hz * 1000, 6001)
    g_db = 20 * math.log10(spec.gain)
    got_db = 20 * np.log10(np.abs(chosen.response(2j * math.pi * wide, opamp))) - g_db
    level3 = -10 * math.log10(2)
    if spec.filter_type == "bandpass":
        f3 = [_crossing(wide, got_db, level3, False), _crossing(wide, got_db, level3, True)]
    else:
        f3 = _crossing(wide, got_db, level3, spec.filter_type == "lowpass")
    figs = {
        "order": result.order, "fc_hz": result.fc_hz,
        "passband_edge_hz": grid["passband_edge_hz"], "transition_end_hz": grid["transition_end_hz"],
        "f3_target_hz": grid["f3_target_hz"], "f3_hz": f3,
        "passband_range_hz": grid["passband_range_hz"], "objective_range_hz": grid["objective_range_hz"],
        "passband_deviation_db": float(np.max(dev_pb)),
        "error_joint_db": objective(errors, choice),
        "error_per_stage_db": objective(errors, per_stage(errors)),
        "error_nearest_db": objective(errors, [st.nearest for st in stages]),
        "error_continuous_db": float(np.max(np.abs(cont_db - ideal_obj))),
        "combinations": int(np.prod([len(e) for e in errors], dtype=float)),
        "examined": int(examined), "candidates_s": t_cand, "search_s": t_search,
        "inverting": sum(get_topology(st.topology).inverting for st in stages) % 2 == 1,
        "sweep_hz": grid["sweep_hz"],
    }
    if spec.has_delay_target:
        figs.update(delay_figures(spec, result.order, result.fc_hz, lambda s: chosen.response(s, opamp)))
    if spec.has_mask:
        h = lambda f: 20 * math.log10(abs(complex(chosen.response(2j * math.pi * f, opamp)))) - g_db  # noqa: E731
        figs["mask_passband_margin_db"] = spec.max_loss_db + min(h(f) for f in spec.passband_edges)
        figs["mask_stopband_margin_db"] = -max(h(f) for f in spec.stopband_edges) - spec.min_attenuation_db
    return figs


def delay_figures(spec: FilterSpec, order: int, fc_hz: float, response) -> dict:
    """A group-delay target's figures: the largest departure of the delay from its DC value, % of it, from
    DC to ``spec.delay_to_hz``, of ``response`` (the chosen parts' cascade; by a central difference of its
    phase, tau = -arg(H(j(w + dw)) / H(j(w - dw))) / (2 dw), which holds at DC too, H(-jw) being H(jw)'s
    conjugate) and of the ideal prototype (exact from its poles, :func:`~designer.filters.prototype.group_delay`).

    Parameters
    ----------
    spec : FilterSpec
        With a delay target.
    order, fc_hz : int, float
        The design's order and cut-off.
    response : callable
        s (rad/s, complex array) -> H.

    Returns
    -------
    dict
        ``delay_error_pct`` (the parts'), ``delay_error_ideal_pct``, ``delay_dc_s``, ``delay_target_met``.
    """
    f, dw = _delay_grid(spec, fc_hz)
    tau = central_delay(response, f, dw)
    ideal = group_delay(prototype_zpk(spec.family, order, 1.0, spec.bessel_norm), f, fc_hz)
    err = delay_error_pct(tau, tau[0])
    return {"delay_error_pct": err, "delay_error_ideal_pct": delay_error_pct(ideal, ideal[0]),
            "delay_dc_s": float(tau[0]), "delay_target_met": bool(err <= spec.max_delay_error_pct)}


def _delay_grid(spec: FilterSpec, fc_hz: float) -> tuple:
    """The frequencies a delay target is judged on (DC to its frequency, DELAY_POINTS) and the half-step dw."""
    return np.linspace(0.0, spec.delay_to_hz, DELAY_POINTS), 2 * math.pi * fc_hz * 1e-4


def central_delay(response, f, dw: float) -> np.ndarray:
    """The group delay by a central difference of the phase, -arg(H(j(w + dw)) / H(j(w - dw))) / (2 dw)
    (:func:`delay_figures`; at DC too, H(-jw) being H(jw)'s conjugate).

    Parameters
    ----------
    response : callable
        s (rad/s, complex array) -> H, along the last axis (rows of candidates or builds allowed).
    f : array_like
        Frequencies, Hz.
    dw : float
        The half-step, rad/s.

    Returns
    -------
    ndarray
        Group delay, s.
    """
    w = 2 * math.pi * np.asarray(f, float)
    return -np.angle(response(1j * (w + dw)) / response(1j * (w - dw))) / (2 * dw)


def with_choice(result: FilterDesign, choice, simulate: bool = False, simulator: str = "ngspice-cli") -> FilterDesign:
    """``result`` built with another candidate of each stage (``--optimize yield --apply-optimum``: the
    yield-optimal set): the achieved figures (``f3_hz``, ``passband_deviation_db``, the mask margins) are the
    new set's, ``error_built_db`` its worst deviation on the joint search's objective; ``error_joint_db``
    and the other search figures stay the joint choice's, reported beside it.

    Parameters
    ----------
    result : FilterDesign
        The design (its stages' candidates).
    choice : sequence of int
        Per stage, the candidate index to build.
    simulate : bool
        Also run the SPICE proof of the new set.
    simulator : str
        ``ngspice-cli`` or ``pyspice``.

    Returns
    -------
    FilterDesign
        A new design; ``result`` is left as it is.
    """
    import dataclasses
    stages = [dataclasses.replace(st, chosen=int(c)) for st, c in zip(result.stages, choice)]
    out = FilterDesign(result.spec, result.order, result.fc_hz, stages)
    grid = analysis_grid(result.spec, result.order, result.fc_hz)
    errors = [st.errors for st in stages]
    f = result.figures
    figs = _figures(out, grid, errors, list(choice), None, f.get("examined", 0), f.get("candidates_s", 0.0),
                    f.get("search_s", 0.0))
    out.figures = {**f, **{k: figs[k] for k in ("f3_hz", "passband_deviation_db", "mask_passband_margin_db",
                                                "mask_stopband_margin_db", "delay_error_pct", "delay_dc_s",
                                                "delay_target_met") if k in figs},
                   "error_built_db": objective(errors, list(choice)), "built": "yield-optimal"}
    if simulate:
        out.proof = prove(out, simulator)
        out.spice = out.proof.to_dict()
    return out


def verify_spice(result: FilterDesign, simulator: str = "ngspice-cli") -> dict:
    """ngspice ``.ac`` of the chosen cascade against its analytic response with the
    op-amp-aware model (the same A0 and GBW as the deck's behavioural op-amp).

    Parameters
    ----------
    result : FilterDesign
        The design.
    simulator : str
        ``ngspice-cli`` or ``pyspice``.

    Returns
    -------
    dict
        ``max_deviation_passband_db`` (over the passband grid's span) and
        ``max_deviation_60db_db`` (wherever the response is within 60 dB of the
        passband gain), ``points``.
    """
    lo, hi = result.figures["sweep_hz"]
    opamp = result.opamp
    chosen = result.cascade()
    f, h = simulate_ac(chosen.netlist(), opamp, lo, hi, simulator=simulator)
    an = chosen.response(2j * math.pi * f, opamp)
    dev = np.abs(20 * np.log10(np.abs(h)) - 20 * np.log10(np.abs(an)))
    a, b = result.figures["passband_range_hz"]
    in_pb = (f >= a * (1 - 1e-9)) & (f <= b * (1 + 1e-9))
    within = 20 * np.log10(np.abs(an)) >= 20 * math.log10(result.spec.gain) - 60
    return {"simulator": simulator, "points": int(f.size),
            "max_deviation_passband_db": float(np.max(dev[in_pb])),
            "max_deviation_60db_db": float(np.max(dev[within]))}
