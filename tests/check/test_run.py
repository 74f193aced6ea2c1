"""check-design's Monte Carlo yield from the outside (designer.check.run: a spec's
tolerances: and yield:): a yield met passes, one missed fails naming the figure
that loses most, the yield with its interval and the worst build's parts, and the
corner's bundle and result.json carry the Monte Carlo."""

import io
import json
import os
import subprocess
import textwrap
import xml.etree.ElementTree as ET

import numpy as np
import pytest
from helpers import script

CHECK_DESIGN = script("check-design")

PLANT = """\
    name: yplant
    kind: plant
    target: {{fc: 3.5k, zeta: 0.2}}
    series: {{r: E24, c: E12}}
    checks:
      fn_hz: {{min: {lo}, max: {hi}}}
      overshoot_pct: {{max: 60}}
      nrms: {{max: 1}}
    tolerances: {{R: 1%, C: 5%, C2: 2%}}
    yield: {{min: 95%, samples: 2000, seed: 1, engine: analytic}}
    """


def run(tmp_path, text, *extra):
    spec = tmp_path / "spec.yaml"
    spec.write_text(textwrap.dedent(text))
    junit = tmp_path / "j.xml"
    p = subprocess.run([CHECK_DESIGN, str(spec), "--junit", str(junit), "--simulator", "ngspice-cli", *extra],
                       capture_output=True, text=True, timeout=300, env=dict(os.environ, MPLBACKEND="Agg"))
    return p, ET.fromstring(junit.read_text()) if junit.exists() else None


def yield_case(root):
    return next(c for c in root.iter("testcase") if c.get("name") == "yield")


@pytest.mark.spice
def test_a_yield_met_passes(tmp_path):
    p, root = run(tmp_path, PLANT.format(lo="3k", hi="4k"))
    assert p.returncode == 0, p.stderr
    case = yield_case(root)
    assert case.find("failure") is None and case.get("classname") == "yplant[LM741]"


@pytest.mark.spice
def test_a_yield_missed_fails_naming_the_figure_the_interval_and_the_corner(tmp_path):
    p, root = run(tmp_path, PLANT.format(lo="3.4k", hi="3.6k"), "--out", str(tmp_path / "out"))
    assert p.returncode == 1, p.stderr
    msg = yield_case(root).find("failure").get("message")
    # an independent count of the corner's monte-carlo.csv, written beside its build sheet
    folder = tmp_path / "out" / "yplant" / "reports" / "LM741"
    rows = np.genfromtxt(io.StringIO((folder / "monte-carlo.csv").read_text()), delimiter=",", names=True)
    fn_in = (rows["fn_hz"] >= 3400) & (rows["fn_hz"] <= 3600)
    passed = int((fn_in & (rows["overshoot_pct"] <= 60)).sum())
    assert msg.startswith(f"yplant [LM741]: yield: {100 * passed / 2000:.4g} % ({passed}/2000 builds; 95 % Wilson "
                          "interval ")
    assert "below min 95 %" in msg and "not counted, no engine figure: nrms" in msg
    assert f"fn_hz loses most: {int((~fn_in).sum())} builds outside 3.4 kHz to 3.6 kHz" in msg
    worst = int(np.argmax(np.where(fn_in, -1, np.abs(rows["fn_hz"] - 3500))))
    assert f"the corner (build {worst}, its worst): R1 " in msg and "C2 " in msg
    assert (folder / "mc-fn_hz.png").read_bytes()[:8] == b"\x89PNG\r\n\x1a\n"
    result = json.loads((tmp_path / "out" / "yplant" / "result.json").read_text())
    mc = result["corners"][0]["design"]["monte_carlo"]
    assert mc["yield"]["passed"] == passed and mc["settings"]["tolerances_pct"]["C2"] == pytest.approx(2.0)


