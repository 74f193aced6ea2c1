"""check-design end to end, with real ngspice: the dogfood specs give their
exact counts with both backends, the JUnit file is what CI reporters read, a
crash or a hang is exit 3 and an <error>, a bad deck exit 2, golden waveforms
are recorded and compared, --out holds each spec's files."""

import json
import math
import shutil
import subprocess
import textwrap
import xml.etree.ElementTree as ET

import pytest
import yaml
from helpers import ROOT, script

from designer.check.sections import SUB
from designer.check.spec import TOP

pytestmark = pytest.mark.spice

SPECS = sorted(str(p) for p in (ROOT / "specs").glob("*.yaml"))
#: the dogfood specs' verdicts: every check passes but the seed's Kp = 45 design, which fails its
#: overshoot limit (the loop oscillates: no overshoot to measure) and four design checks (unstable,
#: phase margin, slew rate, output swing); report-only: zeta on both plant corners and the ZN
#: controller's phase margin
EXPECTED = {"tests": 93, "failures": 5, "errors": 0, "skipped": 5}
EXPECTED_FAILED = {"overshoot_pct", "closed_loop_stable", "phase_margin", "slew_rate", "output_swing"}


def check_design(*args, cwd=None, timeout=600):
    return subprocess.run([script("check-design"), *map(str, args)], capture_output=True, text=True,
                          cwd=cwd, timeout=timeout)


def validate_junit(path) -> ET.Element:
    """The structure GitHub's and GitLab's JUnit readers rely on, checked element by element."""
    root = ET.parse(path).getroot()
    assert root.tag == "testsuites"
    totals = dict.fromkeys(("tests", "failures", "errors", "skipped"), 0)
    for suite in root:
        assert suite.tag == "testsuite" and suite.get("name")
        cases = suite.findall("testcase")
        assert {child.tag for child in suite} <= {"properties", "testcase"}
        count = {"tests": len(cases), "failures": 0, "errors": 0, "skipped": 0}
        for case in cases:
            assert case.get("name") and case.get("classname") and float(case.get("time")) >= 0
            kids = list(case)
            assert len(kids) <= 1 and {k.tag for k in kids} <= {"failure", "error", "skipped"}
            for k in kids:
                assert k.get("message")
                count[{"failure": "failures", "error": "errors", "skipped": "skipped"}[k.tag]] += 1
        for key, value in count.items():
            assert int(suite.get(key)) == value, (suite.get("name"), key)
            totals[key] += value
        float(suite.get("time"))
        for prop in suite.find("properties"):
            assert prop.tag == "property" and prop.get("name") and prop.get("value") is not None
    for key, value in totals.items():
        assert int(root.get(key)) == value
    return root


@pytest.mark.parametrize("simulator", ["pyspice", "ngspice-cli"])
def test_dogfood_specs_give_the_expected_counts(simulator, tmp_path):
    junit, summary = tmp_path / "junit.xml", tmp_path / "summary.md"
    out = check_design(*SPECS, "--root", ROOT, "--junit", junit, "--summary", summary, "--jobs", "2", "--simulator", simulator,
                       cwd=ROOT)
    assert out.returncode == 1, out.stderr
    root = validate_junit(junit)
    assert {k: int(root.get(k)) for k in EXPECTED} == EXPECTED
    # junitparser reads it as the CI reporters do
    from junitparser import JUnitXml
    suites = {s.name: s for s in JUnitXml.fromfile(str(junit))}
    assert set(suites) == {p.split("/")[-1][:-5] for p in SPECS}
    seed = suites["pid_seed_kp45_lm741_fc3500_z0.2"]
    assert seed.failures == len(EXPECTED_FAILED)
    failed = {c.name for c in seed if any(r._tag == "failure" for r in c.result)}
    assert failed == EXPECTED_FAILED
    props = {p.name: p.value for p in suites["plant_fc3500_z0.2"].properties()}
    assert props["simulator"] == simulator and props["ngspice"] and props["tool"].startswith("designer ")
    classnames = {c.classname for c in suites["plant_fc3500_z0.2"]}
    assert classnames == {"plant_fc3500_z0.2[LM741]", "plant_fc3500_z0.2[TL072]"}
    # every failure line names the spec, the corner and the value against its limit
    lines = [ln for ln in out.stderr.splitlines() if ln.startswith("check-design: failed:")]
    assert len(lines) == EXPECTED["failures"]
    assert "check-design: failed: pid_seed_kp45_lm741_fc3500_z0.2 [LM741]: overshoot_pct not measured " \
           "(limits <= 20)" in lines
    md = summary.read_text()
    assert "| pid_seed_kp45_lm741_fc3500_z0.2 | LM741 | **FAIL** |" in md
    assert f"{EXPECTED['failures']} failed" in md


