"""``--tuning optimize`` for every plant: Kp, Ti and Td by numerical
optimisation on the closed loop as it will be built.

For the Sallen-Key plant (:func:`optimize`): the realised blocks (leaky
integrator, filtered derivative), the op-amps' finite gain-bandwidth, and the
op-amps' limits for the actual reference step. This replaces the seed's trial-and-error "x10" step.

The search minimises the ITAE of the step response (a smooth stand-in for
"fast and well damped") subject to, as penalties:

* overshoot at most ``target_overshoot_pct``;
* 2 % settling time at most ``target_settling_s`` (when given);
* every op-amp output inside its swing for the whole square wave, and slewing
  delaying no stage by more than 5 % of the closed-loop rise time
  (:func:`designer.pid.model.waveform_limits`);
* a stable loop.

Nelder-Mead in log(Kp, Ti, Td) from several rule-based starts, inside the
ranges design-pid accepts for given gains (``designer.core.ranges``: kp, ti_s,
td_s); the gains are then sized with E-series parts and checked again by the
caller.

For a plant known as a model (:func:`optimize_model_loop`): the gains that
minimise the IAE of the reference step (or meet ``--target-overshoot``) on the loop as built, with
its phase margin, gain margin and maximum sensitivity held to the spec's
limits (default 45 deg, 6 dB, Ms 1.7) and every op-amp and the plant's input
inside their ranges; with ``--robust`` the margins and Ms hold at every corner
of the model's 95 % box too.

The loop as built is the realised controller (op-amp poles, the integrator's
leak at fc/100 and the derivative filter at 10 fc, fc fixed from the starting
rule's crossover) around the model with its exact dead time. Search, on log Kp,
log Ti, log Td (log Kp, log Ti for a PI start) from the best applicable rule,
the constraints as penalties: first the largest integral gain Kp/Ti inside the
margins and Ms (MIGO, Astrom and Hagglund: the IE of a load step is Ti/Kp;
the margins and Ms on a fixed frequency grid, the dead time's phase -w theta
added exactly to the rational part's unwrapped phase; milliseconds an
evaluation), then Nelder-Mead on the IAE of the simulated reference step from
there (:func:`designer.pid.delayloop.closed_loop_step`, a coarse grid), with
the overshoot target, the controller's output range and, with a real op-amp,
every op-amp output inside its swing and slewing for at most 5 % of the rise
time (the design's own ``slew_rate`` and ``output_swing`` checks, on the
stages of the unrounded circuit, as the Sallen-Key plant's search holds them,
:func:`evaluate_parts`); a rule whose loop beats the search's IAE wins
only when it holds them too. The search's
controller is the circuit's with ideal op-amps in closed form; the result is
checked on the exact margins of the loop as built, op-amp poles included
(:func:`designer.pid.delaymargins.loop_margins`); where the search was
optimistic Kp is lowered until the exact figures hold.
"""

from __future__ import annotations

import math
from dataclasses import dataclass, field

import numpy as np
from scipy import optimize as sopt

from ..core.errors import DesignError
from ..core.i18n import N_, Message
from ..core.metrics import step_metrics
from ..core.opamps import OpAmp
from ..core.ranges import RANGES
from ..core.units import format_eng
from . import blocks, model as M
from .delayloop import closed_loop_step, step_figures
from .delaymargins import loop_margins

__all__ = ["Context", "KICK_POINTS", "ModelOptimizeResult", "SEARCH_POINTS", "SEARCH_STEP_FRACTION", "evaluate",
           "optimize", "optimize_model_loop", "slew_delay_stages"]

#: the search box, log(Kp, Ti, Td): the ranges design-pid accepts for given gains
BOX_LO = np.log([RANGES["kp"].lo, RANGES["ti_s"].lo, RANGES["td_s"].lo])
BOX_HI = np.log([RANGES["kp"].hi, RANGES["ti_s"].hi, RANGES["td_s"].hi])


@dataclass
class Context:
    """What every evaluation needs; ``t`` is the uniform grid (from the step)."""

    plant_num: np.ndarray
    plant_den: np.ndarray
    opamp: OpAmp
    fn_hz: float
    step_v: float
    edge_s: float
    t: np.ndarray
    target_overshoot_pct: float
    target_settling_s: float | None = None
    f_integrator_hz: float | None = None
    f_differentiator_hz: float | None = None
    #: penalties start at these fractions of the swing and slew budgets (margin for part rounding)
    swing_limit: float = 0.98
    slew_limit: float = 0.95
    #: ITAE of the plant alone for the same reference: the cost's unit
    itae_ref: float = 1.0

    def __post_init__(self):
        r = M.reference(self.t, self.step_v, 0.0, self.edge_s)
        # the edged reference is no pure step: the plant's state-space simulation (exact for it)
        y = M.state_space(self.plant_num, self.plant_den).simulate(self.t, r)["y"]
        e = np.abs(r - y) / abs(self.step_v)
        self.itae_ref = max(float(np.trapezoid(self.t * e, self.t)), 1e-30)


