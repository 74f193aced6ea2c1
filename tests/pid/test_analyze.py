"""analyze-pid: the seed's controller as built from its parts (or a result.json),
on its plant, with the same checks, loop and SPICE verification as design-pid."""

import json
import subprocess

import pytest
from helpers import ROOT, script

from designer.core.errors import DesignError
from designer.pid.blocks import PidParts, seed_parts
from designer.pid.design import analyze_pid, design_pid
from designer.pid.spec import PidSpec

ZN = ROOT / "reports" / "pid_zn_lm741_fc3500_z0.2" / "result.json"
PLANT = ["--plant-fc", "3500", "--plant-zeta", "0.2"]


def run(*args):
    return subprocess.run([script("analyze-pid"), *args], capture_output=True, text=True, timeout=600)


def test_the_parts_own_gains_are_the_tuning_without_accuracy_or_bound_checks():
    parts = seed_parts()
    res = analyze_pid(PidSpec(plant_fc_hz=3500, plant_zeta=0.2, controller_parts=parts), simulate=False)
    assert res.tuning.method == "as-built"
    assert (res.tuning.kp, res.tuning.ti_s, res.tuning.td_s) == (parts.kp, parts.ti_s, parts.td_s)
    ids = {c.id for c in res.checks}
    assert not any(i.endswith("_accuracy") or i.endswith("_bounds") for i in ids)
    assert {"closed_loop_stable", "phase_margin", "slew_rate", "output_swing"} <= ids


def test_with_gains_the_parts_are_held_to_them_as_design_pid_does():
    kw = dict(plant_fc_hz=3500, plant_zeta=0.2, kp=45, ti_s=43.215e-6, td_s=10.8037e-6, controller_parts=seed_parts())
    a = analyze_pid(PidSpec(**kw), simulate=False).to_dict()
    d = design_pid(PidSpec(**kw), simulate=False).to_dict()
    assert a["checks"] == d["checks"] and a["components"] == d["components"]


def test_a_spec_without_parts_is_refused():
    with pytest.raises(DesignError, match="controller_parts"):
        analyze_pid(PidSpec(plant_fc_hz=3500, plant_zeta=0.2), simulate=False)


@pytest.mark.parametrize("args, words", [
    ([], "the controller's parts are needed"),
    (["--r3", "12k"], "--r4 is missing"),
    (["--r3", "12k", "--parts-json", str(ZN)], "not both"),
])
def test_refusals_are_one_line(args, words):
    out = run(*PLANT, *args, "--no-sim", "--no-files")
    assert out.returncode == 2 and out.stderr.count("\n") == 1 and words in out.stderr, out.stderr


def test_a_part_out_of_range_names_its_option():
    parts = {f"--{k}": str(v) for k, v in vars(seed_parts()).items()} | {"--r9": "0"}
    out = run(*PLANT, *[x for kv in parts.items() for x in kv], "--no-sim", "--no-files")
    assert out.returncode == 2 and out.stderr.startswith("analyze-pid: error: --r9 must be")


def test_a_pi_leaves_out_the_derivative_path_all_or_nothing():
    pi = {k: v for k, v in vars(seed_parts()).items() if k not in ("r7", "r11", "r12", "c3")}
    ok = run(*PLANT, *[x for k, v in pi.items() for x in (f"--{k}", str(v))], "--no-sim", "--json", "--no-files")
    assert ok.returncode == 0, ok.stderr
    assert json.loads(ok.stdout)["achieved"]["td_s"] == 0
    half = run(*PLANT, *[x for k, v in (pi | {"c3": 4.7e-9}).items() for x in (f"--{k}", str(v))], "--no-sim",
               "--no-files")
    assert half.returncode == 2 and "--r7 is missing" in half.stderr


def test_a_json_that_is_not_a_controllers_is_refused_naming_the_file():
    plant = ROOT / "reports" / "plant_fc3500_z0.2" / "result.json"
    out = run(*PLANT, "--parts-json", str(plant), "--no-sim", "--no-files")
    assert out.returncode == 2 and "--parts-json" in out.stderr and "components" in out.stderr


@pytest.mark.spice
def test_the_zn_reference_rebuilt_from_its_parts_gives_its_spice_figures():
    ref = json.loads(ZN.read_text())
    out = run(*PLANT, "--parts-json", str(ZN), "--json", "--no-files", "--simulator", "ngspice-cli")
    assert out.returncode == 0, out.stderr
    got = json.loads(out.stdout)
    assert got["components"] == ref["components"] and got["tuning"]["method"] == "as-built"
    a, b = got["closed_loop"]["spice"], ref["closed_loop"]["spice"]
    assert a["overshoot_pct"] == pytest.approx(b["overshoot_pct"], abs=0.5)
    assert got["tool"]["simulator"] == "ngspice-cli" and got["schema_version"] >= 2


def test_parts_as_typed_are_checked_by_the_spec():
    with pytest.raises(DesignError, match="r5 must be"):
        PidSpec(plant_fc_hz=3500, plant_zeta=0.2, controller_parts=PidParts(
            **(vars(seed_parts()) | {"r5": "-1k"})))
