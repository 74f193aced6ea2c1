"""``tuning="optimize"`` for a model plant (designer.pid.optimize through
design_model_pid): the limits hold on the loop as built (the E-series parts'
controller with its op-amp poles, exact margins with the dead time), its IAE is
no worse than the best rule's that meets the same limits, and the options
(min_phase_margin_deg, target_overshoot_pct, robust) do what they say."""

import numpy as np
import pytest

from designer.core import process_build
from designer.pid.delayloop import closed_loop_step, step_figures
from designer.pid.delaymargins import loop_margins
from designer.pid.model import controller_tf
from designer.pid.design import (built_controller, corner_frequencies, design_model_pid, ideal_crossover_hz,
                                       leak_limit_hz, plant_of,
                                       response_grid)
from designer.pid.selection import select_parts
from designer.pid.spec import PidSpec

ISSUE_TF = "K=2 tau=1m theta=200u"
SOPDT_TF = "K=1.5 tau1=1m tau2=300u theta=100u"
INTEGRATING_TF = "K=500 tau=100u integrator theta=100u"
#: a double pole with a short dead time: the rule table's fastest loops drive the op-amps past their swing
DOUBLE_POLE_TF = "K=1 tau1=1m tau2=1m theta=50u"


def optimized(**kw):
    return design_model_pid(PidSpec(tuning="optimize", **kw), simulate=False)


def meets(mg, limits) -> bool:
    pm_min, gm_min, ms_max = limits
    return bool(mg.stable and mg.phase_margin_deg >= pm_min and mg.gain_margin_db >= gm_min and mg.ms <= ms_max)


def built_margins(res):
    """The exact margins of the loop as built: the parts' controller around the model."""
    return loop_margins(plant_of(res.model), controller_tf(res.parts, res.opamp))


@pytest.mark.parametrize("tf, opamp, stages", [
    (ISSUE_TF, "LM741", True), (SOPDT_TF, "LM741", True), ("K=1 fn=200 zeta=0.4", "LM741", True),
    (INTEGRATING_TF, "LM741", True),
    # microsecond plants: the derivative filter's corner is held at 1/(2 pi r_min c_min) by the part bounds;
    # the LM741's difference amplifier slews on the 1 V reference step itself (2 us) whatever the gains
    ("K=2 tau=10u theta=2u", "LM741", False), ("K=2 tau=5u theta=1u", "NE5532", True),
])
def test_optimize_meets_the_default_limits_on_the_loop_as_built(tf, opamp, stages):
    res = optimized(plant_tf=tf, opamp=opamp)
    mg = built_margins(res)
    assert meets(mg, res.limits), (mg.phase_margin_deg, mg.gain_margin_db, mg.ms, res.limits)
    assert mg.ms == res.margins.ms and mg.phase_margin_deg == res.margins.phase_margin_deg
    ok = {c.id: c.ok for c in res.checks}
    assert ok["closed_loop_stable"] and ok["phase_margin"] and ok["gain_margin"] and ok["max_sensitivity"]
    assert ok["output_swing"] and (ok["slew_rate"] or not stages), [c.detail for c in res.checks if not c.ok]
    assert res.optimizer.met and "NOT all met" not in res.optimizer.message


#: a fast underdamped plant (a lab's 3.9 kHz second-order filter as identified): every rule's loop makes
#: the LM741 slew past its budget
FAST_TF = "K=1.02 fn=3.913k zeta=0.374 theta=0"


def test_optimize_keeps_every_op_amp_within_its_slew_and_swing():
    """Bug fixed: the model plant's optimiser held the margins, Ms and u's range but not the op-amps' slew:
    on this plant its LM741 loop failed the design's own slew_rate check (U6 slewing 11 us against a
    2.3 us budget); the search now holds every stage's swing and slew as the Sallen-Key optimiser does."""
    res = optimized(plant_tf=FAST_TF)
    ok = {c.id: c for c in res.checks}
    assert ok["slew_rate"].ok and ok["output_swing"].ok, ok["slew_rate"].detail
    assert res.optimizer.met and "every LM741 output within its swing and slew" in res.optimizer.message
    rules = {c.id: c.ok for c in design_model_pid(PidSpec(plant_tf=FAST_TF, tuning="chr20"), simulate=False).checks}
    assert not rules["slew_rate"]      # the limit binds: the starting rule slews


