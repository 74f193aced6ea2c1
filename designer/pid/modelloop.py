"""The figures of a PID loop around a plant model, G(s) = N(s)/D(s) e^(-theta s),
that the model plant's design (:mod:`designer.pid.design`) and its
optimiser (:mod:`designer.pid.optimize`) both use: the spec's limits,
the ideal loop's crossover, the integrator leak and derivative filter corners
(fc/100 and 10 fc, as for a Sallen-Key plant's fn), the step response of the
loop with the exact dead time (:func:`designer.pid.delayloop.closed_loop_step`)
and every op-amp stage's output from it (:func:`designer.pid.model.stage_tfs`),
the controller as it will be built (:func:`designer.pid.model.controller_tf`),
and the E-series sizing (:func:`designer.pid.selection.select_parts`).

Kept apart from :mod:`designer.pid.design` (which re-exports every name) so
that the optimiser needs not import the design that calls it: no cycle
design <-> optimize.
"""

from __future__ import annotations

import math

import numpy as np

from ..core.lti import filter_foh
from . import blocks, model as M, selection
from .delayloop import closed_loop_step, pid_tf, step_figures
from .delaymargins import loop_margins
from .result import LoopFigures
from .spec import DEFAULT_MAX_MS, DEFAULT_MIN_GAIN_MARGIN_DB, DEFAULT_MIN_PHASE_MARGIN_DEG, PidSpec

__all__ = ["LEAK_LOOP_GAIN", "TABLE_STEP_FRACTION", "FAR_FACTOR", "limits", "plant_of", "ideal_crossover_hz",
           "corner_frequencies", "leak_limit_hz", "edged", "stage_waves", "loop_dc_gain", "simulation_controller",
           "loop_figures", "built_controller", "response_grid", "size"]

#: the leaky integrator's DC loop gain at least this (see :func:`corner_frequencies`)
LEAK_LOOP_GAIN = 100.0


def limits(spec: PidSpec) -> tuple:
    """(min phase margin deg, min gain margin dB, max Ms) of the spec, defaults filled in.

    Parameters
    ----------
    spec : PidSpec
        The request.

    Returns
    -------
    tuple
    """
    return (DEFAULT_MIN_PHASE_MARGIN_DEG if spec.min_phase_margin_deg is None else spec.min_phase_margin_deg,
            DEFAULT_MIN_GAIN_MARGIN_DB if spec.min_gain_margin_db is None else spec.min_gain_margin_db,
            DEFAULT_MAX_MS if spec.max_ms is None else spec.max_ms)


def plant_of(model):
    """The (num, den, theta_s) triple the loop functions take.

    Parameters
    ----------
    model : designer.core.process.ProcessModel
        The plant.

    Returns
    -------
    tuple
    """
    return (np.asarray(model.num, float), np.asarray(model.den, float), float(model.theta_s))


# ---- the loop's figures --------------------------------------------------------

def ideal_crossover_hz(model, kp: float, ti_s: float, td_s: float) -> float:
    """The (first) gain crossover of the ideal PID (filter N = 10) around the
    model, or the model's own corner 1/(2 pi time scale) when the loop never
    crosses. |C P| needs no phase: a log grid over eight decades about the
    model's corner, refined between the two samples that straddle 1.

    Parameters
    ----------
    model : designer.core.process.ProcessModel
        The plant.
    kp : float
        Proportional gain.
    ti_s : float
        Integral time (s).
    td_s : float
        Derivative time (s; 0 for a PI).

    Returns
    -------
    float
        Hz.
    """
    from scipy.optimize import brentq
    num, den = pid_tf(kp, ti_s, td_s, 10.0)
    w0 = 1.0 / model.time_scale_s

    def mag(w):
        s = 1j * np.asarray(w, float)
        return np.abs(np.polyval(num, s) / np.polyval(den, s) * np.polyval(model.num, s) / np.polyval(model.den, s))

    w = w0 * np.logspace(-4, 4, 1601)
    with np.errstate(all="ignore"):
        m = mag(w)
    down = np.nonzero((m[:-1] >= 1) & (m[1:] < 1))[0]
    if not down.size:
        return w0 / (2 * math.pi)
    k = int(down[0])
    wc = brentq(lambda x: math.log(mag([x])[0]), w[k], w[k + 1], xtol=1e-12 * w[k])
    return wc / (2 * math.pi)


