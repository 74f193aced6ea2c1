"""Closed-loop ngspice runs: agreement with the analytic loop (ideal and real
op-amps), and saturation and instability detection on circuits built to fail."""

import re

import numpy as np
import pytest

from designer.core import opamps
from designer.pid import blocks, selection, verify
from designer.pid.design import PidSpec, design_pid
from designer.pid.netlist import closed_loop_deck
from designer.pid.plant import sallen_key_circuit
from designer.plant.sallenkey import SallenKeyParts
from designer.spice.deck import SquareTest
from designer.spice.simulate import get_simulator

pytestmark = pytest.mark.spice

SEED_PLANT = SallenKeyParts(820.0, 1e3, 10e-9, 220e-9)   # the seed's rounded parts


def _design(**kw):
    spec = PidSpec(plant_parts=SEED_PLANT, **kw)
    return design_pid(spec, simulate=True, simulator=kw.pop("simulator", "pyspice"))


@pytest.mark.parametrize("backend", ["pyspice", "ngspice-cli"])
def test_ideal_opamps_agree_within_one_point_of_overshoot(backend):
    # Cohen-Coon on the least-squares FOPDT gives a stable loop for this plant (23 % overshoot)
    spec = PidSpec(plant_parts=SEED_PLANT, opamp="ideal", tuning="cohen-coon")
    res = design_pid(spec, simulate=True, simulator=backend)
    a, s = res.analytic, res.spice
    assert s.stable and not s.saturated
    assert abs(s.figures.overshoot_pct - a.figures.overshoot_pct) <= 1.0
    assert s.nrms < 1.0
    assert res.verdict.agree
    # the deck prints its own measurements
    assert {"overshoot_pct", "rise_time_s", "settling_time_s", "u_max", "ve_min"} <= set(s.measurements)


def test_real_opamps_agree_when_all_checks_pass():
    # gains the optimiser finds for an LM741 and a 1 V step: every check passes, SPICE agrees
    res = _design(opamp="LM741", tuning="optimize", target_overshoot_pct=10.0)
    failed = [c.id for c in res.checks if not c.ok]
    assert not failed, failed
    assert abs(res.spice.figures.overshoot_pct - res.analytic.figures.overshoot_pct) <= 1.0
    assert res.spice.nrms < 1.0 and res.spice.stable and not res.spice.saturated


def test_real_opamp_disagreement_is_explained_by_a_failed_check():
    # ZN gains with LM741s: slewing and a thin phase margin; SPICE overshoots more
    res = _design(opamp="LM741", tuning="zn")
    assert not res.verdict.agree
    assert res.verdict.explained_by
    assert not res.verdict.unexplained


def test_seed_final_design_saturates_and_oscillates_with_lm741():
    # the seed's own parts (Kp = 45, Ti = 43.215 us, Td = 10.8037 us) with LM741 models
    res = _design(opamp="LM741", kp=45.0, ti_s=43.215e-6, td_s=10.8037e-6,
                  controller_parts=blocks.seed_parts())
    assert res.spice.saturated
    assert not res.spice.stable
    names = {c.id: c.ok for c in res.checks}
    assert not names["closed_loop_stable"] and not names["phase_margin"]
    assert res.spice.stages["gain"].time_high_s > 0 and res.spice.stages["gain"].time_low_s > 0
    # with ideal op-amps the same parts are stable (the LM741's GBW is what breaks it)
    ok = _design(opamp="ideal", kp=45.0, ti_s=43.215e-6, td_s=10.8037e-6, controller_parts=blocks.seed_parts())
    assert ok.analytic.stable and ok.spice.stable


def test_large_step_saturates_a_stable_loop():
    # a 5 V step: the derivative kick needs far more than the rails; the loop itself is stable
    res = _design(opamp="LM741", kp=0.8228, ti_s=72.55e-6, td_s=15.24e-6, step_v=5.0)
    assert res.analytic.stable
    names = {c.id: c.ok for c in res.checks}
    assert not names["output_swing"] or not names["slew_rate"]
    assert res.spice.saturated or any(v.time_slewing_s > 1e-6 for v in res.spice.stages.values())
    assert res.spice.stable


def test_positive_feedback_latches_at_a_rail():
    # swap the reference and the plant output at the difference amplifier: positive feedback
    amp = opamps.get("LM741")
    parts = selection.select_parts(1.0, 60e-6, 5e-6, SEED_PLANT.fn_hz).parts
    test = SquareTest(1.0, 330.0, 50e-6, 100e-9)
    deck = closed_loop_deck(parts, sallen_key_circuit(SEED_PLANT), amp, test, "positive feedback", 1.0)
    deck = re.sub(r"^R15 ref n2", "R15 y n2", deck, flags=re.M)
    deck = re.sub(r"^R17 y p2", "R17 ref p2", deck, flags=re.M)
    assert "R15 y n2" in deck and "R17 ref p2" in deck
    # the latched loop never crosses the .meas levels: those measurements fail, the run must not
    res = get_simulator("pyspice").run(deck)
    assert "settling_time_s" not in res.measurements
    t = res["time"]
    full = {s: res[s] for s in ("ve", "vp", "vd", "vi", "vs", "u", "y")}
    sat = verify.stages(t, full, amp)
    assert sat["gain"].saturated and sat["plant"].saturated
    tg = np.linspace(0, test.half_period_s, 5001)
    y = np.interp(tg + test.delay_s, t, res["y"])
    osc = verify.oscillation(tg, y, 1.0, 1.0)
    assert not osc.stable
    assert osc.latched or osc.oscillating
    assert abs(osc.tail_mean_v) > 10


def test_oscillation_detector_on_synthetic_waveforms():
    t = np.linspace(0, 1e-3, 10001)
    settled = 1 - np.exp(-t / 50e-6) * np.cos(2 * np.pi * 5e3 * t)
    assert verify.oscillation(t, settled, 1.0, 1.0).stable
    sustained = 1 + 0.3 * np.sin(2 * np.pi * 5e3 * t)
    assert verify.oscillation(t, sustained, 1.0, 1.0).oscillating
    stuck = np.full_like(t, 14.0)
    v = verify.oscillation(t, stuck, 1.0, 1.0)
    assert v.latched and not v.stable


def test_slow_square_wave_still_resolves_the_loop():
    """As for the plant (issue 7.3): the time step follows the loop's time scale, not the
    square wave's period, so a 3 Hz reference gives the figures of the recommended one."""
    from designer.core.errors import DesignError
    fast = design_pid(PidSpec(plant_parts=SEED_PLANT, opamp="ideal", tuning="cohen-coon")).to_dict()
    slow = design_pid(PidSpec(plant_parts=SEED_PLANT, opamp="ideal", tuning="cohen-coon", square_hz=3)).to_dict()
    a, b = fast["closed_loop"]["spice"], slow["closed_loop"]["spice"]
    assert slow["test_signal"]["frequency_hz"] == 3
    assert b["overshoot_pct"] == pytest.approx(a["overshoot_pct"], abs=0.3)
    assert b["peak_time_s"] == pytest.approx(a["peak_time_s"], rel=0.02)
    with pytest.raises(DesignError, match="too slow to simulate"):
        design_pid(PidSpec(plant_parts=SEED_PLANT, opamp="ideal", tuning="cohen-coon", square_hz=1e-3))
