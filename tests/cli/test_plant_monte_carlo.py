"""design-plant and analyze-plant --monte-carlo from the outside (issue 17, the analytic plant engine)."""

import io
import json
import os
import re
import subprocess

import numpy as np
import pytest
from helpers import script

DESIGN_PLANT = script("design-plant")
ANALYZE_PLANT = script("analyze-plant")
SEED = ["--fc", "3500", "--zeta", "0.2"]


def run(exe, *args):
    env = dict(os.environ, MPLBACKEND="Agg")
    return subprocess.run([exe, *args], capture_output=True, text=True, env=env, timeout=300)


@pytest.mark.spice
def test_the_bundle_gains_the_monte_carlo(tmp_path):
    p = run(DESIGN_PLANT, *SEED, "--monte-carlo", "2000", "--seed", "3", "--limit", "fn_hz=3.3k:3.7k",
            "--limit", "overshoot_pct=0:55", "--json", "--out", str(tmp_path), "--simulator", "ngspice-cli")
    assert p.returncode == 0, p.stderr
    d = json.loads(p.stdout)["monte_carlo"]
    assert d["settings"]["samples"] == 2000 and d["settings"]["seed"] == 3
    assert d["settings"]["tolerances_pct"] == {"R1": 5.0, "R2": 5.0, "C1": 10.0, "C2": 10.0}   # E24 / E12
    rows = np.genfromtxt(io.StringIO((tmp_path / "reports" / "plant_fc3500_z0.2" / "monte-carlo.csv").read_text()),
                         delimiter=",", names=True)
    inside = (rows["fn_hz"] >= 3300) & (rows["fn_hz"] <= 3700) & (rows["overshoot_pct"] <= 55)
    assert d["yield"]["passed"] == int(inside.sum())
    assert d["tighten"]["part"] in ("R1", "R2", "C1", "C2")


def test_the_same_seed_gives_the_same_section():
    args = [*SEED, "--monte-carlo", "500", "--seed", "11", "--tol", "R=1%", "C2=2%", "--limit", "zeta=0.19:0.21",
            "--no-sim", "--no-files", "--json"]
    a, b = run(DESIGN_PLANT, *args), run(DESIGN_PLANT, *args)
    assert a.returncode == b.returncode == 0, a.stderr
    ma, mb = json.loads(a.stdout)["monte_carlo"], json.loads(b.stdout)["monte_carlo"]
    assert ma == mb and ma["settings"]["tolerances_pct"]["C2"] == 2.0 and ma["settings"]["tolerances_pct"]["R1"] == 1.0


def test_analyze_plant_parts_typed_by_hand():
    p = run(ANALYZE_PLANT, "--r1", "1k6", "--r2", "3k9", "--c1", "3n3", "--c2", "100n", "--monte-carlo", "200",
            "--no-sim", "--no-files")
    assert p.returncode == 0, p.stderr
    assert "Monte Carlo: 200 samples" in p.stdout


@pytest.mark.parametrize("args, what", [
    (["--monte-carlo", "5"], "--monte-carlo must be 10 to"),
    (["--monte-carlo", "ten"], "whole number"),
    (["--monte-carlo", "100", "--tol", "R=0%"], "above 0"),
    (["--monte-carlo", "100", "--tol", "R=51%"], "at most 50 %"),
    (["--monte-carlo", "100", "--tol", "X1=1%"], "no such part"),
    (["--monte-carlo", "100", "--limit", "fn_hz=3k:"], "both bounds"),
    (["--monte-carlo", "100", "--limit", "fn_hz=4k:3k"], "above max"),
    (["--monte-carlo", "100", "--sampler", "magic"], "invalid choice"),
    (["--monte-carlo", "100", "--seed", "-1"], "--seed"),
    (["--limit", "fn_hz=3k:4k"], "goes with --monte-carlo"),
    (["--worst-case", "--tol", "Q1=1%"], "no such part"),
])
def test_bad_settings_one_line_nothing_written(tmp_path, args, what):
    p = run(DESIGN_PLANT, *SEED, *args, "--no-sim", "--out", str(tmp_path))
    assert p.returncode == 2 and len(p.stderr.splitlines()) == 1 and what in p.stderr, p.stderr
    assert not any(tmp_path.iterdir())


