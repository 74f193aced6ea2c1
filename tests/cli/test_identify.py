"""The installed ``identify`` console script: JSON shape, table, plot, --against, bad input."""

import json
import math
import subprocess
from concurrent.futures import ThreadPoolExecutor

import numpy as np
import pytest
from helpers import FIXTURES, script

from designer.identify.against import overshoot_from_zeta
from designer.identify.structures import model_step
from designer.plant.sallenkey import fn_zeta as sallen_key

EXE = script("identify")
FIX = FIXTURES / "identify"
TRUTH = json.loads((FIX / "truth.json").read_text())


def run(*args, cwd=None):
    return subprocess.run([str(EXE), *map(str, args)], capture_output=True, text=True,
                          cwd=cwd, timeout=120)


def run_many(arglists, cwd=None):
    with ThreadPoolExecutor(max_workers=4) as ex:
        return list(ex.map(lambda a: run(*a, cwd=cwd), arglists))


def _second_order(params):
    """(fn, zeta) of the truth or of a model's params."""
    if "wn_rad_s" in params:
        return params["wn_rad_s"] / (2 * math.pi), params["zeta"]
    return None


@pytest.fixture(scope="module")
def json_runs():
    names = ["generic_ty.csv", "generic_tuy_semicolon.csv", "waveform.csv",
             "tektronix_tds.csv", "tektronix_mso.csv", "rigol_square.csv"]
    args = []
    for n in names:
        extra = ["--step-amplitude", "2"] if n == "tektronix_tds.csv" else []
        args.append([FIX / n, "--json", *extra])
    return dict(zip(names, run_many(args)))


def test_json_shape_and_best_model_for_every_fixture(json_runs):
    for name, proc in json_runs.items():
        assert proc.returncode == 0, (name, proc.stderr)
        out = json.loads(proc.stdout)
        assert {"methods", "best", "preprocessing"} <= set(out)
        for m in out["methods"]:
            assert {"name", "model", "params", "iae", "ise", "valid", "note"} <= set(m)
            assert m["model"] in ("fopdt", "double-pole", "underdamped", "overdamped")
            assert m["name"] == m["name"].lower()
        best = out["best"]
        assert best["valid"] and best in out["methods"]
        valid_iae = [m["iae"] for m in out["methods"] if m["valid"] and m["iae"] is not None]
        assert best["iae"] == min(valid_iae)
        truth = TRUTH[name]
        assert best["params"]["K"] == pytest.approx(truth["params"]["K"], rel=0.02), name
        fz = _second_order(truth["params"])
        if fz:  # the seed 001 plant: fn and zeta within 2 %
            assert best["model"] == "underdamped", name
            fn, z = _second_order(best["params"])
            assert fn == pytest.approx(fz[0], rel=0.02) and z == pytest.approx(fz[1], rel=0.03)
        else:
            # FOPDT or overdamped truth: the best fit's step response matches the truth
            t = np.linspace(0, 10 * sum(v for k, v in truth["params"].items() if k != "K"), 2000)
            yt = model_step(truth["model"], truth["params"], t)
            yb = model_step(best["model"], best["params"], t)
            assert np.max(np.abs(yt - yb)) < 0.02 * truth["params"]["K"], name


def test_rigol_square_wave_is_split(json_runs):
    out = json.loads(json_runs["rigol_square.csv"].stdout)
    pre = out["preprocessing"]
    # two periods: the rising edges at 0 and 3.03 ms averaged, the falling ones
    # kept apart (the one at 4.5 ms has no full half period after it)
    assert pre["steps_averaged"] == pre["rising_edges"] == 2 and pre["falling_edges"] == 1
    assert pre["step_amplitude"] == pytest.approx(2.0, rel=0.01)
    # the seed's bench figures: overshoot ~ 52.7 %, peak time ~ 146 us (analytic)
    meas = out["measured"]
    assert meas["overshoot_pct"] == pytest.approx(overshoot_from_zeta(0.2), abs=1.5)


