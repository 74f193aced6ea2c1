"""From a plant and a tuning choice to a sized, checked and SPICE-verified
op-amp PID controller: the orchestration behind ``design-pid``.

:func:`design_pid` takes a :class:`~designer.pid.spec.PidSpec` (valid by
construction) and returns a :class:`~designer.pid.result.PidResult`; its
``to_dict`` is the JSON of ``design-pid --json`` and ``result.json``. The
steps: the plant as built (designed, given or read), its reaction curve (the
tangent of its exact step, :func:`designer.pid.tuning.model_reaction_curve`),
the gains (a rule of :mod:`designer.pid.rules` on the FOPDT the rule takes,
through :func:`designer.pid.tuning.tune`; explicit; or optimised on the loop
as built), the parts
(:mod:`.blocks`, chosen by :mod:`.selection`), the analytic closed loop with
the op-amp poles (:mod:`.model`), the checks, the deck (:mod:`.netlist`) and
its simulation (:mod:`.verify`).

A plant known only as a model, G(s) = N(s)/D(s) e^(-theta s) (an identified
process from ``identify`` or ``identify-freq``, a typed transfer function, a
design-plant result read as its model, or a registered circuit's own model),
goes through :func:`design_model_pid`, behind ``design-pid
--plant-tf/--plant-model/--plant-capture/--plant-topology``. The steps, as for
the Sallen-Key plant above:

1. the rules of :mod:`designer.pid.rules` on the model each intends (every one,
   side by side, with the reason where one does not apply), or the optimiser
   (:mod:`designer.pid.optimize`), or explicit gains;
2. the parts (:func:`designer.pid.selection.select_parts`), the integrator leak at
   fc/100 and the derivative filter at 10 fc, fc the crossover of the rule's
   ideal loop (as fn/100 and 10 fn for a Sallen-Key plant);
3. the loop as built: the realised controller (op-amp poles, leak, filter:
   :func:`designer.pid.model.controller_tf`) around the model with its exact
   dead time, in the frequency domain (:func:`designer.pid.delaymargins.loop_margins`:
   phase, gain and delay margins, Ms, stability by the argument principle) and
   in time (:func:`designer.pid.delayloop.closed_loop_step`, the reference's
   edge applied exactly as a moving average of the step response); every
   op-amp output from the error by each stage's own transfer function;
4. the checks (parts, margins, Ms, slew and swing, the ranges the plant accepts
   and delivers), and at the corners of the model's 95 % intervals the worst
   phase margin and overshoot;
5. the deck with the model as native elements and a matched line for the dead
   time (:func:`designer.pid.netlist.model_loop_deck`) and its simulation, judged
   as for a Sallen-Key plant (:func:`designer.pid.verify.run_and_compare`).
"""

from __future__ import annotations

import math
import time
from dataclasses import dataclass, replace

import numpy as np

from ..core import opamps
from ..core.checks import Check
from ..core.checks import listing
from ..core.errors import DesignError, ParamError
from ..core.i18n import N_, Message
from ..core.lti import dominant_pair, response_span, step_response
from ..core.metrics import StepMetrics
from ..core.opamps import OpAmp
from ..core.units import format_eng
from ..plant.bench import recommend_square_wave
from ..spice.deck import SquareTest
from . import blocks, rules, selection, tuning
from . import model as M
from .delayloop import closed_loop_step, pid_tf
from .delaymargins import loop_margins
from .loopchecks import designators, named, spice_notes, stage_checks, steady_state_check
# the model loop's figures live in modelloop (the optimiser's too); re-exported here, where they were
from .modelloop import (FAR_FACTOR, LEAK_LOOP_GAIN, TABLE_STEP_FRACTION, built_controller,  # noqa: F401
                        corner_frequencies, edged, ideal_crossover_hz, leak_limit_hz, limits, loop_dc_gain,
                        loop_figures, plant_of, response_grid, simulation_controller, size, stage_waves)
from .netlist import closed_loop_deck, controller_netlist, loop_netlist, model_loop_deck
from .process_notes import opamp_speed_notes, sizing_notes
from .result import Achieved, AnalyticLoop, PidResult, RobustCheck, RuleRow, Waveforms
from .spec import PidSpec
from .verify import explain, loop_metrics, run_and_compare

__all__ = ["PidSpec", "SEED_BENCH_PLANT", "analyse", "analyze_pid", "built_controller", "closed_loop_step", "ideal_pair",
           "corner_frequencies", "design_model_pid", "design_pid", "edged", "ideal_crossover_hz", "leak_limit_hz",
           "loop_dc_gain", "plant_of", "response_grid", "run_spice", "simulation_controller", "stage_waves"]

#: phase margin below which the loop is called under-damped on the bench
MIN_PHASE_MARGIN_DEG = 30.0
#: checks that fail when the gains do not suit the op-amps (then the optimiser is suggested)
LIMITS = ("closed_loop_stable", "phase_margin", "slew_rate", "output_swing")


# ---- plant ------------------------------------------------------------------

def resolve_plant(spec: PidSpec):
    """(circuit, description, series) of the Sallen-Key plant as the generic record
    (:func:`designer.pid.plant.sallen_key_plant`; every plant source as a
    :class:`~designer.pid.plant.Plant`: :func:`designer.pid.plant.resolve_plant`)."""
    from .plant import sallen_key_plant
    return sallen_key_plant(spec)


def plant_model(plant, amp: OpAmp | None = None):
    """The plant's (num, den) as built, with its op-amp's finite gain and
    gain-bandwidth unless ideal, for any circuit plant: each section's own
    op-amp-aware model (:meth:`designer.filters.topology.Topology.opamp_model`:
    the nodal solution, or a section's closed forms, the Sallen-Key low-pass's
    seed 001 IV.3-IV.9; ideal: its coefficients), multiplied.

    Parameters
    ----------
    plant : designer.pid.plant.Plant or designer.pid.plant.PlantCircuit
        The plant (:func:`designer.pid.netlist.plant_circuit`).
    amp : OpAmp, optional
        The op-amp of its sections (None: ideal).

    Returns
    -------
    tuple of ndarray
        (num, den), highest power first (num without leading zeros).
    """
    from .netlist import plant_circuit
    circuit = plant_circuit(plant)[0]
    num, den = np.array([1.0]), np.array([1.0])
    for st in circuit.stages:
        if amp is None or amp.ideal:
            n, d = st.topology.coefficients(st.values)
        else:
            n, d = st.topology.opamp_model(st.values, amp)
        num, den = np.polymul(num, np.trim_zeros(np.asarray(n, float), "f")), np.polymul(den, np.asarray(d, float))
    return num, den


def ideal_pair(plant) -> tuple:
    """(fn in Hz, zeta) of the plant's ideal model: its circuit's
    (:meth:`designer.pid.plant.PlantCircuit.ideal_pair`: a section's own hook,
    :meth:`designer.filters.topology.Topology.ideal_pair`, else the slowest pole pair
    of the cascade's ideal denominator).

    Parameters
    ----------
    plant : designer.pid.plant.Plant or designer.pid.plant.PlantCircuit
        The plant.

    Returns
    -------
    tuple of float
        (fn_hz, zeta).
    """
    from .netlist import plant_circuit
    return plant_circuit(plant)[0].ideal_pair()