def test_worst_case_from_the_command_line():
    p = run(DESIGN_PLANT, *SEED, "--worst-case", "--tol", "R=1%", "--no-sim", "--no-files", "--json")
    assert p.returncode == 0, p.stderr
    w = json.loads(p.stdout)["worst_case"]
    assert w["corners"] == 16 and w["fn_hz"]["min"]["value"] < w["fn_hz"]["max"]["value"]
    q = run(DESIGN_PLANT, *SEED, "--worst-case", "--no-sim", "--no-files")
    assert q.returncode == 0 and "Worst case over the tolerance box" in q.stdout
    r = run(DESIGN_PLANT, *SEED, "--tol", "R=1%", "--no-sim", "--no-files")
    assert r.returncode == 2 and "--tol goes with --monte-carlo N (or --worst-case)" in r.stderr


DESIGN_PID = script("design-pid")


def test_design_pid_monte_carlo_of_the_loop():
    p = run(DESIGN_PID, "--plant-fc", "3500", "--plant-zeta", "0.2", "--monte-carlo", "50", "--seed", "2",
            "--no-sim", "--no-files", "--json")
    assert p.returncode == 0, p.stderr
    d = json.loads(p.stdout)["monte_carlo"]
    assert d["settings"]["samples"] == 50 and "p_unstable" in d and "p_saturated" in d
    assert set(d["settings"]["tolerances_pct"]) >= {"R1", "C2", "R3", "R18", "C4"}


@pytest.mark.parametrize("args, what", [
    # a model plant's loop varies the controller's parts alone (its parameters stay as identified)
    (["--plant-tf", "K=2 tau=1m", "--monte-carlo", "50", "--tol", "C2=1%"], "no such part"),
    (["--plant-fc", "3500", "--plant-zeta", "0.2", "--monte-carlo", "50", "--tol", "C9=1%"], "no such part"),
    (["--plant-fc", "3500", "--plant-zeta", "0.2", "--tol", "R=1%"], "goes with --monte-carlo"),
    (["--plant-fc", "3500", "--plant-zeta", "0.2", "--opamp", "ideal", "--monte-carlo", "50", "--tol", "GBW=30%"],
     "the ideal op-amp has no gain-bandwidth"),
])
def test_design_pid_monte_carlo_refusals(tmp_path, args, what):
    p = run(DESIGN_PID, *args, "--no-sim", "--out", str(tmp_path))
    assert p.returncode == 2 and len(p.stderr.splitlines()) == 1 and what in p.stderr, p.stderr
    assert not any(tmp_path.iterdir())


def test_design_plant_spreads_the_opamp_when_asked():
    p = run(DESIGN_PLANT, *SEED, "--monte-carlo", "200", "--tol", "GBW=30%", "--no-sim", "--no-files", "--json")
    assert p.returncode == 0, p.stderr
    assert json.loads(p.stdout)["monte_carlo"]["settings"]["tolerances_pct"]["GBW"] == 30.0


# --engine spice|both, --spice-samples, --replay (the plant Monte Carlo in SPICE)

@pytest.mark.spice
@pytest.mark.parametrize("simulator", ["ngspice-cli", "pyspice"])
def test_engine_both_reports_the_disagreement(simulator):
    p = run(DESIGN_PLANT, *SEED, "--monte-carlo", "30", "--seed", "4", "--limit", "overshoot_pct=0:53",
            "--engine", "both", "--simulator", simulator, "--no-files", "--json")
    assert p.returncode == 0, p.stderr
    d = json.loads(p.stdout)["monte_carlo"]
    assert d["settings"]["engine"] == "both" and d["spice"]["simulator"] == simulator
    assert d["spice"]["disagreement"]["overshoot_pct"]["compared"] == 30
    assert d["spice"]["disagreement"]["overshoot_pct"]["max_abs"] < 0.02
    assert d["yield"]["fraction"] == d["spice"]["yield_with_spice"]
    q = run(DESIGN_PLANT, *SEED, "--monte-carlo", "500", "--seed", "4", "--limit", "overshoot_pct=0:53",
            "--engine", "both", "--spice-samples", "4", "--simulator", simulator, "--no-files")
    assert q.returncode == 0, q.stderr
    assert "SPICE on 8 samples (4 from the tails, 4 random)" in q.stdout and "with SPICE" in q.stdout