def test_table_and_plot(tmp_path):
    png = tmp_path / "fit.png"
    proc = run(FIX / "waveform.csv", "--plot", png, "--methods", "smith,least-squares", "chen-yang")
    assert proc.returncode == 0, proc.stderr
    assert "ranked by IAE" in proc.stdout and "Best: least-squares (underdamped)" in proc.stdout
    names = {ln.split()[1] for ln in proc.stdout.splitlines()
             if ln[:4].strip().isdigit() and len(ln.split()) > 2}
    assert names == {"smith", "least-squares", "chen-yang"}
    assert png.read_bytes()[:8] == b"\x89PNG\r\n\x1a\n"
    assert [p.name for p in tmp_path.iterdir()] == ["fit.png"]   # no temp files left


def _design(tmp_path, scale=1.0):
    """A design-plant result.json for the seed's rounded parts (820, 1k, 10n, 220n)."""
    r1, r2, c1, c2 = 820.0, 1000.0, 10e-9, 220e-9
    fn, z = sallen_key(r1, r2, c1, c2)
    d = {"spec": {"fc_hz": 3500.0, "zeta": 0.2, "gain": 1.0},
         "built": {"R1_ohm": r1, "R2_ohm": r2, "C1_f": c1, "C2_f": c2, "fn_hz": fn * scale,
                   "zeta": z, "q": 1 / (2 * z)},
         "spice": {"overshoot_pct": overshoot_from_zeta(z), "peak_time_s": None,
                   "rise_time_s": None, "settling_time_s": None}}
    if scale != 1.0:
        del d["built"]["R1_ohm"]   # no parts: band from the nominal fn, zeta
    path = tmp_path / f"result_{scale}.json"
    path.write_text(json.dumps(d))
    return path


def test_against_a_design(tmp_path):
    """The waveform fixture is the seed's unrounded design (3500 Hz, 0.2); the rounded
    parts give ~3747 Hz and ~0.214: inside the 5 % R / 10 % C band."""
    ok, far = run_many([[FIX / "waveform.csv", "--json", "--against", _design(tmp_path)],
                        [FIX / "waveform.csv", "--against", _design(tmp_path, 2.0)]])
    assert ok.returncode == 0, ok.stderr
    c = json.loads(ok.stdout)["comparison"]
    q = c["quantities"]
    assert set(q) == {"fn_hz", "zeta", "gain", "overshoot_pct"}
    fn_built = sallen_key(820.0, 1000.0, 10e-9, 220e-9)[0]
    assert q["fn_hz"]["identified"] == pytest.approx(3500.0, rel=0.01)
    assert q["fn_hz"]["difference_pct"] == pytest.approx(100 * (3500 / fn_built - 1), abs=1.0)
    assert all(v["within_tolerance"] for v in q.values())
    assert "tolerances explain" in c["verdict"] and "5 % R / 10 % C" in c["tolerance_basis"]
    assert far.returncode == 0, far.stderr
    assert "OUTSIDE" in far.stdout and "do not explain" in far.stdout


def test_help_teaches():
    proc = run("--help")
    assert proc.returncode == 0
    assert "examples:" in proc.stdout and "--against" in proc.stdout


