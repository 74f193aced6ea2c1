"""Each part's tolerance: from its E-series (E24 5 %, E96 1 %, E12 10 %, as the
build sheet states, :data:`designer.core.eseries.TOLERANCE`) unless the user gives
it, by class (``R=1%``, ``C=5%``) or by designator (``C2=2%``), which wins.

A :class:`Tolerances` that exists is valid: every value above 0 and at most
:data:`MAX_TOL`, every designator one the design has.

The op-amp's own spread (``--tol GBW=30% SR=20%``) varies only when named (a
datasheet's typical is not a tolerance): one gain-bandwidth and one slew rate per
build, shared by every op-amp of it (one lot). A build's slew rate follows its
gain-bandwidth (SR x GBW/GBW_nominal: the compensation capacitor that sets the
one sets the other, I/C with the input stage's current fixed) unless SR is
spread itself, then it is drawn on its own (:func:`opamp_arrays`).
"""

from __future__ import annotations

import re
from dataclasses import dataclass

import numpy as np

from ..core.errors import DesignError
from ..core.units import parse_value

__all__ = ["DISTRIBUTIONS", "MAX_TOL", "check_items", "opamp_nominal", "parse_tolerance", "resolve"]

#: the largest tolerance accepted (a fraction)
MAX_TOL = 0.5
#: distributions: uniform in nominal (1 +- tol), or normal with sigma = tol/3 truncated at +- tol
DISTRIBUTIONS = ("uniform", "normal")
#: the op-amp's figures a --tol may spread (only when named: no series gives them)
OPAMP_FIGURES = ("GBW", "SR")
#: what each op-amp figure is, for messages
OPAMP_WHAT = {"GBW": "gain-bandwidth", "SR": "slew rate"}
_ITEM = re.compile(r"^\s*([A-Za-z][A-Za-z0-9]*)\s*=\s*(.+?)\s*$")


def parse_tolerance(text: str, where: str) -> float:
    """``1%``, ``0.5 %``, ``0.01`` -> a fraction in (0, MAX_TOL].

    Parameters
    ----------
    text : str
        The tolerance as given.
    where : str
        What the message names.

    Returns
    -------
    float
        The fraction.
    """
    t = str(text).strip()
    pct = t.endswith("%")
    try:
        v = parse_value(t[:-1].strip() if pct else t, where)
    except DesignError:
        raise DesignError(f"{where}: {text!r} is not a tolerance (give a percentage such as 1% or 0.5%)") from None
    v = v / 100 if pct else v
    if not 0 < v <= MAX_TOL:
        raise DesignError(f"{where}: a tolerance must be above 0 and at most {100 * MAX_TOL:g} %, got {text!r}")
    return float(v)


@dataclass(frozen=True)
class Tolerances:
    """Tolerance (fraction) per designator (``R1``, ``C2``) of the parts that vary."""

    of: dict

    def designators(self) -> tuple:
        return tuple(self.of)

    def to_dict(self) -> dict:
        return {k: 100 * v for k, v in self.of.items()}


def split_items(items) -> list:
    """``--tol`` items as (KEY, value text) pairs, each key at most once: ``R=1%`` and
    ``R=2%`` (or ``r=2%``) are refused in one line rather than the last one winning."""
    out, seen = [], {}
    for item in items or ():
        m = _ITEM.match(str(item))
        if not m:
            raise DesignError(f"--tol {item!r}: give CLASS=PCT or DESIGNATOR=PCT, such as R=1% or C2=2%")
        key, value = m.group(1).upper(), m.group(2)
        if key in seen:
            raise DesignError(f"--tol {key} given twice: {seen[key]} and {value}; give each class or part once")
        seen[key] = value
        out.append((key, value))
    return out


def check_items(items, designators) -> None:
    """``--tol`` items checked before any work: the shape, the value, a class or one of ``designators``,
    each once (:func:`split_items`).

    Parameters
    ----------
    items : sequence of str
        The ``--tol`` items.
    designators : iterable of str
        The parts they may name.
    """
    for key, value in split_items(items):
        parse_tolerance(value, f"--tol {key}")
        if key not in ("R", "C") and key not in designators and key not in OPAMP_FIGURES:
            raise DesignError(f"--tol {key}: no such part; the parts are {', '.join(designators)} (or R, C for "
                              "every resistor, every capacitor)")


