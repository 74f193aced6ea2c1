"""The web page's own names for the library's parameters, and a request's
fields turned into the spec objects the command line builds.

One name table per front end (issue 26): the command line maps its
``--flags`` to the library's parameters (:data:`designer.cli.common.FLAGS`);
the page maps its fields to the same parameters here (:data:`PLANT`), each
with the label the page shows beside the field. A request's JSON
(``{"fc": 3500, "zeta": "0.2"}``) becomes a :class:`~designer.plant.spec.PlantSpec`
and, with a Monte Carlo, a :class:`~designer.tolerance.mcspec.MonteCarloSpec`,
typed values in, no command line built nor parsed. The specs check the
values once; their errors name a library parameter, which
:func:`page_message` shows as the field's label (``"fc (Hz)" must be ...``),
never as a ``--flag``.
"""

from __future__ import annotations

import re
from typing import NamedTuple

from ..check.yamldoc import WIDER
from ..core.errors import DesignError, ParamError
from ..core.i18n import N_, Message, localise, translated
from ..core.i18n import gettext as _
from ..filters.sallen_key_lowpass_parts import FIELD_OF, gain_refs, parts_of
from ..filters.sallen_key_lowpass_parts import refs as sallen_key_refs
from .request import option_name, value_text

__all__ = ["ANALYZE_PID", "ANALYZE_PLANT", "AnalyzePlantRequest", "CAPTURE_FIELDS", "CHECK", "CheckRequest",
           "DESIGN_ONLY", "FILTER", "Field", "FilterRequest", "IDENTIFY", "IDENTIFY_FILES", "PID", "PLANT",
           "PidRequest", "PlantRequest", "analyze_pid_request", "analyze_plant_request", "check_message",
           "check_request", "field_of", "filter_request", "identify_request", "page_message", "page_text",
           "pid_request", "plant_request"]


class Field(NamedTuple):
    """One field of a page's form: the library parameter it sets and its label on the page."""

    param: str            #: the library's name (``fc_hz``; a MonteCarloSpec's ``n``)
    label: str            #: what the page shows beside it (``fc (Hz)``)
    kind: str = "value"   #: ``value`` (a number or a text), ``switch`` (true/false), ``list`` (several texts),
    #: ``file`` (a file's content: a JSON object or a text, written in the request's folder)


