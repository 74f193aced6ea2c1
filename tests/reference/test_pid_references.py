"""Regenerating the committed reference PID designs (``make demo``) reproduces
their parts and figures."""

import json
import re
import subprocess

import pytest
from helpers import ROOT

from designer.pid.blocks import seed_parts
from designer.pid.design import PidSpec, design_pid

pytestmark = pytest.mark.spice


def committed(name):
    path = ROOT / "reports" / name / "result.json"
    if not path.exists():
        pytest.skip(f"{path} not generated (run make demo)")
    return json.loads(path.read_text())


def test_zn_reference_reproduces():
    ref = committed("pid_zn_lm741_fc3500_z0.2")
    res = design_pid(PidSpec(plant_fc_hz=3500, plant_zeta=0.2, opamp="LM741")).to_dict()
    assert res["components"] == ref["components"]
    assert res["tuning"]["reaction_curve"]["L_s"] == pytest.approx(ref["tuning"]["reaction_curve"]["L_s"], rel=1e-6)
    a, b = res["closed_loop"], ref["closed_loop"]
    assert a["analytic"]["overshoot_pct"] == pytest.approx(b["analytic"]["overshoot_pct"], abs=0.01)
    assert a["spice"]["overshoot_pct"] == pytest.approx(b["spice"]["overshoot_pct"], abs=0.5)
    assert [c["ok"] for c in res["checks"]] == [c["ok"] for c in ref["checks"]]


def test_seed_example_reproduces():
    ref = committed("pid_seed_kp45_lm741_fc3500_z0.2")
    res = design_pid(PidSpec(plant_fc_hz=3500, plant_zeta=0.2, opamp="LM741", kp=45, ti_s=43.215e-6,
                             td_s=10.8037e-6, controller_parts=seed_parts())).to_dict()
    assert res["components"] == ref["components"]
    s = res["closed_loop"]["spice"]
    assert s["saturated"] is ref["closed_loop"]["spice"]["saturated"] is True
    assert s["stable"] is ref["closed_loop"]["spice"]["stable"] is False


def test_optimised_reference_still_passes_every_check():
    ref = committed("pid_optimize_os10_lm741_fc3500_z0.2")
    assert all(c["ok"] for c in ref["checks"])
    assert ref["closed_loop"]["spice"]["overshoot_pct"] <= 10.0
    assert ref["closed_loop"]["verdict"]["agree"]


def deck_measurements(deck, cwd) -> dict:
    """What ``ngspice -b deck`` alone prints: ``name = value`` lines of its .meas statements."""
    out = subprocess.run(["ngspice", "-b", str(deck)], capture_output=True, text=True, cwd=cwd, timeout=300)
    assert out.returncode == 0, out.stderr[-2000:]
    return {m.group(1): float(m.group(2)) for m in
            re.finditer(r"^(\w+)\s*=\s*([-+0-9.eE]+)", out.stdout, flags=re.M)}


def assert_deck_measures_like_the_report(deck, result, cwd):
    spice = result["closed_loop"]["spice"]
    printed = deck_measurements(deck, cwd)
    # same final value (the expected one, printed in the build sheet), same 2 % band, same window
    assert printed["settling_time_s"] == pytest.approx(spice["settling_time_s"], rel=1e-4)
    assert printed["rise_time_s"] == pytest.approx(spice["rise_time_s"], rel=1e-4)
    assert printed["overshoot_pct"] == pytest.approx(spice["overshoot_pct"], abs=0.01)
    # the report refines the peak with a parabola, ngspice takes its sample
    assert printed["peak_time_s"] == pytest.approx(spice["peak_time_s"], rel=2e-3)


@pytest.mark.parametrize("name", ["pid_zn_lm741_fc3500_z0.2", "pid_optimize_os10_lm741_fc3500_z0.2",
                                  "pid_seed_kp45_lm741_fc3500_z0.2"])
def test_committed_deck_alone_prints_the_reports_spice_figures(name, tmp_path):
    ref = committed(name)
    deck = ROOT / "netlists" / f"{name}.cir"
    if ref["closed_loop"]["spice"]["settling_time_s"] is None:
        # an oscillating loop has no step figures in the report; the deck's numbers mean nothing
        assert ref["closed_loop"]["spice"]["stable"] is False
        return
    assert_deck_measures_like_the_report(deck, ref, tmp_path)


def test_fresh_deck_alone_prints_the_reports_spice_figures(tmp_path):
    # a design no reference covers: a PI (SIMC) with TL072s on an equal-component plant of gain 1.5
    # (fn 1592 Hz, zeta 0.75; R3/R4 derived by the plant validation)
    from designer.pid.report import write_outputs
    from designer.plant.sallenkey import SallenKeyParts
    res = design_pid(PidSpec(plant_parts=SallenKeyParts(10e3, 10e3, 10e-9, 10e-9, 1.5), opamp="TL072",
                             tuning="simc"))
    assert res.spice.stable and res.spice.figures.settling_time_s > 0
    files = write_outputs(res, tmp_path, "fresh")
    assert_deck_measures_like_the_report(files["netlist"], res.to_dict(), tmp_path)
