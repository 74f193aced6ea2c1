"""Second-order methods that read an underdamped (or near-critical) step response (seeds 000, 002 and 003).

Methods
-------
- ``overshoot``: first overshoot and peak time (seed 000 eqs 20-23,
  seed 003 eq 2.2.11); no dead time.
- ``log-decrement``: first and second overshoot and the period
  (seed 002 eqs 5-7), zeta <= 0.5.
- ``t4-t3``: times to 26.4 % and 80.1 % (seed 002 eqs 8-12, Table 2
  computed here from the exact response), 0.5 <= zeta <= 2; its result is
  overdamped above zeta = 1.
- ``chen``: Cheng-Liang Chen, underdamped with dead time (seed 000 eqs 24-30).

Their closed forms are public: :func:`zeta_from_overshoot` (seed 000 eq 23 / 26),
:func:`wn_from_peak_time` (seed 000 eq 20), :func:`normalized_step` (the exact
response for any zeta), :func:`t4_t3_ratio`, :func:`t4_t3_table` and
:func:`zeta_from_t4_t3` (seed 002 eq 9 and Table 2).

Peaks (:func:`extrema`) are the vertex of a parabola fitted around the extreme
sample of each lobe; lobes are delimited by crossings of the final value with
hysteresis.

The signature, the normalisation and the ``valid=False`` notes are those of
every second-order step method (:mod:`._step_methods`).
"""

from __future__ import annotations

import functools
import math

import numpy as np
from scipy.optimize import brentq

from ..core.waveform import crossing_time, moving_average, peak_region, refine_peak
from ._step_methods import fail, flag_late, guarded, prepare, second_order_params
from .structures import MethodResult

__all__ = [
    "overshoot", "log_decrement", "t4_t3", "chen",
    "zeta_from_overshoot", "wn_from_peak_time", "normalized_step",
    "t4_t3_ratio", "t4_t3_table", "zeta_from_t4_t3", "extrema",
]

# seed 002 eq 8 prints 0.26416 and 0.80079; the exact values of its own
# formulas (y at t = 1/wn and 3/wn for zeta = 1) are 0.26424 and 0.80085
Y3_LEVEL = 1.0 - 2.0 / math.e
Y4_LEVEL = 1.0 - 4.0 / math.e ** 3


# --------------------------------------------------------------------------
# closed forms
# --------------------------------------------------------------------------

def zeta_from_overshoot(mp):
    """Damping ratio from the fractional overshoot ``mp`` (0 < mp < 1), seed 000 eq 23 / 26.

    Parameters
    ----------
    mp : float or array_like
        Overshoot as a fraction of the final value.

    Returns
    -------
    float or numpy.ndarray
        Damping ratio.
    """
    lm = np.log(np.asarray(mp, float))
    return -lm / np.sqrt(math.pi ** 2 + lm * lm)


def wn_from_peak_time(tp, zeta):
    """Natural frequency from the peak time, wn = pi / (tp sqrt(1 - zeta^2)) (seed 000 eq 20).

    Parameters
    ----------
    tp : float or array_like
        Peak time in s.
    zeta : float or array_like
        Damping ratio (< 1).

    Returns
    -------
    float or numpy.ndarray
        Natural frequency in rad/s.
    """
    return math.pi / (np.asarray(tp, float) * np.sqrt(1.0 - np.asarray(zeta, float) ** 2))



def normalized_step(zeta: float, t) -> np.ndarray:
    """Exact unit step response of wn^2/(s^2 + 2 zeta wn s + wn^2) with wn = 1,
    for any zeta > 0 (under-, critically or over-damped).

    Parameters
    ----------
    zeta : float
        Damping ratio (> 0).
    t : array_like
        Times in units of 1/wn.

    Returns
    -------
    numpy.ndarray
        The response at ``t``.
    """
    t = np.asarray(t, float)
    if math.isclose(zeta, 1.0, rel_tol=1e-9):
        return 1.0 - (1.0 + t) * np.exp(-t)
    if zeta < 1.0:
        wd = math.sqrt(1.0 - zeta * zeta)
        return 1.0 - np.exp(-zeta * t) * np.sin(wd * t + math.acos(zeta)) / wd
    r = math.sqrt(zeta * zeta - 1.0)
    fast, slow = zeta + r, zeta - r            # pole magnitudes
    return 1.0 - (fast * np.exp(-slow * t) - slow * np.exp(-fast * t)) / (fast - slow)


