"""A check's detail in each sheet's language (designer/core/checks.py): ``detail`` stays the English line that
result.json has always had, :meth:`Check.shown` gives the same line in the language in force (issue 29)."""

import pytest

from helpers import foreign, vocabulary

from designer.core.checks import Check
from designer.core.i18n import catalogue, language


def _designs():
    from designer.pid.design import design_pid
    from designer.pid.spec import PidSpec
    from designer.plant.design import design_plant
    from designer.plant.spec import PlantSpec
    plant = design_plant(PlantSpec(3500, 0.2), simulate=False)
    zn = design_pid(PidSpec(plant_fc_hz=3500, plant_zeta=0.2, opamp="LM741"), simulate=False)
    # the seed's own gains: resistors out of bounds, a slow stage (the failing lines too)
    seed = design_pid(PidSpec(plant_fc_hz=3500, plant_zeta=0.2, kp=45, ti_s=43.215e-6, td_s=10.8037e-6,
                              opamp="LM741"), simulate=False)
    ideal = design_pid(PidSpec(plant_fc_hz=3500, plant_zeta=0.2, opamp="ideal"), simulate=False)
    return [*plant.checks, *zn.checks, *seed.checks, *ideal.checks]


@pytest.fixture(scope="module")
def checks():
    return _designs()


def test_english_shows_the_detail_result_json_keeps(checks):
    assert all(c.shown() == c.detail for c in checks)


def test_spanish_shows_every_check_of_the_plant_and_pid_without_an_english_word(checks):
    english, _spanish = vocabulary()
    with language("es"):
        shown = {c.id: c.shown() for c in checks if c.message is not None}
    # the lines still written without a message (a SPICE disagreement's reasons, a pole list's stage names) aside,
    # every check the designs gave has one
    assert {c.id for c in checks} - set(shown) <= {"spice_agreement"}
    assert foreign(shown.values(), english) == []


def test_a_check_of_a_message_fills_its_values_in_either_language():
    c = Check.of("slew_rate", True, "output needs {need} V/us, {opamp} gives {have} V/us", need="0.1",
                 opamp="LM741", have="0.5")
    assert c.detail == "output needs 0.1 V/us, LM741 gives 0.5 V/us" and c.ok is True
    assert c.to_dict() == {"id": "slew_rate", "name": "slew_rate", "ok": True, "detail": c.detail}
    with language("es"):
        assert c.shown() == catalogue("es")[c.message].format(need="0.1", opamp="LM741", have="0.5") != c.detail
    assert Check("slew_rate", True, "as written").shown() == "as written"
