"""``identify`` on broadband captures (a PRBS, noise): recognised through the
same importers as a step (generic, Tektronix MSO, Rigol), identified by
correlation and spectral analysis; its bad input refused in one line, exit 2."""

import json
import subprocess

import numpy as np
import pytest
from helpers import script

from prbs_capture import capture_csv, prbs_capture

EXE = script("identify")
UNDERDAMPED = ([6.0], [1.0, 0.8, 4.0])      # K 1.5, wn 2 rad/s, zeta 0.2


def run(*args):
    return subprocess.run([str(EXE), *map(str, args)], capture_output=True, text=True, timeout=180)


def one_line_error(proc, *words):
    assert proc.returncode == 2, proc.stderr
    assert proc.stdout == ""
    lines = proc.stderr.strip().splitlines()
    assert len(lines) == 1 and "Traceback" not in proc.stderr, proc.stderr
    for w in words:
        assert w in lines[0], lines[0]


@pytest.fixture(scope="module")
def capture(tmp_path_factory):
    t, u, y = prbs_capture(*UNDERDAMPED, bits=8, per_bit=10, periods=4, ts=0.02, snr_db=10,
                           adc_bits=8, seed=7, offset=1.0, amplitude=0.5, y_offset=0.2)
    return t, u, y, tmp_path_factory.mktemp("bb")


def _check_model(best):
    assert best["model"] == "underdamped"
    p = best["params"]
    assert p["wn_rad_s"] == pytest.approx(2.0, rel=0.03)
    assert p["zeta"] == pytest.approx(0.2, rel=0.03)
    assert p["K"] == pytest.approx(1.5, rel=0.03)


def test_generic_capture_json(capture):
    t, u, y, d = capture
    path = capture_csv(d / "generic.csv", t, u, y)
    proc = run(path, "--json")
    assert proc.returncode == 0, proc.stderr
    out = json.loads(proc.stdout)
    assert out["format"] == "broadband" and out["excitation"]["kind"] == "mls"
    assert out["excitation"]["bits"] == 8 and out["excitation"]["periods_used"] == 3
    assert out["capture"]["input"] == "CH1" and out["capture"]["output"] == "CH2"
    _check_model(out["best"])
    assert len(out["spectrum"]["coherence"]) == out["spectrum"]["points"]
    assert out["correlation"]["best"]["model"] == "underdamped"
    assert not out["impulse"]["wrapped"]


def test_tektronix_mso_and_rigol_layouts(capture):
    t, u, y, d = capture
    tek = d / "tek.csv"
    with open(tek, "w") as fh:
        fh.write("Model,MSO54\nFirmware Version,1.0\n\nTIME,CH1,CH2\n")
        for row in zip(t, u, y):
            fh.write(",".join(f"{v:.6g}" for v in row) + "\n")
    rigol = d / "rigol.csv"
    with open(rigol, "w") as fh:
        fh.write("X,CH1,CH2,Start,Increment,\n")
        fh.write(f"Sequence,Volt,Volt,0,{t[1] - t[0]:.9g},\n")
        for i, (a, b) in enumerate(zip(u, y)):
            fh.write(f"{i},{a:.5g},{b:.5g},\n")
    for path, fmt in ((tek, "tektronix-mso"), (rigol, "rigol")):
        proc = run(path, "--json")
        assert proc.returncode == 0, proc.stderr
        out = json.loads(proc.stdout)
        assert out["capture"]["format"] == fmt
        _check_model(out["best"])


def test_text_plot_and_method(capture):
    t, u, y, d = capture
    path = capture_csv(d / "text.csv", t, u, y)
    proc = run(path, "--plot", d / "bb.png", "--method", "correlation")
    assert proc.returncode == 0, proc.stderr
    assert "Broadband input: maximum-length sequence, 8 bits (N = 255)" in proc.stdout
    assert "== correlation" in proc.stdout and "== spectral" not in proc.stdout
    assert "Best (correlation)" in proc.stdout
    assert (d / "bb.png").read_bytes()[:8] == b"\x89PNG\r\n\x1a\n"


def test_step_capture_with_method_goes_to_the_step_methods(tmp_path):
    t = np.linspace(0, 10, 2000)
    u = (t >= 1).astype(float)
    y = np.where(t >= 1, 1 - np.exp(-(t - 1)), 0.0)
    path = capture_csv(tmp_path / "step.csv", t, u, y, header="t,u,y")
    proc = run(path, "--method", "spectral")
    assert proc.returncode == 0, proc.stderr
    assert "--method spectral ignored: the input is not broadband" in proc.stdout


