"""design-plant --topology NAME over the registry (every registered section, picked up without
editing this file): the design from the CLI with ngspice's .ac check, its JSON (the topology key,
the parts the topology declares), its Monte Carlo rows recomputed from their part values, and the
refusals (one line, exit status 2, nothing written)."""

import csv
import json
import subprocess
from pathlib import Path

import numpy as np
import pytest
from helpers import script

from designer.core import eseries
from designer.core.opamps import get as get_opamp
from designer.filters import REGISTRY
from designer.plant import circuit

TOPOLOGIES = [t for t in REGISTRY.values() if t.name != circuit.DEFAULT_TOPOLOGY]
IDS = [t.name for t in TOPOLOGIES]


def run(*args, cwd=None):
    return subprocess.run([script("design-plant"), *args], capture_output=True, text=True, cwd=cwd, timeout=300)


def refused(out, words, folder) -> None:
    """A refusal: exit status 2, one line holding ``words``, nothing on stdout, nothing written in ``folder``."""
    assert out.returncode == 2 and out.stdout == ""
    line = out.stderr.strip()
    assert "\n" not in line and "Traceback" not in line
    for w in words:
        assert w in line, (w, line)
    assert list(folder.iterdir()) == []


def target_args(topology) -> list:
    """The topology's example as design-plant's target options."""
    ex = topology.example
    out = ["--fc", f"{ex.fn_hz:g}", "--gain", f"{ex.gain:g}", "--topology", topology.name]
    return out + ([] if ex.q is None else ["--zeta", f"{1 / (2 * ex.q):.6g}"])


@pytest.mark.spice
@pytest.mark.parametrize("topology", TOPOLOGIES, ids=IDS)
def test_design_plant_on_every_topology(topology, tmp_path):
    out = run(*target_args(topology), "--json", "--out", str(tmp_path), "--simulator", "ngspice-cli",
              "--monte-carlo", "50", "--seed", "3", "--alternatives", "3")
    assert out.returncode == 0, out.stderr
    d = json.loads(out.stdout)
    assert d["topology"] == topology.name
    assert list(d["parts"]) == list(topology.designators)
    values = {r: p["value"] for r, p in d["parts"].items()}
    f = topology.figures(values)
    assert d["built"]["ideal"]["fn_hz"] == pytest.approx(f.fn_hz, rel=1e-12)
    assert abs(d["built"]["ideal"]["fn_error_pct"]) < 5
    assert d["spice"]["pass"] and d["spice"]["max_db"] <= 0.05
    assert json.loads(Path(d["files"]["result_json"]).read_text()) == d
    # the Monte Carlo's rows: each build's figures recomputed from its part values by the engine's chunk
    # function (the section's own figures where it has them: the Sallen-Key low-pass's gain is the op-amp-aware
    # DC gain, the generic one the ideal passband gain)
    with open(d["files"]["monte_carlo_csv"], newline="") as fh:
        rows = list(csv.DictReader(fh))
    assert len(rows) == 50
    batch = {r: np.array([float(row[r]) for row in rows]) for r in topology.designators}
    figs = circuit.evaluate((topology.name, get_opamp(d["opamp"]["name"])), batch)
    for k in ("fn_hz", "ideal_fn_hz", "gain"):
        got = np.array([float(row[k]) for row in rows])
        assert np.allclose(got, figs[k], rtol=1e-8), k


@pytest.mark.parametrize("topology", TOPOLOGIES, ids=IDS)
def test_a_part_the_topology_does_not_have_is_refused_listing_its_parts(topology, tmp_path):
    out = run(*target_args(topology), "--no-sim", "--tol", "R9=1%", "--worst-case", cwd=tmp_path)
    assert out.returncode == 2 and out.stdout == ""
    line = out.stderr.strip()
    assert "\n" not in line and "R9" in line and ", ".join(topology.designators) in line
    assert list(tmp_path.iterdir()) == []


