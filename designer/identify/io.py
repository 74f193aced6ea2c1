"""Reading the measurements identification starts from: step-response
captures and frequency-response (Bode) tables.

Step-response captures
----------------------
One entry point, :func:`read_capture`, recognises the layouts a student or CI
actually has and returns a :class:`Capture` (time, output and optional input):

- generic ``t,y`` or ``t,u,y`` tables, with or without a header line, comma,
  semicolon (decimal comma allowed) or tab separated;
- the waveforms this project writes: header ``time_s,<signal>,...``;
- Tektronix TDS/TBS exports (``Record Length,...`` header block carried in
  columns 1-3 of the first rows, time and value in columns 4 and 5);
- Tektronix MSO/DPO exports (``Model,...`` key/value lines, then a
  ``TIME,CH1,...`` header and the samples);
- Rigol DS/MSO exports (``X,CH1,Start,Increment,`` then
  ``Sequence,Volt,<start>,<increment>,`` then sample index and values; time is
  start + index * increment).

Which signal is the input and which the output: by name when the header names
them (``u``, ``vin``, ``in``... and ``y``, ``vout``, ``out``...), otherwise by
position (``t,u,y``: the first signal is the input, the last the output; one
signal is the output). ``input_column``/``output_column`` override both.

Files are streamed, never read whole: the layout is recognised from the first
lines, then the samples are parsed a block at a time by numpy's C parser, and
only the (at most three) columns used are kept, so memory is about 8 bytes per
kept value however long the file is. Size, encoding and non-regular files
(a directory, ``/dev/zero``, a FIFO) are handled by :mod:`designer.core.fileio`; the
checks on the samples themselves (finite, increasing time, physical ranges)
are :func:`.preprocess.check_samples`.

Frequency-response tables
-------------------------
:func:`read_freq_table` (:func:`parse_freq_table` for text) reads a table of
frequency, gain (dB or amplitude ratio) and optionally phase (degrees,
radians, or the time shift of the output behind the input, as seed 000
Table IV measures it: phase = -360 f dt degrees) into a :class:`FreqData`.
Every row's values are checked against their physical ranges
(``RANGES["freq_hz"]``, ``["gain_db"]`` or ``["gain_ratio"]``,
``["phase_deg"]``) before any arithmetic, so no overflow reaches the fits.
"""

from __future__ import annotations

import bisect
import io
import math
import re
from dataclasses import dataclass, field

import numpy as np

from ..core.errors import DesignError
from ..core.fileio import (
    BLOCK_BYTES,
    MAX_CAPTURE_BYTES,
    MAX_CAPTURE_ROWS,
    MAX_LINE_BYTES,
    MAX_TABLE_BYTES,
    SNIFF_BYTES,
    check_encoding,
    decode,
    open_limited,
    read_text,
    show_cell,
    shown,
    size_text,
)
from ..core.ranges import RANGES
from .preprocess import check_samples, number_text

#: Header names (lowercase, units stripped) read as the plant input or output.
INPUT_NAMES = ("u", "vin", "v_in", "in", "input", "uin", "u_in", "v(in)", "ve", "step", "source")
OUTPUT_NAMES = ("y", "vout", "v_out", "out", "output", "yout", "y_out", "v(out)", "vs", "response")
TIME_NAMES = ("t", "time", "time_s", "times", "second", "seconds", "s", "x", "tiempo")
#: Lines examined to recognise the layout (header block, delimiter, first data row).
HEAD_LINES = 1000
#: Lines parsed at a time when the text is already in memory.
BLOCK_LINES = 100_000


@dataclass
class Capture:
    """A capture read from a file.

    ``t`` is in seconds as written in the file (it may start before zero, as a
    scope's trigger-relative time does); ``u`` is None when the file has no
    input column. ``fmt`` names the recognised layout; ``columns`` the header
    names (generated ``col1``... when there was no header).
    """

    t: np.ndarray
    y: np.ndarray
    u: np.ndarray | None
    fmt: str
    columns: list = field(default_factory=list)
    output_name: str = ""
    input_name: str | None = None
    source: str = ""
    notes: list = field(default_factory=list)

    def info(self) -> CaptureInfo:
        """What the capture is, without its samples (kept with a result)."""
        return CaptureInfo(self.fmt, tuple(self.columns), int(self.t.size), self.output_name,
                           self.input_name, self.source, tuple(self.notes))


@dataclass(frozen=True)
class CaptureInfo:
    """Where a step response came from: layout, columns, samples, which column
    is the output (and the input), the file and the reader's notes."""

    fmt: str
    columns: tuple
    samples: int
    output_name: str
    input_name: str | None = None
    source: str = ""
    notes: tuple = ()

    def to_dict(self) -> dict:
        return {"format": self.fmt, "columns": list(self.columns), "samples": self.samples,
                "output": self.output_name, "input": self.input_name, "source": self.source,
                "notes": list(self.notes)}


def read_capture(path, *, input_column=None, output_column=None, fmt=None) -> Capture:
    """Read a step-response capture from ``path``, streaming it.

    Parameters
    ----------
    path : str or Path
        The CSV file (at most :data:`~designer.core.fileio.MAX_CAPTURE_BYTES` bytes and
        :data:`~designer.core.fileio.MAX_CAPTURE_ROWS` data rows).
    input_column, output_column : str or int, optional
        Column name (case-insensitive) or 1-based column number (time is column
        1) of the plant input and output; ``input_column="none"`` ignores any
        input column.
    fmt : str, optional
        One of :data:`FORMATS` to read the file as that layout instead of
        recognising it (``auto``, the default, recognises it).

    Raises
    ------
    DesignError
        Missing, unreadable, too large, binary or UTF-16 file, empty file,
        non-numeric cells, NaN or infinite values, values outside their
        physical ranges, time not strictly increasing, the same column asked
        for as input and output.
    """
    with open_limited(path, "capture file", MAX_CAPTURE_BYTES) as fh:
        head, carry = _read_head(fh)
        cap = _parse(head, _file_blocks(fh, carry), fh.name, input_column, output_column,
                     size_hint=fh.size, fmt=fmt)
    cap.source = str(path)
    return cap


