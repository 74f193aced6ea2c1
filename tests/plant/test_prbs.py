"""The plant under the PRBS the bench plays (designer.plant.prbs): the sequence
chosen for the designed plant, the model's response against a first order's
closed form, ngspice against the model on both backends, and the size bounds."""

import math

import numpy as np
import pytest

from designer.core.errors import DesignError
from designer.core.prbs import BAND_FACTOR, HALF_POWER, LINES_IN_BAND, SETTLE_MARGIN, PrbsPlan, mls
from designer.plant import prbs
from designer.plant.design import design_plant
from designer.plant.spec import PlantSpec


@pytest.fixture(scope="module")
def seed():
    return design_plant(PlantSpec(3500, 0.2), simulate=False)


def test_plan_for_the_seed_plant_covers_its_band_and_settling(seed):
    plan = prbs.plan_for_result(seed, 2.0)
    band = seed.sine.f_3db_hz
    # the half-power band covers 3x the bandwidth; one period outlasts 1.2x the settling and holds 10 lines
    assert HALF_POWER / plan.dt_s >= BAND_FACTOR * band
    assert plan.period_s >= SETTLE_MARGIN * seed.analytic_opamp.step.settling_time_s
    assert plan.period_s >= LINES_IN_BAND / band
    # the fewest bits that do: one bit fewer would not
    shorter = ((1 << (plan.bits - 1)) - 1) * plan.dt_s
    assert shorter < max(SETTLE_MARGIN * seed.analytic_opamp.step.settling_time_s, LINES_IN_BAND / band)
    # the bench's range, 0 V to the square wave's amplitude, every period after the first identified
    assert (plan.offset - plan.amplitude, plan.offset + plan.amplitude) == (0.0, 2.0)
    assert plan.periods == prbs.PERIODS >= 3


def test_given_bits_and_clock_are_kept(seed):
    plan = prbs.plan_for_result(seed, 1.0, bits=9, clock_hz=25e3)
    assert plan.bits == 9 and plan.dt_s == pytest.approx(40e-6)


def test_model_response_is_the_first_orders_closed_form():
    """1/(tau s + 1) under the held sequence, from the steady state of its first
    level: y relaxes towards each level with e^(-t/tau) from each clock edge."""
    tau = 3e-4
    plan = PrbsPlan(bits=5, dt_s=1e-4, amplitude=0.7, offset=0.2, periods=2)
    t, u, y = prbs.model_response([1.0], [tau, 1.0], plan, per_interval=8)
    levels = plan.values()
    want = np.empty_like(t)
    y0 = levels[0]
    for k, level in enumerate(levels):            # brute force: interval by interval
        sel = (t >= k * plan.dt_s) & (t < (k + 1) * plan.dt_s)
        want[sel] = level + (y0 - level) * np.exp(-(t[sel] - k * plan.dt_s) / tau)
        y0 = level + (y0 - level) * math.exp(-plan.dt_s / tau)
    assert np.allclose(u, np.repeat(levels, 8))
    assert np.allclose(y, want, atol=1e-12)
    assert np.allclose(t, (np.arange(t.size) + 0.5) * plan.dt_s / 8)


@pytest.mark.spice
@pytest.mark.parametrize("simulator", ["pyspice", "ngspice-cli"])
def test_spice_follows_the_model_under_the_sequence(seed, simulator):
    plan = prbs.plan_for_result(seed, 2.0)
    run = prbs.prbs_run(seed, plan, True, simulator)
    c = run.capture
    assert np.allclose(c.input_v, np.repeat(plan.values(), prbs.SAMPLES_PER_INTERVAL))
    assert run.nrms < 1e-3
    assert np.max(np.abs(c.output_v - c.analytic_opamp_v)) < 1e-3 * np.ptp(c.analytic_opamp_v)
    assert all(ch.ok for ch in run.checks)
    assert "Xgen input prbs_source" in run.deck


def test_with_prbs_adds_its_checks_and_json(seed):
    import copy
    r = prbs.with_prbs(copy.copy(seed), 2.0, simulate=False)
    assert {"prbs_output_swing", "prbs_slew_rate"} <= {c.id for c in r.checks}
    d = r.to_dict()
    assert d["prbs"]["bits"] == r.prbs.plan.bits and d["prbs"]["simulator"] is None
    assert list(d)[-1] == "files"
    # a step design's JSON has no prbs key: the references stay as they are
    assert "prbs" not in seed.to_dict()


def test_output_swing_fails_beyond_the_rails(seed):
    from designer.core import opamps
    amp = opamps.get("LM741")
    t = np.arange(100) * 1e-6
    swing, slew = prbs.op_amp_checks(t, np.linspace(0.0, amp.vout_max * 1.1, 100), amp)
    assert not swing.ok and slew.ok


def test_too_long_a_run_is_refused(seed):
    with pytest.raises(DesignError, match="clock intervals"):
        prbs.plan_for_result(seed, 2.0, bits=16)
    with pytest.raises(DesignError, match="time steps"):
        prbs.plan_for_result(seed, 2.0, bits=12, clock_hz=10.0)
    assert mls(16).size * prbs.PERIODS > prbs.MAX_INTERVALS
