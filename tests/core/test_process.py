"""Process models G(s) = N(s)/D(s) e^(-theta s): exact responses against closed
forms computed here, figures, text and JSON, corners (the constructors and
their refusals: test_process_build; typed models: test_process_text)."""

import json
import math

import numpy as np
import pytest

from designer.core.process_build import (
    fopdt,
    integrating,
    model_from_dict,
    rational,
    sopdt,
    underdamped,
)

RTOL = 1e-9


def _close(a, b, scale):
    """Equal within RTOL relative to the response's size (a response is 0 at the dead time)."""
    np.testing.assert_allclose(a, b, rtol=RTOL, atol=RTOL * scale)


# --------------------------------------------------------------------------- responses

def test_fopdt_step_and_freq():
    K, tau, th = 2.0, 1e-3, 2e-4
    m = fopdt(K, tau, th)
    t = np.linspace(-1e-3, 10e-3, 4001)
    s = t - th
    _close(m.step(t), np.where(s >= 0, K * (1 - np.exp(-np.clip(s, 0, None) / tau)), 0.0), K)
    w = np.logspace(0, 7, 200)
    _close(m.freq(w), K * np.exp(-1j * w * th) / (1j * w * tau + 1), K)
    assert np.all(m.step(t[t < th]) == 0)


def test_sopdt_step_is_the_two_exponential_formula():
    K, t1, t2, th = 0.9, 2e-3, 5e-4, 3e-4
    m = sopdt(K, t1, t2, th)
    t = np.linspace(0, 20e-3, 4001)
    s = np.clip(t - th, 0, None)
    y = K * (1 - (t1 * np.exp(-s / t1) - t2 * np.exp(-s / t2)) / (t1 - t2))
    _close(m.step(t), np.where(t >= th, y, 0.0), K)
    w = np.logspace(0, 7, 200)
    _close(m.freq(w), K * np.exp(-1j * w * th) / ((1j * w * t1 + 1) * (1j * w * t2 + 1)), K)


def test_sopdt_sorts_and_a_double_pole_is_exact():
    assert sopdt(1, 5e-4, 2e-3) == sopdt(1, 2e-3, 5e-4)
    assert sopdt(1, 5e-4, 2e-3).params["tau1_s"] == 2e-3
    tau = 1e-3
    m = sopdt(1.0, tau, tau)
    t = np.linspace(0, 10e-3, 2001)
    _close(m.step(t), 1 - (1 + t / tau) * np.exp(-t / tau), 1.0)


def test_underdamped_step_and_freq():
    K, fn, z, th = 1.5, 500.0, 0.3, 1e-4
    m = underdamped(K, fn, z, th)
    wn = 2 * math.pi * fn
    wd = wn * math.sqrt(1 - z * z)
    t = np.linspace(0, 15e-3, 6001)
    s = np.clip(t - th, 0, None)
    y = K * (1 - np.exp(-z * wn * s) * np.sin(wd * s + math.acos(z)) / math.sqrt(1 - z * z))
    _close(m.step(t), np.where(t >= th, y, 0.0), K)
    w = np.logspace(1, 6, 200)
    _close(m.freq(w), K * wn ** 2 * np.exp(-1j * w * th) / ((1j * w) ** 2 + 2 * z * wn * 1j * w + wn ** 2), K)


def test_integrating_step_and_freq():
    K, tau, th = 50.0, 10e-3, 1e-3
    m = integrating(K, tau, th)
    t = np.linspace(0, 0.1, 2001)
    s = np.clip(t - th, 0, None)
    _close(m.step(t), K * (s - tau * (1 - np.exp(-s / tau))), K * t[-1])
    w = np.logspace(-1, 5, 100)
    _close(m.freq(w), K * np.exp(-1j * w * th) / (1j * w * (1j * w * tau + 1)), K / w[0])
    pure = integrating(K, theta_s=th)
    _close(pure.step(t), K * s, K * t[-1])
    _close(pure.freq(w), K * np.exp(-1j * w * th) / (1j * w), K / w[0])
    assert np.isinf(pure.freq([0.0])[0])
    assert m.integrating and m.gain == K and pure.den == (1.0, 0.0)


def test_rational_against_scipy_shifted_by_the_delay():
    from scipy import signal
    num, den, th = [2e-3, 1.0], [1e-7, 5e-4, 1.0], 1e-4
    m = rational(num, den, th)
    T = np.linspace(0, 10e-3, 2001)
    _, y = signal.step((np.array(num), np.array(den)), T=T)
    _close(m.step(T + th), y, np.max(np.abs(y)))
    assert np.all(m.step(np.linspace(0, th, 50, endpoint=False)) == 0)
    w = np.logspace(1, 6, 100)
    _, h = signal.freqresp((num, den), w)
    _close(m.freq(w), h * np.exp(-1j * w * th), np.max(np.abs(h)))


