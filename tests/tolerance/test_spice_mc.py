"""--engine spice|both, --spice-samples and the replay of one sample (the library side)."""

import io

import numpy as np
import pytest

from designer.tolerance.spice_mc import plant_context
from designer.core.errors import DesignError
from designer.plant.design import design_plant
from designer.plant.spec import PlantSpec
from designer.tolerance import sampling
from designer.tolerance.montecarlo import plant_monte_carlo
from designer.tolerance.plant import plant_figures
from designer.tolerance.spice_mc import plant_monte_carlo_engine, replay, replay_parts, replay_values, spice_samples
from designer.tolerance.stats import parse_limit

pytestmark = pytest.mark.spice

SERIES = {"R": "E24", "C": "E12"}
LIMITS = ["fn_hz=3.3k:3.7k", "overshoot_pct=0:55"]


@pytest.fixture(scope="module")
def seed_plant():
    return design_plant(PlantSpec(fc_hz=3500, zeta=0.2), simulate=False)


@pytest.fixture(scope="module")
def both(seed_plant):
    return plant_monte_carlo_engine(seed_plant, SERIES, 60, seed=5, limit_items=LIMITS, engine="both")


def test_both_yield_from_spices_figures_and_the_model_beside(seed_plant, both):
    rows = np.genfromtxt(io.StringIO(both.csv_text()), delimiter=",", names=True)
    inside = (rows["fn_hz"] >= 3300) & (rows["fn_hz"] <= 3700) & (rows["overshoot_pct"] <= 55)
    assert both.yield_count == int(inside.sum()) and both.to_dict()["settings"]["engine"] == "both"
    model = plant_figures({k: rows[k] for k in ("R1", "R2", "C1", "C2")}, seed_plant.opamp)
    np.testing.assert_allclose(rows["model_overshoot_pct"], model["overshoot_pct"], rtol=1e-8)
    m_inside = (model["fn_hz"] >= 3300) & (model["fn_hz"] <= 3700) & (model["overshoot_pct"] <= 55)
    s = both.to_dict()["spice"]
    assert s["yield_model"] == pytest.approx(m_inside.mean()) and s["yield_with_spice"] == pytest.approx(inside.mean())
    d = s["disagreement"]["overshoot_pct"]
    diff = rows["overshoot_pct"] - rows["model_overshoot_pct"]
    assert d["compared"] == 60 and d["max_abs"] == pytest.approx(np.max(np.abs(diff)))
    assert d["worst_sample"] == int(np.argmax(np.abs(diff))) and d["max_abs"] < 0.02
    # the figures the model alone gives stay the model's; SPICE adds its own
    np.testing.assert_allclose(rows["ideal_fn_hz"], model["ideal_fn_hz"], rtol=1e-8)
    assert np.all(rows["settling_time_s"] > 0)


def test_spice_samples_the_tails_and_random_ones(seed_plant):
    mc = plant_monte_carlo_engine(seed_plant, SERIES, 2000, seed=5, limit_items=LIMITS, engine="both", spice_k=5)
    s = mc.spice
    limits = [parse_limit(t, ("fn_hz", "overshoot_pct")) for t in LIMITS]
    # the worst by brute force: per limited figure, the 5 with the least room inside the window
    expect = set()
    for lim in limits:
        v = mc.figures[lim.figure]
        room = [min(x - lim.min, lim.max - x) for x in v]
        expect |= set(sorted(range(v.size), key=lambda i: room[i])[:5])
    assert set(s["worst"]) == expect and len(s["random"]) == 5 and not set(s["random"]) & expect
    assert (s["worst"], s["random"]) == spice_samples(mc.figures, mc.limits, 5, 5)        # reproducible
    checked = np.array(sorted(s["worst"] + s["random"]))
    assert np.all(np.isfinite(mc.figures["spice_overshoot_pct"][checked]))
    assert np.count_nonzero(np.isfinite(mc.figures["spice_overshoot_pct"])) == checked.size
    flips = len(s["flipped"]["fail_to_pass"]) - len(s["flipped"]["pass_to_fail"])
    assert s["yield_with_spice"] == pytest.approx(s["yield_model"] + flips / 2000)
    # the flips are exactly the checked samples whose verdict SPICE changes
    spice_ok = np.ones(checked.size, bool)
    for lim in limits:
        spice_ok &= lim.inside(mc.figures["spice_" + lim.figure][checked])
    assert sorted(s["flipped"]["pass_to_fail"]) == [int(i) for i in checked[mc.passed[checked] & ~spice_ok]]


def test_spice_samples_need_limits(seed_plant):
    with pytest.raises(DesignError, match="needs --limit"):
        plant_monte_carlo_engine(seed_plant, SERIES, 50, engine="both", spice_k=3)


@pytest.mark.parametrize("sampler", ["random", "lhs", "sobol"])
def test_replay_draws_the_samples_values_again(seed_plant, sampler):
    full = plant_monte_carlo(seed_plant.built, SERIES, seed_plant.opamp, 300, seed=7, sampler=sampler,
                             dist="normal", tol_items=["C2=2%"], tighten=False)
    for i in (0, 123, 299):
        _, _, v = replay_values(*replay_parts(seed_plant), SERIES, seed_plant.opamp, i, 300, 7, sampler, "normal",
                                ["C2=2%"])
        assert v == {k: a[i] for k, a in full.values.items()}
    with pytest.raises(DesignError, match="samples 0 to 299"):
        replay_values(*replay_parts(seed_plant), SERIES, seed_plant.opamp, 300, 300, 7, sampler, "normal")


