"""The SPICE engine of a PID loop's Monte Carlo (issue 17): every build of the
closed loop simulated in ngspice, many builds per ngspice process, beside the
analytic loop engine (:mod:`.loop`).

The loop deck design-pid writes (:func:`designer.pid.netlist.closed_loop_deck`,
or :func:`~designer.pid.netlist.model_loop_deck` for a plant given as a model)
is loaded once, without its ``.tran``, ``.meas`` and settling-probe lines; then,
per build, as the plant's engine does (:mod:`.spice_engine`): its op-amp
commands (``--tol SR``: the subcircuit's slew-rate parameter by ``alterparam`` and
``reset``; ``--tol GBW``: every op-amp's integrating capacitor, U1 to U7, one
lot), an ``alter`` of each varied part (the deck's element names are the
designators: R1 .. R18, C1 .. C4), ``tran`` over the rising half of the square
wave at the deck's own maximum step, and ``meas`` of v(y) from the control block.

Each build's settled output, the level its 10/90 % and 2 % crossings refer to, is
the analytic loop's (step x its DC gain y/r, the leaky integrator's and the
difference amplifier's as built), as the deck's own ``.meas`` lines take the
design's; an unstable build (no settled level) is measured against the step.

The figures: the analytic engine's every figure (:data:`designer.tolerance.loop.FIGURES`:
stability, margins, gains, ``model_*`` step figures, saturation and slewing of
the linear waveforms) and SPICE's step figures as ``spice_overshoot_pct``,
``spice_peak_time_s``, ``spice_rise_time_s``, ``spice_settling_time_s``
(:data:`FIGURES`): overshoot 100 (peak - final)/final, the first peak's time from
the step's edge, 10-90 % rise, the last 2 % crossing (seed 001's definitions, as
:mod:`.spice_engine` measures a plant, but the peak's time where the highest value
is, as the loop deck's own ``.meas`` reads it: a loop's first ripple need not be
its peak). Where the SPICE run slews or clamps, its
figures carry it: the slew-rate spread (``--tol SR``) moves them directly.

:func:`evaluate` is a pure function of picklable arguments (a :class:`LoopSpiceContext`
and a chunk of builds): the runner (:mod:`.runner`) maps it over chunks anywhere.
"""

from __future__ import annotations

import re
from dataclasses import dataclass

import numpy as np

from . import spice_engine

__all__ = ["FIGURES", "context", "evaluate"]

#: the SPICE step figures of a loop (the analytic ones keep their names beside them)
STEP = ("overshoot_pct", "peak_time_s", "rise_time_s", "settling_time_s")
FIGURES = tuple(f"spice_{f}" for f in STEP)
#: builds per ngspice run (a loop's run is some ten times a plant's)
BATCH = 200
#: seconds allowed per build of a batch, on top of the simulator's fixed timeout
SECONDS_PER_SAMPLE = 5.0
_TRAN = re.compile(r"^\.tran\s+(\S+)", re.M | re.I)
_AMP = re.compile(r"^(X\S+)\s.*\bOPAMP_BEH\b", re.M | re.I)


@dataclass(frozen=True)
class LoopSpiceContext:
    """What every build of one loop shares (picklable).

    ``circuit`` is the loop deck without its analyses (op-amps' SR a parameter,
    :func:`designer.tolerance.spice_engine.slew_parametrised`); ``elements`` the varied
    parts' designators -> deck elements; ``cints`` every op-amp's integrating capacitor;
    ``analytic`` the analytic loop engine's (chunk function, context)
    (:func:`designer.tolerance.loop.engine_of`)."""

    circuit: str
    elements: tuple
    cints: tuple
    t0: float
    t1: float
    max_step_s: float
    amplitude_v: float
    a0: float
    rint: float | None
    gbw_hz: float
    sr_v_per_s: float
    analytic: tuple
    simulator: str = "ngspice-cli"


