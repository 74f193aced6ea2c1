"""Where a PID's plant comes from, validated once, when it is given.

A :class:`PlantSource` that exists is a valid one: exactly one source given
(``plant_fc_hz``/``plant_zeta``, ``plant_parts``, ``plant_json``,
``plant_tf``, ``plant_model``, ``plant_process``, ``plant_topology`` with
``plant_values``, or ``plant_circuit``), its numbers inside their physical
ranges (:data:`designer.core.ranges.RANGES`), the Sallen-Key plant's parts
(given, or read from a ``design-plant`` result.json) through the one plant
validation, :func:`designer.plant.sallenkey.check_parts`, a circuit's parts
through its topology's declaration (:func:`designer.pid.plant.parse_part_values`),
a model read and checked (:func:`designer.core.process_text.parse_tf`,
:func:`designer.pid.plant_source.model_from_json`), and the options only a
model plant takes (``plant_input``, ``plant_output``, ``plant_method``) only
with one. :func:`designer.pid.plant.resolve_plant` turns it into a
:class:`~designer.pid.plant.Plant`; :class:`designer.pid.spec.PidSpec` holds
one beside the controller's fields.

Errors name the parameters as :class:`~designer.pid.spec.PidSpec` and every
front end know them (``plant_fc_hz``, ``plant_r1``), as ``{name}`` markers of
a :class:`~designer.core.errors.ParamError` that the command line reads as
its options (:data:`designer.cli.common.FLAGS`). The Sallen-Key plant's part
names (its fields, designators and result.json keys) are read from its
declaration, :mod:`designer.filters.sallen_key_lowpass_parts`.
"""

from __future__ import annotations

from dataclasses import dataclass, field, fields, replace

from ..core.errors import DesignError, ParamError
from ..core.fileio import show_cell, shown
from ..core.jsonio import read_result
from ..core.process import ProcessModel
from ..core.ranges import parse_in_range
from ..filters.sallen_key_lowpass_parts import FIELD_OF, gain_refs, record_of, refs, section_of
from ..plant.sallenkey import SallenKeyParts, check_parts
from .plant_source import BUILT_KEYS

__all__ = ["PLANT_FIELDS", "PlantSource", "filter_plant_from_json", "plant_from_json", "voltage_range"]

#: the plant's numbers and their ranges (keys of RANGES), in the order they are checked
NUMBERS = (("plant_fc_hz", "fc_hz"), ("plant_zeta", "zeta"))
#: the ranges (keys of RANGES) of a part of each kind the section declares
KIND_RANGES = {"R": "resistor_ohm", "C": "capacitor_f"}
#: the Sallen-Key network's fields (``r1`` ..), in the section's declared order
NETWORK_FIELDS = tuple(FIELD_OF[r] for r in refs(with_gain=False))
#: the ranges of the plant's parts the command line gives, by field (keys of RANGES)
PLANT_RANGES = {**{FIELD_OF[p.ref]: KIND_RANGES[p.kind] for p in section_of(with_gain=False).parts},
                "gain": "gain"}
#: what the plant validation calls the fields of ``plant_parts`` (markers: see ParamError): the network's
#: and the gain as the front ends' ``plant_<field>``, the gain pair (not an option) by its designators
PLANT_NAMES = {**{f: f"{{plant_{f}}}" for f in (*NETWORK_FIELDS, "gain")},
               **{FIELD_OF[r]: r for r in gain_refs()},
               "plant": f"{{plant_{NETWORK_FIELDS[0]}}}..{{plant_{NETWORK_FIELDS[-1]}}}"}


