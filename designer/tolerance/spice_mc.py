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

__all__ = ["drawn_values", "plant_context", "plant_monte_carlo_engine", "replay", "replay_result", "replay_values", "run_engine",
           "section_context", "section_monte_carlo_engine", "section_step_context", "section_replay", "section_replay_result",
           "spice_evaluate", "spice_samples"]

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
    plant with its square-wave test (a :class:`~designer.plant.circuit_design.CircuitPlantResult` designed
    or analysed with ``square_hz``, ``--square-freq``): that test's deck (the section's netlist, output net
    ``vout``), the section, its values and op-amp. What the Sallen-Key plant's SPICE engine measures
    (overshoot, peak, rise and settling times from ngspice's ``.tran``), on any low-pass.

    Parameters
    ----------
    result : designer.plant.circuit_design.CircuitPlantResult
        The design, with its square-wave test.
    simulator : str
        The backend.

    Returns
    -------
    designer.tolerance.spice_engine.SpiceContext
        The context.

    Raises
    ------
    DesignError
        No square-wave test, or the section is not a low-pass.
    """
    run = result.square
    if run is None:
        raise DesignError("square_hz: the step engine runs the section's square-wave test; give its frequency "
                          "(a positive number of hertz)", param="square_hz")
    return spice_engine.context(run.deck, result.section, dict(result.values), result.opamp, run.test, simulator,
                                node=result.netlist.amps[0].out)


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
    settings = {"engine": engine, "simulator": ctx.simulator, "max_step_s": ctx.max_step_s,
                "rising_half_s": [ctx.t0, ctx.t1],
                "fn_zeta": "second-order equivalents of the simulated step (zeta from the overshoot, fn from "
                           "the peak time); the model's are its dominant pole pair",
                "measured": list(spice_engine.FIGURES)}
    draw = lambda **kw: plant_monte_carlo(result.built, series, amp, n, seed, sampler, dist,  # noqa: E731
                                          tol_items, limit_items, **where, **kw)
    return run_engine(draw, spice_evaluate(ctx, amp), lambda v: figures_with_fixed(v, {}, amp), settings, engine,
                      spice_k, seed, scale, spice_engine.FIGURES, spice_engine.SHARED)


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
                               target_ci: float | None = None):
    """:func:`plant_monte_carlo_engine` of a plant on a registered section (a
    :class:`~designer.plant.circuit_design.CircuitPlantResult`): the analytic engine over its
    declared parts (:func:`designer.plant.circuit.evaluate`) or, with a SPICE engine, every
    build's ``.ac`` in ngspice (:mod:`.spice_ac`).

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

    Returns
    -------
    designer.tolerance.montecarlo.MonteCarlo
        The Monte Carlo.

    Raises
    ------
    DesignError
        An unknown engine; ``SR`` in ``tol_items`` (both engines are linear:
        :func:`designer.tolerance.montecarlo.check_section_spread`).
    """
    from ..plant import circuit
    from . import spice_ac
    from .montecarlo import check_section_spread, plant_monte_carlo
    if engine not in ENGINES:
        raise DesignError(f"--engine {engine!r} unknown; allowed: {', '.join(ENGINES)}")
    check_section_spread(tol_items)
    model = (result.topology, result.opamp)
    nominal = dict(result.values)
    draw = lambda **kw: plant_monte_carlo(None, series, result.opamp, n, seed, sampler, dist,  # noqa: E731
                                          tol_items, limit_items, scale=scale, target_ci=target_ci,
                                          circuit=(nominal, circuit.evaluate, model), **kw)
    if engine == "analytic":
        return draw()
    ctx = section_context(result, simulator)
    settings = {"engine": engine, "simulator": ctx.simulator, "sweep_hz": [ctx.f_lo_hz, ctx.f_hi_hz],
                "points_per_decade": spice_ac.POINTS_PER_DECADE,
                "fn_zeta": "the section's form fitted to the simulated .ac response over the sweep (Levy's least "
                           "squares); the model's are its dominant pole pair",
                "measured": list(spice_ac.FIGURES)}
    return run_engine(draw, spice_ac.section_evaluate(ctx, model), lambda v: circuit.evaluate(model, v), settings,
                      engine, spice_k, seed, scale, spice_ac.FIGURES, spice_ac.FIGURES)


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


def replay_values(parts, series: dict, opamp, index: int, n: int, seed: int, sampler: str, dist: str,
                  tol_items=()) -> tuple:
    """(nominal, tolerances, values) of sample ``index`` of an ``n``-sample draw: exactly the
    values :func:`designer.tolerance.montecarlo.plant_monte_carlo` drew for it.

    Parameters
    ----------
    parts : designer.plant.sallenkey.SallenKeyParts
        The plant's parts.
    series : dict
        ``{"R": series, "C": series}``.
    opamp : designer.core.opamps.OpAmp
        The op-amp.
    index : int
        The sample.
    n : int
        The draw's samples.
    seed : int
        The seed.
    sampler, dist : str
        How the samples are drawn.
    tol_items : sequence of str
        The ``--tol`` items.

    Returns
    -------
    tuple
        (nominal, tolerances, values).
    """
    from .montecarlo import plant_parts
    return drawn_values(plant_parts(parts), series, opamp, index, n, seed, sampler, dist, tol_items)


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
    """Sample ``index`` of the draw on ``result``'s parts, through the SPICE engine and the model.

    Parameters
    ----------
    result : designer.plant.result.PlantResult
        The design.
    series : dict
        ``{"R": series, "C": series}``.
    index : int
        The sample replayed.
    n : int
        The draw's samples.
    seed : int
        The seed.
    sampler, dist : str
        How the samples are drawn.
    tol_items : sequence of str
        The ``--tol`` items.
    simulator : str
        The backend.

    Returns
    -------
    Replay
        The sample's values and figures.
    """
    from .montecarlo import figures_with_fixed
    _, tol, v = replay_values(result.built, series, result.opamp, index, n, seed, sampler, dist, tol_items)
    arr = {k: np.array([x]) for k, x in v.items()}
    ctx = plant_context(result, simulator)
    sp = spice_engine.evaluate(ctx, arr, start=index)
    model = figures_with_fixed(arr, {}, result.opamp)
    settings = {"samples": n, "seed": seed, "sampler": sampler, "dist": dist, "engine": "spice",
                "simulator": ctx.simulator, "tolerances_pct": tol.to_dict()}
    return Replay(index, settings, v, {k: float(a[0]) for k, a in sp.items()},
                  {k: float(model[k][0]) for k in spice_engine.SHARED})


def replay_result(result, rep: Replay, simulator: str, r_series=None, c_series=None, package=None):
    """The full analyze-plant result (sheet, deck, waveforms) of the replayed sample's parts, exact
    values (no E-series rounding), on the design's op-amp (with the sample's gain-bandwidth and slew
    rate when they vary, :func:`designer.tolerance.parts.sample_opamp`) and square wave; its ``monte_carlo`` is the :class:`Replay`.

    Parameters
    ----------
    result : designer.plant.result.PlantResult
        The design.
    rep : Replay
        The sample replayed.
    simulator : str
        The backend.
    r_series, c_series : str, optional
        The parts' series, shown on the sheet.
    package : str, optional
        The op-amp's package.

    Returns
    -------
    designer.plant.result.PlantResult
        The analysis of the sample.
    """
    from ..plant.design import analyze_plant
    from ..filters.sallen_key_lowpass_parts import parts_of
    from ..plant.spec import AnalysisSpec
    from .parts import sample_opamp
    v = rep.values
    parts = parts_of(v, base=result.built, gain=None)
    amp = sample_opamp(result.opamp, {k: np.array([x]) for k, x in v.items()}, 0)

    class _SampleSpec(AnalysisSpec):
        @property
        def amp(self):            # the sample's op-amp (its GBW, SR drawn), not the catalogue's
            return amp
    spec = _SampleSpec(parts, opamp=result.opamp.name, r_series=r_series, c_series=c_series,
                       amplitude_v=result.test.amplitude_v, square_hz=result.test.frequency_hz, package=package)
    out = analyze_plant(spec, simulate=True, simulator=simulator)
    out.notes.append(f"Monte Carlo sample {rep.index} replayed (seed {rep.settings['seed']}, "
                     f"{rep.settings['sampler']}, {rep.settings['dist']}): these are its exact drawn values")
    out.monte_carlo = rep
    return out


def section_replay(result, series: dict, index: int, n: int, seed: int, sampler: str, dist: str, tol_items=(),
                   simulator: str = "ngspice-cli") -> Replay:
    """Build ``index`` of the Monte Carlo on a section plant's parts (:func:`section_monte_carlo_engine`'s
    draw), through its SPICE engine (the build's ``.ac`` in ngspice, :func:`designer.tolerance.spice_ac.section_chunk`:
    the row ``--engine spice`` gives it) and the analytic engine.

    Parameters
    ----------
    result : designer.plant.circuit_design.CircuitPlantResult
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
    from ..plant import circuit
    from . import spice_ac
    _, tol, v = drawn_values(dict(result.values), series, result.opamp, index, n, seed, sampler, dist, tol_items)
    arr = {k: np.array([x]) for k, x in v.items()}
    ctx = section_context(result, simulator)
    model = (result.topology, result.opamp)
    sp = spice_ac.section_chunk(ctx, model, arr, start=index)
    figs = circuit.evaluate(model, arr)
    settings = {"samples": n, "seed": seed, "sampler": sampler, "dist": dist, "engine": "spice",
                "simulator": ctx.simulator, "tolerances_pct": tol.to_dict()}
    return Replay(index, settings, v, {k: float(a[0]) for k, a in sp.items()},
                  {k: float(figs[k][0]) for k in spice_ac.FIGURES}, spice_ac.FIGURES, spice_ac.FIGURES)


