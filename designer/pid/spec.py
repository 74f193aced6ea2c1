"""What a ``design-pid`` user asks for, validated once, when it is built.

A :class:`PidSpec` that exists is a valid one: every number inside its
physical range (:data:`designer.core.ranges.RANGES`), the options consistent,
the plant's parts (given, or read from a ``design-plant`` result.json) through
the one plant validation, :func:`designer.plant.sallenkey.check_parts`.
Numbers may be given as numbers or in engineering notation (``"43.215u"``),
so that the command line hands over what the user typed and the message for
a bad value quotes it.

Errors name the library's parameters (``kp``, ``ti_s``, ``plant_fc_hz``);
the command line shows its options instead, from one table
(:data:`designer.cli.common.FLAGS`): a message about one parameter starts
with its name (:attr:`DesignError.param`), a message about several writes
them as ``{name}`` markers (:class:`ParamError`).
"""

from __future__ import annotations

from dataclasses import dataclass, field, fields, replace

from ..core import opamps
from ..core.errors import DesignError, ParamError
from ..core.eseries import PartBounds
from ..core.fileio import show_cell, shown
from ..core.jsonio import read_result
from ..core.process import ProcessModel
from ..core.ranges import parse_in_range
from ..plant.sallenkey import SallenKeyParts, check_parts
from . import tuning as rules
from .blocks import PidParts

__all__ = ["PLAIN_PARAMS", "PidSpec", "controller_from_json", "default_name", "pid_spec"]

#: what the plant validation calls the fields of ``plant_parts`` (markers: see ParamError)
PLANT_NAMES = {"r1": "{plant_r1}", "r2": "{plant_r2}", "c1": "{plant_c1}", "c2": "{plant_c2}",
               "gain": "{plant_gain}", "r3": "R3", "r4": "R4", "plant": "{plant_r1}..{plant_c2}"}
#: the ranges of the plant's parts the command line gives (keys of RANGES)
PLANT_RANGES = {"r1": "resistor_ohm", "r2": "resistor_ohm", "c1": "capacitor_f", "c2": "capacitor_f", "gain": "gain"}
#: the spec's own numbers and their ranges (keys of RANGES), in the order they are checked
NUMBERS = (("plant_fc_hz", "fc_hz"), ("plant_zeta", "zeta"), ("kp", "kp"), ("ti_s", "ti_s"), ("td_s", "td_s"),
           ("step_v", "step_v"), ("edge_s", "edge_s"), ("target_overshoot_pct", "target_overshoot_pct"),
           ("target_settling_s", "target_settling_s"), ("f_integrator_hz", "f_integrator_hz"),
           ("f_differentiator_hz", "f_differentiator_hz"), ("square_hz", "square_hz"),
           ("simc_tauc_s", "simc_tauc_s"), ("imc_lambda_s", "imc_lambda_s"),
           ("min_phase_margin_deg", "min_phase_margin_deg"), ("min_gain_margin_db", "min_gain_margin_db"),
           ("max_ms", "max_ms"))
#: a model plant's loop is held to these unless told otherwise (MATLAB's pidtune aims at 60 deg)
DEFAULT_MIN_PHASE_MARGIN_DEG = 45.0
DEFAULT_MIN_GAIN_MARGIN_DB = 6.0
DEFAULT_MAX_MS = 1.7
#: the options that only a model plant (--plant-tf, --plant-model, --plant-capture) takes
MODEL_ONLY = ("plant_input", "plant_output", "simc_tauc_s", "imc_lambda_s", "min_phase_margin_deg",
              "min_gain_margin_db", "max_ms", "plant_method")


