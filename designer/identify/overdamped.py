"""Second-order methods for well-damped and overdamped step responses, read from crossing times (seeds 000, 002, 003).

Methods
-------
- ``two-pole``: two real poles from two points above 50 %
  (seed 002 eqs 16-20), zeta > 2.
- ``stark-mollenkamp``: three points 15/45/75 % (seed 000 eqs 31-37),
  0.45 <= zeta <= 1.3.
- ``jahanmiri-fallahi``: three points 2 or 5/70/90 % (seed 000 eqs 38-42).
- ``peeling``: exponential peeling of two time constants on a semilog plot
  (seed 003 section 2.3).
- ``alfaro-123c-overdamped``: Alfaro's 123c overdamped second order with dead
  time, 25/50/75 % points (the method of seed 000's Table II "Alfaro" row,
  extended to two poles).
- ``harriott``: Harriott (1964): tau1 + tau2 from the 73 % time, their ratio
  from the response at half that sum (his chart, computed here from the exact
  response).

``stark-mollenkamp`` and ``jahanmiri-fallahi`` return an underdamped or an
overdamped model as their zeta falls either side of 1. Overdamped results name
the *fast* time constant ``tau1_s`` and the slow one ``tau2_s`` (tau1 <= tau2),
as seed 003 (tau1 = 5, tau2 = 100) and seed 002 (p1 fast, p2 slow) do.

The signature, the normalisation and the ``valid=False`` notes are those of
every second-order step method (:mod:`._step_methods`).
"""

from __future__ import annotations

import functools
import math

import numpy as np

from ..core.waveform import crossing_time
from ._step_methods import fail, flag_late, guarded, prepare, second_order_params
from .structures import MethodResult, iae_ise, model_step

__all__ = ["two_pole", "stark_mollenkamp", "jahanmiri_fallahi", "peeling",
           "alfaro_123c_overdamped", "harriott"]


@guarded("two-pole", "overdamped")
def two_pole(t, y, yf, sigma=None, levels=(0.6, 0.9)) -> MethodResult:
    """Two real poles from the response above 50 % (seed 002 eqs 16-20), zeta > 2.

    Above 50 % the slow pole dominates: 1 - z = X e^{-a2 t} with a2 = |p2|.
    The seed takes the log-slope between two points Y5, Y6 (eq 16) and the
    fast pole from eqs 17/18, a1 = a2 X / (X - 1) with X = (1 - z_k) e^{a2 t_k}
    at each point (averaged). Here the same straight line ln(1 - z) is fitted
    through every sample between the two levels (60 % and 90 % by default),
    which is the seed's two-point line on clean data and far less sensitive
    to noise. The seed writes e^{p2 t} with p2 signed; only the magnitude
    makes eqs 17/18 consistent.

    Parameters
    ----------
    t, y : array_like
        Times after the step (s) and the response.
    yf : float
        The response's final value.
    sigma : float, optional
        Noise standard deviation of ``y``; estimated from ``y`` when None.
    levels : tuple of float, optional
        The two fractions of the final value bounding the fitted samples.

    Returns
    -------
    MethodResult
        The ``overdamped`` model, or an invalid result with the reason.
    """
    name, model = "two-pole", "overdamped"
    t, z, sigma, err = prepare(t, y, yf, sigma)
    if err:
        return fail(name, model, err, yf)
    ta = crossing_time(t, z, levels[0], sigma=sigma)
    tb = crossing_time(t, z, levels[1], sigma=sigma)
    if not (math.isfinite(ta) and math.isfinite(tb)) or tb <= ta:
        return fail(name, model, f"the response does not rise through {levels[0]:.0%} and "
                     f"{levels[1]:.0%} of its final value", yf)
    sel = (t >= ta) & (t <= tb)
    r = 1.0 - z[sel]
    ok = r > 0.0
    pts = {"t5_s": ta, "t6_s": tb, "y5": levels[0], "y6": levels[1]}
    if ok.sum() >= 3:
        # ln(1 - z) has noise sigma/(1 - z): weight each sample by 1 - z
        slope, icpt = np.polyfit(t[sel][ok], np.log(r[ok]), 1, w=r[ok])
        a2, x = -float(slope), math.exp(float(icpt))
    else:
        a2 = abs((math.log(1.0 - levels[1]) - math.log(1.0 - levels[0])) / (ta - tb))
        x = 0.5 * ((1.0 - levels[0]) * math.exp(a2 * ta) + (1.0 - levels[1]) * math.exp(a2 * tb))
    if a2 <= 0.0 or x <= 1.0:
        return fail(name, model, "the late response is not the tail of two real poles "
                     "(X <= 1 in eqs 17/18): zeta too low or dead time; valid for zeta > 2",
                     yf, pts)
    a1 = a2 * x / (x - 1.0)
    wn = math.sqrt(a1 * a2)
    zeta = (a1 + a2) / (2.0 * wn)
    fast, slow = max(a1, a2), min(a1, a2)
    params = {"K": float(yf), "tau1_s": 1.0 / fast, "tau2_s": 1.0 / slow, "theta_s": 0.0}
    pts.update({"p1_rad_s": -a1, "p2_rad_s": -a2, "X": x, "wn_rad_s": wn, "zeta": zeta})
    valid = zeta > 2.0 - 1e-9
    note = "assumes no dead time" if valid else (
        f"zeta = {zeta:.3f}: outside the method's range zeta > 2 (poles not far enough apart "
        "for the slow one to dominate above 50 %); use t4-t3")
    if valid and x < 1.0 + 20.0 * sigma:
        note += (f"; X = {x:.4f} is within the noise of 1, so the fast pole "
                 f"({fast:.4g} rad/s) is poorly determined")
    return flag_late(MethodResult(name, model, params, valid=valid, note=note, points=pts),
                      t, z, sigma)



