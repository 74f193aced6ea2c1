"""The joint E-series choice (designer.filters.joint): exact over its
candidate set (equal to exhaustive enumeration), never worse than per-stage
rounding, on random error tables and on a real cascade's candidates; with a
group-delay target, meeting it where per-stage rounding misses."""

import itertools

import numpy as np
import pytest
from hypothesis import given
from hypothesis import strategies as st

from designer.filters import FilterSpec
from designer.filters.design import design
from designer.filters.joint import (brute_force, delay_columns, descend, joint_search, objective,
                                    joint_alternatives, per_stage)
from designer.filters.prototype import delay_error_pct


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


@given(seed=st.integers(0, 2 ** 32 - 1), stages=st.integers(1, 4))
def test_joint_with_limit_only_columns_equals_brute_force(seed, stages):
    # columns past n_dev (a delay target's) enter through their limits only, never the deviation
    rng = np.random.default_rng(seed)
    n_dev = 10
    taus = [np.abs(rng.normal(1.0, 0.05, (int(rng.integers(1, 6)), 8))) for _ in range(stages)]
    cols, limits = delay_columns(taus, 2.0, float(sum(t[0, 0] for t in taus)), n_dev)
    errors = [np.hstack([rng.normal(0, 0.2, (len(t), n_dev)), c]) for t, c in zip(taus, cols)]
    choice, j, _ = joint_search(errors, limits=limits, n_dev=n_dev)
    _, j_brute = brute_force(errors, limits, n_dev)
    assert j == pytest.approx(j_brute, abs=1e-9)
    assert objective(errors, choice, limits, n_dev) == pytest.approx(j, abs=1e-9)
    # the limits read the delay error: met exactly when the delay error is within 2 %
    total = sum(t[c] for t, c in zip(taus, choice))
    met = max(0.0, *(sg * np.sum([e[c][col] for e, c in zip(errors, choice)]) + o for col, sg, o in limits)) == 0.0
    assert met == (delay_error_pct(total, total[0]) <= 2.0 + 1e-9)


#: a Bessel mask whose E12 parts the delay target decides (found by a scan of Bessel masks, series and delay_to)
DELAY_CASE = dict(family="bessel", passband_hz=1e3, max_loss_db=3, stopband_hz=5e3, min_attenuation_db=40,
                  delay_to_hz=500.0, r_series="E12", c_series="E12", opamp="TL072")


def test_delay_target_joint_meets_it_where_rounding_misses():
    # a target no choice can miss (50 %): the joint choice is the deviation's alone, as before the delay counted
    loose = design(FilterSpec(max_delay_error_pct=50.0, **DELAY_CASE))
    lf = loose.figures
    # the least delay error any candidate set gives, by enumeration
    least = min(delay_error_pct(t, t[0]) for t in
                (sum(x) for x in itertools.product(*(s.delays for s in loose.stages))))
    # a target between what the candidates can do (and the ideal, so the order stays) and what the deviation's
    # joint choice and the per-stage rounding give
    target = (max(least, lf["delay_error_ideal_pct"]) + min(lf["delay_error_pct"], lf["delay_error_per_stage_pct"])) / 2
    d = design(FilterSpec(max_delay_error_pct=target, **DELAY_CASE))
    f = d.figures
    assert d.order == loose.order
    assert not f["delay_target_met_per_stage"] and f["delay_error_per_stage_pct"] > target
    assert lf["delay_error_pct"] > target        # the joint choice without the delay in its objective misses
    assert f["delay_target_met"] and f["delay_error_pct"] <= target
    assert f["mask_violation_joint_db"] == 0.0
    # exact over its candidates: brute force over the same problem agrees
    search, limits, n_dev = d.problem
    choice = [s.chosen for s in d.stages]
    _, j_brute = brute_force(search, limits, n_dev)
    assert objective(search, choice, limits, n_dev) == pytest.approx(j_brute, abs=1e-9)
    # the delay from the stages' candidate delays is the cascade's (delay_figures, by the cascade's response)
    tau = sum(s.delays[c] for s, c in zip(d.stages, choice))
    assert delay_error_pct(tau, tau[0]) == pytest.approx(f["delay_error_pct"], abs=1e-6)


@given(seed=st.integers(0, 2 ** 32 - 1), stages=st.integers(1, 4), count=st.integers(1, 12),
       masked=st.booleans())
def test_alternatives_are_the_least_j_choices_of_the_enumeration(seed, stages, count, masked):
    """The alternatives are the ``count`` least J of every combination (enumerated here), best first, the
    joint choice first; with mask limits too."""
    rng = np.random.default_rng(seed)
    errors = [rng.normal(0, 0.2, (int(rng.integers(1, 6)), 12)) for _ in range(stages)]
    limits = [(10, -1.0, -0.05), (11, 1.0, -0.1)] if masked else None
    best, j_best, _ = joint_search(errors, limits=limits)
    got = joint_alternatives(errors, best, count, limits)
    every = sorted(objective(errors, ch, limits) for ch in itertools.product(*(range(len(e)) for e in errors)))
    assert [j for _, j in got] == pytest.approx(every[:count], abs=1e-12)
    assert got[0][1] == pytest.approx(j_best, abs=1e-12)
    assert len({tuple(ch) for ch, _ in got}) == len(got)
    for ch, j in got:
        assert objective(errors, ch, limits) == pytest.approx(j, abs=1e-12)