@dataclass(frozen=True)
class PlantStep:
    """The plant as built, with its op-amp: model, dominant pair, and its step (the reaction curve)."""

    num: np.ndarray
    den: np.ndarray
    fn_hz: float            #: of the dominant pair
    zeta: float
    span_s: float           #: long enough to see the step settle
    t: np.ndarray
    y: np.ndarray
    curve: tuning.ReactionCurve


def plant_step(plant, amp: OpAmp) -> PlantStep:
    """The plant as built with its op-amp (:func:`plant_model`), its dominant
    pair and its step on a grid long enough to settle, with the reaction curve
    the rules take (:func:`designer.pid.tuning.model_reaction_curve`).

    Parameters
    ----------
    plant : designer.pid.plant.Plant or designer.pid.plant.PlantCircuit
        Any circuit plant.
    amp : OpAmp
        The op-amp of its sections.

    Returns
    -------
    PlantStep
    """
    pn, pd = plant_model(plant, amp)
    fn_o, z_o = dominant_pair(pd)
    fn, zeta = ideal_pair(plant)
    span = response_span(min(fn, fn_o), min(zeta, z_o))
    # the plant as built's step (an LTI step: the closed form) on a dense grid, for the fit and the plot;
    # the tangent from its exact step, as the rules take it on every model (designer.pid.rules)
    t = np.linspace(0.0, span, 20001)
    y = step_response(pn, pd, t)
    curve = tuning.model_reaction_curve(pn, pd, t, y)
    return PlantStep(pn, pd, fn_o, z_o, span, t, y, curve)


# ---- the flow ----------------------------------------------------------------

def design_pid(spec: PidSpec, simulate: bool = True, simulator: str = "pyspice", rules_spice: bool = False,
               before_spice=None) -> PidResult:
    """Tune, size, check, and (unless ``simulate`` is False) verify in SPICE.

    Parameters
    ----------
    spec : PidSpec
        The request (validated when it was built).
    simulate : bool
        Run the closed-loop deck in ngspice.
    simulator : str
        ``"pyspice"`` (ngspice's shared library) or ``"ngspice-cli"``.
    rules_spice : bool
        A model plant: simulate every rule's loop too (the rule table's SPICE overshoot).
    before_spice : callable, optional
        A model plant: called with the result just before its SPICE run
        (:func:`designer.pid.design.design_model_pid`).

    Returns
    -------
    PidResult
        One type for every plant; for a plant given as a model (``spec.plant.process``)
        its model fields are set (:func:`designer.pid.design.design_model_pid`).
    """
    if spec.plant.process is not None:
        return design_model_pid(spec, simulate, simulator, rules_spice, before_spice)
    return _run(spec, simulate, simulator, as_built=False)


def analyze_pid(spec: PidSpec, simulate: bool = True, simulator: str = "pyspice", opamp=None) -> PidResult:
    """The controller as built from its parts (``spec.controller_parts``), on
    its plant: what Kp, Ti and Td the parts give, the same checks, analytic
    loop and SPICE verification as :func:`design_pid`, and the same result.

    Without gains in the spec (``kp``/``ti_s``/``td_s`` or a ``tuning``
    rule) the parts' own gains are the tuning (method ``as-built``) and the
    Kp/Ti/Td accuracy checks, which would compare the parts with themselves,
    are left out; with them, the parts are held to those gains. ``opamp``: an
    :class:`~designer.core.opamps.OpAmp` in place of ``spec.opamp``'s catalogue entry (a
    Monte Carlo build's, its gain-bandwidth and slew rate drawn: ``--replay``).

    Parameters
    ----------
    spec : PidSpec
        With ``controller_parts``.
    simulate : bool
        Run the closed-loop deck in ngspice.
    simulator : str
        ``"pyspice"`` or ``"ngspice-cli"``.
    opamp : designer.core.opamps.OpAmp, optional
        In place of ``spec.opamp``'s catalogue entry.

    Returns
    -------
    PidResult

    Raises
    ------
    ParamError
        When the spec has no controller parts.
    """
    if spec.controller_parts is None:
        raise ParamError("analyze_pid needs the controller's parts ({controller_parts})", ("controller_parts",))
    if spec.plant.process is not None:
        return design_model_pid(spec, simulate, simulator, opamp=opamp)
    return _run(spec, simulate, simulator, as_built=spec.kp is None and spec.tuning is None, opamp=opamp)


def _run(spec: PidSpec, simulate: bool, simulator: str, as_built: bool, opamp=None) -> PidResult:
    clock = _Clock()
    amp = opamp or opamps.get(spec.opamp)
    plant, source, plant_series = resolve_plant(spec)
    ps = plant_step(plant, amp)
    curve = ps.curve
    rules = tuple(tuning.all_rules(curve))
    notes = []
    opt = presized = None
    clock.lap("plant_s")
    if as_built:
        p = spec.controller_parts
        tun = tuning.Tuning("as-built", p.kp, p.ti_s, p.td_s, curve, ())
    elif spec.kp is not None:
        tun = tuning.Tuning("explicit", spec.kp, spec.ti_s, spec.td_s, curve, ())
    elif spec.tuning == "optimize":
        tun, opt, presized = _optimize(spec, plant, amp, ps)
        notes.append(Message(N_("optimize: {message} after {n} closed-loop evaluations"), message=opt.message,
                             n=str(opt.evaluations)))
    else:
        tun = tuning.tune(spec.tuning or "zn", curve)
    notes += list(tun.notes)
    if tun.method == "zn":
        notes.append(Message(N_("ZN reaction curve: inflection at {t}, L = {l}, T = {tt} (from L to where the tangent "
                                "reaches the final value, {t_final}; the seed used that absolute time as T)"),
                             t=format_eng(curve.t_inflection_s, 's'), l=format_eng(curve.L_s, 's'),
                             tt=format_eng(curve.T_s, 's'), t_final=format_eng(curve.t_tangent_final_s, 's')))
    clock.lap("tuning_s")
    if spec.controller_parts is not None:
        parts, sel = spec.controller_parts, None
        targets = {"kp": tun.kp, "ti_s": tun.ti_s, "td_s": tun.td_s}
    else:
        sel = presized or _select(spec, tun, plant)
        parts, targets = sel.parts, sel.targets
        notes += sel.notes
    static = blocks.static_checks(parts, plant.fn_hz, amp.gbw_hz, targets, r_min=spec.r_min,
                                  r_max=spec.r_max, c_min=spec.c_min, c_max=spec.c_max, tol=spec.tol)
    if as_built:
        # the gains are the parts' own (accuracy would compare the parts with themselves), and the
        # part bounds are the sizing search's: neither says anything about parts already chosen
        static = [c for c in static if not c.id.endswith("_accuracy") and not c.id.endswith("_bounds")]
    clock.lap("sizing_s")
    loop = _analyse(spec, plant, amp, tun, parts, ps, simulate)
    checks = tuple(static) + loop.checks
    if not amp.ideal and any(not c.ok for c in checks if c.id in LIMITS):
        notes.append(Message(N_("to have gains chosen for the loop as built with {opamp}s (stable with the op-amp "
                                "poles, every op-amp inside its swing and slew rate for this step): --tuning optimize "
                                "--target-overshoot P"), opamp=amp.name))
    waves = Waveforms(loop.t, loop.r, loop.waves, loop.y_ideal, loop.y_open, loop.bode_w, loop.loop_gain, ps.t, ps.y,
                      None if curve.fit is None else curve.fit.step(ps.t))
    res = PidResult(spec=spec, plant=plant, plant_source=source, plant_series=plant_series,
                    plant_fn_opamp_hz=ps.fn_hz, plant_zeta_opamp=ps.zeta, opamp=amp, tuning=tun, rules=rules,
                    optimizer=opt, parts=parts, selection=sel, achieved=Achieved.of(parts, amp, tun), checks=checks,
                    analytic=loop.analytic, ideal_pid=loop.ideal, margins=loop.margins, test=loop.test,
                    expected_final_v=loop.expected, deck=loop.deck, waveforms=waves, notes=notes,
                    package=spec.package)
    clock.lap("analytic_s")
    if simulate:
        run_spice(res, simulator)
        clock.lap("simulation_s")
    else:
        res.notes.append(N_("SPICE simulation skipped (--no-sim): the closed-loop figures are analytic only"))
    res.scope = loop_scope(res)
    res.diff_amp = M.diff_amp_balance(parts, amp, ps.num, ps.den, loop.bode_w, loop.analytic.dc_gain)
    if simulate and _same(parts, blocks.seed_bench_parts()) and _same_circuit(plant, SEED_BENCH_PLANT):
        res.seed_bench = seed_bench_finding(res, spec, simulator)
    res.timings = clock.laps
    return res


