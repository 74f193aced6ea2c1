"""A plant Monte Carlo: the yield against an independent count, every CSV row's
figures recomputed from its parts, the part to tighten."""

import io

import numpy as np
import pytest

from designer.core import opamps
from designer.core.errors import DesignError
from designer.filters import registry
from designer.plant import circuit
from designer.plant.sallenkey import SallenKeyParts
from designer.tolerance.montecarlo import plant_monte_carlo
from designer.tolerance.plant import plant_figures

PARTS = SallenKeyParts(1.6e3, 3.9e3, 3.3e-9, 100e-9)
SERIES = {"R": "E24", "C": "E12"}
LIMITS = ["fn_hz=3.3k:3.7k", "overshoot_pct=0:55"]


@pytest.fixture(scope="module")
def mc():
    return plant_monte_carlo(PARTS, SERIES, opamps.get("LM741"), 5000, seed=2, limit_items=LIMITS)


def test_the_series_tolerances_are_the_default(mc):
    assert mc.tolerances.of == {"R1": 0.05, "R2": 0.05, "C1": 0.10, "C2": 0.10}


def test_yield_and_rows_recomputed_from_the_csv(mc):
    rows = np.genfromtxt(io.StringIO(mc.csv_text()), delimiter=",", names=True)
    assert rows.size == 5000 and list(rows["sample"][:3]) == [0, 1, 2]
    v = {k: rows[k] for k in ("R1", "R2", "C1", "C2")}
    again = plant_figures(v, opamps.get("LM741"))
    for k in ("fn_hz", "zeta", "overshoot_pct"):
        np.testing.assert_allclose(again[k], rows[k], rtol=1e-8)
    inside = (rows["fn_hz"] >= 3300) & (rows["fn_hz"] <= 3700) & (rows["overshoot_pct"] <= 55)
    assert mc.yield_count == int(inside.sum())
    d = mc.to_dict()
    assert d["yield"]["fraction"] == pytest.approx(inside.mean())
    assert d["yield"]["ci95"][0] < inside.mean() < d["yield"]["ci95"][1]


def test_failing_samples_are_the_worst(mc):
    fn = mc.figures["fn_hz"]
    worst = mc.failing["fn_hz"]["worst"]
    assert mc.failing["fn_hz"]["count"] == int(np.count_nonzero((fn < 3300) | (fn > 3700)))
    assert abs(fn[worst[0]] - 3500) == pytest.approx(np.max(np.abs(fn[(fn < 3300) | (fn > 3700)] - 3500)))


def test_tightening_the_suggested_part_raises_the_yield(mc):
    t = mc.tighten
    assert t["yield"] >= t["yield_now"]
    again = plant_monte_carlo(PARTS, SERIES, opamps.get("LM741"), 5000, seed=2, limit_items=LIMITS,
                              tol_items=[f"{t['part']}={t['tolerance_pct']}%"], tighten=False)
    assert again.yield_count / 5000 == pytest.approx(t["yield"])


def test_the_same_seed_the_same_run_whatever_the_sampler_settings():
    a = plant_monte_carlo(PARTS, SERIES, opamps.get("LM741"), 300, seed=9, tighten=False)
    b = plant_monte_carlo(PARTS, SERIES, opamps.get("LM741"), 300, seed=9, tighten=False)
    assert a.to_dict() == b.to_dict()
    c = plant_monte_carlo(PARTS, SERIES, opamps.get("LM741"), 300, seed=9, sampler="sobol", tighten=False)
    assert c.to_dict()["settings"]["sampler"] == "sobol"


@pytest.mark.parametrize("kw, what", [({"n": 5}, "--monte-carlo"), ({"tol_items": ["R9=1%"]}, "no part R9"),
                                      ({"tol_items": ["R=0"]}, "above 0"), ({"dist": "cauchy"}, "--dist"),
                                      ({"limit_items": ["fn_hz=3k:"]}, "both bounds")])
def test_bad_settings_are_one_line(kw, what):
    args = dict(n=100) | kw
    with pytest.raises(DesignError, match=what) as e:
        plant_monte_carlo(PARTS, SERIES, opamps.get("LM741"), args.pop("n"), **args)
    assert "\n" not in str(e.value)


def test_parts_typed_by_hand_need_a_tolerance():
    with pytest.raises(DesignError, match="typed by hand"):
        plant_monte_carlo(PARTS, {"R": None, "C": "E12"}, opamps.get("LM741"), 100)
    ok = plant_monte_carlo(PARTS, {"R": None, "C": "E12"}, opamps.get("LM741"), 100, tol_items=["R=1%"])
    assert ok.tolerances.of["R1"] == 0.01


def test_the_opamps_gain_bandwidth_spreads_when_asked():
    amp = opamps.get("LM741")
    fixed = plant_monte_carlo(PARTS, SERIES, amp, 400, seed=1, tighten=False)
    spread = plant_monte_carlo(PARTS, SERIES, amp, 400, seed=1, tol_items=["GBW=30%"], tighten=False)
    assert "GBW" not in fixed.values and spread.tolerances.of["GBW"] == 0.3
    gbw = spread.values["GBW"]
    assert gbw.min() >= 0.7 * amp.gbw_hz and gbw.max() <= 1.3 * amp.gbw_hz
    # a row recomputed with its own GBW: the op-amp's catalogue entry with that gain-bandwidth
    from dataclasses import replace
    i = int(np.argmin(gbw))
    one = {k: v[i:i + 1] for k, v in spread.values.items() if k != "GBW"}
    again = plant_figures(one, replace(amp, gbw_hz=float(gbw[i])))
    assert again["fn_hz"][0] == pytest.approx(spread.figures["fn_hz"][i], rel=1e-12)
    assert spread.stats["fn_hz"].std > fixed.stats["fn_hz"].std
    with pytest.raises(DesignError, match="ideal op-amp"):
        plant_monte_carlo(PARTS, SERIES, opamps.get("ideal"), 100, tol_items=["GBW=30%"])


