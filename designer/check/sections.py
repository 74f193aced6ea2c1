"""The sections of a ``check-design`` spec below its top level, each read from the
YAML document and validated once.

The op-amp corners (``opamp``), the design of a plant or pid spec for every
corner (``target``, ``parts``, ``plant``, ``tuning``, ``controller``,
``series``, ``bounds``, ``stimulus``), ``checks`` (figure -> ``{min, typ,
max, fail}``, :mod:`designer.check.limits`), ``design_checks``,
``spice_agreement`` (:class:`Agreement`), a plant's ``tolerance``, ``yield``
with ``tolerances`` (:class:`YieldSpec`: the Monte Carlo yield over the spec's
own checks, :mod:`designer.tolerance.yields`) and ``golden``
(:class:`Golden`); the keys each mapping allows are :data:`SUB`.
:func:`designer.check.spec.load_spec` puts them together.

Every refusal is one line at the key's line
(:class:`designer.check.yamldoc._Doc`). The design's own
validation (:class:`~designer.plant.spec.PlantSpec`,
:class:`~designer.pid.spec.PidSpec`) runs here for every corner, its messages
naming the spec's keys (``target.fc must be 10 mHz to 10 MHz``) instead of
the library's parameters (:data:`PLANT_KEYS`, :data:`PID_KEYS`).
"""

from __future__ import annotations

from dataclasses import dataclass
from pathlib import Path

from ..core import opamps
from ..core.checks import IDS, SPICE_AGREEMENT
from ..core.errors import DesignError
from ..core.fileio import shown
from ..core.units import parse_value
from ..filters.sallen_key_lowpass_parts import FIELD_OF, parts_of, refs
from . import figures as F
from .golden import record_advice
from .limits import LIMIT_KEYS, limit_from
from .yamldoc import kind_of, closest

__all__ = ["SUB"]

CONTROLLER_PARTS = tuple(f"R{i}" for i in range(3, 19)) + ("C3", "C4")
#: the keys of each mapping below the top level
SUB = {
    "target": ("fc", "zeta", "gain", "compensate_gbw"),
    "parts": (*refs(), "gain"),          # the Sallen-Key low-pass's designators (with its gain pair)
    "series": ("r", "c"),
    "bounds": ("r_min", "r_max", "c_min", "c_max"),
    "plant": ("fc", "zeta", *refs(with_gain=False), "gain", "json"),
    "tuning": ("rule", "kp", "ti", "td", "target_overshoot", "target_settling"),
    "controller": CONTROLLER_PARTS + ("json",),
    "spice_agreement": ("nrms_max", "against"),
    "golden": ("file", "signals", "reltol", "abstol"),
    "yield": ("min", "samples", "seed", "engine", "sampler", "dist"),
}
#: the parts a ``tolerances:`` may name besides the classes R and C
TOLERANCE_PARTS = {"plant": (*refs(), "GBW", "SR"),
                   "pid": refs(with_gain=False) + CONTROLLER_PARTS + ("GBW", "SR"), "filter": ()}
#: a yield's builds: at least, at most, and by default
YIELD_SAMPLES = (10, 10 ** 6, 2000)
STIMULUS = {"plant": ("amplitude", "frequency"), "pid": ("amplitude", "frequency", "edge")}
AGAINST = ("opamp_model", "ideal")
#: golden signals each kind records (a netlist's are the deck's vectors, named in the spec)
SIGNALS = {"plant": ("output_v", "input_v", "analytic_v", "analytic_opamp_v"),
           "pid": ("y_v", "u_v", "ve_v", "vp_v", "vd_v", "vi_v", "vs_v")}
DEFAULT_SIGNALS = {"plant": ("output_v",), "pid": ("y_v",)}
#: default tolerances of a golden signal: 1 % of the value plus 1 mV
RELTOL, ABSTOL = 0.01, 1e-3

