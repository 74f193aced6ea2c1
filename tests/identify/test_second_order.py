"""Second-order step methods: seeds' worked examples recomputed, every method
exact on noise-free responses of its own model structure, validity ranges
reported instead of wrong numbers."""

import math

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

from designer.core.waveform import crossing_time
from designer.identify import second_order as so
from designer.identify.structures import MODELS, MethodResult, iae_ise, model_step

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
    return t, K * so.normalized_step(zeta, wn * t)


gains = st.floats(0.1, 10.0) | st.floats(-10.0, -0.1)
freqs = st.floats(0.01, 1e5)


# ---------------------------------------------------------------- seeds

def test_seed003_example1_rlc():
    # seed 003 lines ~394-420: Mpt = 1.526, Tp = 3.22 s -> zeta = 0.20035, wn = 0.996
    zeta = float(so.zeta_from_overshoot(1.526 - 1.0))
    wn = float(so.wn_from_peak_time(3.22, zeta))
    assert round(zeta, 4) == 0.2004
    assert round(zeta * zeta, 5) == 0.04014
    assert round(wn, 4) == 0.9958


def test_seed003_example1_through_the_method():
    # the same numbers read off a waveform by the method (peak at 3.22 s, 52.6 %)
    zeta = float(so.zeta_from_overshoot(0.526))
    wn = float(so.wn_from_peak_time(3.22, zeta))
    t, y = underdamped(1.0, wn, zeta)
    r = so.overshoot(t, y, 1.0)
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
    l = abs(math.log(mp))
    assert float(so.zeta_from_overshoot(mp)) == pytest.approx(z1, abs=0.0006)
    second = l / math.sqrt(4 * math.pi ** 2 + l * l)
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
    tab = so.t4_t3_table([row[1] for row in SEED002_TABLE2])
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
    assert so.Y3_LEVEL == pytest.approx(0.26416, abs=1e-4)
    assert so.Y4_LEVEL == pytest.approx(0.80079, abs=1e-4)
    assert round(so.Y3_LEVEL, 5) == 0.26424 and round(so.Y4_LEVEL, 5) == 0.80085
    assert so.t4_t3_ratio(1.0) == pytest.approx(3.0, abs=1e-9)
    # at zeta = 1: t3 = 1/wn, t4 = 3/wn (1 - (1 + t) e^-t)
    tab = so.t4_t3_table([1.0])
    assert tab["wn_t3"][0] == pytest.approx(1.0, abs=1e-9)
    assert tab["wn_t4"][0] == pytest.approx(3.0, abs=1e-9)


def test_t4_t3_ratio_is_monotonic():
    z = np.linspace(0.05, 10.0, 60)
    r = np.array([so.t4_t3_ratio(v) for v in z])
    assert np.all(np.diff(r) > 0)


def test_seed000_dc_motor_example():
    # seed 000 lines ~508-512: a = 2, W(inf) = 2.5, t0 = 0.15, w = 1.75
    km, tau = so.dc_motor_velocity(2.0, 2.5, 0.15, 1.75)
    assert km == pytest.approx(1.25, abs=1e-12)
    assert round(tau, 4) == 0.1246
    # the same figures through the method on the exact velocity response
    t = np.linspace(0.0, 1.5, 30001)
    w = 2.0 * model_step("fopdt", {"K": km, "tau_s": tau, "theta_s": 0.0}, t)
    r = so.dc_motor(t, w / 2.0, 2.5 / 2.0)
    assert r.valid and r.model == "fopdt"
    assert r.params["K"] == pytest.approx(1.25, rel=1e-6)
    assert round(r.params["tau_s"], 4) == 0.1246


def test_dc_motor_position():
    km, tau, a = 1.25, 0.1246, 2.0
    t = np.linspace(0.0, 3.0, 3001)
    pos = a * km * (t - tau * (1.0 - np.exp(-t / tau)))
    r = so.dc_motor_position(t, pos, a)
    assert r.valid
    assert r.params["K"] == pytest.approx(km, rel=1e-6)
    assert r.params["tau_s"] == pytest.approx(tau, rel=1e-5)
    short = so.dc_motor_position(t[:200], pos[:200], a)       # 0.2 s: never reaches its asymptote
    assert not short.valid and "too short" in short.note


