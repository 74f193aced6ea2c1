from designer.pid.blocks import seed_parts
from designer.pid.design import PidSpec, design_pid
from designer.pid.report import sections


def test_bill_of_materials_lists_every_part_once():
    # regression: the plant's op-amp U7 was listed twice
    result = design_pid(PidSpec(plant_fc_hz=3500, plant_zeta=0.2), simulate=False)
    bom = dict(sections(result, with_images=False))["Bill of materials"]
    refs = [row[0] for row in bom[0][2]]
    assert len(refs) == len(set(refs))
    assert {"U1", "U6", "U7", "R3", "R18", "C3", "C4", "R1 (plant)"} <= set(refs)


def test_a_designed_plant_keeps_its_series_when_the_controller_uses_the_seed_parts():
    # regression: with --seed-parts the plant's parts were listed "as given"
    result = design_pid(PidSpec(plant_fc_hz=3500, plant_zeta=0.2, kp=45, ti_s=43.215e-6, td_s=10.8037e-6,
                                controller_parts=seed_parts()), simulate=False)
    bom = dict(sections(result, with_images=False))["Bill of materials"][0][2]
    rows = {row[0]: row for row in bom}
    assert rows["R1 (plant)"][3] == "E24" and rows["C2 (plant)"][3] == "E12"
    assert rows["R5"][3] == "as given"