#: library parameter -> the plant spec's key (messages of PlantSpec/AnalysisSpec)
PLANT_KEYS = {"fc_hz": "target.fc", "target_fc_hz": "target.fc", "zeta": "target.zeta",
              "target_zeta": "target.zeta", "gain": "target.gain", "compensate_gbw": "target.compensate_gbw",
              **{f: f"parts.{r}" for r, f in FIELD_OF.items()},
              "plant": "parts", "r_series": "series.r", "c_series": "series.c",
              **{k: f"bounds.{k}" for k in ("r_min", "r_max", "c_min", "c_max")}, "opamp": "opamp",
              "amplitude_v": "stimulus.amplitude", "square_hz": "stimulus.frequency"}
#: library parameter -> the pid spec's key (messages of PidSpec)
PID_KEYS = {"plant_fc_hz": "plant.fc", "plant_zeta": "plant.zeta",
            **{f"plant_{FIELD_OF[r]}": f"plant.{r}" for r in refs(with_gain=False)}, "plant_gain": "plant.gain",
            "plant_json": "plant.json", "tuning": "tuning.rule", "kp": "tuning.kp", "ti_s": "tuning.ti",
            "td_s": "tuning.td", "target_overshoot_pct": "tuning.target_overshoot",
            "target_settling_s": "tuning.target_settling", "opamp": "opamp", "step_v": "stimulus.amplitude",
            "edge_s": "stimulus.edge", "square_hz": "stimulus.frequency", "r_series": "series.r",
            "c_series": "series.c", **{k: f"bounds.{k}" for k in ("r_min", "r_max", "c_min", "c_max")},
            **{p.lower(): f"controller.{p}" for p in CONTROLLER_PARTS}, "controller_json": "controller.json",
            "controller_parts": "controller"}


@dataclass(frozen=True)
class Agreement:
    """``spice_agreement``: SPICE within ``nrms_max`` of a model (``opamp_model`` or ``ideal``)."""

    nrms_max: float
    against: str


@dataclass(frozen=True)
class Golden:
    """``golden``: the file (``{corner}`` in it stands for the op-amp) and each
    signal's (reltol, abstol)."""

    file: str
    signals: dict

    def path(self, corner: str) -> Path:
        return Path(self.file.replace("{corner}", corner))


@dataclass(frozen=True)
class YieldSpec:
    """``yield:`` (and ``tolerances:``): the fraction of builds that must pass the spec's checks,
    over ``samples`` builds drawn from ``seed`` by the engine; ``tolerances`` as ``--tol`` items
    (``R=1%``; the series' own for a part not named)."""

    min: float                  #: a fraction, above 0 and at most 1
    samples: int = YIELD_SAMPLES[2]
    seed: int = 0
    engine: str = "analytic"
    sampler: str = "random"
    dist: str = "uniform"
    tolerances: tuple = ()


def read_corners(doc) -> tuple:
    value = doc.data.get("opamp", "LM741")
    items = value if isinstance(value, list) else [value]
    if not items:
        raise doc.error(("opamp",), f"opamp: an empty list; give one of {', '.join(opamps.names())} or a list")
    out = []
    for i, v in enumerate(items):
        keys = ("opamp", i) if isinstance(value, list) else ("opamp",)
        try:
            amp = opamps.get(v) if isinstance(v, str) else None
        except DesignError:
            amp = None
        if amp is None:
            raise doc.error(keys, f"unknown op-amp {kind_of(v)}; allowed: {', '.join(opamps.names())}"
                            + (f"; closest: {closest(v, opamps.names())!r}" if isinstance(v, str) else ""))
        if amp.name in out:
            raise doc.error(keys, f"op-amp {amp.name} is listed twice")
        out.append(amp.name)
    return tuple(out)


def built_in_spec_words(doc, table: dict, build):
    """``build()`` with the library's refusal shown in the spec's words, at the key's line.

    Parameters
    ----------
    doc : designer.check.yamldoc.YamlDoc
        The spec document.
    table : dict
        Library parameter -> the spec's key path (dotted).
    build : callable
        Builds the library object; its DesignError is re-raised at the key.

    Returns
    -------
    object
        What ``build()`` returned.
    """
    try:
        return build()
    except DesignError as exc:
        msg = exc.naming(table)
        param = getattr(exc, "param", None)
        keys = tuple(table.get(param, "").split(".")) if param in table else ()
        raise doc.error(keys, msg) from None


