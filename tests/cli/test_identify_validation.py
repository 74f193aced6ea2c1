"""``identify`` scores every route's models on validation data (issue 28): the
JSON's ``validation`` and ``output_error``, the text's table, ``--validate``,
``--segment-length``, their bad input in one line (exit 2); ``design-pid
--plant-capture`` tunes for the best validation fit, and on the dryer its loop
agrees with the same controller around an ARX[2 2 3] within 2 pp of overshoot."""

import json
import subprocess

import numpy as np
import pytest
from scipy import signal as sig
from scipy.linalg import logm

from designer.identify.validation import arx_fit
from helpers import EXT_CAPTURES, script
from cli.test_identify_broadband import one_line_error

IDENTIFY = script("identify")
DESIGN_PID = script("design-pid")
DRYER = EXT_CAPTURES / "daisy_dryer.dat"
TS = 0.08


def run(exe, *args):
    return subprocess.run([str(exe), *map(str, args)], capture_output=True, text=True, timeout=300)


def write_csv(path, t, u, y):
    path.write_text("t,u,y\n" + "\n".join(f"{a:.9g},{b:.9g},{c:.9g}" for a, b, c in zip(t, u, y)) + "\n")
    return path


def random_binary(n, p, seed):
    """A random binary signal switching with probability ``p`` each sample (seeded)."""
    rng = np.random.default_rng(seed)
    return np.where(np.cumsum(rng.random(n) < p) % 2 == 0, 1.0, -1.0)


@pytest.fixture(scope="module")
def fopdt_rbs(tmp_path_factory):
    """K 2, tau 0.5 s, theta 0.15 s under a random binary input switching with
    probability 0.2, sampled every 20 ms, noise at about 30 dB SNR (seed 28)."""
    n, ts = 3000, 0.02
    u = 1.0 + random_binary(n, 0.2, 28)
    b, a, _ = sig.cont2discrete(([2.0], [0.5, 1.0]), ts, method="zoh")
    d = int(round(0.15 / ts))
    y = sig.lfilter(np.squeeze(b), a, np.r_[np.full(d, u[0]), u[:-d]] - u[0])
    y += np.random.default_rng(29).normal(0.0, 0.03 * np.std(y), n)
    t = np.arange(n) * ts
    folder = tmp_path_factory.mktemp("val")
    return t, u, y, folder


def test_every_route_in_the_json_and_the_text(fopdt_rbs):
    t, u, y, folder = fopdt_rbs
    path = write_csv(folder / "rbs.csv", t, u, y)
    p = run(IDENTIFY, path, "--json")
    assert p.returncode == 0, p.stderr
    d = json.loads(p.stdout)
    v = d["validation"]
    assert v["scope"] == "split" and v["split"]["estimation"] == [0, 2000]
    assert {m["route"] for m in v["models"]} >= {"correlation", "output-error"}
    assert all(f["route"] == "output-error" for f in d["output_error"])
    best = v["best"]
    assert best["valid"] and best["validation"]["fit_percent"] > 90
    assert best["process_model"]["gain"] == pytest.approx(2.0, rel=0.03)
    # the older keys stay
    for key in ("format", "excitation", "methods", "best", "notes"):
        assert key in d
    assert d["input_whiteness"]["kind"] == "coloured" and d["input_whiteness"]["prewhitened"]
    text = run(IDENTIFY, path)
    assert text.returncode == 0, text.stderr
    assert "== validation" in text.stdout and "Best by validation fit: " in text.stdout
    assert "estimation samples 0-1999" in text.stdout and "output-error" in text.stdout


def test_validate_with_a_second_record(fopdt_rbs):
    t, u, y, folder = fopdt_rbs
    first = write_csv(folder / "first.csv", t[:1500], u[:1500], y[:1500])
    # the second record sampled twice as fast (every other sample is the capture's)
    tt = np.arange(2 * 1500) * 0.01
    uu, yy = np.repeat(u[1500:], 2), np.repeat(y[1500:], 2)
    second = write_csv(folder / "second.csv", tt, uu, yy)
    p = run(IDENTIFY, first, "--validate", second, "--json")
    assert p.returncode == 0, p.stderr
    v = json.loads(p.stdout)["validation"]
    assert v["scope"] == "separate" and "every 2" in v["split_note"]
    assert v["best"]["validation"]["samples"] == 1500
    # another rate that is no whole multiple: refused in one line
    odd = write_csv(folder / "odd.csv", np.arange(1000) * 0.03, u[:1000], y[:1000])
    one_line_error(run(IDENTIFY, first, "--validate", odd), "not a whole multiple")


