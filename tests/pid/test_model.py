"""The realised controller and closed loop: limits that must give the ideal
PID, closed forms for stage and loop gains, the simulator against scipy,
margins of known loops, and the optimiser."""

import math

import numpy as np
import pytest
from scipy import signal

from designer.core import opamps
from designer.core.metrics import step_metrics
from designer.pid import blocks, model, optimize, selection, tuning

A, B = 2.0677e-9, 1.8189e-5      # seed plant 1/(A s^2 + B s + 1)
PN, PD = np.array([1.0]), np.array([A, B, 1.0])
IDEAL = opamps.get("ideal")
LM741 = opamps.get("LM741")


def test_realised_loop_tends_to_the_ideal_pid():
    # leak corner -> 0 and derivative filter -> infinity: the realised loop is the ideal PID
    kp, ti, td = 3.34, 43.215e-6, 10.8037e-6
    parts = blocks.continuous_parts(kp, ti, td, 3500, f_integrator_hz=1e-3, f_differentiator_hz=1e9)
    lm = model.assemble(parts, IDEAL, PN, PD)
    t = np.linspace(0, 1e-3, 5001)
    r = np.ones_like(t)
    r[0] = 0.0
    y = lm.simulate(t, r)["y"]
    yi = model.ideal_loop(kp, ti, td, PN, PD).simulate(t, r)["y"]
    assert np.max(np.abs(y - yi)) < 2e-3
    assert step_metrics(t, y).overshoot_pct == pytest.approx(step_metrics(t, yi).overshoot_pct, abs=0.1)


def test_simulator_matches_scipy_lsim():
    parts = selection.select_parts(3.34, 43.215e-6, 10.8037e-6, 3500).parts
    lm = model.assemble(parts, LM741, PN, PD)
    t = np.linspace(0, 1e-3, 4001)
    r = model.reference(t, 1.0, 20e-6, 3e-6)
    ours = lm.simulate(t, r)
    _, ys, _ = signal.lsim((lm.a, lm.b, lm.c, lm.d), r, t)
    for i, name in enumerate(lm.outputs):
        assert np.max(np.abs(ours[name] - ys[:, i])) < 1e-6 * max(1.0, np.max(np.abs(ys[:, i])))


def test_dc_loop_gain_closed_form():
    # at DC: L(0) = Kp (1 + R13 C4 / Ti) x plant gain, with ideal op-amps
    parts = selection.select_parts(3.34, 43.215e-6, 10.8037e-6, 3500).parts
    L0 = model.loop_gain(parts, IDEAL, PN, PD, np.array([1e-6]))[0]
    assert L0.real == pytest.approx(parts.kp * (1 + parts.integrator_dc_gain), rel=1e-6)
    assert abs(L0.imag) < 1e-6 * abs(L0)
    # and the closed loop's DC gain is L/(1 + L)
    lm = model.assemble(parts, IDEAL, PN, PD)
    iy = lm.outputs.index("y")
    dc = float(-(lm.c[iy] @ np.linalg.solve(lm.a, lm.b)).item() + lm.d[iy, 0])
    assert dc == pytest.approx(L0.real / (1 + L0.real), rel=1e-9)


def test_inverting_stage_with_finite_gbw_closed_form():
    # unity inverter with a single-pole op-amp: -1 / (1 + 2 (1 + s/wp)/A0)
    num, den = model.inverting_stage([1.0], [1.0], [2.0], LM741)
    w = 2 * np.pi * np.array([1.0, 1e4, 1e5, 1e6])
    _, h = signal.freqs(num, den, worN=w)
    a = LM741.a0 / (1 + 1j * w / (2 * np.pi * LM741.pole_hz))
    assert np.allclose(h, -1 / (1 + 2 / a), rtol=1e-9)
    # its -3 dB bandwidth is GBW / noise gain
    f3 = LM741.gbw_hz / 2
    _, h3 = signal.freqs(num, den, worN=[2 * np.pi * f3])
    assert abs(h3[0]) == pytest.approx(1 / math.sqrt(2), rel=1e-3)


def test_margins_of_known_loops():
    w = np.logspace(-2, 3, 20001)
    # integrator wc/s: PM 90 deg at wc, no phase crossover
    m = model.margins(w, 10.0 / (1j * w))
    assert m.phase_margin_deg == pytest.approx(90.0, abs=1e-6)
    assert m.crossover_hz * 2 * np.pi == pytest.approx(10.0, rel=1e-4)
    # K / (s (s + 1)), K = 4: wc^2 sqrt(wc^2 + 1) = 4, PM = 90 - atan(wc)
    L = 4.0 / (1j * w * (1j * w + 1))
    wc = math.sqrt((-1 + math.sqrt(1 + 64)) / 2)
    m = model.margins(w, L)
    assert m.phase_margin_deg == pytest.approx(90 - math.degrees(math.atan(wc)), abs=1e-3)
    # K/(s+1)^3, K = 4: phase -180 at w = sqrt(3), |L| = 4/8: GM = 6.02 dB
    L = 4.0 / (1j * w + 1) ** 3
    m = model.margins(w, L)
    assert m.gain_margin_db == pytest.approx(20 * math.log10(2), abs=1e-3)
    assert m.phase_crossover_hz * 2 * np.pi == pytest.approx(math.sqrt(3), rel=1e-4)


