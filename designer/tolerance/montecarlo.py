"""A Monte Carlo of a Sallen-Key plant as built (analytic engine, :mod:`.plant`):
its parts drawn within their tolerances, every figure of every sample, the
statistics, the yield against the user's limits with its 95 % Wilson interval,
each part's share of each limited figure's variance, the samples that fail each
limit (the worst few), and the part whose tolerance halved raises the yield most.
"""

from __future__ import annotations

from dataclasses import dataclass, field

import numpy as np

from ..core.errors import DesignError
from ..core.figure_titles import figure_spread
from ..filters.sallen_key_lowpass_parts import gain_of, part_values, section_of
from ..plant.circuit import evaluate as section_evaluate
from . import plant as engine
from . import runner, sampling
from .parts import DISTRIBUTIONS, opamp_nominal, resolve
from .stats import Limit, failing_samples, figure_stats, parse_limit, samples_csv, variance_shares, wilson

__all__ = ["MAX_SAMPLES", "MAX_TARGET_CI", "MIN_SAMPLES", "MonteCarlo", "NO_SLEW", "NO_SLEW_SECTION",
           "check_section_spread", "TARGET_ROUND", "apply_engine",
           "check_target_ci", "parse_target_ci", "plant_monte_carlo", "plant_parts", "plant_worst_case"]

#: the number of samples allowed
MIN_SAMPLES, MAX_SAMPLES = 10, 10 ** 7
#: failing samples listed per limit (the worst)
WORST = 5
#: --target-ci: the samples of the first round, and the fewest a round adds
TARGET_ROUND = 500
#: --target-ci: the widest half-width accepted (a fraction)
MAX_TARGET_CI = 0.5
#: --tol SR on the analytic plant engine (a linear model: nothing in it slews)
NO_SLEW = ("--tol SR: the plant's analytic model is linear, no figure of it depends on the slew rate; spread SR "
           "with --engine spice or both (ngspice's op-amp slews)")
#: --tol SR on a plant of another topology where its engine is linear (the analytic one; a high- or band-pass's .ac)
NO_SLEW_SECTION = ("--tol SR: a section plant's analytic model and a high- or band-pass's SPICE engine (ngspice's .ac "
                   "sweep: small signal) are linear, no figure of them depends on the slew rate; spread SR with "
                   "--engine spice or both on a low-pass section (its step slews), or drop SR from --tol (GBW=.. "
                   "spreads the op-amp)")


def check_section_spread(tol_items, slews: bool = False) -> None:
    """Refuse ``--tol SR`` on a plant of another topology (:data:`NO_SLEW_SECTION`), before any work, unless its
    engine ``slews`` (a low-pass's SPICE step engine, :func:`designer.tolerance.spice_mc.section_analysis`).

    Parameters
    ----------
    tol_items : sequence of str
        The ``--tol`` items.
    slews : bool
        The engine simulates the op-amp's slew rate.

    Raises
    ------
    DesignError
        One line, ``param`` "SR".
    """
    if not slews and any(str(t).split("=")[0].strip().upper() == "SR" for t in tol_items or ()):
        raise DesignError(NO_SLEW_SECTION, param="SR")


