import math

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

from designer.core.errors import DesignError
from designer.core.metrics import step_metrics


def second_order(wn, z, t):
    wd = wn * math.sqrt(1 - z * z)
    return 1 - np.exp(-z * wn * t) * (np.cos(wd * t) + z / math.sqrt(1 - z * z) * np.sin(wd * t))


def test_seed_plant_figures():
    # seed 001: Mp 52.66 %, tp 145.8 us, ts 891 us (2 %, MATLAB), tr 55.1 us (10-90 %, MATLAB)
    wn = 2 * math.pi * 3500
    t = np.linspace(0, 2e-3, 40001)
    m = step_metrics(t, second_order(wn, 0.2, t), final=1.0)
    assert m.overshoot_pct == pytest.approx(52.66, abs=0.01)
    assert m.peak_time_s == pytest.approx(145.8e-6, abs=0.1e-6)
    assert m.settling_time_s == pytest.approx(891e-6, abs=1e-6)
    assert m.rise_time_s == pytest.approx(55.1e-6, abs=0.5e-6)


@settings(max_examples=50, deadline=None)
@given(z=st.floats(0.05, 0.95), wn=st.floats(1.0, 1e6))
def test_against_closed_form(z, wn):
    t = np.linspace(0, 12 / (z * wn), 20001)
    m = step_metrics(t, second_order(wn, z, t), final=1.0)
    mp = 100 * math.exp(-math.pi * z / math.sqrt(1 - z * z))
    tp = math.pi / (wn * math.sqrt(1 - z * z))
    tr0 = (math.pi - math.acos(z)) / (wn * math.sqrt(1 - z * z))
    assert m.overshoot_pct == pytest.approx(mp, abs=1e-4 * 100)
    assert m.peak_time_s == pytest.approx(tp, rel=1e-4)
    assert m.rise_time_0_100_s == pytest.approx(tr0, rel=1e-3)


def test_first_order_rise_and_settling():
    tau = 1e-3
    t = np.linspace(0, 20 * tau, 200001)
    m = step_metrics(t, 1 - np.exp(-t / tau), final=1.0)
    assert m.overshoot_pct == 0 and math.isnan(m.peak_time_s)
    assert m.rise_time_s == pytest.approx(tau * math.log(9), rel=1e-5)
    assert m.settling_time_s == pytest.approx(tau * math.log(50), rel=1e-5)
    assert m.settling_time_5pct_s == pytest.approx(tau * math.log(20), rel=1e-5)


def test_step_down_and_offset_and_delay():
    wn, z = 1000.0, 0.3
    t = np.linspace(0, 0.05, 50001)
    y = second_order(wn, z, np.clip(t - 0.01, 0, None))
    up = step_metrics(t, 2 + 3 * y, t_step=0.01, final=5.0)
    down = step_metrics(t, 5 - 3 * y, t_step=0.01, final=2.0)
    ref = step_metrics(t[t >= 0.01] - 0.01, y[t >= 0.01], final=1.0)
    for a in (up, down):
        assert a.overshoot_pct == pytest.approx(ref.overshoot_pct, rel=1e-9)
        assert a.peak_time_s == pytest.approx(ref.peak_time_s, rel=1e-6)
        assert a.settling_time_s == pytest.approx(ref.settling_time_s, rel=1e-6)


def test_bad_waveforms():
    t = np.linspace(0, 1, 10)
    with pytest.raises(DesignError, match="does not change"):
        step_metrics(t, np.ones(10))
    with pytest.raises(DesignError, match="NaN"):
        step_metrics(t, np.r_[np.zeros(9), np.nan])
    with pytest.raises(DesignError, match="increasing"):
        step_metrics(t[::-1], t)
