"""The analytic engine for a PID loop around a Sallen-Key plant (issue 17): the
plant's parts and the controller's eighteen vary together, and each sample's
loop as built (op-amp poles, leak, filter: :func:`designer.pid.model.assemble`)
gives whether it is stable, the gains its parts realise, its phase and gain
margins, its step figures for the design's test step (measured as the deck
measures them, :func:`designer.pid.verify.loop_metrics`), and whether any
op-amp leaves its output swing.

The figures carry check-design's names for a loop (:data:`designer.check.figures.PID`):
``model_overshoot_pct`` is the analytic loop's overshoot; a limit on the SPICE
name (``overshoot_pct``) counts the model's figure, this engine's estimate of
it (:data:`STANDS_IN`). A build is in the yield when its loop is stable and
every limited figure is inside its window.

The op-amp's own spread (``--tol GBW=30% SR=20%``, :func:`designer.tolerance.parts.opamp_nominal`):
each build's seven op-amps share one drawn gain-bandwidth and slew rate
(:func:`designer.tolerance.parts.sample_opamp`). The gain-bandwidth moves every
op-amp pole of the loop (margins, step). The loop as analysed is linear, so
nothing in its margins or step depends on the slew rate; where a real op-amp's
slew rate matters is whether each stage can follow its linear waveform, design-pid's
``slew_rate`` check (:func:`designer.pid.model.waveform_limits`): a stage slews for
sum(max(0, |dv| - SR dt))/SR longer than its linear waveform takes
(:func:`designer.pid.model.slew_delay`), accepted up to
:data:`designer.pid.model.SLEW_DELAY_FRACTION` of the build's rise time. Per build:
``slew_delay_s``, the worst stage's delay, and ``slewing`` (1 when it is over that
budget, or the loop is unstable, as the check fails then); over the builds the
probability of failing the slew check with its Wilson interval (``p_slewing``).
The step is sampled at :data:`STEP_POINTS` points, and the reference's kick
again on a fine grid (:func:`kick_grid`, the optimiser's reading,
:func:`designer.pid.optimize.slew_delay_stages`): on the coarse grid alone
the edge's kick read about 9 % short (the optimised LM741 loop's 2.81 us against
design-pid's own 3.08 us); with it the nominal build reads the design's check.

A plant given as a model (``--plant-tf``, ``--plant-model``, ``--plant-capture``)
keeps its parameters as identified; only the controller's parts vary
(:func:`model_loop_figures`). One sample at a time (a state-space model per
sample, a few milliseconds each; a model plant's loop with its exact dead time
about 0.2 s): the loop's figures have no closed form. Sample i is a function of
(seed, i) alone, as for the plant (:mod:`.sampling`).
"""

from __future__ import annotations

import math
from dataclasses import dataclass, fields, replace

import numpy as np

from ..core.errors import DesignError
from ..core.figure_titles import figure_spread
from .montecarlo import MonteCarlo

__all__ = ["LIMITABLE", "LoopContext", "STEP_POINTS", "evaluate", "kick_grid", "loop_figures", "loop_monte_carlo",
           "loop_parts", "loop_series", "loop_worst_case", "parse_loop_limit"]

STEP = ("overshoot_pct", "peak_time_s", "rise_time_s", "settling_time_s")
#: the figures of each sampled loop that are 1 or 0
FLAGS = ("stable", "saturated", "slewing")
#: every figure of each sampled loop (check-design's names, and the worst stage's slew delay)
FIGURES = ("stable", "saturated", "kp", "ti_s", "td_s", "phase_margin_deg", "crossover_hz", "gain_margin_db",
           "steady_state_error_pct", *(f"model_{f}" for f in STEP), "slewing", "slew_delay_s")
#: the figures a --limit may name (with the names of :data:`STANDS_IN`)
LIMITABLE = tuple(f for f in FIGURES if f not in FLAGS)
#: a SPICE figure's name -> the analytic figure that stands in for it
STANDS_IN = {f: f"model_{f}" for f in STEP}
#: the figures whose spread the summary prints, with their units
SHOWN = (("phase_margin_deg", "deg"), ("gain_margin_db", "dB"), ("model_overshoot_pct", "%"))
#: frequency points of each sample's loop gain (log, from the leak corner / 20 to the op-amp's GBW)
BODE_POINTS = 1500
#: time points of each sample's step
STEP_POINTS = 2001
#: parts tried for "buy this part tighter" (those with the largest variance shares; one more run each)
TIGHTEN_CANDIDATES = 3
#: how a build fails the slew check (the JSON's slew_rule)
SLEW_RULE = ("a build slews when a stage's slew delay sum(max(0, |dv| - SR dt))/SR exceeds 5 % of its rise "
             "time (design-pid's slew_rate check), or its loop is unstable")
