"""Second-order identification from a step response (seeds 000, 002 and 003).

Every method here has the signature ``method(t, y, yf, sigma=None) -> MethodResult``:

- ``t``  time since the step, seconds (t >= 0, increasing);
- ``y``  the response's deviation from its pre-step baseline divided by the
  input step amplitude (starts near 0, settles at ``yf``);
- ``yf`` its settled value, i.e. the static gain K;
- ``sigma`` the noise of ``y`` when the caller measured it (the spread of an
  averaged square wave's plateaus), else estimated here.

They work on the normalised response ``z = y / yf`` (0 -> 1), so a plant with a
negative gain is handled like a positive one. They never raise on data outside
their range: they return ``valid=False`` with a note naming the range and why.
``iae``/``ise`` are left nan (the orchestrator computes them against the data).

Methods (``STEP_METHODS``, in this order):

========================  =======================================================
``overshoot``             first overshoot and peak time (seed 000 eqs 20-23,
                          seed 003 eq 2.2.11); no dead time
``log-decrement``         first and second overshoot and the period
                          (seed 002 eqs 5-7), zeta <= 0.5
``t4-t3``                 times to 26.4 % and 80.1 % (seed 002 eqs 8-12, Table 2
                          computed here from the exact response), 0.5 <= zeta <= 2
``two-pole``              two real poles from two points above 50 %
                          (seed 002 eqs 16-20), zeta > 2
``chen``                  Cheng-Liang Chen, underdamped with dead time
                          (seed 000 eqs 24-30)
``stark-mollenkamp``      three points 15/45/75 % (seed 000 eqs 31-37)
``jahanmiri-fallahi``     three points 2 or 5/70/90 % (seed 000 eqs 38-42)
``peeling``               exponential peeling of two time constants on a
                          semilog plot (seed 003 section 2.3)
``dc-motor``              DC motor velocity, Km = W(inf)/a,
                          tau_m = -t0 / ln(1 - w(t0)/W(inf)) (seed 000 eqs 52-55)
``alfaro-123c-overdamped`` Alfaro's 123c overdamped second order with dead time,
                          25/50/75 % points (the method of seed 000's Table II
                          "Alfaro" row, extended to two poles)
``harriott``              Harriott (1964): tau1 + tau2 from the 73 % time, their
                          ratio from the response at half that sum (his chart,
                          computed here from the exact response)
========================  =======================================================

:func:`dc_motor_position` (an integrating, never-settling response) is not in
``STEP_METHODS`` because the step orchestrator needs a settled final value.

Overdamped results name the *fast* time constant ``tau1_s`` and the slow one
``tau2_s`` (tau1 <= tau2), as seed 003 (tau1 = 5, tau2 = 100) and seed 002
(p1 fast, p2 slow) do.

Crossing times are robust on noisy data: the samples within a few noise
standard deviations of the level are fitted with a straight line, which on
clean data reduces to linear interpolation between the two bracketing samples.
Peaks are the vertex of a parabola fitted around the extreme sample of each
lobe; lobes are delimited by crossings of the final value with hysteresis.
"""

from __future__ import annotations

import functools
import math

import numpy as np
from scipy.optimize import brentq

from ..core.waveform import crossing_time, moving_average, noise_sigma, peak_region, refine_peak
from .structures import MethodResult, iae_ise, model_step

