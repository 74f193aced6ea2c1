"""The first-order sections: RC and CR with a follower, and the inverting low-pass."""

import math

import pytest

from designer.core.errors import DesignError
from designer.filters import SectionTarget, get


@pytest.mark.parametrize("name, kind", [("rc-lowpass", "lowpass"), ("rc-highpass", "highpass")])
def test_followers_put_r_at_the_impedance_and_refuse_a_gain(name, kind):
    values = get(name).synthesize(SectionTarget(kind, 1e3, impedance_ohm=4.7e3))
    assert values["R1"] == pytest.approx(4.7e3)
    assert values["R1"] * values["C1"] == pytest.approx(1 / (2 * math.pi * 1e3))
    with pytest.raises(DesignError, match=f"^gain: {name} is a follower .* add the gain in another stage$"):
        get(name).synthesize(SectionTarget(kind, 1e3, gain=2.0))


def test_inverting_lowpass_gain_and_corner():
    values = get("inverting-lowpass").synthesize(SectionTarget("lowpass", 500.0, gain=3.0, c_f=100e-9))
    assert values["C1"] == 100e-9
    assert values["R2"] / values["R1"] == pytest.approx(3.0)
    assert values["R2"] * values["C1"] == pytest.approx(1 / (2 * math.pi * 500.0))
    assert get("inverting-lowpass").response(values, 0.0).real == pytest.approx(-3.0)
