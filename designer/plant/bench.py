"""The lab bench: the recommended square wave (the seed's 330 Hz, 2 V test of
section IV.9), the slew, swing and period checks for it, the band of the
readings that part tolerances allow (worst case over the tolerance corners),
and the whole bench period as a scope would capture it."""

from __future__ import annotations

import itertools
import math
from dataclasses import dataclass, fields, replace

import numpy as np

from ..core.checks import Check
from ..core.compare import resample
from ..core.lti import dense_time, step_response
from ..core.metrics import step_metrics
from ..core.opamps import OpAmp
from ..spice.deck import SquareTest
from .model import plant_tf
from .sallenkey import SallenKeyParts


def recommend_square_wave(settling_time_s: float, amplitude_v: float, frequency_hz=None,
                          delay_s=None, time_scale_s=None) -> SquareTest:
    """A square wave whose half period leaves the response 1.5 settling times
    (2 %) to settle, rounded down to a round generator setting (the seed used
    330 Hz for its 891 us settling time). ``time_scale_s``: see :class:`SquareTest`."""
    if frequency_hz is None:
        frequency_hz = nice_frequency_below(1.0 / (2 * 1.5 * settling_time_s))
    half = 0.5 / frequency_hz
    if delay_s is None:
        # the rising edge a little after t = 0, within a few time scales for a slow square wave
        delay_s = half * 0.05 if time_scale_s is None else min(half * 0.05, 20 * time_scale_s)
    return SquareTest(amplitude_v=amplitude_v, frequency_hz=frequency_hz, delay_s=delay_s,
                      time_scale_s=time_scale_s)


def signal_checks(t, y_unit, amplitude_v: float, opamp: OpAmp) -> list:
    """Slew and swing checks (:class:`~designer.core.checks.Check`) of the op-amp
    output for a 0 <-> amplitude square wave, given the unit step response
    ``y_unit`` of the output."""
    slope = float(np.max(np.abs(np.gradient(y_unit, t)))) * abs(amplitude_v)
    peak = float(np.max(y_unit)) * amplitude_v
    # the falling edge undershoots below 0 by as much as the rising edge overshoots
    trough = -(float(np.max(y_unit)) - float(y_unit[-1])) * amplitude_v
    if opamp.ideal:
        return [Check("slew_rate", True, f"ideal op-amp; output needs {slope / 1e6:.3g} V/us"),
                Check("output_swing", True, f"ideal op-amp; output spans {trough:.3g} V to {peak:.3g} V")]
    sr = opamp.slew_v_per_s
    slew_ok = slope <= 0.5 * sr
    return [Check("slew_rate", slew_ok,
                  f"output needs {slope / 1e6:.3g} V/us, {opamp.name} gives {sr / 1e6:.3g} V/us"
                  + ("" if slew_ok else " (keep below half of it: lower the amplitude)")),
            Check("output_swing", peak <= opamp.vout_max and trough >= opamp.vout_min,
                  f"output spans {trough:.3g} V to {peak:.3g} V; {opamp.name} on {opamp.vcc:g}/{opamp.vee:g} V "
                  f"reaches {opamp.vout_min:.3g} V to {opamp.vout_max:.3g} V")]


def period_check(test: SquareTest, settling_time_s: float) -> Check | None:
    """A failed check when the square wave's half period is shorter than the 2 %
    settling time (the scope would never show a settled step); None when it is not."""
    if test.half_period_s >= settling_time_s:
        return None
    return Check("square_wave_period", False,
                 f"half period {test.half_period_s * 1e6:.4g} us is shorter than the 2 % settling "
                 f"time {settling_time_s * 1e6:.4g} us: the scope will not show a settled step")


@dataclass(frozen=True)
class Band:
    """The range a reading may take; None when no corner has the reading
    (e.g. the peak time of a response that never overshoots)."""

    lo: float | None
    hi: float | None

    def to_dict(self) -> dict:
        return {"min": self.lo, "max": self.hi}


