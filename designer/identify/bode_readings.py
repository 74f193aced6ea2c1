"""Model responses and classical readings of a measured frequency response (seed 000 section 5, seed 003 section 3.1).

Input is a validated table, :class:`~designer.identify.io.freqtable.FreqData` (read
by :func:`designer.identify.io.read_freq_table`).

Model responses: :func:`model_response` (complex G(j w) of each model of
:data:`PARAMS`), :func:`model_phase` (its unwrapped phase), :func:`fit_error`
and :func:`dead_time_from_phase`; the least-squares fits (:mod:`.freqfit`)
and the reports use them too.

Methods (both return :class:`~designer.identify.structures.MethodResult`):

``asymptotes``     low-frequency gain K, the high-frequency slope -20 n dB/decade
                   (order n), and the corner where the gain has fallen by
                   3.01 n dB (seed 000 examples 1-3 and 6; seed 003 Table 3.1):
                   n = 1 -> ``fopdt`` tau = 1/wc; n = 2 -> ``double-pole``
                   tau = 1/wc (zeta = 1, the seed's reading of Table IV).
``resonant-peak``  zeta from the peak height -10 log(4 zeta^2 (1 - zeta^2)) at
                   wn sqrt(1 - 2 zeta^2) (seed 000 eq 79) -> ``underdamped``;
                   the seed's quicker -20 log(2 zeta)-at-wn reading (eq 75)
                   is in ``points``.

Every method with phase data also reads a dead time from the phase: the
median over the points above a tenth of the corner of
(phase_model_without_delay - phase_data)/w (seed 000 example 2), never
negative.

Fit error (:func:`fit_error`). The step methods' ``iae``/``ise`` (integrals over
time) have no meaning here; in their place, with e_k = |G_model(j w_k)/G_data(j w_k) - 1|
the relative complex error at each tabulated frequency (gain only when the
table has no phase),

- ``iae`` = mean over the points of e_k (dimensionless; 0.01 = 1 %),
- ``ise`` = mean over the points of e_k^2.

:func:`designer.identify.frequency.identify_freq` runs these readings with the
fits and ranks them.

"""

from __future__ import annotations

import math

import numpy as np

from ..core.waveform import parabola_vertex
from .io import FreqData
from .structures import MethodResult

__all__ = ["asymptotes", "low_frequency_slope", "model_phase", "model_response", "peak_gain_db", "resonant_peak",
           "zeta_from_peak"]

DB_PER_POLE = 10.0 * math.log10(2.0)

PARAMS = {
    "fopdt": ("K", "tau_s", "theta_s"),
    "double-pole": ("K", "tau_s", "theta_s"),
    "underdamped": ("K", "wn_rad_s", "zeta", "theta_s"),
    "overdamped": ("K", "tau1_s", "tau2_s", "theta_s"),
}


# --------------------------------------------------------------------------
# model responses
# --------------------------------------------------------------------------

def model_response(model: str, params: dict, w) -> np.ndarray:
    """Complex G(j w) of ``model`` (same parameters as core.model_step).

    Parameters
    ----------
    model : str
        ``fopdt``, ``double-pole``, ``underdamped`` or ``overdamped``.
    params : dict
        The model's parameters: ``K`` and its time constants or ``wn_rad_s`` and
        ``zeta``, optional ``theta_s``.
    w : array_like
        Angular frequencies in rad/s.

    Returns
    -------
    numpy.ndarray
        Complex G(j w) at each ``w``.
    """
    w = np.asarray(w, float)
    s = 1j * w
    K = params["K"]
    delay = np.exp(-s * (params.get("theta_s", 0.0) or 0.0))
    if model == "fopdt":
        g = 1.0 / (1.0 + s * params["tau_s"])
    elif model == "double-pole":
        g = 1.0 / (1.0 + s * params["tau_s"]) ** 2
    elif model == "underdamped":
        wn, z = params["wn_rad_s"], params["zeta"]
        g = wn * wn / (wn * wn + 2.0 * z * wn * s + s * s)
    elif model == "overdamped":
        g = 1.0 / ((1.0 + s * params["tau1_s"]) * (1.0 + s * params["tau2_s"]))
    else:
        raise ValueError(f"unknown model {model!r}")
    return K * g * delay


