"""design-pid and analyze-pid --engine spice|both, --spice-samples K and --replay I from the outside
(issue 17, the loop's Monte Carlo in SPICE): every figure the JSON states recomputed from the bundle's
monte-carlo.csv rows, the same output with --jobs 1 and 2, both simulator backends, a replayed build
equal to its row, bad input one line."""

import io
import json
import os
import subprocess

import numpy as np
import pytest
from helpers import script

DESIGN_PID = script("design-pid")
ANALYZE_PID = script("analyze-pid")
LOOP = ["--plant-fc", "3500", "--plant-zeta", "0.2", "--opamp", "LM741", "--tuning", "optimize",
        "--target-overshoot", "10", "--no-sim"]
STEP = ("overshoot_pct", "peak_time_s", "rise_time_s", "settling_time_s")


def run(exe, *args):
    env = dict(os.environ, MPLBACKEND="Agg")
    return subprocess.run([exe, *args], capture_output=True, text=True, env=env, timeout=900)


def rows_of(path):
    return np.genfromtxt(io.StringIO(path.read_text()), delimiter=",", names=True)


def bundle(tmp_path, name, *args):
    """design-pid's Monte Carlo of the optimised LM741 loop into ``tmp_path/name``: (monte_carlo, CSV rows,
    the CSV's text)."""
    out = tmp_path / name
    p = run(DESIGN_PID, *LOOP, *args, "--name", "mc", "--out", str(out), "--json")
    assert p.returncode == 0, p.stderr
    csv = out / "reports" / "mc" / "monte-carlo.csv"
    return json.loads(p.stdout)["monte_carlo"], rows_of(csv), csv.read_text()


def passed(rows, limits):
    ok = rows["stable"] == 1
    for fig, lo, hi in limits:
        ok &= (rows[fig] >= lo) & (rows[fig] <= hi)
    return ok


@pytest.mark.spice
def test_engine_both_on_every_build_jobs_and_backends(tmp_path):
    args = ["--monte-carlo", "24", "--seed", "5", "--tol", "SR=30%", "--limit", "overshoot_pct=0:10",
            "--limit", "phase_margin_deg=27:90", "--engine", "both"]
    one, rows, text1 = bundle(tmp_path, "j1", *args, "--simulator", "ngspice-cli")
    two, _, text2 = bundle(tmp_path, "j2", *args, "--simulator", "ngspice-cli", "--jobs", "2")
    assert one == two and text1 == text2                       # whatever the workers
    sp = one["spice"]
    assert one["settings"]["engine"] == "both" and sp["simulator"] == "ngspice-cli"
    # the yield counts SPICE's overshoot, the model's yield the analytic loop's: both from the rows
    assert [lim["figure"] for lim in one["limits"]] == ["spice_overshoot_pct", "phase_margin_deg"]
    y_spice = passed(rows, [("spice_overshoot_pct", 0, 10), ("phase_margin_deg", 27, 90)])
    y_model = passed(rows, [("model_overshoot_pct", 0, 10), ("phase_margin_deg", 27, 90)])
    assert one["yield"]["passed"] == y_spice.sum() and sp["yield_with_spice"] == y_spice.mean()
    assert sp["yield_model"] == pytest.approx(y_model.mean())
    assert sp["yield_shift_pp"] == pytest.approx(100 * (y_spice.mean() - y_model.mean()))
    # the disagreement per step figure, SPICE minus the model, from the rows
    for f in STEP:
        d = rows[f"spice_{f}"] - rows[f"model_{f}"]
        assert sp["disagreement"][f]["compared"] == 24
        assert sp["disagreement"][f]["mean"] == pytest.approx(d.mean(), rel=1e-6, abs=1e-12)
        assert sp["disagreement"][f]["max_abs"] == pytest.approx(np.abs(d).max(), rel=1e-6)
        assert sp["disagreement"][f]["worst_sample"] == int(np.argmax(np.abs(d)))
    # the slew rate's spread moves SPICE's overshoot, not the linear model's: they disagree
    assert sp["disagreement"]["overshoot_pct"]["max_abs"] > 0.1
    # the part to buy tighter is searched with the analytic loop, as the plant's
    if one["tighten"]:
        assert one["tighten"]["engine"] == "analytic" and one["tighten"]["yield_now"] == pytest.approx(y_model.mean())
    # the other backend measures the same builds alike
    other, rows_py, _ = bundle(tmp_path, "py", *args, "--simulator", "pyspice")
    assert other["spice"]["simulator"] == "pyspice"
    for f in STEP:
        np.testing.assert_allclose(rows_py[f"spice_{f}"], rows[f"spice_{f}"], rtol=1e-9)