def test_an_unknown_topology_is_one_line_with_the_registered_and_the_closest(tmp_path):
    out = run("--fc", "1k", "--zeta", "0.5", "--topology", "mfb-lowpas", cwd=tmp_path)
    assert out.returncode == 2 and "\n" not in out.stderr.strip()
    assert "did you mean mfb-lowpass?" in out.stderr and ", ".join(REGISTRY) in out.stderr
    assert list(tmp_path.iterdir()) == []


@pytest.mark.parametrize("args, words", [
    # MFB low-pass, Q 5, gain 2: C2/C1 >= 4 Q^2 (1 + 2) = 300, beyond the capacitor bounds' ratio 10
    (["--fc", "1k", "--zeta", "0.1", "--gain", "2", "--topology", "mfb-lowpass", "--c-min", "1n", "--c-max", "10n"],
     ["--c-max", "capacitor ratio must be at least 300", "widen the capacitor bounds"]),
    # MFB band-pass: the gain at f0 must stay below 2 Q^2
    (["--fc", "1k", "--zeta", "0.5", "--gain", "4", "--topology", "mfb-bandpass"], ["--gain", "2 Q^2"]),
    # 40 MHz of GBW needed against the LM741's 1 MHz
    (["--fc", "200k", "--zeta", "0.1", "--gain", "3", "--topology", "mfb-lowpass"], ["--opamp", "too slow", "GBW"]),
    (["--fc", "1k", "--zeta", "0.5", "--topology", "rc-lowpass"], ["--zeta", "first-order"]),
    (["--fc", "1k", "--topology", "mfb-lowpass"], ["required: --zeta"]),
    # the seed's procedure on the MFB low-pass: R C = 10 us is below its Q (1 + |gain|)/wn = 318 us
    (["--fc", "1k", "--zeta", "0.5", "--topology", "mfb-lowpass", "--r", "1k", "--c", "10n"],
     ["--r and --c", "no positive C1", "choose a larger R or C"]),
])
def test_targets_a_topology_cannot_realise_are_one_line(args, words, tmp_path):
    refused(run(*args, "--no-sim", cwd=tmp_path), words, tmp_path)


def test_help_lists_the_topologies():
    out = run("--help")
    assert out.returncode == 0
    text = " ".join(out.stdout.split())
    for name in REGISTRY:
        assert name in text


def analyze(*args, cwd=None):
    return subprocess.run([script("analyze-plant"), *args], capture_output=True, text=True, cwd=cwd, timeout=300)


@pytest.mark.parametrize("topology", TOPOLOGIES, ids=IDS)
def test_analyze_plant_takes_every_topology_s_parts_by_designator(topology, tmp_path):
    """The example's exact synthesis given as --part: its figures are the example's (closed forms)."""
    values = topology.synthesize(topology.example)
    parts = [a for r, v in values.items() for a in ("--part", f"{r}={v!r}")]
    out = analyze("--topology", topology.name, *parts, "--no-sim", "--json", "--out", str(tmp_path))
    assert out.returncode == 0, out.stderr
    d = json.loads(out.stdout)
    assert d["mode"] == "analyze" and d["topology"] == topology.name
    assert d["built"]["ideal"]["fn_hz"] == pytest.approx(topology.example.fn_hz, rel=1e-9)
    assert d["built"]["ideal"]["gain"] == pytest.approx(topology.example.gain, rel=1e-9)


def test_part_takes_a_list_as_design_pid_s_plant_part_does(tmp_path):
    """--part R1=.. R2=.. (one flag, a list) is the repeated flag's result: it was refused as "unrecognized
    arguments" while design-pid --plant-part takes the same words; the two forms accumulate."""
    topology = REGISTRY["mfb-lowpass"]
    items = [f"{r}={v!r}" for r, v in topology.synthesize(topology.example).items()]
    listed = analyze("--topology", topology.name, "--part", *items, "--no-sim", "--json", "--no-files")
    repeated = analyze("--topology", topology.name, *(a for i in items for a in ("--part", i)), "--no-sim", "--json",
                       "--no-files")
    mixed = analyze("--topology", topology.name, "--part", *items[:2], "--part", *items[2:], "--no-sim", "--json",
                    "--no-files")
    assert listed.returncode == repeated.returncode == mixed.returncode == 0, listed.stderr + mixed.stderr
    got = [json.loads(o.stdout) for o in (listed, repeated, mixed)]
    for d in got:
        d.pop("tool")
    assert got[0] == got[1] == got[2]


