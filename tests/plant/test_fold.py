"""The seed's Sallen-Key plant (:func:`designer.plant.design.design_plant`, ``analyze_plant``) against the
section pipeline on the same section (:func:`designer.plant.circuit_design.design_circuit_plant`,
``analyze_circuit_plant``, ``design-plant --topology sallen-key-lowpass``): the fields the two compute
alike, bit for bit, on the same spec (issue 26: one computation; the groundwork of folding the seed's
orchestration into the section pipeline).

What the two still compute differently (measured over the reference specs and 40 random ones; the
fold's report lists them): the exact design the build rounds (the seed's: the build's capacitors with the
resistors that hit the target; the section's: its synthesis at the reference capacitor), the ideal figures
(the seed's closed form, :meth:`~designer.filters.topology.Topology.ideal_pair`, against the section's
coefficient route, an ulp apart), the op-amp-aware step metrics on random specs (another time span, to
1e-8), the tolerance band of a section with gain (the seed holds the gain pair), the scope's CH2 range, the
checks (the seed's slew-rate and output-swing checks, the section's .ac and square-wave agreement) and the
SPICE runs (the seed's ``.tran`` deck with its ``.meas`` lines, the section's ``.ac``).
"""

import pytest

from designer.filters import registry
from designer.filters.sallen_key_lowpass_parts import part_values, section_of
from designer.plant.circuit_design import analyze_circuit_plant, design_circuit_plant
from designer.plant.design import analyze_plant, design_plant
from designer.plant.sallenkey import SallenKeyParts
from designer.plant.spec import AnalysisSpec, PlantSpec

SPECS = [dict(fc_hz=3500, zeta=0.2), dict(fc_hz=1000, zeta=0.707, opamp="TL072"),
         dict(fc_hz=3500, zeta=0.2, r=1000, c=10e-9), dict(fc_hz=3500, zeta=0.2, compensate_gbw=True),
         dict(fc_hz=2200, zeta=0.5, gain=2.5, opamp="NE5532"), dict(fc_hz=300, zeta=1.1, gain=4, opamp="LM741")]


def section_name(gain):
    return section_of(with_gain=gain != 1.0).name


def pair_of(kw):
    seed = design_plant(PlantSpec(**kw), simulate=False)
    section = design_circuit_plant(PlantSpec(**kw, topology=section_name(kw.get("gain", 1.0))), simulate=False)
    return seed, section


def same_fields(seed, section):
    """Assert every field the two compute alike is equal, bit for bit."""
    topo = registry.get(section.topology)
    assert part_values(seed.built) == section.values
    assert [part_values(SallenKeyParts(a.r1, a.r2, a.c1, a.c2)) for a in seed.alternatives] == \
        [{r: c.values[r] for r in ("R1", "R2", "C1", "C2")} for c in section.alternatives]
    for which, model in (("ideal", seed.analytic), ("opamp", seed.analytic_opamp)):
        for label, s in model.sensitivity.items():
            assert s.to_dict() == section.sensitivity[which][label], (which, label)
    assert seed.sourcing.to_dict() == section.sourcing.to_dict()
    assert seed.test.to_dict() == section.test.to_dict()
    assert seed.sine.dc_gain == section.sine.dc_gain and seed.sine.amplitude_v == section.sine.amplitude_v
    if not topo.choice_parts:
        # a follower's band: every part at its tolerance, in both
        assert seed.tolerance.to_dict() == section.tolerance.to_dict()


@pytest.mark.parametrize("kw", SPECS, ids=[str(k) for k in SPECS])
def test_the_seed_plant_and_the_section_pipeline_agree_bit_for_bit(kw):
    same_fields(*pair_of(kw))


def test_parts_as_built_agree_bit_for_bit():
    spec = AnalysisSpec(parts=SallenKeyParts(820.0, 1e3, 10e-9, 220e-9), target_fc_hz=3500, target_zeta=0.2)
    seed = analyze_plant(spec, simulate=False)
    section = analyze_circuit_plant(section_of(spec.parts).name, part_values(spec.parts), spec.opamp,
                                    spec.target_fc_hz, spec.target_zeta, simulate=False)
    same_fields(seed, section)
    assert seed.analytic.step.to_dict() == {**seed.analytic.step.to_dict(), **section.steps["ideal"]}