#: the plant page's fields (the API's keys, as design-plant's option names) -> parameter and label
PLANT = {
    "fc": Field("fc_hz", N_("fc (Hz)")), "zeta": Field("zeta", N_("zeta")), "gain": Field("gain", N_("gain K")),
    "compensate-gbw": Field("compensate_gbw", N_("compensate the op-amp's GBW"), "switch"),
    "r": Field("r", N_("R fixed (Ohm)")), "c": Field("c", N_("C fixed (F)")),
    "r-series": Field("r_series", N_("R series")), "c-series": Field("c_series", N_("C series")),
    "r-min": Field("r_min", N_("R min")), "r-max": Field("r_max", N_("R max")),
    "c-min": Field("c_min", N_("C min")), "c-max": Field("c_max", N_("C max")),
    "alternatives": Field("alternatives", N_("alternatives listed")),
    "opamp": Field("opamp", N_("op-amp")), "amplitude": Field("amplitude_v", N_("amplitude (V)")),
    "square-freq": Field("square_hz", N_("square wave (Hz)")), "package": Field("package", N_("package")),
    "no-sim": Field("no_sim", N_("skip SPICE"), "switch"), "simulator": Field("simulator", N_("simulator")),
    "name": Field("name", N_("design name")), "topology": Field("topology", N_("topology")),
    # the tolerance panel (a MonteCarloSpec)
    "monte-carlo": Field("n", N_("Monte Carlo builds")), "seed": Field("seed", N_("seed")),
    "tol": Field("tol", N_("tolerances"), "list"), "limit": Field("limits", N_("limits"), "list"),
    "dist": Field("dist", N_("distribution")), "sampler": Field("sampler", N_("sampler")),
    "target-ci": Field("target_ci", N_("target interval")), "engine": Field("engine", N_("engine")),
    "spice-samples": Field("spice_samples", N_("SPICE samples")),
    "worst-case": Field("worst_case", N_("worst case"), "switch"),
    "stimulus": Field("stimulus", N_("stimulus")), "prbs-bits": Field("bits", N_("PRBS bits")),
    "prbs-clock": Field("clock_hz", N_("PRBS clock (Hz)")),
}
#: the analyze-plant page's fields (the API's keys, as analyze-plant's option names) -> parameter and label: the
#: parts as built (the Sallen-Key low-pass's by their names, any section's by designator), the target the errors
#: are reported against; the op-amp, bench, run and tolerance fields as the plant page's
ANALYZE_PLANT = {
    **{FIELD_OF[ref]: Field(FIELD_OF[ref], ref) for ref in sallen_key_refs()},
    "part": Field("part", N_("parts"), "list"), "gain": Field("gain", N_("gain K")),
    "fc": Field("target_fc_hz", N_("target fc (Hz)")), "zeta": Field("target_zeta", N_("target zeta")),
    **{k: PLANT[k] for k in PLANT if k not in ("fc", "zeta", "gain", "compensate-gbw", "r", "c", "r-min", "r-max",
                                               "c-min", "c-max", "alternatives")},
    "replay": Field("replay", N_("build replayed")),
}
#: the filter page's fields (the API's keys, as design-filter's option names) -> parameter and label
FILTER = {
    "type": Field("filter_type", N_("type")), "family": Field("family", N_("family")),
    "order": Field("order", N_("order")), "fc": Field("fc_hz", N_("fc (Hz)")), "ripple": Field("ripple_db", N_("ripple (dB)")),
    "bessel-norm": Field("bessel_norm", N_("Bessel cut-off")), "chebyshev-cutoff": Field("chebyshev_cutoff",
                                                                                      N_("Chebyshev cut-off")),
    "passband": Field("passband_hz", N_("passband edge (Hz)")), "max-loss": Field("max_loss_db", N_("max loss (dB)")),
    "stopband": Field("stopband_hz", N_("stopband edge (Hz)")),
    "min-attenuation": Field("min_attenuation_db", N_("min attenuation (dB)")),
    "f-low": Field("f_low_hz", N_("low edge (Hz)")), "f-high": Field("f_high_hz", N_("high edge (Hz)")),
    "bandpass-method": Field("bandpass_method", N_("band-pass method")),
    "topology": Field("topology", N_("topology")), "stage-order": Field("stage_order", N_("stage order")),
    "gain": Field("gain", N_("gain (V/V)")), "stage-gain": Field("stage_gains", N_("stage gains")),
    "opamp": Field("opamp", N_("op-amp")), "amplitude": Field("amplitude_v", N_("amplitude (V)")),
    "gbw-margin": Field("gbw_margin", N_("GBW margin")), "impedance": Field("impedance_ohm", N_("impedance (Ohm)")),
    "compensate-gbw": Field("compensate_gbw", N_("compensate the op-amp's GBW"), "switch"),
    "series": Field("r_series", N_("R series")), "c-series": Field("c_series", N_("C series")),
    "r-min": Field("r_min", N_("R min")), "r-max": Field("r_max", N_("R max")),
    "c-min": Field("c_min", N_("C min")), "c-max": Field("c_max", N_("C max")),
    "alternatives": Field("alternatives", N_("alternatives listed")),
    "no-sim": Field("no_sim", N_("skip SPICE"), "switch"), "simulator": Field("simulator", N_("simulator")),
    "name": Field("name", N_("design name")),
    # the tolerance panel (a MonteCarloSpec, run against the mask)
    "monte-carlo": Field("n", N_("Monte Carlo builds")), "seed": Field("seed", N_("seed")),
    "tol": Field("tol", N_("tolerances"), "list"), "limit": Field("limits", N_("limits"), "list"),
    "dist": Field("dist", N_("distribution")), "sampler": Field("sampler", N_("sampler")),
    "worst-case": Field("worst_case", N_("worst case"), "switch"),
}
#: the identify page's fields (the API's keys, as identify's option names) -> parameter of
#: :func:`designer.identify.spec.identify_spec` and label (``no-refine`` sets ``refine``, inverted)
IDENTIFY = {
    "step-time": Field("step_time_s", N_("step time (s)")), "step-amplitude": Field("step_amplitude", N_("step amplitude")),
    "window": Field("window", N_("window (s)"), "list"), "format": Field("fmt", N_("format")),
    "input-column": Field("input_column", N_("input column")),
    "output-column": Field("output_column", N_("output column")),
    "sample-time": Field("sample_time_s", N_("sample time (s)")), "columns": Field("column_names", N_("columns")),
    "methods": Field("methods", N_("methods"), "list"), "no-refine": Field("refine", N_("skip least squares"), "switch"),
    "method": Field("method", N_("broadband route")), "segment-length": Field("segment_length", N_("Welch segment")),
    "validate": Field("validate", N_("validation capture"), "file"),
    "against": Field("against", N_("design result.json"), "file"),
}
#: the file an identify file field's content is written to, in the request's folder
IDENTIFY_FILES = {"validate": "validation-capture.csv", "against": "design-result.json"}
#: identify's fields a PID request with a plant capture takes too (design-pid's capture options)
CAPTURE_FIELDS = ("step-time", "step-amplitude", "window", "format", "input-column", "output-column", "sample-time",
                  "columns", "methods", "no-refine")
