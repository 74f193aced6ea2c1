"""Least-squares refinement of FOPDT, overdamped and underdamped models with
dead time, as identification methods.

The classical methods read a few points off the curve; least squares uses all
of it (:func:`designer.core.stepfit.fit_step`, which explains the solver, the
bounds and the confidence intervals). Each fit starts from the best-IAE
classical estimate of a compatible model when the orchestrator passes one.
The 95 % half-widths are stored in ``points`` as ``<param>_ci95`` and
summarised in the note.
"""

from __future__ import annotations

import math

from ..core.stepfit import PARAMS, fit_step
from .structures import MethodResult

__all__ = ["fit", "refine_all"]


def fit(model: str, t, y, yf, start: dict | None = None, sigma=None,
        overshoot=None) -> MethodResult:
    """:func:`~designer.core.stepfit.fit_step` as a :class:`MethodResult` named ``least-squares``.

    Parameters
    ----------
    model : str
        ``fopdt``, ``underdamped`` or ``overdamped``.
    t, y : array_like
        Times after the step (s) and the response.
    yf : float
        The response's final value.
    start : dict, optional
        Starting parameters.
    sigma : float, optional
        Noise standard deviation of ``y``.
    overshoot : Overshoot, optional
        The record's overshoot when the caller measured it.

    Returns
    -------
    MethodResult
        The fit, with its validity and note.
    """
    f = fit_step(model, t, y, yf, start, sigma, overshoot)
    points = {f"{k}_ci95": v for k, v in f.ci95.items()}
    points["samples_fitted"] = f.samples
    points["rms_residual"] = f.rms_residual
    ci_txt = ", ".join(f"{k} ±{v:.3g}" for k, v in f.ci95.items() if math.isfinite(v))
    note = "; ".join(s for s in (f.note, f"95 % CI: {ci_txt}" if ci_txt else "") if s)
    return MethodResult("least-squares", model, dict(f.params), valid=f.valid, note=note, points=points)


def refine_all(t, y, yf, starts: dict | None = None, sigma=None, overshoot=None) -> list:
    """The three least-squares fits, each from ``starts[model]`` (a MethodResult) if given;
    ``sigma`` is the noise of ``y`` and ``overshoot`` the
    :class:`~designer.core.metrics.Overshoot` of the record when the caller measured them.

    Parameters
    ----------
    t, y : array_like
        Times after the step (s) and the response.
    yf : float
        The response's final value.
    starts : dict, optional
        Model name -> MethodResult to start from.
    sigma : float, optional
        Noise standard deviation of ``y``.
    overshoot : Overshoot, optional
        The record's overshoot.

    Returns
    -------
    list of MethodResult
        One fit per model.
    """
    starts = starts or {}
    out = []
    for model in PARAMS:
        s = starts.get(model)
        start = {"model": s.model, "params": s.params} if s is not None else None
        out.append(fit(model, t, y, yf, start, sigma, overshoot))
    return out
