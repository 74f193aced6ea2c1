"""The .ac SPICE engine of a section plant's Monte Carlo (designer.tolerance.spice_ac), over the
registry (a new section is picked up without editing this file): the fit recovers each section's
closed forms from its ideal response; each build run in ngspice gives the figures the same fit
gives on the op-amp-aware model's response at ngspice's own frequencies (within 1e-4: ngspice
prints 6 digits), and lands next to the analytic engine's rows (its dominant pair: fn within
1 %, zeta and the gain within 5 %, with the LM741); the Monte Carlo with --engine both records
both engines and their disagreement, and --spice-samples checks the tails."""

import numpy as np
import pytest

from designer.filters import REGISTRY
from designer.plant import circuit
from designer.plant.circuit_design import design_circuit_plant
from designer.plant.spec import PlantSpec
from designer.spice.simulate import get_simulator
from designer.tolerance import spice_ac
from designer.tolerance.spice_mc import section_monte_carlo_engine

TOPOLOGIES = [t for t in REGISTRY.values() if t.name != circuit.DEFAULT_TOPOLOGY]
IDS = [t.name for t in TOPOLOGIES]
SERIES = {"R": "E24", "C": "E12"}
#: the engine's builds against the analytic engine's dominant pair (measured: fn 0.4 %, zeta 2.5 %, gain 2.5 %)
DOMINANT_RTOL = {"fn_hz": 0.01, "zeta": 0.05, "gain": 0.05}


def design_of(topology, opamp="LM741"):
    ex = topology.example
    spec = PlantSpec(fc_hz=ex.fn_hz, zeta=None if ex.q is None else 1 / (2 * ex.q), gain=ex.gain, opamp=opamp,
                     topology=topology.name)
    return design_circuit_plant(spec, simulate=False)


def builds(result, n=8, seed=11):
    """n builds within 5 % of the nominal (a recorded seed)."""
    rng = np.random.default_rng(seed)
    return {r: v * (1 + 0.05 * rng.uniform(-1, 1, n)) for r, v in result.values.items()}


@pytest.mark.parametrize("topology", TOPOLOGIES, ids=IDS)
def test_the_fit_recovers_the_closed_forms_from_the_ideal_response(topology):
    values = topology.synthesize(topology.example)
    fn = float(topology.figures(values).fn_hz)
    f = np.geomspace(fn / spice_ac.SPAN, fn * spice_ac.SPAN, 10)
    num = np.asarray(topology.coefficients(values)[0], float)
    zeros = len(num) - len(np.trim_zeros(num, "b"))
    got = spice_ac.fit(f, topology.response(values, 2j * np.pi * f), topology.order, zeros)
    want = topology.figures(values)
    assert got["fn_hz"][0] == pytest.approx(fn, rel=1e-9)
    assert got["gain"][0] == pytest.approx(float(want.gain), rel=1e-9)
    if topology.order == 2:
        assert got["q"][0] == pytest.approx(float(want.q), rel=1e-9)
    else:
        assert np.isnan(got["q"][0])


@pytest.mark.spice
@pytest.mark.parametrize("topology", TOPOLOGIES, ids=IDS)
def test_each_build_in_ngspice_is_the_model_s_response(topology):
    result = design_of(topology)
    ctx = spice_ac.context(result.deck, result.netlist, topology, result.values, result.figures["ideal"]["fn_hz"])
    vals = builds(result)
    f, h = spice_ac.parse(get_simulator("ngspice-cli").run_script(ctx.circuit, spice_ac.commands(ctx, vals)), 0, 8)
    sp = spice_ac.fit(f, h, topology.order, ctx.zeros)
    model = np.stack([topology.response({r: v[i] for r, v in vals.items()}, 2j * np.pi * f, result.opamp)
                      for i in range(8)])
    again = spice_ac.fit(f, model, topology.order, ctx.zeros)
    rows = circuit.circuit_figures(topology, vals, result.opamp)
    for k in ("fn_hz", "zeta", "gain"):
        if topology.order == 1 and k == "zeta":
            assert np.isnan(sp[k]).all()
            continue
        np.testing.assert_allclose(sp[k], again[k], rtol=1e-4, err_msg=k)
        np.testing.assert_allclose(sp[k], rows[k], rtol=DOMINANT_RTOL[k], err_msg=k)
    # evaluate() is that loop, batched, with the same figures
    ev = spice_ac.evaluate(ctx, vals)
    np.testing.assert_allclose(ev["fn_hz"], sp["fn_hz"], rtol=1e-12)


