"""The Sallen-Key plant's closed-form models against the generic section pipeline's (issue 26): the same
figures from two derivations, and why the plant keeps its own (the JSON's sensitivities are finite
differences: the generic model's rounding, 1e-13 relative, moves them well past the last digits)."""

import math

import numpy as np
import pytest

from designer.core import opamps
from designer.core.lti import dominant_pair
from designer.filters.sallen_key_lowpass_parts import part_values, section_of
from designer.plant import circuit
from designer.plant.model import opamp_pair, plant_model, plant_tf, plant_tf_opamp, sensitivities
from designer.plant.sallenkey import SallenKeyParts

SEED = SallenKeyParts(820.0, 1e3, 10e-9, 220e-9)
GAIN2 = SallenKeyParts(10e3, 10e3, 10e-9, 10e-9, 2.0, 10e3, 10e3)


@pytest.mark.parametrize("parts", [SEED, GAIN2], ids=["follower", "gain2"])
@pytest.mark.parametrize("amp", ["LM741", "TL072", "NE5532"])
def test_the_op_amp_aware_pair_is_the_generic_sections(parts, amp):
    a = opamps.get(amp)
    fn, z = opamp_pair(parts, a)
    assert (fn, z) == dominant_pair(plant_tf_opamp(parts, a)[1])
    f = circuit.circuit_figures(section_of(parts), part_values(parts), a)
    assert math.isclose(fn, float(f["fn_hz"]), rel_tol=1e-10) and math.isclose(z, float(f["zeta"]), rel_tol=1e-10)


def test_the_plant_model_is_the_ideal_one_with_an_ideal_op_amp():
    for parts in (SEED, GAIN2):
        for amp in (opamps.get("ideal"), opamps.get("LM741")):
            got = plant_model(parts, amp)
            want = plant_tf(parts) if amp.ideal else plant_tf_opamp(parts, amp)
            assert all(np.array_equal(g, w) for g, w in zip(got, want))


@pytest.mark.parametrize("parts", [SEED, GAIN2], ids=["follower", "gain2"])
def test_the_sensitivities_agree_with_the_generic_ones_to_finite_difference_accuracy(parts):
    amp = opamps.get("LM741")
    topo, values = section_of(parts), part_values(parts)
    for opamp in (None, amp):
        own, generic = sensitivities(parts, opamp), circuit.sensitivities(topo, values, opamp)
        for ref in topo.designators[:4]:
            assert math.isclose(own[ref].wn, generic[ref]["wn"], rel_tol=1e-6, abs_tol=1e-9)
            assert math.isclose(own[ref].zeta, generic[ref]["zeta"], rel_tol=1e-6, abs_tol=1e-9)
