"""The closed-loop step with exact dead time: each result against a computation
done another way here: the parallel PID's formula, scipy's rational closed loop
without delay, and step responses from a Heun integration of the delay equation
(the delay on the plant input, a buffer of past samples) at a ten times finer
step."""

import math

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st
from scipy import signal

from designer.core.errors import DesignError
from designer.pid import delayloop as dl
from designer.pid.delaymargins import loop_margins


def heun_reference(plant, controller, h, n_steps, r=1.0):
    """Step response y of the loop with the delay on the plant input, by Heun's
    method (explicit trapezoid) on realisations from scipy.signal.tf2ss; theta must
    be a whole number M of steps h, so the delayed input is a stored sample. Both
    one-sided values are kept where u jumps (at 0, and at multiples of theta with
    a direct path), so jumps are not smeared over a step."""
    pn, pd, theta = plant
    m = int(round(theta / h))
    assert abs(m * h - theta) <= 1e-9 * theta
    ap, bp, cp, dp = (np.atleast_2d(x) for x in signal.tf2ss(pn, pd))
    ac, bc, cc, dc = (np.atleast_2d(x) for x in signal.tf2ss(*controller))
    bp, bc, cp, cc = bp[:, 0], bc[:, 0], cp[0], cc[0]
    dp, dc = float(dp[0, 0]), float(dc[0, 0])
    xp, xc = np.zeros(ap.shape[0]), np.zeros(ac.shape[0])
    u_plus, u_minus = np.zeros(n_steps), np.zeros(n_steps)   # u(t_k+), u(t_k-); u(0-) = 0
    y = np.zeros(n_steps)

    def delayed(buf, k):
        return buf[k - m] if k - m >= 0 else 0.0

    def outputs(xp, xc, ud):
        yk = float(cp @ xp) + dp * ud
        ek = r - yk
        return yk, ek, float(cc @ xc) + dc * ek

    y[0], e0, u_plus[0] = outputs(xp, xc, 0.0)
    for k in range(n_steps - 1):
        ud0 = delayed(u_plus, k)
        _, e0, _ = outputs(xp, xc, ud0)
        fp, fc = ap @ xp + bp * ud0, ac @ xc + bc * e0
        xp1, xc1 = xp + h * fp, xc + h * fc
        ud1 = delayed(u_minus, k + 1)
        _, e1, _ = outputs(xp1, xc1, ud1)
        xp = xp + 0.5 * h * (fp + ap @ xp1 + bp * ud1)
        xc = xc + 0.5 * h * (fc + ac @ xc1 + bc * e1)
        _, _, u_minus[k + 1] = outputs(xp, xc, ud1)
        y[k + 1], _, u_plus[k + 1] = outputs(xp, xc, delayed(u_plus, k + 1))
    return y


# ------------------------------------------------------------------ the PID


@pytest.mark.parametrize("kp, ti, td, n", [(2.0, 0.5, 0.1, 8.0), (2.0, 0.5, 0.1, None), (1.5, math.inf, 0.2, 5.0),
                                           (1.5, 0.3, 0.0, None), (0.7, math.inf, 0.0, None)])
def test_pid_tf_is_the_parallel_pid(kp, ti, td, n):
    w = np.geomspace(1e-2, 1e3, 50)
    s = 1j * w
    want = kp * (1 + (1 / (ti * s) if math.isfinite(ti) else 0)
                 + (td * s / (td / n * s + 1) if n else td * s))
    num, den = dl.pid_tf(kp, ti, td, n)
    assert np.allclose(np.polyval(num, s) / np.polyval(den, s), want, rtol=1e-12)


def test_ideal_pid_is_refused_by_the_simulation():
    with pytest.raises(DesignError, match="n_filter"):
        dl.closed_loop_step(([1.0], [1.0, 1.0], 0.1), dl.pid_tf(1.0, 1.0, 0.2), np.linspace(0, 1, 11))


# ------------------------------------------------------------------ (a) no delay: scipy's rational loop


def test_without_delay_the_step_is_scipys_rational_closed_loop():
    pn, pd = [2.0], [0.5, 1.2, 1.0]
    cn, cd = dl.pid_tf(1.5, 0.8, 0.2, 10)
    t = np.linspace(0, 10, 1001)
    num = np.polymul(cn, pn)
    den = np.polyadd(np.polymul(cd, pd), num)
    _, y_ref = signal.step((num, den), T=t)
    _, u_ref = signal.step((np.polymul(cn, pd), den), T=t)
    out = dl.closed_loop_step((pn, pd, 0.0), (cn, cd), t, r_step=1.0)
    assert np.max(np.abs(out["y"] - y_ref)) < 1e-6
    assert np.max(np.abs(out["u"] - u_ref)) < 1e-6 * np.max(np.abs(u_ref))
    assert np.allclose(out["e"], 1.0 - out["y"], atol=1e-12)


# ------------------------------------------------------------------ (b) step responses with the delay