def _same(a, b) -> bool:
    """Two part sets equal to rounding (values typed as text parse to the nearest float)."""
    from dataclasses import fields
    for f in fields(a):
        x, y = getattr(a, f.name), getattr(b, f.name)
        if (x is None) != (y is None) or (x is not None and not math.isclose(x, y, rel_tol=1e-9)):
            return False
    return True


def _same_circuit(a, b) -> bool:
    """Two plant circuits of the same sections with their values equal to rounding."""
    return len(a.stages) == len(b.stages) and all(
        x.topology is y.topology and x.values.keys() == y.values.keys()
        and all(math.isclose(v, y.values[k], rel_tol=1e-9) for k, v in x.values.items())
        for x, y in zip(a.stages, b.stages))


def _seed_bench_plant():
    """The seed's plant as built (001, V.13: R1 = 805 Ohm; its list swaps the C1/C2 names): the follower's
    network in its declared order (input resistor, resistor to +in, capacitor to ground, feedback capacitor)."""
    from ..filters.cascade import Stage
    from ..filters.sallen_key_lowpass_parts import section_of
    from .plant import PlantCircuit, seed_loop_names
    section = section_of(with_gain=False)
    return PlantCircuit((Stage(section, dict(zip(section.designators, (805.0, 1e3, 10e-9, 220e-9)))),),
                        seed_loop_names(section))


#: the seed's plant as built, as the generic record (designer.pid.plant.PlantCircuit)
SEED_BENCH_PLANT = _seed_bench_plant()
#: the test amplitudes the seed-bench finding simulates (volts): small enough to stay linear, and the seed's 2 V
SEED_BENCH_STEPS = (0.5, 2.0)


@dataclass(frozen=True)
class SeedBenchFinding:
    """Why the tool's prediction for the seed's as-built controller (001, V.13)
    differs from what the thesis measured: the loop as named here, the loop with
    the trimmed divider on the feedback input instead (R17 and R18 exchanged), the
    latter with the seed's own LM741 figures, and SPICE runs of it at a small and
    at the seed's 2 V amplitude. ``runs``: (op-amp, step V) -> (analytic stable,
    phase margin deg, SPICE stable, SPICE saturated, SPICE final V, expected final V)."""

    thesis: dict
    runs: dict

    def to_dict(self) -> dict:
        return {"thesis": self.thesis,
                "runs": [{"opamp": k[0], "step_v": k[1], "analytic_stable": v[0], "phase_margin_deg": v[1],
                          "spice_stable": v[2], "spice_saturated": v[3], "spice_final_v": v[4],
                          "expected_final_v": v[5]} for k, v in self.runs.items()]}


def seed_bench_finding(res: PidResult, spec: PidSpec, simulator: str) -> SeedBenchFinding:
    """The runs behind :class:`SeedBenchFinding`: the divider on the feedback input,
    with the catalogue's LM741 and with the seed's (``LM741-seed``), at each of
    :data:`SEED_BENCH_STEPS` (each a full analysis with its SPICE run)."""
    from dataclasses import replace
    swapped = replace(res.parts, r17=res.parts.r18, r18=res.parts.r17)
    runs = {}
    for amp in dict.fromkeys((res.opamp.name, "LM741-seed")):
        for step in SEED_BENCH_STEPS:
            r = _run(replace(spec, controller_parts=swapped, opamp=amp, step_v=step), True, simulator,
                     as_built=spec.kp is None and spec.tuning is None)
            s = r.spice
            runs[(amp, step)] = (r.analytic.stable, r.margins.phase_margin_deg, s.stable, s.saturated,
                                 s.figures.final_value, r.expected_final_v)
    return SeedBenchFinding(dict(blocks.THESIS_BENCH), runs)


def loop_scope(res: PidResult):
    """The scope for the loop's bench test (seed 001, Figures 79-90): CH1 on the
    reference, CH2 on the plant output and then on each op-amp output in turn, each
    channel's volts/div (1-2-5) fitting what SPICE shows there (the analytic levels
    when not simulated; the rails for an unstable analytic loop), and the time base
    showing 1.2 settling times after the edge (at most the half period)."""
    from ..plant.bench import channel, scope_setup
    test, amp = res.test, res.opamp
    rails = (amp.vout_min, amp.vout_max) if not amp.ideal else (amp.vee, amp.vcc)
    levels = {}
    for ref, role, sig in M.OPAMP_OUTPUTS:
        got = (res.spice.stages.get(role) if res.spice is not None else None) or res.analytic.levels.get(role)
        if got is not None:
            levels[sig] = (ref, got.v_min, got.v_max)
        elif sig != "vd" or res.parts.has_derivative:
            levels[sig] = (ref, *rails)
    ts = res.spice.figures.settling_time_s if res.spice is not None else res.analytic.figures.settling_time_s
    window = min(1.2 * ts, test.half_period_s) if ts is not None and math.isfinite(ts) else test.half_period_s
    chans = [channel("CH1", N_("reference r"), 0.0, test.amplitude_v)]
    chans.append(channel("CH2", "y", *levels["y"][1:]))
    chans += [channel("CH2", sig, lo, hi) for sig, (_, lo, hi) in levels.items() if sig != "y"]
    return scope_setup(window, test.amplitude_v / 2, chans)


