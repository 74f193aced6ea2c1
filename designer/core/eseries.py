"""IEC 60063 preferred-number series E3 to E192, nearest-value helpers, and
the part bounds a design chooses within (:class:`PartBounds`).

E3..E24 are tabulated in the standard (they are not the rounded geometric
series); E48..E192 follow round(10**(i/N), 2) with the one exception the
standard makes (E192 lists 9.20 where the formula gives 9.19).
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from .errors import DesignError, ParamError
from .ranges import parse_in_range

__all__ = ["PartBounds", "SERIES", "TOLERANCE", "check_bounds", "nearest", "nearest_ratio_pair", "nearest_ratio_of", "series_name",
           "smallest_series", "values"]

_E24 = (1.0, 1.1, 1.2, 1.3, 1.5, 1.6, 1.8, 2.0, 2.2, 2.4, 2.7, 3.0,
        3.3, 3.6, 3.9, 4.3, 4.7, 5.1, 5.6, 6.2, 6.8, 7.5, 8.2, 9.1)


def _geometric(n: int) -> tuple:
    vals = [round(100 * 10 ** (i / n)) / 100 for i in range(n)]
    if n == 192:
        vals[185] = 9.20
    return tuple(vals)


SERIES = {
    "E3": (1.0, 2.2, 4.7),
    "E6": (1.0, 1.5, 2.2, 3.3, 4.7, 6.8),
    "E12": _E24[::2],
    "E24": _E24,
    "E48": _geometric(48),
    "E96": _geometric(96),
    "E192": _geometric(192),
}

#: Tolerance that goes with each series (IEC 60063), as a fraction.
TOLERANCE = {"E3": 0.40, "E6": 0.20, "E12": 0.10, "E24": 0.05,
             "E48": 0.02, "E96": 0.01, "E192": 0.005}


def series_name(name: str) -> str:
    """Normalise ``"e24"``/``"24"`` to ``"E24"``; a :class:`DesignError` if unknown.

    Parameters
    ----------
    name : str
        A series name as typed.

    Returns
    -------
    str
        The series name.
    """
    key = str(name).strip().upper()
    if not key.startswith("E"):
        key = "E" + key
    if key not in SERIES:
        raise DesignError(
            f"unknown E-series {name!r}; allowed: {', '.join(SERIES)}")
    return key


@dataclass(frozen=True, kw_only=True)
class PartBounds:
    """Where a design's parts come from: the E-series of the resistors and the
    capacitors and the value bounds of each (the ``--r-series``..``--c-max``
    options of every command that chooses parts).

    Validated once, when built: every bound a number (or engineering notation,
    ``"4k7"``) inside the physical range of its kind, each minimum at most its
    maximum, the series names normalised (``"e24"`` -> ``"E24"``). A spec that
    chooses parts derives from it (keyword-only fields, so they follow the
    spec's own) and calls :meth:`check_bounds` in its own ``__post_init__``.
    """

    r_series: str = "E24"
    c_series: str = "E12"
    r_min: float = 1e3
    r_max: float = 1e6
    c_min: float = 1e-9
    c_max: float = 1e-5

    def __post_init__(self):
        self.check_bounds()

    def check_bounds(self) -> None:
        """Parse, check and normalise the bounds and series (frozen: once, here)."""
        for name, key in (("r_min", "resistor_ohm"), ("r_max", "resistor_ohm"),
                          ("c_min", "capacitor_f"), ("c_max", "capacitor_f")):
            object.__setattr__(self, name, parse_in_range(getattr(self, name), name, key))
        for kind, unit in (("r", "Ohm"), ("c", "F")):
            lo, hi = getattr(self, f"{kind}_min"), getattr(self, f"{kind}_max")
            if lo > hi:
                raise ParamError(f"{{{kind}_min}} ({lo:g} {unit}) is above {{{kind}_max}} ({hi:g} {unit})")
        object.__setattr__(self, "r_series", series_name(self.r_series))
        object.__setattr__(self, "c_series", series_name(self.c_series))


def check_bounds(r_series: str, c_series: str, r_min: float, r_max: float, c_min: float, c_max: float):
    """The normalised series names of valid bounds (see :class:`PartBounds`).

    Parameters
    ----------
    r_series, c_series : str
        The resistors' and the capacitors' series.
    r_min, r_max : float
        The resistors' range (Ohm).
    c_min, c_max : float
        The capacitors' range (F).

    Returns
    -------
    tuple of str
        The normalised (r_series, c_series).
    """
    b = PartBounds(r_series=r_series, c_series=c_series, r_min=r_min, r_max=r_max, c_min=c_min, c_max=c_max)
    return b.r_series, b.c_series


def values(series: str, lo: float, hi: float) -> np.ndarray:
    """All values of ``series`` in the closed range [lo, hi], ascending.

    A relative slack of 1e-9 keeps the bounds themselves (1 kOhm, 1 MOhm) in
    despite floating-point decades.

    Parameters
    ----------
    series : str
        The E-series.
    lo, hi : float
        The range.

    Returns
    -------
    numpy.ndarray
        The values.
    """
    key = series_name(series)
    if not (lo > 0 and hi > 0):
        raise DesignError(f"value bounds must be positive, got {lo:g}..{hi:g}")
    if lo > hi:
        raise DesignError(f"value bounds are reversed: {lo:g} > {hi:g}")
    base = np.asarray(SERIES[key])
    d0 = int(np.floor(np.log10(lo))) - 1
    d1 = int(np.ceil(np.log10(hi))) + 1
    decades = 10.0 ** np.arange(d0, d1 + 1)
    # round to 3 significant figures so 4.7 * 1e-9 prints and compares cleanly
    allv = np.array([float(f"{v:.3g}") for v in np.outer(decades, base).ravel()])
    keep = (allv >= lo * (1 - 1e-9)) & (allv <= hi * (1 + 1e-9))
    return np.unique(allv[keep])


def smallest_series(value: float):
    """The coarsest series (E3 first) that holds ``value`` (any decade), or None
    for a value no series has (e.g. 1k26 is E192 only; 1.234k is none).

    Parameters
    ----------
    value : float
        A part's value.

    Returns
    -------
    str or None
        The series name.
    """
    if not (value > 0 and np.isfinite(value)):
        return None
    mant = value / 10.0 ** np.floor(np.log10(value))
    for name, vals in SERIES.items():
        if np.any(np.abs(np.asarray(vals) / mant - 1) < 1e-6) or abs(mant / 10 - 1) < 1e-6 and 1.0 in vals:
            return name
    return None


def nearest(value: float, series: str = "E24") -> float:
    """The series value nearest to ``value`` by log distance (no bounds).

    Parameters
    ----------
    value : float
        The value.
    series : str
        The E-series.

    Returns
    -------
    float
        The nearest series value.
    """
    if not value > 0:
        raise DesignError(f"cannot round {value!r} to a series value: must be positive")
    cands = values(series, value / 20, value * 20)
    return float(cands[np.argmin(np.abs(np.log(cands / value)))])


def nearest_ratio_pair(ratio: float, series: str, lo: float, hi: float):
    """Two values a, b of ``series`` in [lo, hi] whose ratio a/b is nearest to ``ratio``
    (log distance); ties go to the pair with the larger b (lower noise gain error
    does not depend on it, but larger resistors load op-amps less).

    Parameters
    ----------
    ratio : float
        The ratio wanted.
    series : str
        The E-series.
    lo, hi : float
        The range of the values.

    Returns
    -------
    tuple of float
        (a, b).
    """
    v = values(series, lo, hi)
    if v.size == 0:
        raise DesignError(f"no {series} value between {lo:g} and {hi:g}")
    return nearest_ratio_of(ratio, v)


def nearest_ratio_of(ratio: float, v) -> tuple:
    """Two of the values ``v`` whose ratio a/b is nearest to ``ratio`` (log distance; of
    equal ones the first in ``v``'s order of a, then of b): :func:`nearest_ratio_pair` on given values.

    Parameters
    ----------
    ratio : float
        The ratio wanted.
    v : array_like
        The values (ascending, as :func:`values` gives them).

    Returns
    -------
    tuple of float
        (a, b).
    """
    v = np.asarray(v, dtype=float)
    err = np.abs(np.log(np.outer(v, 1.0 / v) / ratio))
    i, j = np.unravel_index(np.argmin(err), err.shape)
    return float(v[i]), float(v[j])