def _common(doc, kind: str) -> dict:
    """series, bounds and stimulus as the library's keyword arguments (as typed: the library checks them)."""
    series = doc.mapping(("series",), SUB["series"])
    bounds = doc.mapping(("bounds",), SUB["bounds"])
    stim = doc.mapping(("stimulus",), STIMULUS[kind])
    out = {f"{k}_series": series[k] for k in ("r", "c") if k in series}
    out.update(bounds)
    amp_key = "amplitude_v" if kind == "plant" else "step_v"
    for key, param in (("amplitude", amp_key), ("frequency", "square_hz"), ("edge", "edge_s")):
        if key in stim:
            out[param] = stim[key]
    return out


def read_topology(doc):
    """``topology:`` (default the seed's Sallen-Key low-pass): the registered section, refused
    in one line listing the registered ones and the closest."""
    from ..filters import registry
    from ..plant.circuit import DEFAULT_TOPOLOGY
    name = doc.data.get("topology", DEFAULT_TOPOLOGY)
    if not isinstance(name, str):
        raise doc.error(("topology",), f"topology must be a name, got {kind_of(name)}; registered: "
                        f"{', '.join(registry.names())}")
    return built_in_spec_words(doc, {"topology": "topology"}, lambda: registry.get(name))


def read_plant_designs(doc, corners):
    from ..plant.circuit import DEFAULT_TOPOLOGY
    from ..plant.spec import AnalysisSpec, PlantSpec
    topo = read_topology(doc)
    target = doc.mapping(("target",), SUB["target"])
    if topo.name != DEFAULT_TOPOLOGY:
        return read_circuit_designs(doc, corners, topo, target)
    parts = doc.mapping(("parts",), SUB["parts"])
    common = _common(doc, "plant")
    if not target and not parts:
        raise doc.error((), "a plant spec needs target: {fc, zeta} (designed) or parts: {R1, R2, C1, C2} (as built)")
    if parts:
        for k in ("gain", "compensate_gbw"):
            if k in target:
                raise doc.error(("target", k), f"target.{k} applies to a design; with parts: the gain is "
                                "parts.gain (or R3/R4)")
        for k in ("bounds",):
            if doc.data.get(k) is not None:
                raise doc.error((k,), "bounds: limit a design's part search; parts: are already chosen")
        sk = parts_of({r: parts.get(r) for r in refs()}, gain=parts.get("gain"))
        kw = {k: v for k, v in common.items() if k in ("r_series", "c_series", "amplitude_v", "square_hz")}
        designs = [built_in_spec_words(doc, PLANT_KEYS, lambda amp=amp: AnalysisSpec(
            sk, opamp=amp, target_fc_hz=target.get("fc"), target_zeta=target.get("zeta"), **kw))
            for amp in corners]
        return designs, True
    for k in ("fc", "zeta"):
        if k not in target:
            raise doc.error(("target",), f"target needs {k} (and zeta/fc): the plant to design")
    extra = {"gain": target["gain"]} if "gain" in target else {}
    if "compensate_gbw" in target:
        if not isinstance(target["compensate_gbw"], bool):
            raise doc.error(("target", "compensate_gbw"), "target.compensate_gbw must be true or false")
        extra["compensate_gbw"] = target["compensate_gbw"]
    designs = [built_in_spec_words(doc, PLANT_KEYS, lambda amp=amp: PlantSpec(
        fc_hz=target["fc"], zeta=target["zeta"], opamp=amp, alternatives=1, **extra, **common))
        for amp in corners]
    return designs, False


