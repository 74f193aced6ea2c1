"""A check-design spec's yield (designer.tolerance.yields): the spec's checks counted
on the analytic engine's figures, against an independent count of the samples' rows;
what is not counted is named; the failure's words."""

import io

import numpy as np
import pytest

from designer.tolerance.spice_mc import plant_context
from designer.check.limits import Limit as CheckLimit
from designer.plant.design import design_plant
from designer.plant.spec import PlantSpec
from designer.tolerance.yields import LOOP, PLANT, counted, spec_yield


@pytest.fixture(scope="module")
def plant():
    return design_plant(PlantSpec(fc_hz=3500, zeta=0.2, alternatives=1), simulate=False)


CHECKS = (CheckLimit("fn_hz", 3.4e3, None, 3.6e3, unit="Hz"), CheckLimit("overshoot_pct", None, None, 60.0),
          CheckLimit("nrms", None, None, 1.0), CheckLimit("zeta", 0.3, None, None, fail=False))


def test_only_failing_checks_on_engine_figures_count():
    use, skipped = counted("plant", CHECKS)
    assert [c.figure for c in use] == ["fn_hz", "overshoot_pct"] and skipped == ("nrms",)
    assert PLANT["model_overshoot_pct"] == PLANT["overshoot_pct"] == "overshoot_pct"
    assert LOOP["overshoot_pct"] == LOOP["model_overshoot_pct"] == "model_overshoot_pct"


def test_the_yield_is_the_count_of_rows_inside_the_checks(plant):
    v = spec_yield("plant", plant, CHECKS, 0.99, 3000, 1, ("R=1%", "C=5%", "C2=2%"))
    rows = np.genfromtxt(io.StringIO(v.mc.csv_text()), delimiter=",", names=True)
    inside = (rows["fn_hz"] >= 3400) & (rows["fn_hz"] <= 3600) & (rows["overshoot_pct"] <= 60)
    assert v.mc.yield_count == int(inside.sum()) and v.fraction == pytest.approx(inside.mean())
    assert v.mc.tolerances.of == pytest.approx({"R1": 0.01, "R2": 0.01, "C1": 0.05, "C2": 0.02})
    assert not v.ok and v.fraction < 0.99
    msg = v.message()
    lo, hi = v.mc.yield_interval()
    assert msg.startswith(f"yield: {100 * v.fraction:.4g} % ({v.mc.yield_count}/3000 builds; 95 % Wilson interval "
                          f"{100 * lo:.4g} % to {100 * hi:.4g} %) below min 99 %")
    assert "not counted, no engine figure: nrms" in msg
    assert f"fn_hz loses most: {int((~((rows['fn_hz'] >= 3400) & (rows['fn_hz'] <= 3600))).sum())} builds " \
           "outside 3.4 kHz to 3.6 kHz" in msg
    i, parts = v.corner()
    far = np.argmax(np.where(inside, -1, np.abs(rows["fn_hz"] - 3500)))
    assert i == far and f"(build {i}, its worst): R1 " in msg
    assert parts["C2"][0] == pytest.approx(rows["C2"][i]) and abs(parts["C2"][1]) <= 0.02


def test_a_yield_met_says_so(plant):
    wide = (CheckLimit("fn_hz", 3e3, None, 4e3, unit="Hz"),)
    v = spec_yield("plant", plant, wide, 0.5, 200, 1)     # the series' tolerances: E24 5 %, E12 10 %
    assert v.mc.tolerances.of == pytest.approx({"R1": 0.05, "R2": 0.05, "C1": 0.10, "C2": 0.10})
    assert v.ok and "at or above min 50 %" in v.message() and "loses" not in v.message()


# ---- engine: spice --------------------------------------------------------------------------------

SPICE_CHECKS = (CheckLimit("fn_hz", 3.4e3, None, 3.6e3, unit="Hz"), CheckLimit("overshoot_pct", None, None, 54.0),
                CheckLimit("settling_time_s", None, None, 1.5e-3, unit="s"), CheckLimit("nrms", None, None, 1.0))