# --------------------------------------------------------------------------- figures

def test_time_constants_and_settling():
    m = fopdt(2, 1e-3, 2e-4)
    assert m.time_constants_s == (1e-3,) and m.time_scale_s == 1e-3
    assert m.settling_time_s == pytest.approx(2e-4 + 1e-3 * math.log(50), rel=1e-6)
    s = sopdt(1, 5e-4, 2e-3, 1e-4)
    assert s.time_constants_s == pytest.approx((2e-3, 5e-4), rel=1e-12)
    u = underdamped(1, 500, 0.3)
    assert u.time_constants_s == pytest.approx((1 / (2 * math.pi * 500),) * 2, rel=1e-9)
    # the underdamped settling time: last exit from the 2 % band of the closed form, dense grid
    wn, z = 2 * math.pi * 500, 0.3
    t = np.linspace(0, 20e-3, 2_000_001)
    y = 1 - np.exp(-z * wn * t) * np.sin(wn * math.sqrt(1 - z * z) * t + math.acos(z)) / math.sqrt(1 - z * z)
    ts = t[np.nonzero(np.abs(y - 1) > 0.02)[0][-1]]
    assert u.settling_time_s == pytest.approx(ts, rel=1e-4)
    i = integrating(50, 10e-3, 1e-3)
    assert i.settling_time_s == pytest.approx(1e-3 + 10e-3 * math.log(50), rel=1e-6)
    assert i.time_constants_s == (10e-3,)
    assert integrating(50, theta_s=1e-3).time_scale_s == 1e-3
    assert integrating(50).time_scale_s == pytest.approx(1 / 50)
    assert integrating(50).settling_time_s == 0.0


def test_text_per_kind():
    assert fopdt(2, 1e-3, 2e-4).text() == "G(s) = 2 e^(-200 us s) / (1 ms s + 1)"
    assert fopdt(2, 1e-3).text() == "G(s) = 2 / (1 ms s + 1)"
    assert sopdt(1, 5e-4, 2e-3, 3e-4).text() == "G(s) = 1 e^(-300 us s) / ((2 ms s + 1)(500 us s + 1))"
    assert underdamped(1, 500, 0.3).text() == ("G(s) = 1 wn^2 / (s^2 + 2 zeta wn s + wn^2), fn = 500 Hz, "
                                               "zeta = 0.3")
    assert integrating(50, 10e-3).text() == "G(s) = 50 / (s (10 ms s + 1))"
    assert integrating(50, theta_s=1e-3).text() == "G(s) = 50 e^(-1 ms s) / s"
    assert rational([2e-3, 1], [1e-6, 2e-3, 1], 1e-5).text() == \
        "G(s) = (0.002 s + 1) e^(-10 us s) / (1e-06 s^2 + 0.002 s + 1)"


@pytest.mark.parametrize("model", [fopdt(2, 1e-3, 2e-4, ci95={"K": 0.1}), sopdt(1, 5e-4, 2e-3, 3e-4),
                                   underdamped(-1, 500, 0.3), integrating(50, 10e-3, 1e-3),
                                   rational([2e-3, 1], [1e-6, 2e-3, 1], 1e-5, source="here")])
def test_to_dict_is_json_and_rebuilds_the_model(model):
    d = json.loads(json.dumps(model.to_dict(), allow_nan=False))
    assert d["kind"] == model.kind and d["text"] == model.text()
    assert model_from_dict(d) == model


def test_corners_span_the_ci95_box_and_stay_physical():
    m = fopdt(2, 1e-3, 1e-5, ci95={"K": 0.1, "tau_s": 2e-3, "theta_s": 5e-5})
    cs = m.corners()
    assert len(cs) == 8 and all(c.ci95 is None and "corner" in c.source for c in cs)
    assert {c.params["K"] for c in cs} == {2.1, 1.9}
    assert min(c.params["tau_s"] for c in cs) == pytest.approx(1e-6)     # clipped: never <= 0
    assert min(c.params["theta_s"] for c in cs) == 0.0
    assert max(c.params["theta_s"] for c in cs) == pytest.approx(6e-5)
    u = underdamped(1, 500, 0.95, ci95={"zeta": 0.2})
    assert sorted(c.params["zeta"] for c in u.corners()) == pytest.approx([0.75, 0.999])
    assert fopdt(2, 1e-3).corners() == []
