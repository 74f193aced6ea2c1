"""check-design with ``topology:`` over the registry (every registered section but the default,
picked up without editing this file): a plant spec designed on it and checked in ngspice (its
.ac agreement a design check), its figures within the spec's limits; the refusals at the key's line."""

import json
import re
import subprocess

import pytest
from helpers import script

from designer.filters import REGISTRY
from designer.plant.circuit import DEFAULT_TOPOLOGY

TOPOLOGIES = [t for t in REGISTRY.values() if t.name != DEFAULT_TOPOLOGY]
IDS = [t.name for t in TOPOLOGIES]


def check(path, *args):
    return subprocess.run([script("check-design"), str(path), *args], capture_output=True, text=True, timeout=300,
                          cwd=path.parent)


def spec_text(topology) -> str:
    ex = topology.example
    zeta = "" if ex.q is None else f", zeta: {1 / (2 * ex.q):.6g}"
    return (f"name: plant-{topology.name}\nkind: plant\ntopology: {topology.name}\n"
            f"target: {{fc: {ex.fn_hz:g}{zeta}, gain: {ex.gain:g}}}\nopamp: TL072\n"
            f"checks:\n  ideal_fn_hz: {{min: {0.95 * ex.fn_hz:g}, max: {1.05 * ex.fn_hz:g}}}\n"
            "design_checks: all\n")


@pytest.mark.spice
@pytest.mark.parametrize("topology", TOPOLOGIES, ids=IDS)
def test_a_check_design_spec_with_its_topology_passes(topology, tmp_path):
    path = tmp_path / "spec.yaml"
    path.write_text(spec_text(topology))
    out = check(path, "--simulator", "ngspice-cli", "--out", str(tmp_path / "out"))
    assert out.returncode == 0, out.stdout + out.stderr
    assert f"plant-{topology.name}: pass" in out.stdout
    results = list((tmp_path / "out").rglob("result.json"))
    designs = [json.loads(p.read_text()) for p in results]
    assert any(d.get("topology") == topology.name for d in designs)


def test_an_unknown_topology_is_refused_at_its_line(tmp_path):
    path = tmp_path / "spec.yaml"
    path.write_text(spec_text(REGISTRY["mfb-lowpass"]).replace("topology: mfb-lowpass", "topology: mfb-lowpas"))
    out = check(path)
    assert out.returncode == 2
    line = out.stderr.strip()
    assert "\n" not in line and "spec.yaml:3: topology: unknown topology" in line and "did you mean mfb-lowpass" in line


def test_parts_keys_are_the_topology_s(tmp_path):
    path = tmp_path / "spec.yaml"
    path.write_text(spec_text(REGISTRY["mfb-lowpass"]) + "parts: {R1: 1k, R5: 2k}\n")
    out = check(path)
    assert out.returncode == 2
    assert "unknown key 'R5' in parts; allowed: R1, R2, R3, C1, C2" in out.stderr


def parts_text(topology, values=None) -> str:
    """A spec of the topology's example synthesised exactly, given as its parts as built."""
    ex = topology.example
    values = topology.synthesize(ex) if values is None else values
    parts = ", ".join(f"{r}: {v!r}" for r, v in values.items())
    return (f"name: built-{topology.name}\nkind: plant\ntopology: {topology.name}\nparts: {{{parts}}}\n"
            f"target: {{fc: {ex.fn_hz:g}}}\nopamp: TL072\n"
            f"checks:\n  ideal_fn_hz: {{min: {0.99 * ex.fn_hz:g}, max: {1.01 * ex.fn_hz:g}}}\n"
            "design_checks: all\n")


@pytest.mark.spice
@pytest.mark.parametrize("topology", TOPOLOGIES, ids=IDS)
def test_its_parts_as_built_are_checked(topology, tmp_path):
    """parts: keys the topology's designators: analysed as built (the example's exact synthesis: its fn)."""
    path = tmp_path / "spec.yaml"
    path.write_text(parts_text(topology))
    out = check(path, "--simulator", "ngspice-cli", "--out", str(tmp_path / "out"))
    assert out.returncode == 0, out.stdout + out.stderr
    assert f"built-{topology.name}: pass" in out.stdout
    designs = [json.loads(p.read_text()) for p in (tmp_path / "out").rglob("result.json")]
    d = next(d for d in designs if d.get("topology") == topology.name)
    assert d["mode"] == "analyze" and d["spice"]["pass"]
    assert d["built"]["ideal"]["fn_hz"] == pytest.approx(topology.example.fn_hz, rel=1e-9)


