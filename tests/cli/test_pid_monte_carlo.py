"""design-pid and analyze-pid --monte-carlo, --limit and --worst-case from the outside
(issue 17, the analytic loop engine)."""

import json
import os
import subprocess

import pytest
from helpers import script

DESIGN_PID = script("design-pid")
LOOP = ["--plant-fc", "3500", "--plant-zeta", "0.2", "--opamp", "LM741", "--tuning", "optimize",
        "--target-overshoot", "10", "--no-sim", "--no-files"]


def run(*args):
    env = dict(os.environ, MPLBACKEND="Agg")
    return subprocess.run([DESIGN_PID, *args], capture_output=True, text=True, env=env, timeout=600)


def test_the_loops_yield_within_its_limits():
    p = run(*LOOP, "--monte-carlo", "30", "--seed", "4", "--limit", "phase_margin_deg=27:90",
            "--limit", "overshoot_pct=0:12", "--json")
    assert p.returncode == 0, p.stderr
    mc = json.loads(p.stdout)["monte_carlo"]
    assert [lim["figure"] for lim in mc["limits"]] == ["phase_margin_deg", "model_overshoot_pct"]
    assert mc["yield"]["samples"] == 30 and mc["yield"]["interval"] == "Wilson"
    assert set(mc["failing_samples"]) == {"phase_margin_deg", "model_overshoot_pct"}
    assert mc["statistics"]["kp"]["nominal"] > 0 and "p_unstable" in mc


def test_the_summary_states_the_yield():
    p = run(*LOOP, "--monte-carlo", "20", "--limit", "phase_margin_deg=20:90")
    assert p.returncode == 0, p.stderr
    assert "Monte Carlo of the loop: 20 builds" in p.stdout and "yield " in p.stdout


def test_the_loops_worst_case():
    p = run(*LOOP, "--worst-case", "--tol", "R=1%", "C=2%", "--json")
    assert p.returncode == 0, p.stderr
    wc = json.loads(p.stdout)["worst_case"]
    assert "slopes" in wc["method"]
    pm = wc["phase_margin_deg"]
    assert pm["min"]["value"] <= pm["max"]["value"]
    assert all(abs(d) <= 1 for d in pm["min"]["deviations"].values()) and len(pm["min"]["deviations"]) == 22


def test_target_ci_on_the_loop_draws_in_rounds():
    p = run(*LOOP, "--monte-carlo", "20000", "--seed", "7", "--limit", "phase_margin_deg=27:90",
            "--limit", "overshoot_pct=0:12", "--target-ci", "3%", "--json")
    assert p.returncode == 0, p.stderr
    mc = json.loads(p.stdout)["monte_carlo"]
    t = mc["settings"]["target_ci"]
    assert t["reached"] and t["half_width_pct"] == 3 and t["max_samples"] == 20000
    assert mc["settings"]["samples"] == mc["yield"]["samples"] == t["rounds"][-1] < 20000
    lo, hi = mc["yield"]["ci95"]
    assert (hi - lo) / 2 < 0.03


@pytest.mark.parametrize("args, words", [
    (["--monte-carlo", "20", "--limit", "fn_hz=3k:4k"], "unknown figure"),
    (["--monte-carlo", "100", "--target-ci", "1%"], "needs --limit"),
    (["--monte-carlo", "100", "--limit", "phase_margin_deg=27:90", "--target-ci", "1%", "--sampler", "lhs"],
     "random or sobol"),
    (["--monte-carlo", "20", "--limit", "phase_margin_deg=45:"], "both bounds"),
    (["--monte-carlo", "20", "--limit", "phase_margin_deg=90:45"], "above max"),
    (["--limit", "phase_margin_deg=45:90"], "goes with --monte-carlo"),
    (["--worst-case", "--tol", "Q9=1%"], "no such part"),
])
def test_bad_loop_tolerance_options_are_one_line(args, words):
    p = run(*LOOP, *args)
    assert p.returncode == 2 and words in p.stderr, p.stderr
    assert len(p.stderr.strip().splitlines()) == 1


def test_a_model_plants_loop_varies_the_controllers_parts():
    p = run("--plant-tf", "K=2 tau=1m theta=200u", "--tuning", "simc", "--monte-carlo", "10", "--limit",
            "phase_margin_deg=50:90", "--no-sim", "--no-files", "--json")
    assert p.returncode == 0, p.stderr
    mc = json.loads(p.stdout)["monte_carlo"]
    assert "R1" not in mc["settings"]["tolerances_pct"] and mc["settings"]["tolerances_pct"]["C4"] == 10.0
    assert mc["yield"]["samples"] == 10


def test_a_model_plant_has_no_plant_parts_to_spread():
    p = run("--plant-tf", "K=2 tau=1m theta=200u", "--monte-carlo", "10", "--tol", "R1=1%", "--no-sim", "--no-files")
    assert p.returncode == 2 and "--tol R1: no such part" in p.stderr, p.stderr


def test_the_opamps_spread_in_the_loop():
    p = run(*LOOP, "--monte-carlo", "20", "--seed", "3", "--tol", "GBW=30%", "SR=20%", "--json")
    assert p.returncode == 0, p.stderr
    mc = json.loads(p.stdout)["monte_carlo"]
    assert mc["settings"]["tolerances_pct"]["GBW"] == 30.0 and mc["settings"]["tolerances_pct"]["SR"] == 20.0
    assert mc["nominal_parts"]["SR"] == 0.5e6 and mc["nominal_parts"]["GBW"] == 1e6      # the LM741's
    ps = mc["p_slewing"]
    assert 0 <= ps["ci95"][0] <= ps["fraction"] <= ps["ci95"][1] and ps["count"] == round(20 * ps["fraction"])
    assert "slew_delay_s" in mc["statistics"]


@pytest.mark.parametrize("items, words", [
    (["SR=0"], "--tol SR: a tolerance must be above 0 and at most 50 %"),
    (["SR=-5%"], "--tol SR: a tolerance must be above 0 and at most 50 %"),
    (["SR=60%"], "--tol SR: a tolerance must be above 0 and at most 50 %"),
    (["GBW=0%"], "--tol GBW: a tolerance must be above 0"),
    (["SR=fast"], "is not a tolerance"),
])
def test_a_bad_opamp_spread_is_one_line(items, words):
    p = run(*LOOP, "--monte-carlo", "20", "--tol", *items)
    assert p.returncode == 2 and words in p.stderr, p.stderr
    assert len(p.stderr.strip().splitlines()) == 1


def test_the_ideal_opamps_have_no_spread(tmp_path):
    p = run("--plant-fc", "3500", "--plant-zeta", "0.2", "--opamp", "ideal", "--monte-carlo", "20", "--tol",
            "SR=20%", "--no-sim", "--out", str(tmp_path))
    assert p.returncode == 2 and "the ideal op-amp has no slew rate to spread" in p.stderr, p.stderr
    assert len(p.stderr.strip().splitlines()) == 1 and not any(tmp_path.iterdir())
