"""Identification from a measured frequency response (seed 000 section 5, seed 003 section 3.1).

Input is a validated table, :class:`~designer.identify.io.freqtable.FreqData` (read
by :func:`designer.identify.io.read_freq_table`).

Methods (all return :class:`~designer.identify.structures.MethodResult`):

``asymptotes``     low-frequency gain K, the high-frequency slope -20 n dB/decade
                   (order n), and the corner where the gain has fallen by
                   3.01 n dB (seed 000 examples 1-3 and 6; seed 003 Table 3.1):
                   n = 1 -> ``fopdt`` tau = 1/wc; n = 2 -> ``double-pole``
                   tau = 1/wc (zeta = 1, the seed's reading of Table IV).
``resonant-peak``  zeta from the peak height -10 log(4 zeta^2 (1 - zeta^2)) at
                   wn sqrt(1 - 2 zeta^2) (seed 000 eq 79) -> ``underdamped``;
                   the seed's quicker -20 log(2 zeta)-at-wn reading (eq 75)
                   is in ``points``.
``least-squares``  complex-response fits of ``fopdt``, ``underdamped`` and
                   ``overdamped`` with dead time (scipy least_squares on the log
                   of G_model/G_data: gain error in nepers, phase error in
                   radians), started from the classical estimates, with 95 %
                   confidence half-widths in ``points`` (``<param>_ci95``).

Every method with phase data also reads a dead time from the phase: the
median over the points above a tenth of the corner of
(phase_model_without_delay - phase_data)/w (seed 000 example 2), never
negative.

Fit error. The step methods' ``iae``/``ise`` (integrals over time) have no
meaning here; in their place, with e_k = |G_model(j w_k)/G_data(j w_k) - 1|
the relative complex error at each tabulated frequency (gain only when the
table has no phase),

- ``iae`` = mean over the points of e_k (dimensionless; 0.01 = 1 %),
- ``ise`` = mean over the points of e_k^2.

Results are ranked by that ``iae`` (valid first), as ``identify`` ranks by IAE.

Validity (:func:`judge`). A result is valid only if it describes the table:
finite parameters, a fit error of at most :data:`MAX_FIT_ERROR`, and every
corner frequency (1/tau of each time constant, wn) inside the measured band
widened :data:`BAND_FACTOR` times each way. A flat table, a ratio read as dB
or a phase of the wrong sign then has no valid model instead of one with
wn = 2e54 rad/s or a 47 % error marked "ok". The fits search time constants
and wn within the band widened :data:`FIT_BAND` times, so every exponential
of a log-parameter stays finite.

"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

from ..core.ranges import RANGES
from ..core.waveform import parabola_vertex
from .io import FreqData
from .structures import MethodResult, rank_key

ERROR_DEFINITION = ("iae = mean over the table's frequencies of |G_model/G_data - 1| "
                    "(relative complex error; gain only when there is no phase), "
                    "ise = mean of its square; dimensionless")

DB_PER_POLE = 10.0 * math.log10(2.0)
#: A model whose fit error (mean |G_model/G_data - 1|) exceeds this does not
#: describe the table: 0.2 is an average miss of about 1.6 dB or 11 degrees,
#: several times what the seeds' hand-read tables show against their own
#: second-order readings (7 %), and what a table read in the wrong units or
#: with the wrong phase sign gives (over 20 %).
MAX_FIT_ERROR = 0.2
#: Corner frequencies and wn must lie inside the measured band widened by this
#: factor each way: a pole ten times beyond the last point changes the table's
#: gain by under 0.05 dB and its phase by under 6 degrees, so the table cannot
#: place it (a flat table "fits" wn = 2e54 rad/s).
BAND_FACTOR = 10.0
#: The fits search time constants and wn within the measured band widened by
#: this factor (far wider than BAND_FACTOR, so a fit that runs out of the band
#: is seen and flagged, yet every exp() of a log-parameter stays finite).
FIT_BAND = 1e3

#: a fitted dead time below this is none (core.process refuses 0 < theta < 1 ps)
MIN_DEAD_TIME_S = 1e-12

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
    """Complex G(j w) of ``model`` (same parameters as core.model_step)."""
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
    """Continuous (unwrapped) phase in radians of ``model`` for K > 0."""
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

def _interp_logf(w, y, level):
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
    0.25 dB error in the second of 151 read a flat first-order table as falling)."""
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