#: the figures whose extremes --worst-case reports for a loop (with every limited one)
WORST_FIGURES = ("phase_margin_deg", "gain_margin_db", "model_overshoot_pct")


def is_model_loop(result) -> bool:
    """Whether ``result`` is a model plant's loop (:class:`~designer.pid.result.PidResult`)."""
    return getattr(result, "model", None) is not None


def loop_parts(result, tol_items=()) -> dict:
    """Designator -> nominal value of the loop's parts: the plant's (R1, R2, C1, C2; none for a plant
    given as a model, whose parameters stay as identified) and the controller's, and the op-amp's
    ``GBW`` (Hz) and ``SR`` (V/s) when the ``--tol`` items ``tol_items`` spread them.

    Parameters
    ----------
    result : designer.pid.result.PidResult
        The design.
    tol_items : sequence of str
        The ``--tol`` items.

    Returns
    -------
    dict
        Designator -> nominal value.
    """
    from ..filters.sallen_key_lowpass_parts import refs
    from .parts import opamp_nominal
    c = result.parts
    p = None if is_model_loop(result) else result.plant   # the generic record (designer.pid.plant.PlantCircuit)
    # the plant's network only: its gain pair's designators are the controller's R3, R4 here
    out = {} if p is None else {r: v for r, v in p.stages[0].values.items() if r in refs(with_gain=False)}
    for f in fields(c):
        v = getattr(c, f.name)
        if v is not None:
            out[f.name.upper()] = v
    return {**out, **opamp_nominal(tol_items, result.opamp)}


def loop_series(result) -> dict:
    """``{"R": series, "C": series}`` of a design-pid result's parts (their default tolerances): the
    controller's series; the plant's where the controller's parts were given (None: typed by hand).

    Parameters
    ----------
    result : designer.pid.result.PidResult
        The design.

    Returns
    -------
    dict
        ``{"R": series, "C": series}``.
    """
    sel = result.selection
    r, c = (sel.r_series, sel.c_series) if sel is not None else (None, None)
    if getattr(result, "plant_series", None) is not None:
        r, c = r or result.plant_series[0], c or result.plant_series[1]
    return {"R": r, "C": c}


def parse_loop_limit(text: str):
    """A ``--limit`` on a loop figure (:data:`LIMITABLE`, or a SPICE name of :data:`STANDS_IN`),
    named by the figure this engine computes.

    Parameters
    ----------
    text : str
        The ``--limit`` item.

    Returns
    -------
    designer.tolerance.stats.Limit
        The limit.
    """
    from .stats import Limit, parse_limit
    lim = text if isinstance(text, Limit) else parse_limit(text, LIMITABLE + tuple(STANDS_IN))
    return replace(lim, figure=STANDS_IN.get(lim.figure, lim.figure))


def _unstable(out: dict, i: int) -> None:
    """An unstable build fails the swing and slew checks (its outputs run to the rails)."""
    out["saturated"][i] = out["slewing"][i] = 1.0


def kick_grid(parts, t, edge_s: float) -> np.ndarray:
    """The fine grid the reference's kick is redone on, as the optimiser does
    (:func:`designer.pid.optimize.slew_delay_stages`): ten derivative-filter time constants
    (twenty edges, three coarse steps at least) in about :data:`designer.pid.optimize.KICK_POINTS`
    points, its step the coarse grid's over a power of two (one matrix exponential for both grids,
    :meth:`designer.pid.model.LoopModel.simulate_with_kick`).

    Parameters
    ----------
    parts
        The controller's parts (its derivative filter's time constant).
    t : array_like
        The coarse grid (s).
    edge_s : float
        The reference's edge (s).

    Returns
    -------
    numpy.ndarray
        The fine grid (s).
    """
    from ..pid.optimize import KICK_POINTS
    f_d = parts.f_differentiator_hz if parts.td_s else math.inf
    dt = t[1] - t[0]
    tw = max(10.0 / (2 * math.pi * f_d) if math.isfinite(f_d) and f_d > 0 else 0.0, 20.0 * edge_s, 3.0 * dt)
    h = dt / 2.0 ** max(0, math.ceil(math.log2(dt * (KICK_POINTS - 1) / tw)))
    return h * np.arange(int(math.ceil(tw / h)) + 1)