@pytest.mark.spice
def test_engine_both_records_both_engines_and_the_tails():
    topology = REGISTRY["mfb-lowpass"]
    result = design_of(topology)
    fn = result.figures["opamp"]["fn_hz"]
    limit = [f"fn_hz={0.97 * fn:.6g}:{1.03 * fn:.6g}"]
    mc = section_monte_carlo_engine(result, SERIES, 40, seed=4, limit_items=limit, engine="both",
                                    simulator="ngspice-cli")
    rows = mc.figures
    model = circuit.circuit_figures(topology, {r: mc.values[r] for r in topology.designators}, result.opamp)
    np.testing.assert_allclose(rows["model_fn_hz"], model["fn_hz"], rtol=1e-12)
    np.testing.assert_allclose(rows["fn_hz"], model["fn_hz"], rtol=DOMINANT_RTOL["fn_hz"])
    # the step figures of SPICE's fitted pair, as the analytic engine's of its own
    step = circuit.step_of_pair(rows["fn_hz"], rows["zeta"])
    np.testing.assert_allclose(rows["overshoot_pct"], step["overshoot_pct"], rtol=1e-12)
    inside = (rows["fn_hz"] >= 0.97 * fn) & (rows["fn_hz"] <= 1.03 * fn)
    assert mc.yield_count == int(inside.sum())
    d = mc.to_dict()["spice"]
    assert d["engine"] == "both" and d["disagreement"]["fn_hz"]["compared"] == 40
    picked = section_monte_carlo_engine(result, SERIES, 40, seed=4, limit_items=limit, engine="both", spice_k=3,
                                        simulator="ngspice-cli")
    s = picked.to_dict()["spice"]
    idx = np.array(s["worst"] + s["random"])
    assert s["samples_checked"] == idx.size and np.isfinite(picked.figures["spice_fn_hz"][idx]).all()
    # the builds SPICE checked are those of the full run, with its figures
    np.testing.assert_allclose(picked.figures["spice_fn_hz"][idx], rows["fn_hz"][idx], rtol=1e-9)


@pytest.mark.spice
@pytest.mark.parametrize("topology", TOPOLOGIES, ids=IDS)
def test_a_drawn_gbw_alters_the_op_amp_of_each_build(topology):
    """GBW drawn per build (the op-amp's spread): ngspice's .ac of each build is the op-amp-aware model's
    response with that build's gain-bandwidth (the same fit within 1e-4), and the analytic engine
    (circuit.evaluate) takes the same GBW."""
    import dataclasses
    result = design_of(topology)
    ctx = spice_ac.context(result.deck, result.netlist, topology, result.values, result.figures["ideal"]["fn_hz"],
                           opamp=result.opamp)
    assert ctx.cints and ctx.gbw_hz == result.opamp.gbw_hz
    vals = {**builds(result, n=4), "GBW": result.opamp.gbw_hz * np.array([0.5, 0.8, 1.2, 1.5])}
    f, h = spice_ac.parse(get_simulator("ngspice-cli").run_script(ctx.circuit, spice_ac.commands(ctx, vals)), 0, 4)
    ev = spice_ac.fit(f, h, topology.order, ctx.zeros)
    np.testing.assert_allclose(spice_ac.evaluate(ctx, vals)["fn_hz"], ev["fn_hz"], rtol=1e-12)
    parts = {r: v for r, v in vals.items() if r != "GBW"}
    again = spice_ac.fit(f, np.stack([topology.response(
        {r: v[i] for r, v in parts.items()}, 2j * np.pi * f, dataclasses.replace(result.opamp, gbw_hz=vals["GBW"][i]))
        for i in range(4)]), topology.order, ctx.zeros)
    np.testing.assert_allclose(ev["fn_hz"], again["fn_hz"], rtol=1e-4)
    model = circuit.evaluate((topology.name, result.opamp), vals)
    for i in range(4):
        one = circuit.circuit_figures(topology, {r: v[i] for r, v in parts.items()},
                                      dataclasses.replace(result.opamp, gbw_hz=vals["GBW"][i]))
        assert model["fn_hz"][i] == pytest.approx(float(one["fn_hz"]), rel=1e-12)
