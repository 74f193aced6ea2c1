"""Reading step-response captures from CSV files.

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
"""

from __future__ import annotations

import math
import re
from dataclasses import dataclass, field
from pathlib import Path

import numpy as np

from ..errors import DesignError

#: Header names (lowercase, units stripped) read as the plant input or output.
INPUT_NAMES = ("u", "vin", "v_in", "in", "input", "uin", "u_in", "v(in)", "ve", "step", "source")
OUTPUT_NAMES = ("y", "vout", "v_out", "out", "output", "yout", "y_out", "v(out)", "vs", "response")
TIME_NAMES = ("t", "time", "time_s", "times", "second", "seconds", "s", "x", "tiempo")


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

    def to_dict(self) -> dict:
        return {"format": self.fmt, "columns": list(self.columns), "samples": int(self.t.size),
                "output": self.output_name, "input": self.input_name, "source": self.source,
                "notes": list(self.notes)}


def read_capture(path, *, input_column=None, output_column=None) -> Capture:
    """Read a step-response capture from ``path``.

    Parameters
    ----------
    path : str or Path
        The CSV file.
    input_column, output_column : str or int, optional
        Column name (case-insensitive) or 1-based column number (time is column
        1) of the plant input and output; ``input_column="none"`` ignores any
        input column.

    Raises
    ------
    DesignError
        Missing or unreadable file, empty file, non-numeric cells, NaN or
        infinite values, time not strictly increasing.
    """
    path = Path(path)
    try:
        raw = path.read_bytes()
    except FileNotFoundError:
        raise DesignError(f"capture file {str(path)!r} does not exist") from None
    except OSError as exc:
        raise DesignError(f"cannot read capture file {str(path)!r}: {exc.strerror or exc}") from None
    text = raw.decode("utf-8", errors="replace")
    cap = parse_capture_text(text, name=str(path), input_column=input_column,
                             output_column=output_column)
    cap.source = str(path)
    return cap


def parse_capture_text(text: str, *, name: str = "capture", input_column=None,
                       output_column=None) -> Capture:
    """Parse the text of a capture file; see :func:`read_capture`."""
    text = text.lstrip("\ufeff")
    lines = text.splitlines()
    # Trailing blank lines are common (and harmless) in exports.
    while lines and not lines[-1].strip():
        lines.pop()
    if not lines:
        raise DesignError(f"{name}: the file is empty; expected CSV rows of time and output "
                          "(t,y or t,u,y)")
    first = _cells(lines[0], ",")
    if first and first[0].lower() == "record length":
        columns, data, fmt, first_row = _read_tektronix_tds(lines, name)
    elif len(first) >= 3 and first[0].lower() == "x" and "increment" in [c.lower() for c in first]:
        columns, data, fmt, first_row = _read_rigol(lines, name)
    else:
        columns, data, fmt, first_row = _read_table(lines, name)
    return _assemble(columns, data, fmt, first_row, name, input_column, output_column)


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


def _delimiter(lines: list) -> str:
    sample = lines[-min(len(lines), 20):]
    counts = {d: sum(line.count(d) for line in sample) for d in (";", "\t", ",")}
    if counts[";"]:
        return ";"
    if counts["\t"] and not counts[","]:
        return "\t"
    if counts[","]:
        return ","
    return "whitespace"


def _split(line: str, delim: str) -> list:
    if delim == "whitespace":
        return line.split()
    cells = _cells(line, delim)
    if delim == ";":
        # Semicolon files from European locales write decimal commas.
        cells = [c.replace(",", ".") for c in cells]
    return cells


def _load_numeric(lines: list, first_row: int, delim: str, name: str, usecols=None,
                  ncols=None) -> np.ndarray:
    """Load numeric rows with numpy's C parser; on failure find the bad cell."""
    body = lines[first_row:]
    if body and '"' in body[0]:
        body = [ln.replace('"', "") for ln in body]   # spreadsheet-quoted numbers
    if delim == ";":
        body = [ln.replace(",", ".") for ln in body]
    kw = {"delimiter": None if delim == "whitespace" else delim, "ndmin": 2, "dtype": float}
    if usecols is not None:
        kw["usecols"] = usecols
    elif ncols is not None and delim not in ("whitespace",):
        kw["usecols"] = range(ncols)
    try:
        data = np.loadtxt(body, **kw)
    except ValueError:
        _raise_bad_cell(body, first_row, delim, name, usecols, ncols)
        raise  # pragma: no cover - _raise_bad_cell always raises
    return data