def read_circuit_designs(doc, corners, topo, target):
    """A plant on another registered topology: designed from ``target:`` or its ``parts:`` as built
    (keys: the topology's designators, every one)."""
    from ..plant.circuit_design import CircuitAnalysisSpec
    from ..plant.spec import PlantSpec
    parts = doc.mapping(("parts",), topo.designators)
    common = _common(doc, "plant")
    if parts:
        for k in ("gain", "compensate_gbw"):
            if k in target:
                raise doc.error(("target", k), f"target.{k} applies to a design; with parts: the gain is the "
                                "parts'")
        if doc.data.get("bounds") is not None:
            raise doc.error(("bounds",), "bounds: limit a design's part search; parts: are already chosen")
        missing = [r for r in topo.designators if r not in parts]
        if missing:
            raise doc.error(("parts",), f"parts: {topo.name} needs {', '.join(missing)} too; its parts are "
                            f"{', '.join(topo.designators)}")
        kw = {k: v for k, v in common.items() if k in ("r_series", "c_series", "amplitude_v", "square_hz")}
        table = {**PLANT_KEYS, "part": "parts", **{f"part {r}": f"parts.{r}" for r in topo.designators}}
        return [built_in_spec_words(doc, table, lambda amp=amp: CircuitAnalysisSpec(
            topo.name, dict(parts), opamp=amp, target_fc_hz=target.get("fc"), target_zeta=target.get("zeta"), **kw))
            for amp in corners], True
    need = ("fc", "zeta") if topo.order == 2 else ("fc",)
    for k in need:
        if k not in target:
            raise doc.error(("target",), f"target needs {' and '.join(need)}: the {topo.name} plant to design")
    extra = {k: target[k] for k in ("gain", "compensate_gbw") if k in target}
    return [built_in_spec_words(doc, PLANT_KEYS, lambda amp=amp: PlantSpec(
        fc_hz=target["fc"], zeta=target.get("zeta"), opamp=amp, alternatives=1, topology=topo.name, **extra,
        **common)) for amp in corners], False


def read_pid_designs(doc, corners):
    from ..pid.blocks import PidParts
    from ..pid.spec import PidSpec, controller_from_json
    plant = doc.mapping(("plant",), SUB["plant"])
    if not plant:
        raise doc.error(("plant",) if "plant" in doc.data else (),
                        "a pid spec needs plant: {fc, zeta}, {R1, R2, C1, C2} or {json: result.json}")
    kw = _common(doc, "pid")
    kw.update({"plant_fc_hz": plant.get("fc"), "plant_zeta": plant.get("zeta")})
    if "json" in plant:
        kw["plant_json"] = str(doc.resolve(("plant", "json")))
    given = [r for r in refs(with_gain=False) if r in plant]
    if given:
        kw["plant_parts"] = parts_of({r: plant.get(r) for r in refs(with_gain=False)}, gain=plant.get("gain"))
    elif "gain" in plant:
        raise doc.error(("plant", "gain"), "plant.gain goes with plant.R1 .. plant.C2")
    tuning = doc.data.get("tuning")
    if isinstance(tuning, str):
        kw["tuning"] = tuning
    elif tuning is not None:
        t = doc.mapping(("tuning",), SUB["tuning"])
        for key, param in (("rule", "tuning"), ("kp", "kp"), ("ti", "ti_s"), ("td", "td_s"),
                           ("target_overshoot", "target_overshoot_pct"), ("target_settling", "target_settling_s")):
            if key in t:
                kw[param] = t[key]
    controller = doc.data.get("controller")
    analyze = controller is not None
    if analyze:
        c = doc.mapping(("controller",), SUB["controller"])
        if "json" in c:
            if len(c) > 1:
                raise doc.error(("controller",), "controller: give json: or the parts, not both")
            path = str(doc.resolve(("controller", "json")))
            kw["controller_parts"] = built_in_spec_words(doc, PID_KEYS, lambda: controller_from_json(path))
        else:
            kw["controller_parts"] = PidParts(**{p.lower(): c.get(p) for p in CONTROLLER_PARTS})
    designs = [built_in_spec_words(doc, PID_KEYS, lambda amp=amp: PidSpec(opamp=amp, **kw)) for amp in corners]
    return designs, analyze