@dataclass(frozen=True)
class PlantSource:
    """A PID's plant as given (SI units), validated on construction.

    Give it one way: ``plant_fc_hz`` with ``plant_zeta`` (designed as
    ``design-plant`` would), ``plant_parts`` (a Sallen-Key low-pass as built),
    ``plant_json`` (a ``design-plant``/``analyze-plant``/``design-filter``
    result.json), ``plant_topology`` with ``plant_values`` (one registered
    filter section, :mod:`designer.filters.registry`, and its part values),
    ``plant_circuit`` (a :class:`~designer.filters.cascade.Cascade` or
    (topology, values) pairs), or as a model only: ``plant_tf`` (typed,
    :func:`~designer.core.process_text.parse_tf`), ``plant_model`` (an
    ``identify``/``identify-freq`` JSON, its best valid model or
    ``plant_method``) or ``plant_process`` (a
    :class:`~designer.core.process.ProcessModel`). A model plant may say the
    ranges it accepts and delivers, ``plant_input`` / ``plant_output``
    (``"0:10"`` or a pair, volts). Numbers may be given as numbers or in
    engineering notation (``"3.5k"``).

    Raises
    ------
    DesignError
        One line naming the parameter at fault and what is allowed.
    """

    plant_fc_hz: float | None = None
    plant_zeta: float | None = None
    #: a Sallen-Key low-pass as built: its parts record (the command line's --plant-r1 .., check-design's
    #: keys), checked and held as the generic record (designer.pid.plant.PlantCircuit), or that record
    plant_parts: object = None
    plant_json: str | None = None
    plant_tf: str | None = None
    plant_model: str | None = None
    plant_method: str | None = None
    plant_process: ProcessModel | None = None
    plant_input: object = None          #: "lo:hi" (volts) or a (lo, hi) pair: what the plant accepts
    plant_output: object = None         #: the same for what it delivers
    #: a plant that is one registered filter section (designer.filters.registry), with ``plant_values``
    plant_topology: str | None = None
    #: its part values: designator -> value (number or engineering notation), or "R1=10k" items
    plant_values: object = None
    #: a plant circuit given as sections: a designer.filters.cascade.Cascade or (topology, values) pairs
    plant_circuit: object = None
    #: the Sallen-Key plant read from a design-plant ``plant_json`` (read and checked on construction, before
    #: any work), as the generic record (designer.pid.plant.PlantCircuit)
    json_plant: object = field(default=None, init=False, repr=False, compare=False)
    #: the model plant, from plant_tf, plant_model or plant_process (None for a Sallen-Key plant)
    process: ProcessModel | None = field(default=None, init=False, repr=False, compare=False)
    #: a circuit plant of any topology (designer.pid.plant.Plant), from plant_topology, plant_circuit or a
    #: design-filter plant_json; its model is ``process``
    circuit: object = field(default=None, init=False, repr=False, compare=False)

    def __post_init__(self):
        def put(name, value):
            object.__setattr__(self, name, value)   # frozen: the source is normalised once, here

        for name, key in NUMBERS:
            value = getattr(self, name)
            if value is not None:
                put(name, parse_in_range(value, name, key))
        sources = sum(x is not None for x in (self.plant_fc_hz, self.plant_parts, self.plant_json,
                                              self.plant_tf, self.plant_model, self.plant_process,
                                              self.plant_topology, self.plant_circuit))
        if sources != 1:
            raise _refused("give the plant one way: {plant_fc_hz}/{plant_zeta}, {plant_r1}..{plant_c2}, "
                           "{plant_topology} with {plant_values}, {plant_json}, {plant_tf}, {plant_model} or "
                           "--plant-capture")
        if (self.plant_values is not None) != (self.plant_topology is not None):
            raise _refused("{plant_topology} and {plant_values} go together (the section and its parts)")
        if self.plant_fc_hz is not None and self.plant_zeta is None:
            raise _refused("{plant_fc_hz} needs {plant_zeta}")
        if self.plant_fc_hz is None and self.plant_zeta is not None:
            raise _refused("{plant_zeta} needs {plant_fc_hz}")
        if self.plant_parts is not None:
            put("plant_parts", _given_plant(self.plant_parts))
        if self.plant_json is not None:
            circuit = filter_plant_from_json(self.plant_json)
            if circuit is not None:
                put("circuit", circuit)
            else:
                put("json_plant", plant_from_json(self.plant_json))
        if self.plant_topology is not None or self.plant_circuit is not None:
            put("circuit", self._circuit())
        put("process", self._process())
        ranges = [k for k in ("plant_input", "plant_output") if getattr(self, k) is not None]
        if ranges and self.process is None:
            raise _refused(f"{{{ranges[0]}}} is for a plant given as a model ({{plant_tf}}, {{plant_model}} or "
                           "--plant-capture), not a Sallen-Key plant")
        for name in ranges:
            put(name, voltage_range(getattr(self, name), name))

    def _circuit(self):
        """The circuit plant of ``plant_topology``/``plant_values`` or ``plant_circuit``."""
        from .plant import circuit_from_cascade, circuit_plant
        try:
            if self.plant_topology is not None:
                return circuit_plant(self.plant_topology, self.plant_values, name="plant_values")
            return circuit_from_cascade(self.plant_circuit, name="plant_circuit")
        except DesignError as exc:
            if exc.param == "topology":   # the registry's refusal, named as this spec's parameter
                where = "{plant_topology}" if self.plant_topology is not None else "{plant_circuit}"
                raise _refused(where + str(exc)[len("topology"):]) from None
            raise

    def _process(self):
        """The model plant, read and checked (None for a Sallen-Key plant)."""
        if self.circuit is not None:
            return self.circuit.design_model   # an inverting circuit: -G, the controller's action reversed
        if self.plant_tf is not None:
            from ..core.process_text import parse_tf
            try:
                return parse_tf(self.plant_tf)
            except DesignError as exc:
                raise _refused("{plant_tf} " + str(exc)) from None
        if self.plant_model is not None:
            from .plant_source import model_from_json
            try:
                return model_from_json(self.plant_model, self.plant_method)
            except DesignError as exc:
                raise _refused(str(exc).replace("--plant-model", "{plant_model}")) from None
        if self.plant_process is not None:
            if not isinstance(self.plant_process, ProcessModel):
                raise _refused("{plant_process} must be a designer.core.process.ProcessModel")
            return self.plant_process
        if self.plant_method is not None:
            raise _refused("{plant_method} chooses among the methods of a {plant_model} file")
        return None


