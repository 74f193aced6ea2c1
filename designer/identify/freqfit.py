"""The complex least-squares fit of a measured frequency response (seed 000 section 5, seed 003 section 3.1).

``least-squares``  complex-response fits of ``fopdt``, ``underdamped`` and
                   ``overdamped`` with dead time (scipy least_squares on the log
                   of G_model/G_data: gain error in nepers, phase error in
                   radians), started from the classical estimates
                   (:func:`start_points`, from the readings of :mod:`.bode_readings`),
                   with 95 % confidence half-widths in ``points`` (``<param>_ci95``).

The fits search time constants and wn within the measured band widened
:data:`FIT_BAND` times, far wider than the band
:func:`designer.identify.frequency.judge` accepts, so a fit that runs out of
the band is seen and flagged, yet every exponential of a log-parameter stays
finite. A fitted dead time below :data:`MIN_DEAD_TIME_S` is reported as none.
The fit error (``iae``/``ise``) is :func:`~.bode_readings.fit_error`'s.

"""

from __future__ import annotations

import math

import numpy as np

from ..core.lsq_intervals import half_widths
from ..core.ranges import RANGES
from .bode_readings import invalid_result, fit_error, model_phase, model_response
from .io import FreqData
from .structures import MethodResult

__all__ = ["least_squares_fit"]

#: The fits search time constants and wn within the measured band widened by
#: this factor (far wider than BAND_FACTOR, so a fit that runs out of the band
#: is seen and flagged, yet every exp() of a log-parameter stays finite).
FIT_BAND = 1e3

#: a fitted dead time below this is none (core.process_build refuses 0 < theta < 1 ps)
MIN_DEAD_TIME_S = 1e-12


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
    dicts) and keep the lowest cost; 95 % half-widths from the Jacobian.

    Parameters
    ----------
    data : FreqData
        The frequency-response table.
    model : str
        ``fopdt``, ``underdamped`` or ``overdamped``.
    starts : iterable of dict
        Starting parameter sets.

    Returns
    -------
    MethodResult
        The best fit named ``least-squares`` with its error and half-widths in
        ``points``, or an invalid result when no start converged.
    """
    from scipy.optimize import least_squares

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
        return invalid_result(name, model, "the fit did not converge from any starting point")
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
            # the one rule of every fit (core.lsq_intervals): a pseudo-inverse on unit-norm columns, and a direction the data do not determine unbounded, where
            # inv() of the unscaled product gave a double pole fitted as two lags tau1 and tau2 +-0 (a
            # negative variance of a singular product clipped to 0) and the fit stayed valid
            half = half_widths(best.jac, s2, m - n)
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


def start_points(model, classical, K, wc):
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