@dataclass
class MonteCarlo:
    """The run's settings and what it found (arrays kept for the CSV; :meth:`to_dict` is the JSON)."""

    n: int
    seed: int
    sampler: str
    dist: str
    engine: str
    tolerances: object                 #: parts.Tolerances
    nominal: dict                      #: designator -> nominal value
    values: dict = field(repr=False)   #: designator -> sampled values
    figures: dict = field(repr=False)  #: figure -> array over the samples
    nominal_figures: dict = field(default_factory=dict)
    limits: tuple = ()
    stats: dict = field(default_factory=dict)
    passed: np.ndarray = field(default=None, repr=False)
    shares: dict = field(default_factory=dict)
    failing: dict = field(default_factory=dict)
    tighten: dict | None = None
    target: dict | None = None         #: --target-ci: the half-width asked, whether reached, each round's end
    spice: dict | None = None          #: SPICE beside the model (designer.tolerance.spice_mc), when asked

    @property
    def headline(self) -> str:
        """The figure a sheet shows first: the first limited one, else fn_hz."""
        return self.limits[0].figure if self.limits else "fn_hz"

    @property
    def yield_count(self) -> int:
        return int(np.count_nonzero(self.passed)) if self.passed is not None else self.n

    def yield_interval(self) -> tuple:
        return wilson(self.yield_count, self.n)

    def record_target(self, target_ci: float | None, n_max: int, ends: list) -> None:
        """``--target-ci``: the half-width asked, whether the yield's interval reached it, the
        most builds allowed and each round's end (:func:`target_plan`); nothing without it."""
        if target_ci is not None:
            lo, hi = self.yield_interval()
            self.target = {"half_width_pct": 100 * target_ci, "max_samples": n_max,
                           "reached": (hi - lo) / 2 < target_ci, "rounds": ends}

    def to_dict(self) -> dict:
        lo, hi = self.yield_interval()
        settings = {"samples": self.n, "seed": self.seed, "sampler": self.sampler, "dist": self.dist,
                    "engine": self.engine, "tolerances_pct": self.tolerances.to_dict()}
        if self.target is not None:
            settings["target_ci"] = self.target
        return {"settings": settings,
                "nominal_parts": self.nominal, "nominal_figures": self.nominal_figures,
                "limits": [lim.to_dict() for lim in self.limits],
                "statistics": {k: v.to_dict() for k, v in self.stats.items()},
                "yield": None if not self.limits else {"passed": self.yield_count, "samples": self.n,
                                                        "fraction": self.yield_count / self.n,
                                                        "ci95": [lo, hi], "interval": "Wilson"},
                "variance_shares": {"method": "standardised regression coefficients, squared", **self.shares},
                "failing_samples": self.failing, "tighten": self.tighten,
                **({} if self.spice is None else {"spice": self.spice})}

    def csv_text(self) -> str:
        """One row per sample: its index, every varied part's value, every figure."""
        return samples_csv(self.values, self.figures)

    def summary_lines(self) -> list:
        """A few lines for the text summary."""
        mc = self
        out = [f"Monte Carlo: {mc.n} samples ({mc.sampler}, {mc.dist}, seed {mc.seed}), tolerances "
               + ", ".join(f"{r} {100 * t:g} %" for r, t in mc.tolerances.of.items())]
        for k in ("fn_hz", "zeta", "overshoot_pct"):
            s = mc.stats[k]
            p = s.percentiles
            # percentiles are empty when no build has the figure (stats.figure_stats leaves NaN out)
            out.append("  " + figure_spread(k, s.nominal, s.mean, s.std, p.get(2.5), p.get(97.5)))
        return out + self.yield_lines()

    def yield_lines(self) -> list:
        """The yield with its interval and the part to buy tighter (none without limits)."""
        mc, out = self, []
        if mc.limits:
            lo, hi = mc.yield_interval()
            out.append(f"  yield {100 * mc.yield_count / mc.n:.2f} % ({mc.yield_count}/{mc.n}; 95 % Wilson interval "
                       f"{100 * lo:.2f}..{100 * hi:.2f} %) within " + ", ".join(lim.text() for lim in mc.limits))
            if mc.tighten:
                t = mc.tighten
                out.append(f"  buy {t['part']} tighter: at {t['tolerance_pct']:g} % the yield is {100 * t['yield']:.2f} %")
        if mc.spice is not None:
            out += spice_lines(mc)
        return out


def spice_lines(mc) -> list:
    """The summary's lines on SPICE's part of a Monte Carlo."""
    s = mc.spice
    # the step engine's record (the Sallen-Key plant's, a low-pass section's) or a section's .ac sweep
    how = (f"rising half, max step {s['max_step_s']:.3g} s" if "max_step_s" in s else
           f".ac {s['sweep_hz'][0]:.4g} Hz to {s['sweep_hz'][1]:.4g} Hz")
    out = [f"  engine {s['engine']}: ngspice ({s['simulator']}), {how}"
           + (f"; SPICE on {s['samples_checked']} samples ({len(s['worst'])} from the tails, "
              f"{len(s['random'])} random)" if "samples_checked" in s else "")]
    for k, d in (s.get("disagreement") or {}).items():
        if d.get("compared"):
            rel = "" if d["max_abs_rel"] is None else f" ({100 * d['max_abs_rel']:.3g} %)"
            out.append(f"    SPICE - model, {k}: mean {d['mean']:.3g}, largest {d['max_abs']:.3g}{rel} "
                       f"at sample {d['worst_sample']}")
    if "yield_shift_pp" in s:
        out.append(f"    yield: model {100 * s['yield_model']:.2f} %, with SPICE {100 * s['yield_with_spice']:.2f} % "
                   f"({s['yield_shift_pp']:+.2f} pp)")
    return out


