"""Process models of seed 000 (FOPDT, double pole, under- and overdamped second
order, each with dead time), their step responses, and their least-squares fit
to a measured or simulated step response.

Used by identification (:mod:`designer.identify.refine` wraps the fit as one of
its methods) and by PID tuning (the FOPDT rules need a fitted FOPDT model).

Parameter names (seconds and rad/s in the names, as in the JSON output):

- ``fopdt``       K, tau_s, theta_s           K e^(-theta s) / (tau s + 1)
- ``double-pole`` K, tau_s, theta_s           K e^(-theta s) / (tau s + 1)^2
- ``underdamped`` K, wn_rad_s, zeta, theta_s  K wn^2 e^(-theta s) / (s^2 + 2 zeta wn s + wn^2)
- ``overdamped``  K, tau1_s, tau2_s, theta_s  K e^(-theta s) / ((tau1 s + 1)(tau2 s + 1)),
  tau1 <= tau2 (the fast time constant first, as seeds 002 and 003 write it)

The fit starts from a classical estimate (or a few points of the response),
minimises the sum of squared errors with scipy's trust-region reflective solver
under physical bounds (tau > 0, theta >= 0, 0 < zeta < 1), and reports 95 %
confidence half-widths from the residual variance and the Jacobian at the
optimum: cov = s^2 (J^T J)^-1, s^2 = SSE / (n - p), by
:func:`~designer.core.lsq_intervals.half_widths` (columns of very different
lengths scaled first; a parameter the data do not determine gets an infinite
half-width). They assume white
residuals; with model-structure error the residuals are correlated and the
intervals are optimistic.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

from .lsq_intervals import half_widths
from .metrics import Overshoot, measure_step
from .waveform import crossing_time, noise_sigma

__all__ = ["MODELS", "PARAMS", "data_overshoot", "fit_step", "model_overshoot_pct", "model_step",
           "overshoot_mismatch", "unphysical"]

MODELS = ("fopdt", "double-pole", "underdamped", "overdamped")


def model_step(model: str, params: dict, t) -> np.ndarray:
    """Unit-input step response (0 -> K) of ``model`` at times ``t`` (step at t = 0).

    Parameters
    ----------
    model : str
        The model's kind.
    params : dict
        Its parameters.
    t : array_like
        The times (s).

    Returns
    -------
    numpy.ndarray
        The response on ``t``.
    """
    t = np.asarray(t, float)
    K = params["K"]
    theta = params.get("theta_s", 0.0) or 0.0
    s = np.clip(t - theta, 0.0, None)
    if model == "fopdt":
        y = 1.0 - np.exp(-s / params["tau_s"])
    elif model == "double-pole":
        tau = params["tau_s"]
        y = 1.0 - (1.0 + s / tau) * np.exp(-s / tau)
    elif model == "overdamped":
        t1, t2 = params["tau1_s"], params["tau2_s"]
        if math.isclose(t1, t2, rel_tol=1e-9):
            y = 1.0 - (1.0 + s / t1) * np.exp(-s / t1)
        else:
            y = 1.0 - (t1 * np.exp(-s / t1) - t2 * np.exp(-s / t2)) / (t1 - t2)
    elif model == "underdamped":
        wn, z = params["wn_rad_s"], params["zeta"]
        if z >= 1.0:
            raise ValueError("underdamped model needs zeta < 1")
        wd = wn * math.sqrt(1.0 - z * z)
        phi = math.acos(z)
        y = 1.0 - np.exp(-z * wn * s) * np.sin(wd * s + phi) / math.sqrt(1.0 - z * z)
    else:
        raise ValueError(f"unknown model {model!r}; allowed: {', '.join(MODELS)}")
    return K * np.where(t >= theta, y, 0.0)


def unphysical(model: str, params: dict) -> str:
    """Why ``params`` are not a stable, causal ``model`` ("" when they are): a
    time constant or wn that is not positive, a negative zeta. Their step
    response grows without bound (exp overflows), so it is never evaluated.

    Parameters
    ----------
    model : str
        The model's kind.
    params : dict
        Its parameters.

    Returns
    -------
    str
        Why not, or "".
    """
    for k, v in params.items():
        if (k.startswith("tau") or k == "wn_rad_s") and not v > 0:
            return f"{k} = {v:.4g} is not positive"
        if k == "zeta" and not v >= 0:
            return f"zeta = {v:.4g} is negative"
    return ""


def model_overshoot_pct(model: str, params: dict) -> float:
    """Overshoot of ``model``'s step response, % of its change: 0 for the
    monotonic models, 100 exp(-pi zeta / sqrt(1 - zeta^2)) for the underdamped one.

    Parameters
    ----------
    model : str
        The model's kind.
    params : dict
        Its parameters.

    Returns
    -------
    float
        The overshoot (%).
    """
    if model in ("fopdt", "double-pole", "overdamped"):
        return 0.0
    if model == "underdamped":
        z = float(params["zeta"])
        return 100.0 * math.exp(-math.pi * z / math.sqrt(1.0 - z * z)) if 0.0 <= z < 1.0 else 0.0
    raise ValueError(f"unknown model {model!r}; allowed: {', '.join(MODELS)}")


def overshoot_mismatch(model: str, params: dict, overshoot: Overshoot) -> str:
    """Why a ``model`` with ``params`` cannot have made data that overshoot as
    measured (:meth:`~designer.core.metrics.Overshoot.differs`), or "" when it
    can: the one model-against-data overshoot rule of every method.

    Parameters
    ----------
    model : str
        The model's kind.
    params : dict
        Its parameters.
    overshoot : Overshoot
        The overshoot measured.

    Returns
    -------
    str
        Why not, or "".
    """
    mos = model_overshoot_pct(model, params)
    if not overshoot.differs(mos):
        return ""
    if mos == 0.0:
        return (f"the data overshoot {overshoot.text()}, which the {model} model, being monotonic, "
                "cannot; use an underdamped method")
    return (f"this model overshoots {mos:.2f} %, the data {overshoot.text()}: more apart than the "
            "noise and the method's accuracy explain")


def data_overshoot(t, y, yf, sigma: float | None = None) -> Overshoot:
    """The :class:`~designer.core.metrics.Overshoot` of a response from 0 to
    ``yf`` (:func:`~designer.core.metrics.measure_step`), for callers that were
    not given the one measured on the whole record.

    Parameters
    ----------
    t, y : array_like
        The response.
    yf : float
        Its final value.
    sigma : float, optional
        The noise's standard deviation; None: estimated.

    Returns
    -------
    Overshoot
        The overshoot.
    """
    y = np.asarray(y, float)
    sig = noise_sigma(y) if sigma is None else sigma
    return measure_step(t, y, initial=0.0, final=float(yf), sigma=sig)[1]


#: A dead time below this fraction of the sample interval is the bound 0 (a
#: fit pinned there; printing it in femtoseconds would be noise).
MIN_DEAD_TIME_OF_DT = 1e-3

#: Fits run on at most this many samples (the data are block-averaged upstream).
MAX_FIT_SAMPLES = 4000
PARAMS = {
    "fopdt": ("K", "tau_s", "theta_s"),
    "overdamped": ("K", "tau1_s", "tau2_s", "theta_s"),
    "underdamped": ("K", "wn_rad_s", "zeta", "theta_s"),
}


def _thin(t, y, n=MAX_FIT_SAMPLES):
    t = np.asarray(t, float)
    y = np.asarray(y, float)
    if t.size <= n:
        return t, y
    idx = np.linspace(0, t.size - 1, n).round().astype(int)
    return t[idx], y[idx]


def _to_x(model, p):
    """Free variables: K, log of the time scales, theta; zeta as is."""
    if model == "fopdt":
        return np.array([p["K"], math.log(p["tau_s"]), p["theta_s"]])
    if model == "overdamped":
        return np.array([p["K"], math.log(p["tau1_s"]), math.log(p["tau2_s"]), p["theta_s"]])
    return np.array([p["K"], math.log(p["wn_rad_s"]), p["zeta"], p["theta_s"]])


def _from_x(model, x):
    if model == "fopdt":
        return {"K": x[0], "tau_s": math.exp(x[1]), "theta_s": x[2]}
    if model == "overdamped":
        return {"K": x[0], "tau1_s": math.exp(x[1]), "tau2_s": math.exp(x[2]), "theta_s": x[3]}
    return {"K": x[0], "wn_rad_s": math.exp(x[1]), "zeta": x[2], "theta_s": x[3]}


def _bounds(model, t_end, x0):
    big = np.inf
    lt = math.log(t_end)
    if model == "fopdt":
        lo, hi = [-big, lt - 25, 0.0], [big, lt + 3, t_end]
    elif model == "overdamped":
        lo, hi = [-big, lt - 25, lt - 25, 0.0], [big, lt + 3, lt + 3, t_end]
    else:
        lo, hi = [-big, -lt - 5, 1e-3, 0.0], [big, -lt + 25, 0.999, t_end]
    lo, hi = np.array(lo, float), np.array(hi, float)
    fin = np.isfinite(lo) & np.isfinite(hi)
    margin = np.where(fin, 1e-6 * (hi - lo), 0.0)
    x0 = np.clip(x0, lo + margin, hi - margin)
    return (lo, hi), x0


def start_point(model, t, y, yf):
    """A starting estimate from the response's own points (when no classical one is given)."""
    sig = noise_sigma(y)
    sgn = 1.0 if yf >= 0 else -1.0
    ya = sgn * np.asarray(y)
    t28 = crossing_time(t, ya, 0.283 * abs(yf), sigma=sig)
    t63 = crossing_time(t, ya, 0.632 * abs(yf), sigma=sig)
    if not (math.isfinite(t28) and math.isfinite(t63)) or t63 <= t28:
        t28, t63 = 0.1 * t[-1], 0.3 * t[-1]
    tau = 1.5 * (t63 - t28)
    theta = max(0.0, t63 - tau)
    if model == "fopdt":
        return {"K": yf, "tau_s": tau, "theta_s": theta}
    if model == "overdamped":
        return {"K": yf, "tau1_s": 0.75 * tau, "tau2_s": 0.25 * tau, "theta_s": theta}
    # Underdamped: overshoot and peak time of the data (textbook inversion).
    i = int(np.argmax(ya))
    mp = max((ya[i] - abs(yf)) / abs(yf), 1e-3)
    lm = math.log(mp)
    zeta = min(max(-lm / math.sqrt(math.pi ** 2 + lm * lm), 0.05), 0.95)
    tp = max(float(t[i]), 1e-12 + t[-1] * 1e-6)
    wn = math.pi / (tp * math.sqrt(1 - zeta * zeta))
    return {"K": yf, "wn_rad_s": wn, "zeta": zeta, "theta_s": 0.0}