def test_bad_broadband_input(capture, tmp_path):
    t, u, y, d = capture
    short = capture_csv(tmp_path / "short.csv", t[:300 * 10], u[:300 * 10], y[:300 * 10])
    one_line_error(run(short), "maximum-length sequence of 8 bits", "at least 2 whole ones")
    # a clock of 2.5 sample intervals
    odd = capture_csv(tmp_path / "odd.csv", t[::4][: len(t) // 4], u[::4][: len(t) // 4],
                      y[::4][: len(t) // 4])
    one_line_error(run(odd), "not a whole number of sample intervals")
    full = capture_csv(tmp_path / "full.csv", t, u, y)
    one_line_error(run(full, "--step-time", "1"), "--step-time is for a step capture")
    one_line_error(run(full, "--method", "fourier"), "--method")


def test_json_is_a_plant_model_for_design_pid_and_make_prbs(capture, tmp_path):
    t, u, y, d = capture
    path = capture_csv(tmp_path / "c.csv", t, u, y)
    proc = run(path, "--json")
    assert proc.returncode == 0, proc.stderr
    models = tmp_path / "models.json"
    models.write_text(proc.stdout)
    from designer.pid.plant_source import model_from_json
    m = model_from_json(models)
    assert m.kind == "underdamped" and m.params["zeta"] == pytest.approx(0.2, rel=0.03)
    again = subprocess.run([script("make-prbs"), "--for-plant", "--plant-model", str(models), "--no-files"],
                           capture_output=True, text=True, timeout=60)
    assert again.returncode == 0, again.stderr
    assert "Plant: G(s)" in again.stdout


def test_build_sheet_folder(capture, tmp_path):
    t, u, y, d = capture
    path = capture_csv(tmp_path / "c.csv", t, u, y)
    out = tmp_path / "sheet"
    proc = run(path, "--out", out)
    assert proc.returncode == 0, proc.stderr
    assert sorted(p.name for p in out.iterdir()) == ["build-sheet.md", "identify.png", "result.json", "spectrum.csv"]
    assert "![data and models](identify.png)" in (out / "build-sheet.md").read_text()
    assert json.loads((out / "result.json").read_text())["format"] == "broadband"
    # the spectral estimate is a table identify-freq reads
    freq = subprocess.run([script("identify-freq"), str(out / "spectrum.csv"), "--json"], capture_output=True,
                          text=True, timeout=120)
    assert freq.returncode == 0, freq.stderr
    assert json.loads(freq.stdout)["best"]["params"]["zeta"] == pytest.approx(0.2, rel=0.03)
    (tmp_path / "afile").write_text("x")
    one_line_error(run(path, "--out", tmp_path / "afile"), "is a file, not a folder")


def test_a_corrupted_m_sequence_is_named_for_what_it_is(tmp_path):
    """Issue 25, 5c: 3 bits flipped in every period: not "a maximum-length sequence, 9 bits"."""
    t, u, y = prbs_capture([2.0], [20e-3, 1.0], bits=9, per_bit=4, periods=4, ts=1e-4, snr_db=40, seed=1,
                           flip=(17, 200, 401))
    path = capture_csv(tmp_path / "flipped.csv", t, u, y)
    proc = run(path)
    assert proc.returncode == 0, proc.stderr
    assert "maximum-length sequence, 9 bits" not in proc.stdout
    assert ("Broadband input: a binary sequence of 511 intervals a period, not maximum-length (3 bits of each "
            "period differ from the nearest 9-bit m-sequence)") in proc.stdout
    out = json.loads(run(path, "--json").stdout)
    assert out["excitation"]["kind"] == "periodic" and out["excitation"]["bits_differing_from_mls"] == 3
    one_line_error(run(path, "--method", "correlation"), "3 bits of each period differ", "--method spectral")


def test_a_three_level_sequence_is_named(tmp_path):
    """Issue 25, item 10: a three-level sequence into a plant was "no step in the input column: it
    never moves"; one line now says what it is and what identify takes, input named or by position."""
    rng = np.random.default_rng(0)
    u = np.repeat(np.tile(rng.integers(-1, 2, 242).astype(float), 4), 4)
    y = np.convolve(u, np.full(40, 1 / 40))[:u.size]
    t = np.arange(u.size) * 1e-4
    for header in ("t,u,y", "t,CH1,CH2"):
        path = capture_csv(tmp_path / f"{header[2:4]}.csv", t, u, y, header=header)
        one_line_error(run(path), "the input is a three-level sequence (levels -1, 0, 1)", "two-level sequence")
