"""The loop's Monte Carlo: every sampled loop's figures equal analyze-pid's for
those parts (sample by sample, from the CSV rows), the same seed the same run;
the yield, the failing samples and the part to tighten against an independent
count of the rows; --target-ci's rounds against an independent Wilson interval, the same on two
workers; the worst case against brute force on a small box."""

import io
import itertools

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

from designer.pid.blocks import PidParts
from designer.pid.design import analyze_pid, design_pid
from designer.pid.spec import PidSpec
from designer.plant.sallenkey import SallenKeyParts
from designer.core.errors import DesignError
from designer.tolerance.loop import LIMITABLE, loop_figures, loop_monte_carlo, loop_parts, parse_loop_limit
from designer.tolerance.montecarlo import TARGET_ROUND
from designer.tolerance.runner import Scale
from designer.tolerance.worstcase import worst_case
from helpers import wilson_half_width

LIMITS = ["phase_margin_deg=27:90", "overshoot_pct=0:12"]


@pytest.fixture(scope="module")
def designed():
    return design_pid(PidSpec(plant_fc_hz=3500, plant_zeta=0.2, tuning="optimize", target_overshoot_pct=10),
                      simulate=False)


@pytest.fixture(scope="module")
def mc(designed):
    return loop_monte_carlo(designed, {"R": "E24", "C": "E12"}, 40, seed=3, tol_items=["R=5%", "C=10%"])


def test_each_row_is_the_loop_analyze_pid_finds(designed, mc):
    rows = np.genfromtxt(io.StringIO(mc.csv_text()), delimiter=",", names=True)
    for row in rows[:4]:
        plant = SallenKeyParts(row["R1"], row["R2"], row["C1"], row["C2"])
        parts = PidParts(**{f: row[f.upper()] for f in PidParts.__dataclass_fields__ if f.upper() in rows.dtype.names})
        res = analyze_pid(PidSpec(plant_parts=plant, controller_parts=parts, step_v=designed.test.amplitude_v,
                                  square_hz=designed.test.frequency_hz), simulate=False)
        assert bool(row["stable"]) == res.analytic.stable
        assert row["phase_margin_deg"] == pytest.approx(res.margins.phase_margin_deg, abs=0.05)
        assert row["model_overshoot_pct"] == pytest.approx(res.analytic.figures.overshoot_pct, abs=0.3)
        assert row["kp"] == pytest.approx(res.achieved.kp, rel=1e-9)
        assert row["crossover_hz"] == pytest.approx(res.margins.crossover_hz, rel=1e-3)


def test_probabilities_count_the_samples(mc):
    d = mc.to_dict()
    stable = mc.figures["stable"]
    assert d["p_unstable"]["count"] == int(np.count_nonzero(stable == 0))
    lo, hi = d["p_unstable"]["ci95"]
    assert lo <= d["p_unstable"]["fraction"] <= hi
    assert d["settings"]["tolerances_pct"]["C4"] == 10.0 and d["settings"]["tolerances_pct"]["R18"] == 5.0


def test_the_same_seed_the_same_run(designed, mc):
    again = loop_monte_carlo(designed, {"R": "E24", "C": "E12"}, 40, seed=3, tol_items=["R=5%", "C=10%"])
    assert again.to_dict() == mc.to_dict()


def test_a_tight_build_of_a_fragile_loop_can_go_unstable():
    # the seed's own final gains with LM741s are unstable as designed: every build is
    res = design_pid(PidSpec(plant_fc_hz=3500, plant_zeta=0.2, kp=45, ti_s=43.215e-6, td_s=10.8037e-6),
                     simulate=False)
    got = loop_monte_carlo(res, {"R": "E24", "C": "E12"}, 20, seed=0).to_dict()
    assert got["p_unstable"]["fraction"] == 1.0 and got["p_unstable"]["ci95"][1] == 1.0


@pytest.fixture(scope="module")
def limited(designed):
    return loop_monte_carlo(designed, {"R": "E24", "C": "E12"}, 60, seed=5, limit_items=LIMITS)


