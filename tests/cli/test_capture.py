"""The installed ``simulate-capture`` console script: the CSV it writes (its
'#' lines, the header t,u,y) is what ``identify`` reads, the same seed gives
the same file, bad input is one line and exit status 2 with nothing written,
and ``identify`` recovers seed 000's DC motor from it."""

import json
import subprocess
from concurrent.futures import ThreadPoolExecutor

import numpy as np
import pytest
from helpers import script

from designer.core.ranges import RANGES

EXE = script("simulate-capture")
IDENTIFY = script("identify")
#: seed 000's DC motor (course notes, UNaM): Km = W(inf)/a = 2.5/2, tau_m = -t0/ln(1 - w/W(inf)) at
#: t0 = 0.15 s, w = 1.75
KM, TAU_M = 1.25, 0.1246
MOTOR = f"K={KM} tau={TAU_M * 1e3}m"


def run(*args, cwd=None):
    return subprocess.run([EXE, *map(str, args)], capture_output=True, text=True, cwd=cwd, timeout=300)


def identify(*args):
    return subprocess.run([IDENTIFY, *map(str, args)], capture_output=True, text=True, timeout=300)


def _comments(path):
    lines = path.read_text().splitlines()
    head = [ln for ln in lines[:20] if ln.startswith("#")]
    return head, lines[len(head)]


@pytest.mark.spice
def test_the_file_is_a_capture_identify_reads(tmp_path):
    out = tmp_path / "c.csv"
    proc = run("--plant-tf", "K=2 tau=1m theta=200u", "--step", "1.5", "--points", "501", "--noise", "2m",
               "--lsb", "1m", "--seed", "11", "--out", out)
    assert proc.returncode == 0, proc.stderr
    assert proc.stderr == "" and "Wrote" in proc.stdout and "501 samples" in proc.stdout
    comments, header = _comments(out)
    assert header == "t,u,y"
    text = "\n".join(comments)
    for words in ("# model: G(s) = 2 e^(-200 us s) / (1 ms s + 1)", "# plant-tf: K=2 tau=1m theta=200u",
                  "-> 1.5 V", "501 samples", "sigma 2 mV", "lsb: 1 mV", "# seed: 11", "ngspice"):
        assert words in text, words
    data = np.loadtxt(out, delimiter=",", comments="#", skiprows=len(comments) + 1)
    assert data.shape == (501, 3)
    assert np.allclose(np.diff(data[:, 0]), data[1, 0], rtol=1e-9)
    assert np.allclose(data[:, 1:] / 1e-3, np.round(data[:, 1:] / 1e-3), atol=1e-6)   # on the LSB grid
    # identify skips the '#' lines and reads t,u,y: the input's step, the model back
    got = identify(out, "--json")
    assert got.returncode == 0, got.stderr
    res = json.loads(got.stdout)
    assert res["capture"]["format"] == "generic" and res["capture"]["columns"] == ["t", "u", "y"]
    assert res["capture"]["input"] == "u" and res["capture"]["output"] == "y"
    assert res["preprocessing"]["step_amplitude"] == pytest.approx(1.5, rel=0.01)
    best = res["best"]
    assert best["model"] == "fopdt"
    assert best["params"]["K"] == pytest.approx(2.0, rel=0.01)
    assert best["params"]["tau_s"] == pytest.approx(1e-3, rel=0.03)
    # the default step falls between two samples, where identify puts it: the dead time to a fraction of one
    assert best["params"]["theta_s"] == pytest.approx(200e-6, abs=0.25 * data[1, 0])


