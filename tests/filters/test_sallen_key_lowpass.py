"""The Sallen-Key low-pass section: the same circuit as the seed's plant
(:mod:`designer.plant.sallenkey`), its capacitor-ratio bound."""

import numpy as np
import pytest

from designer.core.errors import DesignError
from designer.filters import SectionTarget, get
from designer.filters.sallen_key_lowpass import sallen_key_ratio_min
from designer.plant import sallenkey


@pytest.mark.parametrize("name, gain", [("sallen-key-lowpass", 1.0), ("sallen-key-lowpass-gain", 2.2)])
def test_coefficients_are_the_seed_plants(name, gain):
    topology = get(name)
    values = topology.synthesize(SectionTarget("lowpass", 3.5e3, q=0.9, gain=gain))
    a, b = sallenkey.coefficients(values["R1"], values["R2"], values["C1"], values["C2"], gain)
    num, den = topology.coefficients(values)
    np.testing.assert_allclose(den, [a, b, 1.0], rtol=1e-12)
    np.testing.assert_allclose(num, [0.0, 0.0, gain], rtol=1e-12)


def test_unity_gain_default_is_equal_resistors_at_the_bound():
    values = get("sallen-key-lowpass").synthesize(SectionTarget("lowpass", 1e3, q=0.7071, impedance_ohm=22e3))
    assert values["C2"] / values["C1"] == pytest.approx(4 * 0.7071 ** 2)
    assert values["R1"] == pytest.approx(22e3) and values["R2"] == pytest.approx(22e3)


def test_gain_default_is_equal_capacitors_when_the_bound_allows():
    values = get("sallen-key-lowpass-gain").synthesize(SectionTarget("lowpass", 1e3, q=2.0, gain=2.0))
    assert values["C1"] == values["C2"] and values["R4"] == pytest.approx(values["R3"])
    assert sallen_key_ratio_min(2.0, 2.0) < 1


def test_ratio_below_four_q_squared_is_refused_saying_what_to_change():
    with pytest.raises(DesignError) as err:
        get("sallen-key-lowpass").synthesize(SectionTarget("lowpass", 1e3, q=2.0), ratio=10.0)
    msg = str(err.value)
    assert msg == ("ratio: C2/C1 = 10 is below the bound 4 Q^2 = 16 of sallen-key-lowpass at Q = 2, K = 1; use a "
                   "ratio of at least 16, a lower Q, or the gain-K section")


def test_the_follower_refuses_a_gain_and_the_gain_section_unity():
    with pytest.raises(DesignError, match="^gain: sallen-key-lowpass is a follower.*use sallen-key-lowpass-gain$"):
        get("sallen-key-lowpass").synthesize(SectionTarget("lowpass", 1e3, q=0.7, gain=2.0))
    with pytest.raises(DesignError, match="^gain: sallen-key-lowpass-gain needs a gain above 1"):
        get("sallen-key-lowpass-gain").synthesize(SectionTarget("lowpass", 1e3, q=0.7, gain=1.0))


@pytest.mark.parametrize("name, gain", [("sallen-key-lowpass", 1.0), ("sallen-key-lowpass-gain", 2.2)])
def test_opamp_model_is_the_seed_plants_closed_form(name, gain):
    """The section's op-amp-aware model is the plant's closed form (seed 001, IV.3-IV.9;
    :func:`designer.plant.model.plant_tf_opamp`), bit for bit, not the inherited nodal solution."""
    from designer.core.opamps import get as get_opamp
    from designer.filters import Topology
    from designer.filters.sallen_key_lowpass_parts import parts_of
    from designer.plant.model import plant_tf_opamp
    topology = get(name)
    assert type(topology).opamp_model is not Topology.opamp_model
    values = topology.synthesize(SectionTarget("lowpass", 3.5e3, q=0.9, gain=gain))
    for amp in (get_opamp("LM741"), get_opamp("NE5532")):
        num, den = topology.opamp_model(values, amp)
        n_ref, d_ref = plant_tf_opamp(parts_of(values, gain=1.0 + values["R4"] / values["R3"]
                                               if "R3" in values else 1.0), amp)
        assert np.array_equal(den, d_ref) and np.array_equal(np.trim_zeros(num, "f"), n_ref)