def test_the_yield_counts_the_rows_inside_every_limit_of_a_stable_loop(limited):
    rows = np.genfromtxt(io.StringIO(limited.csv_text()), delimiter=",", names=True)
    pm, os_ = rows["phase_margin_deg"], rows["model_overshoot_pct"]
    good = (rows["stable"] == 1) & (pm >= 27) & (pm <= 90) & (os_ >= 0) & (os_ <= 12)
    d = limited.to_dict()
    assert d["yield"]["passed"] == int(good.sum()) and d["yield"]["samples"] == 60
    assert 0 < d["yield"]["passed"] < 60        # the window is chosen to lose some builds
    lo, hi = d["yield"]["ci95"]
    assert lo < d["yield"]["fraction"] < hi
    # the SPICE name counts the analytic loop's figure
    assert [lim["figure"] for lim in d["limits"]] == ["phase_margin_deg", "model_overshoot_pct"]
    bad_pm = np.nonzero(~((pm >= 27) & (pm <= 90)))[0]
    assert d["failing_samples"]["phase_margin_deg"]["count"] == bad_pm.size
    worst = d["failing_samples"]["phase_margin_deg"]["worst"]
    assert set(worst) <= set(bad_pm) and worst[0] == bad_pm[np.argmax(np.abs(pm[bad_pm] - 58.5))]
    assert set(d["variance_shares"]) >= {"phase_margin_deg", "model_overshoot_pct", "method"}
    shares = d["variance_shares"]["phase_margin_deg"]
    assert set(shares) == set(limited.values) and min(shares.values()) >= 0


def test_the_part_to_tighten_gives_the_yield_it_claims(designed, limited):
    t = limited.to_dict()["tighten"]
    assert t["part"] in t["tried"] and len(t["tried"]) == 3
    again = loop_monte_carlo(designed, {"R": "E24", "C": "E12"}, 60, seed=5, limit_items=LIMITS,
                             tol_items=[f"{t['part']}={t['tolerance_pct']}%"], tighten=False)
    assert again.yield_count / 60 == pytest.approx(t["yield"])
    assert again.tolerances.of[t["part"]] == pytest.approx(t["tolerance_pct"] / 100)


#: --target-ci on the loop: a half-width LIMITS' yield reaches in a few rounds
TARGET = 0.03


def test_target_ci_on_a_loop_stops_at_the_first_round_below_it(designed):
    def in_yield(figs, n):   # stable and inside every window, counted here
        pm, os_ = figs["phase_margin_deg"][:n], figs["model_overshoot_pct"][:n]
        return int(np.count_nonzero((figs["stable"][:n] == 1) & (pm >= 27) & (pm <= 90) & (os_ >= 0) & (os_ <= 12)))

    mc = loop_monte_carlo(designed, {"R": "E24", "C": "E12"}, 20000, seed=7, limit_items=LIMITS, target_ci=TARGET,
                          tighten=False)
    d = mc.to_dict()
    t, rounds = d["settings"]["target_ci"], d["settings"]["target_ci"]["rounds"]
    assert t["reached"] and t["half_width_pct"] == 100 * TARGET and t["max_samples"] == 20000
    assert rounds[0] == TARGET_ROUND and len(rounds) >= 2 and rounds == sorted(rounds)
    assert rounds[-1] == mc.n == d["settings"]["samples"] == d["yield"]["samples"] == len(mc.figures["stable"])
    assert d["yield"]["passed"] == in_yield(mc.figures, mc.n)
    assert wilson_half_width(in_yield(mc.figures, mc.n), mc.n) < TARGET
    for end in rounds[:-1]:   # every earlier round was still too wide
        assert wilson_half_width(in_yield(mc.figures, end), end) >= TARGET
    # the builds drawn are the first of the same run at its full size (build i is f(seed, i))
    full = loop_monte_carlo(designed, {"R": "E24", "C": "E12"}, mc.n, seed=7, limit_items=LIMITS, tighten=False)
    np.testing.assert_array_equal(full.figures["phase_margin_deg"], mc.figures["phase_margin_deg"])
    # and the same on two worker processes
    again = loop_monte_carlo(designed, {"R": "E24", "C": "E12"}, 20000, seed=7, limit_items=LIMITS,
                             target_ci=TARGET, tighten=False, scale=Scale(jobs=2))
    assert again.to_dict() == d and again.csv_text() == mc.csv_text()