@pytest.mark.parametrize("n_points", [401, 371])   # theta a whole number of steps, and not
def test_fopdt_pi_step_matches_a_heun_delay_integration(n_points):
    k, tau, theta = 1.5, 2.0, 0.36
    plant = ([k], [tau, 1.0], theta)
    ctrl = dl.pid_tf(0.8 * tau / (k * 2 * theta), 0.6 * tau, 0.0)
    t_end = 18.0
    t = np.linspace(0, t_end, n_points)
    out = dl.closed_loop_step(plant, ctrl, t)
    h = theta / math.ceil(10 * theta / (t[1] - t[0]))        # ten times finer, theta a whole number
    y = heun_reference(plant, ctrl, h, int(math.ceil(t_end / h)) + 2)
    y_ref = np.interp(t, np.arange(y.size) * h, y)
    assert np.max(np.abs(out["y"] - y_ref)) < 1e-3
    assert np.allclose(out["e"], 1 - out["y"])


def test_sopdt_filtered_pid_step_matches_a_heun_delay_integration():
    # the derivative's kick at t = 0 reaches the plant theta later
    plant = ([1.0], np.polymul([1.0, 1.0], [0.3, 1.0]), 0.25)
    ctrl = dl.pid_tf(2.0, 1.2, 0.25, 8.0)
    t = np.linspace(0, 12, 481)
    out = dl.closed_loop_step(plant, ctrl, t, r_step=0.5)
    h = (t[1] - t[0]) / 10
    y = heun_reference(plant, ctrl, h, 10 * (t.size - 1) + 1, r=0.5)
    assert np.max(np.abs(out["y"] - y[::10])) < 1e-3 * 0.5


def test_biproper_plant_jumps_at_each_delay():
    # a direct path through P C: y jumps at theta, 2 theta, ... (a neutral delay equation)
    plant = ([1.0, 2.0], [1.0, 1.0], 0.5)
    ctrl = dl.pid_tf(0.5, 1.0, 0.0)
    assert loop_margins(plant, ctrl).stable
    t = np.linspace(0, 10, 201)
    out = dl.closed_loop_step(plant, ctrl, t)
    h = (t[1] - t[0]) / 10
    y = heun_reference(plant, ctrl, h, 10 * (t.size - 1) + 1)
    assert np.max(np.abs(out["y"] - y[::10])) < 1e-3
    # y jumps at theta by P(inf) C(inf) r = 1 x 0.5 (sample 10 is t = theta, just after the jump)
    assert out["y"][10] - out["y"][9] == pytest.approx(0.5, abs=0.01)
    assert out["y"][9] == 0.0


def test_short_delay_of_a_few_steps_matches_a_heun_delay_integration():
    # theta of a few dozen simulation steps: the delay line is solved as states
    plant = ([1.0], [1.0, 1.0], 0.02)
    ctrl = dl.pid_tf(1 / (2 * 0.02), 0.16, 0.0)
    t = np.linspace(0, 1.5, 151)
    out = dl.closed_loop_step(plant, ctrl, t)
    h = (t[1] - t[0]) / 10
    y = heun_reference(plant, ctrl, h, 10 * (t.size - 1) + 1)
    assert np.max(np.abs(out["y"] - y[::10])) < 1e-3


def test_delay_under_one_step_matches_a_heun_delay_integration():
    # theta a fraction of the simulation's step: read between samples
    plant = ([1.0], [1.0, 1.0], 0.005)
    ctrl = dl.pid_tf(2.0, 1.0, 0.0)
    t = np.linspace(0, 5, 101)
    out = dl.closed_loop_step(plant, ctrl, t)
    h = 0.005 / 20
    y = heun_reference(plant, ctrl, h, int(5.0 / h) + 2)
    assert np.max(np.abs(out["y"] - np.interp(t, np.arange(y.size) * h, y))) < 1e-3


def test_a_vanishing_delay_tends_to_the_loop_without_one():
    plant_n, plant_d = [2.0], [0.5, 1.2, 1.0]
    ctrl = dl.pid_tf(1.5, 0.8, 0.2, 10)
    t = np.linspace(0, 10, 1001)
    y0 = dl.closed_loop_step((plant_n, plant_d, 0.0), ctrl, t)["y"]
    for theta in (1e-6, 1e-3):
        y = dl.closed_loop_step((plant_n, plant_d, theta), ctrl, t)["y"]
        # y moves by about theta times its steepest slope
        assert np.max(np.abs(y - y0)) < 3 * theta * np.max(np.abs(np.gradient(y0, t)))


# ------------------------------------------------------------------ (c) integrating plant