# Stark-Mollenkamp's correlations reproduce the exact response within 3 % in
# zeta and wn over this range (checked against the exact response in the tests).
STARK_RANGE = (0.45, 1.3)


@guarded("stark-mollenkamp", "underdamped")
def stark_mollenkamp(t, y, yf, sigma=None) -> MethodResult:
    """Stark-Mollenkamp three points 15/45/75 % (seed 000 eqs 31-37).

    x = (t45 - t15)/(t75 - t15); zeta = (0.0805 - 5.547 (0.475 - x)^2)/(x - 0.356);
    wn = f2(zeta)/(t75 - t15) with f2 = 0.708 (2.811)^zeta (zeta < 1) or
    2.6 zeta - 0.6; theta = t45 - f3(zeta)/wn with f3 = 0.922 (1.66)^zeta.
    An empirical correlation: within 3 % for 0.45 <= zeta <= 1.3.

    Parameters
    ----------
    t, y : array_like
        Times after the step (s) and the response.
    yf : float
        The response's final value.
    sigma : float, optional
        Noise standard deviation of ``y``; estimated from ``y`` when None.

    Returns
    -------
    MethodResult
        The ``underdamped`` or ``overdamped`` model with dead time, or an invalid
        result with the reason.
    """
    name = "stark-mollenkamp"
    t, z, sigma, err = prepare(t, y, yf, sigma)
    if err:
        return fail(name, "underdamped", err, yf)
    t15, t45, t75 = (crossing_time(t, z, p, sigma=sigma) for p in (0.15, 0.45, 0.75))
    if not all(math.isfinite(v) for v in (t15, t45, t75)) or not t15 < t45 < t75:
        return fail(name, "underdamped", "the response does not rise through 15, 45 and 75 % "
                     "of its final value", yf)
    x = (t45 - t15) / (t75 - t15)
    pts = {"t15_s": t15, "t45_s": t45, "t75_s": t75, "x": x}
    num = 0.0805 - 5.547 * (0.475 - x) ** 2
    if x <= 0.356 or num <= 0.0:
        return fail(name, "underdamped", f"x = {x:.4f}: eq 32 needs x > 0.356 and gives no "
                     "positive "
                     "zeta (the correlation covers about 0.45 <= zeta <= 1.3)", yf, pts)
    zeta = num / (x - 0.356)
    f2 = 0.708 * 2.811 ** zeta if zeta < 1.0 else 2.6 * zeta - 0.60
    wn = f2 / (t75 - t15)
    theta = t45 - 0.922 * 1.66 ** zeta / wn
    note = ""
    if theta < 0.0:
        if -theta > 0.02 * (t75 - t15):
            note = f"eq 36 gives a negative dead time ({theta:.3g} s), set to 0; "
        theta = 0.0
    model, params = second_order_params(float(yf), wn, zeta, theta)
    pts.update({"zeta": zeta, "wn_rad_s": wn})
    valid = STARK_RANGE[0] <= zeta <= STARK_RANGE[1]
    if not valid:
        note += (f"zeta = {zeta:.3f} outside {STARK_RANGE[0]} <= zeta <= {STARK_RANGE[1]}, "
                 "where the published correlations lose accuracy")
    return MethodResult(name, model, params, valid=valid, note=note.rstrip("; "), points=pts)