def test_bad_input_exit_2_with_one_line(tmp_path):
    t = np.linspace(0, 1, 400)
    good = model_step("fopdt", {"K": 1, "tau_s": 0.05, "theta_s": 0.1}, t)
    files = {
        "empty.csv": "",
        "words.csv": "t,y\n" + "".join(f"{a},{b}\n" for a, b in zip(t, good)).replace(
            "\n0.5", "\nhalf", 1),
        "nan.csv": "".join(f"{a},{'nan' if i == 50 else b}\n" for i, (a, b) in enumerate(zip(t, good))),
        "time.csv": "".join(f"{a if i != 60 else 0.0},{b}\n" for i, (a, b) in enumerate(zip(t, good))),
        "flat.csv": "".join(f"{a},1.0\n" for a in t),
        "small.csv": "".join(f"{a},{1e-3 * b + 0.01 * np.sin(1e4 * a * (i % 7))}\n"
                             for i, (a, b) in enumerate(zip(t, good))),
        "unsettled.csv": "".join(f"{a},{b}\n" for a, b in zip(t[:60], good[:60])),
    }
    for name, text in files.items():
        (tmp_path / name).write_text(text)
    good_path = tmp_path / "good.csv"
    good_path.write_text("".join(f"{a},{b}\n" for a, b in zip(t, good)))
    (tmp_path / "notjson.json").write_text("{")
    cases = {
        "empty.csv": ([tmp_path / "empty.csv"], "empty"),
        "words.csv": ([tmp_path / "words.csv"], "is not a number"),
        "nan.csv": ([tmp_path / "nan.csv"], "NaN"),
        "time.csv": ([tmp_path / "time.csv"], "time is not increasing"),
        "flat.csv": ([tmp_path / "flat.csv"], "no usable step"),
        "small.csv": ([tmp_path / "small.csv"], "noise standard deviations"),
        "unsettled.csv": ([tmp_path / "unsettled.csv"], "before the response settles"),
        "missing": ([tmp_path / "missing.csv"], "does not exist"),
        "amp": ([good_path, "--step-amplitude", "abc"], "step-amplitude"),
        "amp0": ([good_path, "--step-amplitude", "0"], "non-zero"),
        "method": ([good_path, "--methods", "magic"], "unknown method"),
        "against": ([good_path, "--against", tmp_path / "notjson.json"], "not JSON"),
        "option": ([good_path, "--frobnicate"], "unrecognized arguments"),
        "noarg": ([], "required"),
    }
    procs = run_many([a for a, _ in cases.values()])
    for (key, (_, needle)), proc in zip(cases.items(), procs):
        assert proc.returncode == 2, (key, proc.stdout, proc.stderr)
        lines = proc.stderr.strip().splitlines()
        assert len(lines) == 1, (key, proc.stderr)
        assert lines[0].startswith("identify: error:") and needle in lines[0], (key, lines[0])
        assert "Traceback" not in proc.stderr and proc.stdout == ""


def test_agreement_band_contains_every_part_combination():
    """Brute force: random parts inside the 5 % R / 10 % C box stay inside the corner band."""
    from designer.identify.against import agreement_band
    r1, r2, c1, c2 = 820.0, 1000.0, 10e-9, 220e-9
    fn, z = sallen_key(r1, r2, c1, c2)
    band = agreement_band({"R1_ohm": r1, "R2_ohm": r2, "C1_f": c1, "C2_f": c2, "fn_hz": fn,
                           "zeta": z})
    rng = np.random.default_rng(0)
    k = rng.uniform(-1, 1, (2000, 4)) * [0.05, 0.05, 0.1, 0.1] + 1
    got = np.array([sallen_key(r1 * a, r2 * b, c1 * c, c2 * d) for a, b, c, d in k])
    assert band.fn_hz[0] <= got[:, 0].min() and got[:, 0].max() <= band.fn_hz[1]
    assert band.zeta[0] <= got[:, 1].min() and got[:, 1].max() <= band.zeta[1]
    # and the corners are attained (the band is not padded)
    assert got[:, 0].max() > band.fn_hz[0] + 0.8 * (band.fn_hz[1] - band.fn_hz[0])
    # without part values the nominal scaling gives the same fn band (fn ~ 1/sqrt(RRCC))
    nominal = agreement_band({"fn_hz": fn, "zeta": z})
    assert nominal.fn_hz == pytest.approx(band.fn_hz, rel=1e-12)


def test_agreement_band_with_gain_is_the_closed_form_at_the_gain_extremes():
    """Brute force: with gain K the band is the plant's fn and zeta (seed 001's closed forms) over the
    network's 16 corners at K's two extremes, 1 + (K - 1)(1 -+ t)/(1 +- t), to the bit: the section's
    corners (its gain pair's too) give nothing outside them."""
    import itertools

    from designer.identify.against import agreement_band
    from designer.plant.design import choose_parts
    from designer.plant.sallenkey import fn_zeta
    from designer.plant.spec import PlantSpec
    for gain, fc, zeta in ((2.5, 1e3, 0.5), (1.5, 3.5e3, 0.3)):
        built = choose_parts(PlantSpec(fc_hz=fc, zeta=zeta, gain=gain)).built
        rt, ct = 0.01, 0.05
        ks = (1 + (gain - 1) * (1 - rt) / (1 + rt), 1 + (gain - 1) * (1 + rt) / (1 - rt))
        got = [fn_zeta(built.r1 * (1 + a * rt), built.r2 * (1 + b * rt), built.c1 * (1 + c * ct),
                       built.c2 * (1 + d * ct), k) for a, b, c, d in itertools.product((-1, 1), repeat=4) for k in ks]
        band = agreement_band(built.as_dict(), gain, rt, ct)
        assert band.fn_hz == (min(g[0] for g in got), max(g[0] for g in got))
        assert band.zeta == (min(g[1] for g in got), max(g[1] for g in got))
        assert band.gain[0] < gain < band.gain[1] and band.basis == "corners of the built parts"


