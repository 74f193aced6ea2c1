import json
import os
import subprocess
from pathlib import Path

import pytest
from helpers import script


def run(name, *args, cwd=None):
    return subprocess.run([script(name), *args], capture_output=True, text=True, cwd=cwd, timeout=300)


REQUIRED = {
    "spec": {"fc_hz", "zeta", "gain"}, "ratios": {"m", "n"},
    "ideal": {"R1_ohm", "R2_ohm", "C1_f", "C2_f", "fn_hz", "zeta"},
    "built": {"R1_ohm", "R2_ohm", "C1_f", "C2_f", "fn_hz", "zeta", "q", "fn_error_pct", "zeta_error_pct"},
    "opamp": {"name", "gbw_hz", "slew_v_per_s"},
    "analytic": {"overshoot_pct", "peak_time_s", "rise_time_s", "settling_time_s"},
    "analytic_opamp": {"overshoot_pct", "peak_time_s", "rise_time_s", "settling_time_s"},
    "spice": {"overshoot_pct", "peak_time_s", "rise_time_s", "settling_time_s", "nrms"},
    "files": {"netlist", "build_sheet_md", "build_sheet_html"},
}


@pytest.mark.spice
def test_design_plant_json_and_files(tmp_path):
    out = run("design-plant", "--fc", "3.5k", "--zeta", "0.2", "--json", "--out", str(tmp_path),
              "--simulator", "ngspice-cli")
    assert out.returncode == 0, out.stderr
    d = json.loads(out.stdout)
    for key, sub in REQUIRED.items():
        assert sub <= set(d[key]), key
    assert "sensitivity" in d
    for key in ("netlist", "build_sheet_md", "build_sheet_html", "result_json"):
        assert os.path.getsize(d["files"][key]) > 0
    assert json.loads(Path(d["files"]["result_json"]).read_text()) == d
    html = Path(d["files"]["build_sheet_html"]).read_text()
    assert "data:image/png;base64," in html and "<table>" in html  # self-contained
    md = Path(d["files"]["build_sheet_md"]).read_text()
    assert "Bill of materials" in md and "Bench test" in md and " %" in md
    # no temporary files left behind
    assert not [p for p in tmp_path.rglob("*.tmp")]


def test_analyze_plant_seed_parts(tmp_path):
    out = run("analyze-plant", "--r1", "820", "--r2", "1k", "--c1", "10n", "--c2", "220n", "--fc", "3500",
              "--zeta", "0.2", "--json", "--no-sim", "--out", str(tmp_path))
    assert out.returncode == 0, out.stderr
    d = json.loads(out.stdout)
    assert round(d["built"]["fn_hz"]) == 3747 and round(d["built"]["zeta"], 3) == 0.214


def test_summary_has_units(tmp_path):
    out = run("design-plant", "--fc", "3500", "--zeta", "0.2", "--no-sim", "--no-files")
    assert out.returncode == 0
    assert "kHz" in out.stdout and "us" in out.stdout and "kOhm" in out.stdout
    assert "SPICE simulation skipped" in out.stdout


@pytest.mark.parametrize("args,needle", [
    (["--fc", "0", "--zeta", "0.2"], "--fc"),
    (["--fc", "-5", "--zeta", "0.2"], "--fc"),
    (["--fc", "nan", "--zeta", "0.2"], "--fc"),
    (["--fc", "inf", "--zeta", "0.2"], "--fc"),
    (["--fc", "abc", "--zeta", "0.2"], "not a number"),
    (["--fc", "3500", "--zeta", "0"], "--zeta"),
    (["--fc", "3500", "--zeta", "0.2", "--r-series", "E7"], "allowed: E3"),
    (["--fc", "3500", "--zeta", "0.2", "--opamp", "uA709"], "allowed: ideal"),
    (["--fc", "3500", "--zeta", "0.2", "--r-min", "1.01k", "--r-max", "1.05k"], "widen the bounds"),
    (["--fc", "1meg", "--zeta", "0.5"], "lower --r-min or --c-min"),
    (["--fc", "3500", "--zeta", "0.2", "--gain", "0.5"], "gain"),
    (["--fc", "3500", "--zeta", "0.2", "--r", "1k"], "--r and --c"),
    (["--fc", "3500", "--zeta", "0.2", "--r", "100k", "--c", "1u"], "R*C"),
    (["--zeta", "0.2"], "--fc"),
    (["--fc", "3500", "--zeta", "0.2", "--bogus"], "unrecognized"),
])
def test_bad_input_is_one_line_and_exit_2(args, needle, tmp_path):
    out = run("design-plant", *args, "--out", str(tmp_path / "o"))
    assert out.returncode == 2
    lines = out.stderr.strip().splitlines()
    assert len(lines) == 1, out.stderr
    assert needle in lines[0] and "Traceback" not in out.stderr
    assert not (tmp_path / "o").exists() or not any((tmp_path / "o").rglob("*.*"))


def test_unwritable_output_dir(tmp_path):
    blocker = tmp_path / "file"
    blocker.write_text("not a directory")
    out = run("design-plant", "--fc", "3500", "--zeta", "0.2", "--no-sim", "--out", str(blocker / "sub"))
    assert out.returncode == 2 and len(out.stderr.strip().splitlines()) == 1
    assert "cannot create directory" in out.stderr


def test_help_teaches():
    out = run("design-plant", "--help")
    assert out.returncode == 0
    assert "examples:" in out.stdout and "4k7" in out.stdout
    assert run("analyze-plant", "--help").returncode == 0


@pytest.mark.parametrize("cmd,args", [
    ("design-plant", ["--fc", "1592", "--zeta", "1"]),
    ("analyze-plant", ["--r1", "10k", "--r2", "10k", "--c1", "10n", "--c2", "10n"]),
])
@pytest.mark.spice
def test_critically_damped_builds_write_their_bundle(cmd, args, tmp_path):
    """Regression (issue 7.1): the textbook equal-component unity-gain Sallen-Key
    (zeta = 1, a repeated pole) crashed after the simulation and left an empty report folder."""
    out = run(cmd, *args, "--json", "--out", str(tmp_path))
    assert out.returncode == 0, out.stderr
    d = json.loads(out.stdout)
    assert d["built"]["zeta"] == pytest.approx(1.0, abs=2e-3)
    assert d["comparison"]["pass"] is True
    for key in ("netlist", "build_sheet_md", "build_sheet_html", "result_json", "waveforms_csv"):
        assert os.path.getsize(d["files"][key]) > 0


@pytest.mark.parametrize("cmd,args", [
    ("design-plant", ["--fc", "3500", "--zeta", "0.2", "--no-sim", "--no-files"]),
    ("design-plant", ["--fc", "3500", "--zeta", "0.2", "--no-sim", "--no-files", "--json"]),
    ("design-pid", ["--plant-fc", "3500", "--plant-zeta", "0.2", "--no-sim", "--no-files", "--json"]),
])
def test_reader_closing_the_pipe_is_not_an_error(cmd, args):
    """Regression (issue 7.10): `--json | head -c 10` was a BrokenPipeError traceback."""
    with subprocess.Popen([script(cmd), *args], stdout=subprocess.PIPE, stderr=subprocess.PIPE) as p:
        p.stdout.close()   # the reader is gone before anything is written
        err = p.stderr.read().decode()
        assert p.wait(timeout=120) == 0
    assert err == ""