@pytest.mark.spice
def test_replay_writes_the_samples_bundle(tmp_path):
    common = ["--r1", "1k6", "--r2", "3k9", "--c1", "3n3", "--c2", "100n", "--monte-carlo", "40", "--seed", "9",
              "--sampler", "sobol", "--tol", "C=5%", "--simulator", "ngspice-cli", "--out", str(tmp_path)]
    p = run(ANALYZE_PLANT, *common, "--engine", "spice", "--name", "mc")
    assert p.returncode == 0, p.stderr
    rows = np.genfromtxt(io.StringIO((tmp_path / "reports" / "mc" / "monte-carlo.csv").read_text()),
                         delimiter=",", names=True)
    q = run(ANALYZE_PLANT, *common, "--replay", "21", "--name", "mc", "--json")
    assert q.returncode == 0, q.stderr
    bundle = tmp_path / "reports" / "mc_sample21"
    d = json.loads((bundle / "result.json").read_text())
    rep = d["monte_carlo"]["replay"]
    assert rep["sample"] == 21 and rep["settings"]["sampler"] == "sobol"
    for k, v in rep["values"].items():
        assert v == pytest.approx(rows[k][21], rel=1e-9)
    for k in ("overshoot_pct", "peak_time_s", "fn_hz", "settling_time_s"):
        assert rep["spice_figures"][k] == pytest.approx(rows[k][21], rel=1e-8)
    # the deck has the sample's own values (not E-series ones), and the bundle its waveforms
    deck = (tmp_path / "netlists" / "mc_sample21.cir").read_text()
    assert f"R1 input v1 {rep['values']['R1']:.6g}" in deck and f"C2 v1 out {rep['values']['C2']:.6g}" in deck
    assert (bundle / "waveforms.csv").stat().st_size > 0 and d["spice"] is not None
    # the bundle's full-deck SPICE run agrees with the engine's rising half
    assert d["spice"]["overshoot_pct"] == pytest.approx(rep["spice_figures"]["overshoot_pct"], abs=0.05)


@pytest.mark.parametrize("args, what", [
    (["--monte-carlo", "100", "--replay", "100"], "--replay '100': give a whole number from 0 to 99"),
    (["--monte-carlo", "100", "--replay", "-1"], "from 0 to 99"),
    (["--replay", "3"], "--replay I goes with --monte-carlo N"),
    (["--monte-carlo", "100", "--spice-samples", "5", "--limit", "fn_hz=3k:4k"], "--spice-samples K goes with "
                                                                                "--engine both"),
    (["--monte-carlo", "100", "--engine", "both", "--spice-samples", "5"], "needs --limit"),
    (["--monte-carlo", "100", "--engine", "both", "--spice-samples", "0", "--limit", "fn_hz=3k:4k"], "from 1 to 100"),
    (["--engine", "spice"], "--engine spice goes with --monte-carlo N"),
    (["--monte-carlo", "100", "--engine", "xyce"], "invalid choice"),
])
def test_bad_spice_settings_one_line_nothing_written(tmp_path, args, what):
    p = run(DESIGN_PLANT, *SEED, *args, "--out", str(tmp_path))
    assert p.returncode == 2 and len(p.stderr.splitlines()) == 1 and what in p.stderr, p.stderr
    assert not any(tmp_path.iterdir())