@dataclass(frozen=True)
class PidSpec(PartBounds):
    """A controller design request (SI units), validated on construction.

    Give the plant one way: ``plant_fc_hz`` with ``plant_zeta`` (designed as
    ``design-plant`` would), ``plant_parts`` (as built), ``plant_json`` (a
    ``design-plant``/``analyze-plant`` result.json), or as a model only:
    ``plant_tf`` (typed, :func:`~designer.core.process_text.parse_tf`),
    ``plant_model`` (an ``identify``/``identify-freq`` JSON, its best valid
    model or ``plant_method``) or ``plant_process`` (a
    :class:`~designer.core.process.ProcessModel`). A model plant is designed
    by :mod:`designer.pid.design`: its rules are :data:`designer.pid.rules.RULES`,
    ``optimize`` holds the loop to ``min_phase_margin_deg``,
    ``min_gain_margin_db`` and ``max_ms`` (defaults 45 deg, 6 dB, 1.7; with
    ``robust`` over the model's 95 % corners too), and ``plant_input`` /
    ``plant_output`` (``"0:10"`` or a pair, volts) are the ranges the plant
    accepts and delivers. Gains come from a rule
    (``tuning``: one of :data:`designer.pid.tuning.RULES`, default ``zn``),
    from ``tuning="optimize"`` with ``target_overshoot_pct``, or explicitly
    from ``kp``, ``ti_s`` and ``td_s`` together (``td_s = 0`` for a PI).
    ``controller_parts`` skips the sizing (e.g. the seed's own parts). The
    part series and bounds (keyword-only) are those of
    :class:`~designer.core.eseries.PartBounds`.

    Raises
    ------
    DesignError
        One line naming the parameter at fault and what is allowed.
    """

    plant_fc_hz: float | None = None
    plant_zeta: float | None = None
    plant_parts: SallenKeyParts | None = None
    plant_json: str | None = None
    tuning: str | None = None          #: rule name, "optimize", or None (zn, or explicit if gains are given)
    kp: float | None = None
    ti_s: float | None = None
    td_s: float | None = None
    opamp: str = "LM741"
    step_v: float = 1.0
    edge_s: float = 100e-9
    target_overshoot_pct: float | None = None
    target_settling_s: float | None = None
    f_integrator_hz: float | None = None
    f_differentiator_hz: float | None = None
    square_hz: float | None = None
    controller_parts: PidParts | None = None
    tol: float = 0.01
    #: how the bench puts the op-amps in packages: single, dual, quad (None: the op-amp's own first)
    package: str | None = None
    plant_tf: str | None = None
    plant_model: str | None = None
    plant_method: str | None = None
    plant_process: ProcessModel | None = None
    plant_input: object = None          #: "lo:hi" (volts) or a (lo, hi) pair: what the plant accepts
    plant_output: object = None         #: the same for what it delivers
    simc_tauc_s: float | None = None
    imc_lambda_s: float | None = None
    min_phase_margin_deg: float | None = None
    min_gain_margin_db: float | None = None
    max_ms: float | None = None
    robust: bool = False
    #: a plant that is one registered filter section (designer.filters.registry), with ``plant_values``
    plant_topology: str | None = None
    #: its part values: designator -> value (number or engineering notation), or "R1=10k" items
    plant_values: object = None
    #: a plant circuit given as sections: a designer.filters.cascade.Cascade or (topology, values) pairs
    plant_circuit: object = None
    #: the plant read from ``plant_json`` (read and checked on construction, before any work)
    json_plant: SallenKeyParts | None = field(default=None, init=False, repr=False, compare=False)
    #: the model plant, from plant_tf, plant_model or plant_process (None for a Sallen-Key plant)
    process: ProcessModel | None = field(default=None, init=False, repr=False, compare=False)
    #: a circuit plant of any topology (designer.pid.plant.Plant), from plant_topology, plant_circuit or a
    #: design-filter plant_json; its model is ``process``
    circuit: object = field(default=None, init=False, repr=False, compare=False)

    def __post_init__(self):
        def put(name, value):
            object.__setattr__(self, name, value)   # frozen: the spec is normalised once, here

        for name, key in NUMBERS:
            value = getattr(self, name)
            if value is not None:
                put(name, parse_in_range(value, name, key))
        self.check_bounds()
        if self.package is not None:
            # refused before any work when the op-amp does not come in it (an NE5532 has no quad)
            from ..core.opamps import get
            get(self.opamp).package(self.package)
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
            # parts typed as text (the command line's) are read here, the rest by the plant validation
            typed = {k: parse_in_range(getattr(self.plant_parts, k), f"plant_{k}", key)
                     for k, key in PLANT_RANGES.items() if isinstance(getattr(self.plant_parts, k), str)}
            put("plant_parts", check_plant(replace(self.plant_parts, **typed), PLANT_NAMES))
        if self.plant_json is not None:
            circuit = filter_plant_from_json(self.plant_json)
            if circuit is not None:
                put("circuit", circuit)
            else:
                put("json_plant", plant_from_json(self.plant_json))
        if self.plant_topology is not None or self.plant_circuit is not None:
            put("circuit", self._circuit())
        if self.controller_parts is not None:
            put("controller_parts", check_controller(self.controller_parts))
        put("opamp", opamps.get(self.opamp).name)
        if self.tuning is not None:
            put("tuning", str(self.tuning).strip().lower())
        put("process", self._process())
        if self.process is not None:
            self._check_model_plant(put)
            return
        given = [k for k in MODEL_ONLY if getattr(self, k) is not None] + (["robust"] if self.robust else [])
        if given:
            raise _refused(f"{{{given[0]}}} is for a plant given as a model ({{plant_tf}}, {{plant_model}} or "
                           "--plant-capture), not a Sallen-Key plant")
        explicit = [v is not None for v in (self.kp, self.ti_s, self.td_s)]
        if any(explicit) and not all(explicit):
            raise _refused("{kp}, {ti_s} and {td_s} go together (give all three)")
        if all(explicit) and self.tuning not in (None, "explicit"):
            raise _refused(f"{{tuning}} {self.tuning} and explicit {{kp}}/{{ti_s}}/{{td_s}} "
                           "exclude each other")
        if (self.process is None and not all(explicit) and self.tuning not in (None, "optimize")
                and self.tuning not in rules.RULES):
            raise _refused(f"unknown {{tuning}} {show_cell(self.tuning)}; allowed: {', '.join(rules.RULES)}, "
                           "optimize")
        if self.tuning == "optimize" and self.process is None:
            if self.target_overshoot_pct is None:
                raise _refused("{tuning} optimize needs {target_overshoot_pct} P (percent)")
        elif self.process is None and (self.target_overshoot_pct is not None or self.target_settling_s is not None):
            raise _refused("{target_overshoot_pct}/{target_settling_s} only apply to {tuning} optimize")

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

    def _check_model_plant(self, put):
        """The options of a model plant: rule names, ranges, robust with intervals."""
        from . import rules as model_rules
        for name in ("plant_input", "plant_output"):
            value = getattr(self, name)
            if value is not None:
                put(name, voltage_range(value, name))
        explicit = self.kp is not None
        if not explicit and self.tuning not in (None, "optimize") and self.tuning not in model_rules.RULES:
            raise _refused(f"unknown {{tuning}} {show_cell(self.tuning)}; allowed for a model plant: "
                           f"{', '.join(model_rules.RULES)}, optimize")
        if self.tuning != "optimize" and self.target_settling_s is not None:
            raise _refused("{target_settling_s} only applies to {tuning} optimize")
        if self.tuning not in ("optimize", None) and self.target_overshoot_pct is not None:
            raise _refused("{target_overshoot_pct} only applies to {tuning} optimize")
        if self.robust and not self.process.ci95:
            raise _refused("{robust} checks the loop over the model's 95 % intervals, and this model has none "
                           "(a typed model; identify's least-squares fits have them)")

    @property
    def method(self) -> str:
        """How the gains are chosen: ``explicit``, ``optimize`` or a rule name."""
        return "explicit" if self.kp is not None else (self.tuning or "zn")


