"""A PID's plant: an analysis model and, optionally, the circuit that realises it.

A :class:`Plant` is what every controller design works on: its ``model`` (a
:class:`~designer.core.process.ProcessModel`, what the tuning rules, the
optimiser and the analytic loop see) and, when the plant is a circuit on the
bench, ``circuit`` (a :class:`PlantCircuit`: one registered filter section or
a cascade of them, :mod:`designer.filters`, with its part values), which then
goes into the closed-loop deck and onto the schematic in place of the model's
behavioural block.

The model of a circuit is its ideal-op-amp transfer function, the product of
its sections' (:meth:`designer.filters.topology.Topology.coefficients`,
:meth:`designer.filters.cascade.Cascade.coefficients`), as a rational
:class:`~designer.core.process.ProcessModel`
(:func:`designer.core.process_build.rational`: proper, strictly stable, a
non-zero static gain, so a high-pass or band-pass section, with N(0) = 0, is
refused: no PID sets the level of a plant that passes no DC).

An inverting circuit (an MFB or inverting low-pass: K < 0) is controlled with
the controller's action reversed (the rules are written for K > 0; Astrom and
Hagglund, *Advanced PID Control*, 2006, section 1.3): the gains are chosen for
-G(s), and the deck exchanges the reference and the plant output at the
difference amplifier (r into R17, y into R15), so that u = -C(s) (r - y) and
the loop y = (-G)(-C)(r - y) is the one designed.

Designators: a plant of one section keeps the section's names with the prefix
``P`` after the letter (RP1, CP2) and its op-amp is ``UP``; stage i of a
cascade is prefixed ``Pi`` (RP11, CP22) with op-amp ``UPi``, so that no plant
part collides with the controller's R3..R18, C3, C4, U2..U7 or the board's
decoupling C101.. (:func:`designer.spice.deck.board`).

:func:`resolve_plant` is the one place that turns every plant source (a
:class:`~designer.pid.plant_spec.PlantSource`, a
:class:`~designer.pid.spec.PidSpec`'s ``plant``) into a :class:`Plant`.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

from ..core.errors import DesignError
from ..core.i18n import N_, Message
from ..core.process import ProcessModel
from ..core.ranges import parse_in_range
from ..spice.deck import Netlist

__all__ = ["PLANT_PREFIX", "LoopNames", "SEED_LOOP_NAMES", "PlantCircuit", "Plant", "parse_part_values", "part_items", "circuit_plant",
           "circuit_from_json",
           "circuit_from_cascade", "sallen_key_plant", "sallen_key_circuit", "seed_loop_names",
           "pair_model", "resolve_plant"]

#: the designator prefix of a one-section plant (R1 -> RP1; stage i of a cascade: RPi1)
PLANT_PREFIX = "P"
#: the ranges a part of a circuit plant is held to (keys of designer.core.ranges.RANGES)
PART_RANGES = {"R": "resistor_ohm", "C": "capacitor_f"}


@dataclass(frozen=True)
class LoopNames:
    """How a one-section plant is named in the loop when not by the generic
    scheme (RP1 .., op-amp ``UP``, internal nets after the op-amp): the seed's
    Sallen-Key plant keeps the names its sheets and reference decks have always
    had (:data:`SEED_LOOP_NAMES`).

    Parameters
    ----------
    prefix : str
        Put after each designator's letter ("" keeps the section's own names).
    amp_ref : str
        The plant's op-amp in the deck.
    amp_role : str
        The op-amp's role on the sheet and in the bill of materials.
    nets : tuple of str
        The section's internal nets, in the order they first appear in its
        netlist (parts in declared order, then the op-amp).
    """

    prefix: str
    amp_ref: str
    amp_role: str
    nets: tuple

    def renamed(self, net: Netlist, keep) -> Netlist:
        """``net`` (one section, its op-amp :attr:`amp_ref`) with its internal
        nets renamed to :attr:`nets` and its op-amp's role :attr:`amp_role`.

        Parameters
        ----------
        net : Netlist
            The section as its topology wrote it.
        keep : collection of str
            The nets it sits between (and ground): not renamed.

        Returns
        -------
        Netlist
            The same circuit, renamed.
        """
        from dataclasses import replace

        from ..spice.deck import GROUND
        order = [n for p in net.parts for n in (p.a, p.b)] + [n for a in net.amps for n in (a.inp, a.inn, a.out)]
        inner = [n for n in dict.fromkeys(order) if n not in keep and n != GROUND]
        to = dict(zip(inner, self.nets))
        r = lambda n: to.get(n, n)  # noqa: E731
        return Netlist(tuple(replace(p, a=r(p.a), b=r(p.b)) for p in net.parts),
                       tuple(replace(a, role=self.amp_role, inp=r(a.inp), inn=r(a.inn), out=r(a.out))
                             for a in net.amps))


#: the seed's Sallen-Key plant in its loop (seed 001, Fig. 43-45 beside Fig. 66): op-amp U1 "plant",
#: nets pv1 (node A), pvp, pvn; its designators unprefixed for the follower, prefixed P with the gain pair
#: (whose R3, R4 the controller owns): the names of the reference decks and sheets
SEED_LOOP_NAMES = LoopNames("", "U1", N_("plant"), ("pv1", "pvp", "pvn"))


@dataclass(frozen=True)
class PlantCircuit:
    """The circuit of a plant: registered filter sections in series, input first.

    Parameters
    ----------
    stages : tuple of designer.filters.cascade.Stage
        Each section (its topology) and its part values (designator -> ohm, farad).
    names : LoopNames, optional
        A one-section plant's names in the loop when not the generic scheme
        (:data:`SEED_LOOP_NAMES` for the seed's Sallen-Key plant).
    """

    stages: tuple
    names: LoopNames | None = None

    @property
    def topology(self) -> str:
        """The registry name of a one-section plant, else ``"cascade"``."""
        return self.stages[0].topology.name if len(self.stages) == 1 else "cascade"

    @property
    def inverting(self) -> bool:
        """Whether the circuit's static gain is negative (an odd number of inverting sections)."""
        return sum(st.topology.inverting for st in self.stages) % 2 == 1

    def prefix(self, i: int) -> str:
        """The designator prefix of stage ``i`` (1-based).

        Parameters
        ----------
        i : int
            The stage, 1 for the plant's input section.

        Returns
        -------
        str
            ``P`` for a one-section plant (R1 -> RP1), ``Pi`` in a cascade (RPi1);
            :attr:`names`' prefix when given.
        """
        if self.names is not None:
            return self.names.prefix
        return PLANT_PREFIX if len(self.stages) == 1 else f"{PLANT_PREFIX}{i}"

    def ideal_pair(self) -> tuple:
        """(fn in Hz, zeta) of the circuit's ideal model, what a PID's plant is named
        and sized by: a one-section plant's :meth:`~designer.filters.topology.Topology.ideal_pair`
        (the section's hook: the Sallen-Key low-pass's record arithmetic), a cascade's
        slowest pole pair (:func:`designer.core.lti.dominant_pair` of the stages' product).

        Returns
        -------
        tuple of float
            (fn_hz, zeta).
        """
        if len(self.stages) == 1:
            st = self.stages[0]
            return st.topology.ideal_pair(st.values)
        from ..core.lti import dominant_pair
        return dominant_pair(np.asarray(self.coefficients()[1], float))

    @property
    def fn_hz(self) -> float:
        """fn of :meth:`ideal_pair`, Hz."""
        return self.ideal_pair()[0]

    @property
    def zeta(self) -> float:
        """zeta of :meth:`ideal_pair`."""
        return self.ideal_pair()[1]

    def with_values(self, values: dict) -> "PlantCircuit":
        """A one-section plant with some of its part values replaced (a Monte Carlo build's).

        Parameters
        ----------
        values : dict
            Designator -> value, designators of the section.

        Returns
        -------
        PlantCircuit
            The same section and names, the other values kept.
        """
        from dataclasses import replace

        from ..filters.cascade import Stage
        (st,) = self.stages
        return replace(self, stages=(Stage(st.topology, {**st.values, **{k: float(v) for k, v in values.items()}}),))

    def __reduce__(self):
        # a registered section pickles by its name and comes back as the registry's instance (a
        # topology compares by identity): a spec holding this circuit reaches --jobs and dask workers equal
        return (_unpickled, (tuple((_by_name(st.topology), st.values) for st in self.stages), self.names))

    def coefficients(self) -> tuple:
        """The ideal (num, den) polynomials in s, highest power first (the stages' products).

        Returns
        -------
        tuple of ndarray
            (num, den).
        """
        from ..filters.cascade import Cascade
        return Cascade(self.stages).coefficients()

    def netlist(self, inp: str = "u", out: str = "y") -> Netlist:
        """The circuit between nets ``inp`` and ``out``: stage i's parts prefixed
        (:meth:`prefix`), its op-amp ``U`` + prefix, its output net ``ps{i}`` the
        next stage's input.

        Parameters
        ----------
        inp, out : str
            The plant's input and output nets.

        Returns
        -------
        Netlist
            Every stage's parts and op-amp, in stage order.
        """
        from ..filters.cascade import Cascade
        if self.names is not None:   # one section, named as given (the seed's plant)
            st = self.stages[0]
            net = st.topology.netlist(st.values, prefix=self.names.prefix, amp_ref=self.names.amp_ref, inp=inp,
                                      out=out)
            return self.names.renamed(net, (inp, out))
        return Cascade(self.stages).netlist(inp, out, prefix=self.prefix, amp_ref=lambda i: f"U{self.prefix(i)}",
                                            link="ps")

    def to_dict(self) -> dict:
        """The circuit as JSON-ready data.

        Returns
        -------
        dict
            ``topology`` and ``stages`` (each its ``topology``, ``title`` and
            ``parts``: designator as on the board -> value).
        """
        out = []
        for i, st in enumerate(self.stages, 1):
            t = st.topology
            out.append({"topology": t.name, "title": t.title,
                        "parts": {t.prefixed(ref, self.prefix(i)): float(v) for ref, v in st.values.items()}})
        return {"topology": self.topology, "stages": out}


def _by_name(topology):
    """A registered topology's name (how it pickles), else the topology itself."""
    from ..filters.registry import REGISTRY
    return topology.name if REGISTRY.get(topology.name) is topology else topology


def _unpickled(stages: tuple, names) -> PlantCircuit:
    """A :class:`PlantCircuit` from (name or topology, values) pairs (:meth:`PlantCircuit.__reduce__`)."""
    from ..filters.cascade import Stage
    from ..filters.registry import get
    return PlantCircuit(tuple(Stage(get(t) if isinstance(t, str) else t, v) for t, v in stages), names)


@dataclass(frozen=True)
class Plant:
    """A PID's plant: its analysis model and, when it is a circuit, the circuit.

    Parameters
    ----------
    model : ProcessModel
        What the rules, the optimiser and the analytic loop see.
    circuit : PlantCircuit or None
        The circuit that realises ``model`` (drawn and simulated as parts), or
        None for a plant known only as a model (a block on the sheet, native
        elements in the deck).
    source : str
        Where the plant came from, for the sheet.
    """

    model: ProcessModel
    circuit: PlantCircuit | None = None
    source: str = ""

    @property
    def reversed_action(self) -> bool:
        """Whether the controller's action is reversed (an inverting circuit)."""
        return self.circuit is not None and self.circuit.inverting

    @property
    def design_model(self) -> ProcessModel:
        """The model the gains are chosen for: ``model``, or -``model`` for a
        reversed action (the rules are written for K > 0)."""
        if not self.reversed_action:
            return self.model
        from dataclasses import replace
        m = self.model
        return replace(m, num=tuple(-c for c in m.num),
                       source=Message(N_("{source}, negated (the controller's action reversed)"), source=m.source))


def part_items(values, name: str = "plant_values") -> dict:
    """Part values as typed, by designator (upper case), not yet checked against a topology.

    Parameters
    ----------
    values : dict or iterable of str
        Designator -> value, or ``REF=VALUE`` items.
    name : str
        The parameter named in messages.

    Returns
    -------
    dict
        Designator -> value as typed.

    Raises
    ------
    DesignError
        One line: an item not ``REF=VALUE``, or a designator given twice.
    """
    if not isinstance(values, dict):
        items = {}
        for item in values:
            ref, eq, value = str(item).partition("=")
            if not eq or not ref.strip() or not value.strip():
                raise DesignError(f"{name}: {item!r} is not REF=VALUE (such as R1=10k)", param=name)
            ref = ref.strip().upper()
            if ref in items:
                raise DesignError(f"{name}: {ref} given twice; give each part once", param=name)
            items[ref] = value.strip()
        values = items
    return {str(k).strip().upper(): v for k, v in values.items()}


def parse_part_values(topology, values, name: str = "plant_values") -> dict:
    """Part values of ``topology`` as typed (numbers, or text in engineering
    notation: ``{"R1": "10k"}``; or ``"R1=10k"`` items), checked against its
    declared parts and the resistor and capacitor ranges.

    Parameters
    ----------
    topology : designer.filters.topology.Topology
        The section.
    values : dict or iterable of str
        Designator -> value, or ``REF=VALUE`` items.
    name : str
        The parameter named in messages.

    Returns
    -------
    dict
        Designator -> float (ohm, farad).

    Raises
    ------
    DesignError
        One line: an item not ``REF=VALUE``, a part the topology does not have
        (its parts listed), one missing, a value out of range.
    """
    values = part_items(values, name)
    parts = ", ".join(topology.designators)
    extra = [r for r in values if r not in topology.designators]
    if extra:
        raise DesignError(f"{name}: {topology.name} has no part {extra[0]}; its parts are {parts}", param=name)
    missing = [r for r in topology.designators if r not in values]
    if missing:
        raise DesignError(f"{name}: {topology.name} needs {', '.join(missing)} too; its parts are {parts}",
                          param=name)
    return {r: parse_in_range(values[r], f"{name} {r}", PART_RANGES[r[0]]) for r in topology.designators}


def circuit_from_cascade(stages, *, source: str = "circuit", name: str = "plant_circuit") -> Plant:
    """A :class:`Plant` from sections and part values, its model the circuit's
    ideal transfer function.

    Parameters
    ----------
    stages : designer.filters.cascade.Cascade or iterable of Stage or (Topology, dict)
        The sections, input first.
    source : str
        Where it came from (the sheet's words).
    name : str
        The parameter named in messages.

    Returns
    -------
    Plant
        With its circuit.

    Raises
    ------
    DesignError
        One line: no section, a topology unknown, part values wrong, or a
        circuit no PID can control (no DC gain, unstable, out of range).
    """
    from ..core.process_build import rational
    from ..filters.cascade import Cascade, Stage
    from ..filters.registry import get
    if isinstance(stages, Cascade):
        stages = stages.stages
    if isinstance(stages, (str, bytes, dict)) or not hasattr(stages, "__iter__"):
        raise DesignError(f"{name}: a plant circuit is a Cascade or a list of (topology, part values) pairs, "
                          f"got {type(stages).__name__}", param=name)
    out = []
    for st in stages:
        try:
            topo, values = (st.topology, st.values) if isinstance(st, Stage) else st
        except (TypeError, ValueError):
            raise DesignError(f"{name}: each section is a (topology, part values) pair, got {st!r}",
                              param=name) from None
        topo = get(topo) if isinstance(topo, str) else topo
        out.append(Stage(topo, parse_part_values(topo, values, name)))
    if not out:
        raise DesignError(f"{name}: a plant circuit needs at least one section", param=name)
    circuit = PlantCircuit(tuple(out))
    lows = [st.topology.name for st in out if st.topology.kind != "lowpass"]
    if lows:
        raise DesignError(f"{name}: {lows[0]} passes no DC (its gain at 0 Hz is 0), so no PID can set the "
                          "plant's level; a PID plant is a low-pass section or a cascade of them", param=name)
    num, den = circuit.coefficients()
    try:
        model = rational(np.asarray(num, float), np.asarray(den, float),
                         source=Message(N_("{title} as built ({source})"), source=source, title=Message.joined(
                             " + ", (Message(st.topology.title) for st in out))))
    except DesignError as exc:
        raise DesignError(f"{name}: the circuit's transfer function is no PID plant: {exc}", param=name) from None
    return Plant(model, circuit, source)


def circuit_plant(topology, values, *, source: str = "parts", name: str = "plant_values") -> Plant:
    """A :class:`Plant` of one registered section with its part values
    (:func:`circuit_from_cascade` of one stage; an unknown topology is refused
    in one line listing the registered ones).

    Parameters
    ----------
    topology : str or designer.filters.topology.Topology
        A registered name (``mfb-lowpass``) or the section.
    values : dict or iterable of str
        Its part values (:func:`parse_part_values`).
    source, name : str
        As for :func:`circuit_from_cascade` (``name``: the values' parameter).

    Returns
    -------
    Plant
        The section's plant.
    """
    from ..filters.registry import get
    topo = get(topology) if isinstance(topology, str) else topology
    return circuit_from_cascade([(topo, values)], source=source, name=name)


def circuit_from_json(data: dict, *, name: str = "result") -> Plant:
    """The circuit of a parsed ``design-filter`` result (its ``stages``: each
    ``topology`` and ``parts``), or of a ``design-plant``/``analyze-plant --topology`` result (its one
    section: ``topology`` and ``parts``, each designator -> ``{value: ..}``), as a :class:`Plant`.

    Parameters
    ----------
    data : dict
        The parsed result.json.
    name : str
        How messages name the file (``--plant-json f.json``).

    Returns
    -------
    Plant
        The file's sections as a cascade plant (one stage: that section's).

    Raises
    ------
    DesignError
        One line naming the file and the key at fault.
    """
    where = name
    if "stages" not in data and data.get("mode") in ("design", "analyze"):
        # a section's plant: its one stage, the parts as its sheet lists them (the seed's Sallen-Key plant,
        # with 'built' and no 'parts', is read by plant_spec.plant_from_json instead)
        parts = data.get("parts")
        if not (isinstance(data.get("topology"), str) and isinstance(parts, dict)
                and all(isinstance(v, dict) and "value" in v for v in parts.values())):
            raise DesignError(f"{where}: a design-plant or analyze-plant result needs topology (a name) and parts "
                              "(designator -> {value})")
        tool = "design-plant" if data["mode"] == "design" else "analyze-plant"
        try:
            return circuit_from_cascade([(data["topology"], {k: v["value"] for k, v in parts.items()})],
                                        source=f"{tool} result", name=where)
        except DesignError as exc:
            raise DesignError(str(exc)) from None
    stages = data.get("stages")
    if not isinstance(stages, list) or not stages:
        raise DesignError(f"{where}: a design-filter result needs stages (each with topology and parts)")
    out = []
    for i, st in enumerate(stages):
        if not (isinstance(st, dict) and isinstance(st.get("topology"), str) and isinstance(st.get("parts"), dict)):
            raise DesignError(f"{where}: stages[{i}] needs topology (a name) and parts (designator -> value)")
        out.append((st["topology"], {k: v for k, v in st["parts"].items()}))
    try:
        return circuit_from_cascade(out, source="design-filter result", name=where)
    except DesignError as exc:
        raise DesignError(str(exc)) from None


def sallen_key_plant(source, *, opamp: str | None = None, bounds=None):
    """(circuit, description, series) of a Sallen-Key plant, designed, given or
    read: its generic record (:class:`PlantCircuit`, :func:`sallen_key_circuit`), every
    way through :func:`designer.plant.sallenkey.check_parts` first (the given and read
    ones when their source was built, :class:`~designer.pid.plant_spec.PlantSource`).
    ``series`` is the (R, C) pair of a plant designed here, else None.

    Parameters
    ----------
    source : designer.pid.plant_spec.PlantSource or designer.pid.spec.PidSpec
        With ``plant_parts``, ``plant_json`` or ``plant_fc_hz``/``plant_zeta``
        (a spec: its ``plant``, its op-amp and its part bounds).
    opamp : str, optional
        The op-amp a plant designed from fn and zeta is built with (default a
        spec's, else LM741).
    bounds : designer.core.eseries.PartBounds, optional
        The series and bounds of its parts (default a spec's, else the defaults).

    Returns
    -------
    tuple
        (:class:`PlantCircuit`, str, tuple or None).
    """
    source, opamp, bounds = _with_design_choices(source, opamp, bounds)
    if source.plant_parts is not None:
        return source.plant_parts, "parts", None
    if source.json_plant is not None:
        return source.json_plant, f"json:{source.plant_json}", None
    from ..core.errors import ParamError
    from ..filters.sallen_key_lowpass_parts import FIELD_OF
    from ..plant.design import choose_parts
    from ..plant.sallenkey import check_parts
    from ..plant.spec import PlantSpec
    fc, zeta = source.plant_fc_hz, source.plant_zeta
    ps = PlantSpec(fc_hz=fc, zeta=zeta, opamp=opamp,
                   r_series=bounds.r_series, c_series=bounds.c_series, r_min=bounds.r_min, r_max=bounds.r_max,
                   c_min=bounds.c_min, c_max=bounds.c_max, alternatives=1)
    res = choose_parts(ps)   # the parts only: no analysis, no deck
    what = f"the plant designed for {{plant_fc_hz}} {fc:g} {{plant_zeta}} {zeta:g}"
    names = {f: f"{what}: {r}" for r, f in FIELD_OF.items()} | {"gain": f"{what}: gain K"}
    try:   # the one plant validation, its parts named after the request (markers: see ParamError)
        built = check_parts(res.built, name_of=names | {"plant": what})
    except DesignError as exc:
        raise ParamError(str(exc), ("plant_fc_hz", "plant_zeta")) from None
    return (sallen_key_circuit(built), f"design-plant fc={fc:g} Hz zeta={zeta:g}", (bounds.r_series, bounds.c_series))


def _with_design_choices(source, opamp, bounds) -> tuple:
    """(plant source, op-amp, part bounds): a spec's plant and its own choices, else the defaults."""
    from ..core.eseries import PartBounds
    spec = source if hasattr(source, "plant") else None
    if spec is not None:
        source = spec.plant
    opamp = opamp if opamp is not None else (spec.opamp if spec is not None else "LM741")
    bounds = bounds if bounds is not None else (spec if spec is not None else PartBounds())
    return source, opamp, bounds


def sallen_key_circuit(parts) -> PlantCircuit:
    """The Sallen-Key plant's parts record (checked) as the generic record: its
    registered section (unity gain, or gain K = 1 + R4/R3) with its values by
    designator, named in the loop as the seed's sheets name it
    (:data:`SEED_LOOP_NAMES`; with the gain pair its designators prefixed
    :data:`PLANT_PREFIX`, clear of the controller's R3 and R4). The one conversion,
    at the edges that read the record's own keys and flags (``--plant-r1`` ..,
    a design-plant result.json's ``built``).

    Parameters
    ----------
    parts : designer.plant.sallenkey.SallenKeyParts
        The plant as built (through :func:`~designer.plant.sallenkey.check_parts`).

    Returns
    -------
    PlantCircuit
        One stage.
    """
    from ..filters.cascade import Stage
    from ..filters.sallen_key_lowpass_parts import part_values, section_of
    follower = math.isclose(parts.gain, 1.0)
    values = part_values(parts)
    section = section_of(with_gain=not follower)
    return PlantCircuit((Stage(section, {r: float(values[r]) for r in section.designators}),),
                        seed_loop_names(section))


def seed_loop_names(section) -> LoopNames:
    """How the seed's Sallen-Key plant on ``section`` is named in the loop: :data:`SEED_LOOP_NAMES`, its
    designators prefixed :data:`PLANT_PREFIX` when the section has parts the controller's names take
    (the gain pair's R3, R4).

    Parameters
    ----------
    section : designer.filters.topology.Topology
        The follower or the section with gain.

    Returns
    -------
    LoopNames
    """
    from dataclasses import replace
    return replace(SEED_LOOP_NAMES, prefix=PLANT_PREFIX if section.choice_parts else "")


def pair_model(circuit: PlantCircuit, source: str = "Sallen-Key") -> ProcessModel:
    """A second-order low-pass plant's ideal model K/(a s^2 + b s + 1) (its
    coefficients, normalised to a constant term 1) as a :class:`ProcessModel`:
    underdamped with the circuit's ideal pair (:meth:`PlantCircuit.ideal_pair`: a section's
    hook, fn = 1/(2 pi sqrt(a)) and zeta = b/(2 sqrt(a)) in the Sallen-Key record's arithmetic,
    so the model's fn and zeta are the plant's named ones to the bit), or for zeta >= 1
    the SOPDT whose (tau1 s + 1)(tau2 s + 1) = a s^2 + b s + 1.

    Parameters
    ----------
    circuit : PlantCircuit
        The plant (its ideal coefficients of degree 2).
    source : str
        Where the model came from (its ``source``).

    Returns
    -------
    ProcessModel
    """
    from ..core.process_build import sopdt, underdamped
    num, den = (np.asarray(c, float) for c in circuit.coefficients())
    if len(den) != 3:
        raise DesignError(f"a pair model is of a second-order plant; this one has order {len(den) - 1}")
    k, a, b = float(num[-1] / den[-1]), float(den[0] / den[-1]), float(den[1] / den[-1])
    fn, zeta = circuit.ideal_pair()
    if zeta < 1.0:
        return underdamped(k, fn, zeta, source=source)
    tau1 = (b + math.sqrt(max(b * b - 4.0 * a, 0.0))) / 2.0
    return sopdt(k, tau1, a / tau1, source=source)   # tau1 tau2 = a, without the cancellation of b - r


def resolve_plant(source, *, opamp: str | None = None, bounds=None) -> Plant:
    """Every plant source as a :class:`Plant`: a circuit of any
    topology (``plant_topology`` with ``plant_values``, ``plant_circuit``, a
    design-filter result in ``plant_json``), a model (``plant_tf``,
    ``plant_model``, ``plant_process``, a capture), or a Sallen-Key plant
    (``plant_fc_hz``/``plant_zeta``, ``plant_parts``, a design-plant
    ``plant_json``: its circuit is the Sallen-Key low-pass section
    (:func:`sallen_key_plant`), its model
    :func:`pair_model`).

    Parameters
    ----------
    source : designer.pid.plant_spec.PlantSource or designer.pid.spec.PidSpec
        The plant as given (validated when built); a spec: its ``plant``.
    opamp : str, optional
        The op-amp of a Sallen-Key plant designed from fn and zeta (default a
        spec's, else LM741).
    bounds : designer.core.eseries.PartBounds, optional
        Its parts' series and bounds (default a spec's, else the defaults).

    Returns
    -------
    Plant
        The plant.
    """
    source, opamp, bounds = _with_design_choices(source, opamp, bounds)
    if source.circuit is not None:
        return source.circuit
    if source.process is not None:
        return Plant(source.process, None, source.process.source)
    circuit, description, _ = sallen_key_plant(source, opamp=opamp, bounds=bounds)
    return Plant(pair_model(circuit, description), circuit, description)