def test_seed003_table21_peeling_example():
    # seed 003 Table 2.1: tau1 = 5, tau2 = 100 -> k1 = 0.0526, k2 = 1.0526; reading
    # 0.2 at tx = 166 s on the slow line gives tau2 = 99.96 s
    tau1, tau2 = 5.0, 100.0
    k1, k2 = tau1 / (tau2 - tau1), tau2 / (tau2 - tau1)
    assert round(k1, 4) == 0.0526 and round(k2, 4) == 1.0526
    assert round(-166.0 / math.log10(0.2 / 1.0526) * math.log10(math.e), 2) == 99.96
    # Table 2.2's 1 - c(t) column (3 decimals) against the exact response
    tab_t = np.array([0, 5, 10, 30, 50, 60, 70, 80, 100, 140, 180, 200, 280.0])
    tab_r = np.array([1, 0.982, 0.946, 0.78, 0.64, 0.58, 0.523, 0.473, 0.387, 0.26, 0.174,
                      0.143, 0.064])
    exact = 1.0 - model_step("overdamped", {"K": 1.0, "tau1_s": tau1, "tau2_s": tau2}, tab_t)
    assert np.max(np.abs(exact - tab_r)) < 0.0025     # printed to 2-3 decimals
    # the method on the exact response recovers both constants
    t, y = overdamped(1.0, tau1, tau2)
    r = so.peeling(t, y, 1.0)
    assert r.valid
    assert r.params["tau1_s"] == pytest.approx(5.0, rel=1e-6)
    assert r.params["tau2_s"] == pytest.approx(100.0, rel=1e-6)
    assert r.points["K1"] == pytest.approx(k1, rel=1e-5)
    assert r.points["K2"] == pytest.approx(k2, rel=1e-6)
    # on the seed's 3-decimal table the slow line is read as the seed read it
    r = so.peeling(tab_t, 1.0 - tab_r, 1.0)
    assert r.points["tau_slow_s"] == pytest.approx(99.96, rel=0.01)


def test_seed003_furnace_is_flagged_not_silently_wrong():
    # seed 003 Table 2.3: both exponentials fall (a zero), which two cascaded
    # poles cannot produce
    t = np.array([0, 5, 13, 20, 30, 53, 80, 100, 140, 170, 240.0])
    c = np.array([0, 300, 500, 600, 700, 800, 860, 870, 878, 883, 890.0])
    r = so.peeling(t, c, 900.0)
    assert not r.valid and r.note


# ---------------------------------------------------------------- exactness

@FAST
@given(K=gains, wn=freqs, zeta=st.floats(0.03, 0.9))
def test_overshoot_exact(K, wn, zeta):
    t, y = underdamped(K, wn, zeta)
    r = so.overshoot(t, y, K)
    assert r.valid and r.model == "underdamped"
    assert r.params["zeta"] == pytest.approx(zeta, rel=1e-5)
    assert r.params["wn_rad_s"] == pytest.approx(wn, rel=1e-5)
    assert r.params["K"] == K


@FAST
@given(K=gains, wn=freqs, zeta=st.floats(0.03, 0.5))
def test_log_decrement_exact(K, wn, zeta):
    t, y = underdamped(K, wn, zeta)
    r = so.log_decrement(t, y, K)
    assert r.valid
    assert r.params["zeta"] == pytest.approx(zeta, rel=1e-5)
    assert r.params["wn_rad_s"] == pytest.approx(wn, rel=1e-5)
    assert r.points["zeta_first"] == pytest.approx(r.points["zeta_second"], rel=1e-5)


@FAST
@given(K=gains, wn=freqs, zeta=st.floats(0.5, 2.0))
def test_t4_t3_exact(K, wn, zeta):
    t, y = second_order(K, wn, zeta)
    r = so.t4_t3(t, y, K)
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
@given(K=gains, wn=freqs, zeta=st.floats(2.05, 10.0))
def test_two_pole_exact(K, wn, zeta):
    t, y = second_order(K, wn, zeta)
    r = so.two_pole(t, y, K)
    assert r.valid and r.model == "overdamped"
    root = math.sqrt(zeta * zeta - 1.0)
    # the fast pole comes from the tail and is the least accurate: the method
    # neglects e^{-p1 t} above 60 %, below 1e-5 for zeta > 2
    assert r.params["tau2_s"] == pytest.approx(1.0 / (wn * (zeta - root)), rel=1e-5)
    assert r.params["tau1_s"] == pytest.approx(1.0 / (wn * (zeta + root)), rel=2e-4)
    assert r.points["zeta"] == pytest.approx(zeta, rel=1e-4)


