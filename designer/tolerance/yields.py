"""The yield a ``check-design`` spec requires (issue 17): the spec's own
``checks:`` limits, named as :mod:`designer.check.figures` names them, counted
on an engine's figures over the builds its ``tolerances:`` allow.

The analytic engine computes the models' figures: where a check limits a SPICE
figure (``overshoot_pct``), the op-amp-aware model's figure stands in for it
(:data:`PLANT`, :data:`LOOP`); a check on a figure no engine computes (``nrms``,
``rise_time_s`` of a plant) is not counted, and the verdict says so. A report-only
check (``fail: false``) is never counted.

The SPICE engine (``engine: spice``) simulates every build in ngspice (a plant:
:mod:`.spice_engine`; a loop: :mod:`.spice_loop`) and counts the SPICE step
figures a check names (``overshoot_pct``, ``peak_time_s``, ``rise_time_s``,
``settling_time_s``) from those runs (:data:`PLANT_SPICE`, :data:`LOOP_SPICE`); the
other figures (``fn_hz``, the gains, the margins, ``model_*``) stay the models',
as check-design reads them on the nominal build.

A plant on another section than the Sallen-Key low-pass (``topology:``) runs the
engine the command line and the page run on it (:func:`designer.tolerance.spice_mc.section_monte_carlo_engine`,
the rule of :func:`designer.tolerance.spice_mc.section_analysis`): with ``engine: spice`` a low-pass's square-wave
step in ngspice, whose step figures a check names are counted from SPICE as the Sallen-Key plant's
(:data:`SECTION_SPICE` ``step``; ``tolerances: {SR: ..}`` spreads the slew its op-amp model has), another
section's ``.ac`` fitted (``ac``: fn_hz, zeta, q and gain SPICE's, the step figures the fitted pair's).

A designed filter (``kind: filter``) counts its checks on :data:`FILTER`'s figures
(the mask's among them) on :func:`designer.tolerance.filter.filter_spec_yield`'s builds:
the analytic engine only, its SPICE comparison is analyze-filter's ``--spice-samples``.
"""

from __future__ import annotations

from dataclasses import dataclass

from ..core.units import format_eng
from .loop import LIMITABLE, STANDS_IN
from .stats import Limit

__all__ = ["ENGINES", "FILTER", "LOOP", "PLANT", "SECTION", "SECTION_SPICE", "TABLES", "counted", "figure_table",
           "spec_yield"]

#: check-design's plant figure -> the analytic plant engine's (designer.tolerance.plant.FIGURES)
PLANT = {**{f: f for f in ("fn_hz", "zeta", "q", "ideal_fn_hz", "ideal_zeta", "ideal_q", "gain", "overshoot_pct",
                            "peak_time_s")},
         "fn_opamp_hz": "fn_hz", "zeta_opamp": "zeta", "model_overshoot_pct": "overshoot_pct",
         "model_peak_time_s": "peak_time_s"}
#: check-design's loop figure -> the analytic loop engine's (designer.tolerance.loop.FIGURES)
LOOP = {**{f: f for f in LIMITABLE}, **STANDS_IN}
#: check-design's filter figure -> the filter engine's (designer.tolerance.filter: the same op-amp-aware figures)
FILTER = {f: f for f in ("passband_loss_db", "stopband_attenuation_db", "f3_hz", "f3_low_hz", "f3_high_hz",
                          "delay_error_pct")}
BY_KIND = {"plant": PLANT, "pid": LOOP, "filter": FILTER}
#: the SPICE step figures a check may name, counted from each build's ngspice run
SPICE_STEP = ("overshoot_pct", "peak_time_s", "rise_time_s", "settling_time_s")
#: check-design's plant figure -> the SPICE engine's (the models' besides SPICE's ``spice_*``)
PLANT_SPICE = {**PLANT, **{f: f"spice_{f}" for f in SPICE_STEP}}
#: check-design's loop figure -> the SPICE engine's (the analytic loop's besides SPICE's ``spice_*``)
LOOP_SPICE = {**{f: f for f in LIMITABLE}, **{f: f"spice_{f}" for f in SPICE_STEP}}
#: the table key of a plant on another topology than the Sallen-Key low-pass: the analytic engine's figures
#: (:func:`designer.plant.circuit.evaluate`, named as the Sallen-Key plant's model names them), and with the
#: SPICE engine those of its analysis (:data:`SECTION_SPICE`)
SECTION = "section"
#: check-design's figure -> a section plant's SPICE engine's, per analysis
#: (:func:`designer.tolerance.spice_mc.section_analysis`): ``step`` (a low-pass: SPICE's step figures as
#: ``spice_*`` beside the analytic engine's, :func:`designer.tolerance.spice_mc.section_step_chunk` apart, as
#: :data:`PLANT_SPICE`); ``ac`` (a high- or band-pass, whose step settles to 0: fn_hz, zeta, q and gain fitted to
#: each build's ngspice .ac, the step figures the fitted pair's, :func:`designer.tolerance.spice_ac.section_chunk`)
SECTION_SPICE = {"step": PLANT_SPICE, "ac": PLANT}
TABLES = {"analytic": {**BY_KIND, SECTION: PLANT},
          "spice": {"plant": PLANT_SPICE, "pid": LOOP_SPICE, SECTION: SECTION_SPICE}}