@pytest.mark.spice
def test_identify_recovers_the_seed_motor(tmp_path):
    """The seed's own test: a = 2 V into the motor, identified back to Km and tau_m
    within 1 % (the seed's dc-motor method within 2 %), through the noise (10 mV rms
    on each channel, 0.4 % of W(inf))."""
    out = tmp_path / "motor.csv"
    proc = run("--plant-tf", MOTOR, "--step", "2", "--noise", "10m", "--seed", "0", "--out", out)
    assert proc.returncode == 0, proc.stderr
    got = identify(out, "--json")
    assert got.returncode == 0, got.stderr
    res = json.loads(got.stdout)
    best = res["best"]
    assert best["model"] == "fopdt", best
    assert best["params"]["K"] == pytest.approx(KM, rel=0.01)
    assert best["params"]["tau_s"] == pytest.approx(TAU_M, rel=0.01)
    # the seed's own dc-motor method (Km = W(inf)/a, tau_m from one point) finds it too
    dc = next(m for m in res["methods"] if m["name"] == "dc-motor")
    assert dc["valid"] and dc["params"]["K"] == pytest.approx(KM, rel=0.01)
    assert dc["params"]["tau_s"] == pytest.approx(TAU_M, rel=0.02)


@pytest.mark.spice
def test_the_same_seed_gives_the_same_file(tmp_path):
    args = ["--plant-tf", "K=1 fn=500 zeta=0.3 theta=100u", "--noise", "5m", "--lsb", "2m", "--points", "801"]
    with ThreadPoolExecutor(max_workers=3) as ex:
        procs = list(ex.map(lambda a: run(*a), [args + ["--seed", "7", "--out", tmp_path / "a.csv"],
                                                args + ["--seed", "7", "--out", tmp_path / "b.csv"],
                                                args + ["--seed", "8", "--out", tmp_path / "c.csv"]]))
    assert all(p.returncode == 0 for p in procs), [p.stderr for p in procs]
    a, b, c = ((tmp_path / n).read_bytes() for n in ("a.csv", "b.csv", "c.csv"))
    assert a == b
    assert a != c and b"# seed: 8" in c


@pytest.mark.spice
def test_both_backends_write_the_same_samples(tmp_path):
    for backend in ("pyspice", "ngspice-cli"):
        proc = run("--plant-tf", "K=50 tau=10m integrator theta=1m", "--points", "301", "--simulator", backend,
                   "--out", tmp_path / f"{backend}.csv")
        assert proc.returncode == 0, proc.stderr
    a, b = (np.loadtxt(tmp_path / f"{n}.csv", delimiter=",", comments="#", skiprows=8)
            for n in ("pyspice", "ngspice-cli"))
    assert np.allclose(a, b, rtol=1e-6, atol=1e-9)


def test_bad_input_is_one_line_exit_2_and_nothing_written(tmp_path):
    out = tmp_path / "x.csv"
    (tmp_path / "dir.csv").mkdir()
    ok = ["--plant-tf", "K=1 tau=1m", "--out", out]
    cases = {
        "no model": (["--out", out], "--plant-tf"),
        "no out": (["--plant-tf", "K=1 tau=1m"], "--out"),
        "model": (["--plant-tf", "K=1 tu=1m", "--out", out], "--plant-tf unknown key 'tu'"),
        "model range": (["--plant-tf", "K=1 tau=-1m", "--out", out], "--plant-tf"),
        "step": (ok + ["--step", "0"], f"--step must be {RANGES['step_v'].text()}"),
        "step text": (ok + ["--step", "abc"], "--step"),
        "points": (ok + ["--points", "5"], f"--points must be {RANGES['capture_points'].text()}"),
        "points whole": (ok + ["--points", "100.5"], "--points must be a whole number"),
        "noise": (ok + ["--noise", "-1m"], f"--noise must be {RANGES['noise_v'].text()}"),
        "lsb": (ok + ["--lsb", "1k"], f"--lsb must be {RANGES['lsb_v'].text()}"),
        "seed": (ok + ["--seed", "-1"], f"--seed must be {RANGES['seed'].text()}"),
        "seed whole": (ok + ["--seed", "0.5"], "--seed must be a whole number"),
        "duration": (ok + ["--duration", "0"], f"--duration must be {RANGES['capture_span_s'].text()}"),
        "too long": (ok + ["--duration", "1k"], "--duration 1 ks needs"),
        "step time": (ok + ["--step-time", "1"], "--step-time must be 0 or later and before the end"),
        "negative step time": (ok + ["--step-time", "-1m"], "--step-time must be 0 or later"),
        "simulator": (ok + ["--simulator", "spectre"], "invalid choice"),
        "out dir": (["--plant-tf", "K=1 tau=1m", "--out", tmp_path / "dir.csv"], "it is a directory"),
        "out empty": (["--plant-tf", "K=1 tau=1m", "--out", ""], "--out needs a file name"),
        "unknown": (ok + ["--frobnicate"], "unrecognized arguments"),
    }
    with ThreadPoolExecutor(max_workers=4) as ex:
        procs = list(ex.map(lambda a: run(*a), [a for a, _ in cases.values()]))
    for (key, (_, needle)), proc in zip(cases.items(), procs):
        assert proc.returncode == 2, (key, proc.stdout, proc.stderr)
        lines = proc.stderr.strip().splitlines()
        assert len(lines) == 1, (key, proc.stderr)
        assert lines[0].startswith("simulate-capture: error: ") and needle in lines[0], (key, lines[0])
        assert "Traceback" not in proc.stderr and proc.stdout == ""
    assert sorted(p.name for p in tmp_path.iterdir()) == ["dir.csv"]