def test_jobs_do_not_change_the_output(tmp_path):
    runs = []
    for jobs in ("1", "2"):
        junit = tmp_path / f"j{jobs}.xml"
        check_design(*SPECS, "--root", ROOT, "--junit", junit, "--jobs", jobs, "--no-fail", cwd=ROOT)
        root = ET.parse(junit).getroot()
        runs.append([(c.get("classname"), c.get("name"), [k.tag for k in c]) for c in root.iter("testcase")])
    assert runs[0] == runs[1]


def _user_project(tmp_path):
    """A user's repository: the dogfood deck and its spec, golden file recorded here."""
    (tmp_path / "decks").mkdir()
    shutil.copy(ROOT / "specs" / "decks" / "rc_ladder.cir", tmp_path / "decks")
    spec = (ROOT / "specs" / "rc_ladder.yaml").read_text().replace("golden/rc_ladder.csv", "golden/rc.csv")
    (tmp_path / "rc.yaml").write_text(spec)
    return tmp_path / "rc.yaml"


def test_golden_waveforms_are_recorded_compared_and_plotted_when_they_fail(tmp_path):
    spec = _user_project(tmp_path)
    rec = check_design(spec, "--update-golden", "--simulator", "ngspice-cli")
    assert rec.returncode == 0, rec.stderr
    golden = tmp_path / "golden" / "rc.csv"
    text = golden.read_text()
    assert "# simulator: ngspice-cli" in text and "# ngspice: " in text and "# tool: designer " in text
    # compared with the other backend: same waveform, a warning (property) for the simulator, no failure
    junit = tmp_path / "j.xml"
    same = check_design(spec, "--junit", junit, "--simulator", "pyspice")
    assert same.returncode == 0, same.stderr
    props = {p.get("name"): p.get("value") for p in ET.parse(junit).getroot().iter("property")}
    assert "simulator ngspice-cli -> pyspice" in props["warning_1"]
    # a golden waveform 5 % off fails, with a plot of gold, test and their normalised error
    lines = text.splitlines()
    head = [ln for ln in lines if ln.startswith("#") or ln.startswith("time_s")]
    rows = [ln.split(",") for ln in lines[len(head):]]
    golden.write_text("\n".join(head + [f"{r[0]},{float(r[1]) * 1.05!r}" for r in rows]) + "\n")
    out_dir = tmp_path / "out"
    bad = check_design(spec, "--out", out_dir, "--junit", junit)
    assert bad.returncode == 1
    assert "rc_ladder: golden_out: nrms = " in bad.stderr and "not below 1" in bad.stderr
    assert (out_dir / "rc_ladder" / "golden-rc_ladder-out.png").read_bytes()[:4] == b"\x89PNG"
    result = json.loads((out_dir / "rc_ladder" / "result.json").read_text())
    assert result["schema_version"] >= 2 and result["status"] == "fail"
    assert result["tool"]["ngspice"] and result["corners"][0]["design"]["measurements"]["v_final"] > 0.9


