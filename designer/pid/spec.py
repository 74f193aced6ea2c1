"""What a ``design-pid`` user asks for, validated once, when it is built.

A :class:`PidSpec` is a plant source (:class:`~designer.pid.plant_spec.PlantSource`,
which validates the plant: exactly one source, its ranges, the Sallen-Key
plant's parts through the one plant validation,
:func:`designer.plant.sallenkey.check_parts`) and the controller's fields. A
spec that exists is a valid one: every number inside its physical range
(:data:`designer.core.ranges.RANGES`), the options consistent with each other
and with the plant. Numbers may be given as numbers or in engineering
notation (``"43.215u"``), so that the command line hands over what the user
typed and the message for a bad value quotes it. The plant's parameters may
also be given flat, as before (``PidSpec(plant_fc_hz=3500, plant_zeta=0.2,
kp=2, ...)``): they make the spec's ``plant``, and read back as its
attributes (``spec.plant_fc_hz`` is ``spec.plant.plant_fc_hz``).

Errors name the library's parameters (``kp``, ``ti_s``, ``plant_fc_hz``);
the command line shows its options instead, from one table
(:data:`designer.cli.common.FLAGS`): a message about one parameter starts
with its name (:attr:`DesignError.param`), a message about several writes
them as ``{name}`` markers (:class:`ParamError`).
"""

from __future__ import annotations

from dataclasses import MISSING, dataclass, fields, replace

from ..core import opamps
from ..core.errors import DesignError, ParamError
from ..core.eseries import PartBounds
from ..core.fileio import show_cell, shown
from ..core.jsonio import read_result
from ..core.ranges import parse_in_range
from ..plant.sallenkey import SallenKeyParts
from . import tuning as rules
from .blocks import PidParts
from .plant_spec import NUMBERS as PLANT_NUMBERS
from .plant_spec import PLANT_FIELDS, PLANT_RANGES, PlantSource

__all__ = ["CONTROLLER_FIELDS", "PLAIN_PARAMS", "PidSpec", "analyzed_name", "controller_as_built",
           "controller_from_json", "default_name", "pid_spec"]

