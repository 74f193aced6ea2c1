"""The statistics against closed forms and an independent numpy computation."""

import math

import numpy as np
import pytest

from designer.core.errors import DesignError
from designer.tolerance import stats


def test_wilson_interval_closed_form():
    # k = 0 of n: the upper end is z^2 / (n + z^2)
    z = stats.Z95
    assert stats.wilson(0, 10) == pytest.approx((0.0, z * z / (10 + z * z)))
    lo, hi = stats.wilson(81, 100)
    p, n = 0.81, 100
    mid = (p + z * z / (2 * n)) / (1 + z * z / n)
    half = z * math.sqrt(p * (1 - p) / n + z * z / (4 * n * n)) / (1 + z * z / n)
    assert (lo, hi) == pytest.approx((mid - half, mid + half))


def test_figure_statistics_equal_numpy():
    rng = np.random.default_rng(0)
    v = rng.normal(10.0, 2.0, 50000)
    s = stats.figure_stats("x", v, 10.0, stats.Limit("x", 4.0, 17.0))
    assert s.mean == pytest.approx(v.mean()) and s.std == pytest.approx(v.std(ddof=1))
    assert s.percentiles[2.5] == pytest.approx(np.percentile(v, 2.5))
    assert s.cpk == pytest.approx(min(17.0 - v.mean(), v.mean() - 4.0) / (3 * v.std(ddof=1)))


def test_variance_shares_of_a_linear_figure():
    rng = np.random.default_rng(1)
    a, b = rng.uniform(-1, 1, 20000), rng.uniform(-1, 1, 20000)
    shares = stats.variance_shares({"A": a, "B": b}, 2 * a + b)
    assert shares["A"] == pytest.approx(0.8, abs=0.01) and shares["B"] == pytest.approx(0.2, abs=0.01)


@pytest.mark.parametrize("text, what", [("fn_hz=3k:", "both bounds"), ("fn_hz=4k:3k", "above max"),
                                        ("nope=1:2", "unknown figure"), ("fn_hz", "FIGURE=MIN:MAX")])
def test_malformed_limits(text, what):
    with pytest.raises(DesignError, match=what):
        stats.parse_limit(text, ("fn_hz",))


def test_limit_counts_nan_as_outside():
    lim = stats.parse_limit("fn_hz=3.3k:3.7k", ("fn_hz",))
    assert list(lim.inside([3.2e3, 3.5e3, 3.8e3, float("nan")])) == [False, True, False, False]
