"""The table layouts every capture reader builds on.

A reader turns the first lines of a file (its header block) into a
:class:`Layout`: which file columns hold time and the signals, where the
samples start, the delimiter and decimal mark. The generic reader
(:func:`read_table`: header or comment lines, then rows of numbers) is the
base of the vendor readers of this package (:mod:`.tektronix`, :mod:`.rigol`,
:mod:`.siglent`, :mod:`.keysight`, :mod:`.picoscope`, :mod:`.digilent`); this
project's own waveforms (``time_s,<signal>,...``) are read here too.
"""

from __future__ import annotations

from dataclasses import dataclass

from ...core.errors import DesignError
from ...core.fileio import show_cell

__all__ = ["FORMAT_NAMES", "FORMATS"]


#: Every layout recognised, in the order they are tried (generic last).
FORMATS = ("tektronix-tds", "tektronix-mso", "rigol", "rigol-no-x", "siglent", "keysight",
           "digilent", "picoscope", "waveform", "generic")
#: What each is, for messages and ``--help``.
FORMAT_NAMES = {"tektronix-tds": "Tektronix TDS/TBS", "tektronix-mso": "Tektronix MSO/DPO",
                "rigol": "Rigol DS1000Z (X column)", "rigol-no-x": "Rigol (no X column)",
                "siglent": "Siglent SDS", "keysight": "Keysight/Agilent InfiniiVision",
                "digilent": "Digilent WaveForms", "picoscope": "PicoScope",
                "waveform": "design-plant/design-pid waveforms", "generic": "generic CSV"}


@dataclass
class Layout:
    """Where the samples are: ``columns`` names time and the signals;
    ``file_cols`` the file column of each; ``first_row`` the head line where the
    samples start; ``time_axis`` (start, increment) when the time column is a
    sample index (Rigol), or when there is no time column (``file_cols[0]`` is
    None: time is start + row * increment); ``comma`` when the samples write
    decimal commas; ``scales`` the unit of each column (PicoScope's units row)."""

    columns: list
    fmt: str
    first_row: int
    delim: str
    file_cols: list
    time_axis: tuple | None = None
    comma: bool = False
    scales: list | None = None
    named: bool = True   # False when the file has no header: the column names were made up



def split_cells(line: str, delim: str) -> list:
    cells = [c.strip().strip('"').strip() for c in line.split(delim)]
    while cells and cells[-1] == "":
        cells.pop()
    return cells


def is_number(cell: str) -> bool:
    try:
        float(cell)
    except ValueError:
        return False
    return True


def first_cells(lines, k: int = 0) -> list:
    """The comma-separated cells of line ``k``, lowercase ([] past the end)."""
    return [c.lower() for c in split_cells(lines[k], ",")] if k < len(lines) else []


def delimiter_of(lines: list) -> str:
    # the last lines are samples; comment and blank lines say nothing
    sample = [ln for ln in lines if ln.strip() and not ln.lstrip().startswith("#")][-20:]
    counts = {d: sum(line.count(d) for line in sample) for d in (";", "\t", ",")}
    if counts[";"]:
        return ";"
    if counts["\t"]:
        return "\t"
    if counts[","]:
        return ","
    return "whitespace"


def _decimal_comma(lines: list, delim: str) -> bool:
    """True when the samples write decimal commas (a ``;``, tab or space
    separated file from a European locale)."""
    if delim == ",":
        return False
    sample = [ln for ln in lines if ln.strip() and not ln.lstrip().startswith("#")][-20:]
    return any("," in ln for ln in sample)


def split_line(line: str, delim: str, comma: bool = False) -> list:
    line = line.split("#", 1)[0]
    cells = line.split() if delim == "whitespace" else split_cells(line, delim)
    if comma or delim == ";":
        cells = [c.replace(",", ".") for c in cells]
    return cells


def _numeric_row(line: str, delim: str, comma: bool) -> bool:
    cells = split_line(line, delim, comma)
    return len(cells) >= 2 and all(is_number(c) for c in cells)


def _data_start(lines, delim, comma, limit: int = 400):
    """The first head line from which every row is numeric (checking a few rows
    ahead, so a lone numeric header value is not taken for the data start), or None."""
    for i, line in enumerate(lines[:limit]):
        if _numeric_row(line, delim, comma) and all(
                _numeric_row(a, delim, comma) for a in lines[i + 1:i + 4]):
            return i
    return None


