from designer.pid.design import PidSpec, design_pid
from designer.pid.report import sections


def test_bill_of_materials_lists_every_part_once():
    # regression: the plant's op-amp U7 was listed twice
    result = design_pid(PidSpec(plant_fc_hz=3500, plant_zeta=0.2), simulate=False)
    bom = dict(sections(result, with_images=False))["Bill of materials"]
    refs = [row[0] for row in bom[0][2]]
    assert len(refs) == len(set(refs))
    assert {"U1", "U6", "U7", "R3", "R18", "C3", "C4", "R1 (plant)"} <= set(refs)
