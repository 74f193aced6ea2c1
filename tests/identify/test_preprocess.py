"""Preprocessing: edges, baseline, final value, steps (the waveform readings are
tests/core/test_waveform.py)."""

import math

import numpy as np
import pytest

from designer.core.errors import DesignError
from designer.core.waveform import noise_sigma
from designer.identify.preprocess import (
    block_mean,
    final_value,
    find_edges,
    prepare_step,
)
from designer.identify.structures import model_step

FOPDT = {"K": 2.0, "tau_s": 1e-3, "theta_s": 2e-4}


def _square(t, f, amp, t0=0.0):
    """Square wave 0 / amp starting high at t0 (and low before it)."""
    ph = np.floor((t - t0) * 2 * f)
    return np.where((t >= t0) & (ph % 2 == 0), amp, 0.0)


def test_edges_of_a_square_wave():
    t = np.linspace(-1e-3, 7e-3, 16001)
    u = 0.5 + _square(t, 330.0, 2.0)
    edges = find_edges(t, u)
    half = 1 / 660
    expect = [k * half for k in range(int(7e-3 / half) + 1)]
    assert len(edges) == len(expect)
    dt = t[1] - t[0]
    for e, te in zip(edges, expect):
        assert abs(e.time - te) <= dt
    assert [round(e.amplitude, 9) for e in edges[:2]] == [2.0, -2.0]
    assert edges[0].before == pytest.approx(0.5) and edges[0].after == pytest.approx(2.5)


def test_no_edges_in_a_flat_or_noisy_input():
    rng = np.random.default_rng(1)
    t = np.linspace(0, 1, 1000)
    assert find_edges(t, np.ones_like(t)) == []
    assert find_edges(t, 1 + 0.01 * rng.standard_normal(t.size)) == []


def test_block_mean_keeps_a_ramp_without_delay():
    t = np.linspace(0, 1, 100_000)
    tb, yb = block_mean(t, 3 * t + 1, 1000)
    assert tb.size <= 1000
    assert np.allclose(yb, 3 * tb + 1, atol=1e-12)


def test_final_value_refuses_a_record_that_has_not_settled():
    t = np.linspace(0, 2e-3, 2001)   # 2 tau after the dead time: still rising
    y = model_step("fopdt", FOPDT, t)
    with pytest.raises(DesignError, match="ends before the response settles"):
        final_value(t, y, 0.0)
    t = np.linspace(0, 10e-3, 2001)
    assert final_value(t, model_step("fopdt", FOPDT, t), 0.0) == pytest.approx(2.0, rel=1e-3)


def test_prepare_step_offset_delay_and_input_column():
    t = np.linspace(-2e-3, 10e-3, 12001)
    u = np.where(t >= 1e-3, 1.5, 0.2)
    y = 0.7 + 1.3 * model_step("fopdt", FOPDT, t - 1e-3)
    s = prepare_step(t, y, u)
    dt = t[1] - t[0]
    assert abs(s.t_step - 1e-3) <= dt
    assert s.amplitude == pytest.approx(1.3)
    assert s.y0 == pytest.approx(0.7)
    # the tail mean (8-9 tau after the step) is within e^-8 of K
    assert s.yf == pytest.approx(FOPDT["K"], rel=math.exp(-8))
    # thresholds are y0 + p (yf - y0): the normalised response starts at 0
    assert abs(s.y[0]) < 1e-9


def test_prepare_step_down_gives_the_same_normalised_response():
    t = np.linspace(-2e-3, 10e-3, 12001)
    up = prepare_step(t, 1 + model_step("fopdt", FOPDT, t), np.where(t >= 0, 1.0, 0.0))
    down = prepare_step(t, 5 - model_step("fopdt", FOPDT, t), np.where(t >= 0, 3.0, 4.0))
    assert down.yf == pytest.approx(up.yf, rel=1e-9)
    assert np.allclose(down.y, up.y, atol=1e-9)


def test_prepare_step_without_input_uses_trigger_or_given_time():
    t = np.linspace(-1e-3, 10e-3, 11001)
    y = model_step("fopdt", FOPDT, t)
    s = prepare_step(t, y)
    assert s.t_step == 0.0 and s.amplitude == 1.0 and any("t = 0" in n for n in s.notes)
    s = prepare_step(t, y, step_time=-0.5e-3, step_amplitude=4.0)
    assert s.t_step == -0.5e-3 and s.yf == pytest.approx(0.5, rel=1e-4)
    with pytest.raises(DesignError, match="outside the record"):
        prepare_step(t, y, step_time=1.0)


def test_square_wave_is_split_and_averaged():
    rng = np.random.default_rng(5)
    f = 50.0   # half period 10 ms = 9.8 tau after the dead time: settled to 6e-5
    t = np.linspace(-1e-3, 60e-3, 30501)
    u = _square(t, f, 2.0)
    y = np.zeros_like(t)
    for k in range(7):
        y += (1 if k % 2 == 0 else -1) * 2.0 * model_step("fopdt", FOPDT, t - k / (2 * f))
    clean = prepare_step(t, y, u)
    # the rising edges at 0, 20 and 40 ms are averaged; the falling ones (10, 30,
    # 50 ms) are kept apart; the edge at 60 ms has no half period after it
    assert clean.n_steps == clean.rising == 3 and clean.falling == 3
    assert clean.yf == pytest.approx(2.0, rel=1e-3)
    ref = model_step("fopdt", FOPDT, clean.t)
    assert np.max(np.abs(clean.y - ref)) < 0.01
    noisy = prepare_step(t, y + 0.02 * rng.standard_normal(t.size), u)
    # averaging n steps divides the noise by about sqrt(n)
    assert noise_sigma(noisy.y) < 0.02 / 2 / math.sqrt(noisy.n_steps) * 1.5


def test_square_wave_too_fast_is_refused():
    f = 1000.0   # half period 0.5 ms < settling (~4 ms)
    t = np.linspace(-1e-3, 10e-3, 11001)
    u = _square(t, f, 1.0)
    y = np.zeros_like(t)
    for k in range(22):
        y += (1 if k % 2 == 0 else -1) * model_step("fopdt", FOPDT, t - k / (2 * f))
    with pytest.raises(DesignError, match="square wave is too fast"):
        prepare_step(t, y, u)


def test_no_step_and_step_too_small():
    rng = np.random.default_rng(2)
    t = np.linspace(0, 1, 2000)
    with pytest.raises(DesignError, match="no usable step"):
        prepare_step(t, np.full_like(t, 3.0))
    small = 0.002 * model_step("fopdt", {"K": 1, "tau_s": 0.05, "theta_s": 0.1}, t)
    with pytest.raises(DesignError, match="noise standard deviations"):
        prepare_step(t, small + 0.01 * rng.standard_normal(t.size))
    with pytest.raises(DesignError, match="no step in the input column"):
        prepare_step(t, small, u=np.ones_like(t))


def test_output_only_square_wave_is_cut_at_the_next_edge():
    """No input column: the output falling back to baseline marks the next edge."""
    f = 50.0
    t = np.linspace(-1e-3, 25e-3, 26001)
    y = 2.0 * (model_step("fopdt", FOPDT, t) - model_step("fopdt", FOPDT, t - 1 / (2 * f)))
    s = prepare_step(t, y, step_time=0.0, step_amplitude=2.0)
    assert any("another input edge" in n for n in s.notes)
    assert s.t[-1] < 1 / (2 * f) + 1e-9
    assert s.t[-1] > 1 / (2 * f) - 2 * (t[1] - t[0])
    assert s.yf == pytest.approx(FOPDT["K"], rel=1e-3)