def _normalized_crossing(zeta: float, level: float) -> float:
    """First time the normalised (wn = 1) response reaches ``level`` (0 < level < 1)."""
    # The response rises monotonically to its first peak (forever if zeta >= 1)
    # and stays above 1 for pi/wd after crossing it, so the first hi of this
    # 1.5x sequence that is past the level brackets only the first crossing.
    hi = 1.0
    while float(normalized_step(zeta, hi)) < level:
        hi *= 1.5
    lo = 0.0
    return brentq(lambda s: float(normalized_step(zeta, s)) - level, lo, hi, xtol=1e-14, rtol=1e-13)


@functools.lru_cache(maxsize=4096)
def _t3_t4(zeta: float) -> tuple[float, float]:
    return _normalized_crossing(zeta, Y3_LEVEL), _normalized_crossing(zeta, Y4_LEVEL)


def t4_t3_ratio(zeta: float) -> float:
    """t4/t3 of the exact response (seed 002 eq 9: 3 at zeta = 1); increasing in zeta.

    Parameters
    ----------
    zeta : float
        Damping ratio.

    Returns
    -------
    float
        t4/t3.
    """
    t3, t4 = _t3_t4(float(zeta))
    return t4 / t3


def t4_t3_table(zetas=(0.5, 0.6, 0.7, 0.8, 0.9, 0.95, 1.0, 1.05, 1.1, 1.2, 1.3, 1.4,
                       1.5, 1.6, 1.7, 1.8, 1.9, 2.0)):
    """Seed 002 Table 2, computed from the exact response rather than typed.

    Parameters
    ----------
    zetas : sequence of float, optional
        The damping ratios of the table's rows.


    Returns
    -------
    dict of arrays
        ``zeta``, ``t4_t3``, ``wn_t3`` and ``wn_t4``.
    """
    z = np.asarray(zetas, float)
    t3 = np.empty_like(z)
    t4 = np.empty_like(z)
    for i, zi in enumerate(z):
        t3[i], t4[i] = _t3_t4(float(zi))
    return {"zeta": z, "t4_t3": t4 / t3, "wn_t3": t3, "wn_t4": t4}


# the ratio is monotonic from 1.84 (zeta -> 0) to 5.26 (zeta -> infinity)
_ZETA_SEARCH = (0.02, 20.0)


def zeta_from_t4_t3(ratio: float) -> float:
    """Invert :func:`t4_t3_ratio` (nan outside what any second-order system gives).

    Parameters
    ----------
    ratio : float
        t4/t3.

    Returns
    -------
    float
        Damping ratio, or nan.
    """
    lo, hi = _ZETA_SEARCH
    f = lambda z: t4_t3_ratio(z) - ratio  # noqa: E731
    flo, fhi = f(lo), f(hi)
    if not (flo <= 0.0 <= fhi):
        return math.nan
    return brentq(f, lo, hi, xtol=1e-12, rtol=1e-12)


# --------------------------------------------------------------------------
# robust reading of the waveform
# --------------------------------------------------------------------------

def _refine_extreme(t, z, zs, idx_lo, idx_hi, sign, sigma):
    """Vertex of a parabola fitted around the extreme of the lobe
    ``z[idx_lo:idx_hi]`` (``sign`` +1 for a maximum, -1 for a minimum).

    Clean data: the parabola through the extreme sample and its two
    neighbours. Noisy data: the extreme of the smoothed ``zs`` locates the
    lobe's top, and a least-squares parabola runs through the raw samples of
    the top twentieth of the lobe (or one sigma, if more), which averages the
    noise out without bending the parabola far from the peak (the fraction
    was chosen on 1 % noise: wider windows bias the damped, asymmetric peak).
    Returns (time, value).
    """
    seg_s = sign * (zs[idx_lo:idx_hi] - 1.0)
    k = int(np.argmax(seg_s))
    height = float(seg_s[k])
    noisy = 8.0 * sigma > 1e-4 * max(height, 1e-12)
    if noisy:
        i = idx_lo + k
        j0, j1 = peak_region(sign * zs, i, max(sigma, 0.05 * height), lo=idx_lo, hi=idx_hi)
    else:
        i = idx_lo + int(np.argmax(sign * z[idx_lo:idx_hi]))
        j0, j1 = i - 1, i + 1
    if not 0 < i < len(z) - 1:
        return float(t[i]), float(z[i])
    tv, v, a = refine_peak(t, sign * z, i, lo=j0, hi=j1)
    if a < 0:
        return tv, sign * v
    return float(t[i]), float(zs[i] if noisy else z[i])


