"""The web page's name table (designer.web.forms): a plant request's fields as the library's specs, and a
library refusal in the page's words (the field's label, never a --flag, a value as it was typed)."""

import dataclasses
from pathlib import Path

import pytest

from designer.core.errors import DesignError, ParamError
from designer.plant.spec import PlantSpec
from designer.tolerance.mcspec import MonteCarloSpec
from designer.web.forms import ANALYZE_PLANT, PLANT, analyze_plant_request, field_of, page_message, plant_request


def test_every_field_sets_a_parameter_of_the_specs_or_of_the_run():
    specs = {f.name for f in dataclasses.fields(PlantSpec)} | {f.name for f in dataclasses.fields(MonteCarloSpec)}
    run = {"no_sim", "simulator", "name", "worst_case", "stimulus", "bits", "clock_hz"}
    assert {f.param for f in PLANT.values()} <= specs | run
    assert len({f.label for f in PLANT.values()}) == len(PLANT)   # a label names one field


def test_a_request_is_the_spec_the_command_line_builds():
    rq = plant_request({"fc": "3.5k", "zeta": 0.2, "opamp": "TL072", "monte-carlo": "200", "tol": "R=1% C=5%",
                        "limit": ["fn_hz=3.3k:3.7k"], "no-sim": True})
    assert rq.spec == PlantSpec(fc_hz="3.5k", zeta=0.2, opamp="TL072")
    assert rq.monte_carlo == MonteCarloSpec(n=200, tol=("R=1%", "C=5%"), limits=("fn_hz=3.3k:3.7k",))
    assert rq.simulate is False and rq.name == "plant_fc3500_z0.2"
    assert rq.argv[:3] == ["design-plant", "--fc=3.5k", "--zeta=0.2"]


def test_a_refusal_names_the_fields_label():
    text, field = page_message(DesignError("zeta must be 0.01 to 10, got '-1'", param="zeta"), PLANT)
    assert (text, field) == ('"zeta" must be 0.01 to 10, got \'-1\'', "zeta")
    text, field = page_message(ParamError("{r_min} (1e+07 Ohm) is above {r_max} (1e+06 Ohm)"), PLANT)
    assert text == '"R min" (1e+07 Ohm) is above "R max" (1e+06 Ohm)' and field == "r-min"
    # a flag the library wrote becomes the label; a value quoted as typed stays as it was
    text, field = page_message(DesignError("--tol '--help': give CLASS=PCT, the seed's way"), PLANT)
    assert text == "\"tolerances\" '--help': give CLASS=PCT, the seed's way" and field == "tol"
    assert field_of(PLANT, "nothing") is None


@pytest.mark.parametrize("fields, param", [
    ({"zeta": 0.2}, "fc_hz"), ({"fc": 3500, "zeta": 0.2, "limit": "fn_hz=1:2"}, "limits"),
    ({"fc": 3500, "zeta": 0.2, "prbs-bits": 7}, "bits"), ({"fc": 3500, "zeta": 0.2, "simulator": "x"}, "simulator"),
    ({"fc": 3500, "zeta": 0.2, "name": "../x"}, "name"), ({"fc": 3500, "zeta": 0.2, "no-sim": "maybe"}, "no_sim"),
])
def test_bad_fields_are_refused_naming_their_parameter(fields, param):
    with pytest.raises(DesignError) as exc:
        plant_request(fields)
    assert exc.value.param == param
    text, _ = page_message(exc.value, PLANT)
    assert "--" not in text and "\n" not in text


def test_every_filter_field_sets_a_parameter_of_the_specs_or_of_the_run():
    from designer.filters.spec import FilterSpec
    from designer.web.forms import FILTER
    specs = {f.name for f in dataclasses.fields(FilterSpec)} | {f.name for f in dataclasses.fields(MonteCarloSpec)}
    assert {f.param for f in FILTER.values()} <= specs | {"no_sim", "simulator", "name", "worst_case", "alternatives"}
    assert len({f.label for f in FILTER.values()}) == len(FILTER)


