"""The plant a controller is designed for, however it arrives (--plant-fc/--plant-zeta,
--plant-r1.. with --plant-gain, --plant-json), goes through one validation,
:func:`designer.plant.sallenkey.check_parts` (issue 7, item 6)."""

import json
import math

import numpy as np
import pytest

from designer.cli.pid import design_pid_main
from designer.core.errors import DesignError
from designer.core.ranges import RANGES
from designer.filters.sallen_key_lowpass_parts import gain_refs
from designer.plant.sallenkey import DEFAULT_R3_OHM, GAIN_TOLERANCE, SallenKeyParts, check_parts

# an equal-component plant: zeta = 1 + (1 - K)/2 (seed 001's b with R1 = R2, C1 = C2)
R, C = 10e3, 10e-9


def equal_component_zeta(k):
    p = SallenKeyParts(R, R, C, C, k)
    return p.b / (2 * math.sqrt(p.a))


def result_json(tmp_path, **built):
    """A design-plant-like result.json whose 'built' object holds ``built``."""
    path = tmp_path / "plant.json"
    path.write_text(json.dumps({"built": built}))
    return path


def refused(capsys, *args):
    code = design_pid_main([*args, "--no-sim", "--no-files"])
    err = capsys.readouterr().err
    assert code == 2, err
    lines = err.strip().splitlines()
    assert len(lines) == 1 and lines[0].startswith("design-pid: error:"), err
    assert "Traceback" not in err and "np.float64" not in err
    return lines[0]


def accepted(capsys, *args):
    code = design_pid_main([*args, "--json", "--no-files"])
    out, err = capsys.readouterr()
    assert code == 0, err
    return json.loads(out)


BASE = {"R1_ohm": R, "R2_ohm": R, "C1_f": C, "C2_f": C}


@pytest.mark.parametrize("built,needle", [
    ({**BASE, "gain": "abc"}, "built.gain must be a number, got 'abc'"),
    ({**BASE, "gain": float("nan")}, "built.gain must be"),
    ({**BASE, "gain": 0.5}, "built.gain must be 1 to 100"),
    ({**BASE, "gain": True}, "built.gain must be a number"),
    ({**BASE, "R1_ohm": "1k"}, "built.R1_ohm must be a number, got '1k'"),
    ({**BASE, "C2_f": None}, "built.C2_f must be a number"),
    ({**BASE, "C1_f": [1e-9]}, "built.C1_f must be a number, got list"),
    ({**BASE, "R2_ohm": 1e300}, "built.R2_ohm must be"),
    ({**BASE, "C1_f": -1e-9}, "built.C1_f must be"),
    # K = 1 + R4/R3 = 2 stated as 1.5
    ({**BASE, "gain": 1.5, "R3_ohm": 10e3, "R4_ohm": 10e3}, "does not match its resistors"),
    ({**BASE, "gain": 1.5, "R3_ohm": 10e3}, "go together"),
    # K = 4 makes this plant's zeta -0.5: it oscillates on its own
    ({**BASE, "gain": 4.0, "R3_ohm": 10e3, "R4_ohm": 30e3}, "oscillates on its own"),
    # 10 ohm, 10 pF: fn 1.6 GHz, outside the range --plant-fc accepts
    ({"R1_ohm": 10.0, "R2_ohm": 10.0, "C1_f": 10e-12, "C2_f": 10e-12}, "natural frequency"),
])
def test_plant_json_values_are_checked(tmp_path, capsys, built, needle):
    line = refused(capsys, "--plant-json", str(result_json(tmp_path, **built)))
    assert needle in line
    assert "--plant-json" in line


def test_unstable_plant_refused_the_same_way_from_parts_and_from_json(tmp_path, capsys):
    assert equal_component_zeta(4.0) == pytest.approx(-0.5)
    by_parts = refused(capsys, "--plant-r1", "10k", "--plant-r2", "10k", "--plant-c1", "10n", "--plant-c2", "10n",
                       "--plant-gain", "4")
    by_json = refused(capsys, "--plant-json", str(result_json(tmp_path, **BASE, gain=4.0)))
    tail = "these parts give zeta = -0.5 <= 0"
    assert tail in by_parts and tail in by_json
    # and the same words as the validation itself
    with pytest.raises(DesignError, match="oscillates on its own"):
        check_parts(SallenKeyParts(R, R, C, C, 4.0))


@pytest.mark.spice
def test_gain_without_its_resistors_gets_them_in_the_model_and_the_netlist(tmp_path, capsys):
    k = 1.5
    d = accepted(capsys, "--plant-json", str(result_json(tmp_path, **BASE, gain=k)), "--tuning", "simc",
                 "--opamp", "TL072")
    p = d["plant"]
    assert p["gain"] == k
    assert p["R3_ohm"] == DEFAULT_R3_OHM and p["R4_ohm"] == (k - 1) * DEFAULT_R3_OHM
    assert p["zeta"] == pytest.approx(equal_component_zeta(k))
    # the deck builds the gain the model assumes (SPICE settles where the analytic loop does)
    s, a = d["closed_loop"]["spice"], d["closed_loop"]["analytic"]
    assert s["stable"] and not s["saturated"]
    assert s["final_value"] == pytest.approx(a["final_value"], rel=2e-3)