class _Clock:
    """Seconds per phase of a run (``timings`` of the result)."""

    def __init__(self):
        self.laps, self._tick = {}, time.perf_counter()

    def lap(self, name: str) -> None:
        now = time.perf_counter()
        self.laps[name], self._tick = now - self._tick, now


def _select(spec, tun, plant):
    return selection.select_parts(tun.kp, tun.ti_s, tun.td_s, plant.fn_hz, r_series=spec.r_series,
                               c_series=spec.c_series, r_min=spec.r_min, r_max=spec.r_max,
                               c_min=spec.c_min, c_max=spec.c_max, f_integrator_hz=spec.f_integrator_hz,
                               f_differentiator_hz=spec.f_differentiator_hz, tol=spec.tol)


def _optimize(spec, plant, amp, ps):
    """Optimise on unrounded parts, size with E-series parts, and check the
    sized circuit in the same model; if rounding pushed it over the slew or
    swing budget, optimise again with a wider margin (at most three rounds)."""
    from . import optimize as O

    def context(points):
        return O.Context(ps.num, ps.den, amp, plant.fn_hz, spec.step_v, spec.edge_s,
                         np.linspace(0.0, 0.6 * ps.span_s, points), spec.target_overshoot_pct,
                         spec.target_settling_s, spec.f_integrator_hz, spec.f_differentiator_hz)

    ctx, fine = context(2001), context(20001)
    # starting points only: ZN's gains and the gentler CHR 0 % formulas on the same
    # tangent (half ZN's Kp, Ti = T); they bracket a working loop even for an underdamped
    # plant, where the rules on the fitted FOPDT can start from an unstable one
    starts = []
    for rule in ("zn", "chr0"):
        r = tuning.tune(rule, ps.curve.tangent)
        starts.append((r.kp, r.ti_s, r.td_s if r.td_s > 0 else 0.3 * ps.curve.L_s))
    evaluations = 0
    for attempt in range(3):
        res = O.optimize(ctx, starts)
        evaluations += res.evaluations
        b = res.best
        sel = _select(spec, tuning.Tuning("optimize", b.kp, b.ti_s, b.td_s), plant)
        # the optimiser's coarse grid under-reads short slewing: check the sized
        # circuit on the fine grid the final checks use
        sized = O.evaluate_parts(sel.parts, fine)
        if not res.met or O.meets(sized, fine):
            break
        ctx.slew_limit *= 0.85
        ctx.swing_limit *= 0.9
        starts = [(b.kp, b.ti_s, b.td_s)]
    res.evaluations, res.sized, res.rounds = evaluations, sized, attempt + 1
    note = Message(N_("optimize: target overshoot <= {os} %{ts} for a {step} V step with {opamp} limits"),
                   os=f"{spec.target_overshoot_pct:g}", step=f"{spec.step_v:g}", opamp=amp.name,
                   ts="" if spec.target_settling_s is None else Message(N_(", settling <= {ts}"),
                                                                         ts=format_eng(spec.target_settling_s, 's')))
    return tuning.Tuning("optimize", b.kp, b.ti_s, b.td_s, ps.curve, (note,)), res, sel


@dataclass(frozen=True)
class _Loop:
    """What :func:`_analyse` finds of the closed loop (the parts of the result it fills)."""

    analytic: AnalyticLoop
    ideal: StepMetrics
    margins: M.Margins
    checks: tuple
    test: SquareTest
    expected: float
    deck: str
    t: np.ndarray
    r: np.ndarray
    waves: dict
    y_ideal: np.ndarray
    y_open: np.ndarray
    bode_w: np.ndarray
    loop_gain: np.ndarray


def _analyse(spec, plant, amp, tun, parts, ps, simulate=True) -> _Loop:
    pn, pd, span = ps.num, ps.den, ps.span_s
    lm = M.assemble(parts, amp, pn, pd)
    stable = lm.stable()
    # closed-loop DC gain y/r from the state-space model (the integrator leaks)
    iy = M.SIGNALS.index("y")
    try:
        dc_cl = float(-(lm.c[iy] @ np.linalg.solve(lm.a, lm.b)).item() + lm.d[iy, 0])
    except np.linalg.LinAlgError:
        dc_cl = math.nan
    # the settled output every figure and the deck's .meas levels refer to (verify.loop_metrics)
    expected = spec.step_v * dc_cl if math.isfinite(dc_cl) and dc_cl > 0 else spec.step_v
    # a first look on a long grid for the settling time, to size the square wave
    t_long = np.linspace(0.0, span, 8001)
    ts = None
    if stable:
        w_long = lm.simulate(t_long, M.reference(t_long, 1.0, 0.0, spec.edge_s))
        ts = loop_metrics(t_long, w_long["y"], expected / spec.step_v).settling_time_s
    if ts is None or math.isnan(ts):
        ts = span / 2
    f_lo = min(parts.f_integrator_hz, plant.fn_hz) / 20
    f_hi = max(amp.gbw_hz if not amp.ideal else 0.0, 100 * plant.fn_hz)
    w = 2 * np.pi * np.logspace(np.log10(f_lo), np.log10(f_hi), 4000)
    gain = M.loop_gain(parts, amp, pn, pd, w)
    # Ms refined on the loop's own transfer function (op-amp poles included, as the margins)
    mg = M.margins(w, gain, lambda x: M.loop_gain(parts, amp, pn, pd, x))
    # the loop's fastest time scale (plant or crossover) bounds the simulation step, so that a
    # slow --square-freq cannot hide the response between time steps (as for the plant)
    f_fast = max(plant.fn_hz, mg.crossover_hz if math.isfinite(mg.crossover_hz) else 0.0)
    time_scale = 1.0 / (2 * math.pi * f_fast)
    sq = recommend_square_wave(ts, spec.step_v, spec.square_hz, time_scale_s=time_scale)
    hp = sq.half_period_s
    test = SquareTest(spec.step_v, sq.frequency_hz, sq.delay_s, spec.edge_s, time_scale_s=time_scale)
    if simulate:
        test.check_simulable()
    # the rising half period, or its start when the square wave is much slower than the loop
    t = np.linspace(0.0, min(hp, 10 * max(span, ts)), 20001)
    r = M.reference(t, spec.step_v, 0.0, spec.edge_s)
    rails = 2 * max(abs(amp.vcc), abs(amp.vee))
    waves = lm.simulate(t, r) if stable else _diverging(lm, t, r, rails)
    il = M.ideal_loop(tun.kp, tun.ti_s, tun.td_s, *plant_model(plant))
    y_ideal = (il.simulate(t, r) if il.stable() else _diverging(il, t, r, rails))["y"]
    # the plant alone, for the plot: the edged reference needs the state-space simulation
    y_open = M.state_space(pn, pd).simulate(t, r)["y"]
    figures = loop_metrics(t, waves["y"], expected)
    ideal = loop_metrics(t, y_ideal, spec.step_v)   # a true integrator: no steady-state error
    rise = figures.rise_time_s if math.isfinite(figures.rise_time_s) and figures.rise_time_s else hp / 20
    names = designators(parts, plant, amp, spec.package)
    levels = M.waveform_limits(waves, t, amp, M.SLEW_DELAY_FRACTION * rise) if stable else {}
    levels = named(levels, names)
    checks = _dynamic_checks(stable, lm, levels, mg, dc_cl, amp, spec.step_v, rise, parts, names.get)
    title = (f"PID closed loop Kp={parts.kp:.4g} Ti={parts.ti_s:.4g}s Td={parts.td_s:.4g}s "
             f"plant fn={plant.fn_hz:.5g}Hz zeta={plant.zeta:.4g} op-amp={amp.name}")
    deck = closed_loop_deck(parts, plant, amp, test, title, expected)
    return _Loop(AnalyticLoop(figures, stable, dc_cl, levels), ideal, mg, tuple(checks), test, expected, deck,
                 t, r, waves, y_ideal, y_open, w, gain)


