"""Comparing two waveforms (analytic, simulated, measured): metric by metric
and sample by sample."""

from __future__ import annotations

import math

import numpy as np

from .metrics import StepMetrics

#: metrics compared, with how the delta is expressed
COMPARED = ("overshoot_pct", "peak_time_s", "rise_time_s", "settling_time_s")


def resample(t_src, y_src, t_dst):
    """Linear interpolation of (t_src, y_src) onto ``t_dst`` (inside the source span)."""
    return np.interp(np.asarray(t_dst, float), np.asarray(t_src, float), np.asarray(y_src, float))


def nrms(reference, other, abstol: float) -> float:
    """Normalised RMS error: RMS of (ref - other) / (0.01 |ref| + abstol).

    Below 1 means the waveforms agree to about 1 % of the value plus
    ``abstol`` everywhere on average (a pass).
    """
    a = np.asarray(reference, float)
    b = np.asarray(other, float)
    if abstol <= 0:
        raise ValueError("abstol must be positive")
    return float(np.sqrt(np.mean(((a - b) / (0.01 * np.abs(a) + abstol)) ** 2)))


def metric_deltas(reference: StepMetrics, other: StepMetrics) -> dict:
    """``other - reference`` for each compared metric: percentage points for
    overshoot, seconds and percent for times."""
    out = {}
    for name in COMPARED:
        a, b = getattr(reference, name), getattr(other, name)
        if a is None or b is None or math.isnan(a) or math.isnan(b):
            out[name] = {"delta": None, "delta_pct": None}
            continue
        d = b - a
        out[name] = {"delta": d, "delta_pct": (100.0 * d / a) if a and name != "overshoot_pct" else None}
    return out


#: how far SPICE may be from the model it should match, per metric: (kind, limit).
#: Settling also gets half a damped period: with ringing, the last 2 % crossing
#: jumps by half a cycle when a peak grazes the band edge.
AGREEMENT = {"overshoot_pct": ("pp", 1.0), "peak_time_s": ("rel", 0.02),
             "rise_time_s": ("rel", 0.02), "settling_time_s": ("rel", 0.05)}


def disagreements(deltas: dict, reference: StepMetrics, half_ring_period_s: float = 0.0) -> list:
    """The compared metrics outside :data:`AGREEMENT`, as readable strings (empty: agree).

    ``deltas`` from :func:`metric_deltas`; a metric the reference has and the other
    lacks (e.g. an overshoot the simulation does not show) is a disagreement.
    """
    out = []
    for name, (kind, limit) in AGREEMENT.items():
        ref = getattr(reference, name)
        d = deltas[name]["delta"]
        if ref is None or math.isnan(ref):
            continue
        if d is None:
            out.append(f"{name}: model {ref:.4g}, simulation has none")
            continue
        allowed = limit if kind == "pp" else limit * abs(ref)
        if name == "settling_time_s":
            allowed = max(allowed, half_ring_period_s)
        if abs(d) > allowed:
            unit = " pp" if kind == "pp" else " s"
            out.append(f"{name}: off by {d:+.4g}{unit} (allowed {allowed:.3g}{unit})")
    return out
