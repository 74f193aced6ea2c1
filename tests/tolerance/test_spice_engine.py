"""The SPICE engine of the plant Monte Carlo against the analytic model, sample by sample.

Tolerances (FACTS.md, "Monte Carlo of the plant deck": the rising half with ten times
the deck's maximum step is within 0.007 pp of overshoot and 0.015 % of peak time of
the full deck): overshoot 0.02 pp, peak time 0.05 %; zeta (a function of the
overshoot alone) 0.1 %; fn from the step against the model's step read the same way
0.05 %, and against the model's dominant pair 0.3 % (the op-amp's third pole, near
its 1 MHz GBW, delays the peak by about 1/(2 pi GBW) = 0.16 us of 145 us: 0.11 %).
"""

import math
import pickle

import numpy as np
import pytest

from designer.core import opamps
from designer.core.errors import SimulatorError
from designer.core.metrics import step_metrics
from designer.plant.design import design_plant
from designer.plant.spec import PlantSpec
from designer.tolerance import sampling, spice_engine
from designer.tolerance.montecarlo import plant_parts
from designer.tolerance.plant import plant_figures

pytestmark = pytest.mark.spice

BACKENDS = ("ngspice-cli", "pyspice")


@pytest.fixture(scope="module")
def seed_plant():
    return design_plant(PlantSpec(fc_hz=3500, zeta=0.2), simulate=False)


def draw(result, n, seed=1, gbw=None):
    nominal = plant_parts(result.built)
    tol = {r: (0.05 if r[0] == "R" else 0.10) for r in nominal}
    if gbw:
        nominal["GBW"], tol["GBW"] = result.opamp.gbw_hz, gbw
    return sampling.values(nominal, tol, n, seed)


def step_equivalent(over_pct, tp):
    """fn of a second-order step with this overshoot and peak time (the engine's reading)."""
    ln = np.log(over_pct / 100)
    z = -ln / np.sqrt(math.pi ** 2 + ln ** 2)
    return math.pi / (tp * np.sqrt(1 - z * z)) / (2 * math.pi)


def assert_agrees(spice, model):
    assert np.all(np.abs(spice["overshoot_pct"] - model["overshoot_pct"]) < 0.02)
    np.testing.assert_allclose(spice["peak_time_s"], model["peak_time_s"], rtol=5e-4)
    np.testing.assert_allclose(spice["zeta"], model["zeta"], rtol=1e-3)
    np.testing.assert_allclose(spice["q"], model["q"], rtol=1e-3)
    np.testing.assert_allclose(spice["fn_hz"], step_equivalent(model["overshoot_pct"], model["peak_time_s"]),
                               rtol=5e-4)
    np.testing.assert_allclose(spice["fn_hz"], model["fn_hz"], rtol=3e-3)


@pytest.fixture(scope="module")
def seed_runs(seed_plant):
    v = draw(seed_plant, 40)
    runs = {b: spice_engine.evaluate(spice_engine.context(seed_plant.deck, seed_plant.built, seed_plant.opamp,
                                                          seed_plant.test, b), v) for b in BACKENDS}
    return v, runs


@pytest.mark.parametrize("backend", BACKENDS)
def test_every_sample_agrees_with_the_model(seed_plant, seed_runs, backend):
    v, runs = seed_runs
    assert_agrees(runs[backend], plant_figures(v, seed_plant.opamp))


def test_both_backends_give_the_same_figures(seed_runs):
    _, runs = seed_runs
    for k in spice_engine.FIGURES:
        np.testing.assert_allclose(runs["ngspice-cli"][k], runs["pyspice"][k], rtol=1e-9)


def test_rise_and_settling_time_against_the_models_step(seed_plant, seed_runs):
    """The SPICE-only figures against the third-order model's step sampled every nanosecond."""
    from scipy import signal

    from designer.plant.model import plant_tf_opamp
    from designer.plant.sallenkey import SallenKeyParts
    v, runs = seed_runs
    amp = seed_plant.opamp
    for i in range(3):
        num, den = plant_tf_opamp(SallenKeyParts(v["R1"][i], v["R2"][i], v["C1"][i], v["C2"][i]), amp)
        t = np.arange(0.0, seed_plant.test.half_period_s, 1e-9)
        _, y = signal.step((num, den), T=t)
        m = step_metrics(t, y, final=float(num[-1] / den[-1]))
        assert runs["ngspice-cli"]["rise_time_s"][i] == pytest.approx(m.rise_time_s, rel=2e-3)
        assert runs["ngspice-cli"]["settling_time_s"][i] == pytest.approx(m.settling_time_s, rel=5e-3)


def test_the_gain_resistors_and_the_opamps_gbw_vary_in_spice():
    """A gain-2 plant (the gain pair R3/R4, as on the command line) with the LM741's GBW spread 30 %:
    were an alter lost, the samples would leave the model's figures."""
    res = design_plant(PlantSpec(fc_hz=1000, zeta=0.1, gain=2), simulate=False)
    v = draw(res, 12, seed=4, gbw=0.3)
    assert set(v) == {"R1", "R2", "C1", "C2", "R3", "R4", "GBW"}
    ctx = spice_engine.context(res.deck, res.built, res.opamp, res.test)
    assert dict(ctx.elements)["R3"] == "r3" and dict(ctx.elements)["R4"] == "r4"
    assert_agrees(spice_engine.evaluate(ctx, v), plant_figures(v, res.opamp))


