"""Preprocessing: a capture to a normalised step, the step given, from the input or from the output
(edges, levels and square waves are test_edges.py, test_settle.py and test_averaging.py; the waveform
readings are tests/core/test_waveform.py)."""

import math

import numpy as np
import pytest

from designer.core.errors import DesignError
from designer.identify.preprocess import prepare_step
from designer.identify.structures import model_step

FOPDT = {"K": 2.0, "tau_s": 1e-3, "theta_s": 2e-4}


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