@pytest.mark.spice
def test_spice_samples_check_the_tails_and_flip_verdicts(tmp_path):
    args = ["--monte-carlo", "300", "--seed", "3", "--limit", "overshoot_pct=0:9", "--engine", "both",
            "--spice-samples", "3", "--simulator", "ngspice-cli"]
    one, rows, text1 = bundle(tmp_path, "j1", *args)
    two, _, text2 = bundle(tmp_path, "j2", *args, "--jobs", "2")
    assert one == two and text1 == text2
    sp = one["spice"]
    # the model on every build: the three with least room in the model's window, and three random others
    room = np.minimum(rows["model_overshoot_pct"] - 0, 9 - rows["model_overshoot_pct"]) / 9
    assert sp["worst"] == sorted(np.argsort(room, kind="stable")[:3].tolist())
    assert len(sp["random"]) == 3 and not set(sp["random"]) & set(sp["worst"])
    checked = sorted(sp["worst"] + sp["random"])
    assert sp["samples_checked"] == 6
    simulated = np.nonzero(np.isfinite(rows["spice_overshoot_pct"]))[0].tolist()
    assert simulated == checked
    # the flips and the yield with them, from the rows
    model_ok = passed(rows, [("model_overshoot_pct", 0, 9)])
    spice_ok = model_ok.copy()
    spice_ok[checked] = passed(rows[checked], [("spice_overshoot_pct", 0, 9)])
    assert sp["flipped"]["pass_to_fail"] == np.nonzero(model_ok & ~spice_ok)[0].tolist()
    assert sp["flipped"]["fail_to_pass"] == np.nonzero(~model_ok & spice_ok)[0].tolist()
    assert one["yield"]["passed"] == model_ok.sum() and sp["yield_with_spice"] == pytest.approx(spice_ok.mean())
    d = rows["spice_overshoot_pct"][checked] - rows["model_overshoot_pct"][checked]
    assert sp["disagreement"]["overshoot_pct"]["compared"] == 6
    assert sp["disagreement"]["overshoot_pct"]["mean"] == pytest.approx(d.mean(), rel=1e-6)


@pytest.mark.spice
def test_replay_is_the_runs_row_and_writes_its_bundle(tmp_path):
    common = [*LOOP, "--monte-carlo", "12", "--seed", "9", "--sampler", "sobol", "--tol", "GBW=20%", "SR=20%",
              "--simulator", "ngspice-cli", "--out", str(tmp_path), "--name", "mc"]
    p = run(DESIGN_PID, *common, "--engine", "spice")
    assert p.returncode == 0, p.stderr
    rows = rows_of(tmp_path / "reports" / "mc" / "monte-carlo.csv")
    q = run(DESIGN_PID, *[a for a in common if a != "--no-sim"], "--replay", "7", "--json")
    assert q.returncode == 0, q.stderr
    out = tmp_path / "reports" / "mc_sample7"
    d = json.loads((out / "result.json").read_text())
    rep = d["monte_carlo"]["replay"]
    assert rep["sample"] == 7 and rep["settings"]["sampler"] == "sobol"
    for k, v in rep["values"].items():
        assert v == pytest.approx(rows[k][7], rel=1e-9)
    for k, v in {**rep["spice_figures"], **rep["model_figures"]}.items():
        assert v == pytest.approx(rows[k][7], rel=1e-8, abs=1e-12), k
    # the bundle's row is the run's row
    assert np.atleast_1d(rows_of(out / "monte-carlo.csv"))[0].tolist() == pytest.approx(rows[7].tolist(), rel=1e-8, abs=1e-12)
    # the deck holds the build's own values and op-amp; its SPICE run is the engine's
    deck = (tmp_path / "netlists" / "mc_sample7.cir").read_text()
    assert f"{rep['values']['R5']:.6g}" in deck and f"{rep['values']['C4']:.6g}" in deck
    assert d["components"]["R5_ohm"] == pytest.approx(rep["values"]["R5"], rel=1e-12)
    sp = d["closed_loop"]["spice"]
    assert sp["overshoot_pct"] == pytest.approx(rep["spice_figures"]["spice_overshoot_pct"], abs=0.02)
    assert sp["settling_time_s"] == pytest.approx(rep["spice_figures"]["spice_settling_time_s"], rel=1e-3)
    assert "Monte Carlo build 7 replayed" in " ".join(d["notes"])