#: the PID page's fields (the API's keys, as design-pid's option names) -> parameter of
#: :func:`designer.pid.spec.pid_spec` (or of the Monte Carlo) and label
PID = {
    # the plant, one way
    "plant-fc": Field("plant_fc_hz", N_("plant fc (Hz)")), "plant-zeta": Field("plant_zeta", N_("plant zeta")),
    # the Sallen-Key plant as built: its parts by their designators (the topology's declaration), their labels
    **{f"plant-{ref.lower()}": Field(f"plant_{ref.lower()}", ref) for ref in sallen_key_refs(with_gain=False)},
    "plant-gain": Field("plant_gain", N_("gain K")), "plant-topology": Field("plant_topology", N_("plant topology")),
    "plant-part": Field("plant_values", N_("plant parts"), "list"),
    "plant-json": Field("plant_json", N_("plant result.json"), "file"), "plant-tf": Field("plant_tf", N_("model")),
    "plant-model": Field("plant_model", N_("identified model"), "file"),
    "plant-capture": Field("plant_capture", N_("plant capture"), "file"),
    # the capture read and identified as identify does, with its options
    **{k: IDENTIFY[k] for k in CAPTURE_FIELDS},
    "plant-method": Field("plant_method", N_("method")),
    "plant-input": Field("plant_input", N_("plant input range (V)")),
    "plant-output": Field("plant_output", N_("plant output range (V)")),
    # the tuning
    "tuning": Field("tuning", N_("rule")), "kp": Field("kp", N_("Kp")), "ti": Field("ti_s", N_("Ti (s)")),
    "td": Field("td_s", N_("Td (s)")), "target-overshoot": Field("target_overshoot_pct", N_("target overshoot (%)")),
    "target-settling": Field("target_settling_s", N_("target settling (s)")),
    "simc-tauc": Field("simc_tauc_s", N_("SIMC tau_c (s)")), "imc-lambda": Field("imc_lambda_s", N_("IMC lambda (s)")),
    "min-pm": Field("min_phase_margin_deg", N_("min phase margin (deg)")),
    "min-gm": Field("min_gain_margin_db", N_("min gain margin (dB)")), "max-ms": Field("max_ms", N_("max Ms")),
    "robust": Field("robust", N_("robust"), "switch"),
    "rules-spice": Field("rules_spice", N_("every rule in SPICE"), "switch"),
    "seed-parts": Field("seed_parts", N_("the seed's parts"), "switch"),
    # the parts
    "r-series": Field("r_series", N_("R series")), "c-series": Field("c_series", N_("C series")),
    "r-min": Field("r_min", N_("R min")), "r-max": Field("r_max", N_("R max")),
    "c-min": Field("c_min", N_("C min")), "c-max": Field("c_max", N_("C max")),
    "f-integrator": Field("f_integrator_hz", N_("integrator corner (Hz)")),
    "f-differentiator": Field("f_differentiator_hz", N_("derivative corner (Hz)")),
    # the op-amps and the test signal
    "opamp": Field("opamp", N_("op-amp")), "step": Field("step_v", N_("step (V)")),
    "edge": Field("edge_s", N_("edge (s)")), "square-freq": Field("square_hz", N_("square wave (Hz)")),
    "package": Field("package", N_("package")),
    "no-sim": Field("no_sim", N_("skip SPICE"), "switch"), "simulator": Field("simulator", N_("simulator")),
    "name": Field("name", N_("design name")),
    # the tolerance panel (a MonteCarloSpec of the loop as built)
    "monte-carlo": Field("n", N_("Monte Carlo builds")), "seed": Field("seed", N_("seed")),
    "tol": Field("tol", N_("tolerances"), "list"), "limit": Field("limits", N_("limits"), "list"),
    "dist": Field("dist", N_("distribution")), "sampler": Field("sampler", N_("sampler")),
    "target-ci": Field("target_ci", N_("target interval")), "engine": Field("engine", N_("engine")),
    "spice-samples": Field("spice_samples", N_("SPICE samples")),
    "worst-case": Field("worst_case", N_("worst case"), "switch"),
    "replay": Field("replay", N_("build replayed")),
}
#: design-pid's fields analyze-pid has not (the tuning and the sizing: its controller is built)
DESIGN_ONLY = ("tuning", "target-overshoot", "target-settling", "rules-spice", "seed-parts", "r-series", "c-series",
               "r-min", "r-max", "c-min", "c-max", "f-integrator", "f-differentiator")
#: the analyze-pid page's fields (the API's keys, as analyze-pid's option names) -> parameter of
#: :func:`designer.pid.spec.pid_spec` (the controller's parts: of :func:`designer.pid.spec.controller_as_built`)
#: and label: the PID page's but the tuning and sizing, and the controller as built
ANALYZE_PID = {
    **{k: f for k, f in PID.items() if k not in DESIGN_ONLY},
    **{name: Field(name, name.upper()) for name in (*(f"r{i}" for i in range(3, 19)), "c3", "c4")},
    "parts-json": Field("controller_json", N_("controller result.json"), "file"),
}
#: the Check page's fields (the API's ``options`` keys, as check-design's option names) -> parameter of
#: :func:`designer.check.batch.check_specs` and label; the files and the folder they stay inside are the request's
CHECK = {
    "simulator": Field("simulator", N_("simulator")),
    "update-golden": Field("update_golden", N_("record the golden files"), "switch"),
}
#: the command line's advice in check-design's refusals (its options the page has not), as the page gives it;
#: ``--update-golden`` then reads as its field's label (:func:`page_message`)
CHECK_WORDS = (
    (WIDER, N_("the folder chosen is the limit: choose a folder holding every file the spec names")),
    ("check-design --update-golden", "--update-golden"),
)
#: design-pid's defaults as its options type them (the spec parses them as it parses the command line's: the
#: same numbers to the last bit, so the page's JSON is design-pid's)
PID_DEFAULTS = {"step_v": "1", "edge_s": "100n", "r_series": "E24", "c_series": "E12", "r_min": "1k", "r_max": "1M",
                "c_min": "1n", "c_max": "10u"}
#: the file a file field's content is written to, in the request's folder (never a path the request gives)
PID_FILES = {"plant_json": "plant-result.json", "plant_model": "plant-model.json",
             "plant_capture": "plant-capture.csv", "controller_json": "parts-result.json"}
#: the simulators a request may choose (designer.spice.simulate's backends)
SIMULATORS = ("pyspice", "ngspice-cli")
_FLAG = re.compile(r"--([a-z][a-z0-9-]*)(?: [A-Z][A-Z_]*\b)?")
#: a value a message quotes as given ('3.5q', '--help'): never read as a flag
_QUOTED = re.compile(r"((?<![A-Za-z])'[^']*')")


class AnalyzePlantRequest(NamedTuple):
    """An analyze-plant page's request (parts as built) as the library takes it."""

    spec: object                #: :class:`~designer.plant.spec.AnalysisSpec` (the Sallen-Key low-pass), or None
    circuit: dict | None        #: another section's :func:`~designer.plant.circuit_design.analyze_circuit_plant`
    #: arguments (its parts checked), or None
    monte_carlo: object         #: :class:`~designer.tolerance.mcspec.MonteCarloSpec` or None
    worst_case: bool            #: the extremes over the tolerance box too
    tol: tuple                  #: the worst case's tolerances (without a Monte Carlo)
    simulate: bool
    simulator: str
    stimulus: tuple | None      #: (bits, clock Hz) of a PRBS bench test, or None
    name: str                   #: the analysis's name (its files)
    argv: list                  #: the command line this request stands for (``tool.argv`` of its JSON)
    replay: int | None = None   #: the Monte Carlo's build analysed alone in SPICE (analyze-plant --replay I)


