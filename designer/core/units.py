"""Engineering notation: parse ``4k7``, ``10n``, ``2u2``, ``3.5k``, ``1e-9``
and format numbers back as ``4k7``-style value codes or ``4.70 kOhm``.

Parsing is strict: anything that is not a finite number is a
:class:`~designer.core.errors.DesignError` naming the field (its ``param``).
"""

from __future__ import annotations

import math
import re

from .errors import DesignError

__all__ = ["figure_unit", "format_eng", "format_figure", "parse_value", "value_code"]

# SI multipliers; "u" and "µ" both mean micro, "M" mega and "m" milli as in engineering
# notation, and SPICE's "meg" (any case: MEG, Meg) mega too.
_PREFIX = {
    "f": 1e-15, "p": 1e-12, "n": 1e-9, "u": 1e-6, "µ": 1e-6, "μ": 1e-6,
    "m": 1e-3, "": 1.0, "k": 1e3, "K": 1e3, "M": 1e6, "meg": 1e6, "G": 1e9, "T": 1e12,
    "R": 1.0, "r": 1.0,
}
_NUM = r"[+-]?(?:\d+\.?\d*|\.\d+)(?:[eE][+-]?\d+)?"
_P = r"(?i:meg)|[fpnuµμmkKMGTRr]"
# 3.5k, 10n, 2.2meg, 1e-9
_SUFFIX = re.compile(rf"^({_NUM})({_P})?$")
# 4k7, 2u2, 1M5, 4R7, 1meg5: the prefix letter stands for the decimal point
_INFIX = re.compile(rf"^([+-]?\d+)({_P})(\d+)$")
# prefix letters a trailing f/F can follow as the farad unit ("10pf", "100fF")
_PREFIX_LETTERS = "fpnuµμmkKMGT"


def _strip_unit(s: str) -> str:
    """Drop a trailing unit: ohm(s)/Ω, Hz, V, s, or F. A trailing ``f`` is femto
    (as in SPICE) unless it follows a prefix (``10pf``, ``100fF``); ``F`` after a
    digit is farads (``10F``)."""
    low = s.lower()
    for unit in ("ohms", "ohm", "ω", "hz"):
        if low.endswith(unit) and len(s) > len(unit):
            return s[: -len(unit)]
    last = s[-1:]
    if len(s) > 1 and last in ("v", "V", "s"):
        return s[:-1]
    if len(s) > 1 and last in ("f", "F"):
        if s[-2] in _PREFIX_LETTERS or low[:-1].endswith("meg") or last == "F":
            return s[:-1]
    return s


def parse_value(text, name: str = "value") -> float:
    """Parse a number in engineering notation.

    Parameters
    ----------
    text : str or float
        ``"4k7"``, ``"10n"``, ``"2u2"``, ``"3.5k"``, ``"1e-9"``, ``"220nF"``,
        ``"3.5MEG"``, ``"1.6 kOhm"`` (this tool's own printed values read back),
        ``"4.7kΩ"``. A trailing ``f`` is femto, as in SPICE (``10f`` = 10e-15),
        unless it is the farad after a prefix (``10pf``); ``10F`` is 10 farads.
    name : str
        What the number is, for the error message.

    Returns
    -------
    float

    Raises
    ------
    DesignError
        If the text is not a finite number.
    """
    if isinstance(text, (int, float)) and not isinstance(text, bool):
        value = float(text)
    else:
        s = "".join(str(text).split())
        s = _strip_unit(s)
        if (m := _SUFFIX.match(s)):
            value = float(m.group(1)) * _PREFIX[_prefix_key(m.group(2))]
        elif (m := _INFIX.match(s)):
            sign = -1.0 if m.group(1).startswith("-") else 1.0
            whole = m.group(1).lstrip("+-")
            value = sign * float(f"{whole}.{m.group(3)}") * _PREFIX[_prefix_key(m.group(2))]
        else:
            raise DesignError(
                f"{name}: {_short(text)} is not a number (use plain or engineering notation "
                "such as 4k7, 820, 10n, 2u2, 3.5k, 1e-9)", param=name)
    if not math.isfinite(value):
        raise DesignError(f"{name}: {_short(text)} is not a finite number", param=name)
    return value


