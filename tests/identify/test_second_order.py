"""Every second-order step method (``STEP_METHODS``): validity ranges reported
instead of wrong numbers, a dead time flagged by the methods that assume none,
no exception on any data."""

import math

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

from designer.identify import dc_motor as dcm
from designer.identify import overdamped as od
from designer.identify import second_order as so
from designer.identify import underdamped as ud
from designer.identify.structures import MODELS, MethodResult, model_step
from step_responses import overdamped, second_order, underdamped


# ---------------------------------------------------------------- ranges and robustness

@pytest.mark.parametrize("method, make, word", [
    (ud.log_decrement, lambda: underdamped(1.0, 2.0, 0.6), "0.5"),
    (ud.t4_t3, lambda: second_order(1.0, 2.0, 0.3), "log-decrement"),
    (ud.t4_t3, lambda: second_order(1.0, 2.0, 3.0), "two-pole"),
    (od.two_pole, lambda: second_order(1.0, 2.0, 1.2), "zeta > 2"),
    (ud.overshoot, lambda: overdamped(1.0, 1.0, 3.0), "underdamped"),
    (ud.chen, lambda: overdamped(1.0, 1.0, 3.0), "underdamped"),
    (od.stark_mollenkamp, lambda: second_order(1.0, 2.0, 2.5), "zeta"),
    (od.jahanmiri_fallahi, lambda: underdamped(1.0, 2.0, 0.3), "0.696"),
    (od.peeling, lambda: underdamped(1.0, 2.0, 0.5), "overshoots"),
    (dcm.dc_motor, lambda: overdamped(1.0, 1.0, 3.0), "first-order"),
])
def test_outside_range_is_flagged(method, make, word):
    t, y = make()
    r = method(t, y, float(y[-1]))
    assert isinstance(r, MethodResult)
    assert not r.valid
    assert word in r.note


BAD = {
    "flat": (np.linspace(0, 1, 100), np.zeros(100), 1.0),
    "zero final": (np.linspace(0, 1, 100), np.zeros(100), 0.0),
    "short": (np.array([0.0, 1.0]), np.array([0.0, 1.0]), 1.0),
    "nan": (np.linspace(0, 1, 100), np.full(100, np.nan), 1.0),
    "noise only": (np.linspace(0, 1, 1000), np.random.default_rng(0).normal(0, 1, 1000), 0.01),
    "ramp": (np.linspace(0, 1, 1000), np.linspace(0, 1, 1000), 0.5),
}


@pytest.mark.parametrize("case", sorted(BAD))
@pytest.mark.parametrize("method", so.STEP_METHODS, ids=lambda m: m.__name__)
def test_methods_never_raise(method, case):
    t, y, yf = BAD[case]
    r = method(t, y, yf)
    assert isinstance(r, MethodResult)
    assert r.model in MODELS
    if not r.valid:
        assert r.note
    r.to_dict()


def test_names_and_models():
    names = [m(*underdamped(1.0, 1.0, 0.3)[:2], 1.0).name for m in so.STEP_METHODS]
    assert names == ["overshoot", "log-decrement", "t4-t3", "two-pole", "chen",
                     "stark-mollenkamp", "jahanmiri-fallahi", "peeling", "dc-motor",
                     "alfaro-123c-overdamped", "harriott"]


@pytest.mark.parametrize("method, make", [
    (ud.overshoot, lambda: underdamped(1.0, 2.0, 0.3, theta=1.0)),
    (ud.log_decrement, lambda: underdamped(1.0, 2.0, 0.3, theta=1.0)),
    (ud.t4_t3, lambda: overdamped(1.0, 1.0, 3.0, theta=1.0)),
    (od.two_pole, lambda: overdamped(1.0, 0.1, 3.0, theta=1.0)),
    (dcm.dc_motor, lambda: (lambda t: (t, model_step("fopdt", {"K": 1.0, "tau_s": 1.0,
                                                               "theta_s": 0.5}, t)))(
        np.linspace(0, 12, 5001))),
])
def test_no_delay_methods_flag_a_dead_time(method, make):
    t, y = make()
    r = method(t, y, 1.0)
    assert not r.valid
    assert ("delay-free" if method is dcm.dc_motor else "dead time") in r.note


@settings(max_examples=60, deadline=None)
@given(y=st.lists(st.floats(-1e3, 1e3), min_size=0, max_size=300),
       yf=st.floats(-1e3, 1e3) | st.just(0.0) | st.just(math.nan),
       dt=st.floats(1e-9, 1e3))
def test_methods_never_raise_on_arbitrary_data(y, yf, dt):
    y = np.array(y, float)
    t = dt * np.arange(y.size)
    for method in so.STEP_METHODS:
        r = method(t, y, yf)
        assert isinstance(r, MethodResult) and r.model in MODELS
        assert r.valid is True or r.valid is False or bool(r.valid) in (True, False)
        if not r.valid:
            assert r.note
