"""Which reader reads a capture: the registry of the layouts, tried in the order
of :data:`FORMATS` (generic last), each recognised by its header signature.
"""

from __future__ import annotations

from ...core.errors import DesignError
from ...core.fileio import show_cell
from .digilent import read_digilent
from .keysight import read_keysight
from .layout import FORMAT_NAMES, FORMATS, first_cells, Layout, read_generic, read_table, read_waveform
from .picoscope import pico_units, read_picoscope
from .rigol import detect_rigol_no_x, read_rigol, read_rigol_no_x
from .siglent import read_siglent
from .tektronix import is_tds, read_tektronix_mso, read_tektronix_tds

__all__ = ["FORMATS", "FORMAT_NAMES", "check_format"]


_READERS = {"tektronix-tds": read_tektronix_tds, "tektronix-mso": read_tektronix_mso,
            "rigol": read_rigol, "rigol-no-x": read_rigol_no_x, "siglent": read_siglent,
            "keysight": read_keysight, "digilent": read_digilent,
            "picoscope": read_picoscope, "waveform": read_waveform,
            "generic": read_generic}
#: Header signatures of the named layouts (MSO, WaveForms and the project's
#: waveforms are tagged by the table reader itself, from their header lines).
_DETECT = (
    ("tektronix-tds", is_tds),
    ("siglent", lambda ls: first_cells(ls)[:1] == ["record length"]),
    ("rigol", lambda ls: first_cells(ls)[:1] == ["x"] and "increment" in first_cells(ls)),
    ("rigol-no-x", detect_rigol_no_x),
    ("keysight", lambda ls: first_cells(ls)[:1] == ["x-axis"]),
    ("picoscope", lambda ls: len(ls) > 1 and pico_units(ls[1]) is not None),
)


def check_format(fmt) -> str:
    """``fmt`` lowercased if it is ``auto`` or one of :data:`FORMATS`.

    Parameters
    ----------
    fmt : str
        The format named by the user.

    Returns
    -------
    str
        The lowercased format.

    Raises
    ------
    DesignError
        When it is neither ``auto`` nor a known format.
    """
    f = str(fmt).strip().lower()
    if f != "auto" and f not in FORMATS:
        raise DesignError(f"unknown capture format {show_cell(str(fmt))}; allowed: auto, "
                          + ", ".join(FORMATS))
    return f



def detect_layout(lines, name, fmt=None) -> Layout:
    """The layout of a capture from its first lines: the first format of
    :data:`FORMATS` whose signature the header shows, or ``fmt`` when given."""
    if fmt is not None:
        fmt = check_format(fmt)
        if fmt != "auto":
            return _READERS[fmt](lines, name, forced=True)
    for key, detect in _DETECT:
        if detect(lines):
            return _READERS[key](lines, name)
    return read_table(lines, name)