def test_help_states_every_range():
    proc = run("--help")
    assert proc.returncode == 0
    text = " ".join(proc.stdout.split())
    for key in ("step_v", "capture_span_s", "capture_points", "noise_v", "lsb_v", "seed"):
        assert RANGES[key].text() in text, key
    assert "0 or later" in text and "simulation steps" in text and "examples:" in text
    assert "K tau [theta] (FOPDT)" in text   # the model forms, as design-pid's


@pytest.mark.spice
@pytest.mark.parametrize("tf, step, lsb, what", [
    ("K=1 tau=1m", "1", "10", "the input's step of 1 V"),       # the case: a record of zeros
    ("K=1 tau=1m", "1", "260m", "the input's step of 1 V"),     # 3.85 steps across it
    ("K=0.1 tau=1m", "1", "50m", "the output's swing of"),      # the input shows it, the output 2 steps
])
def test_an_lsb_too_coarse_for_the_step_is_refused(tmp_path, tf, step, lsb, what):
    """--lsb 10 on a 1 V step wrote a capture of zeros without a note: refused, one line saying the largest
    LSB that shows the step, nothing written."""
    from designer.spice.model_step import MIN_CODES
    out = tmp_path / "c.csv"
    proc = run("--plant-tf", tf, "--step", step, "--lsb", lsb, "--out", out)
    assert proc.returncode == 2 and proc.stdout == ""
    lines = proc.stderr.strip().splitlines()
    assert len(lines) == 1 and "Traceback" not in proc.stderr, proc.stderr
    assert lines[0].startswith("simulate-capture: error: --lsb ") and what in lines[0], lines[0]
    assert f"at least {MIN_CODES}" in lines[0] and "give --lsb at most" in lines[0] and "lsb_v" not in lines[0]
    assert list(tmp_path.iterdir()) == []


@pytest.mark.spice
def test_an_lsb_of_a_quarter_of_the_step_is_taken_and_shows_it(tmp_path):
    from designer.spice.model_step import MIN_CODES
    out = tmp_path / "c.csv"
    proc = run("--plant-tf", "K=1 tau=1m", "--step", "1", "--lsb", repr(1 / MIN_CODES), "--out", out)
    assert proc.returncode == 0 and proc.stderr == "", proc.stderr
    head, header = _comments(out)
    assert header == "t,u,y"
    _, u, y = np.loadtxt(out, delimiter=",", comments="#", skiprows=len(head) + 1).T
    for ch in (u, y):
        assert np.ptp(np.round(ch * MIN_CODES)) == MIN_CODES   # the step spans MIN_CODES codes


# --------------------------------------------------------------------------- --input (issue 28)

from designer.core import process_build as pb  # noqa: E402
from designer.identify.io import read_capture  # noqa: E402
from designer.identify.outputerror import fit_output_error  # noqa: E402

