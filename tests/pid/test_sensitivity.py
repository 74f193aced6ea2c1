"""designer.pid.sensitivity: the sensitivity peak Ms = max 1/|1 + L(jw)| against a
brute-force 2,000,001-point log grid of the same loop (1e-6 relative), on closed
forms of rational loops and, by hypothesis, on random ones; the Sallen-Key
plant's loop as design-pid builds it (op-amp poles in the controller and the
plant) carries its Ms, the brute force's on that loop, and keeps it out of its
JSON (the model plant's: tests/pid/test_delaymargins.py)."""

import math

import numpy as np
import pytest
from hypothesis import example, given, settings
from hypothesis import strategies as st

from designer.filters.sallen_key_lowpass_parts import record_of
from designer.pid import model as M
from designer.pid.design import design_pid
from designer.plant.model import plant_tf_opamp
from designer.pid.sensitivity import sensitivity_peak
from designer.pid.spec import PidSpec

#: the brute-force grid's size (the task's: 2,000,001 points)
BRUTE_POINTS = 2_000_001


def brute_force(loop, w_lo: float, w_hi: float, n: int = BRUTE_POINTS):
    """(max 1/|1 + L|, w there) on an n-point log grid, in chunks (a few MB at a time)."""
    w = np.geomspace(w_lo, w_hi, n)
    best, at = -1.0, math.nan
    for k in range(0, n, 200_000):
        part = w[k:k + 200_000]
        s = 1 / np.abs(1 + loop(part))
        i = int(np.argmax(s))
        if s[i] > best:
            best, at = float(s[i]), float(part[i])
    return best, at


def rational(num, den):
    return lambda w: np.polyval(num, 1j * np.asarray(w)) / np.polyval(den, 1j * np.asarray(w))


def agrees(loop, w_lo, w_hi, points=400):
    """The function's Ms on a coarse caller's grid against the brute force: 1e-6 relative, never below it
    (the refinement only climbs); a peak that stands out (above 1.01) inside the band at the brute force's
    frequency within two of its grid steps (where 1/|1 + L| tends to 1 at high frequency, rounding decides
    which point of the flat tail is largest: no frequency to compare)."""
    w = np.geomspace(w_lo, w_hi, points)
    ms, w_ms = sensitivity_peak(w, loop(w), loop)
    b, w_b = brute_force(loop, w_lo, w_hi)
    step = math.log(w_hi / w_lo) / (BRUTE_POINTS - 1)
    # the grid's own step misses a sharp peak's top by more than 1e-6 (k 0.5, tau 1/128, zeta 0.5, wn 0.5: Ms 363,
    # the grid 1.2e-6 below the refined value): its maximum brute-forced again over its two neighbouring steps
    wf = w_b * np.exp(np.linspace(-step, step, 100_001))
    top = max(b, float(np.max(1 / np.abs(1 + loop(wf)))))
    assert abs(ms - top) <= 1e-6 * top and ms >= b * (1 - 1e-12), (ms, b, top)
    # and the peak is a value of the function, at its frequency
    assert ms == pytest.approx(float(1 / abs(1 + loop(np.array([w_ms])))[0]), rel=1e-12)
    if b > 1.01 and w_lo < w_b < w_hi * (1 - step):
        assert abs(math.log(w_ms / w_b)) <= 2 * step, (w_ms, w_b)
    return ms, w_ms


def test_a_lightly_damped_loop_peaks_where_the_brute_force_grid_says():
    # L = k/(s (s + 1) (0.1 s + 1)): a gain near its limit, a sharp peak the 400-point grid straddles
    loop = rational([4.0], np.polymul([1.0, 1.0, 0.0], [0.1, 1.0]))
    ms, _ = agrees(loop, 1e-2, 1e3)
    # the grid alone falls short of the peak: the refinement is what meets 1e-6
    w = np.geomspace(1e-2, 1e3, 400)
    assert sensitivity_peak(w, loop(w))[0] < ms * (1 - 1e-6)


def test_without_the_loop_the_grids_own_peak_is_returned():
    loop = rational([2.0], [1.0, 1.0, 0.0])
    w = np.geomspace(1e-2, 1e2, 300)
    s = 1 / np.abs(1 + loop(w))
    assert sensitivity_peak(w, loop(w)) == (float(s.max()), float(w[int(np.argmax(s))]))


def test_a_peak_at_the_bands_edge_is_not_refined_outside_it():
    # L = 0.5/(s + 1): 1/|1 + L| rises toward high frequency, its largest value at the band's top
    loop = rational([0.5], [1.0, 1.0])
    w = np.geomspace(1e-2, 1e2, 100)
    ms, w_ms = sensitivity_peak(w, loop(w), loop)
    assert w_ms == w[-1] and ms == pytest.approx(float(1 / abs(1 + loop(w[-1:]))[0]), rel=1e-15)


@settings(max_examples=15, deadline=None)
@given(k=st.floats(0.2, 20.0), tau=st.floats(1e-3, 1.0), zeta=st.floats(0.05, 1.0), wn=st.floats(0.5, 50.0))
# a peak sharper than the brute force's grid resolves (found by hypothesis in a clean-clone run)
@example(k=0.5, tau=0.0078125, zeta=0.5, wn=0.5)
def test_random_rational_loops_agree_with_the_brute_force(k, tau, zeta, wn):
    # L = k wn^2 / (s (tau s + 1)(s^2 + 2 zeta wn s + wn^2)): an integrator, a pole and a resonance
    den = np.polymul(np.polymul([1.0, 0.0], [tau, 1.0]), [1.0, 2 * zeta * wn, wn * wn])
    agrees(rational([k * wn * wn], den), 1e-3, 1e4)


@pytest.mark.parametrize("kw", [{}, {"tuning": "optimize", "target_overshoot_pct": 10}],
                         ids=["zn", "page-default-optimize"])
def test_the_sallen_key_loops_margins_carry_its_ms(kw):
    """Issue 29: design-pid --plant-fc 3500 --plant-zeta 0.2 --opamp LM741 (the seed's Ziegler-Nichols loop) and
    the PID page's opening design (optimize, 10 % overshoot): Ms and its frequency are the brute force's on the
    loop as built, C(s) with every op-amp's pole times the plant with its op-amp, over the band of the loop-gain
    plot; the result's JSON keeps its keys (reports/ stay byte for byte)."""
    res = design_pid(PidSpec(plant_fc_hz=3500, plant_zeta=0.2, opamp="LM741", **kw), simulate=False)
    st = res.plant.stages[0]   # the generic record; the closed forms take its parts record
    pn, pd = plant_tf_opamp(record_of(st.topology, st.values), res.opamp)   # (LM741: not the ideal op-amp)
    loop = lambda w: M.loop_gain(res.parts, res.opamp, pn, pd, w)  # noqa: E731
    bode_w = np.asarray(res.waveforms.bode_w)
    # the loop brute-forced here is the loop plotted and whose margins are reported
    np.testing.assert_allclose(loop(bode_w), res.waveforms.loop_gain, rtol=1e-12)
    b, w_b = brute_force(loop, bode_w[0], bode_w[-1])
    mg = res.margins
    assert abs(mg.ms - b) <= 1e-6 * b and mg.ms >= b * (1 - 1e-12), (mg.ms, b)
    assert abs(math.log(mg.ms_hz * 2 * math.pi / w_b)) <= 2 * math.log(bode_w[-1] / bode_w[0]) / (BRUTE_POINTS - 1)
    assert bode_w[0] < w_b < bode_w[-1] and b > 1
    assert "ms" not in mg.to_dict() and "ms_hz" not in mg.to_dict()