def _jf_from(theta, t70, t90):
    eta = (t90 - t70) / (t90 - theta)
    if eta <= 0.4771:
        zeta = math.sqrt((0.4844651 - 0.75323499 * eta) / (1.0 - 2.0946444 * eta))
    else:
        zeta = 13.9352
    # seed 000 eq 42 prints e^{+zeta}; the denominator then goes negative for
    # zeta > 1.1, so the exponent must be -zeta
    tau = (t90 - theta) / (0.424301 + 4.62533 * zeta - 2.65412 * math.exp(-zeta))
    return eta, zeta, tau


@guarded("jahanmiri-fallahi", "overdamped")
def jahanmiri_fallahi(t, y, yf, sigma=None) -> MethodResult:
    """Jahanmiri-Fallahi three points (seed 000 eqs 38-42).

    theta = t2 or t5 (whichever model has the smaller IAE against the data,
    eq 38), eta = (t90 - t70)/(t90 - theta),
    zeta = sqrt((0.4844651 - 0.75323499 eta)/(1 - 2.0946444 eta)) for
    eta <= 0.4771, else 13.9352 (the seed prints >= twice),
    tau = (t90 - theta)/(0.424301 + 4.62533 zeta - 2.65412 e^{-zeta}).
    The correlation yields zeta >= 0.696 only: for more oscillatory responses
    it is flagged invalid.

    Parameters
    ----------
    t, y : array_like
        Times after the step (s) and the response.
    yf : float
        The response's final value.
    sigma : float, optional
        Noise standard deviation of ``y``; estimated from ``y`` when None.

    Returns
    -------
    MethodResult
        The second-order model with dead time, or an invalid result with the reason.
    """
    name = "jahanmiri-fallahi"
    t, z, sigma, err = prepare(t, y, yf, sigma)
    if err:
        return fail(name, "overdamped", err, yf)
    t2, t5, t70, t90 = (crossing_time(t, z, p, sigma=sigma) for p in (0.02, 0.05, 0.70, 0.90))
    if not all(math.isfinite(v) for v in (t2, t5, t70, t90)) or not t5 < t70 < t90:
        return fail(name, "overdamped", "the response does not rise through 2/5, 70 and 90 % "
                     "of its final value", yf)
    best = None
    for label, theta in (("t2", t2), ("t5", t5)):
        eta, zeta, tau = _jf_from(theta, t70, t90)
        model, params = second_order_params(float(yf), 1.0 / tau, zeta, theta)
        iae, ise = iae_ise(t, z * yf, model_step(model, params, t))
        if best is None or iae < best[0]:
            best = (iae, ise, label, eta, zeta, model, params)
    iae, ise, label, eta, zeta, model, params = best
    pts = {"t2_s": t2, "t5_s": t5, "t70_s": t70, "t90_s": t90, "eta": eta, "theta_from": label}
    # overshoot beyond that of zeta = 0.696 (4.9 %) means the data are more
    # oscillatory than anything the correlation can return
    zmax = float(np.max(z))
    valid = zmax <= 1.0 + 0.049 + 3.0 * sigma and eta <= 0.4771
    note = f"dead time read at {label}"
    if not valid:
        note = ("outside the method's range: the correlation returns zeta >= 0.696 only "
                "and eta <= 0.4771" if zmax > 1.049 + 3.0 * sigma else
                f"eta = {eta:.4f} > 0.4771: zeta pinned at 13.9352 (eq 41)")
    return MethodResult(name, model, params, valid=valid, note=note, points=pts)