def test_target_ci_on_a_loop_needs_a_limit(designed):
    with pytest.raises(DesignError, match="needs --limit"):
        loop_monte_carlo(designed, {"R": "E24", "C": "E12"}, 1000, target_ci=0.01)


@pytest.mark.parametrize("text, figure", [("overshoot_pct=0:12", "model_overshoot_pct"),
                                          ("phase_margin_deg=45:90", "phase_margin_deg"),
                                          ("crossover_hz=1k:20k", "crossover_hz"), ("kp=2:3", "kp")])
def test_a_loop_limit_names_the_engines_figure(text, figure):
    assert parse_loop_limit(text).figure == figure


@pytest.mark.parametrize("text", ["stable=0:1", "fn_hz=1k:2k", "nrms=0:1", "phase_margin_deg=90:45"])
def test_a_loop_limit_on_no_loop_figure_is_refused(text):
    with pytest.raises(DesignError) as info:
        parse_loop_limit(text)
    assert "\n" not in str(info.value)


def test_the_loops_worst_case_meets_brute_force_on_a_small_box(designed):
    # three parts vary (the others nominal): the sensitivity corners and the bounded search, forced by
    # max_corners=4, reach the extremes of a 5 x 5 x 5 grid over the box
    nominal = loop_parts(designed)
    tol = {"C2": 0.10, "C4": 0.10, "R5": 0.05}
    fixed = {r: v for r, v in nominal.items() if r not in tol}

    def evaluate(v):
        n = next(iter(v.values())).size
        return loop_figures({**{r: np.full(n, x) for r, x in fixed.items()}, **v}, designed)

    figs = ("phase_margin_deg", "gain_margin_db")
    wc = worst_case(evaluate, {r: nominal[r] for r in tol}, tol, figs, max_corners=4, maxiter=15)
    assert wc.method.startswith("each part alone")
    grid = np.array(list(itertools.product(np.linspace(-1, 1, 5), repeat=3)))
    f = evaluate({r: nominal[r] * (1 + tol[r] * grid[:, k]) for k, r in enumerate(tol)})
    for fig in figs:
        lo, hi = wc.extremes[fig]
        assert lo.value <= f[fig].min() + 1e-6 and hi.value >= f[fig].max() - 1e-6, fig
        # each extreme is where it says it is
        at = evaluate({r: np.array([nominal[r] * (1 + tol[r] * lo.deviations[r])]) for r in tol})
        assert at[fig][0] == pytest.approx(lo.value, rel=1e-9)


def test_a_model_plants_loop_varies_the_controller_alone_as_analyze_pid_sees_it():
    model = "K=2 tau=1m theta=200u"
    res = design_pid(PidSpec(plant_tf=model, tuning="simc"), simulate=False)
    mc = loop_monte_carlo(res, {"R": "E24", "C": "E12"}, 12, seed=2, limit_items=["phase_margin_deg=55:90"])
    assert set(mc.values) == {p.upper() for p in PidParts.__dataclass_fields__ if getattr(res.parts, p) is not None}
    assert mc.nominal_figures["phase_margin_deg"] == pytest.approx(res.margins.phase_margin_deg, rel=1e-9)
    assert mc.nominal_figures["model_overshoot_pct"] == pytest.approx(res.analytic.figures.overshoot_pct, rel=1e-9)
    rows = np.genfromtxt(io.StringIO(mc.csv_text()), delimiter=",", names=True)
    for row in rows[:2]:
        parts = PidParts(**{f: (row[f.upper()] if f.upper() in rows.dtype.names else None)   # a PI: no R7..C3
                            for f in PidParts.__dataclass_fields__})
        got = analyze_pid(PidSpec(plant_tf=model, controller_parts=parts), simulate=False)
        assert bool(row["stable"]) == got.stable
        assert row["phase_margin_deg"] == pytest.approx(got.margins.phase_margin_deg, rel=1e-6)
        assert row["kp"] == pytest.approx(got.achieved.kp, rel=1e-9)
    good = (rows["stable"] == 1) & (rows["phase_margin_deg"] >= 55) & (rows["phase_margin_deg"] <= 90)
    assert mc.yield_count == int(good.sum())


