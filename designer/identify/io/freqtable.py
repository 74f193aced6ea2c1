"""Frequency-response tables: :func:`read_freq_table` (:func:`parse_freq_table`
for text) reads frequency, gain (dB or amplitude ratio) and optionally phase
(degrees, radians, or the time shift of the output behind the input, as seed
000 Table IV measures it: phase = -360 f dt degrees) into a :class:`FreqData`.
Every row's values are checked against their physical ranges before any
arithmetic, so no overflow reaches the fits.
"""

from __future__ import annotations

import math
import re
from dataclasses import dataclass, field

import numpy as np

from ...core.errors import DesignError
from ...core.fileio import MAX_TABLE_BYTES, read_text, show_cell, shown
from ...core.ranges import RANGES
from ..edges import number_text

__all__ = ["FreqData", "NUMBER", "unit_hint", "FREQ_UNITS", "GAIN_UNITS", "MAX_POINTS", "MIN_POINTS", "PHASE_UNITS",
           "freq_data", "parse_freq_table", "read_freq_table"]


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

    Parameters
    ----------
    freq, gain : array_like
        Frequency and gain columns.
    phase : array_like, optional
        Phase column.
    gain_units, phase_units, freq_units : str, optional
        Units of the columns (``db``/``ratio``, ``deg``/``rad``/``s``, ``hz``/``rad/s``).
    source : str, optional
        The table's name, for messages.
    lines : sequence of int, optional
        The file lines of the rows, for messages.

    Returns
    -------
    FreqData
        The table in rad/s, amplitude ratio and radians.


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


NUMBER = re.compile(r"^[+-]?(\d+\.?\d*|\.\d+)([eE][+-]?\d+)?$")


def _tokens(name: str) -> set:
    return set(re.split(r"[^a-z0-9/µμ°]+", name.lower().replace("µ", "u").replace("μ", "u"))) - {""}


def unit_hint(name: str, kind: str):
    """Units named in a header cell, or None.

    Parameters
    ----------
    name : str
        A header cell.
    kind : str
        The column: ``frequency``, ``gain`` or ``phase``.

    Returns
    -------
    tuple or None
        ``(units, scale)``, e.g. ``("hz", 1e3)`` for kHz, or None.
    """
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

    Parameters
    ----------
    text : str
        The CSV text.
    gain_units, phase_units, freq_units : str, optional
        Units of the columns; None: from the header, else the defaults.
    source : str, optional
        The table's name, for messages.

    Returns
    -------
    FreqData
        The validated table (see :func:`freq_data`).
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
    if not all(NUMBER.match(c) or c.lower() in ("nan", "inf", "-inf") for c in c0):
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
            if not NUMBER.match(c):
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
        h = unit_hint(name, k) if name else None
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
    :data:`~designer.core.fileio.MAX_TABLE_BYTES`, UTF-8 or ASCII.

    Parameters
    ----------
    path : str or path-like
        The CSV file.
    **units
        ``gain_units``, ``phase_units``, ``freq_units`` of :func:`parse_freq_table`.

    Returns
    -------
    FreqData
        The validated table.
    """
    text = read_text(path, "table", MAX_TABLE_BYTES)
    return parse_freq_table(text, source=shown(path), **units)
