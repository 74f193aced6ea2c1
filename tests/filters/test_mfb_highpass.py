"""The MFB high-pass section: TI's equal C1 = C3 and C2 = C/gain."""

import pytest

from designer.filters import SectionTarget, get


def test_capacitors_are_tis_and_the_gain_is_c1_over_c2():
    values = get("mfb-highpass").synthesize(SectionTarget("highpass", 1e3, q=0.7071, gain=4.0, c_f=47e-9))
    assert values["C1"] == values["C3"] == 47e-9 and values["C2"] == pytest.approx(47e-9 / 4)
    num, den = get("mfb-highpass").coefficients(values)
    assert num[0] / den[0] == pytest.approx(-4.0)
