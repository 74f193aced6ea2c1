"""PicoScope exports: ``Time,Channel A,...`` and a units row such as ``(ms),(V)``.
"""

from __future__ import annotations

from .layout import split_cells, delimiter_of, Layout, not_this, read_table

__all__ = []


#: A PicoScope units cell, in seconds or volts per unit.
_PICO_UNITS = {"s": 1.0, "ms": 1e-3, "us": 1e-6, "µs": 1e-6, "μs": 1e-6, "ns": 1e-9,
               "ps": 1e-12, "v": 1.0, "mv": 1e-3, "uv": 1e-6, "µv": 1e-6, "μv": 1e-6}


def pico_units(line) -> list | None:
    """The scales of a PicoScope units row such as ``(ms),(V),(mV)``, or None."""
    cells = split_cells(line, delimiter_of([line]) if "\t" in line or ";" in line else ",")
    if len(cells) < 2 or not all(c.startswith("(") and c.endswith(")") for c in cells):
        return None
    scales = [_PICO_UNITS.get(c[1:-1].strip().lower()) for c in cells]
    return None if any(s is None for s in scales) else scales


def read_picoscope(lines, name, forced=False) -> Layout:
    """PicoScope: ``Time,Channel A[,Channel B...]``, a units row ``(ms),(V)...``
    (honoured: time in seconds, values in volts), maybe a blank line, then samples."""
    scales = pico_units(lines[1]) if len(lines) > 1 else None
    if forced and scales is None:
        raise not_this(name, "picoscope", 1, lines, "is not a units row such as (ms),(V)")
    lay = read_table(lines, name, "picoscope", forced)
    lay.columns = split_cells(lines[0], lay.delim if lay.delim != "whitespace" else ",")[
        :len(lay.file_cols)]
    lay.scales = scales[:len(lay.file_cols)]
    return lay
