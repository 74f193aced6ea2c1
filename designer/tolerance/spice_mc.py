"""The plant Monte Carlo with SPICE (issue 17): ``--engine spice|both``,
``--spice-samples K`` and ``--replay I``.

- ``spice``: every sample simulated (:mod:`.spice_engine`); the figures SPICE
  measures replace the model's, the others (``ideal_*``, the parts' own closed
  forms, and ``gain``, the DC gain K A0/(K + A0)) stay the model's.
- ``both``: the same, with the model's figures of every sample beside SPICE's, and
  their disagreement per figure (SPICE minus the model: mean, largest, the sample
  where it is largest) and the yield each gives.
- ``both`` with ``--spice-samples K``: the model on every sample; SPICE on the K
  samples nearest or furthest beyond each limited figure's window (its tails) plus
  K drawn at random from the rest (a generator seeded from (seed, 1), so the choice
  is reproducible); how many verdicts SPICE flips, and the yield with those flips
  applied (the worst samples are where flips happen; the random ones estimate the
  flip rate in the bulk). Those SPICE samples run through the same runner as the
  model's (``--jobs``, ``--dask``: :class:`designer.tolerance.runner.Picked`).
- replay: sample I alone, its values drawn again from (seed, I) with the same
  sampler, distribution and tolerances, simulated by the same engine.
"""

from __future__ import annotations

import numpy as np

from ..core.errors import DesignError
from . import spice_engine

__all__ = ["drawn_values", "plant_context", "plant_monte_carlo_engine", "replay", "replay_parts", "replay_result",
           "replay_values", "run_engine", "section_analysis", "section_context", "section_engine",
           "section_monte_carlo_engine", "section_step_chunk",
           "section_step_context", "spice_evaluate", "spice_samples", "step_settings"]

ENGINES = ("analytic", "spice", "both")
#: the seed of the random part of --spice-samples: SeedSequence(seed, spawn_key=(RANDOM_KEY,)) (chunks use (c,))
RANDOM_KEY = 2 ** 31


def plant_chunk(ctx, opamp, values: dict, start: int = 0) -> dict:
    """The figures of a chunk of samples with the SPICE engine: the model's, with SPICE's in place
    of those it measures and the SPICE-only ones (rise and settling time) added. Pure, of
    picklable arguments: a chunk runner can send it to workers."""
    from .montecarlo import figures_with_fixed
    return {**figures_with_fixed(values, {}, opamp), **spice_engine.evaluate(ctx, values, start)}


def step_chunk(ctx, opamp, values: dict, start: int = 0) -> dict:
    """The figures of a chunk of samples with the model's figures under their own names and
    SPICE's as ``spice_<figure>`` (:data:`designer.tolerance.spice_engine.FIGURES`), so that a
    check on the model's ``fn_hz`` and one on SPICE's ``overshoot_pct`` each count their own
    (check-design's yield, :mod:`designer.tolerance.yields`). Pure, of picklable arguments."""
    from .montecarlo import figures_with_fixed
    sp = spice_engine.evaluate(ctx, values, start)
    return {**figures_with_fixed(values, {}, opamp), **{f"spice_{k}": v for k, v in sp.items()}}


def spice_step_evaluate(result, simulator: str = "ngspice-cli"):
    """``evaluate(values) -> figures`` of :func:`step_chunk` for a plant result (its deck, parts
    as built, op-amp and test) on the backend ``simulator`` (picklable)."""
    import functools
    return functools.partial(step_chunk, plant_context(result, simulator), result.opamp)


def plant_context(result, simulator: str = "ngspice-cli"):
    """The step engine's context (:func:`designer.tolerance.spice_engine.context`) of a Sallen-Key plant:
    its deck (output net ``out``) on its section (the Sallen-Key low-pass its parts as built realise, their
    values by designator), op-amp and square-wave test.

    Parameters
    ----------
    result : designer.plant.result.PlantResult
        The design.
    simulator : str
        The backend.

    Returns
    -------
    designer.tolerance.spice_engine.SpiceContext
        The context.
    """
    from ..filters.sallen_key_lowpass_parts import part_values, section_of
    return spice_engine.context(result.deck, section_of(result.built), part_values(result.built), result.opamp,
                                result.test, simulator, node="out")


