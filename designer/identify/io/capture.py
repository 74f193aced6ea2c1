"""Reading a time capture (a step response, a square wave, a broadband
excitation and its response): the one code path every layout goes through.

:func:`read_capture` streams the file: the layout is recognised from the first
lines (:mod:`.formats`), then the samples are parsed a block at a time by
numpy's C parser, keeping only the (at most three) columns used; the second half
of a long file by a forked helper on the other core meanwhile (:mod:`.split`).
"""

from __future__ import annotations

import bisect
import io
import re
from dataclasses import dataclass, field

import numpy as np

from ...core.errors import DesignError, ParamError
from ...core.fileio import (
    MAX_CAPTURE_BYTES,
    MAX_CAPTURE_ROWS,
    MAX_LINE_BYTES,
    SNIFF_BYTES,
    check_encoding,
    decode,
    open_limited,
    show_cell,
    size_text,
)
from ..edges import check_samples
from ...core.ranges import RANGES
from .formats import detect_layout
from .layout import FORMAT_NAMES, is_number, Layout, split_line
from .split import PARSED, FileBlocks


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
    #: the input was chosen by position only (no name, no option): the analysis decides whether
    #: it is one (:func:`designer.identify.broadband.positional_input`)
    input_by_position: bool = False

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


__all__ = ["INPUT_NAMES", "OUTPUT_NAMES", "TIME_NAMES", "HEAD_LINES", "BLOCK_LINES", "Capture", "CaptureInfo",
           "read_capture", "parse_capture_text", "plain_columns", "text_lines", "looks_like_step_input"]


def plain_columns(sample_time_s=None, column_names=None) -> tuple | None:
    """The options of a file of signal columns without a time column, checked:
    ``(sample_time_s, names)``, or None when neither is given.

    Parameters
    ----------
    sample_time_s : float, optional
        The sample interval, seconds, inside ``RANGES["sample_time_s"]``; sample
        k is at k * sample_time_s.
    column_names : str or sequence of str, optional
        The name of every column, in order (``"u,y"``, ``["y", "u", "x"]``):
        ``u`` (or another of :data:`INPUT_NAMES`) is the input, ``y`` (or
        another of :data:`OUTPUT_NAMES`) the output, other names are not used.
        Default: the file's header, else by order (the first column the input,
        the second the output; a single column the output).

    Returns
    -------
    tuple or None
        ``(sample_time_s, names or None)``.

    Raises
    ------
    DesignError
        A sample time outside its range, ``column_names`` without
        ``sample_time_s``, an empty or repeated name.
    """
    if sample_time_s is None and column_names is None:
        return None
    if sample_time_s is None:
        raise ParamError("{column_names} names the columns of a file without a time column; give "
                         "{sample_time_s} with it (the sample interval, e.g. 0.08); a file with a time column "
                         "chooses its signals with {input_column} and {output_column}",
                         params=("column_names", "sample_time_s", "input_column", "output_column"))
    dt = RANGES["sample_time_s"].check(sample_time_s, "sample_time_s")
    if column_names is None:
        return dt, None
    names = ([c.strip() for c in column_names.split(",")] if isinstance(column_names, str)
             else [str(c).strip() for c in column_names])
    example = "u,y (or y,u, or u,y,x with a third column unused)"
    if not names or not all(names):
        raise ParamError(f"{{column_names}} {show_cell(str(column_names))} has an empty name: name every "
                         f"column, in order, separated by commas, e.g. {example}", params=("column_names",))
    low = [n.lower() for n in names]
    twice = next((n for n in names if low.count(n.lower()) > 1), None)
    if twice is not None:
        raise ParamError(f"{{column_names}} names two columns {show_cell(twice)}: name each column once, "
                         f"e.g. {example}", params=("column_names",))
    return dt, names


