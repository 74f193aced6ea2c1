"""--plant-model FILE: a process model from identify's and identify-freq's real
--json output on synthetic data, and from a design-plant result.json; every
other file refused in one line."""

import copy
import json
import math
import subprocess

import numpy as np
import pytest
from helpers import REPORTS, script

from designer.core.errors import DesignError
from designer.core.process_build import fopdt, sopdt, underdamped
from designer.pid.plant_source import model_from_json, result_kind, sallen_key_model
from designer.plant.sallenkey import SallenKeyParts

#: what was simulated: (library model, the kind and parameters the file must give back)
TRUTH = {
    "fopdt": fopdt(2.0, 1e-3, 2e-4),
    "sopdt": sopdt(0.9, 2e-3, 5e-4, 3e-4),
    "underdamped": underdamped(1.2, 500.0, 0.35, 1e-4),
}


def _identify(folder, name, model, seed):
    """A capture of ``model``'s step (0.5 % noise, t,u,y) and identify's --json of it."""
    rng = np.random.default_rng(seed)
    t = np.linspace(-2e-3, 8 * model.settling_time_s, 8001)
    y = model.step(t) + 0.005 * abs(model.gain) * rng.standard_normal(t.size)
    capture = folder / f"{name}.csv"
    np.savetxt(capture, np.c_[t, (t >= 0).astype(float), y], delimiter=",", header="t,u,y", comments="")
    out = subprocess.run([script("identify"), str(capture), "--json"], capture_output=True, text=True,
                         check=True, cwd=folder).stdout
    path = folder / f"{name}.json"
    path.write_text(out)
    return path


@pytest.fixture(scope="module")
def identified(tmp_path_factory):
    folder = tmp_path_factory.mktemp("identified")
    return {name: _identify(folder, name, m, seed) for seed, (name, m) in enumerate(TRUTH.items(), 1)}


def _write(tmp_path, data, name="result.json"):
    path = tmp_path / name
    path.write_text(json.dumps(data))
    return path


def _one_line_refusal(path, *words, method=None):
    with pytest.raises(DesignError) as e:
        model_from_json(path, method)
    msg = str(e.value)
    assert "\n" not in msg and "Traceback" not in msg
    for w in words:
        assert w in msg, (w, msg)
    return msg


@pytest.mark.parametrize("name", list(TRUTH))
def test_identify_best_model_is_the_truth(identified, name):
    truth = TRUTH[name]
    m = model_from_json(identified[name])
    assert m.kind == truth.kind
    assert m.source == f"identify least-squares {dict(sopdt='overdamped').get(name, name)} ({name}.csv)"
    scale = truth.time_scale_s
    for k, v in truth.params.items():
        if k == "theta_s":
            assert abs(m.params[k] - v) <= 0.03 * scale, k
        else:
            assert m.params[k] == pytest.approx(v, rel=0.03), k
    # the fit's 95 % half-widths come along, mapped to the model's names, and give the corners
    assert set(m.ci95) == set(truth.params)
    assert all(0 < h < abs(m.params[k]) or k == "theta_s" for k, h in m.ci95.items())
    assert len(m.corners()) == 2 ** len(m.ci95)


def test_the_half_widths_are_identify_s_own(identified):
    data = json.loads(identified["underdamped"].read_text())
    best = data["best"]
    m = model_from_json(identified["underdamped"])
    assert m.params["fn_hz"] == pytest.approx(best["params"]["wn_rad_s"] / (2 * math.pi), rel=1e-12)
    assert m.ci95["fn_hz"] == pytest.approx(best["points"]["wn_rad_s_ci95"] / (2 * math.pi), rel=1e-12)
    assert m.ci95["zeta"] == best["points"]["zeta_ci95"]


def test_the_overdamped_fit_is_sorted_slow_first_with_its_half_widths(identified):
    best = json.loads(identified["sopdt"].read_text())["best"]
    assert best["params"]["tau1_s"] < best["params"]["tau2_s"]      # identify: fast first
    m = model_from_json(identified["sopdt"])
    assert m.params["tau1_s"] == best["params"]["tau2_s"]
    assert m.ci95["tau1_s"] == best["points"]["tau2_s_ci95"]


def test_a_named_method(identified):
    m = model_from_json(identified["fopdt"], "alfaro")
    assert m.kind == "fopdt" and m.source == "identify alfaro fopdt (fopdt.csv)" and m.ci95 is None
    assert m.params["tau_s"] == pytest.approx(1e-3, rel=0.03)
    for spelling in ("least-squares:fopdt", "LEAST-SQUARES fopdt", " least-squares "):
        assert model_from_json(identified["fopdt"], spelling) == model_from_json(identified["fopdt"])


