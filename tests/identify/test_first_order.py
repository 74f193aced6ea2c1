"""First-order and double-pole methods of seed 000 (and the seed 001 tangent example)."""

import math

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

from designer.identify.first_order import (
    FIRST_ORDER_METHODS,
    METHOD_NAMES,
    SUNDARESAN,
    TABLE_II,
    TABLE_III,
    exact_coefficients,
    hagglund,
    nishikawa,
    two_point,
    unit_time,
    ziegler_nichols,
)
from designer.identify.step import identify_step
from designer.identify.structures import model_step

ROWS = list(TABLE_II) + list(TABLE_III) + [SUNDARESAN]
#: Rows whose published coefficients differ from the exact ones by more than
#: their printed rounding (the authors fitted them differently); the tests
#: bound their error by that difference instead. Seed 000 Tables II/III.
AS_PUBLISHED = {"chen-yang": "cd", "ho": "ab", "ho-double-pole": "abcd"}


def _half_ulp(x):
    """Half a unit in the last printed digit of a published coefficient."""
    text = repr(abs(x))
    dec = len(text.split(".")[1]) if "." in text else 0
    return 0.5 * 10.0 ** -dec


@pytest.mark.parametrize("row", ROWS, ids=lambda r: r.name)
def test_published_coefficients_are_the_exact_ones_rounded(row):
    exact = exact_coefficients(row.p1, row.p2, row.model)
    for letter, pub, ex in zip("abcd", (row.a, row.b, row.c, row.d), exact):
        if letter in AS_PUBLISHED.get(row.name, ""):
            assert abs(pub - ex) < 0.03 * abs(ex) + 0.03  # close, but not a rounding
        else:
            assert abs(pub - ex) <= _half_ulp(pub) + 1e-12, (row.name, letter, pub, ex)


@pytest.mark.parametrize("row", ROWS, ids=lambda r: r.name)
def test_two_point_methods_exact_on_their_own_model(row):
    """Noise-free response of the method's own model: error only from the printed coefficients."""
    p = {"K": 1.7, "tau_s": 2e-3, "theta_s": 0.6e-3}
    t = np.linspace(0, 30e-3, 30001)
    y = model_step(row.model, p, t)
    r = two_point(row, t, y, p["K"])
    assert r.valid and r.model == row.model
    t1 = p["theta_s"] + unit_time(row.p1, row.model) * p["tau_s"]
    t2 = p["theta_s"] + unit_time(row.p2, row.model) * p["tau_s"]
    a, b, c, d = exact_coefficients(row.p1, row.p2, row.model)
    grid = 2 * (t[1] - t[0])
    tol_tau = abs(row.a - a) * t1 + abs(row.b - b) * t2 + grid
    tol_theta = abs(row.c - c) * t1 + abs(row.d - d) * t2 + grid
    assert abs(r.params["tau_s"] - p["tau_s"]) <= tol_tau
    assert abs(r.params["theta_s"] - p["theta_s"]) <= tol_theta
    assert r.params["K"] == p["K"]
    assert r.points[next(iter(r.points))] == pytest.approx(t1, abs=grid)


@settings(max_examples=30, deadline=None)
@given(tau=st.floats(1e-5, 1e3), ratio=st.floats(0.05, 3.0), K=st.floats(0.01, 100.0))
def test_exact_methods_recover_any_fopdt(tau, ratio, K):
    """Smith, Vitecková, Alfaro (exact to 3-4 digits), the tangent methods and
    Nishikawa (exact but for 0.368 ~ 1/e) on any FOPDT."""
    p = {"K": K, "tau_s": tau, "theta_s": ratio * tau}
    t = np.linspace(0, p["theta_s"] + 12 * tau, 24001)
    y = model_step("fopdt", p, t)
    for name in ("smith", "viteckova", "alfaro", "ziegler-nichols", "hagglund"):
        r = METHOD_NAMES[name](t, y, K)
        assert r.params["tau_s"] == pytest.approx(tau, rel=3e-3), name
        assert r.params["theta_s"] == pytest.approx(p["theta_s"], abs=3e-3 * tau), name
    r = nishikawa(t, y, K)
    assert r.params["tau_s"] == pytest.approx(tau * math.exp(-1) / 0.368, rel=1e-4)
    t0 = p["theta_s"] + tau
    assert r.points["t0_s"] == pytest.approx(t0, rel=1e-4)


