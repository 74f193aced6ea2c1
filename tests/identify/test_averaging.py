"""Square waves split into their steps and averaged (through :func:`prepare_step`, their entry point)."""

import math

import numpy as np
import pytest

from designer.core.errors import DesignError
from designer.core.waveform import noise_sigma
from designer.identify.preprocess import prepare_step
from designer.identify.structures import model_step

FOPDT = {"K": 2.0, "tau_s": 1e-3, "theta_s": 2e-4}


def _square(t, f, amp, t0=0.0):
    """Square wave 0 / amp starting high at t0 (and low before it)."""
    ph = np.floor((t - t0) * 2 * f)
    return np.where((t >= t0) & (ph % 2 == 0), amp, 0.0)


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