def _diverging(lm, t, r, limit):
    """Waveforms of an unstable loop, cut where they leave +/-``limit`` volts (plots only)."""
    with np.errstate(all="ignore"):
        w = lm.simulate(t, r)
    for k, v in w.items():
        bad = ~np.isfinite(v) | (np.abs(v) > limit)
        if np.any(bad):
            v = v.copy()
            v[np.argmax(bad):] = np.nan
            w[k] = v
    return w


def _dynamic_checks(stable, lm, levels, mg, dc_cl, amp, step_v, rise, parts, name_of=str) -> list:
    """Stability, phase margin, steady-state error, slew rate and output swing of the analytic loop."""
    out = []
    poles = lm.poles()
    worst = float(np.max(poles.real)) if poles.size else -math.inf
    out.append(Check.of("closed_loop_stable", True, N_("all closed-loop poles in the left half plane")) if stable
               else Check.of("closed_loop_stable", False, N_("a closed-loop pole has real part {re} 1/s: the loop "
                                                             "oscillates or latches at a rail"), re=f"{worst:+.4g}"))
    pm = mg.phase_margin_deg
    close = []
    if math.isfinite(pm) and not amp.ideal:
        fc = mg.crossover_hz
        close = [(N_("{stage} {f}"), {"stage": k, "f": format_eng(v, 'Hz')})
                 for k, v in sorted(parts.stage_bandwidths(amp.gbw_hz).items(), key=lambda kv: kv[1]) if v < 10 * fc]
        if parts.has_derivative and parts.f_differentiator_hz < 10 * fc:
            close.append((N_("derivative filter {f}"), {"f": format_eng(parts.f_differentiator_hz, 'Hz')}))
    ok = bool(math.isfinite(pm) and pm >= MIN_PHASE_MARGIN_DEG)
    margin = dict(pm=f"{pm:.3g}", fc=format_eng(mg.crossover_hz, 'Hz'), min=f"{MIN_PHASE_MARGIN_DEG:g}")
    if not math.isfinite(pm):
        out.append(Check.of("phase_margin", ok, N_("the loop gain never crosses 1")))
    elif close:
        out.append(Check.of("phase_margin", ok, N_("{pm} deg at {fc} with the op-amp poles (want >= {min} deg); poles "
                                                   "within 10x of the crossover, each costing phase there: {poles}"),
                            poles=listing(", ", close), **margin))
    else:
        out.append(Check.of("phase_margin", ok, N_("{pm} deg at {fc} with the op-amp poles (want >= {min} deg)"),
                            **margin))
    return out + steady_state_check(dc_cl) + stage_checks(stable, levels, amp, step_v, rise, parts, name_of)


def run_spice(res: PidResult, simulator: str) -> None:
    """Simulate the deck, compare, detect saturation and oscillation; fills
    ``spice``, ``verdict`` and the notes of ``res`` (a model plant's by its own rule).

    Parameters
    ----------
    res : PidResult
        The design, analysed.
    simulator : str
        ``"pyspice"`` or ``"ngspice-cli"``.

    Returns
    -------
    None
    """
    if res.model is not None:
        return run_model_spice(res, simulator)
    w = res.waveforms
    sp = run_and_compare(res.deck, simulator, w.t, res.test.delay_s, w.analytic["y"],
                         res.test.amplitude_v, res.expected_final_v, res.opamp)
    res.spice = sp = replace(sp, stages=named(sp.stages, designators(res.parts, res.plant, res.opamp,
                                                                      res.package)))
    res.verdict = explain(sp, res.analytic.figures, res.checks)
    res.notes += spice_notes(sp, res.verdict, res.expected_final_v)


# ==== a plant known as a model =====================================================


#: the rules tried, in order, when none is named: the first that applies is the default
DEFAULT_RULES = ("amigo", "simc", "imc")
#: analytic samples over the rising half period (as for a Sallen-Key plant)
POINTS = 20001


@dataclass(frozen=True)
class Gains:
    """The gains being built, how they were chosen, and the rule's record (or None)."""

    method: str
    kp: float
    ti_s: float
    td_s: float
    rule: rules.RuleTuning | None = None


# ---- the flow -------------------------------------------------------------------

def choose_gains(spec: PidSpec, model, reduced, amp, table) -> tuple:
    """(Gains, optimizer result or None, notes) for the spec."""
    if spec.controller_parts is not None and spec.kp is None and spec.tuning is None:
        p = spec.controller_parts
        return Gains("as-built", p.kp, p.ti_s, p.td_s), None, []
    if spec.kp is not None:
        return Gains("explicit", spec.kp, spec.ti_s, spec.td_s), None, []
    if spec.tuning == "optimize":
        from .optimize import optimize_model_loop
        opt = optimize_model_loop(spec, model, amp, table)
        return (Gains("optimize", opt.kp, opt.ti_s, opt.td_s), opt, [opt.message])
    if spec.tuning is not None:
        rt = check_gains(rules.tune_model(reduced, spec.tuning, tauc_s=spec.simc_tauc_s, lambda_s=spec.imc_lambda_s))
        return Gains(rt.rule, rt.kp, rt.ti_s, rt.td_s, rt), None, []
    for row in table:
        if row.tuning is not None and row.reason is None and row.rule in DEFAULT_RULES:
            rt = row.tuning
            return (Gains(rt.rule, rt.kp, rt.ti_s, rt.td_s, rt), None,
                    [Message(N_("rule {rule} (the first of {rules} that applies to this model; --tuning names "
                                "another, --tuning optimize meets margins and Ms)"), rule=rt.rule,
                             rules=", ".join(DEFAULT_RULES))])
    # the tangent rules share one reason: each said once
    reasons = list(dict.fromkeys(r.reason for r in table if r.reason))
    raise DesignError("no tuning rule applies to this model (" + "; ".join(reasons)
                      + "); give --kp, --ti and --td", param="tuning")