def voltage_range(value, name: str) -> tuple:
    """``"0:10"`` (engineering notation either side, ``"-5:5"``, ``"0 : 3.3"``)
    or a (lo, hi) pair as a (lo, hi) tuple of volts, lo < hi, both inside
    ``RANGES["plant_voltage_v"]``."""
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


#: the names a message of the spec marks as parameters (``{kp}``): its fields and the plant's parts
PARAMS = frozenset({f.name for f in fields(PidSpec)} | {f"plant_{k}" for k in PLANT_RANGES})


#: the plain parameters :func:`pid_spec` takes beside the spec's own fields: the Sallen-Key plant as built,
#: part by part, and the seed's controller parts (V.13) instead of sizing
PLAIN_PARAMS = ("plant_r1", "plant_r2", "plant_c1", "plant_c2", "plant_gain", "seed_parts")


def pid_spec(params: dict) -> PidSpec:
    """A :class:`PidSpec` from plain parameters, as every front end has them (the command line's options, the
    web page's fields): the one mapping from what a user types to the spec.

    Parameters
    ----------
    params : dict
        The spec's own fields (:class:`PidSpec`; a value None is not given), and :data:`PLAIN_PARAMS`:
        ``plant_r1``, ``plant_r2``, ``plant_c1``, ``plant_c2`` (all four together) with ``plant_gain``
        (default 1) as the plant's :class:`~designer.plant.sallenkey.SallenKeyParts`, and ``seed_parts``
        (true: the seed's controller parts, :func:`designer.pid.blocks.seed_parts`).

    Returns
    -------
    PidSpec
        Checked on construction.

    Raises
    ------
    DesignError
        One line naming the parameters at fault (``{name}`` markers of a :class:`ParamError`).
    """
    p = {k: v for k, v in params.items() if v is not None}
    parts = [p.pop(k, None) for k in PLAIN_PARAMS[:4]]
    gain = p.pop("plant_gain", None)
    if any(v is not None for v in parts):
        if not all(v is not None for v in parts):
            raise _refused("{plant_r1}, {plant_r2}, {plant_c1} and {plant_c2} go together")
        p["plant_parts"] = SallenKeyParts(*parts, gain)
    elif gain is not None:
        raise _refused("{plant_gain} goes with {plant_r1}..{plant_c2}")
    if p.pop("seed_parts", False):
        from .blocks import seed_parts
        p["controller_parts"] = seed_parts()
    return PidSpec(**p)