def _invalid(name, model, note, points=None):
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
    """
    name = "asymptotes"
    lf = low_frequency_slope(data)
    if lf < -10.0:
        return _invalid(name, "fopdt", f"the gain already falls {-lf:.0f} dB/decade at the "
                        "lowest frequencies: a pole at the origin (integrator, seed 000 "
                        "examples 3-4) or a table that starts above the corner; the models "
                        "here need a flat low-frequency gain", {"lf_slope_db_dec": lf})
    K, run = low_frequency_gain(data)
    k_db = 20.0 * math.log10(K)
    slope, sel = high_frequency_slope(data, k_db)
    n = int(round(-slope / 20.0))
    pts = {"K_points": run, "hf_slope_db_dec": slope, "order": n}
    if n < 1:
        return _invalid(name, "fopdt", f"the gain does not roll off (high-frequency slope "
                        f"{slope:.1f} dB/decade): no low-pass model to read", pts)
    # n equal poles are 10 log10(2) = 3.01 dB down per pole at their corner
    wc = _interp_logf(data.w, data.gain_db, k_db - DB_PER_POLE * n)
    # where the -20 n dB/decade line through the high-frequency points meets K
    b = float(np.mean(data.gain_db[sel] + 20.0 * n * np.log10(data.w[sel])))
    pts["w_intersection_rad_s"] = 10.0 ** ((b - k_db) / (20.0 * n))
    if not math.isfinite(wc):
        return _invalid(name, "fopdt" if n == 1 else "double-pole",
                        f"the gain never falls {DB_PER_POLE * n:.1f} dB below K in the table: "
                        "extend it to higher frequencies", pts)
    pts["wc_rad_s"] = wc
    pts["fc_hz"] = wc / (2.0 * math.pi)
    if n > 2:
        if data.phase is not None:
            ph0 = -n * np.arctan(data.w / wc)
            pts["theta_s"] = dead_time_from_phase(data.w, data.phase, ph0, 0.1 * wc)
        return _invalid(name, "double-pole", f"high-frequency slope {slope:.0f} dB/decade means "
                        f"order {n}; the models here have at most two poles (the seed's "
                        f"reading: {n} equal poles at {wc:.4g} rad/s"
                        + (f", dead time {pts['theta_s']:.4g} s" if "theta_s" in pts else "")
                        + ")", pts)
    model = "fopdt" if n == 1 else "double-pole"
    return _with_delay(name, model, {"K": K, "tau_s": 1.0 / wc, "theta_s": 0.0}, data, wc, pts,
                       "" if n == 1 else "two equal poles (zeta = 1)")


def zeta_from_peak(mr_db: float) -> float:
    """Damping ratio from the resonant peak height above K in dB (seed 000 eq 79),
    the root below 1/sqrt(2); nan if ``mr_db`` <= 0."""
    if not mr_db > 0.0:
        return math.nan
    q = 10.0 ** (-mr_db / 10.0)            # = 4 zeta^2 (1 - zeta^2)
    # 1 - sqrt(1 - q) written as q / (1 + sqrt(1 - q)): no cancellation, so a
    # tall peak gives a small zeta, never exactly 0 (G would then divide by 0)
    return math.sqrt(q / (2.0 * (1.0 + math.sqrt(max(0.0, 1.0 - q)))))


def peak_gain_db(zeta: float) -> float:
    """Seed 000 eq 79: -10 log(4 zeta^2 (1 - zeta^2)), for zeta < 1/sqrt(2)."""
    return -10.0 * math.log10(4.0 * zeta * zeta * (1.0 - zeta * zeta))


def resonant_peak(data: FreqData, min_db: float = 0.1) -> MethodResult:
    """Resonant-peak damping (seed 000 example 5, eqs 75 and 79).

    The peak (the vertex of 1/|G|^2 as a parabola in w^2 through the highest
    point and its neighbours, exact for a second-order system) gives
    Mr = peak - K in dB; zeta solves
    -10 log(4 zeta^2 (1 - zeta^2)) = Mr and wn = w_peak / sqrt(1 - 2 zeta^2).
    Valid when the table shows a peak at least ``min_db`` above K between its
    first and last points (zeta < 0.707).
    """
    name, model = "resonant-peak", "underdamped"
    lf = low_frequency_slope(data)
    if lf < -10.0:
        return _invalid(name, model, f"the gain already falls {-lf:.0f} dB/decade at the "
                        "lowest frequencies: no flat low-frequency gain to measure the peak "
                        "against", {"lf_slope_db_dec": lf})
    K, _ = low_frequency_gain(data)
    k_db = 20.0 * math.log10(K)
    db = data.gain_db
    i = int(np.argmax(db))
    if db[i] - k_db < min_db or i == 0 or i == db.size - 1:
        return _invalid(name, model, f"no resonant peak {min_db} dB above the low-frequency gain "
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


# --------------------------------------------------------------------------
# least squares
# --------------------------------------------------------------------------

def _x_to_params(model, x, fit_delay):
    th = float(x[-1]) if fit_delay else 0.0
    if model == "fopdt":
        return {"K": math.exp(x[0]), "tau_s": math.exp(x[1]), "theta_s": th}
    if model == "underdamped":
        return {"K": math.exp(x[0]), "wn_rad_s": math.exp(x[1]), "zeta": float(x[2]),
                "theta_s": th}
    return {"K": math.exp(x[0]), "tau1_s": math.exp(x[1]), "tau2_s": math.exp(x[2]), "theta_s": th}


def _params_to_x(model, p, fit_delay):
    K = abs(p["K"])
    if model == "fopdt":
        x = [math.log(K), math.log(p["tau_s"])]
    elif model == "underdamped":
        x = [math.log(K), math.log(p["wn_rad_s"]), min(max(p["zeta"], 0.011), 0.989)]
    else:
        x = [math.log(K), math.log(p["tau1_s"]), math.log(p["tau2_s"])]
    if fit_delay:
        x.append(max(p.get("theta_s", 0.0) or 0.0, 0.0))
    return np.array(x, float)


def _residual(model, data, fit_delay):
    lg = np.log(data.gain)
    ph = data.phase

    def fun(x):
        p = _x_to_params(model, x, fit_delay)
        gm = np.log(np.abs(model_response(model, p, data.w)))
        r = gm - lg
        if ph is None:
            return r
        return np.concatenate((r, model_phase(model, p, data.w) - ph))
    return fun


def _fit_bounds(model, data, fit_delay) -> tuple:
    """Bounds of the free variables (log K, log time scales or log wn, zeta, theta)."""
    w_lo, w_hi = float(data.w[0]) / FIT_BAND, float(data.w[-1]) * FIT_BAND
    log_k = [math.log(float(data.gain.min())) - 20.0, math.log(float(data.gain.max())) + 20.0]
    log_tau = [-math.log(w_hi), -math.log(w_lo)]
    lo = {"fopdt": [log_k[0], log_tau[0]],
          "underdamped": [log_k[0], math.log(w_lo), 0.01],
          "overdamped": [log_k[0], log_tau[0], log_tau[0]]}[model]
    hi = {"fopdt": [log_k[1], log_tau[1]],
          "underdamped": [log_k[1], math.log(w_hi), 0.99],
          "overdamped": [log_k[1], log_tau[1], log_tau[1]]}[model]
    if fit_delay:
        # the table's phase is at most RANGES["phase_deg"]: a longer delay than
        # that at the lowest frequency cannot be in the data
        theta_max = math.radians(RANGES["phase_deg"].hi) * 2.0 / float(data.w[0])
        lo, hi = lo + [0.0], hi + [theta_max]
    return lo, hi


def least_squares_fit(data: FreqData, model: str, starts) -> MethodResult:
    """Fit ``model`` to the complex response from each of ``starts`` (parameter
    dicts) and keep the lowest cost; 95 % half-widths from the Jacobian."""
    from scipy.optimize import least_squares

    # Student t quantile from scipy.special: scipy.stats costs 0.4 s to import
    from scipy.special import stdtrit

    name = "least-squares"
    fit_delay = data.phase is not None
    fun = _residual(model, data, fit_delay)
    lo, hi = _fit_bounds(model, data, fit_delay)
    best = None
    for p0 in starts:
        try:
            x0 = np.clip(_params_to_x(model, p0, fit_delay), np.array(lo) + 1e-12,
                         np.array(hi) - 1e-12)
            sol = least_squares(fun, x0, bounds=(lo, hi), method="trf", x_scale="jac",
                                max_nfev=200, ftol=1e-12, xtol=1e-12, gtol=1e-12)
        except (ValueError, OverflowError, ZeroDivisionError, KeyError):
            continue
        if np.all(np.isfinite(sol.x)) and (best is None or sol.cost < best.cost):
            best = sol
    if best is None:
        return _invalid(name, model, "the fit did not converge from any starting point")
    params = _x_to_params(model, best.x, fit_delay)
    if params["theta_s"] < MIN_DEAD_TIME_S:
        # the bound at 0 reached in floating point (1e-25 s): no dead time, which
        # a model's consumers accept, where they refuse one below 1 ps
        params["theta_s"] = 0.0
    pts = {}
    m, n = best.fun.size, best.x.size
    note = ("" if fit_delay else
            "no phase in the table: fitted the gain only, dead time not identified")
    if m > n:
        s2 = 2.0 * best.cost / (m - n)
        try:
            cov = np.linalg.inv(best.jac.T @ best.jac) * s2
            half = stdtrit(m - n, 0.975) * np.sqrt(np.clip(np.diag(cov), 0.0, None))
            # back from log variables: d(e^x) = e^x dx
            names = {"fopdt": ["K", "tau_s"], "underdamped": ["K", "wn_rad_s", "zeta"],
                     "overdamped": ["K", "tau1_s", "tau2_s"]}[model]
            names += ["theta_s"] if fit_delay else []
            for k, h, xv in zip(names, half, best.x):
                scale = abs(params[k]) if k not in ("zeta", "theta_s") else 1.0
                if model == "overdamped" and k in ("tau1_s", "tau2_s"):
                    scale = math.exp(xv)
                pts[f"{k}_ci95"] = float(h * scale)
        except np.linalg.LinAlgError:
            note = "; ".join(s for s in (note, "singular Jacobian: no confidence intervals") if s)
    if model == "overdamped" and params["tau1_s"] > params["tau2_s"]:
        params["tau1_s"], params["tau2_s"] = params["tau2_s"], params["tau1_s"]
        if "tau1_s_ci95" in pts:
            pts["tau1_s_ci95"], pts["tau2_s_ci95"] = pts["tau2_s_ci95"], pts["tau1_s_ci95"]
    params["K"] = data.sign * params["K"]
    iae, ise = fit_error(model, params, data)
    valid = True
    if model == "overdamped" and params["tau1_s"] < 1e-3 * params["tau2_s"]:
        note = "; ".join(s for s in (note, "tau1 < tau2/1000: the data show one pole, this is "
                                     "the fopdt fit") if s)
        valid = False
    if model == "underdamped" and params["zeta"] >= 0.98:
        note = "; ".join(s for s in (note, "zeta at its bound 0.99: the data are not underdamped "
                                     "(see the overdamped fit)") if s)
        valid = False
    return MethodResult(name, model, params, iae, ise, valid, note, pts)


def _starts(model, classical, K, wc):
    """Starting points: the classical results of compatible models, then a small grid."""
    out = []
    for m in classical:
        if not m.valid:
            continue
        p = m.params
        try:
            if model == "fopdt":
                tau = p.get("tau_s") or (1.0 / p["wn_rad_s"] if "wn_rad_s" in p else p["tau2_s"])
                out.append({"K": K, "tau_s": tau, "theta_s": p["theta_s"]})
            elif model == "underdamped":
                if m.model == "underdamped":
                    out.append(dict(p))
                else:
                    tau = p.get("tau_s") or math.sqrt(p["tau1_s"] * p["tau2_s"])
                    out.append({"K": K, "wn_rad_s": 1.0 / tau, "zeta": 0.9,
                                "theta_s": p["theta_s"]})
            else:
                if m.model == "overdamped":
                    out.append(dict(p))
                elif m.model == "double-pole":
                    out.append({"K": K, "tau1_s": 0.8 * p["tau_s"], "tau2_s": 1.25 * p["tau_s"],
                                "theta_s": p["theta_s"]})
                elif m.model == "fopdt":
                    out.append({"K": K, "tau1_s": 0.1 * p["tau_s"], "tau2_s": p["tau_s"],
                                "theta_s": p["theta_s"]})
        except (KeyError, TypeError, ZeroDivisionError):
            continue
    if math.isfinite(wc) and wc > 0:
        if model == "fopdt":
            out.append({"K": K, "tau_s": 1.0 / wc, "theta_s": 0.0})
        elif model == "underdamped":
            out += [{"K": K, "wn_rad_s": wc, "zeta": z, "theta_s": 0.0} for z in (0.15, 0.4, 0.7)]
        else:
            out += [{"K": K, "tau1_s": r / wc, "tau2_s": 1.0 / (r * wc), "theta_s": 0.0}
                    for r in (0.9, 0.3, 0.05)]
    return out


# --------------------------------------------------------------------------
# orchestration
# --------------------------------------------------------------------------

@dataclass(frozen=True)
class LoopMargins:
    """Stability margins of an open-loop (loop-gain) table: the gain
    crossover (|L| = 1) and the phase margin there, 180 + phase(L) in
    (-180, 180]; the phase crossover (phase -180 deg) and the gain margin there,
    -20 log |L|. ``None`` where the table does not reach the crossing."""

    crossover_hz: float
    phase_margin_deg: float | None
    phase_crossover_hz: float | None
    gain_margin_db: float | None
    lf_slope_db_dec: float
    note: str = ""

    def to_dict(self) -> dict:
        return {"crossover_hz": self.crossover_hz, "phase_margin_deg": self.phase_margin_deg,
                "phase_crossover_hz": self.phase_crossover_hz,
                "gain_margin_db": self.gain_margin_db,
                "lf_slope_db_dec": self.lf_slope_db_dec, "note": self.note}


def _cross_log(f, v, level, start=0):
    """First f (interpolated in log f) from index ``start`` where ``v`` passes
    ``level`` (either way), and its index; (nan, -1) if never."""
    d = v[start:] - level
    k = np.nonzero(np.sign(d[1:]) != np.sign(d[:-1]))[0]
    if not k.size:
        return math.nan, -1
    i = start + int(k[0])
    frac = 0.0 if v[i + 1] == v[i] else (level - v[i]) / (v[i + 1] - v[i])
    return float(10.0 ** (math.log10(f[i]) + frac * (math.log10(f[i + 1]) - math.log10(f[i])))), i


def loop_margins(data: FreqData) -> LoopMargins | None:
    """Crossover, phase margin and gain margin of a loop-gain table (seed 001
    section V: the loop of a plant and its controller), or None when the gain
    does not start above 0 dB and fall through it (not an open-loop table).

    The phase is the table's own (an inverting table's 180 deg put back); the
    margins are read by linear interpolation in log f between the rows."""
    db = data.gain_db
    f = data.f_hz
    if not (db[0] > 0.0 and np.any(db <= 0.0)):
        return None
    fc, i = _cross_log(f, db, 0.0)
    lf = low_frequency_slope(data)
    if data.phase is None:
        return LoopMargins(fc, None, None, None, lf, "no phase in the table: margins unknown")
    ph = np.rad2deg(data.phase) + (180.0 if data.sign < 0 else 0.0)
    frac = math.log10(fc / f[i]) / math.log10(f[i + 1] / f[i])
    ph_c = float(ph[i] + frac * (ph[i + 1] - ph[i]))
    pm = (180.0 + ph_c + 180.0) % 360.0 - 180.0
    # the phase crossover: where the phase passes -180 deg (mod 360)
    turns = np.round((ph[0] + 180.0) / 360.0)
    fp, j = _cross_log(f, ph, -180.0 + 360.0 * turns)
    gm = None
    note = ""
    if j >= 0:
        gfrac = math.log10(fp / f[j]) / math.log10(f[j + 1] / f[j])
        gm = float(-(db[j] + gfrac * (db[j + 1] - db[j])))
    else:
        fp = None
        note = "the phase never reaches -180 deg in the table: gain margin beyond it"
    return LoopMargins(fc, float(pm), fp, gm, lf, note)


@dataclass
class FreqIdentifyResult:
    """Every method's result, ranked by fit error (valid first), the best, and
    the loop margins when the table is an open loop's."""

    methods: list
    best: MethodResult | None
    data: FreqData
    loop: LoopMargins | None = None

    def to_dict(self) -> dict:
        return {"methods": [m.to_dict() for m in self.methods],
                "best": self.best.to_dict() if self.best else None,
                "data": self.data.to_dict(),
                "loop": self.loop.to_dict() if self.loop else None,
                "error_definition": ERROR_DEFINITION}