def test_a_filter_request_is_the_spec_design_filter_builds():
    from designer.filters.spec import FilterSpec
    from designer.web.forms import filter_request
    rq = filter_request({"family": "chebyshev", "passband": "3k", "max-loss": 1, "stopband": "12k",
                         "min-attenuation": 40, "topology": "mfb", "series": "E96", "monte-carlo": 500,
                         "tol": "R=1% C=5%"})
    assert rq.spec == FilterSpec(family="chebyshev", passband_hz="3k", max_loss_db="1", stopband_hz="12k",
                                 min_attenuation_db="40", topology="mfb", r_series="E96")
    assert rq.monte_carlo == MonteCarloSpec(n=500, tol=("R=1%", "C=5%"))
    assert rq.simulate and rq.simulator == "ngspice-cli" and rq.name == "filter_lowpass_chebyshev_mask"
    assert filter_request({"order": 4, "fc": "1k"}).name == "filter_lowpass_butterworth_o4_fc1000"


@pytest.mark.parametrize("fields, param", [
    ({"fc": "1k"}, "order"), ({"order": 4, "fc": "1k", "family": "chebyshev", "ripple": 5}, "ripple_db"),
    ({"order": 4, "fc": "1k", "type": "notch"}, "filter_type"), ({"order": 4, "fc": "1k", "seed": 3}, "seed"),
    ({"order": 4, "fc": "1k", "name": "a/b"}, "name"),
])
def test_bad_filter_fields_are_refused_in_the_pages_words(fields, param):
    from designer.web.forms import FILTER, filter_request
    with pytest.raises(DesignError) as exc:
        filter_request(fields)
    assert exc.value.param == param
    text, field = page_message(exc.value, FILTER)
    assert "--" not in text and "_" not in text.split("'")[0] and FILTER[field].param == param


def test_every_pid_field_is_a_design_pid_option_setting_a_parameter_of_the_specs_or_of_the_run():
    """Issue 26: the PID page's fields are design-pid's option names, each setting a parameter of
    designer.pid.spec.pid_spec (the spec's fields and its plain parameters), of the Monte Carlo, of the run, or of
    the plant capture's identification (plant_capture and designer.identify.spec.IdentifySpec's fields)."""
    from designer.cli.pid import pid_parser
    from designer.identify.spec import IdentifySpec
    from designer.pid.plant_spec import PLANT_FIELDS
    from designer.pid.spec import PLAIN_PARAMS, PidSpec
    from designer.web.forms import PID
    specs = ({f.name for f in dataclasses.fields(PidSpec)} | set(PLANT_FIELDS) | set(PLAIN_PARAMS)
             | {f.name for f in dataclasses.fields(MonteCarloSpec)}
             | {f.name for f in dataclasses.fields(IdentifySpec)} | {"plant_capture"})
    assert {f.param for f in PID.values()} <= specs | {"no_sim", "simulator", "name", "worst_case", "rules_spice", "replay"}
    assert len({f.label for f in PID.values()}) == len(PID)
    options = {o for a in pid_parser()._actions for o in a.option_strings}
    assert {f"--{k}" for k in PID} <= options


def test_a_pid_request_is_the_spec_design_pid_builds(tmp_path):
    """One mapping (designer.pid.spec.pid_spec): the page's fields and design-pid's options give equal specs,
    the Sallen-Key plant's parts and the seed's controller parts included."""
    from designer.cli.pid import _build_spec, pid_parser
    from designer.web.forms import pid_request
    argv = ["--plant-r1", "820", "--plant-r2", "1k", "--plant-c1", "10n", "--plant-c2", "220n", "--plant-gain", "1",
            "--tuning", "amigo", "--opamp", "TL072", "--seed-parts", "--step", "0.5"]
    rq = pid_request({"plant-r1": 820, "plant-r2": "1k", "plant-c1": "10n", "plant-c2": "220n", "plant-gain": 1,
                      "tuning": "amigo", "opamp": "TL072", "seed-parts": True, "step": 0.5, "monte-carlo": 100,
                      "tol": "R=1% C=5%"}, str(tmp_path))
    assert rq.spec == _build_spec(pid_parser().parse_args(argv))
    assert rq.monte_carlo == MonteCarloSpec(n=100, tol=("R=1%", "C=5%")) and rq.name is None and rq.simulate