def model_phase(model: str, params: dict, w, with_delay: bool = True) -> np.ndarray:
    """Continuous (unwrapped) phase in radians of ``model`` for K > 0.

    Parameters
    ----------
    model : str
        ``fopdt``, ``double-pole``, ``underdamped`` or ``overdamped``.
    params : dict
        The model's parameters (``tau_s``, ``wn_rad_s``/``zeta``, ``tau1_s``/``tau2_s``,
        optional ``theta_s``).
    w : array_like
        Angular frequencies in rad/s.
    with_delay : bool, optional
        Include the dead time's phase -w theta.

    Returns
    -------
    numpy.ndarray
        Phase in radians at each ``w``.
    """
    w = np.asarray(w, float)
    if model == "fopdt":
        ph = -np.arctan(w * params["tau_s"])
    elif model == "double-pole":
        ph = -2.0 * np.arctan(w * params["tau_s"])
    elif model == "underdamped":
        wn, z = params["wn_rad_s"], params["zeta"]
        ph = -np.arctan2(2.0 * z * wn * w, wn * wn - w * w)
    elif model == "overdamped":
        ph = -np.arctan(w * params["tau1_s"]) - np.arctan(w * params["tau2_s"])
    else:
        raise ValueError(f"unknown model {model!r}")
    if with_delay:
        ph = ph - w * (params.get("theta_s", 0.0) or 0.0)
    return ph


def fit_error(model: str, params: dict, data: FreqData) -> tuple[float, float]:
    """(iae, ise) replacement: mean of e and of e^2, e = |G_model/G_data - 1|."""
    p = dict(params)
    p["K"] = abs(p["K"])
    if data.phase is not None:
        gm = np.abs(model_response(model, p, data.w))
        ratio = gm / data.gain * np.exp(1j * (model_phase(model, p, data.w) - data.phase))
        e = np.abs(ratio - 1.0)
    else:
        e = np.abs(np.abs(model_response(model, p, data.w)) / data.gain - 1.0)
    return float(np.mean(e)), float(np.mean(e * e))


def dead_time_from_phase(w, phase_data, phase_model, w_min: float = 0.0) -> float:
    """Dead time from the phase lag the model (without delay) does not explain:
    median of (phase_model - phase_data)/w over ``w >= w_min``, clipped at 0."""
    w = np.asarray(w, float)
    sel = w >= w_min
    if not sel.any():
        return 0.0
    th = (np.asarray(phase_model)[sel] - np.asarray(phase_data)[sel]) / w[sel]
    return max(0.0, float(np.median(th)))


# --------------------------------------------------------------------------
# classical readings
# --------------------------------------------------------------------------

def interp_logf(w, y, level):
    """First w (interpolated in log w) where the decreasing y falls to ``level``."""
    below = np.nonzero(y <= level)[0]
    if below.size == 0:
        return math.nan
    i = int(below[0])
    if i == 0:
        return float(w[0])
    y0, y1 = y[i - 1], y[i]
    frac = 0.0 if y1 == y0 else (level - y0) / (y1 - y0)
    return float(10.0 ** (math.log10(w[i - 1]) + frac * (math.log10(w[i]) - math.log10(w[i - 1]))))


def low_frequency_gain(data: FreqData, tol_db: float = 0.05, span: float = 3.0):
    """K (amplitude ratio) from the lowest frequencies: the mean dB of the points
    within ``span`` times the lowest frequency that stay within ``tol_db`` of
    the first one (the table must start well below the corner, as the seeds'
    do). Returns (K, points used)."""
    db = data.gain_db
    run = 1
    while (run < db.size and data.w[run] <= span * data.w[0]
           and abs(db[run] - db[0]) <= tol_db):
        run += 1
    return float(10.0 ** (np.mean(db[:run]) / 20.0)), run


def low_frequency_slope(data: FreqData) -> float:
    """Slope in dB/decade of the lowest decade of the table: the least-squares
    line through every point up to ten times the lowest frequency (at least the
    three lowest), so one noisy point does not decide it (two points did: a
    0.25 dB error in the second of 151 read a flat first-order table as falling).

    Parameters
    ----------
    data : FreqData
        The frequency-response table.

    Returns
    -------
    float
        Slope of the gain in dB/decade (0 when the points span no frequency).
    """
    lw = np.log10(data.w)
    n = max(3, int(np.searchsorted(lw, lw[0] + 1.0, "right")))
    x, y = lw[:n], data.gain_db[:n]
    if x[-1] - x[0] <= 0:
        return 0.0
    return float(np.polyfit(x - x[0], y, 1)[0])


