"""Exact frequency tables of the models, and the hypothesis settings, that the tests of
identify-freq share (tests/identify/test_bode_readings.py, test_freqfit.py, test_frequency.py)."""

import numpy as np
from helpers import FIXTURES
from hypothesis import settings

from designer.identify import bode_readings as fr
from designer.identify import io as tio

FIX = FIXTURES / "identify_freq"
FAST = settings(max_examples=15, deadline=None)
W = np.geomspace(1e-2, 1e2, 60)     # two decades each side of the corner (scaled below)


def table(model, params, w, phase=True):
    """Exact FreqData of a model at the angular frequencies w."""
    g = fr.model_response(model, params, w)
    ph = fr.model_phase(model, params, w) if phase else None
    return tio.freq_data(w, np.abs(g), ph, gain_units="ratio", phase_units="rad",
                        freq_units="rad/s")