@settings(max_examples=150, deadline=None)
@given(name=st.sampled_from(["phase_margin_deg", "overshoot_pct", "kp", "crossover_hz", "stable", "fn_hz", ""]),
       lo=st.one_of(st.floats(allow_nan=True, allow_infinity=True), st.text(max_size=6)),
       hi=st.one_of(st.floats(allow_nan=True, allow_infinity=True), st.text(max_size=6)),
       sep=st.sampled_from([":", "", "::", "="]))
def test_any_loop_limit_is_a_window_or_one_line(name, lo, hi, sep):
    text = f"{name}={lo}{sep}{hi}"
    try:
        lim = parse_loop_limit(text)
    except DesignError as exc:
        assert "\n" not in str(exc) and str(exc).startswith("--limit")
        return
    assert lim.figure in LIMITABLE and lim.min <= lim.max


# ---- the op-amps' spread (--tol GBW SR): one lot per build ---------------------------------------

@pytest.fixture(scope="module")
def spread(designed):
    return loop_monte_carlo(designed, {"R": "E24", "C": "E12"}, 24, seed=9, tol_items=["GBW=30%", "SR=50%"],
                            limit_items=LIMITS, tighten=False)


def _row_loop(designed, row, amp):
    """A row's loop rebuilt from the pid wing's own model with the row's op-amp: margins and each
    stage's slew delay (design-pid's slew check, the kick on its fine grid)."""
    from designer.pid import model
    from designer.plant.model import plant_tf_opamp
    from designer.tolerance.loop import STEP_POINTS
    plant = SallenKeyParts(row["R1"], row["R2"], row["C1"], row["C2"])
    parts = PidParts(**{f: row[f.upper()] for f in PidParts.__dataclass_fields__ if f.upper() in row.dtype.names})
    pn, pd = plant_tf_opamp(plant, amp)
    from designer.pid.optimize import slew_delay_stages
    from designer.tolerance.loop import kick_grid
    step, edge = designed.test.amplitude_v, designed.test.edge_s
    t = np.linspace(0.0, designed.waveforms.t[-1], STEP_POINTS)
    lm = model.assemble(parts, amp, pn, pd)
    waves = lm.simulate(t, model.reference(t, step, 0.0, edge))
    # the kick again on its fine grid, by its own matrix exponential; its first step read as the edge
    tf = kick_grid(parts, t, edge)
    assert tf[1] - tf[0] <= (tf[-1] - tf[0]) / 200 and tf[-1] >= 10 / (2 * np.pi * parts.f_differentiator_hz)
    fine = lm.simulate(tf, model.reference(tf, step, 0.0, edge))
    delay = max(slew_delay_stages(tf, fine[k], t, v, amp.slew_v_per_s, edge) for k, v in waves.items() if k != "y")
    w = 2 * np.pi * np.logspace(np.log10(min(parts.f_integrator_hz, plant.fn_hz) / 20),
                                np.log10(max(amp.gbw_hz, 100 * plant.fn_hz)), 1500)
    return model.margins(w, model.loop_gain(parts, amp, pn, pd, w)), delay


def test_each_row_is_its_loop_with_its_own_opamp(designed, spread):
    import dataclasses
    rows = np.genfromtxt(io.StringIO(spread.csv_text()), delimiter=",", names=True)
    assert {"GBW", "SR", "slewing", "slew_delay_s"} <= set(rows.dtype.names)
    amp = designed.opamp
    assert spread.nominal["GBW"] == amp.gbw_hz and spread.nominal["SR"] == amp.slew_v_per_s
    assert np.all(np.abs(rows["SR"] / amp.slew_v_per_s - 1) <= 0.5)
    for row in rows[:4]:
        mine = dataclasses.replace(amp, gbw_hz=row["GBW"], slew_v_per_s=row["SR"])
        mg, delay = _row_loop(designed, row, mine)
        assert row["phase_margin_deg"] == pytest.approx(mg.phase_margin_deg, abs=1e-6)
        assert row["slew_delay_s"] == pytest.approx(delay, rel=1e-6)
        budget = 0.05 * row["model_rise_time_s"]
        assert row["slewing"] == float(delay > budget)


