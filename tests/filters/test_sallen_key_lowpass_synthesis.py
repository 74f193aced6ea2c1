import math

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

from designer.core.errors import DesignError
from designer.filters.sallen_key_lowpass_synthesis import SallenKeyParts, fn_zeta, ratios_from_rc, realizability_notes, resistors_for_caps


def test_seed_procedure_m_n_and_transfer_function():
    # seed 001: fc = 3500 Hz, zeta = 0.2, R = 1 kOhm, C = 10 nF -> m = 0.819, n = 25.25,
    # 1 / (2.0678e-9 s^2 + 1.8189e-5 s + 1)
    m, n = ratios_from_rc(3500, 0.2, 1e3, 10e-9)
    assert m == pytest.approx(0.819, abs=5e-4)
    assert n == pytest.approx(25.25, abs=5e-3)
    p = SallenKeyParts(m * 1e3, 1e3, 10e-9, n * 10e-9)
    assert p.a == pytest.approx(2.0678e-9, rel=1e-4)
    assert p.b == pytest.approx(1.8189e-5, rel=1e-4)
    assert p.fn_hz == pytest.approx(3500, rel=1e-12)
    assert p.zeta == pytest.approx(0.2, rel=1e-12)


def test_seed_rounded_parts_really_give():
    # the thesis keeps analysing the unrounded function; 820/1k/10n/220n give fn ~ 3747 Hz, zeta ~ 0.214
    p = SallenKeyParts(820, 1e3, 10e-9, 220e-9)
    assert p.fn_hz == pytest.approx(3747, abs=1)
    assert p.zeta == pytest.approx(0.214, abs=5e-4)
    assert p.q == pytest.approx(1 / (2 * p.zeta))


def test_general_gain_matches_seed_formula():
    p = SallenKeyParts(10e3, 10e3, 10e-9, 10e-9, gain=2.0)
    # b = C1 (R1 + R2) + R1 C2 (1 - K)
    assert p.b == pytest.approx(10e-9 * 20e3 + 10e3 * 10e-9 * (1 - 2.0))
    assert p.zeta == pytest.approx((3 - 2.0) / 2)  # equal-component: zeta = (3 - K) / 2


def test_no_positive_m_says_what_to_change():
    with pytest.raises(DesignError, match="R\\*C < 2\\*zeta/wn"):
        ratios_from_rc(3500, 0.2, 100e3, 1e-6)


@settings(max_examples=200, deadline=None)
@given(fc=st.floats(1.0, 1e6), zeta=st.floats(0.05, 5.0), c1=st.floats(1e-9, 1e-6),
       ratio=st.floats(1.0, 1e4), gain=st.sampled_from([1.0, 1.5, 2.0, 2.9]))
def test_resistors_for_caps_hit_the_targets(fc, zeta, c1, ratio, gain):
    c2 = c1 * ratio
    lo, hi = resistors_for_caps(fc, zeta, c1, c2, gain)
    for r1 in (float(lo), float(hi)):
        if math.isnan(r1):
            continue
        assert r1 > 0
        r2 = 1 / ((2 * math.pi * fc) ** 2 * c1 * c2 * r1)
        f, z = fn_zeta(r1, r2, c1, c2, gain)
        assert f == pytest.approx(fc, rel=1e-9)
        assert z == pytest.approx(zeta, rel=1e-7)
    if gain == 1.0:
        # unity-gain realizability: C2/C1 >= 1/zeta^2 exactly when a solution exists
        assert (not math.isnan(float(lo))) == (ratio >= 1 / zeta ** 2 * (1 + 1e-12)) or \
            abs(ratio * zeta ** 2 - 1) < 1e-9


def test_resistors_for_caps_when_k_c2_nearly_equals_c1_plus_c2():
    # found by hypothesis: gain 2 with C2 = C1 (1 + 2e-16) makes the quadratic's
    # leading coefficient C1 + C2 (1 - K) about -2e-22; the textbook root formula
    # lost every digit there (zeta 0.61 for 1)
    c1 = 1e-6 * (1 - 3e-16)
    c2 = c1 * 1.0000000000000002
    lo, hi = resistors_for_caps(1.0, 1.0, c1, c2, 2.0)
    r1 = float(lo)
    r2 = 1 / ((2 * math.pi) ** 2 * c1 * c2 * r1)
    f, z = fn_zeta(r1, r2, c1, c2, 2.0)
    assert f == pytest.approx(1.0, rel=1e-12)
    assert z == pytest.approx(1.0, rel=1e-9)


def test_realizability_suggests_gain():
    notes = realizability_notes(3500, 0.005, 1.0, 1e-9, 1e-5)
    assert notes and "--gain" in notes[0]
    assert realizability_notes(3500, 0.2, 1.0, 1e-9, 1e-5) == []


def test_vectorised_fn_zeta():
    f, z = fn_zeta(np.array([820.0, 1e3]), 1e3, 10e-9, np.array([220e-9, 1e-6]))
    assert f.shape == (2,) and z.shape == (2,)
