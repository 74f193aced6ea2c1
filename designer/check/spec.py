"""A ``check-design`` spec: one YAML file, validated once, when it is loaded,
into a :class:`CheckSpec`.

The file is read by :func:`designer.check.yamldoc.parse_yaml` (PyYAML's safe
loader, with budgets). A spec may come from a stranger (a pull request): it is
data, and may reach nothing outside its folder (the README's trust boundary).

Three kinds::

    kind: plant                 # a Sallen-Key plant, designed or as built
    target: {fc: 3.5k, zeta: 0.2}        # designed as design-plant does, or
    parts: {R1: 1k6, R2: 3k9, C1: 3n3, C2: 100n}   # as built (target: then only reports errors)

    kind: pid                   # the seed's op-amp PID in its loop
    plant: {fc: 3.5k, zeta: 0.2}         # or {R1: .., R2: .., C1: .., C2: ..} or {json: result.json}
    tuning: zn                           # a rule, or {kp: .., ti: .., td: ..}, or {rule: optimize, target_overshoot: 10}
    controller: {R3: 12k, ..., C4: 47n}  # optional: the parts as built (or {json: result.json})

    kind: netlist               # the user's own ngspice deck
    deck: filter.cir                     # its .meas results are the figures

and, for every kind: ``checks:`` (figure -> ``{min, typ, max, fail}``), and
``golden:``; for plant and pid: ``opamp`` (one name or a list: the corners),
``series``, ``bounds``, ``stimulus``, ``design_checks``, ``spice_agreement``;
a plant also ``tolerance``; for plant, pid and filter (designed) ``yield: {min: 95%, samples: 2000, seed: 1, engine:
analytic|spice}`` with ``tolerances: {R: 1%, C: 5%, C2: 2%, SR: 20%}`` (default: the series'), the Monte Carlo
yield over the spec's own checks (:mod:`designer.tolerance.yields`). Paths (``deck``, ``golden.file``, the ``json``
files) are relative to the spec file and must resolve (links followed) inside
its folder, or the ``root`` given (``--root``), unless ``allow_outside``
(:mod:`designer.check.yamldoc`); a deck and every file it includes are read
and checked here (:func:`designer.spice.trust.expand_deck`) and handed to
ngspice inlined. Numbers may be written in engineering notation (``3n3``,
``1m``, ``3.5k``).

Every refusal is one line: ``file:line: what is wrong, and what is allowed``;
an unknown key names the allowed keys and the closest one. Each section below
the top level is read by :mod:`designer.check.sections`, where the design's
own validation (:class:`~designer.plant.spec.PlantSpec`,
:class:`~designer.pid.spec.PidSpec`) runs for every corner, its messages
naming the spec's keys; :func:`load_spec` checks the top level and puts the
sections together, and reads a netlist's deck itself.
"""

from __future__ import annotations

import re
from dataclasses import dataclass
from pathlib import Path

from ..core.errors import DesignError
from ..core.fileio import check_plain_name, shown
from ..plant.circuit import DEFAULT_TOPOLOGY
from . import figures as F
from .sections import (Agreement, Golden, YieldSpec, read_agreement, read_checks, read_corners, read_design_checks, read_golden,
                       read_pid_designs, read_plant_designs, read_tolerance, read_yield)
from .yamldoc import kind_of, closest, parse_yaml

__all__ = ["TOP", "load_spec"]

KINDS = ("plant", "pid", "netlist", "filter")
#: the top-level keys of each kind
TOP = {
    "plant": ("name", "kind", "description", "topology", "target", "parts", "series", "bounds", "opamp", "stimulus",
              "checks", "design_checks", "spice_agreement", "tolerance", "tolerances", "yield", "golden"),
    "pid": ("name", "kind", "description", "plant", "tuning", "controller", "series", "bounds", "opamp", "stimulus",
            "checks", "design_checks", "spice_agreement", "tolerances", "yield", "golden"),
    "netlist": ("name", "kind", "description", "deck", "checks", "golden"),
    "filter": ("name", "kind", "description", "filter", "stages", "mask", "delay", "series", "bounds", "opamp",
               "checks", "tolerances", "yield"),
}


@dataclass(frozen=True)
class CheckSpec:
    """One spec file, valid by construction (:func:`load_spec`).

    ``corners`` are the op-amps (a netlist has one corner, ``""``); ``designs``
    the library's spec for each (:class:`~designer.plant.spec.PlantSpec`,
    :class:`~designer.plant.spec.AnalysisSpec` or :class:`~designer.pid.spec.PidSpec`;
    a netlist's deck text); ``analyze`` says the parts are as built.
    """

    path: Path
    name: str
    kind: str
    corners: tuple
    designs: tuple
    analyze: bool
    checks: tuple               #: Limit
    design_checks: tuple | str | None   #: "all", ids, or None
    agreement: Agreement | None
    tolerance: tuple            #: figures whose tolerance band must stay inside their limits
    golden: Golden | None
    yield_spec: YieldSpec | None = None   #: the Monte Carlo yield the checks must reach

    def classname(self, corner: str) -> str:
        """``lab3-plant[TL072]``: the spec and the corner (JUnit's classname)."""
        return f"{self.name}[{corner}]" if corner else self.name


