"""``make-prbs``: the files a generator and ngspice read, the plan for a plant,
and its input handling (hypothesis: exit 0 or 2, one line, no file on refusal)."""

import json
import os
import subprocess
import warnings

import numpy as np
import pytest
from helpers import script
from hypothesis import HealthCheck, given, settings
from hypothesis import strategies as st

from designer.cli.prbs import make_prbs_main
from designer.core.prbs import mls

EXE = script("make-prbs")


def run(*args, cwd=None):
    return subprocess.run([str(EXE), *map(str, args)], capture_output=True, text=True, timeout=60, cwd=cwd)


def test_bundle_files(tmp_path):
    out = tmp_path / "gen"
    proc = run("--bits", "6", "--clock", "2k", "--amplitude", "250m", "--offset", "1.5", "--periods", "2",
               "--out", out)
    assert proc.returncode == 0, proc.stderr
    assert sorted(p.name for p in out.iterdir()) == ["prbs.cir", "prbs.csv", "prbs_awg.csv"]
    awg = (out / "prbs_awg.csv").read_text().splitlines()
    assert awg[0] == "sample_rate_hz,2000"
    vals = np.array(awg[1:], float)
    assert np.array_equal(vals, 1.5 + 0.25 * np.tile(mls(6), 2))
    tv = np.loadtxt(out / "prbs.csv", delimiter=",", skiprows=1)
    assert tv[1, 0] == pytest.approx(0.5e-3) and tv.shape[0] == vals.size + 1
    assert "63 intervals" in proc.stdout and "2 kHz" in proc.stdout


@pytest.mark.spice
def test_pwl_file_runs_in_ngspice(tmp_path):
    """The PWL subcircuit drives an RC in ngspice; the RC's output is the sequence filtered."""
    out = tmp_path / "gen"
    assert run("--bits", "4", "--dt", "1m", "--periods", "1", "--out", out).returncode == 0
    deck = tmp_path / "rc.cir"
    deck.write_text(f"* rc\n.include {out / 'prbs.cir'}\nX1 in prbs_source\nR1 in out 1k\nC1 out 0 100n\n"
                    ".tran 10u 15m\n.control\nrun\nwrdata " + str(tmp_path / "o.txt") + " v(in)\n"
                    ".endc\n.end\n")
    proc = subprocess.run(["ngspice", "-b", str(deck)], capture_output=True, text=True, timeout=60)
    assert (tmp_path / "o.txt").exists(), proc.stdout + proc.stderr
    t, v = np.loadtxt(tmp_path / "o.txt", unpack=True)
    mid = (np.arange(15) + 0.5) * 1e-3
    assert np.allclose(np.interp(mid, t, v), mls(4), atol=1e-6)


def test_for_plant_says_why():
    proc = run("--for-plant", "--plant-tf", "K=1 fn=1k zeta=0.2", "--no-files", "--json")
    assert proc.returncode == 0, proc.stderr
    d = json.loads(proc.stdout)["prbs"]
    assert d["band_hz"] >= 3 * 1e3 and d["period_s"] > 0
    assert any("bandwidth" in r for r in d["reasons"]) and any("bits" in r for r in d["reasons"])


def test_for_plant_from_an_identify_json(tmp_path):
    model = {"methods": [{"name": "least-squares", "model": "fopdt", "valid": True, "note": "", "points": {},
                          "params": {"K": 2.0, "tau_s": 0.01, "theta_s": 0.002}, "iae": 0.1, "ise": 0.01}],
             "preprocessing": {}}
    model["best"] = model["methods"][0]
    path = tmp_path / "m.json"
    path.write_text(json.dumps(model))
    proc = run("--for-plant", "--plant-model", path, "--no-files")
    assert proc.returncode == 0, proc.stderr
    assert "Plant: G(s) = 2" in proc.stdout


@pytest.mark.parametrize("args, words", [
    (["--bits", "21", "--clock", "1k"], "from 3 to 20"),
    (["--bits", "2", "--clock", "1k"], "from 3 to 20"),
    (["--bits", "8"], "--clock"),
    (["--bits", "8", "--clock", "0"], "--clock"),
    (["--bits", "8", "--dt", "-1m"], "--dt"),
    (["--bits", "8", "--clock", "1k", "--amplitude", "0"], "--amplitude"),
    (["--bits", "8", "--clock", "1k", "--periods", "2.5"], "--periods"),
    (["--bits", "20", "--clock", "1k", "--periods", "10"], "at most"),
    (["--for-plant", "--plant-tf", "num=[1] den=[1 -2]"], "stable"),
    (["--for-plant", "--plant-tf", "K=1 integrator"], "integrating"),
    (["--for-plant"], "--plant-tf"),
    (["--plant-tf", "K=1 tau=1"], "--for-plant"),
])
def test_bad_input_one_line(args, words, tmp_path):
    proc = run(*args, "--out", tmp_path / "x")
    assert proc.returncode == 2
    lines = proc.stderr.strip().splitlines()
    assert len(lines) == 1 and lines[0].startswith("make-prbs: error:") and words in lines[0], proc.stderr
    assert not (tmp_path / "x").exists()