def read_checks(doc, kind: str, known, unit_kind: str | None = None) -> tuple:
    entries = doc.get(("checks",))
    if entries is None:
        return ()
    allowed = sorted(known)
    if not isinstance(entries, dict):
        raise doc.error(("checks",), "checks must be a mapping: figure -> {min, typ, max, fail}")
    out = []
    for figure, entry in entries.items():
        if kind == "netlist" and isinstance(figure, str):
            figure = figure.lower()   # ngspice reads names case-insensitively (and prints them in lower case)
        if figure not in known:
            what = "measurement" if kind == "netlist" else "figure"
            raise doc.error(("checks", figure), f"unknown {what} {str(figure)!r} in checks; allowed: "
                            f"{', '.join(allowed) or '(none)'}; closest: {closest(figure, allowed or ['-'])!r}")
        keys = ("checks", figure)
        doc.mapping(keys, LIMIT_KEYS, entry if entry is not None else {})
        if not isinstance(entry, dict):
            raise doc.error(keys, f"checks.{figure} needs min and/or max (with typ, fail)")
        try:
            out.append(limit_from(figure, entry, f"checks.{figure}", F.unit_of(kind, figure)))
        except DesignError as exc:
            bad = next((k for k in ("min", "max", "typ", "fail") if k in entry and f".{k}" in str(exc)), None)
            raise doc.error(keys + ((bad,) if bad else ()), str(exc)) from None
    return tuple(out)


def read_design_checks(doc, kind: str):
    value = doc.data.get("design_checks")
    if value is None or value is False:
        return None
    ids = [i for i in IDS[kind] if i != SPICE_AGREEMENT]
    if value == "all" or value is True:
        return "all"
    if not isinstance(value, list) or not value:
        raise doc.error(("design_checks",), f"design_checks: all, or a list of {', '.join(ids)}")
    for i, v in enumerate(value):
        if v not in ids:
            raise doc.error(("design_checks", i), f"unknown design check {kind_of(v)}; allowed: "
                            f"{', '.join(ids)}; closest: {closest(v, ids)!r}")
    return tuple(dict.fromkeys(value))


def read_positive(doc, keys, default=None) -> float:
    """The positive number at ``keys``, or ``default`` when the key is absent.

    Parameters
    ----------
    doc : designer.check.yamldoc.YamlDoc
        The spec document (its refusals point at the key's line).
    keys : tuple
        The key path.
    default : float or None
        The value of an absent key; None: the key is required.

    Returns
    -------
    float
        The number.
    """
    value = doc.get(keys)
    label = ".".join(map(str, keys))
    if value is None:
        if default is None:
            raise doc.error(keys, f"{label} needs a number")
        return default
    try:
        out = parse_value(value, label) if not isinstance(value, bool) else None
    except DesignError:
        out = None
    if out is None or not out > 0:
        raise doc.error(keys, f"{label} must be a positive number, got {kind_of(value)}")
    return out


def read_agreement(doc):
    if doc.data.get("spice_agreement") is None:
        return None
    a = doc.mapping(("spice_agreement",), SUB["spice_agreement"])
    against = a.get("against", "opamp_model")
    if against not in AGAINST:
        raise doc.error(("spice_agreement", "against"), f"spice_agreement.against {kind_of(against)}; "
                        f"allowed: {', '.join(AGAINST)}")
    return Agreement(read_positive(doc, ("spice_agreement", "nrms_max")), against)


def read_tolerance(doc, checks) -> tuple:
    value = doc.data.get("tolerance")
    if value is None or value is False:
        return ()
    limited = [c.figure for c in checks if c.figure in F.BAND]
    if value is True:
        if not limited:
            raise doc.error(("tolerance",), f"tolerance: true needs a check on one of {', '.join(F.BAND)}")
        return tuple(limited)
    if not isinstance(value, list) or not value:
        raise doc.error(("tolerance",), f"tolerance: true, or a list of {', '.join(F.BAND)}")
    for i, v in enumerate(value):
        if v not in F.BAND:
            raise doc.error(("tolerance", i), f"tolerance: {kind_of(v)} has no tolerance band; allowed: "
                            f"{', '.join(F.BAND)}; closest: {closest(v, F.BAND)!r}")
        if v not in limited:
            raise doc.error(("tolerance", i), f"tolerance: {v} needs a check on {v} (checks.{v}: its limits)")
    return tuple(dict.fromkeys(value))