def _logfit(t, v):
    """Least-squares line through (t, ln v), each point weighted by v (ln v has
    noise sigma/v): returns (amplitude at t = 0, time constant)."""
    slope, icpt = np.polyfit(t, np.log(v), 1, w=v)
    return math.exp(icpt), (-1.0 / slope if slope < 0.0 else math.inf)


#: Samples the peeling's alternating log-fits use at most.
PEEL_SAMPLES = 4000


@guarded("peeling", "overdamped")
def peeling(t, y, yf, sigma=None, iterations: int = 500) -> MethodResult:
    """Exponential peeling of two time constants (seed 003 section 2.3).

    1 - z(t) = K2 e^{-t/tau2} - K1 e^{-t/tau1}: the straight tail of
    ln(1 - z) gives K2 and tau2 (seed eqs 2.3.40-2.3.43); the difference
    K2 e^{-t/tau2} - (1 - z) is the fast exponential, whose log-line gives K1
    and tau1 (eq 2.3.44). The seed peels once; here the two fits alternate
    (each one on the data minus the other's exponential) until they agree, so
    a noise-free two-pole response is recovered exactly even when the time
    constants are close. A dead time then follows from where the fitted
    K2 e^{-t/tau2} - K1 e^{-t/tau1} has zero slope (the response's start).

    Valid when the fast term has the sign of two cascaded poles (K1 > 0);
    a response with a zero, like seed 003's furnace (both exponentials
    falling), is reported with valid=False and its amplitudes in ``points``.

    Parameters
    ----------
    t, y : array_like
        Times after the step (s) and the response.
    yf : float
        The response's final value.
    sigma : float, optional
        Noise standard deviation of ``y``; estimated from ``y`` when None.
    iterations : int, optional
        Most alternations of the two fits.

    Returns
    -------
    MethodResult
        The ``overdamped`` model, or an invalid result with the reason.
    """
    name, model = "peeling", "overdamped"
    t, z, sigma, err = prepare(t, y, yf, sigma)
    if err:
        return fail(name, model, err, yf)
    if float(np.max(z)) > 1.0 + max(5.0 * sigma, 1e-3):
        return fail(name, model, "the response overshoots: two real time constants "
                     "cannot produce it (valid for overdamped responses)", yf)
    if t.size > PEEL_SAMPLES:
        # the log-lines are refitted up to `iterations` times: on a dense record
        # every few samples carry the same line (exact data stay exact)
        k = int(math.ceil(t.size / PEEL_SAMPLES))
        t, z = t[::k], z[::k]
    r = 1.0 - z
    r_lo = max(0.01, 5.0 * sigma)
    slow_sel = (r <= 0.35) & (r >= r_lo)
    # the tail fit must come after the response has risen past 50 %
    rise = crossing_time(t, z, 0.5, sigma=sigma)
    if math.isfinite(rise):
        slow_sel &= t >= rise
    # past the dead time: exactly 0 before it on clean data, 5 sigma on noisy data
    fast_sel_base = z > 5.0 * sigma
    if slow_sel.sum() < 3:
        return fail(name, model, "too few samples in the tail (1 - y/yf between "
                     f"{r_lo:.3g} and 0.35) to fit the slow exponential", yf)
    ts = t[slow_sel]
    k1, tau1 = 0.0, math.nan
    k2, tau2 = _logfit(ts, r[slow_sel])
    if not math.isfinite(tau2):
        return fail(name, model, "the tail of 1 - y/yf does not decay", yf)
    negative = 0
    for _ in range(max(1, iterations)):
        f = k2 * np.exp(-t / tau2) - r             # = K1 e^{-t/tau1}
        sel = fast_sel_base & (t < ts[0] + 0.5 * (ts[-1] - ts[0]))
        if sel.sum() < 2:
            break
        fs = f[sel]
        # the fast term is largest just after the rise starts: its sign there
        sign = 1.0 if fs[int(np.argmax(np.abs(fs)))] >= 0.0 else -1.0
        fs = sign * fs
        if float(np.max(fs)) < 3.0 * sigma:
            k1, tau1 = 0.0, math.nan        # nothing above the noise to peel
            break
        # keep the part of the fast exponential still well above the noise and
        # above what the slow fit's error would leave
        keep = fs > max(2.0 * sigma, 0.02 * float(np.max(fs)))
        if keep.sum() < 2:
            break
        a, tau_f = _logfit(t[sel][keep], fs[keep])
        if not math.isfinite(tau_f) or tau_f <= 0.0:
            break
        k1, tau1 = sign * a, tau_f
        # a fast term with the sign of a zero for 20 rounds stays one (an FOPDT's
        # noise): the result is refused below, so stop alternating
        negative = negative + 1 if k1 < 0.0 else 0
        if negative >= 20:
            break
        corr = r[slow_sel] + k1 * np.exp(-ts / tau1)
        if np.any(corr <= 0.0):
            break
        k2_new, tau2_new = _logfit(ts, corr)
        if not math.isfinite(tau2_new):
            break
        done = abs(tau2_new - tau2) <= 1e-12 * tau2 and abs(k2_new - k2) <= 1e-12 * abs(k2)
        k2, tau2 = k2_new, tau2_new
        if done:
            break
    pts = {"K1": k1, "K2": k2, "tau_fast_s": tau1, "tau_slow_s": tau2,
           "tail_from_s": float(ts[0]), "tail_to_s": float(ts[-1])}
    if not math.isfinite(tau1):
        return fail(name, model, "no fast exponential above the noise to peel: the response "
                     "is first order (use a FOPDT method)", yf, pts)
    if k1 <= 0.0:
        return fail(name, model, "the fast exponential has the sign of a sum of lags "
                     "(a zero), not of two cascaded poles: K1 = %.4g, K2 = %.4g, tau1 = %.4g s, "
                     "tau2 = %.4g s" % (k1, k2, tau1, tau2), yf, pts)
    # the two-pole step response leaves its start with zero slope, so the dead
    # time is where the fitted K2 e^{-t/tau2} - K1 e^{-t/tau1} has its maximum
    theta = 0.0
    if tau1 != tau2:
        arg = (k1 * tau2) / (k2 * tau1)
        theta = max(0.0, math.log(arg) / (1.0 / tau1 - 1.0 / tau2)) if arg > 0.0 else 0.0
    pts["theta_s"] = theta
    fast, slow = sorted((tau1, tau2))
    params = {"K": float(yf), "tau1_s": fast, "tau2_s": slow, "theta_s": theta}
    valid = bool(slow >= 1.5 * fast)
    note = "" if valid else (f"time constants {fast:.4g} s and {slow:.4g} s are too close "
                             "(ratio < 1.5) to peel apart reliably")
    # On noisy records the log-lines can lock onto noise; the peeled curve must
    # then at least follow the data to within a few noise widths.
    rms = float(np.sqrt(np.mean((z - model_step(model, dict(params, K=1.0), t)) ** 2)))
    pts["rms_error"] = rms
    if valid and rms > 3.0 * sigma + 0.01:
        valid = False
        note = (f"the peeled curve misses the data by {100 * rms:.2g} % rms (noise "
                f"{100 * sigma:.2g} %): the exponentials are not resolved")
    return MethodResult(name, model, params, valid=valid, note=note, points=pts)