class CheckRequest(NamedTuple):
    """A Check page's request as the library takes it (the spec files apart: the server writes them)."""

    simulator: str
    update_golden: bool         #: record the golden files (answered for download, never kept)
    argv: list                  #: the command line this request stands for (``tool.argv`` of its JSON)


class FilterRequest(NamedTuple):
    """A filter page's request as the library takes it."""

    spec: object                #: :class:`~designer.filters.spec.FilterSpec`
    monte_carlo: object         #: :class:`~designer.tolerance.mcspec.MonteCarloSpec` or None
    worst_case: bool            #: the extremes over the tolerance box too
    tol: tuple                  #: the worst case's tolerances (without a Monte Carlo)
    simulate: bool
    simulator: str
    name: str                   #: the design's name (its files)
    argv: list                  #: the command line this request stands for (``tool.argv`` of its JSON)
    alternatives: int | None = None   #: how many of the joint search's best part sets to list (None: none)


class PidRequest(NamedTuple):
    """A PID page's request as the library takes it."""

    spec: object                #: :class:`~designer.pid.spec.PidSpec`
    monte_carlo: object         #: :class:`~designer.tolerance.mcspec.MonteCarloSpec` or None
    worst_case: bool            #: the extremes over the tolerance box too
    tol: tuple                  #: the worst case's tolerances (without a Monte Carlo)
    simulate: bool
    simulator: str
    rules_spice: bool           #: a model plant: every applicable rule's loop in SPICE too
    name: str | None            #: the design's name (its files); None: design-pid's default, from the result
    argv: list                  #: the command line this request stands for (``tool.argv`` of its JSON)
    replay: int | None = None   #: the Monte Carlo's build analysed as built in SPICE (design-pid --replay I)


class PlantRequest(NamedTuple):
    """A plant page's request as the library takes it."""

    spec: object                #: :class:`~designer.plant.spec.PlantSpec`
    monte_carlo: object         #: :class:`~designer.tolerance.mcspec.MonteCarloSpec` or None
    worst_case: bool            #: the extremes over the tolerance box too
    tol: tuple                  #: the worst case's tolerances (without a Monte Carlo)
    simulate: bool
    simulator: str
    stimulus: tuple | None      #: (bits, clock Hz) of a PRBS bench test, or None
    name: str                   #: the design's name (its files)
    argv: list                  #: the command line this request stands for (``tool.argv`` of its JSON)


def field_of(table: dict, param: str | None) -> str | None:
    """The field of ``table`` that sets the library parameter ``param`` (None: no field).

    Parameters
    ----------
    table : dict
        Field name -> field of a command's form.
    param : str or None
        A library parameter's name.

    Returns
    -------
    str or None
        The field's name.
    """
    return next((k for k, f in table.items() if f.param == param), None)


def page_message(exc: DesignError, table: dict) -> tuple:
    """A library refusal in the page's words: (the message, the field it names or None).

    Parameters
    ----------
    exc : DesignError
        The library's error (its parameter, or ``{name}`` markers).
    table : dict
        The page's fields (:data:`PLANT`).

    Returns
    -------
    tuple
        The message with each parameter (and each ``--flag`` the library wrote) as its field's label,
        quoted; and the field of the parameter it names first.
    """
    labels = {f.param: f'"{_(f.label)}"' for f in table.values()}
    text = exc.naming(labels) if callable(getattr(exc, "naming", None)) else str(exc)
    # a flag the library wrote, outside the values it quotes ('--help' given as a value stays as given)
    # the numbers as the page's language writes them (a value quoted as given stays as given)
    parts = [p if k % 2 else localise(p) for k, p in enumerate(_QUOTED.split(text))]
    # a library name the message writes in its text ("unknown filter_type 'foo'"): the field's label
    names = re.compile(r"(?<![\w.{-])(" + "|".join(sorted((re.escape(f.param) for f in table.values() if "_" in f.param),
                                                          key=len, reverse=True)) + r")(?![\w=])")

    def words(p):
        p = _FLAG.sub(lambda m: f'"{_(table[m.group(1)].label)}"' if m.group(1) in table
                      else m.group(1).replace("-", " "), p)
        return names.sub(lambda m: labels[m.group(1)], p)
    text = "".join(p if k % 2 else words(p) for k, p in enumerate(parts))
    field = field_of(table, getattr(exc, "param", None))
    if field is None:   # a message written with the command line's option: the first one it names
        found = _FLAG.search(str(exc))
        field = found.group(1) if found and found.group(1) in table else None
    return text, field


def _fields(options, table: dict) -> dict:
    """``options`` checked against ``table``: parameter -> typed value (a text, a bool, a tuple of texts)."""
    if not isinstance(options, dict):
        raise DesignError('the request\'s body must be a JSON object of field names and values, '
                          'e.g. {"fc": 3500, "zeta": 0.2}')
    out = {}
    for key, value in options.items():
        name = option_name(key)[2:]   # refuses the server's own settings and what a page may not choose
        f = table.get(name)
        if f is None:
            raise DesignError(f"{name!r} is not a field of this page; allowed: {', '.join(sorted(table))}")
        if value is None:
            continue
        if f.kind == "file":   # the file's content, as design-pid reads it from a file
            out[f.param] = value
        elif f.kind == "switch":
            word = value if isinstance(value, bool) else value.strip().lower() if isinstance(value, str) else None
            if word not in (True, False, "true", "false", "on", "off", ""):
                raise DesignError(f"{f.param} is a switch: true or false, got {str(value)[:40]}", param=f.param)
            out[f.param] = word in (True, "true", "on")
        elif f.kind == "list":   # a list, or one text of items apart (a form's field: "R=1% C=5%")
            values = value if isinstance(value, list) else [value]
            out[f.param] = tuple(w for v in values for w in value_text(v, f.param).split())
        else:
            if isinstance(value, list):
                raise DesignError(f"{f.param} takes one value, got {len(value)}", param=f.param)
            out[f.param] = value_text(value, f.param)
    return out