def test_out_holds_each_specs_result_and_build_sheet(tmp_path):
    spec = ROOT / "specs" / "pid_optimize_os10_lm741_fc3500_z0.2.yaml"
    out = check_design(spec, "--root", ROOT, "--out", tmp_path, cwd=ROOT)
    assert out.returncode == 0, out.stderr
    folder = tmp_path / "pid_optimize_os10_lm741_fc3500_z0.2"
    result = json.loads((folder / "result.json").read_text())
    assert result["status"] == "pass" and result["counts"]["fail"] == 0
    corner = result["corners"][0]
    assert corner["design"]["tool"]["simulator"] == "pyspice"
    assert (folder / "reports" / "LM741" / "build-sheet.md").exists()
    assert corner["files"]["build_sheet"].endswith("build-sheet.md")


FIGHT = "two sources fight\nV1 a 0 1\nV2 a 0 2\nR1 a 0 1k\n.tran 1u 1m\n.meas tran vmax MAX v(a)\n.end\n"
LONG = "long run\nV1 in 0 SIN(0 1 1k)\nR1 in out 1k\nC1 out 0 100n\n.tran 1n 1\n.meas tran vmax MAX v(out)\n.end\n"
BAD = "bad deck\nV1 in 0 1\nR1 in out 1k\nX1 in out nosuchsubckt\n.tran 1u 1m\n.meas tran vmax MAX v(out)\n.end\n"


def _deck_spec(tmp_path, deck):
    (tmp_path / "d.cir").write_text(deck)
    spec = tmp_path / "d.yaml"
    spec.write_text("kind: netlist\ndeck: d.cir\nchecks:\n  vmax: {max: 10}\n")
    return spec


@pytest.mark.parametrize("simulator", ["pyspice", "ngspice-cli"])
@pytest.mark.parametrize("deck, timeout, words", [
    (FIGHT, "600", "timestep too small"),        # ngspice gives up on the circuit: a failed run
    (LONG, "2", "timed out after 2 s"),          # a real run far longer than the timeout: killed
])
def test_a_crashing_or_hanging_simulator_is_exit_3_and_a_junit_error(tmp_path, simulator, deck, timeout, words):
    spec, junit = _deck_spec(tmp_path, deck), tmp_path / "j.xml"
    out = check_design(spec, "--junit", junit, "--timeout", timeout, "--simulator", simulator, timeout=120)
    assert out.returncode == 3, out.stderr
    errors = list(ET.parse(junit).getroot().iter("error"))
    assert len(errors) == 1 and words in errors[0].get("message") and errors[0].get("type") == "simulator"
    assert len(out.stderr.strip().splitlines()) == 1
    assert check_design(spec, "--timeout", timeout, "--simulator", simulator, "--no-fail").returncode == 0


@pytest.mark.parametrize("simulator", ["pyspice", "ngspice-cli"])
def test_a_deck_ngspice_cannot_read_is_a_bad_spec(tmp_path, simulator):
    out = check_design(_deck_spec(tmp_path, BAD), "--simulator", simulator)
    assert out.returncode == 2
    assert out.stderr.count("\n") == 1 and "ngspice cannot read the deck" in out.stderr
    assert "unknown subckt" in out.stderr


def test_fail_on_check_is_exit_1_when_a_check_or_the_spice_agreement_fails(tmp_path):
    def run(name, *args):
        return subprocess.run([script(name), *args, "--no-files", "--fail-on-check", "--simulator", "ngspice-cli"],
                              capture_output=True, text=True, timeout=600)
    ok = run("design-plant", "--fc", "3500", "--zeta", "0.2")
    assert ok.returncode == 0, ok.stderr
    # the example: 20 V through the seed's rounded parts slews, clips and so disagrees with the model
    slow = run("analyze-plant", "--r1", "820", "--r2", "1k", "--c1", "10n", "--c2", "220n", "--amplitude", "20")
    assert slow.returncode == 1
    failed = {ln.split(": ")[2] for ln in slow.stderr.splitlines() if "check failed" in ln}
    assert {"slew_rate", "output_swing", "spice_agreement"} <= failed
    seed = run("design-pid", "--plant-fc", "3500", "--plant-zeta", "0.2", "--kp", "45", "--ti", "43.215u",
               "--td", "10.8037u", "--seed-parts")
    assert seed.returncode == 1 and "check failed: closed_loop_stable" in seed.stderr


