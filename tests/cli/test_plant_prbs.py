"""design-plant / analyze-plant --stimulus prbs (issue 18): the bundle holds the
generator's files and the simulated run, and identify on that run recovers
the design (the seed's plant from a SPICE PRBS run within 1 % in fn and zeta)."""

import json
import math
import subprocess
from pathlib import Path

import pytest
from helpers import script

from designer.core.prbs import PrbsPlan, awg_csv, time_value_csv


def run(name, *args):
    return subprocess.run([script(name), *args], capture_output=True, text=True, timeout=300)


@pytest.mark.spice
def test_identify_recovers_the_seed_plant_from_its_prbs_run(tmp_path):
    out = run("design-plant", "--fc", "3500", "--zeta", "0.2", "--stimulus", "prbs", "--json",
              "--out", str(tmp_path), "--simulator", "ngspice-cli")
    assert out.returncode == 0, out.stderr
    d = json.loads(out.stdout)
    files = d["files"]
    p = d["prbs"]
    plan = PrbsPlan(p["bits"], p["dt_s"], p["amplitude"], p["offset"], p["periods"])
    # the generator's files, as make-prbs writes them
    assert Path(files["prbs_csv"]).read_text() == time_value_csv(plan)
    assert Path(files["prbs_awg_csv"]).read_text() == awg_csv(plan)
    assert "prbs_source" in Path(files["prbs_deck"]).read_text()
    head = Path(files["waveforms_csv"]).read_text().splitlines()[0]
    assert head == "time_s,input_v,output_v,analytic_opamp_v"
    assert p["simulator"] == "ngspice-cli" and p["spice_vs_model_nrms"] < 1e-3
    md = Path(files["build_sheet_md"]).read_text()
    assert "under a PRBS" in md and "Bench test" in md
    assert f"{p['bits']} bits" in md and "(prbs.png)" in md
    assert any(f.endswith("prbs.png") and Path(f).stat().st_size > 0 for f in files["plots"])
    # identify on the run recovers the op-amp-aware design
    ident = run("identify", files["waveforms_csv"], "--json")
    assert ident.returncode == 0, ident.stderr
    got = json.loads(ident.stdout)
    assert got["format"] == "broadband" and got["excitation"]["bits"] == p["bits"]
    best = got["best"]
    assert best["model"] == "underdamped"
    fn, zeta = d["built"]["fn_opamp_hz"], d["built"]["zeta_opamp"]
    assert best["params"]["wn_rad_s"] / (2 * math.pi) == pytest.approx(fn, rel=0.01)
    assert best["params"]["zeta"] == pytest.approx(zeta, rel=0.01)


def test_step_stays_the_default(tmp_path):
    out = run("design-plant", "--fc", "3500", "--zeta", "0.2", "--no-sim", "--json", "--out", str(tmp_path))
    d = json.loads(out.stdout)
    assert "prbs" not in d and "prbs_csv" not in d["files"]
    head = Path(d["files"]["waveforms_csv"]).read_text().splitlines()[0]
    assert head == "time_s,input_v,output_v,analytic_v,analytic_opamp_v"


def test_analyze_plant_takes_the_stimulus_and_its_options():
    out = run("analyze-plant", "--r1", "820", "--r2", "1k", "--c1", "10n", "--c2", "220n", "--stimulus", "prbs",
              "--prbs-bits", "9", "--prbs-clock", "25k", "--no-sim", "--no-files", "--json")
    assert out.returncode == 0, out.stderr
    p = json.loads(out.stdout)["prbs"]
    assert (p["bits"], p["clock_hz"], p["simulator"]) == (9, pytest.approx(25e3), None)
    assert (p["low_v"], p["high_v"]) == (0.0, 2.0)


