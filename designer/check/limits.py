"""A check's limits, as a spec states them: ``min``, ``typ`` and ``max``, each
a number in engineering notation (``3n3``, ``3.5k``) or, for ``min`` and
``max``, a signed percentage of ``typ`` (``"-1%"``, ``"+5%"``, as cicsim
writes them); ``fail: false`` makes a check report-only. A :class:`Limit`
that exists is consistent (a number in each given bound, ``min <= max``), and
:meth:`Limit.judge` is the one place a figure meets its limits.
"""

from __future__ import annotations

import math
import re
from dataclasses import dataclass

from ..core.errors import DesignError
from ..core.i18n import N_, Message
from ..core.units import format_eng, parse_value

__all__ = ["Limit", "limit_from"]

#: a bound relative to typ: a sign, a number, a percent sign
_RELATIVE = re.compile(r"^\s*([+-])\s*(\d+(?:\.\d*)?|\.\d+)(?:[eE][-+]?\d+)?\s*%\s*$")


def _number(value, where: str) -> float:
    """A bound as a float: a number, or text in engineering notation."""
    if isinstance(value, bool) or value is None:
        raise DesignError(f"{where} needs a number, got {value!r}")
    if isinstance(value, (int, float)):
        out = float(value)
    elif isinstance(value, str):
        if value.strip().endswith("%"):
            raise DesignError(f"{where} {value!r}: a percentage is relative to typ and needs a sign "
                              "(\"-1%\", \"+5%\"); write an absolute limit as a plain number")
        try:
            out = parse_value(value, where)
        except DesignError:
            raise DesignError(f"{where} {value!r} is not a number (use plain or engineering notation such "
                              "as 3n3, 3.5k, 1e-9, or \"-1%\" relative to typ)") from None
    else:
        raise DesignError(f"{where} needs a number, got a {type(value).__name__}")
    if not math.isfinite(out):
        raise DesignError(f"{where} needs a finite number, got {value!r}")
    return out


def _bound(value, typ, where: str) -> float | None:
    """``min``/``max``: absolute, or a signed percentage of ``typ``."""
    if value is None:
        return None
    if isinstance(value, str) and _RELATIVE.match(value):
        if typ is None:
            raise DesignError(f"{where} {value!r} is relative to typ, and there is no typ")
        pct = float(value.strip().replace("%", "").replace(" ", ""))
        return typ + abs(typ) * pct / 100.0
    return _number(value, where)


@dataclass(frozen=True)
class Limit:
    """The limits one figure must stay within (absolute values; a relative
    bound is resolved against ``typ`` on construction by :func:`limit_from`).

    ``fail`` False: report-only (the figure is measured and shown, never fails).
    """

    figure: str
    min: float | None
    typ: float | None
    max: float | None
    fail: bool = True
    unit: str = ""

    def judge(self, value) -> tuple:
        """(passed, text): whether ``value`` is within the limits, and the value
        against them in words (``overshoot_pct = 55.2 above max 55``).
        A missing value (None or NaN: not measured) never passes."""
        # typed messages (designer.core.i18n.Message): the text is the English, the page shows its language
        name = self.figure
        if value is None or (isinstance(value, float) and math.isnan(value)):
            return False, Message(N_("{figure} not measured (limits {limits})"), figure=name, limits=self.text())
        v = float(value)
        if self.min is not None and v < self.min:
            return False, Message(N_("{figure} = {value} below min {limit}"), figure=name, value=self.fmt(v),
                                  limit=self.fmt(self.min))
        if self.max is not None and v > self.max:
            return False, Message(N_("{figure} = {value} above max {limit}"), figure=name, value=self.fmt(v),
                                  limit=self.fmt(self.max))
        return True, Message(N_("{figure} = {value} within {limits}"), figure=name, value=self.fmt(v),
                             limits=self.text())

    def text(self) -> str:
        """``3.4 kHz .. 3.6 kHz``, ``<= 55``, ``>= 30``."""
        lo, hi = self.min, self.max
        if lo is not None and hi is not None:
            return f"{self.fmt(lo)} .. {self.fmt(hi)}"
        return f">= {self.fmt(lo)}" if lo is not None else f"<= {self.fmt(hi)}"

    def inside(self, lo, hi) -> bool:
        """Whether the band [lo, hi] stays inside the limits (a missing end is outside)."""
        if lo is None or hi is None:
            return False
        return (self.min is None or lo >= self.min) and (self.max is None or hi <= self.max)

    def fmt(self, v: float) -> str:
        return format_eng(v, self.unit, 5) if self.unit else f"{v:.6g}"


#: the keys a check's limits may have
LIMIT_KEYS = ("min", "typ", "max", "fail")


def limit_from(figure: str, entry: dict, where: str, unit: str = "") -> Limit:
    """A :class:`Limit` from a spec's mapping ``{min, typ, max, fail}`` (keys
    already checked), refusing in one line, prefixed with ``where``: a bound
    that is no number, a relative bound without typ, no bound at all, min above
    max, typ outside them, a ``fail`` that is not true or false.

    Parameters
    ----------
    figure : str
        The figure limited.
    entry : dict
        The spec's ``{min, typ, max, fail}`` mapping.
    where : str
        What an error message starts with (the spec's file and line).
    unit : str
        The figure's unit, for the messages.

    Returns
    -------
    Limit
        The limit.
    """
    typ = None if entry.get("typ") is None else _number(entry["typ"], f"{where}.typ")
    lo = _bound(entry.get("min"), typ, f"{where}.min")
    hi = _bound(entry.get("max"), typ, f"{where}.max")
    fail = entry.get("fail", True)
    if not isinstance(fail, bool):
        raise DesignError(f"{where}.fail must be true or false (false: report only), got {fail!r}")
    if lo is None and hi is None:
        raise DesignError(f"{where} needs min or max (typ alone limits nothing)")
    if lo is not None and hi is not None and lo > hi:
        raise DesignError(f"{where}: min {lo:.6g} is above max {hi:.6g}")
    if typ is not None and not ((lo is None or lo <= typ) and (hi is None or typ <= hi)):
        raise DesignError(f"{where}: typ {typ:.6g} is outside min/max")
    return Limit(figure, lo, typ, hi, fail, unit)
