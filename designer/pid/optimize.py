"""Kp, Ti and Td by numerical optimisation on the closed loop as it will be
built: the realised blocks (leaky integrator, filtered derivative), the
op-amps' finite gain-bandwidth, and the op-amps' limits for the actual
reference step. This replaces the seed's trial-and-error "x10" step.

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
"""

from __future__ import annotations

import math
from dataclasses import dataclass, field

import numpy as np
from scipy import optimize as sopt

from ..core.errors import DesignError
from ..core.metrics import step_metrics
from ..core.opamps import OpAmp
from ..core.ranges import RANGES
from . import blocks, model

__all__ = ["Context", "evaluate", "optimize"]

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
        r = model.reference(self.t, self.step_v, 0.0, self.edge_s)
        # the edged reference is no pure step: the plant's state-space simulation (exact for it)
        y = model.state_space(self.plant_num, self.plant_den).simulate(self.t, r)["y"]
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
    (unrounded parts, :func:`designer.pid.blocks.continuous_parts`)."""
    parts = blocks.continuous_parts(kp, ti, td, ctx.fn_hz, f_integrator_hz=ctx.f_integrator_hz,
                                    f_differentiator_hz=ctx.f_differentiator_hz)
    return evaluate_parts(parts, ctx, (kp, ti, td))


def evaluate_parts(parts, ctx: Context, gains=None) -> Evaluation:
    """Cost and figures of a controller built from ``parts``."""
    kp, ti, td = gains if gains is not None else (parts.kp, parts.ti_s, parts.td_s)
    lm = model.assemble(parts, ctx.opamp, ctx.plant_num, ctx.plant_den)
    if not lm.stable():
        worst = float(np.max(lm.poles().real))   # 1/s, capped below: more than any stable loop costs
        return Evaluation(kp, ti, td, 1e3 + 10.0 * min(worst, 100.0), False)
    r = model.reference(ctx.t, ctx.step_v, 0.0, ctx.edge_s)
    w = lm.simulate(ctx.t, r)
    y = w["y"]
    try:
        m = step_metrics(ctx.t, y, initial=0.0)
    except DesignError:  # a flat response: no figures
        return Evaluation(kp, ti, td, 1e3, True)
    e = np.abs(r - y) / abs(ctx.step_v)
    itae = float(np.trapezoid(ctx.t * e, ctx.t)) / ctx.itae_ref
    rise = m.rise_time_s if math.isfinite(m.rise_time_s) else ctx.t[-1]
    lim = model.waveform_limits(w, ctx.t, ctx.opamp, model.SLEW_DELAY_FRACTION * rise)
    amp = ctx.opamp
    if amp.ideal:
        swing, slew = 0.0, 0.0
    else:
        swing = max(max(v.v_max / amp.vout_max, v.v_min / amp.vout_min) for v in lim.values())
        slew = max(v.slew_delay_s for v in lim.values()) / (model.SLEW_DELAY_FRACTION * rise)
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
    The targets in ``ctx`` are taken as valid (:class:`designer.pid.spec.PidSpec` checks them)."""
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
    msg = ("targets met" if met else
           "targets not met: the best compromise is reported (see the checks); relax the overshoot or "
           "settling target, lower --step, or choose a faster op-amp")
    return OptimizeResult(best, met, count, results, msg)