@FAST
@given(K=gains, wn=freqs, zeta=st.floats(0.03, 0.6), dead=st.floats(0.0, 3.0))
def test_chen_exact(K, wn, zeta, dead):
    theta = dead / wn
    t, y = underdamped(K, wn, zeta, theta)
    r = so.chen(t, y, K)
    assert r.valid
    assert r.params["zeta"] == pytest.approx(zeta, rel=1e-5)
    assert r.params["wn_rad_s"] == pytest.approx(wn, rel=1e-5)
    assert r.params["theta_s"] == pytest.approx(theta, abs=1e-4 / wn)
    assert r.points["y_inf_eq29"] == pytest.approx(K, rel=1e-5)


def _zeta_wn(r):
    if r.model == "underdamped":
        return r.params["zeta"], r.params["wn_rad_s"]
    a, b = r.params["tau1_s"], r.params["tau2_s"]
    wn = 1.0 / math.sqrt(a * b)
    return (a + b) * wn / 2.0, wn


@FAST
@given(K=gains, wn=freqs, zeta=st.floats(0.45, 1.3), dead=st.floats(0.0, 3.0))
def test_stark_mollenkamp_within_its_correlation_error(K, wn, zeta, dead):
    # an empirical correlation: 3 % in zeta and wn over its stated range
    t = np.linspace(0.0, (dead + 40.0) / wn, 40001)
    y = K * so.normalized_step(zeta, np.clip(wn * t - dead, 0.0, None))
    r = so.stark_mollenkamp(t, y, K)
    assert r.valid
    z_hat, wn_hat = _zeta_wn(r)
    assert z_hat == pytest.approx(zeta, rel=0.03)
    assert wn_hat == pytest.approx(wn, rel=0.03)
    assert r.params["theta_s"] == pytest.approx(dead / wn, abs=0.06 / wn)


@pytest.mark.parametrize("zeta", [0.7, 0.8, 1.0, 1.5])
def test_jahanmiri_fallahi_model_follows_the_data(zeta):
    # the correlation trades the slow start for dead time: the model is not the
    # data's parameters but follows the curve (IAE below 6 % of t90)
    wn, K = 3.0, 2.0
    t, y = second_order(K, wn, zeta)
    r = so.jahanmiri_fallahi(t, y, K)
    assert r.valid
    t90 = crossing_time(t, y / K, 0.9)
    iae, _ = iae_ise(t, y, model_step(r.model, r.params, t))
    assert iae / (abs(K) * t90) < 0.06
    assert r.params["theta_s"] in (pytest.approx(r.points["t2_s"]), pytest.approx(r.points["t5_s"]))


def test_jahanmiri_fallahi_equations():
    # eq 40 at eta = 0 gives sqrt(0.4844651); at the switch eta = 0.4771 it meets eq 41
    assert so._jf_from(0.0, 1.0, 1.0)[1] == pytest.approx(math.sqrt(0.4844651))
    t90 = 1.0
    _, z_sw, _ = so._jf_from(0.0, t90 - 0.4771 * t90, t90)
    assert z_sw == pytest.approx(13.9352, rel=0.01)


@FAST
@given(K=gains, tau2=st.floats(1e-4, 1e3), ratio=st.floats(1.6, 50.0),
       dead=st.floats(0.0, 1.0))
def test_peeling_exact(K, tau2, ratio, dead):
    tau1 = tau2 / ratio
    t, y = overdamped(K, tau1, tau2, dead * tau2)
    r = so.peeling(t, y, K)
    assert r.valid and r.model == "overdamped"
    assert r.params["tau1_s"] == pytest.approx(tau1, rel=1e-4)
    assert r.params["tau2_s"] == pytest.approx(tau2, rel=1e-5)
    assert r.params["theta_s"] == pytest.approx(dead * tau2, abs=1e-4 * tau2)