def test_a_band_whose_corners_run_away_has_an_unbounded_overshoot():
    """Bug: a design whose gain puts its tolerance corners past zeta = -1 (two real right-half-plane poles)
    raised a math domain error (a traceback from identify --against); the overshoot there is unbounded, the
    formula's own limit as zeta falls to -1."""
    import math

    from designer.identify.against import agreement_band
    assert overshoot_from_zeta(-1.0) == math.inf and overshoot_from_zeta(-1 + 1e-9) > 1e10
    built = {"R1_ohm": 10e3, "R2_ohm": 10e3, "C1_f": 10e-9, "C2_f": 10e-9, "fn_hz": 1591.5, "zeta": 0.5}
    band = agreement_band(built, 10.0)
    assert band.zeta[1] < -1 and band.overshoot_pct == (math.inf, math.inf)


def test_help_states_every_numeric_range():
    from designer.core.fileio import MAX_CAPTURE_BYTES, MAX_CAPTURE_ROWS, size_text
    from designer.core.ranges import RANGES
    out = " ".join(run("--help").stdout.split())
    for key in ("capture_time_s", "step_amplitude", "capture_span_s", "capture_value",
                "output_step"):
        assert RANGES[key].text() in out, key
    assert size_text(MAX_CAPTURE_BYTES) in out and f"{MAX_CAPTURE_ROWS:,}" in out


def test_step_options_outside_their_range_are_one_line(tmp_path):
    from designer.core.ranges import RANGES
    good = tmp_path / "good.csv"
    t = np.linspace(0, 1, 400)
    good.write_text("".join(f"{a},{b}\n" for a, b in zip(
        t, model_step("fopdt", {"K": 1, "tau_s": 0.05, "theta_s": 0.1}, t))))
    cases = [(["--step-time", "1e300"], RANGES["capture_time_s"].text()),
             (["--step-time", "-1e300"], RANGES["capture_time_s"].text()),
             (["--step-amplitude", "1e-300"], RANGES["step_amplitude"].text()),
             (["--step-amplitude", "-1e300"], RANGES["step_amplitude"].text()),
             (["--step-amplitude", "0"], "non-zero"),
             (["--step-time", "nan"], "is not a number")]
    procs = run_many([[good, *opts] for opts, _ in cases])
    for (opts, words), proc in zip(cases, procs):
        assert proc.returncode == 2, (opts, proc.stderr)
        lines = proc.stderr.strip().splitlines()
        assert len(lines) == 1 and words in lines[0] and "np." not in lines[0], (opts, lines)
    # a negative amplitude inside the range is a falling step, and works
    ok = run(good, "--step-amplitude", "-2", "--json")
    assert ok.returncode == 0, ok.stderr
    assert json.loads(ok.stdout)["best"]["params"]["K"] == pytest.approx(-0.5, rel=0.02)


def test_refused_run_leaves_no_plot_or_folder(tmp_path):
    bad = tmp_path / "bad.csv"
    bad.write_text("t,y\n" + "".join(f"{k},{'nan' if k == 5 else k}\n" for k in range(30)))
    for target in (tmp_path / "new" / "deeper" / "fit.png", tmp_path):
        proc = run(bad, "--plot", target)
        assert proc.returncode == 2 and len(proc.stderr.strip().splitlines()) == 1
    assert sorted(p.name for p in tmp_path.iterdir()) == ["bad.csv"]


def test_unphysical_classical_results_are_not_evaluated():
    """A method that returns tau < 0 (Nishikawa on an overshooting response) made
    the scoring overflow in exp: such a model is never evaluated, only flagged."""
    import warnings

    from designer.identify.step import identify_step
    n = 78
    t = np.linspace(-0.1, 1.0, n) + 1.0
    y = model_step("underdamped", {"K": -1.0, "wn_rad_s": 60.0, "zeta": 0.2, "theta_s": 0.0},
                   t - 1.0) + 0.01 * np.random.default_rng(n).standard_normal(n)
    with warnings.catch_warnings():
        warnings.simplefilter("error")
        res = identify_step(t, y)
    for m in res.methods:
        if any(k.startswith("tau") and v <= 0 for k, v in m.params.items()):
            assert not m.valid and not math.isfinite(m.iae)
    assert res.best.model == "underdamped"


