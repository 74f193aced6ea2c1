"""The inputs simulate-capture plays (designer.core.excitation): held levels on their ticks, the
m-sequence itself, a random binary signal's switching rate and seed, the chirp's frequencies, a
recorded input's refusals."""

import numpy as np
import pytest

from designer.core import excitation as ex
from designer.core.errors import DesignError
from designer.core.prbs import PrbsPlan, mls


def _grid(duration, points):
    return np.linspace(0.0, duration, points)


def test_held_levels_are_reached_on_their_ticks_from_rest():
    t, v = ex.held([1.0, 1.0, 0.0, 2.0], [0.1, 0.2, 0.3, 0.4], 1e-4, 1.0)
    e = ex.Excitation("x", t, v, "")
    assert e.at(0.0) == 0.0 and e.at(0.1 - 2e-4) == 0.0
    assert list(e.at(np.array([0.1, 0.2, 0.3, 0.4, 1.0]))) == [1.0, 1.0, 0.0, 2.0, 2.0]
    assert np.all(np.diff(t) > 0)


def test_the_prbs_is_the_m_sequence_one_level_a_tick_on_samples():
    plan = PrbsPlan(5, 0.01, periods=2)
    duration, per = 2 * plan.period_s, 10
    points = int(round(duration / plan.dt_s)) * per + 1
    e = ex.prbs_input(plan, 2.0, duration, points)
    t = _grid(duration, points)
    u = e.at(t)
    ticks = u[1::per][:plan.n]                  # the level held from each tick (the first at sample 1)
    assert np.array_equal(ticks, (mls(5) + 1.0)) and u[0] == 0.0


def test_a_random_binary_signal_switches_at_its_probability_from_its_seed():
    duration, clock, p = 4000.0, 1.0, 0.2
    points = 4000 * 2 + 1
    a = ex.random_binary_input(p, clock, 1.0, duration, points, seed=9)
    b = ex.random_binary_input(p, clock, 1.0, duration, points, seed=9)
    c = ex.random_binary_input(p, clock, 1.0, duration, points, seed=10)
    assert np.array_equal(a.v, b.v) and not np.array_equal(a.v, c.v)
    ticks = a.at(_grid(duration, points))[1::2]
    rate = np.mean(np.diff(ticks) != 0)
    n = ticks.size - 1
    assert abs(rate - p) < 4 * np.sqrt(p * (1 - p) / n)   # binomial, 4 sigma
    assert set(np.unique(ticks)) == {0.0, 1.0}
    assert "default_rng([9, 1])" in a.text


def test_the_chirp_sweeps_from_f_start_to_f_stop_between_0_and_its_level():
    duration, points, f0, f1 = 100.0, 200_001, 0.05, 5.0
    e = ex.chirp_input(f0, f1, 3.0, duration, points)
    assert e.v[0] == 0.0 and e.v.min() >= 0.0 and e.v.max() <= 3.0 and e.v.max() > 2.99
    # the sweep's frequency, f0 e^(t ln(f1/f0) / T), from f0 to f1
    t = e.t
    rate = np.log(f1 / f0)
    inst = f0 * np.exp(t * rate / duration)
    assert inst[0] == pytest.approx(f0) and inst[-1] == pytest.approx(f1)
    # u crosses A/2 where the phase is pi/2 + k pi: t_k = T/r ln(1 + (pi/2 + k pi) r / (2 pi f0 T))
    x = e.v - 1.5
    i = np.flatnonzero(np.diff(np.sign(x)) != 0)
    got = t[i] - x[i] * (t[i + 1] - t[i]) / (x[i + 1] - x[i])
    k = np.arange(got.size)
    want = duration / rate * np.log1p((np.pi / 2 + k * np.pi) * rate / (2 * np.pi * f0 * duration))
    assert np.max(np.abs(got - want)) < 1e-3 * (t[1] - t[0]) * 1e3   # within a sample interval
    assert got.size == pytest.approx(2 * f0 * duration * (f1 / f0 - 1) / rate, abs=2)   # 2 x the cycles swept


@pytest.mark.parametrize("t, v, words", [
    ([-1.0, 0.0, 1.0], [0.0, 1.0, 0.0], "0 or later"),
    ([0.0, 1.0, 2.0], [0.0, 200.0, 0.0], r"beyond \+-100 V"),
    ([0.0, 1.0, 2.0], [1.0, 1.0, 1.0], "never moves"),
])
def test_a_recorded_input_is_refused_in_one_line(t, v, words):
    with pytest.raises(DesignError, match=words):
        ex.file_input(t, v, "in.csv", 100.0)


def test_a_recorded_input_is_held_from_each_time_on():
    e = ex.file_input([0.0, 1.0, 2.5], [0.5, 1.0, -1.0], "in.csv", 100.0)
    assert list(e.at(np.array([0.5, 1.0, 2.0, 2.5, 3.0]))) == [0.5, 1.0, 1.0, -1.0, -1.0]