def _without_r3(text):
    return re.sub(r"R3: [^,]+, ", "", text)


@pytest.mark.parametrize("edit, words", [
    (lambda t: t.replace(", C2: ", ", C9: "), ["unknown key 'C9' in parts"]),
    (_without_r3, ["parts: mfb-lowpass needs R3 too; its parts are R1, R2, R3, C1, C2"]),
    (lambda t: t.replace("target: {fc: ", "target: {gain: 2, fc: "), ["target.gain applies to a design"]),
    (lambda t: t + "bounds: {r_min: 1k}\n", ["bounds: limit a design's part search"]),
    (lambda t: t.replace("R1: ", "R1: 1x", 1), ["spec.yaml:4: parts.R1: ", "not a number"]),
])
def test_parts_as_built_refusals_are_one_line_at_their_key(edit, words, tmp_path):
    topology = REGISTRY["mfb-lowpass"]
    values = {r: f"{v:.4g}" for r, v in topology.synthesize(topology.example).items()}
    path = tmp_path / "spec.yaml"
    path.write_text(edit(parts_text(topology, values).replace("'", "")))
    out = check(path)
    assert out.returncode == 2, out.stdout + out.stderr
    line = out.stderr.strip()
    assert "\n" not in line and "Traceback" not in line and "spec.yaml:" in line
    for w in words:
        assert w in line, (w, line)


@pytest.mark.spice
def test_a_yield_on_a_section_counts_its_builds(tmp_path):
    """yield: on topology: mfb-lowpass: the analytic engine over its declared parts, the yield the share of
    monte-carlo.csv's rows inside the check, each row's fn recomputed from its parts."""
    import csv

    import numpy as np

    from designer.core.opamps import get as get_opamp
    from designer.plant.circuit import circuit_figures
    topology = REGISTRY["mfb-lowpass"]
    path = tmp_path / "spec.yaml"
    path.write_text("name: ymfb\nkind: plant\ntopology: mfb-lowpass\ntarget: {fc: 1k, zeta: 0.5, gain: 2}\n"
                    "opamp: TL072\nchecks:\n  fn_hz: {min: 950, max: 1050}\n"
                    "tolerances: {R: 2%}\nyield: {min: 50%, samples: 400, seed: 3}\n")
    out = check(path, "--simulator", "ngspice-cli", "--out", str(tmp_path / "out"))
    assert out.returncode == 0, out.stdout + out.stderr
    d = json.loads(next((tmp_path / "out").rglob("reports/*/result.json")).read_text())
    with open(d["files"]["monte_carlo_csv"], newline="") as fh:
        rows = list(csv.DictReader(fh))
    assert len(rows) == 400
    parts = {r: np.array([float(row[r]) for row in rows]) for r in topology.designators}
    fn = circuit_figures(topology, parts, get_opamp("TL072"))["fn_hz"]
    assert np.allclose([float(row["fn_hz"]) for row in rows], fn, rtol=1e-8)
    assert d["monte_carlo"]["yield"]["fraction"] == pytest.approx(np.mean((fn >= 950) & (fn <= 1050)))


@pytest.mark.parametrize("name, extra, words", [
    # a high-pass's SPICE engine is its .ac: no step to time (a low-pass's step counts rise_time_s)
    ("mfb-highpass",
     lambda t: re.sub(r"  ideal_fn_hz: .*\n", "  rise_time_s: {max: 1m}\n", t) + "yield: {min: 50%, engine: spice}\n",
     ["yield counts the builds inside checks:", "the spice engine computes", "not: rise_time_s"]),
    ("mfb-highpass", "tolerances: {SR: 20%}\nyield: {min: 50%, engine: spice}\n",
     ["spec.yaml:9: tolerances.SR: topology mfb-highpass's yield engines are linear", "GBW: spreads the op-amp"]),
    # a low-pass's SPICE step slews, its analytic model does not
    ("mfb-lowpass", "tolerances: {SR: 20%}\nyield: {min: 50%}\n",
     ["spec.yaml:9: tolerances.SR: the plant's analytic model is linear", "give yield.engine: spice"]),
    ("mfb-lowpass",
     lambda t: t.replace("checks:\n", "checks:\n  overshoot_pct: {max: 30}\n") + "tolerance: [overshoot_pct]\n",
     ["spec.yaml:10: tolerance: overshoot_pct has no tolerance band on topology mfb-lowpass", "allowed: fn_hz"]),
])
def test_what_a_section_s_yield_has_not_is_one_line_at_its_key(name, extra, words, tmp_path):
    path = tmp_path / "spec.yaml"
    text = spec_text(REGISTRY[name])
    path.write_text(extra(text) if callable(extra) else text + extra)
    out = check(path)
    assert out.returncode == 2, out.stdout + out.stderr
    line = out.stderr.strip()
    assert "\n" not in line and "spec.yaml:" in line
    for w in words:
        assert w in line, (w, line)


