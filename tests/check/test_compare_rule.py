"""core.compare.nrms: xyce_verify's rule (trapezoidal weights on the test's time
points, gold interpolated onto them, reltol |gold| + abstol), the one waveform
comparison of the design commands and of check-design's golden files."""

import numpy as np
import pytest
from scipy.integrate import trapezoid

from designer.core.compare import nrms, trapezoid_weights


def test_weights_integrate_like_the_trapezoidal_rule_on_an_adaptive_grid():
    rng = np.random.default_rng(1)
    t = np.cumsum(rng.uniform(1e-9, 1e-6, 500))
    f = np.sin(2 * np.pi * t / t[-1]) ** 2
    assert np.sum(trapezoid_weights(t) * f) == pytest.approx(trapezoid(f, t), rel=1e-12)


def test_the_rule_on_an_adaptive_grid_is_the_integral_not_the_sample_mean():
    # a dense burst of samples where the error is large must not outweigh the long quiet part
    t = np.concatenate([np.linspace(0, 1e-3, 1001)[:-1], np.linspace(1e-3, 1.0, 11)])
    gold = np.ones_like(t)
    test = gold + np.where(t < 1e-3, 0.5, 0.0)
    reltol, abstol = 0.01, 0.01
    e = (gold - test) / (reltol * np.abs(gold) + abstol)
    expected = np.sqrt(trapezoid(e ** 2, t) / (t[-1] - t[0]))
    got = nrms(gold, test, abstol, reltol=reltol, t=t)
    assert got == pytest.approx(expected, rel=1e-12)
    assert got < np.sqrt(np.mean(e ** 2)) / 5


def test_gold_is_interpolated_onto_the_tests_time_points():
    t_gold = np.linspace(0, 1, 11)
    t = np.sort(np.random.default_rng(2).uniform(0, 1, 300))
    t[0], t[-1] = 0.0, 1.0
    line = lambda x: 2.0 * x + 1.0  # noqa: E731  (linear: interpolation is exact)
    assert nrms(line(t_gold), line(t), 1e-3, t=t, t_gold=t_gold) == pytest.approx(0.0, abs=1e-9)
    # a constant offset d gives d / (reltol |g| + abstol) in RMS over the span
    d = 0.01
    g = line(t)
    expected = np.sqrt(trapezoid((d / (0.01 * g + 1e-3)) ** 2, t))
    assert nrms(line(t_gold), g + d, 1e-3, t=t, t_gold=t_gold) == pytest.approx(expected, rel=1e-9)


def test_without_time_points_the_samples_are_uniform():
    gold = np.linspace(1, 2, 50)
    test = gold * 1.02
    t = np.arange(50.0)
    assert nrms(gold, test, 1e-3) == nrms(gold, test, 1e-3, t=t)


@pytest.mark.parametrize("abstol, reltol", [(0.0, 0.01), (-1.0, 0.01), (1e-3, -0.1)])
def test_tolerances_are_checked(abstol, reltol):
    with pytest.raises(ValueError):
        nrms([1.0, 2.0], [1.0, 2.0], abstol, reltol=reltol)