def _plain_layout(layout: Layout, plain: tuple, name: str) -> Layout:
    """The layout of a file of signal columns without a time column: every file
    column a signal, time k * sample_time_s (the Rigol-without-X path)."""
    dt, names = plain
    if layout.fmt != "generic" or layout.time_axis is not None:
        raise ParamError(f"{name} is a {FORMAT_NAMES[layout.fmt]} export with its own time axis; "
                         "{sample_time_s} is for a file of signal columns without a time column: drop it",
                         params=("sample_time_s",))
    ncols = len(layout.file_cols)
    if layout.named and _norm(layout.columns[0]) in TIME_NAMES:
        raise ParamError(f"{name}: its first column ({show_cell(layout.columns[0])}) is a time column; "
                         "{sample_time_s} is for a file without one: drop it", params=("sample_time_s",))
    if names is not None and len(names) != ncols:
        raise ParamError(f"{{column_names}} names {len(names)} column{'s' if len(names) > 1 else ''} "
                         f"({show_cell(','.join(names))}) and {name} has {ncols}: name every column, in order, e.g. "
                         + ",".join((["u", "y"] + [f"x{j}" for j in range(3, ncols + 1)])[:max(ncols, 1)]),
                         params=("column_names",))
    if names is not None:
        signals = list(names)
    elif layout.named:
        signals = list(layout.columns)
    else:   # by order: the input, then the output (identification's u y)
        signals = ["y"] if ncols == 1 else ["u", "y"] + [f"col{j + 1}" for j in range(2, ncols)]
    return Layout(["t"] + signals, layout.fmt, layout.first_row, layout.delim, [None] + list(range(ncols)),
                   time_axis=(0.0, dt), comma=layout.comma, named=layout.named)