def section_step_context(result, simulator: str = "ngspice-cli"):
    """The step engine's context (:func:`designer.tolerance.spice_engine.context`) of a low-pass section
    plant (a :class:`~designer.plant.circuit_design.CircuitPlantResult`) under its bench's square wave: its
    square-wave test's deck when it ran one (``square_hz``, ``--square-freq``), else the section's netlist under
    the square wave its bench recommends (``result.test``, :func:`designer.plant.circuit_design.with_bench`, the
    Sallen-Key plant's rule), output net ``vout``; the section, its values and op-amp. What the Sallen-Key
    plant's SPICE engine measures (overshoot, peak, rise and settling times from ngspice's ``.tran``), on any
    low-pass.

    Parameters
    ----------
    result : designer.plant.circuit_design.CircuitPlantResult
        The design, with its bench (or its square-wave test).
    simulator : str
        The backend.

    Returns
    -------
    designer.tolerance.spice_engine.SpiceContext
        The context.

    Raises
    ------
    DesignError
        No square wave (neither a test nor a bench), or the section is not a low-pass.
    """
    run = result.square
    if run is not None:
        deck, test = run.deck, run.test
    elif result.test is not None:
        from ..plant.circuit_design import square_deck
        topo, amp = result.section, result.opamp
        test = result.test
        deck = square_deck(result.netlist, amp, test, f"{topo.title} plant square-wave test op-amp={amp.name}")
    else:
        raise DesignError("square_hz: the step engine runs the section's square-wave test; give its frequency "
                          "(a positive number of hertz)", param="square_hz")
    return spice_engine.context(deck, result.section, dict(result.values), result.opamp, test, simulator,
                                node=result.netlist.amps[0].out)


def section_step_chunk(ctx, model: tuple, values: dict, start: int = 0, apart: bool = False) -> dict:
    """A chunk's figures with a low-pass section's step engine: the analytic engine's
    (:func:`designer.plant.circuit.evaluate` of ``model``, (topology name, op-amp)), with those SPICE's step
    measures (:data:`designer.tolerance.spice_engine.FIGURES`) in their place, as the Sallen-Key plant's
    :func:`plant_chunk`; ``apart``: SPICE's as ``spice_<figure>`` beside the analytic engine's own, as the
    Sallen-Key plant's :func:`step_chunk` (check-design's yield counts each check on its own engine's figure,
    :data:`designer.tolerance.yields.SECTION_SPICE`). Pure, of picklable arguments.

    Parameters
    ----------
    ctx : designer.tolerance.spice_engine.SpiceContext
        The deck and its square wave (:func:`section_step_context`).
    model : tuple
        (topology name, op-amp).
    values : dict
        Designator -> array over the chunk's builds.
    start : int
        The first build's index.
    apart : bool
        SPICE's figures under ``spice_<figure>``, the analytic engine's all kept.

    Returns
    -------
    dict
        Figure -> array over the builds.
    """
    from ..plant.circuit import evaluate as analytic
    sp = spice_engine.evaluate(ctx, values, start)
    if apart:
        sp = {f"spice_{k}": v for k, v in sp.items()}
    return {**analytic(model, values), **sp}


#: a section plant's SPICE engine: the step's ``.tran`` for a low-pass (it settles to its DC gain, the
#: Sallen-Key plant's engine), the ``.ac`` sweep for the others (a high- or band-pass's step settles to 0)
SECTION_ANALYSES = ("step", "ac")


def section_analysis(topology) -> str:
    """Which SPICE engine a section plant's Monte Carlo runs (:data:`SECTION_ANALYSES`): ``step`` (every build's
    square-wave step in ngspice's ``.tran``, :mod:`.spice_engine`, the Sallen-Key plant's engine) for a low-pass,
    ``ac`` (every build's ``.ac`` fitted, :mod:`.spice_ac`) for a high- or band-pass, whose step settles to 0.

    Parameters
    ----------
    topology : designer.filters.topology.Topology
        The section.

    Returns
    -------
    str
        ``step`` or ``ac``.
    """
    return "step" if topology.kind == "lowpass" else "ac"


def spice_evaluate(ctx, opamp):
    """``evaluate(values) -> figures`` (:func:`plant_chunk` bound to a design; picklable).

    Parameters
    ----------
    ctx : designer.tolerance.spice_engine.SpiceContext
        The deck and its test.
    opamp : designer.core.opamps.OpAmp
        The op-amp.

    Returns
    -------
    functools.partial
        ``evaluate(values) -> figures``.
    """
    import functools
    return functools.partial(plant_chunk, ctx, opamp)