def figures_with_fixed(values: dict, fixed: dict, opamp) -> dict:
    return engine.plant_figures({**{k: np.full(next(iter(values.values())).shape, v) for k, v in fixed.items()},
                                 **values}, opamp)


def inside_limits(figs: dict, limits) -> np.ndarray:
    ok = np.ones(next(iter(figs.values())).shape, bool)
    for lim in limits:
        ok &= lim.inside(figs[lim.figure])
    return ok


def plant_parts(parts) -> dict:
    """Designator -> nominal value of the plant's parts that vary (R3, R4 only for a gain above 1).

    Parameters
    ----------
    parts : designer.plant.sallenkey.SallenKeyParts
        The plant's parts.

    Returns
    -------
    dict
        Designator -> nominal value.
    """
    nominal = part_values(parts)
    # the gain pair varies only where it sets a gain (K = 1 + R4/R3 above 1)
    if not gain_of(nominal) > 1:
        nominal = {r: v for r, v in nominal.items() if r not in section_of(parts).choice_parts}
    return nominal


def plant_worst_case(parts, series: dict, opamp, tol_items=()):
    """:func:`designer.tolerance.worstcase.worst_case` of the plant's figures over its tolerance box.

    Parameters
    ----------
    parts : designer.plant.sallenkey.SallenKeyParts
        The plant's parts.
    series : dict
        ``{"R": series, "C": series}``.
    opamp : designer.core.opamps.OpAmp
        The op-amp.
    tol_items : sequence of str
        The ``--tol`` items.

    Returns
    -------
    designer.tolerance.worstcase.WorstCase
        The extremes.
    """
    from .worstcase import worst_case
    nominal = plant_parts(parts)
    tol = resolve(tol_items, nominal, series)
    return worst_case(lambda v: engine.plant_figures(v, opamp), nominal, tol.of)


def plant_monte_carlo(parts, series: dict, opamp, n: int, seed: int = 0, sampler: str = "random",
                      dist: str = "uniform", tol_items=(), limit_items=(), tighten: bool = True, scale=None,
                      target_ci: float | None = None, engine_name: str = "analytic", evaluate=None,
                      circuit=None) -> MonteCarlo:
    """A Monte Carlo of the Sallen-Key ``parts`` (:class:`~designer.plant.sallenkey.SallenKeyParts`).

    Parameters
    ----------
    parts : SallenKeyParts
    series : dict
        ``{"R": "E24", "C": "E12"}``: the series the parts come from (their default tolerances;
        None for a part typed by hand).
    opamp : OpAmp
        The op-amp of the op-amp-aware figures (``fn_hz``, ``zeta``, the step).
    n : int
        Samples, :data:`MIN_SAMPLES` to :data:`MAX_SAMPLES`.
    seed : int
        Sample i is a function of (seed, i) alone.
    sampler, dist : str
        :data:`designer.tolerance.sampling.SAMPLERS`; ``uniform`` or ``normal``.
    tol_items, limit_items : sequence of str
        ``--tol`` items (``R=1%``, ``C2=2%``) and ``--limit`` items (``fn_hz=3.3k:3.7k``; or
        :class:`~designer.tolerance.stats.Limit` objects, one-sided ones too).
    tighten : bool
        Also find the part whose tolerance halved raises the yield most (one more run per part,
        always with the analytic model).
    engine_name, evaluate : str, callable
        The engine's name and, for another engine than the analytic one, its
        ``evaluate(values) -> {figure: array}`` (:mod:`designer.tolerance.spice_mc`).
    circuit : tuple, optional
        A plant on another topology than the Sallen-Key low-pass: (nominal {designator: value},
        chunk function, its context) of its analytic engine (:func:`designer.plant.circuit.evaluate`
        with (topology name, op-amp)); ``parts`` is then unused.
    scale : designer.tolerance.runner.Scale, optional
        Where the samples run (``--jobs``, ``--dask``, a progress bar); default in this process.
        The result is the same wherever they run.
    target_ci : float, optional
        ``--target-ci``: draw in rounds until the yield's 95 % Wilson half-width is below it
        (a fraction), ``n`` samples at most (:func:`target_rounds`); needs limits.

    Returns
    -------
    MonteCarlo
        The Monte Carlo.
    """
    check_draw(n, dist, sampler)
    limits = tuple(t if isinstance(t, Limit) else parse_limit(t, engine.FIGURES) for t in limit_items or ())
    if circuit is None:
        # the Sallen-Key plant: the generic chunk function on its section (its own exact figures)
        circuit = (plant_parts(parts), section_evaluate, engine.context(part_values(parts), opamp))
    analytic = circuit[1:]
    nominal = {**circuit[0], **opamp_nominal(tol_items, opamp)}
    if "SR" in nominal and evaluate is None:
        raise DesignError(NO_SLEW)
    tol = resolve(tol_items, nominal, series)
    until, first = target_plan(target_ci, limits, sampler, n, lambda figs: inside_limits(figs, limits))
    # another engine's evaluate(values) travels to the workers as the context of _apply
    chunk_fn, context = analytic if evaluate is None else (apply_engine, evaluate)
    with runner.Runner(scale or runner.Scale()) as run:
        values, figs, ends = run.run(chunk_fn, context, runner.Draw(nominal, tol.of, n, seed, sampler, dist),
                                     first, until)
        mc = _analyse(seed, sampler, dist, tol, nominal, values, figs, limits,
                      evaluate or (lambda v: analytic[0](analytic[1], v)), engine_name)
        mc.record_target(target_ci, n, ends)
        if tighten and limits:
            mc.tighten = _tighten(run, mc, analytic, n)
            if engine_name != "analytic":
                mc.tighten["engine"] = "analytic"
    return mc