def _step_and_swing(out: dict, i: int, t, waves: dict, expected: float, amp, kick=None) -> None:
    """Sample ``i``'s step figures (against the ``expected`` settled output), whether an op-amp
    output leaves the swing, and its stages' slew delay against the budget (module docstring),
    from a stable loop's waves; ``kick``: (fine grid, its waves, the edge's length), the first
    moments again on the fine grid (:func:`kick_grid`), where the slew delay is read."""
    from ..pid.model import SLEW_DELAY_FRACTION, slew_delay
    from ..pid.optimize import slew_delay_stages
    from ..pid.verify import loop_metrics
    fig = loop_metrics(t, waves["y"], expected)
    for f in STEP:
        out[f"model_{f}"][i] = getattr(fig, f)
    if amp.ideal:
        out["saturated"][i] = out["slewing"][i] = out["slew_delay_s"][i] = 0.0
        return
    stages = [v for k, v in waves.items() if k != "y"]
    peak = max(max(float(np.max(v)), float(v[-1] - np.min(v))) for v in stages)
    low = min(min(float(np.min(v)), float(v[-1] - np.max(v))) for v in stages)
    out["saturated"][i] = float(peak > amp.vout_max or low < amp.vout_min)
    if kick is None:
        delay = max(slew_delay(t, v, amp.slew_v_per_s) for v in stages)
    else:
        t_fine, fine, edge = kick
        delay = max(slew_delay_stages(t_fine, fine[k], t, v, amp.slew_v_per_s, edge)
                    for k, v in waves.items() if k != "y")
    rise = fig.rise_time_s if math.isfinite(fig.rise_time_s) and fig.rise_time_s else t[-1] / 20
    out["slew_delay_s"][i] = delay
    out["slewing"][i] = float(delay > SLEW_DELAY_FRACTION * rise)


def model_loop_figures(values: dict, result) -> dict:
    """:data:`FIGURES` of the controller's sampled parts around a plant given as a model (its
    parameters as identified), each loop analysed as design-pid analyses it
    (:func:`designer.pid.design.analyse`: exact dead time, its margins by the argument
    principle, the step on the result's grid; about 0.2 s a build)."""
    from ..pid import model as M
    from ..pid.blocks import PidParts
    from ..pid.delaymargins import loop_margins
    from ..pid.design import closed_loop_step, edged, loop_dc_gain, plant_of, simulation_controller, stage_waves
    from .parts import sample_opamp
    model = result.model
    plant = plant_of(model)
    n = next(iter(values.values())).size
    out = {k: np.full(n, np.nan) for k in FIGURES}
    names = [f.name for f in fields(PidParts)]
    t, step, edge = result.waveforms.t, result.test.amplitude_v, result.test.edge_s
    r = M.reference(t, step, 0.0, edge)
    for i in range(n):
        parts = PidParts(**{k: (values[k.upper()][i] if k.upper() in values else None) for k in names})
        amp = sample_opamp(result.opamp, values, i)
        out["kp"][i], out["ti_s"][i], out["td_s"][i] = parts.kp, parts.ti_s, parts.td_s
        ctrl = M.controller_tf(parts, amp)
        mg = loop_margins(plant, ctrl)
        out["stable"][i] = float(mg.stable)
        out["phase_margin_deg"][i], out["gain_margin_db"][i] = mg.phase_margin_deg, mg.gain_margin_db
        out["crossover_hz"][i] = mg.crossover_hz
        if not mg.stable:
            _unstable(out, i)
            continue
        dc = loop_dc_gain(model, ctrl)
        out["steady_state_error_pct"][i] = 100 * (1 - dc)
        fc = max(result.fc_ref_hz, mg.crossover_hz if math.isfinite(mg.crossover_hz) else result.fc_ref_hz)
        y = edged(t, closed_loop_step(plant, simulation_controller(ctrl, fc), t, step)["y"], edge)
        _step_and_swing(out, i, t, stage_waves(parts, amp, t, r, y), step * dc, amp)
    return out


@dataclass(frozen=True)
class LoopContext:
    """What the loop engine needs of a design-pid result besides the parts (small and
    picklable: it travels with every chunk, :mod:`.runner`)."""

    opamp: object        #: the op-amp of every stage
    step_v: float        #: the design's test step
    edge_s: float        #: its rise time
    t_end: float         #: the step's duration

    @classmethod
    def of(cls, result) -> "LoopContext":
        return cls(result.opamp, float(result.test.amplitude_v), float(result.test.edge_s),
                   float(result.waveforms.t[-1]))