#: a 22.9 kHz plant (fn and zeta of the parts alone), fast enough for the 700 kHz LM358 to pull its fn 5 % down
FAST_PLANT = """\
name: fast-plant
kind: plant
parts: {R1: 1k, R2: 1k, C1: 2n2, C2: 22n}
opamp: [LM358, TL072]
stimulus: {amplitude: 0.5}
checks:
  fn_hz: {min: 22.2k, max: 26k}
  ideal_fn_hz: {min: 22k, max: 24k}
  fn_opamp_hz: {min: 22.2k, max: 26k}
  q: {min: 1, fail: false}
  ideal_q: {min: 1, fail: false}
"""


def test_fn_hz_is_each_corners_own_and_ideal_fn_hz_the_parts_alone(tmp_path):
    spec = tmp_path / "fast.yaml"
    spec.write_text(FAST_PLANT)
    out = check_design(spec, "--out", tmp_path / "out")
    assert out.returncode == 1, out.stderr
    # the slow op-amp's corner fails on its own fn (and the alias with it), the fast one passes
    failed = [ln for ln in out.stderr.splitlines() if ln.startswith("check-design: failed:")]
    assert len(failed) == 2 and all(ln.startswith("check-design: failed: fast-plant [LM358]: fn") for ln in failed)
    result = json.loads((tmp_path / "out" / "fast-plant" / "result.json").read_text())
    value = {(c["corner"], k["id"]): k["value"] for c in result["corners"] for k in c["cases"]}
    fn = {corner: value[(corner, "fn_hz")] for corner in ("LM358", "TL072")}
    ideal = {corner: value[(corner, "ideal_fn_hz")] for corner in ("LM358", "TL072")}
    assert ideal["LM358"] == ideal["TL072"] == pytest.approx(1 / (2 * math.pi * math.sqrt(1e3 * 1e3 * 2.2e-9 * 22e-9)))
    assert fn["LM358"] < 0.97 * ideal["LM358"] and fn["LM358"] < fn["TL072"] < ideal["TL072"]
    assert all(value[(c, "fn_opamp_hz")] == fn[c] for c in fn)     # the earlier name, still read
    assert value[("LM358", "q")] > value[("TL072", "q")]     # the slow op-amp lowers zeta too
    assert value[("LM358", "ideal_q")] == value[("TL072", "ideal_q")]
    # the corner's fn is the op-amp-aware model's dominant pair, as the design's own JSON gives it
    design = {c["corner"]: c["design"] for c in result["corners"]}
    assert all(fn[c] == pytest.approx(design[c]["built"]["fn_opamp_hz"]) for c in fn)
    assert all(ideal[c] == pytest.approx(design[c]["built"]["fn_hz"]) for c in fn)


def test_the_help_spec_example_is_yaml_of_known_keys():
    text = check_design("--help").stdout
    lines = text[text.index("\nspec file"):].splitlines()[1:]
    start = next(i for i, ln in enumerate(lines) if ln.strip().startswith("name:"))
    end = next(i for i, ln in enumerate(lines) if ln.strip().startswith("golden:"))
    doc = yaml.safe_load(textwrap.dedent("\n".join(lines[start:end + 1])))   # the trailing # comments are YAML's
    assert isinstance(doc, dict) and doc["kind"] in TOP
    assert set(doc) <= set(TOP[doc["kind"]]), set(doc) - set(TOP[doc["kind"]])
    for key, value in doc.items():
        if key in SUB and isinstance(value, dict):
            assert set(value) <= set(SUB[key]), (key, set(value) - set(SUB[key]))
    assert doc["golden"]["file"] == "golden/lab3-{corner}.csv"