def disagreement(spice: dict, model: dict, index, figures=spice_engine.SHARED) -> dict:
    """Per figure both engines give (``figures``, named alike in both): SPICE minus the model
    over the samples ``index`` (absolute and relative), the sample where it is largest, and
    how many samples only one engine gives a value for (a peak SPICE cannot resolve)."""
    out = {}
    index = np.asarray(index)
    for k in figures:
        s, m = np.asarray(spice[k], float), np.asarray(model[k], float)
        both = np.isfinite(s) & np.isfinite(m)
        if not both.any():
            out[k] = {"compared": 0, "only_one": int(np.count_nonzero(np.isfinite(s) ^ np.isfinite(m)))}
            continue
        d = s[both] - m[both]
        rel = d / np.where(m[both] != 0, np.abs(m[both]), np.nan)
        j = int(np.argmax(np.abs(d)))
        out[k] = {"compared": int(both.sum()), "mean": float(d.mean()), "max_abs": float(np.abs(d[j])),
                  "max_abs_rel": float(np.nanmax(np.abs(rel))) if np.isfinite(rel).any() else None,
                  "worst_sample": int(index[both][j]),
                  "only_one": int(np.count_nonzero(np.isfinite(s) ^ np.isfinite(m)))}
    return out


def _passes(figs: dict, limits) -> np.ndarray:
    from .montecarlo import inside_limits
    return inside_limits(figs, limits)


def spice_checked(idx, worst, rand, model_pass, spice_pass, yield_count: int, n: int, disagree: dict) -> dict:
    """What SPICE on the builds ``idx`` (the tails ``worst`` and the random ``rand``) did to the
    model's verdicts (``model_pass``, against SPICE's ``spice_pass``): the builds it flipped, the flip
    rate among the random ones with its Wilson interval, and the yield of ``n`` builds with the flips
    (``monte_carlo.spice`` of a plant's or a loop's ``--engine both --spice-samples``)."""
    from .stats import wilson
    to_fail, to_pass = idx[model_pass & ~spice_pass], idx[~model_pass & spice_pass]
    corrected = yield_count - to_fail.size + to_pass.size
    is_rand = np.isin(idx, rand)
    flips, of = int(np.count_nonzero(model_pass[is_rand] != spice_pass[is_rand])), int(is_rand.sum())
    return {"samples_checked": int(idx.size), "worst": worst, "random": rand, "disagreement": disagree,
            "flipped": {"pass_to_fail": [int(i) for i in to_fail], "fail_to_pass": [int(i) for i in to_pass]},
            "random_flip_rate": {"count": flips, "of": of, "ci95": list(wilson(flips, of))},
            "yield_model": yield_count / n, "yield_with_spice": corrected / n,
            "yield_shift_pp": 100 * (corrected - yield_count) / n}


def spice_samples(figs: dict, limits, k: int, seed: int) -> tuple:
    """(worst, random) sample indices: per limited figure the ``k`` samples with the least room
    inside (most beyond) its window, and ``k`` others drawn at random.

    Parameters
    ----------
    figs : dict
        Figure -> array over the samples.
    limits : list
        The limits.
    k : int
        The samples taken from each tail and at random.
    seed : int
        The seed of the random ones.

    Returns
    -------
    tuple of numpy.ndarray
        (worst, random).
    """
    n = len(next(iter(figs.values())))
    worst = []
    for lim in limits:
        v = np.asarray(figs[lim.figure], float)
        room = np.minimum(v - lim.min, lim.max - v) / max(lim.max - lim.min, 1e-300)
        room = np.where(np.isfinite(room), room, -np.inf)       # no value: outside, the worst
        worst += [int(i) for i in np.argsort(room, kind="stable")[:k]]
    worst = sorted(set(worst))
    rest = np.setdiff1d(np.arange(n), worst)
    rng = np.random.default_rng(np.random.SeedSequence(seed, spawn_key=(RANDOM_KEY,)))
    rand = sorted(int(i) for i in rng.choice(rest, size=min(k, rest.size), replace=False))
    return worst, rand


def run_picked(mc, idx, evaluate, context, scale=None) -> dict:
    """The figures of the builds ``idx`` of the Monte Carlo ``mc`` (``--spice-samples``: the
    ones SPICE checks), their values taken from the run, chunked through the runner on the same
    workers as the run (``scale``: ``--jobs``, ``--dask``)."""
    from .runner import Picked, Runner, Scale
    picked = {r: v[idx] for r, v in mc.values.items()}
    draw = Picked(mc.nominal, mc.tolerances.of, idx.size, mc.seed, mc.sampler, mc.dist, picked=picked)
    with Runner(scale or Scale()) as run:
        return run.run(evaluate, context, draw)[1]


