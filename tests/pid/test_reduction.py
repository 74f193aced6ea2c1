"""Plant models for the tuning rules and their reduction: the tangent of a
model's own step against closed forms, Skogestad's (2003) half rule on his
example and by hand, the ProcessModel adapter, refusals in one line."""

import math

import numpy as np
import pytest
from scipy.optimize import brentq

from designer.core import process_build
from designer.core.errors import DesignError
from designer.pid import reduction as M

# --- the tangent of the model's own step

def test_tangent_of_an_fopdt_step_is_the_model():
    fopdt = M.model_tangent(M.ModelFopdt(2.0, 1e-3, 200e-6))
    assert (fopdt.K, fopdt.L_s, fopdt.T_s) == (2.0, 200e-6, 1e-3)
    assert fopdt.t63_s == pytest.approx(1.2e-3, rel=1e-15)
    tg = M.model_tangent(M.ModelTf((2.0,), (1e-3, 1.0), 200e-6))   # the FOPDT typed as a general model
    assert tg.L_s == pytest.approx(200e-6, rel=1e-6)
    assert tg.T_s == pytest.approx(1e-3, rel=1e-6)
    assert tg.t63_s == pytest.approx(1.2e-3, rel=1e-6)   # the 63 % point of an FOPDT is theta + tau


def sopdt_tangent(K, t1, t2, th):
    """Inflection of K (1 - (t1 e^-t/t1 - t2 e^-t/t2)/(t1 - t2)): t = t1 t2 ln(t1/t2)/(t1 - t2)."""
    ti = t1 * t2 * math.log(t1 / t2) / (t1 - t2)
    y = K * (1 - (t1 * math.exp(-ti / t1) - t2 * math.exp(-ti / t2)) / (t1 - t2))
    slope = K * (math.exp(-ti / t1) - math.exp(-ti / t2)) / (t1 - t2)
    return th + ti - y / slope, K / slope


@pytest.mark.parametrize("K_, t1, t2, th", [(1.5, 2e-3, 0.5e-3, 1e-4), (1.0, 1.0, 0.2, 0.0),
                                           (3.0, 10.0, 9.0, 2.0), (0.2, 1e-6, 1e-9, 0.0)])
def test_sopdt_tangent_matches_the_closed_form(K_, t1, t2, th):
    L_, T_ = sopdt_tangent(K_, t1, t2, th)
    tg = M.model_tangent(M.ModelSopdt(K_, t1, t2, th))
    assert (tg.L_s, tg.T_s) == pytest.approx((L_, T_), rel=1e-8)


def test_double_pole_tangent():
    # (tau s + 1)^-2: inflection at t = tau, y = 1 - 2/e, slope 1/(e tau)
    tau = 3e-3
    tg = M.model_tangent(M.ModelSopdt(1.0, tau, tau))
    assert tg.t_steepest_s == pytest.approx(tau, rel=1e-6)
    assert tg.L_s == pytest.approx(tau - (1 - 2 / math.e) * math.e * tau, rel=1e-8)
    assert tg.T_s == pytest.approx(math.e * tau, rel=1e-8)


def test_sopdt_63_percent_point():
    K_, t1, t2, th = 1.0, 1.0, 0.3, 0.1

    def z(t):
        return 1 - (t1 * math.exp(-t / t1) - t2 * math.exp(-t / t2)) / (t1 - t2) - (1 - math.exp(-1))
    t63 = th + brentq(z, 1e-9, 10.0, xtol=1e-15)
    assert M.model_tangent(M.ModelSopdt(K_, t1, t2, th)).t63_s == pytest.approx(t63, rel=1e-9)


def test_seed_plant_tangent():
    # seed 001: 1/(2.0677e-9 s^2 + 1.8189e-5 s + 1); its inflection in closed form:
    # tan(wd t) = sqrt(1 - z^2)/z
    a, b = 2.0677e-9, 1.8189e-5
    wn = 1 / math.sqrt(a)
    z = b * wn / 2
    wd = wn * math.sqrt(1 - z * z)
    ti = math.atan(math.sqrt(1 - z * z) / z) / wd
    yi = 1 - math.exp(-z * wn * ti) * (math.cos(wd * ti) + z / math.sqrt(1 - z * z) * math.sin(wd * ti))
    slope = wn / math.sqrt(1 - z * z) * math.exp(-z * wn * ti) * math.sin(wd * ti)
    tg = M.model_tangent(M.ModelTf((1.0,), (a, b, 1.0)))
    assert tg.t_steepest_s == pytest.approx(ti, rel=1e-7)
    assert (tg.L_s, tg.T_s) == pytest.approx((ti - yi / slope, 1 / slope), rel=1e-9)
    # and the seed's printed figures (SEEDS.md: L 21.6075 us, T 60.143 us measured from L)
    assert tg.t_steepest_s == pytest.approx(63.5574e-6, rel=2e-4)
    assert tg.L_s == pytest.approx(21.6075e-6, rel=2e-4)
    assert tg.T_s == pytest.approx(60.143e-6, rel=2e-4)
    # the step's overshoot, exp(-pi z/sqrt(1 - z^2))
    assert tg.overshoot_pct == pytest.approx(100 * math.exp(-math.pi * z / math.sqrt(1 - z * z)), rel=1e-4)


