"""Tolerance of a designed active filter (:mod:`designer.filters.design`) against
its mask: every part of every stage drawn within its tolerance (the series'
default, or ``--tol``), the figures the mask needs, the yield with its 95 %
Wilson interval, the stage and the part to buy tighter, the worst case over the
tolerance box, and the E-series set that maximises the yield (``--optimize
yield``).

Engines (both ``evaluate(context, values) -> {figure: array}``, chunked by
:mod:`.runner` so ``--jobs`` and ``--dask`` run them as the plant's Monte Carlo does):

- analytic (:func:`evaluate`), vectorised over the builds and the stages: each
  stage's ideal H(s) from its closed-form coefficients
  (:meth:`designer.filters.topology.Topology.coefficients`, arrays of part values),
  times its op-amp factor H_opamp / H_ideal (the nodal analysis'), expanded to first
  order in the log of each part around the nominal (the factor and its derivatives
  computed once, by central differences): exact at the nominal, its error second
  order in the parts' deviations; the SPICE engine has no such approximation and
  the disagreement is reported;
- SPICE (:func:`spice_evaluate`): the cascade's deck loaded once per chunk and, per
  build, ``alter`` of every part by its designator (R101 is stage 1's R1), an
  ``.ac`` sweep and ``meas`` of the gain at the same frequencies.

Figures (dB relative to the passband gain): ``passband_loss_db`` the largest loss
over the passband (a decade inside its edge: the mask's and the design's grid),
``ripple_db`` the gain's spread over it, ``f3_hz`` (``f3_low_hz``/``f3_high_hz``
for a band-pass) the -3 dB crossing, ``stopband_attenuation_db`` the least
attenuation over the stopband (a decade beyond its edge), ``group_delay_s``
-d(phase)/d(omega) at the passband's low end (a band-pass: its centre); with a
Bessel's group-delay target, ``delay_error_pct``, the build's own delay error as
:func:`designer.filters.design.delay_figures` takes it (the central difference of
the phase, half-step 2 pi fc 1e-4, at the DELAY_POINTS points from DC to the
target's frequency; at DC the pair is H(j dw) and its conjugate), which joins the
mask's limits: a build passes only if it meets the mask and the delay target, and
the part to tighten is judged on both.

The yield's interval is Wilson's (:func:`designer.tolerance.stats.wilson`); the part
to tighten is the one whose tolerance halved, on the same draws, raises the yield
most, and the stage the one whose every tolerance halved does. ``--optimize yield``
compares candidate sets on common random numbers: every set's builds use the same
relative deviations (the draws of one seed), so a difference in yield is the sets',
not the draws'; a coordinate ascent from the joint choice over each stage's
E-series candidates keeps a change only when it raises that yield, so the result
is never below the joint choice's on those draws.
"""

from __future__ import annotations

import math
import re
from dataclasses import dataclass, field

import numpy as np

from ..core.errors import DesignError
from ..core.figure_titles import figure_spread
from ..filters.prototype import DELAY_POINTS
from ..filters.registry import get as get_topology
from ..filters.verify import mask_edges
from . import runner, sampling
from .montecarlo import check_draw
from .parts import resolve
from .stats import Limit, failing_samples, figure_stats, parse_limit, variance_shares, wilson

__all__ = ["LOWHIGH_FIGURES", "BANDPASS_FIGURES", "FilterContext", "FilterMonteCarlo", "YieldOptimum", "figures_of",
           "context", "nominal_parts", "series_of", "mask_limits", "stage_responses", "evaluate", "spice_context",
           "spice_evaluate", "filter_monte_carlo", "filter_worst_case", "optimize_yield",
           "filter_spec_yield"]

#: the figures of a low- or high-pass
LOWHIGH_FIGURES = ("passband_loss_db", "ripple_db", "f3_hz", "stopband_attenuation_db", "group_delay_s")
#: the figures of a band-pass
BANDPASS_FIGURES = ("passband_loss_db", "ripple_db", "f3_low_hz", "f3_high_hz", "stopband_attenuation_db",
                    "group_delay_s")
#: points over the passband and the stopband, and around each -3 dB point (within a factor F3_SPAN)
PASS_POINTS, STOP_POINTS, F3_POINTS, F3_SPAN = 24, 16, 32, 1.6
#: the relative step of the group delay's phase difference
GD_STEP = 1e-3
#: SPICE builds per ngspice run
SPICE_BATCH = 200
#: coordinate-ascent rounds of --optimize yield (each tries every stage's every candidate)
MAX_ROUNDS = 4


@dataclass(frozen=True)
class FilterContext:
    """What every build of one design shares (picklable: names, numbers and arrays).

    Attributes
    ----------
    kind : str
        ``lowpass``, ``highpass`` or ``bandpass``.
    stages : tuple
        Per stage (registry name, designator prefix, its designators).
    gain_db : float
        The passband gain, dB.
    f : ndarray
        Every frequency evaluated (Hz): passband, stopband, -3 dB windows, group-delay pair.
    sl : dict
        Name -> (start, stop) of each group in ``f``.
    correction : tuple of ndarray
        Per stage, ln(H_opamp/H_ideal) of its nominal parts on ``f`` (zeros for the ideal op-amp).
    sensitivity : tuple of ndarray
        Per stage, d ln(H_opamp/H_ideal) / d ln(part), shape (its parts, ``f``).
    nominal : tuple of ndarray
        Per stage, its nominal part values (designator order).
    delay_dw : float
        With a group-delay target, the central difference's half-step (rad/s; ``f`` then ends with the
        groups ``dlp`` and ``dlm``, the DELAY_POINTS points plus and, but DC, minus it); 0 without one.
    """

    kind: str
    stages: tuple
    gain_db: float
    f: np.ndarray
    sl: dict
    correction: tuple
    sensitivity: tuple
    nominal: tuple
    delay_dw: float = 0.0

    @property
    def figures(self) -> tuple:
        """The figures this filter's builds have."""
        return (BANDPASS_FIGURES if self.kind == "bandpass" else LOWHIGH_FIGURES) + \
            (("delay_error_pct",) if self.delay_dw else ())