def plant_monte_carlo_engine(result, series: dict, n: int, seed: int = 0, sampler: str = "random",
                             dist: str = "uniform", tol_items=(), limit_items=(), engine: str = "analytic",
                             spice_k: int | None = None, simulator: str = "ngspice-cli", scale=None,
                             target_ci: float | None = None):
    """:func:`designer.tolerance.montecarlo.plant_monte_carlo` of a plant result (its parts as
    built, op-amp and deck) with the engine ``engine`` (:data:`ENGINES`); ``spice_k``: SPICE on
    the tails and ``spice_k`` random samples only (``both``). ``scale``, ``target_ci``: where the
    samples run and ``--target-ci`` (:mod:`designer.tolerance.runner`).

    Parameters
    ----------
    result : designer.plant.result.PlantResult
        The design.
    series : dict
        ``{"R": series, "C": series}``.
    n : int
        The samples.
    seed : int
        The seed.
    sampler, dist : str
        How the samples are drawn.
    tol_items : sequence of str
        The ``--tol`` items.
    limit_items : sequence of str
        The ``--limit`` items.
    engine : str
        ``analytic``, or a SPICE engine.
    spice_k : int, optional
        The samples SPICE checks from each tail and at random.
    simulator : str
        The backend.
    scale : designer.tolerance.runner.Scale, optional
        Where the chunks run.
    target_ci : float, optional
        ``--target-ci``.

    Returns
    -------
    designer.tolerance.montecarlo.MonteCarlo
        The Monte Carlo.
    """
    where = {"scale": scale, "target_ci": target_ci}
    from .montecarlo import figures_with_fixed, plant_monte_carlo
    if engine not in ENGINES:
        raise DesignError(f"--engine {engine!r} unknown; allowed: {', '.join(ENGINES)}")
    amp = result.opamp
    if engine == "analytic":
        return plant_monte_carlo(result.built, series, amp, n, seed, sampler, dist, tol_items, limit_items, **where)
    ctx = plant_context(result, simulator)
    settings = step_settings(ctx, engine)
    draw = lambda **kw: plant_monte_carlo(result.built, series, amp, n, seed, sampler, dist,  # noqa: E731
                                          tol_items, limit_items, **where, **kw)
    return run_engine(draw, spice_evaluate(ctx, amp), lambda v: figures_with_fixed(v, {}, amp), settings, engine,
                      spice_k, seed, scale, spice_engine.FIGURES, spice_engine.SHARED)


def step_settings(ctx, engine: str) -> dict:
    """The step engine's record under ``monte_carlo.spice`` (the Sallen-Key plant's and a low-pass
    section's): its analysis, backend, time step, the rising half simulated, how fn and zeta are read.

    Parameters
    ----------
    ctx : designer.tolerance.spice_engine.SpiceContext
        The engine's context.
    engine : str
        ``spice`` or ``both``.

    Returns
    -------
    dict
        The record.
    """
    return {"engine": engine, "analysis": "step", "simulator": ctx.simulator, "max_step_s": ctx.max_step_s,
            "rising_half_s": [ctx.t0, ctx.t1],
            "fn_zeta": "second-order equivalents of the simulated step (zeta from the overshoot, fn from "
                       "the peak time); the model's are its dominant pole pair",
            "measured": list(spice_engine.FIGURES)}


def run_engine(draw, evaluate, model, settings: dict, engine: str, spice_k, seed: int, scale, measured, shared):
    """A Monte Carlo with a SPICE engine (``spice`` or ``both``; ``spice_k``: SPICE on the tails and
    ``spice_k`` random builds only), whatever the circuit: the Sallen-Key plant's step engine
    (:mod:`.spice_engine`) or a section's ``.ac`` engine (:mod:`.spice_ac`).

    Parameters
    ----------
    draw : callable
        ``draw(engine_name=.., evaluate=..) -> MonteCarlo``: the circuit's Monte Carlo.
    evaluate : callable
        The SPICE engine's ``evaluate(values) -> figures`` (picklable).
    model : callable
        The analytic engine's ``model(values) -> figures``.
    settings : dict
        The engine's settings, recorded under ``monte_carlo.spice``.
    engine : str
        ``spice`` or ``both``.
    spice_k : int or None
        ``--spice-samples``.
    seed : int
        The draw's seed (the random builds SPICE checks).
    scale : designer.tolerance.runner.Scale or None
        Where the chunks run.
    measured, shared : tuple of str
        The figures SPICE gives; those both engines give (their disagreement).

    Returns
    -------
    designer.tolerance.montecarlo.MonteCarlo
        The Monte Carlo.
    """
    from .montecarlo import apply_engine
    if spice_k is not None:
        mc = draw(engine_name="both")
        n = mc.n       # the builds drawn (--target-ci may stop before --monte-carlo N)
        if not mc.limits:
            raise DesignError("--spice-samples needs --limit: its samples are the tails of each limited figure")
        worst, rand = spice_samples(mc.figures, mc.limits, spice_k, seed)
        idx = np.array(worst + rand, int)
        order = np.argsort(idx)
        idx = idx[order]
        sp = run_picked(mc, idx, apply_engine, evaluate, scale)
        model_pass = mc.passed[idx]
        spice_pass = _passes(sp, mc.limits)
        mc.spice = {**settings, **spice_checked(idx, worst, rand, model_pass, spice_pass, mc.yield_count, n,
                                                disagreement(sp, {k: v[idx] for k, v in mc.figures.items()}, idx,
                                                             shared))}
        for k in measured:          # the CSV: SPICE's figures where simulated
            col = np.full(n, np.nan)
            col[idx] = sp[k]
            mc.figures[f"spice_{k}"] = col
        return mc
    mc = draw(engine_name=engine, evaluate=evaluate)
    n = mc.n
    mc.spice = settings
    figs = model(mc.values)
    if mc.tighten:       # the tightening search runs the model: its yield now is the model's
        mc.tighten["yield_now"] = float(np.mean(_passes(figs, mc.limits)))
    if engine == "both":
        mc.spice["disagreement"] = disagreement(mc.figures, figs, np.arange(n), shared)
        if mc.limits:
            y_model = int(np.count_nonzero(_passes(figs, mc.limits)))
            mc.spice.update(yield_model=y_model / n, yield_with_spice=mc.yield_count / n,
                            yield_shift_pp=100 * (mc.yield_count - y_model) / n)
        for k in shared:
            mc.figures[f"model_{k}"] = figs[k]
    return mc


