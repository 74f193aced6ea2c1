"""Samples depend on (seed, i) alone: the same whatever the slice asked for."""

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

from designer.core.errors import DesignError
from designer.tolerance import sampling


@pytest.mark.parametrize("sampler", sampling.SAMPLERS)
def test_a_slice_is_the_slice_of_the_whole(sampler):
    n = 2 * sampling.CHUNK + 77
    whole = sampling.unit_samples(n, 4, seed=3, sampler=sampler)
    for start, stop in ((0, 10), (sampling.CHUNK - 5, sampling.CHUNK + 5), (n - 100, n), (1000, 8000)):
        got = sampling.unit_samples(n, 4, seed=3, sampler=sampler, start=start, stop=stop)
        np.testing.assert_array_equal(got, whole[start:stop])
    assert whole.shape == (n, 4) and np.all((whole >= 0) & (whole < 1))


@settings(max_examples=30, deadline=None)
@given(start=st.integers(0, 9000), length=st.integers(0, 3000), seed=st.integers(0, 2 ** 32 - 1))
def test_random_samples_do_not_depend_on_the_chunking(start, length, seed):
    n = 12000
    stop = min(n, start + length)
    got = sampling.unit_samples(n, 3, seed, "random", start, stop)
    whole = sampling.unit_samples(n, 3, seed, "random")
    np.testing.assert_array_equal(got, whole[start:stop])


def test_seeds_differ_and_repeat():
    a = sampling.unit_samples(100, 2, 1)
    np.testing.assert_array_equal(a, sampling.unit_samples(100, 2, 1))
    assert not np.array_equal(a, sampling.unit_samples(100, 2, 2))


def test_deviations_stay_in_the_tolerance():
    u = sampling.unit_samples(200000, 1, 5).ravel()
    d = sampling.deviations(u, "uniform")
    assert d.min() >= -1 and d.max() <= 1 and abs(d.std() - 1 / np.sqrt(3)) < 0.005
    g = sampling.deviations(u, "normal")
    # sigma = tol/3, truncated at 3 sigma: the truncated normal's standard deviation is 0.9866 sigma
    assert g.min() >= -1 and g.max() <= 1 and abs(g.std() - 0.98658 / 3) < 0.003


def test_bad_sampler_and_distribution():
    with pytest.raises(DesignError, match="--sampler"):
        sampling.unit_samples(10, 1, 0, "magic")
    with pytest.raises(DesignError, match="--dist"):
        sampling.deviations([0.5], "cauchy")


def test_values_are_nominal_times_one_plus_tol_times_deviation():
    v = sampling.values({"R1": 1e3, "C1": 1e-9}, {"R1": 0.05, "C1": 0.1}, 1000, 7)
    assert 950 <= v["R1"].min() and v["R1"].max() <= 1050
    assert 0.9e-9 <= v["C1"].min() and v["C1"].max() <= 1.1e-9