def test_tangent_numbers_are_the_pointwise_step_responses():
    """Regression (bda0897 made a first design_pid ~15 % slower): the tangent's
    searches evaluate prepared partial-fraction terms instead of refactoring the
    polynomial at every point; the numbers are the construction's on
    step_response itself, bit for bit (so every reference output stays)."""
    from scipy.optimize import brentq, minimize_scalar

    from designer.core.lti import step_response
    num, den = (1.0,), (2.0677e-9 * 1e-5, 2.0677e-9 + 1.8189e-5 * 1e-5, 1.8189e-5 + 1e-5, 1.0)
    tg = M.model_tangent(M.ModelTf(num, den))
    dnum = np.polymul(num, [1.0, 0.0])
    t = M._grid(np.array(den))
    h = step_response(dnum, den, t)
    i = int(np.argmax(h))
    r = minimize_scalar(lambda x: -float(step_response(dnum, den, [x])[0]), bounds=(t[i - 1], t[i + 1]),
                        method="bounded", options={"xatol": 1e-13 * float(t[-1])})
    ts = float(r.x) if -r.fun >= h[i] else float(t[i])
    hs, ys = float(step_response(dnum, den, [ts])[0]), float(step_response(num, den, [ts])[0])
    assert (tg.t_steepest_s, tg.slope_per_s, tg.y_steepest) == (ts, hs, ys)
    assert (tg.L_s, tg.T_s) == (ts - ys / hs, 1.0 / hs)
    j = int(np.argmax(step_response(num, den, t) >= M.F63))
    t63 = brentq(lambda x: float(step_response(num, den, [x])[0]) - M.F63, t[j - 1], t[j], xtol=1e-15 * t[-1])
    assert tg.t63_s == t63


def test_integrating_tangent_is_the_ramp_asymptote():
    tg = M.model_tangent(M.ModelIntegrating(20.0, 1e-3, 0.5e-3))
    assert tg.integrating and (tg.K, tg.L_s, tg.T_s) == (20.0, 1.5e-3, None)   # L = theta + tau
    # the same plant typed as polynomials: L = theta + d1 - n1
    tf = M.ModelTf((20.0,), (1e-3, 1.0, 0.0), 0.5e-3)
    assert M.model_tangent(tf).L_s == pytest.approx(1.5e-3)


# --- Skogestad (2003), "Simple analytic rules for model reduction and PID controller
# tuning", J. Process Control 13, 291-309, example E1 (the project's tests/pid/test_tuning.py
# uses it too): g0 = (-0.3s+1)(0.08s+1)/((2s+1)(s+1)(0.4s+1)(0.2s+1)(0.05s+1)^3).
# Published: half rule FOPDT theta 1.47, tau1 2.5; SOPDT theta 0.77, tau1 2, tau2 1.2.
E1 = M.ModelTf.from_factors(1.0, [2, 1, 0.4, 0.2, 0.05, 0.05, 0.05], [-0.3, 0.08])


def test_half_rule_on_skogestad_e1():
    f = M.half_rule(E1, 1).model
    assert isinstance(f, M.ModelFopdt)
    assert (round(f.K, 2), round(f.tau_s, 2), round(f.theta_s, 2)) == (1.0, 2.5, 1.47)
    assert (f.tau_s, f.theta_s) == pytest.approx((2.5, 1.47), rel=1e-9)
    s = M.half_rule(E1, 2).model
    assert (round(s.tau1_s, 2), round(s.tau2_s, 2), round(s.theta_s, 2)) == (2.0, 1.2, 0.77)
    assert (s.tau1_s, s.tau2_s, s.theta_s) == pytest.approx((2.0, 1.2, 0.77), rel=1e-9)
    # the zero (0.08 s + 1) against (0.2 s + 1) leaves the lag 0.12 (rule T3)
    assert any("rule T3" in x and "120 ms" in x for x in M.half_rule(E1, 1).steps)


