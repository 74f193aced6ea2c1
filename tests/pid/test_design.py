"""designer.pid.design: what the design itself decides (its checks' wording included)."""

import json

import pytest
from helpers import REPORTS

from designer.core.errors import DesignError
from designer.pid.design import design_pid
from designer.pid.report import build_board
from designer.pid.result import PidResult
from designer.pid.spec import PidSpec


@pytest.mark.spice
def test_checks_name_the_opamps_as_the_package_wires_them():
    """Regression (issue 11): with --package dual the sheet wired U1B, U2A ... while
    the checks still named the deck's U2 .. U7."""
    spec = PidSpec(plant_fc_hz=3500, plant_zeta=0.2, kp=2, ti_s=100e-6, td_s=10e-6, opamp="TL072", package="dual")
    res = design_pid(spec, simulate=False)
    names = {v.opamp for v in res.analytic.levels.values()}
    units = {u.designator for u in build_board(res).units}
    assert names <= units and "U1B" in names
    # the SPICE stages name them the same way (a verdict note naming U2 would send the student to U1B's twin)
    from designer.pid.design import run_spice
    run_spice(res, "ngspice-cli")
    assert {s.opamp for s in res.spice.stages.values()} == names
    slew = next(c for c in res.checks if c.id == "slew_rate")
    assert "worst: U" in slew.detail and slew.detail.split("worst: ")[1].split()[0] in units
    d = res.to_dict()
    assert d["package"]["kind"] == "dual" and d["package"]["part"] == "TL072"
    with pytest.raises(DesignError, match="no quad package"):
        PidSpec(plant_fc_hz=3500, plant_zeta=0.2, kp=2, ti_s=100e-6, td_s=10e-6, opamp="NE5532", package="quad")


@pytest.mark.parametrize("spec, reference", [
    (PidSpec(plant_fc_hz=3500, plant_zeta=0.2, opamp="LM741"), "pid_zn_lm741_fc3500_z0.2"),
    (PidSpec(plant_model=str(REPORTS.parent / "captures" / "motor_seed000.identify.json"), tuning="optimize"),
     "pid_motor_seed000"),
])
def test_design_pid_returns_one_type_whose_json_keeps_each_plants_keys(spec, reference):
    """Issue 26: one result type for the Sallen-Key plant and a model plant; the other kind's fields
    stay None and each JSON has the keys (and their order) of the committed reference bundle."""
    res = design_pid(spec, simulate=False)
    assert type(res) is PidResult
    assert (res.plant is None) == (res.model is not None)
    assert res.stable is res.analytic.stable and res.levels is res.analytic.levels
    ref = json.loads((REPORTS / reference / "result.json").read_text())
    out = res.to_dict()
    assert list(out) == list(ref)
    for key in ("plant", "tuning", "closed_loop"):
        assert list(out[key]) == list(ref[key]), key