@dataclass(frozen=True)
class StepFit:
    """A least-squares fit of one process model to a step response."""

    model: str
    params: dict          #: physical parameters (names: :data:`PARAMS`)
    ci95: dict            #: 95 % confidence half-widths of the same parameters
    samples: int          #: samples fitted (after thinning)
    rms_residual: float   #: in the response's units
    valid: bool           #: the structure fits the data (see :func:`_check`)
    note: str = ""        #: why not, when it does not


def fit_step(model: str, t, y, yf, start: dict | None = None, sigma: float | None = None,
             overshoot: Overshoot | None = None) -> StepFit:
    """Least-squares fit of ``model`` to a step response.

    Parameters
    ----------
    model : {"fopdt", "overdamped", "underdamped"}
    t, y, yf : array_like, array_like, float
        Time since the step, the response per unit input step (0 -> K), and its
        settled value.
    start : dict, optional
        Initial parameters ``{"model", "params"}`` (a classical estimate);
        converted when it belongs to another model (FOPDT or double pole ->
        overdamped).
    sigma : float, optional
        Noise of ``y`` when the caller measured it (else :func:`noise_sigma`).
    overshoot : Overshoot, optional
        The overshoot measured on the record (else :func:`data_overshoot` of
        ``t``, ``y``): the validity checks use it.

    Returns
    -------
    StepFit
        A dead time below :data:`MIN_DEAD_TIME_OF_DT` of the sample interval
        is reported as 0.
    """
    from scipy.optimize import least_squares   # imported on use: model_step users need no scipy
    t = np.asarray(t, float)
    y = np.asarray(y, float)
    tf, yfit = _thin(t, y)
    p0 = _convert_start(model, start) if start else None
    if p0 is None:
        p0 = start_point(model, t, y, yf)
    names = PARAMS[model]
    scale = max(abs(yf), 1e-300)

    def resid(x):
        return (model_step(model, _from_x(model, x), tf) - yfit) / scale

    bounds, x0 = _bounds(model, float(t[-1]), _to_x(model, p0))
    best = None
    # Dead time makes the cost kinked; a second start with theta halved
    # avoids the occasional local minimum at the bound.
    starts = [x0]
    if model != "underdamped":
        x1 = x0.copy()
        x1[-1] *= 0.5
        starts.append(x1)
    for xs in starts:
        try:
            sol = least_squares(resid, xs, bounds=bounds, x_scale="jac", method="trf",
                                diff_step=1e-6, max_nfev=300 * len(xs))
        except (ValueError, FloatingPointError) as exc:  # pragma: no cover - defensive
            nan = {k: math.nan for k in names}
            return StepFit(model, nan, dict(nan), int(tf.size), math.nan, False, f"fit failed: {exc}")
        if best is None or sol.cost < best.cost:
            best = sol
    params = _from_x(model, best.x)
    ci = _confidence(model, best, tf.size)
    if tf.size > 1 and params["theta_s"] < MIN_DEAD_TIME_OF_DT * float(np.median(np.diff(tf))):
        params["theta_s"] = 0.0
    # the fast time constant is tau1, as in seeds 002 and 003 (and identify/overdamped.py)
    if model == "overdamped" and params["tau1_s"] > params["tau2_s"]:
        params["tau1_s"], params["tau2_s"] = params["tau2_s"], params["tau1_s"]
        if "tau1_s" in ci and "tau2_s" in ci:
            ci["tau1_s"], ci["tau2_s"] = ci["tau2_s"], ci["tau1_s"]
    if overshoot is None:
        overshoot = data_overshoot(t, y, yf, sigma)
    valid, note = _check(model, params, overshoot, best)
    return StepFit(model, {k: float(params[k]) for k in names}, ci, int(tf.size),
                   float(math.sqrt(2 * best.cost / tf.size)) * scale, valid, note)