@pytest.mark.parametrize("fields, param, words", [
    ({"plant-fc": 3500}, "plant_fc_hz", '"plant fc (Hz)" needs "plant zeta"'),
    ({"plant-fc": 3500, "plant-zeta": 0.2, "plant-r1": "1k"}, "plant_r1", '"R1", "R2", "C1" and "C2" go together'),
    ({"plant-r1": "820", "plant-r2": "1k", "plant-c1": "10n", "plant-c2": "220n", "plant-gain": "x"}, "plant_gain",
     '"gain K"'),
    ({"plant-fc": 3500, "plant-zeta": 0.2, "plant-gain": 2}, "plant_gain", '"gain K" goes with "R1".."C2"'),
    ({"plant-fc": 3500, "plant-zeta": 0.2, "tol": "Q9=1%", "worst-case": True}, "tol", '"tolerances"'),
    ({"plant-fc": 3500, "plant-zeta": 0.2, "monte-carlo": 100, "limit": "nope=1:2"}, "limits", '"limits"'),
    ({"plant-fc": 3500, "plant-zeta": 0.2, "package": "octal"}, "package", '"package"'),
])
def test_bad_pid_fields_are_refused_in_the_pages_words(tmp_path, fields, param, words):
    from designer.web.forms import PID, pid_request
    with pytest.raises(DesignError) as exc:
        pid_request(fields, str(tmp_path))
    text, field = page_message(exc.value, PID)
    assert words in text and "--" not in text and "\n" not in text, text
    assert PID[field].param == param, (field, text)


def test_a_check_request_is_what_check_design_takes():
    """Issue 26: the Check page's options through its name table (CHECK), as check_specs takes them."""
    from designer.web.forms import CHECK, check_request
    rq = check_request({"simulator": "ngspice-cli", "update-golden": "on"})
    assert (rq.simulator, rq.update_golden) == ("ngspice-cli", True)
    assert rq.argv == ["check-design", "--simulator=ngspice-cli", "--update-golden=on"]
    assert check_request({}).simulator == "pyspice" and check_request({}).update_golden is False
    import inspect
    from designer.check.batch import check_specs
    assert {f.param for f in CHECK.values()} <= set(inspect.signature(check_specs).parameters)


@pytest.mark.parametrize("options, field, words", [
    ({"update-golden": "maybe"}, "update-golden", '"record the golden files" is a switch'),
    ({"simulator": "spectre"}, "simulator", "'spectre' unknown; allowed: pyspice, ngspice-cli"),
    ({"jobs": 4}, None, "the server's own setting"),
    ({"root": "/"}, None, "set by the web page itself"),
    ({"allow-outside": True}, None, "set by the web page itself"),
    ({"spec": "x"}, None, "is not a field of this page; allowed: simulator, update-golden"),
])
def test_bad_check_options_are_refused_in_the_pages_words(options, field, words):
    from designer.web.forms import check_message, check_request
    with pytest.raises(DesignError) as caught:
        check_request(options)
    text, got = check_message(caught.value)
    assert words in text and got == field, text


def test_check_designs_advice_reads_as_the_page_offers_it(tmp_path):
    """A spec's path outside its folder, and a golden file to record: check-design's refusals name its
    --root, --allow-outside and --update-golden; the page says what it offers (no option)."""
    from designer.check.spec import load_spec
    from designer.web.forms import check_message
    spec = tmp_path / "in" / "x.yaml"
    spec.parent.mkdir()
    spec.write_text("name: x\nkind: netlist\ndeck: ../d.cir\nchecks:\n  v: {max: 1}\n")
    with pytest.raises(DesignError) as caught:
        load_spec(spec)
    assert "--root" in str(caught.value)
    text, _ = check_message(caught.value)
    assert "--" not in text and "x.yaml:3: deck" in text and "the folder chosen is the limit" in text
    (tmp_path / "in" / "d.cir").write_text("* d\nV1 1 0 1\nR1 1 0 1k\n.tran 1u 10u\n.meas tran v max v(1)\n.end\n")
    spec.write_text("name: x\nkind: netlist\ndeck: d.cir\ngolden: {file: g.csv, signals: {v(1): {reltol: 0.01}}}\n")
    with pytest.raises(DesignError) as caught:
        load_spec(spec)
    assert "check-design --update-golden" in str(caught.value)
    text, _ = check_message(caught.value)
    assert "--" not in text and 'record it with "record the golden files"' in text, text