def section_replay_result(result, rep: Replay, simulator: str, square_hz=None):
    """The analysis (sheet, deck, SPICE's ``.ac`` check) of the replayed build's parts as drawn (no E-series
    rounding) on the design's section and op-amp (with the build's gain-bandwidth and slew rate when they
    vary); its ``monte_carlo`` is the :class:`Replay`.

    Parameters
    ----------
    result : designer.plant.circuit_design.CircuitPlantResult
        The design.
    rep : Replay
        The build replayed.
    simulator : str
        The backend.
    square_hz : float or str, optional
        The square-wave bench test's frequency (None: none).

    Returns
    -------
    designer.plant.circuit_design.CircuitPlantResult
        The analysis of the build (``mode`` "analyze").
    """
    from ..plant.circuit_design import analyze_circuit_plant
    from .parts import sample_opamp
    topo = result.section
    values = {r: rep.values[r] for r in topo.designators}
    amp = sample_opamp(result.opamp, {k: np.array([x]) for k, x in rep.values.items()}, 0)
    s = result.sourcing
    out = analyze_circuit_plant(topo.name, values, amp, result.target.fc_hz, result.target.zeta, s.r_series,
                                s.c_series, result.package, simulate=True, simulator=simulator,
                                amplitude_v=result.amplitude_v, square_hz=square_hz)
    out.notes.append(f"Monte Carlo sample {rep.index} replayed (seed {rep.settings['seed']}, "
                     f"{rep.settings['sampler']}, {rep.settings['dist']}): these are its exact drawn values")
    out.monte_carlo = rep
    return out