def read_capture(path, *, input_column=None, output_column=None, fmt=None, sample_time_s=None,
                 column_names=None) -> Capture:
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
    sample_time_s : float, optional
        The file has no time column: every column is a signal, sampled every
        ``sample_time_s`` seconds from t = 0 (a data set as identification
        keeps it, DaISy's ``u y`` columns). See :func:`plain_columns`.
    column_names : str or sequence of str, optional
        With ``sample_time_s``: the name of every column, in order (``"u,y"``).

    Returns
    -------
    Capture
        Time, output and input (None without an input column).

    Raises
    ------
    DesignError
        Missing, unreadable, too large, binary or UTF-16 file, empty file,
        non-numeric cells, NaN or infinite values, values outside their
        physical ranges, time not strictly increasing (a first column that is
        no time at all: give ``sample_time_s``), the same column asked for as
        input and output, an input column that never moves.
    """
    plain = plain_columns(sample_time_s, column_names)
    with open_limited(path, "capture file", MAX_CAPTURE_BYTES) as fh:
        head, carry = _read_head(fh)
        blocks = FileBlocks(fh, carry)
        try:
            cap = _parse(head, blocks, fh.name, input_column, output_column,
                         size_hint=fh.size, fmt=fmt, plain=plain)
        finally:
            blocks.close()
    cap.source = str(path)
    return cap


def parse_capture_text(text: str, *, name: str = "capture", input_column=None,
                       output_column=None, fmt=None, sample_time_s=None, column_names=None) -> Capture:
    """Parse the text of a capture file; see :func:`read_capture`.

    Parameters
    ----------
    text : str
        The file's text.
    name : str
        The file's name, for messages.
    input_column, output_column, fmt, sample_time_s, column_names
        As :func:`read_capture`'s.

    Returns
    -------
    Capture
    """
    plain = plain_columns(sample_time_s, column_names)
    lines = text.lstrip("\ufeff").splitlines()
    head, rest = lines[:HEAD_LINES], lines[HEAD_LINES:]
    blocks = ((b, _flags(b)) for b in (rest[i:i + BLOCK_LINES]
                                       for i in range(0, len(rest), BLOCK_LINES)))
    return _parse(head, blocks, name, input_column, output_column,
                  size_hint=None if not rest else len(text), fmt=fmt, plain=plain)


# --------------------------------------------------------------------------- streaming

def _flags(lines) -> tuple:
    """(may hold comment or blank lines, has quotes, lines) of a block of lines."""
    text = "\n".join(lines)
    return ("#" in text or "" in lines), '"' in text, len(lines)


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


def _parse(head, blocks, name, input_column, output_column, size_hint=None,
           fmt=None, plain=None) -> Capture:
    first = next(blocks, None)
    lines = list(head)
    if first is None:
        # Trailing blank lines are common (and harmless) in exports.
        while lines and not lines[-1].strip():
            lines.pop()
    if not lines:
        raise DesignError(f"{name}: the file is empty; expected CSV rows of time and output "
                          "(t,y or t,u,y)")
    layout = detect_layout(lines, name, fmt)
    if plain is not None:
        layout = _plain_layout(layout, plain, name)
    j_out, j_in, tentative = _choose_columns(layout.columns, input_column, output_column, name)
    tentative = tentative and plain is None   # a file declared as signal columns: its input by order
    keep = [0, j_out] + ([j_in] if j_in is not None else [])
    more = _then(first, blocks) if first is not None else iter(())
    del first   # the block is the generator's now: freed once parsed
    t2 = _second_time(layout, keep) if plain is None else None
    cols = _load(lines, layout, keep + ([t2] if t2 is not None else []), more, name, size_hint,
                 getattr(blocks, "ahead", None))
    if t2 is not None:
        _check_one_time_axis(cols, layout, t2, len(keep), name)
        cols.data = cols.data[:len(keep)]
    return _assemble(cols, layout, keep, tentative, name, plain is not None)


# another channel's own time: t_y, time_out, time-ch2, time2 (not t1: a thermocouple's name as often)
_TIME_OF = re.compile(r"(t|time)[ _-](u|y|in|out|input|output|ch\d+|\d+)|time\d+|t|time|times")


def _second_time(layout: Layout, keep) -> int | None:
    """A column the header names as another time (``t_y``, ``time_out``, a second ``time``) beside
    the first: each channel's own time axis, which must be the first's."""
    if not layout.named or layout.file_cols[0] is None:
        return None
    for j in range(1, len(layout.columns)):
        n = _norm(layout.columns[j])
        if j not in keep and _TIME_OF.fullmatch(n):
            return j
    return None


def _check_one_time_axis(cols: _Columns, layout: Layout, j: int, row: int, name: str) -> None:
    """Refuse a second time column that is not the first: the input and output sampled at
    different times (or rates), which no method here takes."""
    a, b = cols.data[0, :cols.n], cols.data[row, :cols.n]
    with np.errstate(invalid="ignore"):
        off = ~(np.abs(a - b) <= 1e-9 * np.maximum(np.abs(a), np.abs(b)) + 1e-300)
    if off.any():
        i = int(np.argmax(off))
        raise DesignError(f"{name}: column {layout.file_cols[j] + 1} ({show_cell(layout.columns[j])}) is a second "
                          f"time column and differs from column 1 ({show_cell(layout.columns[0])}) from line "
                          f"{cols.line(i)} on ({a[i]:.6g} s and {b[i]:.6g} s): the signals were sampled at "
                          "different times or rates; put them on one time axis (resample one onto the other's "
                          "times)")


def _then(first, rest):
    """``first``, then the items of ``rest``, holding no reference to ``first``
    once it is consumed (a parsed block is freed before the next is read)."""
    box = [first]
    del first
    yield box.pop()
    yield from rest



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


def _load(head, layout, keep, blocks, name, size_hint, ahead=None) -> _Columns:
    """Parse the samples of the kept columns: the head's data lines, then ``blocks``;
    ``ahead(parse)``, when given, may have a helper parse the second half of the
    blocks meanwhile (:mod:`.split`: the same samples and messages either way)."""
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
    if ahead is not None:
        ahead(lambda text, flags: _parse_block(text, 0, layout.delim, usecols, flags, name, layout.comma))
    for lines, flags in _then((body, _flags(body)), blocks):
        if lines is PARSED:   # the helper's block: its line offsets from this block's first line
            rows, where, count = flags
            where, flags = (line0 if where is None else where + line0), (False, False, count)
        else:
            rows, where = _parse_block(lines, line0, layout.delim, usecols, flags, name,
                                       layout.comma)
        if cols.n + rows.shape[0] > MAX_CAPTURE_ROWS:
            raise DesignError(f"{name}: more than {MAX_CAPTURE_ROWS:,} samples, the most "
                              "identify reads; decimate the record or cut it to the step")
        cols.append(rows, where)
        line0 += flags[2]
        del lines, rows   # before the next block is read
    return cols


def text_lines(text: str) -> int:
    """Lines in a block of text, as ``str.splitlines`` counts them for a CSV.

    Parameters
    ----------
    text : str
        The text.

    Returns
    -------
    int
        The number of lines.
    """
    return text.count("\n") + (0 if not text or text.endswith("\n") else 1)


def _parse_block(lines, line0, delim, usecols, flags, name, comma=False) -> tuple:
    """Numeric rows of a block of lines (a list, or the block's text) and their
    line numbers (the first one's number when no line was skipped, else an array)."""
    gaps, quotes, count = flags
    if isinstance(lines, str):
        text = lines
        if not gaps:
            if quotes:
                text = text.replace('"', "")
            if comma or delim == ";":
                text = text.replace(",", ".")
            if "\r" in text:   # (replace copies the text even when there is none)
                text = text.replace("\r", "")
            try:
                rows = np.loadtxt(io.StringIO(text), delimiter=None if delim == "whitespace" else delim,
                                  usecols=usecols, ndmin=2, dtype=float, comments="#")
                if rows.shape[0] == count:
                    return rows, line0
                gaps = True   # numpy skipped blank or comment lines: every line's number kept below
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
    def missing(line, j):
        cells = split_line(line, delim, comma)
        return j >= len(cells) or cells[j] == ""

    for k, (line, lineno) in enumerate(zip(rows, where)):
        cells = split_line(line, delim, comma)
        for j in usecols:
            if missing(line, j):
                if all(missing(rest, j) for rest in rows[k + 1:k + 1000]):
                    # every row from here on lacks it: the signals were recorded to different lengths
                    raise DesignError(f"{name}: line {lineno} has no value in column {j + 1}, nor any line "
                                      f"after it: the columns have different lengths (input and output "
                                      "need a sample at every time); every data row needs all columns")
                raise DesignError(f"{name}: line {lineno} has no value in column "
                                  f"{j + 1}; every data row needs all columns")
            if not is_number(cells[j]):
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


def _not_a_time(t, layout: Layout, cols: _Columns, name: str) -> None:
    """Refuse a generic table whose first column is no time at all (it falls at most of its
    rows: a signal, as in a data set of ``u y`` columns), saying which options read it."""
    if layout.fmt != "generic" or (layout.named and _norm(layout.columns[0]) in TIME_NAMES):
        return
    if t.size < 2 or not np.isfinite(t).all():
        return   # check_samples names the sample
    up = np.diff(t) > 0
    if np.mean(up) >= 0.5:
        return   # a time column with a glitch: check_samples names the line
    i = int(np.argmin(up))
    raise ParamError(f"{name}: column 1 is not a time (it goes from {t[i]:.6g} to {t[i + 1]:.6g} at line "
                     f"{cols.line(i + 1)}, and rises at only {100 * np.mean(up):.0f} % of its rows): for a file "
                     "of signals without a time column give {sample_time_s} (the sample interval, e.g. 0.08) "
                     "and, unless the first column is the input and the second the output, {column_names} "
                     "(e.g. y,u)", params=("sample_time_s", "column_names"))


def _check_input_moves(u, layout: Layout, j_in: int, name: str) -> None:
    """Refuse an input column that never moves: no identification can use it (an input chosen by
    position only and flat is dropped with a note instead, as any that is not an input)."""
    if u is not None and u.size and np.ptp(u) == 0:
        raise ParamError(f"{name}: the input column {show_cell(layout.columns[j_in])} never moves (every sample "
                         f"{u[0]:.6g}): there is nothing to identify from it; choose the input with "
                         "{input_column}, or give {input_column} none to use the output alone",
                         params=("input_column",))


def _assemble(cols: _Columns, layout: Layout, keep, tentative, name, plain=False) -> Capture:
    if cols.n == 0:
        raise DesignError(f"{name}: the file has no data rows")
    data = cols.columns()
    if not plain:
        _not_a_time(data[0], layout, cols, name)
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
    if not tentative:
        _check_input_moves(u, layout, j_in, name)
    notes = []
    if plain:
        notes.append(f"no time column: sample k at k x {layout.time_axis[1]:.6g} s (the sample time given)")
    # An input chosen by position only is kept, marked: whether it is one (a step, a
    # broadband excitation) is the analysis' decision, not the reader's (e.g.
    # time_s,analytic,spice has no input column).
    return Capture(t=t, y=y, u=u, fmt=layout.fmt, columns=list(columns),
                   output_name=columns[j_out],
                   input_name=None if j_in is None else columns[j_in], source=name,
                   notes=notes, input_by_position=bool(tentative and u is not None))


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
    levels, and under a fifth of the time ``y`` spends between its own.

    Parameters
    ----------
    u, y : array_like
        The input and output columns.

    Returns
    -------
    bool
        Whether ``u`` looks like a step (or square-wave) input.
    """
    u = np.asarray(u, float)
    fu = _transition_fraction(u)
    if np.ptp(u) == 0:
        return False
    return fu < 0.02 and fu < 0.2 * _transition_fraction(np.asarray(y, float))