def test_the_searchs_slew_delay_equals_a_fine_grids():
    """The search's slew delay (its coarse grid, the kick redone finely) against the stages simulated
    on a grid 250 times finer: within 5 %."""
    from designer.core import opamps
    from designer.pid import blocks, model as M
    from designer.pid.design import edged, stage_waves
    from designer.pid.optimize import KICK_POINTS, SEARCH_POINTS, SEARCH_STEP_FRACTION, _Problem
    spec = PidSpec(plant_tf=FAST_TF, tuning="optimize")
    model, amp = spec.process, opamps.get(spec.opamp)
    kp, ti, td, fc = 1.6, 200e-6, 10e-6, 8e3
    t = response_grid(model, fc, SEARCH_POINTS, per_crossover=20.0)
    prob = _Problem(spec, model, amp, fc, t, False)
    out = closed_loop_step(plant_of(model), prob.controller(kp, ti, td), t, spec.step_v,
                           step_fraction=SEARCH_STEP_FRACTION)
    rise = step_figures(t, out["y"], spec.step_v).rise_time_s
    budget = M.SLEW_DELAY_FRACTION * rise
    got = (prob.stage_violation(kp, ti, td, out["y"], rise) + 0.95) * budget   # slew above its budget
    parts = blocks.continuous_parts(kp, ti, td, fc, f_integrator_hz=prob.f_i, f_differentiator_hz=prob.f_d)
    tf = np.linspace(0.0, t[-1], 250 * (t.size - 1) + 1)
    yf = np.interp(tf, t, edged(t, out["y"], spec.edge_s))
    fine = stage_waves(parts, amp, tf, M.reference(tf, spec.step_v, 0.0, spec.edge_s), yf)
    want = max(M.slew_delay(tf, v, amp.slew_v_per_s) for k, v in fine.items() if k != "y")
    assert want > 2 * budget and KICK_POINTS < SEARCH_POINTS
    assert got == pytest.approx(want, rel=0.05)


def _iae(model, ctrl, t, step_v):
    out = closed_loop_step(plant_of(model), ctrl, t, step_v)
    return step_figures(t, out["y"], step_v).iae, out["u"]


def _inside_swing(u, amp) -> bool:
    """u and its mirror on the falling edge inside the op-amp's output range."""
    uf = float(u[-1])
    hi, lo = max(float(u.max()), uf - float(u.min())), min(float(u.min()), uf - float(u.max()))
    return amp.vout_min <= lo and hi <= amp.vout_max


def _compare_with_the_rules(tf):
    res = optimized(plant_tf=tf)
    model, amp, spec = res.model, res.opamp, res.spec
    opt_ctrl = controller_tf(res.parts, amp)
    candidates = []
    for row in res.rules:
        if row.tuning is None:
            continue
        g = row.tuning
        fc = ideal_crossover_hz(model, g.kp, g.ti_s, g.td_s)
        ctrl = built_controller(g.kp, g.ti_s, g.td_s, fc, spec, amp)      # as the rule table builds it
        if meets(loop_margins(plant_of(model), ctrl), res.limits):
            # ... and as the design would build it: the same E-series parts (optimize's own are rounded)
            f_i, f_d = corner_frequencies(spec, fc, leak_limit_hz(model, g.kp, g.ti_s))
            parts = select_parts(g.kp, g.ti_s, g.td_s, fc, r_series=spec.r_series, c_series=spec.c_series,
                                 r_min=spec.r_min, r_max=spec.r_max, c_min=spec.c_min, c_max=spec.c_max,
                                 f_integrator_hz=f_i, f_differentiator_hz=f_d, tol=spec.tol).parts
            ctrl = controller_tf(parts, amp)
            candidates.append((row.rule, ctrl, fc))
    assert candidates, "no rule meets the limits: nothing to compare with"
    # one grid for all, long enough for the slowest loop to settle
    t = response_grid(model, min([fc for _, _, fc in candidates] + [built_margins(res).crossover_hz]), 4001)
    iae_opt, _ = _iae(model, opt_ctrl, t, spec.step_v)
    best = None
    for rule, ctrl, _ in candidates:
        iae, u = _iae(model, ctrl, t, spec.step_v)
        if _inside_swing(u, amp) and (best is None or iae < best[1]):
            best = (rule, iae)
    assert best is not None
    return iae_opt, best