def parse_capture_text(text: str, *, name: str = "capture", input_column=None,
                       output_column=None, fmt=None) -> Capture:
    """Parse the text of a capture file; see :func:`read_capture`."""
    lines = text.lstrip("\ufeff").splitlines()
    head, rest = lines[:HEAD_LINES], lines[HEAD_LINES:]
    blocks = ((b, _flags(b)) for b in (rest[i:i + BLOCK_LINES]
                                       for i in range(0, len(rest), BLOCK_LINES)))
    return _parse(head, blocks, name, input_column, output_column,
                  size_hint=None if not rest else len(text), fmt=fmt)


# --------------------------------------------------------------------------- streaming

def _flags(lines) -> tuple:
    """(may hold comment or blank lines, has quotes) of a block of lines."""
    text = "\n".join(lines)
    return ("#" in text or "" in lines), '"' in text


def _read_head(fh) -> tuple:
    """The first lines of the file (at least HEAD_LINES unless it is shorter, at
    most about MAX_LINE_BYTES of them), decoded, and the bytes that follow them."""
    buf = fh.read(SNIFF_BYTES) or b""
    bom = check_encoding(buf, fh.name, fh.what)
    eof = not buf
    while not eof and buf.count(b"\n") < HEAD_LINES and len(buf) <= MAX_LINE_BYTES:
        more = fh.read(SNIFF_BYTES)
        eof = not more
        buf += more or b""
    if eof:
        return decode(buf[bom:]).splitlines(), b""
    cut = buf.rfind(b"\n")
    if cut < 0:
        raise DesignError(f"capture file {fh.name} has no line break in its first "
                          f"{size_text(len(buf))}: not a CSV text file")
    return decode(buf[bom:cut + 1]).splitlines(), buf[cut + 1:]


def _text_flags(text: str) -> tuple:
    """:func:`_flags` of a block given as text (no list of lines made)."""
    gaps = "#" in text or "\n\n" in text or "\n\r\n" in text or text.startswith(("\n", "\r"))
    return gaps, '"' in text


def _file_blocks(fh, carry: bytes):
    """The rest of the file as blocks of decoded text (about BLOCK_BYTES each, whole
    lines), each with its :func:`_flags`; a line longer than MAX_LINE_BYTES is refused.
    Kept as text: numpy's parser splits the lines itself, a list of a million
    strings costs a tenth of a second per 50 MB."""
    while True:
        data = fh.read(BLOCK_BYTES)
        if not data:
            if carry.strip():
                text = decode(carry)
                yield text, _text_flags(text)
            return
        buf = carry + data
        cut = buf.rfind(b"\n")
        if cut < 0:
            if len(buf) > MAX_LINE_BYTES:
                raise DesignError(f"capture file {fh.name} has a line longer than "
                                  f"{size_text(MAX_LINE_BYTES)}: not a CSV text file")
            carry = buf
            continue
        carry = buf[cut + 1:]
        text = decode(buf[:cut + 1])
        yield text, _text_flags(text)


@dataclass
class _Layout:
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


def _parse(head, blocks, name, input_column, output_column, size_hint=None,
           fmt=None) -> Capture:
    first = next(blocks, None)
    lines = list(head)
    if first is None:
        # Trailing blank lines are common (and harmless) in exports.
        while lines and not lines[-1].strip():
            lines.pop()
    if not lines:
        raise DesignError(f"{name}: the file is empty; expected CSV rows of time and output "
                          "(t,y or t,u,y)")
    layout = _layout(lines, name, fmt)
    j_out, j_in, tentative = _choose_columns(layout.columns, input_column, output_column, name)
    keep = [0, j_out] + ([j_in] if j_in is not None else [])
    more = _then(first, blocks) if first is not None else iter(())
    del first   # the block is the generator's now: freed once parsed
    cols = _load(lines, layout, keep, more, name, size_hint)
    return _assemble(cols, layout, keep, tentative, name)


def _then(first, rest):
    """``first``, then the items of ``rest``, holding no reference to ``first``
    once it is consumed (a parsed block is freed before the next is read)."""
    box = [first]
    del first
    yield box.pop()
    yield from rest


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


# --------------------------------------------------------------------------- layouts

def _cells(line: str, delim: str) -> list:
    cells = [c.strip().strip('"').strip() for c in line.split(delim)]
    while cells and cells[-1] == "":
        cells.pop()
    return cells


def _is_number(cell: str) -> bool:
    try:
        float(cell)
    except ValueError:
        return False
    return True


def _first_cells(lines, k: int = 0) -> list:
    """The comma-separated cells of line ``k``, lowercase ([] past the end)."""
    return [c.lower() for c in _cells(lines[k], ",")] if k < len(lines) else []


def _delimiter(lines: list) -> str:
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


def _split(line: str, delim: str, comma: bool = False) -> list:
    line = line.split("#", 1)[0]
    cells = line.split() if delim == "whitespace" else _cells(line, delim)
    if comma or delim == ";":
        cells = [c.replace(",", ".") for c in cells]
    return cells


def _numeric_row(line: str, delim: str, comma: bool) -> bool:
    cells = _split(line, delim, comma)
    return len(cells) >= 2 and all(_is_number(c) for c in cells)


def _data_start(lines, delim, comma, limit: int = 400):
    """The first head line from which every row is numeric (checking a few rows
    ahead, so a lone numeric header value is not taken for the data start), or None."""
    for i, line in enumerate(lines[:limit]):
        if _numeric_row(line, delim, comma) and all(
                _numeric_row(a, delim, comma) for a in lines[i + 1:i + 4]):
            return i
    return None


def _not_this(name, fmt, k, lines, what) -> DesignError:
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