def test_replay_refuses_no_sim(tmp_path):
    p = run(DESIGN_PLANT, *SEED, "--monte-carlo", "100", "--replay", "3", "--no-sim", "--out", str(tmp_path))
    assert p.returncode == 2 and "drop --no-sim" in p.stderr and len(p.stderr.splitlines()) == 1
    assert not any(tmp_path.iterdir())


@pytest.mark.spice
def test_spice_options_never_crash(tmp_path_factory):
    """Whatever is typed for --engine, --spice-samples, --replay and --monte-carlo: exit 0 or 2 (3 never:
    the deck is ours), a refusal one line and nothing written."""
    from hypothesis import HealthCheck, given, settings
    from hypothesis import strategies as st

    from designer.cli.plant import design_plant_main
    text = st.one_of(st.sampled_from(["0", "1", "3", "9", "10", "19", "20", "-1", "1e3", "2.5", "", " ", "x", "nan",
                                      "99999999999999999999"]), st.text(max_size=6))

    @settings(max_examples=60, deadline=None, suppress_health_check=[HealthCheck.function_scoped_fixture])
    @given(st.sampled_from(["analytic", "spice", "both", "xyce"]), st.none() | text, st.none() | text,
           st.none() | st.sampled_from(["10", "20", "5", "x", ""]), st.booleans(), st.booleans())
    def check(engine, k, replay, n, limit, no_sim):
        import contextlib
        import io as _io
        out = tmp_path_factory.mktemp("out")
        argv = [*SEED, "--engine", engine, "--out", str(out), "--simulator", "ngspice-cli", "--no-files"]
        argv += [] if k is None else ["--spice-samples", k]
        argv += [] if replay is None else ["--replay", replay]
        argv += [] if n is None else ["--monte-carlo", n]
        argv += ["--limit", "overshoot_pct=0:53"] if limit else []
        argv += ["--no-sim"] if no_sim else []
        err = _io.StringIO()
        with contextlib.redirect_stderr(err), contextlib.redirect_stdout(_io.StringIO()):
            try:
                status = design_plant_main(argv)
            except SystemExit as exc:
                status = exc.code
        assert status in (0, 2), (argv, status, err.getvalue())
        assert "Traceback" not in err.getvalue()
        if status == 2:
            assert len(err.getvalue().strip().splitlines()) == 1, (argv, err.getvalue())
        assert not any(out.iterdir())
    check()


@pytest.mark.parametrize("args, what", [
    (["--monte-carlo", "50", "--tol", "SR=20%"], "--engine spice or both"),
    (["--worst-case", "--tol", "SR=20%"], "drop SR from --tol"),
    (["--monte-carlo", "50", "--tol", "SR=0", "--engine", "spice"], "above 0 and at most 50 %"),
    (["--opamp", "ideal", "--monte-carlo", "50", "--tol", "SR=20%", "--engine", "spice"],
     "the ideal op-amp has no slew rate"),
])
def test_a_plants_slew_spread_is_refused_where_nothing_slews(tmp_path, args, what):
    p = run(DESIGN_PLANT, *SEED, *args, "--out", str(tmp_path))
    assert p.returncode == 2 and len(p.stderr.splitlines()) == 1 and what in p.stderr, p.stderr
    assert not any(tmp_path.iterdir())


@pytest.mark.spice
def test_a_spice_monte_carlo_whose_steps_clip_says_so(tmp_path):
    # gain 10 on a 2 V square wave asks 20 V of an LM741 (14 V swing): no build's SPICE step settles to its
    # gain, so no build has fn or zeta; the summary raised KeyError: 2.5 after the files were written
    p = run(DESIGN_PLANT, "--topology", "sallen-key-lowpass-gain", "--fc", "3.5k", "--zeta", "0.7", "--gain", "10",
            "--monte-carlo", "10", "--seed", "1", "--engine", "spice", "--out", str(tmp_path))
    assert p.returncode == 0 and p.stderr == "", p.stderr
    assert "natural frequency fn (fn_hz): nominal n/a, no build has this figure" in p.stdout
    assert not re.search(r"\bnan\b", p.stdout)
