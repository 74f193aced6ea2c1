"""The joint E-series choice (designer.filters.joint): exact over its
candidate set (equal to exhaustive enumeration), never worse than per-stage
rounding, on random error tables and on a real cascade's candidates."""

import numpy as np
import pytest
from hypothesis import given
from hypothesis import strategies as st

from designer.filters import FilterSpec
from designer.filters.design import design
from designer.filters.joint import brute_force, descend, joint_search, objective, per_stage


@given(seed=st.integers(0, 2 ** 32 - 1), stages=st.integers(1, 4), smooth=st.booleans())
def test_joint_equals_brute_force_on_random_tables(seed, stages, smooth):
    rng = np.random.default_rng(seed)
    f = np.linspace(0, 1, 25)
    errors = []
    for _ in range(stages):
        n = int(rng.integers(1, 7))
        if smooth:   # errors shaped like a section's: offsets and slopes over frequency
            e = rng.normal(0, 0.2, (n, 1)) + rng.normal(0, 0.2, (n, 1)) * f[None, :]
        else:
            e = rng.normal(0, 0.2, (n, f.size))
        errors.append(e)
    choice, j, _ = joint_search(errors)
    _, j_brute = brute_force(errors)
    assert j == pytest.approx(j_brute, abs=1e-12)
    assert objective(errors, choice) == pytest.approx(j, abs=1e-12)
    assert j <= objective(errors, per_stage(errors)) + 1e-12
    assert objective(errors, descend(errors, per_stage(errors))) <= objective(errors, per_stage(errors)) + 1e-12


@pytest.mark.parametrize("kw", [dict(order=3, fc_hz=1e3, family="bessel", filter_type="highpass"),
                                dict(order=4, fc_hz=2e3, family="chebyshev", ripple_db=1.0),
                                dict(order=5, fc_hz=500.0, family="butterworth", gain=2.0)])
def test_joint_equals_brute_force_on_a_real_cascade(kw):
    d = design(FilterSpec(**kw))
    errors = [st.errors for st in d.stages]
    assert d.figures["combinations"] <= 20000   # small enough to enumerate
    _, j_brute = brute_force(errors)
    assert d.figures["error_joint_db"] == pytest.approx(j_brute, abs=1e-12)
    assert d.figures["error_joint_db"] <= d.figures["error_per_stage_db"] + 1e-12
    assert d.figures["error_joint_db"] <= d.figures["error_nearest_db"] + 1e-12


@given(seed=st.integers(0, 2 ** 32 - 1), stages=st.integers(1, 4))
def test_joint_with_mask_limits_equals_brute_force(seed, stages):
    rng = np.random.default_rng(seed)
    errors = [rng.normal(0, 0.2, (int(rng.integers(1, 6)), 12)) for _ in range(stages)]
    # the passband edge may lose at most 0.05 dB, the stopband edge gain at most 0.1 dB
    limits = [(10, -1.0, -0.05), (11, 1.0, -0.1)]
    choice, j, _ = joint_search(errors, limits=limits)
    _, j_brute = brute_force(errors, limits)
    assert j == pytest.approx(j_brute, abs=1e-9)
    assert objective(errors, choice, limits) == pytest.approx(j, abs=1e-9)


def test_mask_design_joint_choice_meets_the_mask():
    d = design(FilterSpec(family="butterworth", passband_hz=1e3, max_loss_db=0.5, stopband_hz=3e3,
                          min_attenuation_db=50.0))
    f = d.figures
    assert f["mask_violation_joint_db"] == 0.0
    assert f["mask_passband_margin_db"] >= -1e-9 and f["mask_stopband_margin_db"] >= -1e-9
    # per-stage rounding breaks this mask (the reason the joint objective carries it)
    assert f["mask_violation_per_stage_db"] > 0.1