def _read_table(lines, name, fmt: str | None = None, forced: bool = False) -> _Layout:
    """Generic table, project waveforms, Tektronix MSO/DPO, Digilent WaveForms:
    header or comment lines, then rows of numbers."""
    delim = _delimiter(lines)
    comma = _decimal_comma(lines, delim)
    first_row = _data_start(lines, delim, comma)
    if first_row is None:
        probe = _split(lines[min(len(lines) - 1, 1)], delim, comma)
        if len(lines) <= 1 and probe and not all(_is_number(c) for c in probe):
            raise DesignError(f"{name}: the file has a header but no data rows")
        if len(probe) < 2 and all(_is_number(c) for c in probe):
            raise DesignError(f"{name}: rows need at least two columns (time and output); "
                              f"line {min(len(lines), 2)} has {len(probe)}")
        k, line = _fit_failure(lines, delim, comma)
        if forced and fmt:
            raise _not_this(name, fmt, k, lines, "is not a row of numbers, and no numeric "
                            "table follows the header")
        raise DesignError(f"{name}: not a capture in a known format (tried "
                          f"{', '.join(FORMATS)}): line {k + 1} ({show_cell(line)}) fits "
                          "none of them; expected rows of numbers t,y or t,u,y after at most "
                          "a header")
    ncols = len(_split(lines[first_row], delim, comma))
    header = _split(lines[first_row - 1], delim) if first_row > 0 else []
    if len(header) >= ncols and not all(_is_number(c) for c in header):
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
        if any(_first_cells(lines, k)[:1] == ["model"] for k in range(first_row)):
            fmt = "tektronix-mso"
        elif columns and columns[0].lower() == "time_s":
            fmt = "waveform"
        elif any(ln.lower().startswith("#digilent waveforms") for ln in lines[:first_row]):
            fmt = "digilent"
        else:
            fmt = "generic"
    return _Layout(columns, fmt, first_row, delim, list(range(ncols)), comma=comma)


def _read_generic(lines, name, forced=False) -> _Layout:
    return _read_table(lines, name, "generic", forced)


def _headed_table(fmt: str, first_cell, header: str):
    """The reader of a table layout whose header row's first cell passes
    ``first_cell`` (checked when the format is forced: ``header`` says what it
    should be)."""
    def read(lines, name, forced=False) -> _Layout:
        lay = _read_table(lines, name, fmt, forced)
        if forced and not first_cell(lay.columns[0].lower()):
            raise _not_this(name, fmt, max(lay.first_row - 1, 0), lines,
                            f"is not the header {header}")
        return lay
    read.__doc__ = f"{fmt}: header lines, then {header} and the samples."
    return read


#: This project's waveforms (``time_s,<signal>,...``), Tektronix MSO/DPO
#: (``Model,...`` key/value lines, then ``TIME,CH1,...``), Digilent WaveForms
#: (``#`` comment lines, then ``Time (s),Channel 1 (V),...``).
_read_waveform = _headed_table("waveform", lambda c: c == "time_s", "time_s,<signal>,...")
_read_tektronix_mso = _headed_table("tektronix-mso", lambda c: c == "time", "TIME,CH1,...")
_read_digilent = _headed_table("digilent", lambda c: c.startswith("time"),
                               "Time (s),Channel 1 (V),...")


def _is_tds(lines) -> bool:
    c = _cells(lines[0], ",")
    return (len(c) >= 5 and c[0].lower() == "record length" and _is_number(c[3])
            and _is_number(c[4]))


def _read_tektronix_tds(lines, name, forced=False) -> _Layout:
    """TDS/TBS: rows ``label,value,,time,value,``; the header block occupies
    cells 1-3 of the first rows, and a file of several channels repeats the
    six columns for each (the time of the first is used)."""
    if forced and not _is_tds(lines):
        raise _not_this(name, "tektronix-tds", 0, lines, "is not 'Record Length,<n>,,<time>,"
                        "<value>,' (the six-column TDS/TBS layout)")
    first = _cells(lines[0], ",")
    blocks = [b for b in range(0, len(first), 6) if first[b].lower() == "record length"]
    names, cols = ["TIME"], [3]
    for b in blocks:
        meta = {}
        for line in lines[:40]:
            c = [x.strip() for x in line.split(",")]
            if len(c) > b + 1 and c[b]:
                meta[c[b].lower()] = c[b + 1]
        names.append(meta.get("source", f"CH{len(names)}") or f"CH{len(names)}")
        cols.append(b + 4)
    return _Layout(names, "tektronix-tds", 0, ",", cols)


def _rigol_header(lines, name, fmt, forced):
    head = _cells(lines[0], ",")
    low = [h.lower() for h in head]
    if "start" not in low or "increment" not in low:
        raise _not_this(name, fmt, 0, lines, "is not the header "
                        + ("X," if fmt == "rigol" else "") + "CH1,...,Start,Increment,")
    if len(lines) < 3:
        raise DesignError(f"{name}: Rigol export has a header but no samples")
    second = _cells(lines[1], ",")
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


def _read_rigol(lines, name, forced=False) -> _Layout:
    """Rigol DS1000Z: ``X,CH1[,CH2...],Start,Increment,`` /
    ``Sequence,Volt,...,<start>,<inc>,`` then the sample index and the values;
    time is start + index * increment."""
    if forced and _first_cells(lines)[:1] != ["x"]:
        raise _not_this(name, "rigol", 0, lines, "is not the header X,CH1,...,Start,Increment,")
    head, i_start, start, inc = _rigol_header(lines, name, "rigol", forced)
    channels = head[1:i_start]
    return _Layout(["TIME", *channels], "rigol", 2, ",", list(range(1 + len(channels))),
                   time_axis=(start, inc))


def _read_rigol_no_x(lines, name, forced=False) -> _Layout:
    """Rigol without the index column: ``CH1[,CH2...],Start,Increment,`` /
    ``Volt,...,<start>,<inc>``, then the values only; time is
    start + row * increment."""
    head, i_start, start, inc = _rigol_header(lines, name, "rigol-no-x", forced)
    channels = head[:i_start]
    if not channels:
        raise _not_this(name, "rigol-no-x", 0, lines, "names no channel before Start")
    return _Layout(["TIME", *channels], "rigol-no-x", 2, ",",
                   [None] + list(range(len(channels))), time_axis=(start, inc))


def _read_siglent(lines, name, forced=False) -> _Layout:
    """Siglent SDS: ``Record Length,Analog:N`` and other ``key,value`` lines,
    ``Second,Volt[,Volt...]``, then time and values."""
    if forced and _first_cells(lines)[:1] != ["record length"]:
        raise _not_this(name, "siglent", 0, lines, "is not 'Record Length,Analog:<n>'")
    lay = _read_table(lines, name, "siglent", forced)
    names = []
    for k in range(lay.first_row):
        c = _cells(lines[k], ",")
        if c and c[0].lower() == "source":
            names = c[1:]
    n = len(lay.columns) - 1
    if len(names) != n:
        names = [f"CH{j + 1}" for j in range(n)]
    lay.columns = ["TIME", *names]
    return lay