#: oe_captures' FOPDT and SOPDT with dead time (tests/oe_captures.py)
FOPDT_TF, FOPDT = "K=2 tau=1.3 theta=0.437", pb.fopdt(2.0, 1.3, 0.437)
SOPDT_TF, SOPDT = "K=1.5 poles=[2s+1, 0.5s+1] theta=0.33", pb.sopdt(1.5, 2.0, 0.5, 0.33)


def _recovered(path, kind, truth, hold):
    """identify's reader, then the output-error fit of the whole record (a log sweep's estimation
    part alone has only its low frequencies): the issue's tolerances (gain 2 %, time constants and
    dead time 5 %) against the true model."""
    cap = read_capture(path)
    assert cap.input_name == "u" and cap.u is not None
    fit = fit_output_error(cap.u, cap.y, float(cap.t[1] - cap.t[0]), kind, hold=hold)
    p, want = fit.params, truth.params
    assert fit.valid, p
    assert p["K"] == pytest.approx(want["K"], rel=0.02), p
    for key in ("tau_s", "tau1_s", "tau2_s", "theta_s"):
        if key in want:
            assert p[key] == pytest.approx(want[key], rel=0.05), (key, p)


@pytest.mark.spice
@pytest.mark.parametrize("tf, truth, kind, args, hold", [
    (FOPDT_TF, FOPDT, "fopdt", ["--input", "random-binary", "--switch-prob", "0.1"], "zoh"),
    (FOPDT_TF, FOPDT, "fopdt", ["--input", "random-binary", "--switch-prob", "0.5"], "zoh"),
    (SOPDT_TF, SOPDT, "sopdt", ["--input", "random-binary", "--switch-prob", "0.2"], "zoh"),
    (FOPDT_TF, FOPDT, "fopdt", ["--input", "prbs"], "zoh"),
    (SOPDT_TF, SOPDT, "sopdt", ["--input", "chirp"], "foh"),
])
def test_captures_under_other_inputs_give_the_plant_back(tmp_path, tf, truth, kind, args, hold):
    """Issue 28: simulate-capture --input ..., with a scope's noise and an 8-bit LSB, read back by
    identify's reader; the output-error fit recovers the plant within the issue's tolerances."""
    out = tmp_path / "c.csv"
    proc = run("--plant-tf", tf, *args, "--step", "2", "--noise", "10m", "--lsb", "7.8125m",
               "--seed", "5", "--out", out)
    assert proc.returncode == 0, proc.stderr
    comments, header = _comments(out)
    assert header == "t,u,y" and any(c.startswith("# input: " + args[1]) for c in comments)
    assert "# seed: 5" in "\n".join(comments)
    _recovered(out, kind, truth, hold)


@pytest.mark.spice
def test_a_recorded_input_file_is_played_as_held(tmp_path):
    """--input FILE: make-prbs' prbs.csv (time_s,value, each level from its time on) played to the plant;
    the capture's u is the file's level at every sample, and the plant comes back."""
    mk = subprocess.run([script("make-prbs"), "--bits", "7", "--clock", "1", "--amplitude", "1", "--offset", "1",
                         "--periods", "3", "--out", tmp_path / "seq"], capture_output=True, text=True, timeout=120)
    assert mk.returncode == 0, mk.stderr
    src = tmp_path / "seq" / "prbs.csv"
    out = tmp_path / "c.csv"
    proc = run("--plant-tf", FOPDT_TF, "--input", src, "--points", "3811", "--noise", "5m", "--seed", "2",
               "--out", out)
    assert proc.returncode == 0, proc.stderr
    ft, fv = np.loadtxt(src, delimiter=",", skiprows=1, unpack=True)
    data = np.loadtxt(out, delimiter=",", comments="#", skiprows=len(_comments(out)[0]) + 1)
    t, u = data[:, 0], data[:, 1]
    assert t[-1] == pytest.approx(ft[-1], rel=1e-12)            # the record to the file's last time
    level = fv[np.searchsorted(ft, t[1:], side="right") - 1]    # the level held from each time on
    assert np.std(u[1:] - level) == pytest.approx(0.005, rel=0.1)   # the noise, nothing else
    _recovered(out, "fopdt", FOPDT, "zoh")