@pytest.mark.parametrize("args,needle", [
    (["--stimulus", "noise"], "--stimulus"),
    (["--prbs-bits", "8"], "--prbs-bits goes with --stimulus prbs"),
    (["--prbs-clock", "10k"], "--prbs-clock goes with --stimulus prbs"),
    (["--stimulus", "step", "--prbs-bits", "8"], "--prbs-bits goes with --stimulus prbs"),
    (["--stimulus", "prbs", "--prbs-bits", "21"], "--prbs-bits must be a whole number from 3 to 20"),
    (["--stimulus", "prbs", "--prbs-bits", "7.5"], "--prbs-bits"),
    (["--stimulus", "prbs", "--prbs-clock", "0"], "--prbs-clock"),
    (["--stimulus", "prbs", "--prbs-clock", "abc"], "not a number"),
    (["--stimulus", "prbs", "--prbs-bits", "16"], "clock intervals"),
    (["--stimulus", "prbs", "--monte-carlo", "10", "--replay", "1"], "--replay"),
])
def test_bad_stimulus_is_one_line_and_exit_2(args, needle, tmp_path):
    out = run("design-plant", "--fc", "3500", "--zeta", "0.2", "--no-sim", *args, "--out", str(tmp_path / "o"))
    assert out.returncode == 2, out.stderr
    lines = out.stderr.strip().splitlines()
    assert len(lines) == 1, out.stderr
    assert needle in lines[0] and "Traceback" not in out.stderr
    assert not (tmp_path / "o").exists() or not any((tmp_path / "o").rglob("*.*"))


def test_help_states_the_stimulus():
    out = run("design-plant", "--help")
    assert "--stimulus" in out.stdout and "--prbs-bits" in out.stdout and "3 to 20" in out.stdout
    assert "--stimulus" in run("analyze-plant", "--help").stdout


@pytest.mark.spice
def test_identify_recovers_a_section_plants_fn_from_its_prbs_run(tmp_path):
    """Issue 26: --stimulus prbs on a section plant (an inverting MFB low-pass): the generator's files, the
    run, and identify on the written run recovers the op-amp-aware model's fn (within 2 %) and gain."""
    out = run("design-plant", "--fc", "1k", "--zeta", "0.5", "--topology", "mfb-lowpass", "--stimulus", "prbs",
              "--json", "--out", str(tmp_path), "--simulator", "ngspice-cli")
    assert out.returncode == 0, out.stderr
    d = json.loads(out.stdout)
    files, p = d["files"], d["prbs"]
    plan = PrbsPlan(p["bits"], p["dt_s"], p["amplitude"], p["offset"], p["periods"])
    assert Path(files["prbs_csv"]).read_text() == time_value_csv(plan)
    assert Path(files["prbs_awg_csv"]).read_text() == awg_csv(plan)
    assert "Xgen vin prbs_source" in Path(files["prbs_deck"]).read_text()
    assert p["simulator"] == "ngspice-cli" and p["spice_vs_model_nrms"] < 1e-3
    md = Path(files["build_sheet_md"]).read_text()
    assert "under a PRBS" in md and f"{p['bits']} bits" in md and "(prbs.png)" in md
    ident = run("identify", files["waveforms_csv"], "--json")
    assert ident.returncode == 0, ident.stderr
    best = json.loads(ident.stdout)["best"]
    fn = d["built"]["opamp"]["fn_hz"]
    assert best["params"]["wn_rad_s"] / (2 * math.pi) == pytest.approx(fn, rel=0.02)
    assert best["params"]["K"] == pytest.approx(-d["built"]["ideal"]["gain"], rel=0.02)   # inverting


def test_analyze_plant_on_a_section_takes_the_stimulus_and_its_options():
    out = run("analyze-plant", "--topology", "rc-highpass", "--part", "R1=16k", "--part", "C1=10n",
              "--stimulus", "prbs", "--prbs-bits", "8", "--prbs-clock", "20k", "--amplitude", "1", "--no-sim",
              "--no-files", "--json")
    assert out.returncode == 0, out.stderr
    p = json.loads(out.stdout)["prbs"]
    assert (p["bits"], p["clock_hz"], p["simulator"]) == (8, pytest.approx(20e3), None)
    assert (p["low_v"], p["high_v"]) == (0.0, 1.0)
    # a high-pass blocks the offset: its output swings about 0 V
    assert p["output_min_v"] < 0 < p["output_max_v"]