def section_monte_carlo_engine(result, series: dict, n: int, seed: int = 0, sampler: str = "random",
                               dist: str = "uniform", tol_items=(), limit_items=(), engine: str = "analytic",
                               spice_k: int | None = None, simulator: str = "ngspice-cli", scale=None,
                               target_ci: float | None = None, analysis: str | None = None, tighten: bool = True,
                               apart: bool = False):
    """:func:`plant_monte_carlo_engine` of a plant on a registered section (a
    :class:`~designer.plant.circuit_design.CircuitPlantResult`): the analytic engine over its
    declared parts (:func:`designer.plant.circuit.evaluate`) or, with a SPICE engine, every build in
    ngspice: a low-pass's square-wave step (:mod:`.spice_engine`, the Sallen-Key plant's engine and figures,
    on its bench's square wave: :func:`section_step_context`), another section's ``.ac`` (:mod:`.spice_ac`):
    :func:`section_analysis`. ``monte_carlo.spice.analysis`` records which.

    Parameters
    ----------
    result : designer.plant.circuit_design.CircuitPlantResult
        The design.
    series : dict
        ``{"R": series, "C": series}``.
    n : int
        The builds.
    seed : int
        The seed.
    sampler, dist : str
        How the builds are drawn.
    tol_items, limit_items : sequence of str
        The ``--tol`` and ``--limit`` items.
    engine : str
        :data:`ENGINES`.
    spice_k : int, optional
        The builds SPICE checks from each tail and at random (``both``).
    simulator : str
        The backend.
    scale : designer.tolerance.runner.Scale, optional
        Where the chunks run.
    target_ci : float, optional
        ``--target-ci``.
    analysis : str, optional
        :data:`SECTION_ANALYSES`: ``ac`` runs a low-pass's ``.ac`` instead of its step (None: the rule of
        :func:`section_analysis`).
    tighten : bool
        With limits, also the part to tighten (:func:`designer.tolerance.montecarlo.plant_monte_carlo`).
    apart : bool
        With the engine ``spice``: the step's figures as ``spice_<figure>`` beside the analytic engine's
        (:func:`section_step_chunk`; check-design's yield); an ``.ac``'s replace them either way.

    Returns
    -------
    designer.tolerance.montecarlo.MonteCarlo
        The Monte Carlo.

    Raises
    ------
    DesignError
        An unknown engine or analysis, a step on a section that is no low-pass; ``SR`` in ``tol_items`` but for
        a SPICE step (the other engines are linear: :func:`designer.tolerance.montecarlo.check_section_spread`).
    """
    from ..plant import circuit
    from .montecarlo import check_section_spread, plant_monte_carlo
    if engine not in ENGINES:
        raise DesignError(f"--engine {engine!r} unknown; allowed: {', '.join(ENGINES)}")
    analysis = section_analysis(result.section) if analysis is None else analysis
    check_section_spread(tol_items, slews=engine != "analytic" and analysis == "step")
    model = (result.topology, result.opamp)
    nominal = dict(result.values)
    draw = lambda **kw: plant_monte_carlo(None, series, result.opamp, n, seed, sampler, dist,  # noqa: E731
                                          tol_items, limit_items, tighten=tighten, scale=scale,
                                          target_ci=target_ci, circuit=(nominal, circuit.evaluate, model), **kw)
    if engine == "analytic":
        return draw()
    evaluate, settings, measured, shared = section_engine(result, simulator, engine, analysis, apart)
    return run_engine(draw, evaluate, lambda v: circuit.evaluate(model, v), settings, engine, spice_k, seed, scale,
                      measured, shared)


