"""Siglent SDS exports: ``Record Length,Analog:N`` header lines, then ``Second,Volt,...``.
"""

from __future__ import annotations

from .layout import split_cells, first_cells, Layout, not_this, read_table

__all__ = []


def read_siglent(lines, name, forced=False) -> Layout:
    """Siglent SDS: ``Record Length,Analog:N`` and other ``key,value`` lines,
    ``Second,Volt[,Volt...]``, then time and values."""
    if forced and first_cells(lines)[:1] != ["record length"]:
        raise not_this(name, "siglent", 0, lines, "is not 'Record Length,Analog:<n>'")
    lay = read_table(lines, name, "siglent", forced)
    names = []
    for k in range(lay.first_row):
        c = split_cells(lines[k], ",")
        if c and c[0].lower() == "source":
            names = c[1:]
    n = len(lay.columns) - 1
    if len(names) != n:
        names = [f"CH{j + 1}" for j in range(n)]
    lay.columns = ["TIME", *names]
    return lay
