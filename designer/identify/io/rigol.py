"""Rigol DS/MSO exports: a ``Start,Increment`` header and a sample index
(or no time column at all); time is start + index * increment.
"""

from __future__ import annotations

import numpy as np

from ...core.errors import DesignError
from ...core.fileio import show_cell
from ..edges import number_text
from .layout import split_cells, first_cells, Layout, not_this

__all__ = []


def _rigol_header(lines, name, fmt, forced):
    head = split_cells(lines[0], ",")
    low = [h.lower() for h in head]
    if "start" not in low or "increment" not in low:
        raise not_this(name, fmt, 0, lines, "is not the header "
                        + ("X," if fmt == "rigol" else "") + "CH1,...,Start,Increment,")
    if len(lines) < 3:
        raise DesignError(f"{name}: Rigol export has a header but no samples")
    second = split_cells(lines[1], ",")
    try:
        i_start, i_inc = low.index("start"), low.index("increment")
        start, inc = float(second[i_start]), float(second[i_inc])
    except (ValueError, IndexError):
        raise DesignError(f"{name}: Rigol header line 2 must carry the Start and Increment "
                          f"values under 'Start' and 'Increment'; got "
                          f"{show_cell(lines[1])}") from None
    if not (np.isfinite(inc) and inc > 0):
        raise DesignError(f"{name}: Rigol time increment must be a positive number; "
                          f"got {number_text(inc)}")
    if not np.isfinite(start):
        raise DesignError(f"{name}: Rigol start time must be a finite number; "
                          f"got {number_text(start)}")
    return head, i_start, start, inc


def read_rigol(lines, name, forced=False) -> Layout:
    """Rigol DS1000Z: ``X,CH1[,CH2...],Start,Increment,`` /
    ``Sequence,Volt,...,<start>,<inc>,`` then the sample index and the values;
    time is start + index * increment."""
    if forced and first_cells(lines)[:1] != ["x"]:
        raise not_this(name, "rigol", 0, lines, "is not the header X,CH1,...,Start,Increment,")
    head, i_start, start, inc = _rigol_header(lines, name, "rigol", forced)
    channels = head[1:i_start]
    return Layout(["TIME", *channels], "rigol", 2, ",", list(range(1 + len(channels))),
                   time_axis=(start, inc))


def read_rigol_no_x(lines, name, forced=False) -> Layout:
    """Rigol without the index column: ``CH1[,CH2...],Start,Increment,`` /
    ``Volt,...,<start>,<inc>``, then the values only; time is
    start + row * increment."""
    head, i_start, start, inc = _rigol_header(lines, name, "rigol-no-x", forced)
    channels = head[:i_start]
    if not channels:
        raise not_this(name, "rigol-no-x", 0, lines, "names no channel before Start")
    return Layout(["TIME", *channels], "rigol-no-x", 2, ",",
                   [None] + list(range(len(channels))), time_axis=(start, inc))



def detect_rigol_no_x(lines) -> bool:
    c = first_cells(lines)
    return bool(c) and c[0] != "x" and "start" in c and "increment" in c