@pytest.mark.spice
def test_analyze_pid_on_a_model_plant_runs_spice_and_replays(tmp_path):
    model = ["--plant-tf", "K=2 tau=1m theta=200u"]
    p = run(DESIGN_PID, *model, "--tuning", "simc", "--no-sim", "--out", str(tmp_path), "--name", "pi")
    assert p.returncode == 0, p.stderr
    parts = tmp_path / "reports" / "pi" / "result.json"
    common = [*model, "--parts-json", str(parts), "--tol", "R=5%", "C=10%", "--monte-carlo", "10", "--seed", "2",
              "--simulator", "ngspice-cli", "--out", str(tmp_path), "--name", "as"]
    q = run(ANALYZE_PID, *common, "--engine", "spice", "--limit", "settling_time_s=0:2m", "--json")
    assert q.returncode == 0, q.stderr
    mc = json.loads(q.stdout)["monte_carlo"]
    rows = rows_of(tmp_path / "reports" / "as" / "monte-carlo.csv")
    assert "R1" not in mc["settings"]["tolerances_pct"] and mc["spice"]["engine"] == "spice"
    assert mc["yield"]["passed"] == passed(rows, [("spice_settling_time_s", 0, 2e-3)]).sum()
    r = run(ANALYZE_PID, *common, "--replay", "4", "--json")
    assert r.returncode == 0, r.stderr
    rep = json.loads((tmp_path / "reports" / "as_sample4" / "result.json").read_text())["monte_carlo"]["replay"]
    for k, v in rep["spice_figures"].items():
        assert v == pytest.approx(rows[k][4], rel=1e-8)


@pytest.mark.parametrize("args, what", [
    (["--monte-carlo", "20", "--spice-samples", "5", "--limit", "overshoot_pct=0:10"],
     "--spice-samples K goes with --engine both"),
    (["--monte-carlo", "20", "--engine", "both", "--spice-samples", "5"], "needs --limit"),
    (["--monte-carlo", "20", "--engine", "both", "--spice-samples", "21", "--limit", "overshoot_pct=0:10"],
     "from 1 to 20"),
    (["--monte-carlo", "20", "--replay", "20"], "--replay '20': give a whole number from 0 to 19"),
    (["--monte-carlo", "20", "--replay", "x"], "from 0 to 19"),
    (["--replay", "3"], "--replay I goes with --monte-carlo N"),
    (["--engine", "spice"], "--engine spice goes with --monte-carlo N"),
    (["--monte-carlo", "20", "--engine", "spice", "--limit", "fn_hz=3k:4k"], "unknown figure"),
    (["--monte-carlo", "20", "--replay", "3", "--no-sim"], "drop --no-sim"),
])
def test_bad_spice_settings_one_line_nothing_written(tmp_path, args, what):
    for exe, extra in ((DESIGN_PID, []), (ANALYZE_PID, ["--r3", "12k", "--r4", "1k8", "--r5", "22k", "--r6", "3k3",
                                                         "--r8", "1k2", "--r9", "10k", "--r10", "10k", "--r13", "27k",
                                                         "--r14", "2k7", "--r15", "10k", "--r16", "10k", "--r17",
                                                         "10k", "--r18", "10k", "--c4", "47n"])):
        p = run(exe, *LOOP[:4], *extra, *args, "--out", str(tmp_path))
        assert p.returncode == 2 and len(p.stderr.splitlines()) == 1 and what in p.stderr, (exe, p.stderr)
        assert not any(tmp_path.iterdir())