def test_bad_input_one_line(fopdt_rbs, tmp_path):
    t, u, y, _ = fopdt_rbs
    flat = write_csv(tmp_path / "flat.csv", t, np.full(t.size, 1.5), y)
    one_line_error(run(IDENTIFY, flat), "nothing to identify")
    rbs = write_csv(tmp_path / "rbs.csv", t, u, y)
    one_line_error(run(IDENTIFY, rbs, "--segment-length", "5"), "--segment-length")
    step = write_csv(tmp_path / "step.csv", t, np.where(t > 1, 1.0, 0.0), np.where(t > 1, 1 - np.exp(-(t - 1)), 0))
    one_line_error(run(IDENTIFY, step, "--segment-length", "256"), "segment length")


def test_segment_length_chooses_the_welch_segment(fopdt_rbs):
    t, u, y, folder = fopdt_rbs
    path = write_csv(folder / "seg.csv", t, u, y)
    p = run(IDENTIFY, path, "--segment-length", "512", "--json")
    assert p.returncode == 0, p.stderr
    d = json.loads(p.stdout)
    assert d["segment_length"]["samples"] == 512 and "given" in d["segment_length"]["note"]
    # the lowest frequency kept: the segment's first or second bin (log bands, coherence)
    assert d["spectrum"]["f_min_hz"] <= 1.01 * 2 / (512 * 0.02)
    assert len(d["spectrum"]["coherence"]) == d["spectrum"]["points"]


@pytest.fixture(scope="module")
def dryer(tmp_path_factory):
    if not DRYER.exists():
        pytest.skip(f"the DaISy dryer data is not at {DRYER} (../shared/ext-captures beside the repository)")
    d = np.loadtxt(DRYER)
    u, y = d[:, 0], d[:, 1]
    t = np.arange(u.size) * TS
    return u, y, write_csv(tmp_path_factory.mktemp("dryer") / "dryer.csv", t, u, y)


def arx_continuous(arx, ts: float, hold: str):
    """An ARX model as N(s)/D(s) e^(-theta s): the rational part from its
    sampled form by the zero-order-hold inverse (A = logm(Phi)/T, B = (Phi -
    I)^-1 A Gamma), theta its nk - 1 whole samples, plus half a sample when the
    record was read with a first-order hold (its ramp is centred half a sample
    later than the held step)."""
    na, nb, nk = arx.orders
    Ad, Bd, Cd, _ = sig.tf2ss(arx.b[nk:nk + nb], arx.a)
    Ac = np.real(logm(Ad)) / ts
    Bc = np.linalg.solve(Ad - np.eye(Ad.shape[0]), Ac @ Bd)
    num, den = sig.ss2tf(Ac, Bc, Cd, np.zeros((1, 1)))
    return np.trim_zeros(np.squeeze(num), "f"), den, (nk - 1) * ts + (0.5 * ts if hold == "foh" else 0.0)


def test_design_pid_on_the_dryer_agrees_with_the_arx_loop(dryer, tmp_path):
    from designer.pid.delayloop import SIM_N_FILTER, closed_loop_step, pid_tf
    u, y, path = dryer
    ident = run(IDENTIFY, path, "--json")
    assert ident.returncode == 0, ident.stderr
    v = json.loads(ident.stdout)["validation"]
    p = run(DESIGN_PID, "--plant-capture", path, "--json", "--no-files", "--no-sim")
    assert p.returncode == 0, p.stderr
    d = json.loads(p.stdout)
    # it tunes for identify's best validation fit across every route
    assert d["plant"]["model"]["source"] == v["best"]["process_model"]["source"] + " (dryer.csv)"
    tun = d["tuning"]
    ctrl = pid_tf(tun["kp"], tun["ti_s"], tun["td_s"], SIM_N_FILTER)
    k = v["split"]["estimation"][1]
    arx = arx_fit(u[:k], y[:k], 2, 2, 3)
    t = np.linspace(0.0, 8.0, 4001)
    yy = closed_loop_step(arx_continuous(arx, TS, v["hold"]), ctrl, t, 1.0)["y"]
    arx_overshoot = 100.0 * (yy.max() - 1.0)
    assert d["closed_loop"]["ideal_pid"]["overshoot_pct"] == pytest.approx(arx_overshoot, abs=2.0)


