"""Writing captures: the generic ``t,[u,]y`` CSV (fixtures and round-trip tests).
"""

from __future__ import annotations

import numpy as np

__all__ = ["format_generic"]


def format_generic(t, y, u=None, *, delimiter=",", header=True, decimal_comma=False) -> str:
    """Text of a generic ``t,[u,]y`` CSV (used by fixtures and round-trip tests).

    Parameters
    ----------
    t, y : array_like
        Times (s) and output.
    u : array_like, optional
        Input column.
    delimiter : str, optional
        Cell separator.
    header : bool, optional
        Write a ``t,u,y`` header row.
    decimal_comma : bool, optional
        Write decimal commas.

    Returns
    -------
    str
        The CSV text, one row per sample.
    """
    cols = [np.asarray(t, float)] + ([np.asarray(u, float)] if u is not None else []) \
        + [np.asarray(y, float)]
    names = ["t", "u", "y"] if u is not None else ["t", "y"]
    rows = []
    if header:
        rows.append(delimiter.join(names))
    for vals in zip(*cols):
        cells = [f"{v:.9g}" for v in vals]
        if decimal_comma:
            cells = [c.replace(".", ",") for c in cells]
        rows.append(delimiter.join(cells))
    return "\n".join(rows) + "\n"