def test_the_ideal_opamp():
    res = design_plant(PlantSpec(fc_hz=3500, zeta=0.3, opamp="ideal"), simulate=False)
    v = draw(res, 10, seed=6)
    ctx = spice_engine.context(res.deck, res.built, res.opamp, res.test)
    assert ctx.cint is None
    s, m = spice_engine.evaluate(ctx, v), plant_figures(v, opamps.get("ideal"))
    assert np.all(np.abs(s["overshoot_pct"] - m["overshoot_pct"]) < 0.02)
    np.testing.assert_allclose(s["fn_hz"], m["fn_hz"], rtol=5e-4)      # no third pole: the same definition


def test_chunks_give_the_same_figures_as_the_whole(seed_plant, monkeypatch):
    """evaluate is a pure chunk function: its context pickles, and any split of the samples (into
    chunks, and into ngspice runs of BATCH samples) gives the same figures."""
    ctx = pickle.loads(pickle.dumps(spice_engine.context(seed_plant.deck, seed_plant.built, seed_plant.opamp,
                                                         seed_plant.test)))
    v = draw(seed_plant, 12, seed=8)
    whole = spice_engine.evaluate(ctx, v)
    monkeypatch.setattr(spice_engine, "BATCH", 5)
    parts = [spice_engine.evaluate(ctx, {k: a[lo:hi] for k, a in v.items()}, start=lo) for lo, hi in ((0, 7), (7, 12))]
    for k in spice_engine.FIGURES:
        np.testing.assert_array_equal(np.concatenate([p[k] for p in parts]), whole[k])


def test_parse_a_failed_measure_is_nan_a_missing_row_an_error():
    text = ("MCROW 3\nmcpeak = 3.0e+00 at= 1e-4\nmctpk = 2.0e-04\n meas tran mct10 failed!\n"
            "MCROW 4\nmcpeak = 2.5e+00 at= 1e-4\n")
    raw = spice_engine.parse(text, 3, 2)
    assert raw["mcpeak"].tolist() == [3.0, 2.5] and math.isnan(raw["mct10"][0]) and math.isnan(raw["mctpk"][1])
    with pytest.raises(SimulatorError, match="before Monte Carlo sample 5"):
        spice_engine.parse(text, 3, 3)


def test_commands_refuse_a_part_the_deck_lacks(seed_plant):
    ctx = spice_engine.context(seed_plant.deck, seed_plant.built, seed_plant.opamp, seed_plant.test)
    with pytest.raises(ValueError, match="no part R9"):
        spice_engine.commands(ctx, {"R9": np.array([1.0])})


def test_the_slew_rate_varies_in_spice_as_a_deck_with_that_opamp_says():
    """--tol SR: the op-amp subcircuit's SR parameter changed per build (alterparam + reset) with
    its GBW altered too; each build measures what a standalone deck written with that op-amp
    measures (a 20 kHz plant under a 5 V step, which slews: SR/2 rises half as fast again)."""
    import dataclasses

    from designer.plant.netlist import plant_deck
    from designer.spice.simulate import get_simulator
    res = design_plant(PlantSpec(fc_hz=20000, zeta=0.3, amplitude_v=5), simulate=False)
    amp = res.opamp
    v = {k: np.full(3, x) for k, x in plant_parts(res.built).items()}
    v["GBW"] = amp.gbw_hz * np.array([0.8, 1.0, 1.2])
    v["SR"] = amp.slew_v_per_s * np.array([0.5, 1.0, 1.5])
    ctx = spice_engine.context(res.deck, res.built, amp, res.test)
    assert dict(ctx.nominal)["SR"] == amp.slew_v_per_s and "{mcsr}" in ctx.circuit
    got = spice_engine.evaluate(ctx, v)
    for i in range(3):
        mine = dataclasses.replace(amp, gbw_hz=v["GBW"][i], slew_v_per_s=v["SR"][i])
        m = get_simulator("ngspice-cli").run(plant_deck(res.built, mine, res.test, "build")).measurements
        assert got["overshoot_pct"][i] == pytest.approx(m["overshoot_pct"], abs=0.02)
        assert got["rise_time_s"][i] == pytest.approx(m["rise_time_s"], rel=2e-3)
        assert got["peak_time_s"][i] == pytest.approx(m["peak_time_s"], rel=1e-3)
    assert got["rise_time_s"][0] > 1.4 * got["rise_time_s"][1]        # slewing, not the linear model
    # the nominal of the parametrised circuit is the deck itself
    nominal = {k: a[1:2] for k, a in v.items() if k not in ("GBW", "SR")}
    again = spice_engine.evaluate(ctx, nominal)
    assert again["overshoot_pct"][0] == pytest.approx(got["overshoot_pct"][1], abs=1e-9)


def test_the_plants_analytic_model_refuses_a_slew_spread(seed_plant):
    from designer.core.errors import DesignError
    from designer.tolerance.montecarlo import plant_monte_carlo
    with pytest.raises(DesignError, match="no figure of it depends on the slew rate"):
        plant_monte_carlo(seed_plant.built, {"R": "E24", "C": "E12"}, seed_plant.opamp, 20, tol_items=["SR=20%"])