def test_replay_gives_the_runs_figures(seed_plant):
    mc = plant_monte_carlo_engine(seed_plant, SERIES, 20, seed=3, engine="spice", simulator="pyspice")
    rep = replay(seed_plant, SERIES, 13, 20, 3, "random", "uniform", simulator="ngspice-cli")
    assert rep.values == {k: mc.values[k][13] for k in ("R1", "R2", "C1", "C2")}
    for k, v in rep.spice.items():
        assert v == pytest.approx(mc.figures[k][13], rel=1e-9)
    assert rep.to_dict()["replay"]["sample"] == 13
    row = np.genfromtxt(io.StringIO(rep.csv_text()), delimiter=",", names=True)
    assert int(row["sample"]) == 13 and float(row["R1"]) == pytest.approx(rep.values["R1"], rel=1e-9)


def test_unknown_engine(seed_plant):
    with pytest.raises(DesignError, match="allowed: analytic, spice, both"):
        plant_monte_carlo_engine(seed_plant, SERIES, 50, engine="xyce")


def test_sampling_matches_replay_offsets():
    """The property replay relies on: samples start..stop of a draw are those of the whole draw."""
    nominal, tol = {"R1": 1e3, "C1": 1e-9}, {"R1": 0.05, "C1": 0.1}
    whole = sampling.values(nominal, tol, 10000, 4)
    part = sampling.values(nominal, tol, 10000, 4, start=4095, stop=4098)
    assert all(np.array_equal(part[k], whole[k][4095:4098]) for k in nominal)


def test_the_engine_pickles_for_workers(seed_plant):
    import pickle

    from designer.tolerance.spice_mc import spice_evaluate
    f = pickle.loads(pickle.dumps(spice_evaluate(plant_context(seed_plant),
                                                 seed_plant.opamp)))
    v = sampling.values({"R1": 1.6e3, "R2": 3.9e3, "C1": 3.3e-9, "C2": 100e-9},
                        {"R1": .05, "R2": .05, "C1": .1, "C2": .1}, 4, 1)
    figs = f(v)
    assert set(figs) >= set(plant_figures(v, seed_plant.opamp)) | {"rise_time_s", "settling_time_s"}


def test_spice_samples_run_on_the_runners_workers(seed_plant, monkeypatch):
    """--spice-samples' SPICE builds go through the runner (--jobs, --dask), with the same result."""
    from designer.tolerance import runner
    seen = []
    real = runner._ProcessPool.map

    def spy(self, evaluate, context, draw, tasks, bar):
        seen.append((type(draw).__name__, list(tasks)))
        return real(self, evaluate, context, draw, tasks, bar)

    monkeypatch.setattr(runner._ProcessPool, "map", spy)
    kw = dict(seed=5, limit_items=LIMITS, engine="both", spice_k=4)
    one = plant_monte_carlo_engine(seed_plant, SERIES, 400, **kw)
    two = plant_monte_carlo_engine(seed_plant, SERIES, 400, scale=runner.Scale(jobs=2, chunk=5), **kw)
    picked = [tasks for kind, tasks in seen if kind == "Picked"]
    assert len(picked) == 1 and len(picked[0]) >= 2     # the checked builds, in chunks on two workers
    assert one.to_dict() == two.to_dict() and one.csv_text() == two.csv_text()


@pytest.fixture(scope="module")
def mfb_plant():
    from designer.plant.circuit_design import design_circuit_plant
    return design_circuit_plant(PlantSpec(fc_hz=1000, zeta=0.5, gain=2, topology="mfb-lowpass"), simulate=False)


@pytest.mark.parametrize("sampler", ["random", "lhs", "sobol"])
def test_a_section_replay_draws_the_builds_values_again(mfb_plant, sampler):
    """Issue 26: --replay I on a section plant draws build I of the analytic Monte Carlo over its parts."""
    from designer.tolerance.spice_mc import drawn_values, section_monte_carlo_engine
    full = section_monte_carlo_engine(mfb_plant, SERIES, 200, seed=7, sampler=sampler, dist="normal",
                                      tol_items=["R3=1%"])
    for i in (0, 77, 199):
        _, _, v = drawn_values(dict(mfb_plant.values), SERIES, mfb_plant.opamp, i, 200, 7, sampler, "normal",
                               ["R3=1%"])
        assert v == {k: a[i] for k, a in full.values.items()}


def test_a_section_replay_gives_the_spice_engines_row(mfb_plant):
    """The replayed build's figures are the SPICE engine's row I (its .ac fitted, the model's beside); its
    bundle is the analysis of its exact values."""
    from designer.tolerance.spice_mc import replay, replay_result, section_monte_carlo_engine
    mc = section_monte_carlo_engine(mfb_plant, SERIES, 12, seed=3, engine="spice", simulator="ngspice-cli")
    rep = replay(mfb_plant, SERIES, 9, 12, 3, "random", "uniform", simulator="ngspice-cli")
    assert rep.values == {k: mc.values[k][9] for k in mfb_plant.section.designators}
    assert set(rep.spice) == set(mc.figures)
    for k, v in rep.spice.items():
        assert v == pytest.approx(mc.figures[k][9], rel=1e-9)
    row = np.genfromtxt(io.StringIO(rep.csv_text()), delimiter=",", names=True)
    assert int(row["sample"]) == 9 and float(row["model_fn_hz"]) == pytest.approx(rep.model["fn_hz"], rel=1e-9)
    out = replay_result(mfb_plant, rep, "ngspice-cli")
    assert out.values == rep.values and out.mode == "analyze" and out.spice["pass"]
    assert out.to_dict()["monte_carlo"]["replay"]["sample"] == 9