_numbers = st.one_of(st.floats(allow_nan=True, allow_infinity=True).map(repr),
                     st.integers(-10 ** 30, 10 ** 30).map(str),
                     st.sampled_from(["1k", "2u2", "3.5meg", "-0", "nan", "", " ", "1e400", "0x10", "1,5"]),
                     st.text(max_size=8))


@given(bits=_numbers, clock=_numbers, amp=_numbers, off=_numbers, per=_numbers)
@settings(max_examples=120, deadline=None, suppress_health_check=[HealthCheck.function_scoped_fixture])
def test_fuzz_inputs(bits, clock, amp, off, per, tmp_path, capsys):
    out = tmp_path / "fz"
    argv = ["--bits", bits, "--clock", clock, "--amplitude", amp, "--offset", off, "--periods", per,
            "--out", str(out), "--no-files"]
    with warnings.catch_warnings():
        warnings.simplefilter("error")
        status = make_prbs_main(argv)
    captured = capsys.readouterr()
    assert status in (0, 2)
    if status == 2:
        lines = captured.err.strip().splitlines()
        assert len(lines) == 1 and lines[0].startswith("make-prbs: error:"), captured.err
        assert "Traceback" not in captured.err and "array(" not in captured.err
    assert not out.exists()


def _ours(folder) -> list:
    return sorted(p.name for p in folder.iterdir() if p.name.startswith("."))


def test_out_at_a_dangling_link_is_refused_and_nothing_left(tmp_path):
    """--out at a dangling link turned it into a folder and left a stray .out.new-PID-* link."""
    (tmp_path / "out").symlink_to("nowhere")
    proc = run("--bits", "5", "--clock", "1k", "--out", tmp_path / "out")
    assert proc.returncode == 2 and proc.stdout == ""
    lines = proc.stderr.strip().splitlines()
    assert len(lines) == 1 and "a symbolic link to nothing (nowhere)" in lines[0], proc.stderr
    assert (tmp_path / "out").is_symlink() and os.readlink(tmp_path / "out") == "nowhere"
    assert _ours(tmp_path) == [] and sorted(p.name for p in tmp_path.iterdir()) == ["out"]


def test_out_at_a_link_to_a_folder_writes_through_it(tmp_path):
    (tmp_path / "bench").mkdir()
    (tmp_path / "out").symlink_to("bench")
    proc = run("--bits", "5", "--clock", "1k", "--out", tmp_path / "out")
    assert proc.returncode == 0, proc.stderr
    assert (tmp_path / "out").is_symlink()
    assert sorted(p.name for p in (tmp_path / "bench").iterdir()) == ["prbs.cir", "prbs.csv", "prbs_awg.csv"]
    assert _ours(tmp_path) == [] and _ours(tmp_path / "bench") == []


@pytest.mark.parametrize("tf, tau", [("K=1 tau=1p", "1 ps"), ("K=2 tau=100p theta=0", "100 ps")])
def test_for_plant_clock_stays_in_the_clock_range(tf, tau, tmp_path):
    """tau = 1 ps chose a 2000 GHz clock where --clock stops at 1 GHz: refused, naming the time constant
    and the range."""
    from designer.core.prbs import BAND_FACTOR, HALF_POWER
    from designer.core.ranges import RANGES
    proc = run("--for-plant", "--plant-tf", tf, "--out", tmp_path / "x")
    assert proc.returncode == 2 and proc.stdout == ""
    line = proc.stderr.strip()
    assert "\n" not in line and f"time constant {tau}" in line and RANGES["prbs_clock_hz"].text() in line, line
    assert not (tmp_path / "x").exists()
    # the boundary: the fastest first-order plant whose chosen clock is within range is taken
    hi = RANGES["prbs_clock_hz"].hi
    tau_ok = BAND_FACTOR / (2 * np.pi * HALF_POWER * hi) * 2   # its clock before rounding: hi / 2
    ok = run("--for-plant", "--plant-tf", f"K=1 tau={tau_ok!r}", "--no-files", "--json")
    assert ok.returncode == 0, ok.stderr
    assert json.loads(ok.stdout)["prbs"]["clock_hz"] <= hi


def test_for_plant_takes_the_factored_form():
    """Issue 28: --plant-tf typed as papers print it plans as its expanded rational form does."""
    a = run("--for-plant", "--plant-tf", "K=1 zeros=[-0.3s+1] poles=[2s+1, s+1, (0.05s+1)^3]", "--no-files", "--json")
    b = run("--for-plant", "--plant-tf", "num=[-0.3 1] den=[0.00025 0.015375 0.322625 2.4575 3.15 1]",
            "--no-files", "--json")
    assert a.returncode == 0 and b.returncode == 0, a.stderr
    pa, pb = json.loads(a.stdout), json.loads(b.stdout)
    assert pa["prbs"] == pb["prbs"]
    assert pa["plant"]["settling_time_s"] == pytest.approx(pb["plant"]["settling_time_s"], rel=1e-9)
    bad = run("--for-plant", "--plant-tf", "K=1 poles=[(2s+1]", "--no-files")
    assert bad.returncode == 2 and len(bad.stderr.splitlines()) == 1 and "unbalanced bracket" in bad.stderr