def plant_request(options) -> PlantRequest:
    """A plant page's request (its JSON object) as the library's specs, checked.

    Parameters
    ----------
    options : dict
        Field -> value (:data:`PLANT`'s keys; numbers, or texts in engineering notation).

    Returns
    -------
    PlantRequest
        The :class:`~designer.plant.spec.PlantSpec`, the Monte Carlo's spec and the run's settings.

    Raises
    ------
    DesignError
        One line naming the library parameter at fault (shown by :func:`page_message`).
    """
    from ..plant.spec import PlantSpec
    from ..filters import registry
    from ..plant.circuit import DEFAULT_TOPOLOGY
    v = _fields(options, PLANT)
    topology = v.get("topology", DEFAULT_TOPOLOGY)
    # a first-order section takes no zeta (an unknown name is the spec's to refuse, listing the registered)
    first_order = topology in registry.names() and registry.get(topology).order == 1
    for need in ("fc_hz",) if first_order else ("fc_hz", "zeta"):
        if need not in v:
            raise DesignError(f"{need} is required", param=need)
    spec_keys = ("fc_hz", "zeta", "gain", "r", "c", "opamp", "compensate_gbw", "amplitude_v", "square_hz",
                 "alternatives", "package", "r_series", "c_series", "r_min", "r_max", "c_min", "c_max", "topology")
    spec = PlantSpec(**{"zeta": None, **{k: v[k] for k in spec_keys if k in v}})
    _check_package(v)
    mc = _monte_carlo(v, ("n", "seed", "sampler", "dist", "tol", "limits", "target_ci", "engine", "spice_samples"))
    simulator = _simulator(v, "pyspice")
    stimulus = _stimulus(v)
    where = "" if spec.topology == DEFAULT_TOPOLOGY else f"_{spec.topology}"
    name = _name(v, f"plant{where}_fc{spec.fc_hz:g}" + ("" if spec.zeta is None else f"_z{spec.zeta:g}")
                 + ("" if spec.gain == 1 else f"_k{spec.gain:g}"))
    return PlantRequest(spec, mc, bool(v.get("worst_case")), v.get("tol", ()), not v.get("no_sim", False),
                        simulator, stimulus, name, _argv("design-plant", options))


def analyze_plant_request(options) -> AnalyzePlantRequest:
    """An analyze-plant page's request (its JSON object) as the library's specs, checked as analyze-plant checks
    its options: the Sallen-Key low-pass's parts by their names (``r1`` ..) or designators (``part``:
    ``R1=820``), another section's (``topology``) by designator.

    Parameters
    ----------
    options : dict
        Field -> value (:data:`ANALYZE_PLANT`'s keys; numbers, or texts in engineering notation).

    Returns
    -------
    AnalyzePlantRequest
        The :class:`~designer.plant.spec.AnalysisSpec` (or another section's analysis), the Monte Carlo's spec
        and the run's settings.

    Raises
    ------
    DesignError
        One line naming the library parameter at fault (shown by :func:`page_message`).
    """
    from ..filters import registry
    from ..pid.plant import part_items
    from ..plant.circuit import DEFAULT_TOPOLOGY
    from ..plant.circuit_design import built_name, check_circuit_parts
    v = _fields(options, ANALYZE_PLANT)
    try:
        topo = registry.get(v.get("topology", DEFAULT_TOPOLOGY))
    except DesignError as exc:
        raise DesignError(str(exc), param=getattr(exc, "param", None) or "topology") from None
    parts = part_items(v.get("part", ()), "part")
    bench = {k: v[k] for k in ("opamp", "target_fc_hz", "target_zeta", "r_series", "c_series", "amplitude_v",
                               "square_hz", "package") if k in v}
    _check_package(v)
    mc = _monte_carlo(v, ("n", "seed", "sampler", "dist", "tol", "limits", "target_ci", "engine", "spice_samples"))
    simulator = _simulator(v, "pyspice")
    stimulus = _stimulus(v)
    replay = _replay(v, mc)
    if stimulus is not None and replay is not None:
        raise ParamError("the prbs {stimulus} does not go with {replay} (a replayed build plays the square wave)",
                         ("stimulus", "replay"))
    spec = circuit = None
    if topo.name != DEFAULT_TOPOLOGY:
        named = [k for k in (*FIELD_OF.values(), "gain") if k in v]
        if named:
            raise ParamError("{%s} is the %s's; give %s's parts as {part} (%s)" % (
                named[0], DEFAULT_TOPOLOGY, topo.name, ", ".join(topo.designators)), (named[0], "part"))
        values = check_circuit_parts(topo, parts)
        circuit = {"topology": topo.name, "values": values, **bench}
    else:
        for ref, value in parts.items():
            field = FIELD_OF.get(ref)
            if field is None:
                raise DesignError(f"part {ref}: {DEFAULT_TOPOLOGY} has no part {ref}; its parts are "
                                  f"{', '.join(FIELD_OF)}", param="part")
            if field in v:
                raise ParamError("{part} %s and {%s} name the same part; give it once" % (ref, field),
                                 ("part", field))
            v[field] = value
        missing = [FIELD_OF[r] for r in sallen_key_refs(with_gain=False) if FIELD_OF[r] not in v]
        if missing:
            raise ParamError("{%s} is required (or its {part})" % missing[0], (missing[0], "part"))
        pair = tuple(FIELD_OF[r] for r in gain_refs())   # to ground, feedback
        if pair[0] in v and "gain" in v:
            raise ParamError("give either {gain} or {%s}/{%s}, not both" % pair, ("gain", *pair))
        from ..plant.spec import AnalysisSpec
        spec = AnalysisSpec(parts_of({r: v[FIELD_OF[r]] for r in sallen_key_refs() if FIELD_OF[r] in v},
                                     gain=v.get("gain")), **bench)
        values = {r: getattr(spec.parts, FIELD_OF[r]) for r in sallen_key_refs(with_gain=False)}
    name = _name(v, built_name(topo.name, values))
    return AnalyzePlantRequest(spec, circuit, mc, bool(v.get("worst_case")), v.get("tol", ()),
                               not v.get("no_sim", False), simulator, stimulus, name,
                               _argv("analyze-plant", options), replay)


