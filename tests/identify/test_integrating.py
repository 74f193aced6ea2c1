"""The integrating process's step method (designer.identify.integrating): the
ramp's asymptote against closed-form responses of K e^(-theta s)/s and
K e^(-theta s)/(s (tau s + 1)), seeded noise, and settling responses it must
refuse."""

import math

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

from designer.identify.integrating import METHOD_NAME, asymptote, step_capture_ramp

TS = 0.1


def ramp(K, theta, t, tau=0.0):
    """Closed form: the unit step response of K e^(-theta s)/(s (tau s + 1))."""
    x = np.clip(t - theta, 0.0, None)
    return K * (x - (tau * (1.0 - np.exp(-x / tau)) if tau > 0 else 0.0))


@settings(max_examples=40, deadline=None)
@given(K=st.floats(0.01, 10.0), theta=st.floats(0.0, 20.0), n=st.integers(200, 3000))
def test_a_clean_ramp_gives_its_gain_and_dead_time(K, theta, n):
    t = np.arange(n) * TS
    if theta >= 0.2 * t[-1]:       # the dead time must end before the fitted tail starts
        theta = 0.1 * t[-1]
    m = asymptote(t, ramp(K, theta, t))
    assert m.valid, m.note
    assert m.name == METHOD_NAME and m.model == "integrating"
    assert m.params["K"] == pytest.approx(K, rel=1e-9)
    assert m.params["theta_s"] == pytest.approx(theta, abs=1e-9 * (1 + theta))


def test_a_lag_behind_the_integrator_adds_to_the_apparent_dead_time():
    """K e^(-theta s)/(s (tau s + 1)) tends to K (t - theta - tau): the
    asymptote's intercept is theta + tau (the record's tail 20 tau on)."""
    t = np.arange(6001) * TS
    m = asymptote(t, ramp(0.5, 1.2, t, tau=3.0))
    assert m.valid, m.note
    assert m.params["K"] == pytest.approx(0.5, rel=1e-9)
    assert m.params["theta_s"] == pytest.approx(4.2, rel=1e-9)


@pytest.mark.parametrize("seed", [1, 2, 3])
def test_noisy_ramp_within_its_intervals(seed):
    """Seeded white noise: the estimates within their 95 % intervals of the truth
    (three seeds: the interval's 5 % miss rate makes three misses unlikely)."""
    t = np.arange(3000) * TS
    y = ramp(0.3, 1.1, t) + np.random.default_rng(seed).normal(0.0, 2.0, t.size)
    m = asymptote(t, y)
    assert m.valid, m.note
    assert abs(m.params["K"] - 0.3) <= m.points["K_ci95"]
    assert abs(m.params["theta_s"] - 1.1) <= m.points["theta_s_ci95"]


@pytest.mark.parametrize("tau", [5.0, 200.0])
def test_a_settling_response_is_refused(tau):
    """A first-order lag settled within the record (5 s) has no slope; one of
    200 s over 300 s bends (its tail's halves rise at different rates)."""
    t = np.arange(3000) * TS
    y = 2.0 * (1.0 - np.exp(-t / tau)) + np.random.default_rng(5).normal(0.0, 0.01, t.size)
    m = asymptote(t, y)
    assert not m.valid
    assert ("does not ramp" in m.note) or ("bends" in m.note), m.note


def test_too_few_samples_are_refused():
    m = asymptote(np.arange(10) * TS, np.arange(10.0))
    assert not m.valid and "at least 20" in m.note
    assert math.isnan(m.params["K"])


def test_a_step_capture_is_read_from_its_input():
    """A step of -2 V at sample 300 (the first at the new level), the output
    from a level of 1.5 V: K per second per input volt, the dead time from the
    step's sample."""
    t = np.arange(3001) * TS
    u = np.where(np.arange(t.size) >= 300, 1.0, 3.0)
    y = 1.5 + ramp(0.25, 0.7, t - t[300]) * -2.0
    m = step_capture_ramp(t, u, y)
    assert m.valid, m.note
    assert m.points["t_step_s"] == t[300] and m.points["amplitude"] == pytest.approx(-2.0)
    assert m.params["K"] == pytest.approx(0.25, rel=1e-9)
    assert m.params["theta_s"] == pytest.approx(0.7, abs=1e-9)


def test_an_input_with_two_edges_is_not_a_step_capture():
    t = np.arange(3001) * TS
    u = np.where((np.arange(t.size) >= 300) & (np.arange(t.size) < 1500), 1.0, 0.0)
    assert step_capture_ramp(t, u, np.zeros(t.size)) is None


def test_a_ramp_that_started_before_the_step_is_refused():
    """The output already rising at the step (its line meets the initial level
    5 s before it): not an integrator answering the step."""
    t = np.arange(3000) * TS
    m = asymptote(t, 0.3 * (t + 5.0))
    assert not m.valid and "before the step" in m.note
