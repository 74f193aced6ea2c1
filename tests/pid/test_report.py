import re

import pytest
from helpers import REPORTS, sheet_command, spanish_sheet

from designer.pid.blocks import seed_parts
from designer.pid.design import PidSpec, design_pid


def test_bill_of_materials_lists_every_part_once():
    # regression: the plant's op-amp was listed twice; one designator scheme with the plant's sheet
    from designer.pid.report import bom
    result = design_pid(PidSpec(plant_fc_hz=3500, plant_zeta=0.2), simulate=False)
    refs = [ref for row in bom(result) for ref in row[0].split(", ")]
    assert len(refs) == len(set(refs))
    assert {"U1", "U2", "U7", "R1", "R2", "C1", "C2", "R3", "R18", "C3", "C4"} <= set(refs)
    ics = [row for row in bom(result) if row[0].startswith("U")]
    assert len(ics) == 1 and ics[0][3] == 7 and "U1 plant" in ics[0][7] and "U2 difference" in ics[0][7]


def test_a_designed_plant_keeps_its_series_when_the_controller_uses_the_seed_parts():
    # regression: with --seed-parts the plant's parts were listed "as given"
    from designer.pid.report import bom
    result = design_pid(PidSpec(plant_fc_hz=3500, plant_zeta=0.2, kp=45, ti_s=43.215e-6, td_s=10.8037e-6,
                                controller_parts=seed_parts()), simulate=False)
    rows = {ref: row for row in bom(result) for ref in row[0].split(", ")}
    assert rows["R1"][4] == "E24" and rows["C2"][4] == "E12"
    assert rows["R5"][4] == "as given"


def test_a_gain_plants_parts_keep_the_plants_series_under_their_prefix():
    # regression: the BOM knew the plant's parts by a fixed list (R1 R2 C1 C2 R19 R20); the plant with gain is
    # its section prefixed (RP1 .. RP4) beside the controller's own R3, R4
    from designer.pid.report import bom
    from designer.plant.sallenkey import SallenKeyParts
    result = design_pid(PidSpec(plant_parts=SallenKeyParts(10e3, 10e3, 10e-9, 10e-9, 1.5, 10e3, 5e3),
                                opamp="ideal", tuning="simc"), simulate=False)
    rows = {ref: row for row in bom(result) for ref in row[0].split(", ")}
    assert {"RP1", "RP2", "CP1", "CP2", "RP3", "RP4", "R3", "R4"} <= set(rows)
    assert rows["RP3"][4] == rows["RP1"][4] and rows["CP1"][4] == rows["CP2"][4]
    assert "R1" not in rows and "R19" not in rows


def test_renderers_read_the_typed_result_and_compute_nothing(monkeypatch):
    # the build sheet and the plots take the result as it is: no JSON round trip, no design code
    from designer.pid import design, model, report
    from designer.pid.result import PidResult
    result = design_pid(PidSpec(plant_fc_hz=3500, plant_zeta=0.2, tuning="amigo"), simulate=False)
    expected = report.summary_text(result)

    def forbidden(*args, **kwargs):
        raise AssertionError("a renderer called back into the design or its JSON")

    monkeypatch.setattr(PidResult, "to_dict", forbidden)
    for name in ("plant_model", "design_pid", "resolve_plant"):
        monkeypatch.setattr(design, name, forbidden)
    for name in ("loop_gain", "assemble", "margins", "waveform_limits"):
        monkeypatch.setattr(model, name, forbidden)
    assert report.summary_text(result) == expected
    assert set(report.plots(result)) == {"closed-loop.png", "blocks.png", "loop-bode.png",
                                         "reaction-curve.png"}


def test_the_json_keeps_its_keys():
    # the keys of result.json as committed for the references are all there (additions allowed)
    import json

    from helpers import REPORTS
    result = design_pid(PidSpec(plant_fc_hz=3500, plant_zeta=0.2), simulate=False).to_dict()
    ref = json.loads((REPORTS / "pid_zn_lm741_fc3500_z0.2" / "result.json").read_text())
    assert set(ref) <= set(result)
    for key in ("plant", "opamp", "tuning", "components", "series", "achieved", "test_signal", "closed_loop"):
        assert set(ref[key]) <= set(result[key]), key
    assert set(ref["closed_loop"]["analytic"]) <= set(result["closed_loop"]["analytic"])
    assert set(ref["levels"]["analytic"]["gain"]) <= set(result["levels"]["analytic"]["gain"])
    assert [c["name"] for c in result["checks"]] == [c["name"] for c in ref["checks"]]
    assert all(c["id"] == c["name"] for c in result["checks"])
    assert result["closed_loop"]["spice"] is None and result["levels"]["spice"] is None


#: the Makefile demo's Ziegler-Nichols loop (reports/pid_zn_lm741_fc3500_z0.2)
ZN_DEMO = ["--plant-fc", "3500", "--plant-zeta", "0.2", "--opamp", "LM741", "--name", "pid_zn_lm741_fc3500_z0.2"]


@pytest.mark.spice
def test_the_spanish_pid_sheet_leaves_no_english_message_and_writes_decimal_commas(tmp_path):
    summary, _rep, page, nodes = spanish_sheet("design-pid", ZN_DEMO, tmp_path)
    # the verdict's and the tables' figures: a decimal comma, never a point (notes from the library aside)
    assert re.search(r"\d+,\d+ % de sobrepaso", page) and "Ti = 43,75 µs" in page
    headings = re.findall(r"<h2>([^<]*)</h2>", page)
    assert headings[:3] == ["Veredicto", "Montaje", "Cableado"] and "Lazo cerrado" in headings
    assert not any(re.search(r"(?<![\w.])\d+\.\d+\b(?!\.\d)", n) for n in nodes if n in headings)
    assert "Veredicto" in summary and "Verdict" not in summary


@pytest.mark.spice
def test_the_english_pid_sheet_is_byte_identical_to_the_reference(tmp_path):
    _, rep = sheet_command("design-pid", ZN_DEMO, tmp_path)
    for name in ("build-sheet.md", "build-sheet.html"):
        assert (rep / name).read_bytes() == (REPORTS / "pid_zn_lm741_fc3500_z0.2" / name).read_bytes(), name