def high_frequency_slope(data: FreqData, k_db: float, drop_db: float = 10.0):
    """Slope in dB/decade of the high-frequency asymptote: a line through the
    points at least ``drop_db`` below K (at least the last two points)."""
    db = data.gain_db
    lw = np.log10(data.w)
    sel = np.nonzero(db <= k_db - drop_db)[0]
    if sel.size < 2:
        sel = np.arange(db.size - 2, db.size)
    slope = float(np.polyfit(lw[sel], db[sel], 1)[0])
    return slope, sel


def _with_delay(name, model, params, data, w_corner, points, note=""):
    """Add the dead time read from the phase, and the fit error."""
    if data.phase is not None:
        ph0 = model_phase(model, params, data.w, with_delay=False)
        params["theta_s"] = dead_time_from_phase(data.w, data.phase, ph0, 0.1 * w_corner)
    else:
        params["theta_s"] = 0.0
        note = "; ".join(s for s in (note, "no phase in the table: dead time not identified") if s)
    params["K"] = data.sign * abs(params["K"])
    iae, ise = fit_error(model, params, data)
    return MethodResult(name, model, params, iae, ise, True, note, points)


def invalid_result(name, model, note, points=None):
    return MethodResult(name, model, {k: math.nan for k in PARAMS[model]}, valid=False,
                        note=note, points=points or {})


def asymptotes(data: FreqData) -> MethodResult:
    """Asymptote reading (seed 000 examples 1-3, 6; seed 003 Table 3.1).

    K from the flat low-frequency gain, order n from the high-frequency slope
    (-20 n dB/decade, rounded), corner wc where the gain has fallen
    n 10 log10(2) = 3.01 n dB below K (the seed's "3 dB x n" rule: the
    asymptotes of n equal real poles meet there). n = 1: fopdt with
    tau = 1/wc; n = 2: double pole tau = 1/wc
    (zeta = 1). The intersection of the fitted high-frequency line with K
    is reported in ``points`` as ``w_intersection_rad_s``.

    Parameters
    ----------
    data : FreqData
        The frequency-response table.

    Returns
    -------
    MethodResult
        The ``fopdt`` or ``double-pole`` model read (invalid, with the reason,
        when the table allows no reading).
    """
    name = "asymptotes"
    lf = low_frequency_slope(data)
    if lf < -10.0:
        return invalid_result(name, "fopdt", f"the gain already falls {-lf:.0f} dB/decade at the "
                        "lowest frequencies: a pole at the origin (integrator, seed 000 "
                        "examples 3-4) or a table that starts above the corner; the models "
                        "here need a flat low-frequency gain", {"lf_slope_db_dec": lf})
    K, run = low_frequency_gain(data)
    k_db = 20.0 * math.log10(K)
    slope, sel = high_frequency_slope(data, k_db)
    n = int(round(-slope / 20.0))
    pts = {"K_points": run, "hf_slope_db_dec": slope, "order": n}
    if n < 1:
        return invalid_result(name, "fopdt", f"the gain does not roll off (high-frequency slope "
                        f"{slope:.1f} dB/decade): no low-pass model to read", pts)
    # n equal poles are 10 log10(2) = 3.01 dB down per pole at their corner
    wc = interp_logf(data.w, data.gain_db, k_db - DB_PER_POLE * n)
    # where the -20 n dB/decade line through the high-frequency points meets K
    b = float(np.mean(data.gain_db[sel] + 20.0 * n * np.log10(data.w[sel])))
    pts["w_intersection_rad_s"] = 10.0 ** ((b - k_db) / (20.0 * n))
    if not math.isfinite(wc):
        return invalid_result(name, "fopdt" if n == 1 else "double-pole",
                        f"the gain never falls {DB_PER_POLE * n:.1f} dB below K in the table: "
                        "extend it to higher frequencies", pts)
    pts["wc_rad_s"] = wc
    pts["fc_hz"] = wc / (2.0 * math.pi)
    if n > 2:
        if data.phase is not None:
            ph0 = -n * np.arctan(data.w / wc)
            pts["theta_s"] = dead_time_from_phase(data.w, data.phase, ph0, 0.1 * wc)
        return invalid_result(name, "double-pole", f"high-frequency slope {slope:.0f} dB/decade means "
                        f"order {n}; the models here have at most two poles (the seed's "
                        f"reading: {n} equal poles at {wc:.4g} rad/s"
                        + (f", dead time {pts['theta_s']:.4g} s" if "theta_s" in pts else "")
                        + ")", pts)
    model = "fopdt" if n == 1 else "double-pole"
    return _with_delay(name, model, {"K": K, "tau_s": 1.0 / wc, "theta_s": 0.0}, data, wc, pts,
                       "" if n == 1 else "two equal poles (zeta = 1)")