def _cases(out_dir) -> dict:
    """case id -> case, of the one spec under ``out_dir``."""
    d = json.loads(next(out_dir.glob("*/result.json")).read_text())
    return {c["id"]: c for corner in d["corners"] for c in corner["cases"]}


@pytest.mark.spice
@pytest.mark.parametrize("topology", TOPOLOGIES, ids=IDS)
def test_spice_agreement_on_a_section_is_its_square_wave_test(topology, tmp_path):
    """spice_agreement: on every registered section: SPICE's .tran under the square wave against the
    op-amp-aware model, as the Sallen-Key plant's; the case's nrms recomputed from the run's waveforms.csv."""
    import numpy as np

    from designer.core.compare import nrms
    path = tmp_path / "spec.yaml"
    path.write_text(spec_text(topology) + "stimulus: {amplitude: 0.5}\nspice_agreement: {nrms_max: 1}\n")
    out = check(path, "--simulator", "ngspice-cli", "--out", str(tmp_path / "out"))
    assert out.returncode == 0, out.stdout + out.stderr
    case = _cases(tmp_path / "out")["spice_agreement"]
    assert case["status"] == "pass" and "against the op-amp-aware model" in case["message"]
    d = json.loads(next((tmp_path / "out").rglob("reports/*/result.json")).read_text())
    wave = np.genfromtxt(next((tmp_path / "out").rglob("reports/*/waveforms.csv")), delimiter=",", names=True)
    sq = d["square_test"]
    assert sq["abstol_v"] == pytest.approx(0.01 * 0.5 * abs(d["built"]["ideal"]["gain"]))
    again = nrms(wave["model_v"], wave["spice_v"], sq["abstol_v"], t=wave["time_s"])
    assert case["value"] == pytest.approx(sq["nrms"], rel=1e-12)
    assert case["value"] == pytest.approx(again, rel=1e-3, abs=1e-6)


@pytest.mark.spice
@pytest.mark.parametrize("name", ["mfb-lowpass", "sallen-key-highpass"])
def test_a_section_s_golden_records_then_compares_and_a_changed_part_fails(name, tmp_path):
    """golden: on a section as built: --update-golden records the square-wave run's signals (the
    Sallen-Key plant's names); the same parts compare (exit 0); one part 10 % off fails (exit 1)."""
    topology = REGISTRY[name]
    values = topology.synthesize(topology.example)
    signals = "[output_v, input_v, analytic_v, analytic_opamp_v]"
    golden = f"golden: {{file: 'gold-{{corner}}.csv', signals: {signals}}}\n"
    path = tmp_path / "spec.yaml"
    path.write_text(parts_text(topology, values) + golden)
    rec = check(path, "--simulator", "ngspice-cli", "--update-golden")
    assert rec.returncode == 0, rec.stdout + rec.stderr
    header = (tmp_path / "gold-TL072.csv").read_text().splitlines()
    assert "time_s,output_v,input_v,analytic_v,analytic_opamp_v" in header
    same = check(path, "--simulator", "ngspice-cli", "--out", str(tmp_path / "same"))
    assert same.returncode == 0, same.stdout + same.stderr
    assert all(_cases(tmp_path / "same")[f"golden_{s}"]["status"] == "pass" for s in ("output_v", "analytic_v"))
    first = topology.designators[0]
    path.write_text(parts_text(topology, {**values, first: 1.1 * values[first]}) + golden)
    changed = check(path, "--simulator", "ngspice-cli", "--out", str(tmp_path / "changed"))
    assert changed.returncode == 1, changed.stdout + changed.stderr
    cases = _cases(tmp_path / "changed")
    assert cases["golden_output_v"]["status"] == "fail" and cases["golden_input_v"]["status"] == "pass"
    assert list((tmp_path / "changed").rglob("golden-TL072-output_v.png"))