@pytest.mark.parametrize("fields, param, words", [
    ({"replay": 3}, "replay", '"build replayed" goes with "Monte Carlo builds"'),
    ({"replay": 3, "monte-carlo": 10, "no-sim": True}, "replay", 'leave out "skip SPICE"'),
    ({"replay": 3, "monte-carlo": 10, "rules-spice": True}, "rules_spice", '"build replayed" (a replayed build'),
    ({"replay": 10, "monte-carlo": 10}, "replay", "'10': give a whole number from 0 to 9"),
    ({"replay": "x", "monte-carlo": 10}, "replay", "'x': give a whole number from 0 to 9"),
])
def test_a_replay_is_checked_as_design_pid_checks_it(tmp_path, fields, param, words):
    """Issue 26: design-pid's --replay I through the PID page's name table, refused in the page's words."""
    from designer.web.forms import PID, pid_request
    with pytest.raises(DesignError) as caught:
        pid_request({"plant-fc": 3500, "plant-zeta": 0.2, **fields}, str(tmp_path))
    text, field = page_message(caught.value, PID)
    assert caught.value.param == param and words in text and "--" not in text, text
    assert pid_request({"plant-fc": 3500, "plant-zeta": 0.2, "replay": "9", "monte-carlo": 10},
                       str(tmp_path)).replay == 9


def test_every_identify_field_is_an_identify_option_setting_a_parameter_of_the_spec():
    """Issue 26: the identify page's fields are identify's option names, each setting a parameter of
    designer.identify.spec.identify_spec; an identify request is the spec identify builds from its options."""
    from designer.cli.identify import build_parser, identify_spec_of
    from designer.identify.spec import IdentifySpec
    from designer.web.forms import IDENTIFY, identify_request
    assert {f.param for f in IDENTIFY.values()} <= {f.name for f in dataclasses.fields(IdentifySpec)}
    assert len({f.label for f in IDENTIFY.values()}) == len(IDENTIFY)
    options = {o for a in build_parser()._actions for o in a.option_strings}
    assert {f"--{k}" for k in IDENTIFY} <= options
    argv = ["c.csv", "--step-time", "1m", "--step-amplitude", "-2", "--window", "0", "5m", "--format", "rigol",
            "--input-column", "2", "--methods", "smith", "alfaro", "--no-refine", "--segment-length", "64"]
    rq = identify_request({"step-time": "1m", "step-amplitude": -2, "window": "0 5m", "format": "RIGOL",
                           "input-column": 2, "methods": ["smith", "alfaro"], "no-refine": "on",
                           "segment-length": 64}, "c.csv", None)
    assert rq == identify_spec_of(build_parser().parse_args(argv))
    assert identify_request({"format": ""}, "c.csv", None) == IdentifySpec("c.csv")


def test_a_pid_request_records_a_file_fields_name_never_its_content(tmp_path):
    """tool.argv of a PID request with a capture (or a model) names the file its content was written under, as the
    command line it stands for would; the content (a capture of up to 4 MiB) stays out of the result's JSON."""
    from designer.web.forms import PID_FILES, pid_request
    capture = (Path(__file__).resolve().parents[1] / "fixtures" / "identify" / "tektronix_mso.csv").read_text()
    rq = pid_request({"plant-capture": capture, "tuning": "amigo"}, str(tmp_path))
    assert rq.argv == ["design-pid", f"--plant-capture={PID_FILES['plant_capture']}", "--tuning=amigo"]
    assert rq.spec.process is not None and rq.spec.process.source.endswith("(plant-capture.csv)")


def test_every_analyze_plant_field_is_an_analyze_plant_option_setting_a_parameter():
    """Issue 26: the analysis page's name table: each field is analyze-plant's option of its name, and sets a
    parameter of the analysis's specs (:class:`AnalysisSpec`, :func:`analyze_circuit_plant`), of the Monte
    Carlo or of the run; a label names one field."""
    import inspect

    from designer.cli.plant import analyze_plant_parser
    from designer.plant.circuit_design import analyze_circuit_plant
    from designer.plant.spec import AnalysisSpec
    options = {a.dest.replace("_", "-") for a in analyze_plant_parser()._actions}
    assert set(ANALYZE_PLANT) <= options
    params = ({f.name for f in dataclasses.fields(AnalysisSpec)}
              | set(inspect.signature(analyze_circuit_plant).parameters)
              | {f.name for f in dataclasses.fields(MonteCarloSpec)}
              | {"r1", "r2", "c1", "c2", "r3", "r4", "gain", "part", "no_sim", "name", "worst_case", "stimulus",
                 "bits", "clock_hz", "replay"})
    assert {f.param for f in ANALYZE_PLANT.values()} <= params
    assert len({f.label for f in ANALYZE_PLANT.values()}) == len(ANALYZE_PLANT)