def extrema(t, z, sigma: float = 0.0, count: int = 3):
    """Alternating extrema of an oscillating normalised response about 1.

    Returns a list of ``(kind, time, value)`` with kind ``"max"``/``"min"``, the
    first being the first overshoot peak. Lobes are delimited by crossings of
    1 with hysteresis. On noisy records the crossings are looked for on a
    moving average (n/2000 samples wide, threshold 5 sigma of the average),
    so that a noise spike in a settled tail is not taken for an overshoot;
    each extremum is then refined on the raw samples.

    Parameters
    ----------
    t : array_like
        Times in s.
    z : array_like
        The response divided by its final value.
    sigma : float, optional
        Noise standard deviation of ``z`` (0: no smoothing).
    count : int, optional
        Most extrema returned.

    Returns
    -------
    list of tuple
        ``(kind, time, value)`` per extremum.
    """
    t = np.asarray(t, float)
    z = np.asarray(z, float)
    n = len(z)
    m = max(1, n // 2000) if sigma > 0.0 else 1
    zs = moving_average(z, m)
    h = max(5.0 * sigma / math.sqrt(m), 1e-12)
    d = zs - 1.0
    state = np.zeros(n, np.int8)
    state[d > h] = 1
    state[d < -h] = -1
    nz = state != 0
    if not nz.any():
        return []
    idx = np.where(nz, np.arange(n), 0)
    np.maximum.accumulate(idx, out=idx)
    filled = state[idx]
    filled[:int(np.argmax(nz))] = -1      # the response starts below its final value
    change = np.nonzero(np.diff(filled))[0] + 1
    bounds = np.concatenate(([0], change, [n]))
    out = []
    for a, b in zip(bounds[:-1], bounds[1:]):
        sgn = int(filled[a])
        if not out and sgn < 0:
            continue                       # the initial rise is not an extremum
        if b == n and a + int(np.argmax(sgn * zs[a:b])) >= n - 2:
            break                          # an unfinished last lobe: no interior extremum
        tm, v = _refine_extreme(t, z, zs, a, b, sgn, sigma)
        out.append(("max" if sgn > 0 else "min", tm, v))
        if len(out) >= count:
            break
    return out



# --------------------------------------------------------------------------
# the methods
# --------------------------------------------------------------------------

@guarded("overshoot", "underdamped")
def overshoot(t, y, yf, sigma=None) -> MethodResult:
    """Overshoot and peak time (seeds 000 eqs 20-23 and 003 eq 2.2.11).

    zeta = -ln Mp / sqrt(pi^2 + ln^2 Mp), wn = pi / (tp sqrt(1 - zeta^2)),
    Mp the first overshoot as a fraction of the final value, tp measured from
    the step. Valid for 0 < zeta < 1 with an overshoot above the noise and
    no dead time (a dead time adds to tp and lowers wn).

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
        The ``underdamped`` model, or an invalid result with the reason.
    """
    name, model = "overshoot", "underdamped"
    t, z, sigma, err = prepare(t, y, yf, sigma)
    if err:
        return fail(name, model, err, yf)
    ext = extrema(t, z, sigma, count=1)
    if not ext or ext[0][0] != "max":
        return fail(name, model, "no overshoot above the noise: valid only for "
                     "underdamped responses (0 < zeta < 1); use t4-t3 or two-pole", yf)
    _, tp, zp = ext[0]
    mp = zp - 1.0
    zeta = float(zeta_from_overshoot(mp))
    wn = float(wn_from_peak_time(tp, zeta))
    return flag_late(MethodResult(name, model, {"K": float(yf), "wn_rad_s": wn, "zeta": zeta,
                                                 "theta_s": 0.0},
                                   points={"tp_s": tp, "overshoot": mp, "peak": zp * yf},
                                   note="assumes no dead time (peak time measured from the step)"),
                      t, z, sigma)


@guarded("log-decrement", "underdamped")
def log_decrement(t, y, yf, sigma=None) -> MethodResult:
    """First and second overshoot and the period (seed 002 eqs 5-7), zeta <= 0.5.

    Seed 002 eq 5 has Y1/Y0 = e^{-zeta pi/sqrt(1-zeta^2)} and
    Y2/Y0 = e^{-2 zeta pi/sqrt(1-zeta^2)}: Y1 is the first overshoot above the
    final value and Y2 the next deviation from it, i.e. the depth of the first
    undershoot (the second peak above the final value would be e^{-3 ...}).
    zeta is the mean of |ln Y1|/sqrt(pi^2 + ln^2 Y1) and
    |ln Y2|/sqrt(4 pi^2 + ln^2 Y2) (eq 6; the seed's signs need the magnitude)
    and wn = 2 pi / (T sqrt(1 - zeta^2)) (eq 7), T the time between the first
    two peaks (twice the peak-to-trough time if the record shows one peak only).

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
        The ``underdamped`` model, or an invalid result with the reason.
    """
    name, model = "log-decrement", "underdamped"
    t, z, sigma, err = prepare(t, y, yf, sigma)
    if err:
        return fail(name, model, err, yf)
    ext = extrema(t, z, sigma, count=3)
    if len(ext) < 2 or ext[0][0] != "max" or ext[1][0] != "min":
        return fail(name, model, "needs a first overshoot and an undershoot above the noise: "
                     "valid for zeta <= 0.5", yf)
    (_, t1, z1), (_, tm, zm) = ext[0], ext[1]
    y1, y2 = z1 - 1.0, 1.0 - zm
    if y2 <= 0.0 or y1 <= 0.0 or y2 >= y1:
        return fail(name, model, "the undershoot is not smaller than the overshoot: not a "
                     "decaying second-order oscillation (valid for zeta <= 0.5)", yf)
    period = ext[2][1] - t1 if len(ext) >= 3 and ext[2][0] == "max" else 2.0 * (tm - t1)
    l1, l2 = abs(math.log(y1)), abs(math.log(y2))
    zeta1 = l1 / math.sqrt(math.pi ** 2 + l1 * l1)
    zeta2 = l2 / math.sqrt(4.0 * math.pi ** 2 + l2 * l2)
    zeta = 0.5 * (zeta1 + zeta2)
    wn = 2.0 * math.pi / (period * math.sqrt(1.0 - zeta * zeta))
    valid = zeta <= 0.5 + 1e-9
    note = "assumes no dead time" if valid else (
        f"zeta = {zeta:.3f} > 0.5: outside the method's range (zeta <= 0.5, seed 002); "
        "use t4-t3")
    return flag_late(MethodResult(name, model, {"K": float(yf), "wn_rad_s": wn, "zeta": zeta,
                                                 "theta_s": 0.0},
                                   valid=valid, note=note,
                                   points={"t1_s": t1, "y1": y1, "t_min_s": tm, "y2": y2,
                                           "period_s": period, "zeta_first": zeta1,
                                           "zeta_second": zeta2}),
                      t, z, sigma)


@guarded("t4-t3", "underdamped")
def t4_t3(t, y, yf, sigma=None) -> MethodResult:
    """Seed 002's t4/t3 method, 0.5 <= zeta <= 2.

    t3 and t4 are the times to 1 - 2/e = 26.4 % and 1 - 4/e^3 = 80.1 % of the
    final value; zeta solves t4/t3 = ratio(zeta) on the exact response (the
    seed's Table 2, recomputed), and wn = (wn t4)(zeta) / t4.

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
        The ``underdamped`` model, or an invalid result with the reason.
    """
    name = "t4-t3"
    t, z, sigma, err = prepare(t, y, yf, sigma)
    if err:
        return fail(name, "underdamped", err, yf)
    t3 = crossing_time(t, z, Y3_LEVEL, sigma=sigma)
    t4 = crossing_time(t, z, Y4_LEVEL, sigma=sigma)
    if not (math.isfinite(t3) and math.isfinite(t4)) or t3 <= 0.0 or t4 <= t3:
        return fail(name, "underdamped", "the response does not rise through 26.4 % and 80.1 % "
                     "of its final value after the step", yf)
    ratio = t4 / t3
    zeta = zeta_from_t4_t3(ratio)
    pts = {"t3_s": t3, "t4_s": t4, "t4_t3": ratio}
    if not math.isfinite(zeta):
        return fail(name, "underdamped", f"t4/t3 = {ratio:.3f} is outside what a second-order "
                     "system gives (1.84 to 5.26); dead time or higher order", yf, pts)
    wn = _t3_t4(zeta)[1] / t4
    model, params = second_order_params(float(yf), wn, zeta, 0.0)
    lo, hi = t4_t3_ratio(0.5), t4_t3_ratio(2.0)
    valid = 0.5 - 1e-9 <= zeta <= 2.0 + 1e-9
    note = "assumes no dead time"
    if not valid:
        note = (f"t4/t3 = {ratio:.3f} gives zeta = {zeta:.3f}, outside the method's range "
                f"0.5 <= zeta <= 2 (t4/t3 {lo:.3f} to {hi:.3f}); use "
                + ("log-decrement" if zeta < 0.5 else "two-pole"))
    return flag_late(MethodResult(name, model, params, valid=valid, note=note, points=pts),
                      t, z, sigma)



@guarded("chen", "underdamped")
def chen(t, y, yf, sigma=None) -> MethodResult:
    """Cheng-Liang Chen, underdamped with dead time (seed 000 eqs 24-30).

    From the first peak (t_p1, c_p1), the first minimum (t_m1, c_m1) and the
    second peak c_p2: Mp is the mean of the three successive decay ratios
    (eq 30), zeta from eq 26, tau = 1/wn = (t_m1 - t_p1) sqrt(1 - zeta^2)/pi
    (eq 27), theta = 2 t_p1 - t_m1 (eq 28). K is the measured final value;
    eq 29's estimate of it is reported in ``points``.

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
        The ``underdamped`` model with dead time, or an invalid result with the reason.
    """
    name, model = "chen", "underdamped"
    t, z, sigma, err = prepare(t, y, yf, sigma)
    if err:
        return fail(name, model, err, yf)
    ext = extrema(t, z, sigma, count=3)
    if len(ext) < 3 or [e[0] for e in ext] != ["max", "min", "max"]:
        return fail(name, model, "needs a first peak, a minimum and a second peak above the "
                     "noise: valid for clearly underdamped responses (zeta below about 0.6)", yf)
    (_, tp1, cp1), (_, tm1, cm1), (_, _tp2, cp2) = ext
    den = cp1 + cp2 - 2.0 * cm1
    y_inf = (cp1 * cp2 - cm1 * cm1) / den if den != 0.0 else math.nan
    r1, r2, r3 = cp1 - 1.0, (1.0 - cm1) / (cp1 - 1.0), (cp2 - 1.0) / (1.0 - cm1)
    mp = (r1 + r2 + r3) / 3.0
    pts = {"tp1_s": tp1, "tm1_s": tm1, "cp1": cp1 * yf, "cm1": cm1 * yf, "cp2": cp2 * yf,
           "y_inf_eq29": y_inf * yf, "mp": mp}
    if not 0.0 < mp < 1.0:
        return fail(name, model, f"decay ratio {mp:.3f} outside (0, 1): not an underdamped "
                     "second-order response", yf, pts)
    zeta = float(zeta_from_overshoot(mp))
    tau = (tm1 - tp1) * math.sqrt(1.0 - zeta * zeta) / math.pi
    theta = 2.0 * tp1 - tm1
    note = ""
    if theta < 0.0:
        # a sliver below zero is sampling/noise in the peak times: no remark
        if -theta > 0.02 * (tm1 - tp1):
            note = f"eq 28 gives a negative dead time ({theta:.3g} s), set to 0"
        theta = 0.0
    return MethodResult(name, model, {"K": float(yf), "wn_rad_s": 1.0 / tau, "zeta": zeta,
                                      "theta_s": theta}, note=note, points=pts)