@dataclass
class Evaluation:
    kp: float
    ti_s: float
    td_s: float
    cost: float
    stable: bool
    overshoot_pct: float = math.nan
    settling_time_s: float = math.nan
    rise_time_s: float = math.nan
    swing_ratio: float = math.nan    #: worst |peak| / allowed (<= 1 is inside)
    slew_ratio: float = math.nan     #: worst slew delay / budget (<= 1 is fine)

    def to_dict(self) -> dict:
        return {k: (None if isinstance(v, float) and not math.isfinite(v) else v)
                for k, v in self.__dict__.items()}


@dataclass
class OptimizeResult:
    """The search's outcome: the best point, whether it meets the targets, and
    where each start ended; ``sized`` and ``rounds`` are filled in by the caller
    that sizes the gains with E-series parts (:func:`designer.pid.design.design_pid`)."""

    best: Evaluation
    met: bool
    evaluations: int
    starts: list = field(default_factory=list)   #: the Evaluation each start ended at
    message: str = ""
    sized: Evaluation | None = None               #: the best gains built from E-series parts
    rounds: int = 1

    def to_dict(self) -> dict:
        out = {"met": self.met, "evaluations": self.evaluations, "message": self.message,
               "best": self.best.to_dict(), "starts": [e.to_dict() for e in self.starts]}
        if self.sized is not None:
            out.update(sized=self.sized.to_dict(), rounds=self.rounds)
        return out


def evaluate(kp: float, ti: float, td: float, ctx: Context) -> Evaluation:
    """Cost and figures of one (Kp, Ti, Td) on the realised closed loop
    (unrounded parts, :func:`designer.pid.blocks.continuous_parts`).

    Parameters
    ----------
    kp : float
        Proportional gain.
    ti : float
        Integral time (s).
    td : float
        Derivative time (s).
    ctx : Context
        The plant, the op-amp, the step and the targets.

    Returns
    -------
    Evaluation
    """
    parts = blocks.continuous_parts(kp, ti, td, ctx.fn_hz, f_integrator_hz=ctx.f_integrator_hz,
                                    f_differentiator_hz=ctx.f_differentiator_hz)
    return evaluate_parts(parts, ctx, (kp, ti, td))


def evaluate_parts(parts, ctx: Context, gains=None) -> Evaluation:
    """Cost and figures of a controller built from ``parts``."""
    kp, ti, td = gains if gains is not None else (parts.kp, parts.ti_s, parts.td_s)
    lm = M.assemble(parts, ctx.opamp, ctx.plant_num, ctx.plant_den)
    if not lm.stable():
        worst = float(np.max(lm.poles().real))   # 1/s, capped below: more than any stable loop costs
        return Evaluation(kp, ti, td, 1e3 + 10.0 * min(worst, 100.0), False)
    r = M.reference(ctx.t, ctx.step_v, 0.0, ctx.edge_s)
    w = lm.simulate(ctx.t, r)
    y = w["y"]
    try:
        m = step_metrics(ctx.t, y, initial=0.0)
    except DesignError:  # a flat response: no figures
        return Evaluation(kp, ti, td, 1e3, True)
    e = np.abs(r - y) / abs(ctx.step_v)
    itae = float(np.trapezoid(ctx.t * e, ctx.t)) / ctx.itae_ref
    rise = m.rise_time_s if math.isfinite(m.rise_time_s) else ctx.t[-1]
    lim = M.waveform_limits(w, ctx.t, ctx.opamp, M.SLEW_DELAY_FRACTION * rise)
    amp = ctx.opamp
    if amp.ideal:
        swing, slew = 0.0, 0.0
    else:
        swing = max(max(v.v_max / amp.vout_max, v.v_min / amp.vout_min) for v in lim.values())
        slew = max(v.slew_delay_s for v in lim.values()) / (M.SLEW_DELAY_FRACTION * rise)
    cost = itae
    cost += 0.2 * max(0.0, m.overshoot_pct - ctx.target_overshoot_pct + 0.2) ** 2
    cost += 100.0 * max(0.0, swing - ctx.swing_limit) ** 2 + 100.0 * max(0.0, slew - ctx.slew_limit) ** 2
    ts = m.settling_time_s
    if not math.isfinite(ts):
        cost += 10.0
        ts = math.nan
    elif ctx.target_settling_s is not None:
        cost += 20.0 * max(0.0, ts / ctx.target_settling_s - 1.0) ** 2
    return Evaluation(kp, ti, td, cost, True, m.overshoot_pct, ts, m.rise_time_s, swing, slew)


