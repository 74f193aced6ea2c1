"""Underdamped step methods (overshoot, log-decrement, t4-t3, chen): seeds' worked
examples recomputed, every method exact on noise-free responses of its own model
structure, and robust on noisy ones."""

import math

import numpy as np
import pytest
from hypothesis import given
from hypothesis import strategies as st

from designer.identify import underdamped as ud
from step_responses import FAST, freqs, gains, overdamped, second_order, underdamped


# ---------------------------------------------------------------- seeds

def test_seed003_example1_rlc():
    # seed 003 lines ~394-420: Mpt = 1.526, Tp = 3.22 s -> zeta = 0.20035, wn = 0.996
    zeta = float(ud.zeta_from_overshoot(1.526 - 1.0))
    wn = float(ud.wn_from_peak_time(3.22, zeta))
    assert round(zeta, 4) == 0.2004
    assert round(zeta * zeta, 5) == 0.04014
    assert round(wn, 4) == 0.9958


def test_seed003_example1_through_the_method():
    # the same numbers read off a waveform by the method (peak at 3.22 s, 52.6 %)
    zeta = float(ud.zeta_from_overshoot(0.526))
    wn = float(ud.wn_from_peak_time(3.22, zeta))
    t, y = underdamped(1.0, wn, zeta)
    r = ud.overshoot(t, y, 1.0)
    assert r.valid
    assert r.points["tp_s"] == pytest.approx(3.22, rel=1e-6)
    assert r.points["overshoot"] == pytest.approx(0.526, rel=1e-6)
    assert round(r.params["zeta"], 4) == 0.2004 and round(r.params["wn_rad_s"], 4) == 0.9958


# seed 002 Table 1: overshoot fraction -> zeta from the first and second overshoot
SEED002_TABLE1 = [(0.05, 0.690, 0.431), (0.10, 0.591, 0.344), (0.15, 0.517, 0.289),
                  (0.20, 0.456, 0.248), (0.25, 0.404, 0.216), (0.30, 0.358, 0.188),
                  (0.35, 0.317, 0.165), (0.40, 0.280, 0.144), (0.45, 0.246, 0.126),
                  (0.50, 0.216, 0.110), (0.55, 0.187, 0.095), (0.60, 0.161, 0.081),
                  (0.65, 0.136, 0.068), (0.70, 0.113, 0.057), (0.75, 0.091, 0.046),
                  (0.80, 0.071, 0.036), (0.85, 0.052, 0.026), (0.90, 0.034, 0.017)]


@pytest.mark.parametrize("mp, z1, z2", SEED002_TABLE1)
def test_seed002_table1(mp, z1, z2):
    lm = abs(math.log(mp))
    assert float(ud.zeta_from_overshoot(mp)) == pytest.approx(z1, abs=0.0006)
    second = lm / math.sqrt(4 * math.pi ** 2 + lm * lm)
    if mp == 0.05:
        assert round(second, 3) == 0.430      # printed 0.431: off by one in the last digit
    else:
        assert second == pytest.approx(z2, abs=0.0006)


# seed 002 Table 2 (t4/t3, zeta, wn t4); entries the exact response contradicts
# beyond the table's 2-decimal rounding are listed as misprints below.
SEED002_TABLE2 = [(2.21, 0.5, 1.89), (2.33, 0.6, 2.05), (2.46, 0.7, 2.24), (2.62, 0.8, 2.46),
                  (2.80, 0.9, 2.71), (2.90, 0.95, 2.85), (3.00, 1.0, 3.00), (3.13, 1.05, 3.19),
                  (3.20, 1.1, 3.31), (3.37, 1.2, 3.63), (3.57, 1.3, 3.96), (3.72, 1.4, 4.30),
                  (3.90, 1.5, 4.64), (4.04, 1.6, 4.97), (4.15, 1.7, 5.30), (4.25, 1.8, 5.63),
                  (4.35, 1.9, 5.97), (4.43, 2.0, 6.3)]
# (zeta, column): computed value -> printed value
MISPRINTS = {(1.05, "ratio"): 3.10, (1.05, "wn_t4"): 3.15, (1.2, "ratio"): 3.40,
             (1.4, "ratio"): 3.75}


def test_seed002_table2_recomputed():
    tab = ud.t4_t3_table([row[1] for row in SEED002_TABLE2])
    for (ratio, zeta, wnt4), r_c, w_c in zip(SEED002_TABLE2, tab["t4_t3"], tab["wn_t4"]):
        for col, printed, computed in (("ratio", ratio, r_c), ("wn_t4", wnt4, w_c)):
            if (zeta, col) in MISPRINTS:
                assert round(computed, 2) == MISPRINTS[(zeta, col)]
                assert abs(computed - printed) > 0.02
            else:
                # the table is rounded (sometimes truncated) to 2 decimals
                assert computed == pytest.approx(printed, abs=0.0125), (zeta, col)