def test_part_on_the_sallen_key_low_pass_is_its_r1_to_c2(tmp_path):
    """--part R1=820 is --r1 820: the same result."""
    a = analyze("--part", "R1=820", "--part", "C2=220n", "--r2", "1k", "--c1", "10n", "--no-sim", "--json",
                "--no-files")
    b = analyze("--r1", "820", "--r2", "1k", "--c1", "10n", "--c2", "220n", "--no-sim", "--json", "--no-files")
    assert a.returncode == 0 and b.returncode == 0, a.stderr + b.stderr
    da, db = json.loads(a.stdout), json.loads(b.stdout)
    da.pop("tool"), db.pop("tool")
    assert da == db


@pytest.mark.parametrize("args, words", [
    (["--part", "R1=820", "--part", "R1=1k", "--r2", "1k", "--c1", "10n", "--c2", "220n"],
     ["--part R1 given twice: 820 and 1k"]),
    (["--part", "R5=1k", "--r1", "1k", "--r2", "1k", "--c1", "10n", "--c2", "220n"],
     ["no part R5", "R1, R2, C1, C2, R3, R4"]),
    (["--part", "R1=1k", "--r1", "1k", "--r2", "1k", "--c1", "10n", "--c2", "220n"], ["same part"]),
    (["--r2", "1k", "--c1", "10n"], ["the following arguments are required: --r1, --c2"]),
    (["--topology", "mfb-lowpass", "--part", "R1=1k"], ["needs R2, R3, C1, C2 too"]),
    (["--topology", "mfb-lowpass", "--part", "R5=1k"], ["has no part R5", "R1, R2, R3, C1, C2"]),
    (["--topology", "mfb-lowpass", "--r1", "1k"], ["--r1 is the sallen-key-lowpass's", "--part"]),
    (["--topology", "rc-lowpass", "--part", "R1=1k", "--part", "C1=1x"], ["--part C1", "not a number"]),
])
def test_analyze_plant_part_refusals_are_one_line(args, words, tmp_path):
    refused(analyze(*args, "--no-sim", cwd=tmp_path), words, tmp_path)


@pytest.mark.spice
def test_engine_both_on_a_section_runs_each_build_s_ac_in_ngspice(tmp_path):
    """--engine both on a high-pass (its step settles to 0: no step engine): each build's .ac, recorded as
    such; the CSV's SPICE rows are the analytic engine's next to them (its dominant pair: fn within 1 %), the
    model's rows recomputed from the parts exactly; --spice-samples checks the tails."""
    topology = REGISTRY["mfb-highpass"]
    fn = topology.example.fn_hz
    args = [*target_args(topology), "--monte-carlo", "30", "--seed", "2", "--limit",
            f"fn_hz={0.95 * fn:g}:{1.05 * fn:g}", "--simulator", "ngspice-cli", "--json"]
    out = run(*args, "--engine", "both", "--out", str(tmp_path))
    assert out.returncode == 0, out.stderr
    d = json.loads(out.stdout)
    assert d["monte_carlo"]["spice"]["engine"] == "both" and d["monte_carlo"]["spice"]["analysis"] == "ac"
    with open(d["files"]["monte_carlo_csv"], newline="") as fh:
        rows = list(csv.DictReader(fh))
    col = lambda k: np.array([float(r[k]) for r in rows])  # noqa: E731
    figs = circuit.circuit_figures(topology, {r: col(r) for r in topology.designators},
                                   get_opamp(d["opamp"]["name"]))
    assert np.allclose(col("model_fn_hz"), figs["fn_hz"], rtol=1e-8)
    assert np.allclose(col("fn_hz"), figs["fn_hz"], rtol=0.01)
    text = run(*args[:-1], "--engine", "spice", "--no-files")     # the text summary names the sweep
    assert text.returncode == 0, text.stderr
    assert "engine spice: ngspice (ngspice-cli), .ac " in text.stdout
    picked = run(*args, "--engine", "both", "--spice-samples", "2", "--no-files")
    assert picked.returncode == 0, picked.stderr
    assert json.loads(picked.stdout)["monte_carlo"]["spice"]["samples_checked"] >= 2