def check_draw(n, dist: str, sampler: str, what: str = "samples") -> None:
    """A Monte Carlo's draw settings checked before any work: ``n`` a whole number from
    :data:`MIN_SAMPLES` to :data:`MAX_SAMPLES`, a known distribution and sampler (one line each).

    Parameters
    ----------
    n : int
        The number of draws.
    dist : str
        The distribution's name.
    sampler : str
        The sampler's name.
    what : str
        What is drawn, for the message.
    """
    if isinstance(n, bool) or not isinstance(n, (int, np.integer)) or not MIN_SAMPLES <= n <= MAX_SAMPLES:
        raise DesignError(f"--monte-carlo must be a whole number of {what} from {MIN_SAMPLES} to {MAX_SAMPLES:.0e}, "
                          f"got {n!r}")
    if dist not in DISTRIBUTIONS:
        raise DesignError(f"--dist {dist!r} unknown; allowed: {', '.join(DISTRIBUTIONS)}")
    if sampler not in sampling.SAMPLERS:
        raise DesignError(f"--sampler {sampler!r} unknown; allowed: {', '.join(sampling.SAMPLERS)}")


def apply_engine(evaluate, values: dict) -> dict:
    """The runner's chunk function for an engine given as ``evaluate(values)`` (a picklable partial).

    Parameters
    ----------
    evaluate : callable
        ``evaluate(values) -> figures``.
    values : dict
        Designator -> array over the chunk's samples.

    Returns
    -------
    dict
        Figure -> array over the samples.
    """
    return evaluate(values)


def parse_target_ci(text) -> float:
    """``--target-ci``: ``1%``, ``0.5 %`` or a fraction (``0.01``).

    Parameters
    ----------
    text : str
        ``--target-ci``'s value.

    Returns
    -------
    float
        The width (fraction).
    """
    from ..core.units import parse_value
    t = str(text).strip()
    pct = t.endswith("%")
    try:
        v = parse_value(t[:-1].strip() if pct else t, "--target-ci")
    except DesignError:
        v = None
    if v is None or not np.isfinite(v):
        raise DesignError(f"--target-ci {text!r}: give the yield interval's half-width as a percentage, such as "
                          f"1% (above 0, at most {100 * MAX_TARGET_CI:g} %)")
    v = v / 100 if pct else v
    if not 0 < v <= MAX_TARGET_CI:
        raise DesignError(f"--target-ci must be a half-width above 0 and at most {100 * MAX_TARGET_CI:g} %, got "
                          f"{text!r}")
    return float(v)


def check_target_ci(target_ci, limits, sampler) -> None:
    """``--target-ci``'s value and what it needs, checked before any work.

    Parameters
    ----------
    target_ci : float or None
        ``--target-ci``'s value.
    limits : list
        The ``--limit`` items parsed (a yield needs one).
    sampler : str
        The sampler.
    """
    if not isinstance(target_ci, (int, float)) or not 0 < target_ci <= MAX_TARGET_CI:
        raise DesignError(f"--target-ci must be a half-width above 0 and at most {100 * MAX_TARGET_CI:g} %, got "
                          f"{target_ci!r}")
    if not limits:
        raise DesignError("--target-ci sets the yield's interval: it needs --limit FIGURE=MIN:MAX")
    if sampler == "lhs":
        raise DesignError("--target-ci draws in rounds, and a Latin hypercube's strata depend on the final N: "
                          "use --sampler random or sobol")


