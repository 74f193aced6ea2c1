"""JSON at the edge: results become plain JSON values here (numpy scalars to
Python numbers, nan and inf to null)."""

from __future__ import annotations

import math

import numpy as np


def json_safe(obj):
    """JSON-ready copy: numpy scalars to Python numbers, nan/inf to None."""
    if isinstance(obj, dict):
        return {k: json_safe(v) for k, v in obj.items()}
    if isinstance(obj, (list, tuple)):
        return [json_safe(v) for v in obj]
    if isinstance(obj, np.ndarray):
        return json_safe(obj.tolist())
    if isinstance(obj, np.bool_):
        return bool(obj)
    if isinstance(obj, (np.floating, np.integer)):
        obj = obj.item()
    if isinstance(obj, float) and not math.isfinite(obj):
        return None
    return obj
