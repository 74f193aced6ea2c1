"""DC motor methods: seed 000's worked example recomputed, the velocity and position
methods exact on noise-free motor responses."""

import numpy as np
import pytest
from hypothesis import given
from hypothesis import strategies as st

from designer.identify import dc_motor as dcm
from designer.identify.structures import model_step
from step_responses import FAST, gains


# ---------------------------------------------------------------- seeds

def test_seed000_dc_motor_example():
    # seed 000 lines ~508-512: a = 2, W(inf) = 2.5, t0 = 0.15, w = 1.75
    km, tau = dcm.dc_motor_velocity(2.0, 2.5, 0.15, 1.75)
    assert km == pytest.approx(1.25, abs=1e-12)
    assert round(tau, 4) == 0.1246
    # the same figures through the method on the exact velocity response
    t = np.linspace(0.0, 1.5, 30001)
    w = 2.0 * model_step("fopdt", {"K": km, "tau_s": tau, "theta_s": 0.0}, t)
    r = dcm.dc_motor(t, w / 2.0, 2.5 / 2.0)
    assert r.valid and r.model == "fopdt"
    assert r.params["K"] == pytest.approx(1.25, rel=1e-6)
    assert round(r.params["tau_s"], 4) == 0.1246


def test_dc_motor_position():
    km, tau, a = 1.25, 0.1246, 2.0
    t = np.linspace(0.0, 3.0, 3001)
    pos = a * km * (t - tau * (1.0 - np.exp(-t / tau)))
    r = dcm.dc_motor_position(t, pos, a)
    assert r.valid
    assert r.params["K"] == pytest.approx(km, rel=1e-6)
    assert r.params["tau_s"] == pytest.approx(tau, rel=1e-5)
    short = dcm.dc_motor_position(t[:200], pos[:200], a)       # 0.2 s: never reaches its asymptote
    assert not short.valid and "too short" in short.note


# ---------------------------------------------------------------- exactness

@FAST
@given(K=gains, tau=st.floats(1e-5, 1e4))
def test_dc_motor_exact(K, tau):
    t = np.linspace(0.0, 10 * tau, 5001)
    y = model_step("fopdt", {"K": K, "tau_s": tau, "theta_s": 0.0}, t)
    r = dcm.dc_motor(t, y, K)
    assert r.valid
    assert r.params["tau_s"] == pytest.approx(tau, rel=1e-9)