def test_the_slew_check_fails_as_often_as_the_rows_say(spread):
    rows = np.genfromtxt(io.StringIO(spread.csv_text()), delimiter=",", names=True)
    fails = (rows["stable"] == 0) | (rows["slew_delay_s"] > 0.05 * rows["model_rise_time_s"])
    d = spread.to_dict()
    assert d["p_slewing"]["count"] == int(fails.sum()) and 0 < fails.sum() < 24   # SR 50 % at the budget's edge
    lo, hi = d["p_slewing"]["ci95"]
    assert lo <= fails.mean() <= hi and (lo, hi) == pytest.approx(wilson_interval(int(fails.sum()), 24))
    assert "slew" in d["slew_rule"] and "a stage slewing" in "\n".join(spread.summary_lines())
    # the slew rate alone explains most of the delay's spread
    assert d["statistics"]["slew_delay_s"]["nominal"] > 0


def wilson_interval(k, n, z=1.959963984540054):
    p = k / n
    c = (p + z * z / (2 * n)) / (1 + z * z / n)
    h = z * np.sqrt(p * (1 - p) / n + z * z / (4 * n * n)) / (1 + z * z / n)
    return max(0.0, c - h), min(1.0, c + h)


def test_without_its_own_spread_the_slew_rate_follows_the_gain_bandwidth(designed):
    """--tol GBW alone: each build's slew rate is SR x GBW/GBW_nominal (one compensation capacitor),
    which the slew delay of the row's loop with that op-amp confirms."""
    import dataclasses
    mc = loop_monte_carlo(designed, {"R": "E24", "C": "E12"}, 10, seed=1, tol_items=["GBW=40%"], tighten=False)
    assert "SR" not in mc.values
    rows = np.genfromtxt(io.StringIO(mc.csv_text()), delimiter=",", names=True)
    amp = designed.opamp
    for row in rows[:2]:
        mine = dataclasses.replace(amp, gbw_hz=row["GBW"], slew_v_per_s=amp.slew_v_per_s * row["GBW"] / amp.gbw_hz)
        assert row["slew_delay_s"] == pytest.approx(_row_loop(designed, row, mine)[1], rel=1e-9)


def test_the_ideal_opamp_has_no_spread():
    res = design_pid(PidSpec(plant_fc_hz=3500, plant_zeta=0.2, opamp="ideal"), simulate=False)
    with pytest.raises(DesignError, match="the ideal op-amp has no slew rate"):
        loop_monte_carlo(res, {"R": "E24", "C": "E12"}, 10, tol_items=["SR=20%"])


def test_the_nominal_builds_slew_delay_is_the_design_checks():
    """The optimised LM741 loop sits at its slew budget (the make-demo reference): the Monte Carlo's
    nominal build reads the worst stage's slew delay design-pid's own slew_rate check reads (the kick
    redone on a fine grid; on the coarse step alone it read 9 % short), and so its verdict."""
    from designer.pid.model import SLEW_DELAY_FRACTION
    res = design_pid(PidSpec(plant_fc_hz=3500, plant_zeta=0.2, tuning="optimize", target_overshoot_pct=10),
                     simulate=False)
    nominal = loop_parts(res)
    f = loop_figures({k: np.array([v]) for k, v in nominal.items()}, res)
    design = max(v.slew_delay_s for v in res.analytic.levels.values())
    assert f["slew_delay_s"][0] == pytest.approx(design, rel=0.01)
    budget = SLEW_DELAY_FRACTION * res.analytic.figures.rise_time_s
    check = next(c for c in res.checks if "slew" in c.title.lower())
    assert f["slewing"][0] == float(not check.ok) == float(design > budget)