def test_integrating_plant_with_delay_under_pi_is_stable_with_no_offset():
    k, theta = 0.5, 0.4
    tc = theta                                # SIMC for K e^(-theta s)/s
    kc, ti = 1 / (k * (tc + theta)), 4 * (tc + theta)
    plant = ([k], [1.0, 0.0], theta)
    ctrl = dl.pid_tf(kc, ti, 0.0)
    m = loop_margins(plant, ctrl)
    assert m.stable and m.rhp_roots == 0 and m.phase_margin_deg > 30 and m.gain_margin_db > 3
    t = np.linspace(0, 40, 801)
    out = dl.closed_loop_step(plant, ctrl, t)
    f = dl.step_figures(t, out["y"], 1.0)
    assert abs(f.steady_state_error) < 1e-3
    assert f.settling_time_s < 30
    h = (t[1] - t[0]) / 10
    y = heun_reference(plant, ctrl, h, 10 * (t.size - 1) + 1)
    assert np.max(np.abs(out["y"] - y[::10])) < 1e-3


# ------------------------------------------------------------------ figures


def test_step_figures_of_a_first_order_response():
    tau = 0.5
    t = np.linspace(0, 10, 20001)
    y = 2.0 * (1 - np.exp(-t / tau))
    f = dl.step_figures(t, y, 2.0)
    assert f.iae == pytest.approx(2.0 * tau, rel=1e-6)           # integral of 2 e^(-t/tau)
    assert f.rise_time_s == pytest.approx(tau * math.log(9), rel=1e-4)
    assert f.settling_time_s == pytest.approx(tau * math.log(50), rel=1e-4)
    assert f.overshoot_pct == 0 and math.isnan(f.peak_time_s)
    assert f.steady_state_error == pytest.approx(2.0 * math.exp(-20), abs=1e-12)


# ------------------------------------------------------------------ (d) SIMC on random FOPDT plants


@settings(max_examples=25)
@given(k=st.floats(0.1, 10.0), log_tau=st.floats(-2.0, 2.0), ratio=st.floats(0.02, 3.0))
def test_simc_pi_on_random_fopdt_plants_is_stable_and_settles(k, log_tau, ratio):
    tau = 10 ** log_tau
    theta = ratio * tau
    kc, ti = tau / (k * 2 * theta), min(tau, 8 * theta)
    plant = ([k], [tau, 1.0], theta)
    ctrl = dl.pid_tf(kc, ti, 0.0)
    m = loop_margins(plant, ctrl)
    assert m.stable and m.rhp_roots == 0
    for v in (m.crossover_hz, m.phase_margin_deg, m.gain_margin_db, m.delay_margin_s, m.ms):
        assert math.isfinite(v)
    assert m.phase_margin_deg > 0 and m.gain_margin_db > 0 and m.delay_margin_s > 0
    t = np.linspace(0, 40 * (theta + ti), 2001)
    out = dl.closed_loop_step(plant, ctrl, t)
    f = dl.step_figures(t, out["y"], 1.0)
    assert abs(f.steady_state_error) < 1e-3
    assert f.settling_time_s < 0.8 * t[-1]


# ------------------------------------------------------------------ the step budget (issue 25, item 6)

#: K=2 tau=20m theta=50u under AMIGO's PID (Kp 90.1, Ti 390.7 us, Td 25 us) built with an LM741: its
#: crossover, 2.6e4 rad/s, let the op-amp stages' poles at 2.3e6 and 6.3e6 rad/s into the step's choice
FAST_PLANT = ([2.0], [20e-3, 1.0], 50e-6)


def _fast_controller():
    num, den = dl.pid_tf(90.1, 390.7e-6, 24.98e-6, 10.0)
    for p in (2.3e6, 6.3e6):
        den = np.polymul(den, [1.0 / p, 1.0])
    return num, den


def test_a_long_record_of_a_loop_with_fast_poles_keeps_to_the_step_budget(monkeypatch):
    """A record of 0.235 s (the leak's slow mode) with op-amp poles at 6e6 rad/s
    needed 1e7 steps of 22 ns and was refused ("shorten t"); the matrix exponential
    integrates those modes exactly, so the step only has to follow the delayed plant
    output: at the budget's step (2.35 us) the response is the fine step's."""
    ctrl = _fast_controller()
    lp = dl.parse_loop(FAST_PLANT, ctrl)
    assert dl._simulation_step(lp) * dl.MAX_STEPS < 0.235       # the old choice could not take the record
    t_long = np.linspace(0.0, 0.235, 2001)
    y_long = dl.closed_loop_step(FAST_PLANT, ctrl, t_long)["y"]
    # the first 3 ms at the fine step (136k steps of 22 ns) and at the budget's step
    t = np.linspace(0.0, 3e-3, 3001)
    fine = dl.closed_loop_step(FAST_PLANT, ctrl, t)["y"]
    monkeypatch.setattr(dl, "STEP_BUDGET", t[-1] / (t_long[-1] / dl.STEP_BUDGET))
    coarse = dl.closed_loop_step(FAST_PLANT, ctrl, t)["y"]
    assert np.max(np.abs(coarse - fine)) < 1e-3
    first = t_long <= t[-1]
    assert np.max(np.abs(y_long[first] - np.interp(t_long[first], t, fine))) < 1e-3
    assert np.max(fine) > 1.05                                 # an overshoot the comparison sees