def _raise_bad_cell(body, first_row, delim, name, usecols, ncols):
    want = list(usecols) if usecols is not None else None
    for k, line in enumerate(body):
        cells = _split(line, delim) if delim != "whitespace" else line.split()
        if not cells:
            raise DesignError(f"{name}: line {first_row + k + 1} is blank inside the data; "
                              "remove it")
        idx = want if want is not None else range(ncols or len(cells))
        for j in idx:
            if j >= len(cells) or cells[j] == "":
                raise DesignError(f"{name}: line {first_row + k + 1} has no value in column "
                                  f"{j + 1}; every data row needs all columns")
            if not _is_number(cells[j]):
                raise DesignError(f"{name}: line {first_row + k + 1}, column {j + 1}: "
                                  f"{cells[j]!r} is not a number; data cells must be numbers "
                                  "like 1.5e-3")
    raise DesignError(f"{name}: rows from line {first_row + 1} on do not form a numeric table "
                      "with the same number of columns on every line")


def _read_tektronix_tds(lines, name):
    """TDS/TBS: rows 'label,value,,time,value,'; the header block occupies cells 1-3."""
    meta = {}
    for line in lines[:40]:
        c = [x.strip() for x in line.split(",")]
        if len(c) >= 2 and c[0]:
            meta[c[0].lower()] = c[1]
    data = _load_numeric(lines, 0, ",", name, usecols=(3, 4))
    source = meta.get("source", "CH1") or "CH1"
    return ["TIME", source], data, "tektronix-tds", 0


def _read_rigol(lines, name):
    """Rigol: 'X,CH1[,CH2...],Start,Increment,' / 'Sequence,Volt,...,<start>,<inc>,'."""
    head = _cells(lines[0], ",")
    low = [h.lower() for h in head]
    if len(lines) < 3:
        raise DesignError(f"{name}: Rigol export has a header but no samples")
    second = _cells(lines[1], ",")
    try:
        i_start, i_inc = low.index("start"), low.index("increment")
        start, inc = float(second[i_start]), float(second[i_inc])
    except (ValueError, IndexError):
        raise DesignError(f"{name}: Rigol header line 2 must carry the Start and Increment "
                          f"values under 'Start' and 'Increment'; got {lines[1]!r}") from None
    if not (math.isfinite(inc) and inc > 0):
        raise DesignError(f"{name}: Rigol time increment must be a positive number; got {inc}")
    channels = head[1:i_start]
    data = _load_numeric(lines, 2, ",", name, usecols=range(1 + len(channels)))
    t = start + data[:, 0] * inc
    return ["TIME", *channels], np.column_stack([t, data[:, 1:]]), "rigol", 2


def _read_table(lines, name):
    """Generic table, project waveforms and Tektronix MSO/DPO: header lines, then numbers."""
    delim = _delimiter(lines)
    # Find the first row from which every row is numeric: scan from the top,
    # checking a few rows ahead so a lone numeric header value is not taken
    # for the data start.
    first_row = None
    for i, line in enumerate(lines[:400]):
        cells = _split(line, delim)
        if len(cells) >= 2 and all(_is_number(c) for c in cells):
            ahead = lines[i + 1:i + 4]
            if all(len(_split(a, delim)) >= 2 and all(_is_number(c) for c in _split(a, delim))
                   for a in ahead):
                first_row = i
                break
    if first_row is None:
        probe = _split(lines[min(len(lines) - 1, 1)], delim)
        if len(lines) <= 1 and probe and not all(_is_number(c) for c in probe):
            raise DesignError(f"{name}: the file has a header but no data rows")
        bad = next((c for c in probe if not _is_number(c)), None)
        if len(probe) < 2:
            raise DesignError(f"{name}: rows need at least two columns (time and output); "
                              f"line {min(len(lines), 2)} has {len(probe)}")
        raise DesignError(f"{name}: no numeric table found ({bad!r} is not a number); "
                          "expected rows of numbers: t,y or t,u,y")
    ncols = len(_split(lines[first_row], delim))
    header = _split(lines[first_row - 1], delim) if first_row > 0 else []
    if len(header) >= ncols and not all(_is_number(c) for c in header):
        columns = header[:ncols]
    else:
        columns = ["t"] + [f"col{j + 1}" for j in range(1, ncols)]
        if ncols == 2:
            columns = ["t", "y"]
        elif ncols == 3:
            columns = ["t", "u", "y"]
    is_mso = any(_cells(ln, ",")[:1] and _cells(ln, ",")[0].lower() == "model"
                 for ln in lines[:first_row])
    if is_mso:
        fmt = "tektronix-mso"
    elif columns and columns[0].lower() == "time_s":
        fmt = "waveform"
    else:
        fmt = "generic"
    data = _load_numeric(lines, first_row, delim, name, ncols=ncols)
    return columns, data, fmt, first_row


