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

from ...core.errors import DesignError
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
from .formats import detect_layout
from .layout import is_number, Layout, split_line
from .split import PARSED, FileBlocks

__all__ = ["BLOCK_LINES", "HEAD_LINES", "INPUT_NAMES", "OUTPUT_NAMES", "TIME_NAMES", "Capture", "CaptureInfo",
           "looks_like_step_input", "parse_capture_text", "read_capture", "text_lines"]


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
        blocks = FileBlocks(fh, carry)
        try:
            cap = _parse(head, blocks, fh.name, input_column, output_column,
                         size_hint=fh.size, fmt=fmt)
        finally:
            blocks.close()
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
    layout = detect_layout(lines, name, fmt)
    j_out, j_in, tentative = _choose_columns(layout.columns, input_column, output_column, name)
    keep = [0, j_out] + ([j_in] if j_in is not None else [])
    more = _then(first, blocks) if first is not None else iter(())
    del first   # the block is the generator's now: freed once parsed
    cols = _load(lines, layout, keep, more, name, size_hint, getattr(blocks, "ahead", None))
    return _assemble(cols, layout, keep, tentative, name)


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
    """Lines in a block of text, as ``str.splitlines`` counts them for a CSV."""
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
    for line, lineno in zip(rows, where):
        cells = split_line(line, delim, comma)
        for j in usecols:
            if j >= len(cells) or cells[j] == "":
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


def _assemble(cols: _Columns, layout: Layout, keep, tentative, name) -> Capture:
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
        from ..broadband import looks_broadband, multilevel_levels   # a PRBS or noise input is one too
        if not looks_broadband(u) and multilevel_levels(u) is None:   # a multi-level one is refused as such
            notes.append(f"column {columns[j_in]!r} does not look like a step input "
                         "(its transitions are not much faster than the output's) nor a "
                         "broadband one; no input column used (see --input-column)")
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
