"""A PID loop's Monte Carlo with SPICE (issue 17): design-pid's and analyze-pid's
``--engine spice|both``, ``--spice-samples K`` and ``--replay I``, with the
plant's semantics (:mod:`.spice_mc`), on the loop's SPICE engine (:mod:`.spice_loop`:
a Sallen-Key plant's loop and a model plant's alike).

A loop's builds have two sets of step figures: the analytic loop's ``model_*``
and SPICE's ``spice_*`` (:data:`designer.tolerance.spice_loop.FIGURES`). A
``--limit`` on a SPICE name (``overshoot_pct``, ``peak_time_s``, ``rise_time_s``,
``settling_time_s``) counts SPICE's figure where SPICE ran and the model's
(``model_*``, standing in) where it did not; a limit on any other figure (the
margins, the gains, ``model_*``) counts the analytic loop's, as design-pid reads
them. A build is in the yield when its loop is stable and inside every limit.

- ``spice``: every build simulated; the yield counts SPICE's figures.
- ``both``: the same, with SPICE minus the model per step figure (mean, largest,
  the build where it is largest) and the yield the model alone gives.
- ``both`` with ``--spice-samples K``: the analytic loop on every build; SPICE on
  the K builds nearest or furthest beyond each limited figure's window plus K drawn
  at random from the rest (:func:`designer.tolerance.spice_mc.spice_samples`, the
  same choice as the plant's), through the same runner (``--jobs``, ``--dask``);
  the verdicts SPICE flips, and the yield with those flips applied.
- The part to buy tighter is searched with the analytic loop, the model's limits
  (as the plant's: ``tighten.engine`` says so; ``yield_now`` is the model's).
- ``--replay I``: build I alone, its values drawn again from (seed, I), through
  the SPICE engine (its figures equal the run's row), and its own bundle: analyze-pid
  of its exact parts and op-amp (:func:`replay_result`).
"""

from __future__ import annotations

import dataclasses

import numpy as np

from ..core.errors import DesignError
from . import spice_loop

__all__ = ["loop_monte_carlo_engine", "parse_limit", "replay", "replay_result"]

#: the SPICE step figures a --limit may name (the analytic loop's ``model_*`` stand in for them)
STEP = spice_loop.STEP


def parse_limit(text):
    """A ``--limit`` on a loop figure for the SPICE engines: a SPICE name counts ``spice_<figure>``.

    Parameters
    ----------
    text : str
        The ``--limit`` item.

    Returns
    -------
    designer.tolerance.stats.Limit
        The limit.
    """
    from .loop import LIMITABLE
    from .stats import Limit, parse_limit as parse
    lim = text if isinstance(text, Limit) else parse(text, LIMITABLE + STEP)
    return dataclasses.replace(lim, figure=f"spice_{lim.figure}") if lim.figure in STEP else lim


def model_limit(lim):
    """The same window on the analytic loop's figure (``spice_x`` -> ``model_x``)."""
    f = lim.figure
    return dataclasses.replace(lim, figure="model_" + f[6:]) if f.startswith("spice_") else lim


def _settings(ctx, engine: str) -> dict:
    return {"engine": engine, "simulator": ctx.simulator, "max_step_s": ctx.max_step_s,
            "rising_half_s": [ctx.t0, ctx.t1], "measured": list(spice_loop.FIGURES),
            "limits_counted": "a limit on overshoot_pct, peak_time_s, rise_time_s or settling_time_s counts "
                              "SPICE's figure where SPICE ran (the analytic loop's model_* elsewhere); the "
                              "others are the analytic loop's"}


def _model_figures(figs: dict) -> dict:
    """The analytic loop's step figures under the SPICE figures' plain names (for the disagreement)."""
    return {f: figs[f"model_{f}"] for f in STEP}


def _spice_figures(figs: dict) -> dict:
    return {f: figs[f"spice_{f}"] for f in STEP}