def meets(ev: Evaluation, ctx: Context) -> bool:
    ok = ev.stable and ev.overshoot_pct <= ctx.target_overshoot_pct + 0.25
    ok = ok and (ctx.opamp.ideal or (ev.swing_ratio <= 1.0 and ev.slew_ratio <= 1.0))
    if ctx.target_settling_s is not None:
        ok = ok and math.isfinite(ev.settling_time_s) and ev.settling_time_s <= ctx.target_settling_s
    return bool(ok)


def optimize(ctx: Context, starts, maxiter: int = 120) -> OptimizeResult:
    """Minimise the cost from each (Kp, Ti, Td) in ``starts``; the best point wins.
    The targets in ``ctx`` are taken as valid (:class:`designer.pid.spec.PidSpec` checks them).

    Parameters
    ----------
    ctx : Context
        The plant, the op-amp, the step and the targets.
    starts : iterable of tuple
        (Kp, Ti, Td) starting points (the rules' gains).
    maxiter : int
        Nelder-Mead iterations per start.

    Returns
    -------
    OptimizeResult
    """
    count = 0
    cache = {}

    def f(x):
        nonlocal count
        key = tuple(np.round(x, 9))
        if key not in cache:
            count += 1
            kp, ti, td = np.exp(np.clip(x, -700, 700))
            if np.any(x < BOX_LO) or np.any(x > BOX_HI):
                # outside the gains and times design-pid accepts (designer.core.ranges): no loop
                # to simulate, a cost that grows with the distance back into the box
                out = float(np.sum(np.maximum(BOX_LO - x, 0.0) + np.maximum(x - BOX_HI, 0.0)))
                cache[key] = Evaluation(float(kp), float(ti), float(td), 1e6 * (1.0 + out), False)
            else:
                cache[key] = evaluate(float(kp), float(ti), float(td), ctx)
        return cache[key].cost

    results = []
    for kp0, ti0, td0 in starts:
        x0 = np.log([kp0, ti0, max(td0, 1e-3 * ti0)])
        sol = sopt.minimize(f, x0, method="Nelder-Mead",
                            options={"maxiter": maxiter, "xatol": 2e-3, "fatol": 1e-5,
                                     "initial_simplex": x0 + np.vstack([np.zeros(3), 0.4 * np.eye(3)])})
        f(sol.x)
        results.append(cache[tuple(np.round(sol.x, 9))])
    # a stable loop that misses an unreachable target beats an unstable one, whatever the penalties
    pool = ([e for e in results if meets(e, ctx)] or [e for e in results if e.stable]
            or [e for e in cache.values() if e.stable] or results)
    best = min(pool, key=lambda e: e.cost)
    met = meets(best, ctx)
    msg = (N_("targets met") if met else
           N_("targets not met: the best compromise is reported (see the checks); relax the overshoot or "
              "settling target, lower --step, or choose a faster op-amp"))
    return OptimizeResult(best, met, count, results, msg)


# ==== a model plant's loop ==================================================================

#: evaluations of the search at most
MAX_EVALUATIONS = 30
#: evaluations of the frequency-only first stage at most
FREQUENCY_EVALUATIONS = 300
#: frequency grid of the constraints: points per decade, decades either side of fc
GRID_PER_DECADE, GRID_DECADES = 80, 3
#: time grid of the step in the search
SEARCH_POINTS = 801
#: the search's simulation step (:func:`designer.pid.delayloop.closed_loop_step`): about 2.5e-3 of the step
SEARCH_STEP_FRACTION = 0.1
#: the search's record: this many times 1/wc (a loop with 45 deg of margin has settled by 10/wc)
SEARCH_SPAN = 20.0
#: the stage limits' penalties start at these fractions of the swing and the slew budget (a margin for
#: the coarse grid and the parts' rounding), as the Sallen-Key optimiser's
SWING_LIMIT, SLEW_LIMIT = 0.98, 0.95
#: the op-amps' phase lag (deg) up to 3 fc from which the frequency constraints count it (:meth:`_Problem.opamp_poles_at`)
OPAMP_LAG_DEG = 2.0
#: points of the fine grid over the reference's kick (:meth:`_Problem.stage_violation`)
KICK_POINTS = 401