@FAST
@given(K=gains, tau=st.floats(1e-5, 1e4))
def test_dc_motor_exact(K, tau):
    t = np.linspace(0.0, 10 * tau, 5001)
    y = model_step("fopdt", {"K": K, "tau_s": tau, "theta_s": 0.0}, t)
    r = so.dc_motor(t, y, K)
    assert r.valid
    assert r.params["tau_s"] == pytest.approx(tau, rel=1e-9)


# ---------------------------------------------------------------- ranges and robustness

@pytest.mark.parametrize("method, make, word", [
    (so.log_decrement, lambda: underdamped(1.0, 2.0, 0.6), "0.5"),
    (so.t4_t3, lambda: second_order(1.0, 2.0, 0.3), "log-decrement"),
    (so.t4_t3, lambda: second_order(1.0, 2.0, 3.0), "two-pole"),
    (so.two_pole, lambda: second_order(1.0, 2.0, 1.2), "zeta > 2"),
    (so.overshoot, lambda: overdamped(1.0, 1.0, 3.0), "underdamped"),
    (so.chen, lambda: overdamped(1.0, 1.0, 3.0), "underdamped"),
    (so.stark_mollenkamp, lambda: second_order(1.0, 2.0, 2.5), "zeta"),
    (so.jahanmiri_fallahi, lambda: underdamped(1.0, 2.0, 0.3), "0.696"),
    (so.peeling, lambda: underdamped(1.0, 2.0, 0.5), "overshoots"),
    (so.dc_motor, lambda: overdamped(1.0, 1.0, 3.0), "first-order"),
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


def test_noisy_underdamped_with_dead_time():
    # 1 % noise: the lobe-based methods still read the oscillation within a few %
    K, wn, zeta, theta = 2.0, 3.0, 0.2, 0.5
    t, y = underdamped(K, wn, zeta, theta, n=50001)
    y = y + np.random.default_rng(3).normal(0.0, 0.01 * K, y.size)
    r = so.chen(t, y, K)
    assert r.valid
    assert r.params["zeta"] == pytest.approx(zeta, rel=0.05)
    assert r.params["wn_rad_s"] == pytest.approx(wn, rel=0.02)
    assert r.params["theta_s"] == pytest.approx(theta, abs=0.05)
    r = so.log_decrement(t, y, K)
    assert r.params["zeta"] == pytest.approx(zeta, rel=0.05)


@pytest.mark.parametrize("method, make", [
    (so.overshoot, lambda: underdamped(1.0, 2.0, 0.3, theta=1.0)),
    (so.log_decrement, lambda: underdamped(1.0, 2.0, 0.3, theta=1.0)),
    (so.t4_t3, lambda: overdamped(1.0, 1.0, 3.0, theta=1.0)),
    (so.two_pole, lambda: overdamped(1.0, 0.1, 3.0, theta=1.0)),
    (so.dc_motor, lambda: (lambda t: (t, model_step("fopdt", {"K": 1.0, "tau_s": 1.0,
                                                               "theta_s": 0.5}, t)))(
        np.linspace(0, 12, 5001))),
])
def test_no_delay_methods_flag_a_dead_time(method, make):
    t, y = make()
    r = method(t, y, 1.0)
    assert not r.valid
    assert ("delay-free" if method is so.dc_motor else "dead time") in r.note


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


def test_noise_in_a_settled_tail_is_not_an_overshoot():
    # 200k samples of an overdamped response with 1 % noise: some samples exceed
    # the final value by 4 sigma; none of them may pass for an overshoot
    t, y = overdamped(1.0, 1.0, 3.0, n=200001)
    y = y + np.random.default_rng(11).normal(0.0, 0.01, y.size)
    for method in (so.overshoot, so.log_decrement, so.chen):
        assert not method(t, y, 1.0).valid


@pytest.mark.parametrize("zeta", [0.3, 0.7])
def test_overshoot_on_noisy_data(zeta):
    t, y = second_order(2.0, 3.0, zeta, n=100001)
    y = y + np.random.default_rng(int(10 * zeta)).normal(0.0, 0.02, y.size)   # 1 % of K
    r = so.overshoot(t, y, 2.0)
    assert r.valid
    assert r.params["zeta"] == pytest.approx(zeta, rel=0.02)
    assert r.params["wn_rad_s"] == pytest.approx(3.0, rel=0.03)


def test_peeling_on_noisy_data():
    # 1 % noise: close time constants still come out within 10 %; whatever is
    # reported valid follows the data to a few noise widths
    rng = np.random.default_rng(0)
    t, y = overdamped(1.0, 1.0, 2.0, theta=0.5, n=100001)
    r = so.peeling(t, y + rng.normal(0.0, 0.01, y.size), 1.0)
    assert r.valid
    assert r.params["tau1_s"] == pytest.approx(1.0, rel=0.1)
    assert r.params["tau2_s"] == pytest.approx(2.0, rel=0.1)
    for k in range(4):
        t, y = overdamped(1.0, 1.0, 5.0, theta=0.5, n=100001)
        r = so.peeling(t, y + rng.normal(0.0, 0.01, y.size), 1.0)
        if r.valid:
            assert r.points["rms_error"] <= 0.04


# --------------------------------------------------------------------------- issue 9

@pytest.mark.parametrize("a", [0.0, 0.1, 0.3, 0.5, 0.75, 1.0])
def test_alfaro_123c_overdamped_follows_the_response(a):
    """Alfaro's 123c correlations over their range 0 <= a <= 1: for a >= 0.3 the
    model they give follows the exact response within 1.5 % of the step (the
    parameters themselves are a fitted correlation, T within about 13 %);
    nearer one pole a result is either that close or invalid."""
    from designer.identify.structures import model_step
    T, L, K = 2e-3, 4e-4, 1.5
    t = np.linspace(0.0, L + 25 * T, 50001)
    p = ({"K": K, "tau_s": T, "theta_s": L} if a == 0 else
         {"K": K, "tau1_s": a * T, "tau2_s": T, "theta_s": L})
    y = model_step("fopdt" if a == 0 else "overdamped", p, t)
    r = so.alfaro_123c_overdamped(t, y, K)
    assert r.name == "alfaro-123c-overdamped" and r.model == "overdamped"
    ym = model_step(r.model, r.params, t)
    if a >= 0.3:
        assert r.valid
        assert np.max(np.abs(ym - y)) < 0.015 * K
        assert r.params["tau2_s"] == pytest.approx(T, rel=0.13)
    elif not r.valid:
        # near one pole the correlation drifts and says so
        assert "misses the data" in r.note or "outside 0 <= a <= 1" in r.note
    else:
        assert np.sqrt(np.mean((ym - y) ** 2)) < 0.02 * K


@pytest.mark.parametrize("ratio", [0.05, 0.2, 0.35, 0.5])
def test_harriott_recovers_two_poles(ratio):
    """Harriott's 73 % rule is itself approximate (t73 = 1.3 (tau1 + tau2) within
    about 1 %); with the chart computed exactly, both time constants come back
    within a few per cent."""
    from designer.identify.structures import model_step
    total = 3e-3
    p = {"K": 2.0, "tau1_s": ratio * total, "tau2_s": (1 - ratio) * total + 1e-12,
         "theta_s": 0.0}
    t = np.linspace(0.0, 12 * total, 40001)
    r = so.harriott(t, model_step("overdamped", p, t), 2.0)
    assert r.valid and r.name == "harriott"
    assert r.params["tau1_s"] + r.params["tau2_s"] == pytest.approx(total, rel=0.02)
    assert r.params["tau2_s"] == pytest.approx(p["tau2_s"], rel=0.06)
    ym = model_step("overdamped", r.params, t)
    assert np.max(np.abs(ym - model_step("overdamped", p, t))) < 0.01 * 2.0


def test_harriott_refuses_a_dead_time():
    from designer.identify.structures import model_step
    p = {"K": 1.0, "tau1_s": 1e-3, "tau2_s": 2e-3, "theta_s": 2e-3}
    t = np.linspace(0.0, 0.03, 30001)
    r = so.harriott(t, model_step("overdamped", p, t), 1.0)
    assert not r.valid