def _read_keysight(lines, name, forced=False) -> _Layout:
    """Keysight/Agilent InfiniiVision: ``x-axis,1[,2...]`` / ``second,Volt[,Volt...]``,
    then time and values (channel numbers become CH1, CH2...)."""
    if forced and _first_cells(lines)[:1] != ["x-axis"]:
        raise _not_this(name, "keysight", 0, lines, "is not the header x-axis,1,2,...")
    lay = _read_table(lines, name, "keysight", forced)
    labels = _cells(lines[0], ",")[1:len(lay.columns)]
    lay.columns = ["TIME"] + [f"CH{c}" if c.isdigit() else c for c in labels]
    lay.columns += [f"col{j + 1}" for j in range(len(lay.columns), len(lay.file_cols))]
    return lay


#: A PicoScope units cell, in seconds or volts per unit.
_PICO_UNITS = {"s": 1.0, "ms": 1e-3, "us": 1e-6, "µs": 1e-6, "μs": 1e-6, "ns": 1e-9,
               "ps": 1e-12, "v": 1.0, "mv": 1e-3, "uv": 1e-6, "µv": 1e-6, "μv": 1e-6}


def _pico_units(line) -> list | None:
    """The scales of a PicoScope units row such as ``(ms),(V),(mV)``, or None."""
    cells = _cells(line, _delimiter([line]) if "\t" in line or ";" in line else ",")
    if len(cells) < 2 or not all(c.startswith("(") and c.endswith(")") for c in cells):
        return None
    scales = [_PICO_UNITS.get(c[1:-1].strip().lower()) for c in cells]
    return None if any(s is None for s in scales) else scales


def _read_picoscope(lines, name, forced=False) -> _Layout:
    """PicoScope: ``Time,Channel A[,Channel B...]``, a units row ``(ms),(V)...``
    (honoured: time in seconds, values in volts), maybe a blank line, then samples."""
    scales = _pico_units(lines[1]) if len(lines) > 1 else None
    if forced and scales is None:
        raise _not_this(name, "picoscope", 1, lines, "is not a units row such as (ms),(V)")
    lay = _read_table(lines, name, "picoscope", forced)
    lay.columns = _cells(lines[0], lay.delim if lay.delim != "whitespace" else ",")[
        :len(lay.file_cols)]
    lay.scales = scales[:len(lay.file_cols)]
    return lay


def _detect_rigol_no_x(lines) -> bool:
    c = _first_cells(lines)
    return bool(c) and c[0] != "x" and "start" in c and "increment" in c


#: Every layout recognised, in the order they are tried (generic last).
FORMATS = ("tektronix-tds", "tektronix-mso", "rigol", "rigol-no-x", "siglent", "keysight",
           "digilent", "picoscope", "waveform", "generic")
#: What each is, for messages and ``--help``.
FORMAT_NAMES = {"tektronix-tds": "Tektronix TDS/TBS", "tektronix-mso": "Tektronix MSO/DPO",
                "rigol": "Rigol DS1000Z (X column)", "rigol-no-x": "Rigol (no X column)",
                "siglent": "Siglent SDS", "keysight": "Keysight/Agilent InfiniiVision",
                "digilent": "Digilent WaveForms", "picoscope": "PicoScope",
                "waveform": "design-plant/design-pid waveforms", "generic": "generic CSV"}
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


# --------------------------------------------------------------------------- samples

class _Columns:
    """The kept columns, filled a block at a time (rows of ``data`` are the
    columns, each contiguous), with the file line of every sample."""

    def __init__(self, k: int, hint: int, skip: int = 0):
        self.data = np.empty((k, max(int(hint), 64)))
        self.skip = skip    # leading rows not in the file (a time made from the row)
        self.n = 0
        self._row0 = []     # first sample of each block
        self._lines = []    # its first line number, or every line number

    def append(self, rows: np.ndarray, lines) -> None:
        m = rows.shape[0]
        if self.n + m > self.data.shape[1]:
            grown = np.empty((self.data.shape[0],
                              max(int(1.25 * self.data.shape[1]), self.n + m)))
            grown[:, :self.n] = self.data[:, :self.n]
            self.data = grown
        self.data[self.skip:, self.n:self.n + m] = rows.T
        self._row0.append(self.n)
        self._lines.append(lines)
        self.n += m

    def line(self, row: int) -> int:
        """The file line (1-based) of sample ``row``."""
        b = bisect.bisect_right(self._row0, row) - 1
        lines = self._lines[b]
        k = row - self._row0[b]
        return int(lines[k]) if isinstance(lines, np.ndarray) else lines + k

    def columns(self) -> np.ndarray:
        d = self.data[:, :self.n]
        # the size hint is an estimate: give back a large unused tail
        return d.copy() if self.n < 0.8 * self.data.shape[1] else d


def _load(head, layout, keep, blocks, name, size_hint) -> _Columns:
    """Parse the samples of the kept columns: the head's data lines, then ``blocks``."""
    generated = layout.file_cols[0] is None      # no time column: made from the row
    usecols = [layout.file_cols[j] for j in keep[generated:]]
    body = head[layout.first_row:]
    if size_hint:
        # rows expected from the file size and the head's bytes per data line
        sample = body[:HEAD_LINES]
        per_line = max(sum(len(ln) + 1 for ln in sample) / max(len(sample), 1), 2.0)
        hint = min(size_hint / per_line * 1.1 + 64, MAX_CAPTURE_ROWS + 1)
    else:
        hint = len(body)
    cols = _Columns(len(keep), hint, skip=int(generated))
    line0 = layout.first_row + 1
    for lines, flags in _then((body, _flags(body)), blocks):
        rows, where = _parse_block(lines, line0, layout.delim, usecols, flags, name,
                                   layout.comma)
        if cols.n + rows.shape[0] > MAX_CAPTURE_ROWS:
            raise DesignError(f"{name}: more than {MAX_CAPTURE_ROWS:,} samples, the most "
                              "identify reads; decimate the record or cut it to the step")
        cols.append(rows, where)
        line0 += (text_lines(lines) if isinstance(lines, str) else len(lines))
        del lines, rows   # before the next block is read
    return cols