def _given_plant(parts):
    """``plant_parts`` as the generic record: a Sallen-Key parts record (parts typed as text, the command
    line's, read here, the rest by the plant validation) converted once
    (:func:`designer.pid.plant.sallen_key_circuit`), or that record again (a spec replaced, a Monte Carlo
    build's) checked as the parts record it stands for."""
    from .plant import PlantCircuit, sallen_key_circuit
    if isinstance(parts, PlantCircuit):
        st = parts.stages[0] if len(parts.stages) == 1 else None
        record = None if st is None else record_of(st.topology, st.values)
        if record is None:
            raise _refused("{plant_parts} is the Sallen-Key low-pass plant's parts; give another circuit as "
                           "{plant_topology} with {plant_values} or {plant_circuit}")
        # gain None: the resistors' 1 + R4/R3, as the record the circuit was made from
        return sallen_key_circuit(_checked(replace(record, gain=None), PLANT_NAMES))
    if not isinstance(parts, SallenKeyParts):
        raise _refused("{plant_parts} must be a designer.plant.sallenkey.SallenKeyParts or a "
                       "designer.pid.plant.PlantCircuit")
    typed = {k: parse_in_range(getattr(parts, k), f"plant_{k}", key)
             for k, key in PLANT_RANGES.items() if isinstance(getattr(parts, k), str)}
    return sallen_key_circuit(_checked(replace(parts, **typed), PLANT_NAMES))


#: the parameters a :class:`PlantSource` takes (its fields), as :class:`~designer.pid.spec.PidSpec` takes them
PLANT_FIELDS = tuple(f.name for f in fields(PlantSource) if f.init)
#: the names a message about the plant marks as parameters (``{plant_zeta}``): its fields and the parts'
PARAMS = frozenset({f.name for f in fields(PlantSource)} | {f"plant_{k}" for k in PLANT_RANGES})


