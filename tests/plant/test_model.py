"""The Sallen-Key plant's closed-form models against the generic section pipeline's (issue 26): the same
figures from two derivations, and the plant's sensitivities as the generic function's rows, bit for bit the
reference JSON's."""

import json
import math
from pathlib import Path

import numpy as np
import pytest

from designer.core import opamps
from designer.core.lti import dominant_pair
from designer.filters.sallen_key_lowpass_parts import part_values, section_of
from designer.plant import circuit
from designer.plant.model import opamp_pair, plant_model, plant_tf, plant_tf_opamp, sensitivities
from designer.plant.sallenkey import SallenKeyParts

REFERENCE = Path(__file__).resolve().parents[2] / "reports" / "plant_fc3500_z0.2" / "result.json"
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
@pytest.mark.parametrize("amp", [None, "ideal", "LM741", "TL072"])
def test_the_plants_sensitivities_are_the_generic_sections_rows(parts, amp):
    """The plant's table is the generic one's (issue 26: written once): the network's rows, K's for the gain
    section (not R3's and R4's: the plant has always shown K) and, with a real op-amp, GBW's and A0's."""
    opamp = None if amp is None else opamps.get(amp)
    topo = section_of(parts)
    own, generic = sensitivities(parts, opamp), circuit.sensitivities(topo, part_values(parts), opamp)
    want = [*topo.designators[:4], *(["K"] if parts.gain != 1.0 else []),
            *(["GBW", "A0"] if opamp is not None and not opamp.ideal else [])]
    assert list(own) == want
    assert all((own[k].wn, own[k].zeta) == (generic[k]["wn"], generic[k]["zeta"]) for k in want)


def test_the_seed_plants_sensitivities_are_the_reference_json_to_the_bit():
    """reports/plant_fc3500_z0.2/result.json's table, computed before the plant's went through the generic
    function (its own closed forms, scalar np.roots): the generic rows reproduce every bit (the op-amp's
    |p| as hypot, the difference quotient as ln((1 + h)/(1 - h)), 1/sqrt(a) for wn)."""
    ref = json.loads(REFERENCE.read_text())
    built = ref["built"]
    parts = SallenKeyParts(*(built[k] for k in ("R1_ohm", "R2_ohm", "C1_f", "C2_f")), built["gain"])
    amp = opamps.get(ref["opamp"]["name"])
    assert (amp.a0, amp.gbw_hz) == (ref["opamp"]["a0"], ref["opamp"]["gbw_hz"])
    got = {"ideal": {k: s.to_dict() for k, s in sensitivities(parts).items()},
           "opamp": {k: s.to_dict() for k, s in sensitivities(parts, amp).items()}}
    assert got == ref["sensitivity"]
