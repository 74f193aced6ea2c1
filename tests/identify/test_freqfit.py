"""The complex least-squares fit of a Bode table: exact on a model's own table, with
and without phase."""

import numpy as np
import pytest
from freq_tables import FAST, W, table
from hypothesis import example, given
from hypothesis import strategies as st

from designer.identify import freqfit as fr


@FAST
@given(K=st.floats(0.1, 100.0), tau=st.floats(1e-6, 1e3), dead=st.floats(0.0, 1.0))
@example(K=17.0, tau=1e-6, dead=1e-6)     # a 1 ps dead time: reported as none (found by hypothesis)
def test_least_squares_fopdt_exact(K, tau, dead):
    p = {"K": K, "tau_s": tau, "theta_s": dead * tau}
    d = table("fopdt", p, W / tau)
    r = fr.least_squares_fit(d, "fopdt", [{"K": 1.0, "tau_s": 2 * tau, "theta_s": 0.0}])
    assert r.valid
    for k in ("K", "tau_s"):
        assert r.params[k] == pytest.approx(p[k], rel=1e-6)
    assert r.params["theta_s"] == pytest.approx(p["theta_s"], abs=1e-6 * tau)
    # a dead time near MIN_DEAD_TIME_S may be reported as none: its phase, |e^(-j w theta) - 1|
    # = 2 sin(w theta / 2) per point, is then the error left
    dropped = p["theta_s"] if r.params["theta_s"] == 0.0 else 0.0
    assert r.iae < 1e-6 + np.mean(2 * np.abs(np.sin(W / tau * dropped / 2)))


def test_gain_only_fit():
    p = {"K": 3.0, "tau_s": 2e-3}
    d = table("fopdt", p, W / 2e-3, phase=False)
    r = fr.least_squares_fit(d, "fopdt", [{"K": 1.0, "tau_s": 1e-2, "theta_s": 0.0}])
    assert r.params["tau_s"] == pytest.approx(2e-3, rel=1e-6)
    assert r.params["theta_s"] == 0.0 and "no phase" in r.note