# --------------------------------------------------------------------------
# Alfaro 123c (overdamped) and Harriott
# --------------------------------------------------------------------------

@guarded("alfaro-123c-overdamped", "overdamped")
def alfaro_123c_overdamped(t, y, yf, sigma=None) -> MethodResult:
    """Alfaro's 123c method for K e^(-L s) / ((T s + 1)(a T s + 1)), 0 <= a <= 1
    (V. M. Alfaro, "Identificacion de procesos sobreamortiguados utilizando
    tecnicas de lazo abierto", Ingenieria 11, 2001, the reference of seed 000's
    Table II "Alfaro" row).

    From the times to 25, 50 and 75 %:
    a = (-0.6240 t25 + 0.9866 t50 - 0.3626 t75) / (0.3533 t25 - 0.7036 t50 + 0.3503 t75),
    T = (t75 - t25) / (0.9866 + 0.7036 a), L = t75 - (1.3421 + 1.3455 a) T.
    A correlation fitted over 0 <= a <= 1: for a >= 0.3 its model follows the
    response to about 1 % of the step (checked in the tests), its parameters
    less closely (T within about 13 %); towards a = 0 it drifts (7-12 % of the
    step), so a result whose model misses the data by over 2 % rms is invalid.

    Parameters
    ----------
    t, y : array_like
        Times after the step (s) and the response.
    yf : float
        The response's final value.
    sigma : float, optional
        Noise standard deviation of ``y``; estimated from ``y`` when None.

    Returns
    -------
    MethodResult
        The ``overdamped`` model with dead time, or an invalid result with the reason.
    """
    name, model = "alfaro-123c-overdamped", "overdamped"
    t, z, sigma, err = prepare(t, y, yf, sigma)
    if err:
        return fail(name, model, err, yf)
    t25, t50, t75 = (crossing_time(t, z, p, sigma=sigma) for p in (0.25, 0.5, 0.75))
    if not all(math.isfinite(v) for v in (t25, t50, t75)) or not t25 < t50 < t75:
        return fail(name, model, "the response does not rise through 25, 50 and 75 % of its "
                     "final value", yf)
    pts = {"t25_s": t25, "t50_s": t50, "t75_s": t75}
    den = 0.3533 * t25 - 0.7036 * t50 + 0.3503 * t75
    a = (-0.6240 * t25 + 0.9866 * t50 - 0.3626 * t75) / den
    pts["a"] = a
    if not 0.0 <= a <= 1.0:
        return fail(name, model, f"a = {a:.3f} outside 0 <= a <= 1: " + (
            "one pole dominates (a first-order response: use alfaro-123c)" if a < 0 else
            "the response is not that of two real poles with dead time"), yf, pts)
    big = (t75 - t25) / (0.9866 + 0.7036 * a)
    theta = t75 - (1.3421 + 1.3455 * a) * big
    note = ""
    if theta < 0.0:
        if -theta > 0.02 * (t75 - t25):
            note = f"L = {theta:.3g} s came out negative and was set to 0"
        theta = 0.0
    params = {"K": float(yf), "tau1_s": a * big, "tau2_s": big, "theta_s": theta}
    valid = float(np.max(z)) <= 1.0 + max(4.0 * sigma, 0.02)
    if not valid:
        note = "; ".join(x for x in (note, "the response overshoots: two real poles cannot") if x)
    # the correlation drifts near a = 0 (one dominant pole): its model must
    # still follow the data
    rms = float(np.sqrt(np.mean((z - model_step(model, dict(params, K=1.0), t)) ** 2)))
    pts["rms_error"] = rms
    if valid and rms > 0.02 + 3.0 * sigma:
        valid = False
        note = "; ".join(x for x in (note, f"the correlation's model misses the data by "
                                     f"{100 * rms:.2g} % rms (a = {a:.3f}: one pole dominates; "
                                     "see alfaro-123c)") if x)
    return MethodResult(name, model, params, valid=valid, note=note, points=pts)