def loop_monte_carlo_engine(result, series: dict, n: int, seed: int = 0, sampler: str = "random",
                            dist: str = "uniform", tol_items=(), limit_items=(), engine: str = "analytic",
                            spice_k: int | None = None, simulator: str = "ngspice-cli", scale=None,
                            target_ci: float | None = None):
    """:func:`designer.tolerance.loop.loop_monte_carlo` of a design-pid or analyze-pid result with the
    engine ``engine`` (:data:`designer.tolerance.spice_mc.ENGINES`); ``spice_k``: SPICE on the tails
    and ``spice_k`` random builds only (``both``). ``scale``, ``target_ci``: where the builds run and
    ``--target-ci`` (:mod:`designer.tolerance.runner`). Returns a :class:`~designer.tolerance.loop.LoopMonteCarlo`
    (its ``spice``: the module docstring).

    Parameters
    ----------
    result : designer.pid.result.PidResult
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
    designer.tolerance.loop.LoopMonteCarlo
        The loop's Monte Carlo.
    """
    from .loop import stable_and_inside, engine_of, loop_monte_carlo, loop_parts
    from .spice_mc import ENGINES, disagreement, run_picked, spice_checked, spice_samples
    if engine not in ENGINES:
        raise DesignError(f"--engine {engine!r} unknown; allowed: {', '.join(ENGINES)}")
    where = {"scale": scale, "target_ci": target_ci}
    if engine == "analytic":
        return loop_monte_carlo(result, series, n, seed, sampler, dist, tol_items, limit_items, **where)
    limits = tuple(parse_limit(t) for t in limit_items or ())
    models = tuple(model_limit(lim) for lim in limits)
    ctx = spice_loop.context(result, tuple(loop_parts(result, tol_items)), simulator)
    settings = _settings(ctx, engine)
    if spice_k is not None:
        if not limits:
            raise DesignError("--spice-samples needs --limit: its samples are the tails of each limited figure")
        mc = loop_monte_carlo(result, series, n, seed, sampler, dist, tol_items, models,
                              engine=("both", *engine_of(result)), **where)
        n = mc.n
        worst, rand = spice_samples(mc.figures, mc.limits, spice_k, seed)
        idx = np.array(sorted(worst + rand), int)
        sp = run_picked(mc, idx, spice_loop.evaluate, ctx, scale)
        model_pass = mc.passed[idx]
        spice_pass = stable_and_inside(sp, limits)
        disagree = disagreement(_spice_figures(sp), {f: v[idx] for f, v in _model_figures(mc.figures).items()},
                                idx, STEP)
        mc.spice = {**settings, **spice_checked(idx, worst, rand, model_pass, spice_pass, mc.yield_count, n,
                                                disagree)}
        for k in spice_loop.FIGURES:        # the CSV: SPICE's figures where simulated
            col = np.full(n, np.nan)
            col[idx] = sp[k]
            mc.figures[k] = col
        return mc
    fn, analytic_ctx = engine_of(result)
    mc = loop_monte_carlo(result, series, n, seed, sampler, dist, tol_items, limits,
                          engine=(engine, spice_loop.evaluate, ctx), tighten_with=(fn, analytic_ctx, models), **where)
    if mc.tighten:
        mc.tighten["engine"] = "analytic"
    mc.spice = settings
    if engine == "both":
        mc.spice["disagreement"] = disagreement(_spice_figures(mc.figures), _model_figures(mc.figures),
                                                np.arange(mc.n), STEP)
        if limits:
            y_model = int(np.count_nonzero(stable_and_inside(mc.figures, models)))
            mc.spice.update(yield_model=y_model / mc.n, yield_with_spice=mc.yield_count / mc.n,
                            yield_shift_pp=100 * (mc.yield_count - y_model) / mc.n)
    return mc


class LoopReplay:
    """One build of a loop's Monte Carlo replayed (``--replay I``): its index, the draw's
    settings, its parts' values and every figure the SPICE engine gives it (the analytic
    loop's and SPICE's, as the run's row); the result's ``monte_carlo``."""

    #: no spread to draw: the sheet shows the build itself (designer.report.tolerance)
    headline = None

    def __init__(self, index: int, settings: dict, values: dict, figures: dict):
        self.index, self.settings, self.values, self.figures = index, settings, values, figures

    def to_dict(self) -> dict:
        f = lambda d: {k: (None if not np.isfinite(v) else float(v)) for k, v in d.items()}  # noqa: E731
        sp = {k: v for k, v in self.figures.items() if k in spice_loop.FIGURES}
        model = {k: v for k, v in self.figures.items() if k not in spice_loop.FIGURES}
        return {"replay": {"sample": self.index, "settings": self.settings, "values": dict(self.values),
                           "spice_figures": f(sp), "model_figures": f(model)}}

    def csv_text(self) -> str:
        """The build's row, as the run's monte-carlo.csv has it (its index, parts, figures)."""
        from .stats import samples_csv
        text = samples_csv({k: np.array([v]) for k, v in self.values.items()},
                           {k: np.array([v]) for k, v in self.figures.items()})
        head, row = text.split("\n", 1)
        return head + "\n" + str(self.index) + row[row.index(","):]

    def summary_lines(self) -> list:
        st, f = self.settings, self.figures
        return [f"Replay of Monte Carlo build {self.index} of the loop (of {st['samples']}, {st['sampler']}, "
                f"{st['dist']}, seed {st['seed']}): " + ", ".join(f"{k} {v:.6g}" for k, v in self.values.items()),
                "  SPICE engine: " + ", ".join(f"{k[6:]} {f[k]:.5g}" for k in spice_loop.FIGURES),
                "  analytic loop: " + ", ".join(f"{k} {f[k]:.5g}" for k in (*(f"model_{s}" for s in STEP),
                                                                          "phase_margin_deg", "slew_delay_s"))]