def default_name(spec: PidSpec, result) -> str:
    """design-pid's name of a design (its files) when none is given.

    Parameters
    ----------
    spec : PidSpec
        What was asked.
    result : designer.pid.result.PidResult
        The design (its rule; a Sallen-Key plant's fn and zeta as built).

    Returns
    -------
    str
        ``pid_<rule>_<opamp>_fn<fn>_z<zeta>`` (``_seedparts`` with the seed's controller parts) for a
        Sallen-Key plant; ``pid_<rule>_<opamp>_<kind>`` for a model plant (a circuit plant: its topology).
    """
    if spec.process is not None:
        kind = spec.circuit.circuit.topology if spec.circuit is not None else spec.process.kind
        return f"pid_{result.method}_{spec.opamp.lower()}_{kind}"
    extra = "_seedparts" if spec.controller_parts is not None else ""
    return f"pid_{spec.method}_{spec.opamp.lower()}_fn{result.plant.fn_hz:.5g}_z{result.plant.zeta:.3g}{extra}"


def _refused(marked: str) -> ParamError:
    """A refusal naming parameters as ``{name}`` markers (only :data:`PARAMS`: a
    file name's braces stay as they are)."""
    return ParamError(marked, PARAMS)


def check_plant(parts: SallenKeyParts, names: dict) -> SallenKeyParts:
    """:func:`~designer.plant.sallenkey.check_parts` with its fields named by
    ``names`` (markers allowed); a refusal as a :class:`ParamError`."""
    try:
        return check_parts(parts, name_of=names)
    except DesignError as exc:
        raise _refused(str(exc)) from None


#: result.json keys of the plant's parts (the ``built`` object of design-plant and analyze-plant)
BUILT_KEYS = {"r1": "R1_ohm", "r2": "R2_ohm", "c1": "C1_f", "c2": "C2_f", "gain": "gain", "r3": "R3_ohm",
              "r4": "R4_ohm"}