def context(result, designators, simulator: str = "ngspice-cli") -> LoopSpiceContext:
    """The :class:`LoopSpiceContext` of a design-pid or analyze-pid ``result`` (its deck, test,
    op-amp) for the parts ``designators`` (those that may vary; :func:`designer.tolerance.loop.loop_parts`),
    on the backend ``simulator``.

    Parameters
    ----------
    result : designer.pid.result.PidResult
        The design.
    designators : iterable of str
        The parts that may vary.
    simulator : str
        The backend.

    Returns
    -------
    LoopSpiceContext
        The context.
    """
    from ..core.errors import DesignError
    from ..spice.simulate import get_simulator
    from .loop import engine_of
    deck, test, amp = result.deck, result.test, result.opamp
    m = _TRAN.search(deck)
    if m is None:
        raise DesignError("the loop deck has no .tran line to take its time step from")
    from ..core.units import parse_value
    step = parse_value(m.group(1), ".tran step")
    keep = [ln for ln in deck.splitlines()
            if not re.match(r"\s*(\.(meas\w*|tran|end)\b|Bsettle\b)", ln, re.I)]
    circuit = "\n".join(keep) + "\n.end\n"
    present = {ln.split()[0].upper() for ln in keep if ln.strip() and not ln.startswith(("*", "."))}
    parts = tuple(d for d in designators if d not in spice_engine.OPAMP)
    missing = [d for d in parts if d not in present]
    if missing:
        raise DesignError(f"the loop deck has no part {missing[0]}")
    cints, rint = (), None
    if not amp.ideal:
        cints = tuple(f"c.{x.lower()}.cint" for x in _AMP.findall(circuit))
        rint = spice_engine.deck_rint(deck)
        circuit = spice_engine.slew_parametrised(circuit)
    return LoopSpiceContext(circuit, tuple((d, d.lower()) for d in parts), cints, test.delay_s,
                            test.delay_s + test.half_period_s, step, float(test.amplitude_v), amp.a0, rint,
                            amp.gbw_hz, amp.slew_v_per_s, engine_of(result), get_simulator(simulator).name)


def finals(ctx: LoopSpiceContext, analytic: dict) -> np.ndarray:
    """Each build's settled output: the step x the analytic loop's DC gain (the step where the
    build is unstable)."""
    sse = np.asarray(analytic["steady_state_error_pct"], float)
    return ctx.amplitude_v * np.where(np.isfinite(sse), 1 - sse / 100, 1.0)


def commands(ctx: LoopSpiceContext, values: dict, final, start: int = 0) -> list:
    """The control commands of builds ``start``..: per build its op-amp commands and ``alter``
    lines, ``tran`` over the rising half, a row marker, the ``meas`` lines, ``destroy all``."""
    n = len(next(iter(values.values())))
    elem = dict(ctx.elements)
    unknown = [d for d in values if d not in elem and d not in spice_engine.OPAMP]
    if unknown:
        raise ValueError(f"the loop deck has no part {unknown[0]}")
    if any(d in values for d in spice_engine.OPAMP) and not ctx.cints:
        raise ValueError("the ideal op-amp has no gain-bandwidth or slew rate to vary")
    win = f"FROM={ctx.t0:.10g} TO={ctx.t1:.10g}"
    tran = f"tran {ctx.max_step_s:.6g} {ctx.t1:.10g} 0 {ctx.max_step_s:.6g}"
    out = []
    for i in range(n):
        if ctx.cints:
            out += spice_engine.opamp_commands(values, i, ctx.cints, ctx.a0, ctx.rint, ctx.gbw_hz, ctx.sr_v_per_s)
        out += [f"alter {elem[d]} = {float(v[i]):.12g}" for d, v in values.items() if d in elem]
        out += [tran, f"echo MCROW {start + i}", *spice_engine.measures(win, float(final[i]), "y", first_peak=False), "destroy all"]
    return out


def evaluate(ctx: LoopSpiceContext, values: dict, start: int = 0) -> dict:
    """Every figure of a chunk of builds (designator -> array): the analytic loop engine's
    and SPICE's :data:`FIGURES`, one loaded circuit per :data:`BATCH` builds. Pure: the same
    context and values give the same figures in any process (``start`` labels the builds in
    ngspice's output only).

    Parameters
    ----------
    ctx : LoopSpiceContext
        The loop's deck and test.
    values : dict
        Designator -> array over the chunk's builds.
    start : int
        The first build's index.

    Returns
    -------
    dict
        Figure -> array over the builds.
    """
    from ..spice.simulate import DEFAULT_TIMEOUT_S, get_simulator
    values = {k: np.atleast_1d(np.asarray(v, float)) for k, v in values.items()}
    fn, analytic_ctx = ctx.analytic
    out = dict(fn(analytic_ctx, values))
    final = finals(ctx, out)
    n = len(final)
    sp = {k: np.full(n, np.nan) for k in FIGURES}
    for lo in range(0, n, BATCH):
        hi = min(n, lo + BATCH)
        chunk = {k: v[lo:hi] for k, v in values.items()}
        sim = get_simulator(ctx.simulator, timeout=DEFAULT_TIMEOUT_S + SECONDS_PER_SAMPLE * (hi - lo))
        text = sim.run_script(ctx.circuit, commands(ctx, chunk, final[lo:hi], start + lo))
        figs = spice_engine.step_figures(spice_engine.parse(text, start + lo, hi - lo), final[lo:hi], ctx.t0)
        for f in STEP:
            sp[f"spice_{f}"][lo:hi] = figs[f]
    return {**out, **sp}