@pytest.mark.spice
def test_a_loops_yield_counts_instability_and_the_analytic_loops_figures(tmp_path):
    p, root = run(tmp_path, """\
        name: ypid
        kind: pid
        plant: {fc: 3.5k, zeta: 0.2}
        tuning: {rule: optimize, target_overshoot: 10}
        checks:
          phase_margin_deg: {min: 27}
          overshoot_pct: {max: 12}
        yield: {min: 99%, samples: 40, seed: 2}
        """)
    assert p.returncode == 1, p.stderr
    msg = yield_case(root).find("failure").get("message")
    assert "over phase_margin_deg, overshoot_pct (analytic engine" in msg and "loses most" in msg
    assert "R18 " in msg and "C4 " in msg      # the corner lists the controller's parts too


SPICE_PLANT = """\
    name: splant
    kind: plant
    target: {fc: 3.5k, zeta: 0.2}
    series: {r: E24, c: E12}
    checks:
      fn_hz: {min: 3.4k, max: 3.6k}
      overshoot_pct: {max: 54}
      settling_time_s: {max: 1.5m}
    tolerances: {R: 1%, C: 5%, C2: 2%, SR: 20%}
    yield: {min: 95%, samples: 30, seed: 1, engine: spice}
    """


@pytest.mark.spice
def test_a_spice_yield_on_a_spec_file_fails_as_the_analytic_one_does(tmp_path):
    """engine: spice on a plant spec: every build simulated, SPICE's overshoot and settling time counted
    (an independent count of the corner's monte-carlo.csv), the JUnit failure naming the figure that
    loses most, the yield and its interval, and the worst build's parts (the op-amp's SR among them)."""
    p, root = run(tmp_path, SPICE_PLANT, "--out", str(tmp_path / "out"))
    assert p.returncode == 1, p.stderr
    msg = yield_case(root).find("failure").get("message")
    folder = tmp_path / "out" / "splant" / "reports" / "LM741"
    rows = np.genfromtxt(io.StringIO((folder / "monte-carlo.csv").read_text()), delimiter=",", names=True)
    fn_in = (rows["fn_hz"] >= 3400) & (rows["fn_hz"] <= 3600)
    os_in = rows["spice_overshoot_pct"] <= 54
    ts_in = rows["spice_settling_time_s"] <= 1.5e-3
    passed = int((fn_in & os_in & ts_in).sum())
    assert msg.startswith(f"splant [LM741]: yield: {100 * passed / 30:.4g} % ({passed}/30 builds; 95 % Wilson "
                          "interval ")
    assert "below min 95 % over fn_hz, overshoot_pct, settling_time_s (spice engine, random sampler, seed 1)" in msg
    lost = {"fn_hz": int((~fn_in).sum()), "overshoot_pct": int((~os_in).sum()),
            "settling_time_s": int((~ts_in).sum())}
    fig = max(lost, key=lost.get)
    assert f"{fig} loses most: {lost[fig]} builds outside" in msg
    assert "the corner (build " in msg and "R1 " in msg and "SR " in msg
    mc = json.loads((tmp_path / "out" / "splant" / "result.json").read_text())["corners"][0]["design"]["monte_carlo"]
    assert mc["settings"]["engine"] == "spice" and mc["yield"]["passed"] == passed


@pytest.mark.spice
def test_a_loops_spice_yield_on_a_spec_file(tmp_path):
    p, root = run(tmp_path, """\
        name: spid
        kind: pid
        plant: {fc: 3.5k, zeta: 0.2}
        tuning: {rule: optimize, target_overshoot: 10}
        checks:
          phase_margin_deg: {min: 27}
          overshoot_pct: {max: 8}
        tolerances: {GBW: 30%, SR: 40%}
        yield: {min: 99%, samples: 10, seed: 2, engine: spice}
        """)
    assert p.returncode == 1, p.stderr
    msg = yield_case(root).find("failure").get("message")
    assert "over phase_margin_deg, overshoot_pct (spice engine" in msg and "loses most" in msg
    assert "R18 " in msg and "GBW " in msg and "SR " in msg