def resolve(items, parts: dict, series: dict) -> Tolerances:
    """The tolerance of each part of ``parts`` (designator -> value).

    Parameters
    ----------
    items : sequence of str
        ``R=1%`` (every resistor), ``C=5%`` (every capacitor), ``C2=2%`` (one part), each
        once; a designator wins over its class.
    parts : dict
        Designator -> nominal value of every part that varies.
    series : dict
        ``"R"``/``"C"`` -> the E-series the design's resistors and capacitors come from (their default
        tolerance), or None for parts typed by hand (then the class or the designator must be given).

    Returns
    -------
    Tolerances
        Each part's tolerance and where it came from.
    """
    from ..core.eseries import TOLERANCE
    classes, singles = {}, {}
    for key, value in split_items(items):
        tol = parse_tolerance(value, f"--tol {key}")
        if key in ("R", "C"):
            classes[key] = tol
        elif key in parts:
            singles[key] = tol
        else:
            known = ", ".join(sorted(parts))
            raise DesignError(f"--tol {key}: this design has no part {key}; its parts are {known} (or R, C for "
                              "every resistor, every capacitor)")
    out = {}
    for ref in parts:
        kind = ref[0]
        if ref in singles:
            out[ref] = singles[ref]
        elif kind in classes:
            out[ref] = classes[kind]
        elif ref in OPAMP_FIGURES:
            raise DesignError(f"--tol {ref}: give its spread (such as {ref}=30%)")
        elif series.get(kind) is not None:
            out[ref] = TOLERANCE[series[kind]]
        else:
            raise DesignError(f"--tol: {ref} was typed by hand, so its series (and tolerance) is unknown; give "
                              f"--tol {kind}=PCT or --tol {ref}=PCT")
    return Tolerances(out)


def opamp_nominal(items, opamp) -> dict:
    """The op-amp figures the ``--tol`` ``items`` name (``GBW=30%``, ``SR=20%``) -> their nominal
    values (Hz, V/s) of ``opamp``; empty when none is named.

    Parameters
    ----------
    items : sequence of str
        The ``--tol`` items.
    opamp : designer.core.opamps.OpAmp
        The op-amp.

    Returns
    -------
    dict
        ``GBW`` and ``SR`` -> nominal value.

    Raises
    ------
    DesignError
        When one is named for the ideal op-amp (it has neither).
    """
    named = set()
    for item in items or ():
        m = _ITEM.match(str(item))
        if m and m.group(1).upper() in OPAMP_FIGURES:
            named.add(m.group(1).upper())
    if named and opamp.ideal:
        f = next(f for f in OPAMP_FIGURES if f in named)
        raise DesignError(f"--tol {f}: the ideal op-amp has no {OPAMP_WHAT[f]} to spread")
    nominal = {"GBW": opamp.gbw_hz, "SR": opamp.slew_v_per_s}
    return {f: nominal[f] for f in OPAMP_FIGURES if f in named}


def opamp_arrays(opamp, values: dict, n: int) -> tuple:
    """(gain-bandwidth, slew rate) of each of ``n`` builds, arrays: the drawn ``GBW`` and ``SR``
    where ``values`` has them, else the nominal, SR scaled with GBW when only GBW is drawn
    (module docstring)."""
    gbw = np.broadcast_to(np.asarray(values.get("GBW", opamp.gbw_hz), float), (n,))
    if "SR" in values:
        sr = np.broadcast_to(np.asarray(values["SR"], float), (n,))
    else:
        sr = opamp.slew_v_per_s * gbw / opamp.gbw_hz
    return gbw, sr


def sample_opamp(opamp, values: dict, i: int):
    """The op-amp of build ``i`` (:func:`opamp_arrays`; ``opamp`` itself when neither figure varies)."""
    if "GBW" not in values and "SR" not in values:
        return opamp
    import dataclasses
    gbw, sr = opamp_arrays(opamp, {k: values[k][i:i + 1] for k in OPAMP_FIGURES if k in values}, 1)
    return dataclasses.replace(opamp, gbw_hz=float(gbw[0]), slew_v_per_s=float(sr[0]))