def zeta_from_peak(mr_db: float) -> float:
    """Damping ratio from the resonant peak height above K in dB (seed 000 eq 79),
    the root below 1/sqrt(2); nan if ``mr_db`` <= 0.

    Parameters
    ----------
    mr_db : float
        Peak height above the DC gain in dB.

    Returns
    -------
    float
        Damping ratio, or nan.
    """
    if not mr_db > 0.0:
        return math.nan
    q = 10.0 ** (-mr_db / 10.0)            # = 4 zeta^2 (1 - zeta^2)
    # 1 - sqrt(1 - q) written as q / (1 + sqrt(1 - q)): no cancellation, so a
    # tall peak gives a small zeta, never exactly 0 (G would then divide by 0)
    return math.sqrt(q / (2.0 * (1.0 + math.sqrt(max(0.0, 1.0 - q)))))


def peak_gain_db(zeta: float) -> float:
    """Seed 000 eq 79: -10 log(4 zeta^2 (1 - zeta^2)), for zeta < 1/sqrt(2).

    Parameters
    ----------
    zeta : float
        Damping ratio, below 1/sqrt(2).

    Returns
    -------
    float
        Height of the resonant peak above the DC gain in dB.
    """
    return -10.0 * math.log10(4.0 * zeta * zeta * (1.0 - zeta * zeta))


def resonant_peak(data: FreqData, min_db: float = 0.1) -> MethodResult:
    """Resonant-peak damping (seed 000 example 5, eqs 75 and 79).

    The peak (the vertex of 1/|G|^2 as a parabola in w^2 through the highest
    point and its neighbours, exact for a second-order system) gives
    Mr = peak - K in dB; zeta solves
    -10 log(4 zeta^2 (1 - zeta^2)) = Mr and wn = w_peak / sqrt(1 - 2 zeta^2).
    Valid when the table shows a peak at least ``min_db`` above K between its
    first and last points (zeta < 0.707).

    Parameters
    ----------
    data : FreqData
        The frequency-response table.
    min_db : float, optional
        Smallest peak height above K (dB) that counts as a peak.

    Returns
    -------
    MethodResult
        The ``underdamped`` model read (invalid, with the reason, when the
        table shows no peak).
    """
    name, model = "resonant-peak", "underdamped"
    lf = low_frequency_slope(data)
    if lf < -10.0:
        return invalid_result(name, model, f"the gain already falls {-lf:.0f} dB/decade at the "
                        "lowest frequencies: no flat low-frequency gain to measure the peak "
                        "against", {"lf_slope_db_dec": lf})
    K, _ = low_frequency_gain(data)
    k_db = 20.0 * math.log10(K)
    db = data.gain_db
    i = int(np.argmax(db))
    if db[i] - k_db < min_db or i == 0 or i == db.size - 1:
        return invalid_result(name, model, f"no resonant peak {min_db} dB above the low-frequency gain "
                        "inside the table: zeta >= 0.707 or the peak was not measured")
    # For a second-order system (K/|G|)^2 = (1 - u^2)^2 + 4 zeta^2 u^2 is a
    # quadratic in w^2: a parabola through the three points around the highest
    # one has its vertex exactly at the peak.
    v = data.w[i - 1:i + 2] ** 2
    q = 1.0 / data.gain[i - 1:i + 2] ** 2
    vc = v[1]
    xv, qmin, a = parabola_vertex(v / vc - 1.0, q)
    if a > 0 and -1.0 < xv < 3.0 and qmin > 0:
        peak_db, w_peak = -10.0 * math.log10(qmin), math.sqrt(vc * (1.0 + xv))
    else:
        peak_db, w_peak = float(db[i]), float(data.w[i])
    mr = peak_db - k_db
    zeta = zeta_from_peak(mr)
    wn = w_peak / math.sqrt(1.0 - 2.0 * zeta * zeta)
    pts = {"w_peak_rad_s": w_peak, "peak_db": peak_db, "mr_db": mr,
           "zeta_at_wn_eq75": 10.0 ** (-mr / 20.0) / 2.0}
    return _with_delay(name, model, {"K": K, "wn_rad_s": wn, "zeta": zeta, "theta_s": 0.0},
                       data, wn, pts)