def text_lines(text: str) -> int:
    """Lines in a block of text, as ``str.splitlines`` counts them for a CSV."""
    return text.count("\n") + (0 if not text or text.endswith("\n") else 1)


def _parse_block(lines, line0, delim, usecols, flags, name, comma=False) -> tuple:
    """Numeric rows of a block of lines (a list, or the block's text) and their
    line numbers (the first one's number when no line was skipped, else an array)."""
    gaps, quotes = flags
    if isinstance(lines, str):
        text = lines
        if not gaps:
            if quotes:
                text = text.replace('"', "")
            if comma or delim == ";":
                text = text.replace(",", ".")
            try:
                rows = np.loadtxt(io.StringIO(text.replace("\r", "")),
                                  delimiter=None if delim == "whitespace" else delim,
                                  usecols=usecols, ndmin=2, dtype=float, comments="#")
                if rows.shape[0] == text_lines(lines):
                    return rows, line0
            except ValueError:
                pass  # a bad cell: found, with its line, below
        lines = lines.splitlines()
    if quotes:
        lines = [ln.replace('"', "") for ln in lines]   # spreadsheet-quoted numbers
    if comma or delim == ";":
        lines = [ln.replace(",", ".") for ln in lines]
    kw = {"delimiter": None if delim == "whitespace" else delim, "usecols": usecols,
          "ndmin": 2, "dtype": float, "comments": "#"}
    if not gaps:
        try:
            return np.loadtxt(lines, **kw), line0
        except ValueError:
            pass  # a blank line, or a bad cell: found below
    # Skip blank and comment lines, remembering where every sample came from.
    kept = [i for i, ln in enumerate(lines) if ln.split("#", 1)[0].strip()]
    rows = [lines[i] for i in kept]
    where = np.asarray(kept, dtype=np.int64) + line0
    if not rows:
        return np.empty((0, len(usecols))), where
    try:
        return np.loadtxt(rows, **kw), where
    except ValueError:
        _raise_bad_cell(rows, where, delim, name, usecols, comma)
        raise  # pragma: no cover - _raise_bad_cell always raises


def _raise_bad_cell(rows, where, delim, name, usecols, comma=False):
    for line, lineno in zip(rows, where):
        cells = _split(line, delim, comma)
        for j in usecols:
            if j >= len(cells) or cells[j] == "":
                raise DesignError(f"{name}: line {lineno} has no value in column "
                                  f"{j + 1}; every data row needs all columns")
            if not _is_number(cells[j]):
                raise DesignError(f"{name}: line {lineno}, column {j + 1}: "
                                  f"{show_cell(cells[j])} is not a number; data cells must "
                                  "be numbers like 1.5e-3")
    raise DesignError(f"{name}: rows from line {where[0]} on do not form a numeric table "
                      "with the same number of columns on every line")


# --------------------------------------------------------------------------- columns

def _norm(name: str) -> str:
    n = name.strip().lower()
    n = re.sub(r"\s*[\(\[](s|v|a|volt|volts|sec|seconds)[\)\]]$", "", n)
    n = re.sub(r"_(v|a|s)$", "", n)
    return n


def _pick(spec, columns, what, name):
    if spec is None:
        return None
    text = str(spec).strip()
    if isinstance(spec, int) or (text.isascii() and text.isdigit() and len(text) < 10):
        k = int(text)
        if not 2 <= k <= len(columns):
            raise DesignError(f"{name}: {what} column {k} does not exist; columns 2..{len(columns)} "
                              f"are signals ({', '.join(columns)})")
        return k - 1
    low = [c.lower() for c in columns]
    if text.lower() in low[1:]:
        return low.index(text.lower(), 1)
    raise DesignError(f"{name}: no {what} column named {show_cell(str(spec))}; the file has "
                      f"{', '.join(columns[1:])}")


def _choose_columns(columns, input_column, output_column, name) -> tuple:
    """(output, input, tentative): column indices from the options, the header
    names or the positions; ``tentative`` when the input was chosen by position
    only (it must then look like a step, see :func:`looks_like_step_input`)."""
    norm = [_norm(c) for c in columns]
    no_input = isinstance(input_column, str) and input_column.strip().lower() == "none"
    j_out = _pick(output_column, columns, "output", name)
    j_in = None if no_input else _pick(input_column, columns, "input", name)
    if j_out is not None and j_out == j_in:
        raise DesignError(f"{name}: column {j_out + 1} ({columns[j_out]}) is given as both the "
                          "input and the output; they must be different columns")
    if j_out is None:
        named = [j for j in range(1, len(norm)) if norm[j] in OUTPUT_NAMES and j != j_in]
        others = [j for j in range(len(columns) - 1, 0, -1) if j != j_in]
        if not others:
            raise DesignError(f"{name}: the only signal column ({columns[j_in]}) cannot be both "
                              "the input and the output; drop --input-column or give a "
                              "t,u,y file")
        j_out = named[0] if named else others[0]
    tentative = False
    if j_in is None and not no_input and len(columns) >= 3:
        named = [j for j in range(1, len(norm)) if norm[j] in INPUT_NAMES and j != j_out]
        if named:
            j_in = named[0]
        else:
            j_in = next(j for j in range(1, len(columns)) if j != j_out)
            tentative = True
    return j_out, j_in, tentative