@pytest.mark.parametrize("args, words", [
    (["--monte-carlo", "20", "--replay", "3"], ["--replay simulates the build in SPICE: drop --no-sim"]),
    (["--replay", "3"], ["--replay I goes with --monte-carlo N"]),
    (["--engine", "spice"], ["--engine spice goes with --monte-carlo N"]),
    (["--monte-carlo", "20", "--spice-samples", "2"], ["--spice-samples K goes with --engine both"]),
    (["--monte-carlo", "20", "--tol", "SR=20%"], ["--tol SR", "linear", "drop SR from --tol"]),
    (["--worst-case", "--tol", "SR=20%"], ["--tol SR", "linear"]),
    (["--monte-carlo", "20", "--engine", "spice", "--worst-case", "--tol", "SR=20%"], ["--tol SR", "linear"]),
])
def test_what_a_section_plant_has_not_is_one_line(args, words, tmp_path):
    refused(run(*target_args(REGISTRY["mfb-lowpass"]), *args, "--no-sim", cwd=tmp_path), words, tmp_path)


def test_a_slew_spread_on_an_ac_engine_is_one_line(tmp_path):
    """--tol SR on a high-pass's SPICE engine (its .ac: small signal, linear) is refused before any work."""
    refused(run(*target_args(REGISTRY["mfb-highpass"]), "--monte-carlo", "20", "--engine", "spice", "--tol",
                "SR=20%", "--no-sim", cwd=tmp_path), ["--tol SR", "linear", "on a low-pass section"], tmp_path)


@pytest.mark.spice
def test_square_freq_on_a_section_simulates_the_bench_test(tmp_path):
    """--square-freq: one period in ngspice against the op-amp-aware model (NRMS below 1), its deck and
    waveforms in the bundle; the waveforms' model column recomputed from the input by superposition."""
    out = run(*target_args(REGISTRY["mfb-lowpass"]), "--opamp", "TL072", "--square-freq", "300", "--json",
              "--simulator", "ngspice-cli", "--out", str(tmp_path))
    assert out.returncode == 0, out.stderr
    d = json.loads(out.stdout)
    sq = d["square_test"]
    assert sq["pass"] and sq["nrms"] < 1 and sq["generator"]["frequency_hz"] == 300
    assert any(c["id"] == "square_wave_agreement" and c["ok"] for c in d["checks"])
    assert "PULSE(" in Path(d["files"]["square_deck"]).read_text()
    w = np.genfromtxt(d["files"]["waveforms_csv"], delimiter=",", names=True)
    assert w["input_v"].max() == pytest.approx(2.0) and np.all(np.diff(w["time_s"]) >= 0)


@pytest.mark.spice
def test_analyze_plant_square_freq_on_a_section(tmp_path):
    """analyze-plant --topology rc-lowpass --square-freq: the parts as built under the square wave (the
    model's response the closed form, tests/plant/test_circuit_design.py), and a bad frequency refused."""
    parts = ["--topology", "rc-lowpass", "--part", "R1=1k", "--part", "C1=100n"]
    out = analyze(*parts, "--square-freq", "100", "--amplitude", "1", "--simulator", "ngspice-cli", "--json",
                  "--no-files")
    assert out.returncode == 0, out.stderr
    sq = json.loads(out.stdout)["square_test"]
    assert sq["pass"] and sq["nrms"] < 1e-2 and sq["generator"]["high_v"] == 1
    refused(analyze(*parts, "--square-freq", "1x", "--no-sim", cwd=tmp_path), ["--square-freq", "not a number"],
            tmp_path)