def test_an_analyze_plant_request_is_the_spec_analyze_plant_builds():
    from designer.filters import registry
    from designer.plant.circuit_design import check_circuit_parts
    from designer.plant.sallenkey import SallenKeyParts
    from designer.plant.spec import AnalysisSpec
    rq = analyze_plant_request({"r1": 820, "part": ["R2=1k", "C1=10n"], "c2": "220n", "fc": 3500, "zeta": "0.2",
                                "opamp": "TL072", "monte-carlo": 50, "no-sim": True})
    assert rq.spec == AnalysisSpec(SallenKeyParts(820, "1k", "10n", "220n"), opamp="TL072", target_fc_hz=3500,
                                   target_zeta="0.2")
    assert rq.circuit is None and rq.monte_carlo == MonteCarloSpec(n=50) and rq.simulate is False
    assert rq.name == analyze_plant_request({"r1": 820, "r2": "1k", "c1": "10n", "c2": "220n"}).name
    assert rq.argv[:2] == ["analyze-plant", "--r1=820"]
    parts = {"R1": "1k1", "R2": "2k2", "R3": "43k", "C1": "1n2", "C2": "220n"}
    rq = analyze_plant_request({"topology": "mfb-lowpass", "part": [f"{r}={v}" for r, v in parts.items()]})
    assert rq.spec is None and rq.circuit == {"topology": "mfb-lowpass",
                                              "values": check_circuit_parts(registry.get("mfb-lowpass"), parts)}
    assert rq.name.startswith("built_mfb-lowpass_r1")


@pytest.mark.parametrize("fields, param, words", [
    ({"r1": 820, "r2": "1k", "c1": "10n"}, "c2", '"C2" is required'),
    ({"r1": 820, "r2": "1k", "c1": "10n", "c2": "-1"}, "c2", '"C2" must be'),
    ({"part": "R1=1k R9=2", "r2": "1k", "c1": "10n", "c2": "1n"}, "part", "its parts are R1, R2, C1, C2, R3, R4"),
    ({"part": "R1=1k", "r1": 3, "r2": 1, "c1": "1n", "c2": "1n"}, "part", '"R1" name the same part'),
    ({"r1": 820, "r2": "1k", "c1": "10n", "c2": "220n", "gain": 2, "r3": "1k"}, "gain", '"gain K" or "R3"/"R4"'),
    ({"topology": "mfb-lowpass", "r1": 5}, "r1", "give mfb-lowpass's parts as \"parts\""),
    ({"topology": "mfb-lowpass", "part": "R1=1k"}, "part", "needs R2, R3, C1, C2 too"),
    ({"topology": "nope"}, "topology", "registered: sallen-key-lowpass"),
    ({"r1": 820, "r2": "1k", "c1": "10n", "c2": "220n", "replay": 3}, "replay", '"build replayed" goes with'),
])
def test_bad_analyze_plant_fields_are_refused_in_the_pages_words(fields, param, words):
    with pytest.raises(DesignError) as exc:
        analyze_plant_request(fields)
    text, field = page_message(exc.value, ANALYZE_PLANT)
    assert ANALYZE_PLANT[field].param == param and words in text and "--" not in text, text


def test_every_analyze_pid_field_is_an_analyze_pid_option_setting_a_parameter():
    """Issue 26: the analyze-pid name table: design-pid's fields but the tuning and sizing, and the controller
    as built (:func:`designer.pid.spec.controller_as_built`'s parameters); each an analyze-pid option."""
    from designer.cli.pid import analyze_pid_parser
    from designer.pid.spec import CONTROLLER_FIELDS
    from designer.web.forms import ANALYZE_PID, DESIGN_ONLY, PID
    options = {a.dest.replace("_", "-") for a in analyze_pid_parser()._actions}
    assert set(ANALYZE_PID) <= options and not set(DESIGN_ONLY) & options
    own = {f.param for k, f in ANALYZE_PID.items() if k not in PID}
    assert own == {*CONTROLLER_FIELDS, "controller_json"}
    assert len({f.label for f in ANALYZE_PID.values()}) == len(ANALYZE_PID)