@pytest.mark.spice
def test_the_input_s_draws_come_from_the_recorded_seed(tmp_path):
    a, b, c = (tmp_path / n for n in ("a.csv", "b.csv", "c.csv"))
    common = ["--plant-tf", FOPDT_TF, "--input", "random-binary", "--points", "1001", "--duration", "100"]
    for path, seed in ((a, 3), (b, 3), (c, 4)):
        assert run(*common, "--seed", seed, "--out", path).returncode == 0
    assert a.read_bytes() == b.read_bytes() and a.read_bytes() != c.read_bytes()
    assert "default_rng([3, 1])" in a.read_text()


@pytest.mark.spice
def test_the_factored_form_is_simulated_as_its_expansion(tmp_path):
    a, b = tmp_path / "a.csv", tmp_path / "b.csv"
    assert run("--plant-tf", "K=2 zeros=[-0.3s+1] poles=[(s+1)^2]", "--points", "501", "--out", a).returncode == 0
    assert run("--plant-tf", "num=[-0.6 2] den=[1 2 1]", "--points", "501", "--out", b).returncode == 0
    strip = [ln for ln in a.read_text().splitlines() if not ln.startswith("# plant-tf")]
    assert strip == [ln for ln in b.read_text().splitlines() if not ln.startswith("# plant-tf")]


def test_bad_inputs_of_other_kinds_are_one_line_and_write_nothing(tmp_path):
    out = tmp_path / "x.csv"
    ok = ["--plant-tf", "K=1 tau=1m", "--out", out]
    flat = tmp_path / "flat.csv"
    flat.write_text("time_s,value\n" + "".join(f"{i * 1e-3},1\n" for i in range(20)))
    early = tmp_path / "early.csv"
    early.write_text("".join(f"{(i - 2) * 1e-3},{i % 2}\n" for i in range(20)))
    cases = {
        "kind": (ok + ["--input", "sine"], "--input sine is neither step, prbs, random-binary nor chirp"),
        "clock for chirp": (ok + ["--input", "chirp", "--clock", "1k"], "--clock is for --input prbs or random-binary"),
        "step time": (ok + ["--input", "prbs", "--step-time", "1m"], "--step-time is for --input step"),
        "bits": (ok + ["--input", "random-binary", "--bits", "7"], "--bits is for --input prbs"),
        "prob": (ok + ["--input", "random-binary", "--switch-prob", "0"],
                 f"--switch-prob must be {RANGES['switch_probability'].text()}"),
        "f order": (ok + ["--input", "chirp", "--f-start", "1k", "--f-stop", "10"], "must be below --f-stop"),
        "f range": (ok + ["--input", "chirp", "--f-start", "0"], f"--f-start must be {RANGES['chirp_hz'].text()}"),
        "nyquist": (ok + ["--input", "chirp", "--f-stop", "100k", "--points", "1001"], "above a tenth of the sample rate"),
        "clock": (ok + ["--input", "prbs", "--clock", "0"], "--clock must be"),
        "integrating": (["--plant-tf", "K=5 tau=1m integrator", "--input", "prbs", "--out", out], "give --clock"),
        "flat file": (ok + ["--input", flat], "never moves"),
        "early file": (ok + ["--input", early], "times must be 0 or later"),
    }
    with ThreadPoolExecutor(max_workers=4) as ex:
        procs = list(ex.map(lambda a: run(*a), [a for a, _ in cases.values()]))
    for (key, (_, needle)), proc in zip(cases.items(), procs):
        assert proc.returncode == 2, (key, proc.stdout, proc.stderr)
        lines = proc.stderr.strip().splitlines()
        assert len(lines) == 1 and needle in lines[0] and "Traceback" not in proc.stderr, (key, lines)
    assert not out.exists()


def test_help_states_the_input_ranges():
    text = " ".join(run("--help").stdout.split())
    for key in ("switch_probability", "chirp_hz", "prbs_clock_hz"):
        assert RANGES[key].text() in text, key
    assert "--input KIND|FILE" in text and "random-binary" in text and "default_rng([--seed, 1])" in text