@pytest.mark.spice
@pytest.mark.parametrize("engine", ["analytic", "both"])
def test_tol_gbw_on_a_section_spreads_the_op_amp_in_both_engines(engine, tmp_path):
    """--tol GBW=30% on --topology mfb-lowpass: a gain-bandwidth per build in the CSV; the model's rows are the
    op-amp-aware model with that build's GBW (recomputed exactly), SPICE's (--engine both: each build's .ac with
    the op-amp's integrating capacitor altered) next to them; --worst-case reaches GBW too."""
    import dataclasses
    topology = REGISTRY["mfb-lowpass"]
    out = run(*target_args(topology), "--monte-carlo", "20", "--seed", "5", "--tol", "GBW=30%", "--engine", engine,
              "--worst-case", "--simulator", "ngspice-cli", "--json", "--out", str(tmp_path))
    assert out.returncode == 0, out.stderr
    d = json.loads(out.stdout)
    assert d["monte_carlo"]["settings"]["tolerances_pct"]["GBW"] == 30
    assert "GBW" in d["worst_case"]["fn_hz"]["min"]["deviations"]
    with open(d["files"]["monte_carlo_csv"], newline="") as fh:
        rows = list(csv.DictReader(fh))
    col = lambda k: np.array([float(r[k]) for r in rows])  # noqa: E731
    amp = get_opamp(d["opamp"]["name"])
    gbw = col("GBW")
    assert np.all(np.abs(gbw / amp.gbw_hz - 1) <= 0.3) and np.ptp(gbw) > 0
    model = "fn_hz" if engine == "analytic" else "model_fn_hz"
    for i, row in enumerate(rows):
        want = circuit.circuit_figures(topology, {r: float(row[r]) for r in topology.designators},
                                       dataclasses.replace(amp, gbw_hz=gbw[i]))["fn_hz"]
        assert float(row[model]) == pytest.approx(float(want), rel=1e-9)
    if engine == "both":
        assert np.allclose(col("fn_hz"), col("model_fn_hz"), rtol=0.01)


@pytest.mark.spice
def test_replay_on_a_section_is_the_monte_carlos_build(tmp_path):
    """Issue 26: --replay I on a section plant: build I of the Monte Carlo with the same options (seed, sampler,
    dist, --tol), its exact values analysed and simulated alone, its bundle under <name>_sample<I>; printed as the
    Sallen-Key replay is."""
    args = [*target_args(REGISTRY["sallen-key-highpass"]), "--monte-carlo", "20", "--seed", "4", "--sampler", "sobol",
            "--dist", "normal", "--tol", "C=2%", "--simulator", "ngspice-cli"]
    mc = run(*args, "--json", "--out", str(tmp_path / "mc"))
    assert mc.returncode == 0, mc.stderr
    with open(json.loads(mc.stdout)["files"]["monte_carlo_csv"], newline="") as fh:
        row = list(csv.DictReader(fh))[5]
    out = run(*args, "--replay", "5", "--json", "--out", str(tmp_path / "r"))
    assert out.returncode == 0, out.stderr
    d = json.loads(out.stdout)
    rep = d["monte_carlo"]["replay"]
    assert rep["sample"] == 5 and d["mode"] == "analyze" and d["spice"]["pass"]
    for ref in REGISTRY["sallen-key-highpass"].designators:
        assert rep["values"][ref] == pytest.approx(float(row[ref]), rel=1e-9)
        assert d["parts"][ref]["value"] == rep["values"][ref]
    assert Path(d["files"]["result_json"]).parent.name.endswith("_sample5")
    text = run(*args, "--replay", "5", "--no-files")
    assert text.returncode == 0 and "Replay of Monte Carlo sample 5 (of 20, sobol, normal, seed 4)" in text.stdout


