"""``identify-freq`` end to end, through the installed console script."""

import json
import math
import subprocess

import numpy as np
import pytest
from helpers import FIXTURES, script

EXE = script("identify-freq")
FIX = FIXTURES / "identify_freq"


def run(*args, cwd=None):
    return subprocess.run([EXE, *map(str, args)], capture_output=True, text=True, timeout=120,
                          cwd=cwd)


def one_line_error(p):
    assert p.returncode == 2, p.stderr
    assert p.stdout == ""
    lines = p.stderr.strip().splitlines()
    assert len(lines) == 1, p.stderr
    assert "Traceback" not in p.stderr
    assert lines[0].startswith("identify-freq: error: ")
    return lines[0]


def test_table_output_seed000():
    p = run(FIX / "seed000_table4_deg.csv")
    assert p.returncode == 0, p.stderr
    out = p.stdout
    assert "14 points" in out and "10 Hz to 200 kHz" in out
    for word in ("asymptotes", "resonant-peak", "least-squares", "double-pole", "Best:",
                 "rad/s", "Hz", "tau 2.236 us", "%"):
        assert word in out


def test_json_seed003(tmp_path):
    png = tmp_path / "bode.png"
    p = run(FIX / "seed003_table31.csv", "--json", "--plot", png)
    assert p.returncode == 0, p.stderr
    d = json.loads(p.stdout)
    assert set(d) >= {"methods", "best", "data", "error_definition"}
    assert d["best"] in d["methods"]
    for m in d["methods"]:
        assert set(m) >= {"name", "model", "params", "iae", "ise", "valid", "note"}
    assert d["best"]["model"] == "fopdt"
    fc = 1 / (2 * math.pi * d["best"]["params"]["tau_s"])
    assert 4500 <= fc <= 4900          # seed 003: 4850 Hz read off the plot
    assert d["data"]["has_phase"] is False
    assert png.read_bytes()[:8] == b"\x89PNG\r\n\x1a\n"
    assert not list(tmp_path.glob(".*.tmp"))        # atomic write leaves no temp file


def test_units_options_and_header(tmp_path):
    # the same sensor table with kHz, ratio and microseconds named in the header
    a = json.loads(run(FIX / "seed000_table4_deg.csv", "--json").stdout)
    b = json.loads(run(FIX / "seed000_table4_us.csv", "--json").stdout)
    ta = next(m for m in a["methods"] if m["name"] == "asymptotes")
    tb = next(m for m in b["methods"] if m["name"] == "asymptotes")
    assert ta["params"]["tau_s"] == pytest.approx(tb["params"]["tau_s"], rel=0.01)
    # no header: options say the units
    w = np.geomspace(10, 1e5, 30)
    g = 1 / (1 + 1j * w * 1e-3)
    rows = "\n".join(f"{wi:.8g} {abs(gi):.10g} {-wi * 1e-4 + np.angle(gi):.10g}"
                     for wi, gi in zip(w, g))
    f = tmp_path / "t.txt"
    f.write_text(rows + "\n")
    p = run(f, "--freq-units", "rad/s", "--gain-units", "ratio", "--phase-units", "rad", "--json")
    assert p.returncode == 0, p.stderr
    best = json.loads(p.stdout)["best"]
    assert best["model"] == "fopdt"
    assert best["params"]["tau_s"] == pytest.approx(1e-3, rel=1e-6)
    assert best["params"]["theta_s"] == pytest.approx(1e-4, rel=1e-5)


def test_help_teaches():
    p = run("--help")
    assert p.returncode == 0
    assert "examples:" in p.stdout and "--gain-units" in p.stdout and "-360 f dt" in p.stdout


@pytest.mark.parametrize("content, words", [
    ("", "empty"),
    ("f,g\n", "no data"),
    ("1,0\n2,abc\n3,-1\n4,-2\n5,-3\n", "not a number"),
    ("1,0\n2,NaN\n3,-1\n4,-2\n5,-3\n", "not a finite number"),
    ("1,0\n3,-1\n2,-2\n4,-3\n5,-4\n", "not increasing"),
    ("1,0\n2,-1\n3,-2\n", "too few points"),
])
def test_bad_tables_one_line(tmp_path, content, words):
    f = tmp_path / "bad.csv"
    f.write_text(content)
    line = one_line_error(run(f))
    assert words in line


def test_bad_invocations(tmp_path):
    assert "does not exist" in one_line_error(run(tmp_path / "missing.csv"))
    line = one_line_error(run(FIX / "seed003_table31.csv", "--gain-units", "np"))
    assert "invalid choice" in line
    one_line_error(run())
    blocker = tmp_path / "file"
    blocker.write_text("x")
    line = one_line_error(run(FIX / "seed003_table31.csv", "--plot", blocker / "sub" / "b.png"))
    assert "cannot create directory" in line


def test_help_states_the_limits_and_the_validity_rule():
    from designer.core.fileio import MAX_TABLE_BYTES, size_text
    from designer.core.ranges import RANGES
    from designer.identify.frequency import BAND_FACTOR, MAX_FIT_ERROR
    from designer.identify.io import MAX_POINTS
    out = " ".join(run("--help").stdout.split())
    for key in ("freq_hz", "gain_db", "gain_ratio", "phase_deg"):
        assert RANGES[key].text() in out, key
    assert size_text(MAX_TABLE_BYTES) in out and f"{MAX_POINTS:,}" in out
    assert f"at most {100 * MAX_FIT_ERROR:g} %" in out and f"widened {BAND_FACTOR:g} times" in out


def test_gain_units_any_case_and_notes_in_the_table(tmp_path):
    d = json.loads(run(FIX / "seed000_table4_deg.csv", "--json").stdout)
    p = run(FIX / "seed000_table4_deg.csv", "--json", "--gain-units", "dB", "--phase-units",
            "DEG", "--freq-units", "Hz")
    assert p.returncode == 0, p.stderr
    assert json.loads(p.stdout)["best"] == d["best"]
    # a flipped phase: the table says why no model is valid
    rows = [ln.split(",") for ln in (FIX / "seed000_table4_deg.csv").read_text().splitlines()
            if ln and ln[0].isdigit()]
    flipped = tmp_path / "flipped.csv"
    flipped.write_text("f_hz,gain_db,phase_deg\n" + "".join(
        f"{f},{g},{-float(ph)}\n" for f, g, ph in rows))
    p = run(flipped)
    assert p.returncode == 0, p.stderr
    assert "Best: none of the methods is valid" in p.stdout and "note: the phase rises" in p.stdout