def _assemble(cols: _Columns, layout: _Layout, keep, tentative, name) -> Capture:
    if cols.n == 0:
        raise DesignError(f"{name}: the file has no data rows")
    data = cols.columns()
    what = ["time", "output", "input"]
    if layout.file_cols[0] is None:
        data[0] = np.arange(cols.n)        # Rigol without X: the row is the index
    if layout.time_axis is not None:
        # Rigol: the first column is the sample index. An absurd index or
        # increment overflows to inf here, which check_samples then refuses
        # naming the line: the overflow itself is expected and harmless.
        start, inc = layout.time_axis
        with np.errstate(over="ignore", invalid="ignore"):
            data[0] *= inc
            data[0] += start
    if layout.scales is not None:
        # PicoScope's units row: time in seconds, values in volts
        with np.errstate(over="ignore", invalid="ignore"):
            for row, j in enumerate(keep):
                if j < len(layout.scales) and layout.scales[j] != 1.0:
                    data[row] *= layout.scales[j]
    file_col = [(layout.file_cols[j] + 1) if layout.file_cols[j] is not None else 0
                for j in keep]
    check_samples(*data, name=name, what=what[:len(keep)],
                  where=lambda i, k: f"line {cols.line(i)}"
                  + (f", column {file_col[k]}" if file_col[k] else ""))
    t, y = data[0], data[1]
    u = data[2] if len(keep) == 3 else None
    columns = layout.columns
    j_out, j_in = keep[1], (keep[2] if u is not None else None)
    notes = []
    # An input chosen by position only is used only if it looks like one
    # (e.g. time_s,analytic,spice has no input column).
    if tentative and not looks_like_step_input(u, y):
        notes.append(f"column {columns[j_in]!r} does not look like a step input "
                     "(its transitions are not much faster than the output's); "
                     "no input column used (see --input-column)")
        u, j_in = None, None
    return Capture(t=t, y=y, u=u, fmt=layout.fmt, columns=list(columns),
                   output_name=columns[j_out],
                   input_name=None if j_in is None else columns[j_in], source=name,
                   notes=notes)


def _transition_fraction(x) -> float:
    lo, hi = np.percentile(x, [1, 99])
    span = hi - lo
    if span <= 0:
        return 1.0
    mid = (x > lo + 0.1 * span) & (x < lo + 0.9 * span)
    return float(np.count_nonzero(mid)) / x.size


def looks_like_step_input(u, y) -> bool:
    """True when ``u`` is a two-level signal whose transitions are much faster
    than ``y``'s: it spends under 2 % of the record between its 10 % and 90 %
    levels, and under a fifth of the time ``y`` spends between its own."""
    u = np.asarray(u, float)
    fu = _transition_fraction(u)
    if np.ptp(u) == 0:
        return False
    return fu < 0.02 and fu < 0.2 * _transition_fraction(np.asarray(y, float))


# --------------------------------------------------------------------------- writers

def format_generic(t, y, u=None, *, delimiter=",", header=True, decimal_comma=False) -> str:
    """Text of a generic ``t,[u,]y`` CSV (used by fixtures and round-trip tests)."""
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


# --------------------------------------------------------------------------- frequency tables

GAIN_UNITS = ("db", "ratio")
PHASE_UNITS = ("deg", "rad", "s")
FREQ_UNITS = ("hz", "rad/s")
MIN_POINTS = 5
#: Most rows a table may have (a network analyser sweeps a few thousand).
MAX_POINTS = 100_000


@dataclass
class FreqData:
    """A validated frequency-response table.

    ``w`` in rad/s (increasing, > 0), ``gain`` as an amplitude ratio (> 0),
    ``phase`` in radians, unwrapped, 0 at DC for a non-inverting plant (or
    None when the table has no phase). ``sign`` is -1 when the low-frequency
    phase is within 45 degrees of +-180 (an inverting plant; the phase is then stored
    without that 180 degrees).
    """

    w: np.ndarray
    gain: np.ndarray
    phase: np.ndarray | None = None
    sign: float = 1.0
    source: str = ""
    units: dict = field(default_factory=dict)
    notes: list = field(default_factory=list)
    fmt: str = "table"

    @property
    def f_hz(self) -> np.ndarray:
        return self.w / (2.0 * math.pi)

    @property
    def gain_db(self) -> np.ndarray:
        return 20.0 * np.log10(self.gain)

    def response(self) -> np.ndarray:
        """Complex G(j w) of the data (magnitude only, phase 0, if no phase)."""
        ph = self.phase if self.phase is not None else np.zeros_like(self.w)
        return self.gain * np.exp(1j * ph)

    def to_dict(self) -> dict:
        return {"source": self.source, "format": self.fmt, "points": int(self.w.size),
                "f_min_hz": float(self.f_hz[0]), "f_max_hz": float(self.f_hz[-1]),
                "has_phase": self.phase is not None, "inverting": self.sign < 0,
                "units": dict(self.units), "notes": list(self.notes)}


def _units(value, allowed, what) -> str:
    """Units as given, case-insensitive (``dB``, ``Hz``, ``RAD/S``)."""
    u = str(value).strip().lower()
    if u not in allowed:
        raise DesignError(f"{what} units {str(value)!r} unknown; allowed: {', '.join(allowed)}")
    return u