def filter_plant_from_json(path):
    """The circuit of a ``design-filter`` result.json as a
    :class:`~designer.pid.plant.Plant`, or None for any other file (read then
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
    if not (isinstance(data, dict) and data.get("tool") == "design-filter"):
        return None
    from .plant import circuit_from_json
    try:
        return circuit_from_json(data, name=f"{{plant_json}} {shown(path)}")
    except DesignError as exc:
        raise _refused(str(exc)) from None


def plant_from_json(path) -> SallenKeyParts:
    """The built plant of a ``design-plant``/``analyze-plant`` result.json, read
    by the one reader (:func:`designer.core.jsonio.read_result`) and checked by
    the one plant validation (:func:`designer.plant.sallenkey.check_parts`):
    values of the wrong type, out of range, a gain that disagrees with R3/R4 or
    an unstable circuit are refused in one line naming the file and the key."""
    needed = tuple(BUILT_KEYS[k] for k in ("r1", "r2", "c1", "c2"))
    try:
        built = read_result(path, "{plant_json}", needs={"built": needed})["built"]
    except DesignError as exc:
        raise _refused(str(exc)) from None
    raw = SallenKeyParts(*(built.get(v) for v in BUILT_KEYS.values()))
    names = {k: f"{{plant_json}} {shown(path)}: built.{v}" for k, v in BUILT_KEYS.items()}
    return check_plant(raw, names | {"plant": f"{{plant_json}} {shown(path)}"})


#: the controller's parts (:class:`~designer.pid.blocks.PidParts` fields) and their ranges (keys of RANGES)
CONTROLLER_RANGES = {**{f"r{i}": "resistor_ohm" for i in range(3, 19)}, "c3": "capacitor_f", "c4": "capacitor_f"}
#: the derivative path: all four given (a PID) or none (a PI)
DERIVATIVE_PARTS = ("r7", "r11", "r12", "c3")


def check_controller(parts: PidParts, names: dict | None = None) -> PidParts:
    """The controller as built, checked once: every part a number (or text in
    engineering notation) inside its physical range, the derivative path
    (R7, R11, R12, C3) all given or all left out (a PI).

    ``names`` maps a field (``r5``) to how a message names it (default the
    field itself, e.g. ``r5``, which the command line shows as ``--r5``).

    Raises
    ------
    DesignError
        One line naming the part at fault and what is allowed.
    """
    names = names or {}
    values = {}
    for key, rng in CONTROLLER_RANGES.items():
        value = getattr(parts, key)
        name = names.get(key, key)
        if value is None:
            if key not in DERIVATIVE_PARTS:
                raise DesignError(f"{name} is missing: every controller part but the derivative path "
                                  "(R7, R11, R12, C3; all four, or none for a PI) is needed", param=name)
            values[key] = None
            continue
        values[key] = parse_in_range(value, name, rng)
    given = [k for k in DERIVATIVE_PARTS if values[k] is not None]
    if given and len(given) != len(DERIVATIVE_PARTS):
        lacking = [names.get(k, k) for k in DERIVATIVE_PARTS if values[k] is None]
        raise DesignError(f"{lacking[0]} is missing: the derivative path needs R7, R11, R12 and C3 together "
                          "(leave all four out for a PI)", param=lacking[0])
    return PidParts(**values)


def controller_from_json(path) -> PidParts:
    """The controller parts of a ``design-pid``/``analyze-pid`` result.json (its
    ``components`` object: ``R3_ohm`` .. ``C4_f``), read by the one reader and
    checked by :func:`check_controller`; a refusal names the file and the key.

    Parameters
    ----------
    path : str or Path
        The result.json.

    Returns
    -------
    PidParts
    """
    try:
        comp = read_result(path, "{controller_json}", needs={"components": ("R3_ohm",)},
                           what="a design-pid result.json")["components"]
    except DesignError as exc:
        raise ParamError(str(exc), ("controller_json",)) from None
    keys = {k: (f"{k.upper()}_ohm" if k[0] == "r" else f"{k.upper()}_f") for k in CONTROLLER_RANGES}
    raw = PidParts(**{k: comp.get(v) for k, v in keys.items()})
    try:
        return check_controller(raw, {k: f"{{controller_json}} {shown(path)}: components.{v}"
                                      for k, v in keys.items()})
    except DesignError as exc:
        raise ParamError(str(exc), ("controller_json",)) from None