@pytest.mark.parametrize("name,args", [
    ("sallen-key-highpass", ["--fc", "1k", "--zeta", "0.5", "--r", "10k", "--c", "10n"]),
    ("mfb-lowpass", ["--fc", "1k", "--zeta", "0.5", "--gain", "2", "--r", "10k", "--c", "100n"]),
])
def test_r_and_c_on_a_section_is_its_exact_design_rounded_jointly(name, args, tmp_path):
    """design-plant --topology NAME --r R --c C: the JSON's ideal is the section's synthesize_rc design (R and C
    among its parts), the build each part within two series values of it, a note says so."""
    topo = REGISTRY[name]
    out = run(*args, "--topology", name, "--no-sim", "--json", "--out", str(tmp_path))
    assert out.returncode == 0, out.stderr
    d = json.loads(out.stdout)
    fc, zeta, gain = d["spec"]["fc_hz"], d["spec"]["zeta"], d["spec"]["gain"]
    c = float(args[args.index("--c") + 1][:-1]) * 1e-9
    exact = topo.synthesize_rc(circuit.plant_target(topo, fc, zeta, gain), 10e3, c)
    assert d["ideal"] == pytest.approx(exact, rel=1e-12)
    for ref, part in d["parts"].items():
        v = part["value"]
        series = eseries.values("E24", 1, 1e9) if ref[0] == "R" else eseries.values("E12", 1e-13, 1)
        i = int(np.searchsorted(series, exact[ref]))
        assert v in series[max(0, i - 2):i + 2], (ref, v, exact[ref])
    assert any("fixed (the seed's procedure)" in n for n in d["notes"])


@pytest.mark.parametrize("args,words", [
    (["--fc", "1k", "--topology", "rc-lowpass", "--r", "1k", "--c", "10n"],
     ["--r: rc-lowpass has one free scale", "give R = 15.92 kOhm, or C = 159.2 nF"]),
    (["--fc", "1k", "--zeta", "0.5", "--gain", "2", "--topology", "mfb-lowpass", "--r", "1k", "--c", "10n"],
     ["--r and --c: no positive C1", "R*C > Q (1 + |gain|)/wn"]),
    (["--fc", "1k", "--zeta", "0.5", "--topology", "mfb-highpass", "--r", "1k"], ["--r and --c go together"]),
])
def test_r_and_c_a_section_cannot_take_are_one_line(args, words, tmp_path):
    refused(run(*args, "--no-sim", cwd=tmp_path), words, tmp_path)


@pytest.mark.spice
@pytest.mark.parametrize("name", ["mfb-lowpass", "rc-lowpass"])
def test_engine_both_on_a_lowpass_section_is_the_seed_plant_s_step_engine(name, tmp_path):
    """Issue 26: --engine spice|both on a low-pass section runs the seed plant's step engine (each build's
    rising half under the bench's square wave, result.json's monte_carlo.spice.analysis "step", the same
    figures), within the seed plant's test tolerance of the analytic engine (overshoot 0.02 pp; zeta 0.1 %, fn
    0.3 %: the step's second-order equivalents against the dominant pair); a first-order step has no peak (fn,
    zeta, Q, peak time compared on no build), its rise and settling times those of its pole, ln 9 and ln 50
    time constants. The replay of a build gives that build's row (one replay function for every plant)."""
    from designer.tolerance import spice_engine
    topology = REGISTRY[name]
    args = [*target_args(topology), "--monte-carlo", "12", "--seed", "3", "--simulator", "ngspice-cli"]
    out = run(*args, "--engine", "both", "--json", "--out", str(tmp_path / "mc"))
    assert out.returncode == 0, out.stderr
    d = json.loads(out.stdout)
    s = d["monte_carlo"]["spice"]
    assert s["analysis"] == "step" and s["measured"] == list(spice_engine.FIGURES)
    assert s["rising_half_s"][1] - s["rising_half_s"][0] == pytest.approx(0.5 / d["test_signal"]["frequency_hz"])
    dis = s["disagreement"]
    with open(d["files"]["monte_carlo_csv"], newline="") as fh:
        rows = list(csv.DictReader(fh))
    col = lambda k: np.array([float(r[k]) for r in rows])  # noqa: E731
    if topology.order == 2:
        assert dis["overshoot_pct"]["compared"] == 12 and dis["overshoot_pct"]["max_abs"] < 0.02
        np.testing.assert_allclose(col("zeta"), col("model_zeta"), rtol=1e-3)
        np.testing.assert_allclose(col("fn_hz"), col("model_fn_hz"), rtol=3e-3)
    else:
        assert all(dis[k]["compared"] == 0 for k in ("fn_hz", "zeta", "q", "peak_time_s"))
        tau = 1 / (2 * np.pi * col("model_fn_hz"))
        np.testing.assert_allclose(col("rise_time_s"), np.log(9) * tau, rtol=5e-3)
        np.testing.assert_allclose(col("settling_time_s"), np.log(50) * tau, rtol=5e-3)
    rep = run(*args, "--replay", "7", "--json", "--out", str(tmp_path / "r"))
    assert rep.returncode == 0, rep.stderr
    r = json.loads(rep.stdout)["monte_carlo"]["replay"]
    for k in ("overshoot_pct", "rise_time_s", "settling_time_s"):
        assert r["spice_figures"][k] == pytest.approx(col(k)[7], rel=1e-9, abs=1e-12)