@pytest.mark.parametrize("name", ["mfb-lowpass", "sallen-key-highpass"])
def test_a_section_s_tolerance_band_is_the_worst_over_its_declared_parts(name):
    """circuit_band_of: the band over every declared part at +/- its series tolerance; brute force on a
    3-level grid of each part (-tol, 0, +tol: 3^n builds, the corners among them) lands inside it and
    reaches both ends."""
    import itertools

    import numpy as np

    from designer.check.figures import SECTION_BAND, circuit_band_of
    from designer.core.eseries import TOLERANCE
    from designer.plant.circuit import circuit_figures
    from designer.plant.circuit_design import design_circuit_plant
    from designer.plant.spec import PlantSpec
    topology = REGISTRY[name]
    ex = topology.example
    res = design_circuit_plant(PlantSpec(fc_hz=ex.fn_hz, zeta=1 / (2 * ex.q), gain=ex.gain, opamp="TL072",
                                         topology=name), simulate=False)
    band = circuit_band_of(res)
    assert set(band) == set(SECTION_BAND)
    series = {"R": res.sourcing.r_series, "C": res.sourcing.c_series}
    refs = topology.designators
    grid = np.array(list(itertools.product((-1.0, 0.0, 1.0), repeat=len(refs))))
    values = {r: res.values[r] * (1 + TOLERANCE[series[r[0]]] * grid[:, k]) for k, r in enumerate(refs)}
    brute = {**circuit_figures(topology, values, res.opamp),
             **{f"ideal_{f}": circuit_figures(topology, values)[f] for f in ("fn_hz", "zeta")}}
    for fig in ("fn_hz", "zeta", "ideal_fn_hz", "ideal_zeta"):
        lo, hi = band[fig]
        assert lo == pytest.approx(brute[fig].min(), rel=1e-9) and hi == pytest.approx(brute[fig].max(), rel=1e-9)
        assert lo < getattr(res, "figures")["opamp" if fig in ("fn_hz", "zeta") else "ideal"][
            fig.replace("ideal_", "")] < hi


@pytest.mark.spice
@pytest.mark.parametrize("name", ["mfb-lowpass", "sallen-key-highpass"])
def test_tolerance_on_a_section_passes_inside_and_fails_outside_its_limits(name, tmp_path):
    """tolerance: [fn_hz] on a section: limits around the band pass (exit 0), limits inside it fail (exit 1)."""
    from designer.check.figures import circuit_band_of
    from designer.plant.circuit_design import design_circuit_plant
    from designer.plant.spec import PlantSpec
    topology = REGISTRY[name]
    ex = topology.example
    lo, hi = circuit_band_of(design_circuit_plant(PlantSpec(
        fc_hz=ex.fn_hz, zeta=1 / (2 * ex.q), gain=ex.gain, opamp="TL072", topology=name), simulate=False))["fn_hz"]
    base = spec_text(topology).replace("design_checks: all\n", "")
    for (a, b), code in (((0.999 * lo, 1.001 * hi), 0), ((1.001 * lo, 0.999 * hi), 1)):
        path = tmp_path / "spec.yaml"
        path.write_text(base.replace("checks:\n", f"checks:\n  fn_hz: {{min: {a!r}, max: {b!r}}}\n")
                        + "tolerance: [fn_hz]\n")
        out = check(path, "--simulator", "ngspice-cli", "--out", str(tmp_path / f"out{code}"))
        assert out.returncode == code, out.stdout + out.stderr
        case = _cases(tmp_path / f"out{code}")["tolerance_fn_hz"]
        assert case["status"] == ("pass" if code == 0 else "fail")


