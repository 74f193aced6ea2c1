"""The loop's frequency domain with exact dead time: each result against a
computation done another way here: closed forms of the integrator-plus-delay
loop and of an unstable plant's delay limit, the ultimate gain by bisection on
a time simulation (Heun's method on the FOPDT loop under PI), and Ms on a very
dense grid."""

import math

import numpy as np
import pytest

from designer.pid import delaymargins as dm
from designer.pid.delayloop import pid_tf

INTEGRATOR = ([1.0], [1.0, 0.0])


def fopdt_pi_grows(k, tau, theta, kc, ti, h, t_end):
    """True when the FOPDT loop K e^(-theta s)/(tau s + 1) under Kc (1 + 1/(Ti s)),
    integrated by Heun's method (pure Python floats, for speed), oscillates with a
    growing envelope: the error's peak over the last quarter of the record beats
    the peak over the quarter before it."""
    m = int(round(theta / h))
    n = int(t_end / h)
    x = z = 0.0
    ubuf = [0.0] * n
    err = [0.0] * n
    for i in range(n - 1):
        e = 1.0 - x
        err[i] = e
        ubuf[i] = kc * (e + z / ti)
        ud0 = ubuf[i - m] if i >= m else 0.0
        ud1 = ubuf[i + 1 - m] if i + 1 >= m else 0.0
        fx = (k * ud0 - x) / tau
        xp = x + h * fx
        x, z = x + 0.5 * h * (fx + (k * ud1 - xp) / tau), z + 0.5 * h * (e + 1.0 - xp)
    q = n // 4
    late = max(abs(v) for v in err[n - q - 1:n - 1])
    before = max(abs(v) for v in err[n - 2 * q - 1:n - q - 1])
    return late > before


# ------------------------------------------------------------------ the loop's response


def test_loop_response_is_the_product_with_the_exact_delay():
    w = np.geomspace(1e-2, 1e2, 30)
    s = 1j * w
    c = pid_tf(1.2, 0.8, 0.1, 10)
    got = dm.loop_response(([3.0], [2.0, 1.0], 0.4), c, w)
    want = 3 / (2 * s + 1) * 1.2 * (1 + 1 / (0.8 * s) + 0.1 * s / (0.01 * s + 1)) * np.exp(-0.4 * s)
    assert np.allclose(got, want, rtol=1e-12)


# ------------------------------------------------------------------ (a) integrator plus delay, closed forms


@pytest.mark.parametrize("k, theta", [(1.0, 0.5), (2.0, 0.1), (0.3, 2.0), (5.0, 0.3)])
def test_integrator_plus_delay_margins_closed_form(k, theta):
    # L = k e^(-theta s)/s: |L| = k/w, arg L = -pi/2 - w theta
    m = dm.loop_margins((*INTEGRATOR, theta), ([k], [1.0]))
    assert m.crossover_hz == pytest.approx(k / (2 * math.pi), rel=1e-10)
    assert m.phase_margin_deg == pytest.approx(90 - math.degrees(k * theta), abs=1e-8)
    assert m.phase_crossover_hz == pytest.approx(math.pi / (2 * theta) / (2 * math.pi), rel=1e-10)
    assert m.gain_margin_db == pytest.approx(20 * math.log10(math.pi / (2 * k * theta)), abs=1e-8)
    assert m.delay_margin_s == pytest.approx(math.pi / (2 * k) - theta, rel=1e-9)
    # every -180 - 360 n crossing: w_n = (pi/2 + 2 pi n)/theta, GM_n = 20 log10(w_n/k)
    wn = (math.pi / 2 + 2 * math.pi * np.arange(len(m.phase_crossovers_hz))) / theta
    assert np.allclose(np.array(m.phase_crossovers_hz) * 2 * math.pi, wn, rtol=1e-10)
    assert np.allclose(m.gain_margins_db, 20 * np.log10(wn / k), atol=1e-8)
    assert m.stable == (k * theta < math.pi / 2)


@pytest.mark.parametrize("k_theta, roots", [(1.5, 0), (1.65, 2), (7.5, 2), (8.0, 4), (14.5, 6)])
def test_integrator_plus_delay_unstable_roots(k_theta, roots):
    # s + k e^(-theta s) gains a right half-plane pair each time k theta passes pi/2 + 2 pi n
    m = dm.loop_margins((*INTEGRATOR, 0.5), ([k_theta / 0.5], [1.0]))
    assert m.rhp_roots == roots
    assert m.stable == (roots == 0)
    # the continuous phase: the margin is negative (never wrapped) once unstable
    assert m.phase_margin_deg == pytest.approx(90 - math.degrees(k_theta), abs=1e-8)


@pytest.mark.parametrize("ratio, stable", [(0.9, True), (1.1, False)])
def test_unstable_plant_delay_limit_closed_form(ratio, stable):
    # P = e^(-theta s)/(s - a) under gain k > a: s - a + k e^(-theta s) is stable while
    # theta < acos(a/k)/sqrt(k^2 - a^2); the delay margin is that limit minus theta
    a, k = 1.0, 3.0
    w0 = math.sqrt(k * k - a * a)
    theta_max = math.acos(a / k) / w0
    theta = ratio * theta_max
    m = dm.loop_margins(([1.0], [1.0, -a], theta), ([k], [1.0]))
    assert m.stable is stable
    assert m.rhp_roots == (0 if stable else 2)
    assert m.crossover_hz == pytest.approx(w0 / (2 * math.pi), rel=1e-10)
    assert m.delay_margin_s == pytest.approx(theta_max - theta, rel=1e-8)