def _tolerances(doc, kind: str) -> tuple:
    """``tolerances: {R: 1%, C: 5%, C2: 2%}`` as ``--tol`` items, each checked (a class or one of the
    kind's parts, above 0 and at most 50 %)."""
    from ..tolerance.parts import MAX_TOL, parse_tolerance
    allowed = ("R", "C") + TOLERANCE_PARTS[kind]
    value = doc.mapping(("tolerances",), allowed)
    out = []
    for key, tol in value.items():
        if isinstance(tol, bool) or not isinstance(tol, (str, int, float)):
            raise doc.error(("tolerances", key), f"tolerances.{key} must be a percentage such as 1% (above 0, at "
                            f"most {100 * MAX_TOL:g} %), got {kind_of(tol)}")
        try:
            f = parse_tolerance(str(tol), f"tolerances.{key}")
        except DesignError as exc:
            raise doc.error(("tolerances", key), str(exc)) from None
        out.append(f"{key}={100 * f!r}%")
    return tuple(out)


def _fraction(doc, keys) -> float:
    """``yield.min``: 95% or 0.95, above 0 and at most 100 %."""
    value = doc.get(keys)
    label = ".".join(keys)
    shape = f"{label} must be a percentage above 0 and at most 100 % (such as 95% or 0.95), got {kind_of(value)}"
    if isinstance(value, bool) or not isinstance(value, (str, int, float)):
        raise doc.error(keys, shape)
    text = str(value).strip()
    pct = text.endswith("%")
    try:
        out = parse_value(text[:-1].strip() if pct else text, label)
    except DesignError:
        raise doc.error(keys, shape) from None
    out = out / 100 if pct else out
    if not 0 < out <= 1:
        raise doc.error(keys, shape + ("" if pct or out <= 1 else f" (for {text} % write {text}%)"))
    return float(out)


def _whole(doc, keys, lo: int, hi: int, default: int) -> int:
    value = doc.get(keys)
    if value is None:
        return default
    label = ".".join(keys)
    if isinstance(value, bool) or not isinstance(value, (int, str)) or not str(value).strip().isdigit() \
            or not lo <= int(str(value).strip()) <= hi:
        span = f"from {lo} to {hi:g}" if hi < 2 ** 32 else f">= {lo}"
        raise doc.error(keys, f"{label} must be a whole number {span}, got {kind_of(value)}")
    return int(str(value).strip())