def check_gains(rt):
    """A rule's gains inside what the circuit takes (:data:`designer.core.ranges.RANGES` of kp, ti_s,
    td_s), else a one-line refusal naming the rule (a dead time of 1e-144 s makes SIMC's Kp 1e143)."""
    from ..core.ranges import RANGES
    for key, value, label in (("kp", rt.kp, "Kp"), ("ti_s", rt.ti_s, "Ti"), ("td_s", rt.td_s, "Td")):
        try:
            RANGES[key].check(value, label)
        except DesignError as exc:
            raise DesignError(f"{rt.rule}: its {exc} (the circuit's range): this model is outside what the "
                              "rule is for") from None
    return rt


def rule_table(spec, model, reduced, amp) -> tuple:
    """Every rule of :data:`designer.pid.rules.RULES` on the model: its gains and
    the figures of its loop as it would be built (or why it does not apply)."""
    rows = []
    for r in rules.all_rules(reduced, tauc_s=spec.simc_tauc_s, lambda_s=spec.imc_lambda_s):
        if isinstance(r, tuple):
            rows.append(RuleRow(r[0], None, r[1], None))
            continue
        try:
            check_gains(r)
            fc = ideal_crossover_hz(model, r.kp, r.ti_s, r.td_s)
            ctrl = built_controller(r.kp, r.ti_s, r.td_s, fc, spec, amp)
            rows.append(RuleRow(r.rule, r, None, loop_figures(model, ctrl, r.kp, r.ti_s, r.td_s,
                                                                response_grid(model, fc), spec.step_v)))
        except DesignError as exc:   # gains outside what the circuit can be sized for
            rows.append(RuleRow(r.rule, r, str(exc), None))
    return tuple(rows)


def design_model_pid(spec: PidSpec, simulate: bool = True, simulator: str = "pyspice",
                     rules_spice: bool = False, before_spice=None, opamp=None) -> PidResult:
    """Tune, size, check and (unless ``simulate`` is False) verify in SPICE a PID
    for ``spec.plant.process``, a plant known only as a model.

    Parameters
    ----------
    spec : PidSpec
        With a model plant (``spec.plant.process`` not None).
    simulate : bool
        Run the closed-loop deck in ngspice.
    simulator : str
        ``"pyspice"`` or ``"ngspice-cli"``.
    rules_spice : bool
        Also simulate every applicable rule's loop, sized as this one is, for the
        rule table's SPICE overshoot (one more ngspice run per rule).
    before_spice : callable, optional
        Called with the result, analysed but not yet simulated, just before the
        SPICE run (a command starts drawing the pictures that need no SPICE then).
    opamp : designer.core.opamps.OpAmp, optional
        In place of ``spec.opamp``'s catalogue entry (a Monte Carlo build's).

    Returns
    -------
    PidResult
    """
    from .reduction import from_process
    tick = time.perf_counter()
    laps = {}

    def lap(name):
        nonlocal tick
        now = time.perf_counter()
        laps[name], tick = now - tick, now

    model = spec.plant.process
    amp = opamp or opamps.get(spec.opamp)   # a Monte Carlo build's own (--replay), or the catalogue's
    reduced = from_process(model)
    table = rule_table(spec, model, reduced, amp)
    gains, opt, notes = choose_gains(spec, model, reduced, amp, table)
    if gains.rule is not None:
        notes = notes + list(gains.rule.notes)
    lap("tuning_s")
    # the optimiser sized its loop with the corners of its start's crossover: build those
    fc = opt.fc_hz if opt is not None else ideal_crossover_hz(model, gains.kp, gains.ti_s, gains.td_s)
    f_i, f_d = ((opt.f_integrator_hz, opt.f_differentiator_hz) if opt is not None
                else corner_frequencies(spec, fc, leak_limit_hz(model, gains.kp, gains.ti_s)))
    if spec.controller_parts is not None:
        parts, sel = spec.controller_parts, None
        targets = {"kp": gains.kp, "ti_s": gains.ti_s, "td_s": gains.td_s}
    else:
        sel = size(spec, gains.kp, gains.ti_s, gains.td_s, fc, f_i, f_d)
        parts, targets = sel.parts, sel.targets
        notes += sel.notes + sizing_notes(sel, spec)
    static = blocks.static_checks(parts, fc, amp.gbw_hz, targets, r_min=spec.r_min, r_max=spec.r_max,
                                  c_min=spec.c_min, c_max=spec.c_max, tol=spec.tol, fn_name="fc")
    if gains.method == "as-built":
        static = [c for c in static if not c.id.endswith("_accuracy") and not c.id.endswith("_bounds")]
    lap("sizing_s")
    loop = analyse(spec, model, amp, parts, gains, fc, simulate)
    notes += opamp_speed_notes(amp, loop.margins, loop.ideal_margins, limits(spec)[0], gains.method == "optimize")
    robust = robust_check(spec, model, loop.controller, loop.t, gains) if model.ci95 else None
    checks = tuple(static) + loop.checks + (robust.checks() if robust is not None else ())
    res = PidResult(
        spec=spec, model=model, reduced=reduced, opamp=amp, method=gains.method, kp=gains.kp, ti_s=gains.ti_s,
        td_s=gains.td_s, rule=gains.rule, rules=table, optimizer=opt, parts=parts, selection=sel,
        achieved=Achieved.of(parts, amp, gains), fc_ref_hz=fc, checks=checks, margins=loop.margins,
        ideal_margins=loop.ideal_margins, ideal_pid=loop.ideal_figures,
        analytic=AnalyticLoop(loop.figures, loop.margins.stable, loop.dc, loop.levels), robust=robust,
        test=loop.test, expected_final_v=loop.expected, deck=loop.deck,
        waveforms=loop.waves, notes=list(notes), package=spec.package, limits=limits(spec),
        plant=None if spec.plant.circuit is None else spec.plant.circuit.circuit)   # a circuit's generic record
    lap("analytic_s")
    if before_spice is not None:
        before_spice(res)
    if simulate:
        run_model_spice(res, simulator)
        if rules_spice:
            res.rules = rules_in_spice(res, simulator)
        lap("simulation_s")
    else:
        res.notes.append(N_("SPICE simulation skipped (--no-sim): the closed-loop figures are analytic only"))
    res.scope = model_loop_scope(res)
    res.timings = laps
    return res


