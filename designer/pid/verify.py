"""Simulate the closed-loop deck and judge the result: compare it with the
analytic closed loop, and detect the two ways analog loops fail on the bench:

* saturation: an op-amp output pinned at its rail (within 1 % of the swing
  range of the clamp level for at least 0.5 us in all);
* instability: a plant output that still oscillates at the end of the rising
  half period (several zero crossings about its mean, a peak-to-peak above
  2 % of the step, and no decay between the two halves of the last 30 %), or
  that sits far from where it should settle (latch-up, typically at a rail).

Every closed-loop step figure (analytic, SPICE, and the deck's own ``.meas``
lines, :func:`designer.netlist.measure_lines`) is measured one way,
:func:`loop_metrics`: levels and the 2 % band relative to the EXPECTED settled
value (the analytic closed loop's DC gain times the step, known before the
simulation, so the standalone deck can use it), over the rising half period.
"""

from __future__ import annotations

import math

import numpy as np

from ..core.compare import metric_deltas, nrms, resample
from ..core.errors import DesignError
from ..core.metrics import step_metrics
from ..core.opamps import OpAmp
from ..spice.simulate import get_simulator
from .model import OPAMP_OUTPUTS

PIN_FRACTION = 0.01
PIN_MIN_TIME_S = 0.5e-6


#: what a step figure is when the response has none (flat, or NaN samples)
NO_FIGURES = {k: None for k in ("overshoot_pct", "peak_time_s", "rise_time_s", "rise_time_0_100_s",
                                "settling_time_s", "settling_time_5pct_s", "peak_value")}


def loop_metrics(t, y, expected_final: float) -> dict:
    """Step figures of a closed-loop response the way the deck measures them.

    Parameters
    ----------
    t : array_like
        Time from the rising edge, over the rising half period (the deck's
        ``.meas`` window).
    y : array_like
        Plant output, from rest (0 V).
    expected_final : float
        The settled output the levels refer to (the deck's literal levels):
        10/90 % for the rise time, the 2 % (and 5 %) band for the settling
        time and the overshoot are all relative to it.

    Returns
    -------
    dict
        :class:`designer.metrics.StepMetrics` fields (None when undefined),
        with ``final_value`` the last sample (what the scope shows at the end
        of the half period), not the expected value.
    """
    y = np.asarray(y, float)
    try:
        m = step_metrics(t, y, initial=0.0, final=expected_final).to_dict()
    except DesignError:  # a flat response or one with NaN samples has no step figures
        m = dict(NO_FIGURES)
    last = float(y[-1]) if y.size else math.nan
    m["final_value"] = last if math.isfinite(last) else None
    return m


def saturation(t, waves: dict, opamp: OpAmp) -> dict:
    """Per op-amp output: time spent pinned at each rail (s) over the record."""
    t = np.asarray(t, float)
    out = {}
    if opamp.ideal:
        return out
    band = PIN_FRACTION * (opamp.vout_max - opamp.vout_min)
    dt = np.diff(t, append=t[-1])
    for ref, role, sig in OPAMP_OUTPUTS:
        if sig not in waves:
            continue
        v = np.asarray(waves[sig], float)
        hi = float(np.sum(dt[v >= opamp.vout_max - band]))
        lo = float(np.sum(dt[v <= opamp.vout_min + band]))
        out[role] = {"opamp": ref, "signal": sig, "time_high_s": hi, "time_low_s": lo,
                     "saturated": hi + lo >= PIN_MIN_TIME_S}
    return out


def slewing(t, waves: dict, opamp: OpAmp) -> dict:
    """Per op-amp output: time spent changing at 90 % of the slew rate or faster."""
    t = np.asarray(t, float)
    out = {}
    if opamp.ideal:
        return out
    for ref, role, sig in OPAMP_OUTPUTS:
        if sig not in waves:
            continue
        v = np.asarray(waves[sig], float)
        dt = np.diff(t)
        fast = np.abs(np.diff(v)) / dt >= 0.9 * opamp.slew_v_per_s
        out[role] = {"opamp": ref, "signal": sig, "time_slewing_s": float(np.sum(dt[fast]))}
    return out