def _yield_run(tmp_path, text: str) -> tuple:
    """check-design of the spec ``text`` in ngspice (it passes or fails, no error): (result.json's
    monte_carlo, monte-carlo.csv's rows)."""
    import csv
    path = tmp_path / "spec.yaml"
    path.write_text(text)
    out = check(path, "--simulator", "ngspice-cli", "--out", str(tmp_path / "out"))
    assert out.returncode in (0, 1), out.stdout + out.stderr
    d = json.loads(next((tmp_path / "out").rglob("reports/*/result.json")).read_text())
    with open(d["files"]["monte_carlo_csv"], newline="") as fh:
        return d["monte_carlo"], list(csv.DictReader(fh))


@pytest.mark.spice
@pytest.mark.parametrize("name", ["mfb-lowpass", "sallen-key-highpass"])
def test_a_section_s_yield_with_the_spice_engine_and_the_op_amp_s_spread(name, tmp_path):
    """yield: {engine: spice} with tolerances: {GBW: 30%} on a section: a high-pass's .ac in ngspice (its fitted
    fn next to the op-amp-aware model with that build's parts and GBW: within 1 %, the engine's tested bound),
    a low-pass's step (fn_hz then the model's, SPICE's step figures beside it); the yield the share of
    monte-carlo.csv's rows inside the check."""
    import dataclasses

    import numpy as np

    from designer.core.opamps import get as get_opamp
    from designer.plant.circuit import circuit_figures
    topology = REGISTRY[name]
    ex = topology.example
    mc, rows = _yield_run(tmp_path, spec_text(topology).replace("opamp: TL072", "opamp: LM741").replace(
        "checks:\n", f"checks:\n  fn_hz: {{min: {0.98 * ex.fn_hz:g}, max: {1.02 * ex.fn_hz:g}}}\n")
        + "tolerances: {R: 1%, C: 2%, GBW: 30%}\nyield: {min: 10%, samples: 30, seed: 7, engine: spice}\n")
    assert mc["settings"]["engine"] == "spice" and mc["settings"]["tolerances_pct"]["GBW"] == 30
    assert len(rows) == 30
    amp = get_opamp("LM741")
    fn = np.array([float(r["fn_hz"]) for r in rows])
    model = np.array([float(circuit_figures(topology, {p: float(r[p]) for p in topology.designators},
                                            dataclasses.replace(amp, gbw_hz=float(r["GBW"])))["fn_hz"]) for r in rows])
    np.testing.assert_allclose(fn, model, rtol=0.01)
    inside = (fn >= 0.98 * ex.fn_hz) & (fn <= 1.02 * ex.fn_hz)
    assert mc["yield"]["fraction"] == pytest.approx(inside.mean())
    assert _cases(tmp_path / "out")["yield"]["status"] == ("pass" if inside.mean() >= 0.1 else "fail")


@pytest.mark.spice
def test_a_low_pass_section_s_spice_yield_counts_spice_s_step_with_the_slew_spread(tmp_path):
    """yield: {engine: spice} on a low-pass section runs its square-wave step in ngspice, as design-plant
    --topology --engine spice does: tolerances: {SR: ..} accepted (the step slews), rise_time_s and
    overshoot_pct counted from SPICE's step (monte-carlo.csv's spice_* columns), the yield their share."""

    import numpy as np
    topology = REGISTRY["mfb-lowpass"]
    mc, rows = _yield_run(tmp_path, spec_text(topology).replace(
        "checks:\n", "checks:\n  overshoot_pct: {max: 4.5}\n  rise_time_s: {max: 1m}\n")
        + "tolerances: {R: 2%, C: 5%, SR: 20%}\nyield: {min: 10%, samples: 12, seed: 5, engine: spice}\n")
    assert mc["settings"]["engine"] == "spice" and mc["settings"]["tolerances_pct"]["SR"] == 20
    assert mc["spice"]["analysis"] == "step"
    over = np.array([float(r["spice_overshoot_pct"]) for r in rows])
    rise = np.array([float(r["spice_rise_time_s"]) for r in rows])
    assert len(rows) == 12 and not np.allclose(over, [float(r["overshoot_pct"]) for r in rows], rtol=1e-9, atol=0)
    ideal = np.array([float(r["ideal_fn_hz"]) for r in rows])     # spec_text's own check, the model's
    ex = topology.example
    inside = (over <= 4.5) & (rise <= 1e-3) & (ideal >= float(f"{0.95 * ex.fn_hz:g}")) \
        & (ideal <= float(f"{1.05 * ex.fn_hz:g}"))
    assert mc["yield"]["fraction"] == pytest.approx(inside.mean())
    case = _cases(tmp_path / "out")["yield"]
    assert case["status"] == ("pass" if inside.mean() >= 0.1 else "fail")
    assert "over overshoot_pct, rise_time_s, ideal_fn_hz (spice engine" in case["message"]