@pytest.mark.parametrize("tf", [ISSUE_TF, SOPDT_TF, INTEGRATING_TF])
def test_optimize_is_no_worse_than_the_best_rule_meeting_the_same_limits(tf):
    iae_opt, (rule, iae_rule) = _compare_with_the_rules(tf)
    assert iae_opt <= iae_rule, (iae_opt, rule, iae_rule)


def test_optimize_on_a_double_pole_is_no_worse_than_imc():
    """Bug fixed: the search's controller has ideal op-amps, so the derivative kick it simulates (u 15.2 V
    for IMC's gains) is twice the built circuit's (7.4 V), and it ended at IAE 1.98 mV s where IMC, meeting
    every limit as built, gives 1.22 mV s; a rule that meets every limit with a smaller IAE now wins."""
    iae_opt, (rule, iae_rule) = _compare_with_the_rules(DOUBLE_POLE_TF)
    assert iae_opt <= iae_rule, (iae_opt, rule, iae_rule)


@pytest.mark.parametrize("tf", [ISSUE_TF, INTEGRATING_TF])
def test_a_higher_phase_margin_is_met_on_the_parts(tf):
    res = optimized(plant_tf=tf, min_phase_margin_deg=60)
    assert res.limits[0] == 60
    mg = built_margins(res)
    assert meets(mg, res.limits), (mg.phase_margin_deg, mg.gain_margin_db, mg.ms)
    assert next(c for c in res.checks if c.id == "phase_margin").ok


@pytest.mark.parametrize("tf", [SOPDT_TF, INTEGRATING_TF])
def test_a_target_overshoot_is_met_by_the_analytic_loop(tf):
    """Bug fixed: the search met the target on its coarse grid and the design's read 5.02 % for a 5 % target
    on the integrating plant; the target is now checked on the loop as built, Kp lowered until it holds."""
    free = optimized(plant_tf=tf)
    # 5 %, or below the free optimum where the op-amp's slew already holds it lower: the target binds
    target = min(5.0, round(0.6 * free.analytic.figures.overshoot_pct, 1))
    assert free.analytic.figures.overshoot_pct > target
    res = optimized(plant_tf=tf, target_overshoot_pct=target)
    assert res.analytic.figures.overshoot_pct <= target, res.analytic.figures.overshoot_pct
    assert meets(built_margins(res), res.limits)


def test_robust_holds_the_limits_at_every_corner_of_the_95_percent_box():
    nominal = process_build.fopdt(2.0, 1e-3, 200e-6)
    # 10 % half-widths on every parameter
    model = process_build.fopdt(2.0, 1e-3, 200e-6, ci95={k: 0.1 * v for k, v in nominal.params.items()})
    plain = optimized(plant_process=model)
    assert plain.robust is not None and len(plain.robust.corners) == 2 ** 3
    assert not all(meets(f.margins, plain.limits) for _, f in plain.robust.corners)   # the nominal loop does not
    res = optimized(plant_process=model, robust=True)
    assert res.optimizer.robust and res.optimizer.met
    assert meets(built_margins(res), res.limits)
    assert len(res.robust.corners) == 2 ** 3
    ctrl = controller_tf(res.parts, res.opamp)
    for (label, fig), corner in zip(res.robust.corners, model.corners()):
        assert corner.source.endswith(label)
        mg = loop_margins(plant_of(corner), ctrl)
        assert (mg.phase_margin_deg, mg.gain_margin_db, mg.ms) == (fig.margins.phase_margin_deg,
                                                                  fig.margins.gain_margin_db, fig.margins.ms)
        assert meets(fig.margins, res.limits), (label, fig.margins.phase_margin_deg, fig.margins.gain_margin_db,
                                                fig.margins.ms)
    assert all(c.ok for c in res.checks if c.id.startswith("robust_"))