def load_spec(path, update_golden: bool = False, root=None, allow_outside: bool = False) -> CheckSpec:
    """A :class:`CheckSpec` from a YAML file, checked in full (the design's
    own validation for every corner, the deck's ``.meas`` names, the golden
    files exist unless ``update_golden``).

    Parameters
    ----------
    path : path-like
        The YAML spec file.
    update_golden : bool
        The golden files are to be recorded (they need not exist).
    root : path-like, optional
        The folder the files the spec names must resolve inside (``--root``); None: the spec's folder.
    allow_outside : bool
        Files outside ``root`` are allowed (``--allow-outside``, trusted use).

    Returns
    -------
    CheckSpec
        The spec.

    Raises
    ------
    DesignError
        One line: ``file:line: what is wrong``.
    """
    doc = parse_yaml(path)
    doc.root = None if allow_outside else Path(root if root is not None else doc.path.parent).resolve()
    kind = doc.data.get("kind")
    if kind not in KINDS:
        got = "no kind" if kind is None else f"kind {kind_of(kind)}"
        raise doc.error(("kind",), f"{got}; allowed: {', '.join(KINDS)}"
                        + (f"; closest: {closest(kind, KINDS)!r}" if isinstance(kind, str) else ""))
    doc.mapping((), TOP[kind])
    name = doc.data.get("name", Path(path).stem)
    try:
        check_plain_name(name if isinstance(name, str) else "", "name")
    except DesignError as exc:
        raise doc.error(("name",), str(exc)) from None
    if kind == "netlist":
        return _netlist(doc, name, update_golden)
    corners = read_corners(doc)
    if kind == "filter":
        return _filter(doc, name, corners)
    designs, analyze = (read_plant_designs if kind == "plant" else read_pid_designs)(doc, corners)
    checks = read_checks(doc, kind, set(F.FIGURES[kind]))
    design_checks = read_design_checks(doc, kind)
    agreement = read_agreement(doc)
    tolerance = read_tolerance(doc, checks) if kind == "plant" else ()
    golden = read_golden(doc, kind, corners, update_golden)
    yield_spec = read_yield(doc, kind, checks)
    if kind == "plant" and getattr(designs[0], "topology", DEFAULT_TOPOLOGY) != DEFAULT_TOPOLOGY:
        other = [f for f in tolerance if f not in F.SECTION_BAND]
        if other:
            listed = doc.data["tolerance"]
            keys = ("tolerance", listed.index(other[0])) if isinstance(listed, list) else ("tolerance",)
            raise doc.error(keys, f"tolerance: {other[0]} has no tolerance band on topology {designs[0].topology} "
                            f"(its SPICE run is an .ac sweep, no step); allowed: {', '.join(F.SECTION_BAND)}")
    if not (checks or design_checks or agreement or golden):
        raise doc.error((), "nothing to check: give checks:, design_checks:, spice_agreement: or golden:")
    return CheckSpec(doc.path, name, kind, corners, tuple(designs), analyze, checks, design_checks, agreement,
                     tolerance, golden, yield_spec)


# ---- kind: netlist ----------------------------------------------------------------

_ANALYSIS = re.compile(r"^\s*\.(tran|ac)\b", re.I | re.M)


def _netlist(doc, name: str, update: bool) -> CheckSpec:
    from ..spice.simulate import measure_names
    from ..spice.trust import expand_deck
    path = doc.resolve(("deck",))
    try:
        # the deck and everything it includes, read and checked here, inlined: ngspice opens none of them
        deck = expand_deck(path, doc.root)
    except DesignError as exc:
        raise doc.error(("deck",), str(exc)) from None
    shown_deck = shown(path)
    lines = [ln for ln in deck.splitlines() if ln.strip()]
    if len(lines) < 2:
        raise doc.error(("deck",), f"deck {shown_deck} is not an ngspice deck: a title line, then the circuit")
    if not _ANALYSIS.search(deck):
        raise doc.error(("deck",), f"deck {shown_deck} has no .tran or .ac line: "
                        "nothing to simulate")
    measures = measure_names(deck)
    checks = read_checks(doc, "netlist", set(measures))
    golden = read_golden(doc, "netlist", ("",), update)
    if not (checks or golden):
        raise doc.error((), "nothing to check: give checks: (the deck's .meas names) or golden:")
    return CheckSpec(doc.path, name, "netlist", ("",), (deck,), False, checks, None, None, (), golden)


# ---- kind: filter -----------------------------------------------------------------

def _filter(doc, name: str, corners) -> CheckSpec:
    from .filter_kind import delay_limits, filter_designs, mask_limits
    designs, analyze = filter_designs(doc, corners)
    checks = read_checks(doc, "filter", set(F.FIGURES["filter"])) + mask_limits(designs[0].mask) + \
        delay_limits(designs[0].delay)
    if not checks:
        raise doc.error((), "nothing to check: give checks: (figures), mask: or delay:")
    if analyze and doc.data.get("yield") is not None:
        raise doc.error(("yield",), "yield: draws a design's parts around their E-series values; give filter: "
                        "(designed) for a yield, stages: (as built) are checked as they are")
    yield_spec = read_yield(doc, "filter", checks)
    return CheckSpec(doc.path, name, "filter", corners, tuple(designs), analyze, checks, None, None, (), None,
                     yield_spec)
