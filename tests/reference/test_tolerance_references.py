"""The committed Monte Carlo references (``make demo``) reproduce: the seed's plant
with its E-series tolerances (yield, worst case, the part to tighten) and the
optimised LM741 loop (its probability of instability, its yield within its limits
and the part to tighten); each bundle holds a histogram per limited figure."""

import io
import json

import numpy as np
import pytest
from helpers import ROOT

from designer.core import opamps
from designer.pid.design import design_pid
from designer.pid.spec import PidSpec
from designer.plant.sallenkey import SallenKeyParts
from designer.tolerance.loop import loop_monte_carlo
from designer.tolerance.montecarlo import plant_monte_carlo, plant_worst_case


def committed(name):
    path = ROOT / "reports" / name / "result.json"
    if not path.exists():
        pytest.skip(f"{path} not generated (run make demo)")
    return json.loads(path.read_text()), path.parent


def test_the_plants_monte_carlo_reproduces():
    ref, folder = committed("plant_fc3500_z0.2")
    mc_ref, b = ref["monte_carlo"], ref["built"]
    parts = SallenKeyParts(b["R1_ohm"], b["R2_ohm"], b["C1_f"], b["C2_f"])
    st = mc_ref["settings"]
    limits = [f"{lim['figure']}={lim['min']}:{lim['max']}" for lim in mc_ref["limits"]]
    mc = plant_monte_carlo(parts, {"R": ref["series"]["r"], "C": ref["series"]["c"]}, opamps.get(ref["opamp"]["name"]),
                           st["samples"], st["seed"], st["sampler"], st["dist"], limit_items=limits)
    got = json.loads(json.dumps(mc.to_dict()))
    assert got["yield"]["passed"] == mc_ref["yield"]["passed"]
    assert got["tighten"] == pytest.approx(mc_ref["tighten"])
    assert got["statistics"]["fn_hz"]["mean"] == pytest.approx(mc_ref["statistics"]["fn_hz"]["mean"], rel=1e-9)
    rows = np.genfromtxt(io.StringIO((folder / "monte-carlo.csv").read_text()), delimiter=",", names=True)
    np.testing.assert_allclose(rows["fn_hz"], mc.figures["fn_hz"], rtol=1e-8)
    for lim in mc_ref["limits"]:
        assert (folder / f"mc-{lim['figure']}.png").read_bytes()[:4] == b"\x89PNG"
    wc = plant_worst_case(parts, {"R": ref["series"]["r"], "C": ref["series"]["c"]}, opamps.get(ref["opamp"]["name"]))
    assert wc.to_dict()["fn_hz"]["max"]["value"] == pytest.approx(ref["worst_case"]["fn_hz"]["max"]["value"], rel=1e-6)


def test_the_loops_monte_carlo_reproduces():
    ref, folder = committed("pid_optimize_os10_lm741_fc3500_z0.2")
    mc_ref = ref["monte_carlo"]
    res = design_pid(PidSpec(plant_fc_hz=3500, plant_zeta=0.2, opamp="LM741", tuning="optimize",
                             target_overshoot_pct=10), simulate=False)
    st = mc_ref["settings"]
    limits = [f"{lim['figure']}={lim['min']}:{lim['max']}" for lim in mc_ref["limits"]]
    assert [lim["figure"] for lim in mc_ref["limits"]] == ["phase_margin_deg", "model_overshoot_pct"]
    mc = loop_monte_carlo(res, {"R": "E24", "C": "E12"}, st["samples"], st["seed"], st["sampler"], st["dist"],
                          limit_items=limits)
    got = json.loads(json.dumps(mc.to_dict()))
    assert got["yield"]["passed"] == mc_ref["yield"]["passed"]
    assert got["failing_samples"] == mc_ref["failing_samples"]
    assert got["tighten"]["part"] == mc_ref["tighten"]["part"]
    assert got["tighten"]["yield"] == pytest.approx(mc_ref["tighten"]["yield"])
    rows = np.genfromtxt(io.StringIO((folder / "monte-carlo.csv").read_text()), delimiter=",", names=True)
    good = (rows["stable"] == 1)
    for lim in mc_ref["limits"]:
        good &= (rows[lim["figure"]] >= lim["min"]) & (rows[lim["figure"]] <= lim["max"])
    assert int(good.sum()) == mc_ref["yield"]["passed"]
    for lim in mc_ref["limits"]:
        assert (folder / f"mc-{lim['figure']}.png").read_bytes()[:4] == b"\x89PNG"
    assert got["p_unstable"]["count"] == mc_ref["p_unstable"]["count"]
    assert got["p_saturated"]["count"] == mc_ref["p_saturated"]["count"]
    assert got["statistics"]["phase_margin_deg"]["mean"] == pytest.approx(
        mc_ref["statistics"]["phase_margin_deg"]["mean"], abs=0.01)
