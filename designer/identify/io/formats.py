"""Which reader reads a capture: the registry of the layouts, tried in the order
of :data:`FORMATS` (generic last), each recognised by its header signature.
"""

from __future__ import annotations

from ...core.errors import DesignError
from ...core.fileio import show_cell
from .digilent import _read_digilent
from .keysight import _read_keysight
from .layout import FORMAT_NAMES, FORMATS, _first_cells, _Layout, _read_generic, _read_table, _read_waveform
from .picoscope import _pico_units, _read_picoscope
from .rigol import _detect_rigol_no_x, _read_rigol, _read_rigol_no_x
from .siglent import _read_siglent
from .tektronix import _is_tds, _read_tektronix_mso, _read_tektronix_tds

__all__ = ["FORMATS", "FORMAT_NAMES", "check_format"]


_READERS = {"tektronix-tds": _read_tektronix_tds, "tektronix-mso": _read_tektronix_mso,
            "rigol": _read_rigol, "rigol-no-x": _read_rigol_no_x, "siglent": _read_siglent,
            "keysight": _read_keysight, "digilent": _read_digilent,
            "picoscope": _read_picoscope, "waveform": _read_waveform,
            "generic": _read_generic}
#: Header signatures of the named layouts (MSO, WaveForms and the project's
#: waveforms are tagged by the table reader itself, from their header lines).
_DETECT = (
    ("tektronix-tds", _is_tds),
    ("siglent", lambda ls: _first_cells(ls)[:1] == ["record length"]),
    ("rigol", lambda ls: _first_cells(ls)[:1] == ["x"] and "increment" in _first_cells(ls)),
    ("rigol-no-x", _detect_rigol_no_x),
    ("keysight", lambda ls: _first_cells(ls)[:1] == ["x-axis"]),
    ("picoscope", lambda ls: len(ls) > 1 and _pico_units(ls[1]) is not None),
)


def check_format(fmt) -> str:
    """``fmt`` lowercased if it is ``auto`` or one of :data:`FORMATS`."""
    f = str(fmt).strip().lower()
    if f != "auto" and f not in FORMATS:
        raise DesignError(f"unknown capture format {show_cell(str(fmt))}; allowed: auto, "
                          + ", ".join(FORMATS))
    return f



def _layout(lines, name, fmt=None) -> _Layout:
    """The layout of a capture from its first lines: the first format of
    :data:`FORMATS` whose signature the header shows, or ``fmt`` when given."""
    if fmt is not None:
        fmt = check_format(fmt)
        if fmt != "auto":
            return _READERS[fmt](lines, name, forced=True)
    for key, detect in _DETECT:
        if detect(lines):
            return _READERS[key](lines, name)
    return _read_table(lines, name)