def model_loop_scope(res: PidResult):
    """The bench scope for the loop (as :func:`designer.pid.design.loop_scope`): CH1
    the reference, CH2 the plant output y and then each op-amp output in turn,
    volts/div fitting what SPICE (else the analytic loop) shows there, 1.2 settling
    times on screen (at most the half period)."""
    from ..plant.bench import channel, scope_setup
    test, amp = res.test, res.opamp
    rails = (amp.vout_min, amp.vout_max) if not amp.ideal else (amp.vee, amp.vcc)
    y = res.waveforms.analytic["y"]
    if res.spice is not None and "y" in res.spice.waves:
        y = res.spice.waves["y"]
    y_lo, y_hi = (float(np.nanmin(y)), float(np.nanmax(y))) if np.any(np.isfinite(y)) else rails
    chans = [channel("CH1", N_("reference r"), 0.0, test.amplitude_v), channel("CH2", "y", y_lo, y_hi)]
    for ref, role, sig in M.OPAMP_OUTPUTS:
        got = (res.spice.stages.get(role) if res.spice is not None else None) or res.levels.get(role)
        if got is not None:
            chans.append(channel("CH2", sig, got.v_min, got.v_max))
        elif role != "plant" and (sig != "vd" or res.parts.has_derivative):
            chans.append(channel("CH2", sig, *rails))
    ts = res.spice.figures.settling_time_s if res.spice is not None else res.analytic.figures.settling_time_s
    window = min(1.2 * ts, test.half_period_s) if ts is not None and math.isfinite(ts) else test.half_period_s
    return scope_setup(window, test.amplitude_v / 2, chans)


@dataclass(frozen=True)
class _ModelLoop:
    controller: tuple
    margins: object
    ideal_margins: object
    ideal_figures: object
    figures: object
    dc: float
    levels: dict
    checks: tuple
    test: SquareTest
    expected: float
    deck: str
    t: np.ndarray
    waves: Waveforms


def analyse(spec, model, amp, parts, gains, fc, simulate) -> _ModelLoop:
    """The loop as built around the model: margins, time response, every stage, checks, deck.

    Parameters
    ----------
    spec : PidSpec
        The request (a model plant).
    model : designer.core.process.ProcessModel
        The plant.
    amp : designer.core.opamps.OpAmp
        The op-amp of every stage.
    parts : designer.pid.blocks.PidParts
        The controller as built.
    gains : Gains
        The gains the parts are for.
    fc : float
        The ideal loop's crossover (Hz): the scale of the time grids and the bench test.
    simulate : bool
        Whether the deck will be simulated (its notes say so).

    Returns
    -------
    _ModelLoop
    """
    ctrl = M.controller_tf(parts, amp)
    plant = plant_of(model)
    mg = loop_margins(plant, ctrl)
    ideal_mg = loop_margins(plant, pid_tf(gains.kp, gains.ti_s, gains.td_s))
    dc = loop_dc_gain(model, ctrl)
    expected = spec.step_v * dc
    sim_ctrl = simulation_controller(ctrl, max(fc, mg.crossover_hz if math.isfinite(mg.crossover_hz) else fc))
    # a first look on a long grid, for the settling time that sizes the square wave
    t_long = response_grid(model, mg.crossover_hz if math.isfinite(mg.crossover_hz) else fc, 4001)
    ts = None
    if mg.stable:
        y_long = closed_loop_step(plant, sim_ctrl, t_long, 1.0, step_fraction=TABLE_STEP_FRACTION)["y"]
        ts = loop_metrics(t_long, y_long, dc).settling_time_s
    if ts is None or not math.isfinite(ts):
        ts = t_long[-1] / 2
    f_fast = max(fc, mg.crossover_hz if math.isfinite(mg.crossover_hz) else 0.0)
    time_scale = 1.0 / (2 * math.pi * f_fast)
    sq = recommend_square_wave(ts, spec.step_v, spec.square_hz, time_scale_s=time_scale)
    test = SquareTest(spec.step_v, sq.frequency_hz, sq.delay_s, spec.edge_s, time_scale_s=time_scale)
    if simulate:
        test.check_simulable()
    t = np.linspace(0.0, min(test.half_period_s, 10 * max(t_long[-1], ts)), POINTS)
    r = M.reference(t, spec.step_v, 0.0, spec.edge_s)
    if mg.stable:
        step = closed_loop_step(plant, sim_ctrl, t, spec.step_v)
        y = edged(t, step["y"], spec.edge_s)
        if spec.plant.circuit is not None and spec.plant.circuit.reversed_action:
            # r and y exchanged at the difference amplifier: every controller stage is its own for (y, r)
            waves = {**stage_waves(parts, amp, t, y, r), "y": y}
        else:
            waves = stage_waves(parts, amp, t, r, y)
    else:
        waves = {k: np.full(t.size, np.nan) for k in M.SIGNALS if k != "vd" or parts.has_derivative}
    ideal = pid_tf(gains.kp, gains.ti_s, gains.td_s, 10.0 if gains.td_s > 0 else None)
    y_ideal = (edged(t, closed_loop_step(plant, ideal, t, spec.step_v)["y"], spec.edge_s)
               if loop_margins(plant, ideal).stable else np.full(t.size, np.nan))
    y_open = edged(t, spec.step_v * model.step(t), spec.edge_s)
    figures = loop_metrics(t, waves["y"], expected)
    # the ideal PID has a true integrator: it settles on the step itself
    ideal_figures = loop_metrics(t, y_ideal, spec.step_v) if np.all(np.isfinite(y_ideal)) else None
    rise = figures.rise_time_s if math.isfinite(figures.rise_time_s) and figures.rise_time_s else t[-1] / 20
    names = designators(parts, None, amp, spec.package, loop_netlist_of(spec, parts))
    levels = M.waveform_limits({k: v for k, v in waves.items() if k != "y"}, t, amp,
                               M.SLEW_DELAY_FRACTION * rise) if mg.stable else {}
    levels = named(levels, names)
    checks = loop_checks(spec, mg, dc, amp, levels, waves, t, parts) + stage_checks(
        mg.stable, levels, amp, spec.step_v, rise, parts, names.get)
    title = (f"PID closed loop Kp={parts.kp:.4g} Ti={parts.ti_s:.4g}s Td={parts.td_s:.4g}s "
             f"plant {model.text()} op-amp={amp.name}")
    deck = loop_deck(spec, parts, model, amp, test, title, expected)
    lo, hi = min(fc, mg.crossover_hz if math.isfinite(mg.crossover_hz) else fc) / 100, 100 * f_fast
    bode_w = 2 * np.pi * np.logspace(np.log10(lo), np.log10(hi), 2000)
    from .delaymargins import loop_response
    wf = Waveforms(t, r, waves, y_ideal, y_open, bode_w, loop_response(plant, ctrl, bode_w), t_long,
                   model.step(t_long), None)
    return _ModelLoop(ctrl, mg, ideal_mg, ideal_figures, figures, dc, levels, tuple(checks), test, expected, deck, t, wf)


def loop_netlist_of(spec: PidSpec, parts):
    """The loop's part and net table as built: the controller alone around a
    model plant, or with the plant's own circuit (:func:`~designer.pid.netlist.loop_netlist`).

    Parameters
    ----------
    spec : PidSpec
        The request (its ``circuit``, if any).
    parts : designer.pid.blocks.PidParts
        The controller.

    Returns
    -------
    designer.spice.deck.Netlist
        The table the board, the BOM and the schematic are written from.
    """
    if spec.plant.circuit is not None:
        return loop_netlist(parts, spec.plant.circuit)
    return controller_netlist(parts)


