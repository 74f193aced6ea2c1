"""Shared vocabulary of the identification methods: the result record every
method returns and the IAE/ISE indices. The process models, their parameter
names and their step responses come from :mod:`designer.core.stepfit`."""

from __future__ import annotations

import math
from dataclasses import dataclass, field

import numpy as np

from ..core.jsonio import json_safe
from ..core.stepfit import MODELS, model_step, unphysical  # noqa: F401  (the methods' vocabulary)

__all__ = ["MODELS", "MethodResult", "iae_ise", "model_step"]


def iae_ise(t, y, y_model):
    """Integral of |error| and of error^2 over the record (trapezoid rule).

    Parameters
    ----------
    t, y : array_like
        The record's time (s) and output.
    y_model : array_like
        The model's output at the same times.

    Returns
    -------
    tuple of (float, float)
        IAE and ISE.
    """
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


def assessment_dict(assessment) -> dict:
    """The JSON keys an assessed result adds (:class:`~designer.identify.assess.Assessment`):
    ``validation`` (the split, every route's models with their validation fit and
    residual tests, the best by validation fit) and ``output_error`` (the
    output-error fits, route ``"output-error"``)."""
    return {"validation": assessment.to_dict(),
            "output_error": [{"route": "output-error", **f.to_dict()} for f in assessment.output_error]}