def loop_figures(values: dict, result) -> dict:
    """Every figure of :data:`FIGURES` for each sample (arrays over the samples).

    Parameters
    ----------
    values : dict
        Designator -> array over the samples.
    result : designer.pid.result.PidResult
        The design whose loop is varied.

    Returns
    -------
    dict
        Figure -> array over the samples.
    """
    if is_model_loop(result):
        return model_loop_figures(values, result)
    return evaluate(LoopContext.of(result), values)


def evaluate(context: LoopContext, values: dict) -> dict:
    """The engine's chunk function for a Sallen-Key plant's loop (:mod:`.runner`): every figure of
    :data:`FIGURES` of each sample.

    Parameters
    ----------
    context : LoopContext
        The loop's design and test.
    values : dict
        Designator -> array over the chunk's samples.

    Returns
    -------
    dict
        Figure -> array over the samples.
    """
    from ..pid import model
    from ..pid.blocks import PidParts
    from ..plant.model import plant_model
    from ..filters.sallen_key_lowpass_parts import parts_of, refs
    from .parts import sample_opamp
    n = next(iter(values.values())).size
    out = {k: np.full(n, np.nan) for k in FIGURES}
    step = context.step_v
    names = [f.name for f in fields(PidParts)]
    t = np.linspace(0.0, context.t_end, STEP_POINTS)
    r = model.reference(t, step, 0.0, context.edge_s)
    for i in range(n):
        plant = parts_of({r: values[r][i] for r in refs(with_gain=False)})
        parts = PidParts(**{k: (values[k.upper()][i] if k.upper() in values else None) for k in names})
        amp = sample_opamp(context.opamp, values, i)
        out["kp"][i], out["ti_s"][i], out["td_s"][i] = parts.kp, parts.ti_s, parts.td_s
        pn, pd = plant_model(plant, amp)
        lm = model.assemble(parts, amp, pn, pd)
        stable = lm.stable()
        out["stable"][i] = float(stable)
        f_lo = min(parts.f_integrator_hz, plant.fn_hz) / 20
        f_hi = max(amp.gbw_hz if not amp.ideal else 0.0, 100 * plant.fn_hz)
        w = 2 * np.pi * np.logspace(math.log10(f_lo), math.log10(f_hi), BODE_POINTS)
        mg = model.margins(w, model.loop_gain(parts, amp, pn, pd, w))
        out["phase_margin_deg"][i], out["gain_margin_db"][i] = mg.phase_margin_deg, mg.gain_margin_db
        out["crossover_hz"][i] = mg.crossover_hz
        if not stable:
            _unstable(out, i)
            continue
        dc = model.dc_gain(lm)
        out["steady_state_error_pct"][i] = 100 * (1 - dc)
        kick = None
        if amp.ideal:
            waves = lm.simulate(t, r)
        else:      # the slew delay is read on a fine grid over the kick (module docstring)
            t_fine = kick_grid(parts, t, context.edge_s)
            waves, fine = lm.simulate_with_kick(t, r, t_fine, model.reference(t_fine, step, 0.0, context.edge_s))
            kick = (t_fine, fine, context.edge_s)
        _step_and_swing(out, i, t, waves, step * dc, amp, kick)
    return out


def stable_and_inside(figs: dict, limits) -> np.ndarray:
    """Stable and inside every limit."""
    from .montecarlo import inside_limits
    return (figs["stable"] == 1) & inside_limits(figs, limits)


def _model_evaluate(result, values: dict) -> dict:
    """The engine's chunk function for a plant given as a model (the result travels as the context)."""
    return model_loop_figures(values, result)


def engine_of(result) -> tuple:
    """(chunk function, context) of the result's loop engine (:mod:`.runner`)."""
    return (_model_evaluate, result) if is_model_loop(result) else (evaluate, LoopContext.of(result))