def _check_package(v: dict) -> None:
    """The op-amp package asked for: single, dual or quad."""
    if v.get("package") not in (None, "single", "dual", "quad"):
        raise DesignError(f"package {v['package']!r} unknown; allowed: single, dual, quad", param="package")


def check_request(options) -> CheckRequest:
    """A Check page's options (the ``options`` of its JSON, or a form's other fields) as the library takes them.

    Parameters
    ----------
    options : dict
        Field -> value (:data:`CHECK`'s keys).

    Returns
    -------
    CheckRequest
        The simulator, whether to record the golden files, and the command line the request stands for.

    Raises
    ------
    DesignError
        One line naming the library parameter at fault (shown by :func:`check_message`).
    """
    v = _fields(options, CHECK)
    return CheckRequest(_simulator(v, "pyspice"), bool(v.get("update_golden")), _argv("check-design", options))


def page_text(text, table: dict) -> str:
    """A library text in the page's words and language: a typed message (:class:`designer.core.i18n.Message`)
    with each value it carries under a library parameter of ``table`` (check-design's ``{update_golden}``,
    written ``--update-golden`` for the command line) read as that field's label, quoted; its other values, and
    its text, translated (:func:`designer.core.i18n.translated`).

    Parameters
    ----------
    text : str
        A :class:`~designer.core.i18n.Message` or plain text.
    table : dict
        The page's fields (:data:`CHECK`).

    Returns
    -------
    str
        The text to show.
    """
    if not isinstance(text, Message):
        return translated(text)
    labels = {f.param: f'"{_(f.label)}"' for f in table.values()}
    return _(text.message).format(**{k: labels[k] if k in labels else page_text(v, table)
                                     for k, v in text.values.items()})


def check_message(exc: DesignError) -> tuple:
    """A check-design refusal in the Check page's words: :func:`page_message` over :data:`CHECK`, the command
    line's advice (:data:`CHECK_WORDS`) as the page gives it.

    Parameters
    ----------
    exc : DesignError
        The library's error.

    Returns
    -------
    tuple
        (the message, the field it names or None).
    """
    if exc.args and isinstance(exc.args[0], Message):   # a typed message: its parameters by their labels
        return page_text(exc.args[0], CHECK), None
    if not isinstance(exc, ParamError) and getattr(exc, "param", None) is None:
        text = str(exc)
        for cli, page in CHECK_WORDS:
            text = text.replace(cli, page if page.startswith("--") else _(page))
        exc = DesignError(text)
    return page_message(exc, CHECK)


def filter_request(options) -> FilterRequest:
    """A filter page's request (its JSON object) as the library's specs, checked.

    Parameters
    ----------
    options : dict
        Field -> value (:data:`FILTER`'s keys; numbers, or texts in engineering notation).

    Returns
    -------
    FilterRequest
        The :class:`~designer.filters.spec.FilterSpec`, the Monte Carlo's spec and the run's settings.

    Raises
    ------
    DesignError
        One line naming the library parameter at fault (shown by :func:`page_message`).
    """
    from ..filters.alternatives import alternatives_count
    from ..filters.spec import FilterSpec
    v = _fields(options, FILTER)
    spec_keys = ("filter_type", "family", "order", "fc_hz", "ripple_db", "bessel_norm", "chebyshev_cutoff",
                 "passband_hz", "max_loss_db", "stopband_hz", "min_attenuation_db", "f_low_hz", "f_high_hz",
                 "bandpass_method", "topology", "stage_order", "gain", "stage_gains", "opamp", "amplitude_v",
                 "gbw_margin", "impedance_ohm", "compensate_gbw", "r_series", "c_series", "r_min", "r_max", "c_min",
                 "c_max")
    spec = FilterSpec(**{k: v[k] for k in spec_keys if k in v})
    mc = _monte_carlo(v, ("n", "seed", "sampler", "dist", "tol", "limits"))
    simulator = _simulator(v, "ngspice-cli")
    where = f"_o{spec.order}" if spec.order is not None else ""
    where += f"_fc{spec.fc_hz:g}" if spec.fc_hz is not None else "_mask" if spec.has_mask else ""
    name = _name(v, f"filter_{spec.filter_type}_{spec.family}{where}")
    alternatives = alternatives_count(v["alternatives"]) if "alternatives" in v else None
    return FilterRequest(spec, mc, bool(v.get("worst_case")), v.get("tol", ()), not v.get("no_sim", False),
                         simulator, name, _argv("design-filter", options), alternatives)