def test_t4_t3_is_three_at_critical_damping():
    # seed 002 eq 8 prints 0.26416 and 0.80079 for 1 - 2/e and 1 - 4/e^3; the
    # exact values differ in the 4th decimal (misprints): the code uses the formulas
    assert ud.Y3_LEVEL == pytest.approx(0.26416, abs=1e-4)
    assert ud.Y4_LEVEL == pytest.approx(0.80079, abs=1e-4)
    assert round(ud.Y3_LEVEL, 5) == 0.26424 and round(ud.Y4_LEVEL, 5) == 0.80085
    assert ud.t4_t3_ratio(1.0) == pytest.approx(3.0, abs=1e-9)
    # at zeta = 1: t3 = 1/wn, t4 = 3/wn (1 - (1 + t) e^-t)
    tab = ud.t4_t3_table([1.0])
    assert tab["wn_t3"][0] == pytest.approx(1.0, abs=1e-9)
    assert tab["wn_t4"][0] == pytest.approx(3.0, abs=1e-9)


def test_t4_t3_ratio_is_monotonic():
    z = np.linspace(0.05, 10.0, 60)
    r = np.array([ud.t4_t3_ratio(v) for v in z])
    assert np.all(np.diff(r) > 0)


# ---------------------------------------------------------------- exactness

@FAST
@given(K=gains, wn=freqs, zeta=st.floats(0.03, 0.9))
def test_overshoot_exact(K, wn, zeta):
    t, y = underdamped(K, wn, zeta)
    r = ud.overshoot(t, y, K)
    assert r.valid and r.model == "underdamped"
    assert r.params["zeta"] == pytest.approx(zeta, rel=1e-5)
    assert r.params["wn_rad_s"] == pytest.approx(wn, rel=1e-5)
    assert r.params["K"] == K


@FAST
@given(K=gains, wn=freqs, zeta=st.floats(0.03, 0.5))
def test_log_decrement_exact(K, wn, zeta):
    t, y = underdamped(K, wn, zeta)
    r = ud.log_decrement(t, y, K)
    assert r.valid
    assert r.params["zeta"] == pytest.approx(zeta, rel=1e-5)
    assert r.params["wn_rad_s"] == pytest.approx(wn, rel=1e-5)
    assert r.points["zeta_first"] == pytest.approx(r.points["zeta_second"], rel=1e-5)


@FAST
@given(K=gains, wn=freqs, zeta=st.floats(0.5, 2.0))
def test_t4_t3_exact(K, wn, zeta):
    t, y = second_order(K, wn, zeta)
    r = ud.t4_t3(t, y, K)
    assert r.valid
    if r.model == "underdamped":
        z_hat, wn_hat = r.params["zeta"], r.params["wn_rad_s"]
    else:
        a, b = r.params["tau1_s"], r.params["tau2_s"]
        wn_hat = 1.0 / math.sqrt(a * b)
        z_hat = (a + b) * wn_hat / 2.0
    assert z_hat == pytest.approx(zeta, rel=1e-5)
    assert wn_hat == pytest.approx(wn, rel=1e-5)


@FAST
@given(K=gains, wn=freqs, zeta=st.floats(0.03, 0.6), dead=st.floats(0.0, 3.0))
def test_chen_exact(K, wn, zeta, dead):
    theta = dead / wn
    t, y = underdamped(K, wn, zeta, theta)
    r = ud.chen(t, y, K)
    assert r.valid
    assert r.params["zeta"] == pytest.approx(zeta, rel=1e-5)
    assert r.params["wn_rad_s"] == pytest.approx(wn, rel=1e-5)
    assert r.params["theta_s"] == pytest.approx(theta, abs=1e-4 / wn)
    assert r.points["y_inf_eq29"] == pytest.approx(K, rel=1e-5)


# ---------------------------------------------------------------- ranges and robustness

def test_noisy_underdamped_with_dead_time():
    # 1 % noise: the lobe-based methods still read the oscillation within a few %
    K, wn, zeta, theta = 2.0, 3.0, 0.2, 0.5
    t, y = underdamped(K, wn, zeta, theta, n=50001)
    y = y + np.random.default_rng(3).normal(0.0, 0.01 * K, y.size)
    r = ud.chen(t, y, K)
    assert r.valid
    assert r.params["zeta"] == pytest.approx(zeta, rel=0.05)
    assert r.params["wn_rad_s"] == pytest.approx(wn, rel=0.02)
    assert r.params["theta_s"] == pytest.approx(theta, abs=0.05)
    r = ud.log_decrement(t, y, K)
    assert r.params["zeta"] == pytest.approx(zeta, rel=0.05)


def test_noise_in_a_settled_tail_is_not_an_overshoot():
    # 200k samples of an overdamped response with 1 % noise: some samples exceed
    # the final value by 4 sigma; none of them may pass for an overshoot
    t, y = overdamped(1.0, 1.0, 3.0, n=200001)
    y = y + np.random.default_rng(11).normal(0.0, 0.01, y.size)
    for method in (ud.overshoot, ud.log_decrement, ud.chen):
        assert not method(t, y, 1.0).valid


@pytest.mark.parametrize("zeta", [0.3, 0.7])
def test_overshoot_on_noisy_data(zeta):
    t, y = second_order(2.0, 3.0, zeta, n=100001)
    y = y + np.random.default_rng(int(10 * zeta)).normal(0.0, 0.02, y.size)   # 1 % of K
    r = ud.overshoot(t, y, 2.0)
    assert r.valid
    assert r.params["zeta"] == pytest.approx(zeta, rel=0.02)
    assert r.params["wn_rad_s"] == pytest.approx(3.0, rel=0.03)
