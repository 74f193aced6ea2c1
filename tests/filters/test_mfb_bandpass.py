"""The MFB band-pass section: TI's equal-capacitor design and its gain bound Am < 2 Q^2."""

import math

import numpy as np
import pytest

from designer.core.errors import DesignError
from designer.filters import SectionTarget, get


def test_peak_is_at_f0_with_the_gain_and_the_3db_bandwidth_f0_over_q():
    topology = get("mfb-bandpass")
    values = topology.synthesize(SectionTarget("bandpass", 1e3, q=10.0, gain=5.0))
    f = np.linspace(900, 1100, 20001)
    mag = np.abs(topology.response(values, 2j * math.pi * f))
    assert f[np.argmax(mag)] == pytest.approx(1e3, abs=0.01) and mag.max() == pytest.approx(5.0, rel=1e-8)
    band = f[mag >= 5.0 / math.sqrt(2)]
    assert band[-1] - band[0] == pytest.approx(100.0, abs=0.05)


def test_a_gain_at_or_above_two_q_squared_is_refused_in_one_line():
    with pytest.raises(DesignError) as err:
        get("mfb-bandpass").synthesize(SectionTarget("bandpass", 1e3, q=2.0, gain=8.0))
    assert str(err.value) == ("gain: 8 at f0 is not below the bound 2 Q^2 = 8 of mfb-bandpass at Q = 2; ask for a "
                              "lower gain or a higher Q, or add gain in another stage")