def pid_request(options, tmp: str | None) -> PidRequest:
    """A PID page's request (its JSON object) as the library's specs, checked as design-pid checks its options.

    Parameters
    ----------
    options : dict
        Field -> value (:data:`PID`'s keys; numbers, or texts in engineering notation; a file field's
        content as a JSON object or a text).
    tmp : str or None
        The request's private folder: a file field's content is written there (:data:`PID_FILES`).

    Returns
    -------
    PidRequest
        The :class:`~designer.pid.spec.PidSpec` (made by :func:`designer.pid.spec.pid_spec`, the mapping the
        command line uses too), the Monte Carlo's spec and the run's settings.

    Raises
    ------
    DesignError
        One line naming the library parameter at fault (shown by :func:`page_message`).
    """
    return _loop_request(options, tmp, PID, "design-pid")


def analyze_pid_request(options, tmp: str | None) -> PidRequest:
    """An analyze-pid page's request (its JSON object) as the library's specs, checked as analyze-pid checks
    its options: the controller's parts as built (:func:`designer.pid.spec.controller_as_built`, every part
    or a result.json's) on the plant, as :func:`pid_request` takes it.

    Parameters
    ----------
    options : dict
        Field -> value (:data:`ANALYZE_PID`'s keys; numbers, or texts in engineering notation; a file field's
        content as a JSON object or a text).
    tmp : str or None
        The request's private folder: a file field's content is written there (:data:`PID_FILES`).

    Returns
    -------
    PidRequest
        The :class:`~designer.pid.spec.PidSpec` with its ``controller_parts``, the Monte Carlo's spec and the
        run's settings.

    Raises
    ------
    DesignError
        One line naming the library parameter at fault (shown by :func:`page_message`).
    """
    return _loop_request(options, tmp, ANALYZE_PID, "analyze-pid")


def _loop_request(options, tmp: str | None, table: dict, prog: str) -> PidRequest:
    """A PID page's request (design-pid's, or analyze-pid's: ``table`` :data:`ANALYZE_PID`) as the library's
    specs, checked in the order the command checks its options."""
    from ..cli.pid import plant_capture_model
    from ..pid.spec import CONTROLLER_FIELDS, PLAIN_PARAMS, controller_as_built, pid_spec
    params = {f.param for f in table.values()}
    v = {**{k: d for k, d in PID_DEFAULTS.items() if k in params}, **_fields(options, table)}
    _write_files(v, PID_FILES, tmp)
    built = {}
    if table is ANALYZE_PID:   # the controller as built, checked first as analyze-pid does
        built["controller_parts"] = controller_as_built({k: v.pop(k, None)
                                                         for k in (*CONTROLLER_FIELDS, "controller_json")})
    # a plant capture: identified first (as design-pid --plant-capture), its model the plant
    capture = _identify_params({"capture": v.pop("plant_capture", None),
                                **{IDENTIFY[k].param: v.pop(IDENTIFY[k].param, None) for k in CAPTURE_FIELDS}})
    process = plant_capture_model(capture, v.pop("plant_method", None) if capture["capture"] is not None else None)
    spec_keys = ("plant_fc_hz", "plant_zeta", "plant_topology", "plant_values", "plant_json", "plant_tf",
                 "plant_model", "plant_method", "plant_input", "plant_output", "tuning", "kp", "ti_s", "td_s",
                 "target_overshoot_pct", "target_settling_s", "simc_tauc_s", "imc_lambda_s", "min_phase_margin_deg",
                 "min_gain_margin_db", "max_ms", "robust", "r_series", "c_series", "r_min", "r_max", "c_min",
                 "c_max", "f_integrator_hz", "f_differentiator_hz", "opamp", "step_v", "edge_s", "square_hz",
                 "package") + PLAIN_PARAMS
    _check_package(v)
    spec = pid_spec({**{k: v[k] for k in spec_keys if k in v}, **built, "plant_process": process})
    mc = _monte_carlo(v, ("n", "seed", "sampler", "dist", "tol", "limits", "target_ci", "engine", "spice_samples"))
    _check_loop_tolerance(spec, mc, v.get("tol", ()))
    simulator = _simulator(v, "pyspice")
    name = _name(v, "pid") if "name" in v else None
    return PidRequest(spec, mc, bool(v.get("worst_case")), v.get("tol", ()), not v.get("no_sim", False), simulator,
                      bool(v.get("rules_spice")), name, _argv(prog, options, table, PID_FILES), _replay(v, mc))


def _replay(v: dict, mc) -> int | None:
    """The build of the Monte Carlo ``mc`` to replay (design-pid's ``--replay I``, checked as it checks it), or
    None."""
    if "replay" not in v:
        return None
    if mc is None:
        raise ParamError("{replay} goes with {n} (and the run's {seed}, {sampler}, {dist}, {tol})",
                         ("replay", "n", "seed", "sampler", "dist", "tol"))
    if v.get("no_sim"):
        raise ParamError("{replay} simulates the build in SPICE: leave out {no_sim}", ("replay", "no_sim"))
    if v.get("rules_spice"):
        raise ParamError("{rules_spice} does not go with {replay} (a replayed build is analysed as built)",
                         ("rules_spice", "replay"))
    try:
        i = int(v["replay"].strip())
    except ValueError:
        i = None
    if i is None or not 0 <= i <= mc.n - 1:
        raise DesignError(f"replay {v['replay']!r}: give a whole number from 0 to {mc.n - 1}", param="replay")
    return i