def nominal_parts(result) -> dict:
    """Every part of the chosen cascade by its cascade designator (R101 is stage 1's R1).

    Parameters
    ----------
    result : designer.filters.FilterDesign
        The design.

    Returns
    -------
    dict
        Designator -> value (ohm, farad).
    """
    return dict(result.cascade().values)


def series_of(result) -> dict:
    """``{"R": series, "C": series}`` of a design (its parts' default tolerances).

    Parameters
    ----------
    result : designer.filters.design.FilterDesign
        The design.

    Returns
    -------
    dict
        ``"R"`` and ``"C"`` -> the E-series name.
    """
    return {"R": result.spec.r_series, "C": result.spec.c_series}


def context(result, stage_values=None, edges=None) -> FilterContext:
    """The analytic engine's context of ``result`` (its chosen parts, or ``stage_values``: one
    designator -> value dict per stage, for another candidate set).

    Parameters
    ----------
    result : designer.filters.FilterDesign
        The design.
    stage_values : list of dict, optional
        Per stage its part values (default the chosen ones).
    edges : tuple, optional
        (passband edge, stopband edge) to judge at, such as a check spec's own ``mask:``
        (default :func:`designer.filters.verify.mask_edges`).

    Returns
    -------
    FilterContext
        Frequencies and each stage's op-amp factor.
    """
    kind = result.spec.filter_type
    fp, fs = edges if edges is not None else mask_edges(result)
    f3 = result.figures["f3_target_hz"]
    groups = {}
    if kind == "bandpass":
        groups["pass"] = np.geomspace(fp[0], fp[1], PASS_POINTS)
        groups["stop"] = np.concatenate([np.geomspace(fs[0] / 10, fs[0], STOP_POINTS // 2),
                                         np.geomspace(fs[1], fs[1] * 10, STOP_POINTS // 2)])
        groups["f3lo"] = np.geomspace(f3[0] / F3_SPAN, min(f3[0] * F3_SPAN, result.fc_hz), F3_POINTS)
        groups["f3hi"] = np.geomspace(max(f3[1] / F3_SPAN, result.fc_hz), f3[1] * F3_SPAN, F3_POINTS)
        at = result.fc_hz
    else:
        low = kind == "lowpass"
        groups["pass"] = np.geomspace(fp / 10, fp, PASS_POINTS) if low else np.geomspace(fp, fp * 10, PASS_POINTS)
        groups["stop"] = np.geomspace(fs, fs * 10, STOP_POINTS) if low else np.geomspace(fs / 10, fs, STOP_POINTS)
        groups["f3"] = np.geomspace(f3 / F3_SPAN, f3 * F3_SPAN, F3_POINTS)
        at = fp / 10 if low else fp * 10
    groups["gd"] = np.array([at * (1 - GD_STEP), at * (1 + GD_STEP)])
    dw = 0.0
    if result.spec.has_delay_target:
        # design.delay_figures' grid and step, so the nominal build's figure is the design's
        f_d, dw = np.linspace(0.0, result.spec.delay_to_hz, DELAY_POINTS), 2 * math.pi * result.fc_hz * 1e-4
        groups["dlp"], groups["dlm"] = f_d + dw / (2 * math.pi), f_d[1:] - dw / (2 * math.pi)
    sl, start = {}, 0
    for k, v in groups.items():
        sl[k] = (start, start + v.size)
        start += v.size
    f = np.concatenate(list(groups.values()))
    op = result.opamp
    stage_values = stage_values or [st.values for st in result.stages]
    stages, corr, sens, nom = [], [], [], []
    s = 2j * math.pi * f
    for i, (st, vals) in enumerate(zip(result.stages, stage_values), 1):
        topo = get_topology(st.topology)
        stages.append((st.topology, f"{i}0", topo.designators))
        c, d = _correction(topo, vals, s, op)
        corr.append(c)
        sens.append(d)
        nom.append(np.array([vals[r] for r in topo.designators], float))
    return FilterContext(kind, tuple(stages), 20 * math.log10(result.spec.gain), f, sl, tuple(corr), tuple(sens),
                         tuple(nom), dw)


#: the relative step of the op-amp factor's sensitivities (central differences)
SENS_STEP = 1e-4


def _correction(topo, values: dict, s, opamp) -> tuple:
    """ln(H_opamp / H_ideal) of one stage's parts on ``s`` and its derivative in the log of each part
    (central differences; zeros for the ideal op-amp): the factor is then first-order in each build's
    deviation, its error second-order (about (tol)^2 of the factor's own size)."""
    refs = topo.designators
    if opamp.ideal:
        return np.zeros(s.shape, complex), np.zeros((len(refs),) + s.shape, complex)
    def log_factor(vals):
        return np.log(topo.response(vals, s, opamp) / topo.response(vals, s))
    base = log_factor(values)
    rows = []
    for r in refs:
        up = log_factor({**values, r: values[r] * (1 + SENS_STEP)})
        down = log_factor({**values, r: values[r] * (1 - SENS_STEP)})
        rows.append((up - down) / math.log((1 + SENS_STEP) / (1 - SENS_STEP)))
    return base, np.array(rows)


def _squared_magnitude(coef: np.ndarray, x: np.ndarray) -> np.ndarray:
    """|P(j w)|^2 of a polynomial of degree at most 2 for every build, at x = w^2: with
    P = c2 s^2 + c1 s + c0 (``coef`` (builds, k), highest power first),

        |P(j w)|^2 = (c0 - c2 w^2)^2 + (c1 w)^2 = c0^2 + (c1^2 - 2 c0 c2) x + c2^2 x^2,

    a polynomial in x whose coefficients are per build (Horner's rule over the frequencies); a
    coefficient zero for every build (a low-pass numerator's s terms) costs nothing."""
    c = np.zeros((coef.shape[0], 3))
    c[:, 3 - coef.shape[1]:] = coef
    c2, c1, c0 = c[:, 0], c[:, 1], c[:, 2]
    e = [c0 * c0, c1 * c1 - 2 * c0 * c2, c2 * c2]
    top = max([k for k in range(3) if np.any(e[k])], default=0)
    if top == 0:
        return e[0][:, None]
    out = e[top][:, None] * x[None, :]
    for k in range(top - 1, -1, -1):
        if np.any(e[k]):
            out += e[k][:, None]
        if k:
            out *= x[None, :]
    return out


def stage_responses(ctx: FilterContext, values: dict) -> list:
    """Each stage's op-amp-aware response on ``ctx.f`` for every build (module docstring): the
    ideal section's squared magnitude, the op-amp factor's log magnitude, and H itself at the
    group delay's two frequencies.

    Parameters
    ----------
    ctx : FilterContext
        The design's context.
    values : dict
        Cascade designator -> array over the builds.

    Returns
    -------
    list of tuple
        Per stage (ideal |H|^2 and the op-amp factor's ln |.|, each of shape (builds, frequencies),
        H at the group-delay pair and at the delay target's points (builds, 2 + their number)).
    """
    n = len(next(iter(values.values())))
    out = []
    a, b = ctx.sl["gd"][0], ctx.f.size
    x = (2 * math.pi * ctx.f) ** 2
    s_gd = 2j * math.pi * ctx.f[a:b]
    for (name, prefix, refs), corr, sens, nom in zip(ctx.stages, ctx.correction, ctx.sensitivity, ctx.nominal):
        topo = get_topology(name)
        vals = {r: np.broadcast_to(np.asarray(values[topo.prefixed(r, prefix)], float), (n,)) for r in refs}
        num, den = (np.asarray(p, float).reshape(p.shape[0], n).T for p in topo.coefficients(vals))
        ratio = _squared_magnitude(num, x) / _squared_magnitude(den, x)
        # the op-amp factor, first order in the log of each part (_correction): its log magnitude is real
        dev = np.log(np.column_stack([vals[r] for r in refs]) / nom[None, :])
        # a sum of (at most four) terms by broadcasting: a BLAS product this thin loses to its threads' start-up
        log_mag = dev[:, 0, None] * sens[0].real[None, :]
        for k in range(1, len(refs)):
            log_mag += dev[:, k, None] * sens[k].real[None, :]
        log_mag += corr.real[None, :]
        h_gd = (sum(num[:, i, None] * s_gd ** (num.shape[1] - 1 - i) for i in range(num.shape[1]))
                / sum(den[:, i, None] * s_gd ** (den.shape[1] - 1 - i) for i in range(den.shape[1])))
        h_gd = h_gd * np.exp(corr[None, a:b] + dev @ sens[:, a:b])
        out.append((ratio, log_mag, h_gd))
    return out


def _combine(parts: list) -> tuple:
    """The cascade's dB (relative to nothing) and group-delay pair from the stages'
    (:func:`stage_responses`): the ideal ratios multiplied, the op-amp factors' logs added, one
    logarithm at the end."""
    ratio, log_mag, h_gd = parts[0]
    for r, m, h in parts[1:]:
        ratio, log_mag, h_gd = ratio * r, log_mag + m, h_gd * h
    return 10 * np.log10(ratio) + (20 / math.log(10)) * log_mag, h_gd


def _crossing(f: np.ndarray, db: np.ndarray, level: float, low: bool) -> np.ndarray:
    """Per row of ``db`` (builds x f), where it crosses ``level`` leaving the passband: the last point
    at or above it (a low side: the first) and the next, linear in log f; NaN off the window."""
    above = db >= level
    m = f.size
    if low:
        i = m - 1 - np.argmax(above[:, ::-1], axis=1)
        j = i + 1
    else:
        i = np.argmax(above, axis=1)
        j = i - 1
    ok = above.any(axis=1) & (j >= 0) & (j < m)
    j = np.clip(j, 0, m - 1)
    rows = np.arange(db.shape[0])
    a, b = db[rows, i], db[rows, j]
    lf = np.log(f)
    # a row without a crossing in the window divides 0 by 0 here: NaN, kept out by ``ok``
    with np.errstate(divide="ignore", invalid="ignore"):
        t = (a - level) / (a - b)
        out = np.exp(lf[i] + t * (lf[j] - lf[i]))
    return np.where(ok, out, np.nan)


def figures_of(ctx: FilterContext, db: np.ndarray, h_gd: np.ndarray) -> dict:
    """The figures (module docstring) of the cascade's responses.

    Parameters
    ----------
    ctx : FilterContext
        The design's context.
    db : ndarray
        20 log10 |H|, shape (builds, ``ctx.f``).
    h_gd : ndarray
        H at the group delay's two frequencies, then (with a delay target) at ``dlp`` and ``dlm``'s,
        shape (builds, 2 + their number).

    Returns
    -------
    dict
        Figure -> array over the builds.
    """
    db = db - ctx.gain_db
    part = lambda k: db[:, slice(*ctx.sl[k])]  # noqa: E731
    out = {"passband_loss_db": -np.min(part("pass"), axis=1),
           "ripple_db": np.ptp(part("pass"), axis=1),
           "stopband_attenuation_db": -np.max(part("stop"), axis=1)}
    level = -10 * math.log10(2)
    if ctx.kind == "bandpass":
        out["f3_low_hz"] = _crossing(ctx.f[slice(*ctx.sl["f3lo"])], part("f3lo"), level, False)
        out["f3_high_hz"] = _crossing(ctx.f[slice(*ctx.sl["f3hi"])], part("f3hi"), level, True)
    else:
        out["f3_hz"] = _crossing(ctx.f[slice(*ctx.sl["f3"])], part("f3"), level, ctx.kind == "lowpass")
    a, b = ctx.sl["gd"]
    w = 2 * math.pi * ctx.f[a:b]
    out["group_delay_s"] = -np.angle(h_gd[:, 1] / h_gd[:, 0]) / (w[1] - w[0])
    if ctx.delay_dw:
        plus = h_gd[:, 2:2 + DELAY_POINTS]
        # at DC the lower point is -dw: H(-j dw) is H(j dw)'s conjugate
        minus = np.column_stack([np.conj(plus[:, 0]), h_gd[:, 2 + DELAY_POINTS:]])
        tau = -np.angle(plus / minus) / (2 * ctx.delay_dw)
        out["delay_error_pct"] = 100 * np.max(np.abs(tau / tau[:, :1] - 1), axis=1)
    return {k: out[k] for k in ctx.figures}


def evaluate(ctx: FilterContext, values: dict) -> dict:
    """The analytic engine: every figure of every build (a runner's chunk function).

    Parameters
    ----------
    ctx : FilterContext
        The design's context.
    values : dict
        Cascade designator -> array over the builds.

    Returns
    -------
    dict
        Figure -> array.
    """
    return figures_of(ctx, *_combine(stage_responses(ctx, values)))


def mask_limits(result, limit_items=()) -> tuple:
    """The limits a build must meet: ``limit_items`` (``FIGURE=MIN:MAX``) when given, else the mask's
    (``passband_loss_db`` at most ``--max-loss``, ``stopband_attenuation_db`` at least
    ``--min-attenuation``) and a group-delay target's (``delay_error_pct`` at most ``--max-delay-error``).

    Parameters
    ----------
    result : designer.filters.FilterDesign
        The design.
    limit_items : sequence of str or Limit
        The user's limits.

    Returns
    -------
    tuple of Limit
        Possibly empty (no mask and no limit: no yield).
    """
    s = result.spec
    figs = (BANDPASS_FIGURES if s.filter_type == "bandpass" else LOWHIGH_FIGURES) + \
        (("delay_error_pct",) if s.has_delay_target else ())
    if limit_items:
        return tuple(t if isinstance(t, Limit) else parse_limit(t, figs) for t in limit_items)
    if not s.has_mask:
        return ()
    return (Limit("passband_loss_db", None, s.max_loss_db), Limit("stopband_attenuation_db", s.min_attenuation_db,
                                                                   None)) + \
        ((Limit("delay_error_pct", None, s.max_delay_error_pct),) if s.has_delay_target else ())


def _passed(figs: dict, limits) -> np.ndarray:
    ok = np.ones(len(next(iter(figs.values()))), bool)
    for lim in limits:
        ok &= lim.inside(figs[lim.figure])
    return ok


# ---- the SPICE engine ---------------------------------------------------------------------------
@dataclass(frozen=True)
class SpiceFilterContext:
    """The SPICE engine's context: the cascade's deck without analyses, the sweep, the analytic
    context (its frequencies and figures), the backend."""

    circuit: str
    sweep: tuple
    ctx: FilterContext
    simulator: str = "ngspice-cli"


def spice_context(result, simulator: str = "ngspice-cli") -> SpiceFilterContext:
    """The SPICE engine's context of ``result``'s chosen cascade.

    Parameters
    ----------
    result : designer.filters.FilterDesign
        The design.
    simulator : str
        ``ngspice-cli`` or ``pyspice``.

    Returns
    -------
    SpiceFilterContext
        Picklable.
    """
    from ..filters.deck import ac_deck
    ctx = context(result)
    f = ctx.f[:ctx.sl["gd"][1]]   # the delay target's points have sweeps of their own
    lo = float(min(f.min() / 3, result.figures["sweep_hz"][0]))
    hi = float(max(f.max() * 3, result.figures["sweep_hz"][1]))
    text = ac_deck(result.cascade().netlist(), result.opamp, lo, hi, title="filter Monte Carlo")
    keep = [ln for ln in text.splitlines() if not re.match(r"\s*\.(ac|end)\b", ln, re.I)]
    return SpiceFilterContext("\n".join(keep) + "\n.end\n", (lo, hi), ctx, simulator)


_ROW = re.compile(r"^\s*MCROW (\d+)\s*$", re.M)
_MEAS = re.compile(r"^\s*(mg\d+|mp[ri]\d+)\s*=\s*([-+]?[\d.]+(?:[eE][-+]?\d+)?)", re.M)


def _spice_commands(sctx: SpiceFilterContext, values: dict, start: int) -> list:
    n = len(next(iter(values.values())))
    lo, hi = sctx.sweep
    out = []
    for i in range(n):
        out += [f"alter {ref.lower()} = {float(v[i]):.12g}" for ref, v in values.items()]
        out += [f"ac dec 100 {lo:.6g} {hi:.6g}", f"echo MCROW {start + i}"]
        a, b = sctx.ctx.sl["gd"]
        out += [f"meas ac mg{k} find vdb(vout) at={f:.10g}" for k, f in enumerate(sctx.ctx.f[:b])]
        # the group delay's pair on a sweep of its own, points 0.1 % apart (interpolating between a decade
        # sweep's would swamp a 0.2 % phase step), from the real and imaginary parts (vp() wraps)
        lo_gd, hi_gd = sctx.ctx.f[a] * (1 - GD_STEP), sctx.ctx.f[b - 1] * (1 + GD_STEP)
        out.append(f"ac lin 9 {lo_gd:.12g} {hi_gd:.12g}")
        out += [f"meas ac m{p}{k} find v{p[-1]}(vout) at={sctx.ctx.f[k]:.12g}" for k in range(a, b) for p in ("pr", "pi")]
        for group in ("dlp", "dlm") if sctx.ctx.delay_dw else ():
            # the delay target's points: a linear sweep through exactly them (evenly spaced)
            c, d = sctx.ctx.sl[group]
            # a hair wider than the points: a measurement at a sweep's very end can fall outside it by rounding
            pad = 1e-6 * (sctx.ctx.f[d - 1] - sctx.ctx.f[c]) / (d - c - 1)
            out.append(f"ac lin {d - c} {sctx.ctx.f[c] - pad:.15g} {sctx.ctx.f[d - 1] + pad:.15g}")
            out += [f"meas ac m{p}{k} find v{p[-1]}(vout) at={sctx.ctx.f[k]:.12g}" for k in range(c, d)
                    for p in ("pr", "pi")]
        out.append("destroy all")
    return out


def spice_evaluate(sctx: SpiceFilterContext, values: dict, start: int = 0) -> dict:
    """The SPICE engine: every build simulated (``alter`` by designator, ``.ac``, the gain and phase
    at the analytic engine's frequencies), the same figures (:func:`figures_of`).

    Parameters
    ----------
    sctx : SpiceFilterContext
        The design's deck and frequencies.
    values : dict
        Cascade designator -> array over the builds.
    start : int
        The first build's number (labels only).

    Returns
    -------
    dict
        Figure -> array.

    Raises
    ------
    SimulatorError
        ngspice failed or stopped before a build.
    """
    from ..core.errors import SimulatorError
    from ..spice.simulate import DEFAULT_TIMEOUT_S, get_simulator
    values = {k: np.atleast_1d(np.asarray(v, float)) for k, v in values.items()}
    n = len(next(iter(values.values())))
    nf = sctx.ctx.f.size
    h = np.full((n, nf), np.nan, complex)
    a, b = sctx.ctx.sl["gd"]
    for lo in range(0, n, SPICE_BATCH):
        hi = min(n, lo + SPICE_BATCH)
        chunk = {k: v[lo:hi] for k, v in values.items()}
        sim = get_simulator(sctx.simulator, timeout=DEFAULT_TIMEOUT_S + 1.0 * (hi - lo))
        text = sim.run_script(sctx.circuit, _spice_commands(sctx, chunk, start + lo))
        marks = list(_ROW.finditer(text))
        seen = set()
        for j, m in enumerate(marks):
            i = int(m.group(1)) - start - lo
            seg = text[m.end():marks[j + 1].start() if j + 1 < len(marks) else len(text)]
            got = {k: float(v) for k, v in _MEAS.findall(seg)}
            h[lo + i] = [10 ** (got.get(f"mg{k}", np.nan) / 20) for k in range(nf)]
            for k in range(a, nf):
                h[lo + i, k] = got.get(f"mpr{k}", np.nan) + 1j * got.get(f"mpi{k}", np.nan)
            seen.add(i)
        if len(seen) < hi - lo:
            missing = min(set(range(hi - lo)) - seen) + start + lo
            raise SimulatorError(f"ngspice stopped before filter Monte Carlo build {missing}")
    return figures_of(sctx.ctx, 20 * np.log10(np.abs(h)), h[:, a:])


def _spice_chunk(sctx, values: dict) -> dict:
    return spice_evaluate(sctx, values)


# ---- the Monte Carlo ----------------------------------------------------------------------------
@dataclass
class FilterMonteCarlo:
    """A filter's Monte Carlo: settings, figures, yield, what to tighten, SPICE beside it.

    Attributes
    ----------
    n, seed, sampler, dist : int, int, str, str
        The draws.
    tolerances : dict
        Designator -> tolerance (fraction).
    nominal : dict
        Designator -> nominal value.
    nominal_figures : dict
        The chosen parts' figures.
    figures : dict
        Figure -> array over the builds.
    limits : tuple of Limit
        What a build must meet.
    passed : ndarray or None
        Per build, inside every limit.
    stats : dict
        Figure -> :class:`~designer.tolerance.stats.FigureStats`.
    shares : dict
        Limited figure -> designator -> its share of the variance.
    tighten : dict or None
        The part and the stage whose tolerance halved raises the yield most.
    spice : dict or None
        The SPICE engine on the first builds: its yield and the disagreement.
    values : dict
        Designator -> the builds' values (the draws).
    engine : str
        The engine that computed the figures.
    """

    n: int
    seed: int
    sampler: str
    dist: str
    tolerances: dict
    nominal: dict
    nominal_figures: dict
    figures: dict = field(repr=False)
    limits: tuple = ()
    passed: np.ndarray | None = field(default=None, repr=False)
    stats: dict = field(default_factory=dict)
    shares: dict = field(default_factory=dict)
    tighten: dict | None = None
    spice: dict | None = None
    values: dict = field(default_factory=dict, repr=False)
    engine: str = "analytic"

    @property
    def failing(self) -> dict:
        """Limited figure -> {count, worst}: the builds outside its window (:func:`~.stats.failing_samples`)."""
        return failing_samples(self.figures, self.limits)

    @property
    def yield_count(self) -> int:
        """Builds inside every limit."""
        return int(np.count_nonzero(self.passed)) if self.passed is not None else self.n

    def yield_interval(self) -> tuple:
        """The yield's 95 % Wilson interval."""
        return wilson(self.yield_count, self.n)

    def to_dict(self) -> dict:
        """The run as JSON.

        Returns
        -------
        dict
            Settings, statistics, yield, variance shares, what to tighten, SPICE.
        """
        lo, hi = self.yield_interval()
        return {"settings": {"samples": self.n, "seed": self.seed, "sampler": self.sampler, "dist": self.dist,
                             "engine": "analytic", "tolerances_pct": {k: 100 * v for k, v in self.tolerances.items()}},
                "nominal_parts": self.nominal, "nominal_figures": self.nominal_figures,
                "limits": [lim.to_dict() for lim in self.limits],
                "statistics": {k: v.to_dict() for k, v in self.stats.items()},
                "yield": None if not self.limits else {"passed": self.yield_count, "samples": self.n,
                                                        "fraction": self.yield_count / self.n, "ci95": [lo, hi],
                                                        "interval": "Wilson"},
                "variance_shares": {"method": "standardised regression coefficients, squared", **self.shares},
                "tighten": self.tighten, "spice": self.spice}

    def lines(self) -> list:
        """The summary's lines."""
        out = [f"Monte Carlo: {self.n} builds ({self.sampler}, {self.dist}, seed {self.seed}), every part of every "
               "stage within its tolerance"]
        for k, s in self.stats.items():
            p = s.percentiles
            out.append("  " + figure_spread(k, s.nominal, s.mean, s.std, p.get(2.5, math.nan),
                                            p.get(97.5, math.nan)))
        if self.limits:
            lo, hi = self.yield_interval()
            out.append(f"  yield {100 * self.yield_count / self.n:.2f} % ({self.yield_count}/{self.n}; 95 % Wilson "
                       f"interval {100 * lo:.2f}..{100 * hi:.2f} %) within "
                       + ", ".join(lim.text() for lim in self.limits))
        t = self.tighten
        if t and max(t["yield"], t["stage_yield"]) <= t["yield_now"]:
            out.append("  no part's (or stage's) tolerance halved raises the yield: the nominal parts themselves "
                       "sit outside the limits, change them (--optimize yield)")
        elif t:
            words = []
            if t["stage_yield"] > t["yield_now"]:
                words.append(f"stage {t['stage']} (every part at half its tolerance: yield {100 * t['stage_yield']:.2f} %)")
            if t["yield"] > t["yield_now"]:
                words.append(f"the part {t['part']} at {t['tolerance_pct']:g} % (yield {100 * t['yield']:.2f} %)")
            out.append("  tighten " + "; or ".join(words))
        if self.spice:
            sp = self.spice
            out.append(f"  SPICE on builds 0..{sp['samples'] - 1}: yield {100 * sp['yield_spice']:.2f} % against "
                       f"{100 * sp['yield_analytic']:.2f} % analytic on the same builds; {sp['disagree']} builds judged "
                       f"differently; largest figure differences: " + ", ".join(
                           f"{k} {v:.3g}" for k, v in sp["max_abs_difference"].items()))
        return out


def filter_monte_carlo(result, n: int, seed: int = 0, sampler: str = "random", dist: str = "uniform",
                       tol_items=(), limit_items=(), tighten: bool = True, scale=None, spice_samples: int = 0,
                       simulator: str = "ngspice-cli", edges=None) -> FilterMonteCarlo:
    """A Monte Carlo of ``result``'s chosen parts against its mask (module docstring).

    Parameters
    ----------
    result : designer.filters.FilterDesign
        The design.
    n, seed : int
        Builds, and the seed (build i is a function of (seed, i) alone).
    sampler, dist : str
        :data:`designer.tolerance.sampling.SAMPLERS`; ``uniform`` or ``normal``.
    tol_items, limit_items : sequence of str
        ``--tol`` (``R=1%``, ``C203=2%``) and ``--limit`` items (default: the mask's limits).
    tighten : bool
        Also find the part and the stage to buy tighter.
    scale : designer.tolerance.runner.Scale, optional
        ``--jobs``, ``--dask``: where the chunks run (the same figures wherever).
    spice_samples : int
        Also simulate builds 0 .. spice_samples - 1 in ngspice (the same draws) and report the
        yield of both engines on them and their disagreement.
    simulator : str
        ``ngspice-cli`` or ``pyspice``.
    edges : tuple, optional
        (passband edge, stopband edge) the figures are taken at (:func:`context`).

    Returns
    -------
    FilterMonteCarlo
        The run.
    """
    check_draw(n, dist, sampler, "builds")
    limits = mask_limits(result, limit_items)
    nominal = nominal_parts(result)
    tol = resolve(tol_items, nominal, series_of(result))
    ctx = context(result, edges=edges)
    draw = runner.Draw(nominal, tol.of, n, seed, sampler, dist)
    with runner.Runner(scale or runner.Scale()) as run:
        values, figs, _ = run.run(evaluate, ctx, draw)
    nom = {k: float(v[0]) for k, v in evaluate(ctx, {r: np.array([x]) for r, x in nominal.items()}).items()}
    by_fig = {lim.figure: lim for lim in limits}
    stats = {k: figure_stats(k, v, nom[k], by_fig.get(k)) for k, v in figs.items()}
    rel = {r: values[r] / nominal[r] - 1 for r in values}
    shares = {k: variance_shares(rel, figs[k]) for k in by_fig}
    mc = FilterMonteCarlo(n, seed, sampler, dist, dict(tol.of), nominal, nom, figs, limits,
                          _passed(figs, limits) if limits else None, stats, shares, values=values)
    if tighten and limits:
        mc.tighten = _tighten(result, ctx, mc)
    if spice_samples:
        k = min(int(spice_samples), n)
        sctx = spice_context(result, simulator)
        picked = runner.Picked(nominal, tol.of, k, seed, sampler, dist, picked={r: v[:k] for r, v in values.items()})
        # the SPICE builds in the longer chunks of a SPICE engine (each chunk starts ngspice once)
        import dataclasses
        spice_scale = dataclasses.replace(scale or runner.Scale(), work="ngspice-cli" if sctx.simulator == "ngspice-cli"
                                          else "spice")
        with runner.Runner(spice_scale) as run:
            _, sfigs, _ = run.run(_spice_chunk, sctx, picked)
        mc.spice = _disagreement(sfigs, {f: v[:k] for f, v in figs.items()}, limits, k)
    return mc


def _disagreement(spice: dict, model: dict, limits, k: int) -> dict:
    """Both engines' yields on the same builds, how many builds they judge differently, and each
    figure's largest difference."""
    sp = _passed(spice, limits) if limits else np.ones(k, bool)
    an = _passed(model, limits) if limits else np.ones(k, bool)
    diff = {f: float(np.nanmax(np.abs(spice[f] - model[f]))) if np.any(np.isfinite(spice[f] - model[f])) else math.nan
            for f in model}
    return {"samples": k, "yield_spice": float(np.mean(sp)), "yield_analytic": float(np.mean(an)),
            "ci95_spice": list(wilson(int(np.sum(sp)), k)), "disagree": int(np.sum(sp != an)),
            "max_abs_difference": diff}


def _yield_with(ctx: FilterContext, draw: runner.Draw, limits) -> float:
    figs = evaluate(ctx, draw.values())
    return float(np.mean(_passed(figs, limits)))


def _tighten(result, ctx: FilterContext, mc: FilterMonteCarlo) -> dict:
    """The part, and the stage, whose tolerance halved (the same draws) raises the yield most."""
    best_part, best_stage = None, None
    for ref, t in mc.tolerances.items():
        draw = runner.Draw(mc.nominal, dict(mc.tolerances, **{ref: t / 2}), mc.n, mc.seed, mc.sampler, mc.dist)
        y = _yield_with(ctx, draw, mc.limits)
        if best_part is None or y > best_part[1]:
            best_part = (ref, y)
    for i, (name, prefix, refs) in enumerate(ctx.stages, 1):
        mine = {get_topology(name).prefixed(r, prefix) for r in refs}
        tol = {r: (t / 2 if r in mine else t) for r, t in mc.tolerances.items()}
        draw = runner.Draw(mc.nominal, tol, mc.n, mc.seed, mc.sampler, mc.dist)
        y = _yield_with(ctx, draw, mc.limits)
        if best_stage is None or y > best_stage[1]:
            best_stage = (i, y)
    ref = best_part[0]
    return {"part": ref, "tolerance_pct": 100 * mc.tolerances[ref] / 2, "yield": best_part[1],
            "stage": best_stage[0], "stage_yield": best_stage[1], "yield_now": mc.yield_count / mc.n}


def filter_worst_case(result, tol_items=(), maxiter: int = 20):
    """The extremes of the filter's figures over the tolerance box of every part
    (:func:`designer.tolerance.worstcase.worst_case` with the analytic engine).

    Parameters
    ----------
    result : designer.filters.FilterDesign
        The design.
    tol_items : sequence of str
        ``--tol`` items.
    maxiter : int
        The bounded search's iterations per figure and direction.

    Returns
    -------
    designer.tolerance.worstcase.WorstCase
        Figure -> (min, max) extremes.
    """
    from .worstcase import worst_case
    nominal = nominal_parts(result)
    tol = resolve(tol_items, nominal, series_of(result))
    ctx = context(result)
    return worst_case(lambda v: evaluate(ctx, v), nominal, tol.of, figures=ctx.figures, maxiter=maxiter)


# ---- --optimize yield ---------------------------------------------------------------------------
@dataclass
class YieldOptimum:
    """``--optimize yield``: the set found and both designs' yields on the same draws.

    Attributes
    ----------
    choice : list of int
        Per stage, the candidate index chosen.
    values : list of dict
        Per stage, its part values.
    yield_nominal, yield_optimum : float
        The joint choice's and the found set's yield on the same builds.
    n, seed : int
        The draws.
    ci_nominal, ci_optimum : tuple
        The Wilson intervals.
    changed : list of int
        The stages whose parts changed.
    tried : int
        Candidate sets evaluated.
    joint_values : list of dict or None
        Per stage the joint choice's parts, when the found set is the one built (``--apply-optimum``).
    """

    choice: list
    values: list
    yield_nominal: float
    yield_optimum: float
    n: int
    seed: int
    ci_nominal: tuple
    ci_optimum: tuple
    changed: list
    tried: int
    joint_values: list | None = None

    def to_dict(self) -> dict:
        """The optimum as JSON."""
        return {"method": "coordinate ascent over each stage's E-series candidates, common random numbers",
                "samples": self.n, "seed": self.seed, "yield_joint": self.yield_nominal,
                "ci95_joint": list(self.ci_nominal), "yield_optimized": self.yield_optimum,
                "ci95_optimized": list(self.ci_optimum), "stages_changed": self.changed, "sets_tried": self.tried,
                "parts": [{k: float(v) for k, v in vals.items()} for vals in self.values],
                # only when applied: without --apply-optimum the JSON stays as it was
                **({"applied": True, "joint_parts": [{k: float(v) for k, v in vals.items()}
                                                     for vals in self.joint_values]}
                   if self.joint_values is not None else {})}

    def lines(self) -> list:
        """The summary's lines."""
        from ..core.units import format_eng
        out = [f"Yield-optimal parts ({self.n} builds, seed {self.seed}, the same draws for both): joint choice "
               f"{100 * self.yield_nominal:.2f} %, optimized {100 * self.yield_optimum:.2f} % "
               f"(stages changed: {', '.join(map(str, self.changed)) or 'none'}; {self.tried} sets tried)"]
        def shown(parts, i):
            return ", ".join(f"{r[0]}{i}0{r[1:]} {format_eng(v, 'Ohm' if r.startswith('R') else 'F')}"
                             for r, v in parts.items())
        for i in self.changed:
            out.append(f"  stage {i}: {shown(self.values[i - 1], i)}")
        if self.joint_values is not None:
            out.append("  built: the yield-optimal set (the stages above, the deck, result.json, the sheet); the "
                       "joint choice had" + "".join(f" stage {i}: {shown(self.joint_values[i - 1], i)};"
                                                    for i in self.changed).rstrip(";")
                       + ("" if self.changed else " the same parts"))
        return out


def optimize_yield(result, n: int = 2000, seed: int = 0, sampler: str = "random", dist: str = "uniform",
                   tol_items=(), limit_items=()) -> YieldOptimum:
    """Among each stage's E-series candidates (the neighbours of the continuous design that the
    joint search chose from), the set that maximises the yield against the mask, by coordinate
    ascent from the joint choice on common random numbers (module docstring).

    Parameters
    ----------
    result : designer.filters.FilterDesign
        The design (its stages' candidates and joint choice).
    n, seed, sampler, dist
        The draws (the same relative deviations for every set).
    tol_items, limit_items : sequence of str
        ``--tol`` and ``--limit`` items (default: the series' tolerances, the mask).

    Returns
    -------
    YieldOptimum
        The set found, never below the joint choice's yield on these draws.

    Raises
    ------
    DesignError
        No mask and no limit to count a yield against.
    """
    check_draw(n, dist, sampler, "builds")
    limits = mask_limits(result, limit_items)
    if not limits:
        raise DesignError("--optimize yield needs a mask (--passband, --max-loss, --stopband, --min-attenuation) or "
                          "--limit FIGURE=MIN:MAX")
    nominal = nominal_parts(result)
    tol = resolve(tol_items, nominal, series_of(result)).of
    refs = list(tol)
    dev = sampling.deviations(sampling.unit_samples(n, len(refs), seed, sampler), dist)
    rel = {r: 1.0 + tol[r] * dev[:, k] for k, r in enumerate(refs)}
    ctx = context(result)
    s = 2j * math.pi * ctx.f
    op = result.opamp
    # per stage: its response for one candidate, on the common draws
    cache = {}

    def response(i: int, c: int) -> tuple:
        if (i, c) not in cache:
            name, prefix, refs = ctx.stages[i]
            topo = get_topology(name)
            cand = result.stages[i].candidates[c]
            corr, sens = _correction(topo, cand, s, op)
            one = FilterContext(ctx.kind, (ctx.stages[i],), ctx.gain_db, ctx.f, ctx.sl, (corr,), (sens,),
                                (np.array([cand[r] for r in refs], float),), ctx.delay_dw)
            vals = {topo.prefixed(r, prefix): cand[r] * rel[topo.prefixed(r, prefix)] for r in refs}
            cache[(i, c)] = stage_responses(one, vals)[0]
        return cache[(i, c)]

    def score(choice) -> float:
        parts = [response(i, c) for i, c in enumerate(choice)]
        return float(np.mean(_passed(figures_of(ctx, *_combine(parts)), limits)))

    start = [st.chosen for st in result.stages]
    choice, best = list(start), score(start)
    y0, tried = best, 1
    for _ in range(MAX_ROUNDS):
        improved = False
        for i, st in enumerate(result.stages):
            for c in range(len(st.candidates)):
                if c == choice[i]:
                    continue
                trial = choice[:i] + [c] + choice[i + 1:]
                y = score(trial)
                tried += 1
                if y > best:
                    choice, best, improved = trial, y, True
            # keep the cache to the current choice's responses and this stage's: memory stays bounded
            for key in [k for k in cache if k[1] != choice[k[0]]]:
                del cache[key]
        if not improved:
            break
    k0, k1 = round(y0 * n), round(best * n)
    return YieldOptimum(choice, [st.candidates[c] for st, c in zip(result.stages, choice)], y0, best, n, seed,
                        wilson(k0, n), wilson(k1, n), [i + 1 for i, (a, b) in enumerate(zip(start, choice)) if a != b],
                        tried)


# ---- check-design's yield (kind: filter) ---------------------------------------------------------
def filter_spec_yield(result, mask, limits, samples: int, seed: int, tol_items=(),
                      sampler: str = "random", dist: str = "uniform") -> FilterMonteCarlo:
    """The yield of one corner's designed filter within a check spec's ``limits`` (its checks on the
    figures this engine has, :data:`designer.tolerance.yields.FILTER`; the ``mask:``'s among them).

    The builds are :func:`filter_monte_carlo`'s (the analytic engine, every part of every stage within
    its tolerance), judged at the spec's mask edges when it has ``mask:``, else the design's own; two
    limits on one figure both hold.

    Parameters
    ----------
    result : designer.filters.FilterDesign
        The corner's design.
    mask : dict or None
        The spec's ``{passband, max_loss, stopband, min_attenuation}``.
    limits : sequence of designer.tolerance.stats.Limit
        The windows a build must be inside.
    samples, seed : int
        The Monte Carlo's builds and seed.
    tol_items : sequence of str
        ``--tol`` items (``R=1%``) from the spec's ``tolerances:``.
    sampler, dist : str
        How the builds are drawn.

    Returns
    -------
    FilterMonteCarlo
        The Monte Carlo (its draws kept: :class:`designer.tolerance.yields.YieldVerdict` names the worst build).
    """
    edges = None if mask is None else (mask["passband"], mask["stopband"])
    return filter_monte_carlo(result, samples, seed, sampler, dist, tol_items, tuple(limits), tighten=False,
                              edges=edges)