# --------------------------------------------------------------------------- issue 9

def test_format_window_and_bench_files_on_the_command_line(tmp_path):
    fix = FIX / "tds_output_only_square.csv"
    runs = run_many([[fix, "--json"], [fix, "--json", "--window", "-0.5m", "6.5m"],
                     [fix, "--format", "tektronix-tds"], [fix, "--format", "rigol"],
                     [fix, "--window", "7m", "1m"], [fix, "--window", "0", "1e300"],
                     [fix, "--format", "lecroy"], [FIX / "rigol_nox_slew.csv"]])
    full, win, forced, wrong, backwards, huge, unknown, slew = runs
    out = json.loads(full.stdout)
    assert out["capture"]["format"] == "tektronix-tds"
    pre = out["preprocessing"]
    assert pre["noise_sigma"] > 0 and pre["edges_averaged"] == 1 and pre["quantisation_step"]
    assert "rise_time_0_100_s" in out["measured"]
    assert json.loads(win.stdout)["preprocessing"]["window_s"] == pytest.approx([-0.5e-3, 6.5e-3])
    assert forced.returncode == 0 and "(tektronix-tds," in forced.stdout
    assert "Noise " in forced.stdout and "one edge" in forced.stdout
    for proc, words in ((wrong, "not a Rigol"), (backwards, "must start before it ends"),
                        (huge, "--window T1"), (unknown, "invalid choice")):
        assert proc.returncode == 2, (words, proc.stderr)
        lines = proc.stderr.strip().splitlines()
        assert len(lines) == 1 and words in lines[0] and "np." not in lines[0], proc.stderr
    assert slew.returncode == 0 and "NON-LINEAR" in slew.stdout
    assert "Best: none of the methods is valid" in slew.stdout


# --------------------------------------------------------------------------- a frequency table given to identify

#: the known responses the tables are written from: a first-order plant and an underdamped second-order one
FIRST = {"K": 2.0, "tau_s": 1 / (2 * math.pi * 1e3)}
SECOND = {"K": 1.0, "wn_rad_s": 2 * math.pi * 5e3, "zeta": 0.3}


def _response(model, w):
    s = 1j * w
    if model == "first":
        return FIRST["K"] / (FIRST["tau_s"] * s + 1)
    wn, z = SECOND["wn_rad_s"], SECOND["zeta"]
    return SECOND["K"] * wn ** 2 / (s ** 2 + 2 * z * wn * s + wn ** 2)


def _column(kind, f, g):
    """One column of the table as its header names it (phase as the output's lag: phase = -w dt)."""
    w = 2 * math.pi * f
    phase = np.unwrap(np.angle(g))
    return {"f_hz": f, "f_khz": f / 1e3, "w_rad_s": w, "gain_db": 20 * np.log10(np.abs(g)),
            "gain_ratio": np.abs(g), "phase_deg": np.degrees(phase), "phase_rad": phase,
            "shift_s": -phase / w, "shift_us": -phase / w * 1e6}[kind]


def _table(model, header, sep=",", decimal_comma=False, head="", names=None):
    """A table of ``model`` from 10 Hz to 100 kHz with the columns ``header`` names."""
    f = np.geomspace(10, 1e5, 61)
    g = _response(model, 2 * math.pi * f)
    kinds = header.split(",")
    cols = [_column(k, f, g) for k in kinds]

    def cell(v):
        text = repr(float(v))
        return text.replace(".", ",") if decimal_comma else text
    rows = [sep.join(cell(v) for v in row) for row in zip(*cols)]
    return head + sep.join(names or kinds) + "\n" + "\n".join(rows) + "\n"