def test_several_gain_crossovers_report_the_smallest_margin():
    # a light resonance above the crossover lifts |L| over 1 again: three crossovers
    wn, zeta, theta = 10.0, 0.02, 0.02
    plant = ([wn ** 2], np.polymul([1.0, 0.0], [1.0, 2 * zeta * wn, wn ** 2]), theta)
    ctrl = ([0.8], [1.0])
    m = dm.loop_margins(plant, ctrl)
    # brute force: |L| = 1 and the phase there, on a very dense grid
    w = np.linspace(0.01, 100, 2_000_001)
    s = 1j * w
    L = 0.8 * wn ** 2 / (s * (s ** 2 + 2 * zeta * wn * s + wn ** 2)) * np.exp(-theta * s)
    up = np.abs(L) >= 1
    idx = np.nonzero(up[:-1] != up[1:])[0]
    assert len(m.crossovers_hz) == idx.size == 3
    assert np.allclose(np.array(m.crossovers_hz) * 2 * math.pi, w[idx], atol=1e-4)
    phase = np.unwrap(np.angle(L))[idx]
    pm = 180 + np.degrees(phase)
    assert np.allclose(m.phase_margins_deg, pm, atol=0.01)
    assert m.phase_margin_deg == pytest.approx(pm.min(), abs=0.01)
    assert m.crossover_hz * 2 * math.pi == pytest.approx(w[idx][np.argmin(pm)], abs=1e-4)


# ------------------------------------------------------------------ (b) the ultimate gain by brute force


def test_fopdt_pi_stability_flips_at_the_brute_force_ultimate_gain():
    k, tau, theta, ti = 1.0, 1.0, 0.5, 0.8
    h, t_end = theta / 40, 150.0
    lo, hi = 0.2, 0.4
    while not fopdt_pi_grows(k, tau, theta, hi, ti, h, t_end):
        lo, hi = hi, 2 * hi
    while hi / lo > 1.001:
        mid = math.sqrt(lo * hi)
        lo, hi = (lo, mid) if fopdt_pi_grows(k, tau, theta, mid, ti, h, t_end) else (mid, hi)
    ku = math.sqrt(lo * hi)
    plant = ([k], [tau, 1.0], theta)
    assert dm.loop_margins(plant, pid_tf(0.995 * ku, ti, 0.0)).stable
    assert not dm.loop_margins(plant, pid_tf(1.005 * ku, ti, 0.0)).stable
    kc = 0.4
    m = dm.loop_margins(plant, pid_tf(kc, ti, 0.0))
    assert kc * 10 ** (m.gain_margin_db / 20) == pytest.approx(ku, rel=5e-3)


# ------------------------------------------------------------------ (c) Ms by brute force


def test_sensitivity_peak_matches_a_dense_grid():
    plant = ([1.5], [2.0, 3.0, 1.0], 0.3)
    cn, cd = pid_tf(1.8, 1.2, 0.3, 10)
    m = dm.loop_margins(plant, (cn, cd))
    w = np.linspace(1e-3, 40, 4_000_001)
    s = 1j * w
    L = 1.5 / (2 * s ** 2 + 3 * s + 1) * np.polyval(cn, s) / np.polyval(cd, s) * np.exp(-0.3 * s)
    sens = 1 / np.abs(1 + L)
    i = int(np.argmax(sens))
    assert m.ms == pytest.approx(sens[i], rel=1e-7)
    assert m.ms >= sens[i] * (1 - 1e-12)
    assert m.ms_hz * 2 * math.pi == pytest.approx(w[i], abs=2e-5)


# ------------------------------------------------------------------ (d) |L| never below 1; JSON


def test_loops_that_never_fall_below_one_are_unstable_with_a_delay():
    # biproper with |L(j inf)| >= 1 (a neutral equation) and improper (the ideal PID):
    # infinitely many roots at or right of the axis; the margins are still read
    plant = ([1.0, 2.0], [1.0, 1.0], 0.5)
    m = dm.loop_margins(plant, pid_tf(1.5, 1.0, 0.0))
    assert m.rhp_roots == math.inf and not m.stable
    m = dm.loop_margins(([1.0], [1.0], 0.1), pid_tf(0.5, 1.0, 0.1))
    assert m.rhp_roots == math.inf and not m.stable
    assert math.isfinite(m.crossover_hz)
    # the ideal PID on a first-order plant is biproper, |L(j inf)| = Kp Td = 0.2: stable
    assert dm.loop_margins(([1.0], [1.0, 1.0], 0.1), pid_tf(2.0, 1.0, 0.1)).stable


def test_margins_are_json_ready():
    d = dm.loop_margins(([1.0], [1.0, 1.0], 0.0), pid_tf(1.0, 1.0, 0.0)).to_dict()
    assert d["gain_margin_db"] is None and d["stable"] is True   # no phase crossover: inf -> None