def loop_monte_carlo(result, series: dict, n: int, seed: int = 0, sampler: str = "random", dist: str = "uniform",
                     tol_items=(), limit_items=(), tighten: bool = True, scale=None, target_ci: float | None = None,
                     engine=None, tighten_with=None):
    """A Monte Carlo of a design-pid result's loop: the probabilities of instability, of
    saturation and of failing the slew check with their Wilson intervals, the statistics of every figure and, with
    ``limit_items`` (``--limit`` texts such as ``phase_margin_deg=45:90``), the yield with its
    interval, each part's share of each limited figure's variance, the worst failing samples per
    limit and the part whose tolerance halved raises the yield most (tried on the
    :data:`TIGHTEN_CANDIDATES` parts with the largest shares, one more run each). ``scale``: where
    the samples run (:class:`designer.tolerance.runner.Scale`; default here); the result is the
    same wherever they run. ``target_ci``: ``--target-ci``, builds drawn in rounds until the
    yield's 95 % Wilson half-width is below it, ``n`` at most, as the plant's
    (:func:`designer.tolerance.montecarlo.target_plan`; needs limits). ``engine``: (name, chunk
    function, context) of another engine than the analytic one (the SPICE engine's,
    :mod:`designer.tolerance.spice_loop`, whose figures include the analytic ones); the part to
    tighten is then searched with it too, unless ``tighten_with`` (chunk function, context,
    limits) names another (the analytic engine with the model's limits: ``yield_now`` is then
    theirs, counted on the engine's figures, which must include them).

    Returns a :class:`LoopMonteCarlo`.

    Parameters
    ----------
    result : designer.pid.result.PidResult
        The design.
    series : dict
        ``{"R": series, "C": series}`` (:func:`loop_series`).
    n : int
        The samples.
    seed : int
        The seed.
    sampler, dist : str
        How the samples are drawn (:mod:`designer.tolerance.sampling`).
    tol_items : sequence of str
        The ``--tol`` items.
    limit_items : sequence of str
        The ``--limit`` items.
    tighten : bool
        Find the part to buy tighter.
    scale : designer.tolerance.runner.Scale, optional
        Where the chunks run.
    target_ci : float, optional
        ``--target-ci``: draw until the yield's interval is this narrow.
    engine : callable, optional
        Another engine (the SPICE one); None: :func:`evaluate`.
    tighten_with : callable, optional
        The engine the part to buy tighter is found with.

    Returns
    -------
    designer.tolerance.montecarlo.MonteCarlo
        The Monte Carlo.
    """
    from .montecarlo import MAX_SAMPLES, MIN_SAMPLES, target_plan
    from .parts import resolve
    from .runner import Draw, Runner, Scale
    from .stats import failing_samples, figure_stats, variance_shares, wilson
    if isinstance(n, bool) or not isinstance(n, (int, np.integer)) or not MIN_SAMPLES <= n <= MAX_SAMPLES:
        raise DesignError(f"--monte-carlo must be a whole number of samples from {MIN_SAMPLES} to {MAX_SAMPLES:.0e}, "
                          f"got {n!r}")
    limits = tuple(parse_loop_limit(t) for t in limit_items or ())
    nominal = loop_parts(result, tol_items)
    tol = resolve(tol_items, nominal, series)
    until, first = target_plan(target_ci, limits, sampler, n, lambda figs: stable_and_inside(figs, limits))
    name, chunk_fn, context = engine or ("analytic", *engine_of(result))
    n_max, n = n, first
    with Runner(scale or Scale()) as run:
        values, figs, ends = run.run(chunk_fn, context, Draw(nominal, tol.of, n_max, seed, sampler, dist), first,
                                     until)
        n = ends[-1]     # the builds drawn (--target-ci may stop before n_max)
        nominal_figs = {k: float(v[0]) for k, v in chunk_fn(context, {r: np.array([x]) for r, x in
                                                                      nominal.items()}).items()}
        by_fig = {lim.figure: lim for lim in limits}
        stats = {k: figure_stats(k, figs[k], nominal_figs[k], by_fig.get(k)) for k in figs if k not in FLAGS}
        rel = {r: values[r] / nominal[r] - 1 for r in values}
        shares = {k: variance_shares(rel, figs[k]) for k in (by_fig or dict(SHOWN))}

        def share(flag, value):
            k = int(np.count_nonzero(figs[flag] == value))
            return {"count": k, "fraction": k / n, "ci95": list(wilson(k, n))}
        mc = LoopMonteCarlo(n, seed, sampler, dist, name, tol, nominal, values, figs, nominal_figs, limits,
                            stats, stable_and_inside(figs, limits) if limits else None, shares,
                            failing_samples(figs, limits),
                            p_unstable=share("stable", 0), p_saturated=share("saturated", 1),
                            unstable_samples=[int(i) for i in np.nonzero(figs["stable"] == 0)[0][:5]],
                            p_slewing=share("slewing", 1))
        mc.record_target(target_ci, n_max, ends)
        if tighten and limits and mc.yield_count < n:
            weight = {r: sum(shares[k][r] for k in by_fig) for r in tol.of}
            tried = sorted(tol.of, key=lambda r: -weight[r])[:TIGHTEN_CANDIDATES]
            t_fn, t_ctx, t_lim = tighten_with or (chunk_fn, context, limits)
            best = None
            for ref in tried:
                halved = dict(tol.of, **{ref: tol.of[ref] / 2})
                _, f, _ = run.run(t_fn, t_ctx, Draw(nominal, halved, n_max, seed, sampler, dist), n,
                                  progress=False)
                y = float(np.mean(stable_and_inside(f, t_lim)))
                if best is None or y > best[1]:
                    best = (ref, y)
            mc.tighten = {"part": best[0], "tolerance_pct": 100 * tol.of[best[0]] / 2, "yield": best[1],
                          "yield_now": float(np.mean(stable_and_inside(figs, t_lim))), "tried": tried}
    return mc