def section_engine(result, simulator: str = "ngspice-cli", engine: str = "spice", analysis: str | None = None,
                   apart: bool = False):
    """A section plant's SPICE engine (:func:`section_analysis`): (``evaluate(values) -> figures``, picklable;
    its record under ``monte_carlo.spice``; the figures SPICE measures; those the model gives too).

    Parameters
    ----------
    result : designer.plant.circuit_design.CircuitPlantResult
        The design.
    simulator : str
        The backend.
    engine : str
        ``spice`` or ``both`` (recorded).
    analysis : str, optional
        ``step`` or ``ac`` (None: :func:`section_analysis`).
    apart : bool
        A step's figures as ``spice_<figure>`` beside the analytic engine's (:func:`section_step_chunk`).

    Returns
    -------
    tuple
        (evaluate, settings, measured, shared).
    """
    import functools
    from . import spice_ac
    analysis = section_analysis(result.section) if analysis is None else analysis
    if analysis not in SECTION_ANALYSES:
        raise DesignError(f"analysis {analysis!r} unknown; allowed: {', '.join(SECTION_ANALYSES)}", param="analysis")
    model = (result.topology, result.opamp)
    if analysis == "step":
        ctx = section_step_context(result, simulator)
        return (functools.partial(section_step_chunk, ctx, model, apart=apart), step_settings(ctx, engine),
                spice_engine.FIGURES, spice_engine.SHARED)
    ctx = section_context(result, simulator)
    settings = {"engine": engine, "analysis": "ac", "simulator": ctx.simulator, "sweep_hz": [ctx.f_lo_hz, ctx.f_hi_hz],
                "points_per_decade": spice_ac.POINTS_PER_DECADE,
                "fn_zeta": "the section's form fitted to the simulated .ac response over the sweep (Levy's least "
                           "squares); the model's are its dominant pole pair",
                "measured": list(spice_ac.FIGURES)}
    return spice_ac.section_evaluate(ctx, model), settings, spice_ac.FIGURES, spice_ac.FIGURES


def section_context(result, simulator: str = "ngspice-cli"):
    """The SPICE engine's context of a section plant (:func:`designer.tolerance.spice_ac.context`): its
    ``.ac`` deck, its parts as built, the sweep about its ideal fn.

    Parameters
    ----------
    result : designer.plant.circuit_design.CircuitPlantResult
        The design.
    simulator : str
        The backend.

    Returns
    -------
    designer.tolerance.spice_ac.AcContext
        The context.
    """
    from . import spice_ac
    return spice_ac.context(result.deck, result.netlist, result.section, dict(result.values),
                            result.figures["ideal"]["fn_hz"], simulator, result.opamp)


class Replay:
    """One Monte Carlo sample replayed (``--replay I``): its index, the draw's settings, its parts'
    values and its figures from the SPICE engine and the model (the result's ``monte_carlo``)."""

    #: no spread to draw: the sheet shows the build itself (designer.report.tolerance)
    headline = None

    def __init__(self, index: int, settings: dict, values: dict, spice: dict, model: dict,
                 measured=spice_engine.FIGURES, shared=spice_engine.SHARED):
        self.index, self.settings, self.values, self.spice, self.model = index, settings, values, spice, model
        # the figures the engine measures (printed) and those the model gives too (model_<figure> in the CSV)
        self.measured, self.shared = tuple(measured), tuple(shared)

    def to_dict(self) -> dict:
        f = lambda d: {k: (None if not np.isfinite(v) else float(v)) for k, v in d.items()}  # noqa: E731
        return {"replay": {"sample": self.index, "settings": self.settings, "values": dict(self.values),
                           "spice_figures": f(self.spice), "model_figures": f(self.model)}}

    def csv_text(self) -> str:
        from .stats import samples_csv
        text = samples_csv({k: np.array([v]) for k, v in self.values.items()},
                           {**{k: np.array([v]) for k, v in self.spice.items()},
                            **{f"model_{k}": np.array([self.model[k]]) for k in self.shared}})
        head, row = text.split("\n", 1)
        return head + "\n" + str(self.index) + row[row.index(","):]

    def summary_lines(self) -> list:
        st = self.settings
        return [f"Replay of Monte Carlo sample {self.index} (of {st['samples']}, {st['sampler']}, {st['dist']}, "
                f"seed {st['seed']}): " + ", ".join(f"{k} {v:.6g}" for k, v in self.values.items()),
                "  SPICE engine: " + ", ".join(f"{k} {self.spice[k]:.5g}" for k in self.measured),
                "  model: " + ", ".join(f"{k} {self.model[k]:.5g}" for k in self.shared)]


