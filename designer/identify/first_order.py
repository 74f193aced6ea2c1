"""First-order-plus-dead-time (and double-pole) methods of seed 000, section 3.1.

Every method has the signature ``method(t, y, yf, sigma=None, overshoot=None) -> MethodResult``
where ``t`` is time since the step (s), ``y`` the response deviation divided by
the input amplitude, ``yf`` its settled value (the static gain K) and ``sigma``
the noise of ``y`` when the caller measured it (an averaged square wave's
ripple, which :func:`~designer.core.waveform.noise_sigma` cannot see), else
estimated here. Thresholds are
always fractions of the change, y0 + p (yf - y0), with y0 = 0 here because
``y`` is already relative to the baseline.

Methods
-------
- ``ziegler-nichols``: tangent at the steepest point
  (:func:`designer.core.waveform.inflection_tangent`, the one the PID tuning
  reads too); theta where it meets the baseline, tau from there to where it
  meets yf (seed 000 eq. 7, fig. 3).
- ``hagglund``: theta from the same tangent, tau = t63.2 - theta.
- ``smith``: 28.3 % and 63.2 %: tau = 1.5 (t2 - t1), theta = t2 - tau (eq. 10).
- ``sundaresan-krishnaswamy``: 35.3 % and 85.3 %: tau = 0.67 (t2 - t1),
  theta = 1.3 t1 - 0.29 t2 (eq. 12).
- ``nishikawa``: areas: t0 = A0 / yf with A0 = integral of (yf - y);
  tau = A1 / (0.368 yf) with A1 = integral of y up to t0; theta = t0 - tau (eq. 13-15).
- General two-point family (Table II): tau = a t1 + b t2, theta = c t1 + d t2:
  ``alfaro``, ``broida``, ``chen-yang``, ``ho``, ``viteckova`` (Smith is the
  ``smith`` entry above, with identical coefficients).
- Double-pole two-point versions (Table III): ``ho-double-pole``,
  ``viteckova-double-pole`` (model ``double-pole``).
- ``alfaro-123c``: Alfaro's 123c FOPDT, the Table II row with the original's
  four digits (its overdamped second-order version is
  :func:`designer.identify.overdamped.alfaro_123c_overdamped`).

Validity range (checked, and reported as ``valid=False`` with a note): the
response must be monotonic, as FOPDT and double-pole models cannot overshoot
(more than 2 % overshoot beyond the noise is refused), and it must reach the
method's percentage points. Some published coefficients are not the exact
ones for their points (Chen-Yang c, d; Ho a, b; Ho double pole): even on their
own model those methods are off by up to ~2 % of tau, as published; the tests
bound each method's error by exactly that difference.

The published coefficients are used as printed, except Vitecková's
double-pole a, b, which seed 000 prints as -/+0.749: the exact value for
33 %/70 % on a double pole is 0.7939 and Vitecková's published 0.794 (Alfaro's
survey) matches it; 0.749 is a digit transposition in the seed.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

from ..core.metrics import Overshoot
from ..core.stepfit import data_overshoot, overshoot_mismatch
from ..core.waveform import crossing_time, inflection_tangent, noise_sigma
from .structures import MethodResult

__all__ = ["FIRST_ORDER_METHODS", "METHOD_NAMES", "SUNDARESAN", "TABLE_II", "TABLE_III", "exact_coefficients",
           "hagglund", "nishikawa", "two_point", "unit_time", "ziegler_nichols"]

@dataclass(frozen=True)
class TwoPoint:
    """One row of seed 000 Table II/III: percentages and tau/theta coefficients."""

    name: str
    p1: float
    p2: float
    a: float
    b: float
    c: float
    d: float
    model: str = "fopdt"


#: Seed 000 Table II (FOPDT) and Table III (double pole), as published.
TABLE_II = (
    TwoPoint("alfaro", 0.25, 0.75, -0.91, 0.91, 1.262, -0.262),
    TwoPoint("broida", 0.28, 0.40, -5.5, 5.5, 2.8, -1.8),
    TwoPoint("chen-yang", 0.33, 0.67, -1.4, 1.4, 1.54, -0.54),
    TwoPoint("ho", 0.35, 0.85, -0.67, 0.67, 1.3, -0.29),
    TwoPoint("smith", 0.283, 0.632, -1.5, 1.5, 1.5, -0.5),
    TwoPoint("viteckova", 0.33, 0.70, -1.245, 1.245, 1.498, -0.498),
)
TABLE_III = (
    TwoPoint("ho-double-pole", 0.35, 0.85, -0.463, 0.463, 1.574, -0.574, "double-pole"),
    TwoPoint("viteckova-double-pole", 0.33, 0.70, -0.794, 0.794, 1.937, -0.937, "double-pole"),
)
#: Sundaresan-Krishnaswamy (seed 000 eq. 11-12): same form, its own points.
SUNDARESAN = TwoPoint("sundaresan-krishnaswamy", 0.353, 0.853, -0.67, 0.67, 1.3, -0.29)
#: Alfaro's "123c" FOPDT (V. M. Alfaro, Ingenieria 11, 2001; the survey seed 000
#: cites): the 25 % and 75 % points of seed 000's Table II row with the four
#: digits of the original, tau = 0.9102 (t75 - t25), theta = 1.2620 t25 - 0.2620 t75
#: (0.9102 = 1/ln 3: exact on an FOPDT).
ALFARO_123C = TwoPoint("alfaro-123c", 0.25, 0.75, -0.9102, 0.9102, 1.2620, -0.2620)


def exact_coefficients(p1: float, p2: float, model: str = "fopdt") -> tuple:
    """(a, b, c, d) that make a two-point method exact for its model.

    For FOPDT, y reaches p at theta + x(p) tau with x(p) = -ln(1 - p); for a
    double pole x solves 1 - (1 + x) e^-x = p. Then tau = (t2 - t1)/(x2 - x1)
    and theta = t1 - x1 tau. Used by the tests to bound each published
    coefficient's rounding.

    Parameters
    ----------
    p1, p2 : float
        The two fractions of the final value the method reads (0 < p < 1).
    model : str, optional
        ``fopdt`` or ``double-pole``.

    Returns
    -------
    tuple of float
        ``(a, b, c, d)`` of tau = a t1 + b t2, theta = c t1 + d t2.
    """
    x1, x2 = unit_time(p1, model), unit_time(p2, model)
    b = 1.0 / (x2 - x1)
    c = 1.0 + x1 * b
    return -b, b, c, 1.0 - c


def unit_time(p: float, model: str = "fopdt") -> float:
    """Time (in units of tau, after the dead time) at which the model reaches fraction p.

    Parameters
    ----------
    p : float
        Fraction of the final value (0 < p < 1).
    model : str, optional
        ``fopdt`` or ``double-pole``.

    Returns
    -------
    float
        The time in units of tau.
    """
    if model == "fopdt":
        return -math.log(1.0 - p)
    from scipy.optimize import brentq
    return brentq(lambda x: 1.0 - (1.0 + x) * math.exp(-x) - p, 1e-12, 60.0)


# --------------------------------------------------------------------------- helpers

def _validity(t, y, yf, sigma, overshoot: Overshoot | None = None, model: str = "fopdt"):
    """(valid, note) common to every first-order method: the data's measured
    ``overshoot`` (else :func:`~designer.core.stepfit.data_overshoot` of ``t``,
    ``y``) must be one a monotonic ``model`` can leave
    (:func:`~designer.core.stepfit.overshoot_mismatch`)."""
    if overshoot is None:
        overshoot = data_overshoot(t, y, yf, sigma)
    why = overshoot_mismatch(model, {}, overshoot)
    return not why, why


def _result(name, model, K, tau, theta, points, valid, note):
    notes = [note] if note else []
    if not (math.isfinite(tau) and tau > 0):
        valid = False
        notes.append(f"tau = {tau:.4g} s is not positive: the points are inconsistent with the model")
    if math.isfinite(theta) and theta < 0:
        # A small negative dead time is rounding of the coefficients on a
        # delay-free process; clip it, as every author does.
        notes.append(f"theta = {theta:.4g} s came out negative and was set to 0")
        theta = 0.0
    return MethodResult(name=name, model=model, params={"K": float(K), "tau_s": float(tau),
                        "theta_s": float(theta)}, valid=valid, note="; ".join(notes),
                        points=points)


def _points_ok(name, model, times, K):
    if any(not math.isfinite(x) for x in times):
        return MethodResult(name=name, model=model,
                            params={"K": float(K), "tau_s": math.nan, "theta_s": math.nan},
                            valid=False, note="the response never reaches the method's "
                            "percentage points")
    return None


# --------------------------------------------------------------------------- tangent

def ziegler_nichols(t, y, yf, sigma=None, overshoot=None) -> MethodResult:
    """Ziegler-Nichols reaction curve (seed 000 eq. 7, fig. 3).

    Validity: monotonic S-shaped response with an identifiable inflection.

    Parameters
    ----------
    t, y : array_like
        Times after the step (s) and the response.
    yf : float
        The response's final value.
    sigma : float, optional
        Noise standard deviation of ``y``; estimated from ``y`` when None.
    overshoot : Overshoot, optional
        The record's overshoot when the caller measured it, else measured here.

    Returns
    -------
    MethodResult
        The ``fopdt`` model, flagged invalid with the reason when it does not apply.
    """
    sigma = noise_sigma(y) if sigma is None else sigma
    tg = inflection_tangent(t, y, yf, sigma=sigma)
    theta = tg.t_base
    t3 = tg.t_level(yf)
    valid, note = _validity(t, y, yf, sigma, overshoot)
    return _result("ziegler-nichols", "fopdt", yf, t3 - theta, theta,
                   {"t_inflection_s": tg.t, "y_inflection": tg.y, "slope_per_s": tg.slope,
                    "t1_s": theta, "t3_s": t3, "window_s": tg.window_s}, valid, note)


def hagglund(t, y, yf, sigma=None, overshoot=None) -> MethodResult:
    """Hägglund: ZN dead time, tau to the 63.2 % point (seed 000 fig. 3).

    Parameters
    ----------
    t, y : array_like
        Times after the step (s) and the response.
    yf : float
        The response's final value.
    sigma : float, optional
        Noise standard deviation of ``y``; estimated from ``y`` when None.
    overshoot : Overshoot, optional
        The record's overshoot when the caller measured it, else measured here.

    Returns
    -------
    MethodResult
        The ``fopdt`` model, flagged invalid with the reason when it does not apply.
    """
    sigma = noise_sigma(y) if sigma is None else sigma
    tg = inflection_tangent(t, y, yf, sigma=sigma)
    theta = tg.t_base
    t2 = _cross(t, y, yf, 0.632, sigma)
    bad = _points_ok("hagglund", "fopdt", [t2], yf)
    if bad:
        return bad
    valid, note = _validity(t, y, yf, sigma, overshoot)
    return _result("hagglund", "fopdt", yf, t2 - theta, theta,
                   {"t_inflection_s": tg.t, "slope_per_s": tg.slope, "t1_s": theta,
                    "t2_s": t2, "window_s": tg.window_s}, valid, note)


def _cross(t, y, yf, p, sigma):
    sgn = 1.0 if yf >= 0 else -1.0
    return crossing_time(t, sgn * np.asarray(y), p * abs(yf), sigma=sigma)


def two_point(row: TwoPoint, t, y, yf, sigma=None, overshoot=None) -> MethodResult:
    """General two-point method: tau = a t1 + b t2, theta = c t1 + d t2 (seed 000 eq. 16).

    Parameters
    ----------
    row : TwoPoint
        The method: its name, model, the two fractions read and a, b, c, d.
    t, y : array_like
        Times after the step (s) and the response.
    yf : float
        The response's final value.
    sigma : float, optional
        Noise standard deviation of ``y``; estimated from ``y`` when None.
    overshoot : Overshoot, optional
        The record's overshoot when the caller measured it, else measured here.

    Returns
    -------
    MethodResult
        The row's model, flagged invalid with the reason when it does not apply.
    """
    sigma = noise_sigma(y) if sigma is None else sigma
    t1 = _cross(t, y, yf, row.p1, sigma)
    t2 = _cross(t, y, yf, row.p2, sigma)
    bad = _points_ok(row.name, row.model, [t1, t2], yf)
    if bad:
        return bad
    tau = row.a * t1 + row.b * t2
    theta = row.c * t1 + row.d * t2
    valid, note = _validity(t, y, yf, sigma, overshoot, row.model)
    k1, k2 = _pct_key(row.p1), _pct_key(row.p2)
    return _result(row.name, row.model, yf, tau, theta, {k1: t1, k2: t2}, valid, note)


def _pct_key(p):
    return f"t{100 * p:g}_s".replace(".", "_")


def nishikawa(t, y, yf, sigma=None, overshoot=None) -> MethodResult:
    """Nishikawa areas (seed 000 eq. 13-15).

    A0 is the signed area between yf and y (the seed writes |.|; for the
    monotonic responses the method is meant for they coincide, and only the
    signed area equals the sum of time constants plus dead time). The record
    must cover the settling: the area is truncated at its end.

    Parameters
    ----------
    t, y : array_like
        Times after the step (s) and the response.
    yf : float
        The response's final value.
    sigma : float, optional
        Noise standard deviation of ``y``; estimated from ``y`` when None.
    overshoot : Overshoot, optional
        The record's overshoot when the caller measured it, else measured here.

    Returns
    -------
    MethodResult
        The ``fopdt`` model, flagged invalid with the reason when it does not apply.
    """
    t = np.asarray(t, float)
    y = np.asarray(y, float)
    sigma = noise_sigma(y) if sigma is None else sigma
    a0 = float(np.trapezoid(yf - y, t))
    t0 = a0 / yf
    if not (math.isfinite(t0) and t[0] < t0 < t[-1]):
        return MethodResult("nishikawa", "fopdt", {"K": float(yf), "tau_s": math.nan,
                            "theta_s": math.nan}, valid=False,
                            note="area A0 gives t0 outside the record")
    m = t <= t0
    tt = np.append(t[m], t0)
    yy = np.append(y[m], np.interp(t0, t, y))
    a1 = float(np.trapezoid(yy, tt))
    tau = a1 / (0.368 * yf)
    theta = t0 - tau
    valid, note = _validity(t, y, yf, sigma, overshoot)
    return _result("nishikawa", "fopdt", yf, tau, theta, {"A0_s": a0, "A1_s": a1, "t0_s": t0},
                   valid, note)


def smith(t, y, yf, sigma=None, overshoot=None):
    return two_point(TABLE_II[4], t, y, yf, sigma, overshoot)


def sundaresan_krishnaswamy(t, y, yf, sigma=None, overshoot=None):
    return two_point(SUNDARESAN, t, y, yf, sigma, overshoot)


def alfaro_123c(t, y, yf, sigma=None, overshoot=None):
    """Alfaro 123c, FOPDT: 25 % and 75 % points (:data:`ALFARO_123C`)."""
    return two_point(ALFARO_123C, t, y, yf, sigma, overshoot)


def _bind(row):
    def method(t, y, yf, sigma=None, overshoot=None):
        return two_point(row, t, y, yf, sigma, overshoot)
    method.__name__ = row.name.replace("-", "_")
    method.__doc__ = (f"{row.name}: {100 * row.p1:g} % and {100 * row.p2:g} % points, "
                      f"{row.model} (seed 000 Table {'III' if row.model != 'fopdt' else 'II'}).")
    return method


#: Every first-order and double-pole method, in the seed's order (Alfaro 123c last).
FIRST_ORDER_METHODS = [ziegler_nichols, hagglund, smith, sundaresan_krishnaswamy, nishikawa] + [
    _bind(r) for r in TABLE_II if r.name != "smith"] + [_bind(r) for r in TABLE_III] + [
    alfaro_123c]

#: name -> method, for ``--methods``.
METHOD_NAMES = {"ziegler-nichols": ziegler_nichols, "hagglund": hagglund, "smith": smith,
                "sundaresan-krishnaswamy": sundaresan_krishnaswamy, "nishikawa": nishikawa,
                **{r.name: m for r, m in zip([r for r in TABLE_II if r.name != "smith"]
                                              + list(TABLE_III), FIRST_ORDER_METHODS[5:])},
                "alfaro-123c": alfaro_123c}