def test_ziegler_nichols_on_a_double_pole_is_the_closed_form():
    """The tangent at theta + tau (tests/core/test_waveform.py) gives L and T."""
    p = {"K": 1.0, "tau_s": 1e-3, "theta_s": 0.5e-3}
    t = np.linspace(0, 15e-3, 15001)
    r = ziegler_nichols(t, model_step("double-pole", p, t), 1.0)
    # L = theta + tau (1 - (e - 2)) and T = e tau, from the line above
    assert r.params["theta_s"] == pytest.approx(0.5e-3 + 1e-3 * (3 - math.e), rel=1e-4)
    assert r.params["tau_s"] == pytest.approx(math.e * 1e-3, rel=1e-4)


def test_seed001_ziegler_nichols_tangent():
    """Seed 001 (lines ~2882-3105): plant 1/(2.0677e-9 s^2 + 1.8189e-5 s + 1).

    Published: inflection at 63.5574 us, y = 0.6975, slope 16627.03 /s, L = 21.6075 us,
    tangent reaches 1 at 81.7506 us so T = 60.143 us (SEEDS.md: not 81.75 us)."""
    a, b = 2.0677e-9, 1.8189e-5
    wn = 1 / math.sqrt(a)
    p = {"K": 1.0, "wn_rad_s": wn, "zeta": b * wn / 2, "theta_s": 0.0}
    t = np.linspace(0, 1.2e-3, 120001)
    r = ziegler_nichols(t, model_step("underdamped", p, t), 1.0)
    assert r.points["t_inflection_s"] == pytest.approx(63.5574e-6, rel=2e-4)
    assert r.points["y_inflection"] == pytest.approx(0.6975, abs=6e-5)
    assert r.points["slope_per_s"] == pytest.approx(16627.03, rel=2e-4)
    assert r.params["theta_s"] == pytest.approx(21.6075e-6, rel=2e-4)
    assert r.points["t3_s"] == pytest.approx(81.7506e-6, rel=2e-4)
    assert r.params["tau_s"] == pytest.approx(60.143e-6, rel=2e-4)
    # An underdamped response is outside the FOPDT validity range: said, not hidden.
    assert not r.valid and "the data overshoot" in r.note


def test_hagglund_uses_the_63_percent_point():
    p = {"K": 1.0, "tau_s": 1e-3, "theta_s": 0.5e-3}
    t = np.linspace(0, 15e-3, 15001)
    y = model_step("double-pole", p, t)
    r = hagglund(t, y, 1.0)
    zn = ziegler_nichols(t, y, 1.0)
    assert r.params["theta_s"] == zn.params["theta_s"]
    assert r.params["theta_s"] + r.params["tau_s"] == pytest.approx(
        0.5e-3 + unit_time(0.632, "double-pole") * 1e-3, rel=1e-4)


def test_methods_flag_data_outside_their_range():
    t = np.linspace(0, 10, 10001)
    y = model_step("fopdt", {"K": 1.0, "tau_s": 1.0, "theta_s": 0.2}, t)
    # a record that stops at 80 %: the 85 % methods cannot work
    short = y[t <= 1.8]
    ts = t[t <= 1.8]
    r = two_point(TABLE_II[3], ts, short, 1.0)
    assert not r.valid and "never reaches" in r.note
    for fn in FIRST_ORDER_METHODS:
        out = fn(t, y, 1.0)
        assert out.valid, out.name
        assert set(out.params) == {"K", "tau_s", "theta_s"}


def test_negative_gain_is_identified_with_its_sign():
    t = np.linspace(-1, 10, 11001)
    y = 3.0 - 2.0 * model_step("fopdt", {"K": 1.0, "tau_s": 1.0, "theta_s": 0.3}, t)
    r = identify_step(t, y, np.where(t >= 0, 1.0, 0.0), refine=False, methods=["smith"])
    assert len(r.methods) == 1
    m = r.methods[0]
    assert m.params["K"] == pytest.approx(-2.0, rel=1e-3)  # tail mean 9 tau after the step
    assert m.params["tau_s"] == pytest.approx(1.0, rel=2e-3)


def test_alfaro_123c_is_exact_on_an_fopdt():
    """0.9102 = 1/ln 3 to four digits and 1.2620 = 1 + ln(4/3)/ln 3: on an FOPDT
    the 123c row is exact where the seed's rounded Alfaro row is 0.02 % off."""
    p = {"K": 3.0, "tau_s": 2e-3, "theta_s": 5e-4}
    t = np.linspace(0, 0.03, 60001)
    r = METHOD_NAMES["alfaro-123c"](t, model_step("fopdt", p, t), 3.0)
    assert r.params["tau_s"] == pytest.approx(2e-3, rel=2e-4)
    assert r.params["theta_s"] == pytest.approx(5e-4, rel=1e-3)
    assert METHOD_NAMES["alfaro-123c"] in FIRST_ORDER_METHODS