def replay_values(topology, values: dict, series: dict, opamp, index: int, n: int, seed: int, sampler: str,
                  dist: str, tol_items=()) -> tuple:
    """(nominal, tolerances, values) of build ``index`` of an ``n``-build draw over a section's parts
    (``values``, designator -> nominal value: those of ``topology``'s that vary, in its order): exactly the
    values :func:`designer.tolerance.montecarlo.plant_monte_carlo` drew for it, the Sallen-Key plant's
    (:func:`replay_parts`) or any section's.

    Parameters
    ----------
    topology : designer.filters.topology.Topology
        The section.
    values : dict
        Designator -> nominal value of the parts that vary.
    series : dict
        ``{"R": series, "C": series}``.
    opamp : designer.core.opamps.OpAmp
        The op-amp.
    index : int
        The build.
    n : int
        The draw's builds.
    seed : int
        The seed.
    sampler, dist : str
        How the builds are drawn.
    tol_items : sequence of str
        The ``--tol`` items.

    Returns
    -------
    tuple
        (nominal, tolerances, values).
    """
    parts = {r: values[r] for r in topology.designators if r in values}
    return drawn_values(parts, series, opamp, index, n, seed, sampler, dist, tol_items)


def replay_parts(result) -> tuple:
    """(section, designator -> nominal value of the parts its Monte Carlo varies) of a plant result: the
    Sallen-Key plant's (:class:`~designer.plant.result.PlantResult`: the section its parts as built realise,
    the gain pair only for a gain above 1, :func:`designer.tolerance.montecarlo.plant_parts`) or a section
    plant's (:class:`~designer.plant.circuit_design.CircuitPlantResult`: every declared part).

    Parameters
    ----------
    result : designer.plant.result.PlantResult or designer.plant.circuit_design.CircuitPlantResult
        The design.

    Returns
    -------
    tuple
        (designer.filters.topology.Topology, dict).
    """
    if hasattr(result, "built"):
        from ..filters.sallen_key_lowpass_parts import section_of
        from .montecarlo import plant_parts
        return section_of(result.built), plant_parts(result.built)
    return result.section, dict(result.values)


def drawn_values(parts: dict, series: dict, opamp, index: int, n: int, seed: int, sampler: str, dist: str,
                 tol_items=()) -> tuple:
    """(nominal, tolerances, values) of build ``index`` of an ``n``-build draw over the parts ``parts``
    (designator -> nominal value, any circuit's) and the op-amp's spread figures: exactly the values
    :func:`designer.tolerance.montecarlo.plant_monte_carlo` drew for it.

    Parameters
    ----------
    parts : dict
        Designator -> nominal value, in the Monte Carlo's order.
    series : dict
        ``{"R": series, "C": series}``.
    opamp : designer.core.opamps.OpAmp
        The op-amp.
    index : int
        The build.
    n : int
        The draw's builds.
    seed : int
        The seed.
    sampler, dist : str
        How the builds are drawn.
    tol_items : sequence of str
        The ``--tol`` items.

    Returns
    -------
    tuple
        (nominal, tolerances, values).
    """
    from . import sampling
    from .parts import opamp_nominal, resolve
    if not 0 <= index < n:
        raise DesignError(f"--replay {index}: the Monte Carlo has samples 0 to {n - 1}")
    nominal = {**parts, **opamp_nominal(tol_items, opamp)}
    tol = resolve(tol_items, nominal, series)
    v = sampling.values(nominal, tol.of, n, seed, sampler, dist, start=index, stop=index + 1)
    return nominal, tol, {k: float(a[0]) for k, a in v.items()}