def _waveforms(model):
    """As a Digilent WaveForms network analyser exports it: comment block, four columns, phase in +-180."""
    f = np.geomspace(10, 1e5, 61)
    g = _response(model, 2 * math.pi * f)
    head = ("#Digilent WaveForms Network Analyzer - Bode\n#Device Name: Discovery2\n#Steps: 61\n\n"
            "Frequency (Hz),Channel 1 Magnitude (dB),Channel 2 Magnitude (dB),Channel 2 Phase (deg)\n")
    return head + "".join(f"{a!r},{-0.01 * k!r},{20 * math.log10(abs(b))!r},{math.degrees(np.angle(b))!r}\n"
                          for k, (a, b) in enumerate(zip(f.tolist(), g.tolist())))


#: name -> (the table's text, the model written into it)
TABLES = {
    "f_hz,gain_db,phase_deg": (_table("second", "f_hz,gain_db,phase_deg"), SECOND),
    "f_khz,gain_ratio,phase_rad": (_table("first", "f_khz,gain_ratio,phase_rad"), FIRST),
    "w_rad_s,gain_db,shift_s": (_table("second", "w_rad_s,gain_db,shift_s"), SECOND),
    "f_hz,gain_ratio,shift_us": (_table("first", "f_hz,gain_ratio,shift_us"), FIRST),
    "f_hz,gain_db (no phase)": (_table("first", "f_hz,gain_db"), FIRST),
    "semicolons and decimal commas": (_table("second", "f_hz,gain_db,phase_deg", sep=";", decimal_comma=True),
                                      SECOND),
    "tabs, a BOM and a comment": (_table("first", "f_hz,gain_db,phase_deg", sep="\t",
                                         head="\ufeff# sweep of the RC plant\n"), FIRST),
    "Frequency (Hz),Gain (dB),Phase (deg)": (_table("second", "f_hz,gain_db,phase_deg",
                                                    names=["Frequency (Hz)", "Gain (dB)", "Phase (deg)"]), SECOND),
    "WaveForms network analyser": (_waveforms("second"), SECOND),
}


@pytest.fixture(scope="module")
def table_runs(tmp_path_factory):
    """identify and identify-freq on every table, as JSON, as text and with --plot."""
    folder = tmp_path_factory.mktemp("tables")
    freq = script("identify-freq")
    jobs, paths = [], {}
    for k, (name, (text, _)) in enumerate(TABLES.items()):
        path = paths[name] = folder / f"table{k}.csv"
        path.write_text(text, encoding="utf-8")
        for exe in (EXE, freq):
            tag = "i" if exe == EXE else "f"
            jobs += [[exe, path, "--json"], [exe, path], [exe, path, "--plot", folder / f"{tag}{k}.png"]]
    with ThreadPoolExecutor(max_workers=4) as ex:
        procs = list(ex.map(lambda a: subprocess.run(list(map(str, a)), capture_output=True, text=True,
                                                     timeout=120), jobs))
    out = {}
    for k, name in enumerate(TABLES):
        ij, it, ip, fj, ft, fp = procs[6 * k:6 * k + 6]
        out[name] = {"identify": (ij, it, ip), "identify-freq": (fj, ft, fp),
                     "png": (folder / f"i{k}.png", folder / f"f{k}.png"), "path": paths[name]}
    return out


@pytest.mark.parametrize("name", list(TABLES))
def test_a_frequency_table_given_to_identify_is_analysed_as_identify_freq_does(table_runs, name):
    runs = table_runs[name]
    for proc in runs["identify"] + runs["identify-freq"]:
        assert proc.returncode == 0 and proc.stderr == "", (name, proc.args, proc.stderr)
    (ij, it, ip), (fj, ft, fp) = runs["identify"], runs["identify-freq"]
    # the JSON: identify-freq's own, saying it was read as a frequency table
    got, want = json.loads(ij.stdout), json.loads(fj.stdout)
    assert got.pop("format") == "frequency-table" and list(got)[:1] == ["methods"]
    assert got == want and "preprocessing" not in got
    # the summary: one line saying so, then identify-freq's table; the plot is identify-freq's Bode plot
    first, rest = it.stdout.split("\n", 1)
    assert first.startswith("Format: frequency table (header ") and "analysed as identify-freq does" in first
    assert rest == ft.stdout
    ipng, fpng = runs["png"]
    assert ipng.read_bytes()[:4] == b"\x89PNG" and ipng.read_bytes() == fpng.read_bytes()
    assert ip.stdout.split("\n", 1)[1].replace(str(ipng), "PLOT") == fp.stdout.replace(str(fpng), "PLOT")
    # and the analysis found the response the table was written from
    truth = TABLES[name][1]
    best = got["best"]
    assert best["params"]["K"] == pytest.approx(truth["K"], rel=0.02), name
    if "zeta" in truth:
        assert best["model"] == "underdamped", name
        assert best["params"]["wn_rad_s"] == pytest.approx(truth["wn_rad_s"], rel=0.02)
        assert best["params"]["zeta"] == pytest.approx(truth["zeta"], rel=0.05)
    else:
        assert best["params"]["tau_s"] == pytest.approx(truth["tau_s"], rel=0.03), name