def slew_delay_stages(t_fine, v_fine, t, v, slew_v_per_s: float, edge_s: float) -> float:
    """The slew delay (:func:`designer.pid.model.slew_delay`) of a stage output known on
    a fine grid ``t_fine`` over the kick and on the coarse ``t`` after it; the fine grid's
    first step, which holds the reference's edge, counts as the edge's length.

    Parameters
    ----------
    t_fine, v_fine : numpy.ndarray
        The fine grid over the kick (s) and the output on it (V).
    t, v : numpy.ndarray
        The coarse grid (s) and the output on it (V).
    slew_v_per_s : float
        The op-amp's slew rate.
    edge_s : float
        The reference's edge (s).

    Returns
    -------
    float
        The delay (s).
    """
    dv = np.abs(np.diff(v_fine))
    dt = np.diff(t_fine)
    if edge_s > 0:
        dt[0] = min(dt[0], edge_s)
    k = int(np.searchsorted(t, t_fine[-1], side="right"))
    kick = float(np.sum(np.maximum(0.0, dv - slew_v_per_s * dt))) / slew_v_per_s
    return kick + M.slew_delay(np.r_[t_fine[-1], t[k:]], np.r_[v_fine[-1], v[k:]], slew_v_per_s)


@dataclass
class ModelOptimizeResult:
    """The optimiser's gains, its start, the figures it reached, and what it did."""

    kp: float
    ti_s: float
    td_s: float
    start_rule: str
    fc_hz: float
    iae: float
    overshoot_pct: float
    met: bool
    evaluations: int
    message: str
    robust: bool
    f_integrator_hz: float = math.nan     #: the corners the search built (the design keeps them)
    f_differentiator_hz: float = math.nan

    def to_dict(self) -> dict:
        return {"kp": self.kp, "ti_s": self.ti_s, "td_s": self.td_s, "start_rule": self.start_rule,
                "fc_hz": self.fc_hz, "iae": self.iae, "overshoot_pct": self.overshoot_pct, "met": self.met,
                "evaluations": self.evaluations, "message": self.message, "robust": self.robust,
                "f_integrator_hz": self.f_integrator_hz, "f_differentiator_hz": self.f_differentiator_hz}