def replay(result, series: dict, index: int, n: int, seed: int, sampler: str, dist: str, tol_items=(),
           simulator: str = "ngspice-cli") -> Replay:
    """Build ``index`` of the Monte Carlo on ``result``'s parts (its section and values by designator,
    :func:`replay_parts`), through its SPICE engine (the row ``--engine spice`` gives it) and its model: the
    Sallen-Key plant's step engine (:func:`plant_context`) and third-order model, a low-pass section's step
    engine (:func:`section_step_context`) or another section's ``.ac`` (:func:`section_engine`) and the analytic
    engine (:func:`designer.plant.circuit.evaluate`).

    Parameters
    ----------
    result : designer.plant.result.PlantResult or designer.plant.circuit_design.CircuitPlantResult
        The design.
    series : dict
        ``{"R": series, "C": series}``.
    index : int
        The build replayed.
    n : int
        The draw's builds.
    seed : int
        The seed.
    sampler, dist : str
        How the builds are drawn.
    tol_items : sequence of str
        The ``--tol`` items.
    simulator : str
        The backend.

    Returns
    -------
    Replay
        The build's values and figures.
    """
    topology, nominal = replay_parts(result)
    _, tol, v = replay_values(topology, nominal, series, result.opamp, index, n, seed, sampler, dist, tol_items)
    arr = {k: np.array([x]) for k, x in v.items()}
    if hasattr(result, "built"):         # the Sallen-Key plant: SPICE's step figures, its model's beside
        from .montecarlo import figures_with_fixed
        ctx = plant_context(result, simulator)
        sp, backend = spice_engine.evaluate(ctx, arr, start=index), ctx.simulator
        model, measured, shared = figures_with_fixed(arr, {}, result.opamp), spice_engine.FIGURES, spice_engine.SHARED
    else:                                # a section: the SPICE engine's whole row, the analytic engine's beside
        from ..plant import circuit
        from .montecarlo import check_section_spread
        check_section_spread(tol_items, slews=section_analysis(result.section) == "step")
        evaluate, st, measured, shared = section_engine(result, simulator)
        sp, backend = evaluate(arr, start=index), st["simulator"]
        model = circuit.evaluate((result.topology, result.opamp), arr)
    settings = {"samples": n, "seed": seed, "sampler": sampler, "dist": dist, "engine": "spice",
                "simulator": backend, "tolerances_pct": tol.to_dict()}
    return Replay(index, settings, v, {k: float(a[0]) for k, a in sp.items()},
                  {k: float(model[k][0]) for k in shared}, measured, shared)


def replay_result(result, rep: Replay, simulator: str, r_series=None, c_series=None, package=None, square_hz=None):
    """The full analysis (sheet, deck, SPICE) of the replayed build's parts as drawn (its values by designator,
    no E-series rounding) on the design's section and op-amp (with the build's gain-bandwidth and slew rate when
    they vary, :func:`designer.tolerance.parts.sample_opamp`); its ``monte_carlo`` is the :class:`Replay`. The
    Sallen-Key plant's (analyze-plant: its square wave, waveforms) or a section's (analyze-plant --topology: its
    ``.ac`` check, and the square-wave test of ``square_hz``, else, for a low-pass whose engine is the step, of the
    design's bench square wave, the one its engine stepped).

    Parameters
    ----------
    result : designer.plant.result.PlantResult or designer.plant.circuit_design.CircuitPlantResult
        The design.
    rep : Replay
        The build replayed.
    simulator : str
        The backend.
    r_series, c_series : str, optional
        The parts' series, shown on the sheet (None: the design's).
    package : str, optional
        The op-amp's package (None: the design's).
    square_hz : float or str, optional
        A section's square-wave test's frequency (None: as above).

    Returns
    -------
    designer.plant.result.PlantResult or designer.plant.circuit_design.CircuitPlantResult
        The analysis of the build.
    """
    from .parts import sample_opamp
    v = rep.values
    amp = sample_opamp(result.opamp, {k: np.array([x]) for k, x in v.items()}, 0)
    if hasattr(result, "built"):
        out = _replay_plant(result, v, amp, simulator, r_series, c_series, package)
    else:
        from ..plant.circuit_design import analyze_circuit_plant
        topo, s = result.section, result.sourcing
        if square_hz is None and section_analysis(topo) == "step" and result.test is not None:
            square_hz = result.test.frequency_hz
        out = analyze_circuit_plant(topo.name, {r: v[r] for r in topo.designators}, amp, result.target.fc_hz,
                                    result.target.zeta, r_series or s.r_series, c_series or s.c_series,
                                    package or result.package, simulate=True, simulator=simulator,
                                    amplitude_v=result.amplitude_v, square_hz=square_hz)
    out.notes.append(f"Monte Carlo sample {rep.index} replayed (seed {rep.settings['seed']}, "
                     f"{rep.settings['sampler']}, {rep.settings['dist']}): these are its exact drawn values")
    out.monte_carlo = rep
    return out


def _replay_plant(result, values: dict, amp, simulator: str, r_series, c_series, package):
    """analyze-plant of the Sallen-Key plant's build ``values`` (by designator; a gain pair not drawn is the
    design's) on the op-amp ``amp`` and the design's square wave."""
    from ..filters.sallen_key_lowpass_parts import parts_of
    from ..plant.design import analyze_plant
    from ..plant.spec import AnalysisSpec
    parts = parts_of(values, base=result.built, gain=None)

    class _SampleSpec(AnalysisSpec):
        @property
        def amp(self):            # the sample's op-amp (its GBW, SR drawn), not the catalogue's
            return amp
    spec = _SampleSpec(parts, opamp=result.opamp.name, r_series=r_series, c_series=c_series,
                       amplitude_v=result.test.amplitude_v, square_hz=result.test.frequency_hz, package=package)
    return analyze_plant(spec, simulate=True, simulator=simulator)