def freq_data(freq, gain, phase=None, *, gain_units="db", phase_units="deg",
              freq_units="hz", source="", lines=None) -> FreqData:
    """Validate and convert a table (arrays) into :class:`FreqData`.

    ``lines`` (optional) are the file lines of the rows, for messages.

    Raises
    ------
    DesignError
        Too few or too many points, non-finite values, values outside their
        physical ranges (``freq_hz``, ``gain_db`` or ``gain_ratio``,
        ``phase_deg`` of :data:`designer.ranges.RANGES`), frequency not strictly
        increasing or not positive, non-positive amplitude ratio, unknown units.
    """
    gain_units = _units(gain_units, GAIN_UNITS, "gain")
    phase_units = _units(phase_units, PHASE_UNITS, "phase")
    freq_units = _units(freq_units, FREQ_UNITS, "frequency")
    pre = f"{source}: " if source else ""

    def row(k):
        return f"line {lines[k]}" if lines is not None else f"row {k + 1}"

    f = np.asarray(freq, float)
    g = np.asarray(gain, float)
    if f.ndim != 1 or g.shape != f.shape:
        raise DesignError("frequency and gain must be columns of the same length")
    if f.size < MIN_POINTS:
        raise DesignError(f"{pre}too few points: {f.size}; at least {MIN_POINTS} frequencies are "
                          "needed to fit a model")
    if f.size > MAX_POINTS:
        raise DesignError(f"{pre}{f.size} points; at most {MAX_POINTS:,} are read (thin the "
                          "sweep: a few hundred points over the band are plenty)")
    p = None
    if phase is not None:
        p = np.asarray(phase, float)
        if p.shape != f.shape:
            raise DesignError("phase column must have as many rows as frequency")
    for name, arr in (("frequency", f), ("gain", g), ("phase", p)):
        if arr is not None and not np.all(np.isfinite(arr)):
            k = int(np.argmin(np.isfinite(arr)))
            raise DesignError(f"{pre}{name} at {row(k)} is not a finite number "
                              f"({number_text(arr[k])})")
    if np.any(f <= 0):
        k = int(np.argmax(f <= 0))
        raise DesignError(f"{pre}frequency at {row(k)} is {f[k]:g}: frequencies must be positive")
    bad = np.nonzero(np.diff(f) <= 0)[0]
    if bad.size:
        k = int(bad[0])
        raise DesignError(f"{pre}frequency not increasing at {row(k + 1)} ({f[k + 1]:g} after "
                          f"{f[k]:g}); sort the table and remove repeated frequencies")
    f_unit = "rad/s" if freq_units == "rad/s" else "Hz"
    _check_column(f / (2.0 * math.pi) if freq_units == "rad/s" else f, "freq_hz", f, f_unit,
                  "frequency", pre, row)
    w = f if freq_units == "rad/s" else 2.0 * math.pi * f
    if gain_units == "ratio":
        if np.any(g <= 0):
            k = int(np.argmax(g <= 0))
            raise DesignError(f"{pre}gain at {row(k)} is {g[k]:g}: an amplitude ratio must be "
                              "positive (use --gain-units db for decibels)")
        _check_column(g, "gain_ratio", g, "", "gain (amplitude ratio)", pre, row)
        ratio = g
    else:
        _check_column(g, "gain_db", g, "dB", "gain", pre, row)
        ratio = 10.0 ** (g / 20.0)
    ph = None
    sign = 1.0
    notes = []
    if p is not None:
        # An absurd phase or time shift (1e300 s) overflows to inf in these
        # conversions; the range check right after refuses it by line, so the
        # overflow is expected and harmless.
        with np.errstate(over="ignore"):
            if phase_units == "deg":
                ph, ph_deg = np.deg2rad(p), p
            elif phase_units == "rad":
                ph, ph_deg = p.copy(), np.rad2deg(p)
            else:
                # a positive time shift is the output lagging the input: -w dt
                ph = -w * p
                ph_deg = np.rad2deg(ph)
        unit = {"deg": "deg", "rad": "rad", "s": "s of time shift"}[phase_units]
        _check_column(ph_deg, "phase_deg", p, unit, "phase (in degrees)", pre, row)
        if phase_units != "s":
            ph = _unwrap_lag(ph)
        ph -= 2.0 * math.pi * round(ph[0] / (2.0 * math.pi))
        # within 45 degrees of +-180 at the lowest frequency: an inverting plant
        if abs(ph[0]) > 0.75 * math.pi:
            sign = -1.0
            ph -= math.copysign(math.pi, ph[0])
        if ph[-1] > 0.25 * math.pi:
            notes.append(f"the phase rises to {math.degrees(ph[-1]):+.0f} deg at the highest "
                         "frequency: a low-pass plant's output lags its input (negative phase); "
                         "if the table gives the lag as a positive number, negate that column")
    return FreqData(w, ratio, ph, sign, source,
                    {"frequency": freq_units, "gain": gain_units,
                     "phase": phase_units if phase is not None else None}, notes)


def _check_column(values, key, shown_values, unit, what, pre, row) -> None:
    """One line naming the first row whose value (converted to ``RANGES[key]``'s
    unit as ``values``; as the table gives it in ``shown_values``) is outside the range."""
    rng = RANGES[key]
    lo_ok = rng.contains(float(np.min(values)))
    if lo_ok and rng.contains(float(np.max(values))):
        return
    k = next(i for i, v in enumerate(values) if not rng.contains(float(v)))
    got = number_text(shown_values[k]) + (f" {unit}" if unit else "")
    raise DesignError(f"{pre}{what} at {row(k)} must be {rng.text()}, got {got}")


def _unwrap_lag(ph: np.ndarray) -> np.ndarray:
    """Undo the wrapping of a phase read into (-180, 180] degrees.

    A causal low-pass plant's phase falls with frequency, so a rise of more
    than pi between neighbouring rows can only be a wrap, and is removed. A
    fall of any size is kept: with a dead time a sparse table legitimately
    drops by more than pi between rows (np.unwrap would "correct" that)."""
    d = np.diff(ph)
    jumps = np.where(d > math.pi, -2.0 * math.pi * np.ceil((d - math.pi) / (2.0 * math.pi)), 0.0)
    return np.concatenate(([ph[0]], ph[0] + np.cumsum(d + jumps)))


_NUM = re.compile(r"^[+-]?(\d+\.?\d*|\.\d+)([eE][+-]?\d+)?$")


def _tokens(name: str) -> set:
    return set(re.split(r"[^a-z0-9/µμ°]+", name.lower().replace("µ", "u").replace("μ", "u"))) - {""}


def _hint(name: str, kind: str):
    """Units named in a header cell, or None."""
    tk = _tokens(name)
    low = name.lower()
    if kind == "frequency":
        if tk & {"rad/s", "rad_s", "rads", "w", "omega"} or "rad/s" in low:
            return "rad/s", 1.0
        if "khz" in tk:
            return "hz", 1e3
        if "mhz" in tk:
            return "hz", 1e6
        if "hz" in tk or "f" in tk:
            return "hz", 1.0
    elif kind == "gain":
        if "db" in tk:
            return "db", 1.0
        if tk & {"ratio", "v/v", "abs", "mag"}:
            return "ratio", 1.0
    elif kind == "phase":
        if tk & {"deg", "degrees", "°"} or "°" in low:
            return "deg", 1.0
        if tk & {"rad", "radians"}:
            return "rad", 1.0
        if "us" in tk:
            return "s", 1e-6
        if "ms" in tk:
            return "s", 1e-3
        if tk & {"s", "shift", "dt", "delay"}:
            return "s", 1.0
    return None