def test_an_analyze_pid_request_is_the_spec_analyze_pid_builds(tmp_path):
    from designer.pid.blocks import seed_parts
    from designer.pid.spec import pid_spec
    from designer.web.forms import analyze_pid_request
    parts = seed_parts()
    fields = {k: getattr(parts, k) for k in dataclasses.asdict(parts) if getattr(parts, k) is not None}
    rq = analyze_pid_request({"plant-fc": 3500, "plant-zeta": 0.2, **fields}, str(tmp_path))
    assert rq.spec == pid_spec({"plant_fc_hz": 3500, "plant_zeta": 0.2, "controller_parts": parts, "step_v": "1",
                                "edge_s": "100n"})
    assert rq.argv[:3] == ["analyze-pid", "--plant-fc=3500", "--plant-zeta=0.2"]
    # the parts of a result.json, its content written in the request's folder
    components = {(f"{k.upper()}_ohm" if k[0] == "r" else f"{k.upper()}_f"): v for k, v in fields.items()}
    rq = analyze_pid_request({"plant-fc": 3500, "plant-zeta": 0.2, "parts-json": {"components": components}},
                             str(tmp_path))
    assert rq.spec.controller_parts == parts and "--parts-json=parts-result.json" in rq.argv


@pytest.mark.parametrize("fields, param, words", [
    ({"plant-fc": 3500, "plant-zeta": 0.2}, "r3", "the controller's parts are needed"),
    ({"plant-fc": 3500, "plant-zeta": 0.2, "r3": "1k", "parts-json": {"components": {}}}, "r3",
     "either part by part"),
    ({"plant-fc": 3500, "plant-zeta": 0.2, "tuning": "zn"}, None, "'tuning' is not a field of this page"),
])
def test_bad_analyze_pid_fields_are_refused_in_the_pages_words(tmp_path, fields, param, words):
    from designer.web.forms import ANALYZE_PID, analyze_pid_request
    with pytest.raises(DesignError) as exc:
        analyze_pid_request(fields, str(tmp_path))
    text, field = page_message(exc.value, ANALYZE_PID)
    assert (ANALYZE_PID[field].param if field else None) == param and words in text and "--" not in text, text


@pytest.mark.parametrize("lang", ["en", "es"])
def test_page_text_names_a_parameter_a_message_carries_by_its_fields_label(lang):
    """Issue 29: a typed message carrying check_specs' update_golden (its text the command line's words) reads
    on the page with the field's label, in the page's language; its other values as they are."""
    from designer.check.golden import RECORD_GOLDEN, record_advice
    from designer.core.i18n import catalogue, language
    from designer.web.forms import CHECK, page_text
    advice = record_advice("golden file g.csv does not exist")
    assert str(advice) == f"golden file g.csv does not exist; record it with {RECORD_GOLDEN}"
    with language(lang):
        shown = page_text(advice, CHECK)
    words = (lambda m: m) if lang == "en" else (lambda m: catalogue("es")[m])
    assert shown == words("{problem}; record it with {update_golden}").format(
        problem="golden file g.csv does not exist", update_golden=f'"{words(CHECK["update-golden"].label)}"')
    assert "--" not in shown and page_text("plain text", CHECK) == "plain text"


def test_r_and_c_on_a_section_reach_its_synthesize_rc():
    """The plant API's r and c (the seed's procedure) are taken with any topology, as design-plant --r/--c."""
    from designer.filters import REGISTRY
    from designer.plant.circuit import plant_target
    from designer.plant.circuit_design import design_circuit_plant
    rq = plant_request({"fc": 1000, "zeta": 0.5, "topology": "sallen-key-highpass", "r": "10k", "c": "10n"})
    assert (rq.spec.topology, rq.spec.r, rq.spec.c) == ("sallen-key-highpass", 10e3, 10e-9)
    topo = REGISTRY["sallen-key-highpass"]
    assert design_circuit_plant(rq.spec, simulate=False).ideal == topo.synthesize_rc(
        plant_target(topo, 1000.0, 0.5), 10e3, 10e-9)
