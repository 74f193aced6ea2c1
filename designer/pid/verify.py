"""Simulate the closed-loop deck and judge the result: compare it with the
analytic closed loop, and detect the two ways analog loops fail on the bench:

* saturation: an op-amp output pinned at its rail (within 1 % of the swing
  range of the clamp level for at least 0.5 us in all);
* instability: a plant output that still oscillates at the end of the rising
  half period (several zero crossings about its mean, a peak-to-peak above
  2 % of the step, and no decay between the two halves of the last 30 %), or
  that sits far from where it should settle (latch-up, typically at a rail).

Every closed-loop step figure (analytic, SPICE, and the deck's own ``.meas``
lines, :func:`designer.spice.deck.measure_lines`) is measured one way,
:func:`loop_metrics`: levels and the 2 % band relative to the EXPECTED settled
value (the analytic closed loop's DC gain times the step, known before the
simulation, so the standalone deck can use it), over the rising half period.
"""

from __future__ import annotations

import math
from dataclasses import dataclass, replace

import numpy as np

from ..core.compare import metric_deltas, nrms, resample
from ..core.errors import DesignError
from ..core.metrics import StepMetrics, step_metrics
from ..core.opamps import OpAmp
from ..spice.simulate import get_simulator
from .model import OPAMP_OUTPUTS

__all__ = ["loop_metrics", "oscillation", "stages"]

PIN_FRACTION = 0.01
PIN_MIN_TIME_S = 0.5e-6
#: the failed checks that can explain SPICE disagreeing with the analytic loop (besides every bandwidth_*)
EXPLAINING = ("slew_rate", "output_swing", "phase_margin", "closed_loop_stable")


def loop_metrics(t, y, expected_final: float) -> StepMetrics:
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
    StepMetrics
        NaN where a figure is undefined (every figure of a flat response or
        one with NaN samples), with ``final_value`` the last sample (what the
        scope shows at the end of the half period), not the expected value.
    """
    y = np.asarray(y, float)
    last = float(y[-1]) if y.size else math.nan
    try:
        m = step_metrics(t, y, initial=0.0, final=expected_final)
    except DesignError:  # a flat response or one with NaN samples has no step figures
        return no_figures(last)
    return replace(m, final_value=last)


def no_figures(final_value: float = math.nan) -> StepMetrics:
    """Step figures of a response that has none (flat, NaN samples, oscillating), but its last value."""
    nan = math.nan
    return StepMetrics(final_value, nan, nan, nan, nan, nan, nan, nan)


@dataclass(frozen=True)
class SpiceStage:
    """One op-amp output in the simulation: its extremes over the period and,
    for a real op-amp, the time it spends pinned at each rail and slewing
    (changing at 90 % of the slew rate or faster); None for an ideal one."""

    opamp: str
    signal: str
    v_min: float
    v_max: float
    time_high_s: float | None = None
    time_low_s: float | None = None
    time_slewing_s: float | None = None

    @property
    def saturated(self) -> bool | None:
        """Pinned at a rail for at least :data:`PIN_MIN_TIME_S` in all."""
        if self.time_high_s is None:
            return None
        return self.time_high_s + self.time_low_s >= PIN_MIN_TIME_S

    def to_dict(self) -> dict:
        if self.time_high_s is None:   # ideal op-amps: the extremes only
            return {"v_min": self.v_min, "v_max": self.v_max}
        return {"opamp": self.opamp, "signal": self.signal, "time_high_s": self.time_high_s,
                "time_low_s": self.time_low_s, "saturated": self.saturated, "time_slewing_s": self.time_slewing_s,
                "v_min": self.v_min, "v_max": self.v_max}


def stages(t, waves: dict, opamp: OpAmp) -> dict:
    """Per op-amp role (:data:`designer.pid.model.OPAMP_OUTPUTS`) present in
    ``waves``: a :class:`SpiceStage` over the whole record.

    Parameters
    ----------
    t : array_like
        Times (s).
    waves : dict
        Signal -> SPICE waveform (V).
    opamp : OpAmp
        The op-amp of every stage.

    Returns
    -------
    dict
        Role -> :class:`SpiceStage`.
    """
    t = np.asarray(t, float)
    dt_next = np.diff(t, append=t[-1])
    dt = np.diff(t)
    band = PIN_FRACTION * (opamp.vout_max - opamp.vout_min)
    out = {}
    for ref, role, sig in OPAMP_OUTPUTS:
        if sig not in waves:
            continue
        v = np.asarray(waves[sig], float)
        stage = SpiceStage(ref, sig, float(np.min(v)), float(np.max(v)))
        if not opamp.ideal:
            fast = np.abs(np.diff(v)) / dt >= 0.9 * opamp.slew_v_per_s
            stage = replace(stage, time_high_s=float(np.sum(dt_next[v >= opamp.vout_max - band])),
                            time_low_s=float(np.sum(dt_next[v <= opamp.vout_min + band])),
                            time_slewing_s=float(np.sum(dt[fast])))
        out[role] = stage
    return out


@dataclass(frozen=True)
class Oscillation:
    """Is the output still moving at the end of the record, or stuck away from where it should settle?"""

    oscillating: bool
    latched: bool
    tail_p2p_v: float
    tail_crossings: int
    tail_mean_v: float

    @property
    def stable(self) -> bool:
        return not self.oscillating and not self.latched

    def to_dict(self) -> dict:
        return {"oscillating": self.oscillating, "latched": self.latched, "tail_p2p_v": self.tail_p2p_v,
                "tail_crossings": self.tail_crossings, "tail_mean_v": self.tail_mean_v, "stable": self.stable}


def oscillation(t, y, step_v: float, expected_final: float, tail: float = 0.3) -> Oscillation:
    """:class:`Oscillation` of ``y``, judged on the last ``tail`` fraction of the record.

    Parameters
    ----------
    t : array_like
        Times (s).
    y : array_like
        The output (V).
    step_v : float
        The reference step (V).
    expected_final : float
        Where the output should settle (V).
    tail : float
        The fraction of the record judged.

    Returns
    -------
    Oscillation
    """
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
    return Oscillation(bool(oscillating), bool(latched), p2p, crossings, float(seg.mean()))


@dataclass(frozen=True)
class SpiceRun:
    """The closed loop in ngspice, on the analytic grid: step figures (NaN for
    an oscillating or latched output: they would mean nothing), the normalised
    RMS distance from the analytic loop, every op-amp output, the oscillation
    verdict, the metric deltas and the deck's own ``.meas`` values."""

    figures: StepMetrics
    nrms: float
    saturated: bool
    oscillation: Oscillation
    deltas_vs_analytic: dict
    nrms_abstol_v: float
    measurements: dict
    backend: str
    stages: dict              #: role -> SpiceStage
    waves: dict               #: signal -> samples on the analytic grid (plots)

    @property
    def stable(self) -> bool:
        return self.oscillation.stable

    def to_dict(self) -> dict:
        return {**self.figures.to_dict(), "nrms": self.nrms, "saturated": self.saturated, "stable": self.stable,
                "deltas_vs_analytic": self.deltas_vs_analytic, "nrms_abstol_v": self.nrms_abstol_v,
                "measurements": self.measurements, "oscillation": self.oscillation.to_dict(),
                "backend": self.backend}