class _Problem:
    """Everything one evaluation needs, computed once."""

    def __init__(self, spec, model, amp, fc_hz, t, robust, leak_hz=None):
        from .modelloop import corner_frequencies, limits, plant_of
        self.spec, self.model, self.amp, self.fc = spec, model, amp, fc_hz
        self.pm_min, self.gm_min, self.ms_max = limits(spec)
        self.f_i, self.f_d = corner_frequencies(spec, fc_hz, leak_hz)
        self.w = 2 * np.pi * fc_hz * np.logspace(-GRID_DECADES, GRID_DECADES, 2 * GRID_DECADES * GRID_PER_DECADE + 1)
        self.s = 1j * self.w
        plants = [model] + (list(model.corners()) if robust else [])
        self.plants = [plant_of(p) for p in plants]
        self.p_rat = [np.polyval(n, self.s) / np.polyval(d, self.s) for n, d, _ in self.plants]
        self.t = t
        self.step_v = spec.step_v
        lo, hi = (amp.vout_min, amp.vout_max) if not amp.ideal else (-math.inf, math.inf)
        if spec.plant.plant_input is not None:
            lo, hi = max(lo, spec.plant.plant_input[0]), min(hi, spec.plant.plant_input[1])
        self.u_range = (lo, hi)
        self.evaluations = 0
        self.reference = M.reference(t, spec.step_v, 0.0, spec.edge_s)
        self.opamp_lag = 1.0   #: the op-amps' part of the controller's response (:meth:`opamp_poles_at`)
        #: whether :meth:`evaluate` counts the op-amps' swing and slew (:meth:`stage_violation`)
        self.stages = True

    def built(self, kp, ti, td):
        """The controller as built (op-amp poles included): the E-series parts the design
        selects for these gains (the same call), else before rounding."""
        from .modelloop import size
        try:
            parts = size(self.spec, kp, ti, td, self.fc, self.f_i, self.f_d).parts
        except DesignError:
            parts = blocks.continuous_parts(kp, ti, td, self.fc, f_integrator_hz=self.f_i,
                                            f_differentiator_hz=self.f_d)
        return M.controller_tf(parts, self.amp)

    def controller(self, kp, ti, td):
        """The search's controller: the circuit's with ideal op-amps, in closed form,
        Kp [1 + 1/(Ti (s + wi)) + Td s/(1 + s/wd)] (leak wi, derivative filter wd);
        the op-amp poles, far above the crossover, enter at the exact check."""
        a, b = 2 * math.pi * self.f_i, 2 * math.pi * self.f_d
        if td <= 0:
            return kp * np.array([1.0, a + 1.0 / ti]), np.array([1.0, a])
        num = np.array([1.0 / b + td, 1.0 + a / b + 1.0 / (ti * b) + td * a, a + 1.0 / ti])
        return kp * num, np.array([1.0 / b, 1.0 + a / b, a])

    def opamp_poles_at(self, kp, ti, td) -> None:
        """Let the frequency constraints see the op-amps' poles as they are at these gains:
        the ratio of the circuit's controller with its real op-amps to the closed form on
        the grid, applied to every later candidate (the lag barely moves with the gains
        nearby; the exact margins of the loop as built decide at the end). Without it a
        plant within a decade of the op-amp's bandwidth gets a loop its op-amps make
        unstable."""
        if self.amp.ideal:
            return
        parts = blocks.continuous_parts(kp, ti, td, self.fc, f_integrator_hz=self.f_i, f_differentiator_hz=self.f_d)
        real, ideal = M.controller_tf(parts, self.amp), self.controller(kp, ti, td)
        lag = ((np.polyval(real[0], self.s) / np.polyval(real[1], self.s))
               / (np.polyval(ideal[0], self.s) / np.polyval(ideal[1], self.s)))
        # where the op-amps cost under OPAMP_LAG_DEG up to 3 fc the closed form stands (the search's
        # path stays the one it was for every plant well below the op-amps' bandwidth)
        near = self.w <= 3 * 2 * math.pi * self.fc
        self.opamp_lag = lag if np.max(np.abs(np.degrees(np.angle(lag[near])))) >= OPAMP_LAG_DEG else 1.0

    def frequency_violation(self, ctrl) -> float:
        """Sum of the relative violations of PM, GM and Ms over every plant (0: all met)."""
        c = np.polyval(ctrl[0], self.s) / np.polyval(ctrl[1], self.s) * self.opamp_lag
        total = 0.0
        for (_, _, theta), pr in zip(self.plants, self.p_rat):
            lr = c * pr
            mag = np.abs(lr)
            phase = np.unwrap(np.angle(lr)) - self.w * theta
            # the unwrapped phase starts where it should: within (-pi, pi] at the lowest frequency... shifted
            phase -= 2 * np.pi * np.round((phase[0] - np.angle(lr[0])) / (2 * np.pi))
            lj = mag * np.exp(1j * phase)
            ms = float(np.max(1 / np.abs(1 + lj)))
            total += max(0.0, ms / self.ms_max - 1) * 5
            down = np.nonzero((mag[:-1] >= 1) & (mag[1:] < 1))[0]
            if down.size:
                k = down[0]
                f = (mag[k] - 1) / (mag[k] - mag[k + 1])
                pm = math.degrees(math.pi + phase[k] + f * (phase[k + 1] - phase[k]))
                total += max(0.0, (self.pm_min - pm) / max(self.pm_min, 1.0))
            cross = np.nonzero((phase[:-1] > -np.pi) & (phase[1:] <= -np.pi))[0]
            if cross.size:
                k = cross[0]
                f = (phase[k] + np.pi) / (phase[k] - phase[k + 1])
                gm = -20 * math.log10(max(mag[k] + f * (mag[k + 1] - mag[k]), 1e-300))
                total += max(0.0, (self.gm_min - gm) / max(self.gm_min, 1.0))
        return total

    def stage_violation(self, kp, ti, td, y, rise_s, corners=None) -> float:
        """How far the op-amp outputs pass their swing and slew budgets (0: within; an ideal
        op-amp has none): every stage of the unrounded circuit
        (:func:`designer.pid.blocks.continuous_parts`) for the plant output ``y``.

        The reference's edge kicks the stages faster than the search's grid resolves (its
        step is a few derivative-filter time constants; on it the slew delay reads half
        the true one), so the stages' first ten derivative time constants are redone on a
        grid 400 steps long, the plant's output (smooth there) interpolated; the grid's
        first step is read as the edge it holds (:func:`slew_delay_stages`). ``corners``:
        (fc, f_i, f_d) of another build than the search's (a rule's own)."""
        from .modelloop import edged, stage_waves
        amp = self.amp
        if amp.ideal:
            return 0.0
        fc, f_i, f_d = corners if corners is not None else (self.fc, self.f_i, self.f_d)
        parts = blocks.continuous_parts(kp, ti, td, fc, f_integrator_hz=f_i, f_differentiator_hz=f_d)
        t, edge = self.t, self.spec.edge_s
        ye = edged(t, y, edge)
        waves = stage_waves(parts, amp, t, self.reference, ye)
        tw = max(10.0 / (2 * math.pi * f_d), 20.0 * edge, 3.0 * (t[1] - t[0]))
        t_fine = np.linspace(0.0, tw, KICK_POINTS)
        fine = stage_waves(parts, amp, t_fine, M.reference(t_fine, self.step_v, 0.0, edge), np.interp(t_fine, t, ye))
        rise = rise_s if math.isfinite(rise_s) and rise_s > 0 else t[-1] / 20
        budget = M.SLEW_DELAY_FRACTION * rise
        lim = M.waveform_limits({k: v for k, v in waves.items() if k != "y"}, t, amp, budget)
        if not lim:
            return 0.0
        swing = max(max(v.v_max / amp.vout_max, v.v_min / amp.vout_min) for v in lim.values())
        slew = max(slew_delay_stages(t_fine, fine[v.signal], t, waves[v.signal], amp.slew_v_per_s, edge)
                   for v in lim.values()) / budget
        return max(0.0, swing - SWING_LIMIT) + max(0.0, slew - SLEW_LIMIT)

    def rule_within_stages(self, f) -> bool:
        """Whether a rule's loop (:class:`~designer.pid.result.LoopFigures` ``f``), built
        as the design builds it (its own crossover's corners, the op-amp poles), keeps every
        op-amp output within its swing and slew (its row holds its margins and u only)."""
        from .modelloop import (built_controller, corner_frequencies, ideal_crossover_hz, leak_limit_hz,
                                   simulation_controller)
        if self.amp.ideal:
            return True
        fc = ideal_crossover_hz(self.model, f.kp, f.ti_s, f.td_s)
        f_i, f_d = corner_frequencies(self.spec, fc, leak_limit_hz(self.model, f.kp, f.ti_s))
        ctrl = built_controller(f.kp, f.ti_s, f.td_s, fc, self.spec, self.amp)
        out = closed_loop_step(self.plants[0], simulation_controller(ctrl, fc), self.t, self.step_v,
                               step_fraction=SEARCH_STEP_FRACTION)
        rise = step_figures(self.t, out["y"], self.step_v).rise_time_s
        return self.stage_violation(f.kp, f.ti_s, f.td_s, out["y"], rise, (fc, f_i, f_d)) <= 1e-6

    def evaluate(self, kp, ti, td, stages=None):
        """(cost, iae, overshoot %, violation) of the gains."""
        self.evaluations += 1
        ctrl = self.controller(kp, ti, td)
        viol = self.frequency_violation(ctrl)
        out = closed_loop_step(self.plants[0], ctrl, self.t, self.step_v, step_fraction=SEARCH_STEP_FRACTION)
        y, u = out["y"], out["u"]
        if not (np.all(np.isfinite(y)) and np.max(np.abs(y)) < 1e3 * self.step_v):
            return math.inf, math.inf, math.nan, math.inf
        fig = step_figures(self.t, y, self.step_v)
        uf = float(u[-1])
        umax, umin = max(float(u.max()), uf - float(u.min())), min(float(u.min()), uf - float(u.max()))
        span = self.u_range[1] - self.u_range[0] if math.isfinite(self.u_range[1] - self.u_range[0]) else 1.0
        viol += max(0.0, umax - self.u_range[1]) / span + max(0.0, self.u_range[0] - umin) / span
        target = self.spec.target_overshoot_pct
        if target is not None and math.isfinite(fig.overshoot_pct):
            viol += max(0.0, fig.overshoot_pct - target) / max(target, 1.0)
        if self.stages if stages is None else stages:
            viol += self.stage_violation(kp, ti, td, y, fig.rise_time_s)
        # an unsettled tail (the record cut while the loop still moves) counts as error too
        return fig.iae, fig.iae, fig.overshoot_pct, viol