def voltage_range(value, name: str) -> tuple:
    """A range of volts as typed, checked.

    Parameters
    ----------
    value : str or pair
        ``"0:10"`` (engineering notation either side, ``"-5:5"``, ``"0 : 3.3"``) or a (lo, hi) pair.
    name : str
        The parameter named in messages.

    Returns
    -------
    tuple of float
        (lo, hi) in volts, lo < hi, both inside ``RANGES["plant_voltage_v"]``.
    """
    if isinstance(value, str):
        cells = value.split(":")
        if len(cells) != 2:
            raise DesignError(f"{name} is a range LO:HI in volts, such as 0:10 or -5:5; got {show_cell(value)}",
                              param=name)
        lo, hi = (parse_in_range(c.strip(), name, "plant_voltage_v") for c in cells)
    else:
        try:
            lo, hi = (parse_in_range(v, name, "plant_voltage_v") for v in value)
        except (TypeError, ValueError):
            raise DesignError(f"{name} is a range (lo, hi) in volts", param=name) from None
    if not lo < hi:
        raise DesignError(f"{name} needs LO < HI, got {lo:g}:{hi:g} V", param=name)
    return float(lo), float(hi)


def _refused(marked: str) -> ParamError:
    """A refusal naming parameters as ``{name}`` markers (only :data:`PARAMS`: a
    file name's braces stay as they are)."""
    return ParamError(marked, PARAMS)


def _checked(parts: SallenKeyParts, names: dict) -> SallenKeyParts:
    """:func:`~designer.plant.sallenkey.check_parts` with its fields named by
    ``names`` (markers allowed); a refusal as a :class:`ParamError`."""
    try:
        return check_parts(parts, name_of=names)
    except DesignError as exc:
        raise _refused(str(exc)) from None


def filter_plant_from_json(path):
    """The circuit of a ``design-filter`` result.json (its cascade) or of a ``design-plant``/``analyze-plant
    --topology`` one (its section) as a :class:`~designer.pid.plant.Plant`, or None for any other file (read then
    by :func:`plant_from_json`, whose refusals name what it accepts).

    Parameters
    ----------
    path : str or Path
        The ``plant_json`` file.

    Returns
    -------
    designer.pid.plant.Plant or None
        The cascade plant, or None for another kind of file.
    """
    try:
        data = read_result(path, "{plant_json}")
    except DesignError:
        return None
    if not isinstance(data, dict):
        return None
    # a design-plant/analyze-plant --topology result is a section's plant (its 'parts'); the seed's
    # Sallen-Key plant has 'built' parts and no 'parts', and stays plant_from_json's
    section = data.get("mode") in ("design", "analyze") and isinstance(data.get("topology"), str) and "parts" in data
    if not (data.get("tool") == "design-filter" or section):
        return None
    from .plant import circuit_from_json
    try:
        return circuit_from_json(data, name=f"{{plant_json}} {shown(path)}")
    except DesignError as exc:
        raise _refused(str(exc)) from None


def plant_from_json(path):
    """The built plant of a ``design-plant``/``analyze-plant`` result.json, as the
    generic record (:class:`~designer.pid.plant.PlantCircuit`: its keys read as the
    Sallen-Key parts record and converted once, :func:`designer.pid.plant.sallen_key_circuit`).

    Read by the one reader (:func:`designer.core.jsonio.read_result`) and
    checked by the one plant validation (:func:`designer.plant.sallenkey.check_parts`):
    values of the wrong type, out of range, a gain that disagrees with R3/R4 or
    an unstable circuit are refused in one line naming the file and the key.

    Parameters
    ----------
    path : str or Path
        ``plant_json``: a result.json whose ``built`` object holds the parts.

    Returns
    -------
    designer.pid.plant.PlantCircuit
        The plant as built.
    """
    from .plant import sallen_key_circuit
    needed = tuple(BUILT_KEYS[k] for k in NETWORK_FIELDS)
    try:
        built = read_result(path, "{plant_json}", needs={"built": needed})["built"]
    except DesignError as exc:
        raise _refused(str(exc)) from None
    raw = SallenKeyParts(**{k: built.get(v) for k, v in BUILT_KEYS.items()})
    names = {k: f"{{plant_json}} {shown(path)}: built.{v}" for k, v in BUILT_KEYS.items()}
    return sallen_key_circuit(_checked(raw, names | {"plant": f"{{plant_json}} {shown(path)}"}))
