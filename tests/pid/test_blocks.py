"""Controller sizing: the seed's equations and numbers, the exact parts, the
parts' dict round trip, and the static checks."""

import math

import pytest

from designer.pid import blocks, selection


def test_seed_part_list_gives_the_seed_gains_and_corners():
    p = blocks.seed_parts()
    # Kp = R5 R3/(R6 R4), Ti = R8 R14 C4/R6, Td = R6 R11 C3/R7 (seed V.11)
    assert p.kp == pytest.approx(22e3 * 12e3 / (3.3e3 * 1.777e3))
    assert p.kp == pytest.approx(45, rel=1e-3)
    assert p.ti_s == pytest.approx(43.215e-6, rel=1e-3)
    assert p.td_s == pytest.approx(10.8037e-6, rel=1e-3)
    # corners (seed V.12): 130 Hz and 33 kHz
    assert p.f_integrator_hz == pytest.approx(130, rel=1e-3)
    assert p.f_differentiator_hz == pytest.approx(33e3, rel=1e-3)
    # the seed's summer corner uses A_VD = R5/(R6||R7||R8) with f1 = 1.5 MHz; recomputed from its
    # parts that is 56.53 kHz, the seed prints 56.048 kHz (0.9 % lower, an arithmetic slip)
    ng = p.noise_gains()["summer"]
    assert 1.5e6 / (ng - 1) == pytest.approx(1.5e6 / (22e3 * (1 / 3.3e3 + 1 / 14.356e3 + 1 / 1.2e3)))
    assert 1.5e6 / (ng - 1) == pytest.approx(56.048e3, rel=0.01)


def test_seed_resistor_values_from_its_equations():
    # V.11: R4 from Kp = 45 with R3 = 12k, R5 = 22k, R6 = 3.3k; R14 from Ti; R7 from Td; R13, R12 from corners
    assert 22e3 * 12e3 / (3.3e3 * 45) == pytest.approx(1.777e3, rel=1e-3)
    assert 43.215e-6 * 3.3e3 / (1.2e3 * 47e-9) == pytest.approx(2.528e3, rel=1e-3)
    assert 3.3e3 * 10e3 * 4.7e-9 / 10.8037e-6 == pytest.approx(14.356e3, rel=1e-3)
    assert 1 / (2 * math.pi * 130 * 47e-9) == pytest.approx(26.048e3, rel=1e-3)
    assert 1 / (2 * math.pi * 33e3 * 4.7e-9) == pytest.approx(1.026e3, rel=1e-3)


def test_continuous_parts_are_exact_and_balanced():
    p = blocks.continuous_parts(3.34, 43.2e-6, 10.8e-6, 3500)
    assert (p.kp, p.ti_s, p.td_s) == pytest.approx((3.34, 43.2e-6, 10.8e-6))
    ng = p.noise_gains()
    assert ng["summer"] == pytest.approx(ng["gain"])
    assert p.f_integrator_hz == pytest.approx(35.0)
    assert p.f_differentiator_hz == pytest.approx(35e3)
    pi = blocks.continuous_parts(2.0, 50e-6, 0.0, 3500)
    assert not pi.has_derivative and pi.td_s == 0 and pi.kp == pytest.approx(2.0)


def test_round_trip_dict():
    p = selection.select_parts(3.34, 43.215e-6, 10.8037e-6, 3500).parts
    assert blocks.PidParts.from_dict(p.to_dict()) == p


def test_static_checks_pass_and_fail():
    sel = selection.select_parts(3.34, 43.215e-6, 10.8037e-6, 3500)
    kw = dict(r_min=1e3, r_max=1e6, c_min=1e-9, c_max=10e-6)
    ok = {c.id: c.ok for c in blocks.static_checks(sel.parts, 3500, 1e6, sel.targets, **kw)}
    assert all(ok.values()), ok
    # a derivative filter at the plant's fn and an integrator leak just below it: both corners fail
    bad = selection.select_parts(3.34, 43.215e-6, 10.8037e-6, 3500, f_integrator_hz=2000,
                              f_differentiator_hz=4000)
    res = {c.id: c for c in blocks.static_checks(bad.parts, 3500, 1e6, bad.targets, **kw)}
    assert not res["integrator_corner"].ok and not res["differentiator_corner"].ok
    # a slow op-amp: the stages' bandwidth falls below the derivative corner
    slow = {c.id: c.ok for c in blocks.static_checks(sel.parts, 3500, 50e3, sel.targets, **kw)}
    assert not slow["bandwidth_summer"] and not slow["bandwidth_gain"]
    # the seed's parts with the seed's own f1 = 1.5 MHz: its summer corner 56 kHz (54 kHz with
    # the noise gain) is above its derivative corner 33 kHz, as the seed found
    seed = {c.id: c for c in blocks.static_checks(
        blocks.seed_parts(), 3500, 1.5e6, {"kp": 45, "ti_s": 43.215e-6, "td_s": 10.8037e-6}, **kw)}
    assert seed["bandwidth_summer"].ok and seed["kp_accuracy"].ok
    # ... and R4 = 1.777k etc. are not in E24: the bounds check still passes, they are in range
    assert seed["resistor_bounds"].ok