def test_step_options_with_a_frequency_table_are_one_line(tmp_path):
    path = tmp_path / "bode.csv"
    path.write_text(TABLES["f_hz,gain_db,phase_deg"][0])
    plot = tmp_path / "fit.png"
    cases = [["--step-time", "0"], ["--step-amplitude", "2"], ["--window", "0", "1m"], ["--format", "generic"],
             ["--input-column", "2"], ["--output-column", "3"], ["--methods", "smith"], ["--no-refine"],
             ["--against", tmp_path / "result.json"], ["--step-time", "0", "--no-refine", "--json"]]
    procs = run_many([[path, *opts, "--plot", plot] for opts in cases])
    for opts, proc in zip(cases, procs):
        assert proc.returncode == 2 and proc.stdout == "", (opts, proc.stderr)
        lines = proc.stderr.strip().splitlines()
        assert len(lines) == 1 and lines[0].startswith("identify: error: "), (opts, proc.stderr)
        flags = [o for o in opts if str(o).startswith("--") and o != "--json"]
        assert all(f in lines[0] for f in flags) and "frequency-response table" in lines[0], lines[0]
        assert "identify-freq" in lines[0] and "f_hz,gain_db,phase_deg" in lines[0]
    assert sorted(p.name for p in tmp_path.iterdir()) == ["bode.csv"]
    # --format auto is the default, not a step option; a step capture is still a step capture
    auto = run(path, "--format", "auto", "--json")
    assert auto.returncode == 0 and json.loads(auto.stdout)["format"] == "frequency-table"
    step = run(FIX / "generic_ty.csv", "--json")
    assert step.returncode == 0 and "format" not in json.loads(step.stdout)
    assert json.loads(step.stdout)["capture"]["format"] == "generic"


def test_plain_columns_need_and_take_a_sample_time(tmp_path):
    """Issue 28: a file of u y columns without time (DaISy's layout) is read with --sample-time
    (engineering notation) and --columns; without --sample-time it is refused naming the option."""
    t = np.arange(1500) * 2e-5
    u = np.where(t >= 3e-3, 1.0, 0.0)
    y = model_step("fopdt", {"K": 2.0, "tau_s": 2e-3, "theta_s": 0.0}, t - 3e-3)
    plain = tmp_path / "plain.dat"
    plain.write_text("".join(f"{a:15.7e}\t{b:15.7e}\t\n" for a, b in zip(u, y)))
    p = run(plain, "--sample-time", "20u", "--columns", "u,y", "--json")
    assert p.returncode == 0, p.stderr
    d = json.loads(p.stdout)
    assert d["capture"]["samples"] == 1500 and d["capture"]["input"] == "u"
    assert any("no time column" in n for n in d["capture"]["notes"])
    best = d["best"]["params"]
    assert best["K"] == pytest.approx(2.0, rel=0.02) and best["tau_s"] == pytest.approx(2e-3, rel=0.05)
    for args, words in (([], "give --sample-time"), (["--columns", "u,y"], "give --sample-time with it"),
                        (["--sample-time", "0"], "--sample-time must be 1 ps to 1e+06 s"),
                        (["--sample-time", "20u", "--columns", "u,y,x"], "--columns names 3 columns")):
        q = run(plain, *args)
        assert q.returncode == 2 and len(q.stderr.splitlines()) == 1 and words in q.stderr, q.stderr
    helptext = " ".join(run("--help").stdout.split())
    assert "--sample-time S" in helptext and "seconds (1 ps to 1e+06 s)" in helptext