#: the engines a spec's yield may use
ENGINES = ("analytic", "spice")


def figure_table(kind: str, engine: str = "analytic", analysis: str | None = None) -> dict:
    """check-design's figure -> the engine's, of a spec's kind (:data:`TABLES`).

    Parameters
    ----------
    kind : str
        ``plant``, ``pid``, ``filter`` or :data:`SECTION` (a plant on another topology).
    engine : str
        The yield's engine (:data:`ENGINES`).
    analysis : str, optional
        A section's SPICE analysis (:data:`SECTION_SPICE`: ``step`` or ``ac``,
        :func:`designer.tolerance.spice_mc.section_analysis`); needed for a section with the SPICE engine.

    Returns
    -------
    dict
        Spec figure -> engine figure.
    """
    out = TABLES[engine][kind]
    if out is SECTION_SPICE:
        if analysis not in SECTION_SPICE:
            raise ValueError(f"a section's SPICE yield needs its analysis ({', '.join(SECTION_SPICE)}), "
                             f"got {analysis!r}")
        out = SECTION_SPICE[analysis]
    return out


def counted(kind: str, checks, engine: str = "analytic", analysis: str | None = None) -> tuple:
    """(the checks the yield counts, the names of those it cannot): failing checks whose figure the
    ``engine`` computes, and the others'.

    Parameters
    ----------
    kind : str
        ``plant``, ``pid``, ``filter`` or :data:`SECTION` (a plant on another topology).
    checks : sequence of designer.check.limits.Limit
        The spec's checks.
    engine : str
        The yield's engine.
    analysis : str, optional
        A section's SPICE analysis (:func:`figure_table`).

    Returns
    -------
    tuple
        (the checks counted, the names of the others).
    """
    known = figure_table(kind, engine, analysis)
    live = [c for c in checks if c.fail]
    return tuple(c for c in live if c.figure in known), tuple(c.figure for c in live if c.figure not in known)


@dataclass(frozen=True)
class YieldVerdict:
    """A spec's yield on one corner: the Monte Carlo, the limits counted (spec names), its verdict."""

    mc: object                  #: designer.tolerance.montecarlo.MonteCarlo (or the loop's)
    required: float             #: the fraction the spec requires
    names: dict                 #: engine figure -> the spec's name of it
    skipped: tuple              #: the spec's figures not counted

    @property
    def fraction(self) -> float:
        return self.mc.yield_count / self.mc.n

    @property
    def ok(self) -> bool:
        return self.fraction >= self.required

    def losses(self) -> list:
        """(spec figure, builds lost) largest first; a loop's unstable builds as ``stable``."""
        out = [(self.names[k], v["count"]) for k, v in self.mc.failing.items()]
        p = getattr(self.mc, "p_unstable", None)
        if p is not None:
            out.append(("stable", p["count"]))
        return sorted(out, key=lambda kv: -kv[1])

    def corner(self) -> tuple:
        """(build index, {designator: (value, relative deviation)}) of the worst build of the figure that
        loses most (None when every build passes)."""
        lost = self.losses()
        if not lost or not lost[0][1]:
            return None, {}
        fig = lost[0][0]
        mc = self.mc
        if fig == "stable":
            i = mc.unstable_samples[0]
        else:
            engine = next(k for k, v in self.names.items() if v == fig)
            i = mc.failing[engine]["worst"][0]
        return i, {r: (float(mc.values[r][i]), float(mc.values[r][i] / mc.nominal[r] - 1)) for r in mc.values}

    def message(self) -> str:
        """``yield: 91.2 % (...) below min 95 %; fn_hz loses most ...; the corner: build 12, R1 ...``."""
        mc = self.mc
        lo, hi = mc.yield_interval()
        over = ", ".join(dict.fromkeys(self.names.values()))
        text = (f"yield: {100 * self.fraction:.4g} % ({mc.yield_count}/{mc.n} builds; 95 % Wilson interval "
                f"{100 * lo:.4g} % to {100 * hi:.4g} %) {'at or above' if self.ok else 'below'} min "
                f"{100 * self.required:g} % over {over} ({mc.engine} engine, {mc.sampler} sampler, seed {mc.seed}")
        text += ")" if not self.skipped else f"; not counted, no engine figure: {', '.join(self.skipped)})"
        if self.ok:
            return text
        fig, count = self.losses()[0]
        lim = next((lim for lim in mc.limits if self.names[lim.figure] == fig), None)
        where = "unstable" if lim is None else f"outside {lim.window()}"
        i, parts = self.corner()
        corner = ", ".join(f"{r} {format_eng(v, _unit(r), 4)} ({100 * d:+.2f} %)" for r, (v, d) in parts.items())
        return f"{text}; {fig} loses most: {count} builds {where}; the corner (build {i}, its worst): {corner}"


