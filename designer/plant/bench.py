"""The bench test and what to expect on the scope: recommended square wave,
slew and swing checks for it, and the +/- band of the readings that part
tolerances allow (worst case over the tolerance corners)."""

from __future__ import annotations

import itertools
import math
from dataclasses import replace

import numpy as np

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
    """Slew and swing checks of the op-amp output for a 0 <-> amplitude square
    wave, given the unit step response ``y_unit`` of the output."""
    slope = float(np.max(np.abs(np.gradient(y_unit, t)))) * abs(amplitude_v)
    peak = float(np.max(y_unit)) * amplitude_v
    # the falling edge undershoots below 0 by as much as the rising edge overshoots
    trough = -(float(np.max(y_unit)) - float(y_unit[-1])) * amplitude_v
    checks = []
    if opamp.ideal:
        checks.append({"name": "slew rate", "ok": True,
                       "detail": f"ideal op-amp; output needs {slope / 1e6:.3g} V/us"})
        checks.append({"name": "output swing", "ok": True,
                       "detail": f"ideal op-amp; output spans {trough:.3g} V to {peak:.3g} V"})
        return checks
    sr = opamp.slew_v_per_s
    checks.append({"name": "slew rate", "ok": slope <= 0.5 * sr,
                   "detail": f"output needs {slope / 1e6:.3g} V/us, {opamp.name} gives {sr / 1e6:.3g} V/us"
                             + ("" if slope <= 0.5 * sr else " (keep below half of it: lower the amplitude)")})
    ok = peak <= opamp.vout_max and trough >= opamp.vout_min
    checks.append({"name": "output swing", "ok": ok,
                   "detail": f"output spans {trough:.3g} V to {peak:.3g} V; {opamp.name} on "
                             f"{opamp.vcc:g}/{opamp.vee:g} V reaches {opamp.vout_min:.3g} V to {opamp.vout_max:.3g} V"})
    return checks


def tolerance_band(parts: SallenKeyParts, r_tol: float, c_tol: float, t_end: float) -> dict:
    """Min and max of fn, zeta and the step metrics over the 16 corners of
    R1, R2, C1, C2 at +/- their tolerance (ideal op-amp), for the scope readings."""
    t = dense_time(t_end, 8001)
    rows = []
    for s in itertools.product((-1, 1), repeat=4):
        p = replace(parts, r1=parts.r1 * (1 + s[0] * r_tol), r2=parts.r2 * (1 + s[1] * r_tol),
                    c1=parts.c1 * (1 + s[2] * c_tol), c2=parts.c2 * (1 + s[3] * c_tol))
        m = step_metrics(t, step_response(*plant_tf(p), t), final=p.gain)
        rows.append({"fn_hz": p.fn_hz, "zeta": p.zeta, "overshoot_pct": m.overshoot_pct,
                     "peak_time_s": m.peak_time_s, "rise_time_s": m.rise_time_s,
                     "settling_time_s": m.settling_time_s})
    band = {}
    for key in rows[0]:
        vals = [r[key] for r in rows if r[key] is not None and not math.isnan(r[key])]
        band[key] = {"min": min(vals), "max": max(vals)} if vals else {"min": None, "max": None}
    band["r_tolerance_pct"] = 100 * r_tol
    band["c_tolerance_pct"] = 100 * c_tol
    return band


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
