"""A small op-amp catalogue (data in ``data/opamps.json``) and the single-pole
op-amp model that both the analytic models and the SPICE subcircuit use.

The model: A(s) = A0 / (1 + s / wp) with wp = 2 pi GBW / A0, a slew-rate
limit, and an output that stays ``swing_*`` volts inside the rails.

The packages an op-amp comes in (:class:`Package`: DIP-8 single, DIP-8 dual,
DIP-14 quad, with the datasheet pin numbers) and the assignment of a circuit's
op-amps to the units of such packages (:func:`assign`) live here too: the
seed's bench (001, section V.13, Figure 77) wires seven LM741s, one per DIP-8.
"""

from __future__ import annotations

import json
from dataclasses import dataclass
from functools import lru_cache
from importlib import resources

from .errors import DesignError

__all__ = ["OpAmp", "PACKAGE_KINDS", "Unit", "assign", "get", "names", "spare_units"]


@dataclass(frozen=True)
class OpAmp:
    """Datasheet-typical figures of one op-amp."""

    name: str
    description: str
    a0: float            #: DC open-loop gain (V/V)
    gbw_hz: float        #: gain-bandwidth product (Hz)
    slew_v_per_s: float  #: slew rate (V/s)
    vcc: float           #: positive supply (V)
    vee: float           #: negative supply (V)
    swing_high_v: float  #: output headroom below vcc (V)
    swing_low_v: float   #: output headroom above vee (V)
    ideal: bool = False
    packages: dict | None = None  #: kind (single, dual, quad) -> {"part", "pinout"}; the first is the default

    @property
    def vout_max(self) -> float:
        return self.vcc - self.swing_high_v

    @property
    def vout_min(self) -> float:
        return self.vee + self.swing_low_v

    @property
    def pole_hz(self) -> float:
        """Open-loop dominant pole, GBW / A0."""
        return self.gbw_hz / self.a0

    def package(self, kind: str | None = None) -> "Package":
        """The package of ``kind`` (``single``, ``dual``, ``quad``; None: the op-amp's
        default, its first listed). An ideal op-amp is drawn in a generic DIP-8 single.

        Raises
        ------
        DesignError
            When the op-amp does not come in that kind of package (one line, naming
            the kinds it has).
        """
        if kind is not None and kind not in PACKAGE_KINDS:
            raise DesignError(f"unknown package {kind!r}; allowed: {', '.join(PACKAGE_KINDS)}", param="package")
        offered = self.packages or {"single": {"part": "op-amp", "pinout": "DIP-8 single"}}
        if kind is None:
            kind = next(iter(offered))
        if kind not in offered:
            raise DesignError(f"{self.name} has no {kind} package; it comes as "
                              + ", ".join(f"{k} ({v['part']})" for k, v in offered.items()), param="package")
        entry = offered[kind]
        p = _catalogue_raw()["_pinouts"][entry["pinout"]]
        return Package(kind, entry["part"], entry["pinout"], p["pins"],
                       {u: dict(v) for u, v in p["units"].items()}, p["vcc"], p["vee"],
                       {int(k): v for k, v in p["unused"].items()})

    def to_dict(self) -> dict:
        """The op-amp as every result's JSON gives it: the figures a design used."""
        return {"name": self.name, "gbw_hz": self.gbw_hz, "slew_v_per_s": self.slew_v_per_s, "a0": self.a0,
                "vcc": self.vcc, "vee": self.vee, "vout_max": self.vout_max, "vout_min": self.vout_min}


#: the package kinds ``--package`` accepts
PACKAGE_KINDS = ("single", "dual", "quad")


@dataclass(frozen=True)
class Package:
    """One kind of package an op-amp comes in: its part number, pinout name,
    pin count, the pins of each unit (``units``: "" for a single, "A".."D";
    each {"out", "inn", "inp"}), the supply pins and what the other pins are."""

    kind: str
    part: str
    pinout: str
    pins: int
    units: dict
    vcc: int
    vee: int
    unused: dict

    def to_dict(self) -> dict:
        """The package as the results' JSON gives it: what the build sheet wires."""
        return {"kind": self.kind, "part": self.part, "pinout": self.pinout, "pins": self.pins,
                "units_per_package": self.per_package}

    @property
    def per_package(self) -> int:
        return len(self.units)


@dataclass(frozen=True)
class Unit:
    """One op-amp of a circuit placed in a package: designator ``U2`` (single) or
    ``U1B``, the package number, the unit letter and its pins."""

    designator: str
    ic: int
    unit: str
    pins: dict
    package: Package

    @property
    def ic_ref(self) -> str:
        return f"U{self.ic}"


def assign(count: int, package: Package) -> list:
    """The first ``count`` units of as many packages as needed, in order: U1 (or
    U1A, U1B, ...), U2 (U2A ...): a circuit's op-amps in the order it lists them.

    Parameters
    ----------
    count : int
        The circuit's op-amps.
    package : Package
        The package they come in.

    Returns
    -------
    list
        The units.
    """
    letters = list(package.units)
    out = []
    for i in range(count):
        ic, u = divmod(i, len(letters))
        unit = letters[u]
        out.append(Unit(f"U{ic + 1}{unit}", ic + 1, unit, package.units[unit], package))
    return out


def spare_units(count: int, package: Package) -> list:
    """The units of the last package that ``count`` op-amps leave free (to be tied off).

    Parameters
    ----------
    count : int
        The circuit's op-amps.
    package : Package
        The package they come in.

    Returns
    -------
    list
        The free units.
    """
    per = package.per_package
    used = count % per
    if used == 0:
        return []
    ic = count // per + 1
    return [Unit(f"U{ic}{u}", ic, u, package.units[u], package) for u in list(package.units)[used:]]


@lru_cache(maxsize=1)
def _catalogue_raw() -> dict:
    return json.loads(resources.files("designer.core").joinpath("data/opamps.json").read_text())


@lru_cache(maxsize=1)
def _catalogue() -> dict:
    raw = _catalogue_raw()
    return {name: OpAmp(name=name, ideal=spec.pop("ideal", False), **spec)
            for name, spec in ((k, dict(v)) for k, v in raw.items() if not k.startswith("_"))}


def names() -> list:
    """Catalogue names, as ``--opamp`` accepts them.

    Returns
    -------
    list of str
        The names.
    """
    return list(_catalogue())


def fast_enough(gbw_hz: float) -> OpAmp | None:
    """The slowest catalogue op-amp (the ideal one aside) whose gain-bandwidth is at least ``gbw_hz``.

    Parameters
    ----------
    gbw_hz : float
        The gain-bandwidth needed, Hz.

    Returns
    -------
    OpAmp or None
        None when none is that fast.
    """
    ok = sorted((a for a in _catalogue().values() if not a.ideal and a.gbw_hz >= gbw_hz), key=lambda a: a.gbw_hz)
    return ok[0] if ok else None


def get(name: str) -> OpAmp:
    """Look up an op-amp by name (case-insensitive).

    Parameters
    ----------
    name : str
        The op-amp's name.

    Returns
    -------
    OpAmp
        Its data.
    """
    for key, amp in _catalogue().items():
        if key.lower() == str(name).strip().lower():
            return amp
    raise DesignError(f"unknown op-amp {name!r}; allowed: {', '.join(names())}")
