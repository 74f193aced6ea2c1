"""The Sallen-Key high-pass section: every Q reachable, at the price of the resistor spread."""

import pytest

from designer.filters import SectionTarget, get


@pytest.mark.parametrize("q", [0.3, 0.7071, 3.0, 20.0])
def test_unity_gain_equal_capacitors_spread_the_resistors_by_four_q_squared(q):
    values = get("sallen-key-highpass").synthesize(SectionTarget("highpass", 1e3, q=q))
    assert values["C1"] == values["C2"]
    assert values["R2"] / values["R1"] == pytest.approx(4 * q * q, rel=1e-12)


def test_gain_section_reaches_a_high_q_with_a_small_spread():
    values = get("sallen-key-highpass-gain").synthesize(SectionTarget("highpass", 1e3, q=5.0, gain=2.9))
    assert values["R2"] / values["R1"] < 4 * 25
    assert values["R4"] / values["R3"] == pytest.approx(1.9)