#: Harriott's 73 % rule: t73 = 1.3 (tau1 + tau2), the curves' common point.
HARRIOTT_73 = 1.3


@functools.lru_cache(maxsize=1)
def _harriott_chart():
    """Harriott's chart, computed: (tau1/(tau1+tau2), y at t = (tau1+tau2)/2) for
    tau1/(tau1+tau2) from 0 (one pole) to 0.5 (a double pole)."""
    r = np.linspace(1e-6, 0.5, 2001)
    h = np.empty_like(r)
    for i, ri in enumerate(r):
        h[i] = float(model_step("overdamped", {"K": 1.0, "tau1_s": ri,
                                               "tau2_s": 1.0 - ri + 1e-9 * (ri == 0.5)},
                                np.array([0.5]))[0])
    return r, h


@guarded("harriott", "overdamped")
def harriott(t, y, yf, sigma=None) -> MethodResult:
    """Harriott's method for two real poles without dead time (P. Harriott,
    Process Control, McGraw-Hill 1964; in most process-control texts).

    tau1 + tau2 = t73 / 1.3, the time to 73 % divided by 1.3; the response at
    half that sum, y(0.5 (tau1 + tau2)) / yf, gives tau1 / (tau1 + tau2) from
    Harriott's chart, computed here from the exact two-pole response (0.393 for
    one pole down to 0.264 for a double pole). Valid for responses inside the
    chart and without dead time.

    Parameters
    ----------
    t, y : array_like
        Times after the step (s) and the response.
    yf : float
        The response's final value.
    sigma : float, optional
        Noise standard deviation of ``y``; estimated from ``y`` when None.

    Returns
    -------
    MethodResult
        The ``overdamped`` model, or an invalid result with the reason.
    """
    name, model = "harriott", "overdamped"
    t, z, sigma, err = prepare(t, y, yf, sigma)
    if err:
        return fail(name, model, err, yf)
    t73 = crossing_time(t, z, 0.73, sigma=sigma)
    if not (math.isfinite(t73) and t73 > 0.0):
        return fail(name, model, "the response does not reach 73 % of its final value", yf)
    total = t73 / HARRIOTT_73
    th = 0.5 * total
    zh = float(np.interp(th, t, z))
    pts = {"t73_s": t73, "tau_sum_s": total, "y_half": zh}
    r, h = _harriott_chart()
    if not h[-1] - 0.01 <= zh <= h[0] + 0.01:
        return fail(name, model, f"y((tau1 + tau2)/2) = {zh:.3f} is outside Harriott's chart "
                     f"({h[-1]:.3f} to {h[0]:.3f}): a dead time or not two real poles", yf, pts)
    ratio = float(np.interp(zh, h[::-1], r[::-1]))
    pts["tau1_fraction"] = ratio
    params = {"K": float(yf), "tau1_s": max(ratio * total, 1e-300),
              "tau2_s": (1.0 - ratio) * total, "theta_s": 0.0}
    valid = float(np.max(z)) <= 1.0 + max(4.0 * sigma, 0.02)
    note = "assumes no dead time" if valid else "the response overshoots: two real poles cannot"
    return flag_late(MethodResult(name, model, params, valid=valid, note=note, points=pts),
                      t, z, sigma)