def parse_freq_table(text: str, *, gain_units=None, phase_units=None, freq_units=None,
                     source="") -> FreqData:
    """Parse CSV text: ``frequency, gain[, phase]`` per row.

    Comma, semicolon (with decimal commas), tab or space separated; ``#``
    comment lines and blank lines ignored; one optional header row whose names
    may give units (``f_hz``, ``f_khz``, ``w_rad_s``, ``gain_db``,
    ``gain_ratio``, ``phase_deg``, ``phase_rad``, ``shift_us``...). Units given
    as arguments (any case: ``dB``, ``Hz``) win over the header; the defaults
    are Hz, dB and degrees.
    """
    pre = f"{source}: " if source else ""
    lines = [(i + 1, ln.strip()) for i, ln in enumerate(text.lstrip("\ufeff").splitlines())]
    fmt = ("digilent-bode" if lines and lines[0][1].lower().startswith("#digilent waveforms")
           else "table")
    lines = [(i, ln) for i, ln in lines if ln and not ln.startswith("#")]
    if not lines:
        raise DesignError(f"{source or 'table'} is empty: expected rows of "
                          "frequency, gain[, phase]")
    if len(lines) > MAX_POINTS + 1:
        raise DesignError(f"{pre}{len(lines):,} rows; at most {MAX_POINTS:,} are read (thin the "
                          "sweep: a few hundred points over the band are plenty)")
    first = lines[0][1]
    if ";" in first:
        sep, decimal_comma = ";", True
    elif "," in first:
        sep, decimal_comma = ",", False
    elif "\t" in first:
        sep, decimal_comma = "\t", False
    else:
        sep, decimal_comma = None, False

    def cells(ln):
        parts = ln.split(sep) if sep else ln.split()
        parts = [c.strip().strip('"').strip("'") for c in parts]
        if decimal_comma:
            parts = [c.replace(",", ".") for c in parts]
        while parts and parts[-1] == "":
            parts.pop()
        return parts

    header = None
    c0 = cells(first)
    if not all(_NUM.match(c) or c.lower() in ("nan", "inf", "-inf") for c in c0):
        header = c0
        lines = lines[1:]
    if not lines:
        raise DesignError(f"{source or 'table'} has a header but no data rows")
    rows = []
    ncol = None
    use, picked = _analyser_columns(header)
    for lineno, ln in lines:
        cs = cells(ln)
        if ncol is None:
            ncol = len(cs)
            if use is not None and ncol == len(header):
                ncol = len(use)
            elif ncol not in (2, 3):
                raise DesignError(f"{pre}line {lineno}: {ncol} columns; expected 2 or 3 "
                                  "(frequency, gain[, phase])")
        if use is not None and len(cs) == len(header):
            cs = [cs[j] for j in use]
        if len(cs) != ncol:
            raise DesignError(f"{pre}line {lineno}: {len(cs)} columns where the table has {ncol}")
        vals = []
        for c in cs:
            if c.lower() in ("nan", "inf", "-inf", "+inf"):
                raise DesignError(f"{pre}line {lineno}: {show_cell(c)} is not a finite number")
            if not _NUM.match(c):
                raise DesignError(f"{pre}line {lineno}: {show_cell(c)} is not a number (plain "
                                  "decimal or 1e3 notation)")
            vals.append(float(c))
        rows.append(vals)
    arr = np.array(rows, float)
    if use is not None and ncol == len(use):
        header = [header[j] for j in use]
    names = header if header and len(header) == ncol else [""] * ncol
    kinds = ("frequency", "gain", "phase")
    units, scale = {}, {}
    given = {"frequency": freq_units, "gain": gain_units, "phase": phase_units}
    given = {k: None if v is None else str(v).strip().lower() for k, v in given.items()}
    default = {"frequency": "hz", "gain": "db", "phase": "deg"}
    defaulted = set()
    for k, name in zip(kinds, names):
        h = _hint(name, k) if name else None
        if given[k] is not None:
            units[k], scale[k] = given[k], 1.0
            if h and h[0] == given[k]:
                scale[k] = h[1]        # e.g. a "shift_us" column with --phase-units s
        elif h:
            units[k], scale[k] = h
        else:
            units[k], scale[k] = default[k], 1.0
            defaulted.add(k)
    # A value near 1e308 times a unit prefix (kHz) overflows to inf: freq_data
    # refuses it by line as not finite, so the overflow is expected and harmless.
    with np.errstate(over="ignore"):
        f = arr[:, 0] * scale["frequency"]
        g = arr[:, 1] * scale["gain"]
        p = arr[:, 2] * scale["phase"] if ncol == 3 else None
    data = freq_data(f, g, p, gain_units=units["gain"], phase_units=units.get("phase", "deg"),
                     freq_units=units["frequency"], source=source,
                     lines=[lineno for lineno, _ in lines])
    data.fmt = fmt
    if picked:
        data.notes.append(picked)
    if "gain" in defaulted and 0.0 <= g.min() and g.max() <= 10.0 and np.ptp(g) > 0.1:
        data.notes.append("the gain column was read as dB (the default: neither the header "
                          "nor --gain-units names it), but every value lies between 0 and 10, "
                          "as an amplitude ratio Vout/Vin would; if it is one, pass "
                          "--gain-units ratio")
    return data


def _analyser_columns(header):
    """``(columns, note)``: for a network analyser's export of more than three
    columns (WaveForms: frequency, each channel's magnitude, the relative
    channel's phase), the frequency, the magnitude of the channel whose phase
    is given (the response relative to the reference channel) and that phase;
    ``(None, "")`` for any other header."""
    if not header or len(header) <= 3:
        return None, ""
    low = [h.lower() for h in header]
    phase = [j for j, h in enumerate(low) if "phase" in h]
    mag = [j for j, h in enumerate(low) if "magnitude" in h or "gain" in h or "mag " in h]
    if not phase or not mag:
        return None, ""
    p = phase[-1]
    channel = low[p].split("phase")[0].strip()
    same = [j for j in mag if channel and low[j].startswith(channel)]
    g = same[-1] if same else mag[-1]
    return [0, g, p], (f"network-analyser export of {len(header)} columns: read "
                       f"{header[g]!r} and {header[p]!r} (the response relative to the "
                       "reference channel)")


def read_freq_table(path, **units) -> FreqData:
    """Read a frequency-response CSV file (see :func:`parse_freq_table`): at most
    :data:`~designer.core.fileio.MAX_TABLE_BYTES`, UTF-8 or ASCII."""
    text = read_text(path, "table", MAX_TABLE_BYTES)
    return parse_freq_table(text, source=shown(path), **units)