@pytest.mark.spice
def test_a_replayed_section_build_steps_under_the_runs_square_wave(tmp_path):
    """analyze-plant --topology --square-freq --replay I: the build's step under the run's --square-freq (the
    design the draw is made on had the recommended square wave before: its row I then differed from the run's),
    and its bundle the square-wave test of that frequency."""
    parts = ["--part", "R1=10k", "--part", "R2=20k", "--part", "R3=24k", "--part", "C1=4n7", "--part", "C2=47n"]
    args = ["--topology", "mfb-lowpass", *parts, "--square-freq", "120", "--monte-carlo", "10", "--seed", "1",
            "--engine", "spice", "--simulator", "ngspice-cli", "--json"]
    mc = analyze(*args, "--out", str(tmp_path / "mc"))
    assert mc.returncode == 0, mc.stderr
    d = json.loads(mc.stdout)
    assert d["monte_carlo"]["spice"]["rising_half_s"][1] - d["monte_carlo"]["spice"]["rising_half_s"][0] == \
        pytest.approx(0.5 / 120)
    with open(d["files"]["monte_carlo_csv"], newline="") as fh:
        row = list(csv.DictReader(fh))[4]
    rep = analyze(*args, "--replay", "4", "--out", str(tmp_path / "r"))
    assert rep.returncode == 0, rep.stderr
    r = json.loads(rep.stdout)
    for k in ("overshoot_pct", "peak_time_s", "settling_time_s"):
        assert r["monte_carlo"]["replay"]["spice_figures"][k] == pytest.approx(float(row[k]), rel=1e-9)
    assert r["square_test"]["generator"]["frequency_hz"] == 120


@pytest.mark.spice
def test_a_slew_spread_reaches_a_lowpass_sections_step(tmp_path):
    """--tol SR on a low-pass section with the step engine (as on the seed plant): each build's op-amp slews at its
    drawn rate in ngspice. A 20 kHz MFB low-pass, gain 2, 0 -> 5 V on an LM741 (0.5 V/us): the 10 V edge is
    slew-limited, so each build's rise time follows 1/SR (correlation above 0.95) while the parts, at 0.01 %, move
    it by less than 0.1 % without SR."""
    base = ["--fc", "20k", "--zeta", "0.5", "--gain", "2", "--topology", "mfb-lowpass", "--amplitude", "5",
            "--monte-carlo", "12", "--seed", "1", "--engine", "spice", "--simulator", "ngspice-cli", "--json"]
    cols = {}
    for tag, tol in (("sr", ["R=0.01%", "C=0.01%", "SR=40%"]), ("parts", ["R=0.01%", "C=0.01%"])):
        out = run(*base, "--tol", *tol, "--out", str(tmp_path / tag))
        assert out.returncode == 0, out.stderr
        with open(json.loads(out.stdout)["files"]["monte_carlo_csv"], newline="") as fh:
            cols[tag] = list(csv.DictReader(fh))
    sr = np.array([float(r["SR"]) for r in cols["sr"]])
    rise = np.array([float(r["rise_time_s"]) for r in cols["sr"]])
    assert np.corrcoef(1 / sr, rise)[0, 1] > 0.95
    still = np.array([float(r["rise_time_s"]) for r in cols["parts"]])
    assert np.ptp(still) / np.mean(still) < 1e-3 < np.ptp(rise) / np.mean(rise)
