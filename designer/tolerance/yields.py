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

A designed filter (``kind: filter``) counts its checks on :data:`FILTER`'s figures
(the mask's among them) on :func:`designer.tolerance.filter.filter_spec_yield`'s builds:
the analytic engine only, its SPICE comparison is analyze-filter's ``--spice-samples``.
"""

from __future__ import annotations

from dataclasses import dataclass

from ..core.units import format_eng
from .loop import LIMITABLE, STANDS_IN
from .stats import Limit

__all__ = ["ENGINES", "FILTER", "LOOP", "PLANT", "SECTION", "TABLES", "counted", "spec_yield"]

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
#: (:func:`designer.plant.circuit.evaluate`) under both engines; with the SPICE engine fn_hz, zeta, q and gain
#: are fitted to each build's ngspice .ac and the step figures follow from the fitted pair
#: (:func:`designer.tolerance.spice_ac.section_chunk`): its SPICE run has no step to measure
SECTION = "section"
TABLES = {"analytic": {**BY_KIND, SECTION: PLANT}, "spice": {"plant": PLANT_SPICE, "pid": LOOP_SPICE, SECTION: PLANT}}
#: the engines a spec's yield may use
ENGINES = ("analytic", "spice")


def counted(kind: str, checks, engine: str = "analytic") -> tuple:
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

    Returns
    -------
    tuple
        (the checks counted, the names of the others).
    """
    table = TABLES[engine][kind]
    live = [c for c in checks if c.fail]
    return tuple(c for c in live if c.figure in table), tuple(c.figure for c in live if c.figure not in table)


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
        analytic engine, :func:`designer.plant.circuit.evaluate`).
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
    section = kind == "plant" and hasattr(res, "section")
    use, skipped = counted(SECTION if section else kind, checks, engine)
    table = TABLES[engine][SECTION if section else kind]
    limits = tuple(Limit(table[c.figure], c.min, c.max) for c in use)
    names = {table[c.figure]: c.figure for c in use}
    if kind == "filter":   # a FilterRun of check-design: its design and the spec's mask
        from .filter import filter_spec_yield
        mc = filter_spec_yield(res.design, res.case.mask, limits, samples, seed, tol_items, sampler, dist)
        return YieldVerdict(mc, required, names, skipped)
    if section:
        # a plant on a registered section: its analytic engine over the declared parts (and GBW), or every
        # build's .ac in ngspice (designer.tolerance.spice_ac)
        from ..plant import circuit
        from .montecarlo import check_section_spread
        check_section_spread(tol_items)
        s = res.sourcing
        model = (res.topology, res.opamp)
        evaluate = None
        if engine == "spice":
            from . import spice_ac
            evaluate = spice_ac.section_evaluate(spice_ac.context(
                res.deck, res.netlist, res.section, dict(res.values), res.figures["ideal"]["fn_hz"], simulator,
                res.opamp), model)
        mc = plant_monte_carlo(None, {"R": s.r_series, "C": s.c_series}, res.opamp, samples, seed, sampler, dist,
                               tol_items, limits, tighten=False, engine_name=engine, evaluate=evaluate,
                               circuit=(dict(res.values), circuit.evaluate, model))
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