def test_seed_final_gains_are_unstable_with_lm741_but_not_ideal():
    seed = blocks.seed_parts()
    assert model.assemble(seed, IDEAL, PN, PD).stable()
    assert not model.assemble(seed, LM741, PN, PD).stable()
    w = 2 * np.pi * np.logspace(1, 7, 4000)
    assert model.margins(w, model.loop_gain(seed, LM741, PN, PD, w)).phase_margin_deg < 0


def test_waveform_limits_and_slew_delay():
    t = np.linspace(0, 10e-6, 1001)
    v = np.clip(t / 1e-6, 0, 1) * 5.0        # 5 V in 1 us: 5 V/us
    # at 1 V/us the op-amp needs 5 us instead of 1 us: 4 us late
    assert model.slew_delay(t, v, 1e6) == pytest.approx(4e-6, rel=1e-3)
    assert model.slew_delay(t, v, 10e6) == 0.0
    lim = model.waveform_limits({"u": v}, t, LM741, 1e-6)
    assert lim["gain"].v_max == pytest.approx(5.0) and lim["gain"].v_min == pytest.approx(0.0)
    assert lim["gain"].swing_ok and not lim["gain"].slew_ok
    big = model.waveform_limits({"u": 3 * v}, t, LM741, 1e-3)
    assert not big["gain"].swing_ok


def test_optimizer_meets_overshoot_target_with_ideal_opamps():
    t = np.linspace(0, 1.2e-3, 2001)
    ctx = optimize.Context(PN, PD, IDEAL, 3500, 1.0, 100e-9, t, 10.0)
    tp = np.linspace(0, 2e-3, 20001)
    _, yp = signal.step((PN, PD), T=tp)
    c = tuning.reaction_curve(tp, yp, final=1.0)
    res = optimize.optimize(ctx, [(r.kp, r.ti_s, r.td_s) for r in (tuning.tune("zn", c),)], maxiter=80)
    assert res.met
    assert res.best.overshoot_pct <= 10.25
    # and it is better (ITAE) than the plant alone and than the ZN start
    zn = tuning.tune("zn", c)
    assert res.best.cost < optimize.evaluate(zn.kp, zn.ti_s, zn.td_s, ctx).cost
    assert res.best.cost < 1.0


def test_optimizer_respects_lm741_limits():
    t = np.linspace(0, 1.2e-3, 2001)
    pn, pd = PN, PD
    ctx = optimize.Context(pn, pd, LM741, 3500, 1.0, 100e-9, t, 10.0)
    res = optimize.optimize(ctx, [(0.8, 70e-6, 14e-6)], maxiter=60)
    b = res.best
    assert b.stable and b.swing_ratio <= 1.0 and b.slew_ratio <= 1.0
    assert b.overshoot_pct <= 10.25
    # the seed's gains break the limits in the same model
    seed = optimize.evaluate(45, 43.215e-6, 10.8037e-6, ctx)
    assert not seed.stable or seed.swing_ratio > 1 or seed.slew_ratio > 1


def test_realised_controller_tf_is_the_pid_between_its_corners():
    kp, ti, td = 3.34, 43.215e-6, 10.8037e-6
    parts = blocks.continuous_parts(kp, ti, td, 3500, f_integrator_hz=1.0, f_differentiator_hz=1e7)
    num, den = model.controller_tf(parts, IDEAL)
    w = 2 * np.pi * np.array([300.0, 3500.0, 30e3])
    _, c = signal.freqs(num, den, worN=w)
    ideal = kp * (1 + 1 / (1j * w * ti) + 1j * w * td)
    assert np.allclose(c, ideal, rtol=0.01)
    # the leak and the filter: finite gain at DC (Kp (1 + R13 C4/Ti)) and at high frequency (Kp (1 + Td/Tf))
    _, c0 = signal.freqs(num, den, worN=[1e-3])
    assert c0[0].real == pytest.approx(kp * (1 + parts.integrator_dc_gain), rel=1e-4)
    # with the LM741 the controller's loop is the one loop_gain evaluates
    num7, den7 = model.controller_tf(parts, LM741)
    w = 2 * np.pi * np.logspace(2, 6, 50)
    _, c7 = signal.freqs(num7, den7, worN=w)
    _, p7 = signal.freqs(PN, PD, worN=w)
    assert np.allclose(c7 * p7, model.loop_gain(parts, LM741, PN, PD, w), rtol=1e-6)


def test_the_kicks_fine_grid_and_the_coarse_one_from_one_exponential():
    """simulate_with_kick (the coarse propagator squared up from the fine one, the ramp's increment
    rescaled) gives what simulate gives on each grid by its own matrix exponential."""
    parts = selection.select_parts(3.34, 43.215e-6, 10.8037e-6, 3500).parts
    lm = model.assemble(parts, LM741, PN, PD)
    t = np.linspace(0.0, 1e-3, 2001)
    h = (t[1] - t[0]) / 8
    t_fine = h * np.arange(400)
    r, r_fine = (model.reference(x, 1.0, 0.0, 1e-7) for x in (t, t_fine))
    coarse, fine = lm.simulate_with_kick(t, r, t_fine, r_fine)
    for k, v in lm.simulate(t, r).items():
        np.testing.assert_allclose(coarse[k], v, rtol=1e-7, atol=1e-9 * max(1.0, np.abs(v).max()))
    for k, v in lm.simulate(t_fine, r_fine).items():
        np.testing.assert_array_equal(fine[k], v)
    with pytest.raises(ValueError, match="power of two"):
        lm.simulate_with_kick(t, r, t_fine[:10] * 1.5, r_fine[:10])