@pytest.mark.spice
def test_the_spice_engine_counts_spices_step_figures_and_the_models_others(plant):
    """engine: spice counts overshoot_pct and settling_time_s (which the analytic engine cannot) from
    each build's ngspice run, and fn_hz from the model, against an independent count of the rows;
    a SPICE row is the build's own run (spice_engine.evaluate of its parts)."""
    from designer.tolerance import spice_engine
    use, skipped = counted("plant", SPICE_CHECKS, "spice")
    assert [c.figure for c in use] == ["fn_hz", "overshoot_pct", "settling_time_s"] and skipped == ("nrms",)
    v = spec_yield("plant", plant, SPICE_CHECKS, 0.99, 30, 3, ("R=1%", "C=5%", "SR=20%"), engine="spice")
    rows = np.genfromtxt(io.StringIO(v.mc.csv_text()), delimiter=",", names=True)
    assert {"SR", "spice_overshoot_pct", "spice_settling_time_s", "fn_hz"} <= set(rows.dtype.names)
    inside = ((rows["fn_hz"] >= 3400) & (rows["fn_hz"] <= 3600) & (rows["spice_overshoot_pct"] <= 54)
              & (rows["spice_settling_time_s"] <= 1.5e-3))
    assert v.mc.yield_count == int(inside.sum()) and v.mc.engine == "spice"
    ctx = plant_context(plant)
    parts = ("R1", "R2", "C1", "C2", "SR")
    again = spice_engine.evaluate(ctx, {k: rows[k][:3] for k in parts})
    np.testing.assert_allclose(again["overshoot_pct"], rows["spice_overshoot_pct"][:3], rtol=1e-9)
    msg = v.message()
    assert "over fn_hz, overshoot_pct, settling_time_s (spice engine" in msg
    if not v.ok:
        fig, count = v.losses()[0]
        assert f"{fig} loses most: {count} builds" in msg and "SR " in msg and "kV/s" in msg


@pytest.mark.spice
def test_a_loops_spice_yield_counts_spices_overshoot():
    from designer.pid.design import design_pid
    from designer.pid.spec import PidSpec
    res = design_pid(PidSpec(plant_fc_hz=3500, plant_zeta=0.2, tuning="optimize", target_overshoot_pct=10),
                     simulate=False)
    checks = (CheckLimit("phase_margin_deg", 27.0, None, None), CheckLimit("overshoot_pct", None, None, 8.0))
    v = spec_yield("pid", res, checks, 0.99, 10, 2, ("GBW=30%", "SR=40%"), engine="spice")
    rows = np.genfromtxt(io.StringIO(v.mc.csv_text()), delimiter=",", names=True)
    inside = (rows["stable"] == 1) & (rows["phase_margin_deg"] >= 27) & (rows["spice_overshoot_pct"] <= 8)
    assert v.mc.yield_count == int(inside.sum()) and 0 < inside.sum() < 10
    assert v.names == {"phase_margin_deg": "phase_margin_deg", "spice_overshoot_pct": "overshoot_pct"}
    assert "GBW " in v.message() and "SR " in v.message() and "(spice engine" in v.message()


# ---- a plant on a registered section ----------------------------------------------------------------

def _section(name: str, **target):
    from designer.plant.circuit_design import design_circuit_plant
    return design_circuit_plant(PlantSpec(opamp="TL072", topology=name, **target), simulator="ngspice-cli")