def test_an_unknown_method_lists_the_methods(identified):
    msg = _one_line_refusal(identified["fopdt"], "no method 'smiht'", "did you mean smith", "methods:",
                            "least-squares:overdamped", method="smiht")
    assert "alfaro" in msg


def test_a_method_that_is_not_valid_lists_the_valid_ones(identified):
    data = json.loads(identified["fopdt"].read_text())
    invalid = next(m for m in data["methods"] if not m["valid"] and m["name"] != "least-squares")
    msg = _one_line_refusal(identified["fopdt"], f"method {invalid['name']} is not valid", "valid methods:",
                            "least-squares:fopdt", method=invalid["name"])
    assert f" {invalid['name']}," not in msg.split("valid methods:")[1]


@pytest.mark.parametrize("change, words", [
    (lambda d: d.update(best=None), ["no valid model", "valid methods: least-squares:fopdt"]),
    (lambda d: d.pop("best"), ["no valid model"]),
    (lambda d: d["best"].update(valid=False, note="made up"), ["best model", "not valid (made up)",
                                                               "valid methods:"]),
    (lambda d: [m.update(valid=False) for m in d["methods"]] and d.update(best=None),
     ["no valid model", "valid methods: none"]),
])
def test_a_best_that_is_missing_or_invalid(identified, tmp_path, change, words):
    data = json.loads(identified["fopdt"].read_text())
    change(data)
    _one_line_refusal(_write(tmp_path, data, "models.json"), "plant model", *words)


def test_parameters_outside_the_model_ranges_are_refused_naming_the_method(identified, tmp_path):
    data = json.loads(identified["fopdt"].read_text())
    data["best"]["params"]["theta_s"] = 1.0      # 1000 tau
    _one_line_refusal(_write(tmp_path, data), "least-squares fopdt", "theta_s", "100 times")


def test_identify_freq_result(tmp_path):
    truth = TRUTH["underdamped"]
    f = np.logspace(1, 4, 60)
    g = truth.freq(2 * np.pi * f)
    table = tmp_path / "bode.csv"
    np.savetxt(table, np.c_[f, 20 * np.log10(np.abs(g)), np.degrees(np.unwrap(np.angle(g)))], delimiter=",",
               header="f_hz,gain_db,phase_deg", comments="")
    for tool in ("identify-freq", "identify"):      # identify reads a frequency table as identify-freq does
        out = subprocess.run([script(tool), str(table), "--json"], capture_output=True, text=True,
                             check=True).stdout
        path = _write(tmp_path, json.loads(out), f"{tool}.json")
        assert result_kind(json.loads(out)) == "identify-freq"
        m = model_from_json(path)
        assert m.kind == "underdamped" and m.source == "identify-freq least-squares underdamped (bode.csv)"
        for k, v in truth.params.items():
            assert m.params[k] == pytest.approx(v, rel=1e-3), k
        assert model_from_json(path, "resonant-peak").kind == "underdamped"
        _one_line_refusal(path, "no method", method="alfaro")


def test_design_plant_result_gives_its_fn_and_zeta():
    path = REPORTS / "plant_fc3500_z0.2" / "result.json"
    built = json.loads(path.read_text())["built"]
    m = model_from_json(path)
    assert m.kind == "underdamped" and m.ci95 is None
    assert m.params["fn_hz"] == pytest.approx(built["fn_hz"], rel=1e-12)
    assert m.params["zeta"] == pytest.approx(built["zeta"], rel=1e-12)
    assert m.params["K"] == built["gain"] and m.theta_s == 0.0
    assert m.source == "design-plant Sallen-Key as built (result.json)"
    # its den is plant_tf's a s^2 + b s + 1
    a = built["R1_ohm"] * built["R2_ohm"] * built["C1_f"] * built["C2_f"]
    assert m.den[0] == pytest.approx(a, rel=1e-12) and m.den[2] == 1.0
    _one_line_refusal(path, "design-plant result", "method", method="alfaro")


def test_a_design_plant_result_with_bad_parts(tmp_path):
    data = json.loads((REPORTS / "plant_fc3500_z0.2" / "result.json").read_text())
    data["built"]["R1_ohm"] = -5.0
    _one_line_refusal(_write(tmp_path, data), "built.R1_ohm")
    data["built"]["R1_ohm"] = "1k"
    _one_line_refusal(_write(tmp_path, data), "built.R1_ohm", "number")