def _confidence(model, sol, n):
    """95 % half-widths of the physical parameters (delta method through the log scale)."""
    names = PARAMS[model]
    J = sol.jac
    p = J.shape[1]
    dof = max(n - p, 1)
    s2 = 2.0 * sol.cost / dof
    try:
        # unit-norm columns before the pseudo-inverse: an overdamped fit of a first-order
        # response shrinks tau1 towards 0, its column with it, and the unscaled pseudo-inverse dropped it
        # (tau1 +-3.4e-8 s, an unidentifiable time constant reported as exact)
        sd = half_widths(J, s2, dof)
    except np.linalg.LinAlgError:  # pragma: no cover - defensive
        return {k: math.nan for k in names}
    x = sol.x
    out = {}
    for i, k in enumerate(names):
        if k in ("tau_s", "tau1_s", "tau2_s", "wn_rad_s"):
            out[k] = float(sd[i] * math.exp(x[i]))  # d exp(x) = exp(x) dx
        else:
            # K, zeta, theta are free variables themselves. (Residuals are
            # divided by |yf|, a constant: it cancels between s^2 and J.)
            out[k] = float(sd[i])
    return out


def _check(model, params, overshoot: Overshoot, sol):
    """Validity of the fitted structure against the data's measured ``overshoot``."""
    if model == "underdamped":
        if params["zeta"] >= 0.99:
            return False, ("fitted zeta reached the bound 1: the data are not underdamped; "
                           "use the overdamped fit")
        if not overshoot.above_noise():
            return False, (f"the data's overshoot, {overshoot.text()}, is not above the noise: "
                           "underdamped model not identifiable")
    why = overshoot_mismatch(model, params, overshoot)
    if why:
        return False, why
    if not sol.success:
        return False, f"solver did not converge: {sol.message}"
    return True, ""


def _convert_start(model, start):
    p = dict(start.get("params", start))
    m = start.get("model", model)
    try:
        if model == "fopdt":
            if m == "fopdt":
                return {k: p[k] for k in PARAMS["fopdt"]}
            return None
        if model == "overdamped":
            if m == "overdamped":
                return {k: p[k] for k in PARAMS["overdamped"]}
            if m == "double-pole":
                return {"K": p["K"], "tau1_s": 1.2 * p["tau_s"], "tau2_s": 0.8 * p["tau_s"],
                        "theta_s": p["theta_s"]}
            if m == "fopdt":
                return {"K": p["K"], "tau1_s": 0.8 * p["tau_s"], "tau2_s": 0.2 * p["tau_s"],
                        "theta_s": p["theta_s"]}
            return None
        if m == "underdamped":
            return {k: p[k] for k in PARAMS["underdamped"]}
    except KeyError:
        return None
    return None
