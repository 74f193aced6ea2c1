"""The MFB low-pass section: TI's bound C2/C1 >= 4 Q^2 (1 + |gain|) and its design."""

import math

import pytest

from designer.core.errors import DesignError
from designer.filters import SectionTarget, get


def test_default_ratio_is_the_bound_and_r2_the_double_root():
    target = SectionTarget("lowpass", 2e3, q=0.54, gain=3.0, c_f=10e-9)
    values = get("mfb-lowpass").synthesize(target)
    assert values["C1"] == 10e-9
    assert values["C2"] / values["C1"] == pytest.approx(4 * 0.54 ** 2 * 4)
    assert values["R2"] == pytest.approx(1 / (2 * 2 * math.pi * 2e3 * 0.54 * 10e-9))
    assert values["R2"] / values["R1"] == pytest.approx(3.0)


def test_above_the_bound_r2_is_tis_smaller_root():
    target = SectionTarget("lowpass", 1e3, q=0.7071, gain=1.0, c_f=10e-9)
    values = get("mfb-lowpass").synthesize(target, ratio=5.0)
    w, c1, c2 = 2 * math.pi * 1e3, 10e-9, 50e-9
    # TI: R2 = (a1 C2 - sqrt(a1^2 C2^2 - 4 b1 C1 C2 (1 - A0))) / (4 pi fc C1 C2), a1 = 1/Q, b1 = 1, A0 = -1
    a1 = 1 / 0.7071
    r2 = (a1 * c2 - math.sqrt(a1 ** 2 * c2 ** 2 - 4 * c1 * c2 * 2)) / (2 * w * c1 * c2)
    assert values["R2"] == pytest.approx(r2, rel=1e-12)
    assert values["R3"] == pytest.approx(1 / (w * w * c1 * c2 * r2), rel=1e-12)


def test_a_ratio_below_the_bound_is_refused_in_one_line():
    with pytest.raises(DesignError) as err:
        get("mfb-lowpass").synthesize(SectionTarget("lowpass", 1e3, q=1.0, gain=2.0), ratio=10.0)
    assert str(err.value) == ("ratio: C2/C1 = 10 is below the bound 4 Q^2 (1 + |gain|) = 12 of mfb-lowpass at Q = 1, "
                              "gain 2; use a ratio of at least 12, a lower Q or gain, or a Sallen-Key section")