def corner_frequencies(spec: PidSpec, fc_hz: float, loop_gain_hz: float | None = None) -> tuple:
    """(leak corner, derivative filter corner) in Hz: the spec's, else fc/100 and
    10 fc; the leak also at most ``loop_gain_hz`` / :data:`LEAK_LOOP_GAIN` (with
    ``loop_gain_hz`` = |K| Kp/(2 pi Ti), the leaky integrator's DC loop gain is
    then at least that: a steady-state error under 1/(1 + 100)).

    Parameters
    ----------
    spec : PidSpec
        Its ``f_integrator_hz`` and ``f_differentiator_hz``, when given.
    fc_hz : float
        The ideal loop's crossover.
    loop_gain_hz : float, optional
        |K| Kp/(2 pi Ti) (:func:`leak_limit_hz`); None: no limit.

    Returns
    -------
    tuple
    """
    f_i = spec.f_integrator_hz
    if f_i is None:
        f_i = fc_hz * blocks.F_INTEGRATOR_RATIO
        if loop_gain_hz is not None and math.isfinite(loop_gain_hz) and loop_gain_hz > 0:
            f_i = min(f_i, loop_gain_hz / LEAK_LOOP_GAIN)
    f_d = spec.f_differentiator_hz if spec.f_differentiator_hz is not None else fc_hz * blocks.F_DIFFERENTIATOR_RATIO
    return f_i, f_d


def leak_limit_hz(model, kp: float, ti_s: float) -> float | None:
    """|K| Kp/(2 pi Ti) of a non-integrating model (None for an integrating one, whose
    own pole at 0 makes the steady-state error zero whatever the leak).

    Parameters
    ----------
    model : designer.core.process.ProcessModel
        The plant.
    kp : float
        Proportional gain.
    ti_s : float
        Integral time (s).

    Returns
    -------
    float or None
    """
    return None if model.integrating else abs(model.gain) * kp / (2 * math.pi * ti_s)


def edged(t, x, edge_s: float) -> np.ndarray:
    """The response to a reference ramping over ``edge_s`` from the response ``x``
    to a step at 0 (an LTI loop: the moving average of the step response over the
    edge, exactly, from its running integral).

    Parameters
    ----------
    t : array_like
        Times from the step (s).
    x : array_like
        The step response on ``t``.
    edge_s : float
        The reference's edge (s; 0: ``x`` itself).

    Returns
    -------
    numpy.ndarray
    """
    if edge_s <= 0 or t.size < 2:
        return x
    h = t[1] - t[0]
    cum = np.concatenate([[0.0], np.cumsum(0.5 * (x[1:] + x[:-1]) * h)])
    earlier = np.interp(t - edge_s, t, cum, left=0.0)
    # before the edge ends the ramp has covered only part of the step
    return (cum - earlier) / edge_s


def stage_waves(parts, amp, t, r, y) -> dict:
    """Every op-amp output of the controller for the reference ``r`` and the plant
    output ``y`` (the controller is linear from them: each stage's transfer
    function, :func:`designer.pid.model.stage_tfs`, on its inputs).

    Parameters
    ----------
    parts : designer.pid.blocks.PidParts
        The controller as built.
    amp : designer.core.opamps.OpAmp
        The op-amp of every stage.
    t : array_like
        Times (s).
    r, y : array_like
        The reference and the plant's output on ``t`` (V).

    Returns
    -------
    dict
        Signal -> waveform (V).
    """
    tfs = M.stage_tfs(parts, amp)
    g_y, g_r = M.difference_weights(parts)
    w = {"ve": filter_foh(*tfs["ve"], t, g_y * y - g_r * r)}
    for sig in ("vp", "vd", "vi"):
        if sig in tfs:
            w[sig] = filter_foh(*tfs[sig], t, w["ve"])
    sw = M.summer_weights(parts)
    w["vs"] = filter_foh(*tfs["vs"], t, sum(sw[k] * w[k] for k in sw))
    w["u"] = filter_foh(*tfs["u"], t, w["vs"])
    w["y"] = y
    return w


def loop_dc_gain(model, controller) -> float:
    """y/r at DC of the loop as built (an integrating plant: 1).

    Parameters
    ----------
    model : designer.core.process.ProcessModel
        The plant.
    controller : tuple
        The controller's (num, den), descending powers of s.

    Returns
    -------
    float
    """
    if model.integrating:
        return 1.0
    c0 = controller[0][-1] / controller[1][-1]
    l0 = c0 * model.gain
    return float(l0 / (1 + l0))


#: the rule table's and the corners' simulation step (about 6e-4 of the step)
TABLE_STEP_FRACTION = 0.05
#: the time simulations leave out the controller's poles and zeros this far above the loop's
#: crossover (an op-amp pole at 1000 wc costs 0.06 deg there): a 100 s plant's controller spans
#: 1e-4 to 1e6 rad/s, and its companion form (coefficients to 1e39) cannot be integrated
FAR_FACTOR = 1e3