#: the spec's own numbers and their ranges (keys of RANGES), in the order they are checked (the plant's:
#: designer.pid.plant_spec)
NUMBERS = (("kp", "kp"), ("ti_s", "ti_s"), ("td_s", "td_s"),
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
#: the controller's options that only a model plant (--plant-tf, --plant-model, --plant-capture) takes (the
#: plant's own, plant_input, plant_output and plant_method, are checked by PlantSource)
MODEL_ONLY = ("simc_tauc_s", "imc_lambda_s", "min_phase_margin_deg", "min_gain_margin_db", "max_ms")
#: what the plant source resolves on construction, read through the spec too
RESOLVED = ("json_plant", "process", "circuit")


@dataclass(frozen=True, init=False)
class PidSpec(PartBounds):
    """A controller design request (SI units), validated on construction.

    ``plant`` is where the plant comes from (a
    :class:`~designer.pid.plant_spec.PlantSource`: fn and zeta, Sallen-Key
    parts, a result.json, a filter section or cascade, a typed or identified
    model); its fields may instead be given flat (``plant_fc_hz=3500,
    plant_zeta=0.2``; with ``plant`` too, they replace its fields) and read
    back as the spec's attributes. A model plant is designed
    by :mod:`designer.pid.design`: its rules are :data:`designer.pid.rules.RULES`,
    ``optimize`` holds the loop to ``min_phase_margin_deg``,
    ``min_gain_margin_db`` and ``max_ms`` (defaults 45 deg, 6 dB, 1.7; with
    ``robust`` over the model's 95 % corners too). Gains come from a rule
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

    plant: PlantSource | None = None
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
    simc_tauc_s: float | None = None
    imc_lambda_s: float | None = None
    min_phase_margin_deg: float | None = None
    min_gain_margin_db: float | None = None
    max_ms: float | None = None
    robust: bool = False

    def __init__(self, plant: PlantSource | None = None, **kw):
        # the plant's fields given flat (the spec's keywords before PlantSource) are taken apart here and
        # made into ``plant`` in the checks' order (after the controller's numbers, bounds and package)
        flat = {k: kw.pop(k) for k in PLANT_FIELDS if k in kw}
        unknown = [k for k in kw if k not in _DEFAULTS]
        if unknown:
            raise TypeError(f"PidSpec.__init__() got an unexpected keyword argument {unknown[0]!r}")
        for name, default in _DEFAULTS.items():
            object.__setattr__(self, name, kw[name] if name in kw else default)
        object.__setattr__(self, "plant", plant)
        self._validate(flat)

    def _validate(self, flat: dict):
        """Parse, check and normalise every field (frozen: once, here); ``flat`` the plant's fields given flat."""
        def put(name, value):
            object.__setattr__(self, name, value)   # frozen: the spec is normalised once, here

        for name, key in PLANT_NUMBERS:    # the plant's numbers first, as they always were
            if flat.get(name) is not None:
                flat[name] = parse_in_range(flat[name], name, key)
        for name, key in NUMBERS:
            value = getattr(self, name)
            if value is not None:
                put(name, parse_in_range(value, name, key))
        self.check_bounds()
        if self.package is not None:
            # refused before any work when the op-amp does not come in it (an NE5532 has no quad)
            from ..core.opamps import get
            get(self.opamp).package(self.package)
        if self.plant is None:
            put("plant", PlantSource(**flat))
        elif not isinstance(self.plant, PlantSource):
            raise _refused("{plant} must be a designer.pid.plant_spec.PlantSource")
        elif flat:
            put("plant", replace(self.plant, **flat))
        if self.controller_parts is not None:
            put("controller_parts", check_controller(self.controller_parts))
        put("opamp", opamps.get(self.opamp).name)
        if self.tuning is not None:
            put("tuning", str(self.tuning).strip().lower())
        if self.process is not None:
            self._check_model_plant()
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
        if not all(explicit) and self.tuning not in (None, "optimize") and self.tuning not in rules.RULES:
            raise _refused(f"unknown {{tuning}} {show_cell(self.tuning)}; allowed: {', '.join(rules.RULES)}, "
                           "optimize")
        if self.tuning == "optimize":
            if self.target_overshoot_pct is None:
                raise _refused("{tuning} optimize needs {target_overshoot_pct} P (percent)")
        elif self.target_overshoot_pct is not None or self.target_settling_s is not None:
            raise _refused("{target_overshoot_pct}/{target_settling_s} only apply to {tuning} optimize")

    def _check_model_plant(self):
        """The controller's options for a model plant: rule names, targets, robust with intervals."""
        from . import rules as model_rules
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


def _plant_attribute(name: str) -> property:
    """The plant source's ``name`` read through the spec (the spec's attribute before PlantSource)."""
    def get(self):
        return getattr(self.plant, name)
    get.__name__ = name
    get.__doc__ = f"``plant.{name}`` (:class:`~designer.pid.plant_spec.PlantSource`)."
    return property(get)


#: the spec's own fields but its plant, and their defaults (every one a plain value: no default_factory)
_DEFAULTS = {f.name: f.default for f in fields(PidSpec) if f.init and f.name != "plant"}
assert MISSING not in _DEFAULTS.values()

for _name in (*PLANT_FIELDS, *RESOLVED):
    setattr(PidSpec, _name, _plant_attribute(_name))


#: the names a message of the spec marks as parameters (``{kp}``): its fields, the plant's and its parts
PARAMS = frozenset({f.name for f in fields(PidSpec)} | set(PLANT_FIELDS) | set(RESOLVED)
                   | {f"plant_{k}" for k in PLANT_RANGES})


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
        (default 1) as the plant's :class:`~designer.plant.sallenkey.SallenKeyParts` (the flags' record, which the
        plant source converts once into the generic record, :func:`designer.pid.plant.sallen_key_circuit`), and
        ``seed_parts``
        (true: the seed's controller parts, :func:`designer.pid.blocks.seed_parts`).

    Returns
    -------
    PidSpec
        Checked on construction: its ``plant`` (a :class:`~designer.pid.plant_spec.PlantSource`) made of the
        plant's parameters (:data:`~designer.pid.plant_spec.PLANT_FIELDS`), the rest its controller's fields.
        The plant's parameters go to the spec flat, so that it makes the plant source where it checked the
        plant before (after the plant's and the controller's numbers, the bounds and the package): the first
        refusal of a request with several faults stays the one it was, but for a plant read or parsed (a
        model, a file) that now comes before the controller's parts and op-amp.

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


#: the controller as built, part by part (:func:`controller_as_built`), as :class:`~designer.pid.blocks.PidParts`
#: fields
CONTROLLER_FIELDS = tuple(f"r{i}" for i in range(3, 19)) + ("c3", "c4")


def controller_as_built(params: dict) -> PidParts:
    """The controller's parts as built, from plain parameters (analyze-pid's options, the web page's fields):
    every part (:data:`CONTROLLER_FIELDS`: ``r3`` .. ``c4``, as typed) or a result.json's (``controller_json``,
    its path); the one mapping every front end uses.

    Parameters
    ----------
    params : dict
        :data:`CONTROLLER_FIELDS` and ``controller_json`` (a value None is not given).

    Returns
    -------
    PidParts
        The parts (checked by :class:`PidSpec` when they go into one, or by :func:`controller_from_json`).

    Raises
    ------
    DesignError
        Both ways given, or neither (one line naming the parameters).
    """
    typed = {k: params.get(k) for k in CONTROLLER_FIELDS}
    names = (*CONTROLLER_FIELDS, "controller_json")
    if params.get("controller_json") is not None:
        if any(v is not None for v in typed.values()):
            raise ParamError("give the controller either part by part ({r3} .. {c4}) or {controller_json}, not both",
                             names)
        return controller_from_json(params["controller_json"])
    if all(v is None for v in typed.values()):
        raise ParamError("the controller's parts are needed: {r3} .. {r18}, {c3}, {c4} (or {controller_json} FILE)",
                         names)
    return PidParts(**typed)


def analyzed_name(spec: PidSpec, result) -> str:
    """analyze-pid's name of an analysis (its files) when none is given: from the tuning, the op-amp and the
    plant (a model plant's: :func:`default_name`).

    Parameters
    ----------
    spec : PidSpec
        What was asked.
    result : designer.pid.result.PidResult
        The analysis.

    Returns
    -------
    str
        The name.
    """
    if spec.process is not None:
        return default_name(spec, result)
    return f"pid_{result.tuning.method}_{spec.opamp.lower()}_fn{result.plant.fn_hz:.5g}_z{result.plant.zeta:.3g}"


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
    if spec.plant.process is not None:
        kind = spec.plant.circuit.circuit.topology if spec.plant.circuit is not None else spec.plant.process.kind
        return f"pid_{result.method}_{spec.opamp.lower()}_{kind}"
    extra = "_seedparts" if spec.controller_parts is not None else ""
    return f"pid_{spec.method}_{spec.opamp.lower()}_fn{result.plant.fn_hz:.5g}_z{result.plant.zeta:.3g}{extra}"


def _refused(marked: str) -> ParamError:
    """A refusal naming parameters as ``{name}`` markers (only :data:`PARAMS`: a
    file name's braces stay as they are)."""
    return ParamError(marked, PARAMS)


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