def half_width(k: int, n: int) -> float:
    """The 95 % Wilson interval's half-width of k in n."""
    lo, hi = wilson(k, n)
    return (hi - lo) / 2


def target_plan(target_ci, limits, sampler, n: int, passed) -> tuple:
    """``(until, first)`` of :meth:`designer.tolerance.runner.Runner.run`: without ``--target-ci``
    (None) every one of the ``n`` samples at once; with it (checked, :func:`check_target_ci`),
    :data:`TARGET_ROUND` first, then :func:`target_rounds` of ``passed``."""
    if target_ci is None:
        return None, n
    check_target_ci(target_ci, limits, sampler)
    return target_rounds(passed, target_ci, n), min(n, TARGET_ROUND)


def target_rounds(passed, target: float, n_max: int):
    """``until`` of :meth:`designer.tolerance.runner.Runner.run` for ``--target-ci``: after a
    round of n samples with k in the yield (``passed(figures)``: a boolean array, the plant's
    inside every limit, the loop's stable too), None when the Wilson half-width is below
    ``target``, else the next total: where the half-width would reach it at the same yield,
    at least :data:`TARGET_ROUND` more and at most twice n (a first estimate is rough)."""
    def until(figs):
        ok = passed(figs)
        n = ok.size
        k = int(np.count_nonzero(ok))
        if half_width(k, n) < target:
            return None
        m = n
        while m < n_max and half_width(round(k / n * m), m) >= target:   # the n that would do at this yield
            m = min(n_max, 2 * m)
        lo = n
        while lo < m - 1:
            mid = (lo + m) // 2
            lo, m = (lo, mid) if half_width(round(k / n * mid), mid) < target else (mid, m)
        return min(n_max, max(n + TARGET_ROUND, min(2 * n, -(-m // TARGET_ROUND) * TARGET_ROUND)))
    return until


def _analyse(seed, sampler, dist, tol, nominal, values, figs, limits, figure_of, engine_name) -> MonteCarlo:
    """The statistics of the samples drawn (``figure_of(values)``: the nominal's figures)."""
    n = len(next(iter(figs.values())))
    nominal_figs = {k: float(v[0]) for k, v in figure_of({r: np.array([x]) for r, x in nominal.items()}).items()}
    by_fig = {lim.figure: lim for lim in limits}
    stats = {k: figure_stats(k, v, nominal_figs[k], by_fig.get(k)) for k, v in figs.items()}
    rel = {r: values[r] / nominal[r] - 1 for r in values}
    shares = {k: variance_shares(rel, figs[k]) for k in (by_fig or ("fn_hz", "zeta", "overshoot_pct"))}
    mc = MonteCarlo(n, seed, sampler, dist, engine_name, tol, nominal, values, figs, nominal_figs, limits, stats,
                    inside_limits(figs, limits) if limits else None, shares)
    mc.failing.update(failing_samples(figs, limits, WORST))
    return mc


#: builds up to which the tightening's runs (the analytic model, vectorised: 20000 builds in about
#: 0.1 s) stay in this process: a pool's round trips (forks, a cluster's tasks) cost more than them
TIGHTEN_HERE = 20000


def _tighten(run, mc: MonteCarlo, analytic, n_max: int) -> dict:
    """The part whose tolerance halved raises the yield most (the same samples' deviations, each
    part's halved in turn), and the yield it gives (on ``run``'s workers, or here for a few builds:
    the same figures either way)."""
    if mc.n <= TIGHTEN_HERE:
        run = runner.Runner()
    best = None
    for ref, t in mc.tolerances.of.items():
        draw = runner.Draw(mc.nominal, dict(mc.tolerances.of, **{ref: t / 2}), n_max, mc.seed, mc.sampler, mc.dist)
        _, figs, _ = run.run(*analytic, draw, mc.n, progress=False)
        y = float(np.mean(inside_limits(figs, mc.limits)))
        if best is None or y > best[1]:
            best = (ref, y)
    return {"part": best[0], "tolerance_pct": 100 * mc.tolerances.of[best[0]] / 2, "yield": best[1],
            "yield_now": mc.yield_count / mc.n}