def oscillation(t, y, step_v: float, expected_final: float, tail: float = 0.3) -> dict:
    """Is the output still moving at the end of the record, or stuck away from
    where it should settle? Looks at the last ``tail`` fraction of the record."""
    t = np.asarray(t, float)
    y = np.asarray(y, float)
    k = int(len(y) * (1 - tail))
    seg = y[k:]
    p2p = float(seg.max() - seg.min())
    centred = seg - seg.mean()
    crossings = int(np.sum(np.sign(centred[:-1]) * np.sign(centred[1:]) < 0))
    half = len(seg) // 2
    early = float(np.ptp(seg[:half])) if half > 1 else p2p
    late = float(np.ptp(seg[half:])) if half > 1 else p2p
    # ringing that still decays is a slow but stable loop; a sustained or
    # growing swing is an oscillation
    oscillating = ((p2p > 0.02 * abs(step_v) and crossings >= 4 and late >= 0.7 * early)
                   # a slow, large swing (rail to rail, slew-limited) crosses fewer times
                   or (p2p > 0.2 * abs(step_v) and crossings >= 2))
    offset = abs(float(seg.mean()) - expected_final)
    latched = (not oscillating) and offset > 0.2 * abs(step_v) and p2p < 0.02 * abs(step_v)
    return {"oscillating": bool(oscillating), "latched": bool(latched), "tail_p2p_v": p2p,
            "tail_crossings": crossings, "tail_mean_v": float(seg.mean()),
            "stable": bool(not oscillating and not latched)}


def run_and_compare(deck: str, simulator: str, t_grid, delay_s: float, half_period_s: float,
                    analytic: dict, step_v: float, expected_final: float, opamp: OpAmp) -> dict:
    """Simulate ``deck``, resample its rising half onto ``t_grid`` (times from the
    step) and compare with the analytic waveforms ``analytic`` (signal -> array).

    Returns a dict with the SPICE metrics (plus ``saturated``, ``stable`` and
    ``nrms``), per-op-amp saturation and slewing, the oscillation verdict, the
    metric deltas, the resampled waveforms and ngspice's ``.meas`` values.
    """
    sim = get_simulator(simulator)
    # a loop that latches never crosses the .meas levels: ngspice reports those
    # measurements as failed, the simulator leaves them out and the waveforms stay
    res = sim.run(deck)
    t = res["time"]
    full = {sig: res[sig] for _, _, sig in OPAMP_OUTPUTS if sig in res.vectors}
    tg = np.asarray(t_grid, float)
    waves = {sig: resample(t, v, tg + delay_s) for sig, v in full.items()}
    sat = saturation(t, full, opamp)
    slw = slewing(t, full, opamp)
    osc = oscillation(tg, waves["y"], step_v, expected_final)
    saturated = any(v["saturated"] for v in sat.values())
    m = loop_metrics(tg, waves["y"], expected_final)
    if not osc["stable"]:
        # step figures of an oscillating or latched output mean nothing
        m = {k: (v if k == "final_value" else None) for k, v in m.items()}
    abstol = 0.01 * abs(step_v)
    m.update(nrms=nrms(analytic["y"], waves["y"], abstol), saturated=saturated, stable=osc["stable"])
    try:
        deltas = metric_deltas(step_metrics(tg, analytic["y"], initial=0.0, final=expected_final),
                               step_metrics(tg, waves["y"], initial=0.0, final=expected_final))
    except DesignError:  # a flat or broken waveform has no figures to compare
        deltas = {}
    extremes = {sig: (float(np.min(v)), float(np.max(v))) for sig, v in full.items()}
    return {"metrics": m, "saturation": sat, "extremes": extremes, "slewing": slw, "oscillation": osc, "deltas": deltas,
            "waves": waves, "measurements": res.measurements, "backend": sim.name,
            "nrms_abstol_v": abstol}


def explain(spice_metrics: dict, analytic_metrics: dict, checks: list, overshoot_tol_pp: float = 1.0) -> dict:
    """Does SPICE agree with the analytic loop, and if not, which failed check
    explains it? (With real op-amps a disagreement must come with a failed
    slew, swing, phase-margin or stability check.)"""
    a, s = analytic_metrics.get("overshoot_pct"), spice_metrics.get("overshoot_pct")
    d_os = None if a is None or s is None else s - a
    agree = (d_os is not None and abs(d_os) <= overshoot_tol_pp and spice_metrics.get("nrms", math.inf) < 1.0
             and spice_metrics.get("stable", False) and not spice_metrics.get("saturated", False))
    failed = [c["name"] for c in checks if not c["ok"] and c["name"] in
              ("slew_rate", "output_swing", "phase_margin", "closed_loop_stable")
              or (not c["ok"] and c["name"].startswith("bandwidth_"))]
    return {"agree": bool(agree), "overshoot_delta_pp": d_os, "explained_by": failed,
            "unexplained": bool(not agree and not failed)}