def loop_worst_case(result, series: dict, tol_items=(), limit_items=(), max_corners: int = 4096):
    """:func:`designer.tolerance.worstcase.worst_case` of the loop's figures (:data:`WORST_FIGURES`, the
    slew delay when ``--tol SR`` spreads the slew rate, and every limited one) over its tolerance box: with 22 parts, the corners the sensitivities point to,
    then a bounded search from the worst.

    Parameters
    ----------
    result : designer.pid.result.PidResult
        The design.
    series : dict
        ``{"R": series, "C": series}``.
    tol_items : sequence of str
        The ``--tol`` items.
    limit_items : sequence of str
        The ``--limit`` items.
    max_corners : int
        Every corner is evaluated up to this many.

    Returns
    -------
    designer.tolerance.worstcase.WorstCase
        The extremes.
    """
    from .parts import resolve
    from .worstcase import worst_case
    nominal = loop_parts(result, tol_items)
    tol = resolve(tol_items, nominal, series)
    slew = ("slew_delay_s",) if "SR" in nominal else ()
    figs = tuple(dict.fromkeys([*WORST_FIGURES, *slew, *(parse_loop_limit(t).figure for t in limit_items or ())]))
    return worst_case(lambda v: loop_figures(v, result), nominal, tol.of, figs, max_corners=max_corners,
                      maxiter=15)


@dataclass
class LoopMonteCarlo(MonteCarlo):
    """A loop's Monte Carlo: :class:`~designer.tolerance.montecarlo.MonteCarlo` and the
    probabilities of instability, saturation and of failing the slew check (count, fraction,
    95 % Wilson interval)."""

    p_unstable: dict = None
    p_saturated: dict = None
    unstable_samples: list = None
    p_slewing: dict = None

    @property
    def headline(self) -> str:
        """The first limited figure, else the phase margin."""
        return self.limits[0].figure if self.limits else "phase_margin_deg"

    def to_dict(self) -> dict:
        out = super().to_dict()
        return {**out, "yield_rule": "a build is in the yield when its loop is stable and inside every limit",
                "p_unstable": self.p_unstable, "p_saturated": self.p_saturated,
                "p_slewing": self.p_slewing, "slew_rule": SLEW_RULE, "unstable_samples": self.unstable_samples}

    def summary_lines(self) -> list:
        out = [f"Monte Carlo of the loop: {self.n} builds ({self.sampler}, {self.dist}, seed {self.seed}), "
               "the plant's and the controller's parts varying together"
               + (f", the op-amps' {' and '.join(k for k in ('GBW', 'SR') if k in self.values)} too"
                  if "GBW" in self.values or "SR" in self.values else "")]
        for what, p in (("unstable", self.p_unstable), ("an op-amp beyond its swing", self.p_saturated),
                        ("a stage slewing past the slew check's budget", self.p_slewing)):
            if p is not None:
                out.append(f"  {what}: {100 * p['fraction']:.2f} % (95 % Wilson {100 * p['ci95'][0]:.2f}.."
                           f"{100 * p['ci95'][1]:.2f} %)")
        for k, _unit in SHOWN:
            s = self.stats.get(k)
            if s is not None and s.percentiles:
                p = s.percentiles
                out.append("  " + figure_spread(k, s.nominal, s.mean, s.std, p[2.5], p[97.5], digits=4))
        return out + self.yield_lines()