def _unit(ref: str) -> str:
    return {"R": "Ohm", "C": "F", "G": "Hz", "S": "V/s"}[ref[0]]


def spec_yield(kind: str, res, checks, required: float, samples: int, seed: int, tol_items=(),
               sampler: str = "random", dist: str = "uniform", engine: str = "analytic",
               simulator: str = "ngspice-cli") -> YieldVerdict:
    """The yield of one corner's design ``res`` (a PlantResult or a PidResult) over ``checks``
    (:class:`designer.check.limits.Limit`, the spec's), required to reach ``required``.

    Parameters
    ----------
    kind : str
        ``plant``, ``pid`` or ``filter``.
    res : designer.plant.result.PlantResult or designer.pid.result.PidResult or FilterRun
        The corner's design (a filter: check-design's run, :func:`designer.tolerance.filter.filter_spec_yield`;
        a plant on a registered section: a :class:`~designer.plant.circuit_design.CircuitPlantResult`, its
        engines :func:`designer.tolerance.spice_mc.section_monte_carlo_engine`'s).
    checks : sequence of designer.check.limits.Limit
        The spec's checks.
    required : float
        The yield required (fraction).
    samples : int
        The Monte Carlo's samples.
    seed : int
        Its seed.
    tol_items : sequence of str
        The spec's ``tolerances:`` as ``--tol`` items (``R=1%``, ``SR=20%``); they win over the
        series' defaults, as ``--tol`` does.
    engine : str
        :data:`ENGINES`: ``analytic`` (the models) or ``spice`` (every build simulated in ngspice
        on the backend ``simulator``, the module docstring).
    sampler, dist : str
        How the samples are drawn (:mod:`designer.tolerance.sampling`).
    simulator : str
        The SPICE engine's backend.

    Returns
    -------
    YieldVerdict
        The Monte Carlo, the limits counted and the verdict.
    """
    from .loop import loop_monte_carlo, loop_series
    from .montecarlo import plant_monte_carlo
    from .spice_mc import section_analysis
    section = kind == "plant" and hasattr(res, "section")
    key = SECTION if section else kind
    analysis = section_analysis(res.section) if section else None
    use, skipped = counted(key, checks, engine, analysis)
    known = figure_table(key, engine, analysis)
    limits = tuple(Limit(known[c.figure], c.min, c.max) for c in use)
    names = {known[c.figure]: c.figure for c in use}
    if kind == "filter":   # a FilterRun of check-design: its design and the spec's mask
        from .filter import filter_spec_yield
        mc = filter_spec_yield(res.design, res.case.mask, limits, samples, seed, tol_items, sampler, dist)
        return YieldVerdict(mc, required, names, skipped)
    if section:
        # a plant on a registered section: the engine the command line and the page run on it (its analytic
        # engine, or in ngspice a low-pass's step, another section's .ac; SR refused but where the step slews),
        # the step's figures apart from the analytic engine's so that each check counts its own (SECTION_SPICE)
        from .spice_mc import section_monte_carlo_engine
        s = res.sourcing
        mc = section_monte_carlo_engine(res, {"R": s.r_series, "C": s.c_series}, samples, seed, sampler, dist,
                                        tol_items, limits, engine, simulator=simulator, tighten=False, apart=True)
    elif kind == "plant":
        s = res.sourcing
        evaluate = None
        if engine == "spice":
            from .spice_mc import spice_step_evaluate
            evaluate = spice_step_evaluate(res, simulator)
        mc = plant_monte_carlo(res.built, {"R": s.r_series, "C": s.c_series}, res.opamp, samples, seed, sampler,
                               dist, tol_items, limits, tighten=False, engine_name=engine, evaluate=evaluate)
    else:
        spice = None
        if engine == "spice":
            from . import spice_loop
            from .loop import loop_parts
            spice = ("spice", spice_loop.evaluate,
                     spice_loop.context(res, tuple(loop_parts(res, tol_items)), simulator))
        mc = loop_monte_carlo(res, loop_series(res), samples, seed, sampler, dist, tol_items, limits, tighten=False,
                              engine=spice)
    return YieldVerdict(mc, required, names, skipped)