# --------------------------------------------------------------------------- columns

def _norm(name: str) -> str:
    n = name.strip().lower()
    n = re.sub(r"\s*[\(\[](s|v|a|volt|volts|sec|seconds)[\)\]]$", "", n)
    n = re.sub(r"_(v|a|s)$", "", n)
    return n


def _pick(spec, columns, what, name):
    if spec is None:
        return None
    if isinstance(spec, int) or (isinstance(spec, str) and spec.strip().isdigit()):
        k = int(spec)
        if not 2 <= k <= len(columns):
            raise DesignError(f"{name}: {what} column {k} does not exist; columns 2..{len(columns)} "
                              f"are signals ({', '.join(columns)})")
        return k - 1
    low = [c.lower() for c in columns]
    if spec.lower() in low[1:]:
        return low.index(spec.lower(), 1)
    raise DesignError(f"{name}: no {what} column named {spec!r}; the file has "
                      f"{', '.join(columns[1:])}")


def _assemble(columns, data, fmt, first_row, name, input_column, output_column) -> Capture:
    if data.shape[0] == 0:
        raise DesignError(f"{name}: the file has no data rows")
    if data.shape[1] < 2:
        raise DesignError(f"{name}: rows need at least two columns (time and output)")
    columns = list(columns) + [f"col{j + 1}" for j in range(len(columns), data.shape[1])]
    bad = ~np.isfinite(data)
    if bad.any():
        r, c = np.argwhere(bad)[0]
        raise DesignError(f"{name}: line {first_row + r + 1}, column {c + 1} is "
                          f"{data[r, c]!r}; NaN and infinite values are not allowed "
                          "(remove or interpolate those samples)")
    if data.shape[0] < 10:
        raise DesignError(f"{name}: only {data.shape[0]} samples; a step response needs at "
                          "least 10 (a few hundred is better)")
    t = data[:, 0]
    dt = np.diff(t)
    if not np.all(dt > 0):
        k = int(np.argmax(~(dt > 0)))
        raise DesignError(f"{name}: time is not increasing at line {first_row + k + 2} "
                          f"({t[k]!r} then {t[k + 1]!r}); the first column must be time in "
                          "seconds, strictly increasing")
    norm = [_norm(c) for c in columns]
    n_sig = data.shape[1] - 1
    no_input = isinstance(input_column, str) and input_column.lower() == "none"
    j_out = _pick(output_column, columns, "output", name)
    j_in = None if no_input else _pick(input_column, columns, "input", name)
    if j_out is None:
        named = [j for j in range(1, len(norm)) if norm[j] in OUTPUT_NAMES and j != j_in]
        j_out = named[0] if named else data.shape[1] - 1
        if j_out == j_in:
            j_out = next(j for j in range(data.shape[1] - 1, 0, -1) if j != j_in)
    notes = []
    if j_in is None and not no_input and n_sig >= 2:
        named = [j for j in range(1, len(norm)) if norm[j] in INPUT_NAMES and j != j_out]
        if named:
            j_in = named[0]
        else:
            j_in = next(j for j in range(1, data.shape[1]) if j != j_out)
            # Chosen by position only: accept it as the input only if it
            # looks like one (e.g. time_s,analytic,spice has no input column).
            if not looks_like_step_input(data[:, j_in], data[:, j_out]):
                notes.append(f"column {columns[j_in]!r} does not look like a step input "
                             "(its transitions are not much faster than the output's); "
                             "no input column used (see --input-column)")
                j_in = None
    u = None if j_in is None else np.ascontiguousarray(data[:, j_in])
    return Capture(t=np.ascontiguousarray(t), y=np.ascontiguousarray(data[:, j_out]), u=u,
                   fmt=fmt, columns=columns, output_name=columns[j_out],
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
