"""A check-design spec's yield (designer.tolerance.yields): the spec's checks counted
on the analytic engine's figures, against an independent count of the samples' rows;
what is not counted is named; the failure's words."""

import io

import numpy as np
import pytest

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