def test_half_rule_on_a_higher_order_model():
    # 3 (-0.4 s + 1) e^(-0.1 s)/((5 s + 1)(3 s + 1)(0.5 s + 1)(0.2 s + 1)), by hand:
    m = M.ModelTf.from_factors(3.0, [0.5, 5.0, 0.2, 3.0], [-0.4], theta_s=0.1)
    f = M.half_rule(m, 1).model
    assert (f.K, f.tau_s, f.theta_s) == pytest.approx((3.0, 5 + 3 / 2, 0.1 + 0.4 + 3 / 2 + 0.5 + 0.2), rel=1e-9)
    s = M.half_rule(m, 2).model
    assert (s.K, s.tau1_s, s.tau2_s, s.theta_s) == pytest.approx(
        (3.0, 5.0, 3 + 0.5 / 2, 0.1 + 0.4 + 0.5 / 2 + 0.2), rel=1e-9)


def test_half_rule_on_an_integrating_model():
    m = M.ModelTf.from_factors(4.0, [2.0, 0.5, 0.1], theta_s=0.3, integrator=True)
    a = M.half_rule(m, 1).model
    assert isinstance(a, M.ModelIntegrating)
    assert (a.K, a.tau_s, a.theta_s) == pytest.approx((4.0, 0.0, 0.3 + 2.0 / 2 + 0.5 + 0.1), rel=1e-9)
    b = M.half_rule(m, 2).model
    assert (b.K, b.tau_s, b.theta_s) == pytest.approx((4.0, 2.0 + 0.25, 0.3 + 0.25 + 0.1), rel=1e-9)


def test_half_rule_refuses_complex_poles_in_one_line():
    with pytest.raises(DesignError, match="complex poles") as e:
        M.half_rule(M.ModelTf((1.0,), (2.0677e-9, 1.8189e-5, 1.0)))
    assert str(e.value).startswith("half rule:") and "\n" not in str(e.value)


# --- the project's ProcessModel, as the rules' model

def _wn(fn):
    return 2 * math.pi * fn


@pytest.mark.parametrize("pm, expected", [
    (process_build.fopdt(2.0, 1e-3, 200e-6), M.ModelFopdt(2.0, 1e-3, 200e-6)),
    (process_build.fopdt(-2.0, 1e-3, 0.0), M.ModelFopdt(-2.0, 1e-3, 0.0)),
    (process_build.sopdt(1.5, 0.5e-3, 2e-3, 1e-4), M.ModelSopdt(1.5, 2e-3, 0.5e-3, 1e-4)),   # the slow one first
    (process_build.integrating(20.0, 1e-3, 0.5e-3), M.ModelIntegrating(20.0, 1e-3, 0.5e-3)),
    (process_build.integrating(3.0, 0.0, 1e-3), M.ModelIntegrating(3.0, 0.0, 1e-3)),
    (process_build.underdamped(1.0, 3500.0, 0.2, 20e-6),
     M.ModelTf((1.0,), (1 / _wn(3500.0) ** 2, 2 * 0.2 / _wn(3500.0), 1.0), 20e-6)),
    (process_build.rational([4.0], [2e-3, 2.0], 200e-6), M.ModelTf((2.0,), (1e-3, 1.0), 200e-6)),   # D(0) = 1
])
def test_from_process_by_kind(pm, expected):
    got = M.from_process(pm)
    assert type(got) is type(expected)
    if isinstance(expected, M.ModelTf):
        assert (got.num, got.theta_s) == (expected.num, expected.theta_s)
        assert got.den == pytest.approx(expected.den, rel=1e-12)
    else:
        assert got == expected
    t = np.linspace(0.0, 10 * pm.time_scale_s + pm.theta_s, 401)
    assert M.model_step(got, t) == pytest.approx(pm.step(t), rel=1e-12, abs=1e-12 * abs(pm.gain))


def test_from_process_refuses_what_is_not_a_process_model():
    with pytest.raises(DesignError, match="not a ProcessModel") as e:
        M.from_process(M.ModelFopdt(1.0, 1.0))
    assert "\n" not in str(e.value)


# --- refusals

def test_model_refusals_are_one_line():
    cases = [
        (lambda: M.ModelSopdt(1.0, 1.0, 2.0), "larger"),
        (lambda: M.ModelFopdt(1.0, 0.0, 1.0), "tau_s"),
        (lambda: M.ModelFopdt(0.0, 1.0, 1.0), "no gain"),
        (lambda: M.ModelTf((1.0, 0.0, 0.0), (1.0, 1.0)), "proper"),
        (lambda: M.half_rule(M.ModelFopdt(1.0, 1.0), 3), "order"),
        (lambda: M.model_tangent(M.ModelTf((1.0,), (1.0, -1.0))), "right half-plane"),
        (lambda: M.model_tangent(M.ModelTf((1.0, 1.0), (2.0, 1.0))), "jumps at t = 0"),
        (lambda: M.model_tangent("K=1 tau=1"), "not a plant model"),
    ]
    for call, what in cases:
        with pytest.raises(DesignError, match=what) as e:
            call()
        assert "\n" not in str(e.value)
