"""Shared vocabulary of the identification methods: model step responses,
the result record every method returns, and the IAE/ISE indices.

Parameter names (seconds and rad/s in the names, as in the JSON output):
- ``fopdt``       K, tau_s, theta_s           K e^(-theta s) / (tau s + 1)
- ``double-pole`` K, tau_s, theta_s           K e^(-theta s) / (tau s + 1)^2
- ``underdamped`` K, wn_rad_s, zeta, theta_s  K wn^2 e^(-theta s) / (s^2 + 2 zeta wn s + wn^2)
- ``overdamped``  K, tau1_s, tau2_s, theta_s  K e^(-theta s) / ((tau1 s + 1)(tau2 s + 1)),
  tau1 <= tau2 (the fast time constant first, as seeds 002 and 003 write it)
"""

from __future__ import annotations

import math
from dataclasses import dataclass, field

import numpy as np

from ..core.jsonio import json_safe

MODELS = ("fopdt", "double-pole", "underdamped", "overdamped")


def model_step(model: str, params: dict, t) -> np.ndarray:
    """Unit-input step response (0 -> K) of ``model`` at times ``t`` (step at t = 0)."""
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
    response grows without bound (exp overflows), so it is never evaluated."""
    for k, v in params.items():
        if (k.startswith("tau") or k == "wn_rad_s") and not v > 0:
            return f"{k} = {v:.4g} is not positive"
        if k == "zeta" and not v >= 0:
            return f"zeta = {v:.4g} is negative"
    return ""


def iae_ise(t, y, y_model):
    """Integral of |error| and of error^2 over the record (trapezoid rule)."""
    e = np.asarray(y, float) - np.asarray(y_model, float)
    t = np.asarray(t, float)
    return float(np.trapezoid(np.abs(e), t)), float(np.trapezoid(e * e, t))


@dataclass
class MethodResult:
    """What one identification method found.

    ``name`` is a lowercase author or technique name (``smith``, ``alfaro``,
    ``least-squares``...); ``points`` are the data points the method used
    (e.g. ``{"t28_s": ..., "t63_s": ...}``); ``valid`` is False when the data lie
    outside the method's validity range, and ``note`` then says why.
    """

    name: str
    model: str
    params: dict
    iae: float = math.nan
    ise: float = math.nan
    valid: bool = True
    note: str = ""
    points: dict = field(default_factory=dict)

    def to_dict(self) -> dict:
        return json_safe({"name": self.name, "model": self.model, "params": self.params,
                          "iae": self.iae, "ise": self.ise, "valid": bool(self.valid),
                          "note": self.note, "points": self.points})


def rank_key(m: MethodResult) -> tuple:
    """Sort key of a ranking: valid results first, then by ``iae`` (nan last)."""
    iae = m.iae if m.iae is not None and math.isfinite(m.iae) else math.inf
    return (not m.valid, iae)