def read_yield(doc, kind: str, checks):
    """``yield:`` with ``tolerances:`` (None without ``yield:``; ``tolerances:`` alone is refused)."""
    from ..tolerance import sampling, yields
    from ..tolerance.parts import DISTRIBUTIONS
    from ..tolerance.spice_mc import section_analysis
    if doc.data.get("yield") is None:
        if doc.data.get("tolerances") is not None:
            raise doc.error(("tolerances",), "tolerances: set the parts' spread of a yield: give yield: {min: "
                            "95%} too (the tolerance: band uses the series' tolerances)")
        return None
    y = doc.mapping(("yield",), SUB["yield"])
    if "min" not in y:
        raise doc.error(("yield",), "yield needs min: the fraction of builds that must pass (such as 95%)")
    engine = y.get("engine", "analytic")
    for key, allowed in (("engine", yields.ENGINES), ("sampler", sampling.SAMPLERS), ("dist", DISTRIBUTIONS)):
        if key in y and y[key] not in allowed:
            raise doc.error(("yield", key), f"yield.{key} {kind_of(y[key])} unknown; allowed: {', '.join(allowed)}")
    if kind == "filter" and engine != "analytic":
        raise doc.error(("yield", "engine"), "yield.engine: a filter's yield has the analytic engine only (allowed: "
                        "analytic); analyze-filter --spice-samples compares it with ngspice on the same builds")
    from ..filters import registry
    from ..plant.circuit import DEFAULT_TOPOLOGY
    # the topology: read (and checked) with the designs, before the yield
    topo = registry.get(doc.data["topology"]) if kind == "plant" and "topology" in doc.data else None
    topology = None if topo is None else topo.name
    section = topology is not None and topology != DEFAULT_TOPOLOGY
    # a section's engines: its analytic figures, or SPICE's of the analysis its engine runs (a low-pass's step,
    # another section's .ac: the command line's rule, designer.tolerance.spice_mc.section_analysis)
    table = yields.SECTION if section else kind
    analysis = section_analysis(topo) if section else None
    use, skipped = yields.counted(table, checks, engine, analysis)
    if not use:
        known = ", ".join(yields.figure_table(table, engine, analysis))
        raise doc.error(("yield",), "yield counts the builds inside checks:, and none of them limits a figure the "
                        f"{engine} engine computes ({known})" + (f"; not: {', '.join(skipped)}" if skipped else ""))
    tolerances = _tolerances(doc, kind)
    spreads_sr = any(t.startswith("SR=") for t in tolerances)
    if section and spreads_sr and analysis != "step":
        raise doc.error(("tolerances", "SR"), f"tolerances.SR: topology {topology}'s yield engines are linear (its "
                        "analytic model, and ngspice's .ac sweep: small signal), no figure of them depends on the "
                        "slew rate; GBW: spreads the op-amp")
    if kind == "plant" and engine == "analytic" and spreads_sr:
        raise doc.error(("tolerances", "SR"), "tolerances.SR: the plant's analytic model is linear, no figure of it "
                        "depends on the slew rate; give yield.engine: spice (ngspice's op-amp slews)")
    lo, hi, default = YIELD_SAMPLES
    return YieldSpec(_fraction(doc, ("yield", "min")), _whole(doc, ("yield", "samples"), lo, hi, default),
                     _whole(doc, ("yield", "seed"), 0, 2 ** 63 - 1, 0), engine, y.get("sampler", "random"),
                     y.get("dist", "uniform"), tolerances)


def read_golden(doc, kind: str, corners, update: bool):
    if doc.data.get("golden") is None:
        return None
    g = doc.mapping(("golden",), SUB["golden"])
    file = doc.resolve(("golden", "file"))
    if len(corners) > 1 and "{corner}" not in str(file):
        raise doc.error(("golden", "file"), "golden.file needs {corner} in its name with several op-amps "
                        f"(one golden waveform per corner: {', '.join(corners)})")
    reltol = read_positive(doc, ("golden", "reltol"), RELTOL) if "reltol" in g else RELTOL
    abstol = read_positive(doc, ("golden", "abstol"), ABSTOL) if "abstol" in g else ABSTOL
    raw = g.get("signals", list(DEFAULT_SIGNALS.get(kind, ())))
    if not raw:
        raise doc.error(("golden",), "golden.signals: name the deck's vectors to compare (e.g. [out])")
    known = SIGNALS.get(kind)
    signals = {}
    items = raw.items() if isinstance(raw, dict) else ((s, None) for s in raw) if isinstance(raw, list) else None
    if items is None:
        raise doc.error(("golden", "signals"), "golden.signals: a list of names, or name -> {reltol, abstol}")
    for sig, tol in items:
        keys = ("golden", "signals", sig)
        if not isinstance(sig, str) or (known is not None and sig not in known):
            allowed = known or ("a vector name",)
            raise doc.error(keys, f"unknown golden signal {kind_of(sig)}; allowed: {', '.join(allowed)}; "
                            f"closest: {closest(sig, allowed)!r}")
        doc.mapping(keys, ("reltol", "abstol"), tol if tol is not None else {})
        signals[sig] = (read_positive(doc, keys + ("reltol",), reltol) if tol and "reltol" in tol else reltol,
                        read_positive(doc, keys + ("abstol",), abstol) if tol and "abstol" in tol else abstol)
    golden = Golden(str(file), signals)
    for c in corners:   # each corner's own file: one of them may be a link out of the folder
        doc.inside(("golden", "file"), golden.path(c))
    if not update:
        for c in corners:
            if not golden.path(c).is_file():
                raise doc.error(("golden", "file"), record_advice(f"golden file {shown(golden.path(c))} does not "
                                                                  "exist"))
    return golden
