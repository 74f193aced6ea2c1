"""Exact step responses of the second-order model structures, and the hypothesis
settings and strategies, that the tests of the second-order step methods share
(tests/identify/test_underdamped.py, test_overdamped.py, test_dc_motor.py, test_second_order.py)."""

import math

import numpy as np
from hypothesis import settings
from hypothesis import strategies as st

from designer.identify import underdamped as ud
from designer.identify.structures import model_step

FAST = settings(max_examples=25, deadline=None)


def underdamped(K, wn, zeta, theta=0.0, periods=12.0, n=20001):
    t = np.linspace(0.0, theta + periods * 2 * math.pi / wn, n)
    return t, model_step("underdamped", {"K": K, "wn_rad_s": wn, "zeta": zeta, "theta_s": theta}, t)


def overdamped(K, tau1, tau2, theta=0.0, n=20001):
    t = np.linspace(0.0, theta + 14.0 * max(tau1, tau2), n)
    p = {"K": K, "tau1_s": tau1, "tau2_s": tau2, "theta_s": theta}
    return t, model_step("overdamped", p, t)


def second_order(K, wn, zeta, n=40001):
    """Exact response for any zeta (under, critical, over) via the normalised form."""
    t = np.linspace(0.0, 20.0 * max(1.0, 2 * zeta) / wn, n)
    return t, K * ud.normalized_step(zeta, wn * t)


gains = st.floats(0.1, 10.0) | st.floats(-10.0, -0.1)
freqs = st.floats(0.01, 1e5)