def test_the_tightening_here_or_on_the_workers_gives_the_same_part_and_yield(monkeypatch):
    """A few builds' tightening runs (the analytic model, four parts) stay in this process: the
    pool sees the Monte Carlo's run only; on the workers they give the same section."""
    from designer.tolerance import montecarlo, runner
    calls = []
    real = runner._ProcessPool.map

    def spy(self, *a):
        calls.append(len(a[3]))
        return real(self, *a)

    monkeypatch.setattr(runner._ProcessPool, "map", spy)
    amp = opamps.get("LM741")
    scale = runner.Scale(jobs=2, chunk=128)
    here = plant_monte_carlo(PARTS, SERIES, amp, 2000, seed=5, limit_items=LIMITS, scale=scale)
    assert len(calls) == 1 and here.tighten["part"] in ("R1", "R2", "C1", "C2")
    monkeypatch.setattr(montecarlo, "TIGHTEN_HERE", 0)
    there = plant_monte_carlo(PARTS, SERIES, amp, 2000, seed=5, limit_items=LIMITS, scale=scale)
    assert len(calls) == 1 + 1 + 4
    assert there.to_dict() == here.to_dict()


def test_a_plant_on_another_topology_runs_the_same_monte_carlo_over_its_declared_parts():
    """circuit=(nominal, designer.plant.circuit.evaluate, (name, op-amp)): the MFB low-pass's five parts
    drawn, every figure recomputed from the drawn values, and the tightening over its own parts."""
    mfb = registry.get("mfb-lowpass")
    nominal = mfb.synthesize(mfb.example)
    amp = opamps.get("LM741")
    fn0 = float(mfb.figures(nominal).fn_hz)
    mc = plant_monte_carlo(None, {"R": "E24", "C": "E12"}, amp, 200, seed=4, limit_items=[f"fn_hz={0.95 * fn0}:{1.05 * fn0}"],
             circuit=(nominal, circuit.evaluate, (mfb.name, amp)))
    assert set(mc.values) == set(mfb.designators)
    again = circuit.circuit_figures(mfb, mc.values, amp)
    for k in ("fn_hz", "zeta", "ideal_fn_hz", "gain"):
        assert np.allclose(mc.figures[k], again[k], rtol=1e-12), k
    assert mc.tighten["part"] in mfb.designators


@pytest.mark.parametrize("parts", [PARTS, SallenKeyParts(10e3, 10e3, 10e-9, 10e-9, 2.0, 10e3, 10e3)],
                         ids=["follower", "gain2"])
def test_the_sallen_key_plant_and_its_section_run_one_monte_carlo(parts):
    """Issue 26, written once: the plant's Monte Carlo is the generic one on its section (the chunk function
    circuit.evaluate, which takes the Sallen-Key low-pass's own exact figures), so the section given as a
    circuit draws the same builds and finds the same figures, to the bit, GBW spread included."""
    from designer.filters.sallen_key_lowpass_parts import part_values, section_of
    from designer.tolerance.montecarlo import plant_parts
    amp = opamps.get("LM741")
    kw = dict(seed=3, limit_items=["overshoot_pct=0:60"], tol_items=["GBW=30%"])
    plant = plant_monte_carlo(parts, SERIES, amp, 300, **kw)
    section = plant_monte_carlo(None, SERIES, amp, 300, circuit=(plant_parts(parts), circuit.evaluate,
                                                                 (section_of(parts).name, amp)), **kw)
    assert plant.to_dict() == section.to_dict()
    assert plant.csv_text() == section.csv_text()
    assert set(plant.values) == set(part_values(parts)) | {"GBW"}


def test_a_figure_no_build_has_is_said_not_a_traceback(mc):
    # a SPICE step clipped at the op-amp's swing never settles to its gain: every build's fn and zeta are
    # NaN, so the figure's percentiles are empty; the summary raised KeyError: 2.5 (design-plant --topology
    # sallen-key-lowpass-gain --fc 3.5k --zeta 0.7 --gain 10 --monte-carlo 50 --engine spice)
    import dataclasses

    from designer.tolerance.stats import figure_stats
    nothing = np.full(mc.n, np.nan)
    bad = dataclasses.replace(mc, stats={**mc.stats, "fn_hz": figure_stats("fn_hz", nothing, np.nan),
                                         "zeta": figure_stats("zeta", nothing, np.nan)})
    lines = bad.summary_lines()
    assert "  natural frequency fn (fn_hz): nominal n/a, no build has this figure" in lines
    assert "  damping ratio zeta: nominal n/a, no build has this figure" in lines
    assert not any("nan" in line for line in lines)
    assert lines[3] == mc.summary_lines()[3]    # the overshoot's line as before