@pytest.mark.spice
def test_spice_agreement_against_the_ideal_model_on_a_section(tmp_path):
    """against: ideal: the same square-wave run against the ideal-op-amp model (the library's nrms_ideal of the
    same design), farther from SPICE than the op-amp-aware model."""
    from designer.plant.circuit_design import default_square_hz, design_circuit_plant, with_square_test
    from designer.plant.spec import PlantSpec
    topology = REGISTRY["mfb-lowpass"]
    ex = topology.example
    path = tmp_path / "spec.yaml"
    path.write_text(spec_text(topology) + "spice_agreement: {nrms_max: 1, against: ideal}\n")
    out = check(path, "--simulator", "ngspice-cli", "--out", str(tmp_path / "out"))
    assert out.returncode == 0, out.stdout + out.stderr
    case = _cases(tmp_path / "out")["spice_agreement"]
    assert "against the ideal model" in case["message"]
    res = design_circuit_plant(PlantSpec(fc_hz=ex.fn_hz, zeta=1 / (2 * ex.q), gain=ex.gain, opamp="TL072",
                                         alternatives=1, topology=topology.name), simulator="ngspice-cli")
    with_square_test(res, 2.0, default_square_hz(res), "ngspice-cli")
    assert case["value"] == pytest.approx(res.square.nrms_ideal, rel=1e-6)
    assert res.square.nrms < res.square.nrms_ideal


@pytest.mark.spice
@pytest.mark.parametrize("stimulus", ["", "stimulus: {frequency: 50}\n"], ids=["its-own-test", "the-spec-s"])
def test_a_section_s_bench_is_set_for_the_square_wave_test_it_ran(stimulus, tmp_path):
    """The bench a section's sheet and JSON give (test signal, scope, tolerance band) is the one of the square
    wave its SPICE run played, as the seed plant's: the spec's stimulus.frequency when it gives one, else the
    test check-design runs for spice_agreement (default_square_hz), not the square wave recommended before that
    test ran (a bug: the scope was set for another frequency than the run's)."""
    from designer.core.jsonio import json_safe
    from designer.plant.circuit_design import default_square_hz, design_circuit_plant, with_bench, with_square_test
    from designer.plant.spec import PlantSpec
    topology = REGISTRY["mfb-lowpass"]
    ex = topology.example
    path = tmp_path / "spec.yaml"
    # critically damped: the step's 2 % settling (the bench's recommended 330 Hz) and the slowest pole's
    # (check-design's own test, 470 Hz) round to two square waves
    text = spec_text(topology).replace(f"zeta: {1 / (2 * ex.q):.6g}", "zeta: 1")
    path.write_text(text + stimulus + "spice_agreement: {nrms_max: 1}\n")
    out = check(path, "--simulator", "ngspice-cli", "--out", str(tmp_path / "out"))
    assert out.returncode == 0, out.stdout + out.stderr
    d = json.loads(next((tmp_path / "out").rglob("reports/*/result.json")).read_text())
    res = design_circuit_plant(PlantSpec(fc_hz=ex.fn_hz, zeta=1, gain=ex.gain, opamp="TL072", alternatives=1,
                                         topology=topology.name), simulate=False)
    recommended = res.test.frequency_hz
    want = 50.0 if stimulus else default_square_hz(res)
    assert stimulus or want != pytest.approx(recommended, rel=1e-3)     # the case the bug hid in
    assert d["square_test"]["generator"]["frequency_hz"] == pytest.approx(want, rel=1e-12)
    assert d["test_signal"] == d["square_test"]["generator"]
    # the scope and the tolerance band the library sets for that square wave, to the bit
    with_square_test(res, 2.0, want, "ngspice-cli")
    with_bench(res)
    for key, part in (("scope", res.scope), ("tolerance_band", res.tolerance)):
        assert d[key] == json.loads(json.dumps(json_safe(part.to_dict()))), key