def _prefix_key(p) -> str:
    if p is None:
        return ""
    return "meg" if p.lower() == "meg" else p


def _short(text, limit: int = 40) -> str:
    """A printable, bounded rendering of user text for a one-line message."""
    if isinstance(text, float):
        return f"{text:g}"
    r = repr(str(text))
    return r if len(r) <= limit else r[: limit - 4] + "...'"


_ENG = [(1e9, "G"), (1e6, "M"), (1e3, "k"), (1.0, ""), (1e-3, "m"), (1e-6, "u"),
        (1e-9, "n"), (1e-12, "p"), (1e-15, "f")]


def _split(value: float):
    a = abs(value)
    if a == 0 or not math.isfinite(a):
        return value, ""
    for mult, prefix in _ENG:
        if a >= mult * 0.9995:
            return value / mult, prefix
    return value / 1e-15, "f"


def format_eng(value: float, unit: str = "", digits: int = 4) -> str:
    """``format_eng(4700, "Ohm")`` -> ``"4.7 kOhm"``; ``digits`` significant.

    Parameters
    ----------
    value : float
        The value.
    unit : str
        Its unit.
    digits : int
        Significant digits.

    Returns
    -------
    str
        The text.
    """
    if value is None or (isinstance(value, float) and math.isnan(value)):
        return "n/a"
    mant, prefix = _split(float(value))
    text = f"{mant:.{digits}g}"
    sep = " " if unit or prefix else ""
    return f"{text}{sep}{prefix}{unit}"


def value_code(value: float) -> str:
    """Part marking style: 4700 -> ``4k7``, 820 -> ``820``, 1e-8 -> ``10n``,
    2.2e-6 -> ``2u2``, 4.7 -> ``4R7``, 1e6 -> ``1M``.

    Parameters
    ----------
    value : float
        A part's value.

    Returns
    -------
    str
        Its marking.
    """
    mant, prefix = _split(float(value))
    text = f"{mant:.3g}"
    if "e" in text:  # mantissa always < 1000, but be safe
        text = f"{mant:.0f}"
    if "." in text:
        whole, frac = text.split(".")
        return f"{whole}{prefix or 'R'}{frac}"
    return f"{text}{prefix}"


#: a figure's unit from its name's suffix (the figures of designer.check.figures and the tolerance engines)
_SUFFIX_UNITS = (("_hz", "Hz"), ("_s", "s"), ("_pct", "%"), ("_deg", "deg"), ("_db", "dB"))


def figure_unit(name: str) -> str:
    """``fn_hz`` -> Hz, ``peak_time_s`` -> s, ``overshoot_pct`` -> %, ``phase_margin_deg`` -> deg,
    ``gain_margin_db`` -> dB; a figure without a unit (``zeta``, ``kp``) -> "".

    Parameters
    ----------
    name : str
        The figure's name.

    Returns
    -------
    str
        Its unit.
    """
    return next((u for s, u in _SUFFIX_UNITS if name.endswith(s)), "")


def format_figure(name: str, value: float, digits: int = 4) -> str:
    """A figure's value with its unit: engineering notation for Hz and s (``3.3 kHz``), else the number
    and the unit (``25 deg``, ``15 %``, ``0.2``).

    Parameters
    ----------
    name : str
        The figure's name.
    value : float
        Its value.
    digits : int
        Significant digits.

    Returns
    -------
    str
        The text.
    """
    unit = figure_unit(name)
    if unit in ("Hz", "s"):
        return format_eng(value, unit, digits)
    if value is None or math.isnan(value):
        # as format_eng words it: a figure no build has (a clipped SPICE step's zeta) is not a number to show
        return "n/a"
    return f"{value:.{digits}g}" + (f" {unit}" if unit else "")