def test_gain_without_resistors_from_parts_builds_them_too(capsys):
    from designer.pid.design import PidSpec, design_pid
    res = design_pid(PidSpec(plant_parts=SallenKeyParts(R, R, C, C, 1.5), opamp="ideal", tuning="simc"),
                     simulate=False)
    gain_pair = [res.plant.stages[0].values[r] for r in gain_refs()]   # the generic record's values
    assert gain_pair == [DEFAULT_R3_OHM, 0.5 * DEFAULT_R3_OHM]
    # the controller owns R3, R4: the plant's section carries the chaining prefix P (RP1 .. RP4), no renaming
    assert "RP3 pvn 0" in res.deck and "RP4 y pvn" in res.deck and "RP1 u pv1" in res.deck
    assert "RP" not in design_pid(PidSpec(plant_parts=SallenKeyParts(820, 1e3, 10e-9, 220e-9), opamp="ideal",
                                           tuning="simc"), simulate=False).deck


def test_gain_from_resistors_when_the_json_has_none(tmp_path, capsys):
    d = accepted(capsys, "--plant-json", str(result_json(tmp_path, **BASE, R3_ohm=10e3, R4_ohm=4.7e3)),
                 "--no-sim", "--tuning", "simc")
    assert d["plant"]["gain"] == pytest.approx(1.47)


def test_design_plant_result_round_trips(tmp_path, capsys):
    # design-plant's own result.json (gain 1.5 realised with E-series R3/R4) is accepted unchanged
    from designer.cli.plant import design_plant_main
    assert design_plant_main(["--fc", "1k", "--zeta", "0.5", "--gain", "1.5", "--no-sim", "--out", str(tmp_path),
                              "--name", "p"]) == 0
    capsys.readouterr()
    rj = tmp_path / "reports" / "p" / "result.json"
    built = json.loads(rj.read_text())["built"]
    d = accepted(capsys, "--plant-json", str(rj), "--no-sim", "--tuning", "amigo")
    for k in ("R1_ohm", "R2_ohm", "C1_f", "C2_f", "R3_ohm", "R4_ohm"):
        assert d["plant"][k] == built[k]
    assert d["plant"]["gain"] == pytest.approx(1 + built["R4_ohm"] / built["R3_ohm"], rel=1e-12)


def test_check_parts_closed_forms():
    # tolerance: a stated gain within GAIN_TOLERANCE of 1 + R4/R3 takes the resistors' value
    r4 = 4.7e3
    k = 1 + r4 / 10e3
    p = check_parts(SallenKeyParts(R, R, C, C, k * (1 + 0.5 * GAIN_TOLERANCE), 10e3, r4))
    assert p.gain == k
    with pytest.raises(DesignError, match="does not match"):
        check_parts(SallenKeyParts(R, R, C, C, k * (1 + 2 * GAIN_TOLERANCE), 10e3, r4))
    # the edges of the ranges are inside, a hair beyond is not
    lo, hi = RANGES["resistor_ohm"].lo, RANGES["capacitor_f"].hi
    with pytest.raises(DesignError, match="R1"):
        check_parts(SallenKeyParts(lo * 0.99, R, C, C))
    with pytest.raises(DesignError, match="C2"):
        check_parts(SallenKeyParts(R, R, C, hi * 1.01))
    # numpy scalars are numbers; the result is plain floats
    p = check_parts(SallenKeyParts(np.float64(R), np.int64(10000), C, C))
    assert type(p.r1) is float and type(p.r2) is float and p.r3 is None
    # names for messages
    with pytest.raises(DesignError, match="^--x1 must be"):
        check_parts(SallenKeyParts(-1.0, R, C, C), name_of={"r1": "--x1"})
    with pytest.raises(DesignError, match="^part r2 must be"):
        check_parts(SallenKeyParts(R, -1.0, C, C), name_of=lambda k: f"part {k}")


def test_a_typed_gain_plants_json_figures_are_the_circuits_it_was_sized_with():
    # a gain typed without its resistors is built as R4 = (K - 1) R3: the result's plant is that circuit (the
    # generic record), and its JSON figures are the ones the loop was named and sized with, 1 + R4/R3 (1.82
    # typed: 1.8199999999999998, the last bit of 0.82), as the deck and the model build it
    from designer.pid.design import PidSpec, design_pid
    res = design_pid(PidSpec(plant_parts=SallenKeyParts(R, R, C, C, 1.82), opamp="ideal", tuning="simc"),
                     simulate=False)
    to_ground, feedback = (res.plant.stages[0].values[r] for r in gain_refs())
    plant = res.to_dict()["plant"]
    assert plant["gain"] == 1.0 + feedback / to_ground == pytest.approx(1.82, rel=1e-15)
    assert (plant["fn_hz"], plant["zeta"]) == res.plant.ideal_pair()