def corner_frequencies(model: str, params: dict) -> dict:
    """The model's corner frequencies (rad/s): 1/tau of each time constant, wn."""
    out = {}
    for k, v in params.items():
        if k.startswith("tau") and isinstance(v, float) and v > 0:
            out[k] = 1.0 / v
        elif k == "wn_rad_s":
            out[k] = v
    return out


def judge(m: MethodResult, data: FreqData) -> None:
    """Mark a result invalid, saying why, unless it describes the table: finite
    parameters and error, fit error at most MAX_FIT_ERROR, and every corner
    frequency inside the measured band widened BAND_FACTOR times."""
    if not m.valid:
        return
    why = None
    if not (all(math.isfinite(v) for v in m.params.values()) and math.isfinite(m.iae)):
        why = "degenerate result: the table does not have this model's shape"
    elif m.iae > MAX_FIT_ERROR:
        why = (f"fit error {100 * m.iae:.3g} % is above the {100 * MAX_FIT_ERROR:g} % a model "
               "must reach to describe the table (gain or phase in other units than read, "
               "or the phase sign flipped?)")
    else:
        w_lo, w_hi = data.w[0] / BAND_FACTOR, data.w[-1] * BAND_FACTOR
        for k, wc in corner_frequencies(m.model, m.params).items():
            if not w_lo <= wc <= w_hi:
                name = "wn" if k == "wn_rad_s" else f"the corner of {k[:-2]}"
                why = (f"{name} ({wc:.4g} rad/s, {wc / (2 * math.pi):.4g} Hz) lies outside the "
                       f"measured band widened {BAND_FACTOR:g} times ({w_lo:.4g} to "
                       f"{w_hi:.4g} rad/s): the table cannot place it")
                break
    if why:
        m.valid = False
        m.note = "; ".join(x for x in (m.note, why) if x)


def identify_freq(data: FreqData) -> FreqIdentifyResult:
    """Run the classical readings and the least-squares fits; rank by fit error."""
    classical = [asymptotes(data), resonant_peak(data)]
    K, _ = low_frequency_gain(data)
    wc = _interp_logf(data.w, data.gain_db, 20.0 * math.log10(K) - 3.0)
    if not math.isfinite(wc):
        wc = float(data.w[-1])
    fits = [least_squares_fit(data, model, _starts(model, classical, K, wc))
            for model in ("fopdt", "underdamped", "overdamped")]
    for m in classical + fits:
        judge(m, data)
    methods = sorted(classical + fits, key=rank_key)
    best = next((m for m in methods if m.valid and math.isfinite(m.iae)), None)
    return FreqIdentifyResult(methods, best, data, loop_margins(data))
