"""An integrating process from its step response: the ramp's asymptote.

The model is G(s) = K e^(-theta s) / s (K the velocity gain, output units per
second per input unit). Under a step of amplitude A at t = 0 its output leaves
the initial level y0 at t = theta and ramps at K A: after the transient of any
lag the process also has, the response follows the straight line

    y(t) = y0 + K A (t - theta)

so a straight line fitted to the record's tail gives K = slope / A, and its
intercept with the initial level, t = theta, the apparent dead time (the dead
time plus the lags the integrator hides behind it).

Sources: K. J. Astrom and T. Hagglund, *PID Controllers: Theory, Design, and
Tuning*, 2nd ed. (ISA, 1995), chapter 2 (transient-response methods: the
integrating process K_v e^(-sL)/s read off the step response's asymptote, its
slope the velocity gain and its intercept with the initial level the
apparent dead time L); seed 000 eqs 45 and 57 (the DC motor's position, the
same asymptote with the intercept read as a time constant,
:func:`~designer.identify.dc_motor.dc_motor_position`).

The line is an ordinary least-squares fit, its 95 % intervals from its
covariance (t(0.975, N - 2) and the residuals' variance; the dead time's by the
delta method, theta = -b0 / b1). The record ramps when the slopes of the
tail's two halves agree within :data:`RAMP_TOLERANCE` beyond their noise: a
settling response flattens (a lag of 200 s over a 270 s record: its halves'
slopes differ by about 30 %).
"""

from __future__ import annotations

import math

import numpy as np

from .structures import MethodResult

__all__ = ["METHOD_NAME", "TAIL_FRACTION", "RAMP_TOLERANCE", "asymptote", "step_capture_ramp"]

#: the method's name in the tables (route ``step``)
METHOD_NAME = "integrating-asymptote"
#: the line is fitted to this last fraction of the post-step record
TAIL_FRACTION = 0.75
#: the slopes of the tail's two halves may differ by this fraction (beyond their noise) for a ramp
RAMP_TOLERANCE = 0.1


def _line(t, y) -> tuple:
    """(b0, b1, covariance, dof) of y = b0 + b1 t by least squares."""
    X = np.column_stack((np.ones(t.size), t))
    coef, *_ = np.linalg.lstsq(X, y, rcond=None)
    r = y - X @ coef
    dof = max(t.size - 2, 1)
    cov = np.linalg.inv(X.T @ X) * float(r @ r) / dof
    return float(coef[0]), float(coef[1]), cov, dof


def asymptote(t, y, *, tail: float = TAIL_FRACTION) -> MethodResult:
    """The integrating process K e^(-theta s)/s from a unit step response's ramp.

    Parameters
    ----------
    t : array_like
        Times since the step (s, increasing, the step at 0).
    y : array_like
        The response's deviation from its pre-step level divided by the step
        amplitude (the step methods' convention, :mod:`._step_methods`).
    tail : float
        The last fraction of the record the straight line is fitted to.

    Returns
    -------
    MethodResult
        Model ``integrating``, parameters ``K`` (1/s) and ``theta_s``; points:
        the line's ``slope``, ``intercept``, ``tail_from_s``, the halves'
        ``slope_first``/``slope_second`` and ``K_ci95``/``theta_s_ci95``.
        Not valid (the note says why) when the tail does not ramp (a settling
        response), the slope is not above its noise, or the intercept falls
        before the step by more than its interval.
    """
    from scipy.special import stdtrit
    t = np.asarray(t, float)
    y = np.asarray(y, float)
    nan = {"K": math.nan, "theta_s": math.nan}
    if t.size < 20 or t.shape != y.shape or not (np.all(np.isfinite(t)) and np.all(np.isfinite(y))):
        return MethodResult(METHOD_NAME, "integrating", nan, valid=False,
                            note="needs at least 20 finite samples after the step")
    k0 = int(t.size * (1.0 - tail))
    tt, yy = t[k0:], y[k0:]
    b0, b1, cov, dof = _line(tt, yy)
    q = float(stdtrit(dof, 0.975))
    h = tt.size // 2
    a0, a1, ca, _ = _line(tt[:h], yy[:h])
    c0, c1, cc, _ = _line(tt[h:], yy[h:])
    k_ci = q * math.sqrt(cov[1, 1])
    points = {"slope": b1, "intercept": b0, "tail_from_s": float(tt[0]), "slope_first": a1, "slope_second": c1,
              "K_ci95": k_ci}
    if b1 == 0.0 or not k_ci < abs(b1):
        return MethodResult(METHOD_NAME, "integrating", {"K": b1, "theta_s": math.nan}, valid=False,
                            note=f"the tail's slope ({b1:.4g} /s, +-{k_ci:.3g}) is not above its noise: the "
                                 "response does not ramp (not an integrating process)", points=points)
    theta = -b0 / b1
    grad = np.array([-1.0 / b1, b0 / (b1 * b1)])
    th_ci = q * math.sqrt(float(grad @ cov @ grad))
    points["theta_s_ci95"] = th_ci
    notes = []
    bend = abs(c1 - a1) - 2.0 * q * math.sqrt(ca[1, 1] + cc[1, 1])
    if bend > RAMP_TOLERANCE * abs(b1):
        notes.append(f"the tail's halves rise at {a1:.4g} and {c1:.4g} /s (differing by "
                     f"{100 * abs(c1 - a1) / abs(b1):.0f} %, allowed {100 * RAMP_TOLERANCE:.0f} % beyond the "
                     "noise): the response bends, it does not ramp (a settling plant or a lag slower than the "
                     "record)")
    if theta < 0.0:
        # within its interval, or within half a sample (the step is known to a sample): no dead time
        if theta < -max(th_ci, 0.5 * float(np.median(np.diff(t)))):
            notes.append(f"the asymptote meets the initial level {-theta:.4g} s before the step: not an "
                         "integrating process with dead time")
        theta = 0.0
    elif theta >= tt[0]:
        notes.append(f"the dead time ({theta:.4g} s) reaches into the fitted tail (from {tt[0]:.4g} s): "
                     "record longer after the step")
    return MethodResult(METHOD_NAME, "integrating", {"K": b1, "theta_s": float(theta)}, valid=not notes,
                        note="; ".join(notes), points=points)


def step_capture_ramp(t, u, y):
    """The asymptote method on a step capture (input channel ``u``), or None
    when the input is not one step.

    The step time is the first sample at the input's new level (the held
    input every model is simulated with, :func:`~.outputerror.simulate`), the
    initial level the mean output before it, the amplitude the input's change.

    Parameters
    ----------
    t, u, y : array_like
        The capture: time (s), input and output.

    Returns
    -------
    MethodResult or None
        In the record's units (K per second per input unit), its points with
        ``t_step_s`` and ``amplitude``; None when the input has not exactly one edge.
    """
    from .edges import find_edges
    from .settle import baseline
    t = np.asarray(t, float)
    u = np.asarray(u, float)
    y = np.asarray(y, float)
    edges = find_edges(t, u)
    if len(edges) != 1 or edges[0].amplitude == 0:
        return None
    e = edges[0]
    t_step = float(t[e.index])
    y0, _ = baseline(t, y, t_step)
    post = t >= t_step
    m = asymptote(t[post] - t_step, (y[post] - y0) / e.amplitude)
    m.points.update(t_step_s=t_step, amplitude=float(e.amplitude))
    return m