def simulation_controller(controller, fc_hz: float):
    """``controller`` without its poles and zeros above :data:`FAR_FACTOR` x the
    crossover ``fc_hz``, its gain matched at the crossover (for the time
    simulations; the margins use the whole controller).

    Parameters
    ----------
    controller : tuple
        The controller's (num, den), descending powers of s.
    fc_hz : float
        The loop's crossover.

    Returns
    -------
    tuple
        (num, den).
    """
    num, den = (np.atleast_1d(np.asarray(c, float)) for c in controller)
    w_keep = FAR_FACTOR * 2 * math.pi * fc_hz
    z, p = np.roots(num), np.roots(den)
    zk, pk = z[np.abs(z) <= w_keep], p[np.abs(p) <= w_keep]
    if zk.size == z.size and pk.size == p.size:
        return num, den
    s = 2j * math.pi * fc_hz
    n_red, d_red = np.atleast_1d(np.real(np.poly(zk))), np.atleast_1d(np.real(np.poly(pk)))
    k = np.polyval(num, s) / np.polyval(den, s) / (np.polyval(n_red, s) / np.polyval(d_red, s))
    return float(k.real) * n_red, d_red


def loop_figures(model, controller, kp, ti_s, td_s, t, step_v=1.0) -> LoopFigures:
    """Margins, Ms and the closed-loop step figures (IAE included) of ``controller``
    around ``model`` on the grid ``t`` (from the step).

    Parameters
    ----------
    model : designer.core.process.ProcessModel
        The plant.
    controller : tuple
        The controller's (num, den), descending powers of s.
    kp : float
        Proportional gain.
    ti_s : float
        Integral time (s).
    td_s : float
        Derivative time (s; 0 for a PI).
    t : array_like
        Times from the step (s).
    step_v : float
        The reference step (V).

    Returns
    -------
    LoopFigures
    """
    mg = loop_margins(plant_of(model), controller)
    if not mg.stable:
        return LoopFigures(kp, ti_s, td_s, mg, None, math.nan, math.nan)
    fc = mg.crossover_hz if math.isfinite(mg.crossover_hz) else 1.0 / (2 * math.pi * model.time_scale_s)
    out = closed_loop_step(plant_of(model), simulation_controller(controller, fc), t, r_step=step_v,
                           step_fraction=TABLE_STEP_FRACTION)
    return LoopFigures(kp, ti_s, td_s, mg, step_figures(t, out["y"], step_v), float(out["u"].min()),
                       float(out["u"].max()))


def built_controller(kp, ti_s, td_s, fc_hz, spec, amp):
    """The controller as it will be built, before any part is rounded
    (:func:`designer.pid.blocks.continuous_parts` with the spec's corners), as (num, den).

    Parameters
    ----------
    kp : float
        Proportional gain.
    ti_s : float
        Integral time (s).
    td_s : float
        Derivative time (s; 0 for a PI).
    fc_hz : float
        The ideal loop's crossover the corners are set from.
    spec : PidSpec
        The request (its corners, when given).
    amp : designer.core.opamps.OpAmp
        The op-amp of every stage.

    Returns
    -------
    tuple
    """
    f_i, f_d = corner_frequencies(spec, fc_hz, leak_limit_hz(spec.plant.process, kp, ti_s))
    parts = blocks.continuous_parts(kp, ti_s, td_s, fc_hz, f_integrator_hz=f_i, f_differentiator_hz=f_d)
    return M.controller_tf(parts, amp)


def response_grid(model, fc_hz: float, points: int = 2001, per_crossover: float = 40.0) -> np.ndarray:
    """A grid long enough to see the loop settle: ``per_crossover`` times 1/wc,
    or three open-loop settling times, whichever is longer.

    Parameters
    ----------
    model : designer.core.process.ProcessModel
        The plant.
    fc_hz : float
        The loop's crossover.
    points : int
        Samples.
    per_crossover : float
        How many 1/wc the grid spans at least.

    Returns
    -------
    numpy.ndarray
        Times from 0 (s).
    """
    span = max(per_crossover / (2 * math.pi * fc_hz), 3.0 * (model.settling_time_s if not model.integrating
                                                             else model.time_scale_s + model.theta_s))
    return np.linspace(0.0, span, points)


def size(spec: PidSpec, kp: float, ti_s: float, td_s: float, fc_hz: float, f_i: float, f_d: float):
    """The E-series parts for these gains with the spec's series, bounds and tolerance, the leak and
    filter at ``f_i`` and ``f_d`` (:func:`designer.pid.selection.select_parts`): the design's, the rule
    table's SPICE runs' and the optimiser's final check's one call.

    Parameters
    ----------
    spec : PidSpec
        The request (series, bounds, tolerance).
    kp : float
        Proportional gain.
    ti_s : float
        Integral time (s).
    td_s : float
        Derivative time (s; 0 for a PI).
    fc_hz : float
        The ideal loop's crossover.
    f_i, f_d : float
        The leak's and the derivative filter's corners (Hz).

    Returns
    -------
    designer.pid.selection.Selection
    """
    return selection.select_parts(kp, ti_s, td_s, fc_hz, r_series=spec.r_series, c_series=spec.c_series,
                               r_min=spec.r_min, r_max=spec.r_max, c_min=spec.c_min, c_max=spec.c_max,
                               f_integrator_hz=f_i, f_differentiator_hz=f_d, tol=spec.tol)