def run_and_compare(deck: str, simulator: str, t_grid, delay_s: float, analytic_y, step_v: float,
                    expected_final: float, opamp: OpAmp) -> SpiceRun:
    """Simulate ``deck``, resample its rising half onto ``t_grid`` (times from the
    step) and compare its plant output with the analytic one, ``analytic_y``."""
    sim = get_simulator(simulator)
    # a loop that latches never crosses the .meas levels: ngspice reports those
    # measurements as failed, the simulator leaves them out and the waveforms stay
    res = sim.run(deck)
    t = res["time"]
    full = {sig: res[sig] for _, _, sig in OPAMP_OUTPUTS if sig in res.vectors}
    tg = np.asarray(t_grid, float)
    waves = {sig: resample(t, v, tg + delay_s) for sig, v in full.items()}
    osc = oscillation(tg, waves["y"], step_v, expected_final)
    figures = loop_metrics(tg, waves["y"], expected_final)
    if not osc.stable:
        # step figures of an oscillating or latched output mean nothing
        figures = no_figures(figures.final_value)
    abstol = 0.01 * abs(step_v)
    try:
        deltas = metric_deltas(step_metrics(tg, analytic_y, initial=0.0, final=expected_final),
                               step_metrics(tg, waves["y"], initial=0.0, final=expected_final))
    except DesignError:  # a flat or broken waveform has no figures to compare
        deltas = {}
    per_stage = stages(t, full, opamp)
    return SpiceRun(figures, nrms(analytic_y, waves["y"], abstol), any(s.saturated for s in per_stage.values()),
                    osc, deltas, abstol, res.measurements, sim.name, per_stage, waves)


@dataclass(frozen=True)
class Verdict:
    """Does SPICE agree with the analytic loop, and if not, which failed checks explain it?"""

    agree: bool
    overshoot_delta_pp: float | None
    explained_by: tuple       #: ids of the failed checks that explain a disagreement
    unexplained: bool

    def to_dict(self) -> dict:
        return {"agree": self.agree, "overshoot_delta_pp": self.overshoot_delta_pp,
                "explained_by": list(self.explained_by), "unexplained": self.unexplained}


def explain(spice: SpiceRun, analytic: StepMetrics, checks, overshoot_tol_pp: float = 1.0) -> Verdict:
    """Judge ``spice`` against the ``analytic`` figures. With real op-amps a
    disagreement must come with a failed slew, swing, phase-margin, stability
    or bandwidth check (:class:`designer.core.checks.Check`)."""
    a, s = analytic.overshoot_pct, spice.figures.overshoot_pct
    d_os = s - a if math.isfinite(a) and math.isfinite(s) else None
    agree = (d_os is not None and abs(d_os) <= overshoot_tol_pp and spice.nrms < 1.0
             and spice.stable and not spice.saturated)
    failed = tuple(c.id for c in checks if not c.ok and (c.id in EXPLAINING or c.id.startswith("bandwidth_")))
    return Verdict(bool(agree), d_os, failed, bool(not agree and not failed))