@pytest.mark.spice
def test_a_low_pass_section_s_spice_yield_counts_spice_s_step_as_the_command_line_does(tmp_path):
    """engine: spice on an MFB low-pass runs its step in ngspice (the command line's engine on it,
    spice_mc.section_analysis), SR spread: overshoot_pct counted from SPICE's step beside the model's own
    figures; the yield equals design-plant --topology --engine spice's on the same seed, build by build."""
    import csv
    import json
    import subprocess

    from helpers import script
    res = _section("mfb-lowpass", fc_hz=1000, zeta=0.3, gain=2)
    tol = ("R=2%", "C=5%", "SR=20%")
    model = spec_yield("plant", res, (CheckLimit("overshoot_pct", 0.0, None, 37.0),), 0.5, 12, 4, tol[:2])
    v = spec_yield("plant", res, (CheckLimit("overshoot_pct", 0.0, None, 37.0),), 0.5, 12, 4, tol, engine="spice")
    assert v.names == {"spice_overshoot_pct": "overshoot_pct"} and v.mc.engine == "spice"
    assert v.mc.spice["analysis"] == "step" and v.mc.tolerances.of["SR"] == pytest.approx(0.2)
    figs = v.mc.figures
    # the model's figures kept under their own names, SPICE's step beside them (its own numbers)
    assert not np.array_equal(figs["spice_overshoot_pct"], figs["overshoot_pct"])
    assert np.isfinite(figs["spice_settling_time_s"]).all() and "SR" in v.message()
    assert v.mc.yield_count == int(np.count_nonzero(figs["spice_overshoot_pct"] <= 37.0))
    assert model.mc.engine == "analytic" and "spice_overshoot_pct" not in model.mc.figures
    out = subprocess.run([script("design-plant"), "--topology", "mfb-lowpass", "--fc", "1000", "--zeta", "0.3",
                          "--gain", "2", "--opamp", "TL072", "--monte-carlo", "12", "--seed", "4", "--engine",
                          "spice", *(a for t in tol for a in ("--tol", t)), "--limit", "overshoot_pct=0:37",
                          "--simulator", "ngspice-cli", "--out", str(tmp_path)],
                         capture_output=True, text=True, timeout=300)
    assert out.returncode == 0, out.stdout + out.stderr
    d = json.loads(next(tmp_path.rglob("result.json")).read_text())
    assert d["monte_carlo"]["yield"]["passed"] == v.mc.yield_count
    with open(d["files"]["monte_carlo_csv"], newline="") as fh:
        rows = list(csv.DictReader(fh))
    np.testing.assert_allclose([float(r["overshoot_pct"]) for r in rows], figs["spice_overshoot_pct"], rtol=1e-9)


@pytest.mark.spice
def test_a_high_pass_section_s_spice_yield_is_its_ac_as_before():
    """engine: spice on a high-pass stays each build's .ac fitted (its step settles to 0): the same builds
    and figures as the .ac engine's own Monte Carlo (plant_monte_carlo with spice_ac.section_evaluate)."""
    from designer.plant import circuit
    from designer.tolerance import spice_ac
    from designer.tolerance.montecarlo import plant_monte_carlo
    res = _section("sallen-key-highpass", fc_hz=1000, zeta=0.4)
    checks = (CheckLimit("fn_hz", 980.0, None, 1020.0), CheckLimit("overshoot_pct", 0.0, None, 40.0))
    v = spec_yield("plant", res, checks, 0.5, 10, 2, ("R=1%", "C=2%"), engine="spice")
    assert v.names == {"fn_hz": "fn_hz", "overshoot_pct": "overshoot_pct"} and v.mc.spice["analysis"] == "ac"
    model = (res.topology, res.opamp)
    evaluate = spice_ac.section_evaluate(spice_ac.context(res.deck, res.netlist, res.section, dict(res.values),
                                                          res.figures["ideal"]["fn_hz"], "ngspice-cli", res.opamp),
                                         model)
    s = res.sourcing
    before = plant_monte_carlo(None, {"R": s.r_series, "C": s.c_series}, res.opamp, 10, 2, "random", "uniform",
                               ("R=1%", "C=2%"), v.mc.limits, tighten=False, engine_name="spice",
                               evaluate=evaluate, circuit=(dict(res.values), circuit.evaluate, model))
    assert v.mc.yield_count == before.yield_count
    for k in before.figures:
        np.testing.assert_array_equal(v.mc.figures[k], before.figures[k])
    from designer.core.errors import DesignError
    with pytest.raises(DesignError, match="SR") as err:
        spec_yield("plant", res, checks, 0.5, 10, 2, ("SR=20%",), engine="spice")
    assert err.value.param == "SR"
