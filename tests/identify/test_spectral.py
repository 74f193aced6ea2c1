"""Spectral estimates: H = S_yu/S_uu over whole periods and by Welch, the bands
and the table identify-freq reads."""

import numpy as np
import pytest
import scipy.signal as sig

from designer.identify import spectral as spec
from designer.identify.io import parse_freq_table
from designer.core.prbs import mls

TS = 1e-3


def _plant(u):
    b, a, _ = sig.cont2discrete(([1.0], [0.01, 1.0]), TS, method="zoh")
    return sig.lfilter(np.squeeze(b), a, u)


def _discrete(f):
    b, a, _ = sig.cont2discrete(([1.0], [0.01, 1.0]), TS, method="zoh")
    return sig.freqz(np.squeeze(b), a, worN=f, fs=1 / TS)[1]


def test_periodic_response_is_exact_without_noise():
    u = np.repeat(np.tile(mls(8).astype(float), 4), 2)
    y = _plant(u)
    p = 255 * 2
    sp = spec.periodic_response(u, y, start=p, period=p, count=3, ts=TS, f_max=200.0)
    assert sp.f.size > 50 and np.all(sp.coh > 0.999)
    assert np.allclose(sp.h, _discrete(sp.f), rtol=1e-6)


def test_welch_response_of_noise():
    rng = np.random.default_rng(2)
    u = rng.normal(size=200_000)
    y = _plant(u) + 0.05 * rng.normal(size=u.size)
    sp = spec.welch_response(u, y, ts=TS, nperseg=4096, f_max=100.0)
    assert np.all(sp.coh >= spec.MIN_COHERENCE)
    assert np.max(np.abs(sp.h / _discrete(sp.f) - 1)) < 0.1


def test_bands_and_table_round_trip():
    u = np.repeat(np.tile(mls(9).astype(float), 3), 2)
    y = _plant(u)
    p = 511 * 2
    sp = spec.log_bands(spec.periodic_response(u, y, start=p, period=p, count=2, ts=TS, f_max=300.0))
    assert np.all(np.diff(np.log10(sp.f)) > 0.5 / spec.BANDS_PER_DECADE)
    assert np.max(np.abs(sp.h / _discrete(sp.f) - 1)) < 0.02
    data = parse_freq_table(spec.table_text(sp))
    assert data.w.size == sp.f.size
    assert np.allclose(data.gain, np.abs(sp.h), rtol=1e-5)
    fd = spec.to_freq_data(sp)
    assert np.allclose(fd.f_hz, sp.f) and fd.phase[-1] < 0
    assert sp.to_dict()["points"] == sp.f.size


def test_noisy_bands_are_left_out():
    rng = np.random.default_rng(1)
    u = np.repeat(np.tile(mls(9).astype(float), 9), 2)
    y = _plant(u)
    y = y + rng.normal(0, np.std(y) / np.sqrt(10), y.size)      # 10 dB SNR
    p = 511 * 2
    raw = spec.periodic_response(u, y, start=p, period=p, count=8, ts=TS, f_max=500.0)
    banded = spec.log_bands(raw)
    rel = np.sqrt(banded.var) / np.abs(banded.h)
    assert np.all(rel <= spec.MAX_REL_ERROR)
    assert banded.f[-1] < raw.f[-1]
    assert pytest.approx(1.0, rel=0.1) == abs(banded.h[0])
