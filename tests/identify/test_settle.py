"""A step response's levels and readings: block means, the final value of a settled tail."""

import numpy as np
import pytest

from designer.core.errors import DesignError
from designer.identify.settle import block_mean, final_value
from designer.identify.structures import model_step

FOPDT = {"K": 2.0, "tau_s": 1e-3, "theta_s": 2e-4}


def test_block_mean_keeps_a_ramp_without_delay():
    t = np.linspace(0, 1, 100_000)
    tb, yb = block_mean(t, 3 * t + 1, 1000)
    assert tb.size <= 1000
    assert np.allclose(yb, 3 * tb + 1, atol=1e-12)


def test_final_value_refuses_a_record_that_has_not_settled():
    t = np.linspace(0, 2e-3, 2001)   # 2 tau after the dead time: still rising
    y = model_step("fopdt", FOPDT, t)
    with pytest.raises(DesignError, match="ends before the response settles"):
        final_value(t, y, 0.0)
    t = np.linspace(0, 10e-3, 2001)
    assert final_value(t, model_step("fopdt", FOPDT, t), 0.0) == pytest.approx(2.0, rel=1e-3)
