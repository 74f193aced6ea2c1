"""The loop's SPICE engine (designer.tolerance.spice_loop): the nominal build measures what
design-pid's own deck measures, and every sampled build (its parts, its op-amps' gain-bandwidth
and slew rate altered in one loaded circuit) what a standalone deck written with that build's
parts and op-amp measures, run alone by ngspice; both backends agree; the slew rate moves the
figures where the loop slews."""

import dataclasses
import pickle

import numpy as np
import pytest

from designer.pid.blocks import PidParts
from designer.pid.design import design_pid
from designer.pid.netlist import closed_loop_deck
from designer.pid.spec import PidSpec
from designer.pid.plant import sallen_key_circuit
from designer.plant.sallenkey import SallenKeyParts
from designer.spice.simulate import get_simulator
from designer.tolerance import sampling, spice_loop
from designer.tolerance.loop import loop_parts

pytestmark = pytest.mark.spice

BACKENDS = ("ngspice-cli", "pyspice")
TOL = ["GBW=30%", "SR=50%"]


@pytest.fixture(scope="module")
def loop():
    # the optimised LM741 loop sits at its slew budget: the slew rate's spread shows in SPICE
    return design_pid(PidSpec(plant_fc_hz=3500, plant_zeta=0.2, tuning="optimize", target_overshoot_pct=10),
                      simulate=True, simulator="ngspice-cli")


@pytest.fixture(scope="module")
def nominal(loop):
    return loop_parts(loop, TOL)


def test_the_nominal_build_measures_what_the_designs_deck_measures(loop, nominal):
    ctx = spice_loop.context(loop, tuple(nominal), "ngspice-cli")
    f = spice_loop.evaluate(ctx, {k: np.array([v]) for k, v in nominal.items()})
    sp = loop.spice.figures
    assert f["spice_overshoot_pct"][0] == pytest.approx(sp.overshoot_pct, abs=1e-3)
    assert f["spice_rise_time_s"][0] == pytest.approx(sp.rise_time_s, rel=1e-4)
    assert f["spice_settling_time_s"][0] == pytest.approx(sp.settling_time_s, rel=1e-4)
    m = get_simulator("ngspice-cli").run(loop.deck).measurements      # the deck's own .meas lines
    assert f["spice_peak_time_s"][0] == pytest.approx(m["peak_time_s"], rel=2e-5)   # printed to 6 digits
    # the analytic figures ride along, under their own names
    assert f["phase_margin_deg"][0] == pytest.approx(loop.margins.phase_margin_deg, abs=0.05)


def build_deck(loop, values, i):
    """A standalone deck of build ``i``: its parts and its op-amp (the drawn GBW and SR), as
    design-pid would write it, its .meas levels the engine's settled output for it."""
    v = {k: float(a[i]) for k, a in values.items()}
    plant = sallen_key_circuit(SallenKeyParts(v["R1"], v["R2"], v["C1"], v["C2"]))   # the loop's generic record
    parts = PidParts(**{f.name: v.get(f.name.upper()) for f in dataclasses.fields(PidParts)})
    amp = dataclasses.replace(loop.opamp, gbw_hz=v["GBW"], slew_v_per_s=v["SR"])
    return plant, parts, amp


@pytest.fixture(scope="module")
def drawn(loop, nominal):
    tol = {k: 0.05 for k in nominal}
    tol.update(GBW=0.3, SR=0.5)
    values = sampling.values(nominal, tol, 4, 11)
    runs = {b: spice_loop.evaluate(spice_loop.context(loop, tuple(nominal), b), values) for b in BACKENDS}
    return values, runs


def test_every_build_measures_what_its_own_deck_measures(loop, drawn):
    values, runs = drawn
    f = runs["ngspice-cli"]
    final = loop.test.amplitude_v * (1 - f["steady_state_error_pct"] / 100)   # every build is stable
    for i in range(len(final)):
        plant, parts, amp = build_deck(loop, values, i)
        deck = closed_loop_deck(parts, plant, amp, loop.test, f"build {i}", float(final[i]))
        m = get_simulator("ngspice-cli").run(deck).measurements
        assert f["spice_overshoot_pct"][i] == pytest.approx(m["overshoot_pct"], abs=2e-3)
        assert f["spice_peak_time_s"][i] == pytest.approx(m["peak_time_s"], rel=2e-5)   # printed to 6 digits
        assert f["spice_rise_time_s"][i] == pytest.approx(m["rise_time_s"], rel=1e-4)
        assert f["spice_settling_time_s"][i] == pytest.approx(m["settling_time_s"], rel=1e-4)


def test_both_backends_give_the_same_figures(drawn):
    _, runs = drawn
    for k in spice_loop.FIGURES:
        np.testing.assert_allclose(runs["ngspice-cli"][k], runs["pyspice"][k], rtol=1e-9)


def test_the_slew_rate_moves_the_loop_where_it_slews(loop, nominal):
    """The same parts with the slew rate at -50 % and +50 %: a slower op-amp slews longer at the
    edge (U7's kick), the integrator winds further and the loop overshoots more and peaks later
    (the analytic step, linear, stays put; its slew check sees the delay)."""
    ctx = spice_loop.context(loop, tuple(nominal), "ngspice-cli")
    values = {k: np.full(2, v) for k, v in nominal.items()}
    values["SR"] = nominal["SR"] * np.array([0.5, 1.5])
    f = spice_loop.evaluate(ctx, values)
    assert f["spice_overshoot_pct"][0] > f["spice_overshoot_pct"][1] + 0.2
    assert f["spice_peak_time_s"][0] > f["spice_peak_time_s"][1]
    assert f["spice_settling_time_s"][0] > f["spice_settling_time_s"][1]
    assert f["model_overshoot_pct"][0] == f["model_overshoot_pct"][1]
    assert f["slew_delay_s"][0] > 2.5 * f["slew_delay_s"][1]      # 1/SR, and more: the budget is crossed
    assert f["slewing"].tolist() == [1.0, 0.0]


def test_the_context_pickles_and_chunks_give_the_whole(loop, nominal, drawn, monkeypatch):
    values, runs = drawn
    ctx = pickle.loads(pickle.dumps(spice_loop.context(loop, tuple(nominal), "ngspice-cli")))
    monkeypatch.setattr(spice_loop, "BATCH", 3)
    parts = [spice_loop.evaluate(ctx, {k: a[lo:hi] for k, a in values.items()}, start=lo) for lo, hi in ((0, 1), (1, 4))]
    for k in spice_loop.FIGURES:
        np.testing.assert_array_equal(np.concatenate([p[k] for p in parts]), runs["ngspice-cli"][k])


def test_a_part_the_deck_lacks_is_refused(loop):
    from designer.core.errors import DesignError
    with pytest.raises(DesignError, match="no part R99"):
        spice_loop.context(loop, ("R1", "R99"))
