"""The base: polynomials, the quadratic root of the syntheses, the single-pole
op-amp and the nodal analysis, checked against closed forms."""

import dataclasses
import math

import numpy as np
import pytest

from designer.core.opamps import get as get_opamp
from designer.filters.topology import nodal_response, open_loop_gain, polynomial, polyval, quadratic_root
from designer.spice.deck import GROUND, Amp, Netlist, Part


def test_polyval_broadcasts_batch_against_s():
    poly = polynomial(np.array([[1.0], [2.0]]), 3.0, 4.0)
    s = np.array([0.5j, 2.0])
    out = polyval(poly, s)
    assert out.shape == (2, 2)
    assert out[1, 1] == pytest.approx(2 * 4 + 3 * 2 + 4)
    assert polyval(polynomial(1.0, 0.0), 3.0) == 3.0


@pytest.mark.parametrize("a, b, c", [(1.0, 5.0, 4.0), (-2.0, 1.0, 3.0), (3.0, 2.0, -5.0), (1e-30, 2.0, 1.0)])
def test_quadratic_root_is_a_positive_root(a, b, c):
    x = quadratic_root(a, b, c)
    assert x > 0 and a * x * x - b * x + c == pytest.approx(0, abs=1e-12 * max(b * x, abs(c)))


def test_quadratic_root_at_a_double_root_and_none_below():
    assert quadratic_root(1.0, 2.0, 1.0 + 1e-15) == pytest.approx(1.0, rel=1e-6)
    assert math.isnan(quadratic_root(1.0, 2.0, 1.1))


def test_open_loop_gain_is_a0_at_dc_and_gbw_at_unity():
    amp = get_opamp("LM741")
    assert open_loop_gain(amp, 0) == amp.a0
    assert abs(open_loop_gain(amp, 2j * math.pi * amp.gbw_hz)) == pytest.approx(1.0, rel=1e-6)


def test_nodal_response_of_a_non_inverting_amplifier_is_the_finite_gain_closed_form():
    """K = 1 + R2/R1 with gain A: A / (1 + A/K)."""
    net = Netlist((Part("R1", "n", GROUND, 1e3), Part("R2", "vout", "n", 9e3)), (Amp("U1", "amp", "vin", "n", "vout"),))
    amp = dataclasses.replace(get_opamp("LM741"), a0=1e4, gbw_hz=1e6)
    s = 2j * math.pi * np.array([10.0, 1e4, 1e5])
    a = open_loop_gain(amp, s)
    np.testing.assert_allclose(nodal_response(net, {"R1": 1e3, "R2": 9e3}, s, amp), a / (1 + a / 10), rtol=1e-12)


def test_nodal_response_of_an_inverting_integrator_with_the_input_on_the_inverting_side():
    net = Netlist((Part("R1", "vin", "n", 1e3), Part("C1", "n", "vout", 1e-6)),
                  (Amp("U1", "amp", GROUND, "n", "vout"),))
    amp = get_opamp("TL072")
    s = 2j * math.pi * np.array([1.0, 100.0])
    a = open_loop_gain(amp, s)
    ideal = -1 / (s * 1e3 * 1e-6)
    # nodal: (Vi - Vn)/R = (Vn - Vo) s C, Vo = -A Vn
    expect = ideal * a / (a + 1 - ideal)
    np.testing.assert_allclose(nodal_response(net, {"R1": 1e3, "C1": 1e-6}, s, amp), expect, rtol=1e-12)
