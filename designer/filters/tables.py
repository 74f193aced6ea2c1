"""The normalised section tables of the filter literature, computed from
scipy's prototypes (:func:`designer.filters.prototype.plan_sections`), never typed:
the coefficient tables of TI's "Op Amps for Everyone", ch. 16 (SLOA088,
section 16.9: Bessel, Butterworth and Tschebyscheff 0.5/1/2/3 dB, after
Tietze and Schenk, "Halbleiter-Schaltungstechnik").

Those tables write section i of a low-pass normalised to the filter's corner
fC as 1 / (1 + a_i s + b_i s^2) (first order: b_i = 0), s in units of 2 pi fC,
so that

    fn_i / fC = 1 / sqrt(b_i),   Q_i = sqrt(b_i) / a_i,   first order: fn_i / fC = 1 / a_i,

and list k_i = fC_i / fC, the -3 dB frequency of section i alone (relative to
its own DC gain), which is not its fn: for a second-order section with
x = f / fn, |H|^2 = 1 / ((1 - x^2)^2 + x^2 / Q^2) is half its DC value at

    x^2 = (2 - 1/Q^2 + sqrt((2 - 1/Q^2)^2 + 4)) / 2.

Their corner fC is the frequency where the whole filter is 3 dB below its DC
gain: Butterworth and Bessel (``besselap``'s ``norm="mag"``) at 1 rad/s as
scipy gives them; a Chebyshev of ripple r dB, eps = sqrt(10^(r/10) - 1), at
|T_n(w)| = sqrt(1/eps^2 + 2 T_n(0)^2), T_n(0)^2 = 0 for odd n and 1 for even n
(an even-order Chebyshev starts at the bottom of its ripple), i.e.

    w = cosh(acosh(sqrt(1/eps^2 + 2 T_n(0)^2)) / n)

times the ripple edge: neither scipy's ``cheby1`` convention (the ripple edge)
nor this package's ``--chebyshev-cutoff 3db`` (3 dB below the ripple's top) for
an even order. That is one reason a design's fn differ from a table's.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

from .prototype import plan_sections

__all__ = ["TableRow", "table_corner", "section_3db_ratio", "coefficient_table"]


@dataclass(frozen=True)
class TableRow:
    """One section of a normalised coefficient table.

    Parameters
    ----------
    number : int
        i, 1-based, in the table's order (the first-order section first, then rising Q).
    order : int
        1 or 2.
    a, b : float
        The coefficients of 1 + a s + b s^2 (b = 0 for first order).
    k : float
        fC_i / fC: the section's own -3 dB frequency over the filter's corner.
    fn_ratio : float
        fn_i / fC.
    q : float or None
        Quality factor (None for first order).
    """

    number: int
    order: int
    a: float
    b: float
    k: float
    fn_ratio: float
    q: float | None


def table_corner(family: str, order: int, ripple_db: float = 1.0) -> float:
    """The tables' corner fC over the prototype's 1 rad/s (Chebyshev: its ripple edge).

    Parameters
    ----------
    family : str
        ``butterworth``, ``bessel`` or ``chebyshev``.
    order : int
        Filter order.
    ripple_db : float
        Chebyshev ripple, dB.

    Returns
    -------
    float
        1 for Butterworth and Bessel (magnitude-normalised); for a Chebyshev the
        frequency 3 dB below its DC gain (the module docstring's closed form).
    """
    if family != "chebyshev":
        return 1.0
    eps = math.sqrt(10 ** (ripple_db / 10) - 1)
    t0_sq = 0.0 if order % 2 else 1.0
    return math.cosh(math.acosh(math.sqrt(1 / eps ** 2 + 2 * t0_sq)) / order)


def section_3db_ratio(q: float | None) -> float:
    """f_-3dB / fn of one low-pass section alone (relative to its DC gain).

    Parameters
    ----------
    q : float or None
        The section's Q (None: first order).

    Returns
    -------
    float
        1 for first order; else sqrt(x^2) of the module docstring.
    """
    if q is None:
        return 1.0
    u = 2 - 1 / q ** 2
    return math.sqrt((u + math.sqrt(u * u + 4)) / 2)


def coefficient_table(family: str, order: int, ripple_db: float = 1.0) -> list:
    """The normalised coefficient table of a low-pass (SLOA088 section 16.9's layout).

    Parameters
    ----------
    family : str
        ``butterworth``, ``bessel`` (magnitude-normalised) or ``chebyshev``.
    order : int
        1..10.
    ripple_db : float
        Chebyshev passband ripple, dB.

    Returns
    -------
    list of TableRow
        The sections, first order first, then in rising Q.
    """
    corner = table_corner(family, order, ripple_db)
    rows = []
    for i, sec in enumerate(plan_sections("lowpass", family, order, 1.0, ripple_db, "mag", "ripple"), 1):
        fn = sec.fn_hz / corner
        if sec.q is None:
            rows.append(TableRow(i, 1, 1 / fn, 0.0, fn, fn, None))
        else:
            rows.append(TableRow(i, 2, 1 / (fn * sec.q), 1 / fn ** 2, fn * section_3db_ratio(sec.q), fn, sec.q))
    return rows
