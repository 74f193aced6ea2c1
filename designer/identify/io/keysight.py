"""Keysight/Agilent InfiniiVision exports: ``x-axis,1,2,...`` / ``second,Volt,...``.
"""

from __future__ import annotations

from .layout import split_cells, first_cells, Layout, not_this, read_table

__all__ = []


def read_keysight(lines, name, forced=False) -> Layout:
    """Keysight/Agilent InfiniiVision: ``x-axis,1[,2...]`` / ``second,Volt[,Volt...]``,
    then time and values (channel numbers become CH1, CH2...)."""
    if forced and first_cells(lines)[:1] != ["x-axis"]:
        raise not_this(name, "keysight", 0, lines, "is not the header x-axis,1,2,...")
    lay = read_table(lines, name, "keysight", forced)
    labels = split_cells(lines[0], ",")[1:len(lay.columns)]
    lay.columns = ["TIME"] + [f"CH{c}" if c.isdigit() else c for c in labels]
    lay.columns += [f"col{j + 1}" for j in range(len(lay.columns), len(lay.file_cols))]
    return lay