def not_this(name, fmt, k, lines, what) -> DesignError:
    """The one line of a file that does not fit a forced (or recognised) format."""
    line = lines[k] if k < len(lines) else ""
    return DesignError(f"{name}: not a {FORMAT_NAMES[fmt]} export: line {k + 1} "
                       f"({show_cell(line)}) {what}")


def _fit_failure(lines, delim, comma) -> tuple:
    """(line index, text) of the first line that is neither a comment, a blank,
    the one header line before the samples, nor a row of numbers."""
    rows = [i for i, ln in enumerate(lines) if ln.split("#", 1)[0].strip()]
    for n, i in enumerate(rows):
        if _numeric_row(lines[i], delim, comma):
            continue
        # a single header right before numeric rows fits the generic layout
        nxt = rows[n + 1] if n + 1 < len(rows) else None
        if n == 0 and nxt is not None and _numeric_row(lines[nxt], delim, comma):
            continue
        return i, lines[i]
    return rows[0] if rows else 0, lines[rows[0]] if rows else ""


def read_table(lines, name, fmt: str | None = None, forced: bool = False) -> Layout:
    """Generic table, project waveforms, Tektronix MSO/DPO, Digilent WaveForms:
    header or comment lines, then rows of numbers."""
    delim = delimiter_of(lines)
    comma = _decimal_comma(lines, delim)
    first_row = _data_start(lines, delim, comma)
    if first_row is None:
        probe = split_line(lines[min(len(lines) - 1, 1)], delim, comma)
        if len(lines) <= 1 and probe and not all(is_number(c) for c in probe):
            raise DesignError(f"{name}: the file has a header but no data rows")
        if len(probe) < 2 and all(is_number(c) for c in probe):
            raise DesignError(f"{name}: rows need at least two columns (time and output); "
                              f"line {min(len(lines), 2)} has {len(probe)}")
        k, line = _fit_failure(lines, delim, comma)
        if forced and fmt:
            raise not_this(name, fmt, k, lines, "is not a row of numbers, and no numeric "
                            "table follows the header")
        raise DesignError(f"{name}: not a capture in a known format (tried "
                          f"{', '.join(FORMATS)}): line {k + 1} ({show_cell(line)}) fits "
                          "none of them; expected rows of numbers t,y or t,u,y after at most "
                          "a header")
    ncols = len(split_line(lines[first_row], delim, comma))
    header = split_line(lines[first_row - 1], delim) if first_row > 0 else []
    named = len(header) >= ncols and not all(is_number(c) for c in header)
    if named:
        columns = header[:ncols]
    else:
        columns = ["t"] + [f"col{j + 1}" for j in range(1, ncols)]
        if ncols == 2:
            columns = ["t", "y"]
        elif ncols == 3:
            columns = ["t", "u", "y"]
    if columns[0].lower().startswith(("freq", "frequency")):
        raise DesignError(f"{name}: a frequency-response (Bode) table, not a time capture: its "
                          f"first column is {show_cell(columns[0])}; read it with identify-freq")
    if fmt is None:
        if any(first_cells(lines, k)[:1] == ["model"] for k in range(first_row)):
            fmt = "tektronix-mso"
        elif columns and columns[0].lower() == "time_s":
            fmt = "waveform"
        elif any(ln.lower().startswith("#digilent waveforms") for ln in lines[:first_row]):
            fmt = "digilent"
        else:
            fmt = "generic"
    return Layout(columns, fmt, first_row, delim, list(range(ncols)), comma=comma, named=named)


def read_generic(lines, name, forced=False) -> Layout:
    return read_table(lines, name, "generic", forced)


def headed_table(fmt: str, first_cell, header: str):
    """The reader of a table layout whose header row's first cell passes
    ``first_cell`` (checked when the format is forced: ``header`` says what it
    should be)."""
    def read(lines, name, forced=False) -> Layout:
        lay = read_table(lines, name, fmt, forced)
        if forced and not first_cell(lay.columns[0].lower()):
            raise not_this(name, fmt, max(lay.first_row - 1, 0), lines,
                            f"is not the header {header}")
        return lay
    read.__doc__ = f"{fmt}: header lines, then {header} and the samples."
    return read


#: This project's waveforms (``time_s,<signal>,...``).
read_waveform = headed_table("waveform", lambda c: c == "time_s", "time_s,<signal>,...")