def optimize_model_loop(spec, model, amp, table) -> ModelOptimizeResult:
    """Optimise the gains for ``spec.plant.process`` (see the module's notes).

    ``table`` is the rule table (:func:`designer.pid.design.rule_table`):
    its applicable, stable rows are the candidate starts; the one with the
    smallest IAE among those that meet the limits (else the smallest Ms) wins.

    Parameters
    ----------
    spec : designer.pid.spec.PidSpec
        The request (its limits, targets and ``robust``).
    model : designer.core.process.ProcessModel
        The plant.
    amp : designer.core.opamps.OpAmp
        The op-amp of every stage.
    table : tuple of designer.pid.result.RuleRow
        Every rule on the plant.

    Returns
    -------
    ModelOptimizeResult
    """
    from scipy.optimize import minimize

    from dataclasses import replace

    from .modelloop import (edged, ideal_crossover_hz, leak_limit_hz, limits, loop_dc_gain, response_grid,
                               simulation_controller)
    from .verify import loop_metrics
    pm_min, gm_min, ms_max = limits(spec)
    starts = [r for r in table if r.figures is not None and r.figures.margins.stable and r.figures.step is not None]
    if not starts:
        # a rule's refusal already names the rule ("simc: the model has complex poles .."): not twice
        raise DesignError("optimize needs a rule whose loop is stable to start from, and none is: "
                          + "; ".join((r.reason if (r.reason or "").startswith(f"{r.rule}: ")
                                       else f"{r.rule}: {r.reason or 'unstable'}") for r in table), param="tuning")

    def meets(f):
        m = f.margins
        return m.phase_margin_deg >= pm_min and m.gain_margin_db >= gm_min and m.ms <= ms_max

    good = [r for r in starts if meets(r.figures)]
    start = (min(good, key=lambda r: r.figures.step.iae) if good else min(starts, key=lambda r: r.figures.margins.ms))
    g = start.figures
    fc = ideal_crossover_hz(model, g.kp, g.ti_s, g.td_s)
    t = response_grid(model, fc, SEARCH_POINTS, per_crossover=SEARCH_SPAN)
    # the leak stays where the start puts it (a tenth more margin: the search raises Kp/Ti)
    leak = leak_limit_hz(model, g.kp, g.ti_s)
    prob = _Problem(spec, model, amp, fc, t, spec.robust, None if leak is None else leak / 10)
    pid = g.td_s > 0
    x0 = np.log([g.kp, g.ti_s] + ([g.td_s] if pid else []))
    prob.opamp_poles_at(g.kp, g.ti_s, g.td_s)
    base = prob.evaluate(g.kp, g.ti_s, g.td_s)
    scale = base[1] if math.isfinite(base[1]) and base[1] > 0 else 1.0

    def gains(x):
        kp, ti = math.exp(x[0]), math.exp(x[1])
        return kp, ti, math.exp(x[2]) if pid else 0.0

    def inside(x):
        return bool(np.all(np.abs(x - x0) <= math.log(1e3)))     # three decades from the start at most

    def cost_frequency(x):
        # MIGO (Astrom-Hagglund): the largest integral gain Kp/Ti (the IE of a load step is
        # Ti/Kp) inside the margins and Ms; milliseconds an evaluation, no time response
        if not inside(x):
            return 1e6
        kp, ti, td = gains(x)
        prob.evaluations += 1
        return -(x[0] - x[1]) + 50.0 * prob.frequency_violation(prob.controller(kp, ti, td))

    def cost(x):
        if not inside(x):
            return 1e6
        kp, ti, td = gains(x)
        try:
            c, iae, _, viol = prob.evaluate(kp, ti, td)
        except DesignError:
            return 1e6
        return (c / scale if math.isfinite(c) else 1e3) + 50.0 * viol + (1e3 if not math.isfinite(viol) else 0.0)

    simplex = lambda x: np.vstack([x] + [x + 0.25 * e for e in np.eye(x.size)])  # noqa: E731
    first = minimize(cost_frequency, x0, method="Nelder-Mead",
                     options={"maxfev": FREQUENCY_EVALUATIONS, "xatol": 1e-3, "fatol": 1e-5,
                              "initial_simplex": simplex(x0)})
    x1 = first.x if cost(first.x) <= cost(x0) else x0
    prob.opamp_poles_at(*gains(x1))
    def search(x1):
        res = minimize(cost, x1, method="Nelder-Mead",
                       options={"maxfev": MAX_EVALUATIONS, "xatol": 1e-3, "fatol": 1e-4,
                                "initial_simplex": np.vstack([x1] + [x1 + 0.1 * e for e in np.eye(x1.size)])})
        return res.x if res.fun <= cost(x1) else x1

    # the op-amps' swing and slew join the search only when its result passes them (a stage's waveforms
    # cost as much as the step: a slow plant's search, far from its op-amps' limits, need not pay them)
    prob.stages = False
    best = search(x1)
    prob.stages = True
    if prob.evaluate(*gains(best))[3] > prob.evaluate(*gains(best), stages=False)[3] + 1e-9:
        x1 = first.x if cost(first.x) <= cost(x0) else x0
        best = search(x1)
    kp, ti, td = gains(best)
    target = spec.target_overshoot_pct
    t_fine = response_grid(model, fc, 8001)

    def built_overshoot(ctrl):
        # the built loop's step as the design measures it (the reference's edge, the levels against the
        # leaky loop's settled output) on a fine grid: the search's coarse one reads overshoot a little low
        out = closed_loop_step(prob.plants[0], simulation_controller(ctrl, fc), t_fine, spec.step_v)
        y = edged(t_fine, out["y"], spec.edge_s)
        fig = step_figures(t_fine, y, spec.step_v)
        os_ = loop_metrics(t_fine, y, spec.step_v * loop_dc_gain(model, ctrl)).overshoot_pct
        return replace(fig, overshoot_pct=os_)

    # the exact margins of the loop as built decide: lower Kp while the search was optimistic
    backed, exact = 0, False
    for backed in range(12):
        ctrl = prob.built(kp, ti, td)
        m = loop_margins(prob.plants[0], ctrl)
        worst = [loop_margins(p, ctrl) for p in prob.plants[1:]]
        exact = all(x.stable and x.phase_margin_deg >= pm_min and x.gain_margin_db >= gm_min and x.ms <= ms_max
                    for x in [m] + worst)
        if exact and target is not None:
            exact = built_overshoot(ctrl).overshoot_pct <= target
        if exact:
            break
        kp *= 0.95
    _, iae, os_, viol = prob.evaluate(kp, ti, td)
    met = viol <= 1e-6 and m.stable and exact
    if met or not exact:
        fig = built_overshoot(prob.built(kp, ti, td)) if m.stable else None
        iae, os_ = (fig.iae, fig.overshoot_pct) if fig is not None else (iae, os_)
    # a rule that already meets every limit as built with a smaller IAE wins over the search
    beaten = None
    lo, hi = prob.u_range
    for r in table if not spec.robust else ():
        f = r.figures
        if (f is None or f.step is None or not meets(f) or not lo <= f.u_min_v or not f.u_max_v <= hi
                or (target is not None and f.step.overshoot_pct > target)):
            continue
        if f.step.iae < iae * (1 - 1e-3) and (beaten is None or f.step.iae < beaten.figures.step.iae):
            if prob.rule_within_stages(f):
                beaten = r
    f_i, f_d = prob.f_i, prob.f_d
    if beaten is not None:
        # built as the rule's row was: its own crossover sets the corners
        from .modelloop import corner_frequencies
        f = beaten.figures
        kp, ti, td, iae, os_, met = f.kp, f.ti_s, f.td_s, f.step.iae, f.step.overshoot_pct, True
        fc = ideal_crossover_hz(model, kp, ti, td)
        f_i, f_d = corner_frequencies(spec, fc, leak_limit_hz(model, kp, ti))
    parts = [Message(N_("optimize: IAE {iae} (start {rule}: {iae0}) with phase margin >= {pm} deg, gain margin >= "
                        "{gm} dB, Ms <= {ms}"), iae=format_eng(iae, 'V s'), rule=start.rule,
                     iae0=format_eng(g.step.iae, 'V s'), pm=f"{pm_min:g}", gm=f"{gm_min:g}", ms=f"{ms_max:g}")]
    if target is not None:
        parts.append(Message(N_(", overshoot <= {target} %"), target=f"{target:g}"))
    if not amp.ideal:
        parts.append(Message(N_(", every {opamp} output within its swing and slew"), opamp=amp.name))
    if spec.robust:
        parts.append(Message(N_(" at all {n} corners of the 95 % box too"), n=str(len(prob.plants) - 1)))
    parts.append(Message(N_(", after {n} evaluations"), n=str(prob.evaluations)))
    if beaten is not None:
        parts.append(Message(N_(": rule {rule}'s gains, which meet every limit as built with the smallest IAE, beat "
                                "the search"), rule=beaten.rule))
    if not met:
        parts.append(N_("; NOT all met: the closest found"))
    if backed and not beaten:
        parts.append(Message(N_(" (Kp lowered {n} x 5 % where the search grid was optimistic)"), n=str(backed)))
    what = Message.joined("", parts)
    return ModelOptimizeResult(kp, ti, td, start.rule, fc, iae, os_, bool(met), prob.evaluations, what,
                               bool(spec.robust), f_i, f_d)