__all__ = [
    "STEP_METHODS", "overshoot", "log_decrement", "t4_t3", "two_pole", "chen",
    "stark_mollenkamp", "jahanmiri_fallahi", "peeling", "dc_motor", "dc_motor_position",
    "alfaro_123c_overdamped", "harriott",
    "zeta_from_overshoot", "wn_from_peak_time", "dc_motor_velocity", "normalized_step",
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
    """Damping ratio from the fractional overshoot ``mp`` (0 < mp < 1), seed 000 eq 23 / 26."""
    lm = np.log(np.asarray(mp, float))
    return -lm / np.sqrt(math.pi ** 2 + lm * lm)


def wn_from_peak_time(tp, zeta):
    """Natural frequency from the peak time, wn = pi / (tp sqrt(1 - zeta^2)) (seed 000 eq 20)."""
    return math.pi / (np.asarray(tp, float) * np.sqrt(1.0 - np.asarray(zeta, float) ** 2))


def dc_motor_velocity(a, w_inf, t0, w_t0):
    """Seed 000 eqs 52 and 55: ``(Km, tau_m)`` from the step size ``a``, the final
    velocity ``w_inf`` and one transient sample ``w_t0`` at ``t0``."""
    km = w_inf / a
    tau = -t0 / math.log(1.0 - w_t0 / w_inf)
    return km, tau


def normalized_step(zeta: float, t) -> np.ndarray:
    """Exact unit step response of wn^2/(s^2 + 2 zeta wn s + wn^2) with wn = 1,
    for any zeta > 0 (under-, critically or over-damped)."""
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
    """t4/t3 of the exact response (seed 002 eq 9: 3 at zeta = 1); increasing in zeta."""
    t3, t4 = _t3_t4(float(zeta))
    return t4 / t3


def t4_t3_table(zetas=(0.5, 0.6, 0.7, 0.8, 0.9, 0.95, 1.0, 1.05, 1.1, 1.2, 1.3, 1.4,
                       1.5, 1.6, 1.7, 1.8, 1.9, 2.0)):
    """Seed 002 Table 2, computed from the exact response rather than typed.

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
    """Invert :func:`t4_t3_ratio` (nan outside what any second-order system gives)."""
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


def _prepare(t, y, yf, sigma=None):
    """Normalised arrays and noise (``sigma`` of ``y`` when given), or an error note."""
    t = np.asarray(t, float)
    y = np.asarray(y, float)
    if t.ndim != 1 or t.shape != y.shape or t.size < 5:
        return None, None, 0.0, "needs at least 5 samples of time and response"
    if not (math.isfinite(yf) and yf != 0.0):
        return None, None, 0.0, "the final value is zero or not finite"
    z = y / yf
    if not (np.all(np.isfinite(z)) and np.all(np.isfinite(t))):
        return None, None, 0.0, "the record has non-finite samples"
    return t, z, (noise_sigma(z) if sigma is None else sigma / abs(yf)), ""


def _nan_params(model):
    names = {"fopdt": ("K", "tau_s", "theta_s"), "double-pole": ("K", "tau_s", "theta_s"),
             "underdamped": ("K", "wn_rad_s", "zeta", "theta_s"),
             "overdamped": ("K", "tau1_s", "tau2_s", "theta_s")}[model]
    return {k: math.nan for k in names}


def _fail(name, model, note, yf=math.nan, points=None):
    p = _nan_params(model)
    p["K"] = float(yf) if yf is not None else math.nan
    return MethodResult(name, model, p, valid=False, note=note, points=points or {})


def _second_order_params(K, wn, zeta, theta):
    """(model, params) for a K wn^2 e^{-theta s}/(s^2 + 2 zeta wn s + wn^2):
    underdamped below zeta = 1, otherwise two real time constants."""
    if zeta < 1.0:
        return "underdamped", {"K": K, "wn_rad_s": wn, "zeta": zeta, "theta_s": theta}
    r = math.sqrt(zeta * zeta - 1.0)
    return "overdamped", {"K": K, "tau1_s": 1.0 / (wn * (zeta + r)),
                          "tau2_s": 1.0 / (wn * (zeta - r)), "theta_s": theta}


def _late_start(t, z, sigma, model, params):
    """For the methods that assume no dead time: how much later than the
    identified model the data leave zero (time to 5 %), or 0. A lag over a
    tenth of the time to 50 % means a dead time the method cannot represent."""
    t05 = crossing_time(t, z, 0.05, sigma=sigma)
    t50 = crossing_time(t, z, 0.5, sigma=sigma)
    if not (math.isfinite(t05) and math.isfinite(t50)) or t50 <= 0.0:
        return 0.0
    p = dict(params, K=1.0, theta_s=0.0)
    try:
        tm = np.linspace(0.0, 2.0 * t50, 4001)
        m05 = crossing_time(tm, model_step(model, p, tm), 0.05)
    except (ValueError, KeyError, ZeroDivisionError, OverflowError):
        return 0.0
    lag = t05 - m05 if math.isfinite(m05) else 0.0
    return lag if lag > 0.1 * t50 else 0.0


def _flag_late(result, t, z, sigma):
    """Mark a no-dead-time method's result invalid when the data start late
    (the dead time is then the first thing to tell, before any range note)."""
    if not all(math.isfinite(v) for v in result.params.values()):
        return result
    lag = _late_start(t, z, sigma, result.model, result.params)
    if lag > 0.0:
        result.valid = False
        result.note = (f"the data leave zero {lag:.3g} s later than this model: a dead time, "
                       "which this method assumes absent (use chen, stark-mollenkamp, "
                       "jahanmiri-fallahi or least-squares)")
    return result


_POSITIVE = ("tau_s", "tau1_s", "tau2_s", "wn_rad_s", "zeta")


def _guarded(name, model):
    """Decorator: run a method with numpy's warnings silenced (degenerate data
    give inf/nan, handled here), turn an arithmetic failure on degenerate data
    into valid=False, and likewise any non-finite or non-physical parameter
    of a "valid" result."""
    def wrap(method):
        @functools.wraps(method)
        def run(t, y, yf, *args, **kwargs):
            try:
                with np.errstate(all="ignore"):
                    r = method(t, y, yf, *args, **kwargs)
            except (ArithmeticError, ValueError, np.linalg.LinAlgError) as exc:
                return _fail(name, model, "the data do not have this method's shape "
                             f"({type(exc).__name__}: {exc})",
                             math.nan if name == "dc-motor-position" else yf)
            bad = [k for k, v in r.params.items()
                   if not math.isfinite(v) or (k in _POSITIVE and v <= 0.0)
                   or (k == "theta_s" and v < 0.0)]
            if r.valid and bad:
                r.valid = False
                r.note = "; ".join(x for x in (r.note, "degenerate result (" + ", ".join(bad)
                                              + " not a positive finite number): the data do "
                                              "not have this method's shape") if x)
            return r
        return run
    return wrap


# --------------------------------------------------------------------------
# the methods
# --------------------------------------------------------------------------

@_guarded("overshoot", "underdamped")
def overshoot(t, y, yf, sigma=None) -> MethodResult:
    """Overshoot and peak time (seeds 000 eqs 20-23 and 003 eq 2.2.11).

    zeta = -ln Mp / sqrt(pi^2 + ln^2 Mp), wn = pi / (tp sqrt(1 - zeta^2)),
    Mp the first overshoot as a fraction of the final value, tp measured from
    the step. Valid for 0 < zeta < 1 with an overshoot above the noise and
    no dead time (a dead time adds to tp and lowers wn).
    """
    name, model = "overshoot", "underdamped"
    t, z, sigma, err = _prepare(t, y, yf, sigma)
    if err:
        return _fail(name, model, err, yf)
    ext = extrema(t, z, sigma, count=1)
    if not ext or ext[0][0] != "max":
        return _fail(name, model, "no overshoot above the noise: valid only for "
                     "underdamped responses (0 < zeta < 1); use t4-t3 or two-pole", yf)
    _, tp, zp = ext[0]
    mp = zp - 1.0
    zeta = float(zeta_from_overshoot(mp))
    wn = float(wn_from_peak_time(tp, zeta))
    return _flag_late(MethodResult(name, model, {"K": float(yf), "wn_rad_s": wn, "zeta": zeta,
                                                 "theta_s": 0.0},
                                   points={"tp_s": tp, "overshoot": mp, "peak": zp * yf},
                                   note="assumes no dead time (peak time measured from the step)"),
                      t, z, sigma)


@_guarded("log-decrement", "underdamped")
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
    """
    name, model = "log-decrement", "underdamped"
    t, z, sigma, err = _prepare(t, y, yf, sigma)
    if err:
        return _fail(name, model, err, yf)
    ext = extrema(t, z, sigma, count=3)
    if len(ext) < 2 or ext[0][0] != "max" or ext[1][0] != "min":
        return _fail(name, model, "needs a first overshoot and an undershoot above the noise: "
                     "valid for zeta <= 0.5", yf)
    (_, t1, z1), (_, tm, zm) = ext[0], ext[1]
    y1, y2 = z1 - 1.0, 1.0 - zm
    if y2 <= 0.0 or y1 <= 0.0 or y2 >= y1:
        return _fail(name, model, "the undershoot is not smaller than the overshoot: not a "
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
    return _flag_late(MethodResult(name, model, {"K": float(yf), "wn_rad_s": wn, "zeta": zeta,
                                                 "theta_s": 0.0},
                                   valid=valid, note=note,
                                   points={"t1_s": t1, "y1": y1, "t_min_s": tm, "y2": y2,
                                           "period_s": period, "zeta_first": zeta1,
                                           "zeta_second": zeta2}),
                      t, z, sigma)


@_guarded("t4-t3", "underdamped")
def t4_t3(t, y, yf, sigma=None) -> MethodResult:
    """Seed 002's t4/t3 method, 0.5 <= zeta <= 2.

    t3 and t4 are the times to 1 - 2/e = 26.4 % and 1 - 4/e^3 = 80.1 % of the
    final value; zeta solves t4/t3 = ratio(zeta) on the exact response (the
    seed's Table 2, recomputed), and wn = (wn t4)(zeta) / t4.
    """
    name = "t4-t3"
    t, z, sigma, err = _prepare(t, y, yf, sigma)
    if err:
        return _fail(name, "underdamped", err, yf)
    t3 = crossing_time(t, z, Y3_LEVEL, sigma=sigma)
    t4 = crossing_time(t, z, Y4_LEVEL, sigma=sigma)
    if not (math.isfinite(t3) and math.isfinite(t4)) or t3 <= 0.0 or t4 <= t3:
        return _fail(name, "underdamped", "the response does not rise through 26.4 % and 80.1 % "
                     "of its final value after the step", yf)
    ratio = t4 / t3
    zeta = zeta_from_t4_t3(ratio)
    pts = {"t3_s": t3, "t4_s": t4, "t4_t3": ratio}
    if not math.isfinite(zeta):
        return _fail(name, "underdamped", f"t4/t3 = {ratio:.3f} is outside what a second-order "
                     "system gives (1.84 to 5.26); dead time or higher order", yf, pts)
    wn = _t3_t4(zeta)[1] / t4
    model, params = _second_order_params(float(yf), wn, zeta, 0.0)
    lo, hi = t4_t3_ratio(0.5), t4_t3_ratio(2.0)
    valid = 0.5 - 1e-9 <= zeta <= 2.0 + 1e-9
    note = "assumes no dead time"
    if not valid:
        note = (f"t4/t3 = {ratio:.3f} gives zeta = {zeta:.3f}, outside the method's range "
                f"0.5 <= zeta <= 2 (t4/t3 {lo:.3f} to {hi:.3f}); use "
                + ("log-decrement" if zeta < 0.5 else "two-pole"))
    return _flag_late(MethodResult(name, model, params, valid=valid, note=note, points=pts),
                      t, z, sigma)


@_guarded("two-pole", "overdamped")
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
    """
    name, model = "two-pole", "overdamped"
    t, z, sigma, err = _prepare(t, y, yf, sigma)
    if err:
        return _fail(name, model, err, yf)
    ta = crossing_time(t, z, levels[0], sigma=sigma)
    tb = crossing_time(t, z, levels[1], sigma=sigma)
    if not (math.isfinite(ta) and math.isfinite(tb)) or tb <= ta:
        return _fail(name, model, f"the response does not rise through {levels[0]:.0%} and "
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
        return _fail(name, model, "the late response is not the tail of two real poles "
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
    return _flag_late(MethodResult(name, model, params, valid=valid, note=note, points=pts),
                      t, z, sigma)


@_guarded("chen", "underdamped")
def chen(t, y, yf, sigma=None) -> MethodResult:
    """Cheng-Liang Chen, underdamped with dead time (seed 000 eqs 24-30).

    From the first peak (t_p1, c_p1), the first minimum (t_m1, c_m1) and the
    second peak c_p2: Mp is the mean of the three successive decay ratios
    (eq 30), zeta from eq 26, tau = 1/wn = (t_m1 - t_p1) sqrt(1 - zeta^2)/pi
    (eq 27), theta = 2 t_p1 - t_m1 (eq 28). K is the measured final value;
    eq 29's estimate of it is reported in ``points``.
    """
    name, model = "chen", "underdamped"
    t, z, sigma, err = _prepare(t, y, yf, sigma)
    if err:
        return _fail(name, model, err, yf)
    ext = extrema(t, z, sigma, count=3)
    if len(ext) < 3 or [e[0] for e in ext] != ["max", "min", "max"]:
        return _fail(name, model, "needs a first peak, a minimum and a second peak above the "
                     "noise: valid for clearly underdamped responses (zeta below about 0.6)", yf)
    (_, tp1, cp1), (_, tm1, cm1), (_, _tp2, cp2) = ext
    den = cp1 + cp2 - 2.0 * cm1
    y_inf = (cp1 * cp2 - cm1 * cm1) / den if den != 0.0 else math.nan
    r1, r2, r3 = cp1 - 1.0, (1.0 - cm1) / (cp1 - 1.0), (cp2 - 1.0) / (1.0 - cm1)
    mp = (r1 + r2 + r3) / 3.0
    pts = {"tp1_s": tp1, "tm1_s": tm1, "cp1": cp1 * yf, "cm1": cm1 * yf, "cp2": cp2 * yf,
           "y_inf_eq29": y_inf * yf, "mp": mp}
    if not 0.0 < mp < 1.0:
        return _fail(name, model, f"decay ratio {mp:.3f} outside (0, 1): not an underdamped "
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


# Stark-Mollenkamp's correlations reproduce the exact response within 3 % in
# zeta and wn over this range (checked against the exact response in the tests).
STARK_RANGE = (0.45, 1.3)


@_guarded("stark-mollenkamp", "underdamped")
def stark_mollenkamp(t, y, yf, sigma=None) -> MethodResult:
    """Stark-Mollenkamp three points 15/45/75 % (seed 000 eqs 31-37).

    x = (t45 - t15)/(t75 - t15); zeta = (0.0805 - 5.547 (0.475 - x)^2)/(x - 0.356);
    wn = f2(zeta)/(t75 - t15) with f2 = 0.708 (2.811)^zeta (zeta < 1) or
    2.6 zeta - 0.6; theta = t45 - f3(zeta)/wn with f3 = 0.922 (1.66)^zeta.
    An empirical correlation: within 3 % for 0.45 <= zeta <= 1.3.
    """
    name = "stark-mollenkamp"
    t, z, sigma, err = _prepare(t, y, yf, sigma)
    if err:
        return _fail(name, "underdamped", err, yf)
    t15, t45, t75 = (crossing_time(t, z, p, sigma=sigma) for p in (0.15, 0.45, 0.75))
    if not all(math.isfinite(v) for v in (t15, t45, t75)) or not t15 < t45 < t75:
        return _fail(name, "underdamped", "the response does not rise through 15, 45 and 75 % "
                     "of its final value", yf)
    x = (t45 - t15) / (t75 - t15)
    pts = {"t15_s": t15, "t45_s": t45, "t75_s": t75, "x": x}
    num = 0.0805 - 5.547 * (0.475 - x) ** 2
    if x <= 0.356 or num <= 0.0:
        return _fail(name, "underdamped", f"x = {x:.4f}: eq 32 needs x > 0.356 and gives no "
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
    model, params = _second_order_params(float(yf), wn, zeta, theta)
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


@_guarded("jahanmiri-fallahi", "overdamped")
def jahanmiri_fallahi(t, y, yf, sigma=None) -> MethodResult:
    """Jahanmiri-Fallahi three points (seed 000 eqs 38-42).

    theta = t2 or t5 (whichever model has the smaller IAE against the data,
    eq 38), eta = (t90 - t70)/(t90 - theta),
    zeta = sqrt((0.4844651 - 0.75323499 eta)/(1 - 2.0946444 eta)) for
    eta <= 0.4771, else 13.9352 (the seed prints >= twice),
    tau = (t90 - theta)/(0.424301 + 4.62533 zeta - 2.65412 e^{-zeta}).
    The correlation yields zeta >= 0.696 only: for more oscillatory responses
    it is flagged invalid.
    """
    name = "jahanmiri-fallahi"
    t, z, sigma, err = _prepare(t, y, yf, sigma)
    if err:
        return _fail(name, "overdamped", err, yf)
    t2, t5, t70, t90 = (crossing_time(t, z, p, sigma=sigma) for p in (0.02, 0.05, 0.70, 0.90))
    if not all(math.isfinite(v) for v in (t2, t5, t70, t90)) or not t5 < t70 < t90:
        return _fail(name, "overdamped", "the response does not rise through 2/5, 70 and 90 % "
                     "of its final value", yf)
    best = None
    for label, theta in (("t2", t2), ("t5", t5)):
        eta, zeta, tau = _jf_from(theta, t70, t90)
        model, params = _second_order_params(float(yf), 1.0 / tau, zeta, theta)
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


@_guarded("peeling", "overdamped")
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
    """
    name, model = "peeling", "overdamped"
    t, z, sigma, err = _prepare(t, y, yf, sigma)
    if err:
        return _fail(name, model, err, yf)
    if float(np.max(z)) > 1.0 + max(5.0 * sigma, 1e-3):
        return _fail(name, model, "the response overshoots: two real time constants "
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
        return _fail(name, model, "too few samples in the tail (1 - y/yf between "
                     f"{r_lo:.3g} and 0.35) to fit the slow exponential", yf)
    ts = t[slow_sel]
    k1, tau1 = 0.0, math.nan
    k2, tau2 = _logfit(ts, r[slow_sel])
    if not math.isfinite(tau2):
        return _fail(name, model, "the tail of 1 - y/yf does not decay", yf)
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
        return _fail(name, model, "no fast exponential above the noise to peel: the response "
                     "is first order (use a FOPDT method)", yf, pts)
    if k1 <= 0.0:
        return _fail(name, model, "the fast exponential has the sign of a sum of lags "
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


@_guarded("dc-motor", "fopdt")
def dc_motor(t, y, yf, sigma=None) -> MethodResult:
    """DC motor velocity from a step of armature voltage (seed 000 eqs 46-55).

    Km = W(inf)/a is the final value of the normalised response, and
    tau_m = -t0 / ln(1 - w(t0)/W(inf)); the seed uses one point t0, here the
    median over every sample between 20 % and 80 % (robust to noise; on a
    clean first-order response every sample gives the same value). Valid for
    a delay-free first-order lag: the spread of those estimates says whether
    the data are one.
    """
    name, model = "dc-motor", "fopdt"
    t, z, sigma, err = _prepare(t, y, yf, sigma)
    if err:
        return _fail(name, model, err, yf)
    sel = (z >= 0.2) & (z <= 0.8) & (t > 0.0)
    # only the first rise: a later return into the band (oscillation) is not first order
    if sel.any():
        first_out = np.nonzero((z > 0.8) & (t > 0.0))[0]
        if first_out.size:
            sel[first_out[0]:] = False
    if sel.sum() < 2:
        return _fail(name, model, "too few samples between 20 % and 80 % of the final value", yf)
    taus = -t[sel] / np.log(1.0 - z[sel])
    tau = float(np.median(taus))
    q10, q90 = np.percentile(taus, [10, 90])
    spread = float((q90 - q10) / tau)
    t0 = crossing_time(t, z, 1.0 - math.exp(-1.0), sigma=sigma)
    pts = {"t0_s": t0, "w_t0": (1.0 - math.exp(-1.0)) * yf, "tau_spread": spread}
    valid = bool(spread <= 0.1)
    note = ("" if valid else f"tau_m from the 20-80 % samples varies by {spread:.0%}: not a "
            "delay-free first-order lag (the method's model)")
    # (a dead time already shows as the spread: no separate late-start check)
    return MethodResult(name, model, {"K": float(yf), "tau_s": tau, "theta_s": 0.0},
                        valid=valid, note=note, points=pts)


@_guarded("dc-motor-position", "fopdt")
def dc_motor_position(t, theta, a: float = 1.0, tail: float = 0.3) -> MethodResult:
    """DC motor from its shaft *position* step response (seed 000 eq 45/57).

    theta(t) = a Km (t - tau_m (1 - e^{-t/tau_m})) tends to the line
    a Km (t - tau_m): a straight-line fit to the last ``tail`` fraction of the
    record gives Km = slope/a and tau_m = -intercept/slope. The result is
    reported as the velocity model W/U = Km/(tau_m s + 1) (``fopdt`` with no
    dead time); the position model is Km/(s (tau_m s + 1)).
    """
    name, model = "dc-motor-position", "fopdt"
    t = np.asarray(t, float)
    th = np.asarray(theta, float) / a
    n = len(t)
    if n < 10 or not (np.all(np.isfinite(t)) and np.all(np.isfinite(th))):
        return _fail(name, model, "needs at least 10 finite samples", math.nan)
    k0 = int(n * (1.0 - tail))
    slope, icpt = np.polyfit(t[k0:], th[k0:], 1)
    if slope == 0.0:
        return _fail(name, model, "the position does not ramp: not an integrating response", 0.0)
    tau = -icpt / slope
    # the asymptote is reached only if the fitted tail starts several tau_m after the step
    valid = tau > 0.0 and t[k0] >= 5.0 * tau
    note = "velocity model W/U = K/(tau s + 1); position Theta/U = K/(s (tau s + 1))"
    if not valid:
        note = ("the record is too short: the ramp's tail must start 5 tau_m after the step "
                "(or tau_m <= 0: not a motor position response); " + note)
    return MethodResult(name, model, {"K": float(slope), "tau_s": float(tau), "theta_s": 0.0},
                        valid=valid, note=note, points={"tail_from_s": float(t[k0])})


# --------------------------------------------------------------------------
# Alfaro 123c (overdamped) and Harriott
# --------------------------------------------------------------------------

@_guarded("alfaro-123c-overdamped", "overdamped")
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
    """
    name, model = "alfaro-123c-overdamped", "overdamped"
    t, z, sigma, err = _prepare(t, y, yf, sigma)
    if err:
        return _fail(name, model, err, yf)
    t25, t50, t75 = (crossing_time(t, z, p, sigma=sigma) for p in (0.25, 0.5, 0.75))
    if not all(math.isfinite(v) for v in (t25, t50, t75)) or not t25 < t50 < t75:
        return _fail(name, model, "the response does not rise through 25, 50 and 75 % of its "
                     "final value", yf)
    pts = {"t25_s": t25, "t50_s": t50, "t75_s": t75}
    den = 0.3533 * t25 - 0.7036 * t50 + 0.3503 * t75
    a = (-0.6240 * t25 + 0.9866 * t50 - 0.3626 * t75) / den
    pts["a"] = a
    if not 0.0 <= a <= 1.0:
        return _fail(name, model, f"a = {a:.3f} outside 0 <= a <= 1: " + (
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


@_guarded("harriott", "overdamped")
def harriott(t, y, yf, sigma=None) -> MethodResult:
    """Harriott's method for two real poles without dead time (P. Harriott,
    Process Control, McGraw-Hill 1964; in most process-control texts).

    tau1 + tau2 = t73 / 1.3, the time to 73 % divided by 1.3; the response at
    half that sum, y(0.5 (tau1 + tau2)) / yf, gives tau1 / (tau1 + tau2) from
    Harriott's chart, computed here from the exact two-pole response (0.393 for
    one pole down to 0.264 for a double pole). Valid for responses inside the
    chart and without dead time.
    """
    name, model = "harriott", "overdamped"
    t, z, sigma, err = _prepare(t, y, yf, sigma)
    if err:
        return _fail(name, model, err, yf)
    t73 = crossing_time(t, z, 0.73, sigma=sigma)
    if not (math.isfinite(t73) and t73 > 0.0):
        return _fail(name, model, "the response does not reach 73 % of its final value", yf)
    total = t73 / HARRIOTT_73
    th = 0.5 * total
    zh = float(np.interp(th, t, z))
    pts = {"t73_s": t73, "tau_sum_s": total, "y_half": zh}
    r, h = _harriott_chart()
    if not h[-1] - 0.01 <= zh <= h[0] + 0.01:
        return _fail(name, model, f"y((tau1 + tau2)/2) = {zh:.3f} is outside Harriott's chart "
                     f"({h[-1]:.3f} to {h[0]:.3f}): a dead time or not two real poles", yf, pts)
    ratio = float(np.interp(zh, h[::-1], r[::-1]))
    pts["tau1_fraction"] = ratio
    params = {"K": float(yf), "tau1_s": max(ratio * total, 1e-300),
              "tau2_s": (1.0 - ratio) * total, "theta_s": 0.0}
    valid = float(np.max(z)) <= 1.0 + max(4.0 * sigma, 0.02)
    note = "assumes no dead time" if valid else "the response overshoots: two real poles cannot"
    return _flag_late(MethodResult(name, model, params, valid=valid, note=note, points=pts),
                      t, z, sigma)


STEP_METHODS = [overshoot, log_decrement, t4_t3, two_pole, chen, stark_mollenkamp,
                jahanmiri_fallahi, peeling, dc_motor, alfaro_123c_overdamped, harriott]