@dataclass(frozen=True)
class ToleranceBand:
    """Where the scope readings of a build may land, given its parts'
    tolerances: each figure's band over the tolerance corners."""

    fn_hz: Band
    zeta: Band
    overshoot_pct: Band
    peak_time_s: Band
    rise_time_s: Band
    settling_time_s: Band
    r_tolerance_pct: float
    c_tolerance_pct: float

    def to_dict(self) -> dict:
        out = {}
        for f in fields(self):
            value = getattr(self, f.name)
            out[f.name] = value.to_dict() if isinstance(value, Band) else value
        return out


def tolerance_band(parts: SallenKeyParts, r_tol: float, c_tol: float, t_end: float) -> ToleranceBand:
    """Min and max of fn, zeta and the step metrics over the 16 corners of
    R1, R2, C1, C2 at +/- their tolerance (ideal op-amp), for the scope readings."""
    t = dense_time(t_end, 8001)
    rows = []
    for s in itertools.product((-1, 1), repeat=4):
        p = replace(parts, r1=parts.r1 * (1 + s[0] * r_tol), r2=parts.r2 * (1 + s[1] * r_tol),
                    c1=parts.c1 * (1 + s[2] * c_tol), c2=parts.c2 * (1 + s[3] * c_tol))
        m = step_metrics(t, step_response(*plant_tf(p), t), final=p.gain)
        rows.append((p.fn_hz, p.zeta, m.overshoot_pct, m.peak_time_s, m.rise_time_s, m.settling_time_s))
    bands = []
    for column in zip(*rows):
        vals = [v for v in column if v is not None and not math.isnan(v)]
        bands.append(Band(min(vals), max(vals)) if vals else Band(None, None))
    return ToleranceBand(*bands, r_tolerance_pct=100 * r_tol, c_tolerance_pct=100 * c_tol)


@dataclass(frozen=True)
class BenchPeriod:
    """One whole bench period (rising and falling edge) on a uniform grid, as
    a scope captures it: the input, the output (SPICE when simulated, else the
    op-amp-aware model) and both analytic models. ``identify`` reads it back."""

    time_s: np.ndarray
    input_v: np.ndarray
    output_v: np.ndarray
    analytic_v: np.ndarray
    analytic_opamp_v: np.ndarray

    def columns(self) -> dict:
        """Column name -> samples, in the order of the CSV."""
        return {f.name: getattr(self, f.name) for f in fields(self)}


def bench_period(test: SquareTest, ideal_tf, opamp_tf, spice=None, n: int = 4001) -> BenchPeriod:
    """The :class:`BenchPeriod` of ``test``: the models' responses to the square
    wave by superposition of two steps; ``spice``, when simulated, is its
    (time, output, input) over the period."""
    t = np.linspace(0.0, test.stop_s, n)
    u = np.where((t >= test.delay_s) & (t < test.delay_s + test.half_period_s), test.amplitude_v, 0.0)

    def square(num, den):
        up = np.clip(t - test.delay_s, 0.0, None)
        down = np.clip(t - test.delay_s - test.half_period_s, 0.0, None)
        y = step_response(num, den, up) * (t >= test.delay_s)
        return test.amplitude_v * (y - step_response(num, den, down) * (t >= test.delay_s + test.half_period_s))

    ideal, with_opamp = square(*ideal_tf), square(*opamp_tf)
    if spice is None:
        return BenchPeriod(t, u, with_opamp, ideal, with_opamp)
    ts, ys, us = spice
    return BenchPeriod(t, resample(ts, us, t), resample(ts, ys, t), ideal, with_opamp)


def nice_frequency_below(f: float) -> float:
    """The largest 1-1.5-2.2-3.3-4.7-6.8 (E6) x 10^k value not above ``f``
    (function generators are set to round numbers)."""
    k = math.floor(math.log10(f))
    best = None
    for dec in (k - 1, k):
        for m in (1.0, 1.5, 2.2, 3.3, 4.7, 6.8):
            v = float(f"{m * 10 ** dec:.3g}")
            if v <= f * (1 + 1e-12):
                best = v
    return best