def identify_request(options, capture: str, tmp: str | None):
    """An identify page's request (its fields; the capture already written) as the library's request.

    Parameters
    ----------
    options : dict
        Field -> value (:data:`IDENTIFY`'s keys; numbers or texts; a list for ``window`` and ``methods``, or
        one text of items apart; a file field's content as a text or a JSON object).
    capture : str
        The uploaded capture's path (in the request's folder).
    tmp : str or None
        The request's private folder: a file field's content is written there (:data:`IDENTIFY_FILES`).

    Returns
    -------
    IdentifySpec
        Made by :func:`designer.identify.spec.identify_spec`, the mapping the command line uses too.

    Raises
    ------
    DesignError
        One line naming the library parameter at fault (shown by :func:`page_message`).
    """
    from ..identify.spec import identify_spec
    v = _fields(options, IDENTIFY)
    _write_files(v, IDENTIFY_FILES, tmp)
    return identify_spec(_identify_params({"capture": capture, **v}))


def _identify_params(v: dict) -> dict:
    """The identify fields' values as :func:`designer.identify.spec.identify_spec`'s parameters: the format
    menu's first entry ("") is recognised, and the field of ``refine`` is "skip least squares"."""
    if v.get("fmt") == "":
        v.pop("fmt")
    return {**v, "refine": not v.get("refine")}


def _write_files(v: dict, files: dict, tmp: str | None) -> None:
    """Each file field's content of ``v`` written in the request's folder under its fixed name (``files``),
    its path in its place."""
    from .request import write_content
    for param, filename in files.items():
        if param in v:
            try:
                v[param] = write_content(tmp, filename, v[param], param)
            except DesignError as exc:
                raise DesignError(str(exc), param=param) from None


def _check_loop_tolerance(spec, mc, tol) -> None:
    """The loop's tolerances and limits checked before any work, as design-pid checks them: the parts a
    tolerance may name (a model plant's parameters stay as given: the controller's alone), the op-amp's
    spread, each limit a figure of the engine."""
    from ..cli.pid_tolerance import CONTROLLER_PARTS, LOOP_PARTS
    from ..core import opamps
    from ..tolerance.parts import check_items, opamp_nominal
    items = mc.tol if mc is not None else tuple(tol)
    if items:
        check_items(items, LOOP_PARTS if spec.process is None else CONTROLLER_PARTS)
        opamp_nominal(items, opamps.get(spec.opamp))
    if mc is not None:
        from ..tolerance.loop import parse_loop_limit
        from ..tolerance.spice_loop_mc import parse_limit
        for item in mc.limits:
            (parse_loop_limit if mc.engine == "analytic" else parse_limit)(item)


def _monte_carlo(v: dict, keys: tuple):
    """The Monte Carlo asked for (a :class:`~designer.tolerance.mcspec.MonteCarloSpec` of ``keys``), or None;
    one of its settings without its builds (``n``) refused (the worst case's tolerances apart)."""
    from ..tolerance.mcspec import MonteCarloSpec
    if "n" in v:
        return MonteCarloSpec(**{k: v[k] for k in keys if k in v})
    alone = [k for k in keys if k in v and not (k == "tol" and v.get("worst_case"))
             and not (k == "engine" and v[k] == "analytic")]
    if alone:
        raise ParamError("{%s} goes with {n}" % alone[0], keys)
    return None


def _simulator(v: dict, default: str) -> str:
    """The simulator asked for (:data:`SIMULATORS`)."""
    simulator = v.get("simulator", default)
    if simulator not in SIMULATORS:
        raise DesignError(f"simulator {simulator!r} unknown; allowed: {', '.join(SIMULATORS)}", param="simulator")
    return simulator


def _name(v: dict, default: str) -> str:
    """The design's name (its files), the one given or ``default``, checked as ``--name`` is."""
    from ..cli.common import check_name
    name = v.get("name") or default
    try:
        check_name(name)
    except DesignError as exc:
        raise DesignError(str(exc).replace("--name", "name", 1), param="name") from None
    return name


def _argv(prog: str, options: dict, table: dict | None = None, files: dict | None = None) -> list:
    """The command line a request stands for (a record: nothing parses it); a file field of ``table`` (its
    parameter a key of ``files``) as the name its content was written under, never the content."""
    def shown(key, value):
        field = (table or {}).get(option_name(key)[2:])
        return files[field.param] if field is not None and field.param in (files or {}) else value
    return [prog] + [a for key, value in options.items() if value is not None
                     for a in _flag_words(key, shown(key, value))]


def _stimulus(v: dict):
    """The PRBS bench test asked for: None, or (bits or None, clock Hz or None)."""
    kind = v.get("stimulus", "step")
    if kind not in ("step", "prbs"):
        raise DesignError(f"stimulus {kind!r} unknown; allowed: step, prbs", param="stimulus")
    given = [k for k in ("bits", "clock_hz") if k in v]
    if kind != "prbs":
        if given:
            raise ParamError("{%s} goes with the prbs {stimulus}" % given[0], ("bits", "clock_hz", "stimulus"))
        return None
    from ..core.prbs import check_bits
    from ..core.ranges import parse_in_range
    bits = None
    if "bits" in v:
        try:
            bits = check_bits(v["bits"])
        except DesignError as exc:
            raise DesignError(str(exc).replace("--bits", "bits", 1), param="bits") from None
    clock = None if "clock_hz" not in v else parse_in_range(v["clock_hz"], "clock_hz", "prbs_clock_hz")
    return bits, clock


def _flag_words(key, value) -> list:
    """A field as the command line writes it (for the record only: nothing parses it)."""
    flag = "--" + str(key).replace("_", "-")
    if isinstance(value, bool):
        return [flag] if value else []
    values = value if isinstance(value, list) else [value]
    return [f"{flag}={x}" for x in values]

