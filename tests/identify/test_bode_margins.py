"""Loop margins read from a loop-gain Bode table (issue 9): a Digilent WaveForms
export, a plant's table (no margins), a real capture."""

import math

import numpy as np
import pytest

from designer.identify import frequency as fr
from designer.identify import io as tio


def _waveforms_bode(f, loop):
    """A Digilent WaveForms network-analyser export of the complex ``loop``."""
    rows = ["#Digilent WaveForms Network Analyzer - Bode", "#Device Name: Discovery2",
            "#Steps: %d" % f.size, "", "Frequency (Hz),Channel 1 Magnitude (dB),"
            "Channel 2 Magnitude (dB),Channel 2 Phase (deg)"]
    ph = np.rad2deg(np.angle(loop))
    rows += [f"{a!r},{-36.5 + 0.01 * k},{20 * math.log10(abs(g))!r},{p!r}"
             for k, (a, g, p) in enumerate(zip(f.tolist(), loop.tolist(), ph.tolist()))]
    return "\n".join(rows) + "\n"


def test_waveforms_bode_export_and_loop_margins():
    """A loop gain k e^(-s T)/(s (tau s + 1)) from 100 Hz to 50 kHz, written as
    WaveForms writes it (4 columns, phase wrapped to +-180): read, and its
    crossover and margins match the ones solved from the same expression."""
    from scipy.optimize import brentq
    k, tau, T = 2 * math.pi * 3000.0 * 1.2, 1 / (2 * math.pi * 8e3), 5e-6
    f = np.geomspace(100, 50e3, 151)

    def loop(ff):
        s = 2j * math.pi * np.asarray(ff, float)
        return k * np.exp(-s * T) / (s * (tau * s + 1))
    data = tio.parse_freq_table(_waveforms_bode(f, loop(f)), source="bode.csv")
    assert data.fmt == "digilent-bode" and data.phase is not None
    assert "Channel 2 Magnitude (dB)" in data.notes[0]
    r = fr.identify_freq(data)
    fc = brentq(lambda x: abs(loop(x)) - 1.0, 100, 50e3)
    phase = lambda x: -90.0 - math.degrees(math.atan(2 * math.pi * x * tau)) \
        - 360.0 * x * T  # noqa: E731
    fp = brentq(lambda x: phase(x) + 180.0, 100, 50e3)
    lp = r.loop
    assert lp.lf_slope_db_dec == pytest.approx(-20.0, abs=0.5)
    assert lp.crossover_hz == pytest.approx(fc, rel=2e-3)
    assert lp.phase_margin_deg == pytest.approx(180.0 + phase(fc), abs=0.3)
    assert lp.phase_crossover_hz == pytest.approx(fp, rel=2e-3)
    assert lp.gain_margin_db == pytest.approx(-20 * math.log10(abs(loop(fp))), abs=0.1)
    assert r.to_dict()["loop"]["crossover_hz"] == lp.crossover_hz


def test_a_plant_table_has_no_loop_margins():
    f = np.geomspace(10, 1e5, 60)
    g = 1 / (1 + 1j * f / 1e3)
    text = "".join(f"{a},{20 * math.log10(abs(b))},{math.degrees(np.angle(b))}\n"
                   for a, b in zip(f, g))
    assert fr.identify_freq(tio.parse_freq_table(text)).loop is None


def test_real_waveforms_open_loop():
    from helpers import EXT_CAPTURES
    path = EXT_CAPTURES / "cbabe_Lab10_open_loop_bode.csv"
    if not path.exists():
        pytest.skip(f"{path} not found: real captures live beside the project")
    r = fr.identify_freq(tio.read_freq_table(path))
    assert r.data.fmt == "digilent-bode"
    assert r.loop.lf_slope_db_dec == pytest.approx(-20, abs=3)
    assert r.loop.crossover_hz == pytest.approx(3.4e3, rel=0.05)
    assert r.loop.phase_margin_deg == pytest.approx(43, abs=4)