def replay_values(result, series: dict, index: int, n: int, seed: int, sampler: str, dist: str,
                  tol_items=()) -> tuple:
    """(tolerances, values) of build ``index`` of an ``n``-build draw on the result's loop: exactly
    the values :func:`designer.tolerance.loop.loop_monte_carlo` drew for it."""
    from . import sampling
    from .loop import loop_parts
    from .parts import resolve
    if not 0 <= index < n:
        raise DesignError(f"--replay {index}: the Monte Carlo has builds 0 to {n - 1}")
    nominal = loop_parts(result, tol_items)
    tol = resolve(tol_items, nominal, series)
    v = sampling.values(nominal, tol.of, n, seed, sampler, dist, start=index, stop=index + 1)
    return tol, {k: float(a[0]) for k, a in v.items()}


def replay(result, series: dict, index: int, n: int, seed: int, sampler: str, dist: str, tol_items=(),
           simulator: str = "ngspice-cli") -> LoopReplay:
    """Build ``index`` of the draw on ``result``'s loop, through the loop's SPICE engine.

    Parameters
    ----------
    result : designer.pid.result.PidResult
        The design.
    series : dict
        ``{"R": series, "C": series}``.
    index : int
        The build replayed.
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
    LoopReplay
        The build's values and figures.
    """
    tol, v = replay_values(result, series, index, n, seed, sampler, dist, tol_items)
    ctx = spice_loop.context(result, tuple(v), simulator)
    figs = spice_loop.evaluate(ctx, {k: np.array([x]) for k, x in v.items()}, start=index)
    settings = {"samples": n, "seed": seed, "sampler": sampler, "dist": dist, "engine": "spice",
                "simulator": ctx.simulator, "tolerances_pct": tol.to_dict()}
    return LoopReplay(index, settings, v, {k: float(a[0]) for k, a in figs.items()})


def replay_spec(spec, result, values: dict):
    """The analyze-pid spec of a replayed build: ``spec`` (the run's) with the build's exact parts (the
    plant's too for a Sallen-Key plant; a model plant stays as given), no gains to meet (as built), and
    the run's square wave."""
    from ..pid.blocks import PidParts
    from ..filters.sallen_key_lowpass_parts import refs
    parts = PidParts(**{f.name: (values[f.name.upper()] if f.name.upper() in values else getattr(result.parts, f.name))
                        for f in dataclasses.fields(PidParts)})
    change = dict(controller_parts=parts, tuning=None, kp=None, ti_s=None, td_s=None, target_overshoot_pct=None,
                  target_settling_s=None, square_hz=result.test.frequency_hz)
    if spec.plant.process is None:
        from ..pid.plant_spec import PlantSource
        p = result.plant
        # the network's parts from the build; the gain pair the design's (the build's R3 and R4 are the
        # controller's: the loop's values share its designators)
        change.update(plant=PlantSource(plant_parts=p.with_values({r: values[r] for r in refs(with_gain=False)})))
    return dataclasses.replace(spec, **change)


def replay_result(spec, result, rep: LoopReplay, simulator: str):
    """The full analyze-pid result (sheet, deck, waveforms) of the replayed build: its exact parts,
    on the design's op-amp with the build's gain-bandwidth and slew rate when they vary, and the
    run's square wave; its ``monte_carlo`` is the :class:`LoopReplay`.

    Parameters
    ----------
    spec : designer.pid.spec.PidSpec
        The design's request.
    result : designer.pid.result.PidResult
        The design.
    rep : LoopReplay
        The build replayed.
    simulator : str
        The backend.

    Returns
    -------
    designer.pid.result.PidResult
        The analysis of the build.
    """
    from ..pid.design import analyze_pid
    from .parts import sample_opamp
    amp = sample_opamp(result.opamp, {k: np.array([x]) for k, x in rep.values.items()}, 0)
    out = analyze_pid(replay_spec(spec, result, rep.values), simulate=True, simulator=simulator, opamp=amp)
    out.notes.append(f"Monte Carlo build {rep.index} replayed (seed {rep.settings['seed']}, "
                     f"{rep.settings['sampler']}, {rep.settings['dist']}): these are its exact drawn values")
    out.monte_carlo = rep
    return out
