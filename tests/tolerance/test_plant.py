"""The vectorised plant engine against the scalar models, sample by sample."""

import numpy as np
import pytest

from designer.core import opamps
from designer.core.lti import dominant_pair, step_response
from designer.plant.model import plant_tf, plant_tf_opamp
from designer.plant.sallenkey import SallenKeyParts
from designer.tolerance import sampling
from designer.tolerance.plant import plant_figures

SEED_PLANT = {"R1": 1.6e3, "R2": 3.9e3, "C1": 3.3e-9, "C2": 100e-9}


@pytest.mark.parametrize("opamp", ["LM741", "TL072", "ideal"])
def test_every_sample_equals_the_scalar_model(opamp):
    amp = opamps.get(opamp)
    v = sampling.values(SEED_PLANT, {"R1": 0.05, "R2": 0.05, "C1": 0.1, "C2": 0.1}, 12, seed=4)
    f = plant_figures(v, amp)
    for i in range(12):
        parts = SallenKeyParts(v["R1"][i], v["R2"][i], v["C1"][i], v["C2"][i])
        num, den = plant_tf(parts) if amp.ideal else plant_tf_opamp(parts, amp)
        fn, zeta = dominant_pair(den)
        assert f["fn_hz"][i] == pytest.approx(fn, rel=1e-9) and f["zeta"][i] == pytest.approx(zeta, rel=1e-9)
        assert f["ideal_fn_hz"][i] == pytest.approx(parts.fn_hz, rel=1e-12)
        # the step's first peak, brute force on a fine grid about it
        tp = f["peak_time_s"][i]
        t = np.linspace(0.5 * tp, 1.5 * tp, 20001)
        y = step_response(num, den, t)
        g0 = num[-1] / den[-1]
        assert f["overshoot_pct"][i] == pytest.approx(100 * (y.max() / g0 - 1), abs=1e-6)
        assert tp == pytest.approx(t[np.argmax(y)], rel=1e-4)
        assert f["gain"][i] == pytest.approx(g0, rel=1e-12)


def test_an_overdamped_plant_has_no_overshoot():
    v = {k: np.array([x]) for k, x in {"R1": 10e3, "R2": 10e3, "C1": 100e-9, "C2": 10e-9}.items()}
    f = plant_figures(v, opamps.get("LM741"))
    assert f["zeta"][0] > 1 and f["overshoot_pct"][0] == 0 and np.isnan(f["peak_time_s"][0])


def test_gain_above_one():
    v = {k: np.array([x]) for k, x in {"R1": 10e3, "R2": 10e3, "C1": 10e-9, "C2": 10e-9, "R3": 10e3,
                                       "R4": 5e3}.items()}
    f = plant_figures(v, opamps.get("ideal"))
    parts = SallenKeyParts(10e3, 10e3, 10e-9, 10e-9, 1.5, 10e3, 5e3)
    assert f["gain"][0] == pytest.approx(1.5) and f["ideal_zeta"][0] == pytest.approx(parts.zeta)