def loop_deck(spec: PidSpec, parts, model, amp, test, title: str, expected: float) -> str:
    """The loop's deck: the model as native elements
    (:func:`~designer.pid.netlist.model_loop_deck`), or the plant's circuit
    (:func:`~designer.pid.netlist.closed_loop_deck`).

    Parameters
    ----------
    spec, parts : PidSpec, designer.pid.blocks.PidParts
        As for :func:`loop_netlist_of`.
    model : designer.core.process.ProcessModel
        The plant's model (a model plant's deck is written from it).
    amp : designer.core.opamps.OpAmp
        The op-amps.
    test : designer.spice.deck.SquareTest
        The reference square wave.
    title : str
        The deck's title.
    expected : float
        The settled output the ``.meas`` levels refer to, volts.

    Returns
    -------
    str
        The deck.
    """
    if spec.plant.circuit is not None:
        return closed_loop_deck(parts, spec.plant.circuit, amp, test, title, expected)
    return model_loop_deck(parts, model, amp, test, title, expected)


def loop_checks(spec, mg, dc, amp, levels, waves, t, parts) -> list:
    """Stability, phase and gain margins, Ms, steady-state error and the plant's ranges."""
    pm_min, gm_min, ms_max = limits(spec)
    out = [Check.of("closed_loop_stable", mg.stable,
                    N_("no closed-loop root in the right half plane (argument principle, exact dead time)"))
           if mg.stable else
           Check.of("closed_loop_stable", False, N_("{n} closed-loop roots in the right half plane: the loop "
                                                    "oscillates or runs to a rail"), n=f"{mg.rhp_roots:g}")]
    pm = mg.phase_margin_deg
    out.append(Check.of("phase_margin", math.isfinite(pm) and pm >= pm_min,
                        N_("{pm} deg at {fc} with the op-amp poles and the dead time (want >= {pm_min} deg; delay "
                           "margin {dm})"), pm=f"{pm:.3g}", fc=format_eng(mg.crossover_hz, 'Hz'), pm_min=f"{pm_min:g}",
                        dm=format_eng(mg.delay_margin_s, 's'))
               if math.isfinite(pm) else Check.of("phase_margin", False, N_("the loop gain never crosses 1")))
    gm = mg.gain_margin_db
    out.append(Check.of("gain_margin", gm >= gm_min, N_("{gm} dB at {f180} (want >= {gm_min} dB)"), gm=f"{gm:.3g}",
                        f180=format_eng(mg.phase_crossover_hz, 'Hz'), gm_min=f"{gm_min:g}")
               if math.isfinite(gm) else
               Check.of("gain_margin", gm >= gm_min, N_("the phase never reaches -180 deg (want >= {gm_min} dB)"),
                        gm_min=f"{gm_min:g}"))
    out.append(Check.of("max_sensitivity", mg.ms <= ms_max,
                        N_("Ms = {ms} at {f} (want <= {ms_max}; 1/Ms = {inv} is the distance of the Nyquist curve "
                           "from -1)"), ms=f"{mg.ms:.3g}", f=format_eng(mg.ms_hz, 'Hz'), ms_max=f"{ms_max:g}",
                        inv=f"{1 / mg.ms:.3g}"))
    out += steady_state_check(dc)
    for key, sig, what in (("plant_input", "u", N_("input (the controller's output u)")),
                           ("plant_output", "y", N_("output y"))):
        rng = getattr(spec.plant, key)
        if rng is None or not mg.stable:
            continue
        v = np.asarray(waves[sig], float)
        vf = float(v[-1])
        vmax, vmin = max(float(v.max()), vf - float(v.min())), min(float(v.min()), vf - float(v.max()))
        ok = vmin >= rng[0] - 1e-9 and vmax <= rng[1] + 1e-9
        out.append(Check.of(f"{key}_range", ok, N_("the plant's {what} spans {lo} V to {hi} V over the square wave "
                                                   "(rising and falling edge); it accepts {lo_ok} V to {hi_ok} V{fix}"),
                            what=what, lo=f"{vmin:.3g}", hi=f"{vmax:.3g}", lo_ok=f"{rng[0]:g}", hi_ok=f"{rng[1]:g}",
                            fix="" if ok else N_(": lower --step or the gains (a softer rule, --tuning optimize)")))
    return out


def robust_check(spec, model, controller, t, gains) -> RobustCheck:
    """The loop as built at every corner of the model's 95 % box: the worst phase
    margin, gain margin, Ms and overshoot, and the corner where each is reached."""
    pm_min, gm_min, ms_max = limits(spec)
    rows = []
    for corner in model.corners():
        fig = loop_figures(corner, controller, gains.kp, gains.ti_s, gains.td_s, t[:: max(1, t.size // 4000)],
                           spec.step_v)
        rows.append((corner.source.rsplit("corner ", 1)[-1], fig))
    return RobustCheck(tuple(rows), pm_min, gm_min, ms_max)


def rules_in_spice(res: PidResult, simulator: str) -> tuple:
    """The rule table with each applicable, stable rule's SPICE overshoot: its
    gains sized as the design's were (same series, bounds and corner rules), its
    deck on the same bench test, the deck's own ``overshoot_pct`` measurement."""
    from ..spice.simulate import get_simulator
    spec, sim, out = res.spec, get_simulator(simulator), []
    for row in res.rules:
        if row.figures is None or not row.figures.margins.stable:
            out.append(row)
            continue
        r = row.tuning
        fc = ideal_crossover_hz(res.model, r.kp, r.ti_s, r.td_s)
        f_i, f_d = corner_frequencies(spec, fc, leak_limit_hz(res.model, r.kp, r.ti_s))
        try:
            parts = size(spec, r.kp, r.ti_s, r.td_s, fc, f_i, f_d).parts
        except DesignError:
            out.append(row)
            continue
        expected = spec.step_v * loop_dc_gain(res.model, M.controller_tf(parts, res.opamp))
        deck = loop_deck(spec, parts, res.model, res.opamp, res.test, f"rule {r.rule}", expected)
        got = sim.run(deck).measurements.get("overshoot_pct")
        out.append(replace(row, spice_overshoot_pct=None if got is None else float(got)))
    return tuple(out)


def run_model_spice(res: PidResult, simulator: str) -> None:
    """Simulate the deck, compare with the analytic loop; fills ``spice``,
    ``verdict`` and the notes."""
    w = res.waveforms
    sp = run_and_compare(res.deck, simulator, w.t, res.test.delay_s, w.analytic["y"], res.test.amplitude_v,
                         res.expected_final_v, res.opamp)
    stages = {k: v for k, v in sp.stages.items() if k != "plant"}   # y is the model's, not an op-amp's
    res.spice = sp = replace(sp, stages=named(stages, designators(res.parts, None, res.opamp, res.package,
                                                                     loop_netlist_of(res.spec, res.parts))))
    res.verdict = explain(sp, res.analytic.figures, res.checks)
    res.notes += spice_notes(sp, res.verdict, res.expected_final_v)