def test_a_chirp_capture_is_identified_by_output_error(tmp_path):
    """K 2, tau 0.5 s, theta 0.15 s under a sine sweep (0.05 to 2 Hz, 0 to 2 V,
    sampled every 20 ms, noise at about 30 dB SNR, seeded): no step, no
    sequence; identify exits 0 with the output-error route alone, its best model
    within 2 % (gain) and 5 % (lag, dead time) of the plant, and says why the
    other routes were skipped."""
    n, ts, fine = 3000, 0.02, 10
    tf = np.arange((n - 1) * fine + 1) * (ts / fine)

    def sweep(x):
        return 1.0 - np.cos(2 * np.pi * 0.05 * 60.0 * np.expm1(np.asarray(x) * np.log(40.0) / 60.0) / np.log(40.0))

    ud = np.where(tf >= 0.15, sweep(tf - 0.15), sweep(0.0 * tf))
    _, y, _ = sig.lsim(([2.0], [0.5, 1.0]), ud - ud[0], tf)
    y = y[::fine]
    y = y + np.random.default_rng(30).normal(0.0, 0.03 * np.std(y), n)
    t = np.arange(n) * ts
    path = write_csv(tmp_path / "chirp.csv", t, sweep(t), y)
    r = run(IDENTIFY, path, "--json")
    assert r.returncode == 0, r.stderr
    d = json.loads(r.stdout)
    assert d["excitation"]["kind"] == "other"
    v = d["validation"]
    assert set(v["skipped"]) >= {"step", "correlation", "spectral"}
    best = v["best"]
    assert best["route"] == "output-error" and best["model"] == "fopdt", best
    assert best["params"]["K"] == pytest.approx(2.0, rel=0.02)
    assert best["params"]["tau_s"] == pytest.approx(0.5, rel=0.05)
    assert best["params"]["theta_s"] == pytest.approx(0.15, rel=0.05)
    text = run(IDENTIFY, path, "--plot", tmp_path / "fit.png")
    assert text.returncode == 0 and "output-error fit alone" in text.stdout, text.stderr
    assert text.stderr == "" and (tmp_path / "fit.png").stat().st_size > 0    # no warning lines


#: a plant under a logarithmic sweep (simulate-capture --input chirp, seeded): an input only output error reads
CHIRP_ARGS = ("--plant-tf", "K=2 tau=1.3 theta=0.437", "--input", "chirp", "--step", "2", "--noise", "10m",
              "--seed", "5", "--points", "1200")


def chirp_capture(folder):
    """simulate-capture's chirp capture (ngspice) in ``folder``; its path."""
    path = folder / "chirp.csv"
    r = run(script("simulate-capture"), *CHIRP_ARGS, "--out", path)
    assert r.returncode == 0, r.stderr
    return path


def record_expected(a, u, y):
    """The assessment's own simulation of each valid model, best first (assess's public API: the models
    simulated from the record's start at the assessment's interval and hold, raised to the validation
    part's mean), and each one's fit on the validation part, as compare scores it."""
    from designer.identify.outputerror import simulate
    from designer.identify.validation import compare_fit
    val = a.split.validation
    out = []
    for c in sorted((c for c in a.candidates if c.valid), key=lambda c: -c.fit_percent)[:3]:
        ym = simulate(c.model, u - u[0], a.sample_time_s, a.hold)
        ym = ym + y[val].mean() - ym[val].mean()
        out.append((c, ym, compare_fit(y[val] - y[val].mean(), ym[val] - ym[val].mean())))
    return out


@pytest.mark.spice
def test_a_chirp_capture_is_drawn_with_its_best_models(tmp_path):
    """Issues 28/29: an input only the output-error route reads is drawn as the record with its best valid
    models simulated under the recorded input (not empty estimate axes): identify --plot writes the PNG
    without a warning line, and the view's series are the assessment's own simulation, scored as it was."""
    from designer.identify.assess import identify_record
    from designer.identify.io import read_capture
    path = chirp_capture(tmp_path)
    r = run(IDENTIFY, path, "--plot", tmp_path / "fit.png")
    assert r.returncode == 0 and r.stderr == "", r.stderr
    assert (tmp_path / "fit.png").read_bytes()[:8] == b"\x89PNG\r\n\x1a\n"
    cap = read_capture(path)
    result = identify_record(cap.t, cap.y, cap.u)
    a, view = result.assessment, result.assessment.view
    assert result.excitation.kind == "other" and a.scope == "split" and a.decimated_by == 1
    assert view.validation_start_s == cap.t[a.split.n_est]
    np.testing.assert_array_equal(view.y, cap.y)
    expected = record_expected(a, cap.u, cap.y)
    assert [m.label for m in view.models] == [f"{c.route} {c.name} ({c.kind}), validation fit {c.fit_percent:.1f} %"
                                             for c, _, _ in expected]
    assert view.models and view.models[0].fit_percent == a.best_candidate.fit_percent
    for m, (c, ym, fit) in zip(view.models, expected):
        np.testing.assert_allclose(m.y, ym, rtol=1e-12, atol=1e-12)
        assert fit == pytest.approx(c.fit_percent, rel=1e-9)    # the line drawn is the one scored