def test_an_overdamped_sallen_key_is_an_sopdt():
    parts = SallenKeyParts(10e3, 10e3, 10e-9, 10e-9)     # zeta = 1: a double pole at 1/(R C)
    m = sallen_key_model(parts)
    assert m.kind == "sopdt"
    assert m.params["tau1_s"] == pytest.approx(1e-4, rel=1e-6) and m.params["tau2_s"] == pytest.approx(1e-4, rel=1e-6)
    assert m.den == pytest.approx((parts.a, parts.b, 1.0), rel=1e-12)


def test_a_check_design_result_is_refused(tmp_path):
    from designer.check.result import Case, CornerOutcome, SpecOutcome
    plant = json.loads((REPORTS / "plant_fc3500_z0.2" / "result.json").read_text())
    outcome = SpecOutcome("lab3", "lab3.yaml", "plant",
                          [CornerOutcome("TL072", (Case("overshoot_pct", "TL072", "pass", "fine"),), design=plant)])
    _one_line_refusal(_write(tmp_path, outcome.to_dict()), "check-design result", "identify",
                      "design-plant/analyze-plant result.json")


@pytest.mark.parametrize("content, words", [
    ("not json", ["is not JSON", "expected an identify"]),
    ("[1, 2]", ["is not an identify", "expected a JSON object"]),
    ('{"methods": "x"}', ["is not a plant model"]),
    ('{"methods": [1], "best": null}', ["methods[0] is not a method result"]),
    ("[" * 100000, ["nested too deeply"]),
])
def test_anything_else_is_refused_in_one_line(tmp_path, content, words):
    path = tmp_path / "x.json"
    path.write_text(content)
    _one_line_refusal(path, "x.json", *words)


def test_a_design_pid_result_and_a_folder_are_refused(tmp_path):
    _one_line_refusal(REPORTS / "pid_zn_lm741_fc3500_z0.2" / "result.json", "design-pid result")
    _one_line_refusal(tmp_path, "--plant-model file", "directory")


def test_a_failed_method_has_no_model(identified, tmp_path):
    data = json.loads(identified["fopdt"].read_text())
    best = copy.deepcopy(data["best"])
    best["params"]["tau_s"] = None
    data["best"] = best
    _one_line_refusal(_write(tmp_path, data), "tau_s", "not a number")


@pytest.fixture(scope="module")
def noise_identified(tmp_path_factory):
    """identify's own --json of a PRBS capture whose output is white noise alone (nothing identified)."""
    from prbs_capture import noise_identify_json
    return noise_identify_json(tmp_path_factory.mktemp("noise"))


def test_identify_json_of_noise_has_no_model_to_design_for(noise_identified):
    data = json.loads(noise_identified.read_text())
    assert data["format"] == "broadband" and data["best"] is None    # what identify wrote: nothing fitted
    assert result_kind(data) == "identify"
    msg = _one_line_refusal(noise_identified, "this identify result has no valid model (best: none): nothing to "
                            "design for")
    assert "identify-freq" not in msg and "not a plant model" not in msg


def test_the_command_named_is_the_one_that_wrote_the_file(identified, tmp_path):
    """A best of none in an identify (step) result and in identify's broadband spectral layout (which carries
    identify-freq's keys) is said of identify; in identify-freq's own, of identify-freq."""
    step = json.loads(identified["fopdt"].read_text())
    step["best"] = None
    for m in step["methods"]:
        m["valid"] = False
    _one_line_refusal(_write(tmp_path, step, "step.json"), "this identify result has no valid model")
    broadband = dict(step, format="broadband", error_definition="...", data={})
    msg = _one_line_refusal(_write(tmp_path, broadband, "bb.json"), "this identify result has no valid model")
    assert "identify-freq" not in msg
    freq = {k: v for k, v in broadband.items() if k not in ("format", "preprocessing")}
    _one_line_refusal(_write(tmp_path, freq, "freq.json"), "this identify-freq result has no valid model")


def test_a_key_twice_in_the_file_is_refused_naming_it(identified, tmp_path):
    """json keeps the last of a repeated key: a model file whose best is given twice was read as the
    second ("the best model, ?, is not valid"); it is refused, naming the key."""
    text = identified["fopdt"].read_text()
    path = tmp_path / "twice.json"
    path.write_text(text.replace('"best": {', '"best": {"valid": false},\n  "best": {', 1))
    assert json.loads(path.read_text())["best"]["valid"] is True     # what a plain reader makes of it
    msg = _one_line_refusal(path, "has the key 'best' twice in one object")
    assert "?" not in msg
