"""Comparing two waveforms (analytic, simulated, measured): metric by metric
and sample by sample."""

from __future__ import annotations

import math

import numpy as np

from .metrics import StepMetrics

__all__ = ["AGREEMENT", "disagreements", "metric_deltas", "nrms", "resample", "trapezoid_weights"]

#: metrics compared, with how the delta is expressed
COMPARED = ("overshoot_pct", "peak_time_s", "rise_time_s", "settling_time_s")


def resample(t_src, y_src, t_dst):
    """Linear interpolation of (t_src, y_src) onto ``t_dst`` (inside the source span).

    Parameters
    ----------
    t_src, y_src : array_like
        The source samples.
    t_dst : array_like
        Where they are wanted.

    Returns
    -------
    numpy.ndarray
        The values on ``t_dst``.
    """
    return np.interp(np.asarray(t_dst, float), np.asarray(t_src, float), np.asarray(y_src, float))


def trapezoid_weights(t) -> np.ndarray:
    """Each sample's share of the span of ``t`` under the trapezoidal rule
    (half an interval on each side; the ends get half of one), so that
    ``sum(w * f)`` integrates ``f`` over a grid whether its steps are uniform or
    adaptive (ngspice's are).

    Parameters
    ----------
    t : array_like
        The grid, increasing.

    Returns
    -------
    numpy.ndarray
        The weights.
    """
    t = np.asarray(t, float)
    dt = np.diff(t)
    w = np.zeros_like(t)
    w[:-1] += dt / 2
    w[1:] += dt / 2
    return w


def nrms(gold, test, abstol: float, *, reltol: float = 0.01, t=None, t_gold=None) -> float:
    """The normalised RMS error of ``test`` against ``gold``: Xyce's
    ``xyce_verify`` rule,

        sqrt( (1/T) integral( ((gold - test) / (reltol |gold| + abstol))^2 dt ) )

    over the test's time points ``t`` (span T) with trapezoidal weights, so
    adaptive simulator steps count by the time they cover, not by their
    number. Below 1 is a pass: the waveforms agree to ``reltol`` of the value
    plus ``abstol`` on (RMS) average. The design commands compare SPICE with
    their models this way (the model is the gold), and ``check-design`` a run
    with its golden waveform.

    Parameters
    ----------
    gold, test : array_like
        The reference and the waveform under test. ``gold`` is on the test's
        time points, or on its own ``t_gold``, then interpolated (linearly) onto ``t``.
    abstol : float
        Absolute tolerance, in the signals' units (> 0).
    reltol : float
        Relative tolerance (>= 0; 0.01 is 1 %).
    t : array_like, optional
        The test's time points (increasing); default a uniform grid.
    t_gold : array_like, optional
        The gold's own time points (needs ``t``).

    Returns
    -------
    float
        The error; a single sample (T = 0) gives the plain normalised error there.
    """
    if not abstol > 0:
        raise ValueError("abstol must be positive")
    if not reltol >= 0:
        raise ValueError("reltol must not be negative")
    b = np.asarray(test, float)
    t = np.arange(b.size, dtype=float) if t is None else np.asarray(t, float)
    if t_gold is not None:
        a = resample(t_gold, gold, t)
    else:
        a = np.asarray(gold, float)
    err2 = ((a - b) / (reltol * np.abs(a) + abstol)) ** 2
    span = float(t[-1] - t[0]) if t.size > 1 else 0.0
    if span <= 0:
        return float(np.sqrt(np.mean(err2)))
    return float(np.sqrt(np.sum(trapezoid_weights(t) * err2) / span))


def metric_deltas(reference: StepMetrics, other: StepMetrics) -> dict:
    """``other - reference`` for each compared metric: percentage points for
    overshoot, seconds and percent for times.

    Parameters
    ----------
    reference, other : StepMetrics
        The metrics compared.

    Returns
    -------
    dict
        Metric -> difference.
    """
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

    Parameters
    ----------
    deltas : dict
        Metric -> difference (:func:`metric_deltas`).
    reference : StepMetrics
        The reference's metrics.
    half_ring_period_s : float
        Half the ringing period (s): the settling times may differ by that much (one ring).

    Returns
    -------
    list of str
        The disagreements.
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
