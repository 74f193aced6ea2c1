"""A Monte Carlo request, validated once: :class:`MonteCarloSpec` holds what the
(n, seed) and (engine, k, i) tuples of the command line carried, with the
sampler, distribution, tolerances and limits, so that every front end (the web
page, and later the command line and check-design) hands the library one typed
object; :func:`plant_tolerance` runs the plant's tolerance analysis from it.

Errors name the spec's parameters (``n``, ``seed``, ``target_ci``): each front
end shows them under its own names (the page's field labels, the command
line's ``--monte-carlo``). The statistics themselves (the yield's 95 % Wilson
interval, the part to tighten) are :mod:`designer.tolerance.montecarlo`'s,
after Wilson (1927), "Probable inference, the law of succession, and
statistical inference", JASA 22.
"""

from __future__ import annotations

from dataclasses import dataclass

from ..core.errors import DesignError, ParamError
from .montecarlo import MAX_SAMPLES, MIN_SAMPLES
from .parts import DISTRIBUTIONS
from .sampling import SAMPLERS

__all__ = ["ENGINES", "MonteCarloSpec", "loop_tolerance", "plant_tolerance", "section_tolerance"]

#: where each build's figures come from (the plant's; a loop's Monte Carlo is analytic)
ENGINES = ("analytic", "spice", "both")
#: the spec's parameters, as the messages mark them
_PARAMS = ("n", "seed", "sampler", "dist", "tol", "limits", "target_ci", "engine", "spice_samples")


def _whole(value, name: str, lo: int, hi: int | None) -> int:
    """``value`` (a number, or text as typed) as a whole number from ``lo`` to ``hi``."""
    try:
        v = int(str(value).strip()) if not isinstance(value, bool) else None
    except ValueError:
        v = None
    if v is None and isinstance(value, float) and value.is_integer():
        v = int(value)
    if v is None or v < lo or (hi is not None and v > hi):
        top = "" if hi is None else f" to {hi:.0e}" if hi >= 10 ** 6 else f" to {hi}"
        raise DesignError(f"{name} must be a whole number from {lo}{top}, got {str(value)[:40]!r}", param=name)
    return v


@dataclass(frozen=True)
class MonteCarloSpec:
    """A Monte Carlo of builds within the parts' tolerances, checked on construction.

    Parameters
    ----------
    n : int or str
        Builds drawn, ``MIN_SAMPLES`` to ``MAX_SAMPLES`` (with ``target_ci``: at most).
    seed : int or str
        Build i depends on (seed, i) alone; whole, >= 0.
    sampler, dist : str
        :data:`designer.tolerance.sampling.SAMPLERS`; ``uniform`` or ``normal``.
    tol : tuple of str
        Tolerance items (``R=1%``, ``C2=2%``, ``GBW=30%``); empty: the series'.
    limits : tuple of str
        The yield's windows (``fn_hz=3.3k:3.7k``), checked by the engine against its figures.
    target_ci : float, str or None
        Draw in rounds until the yield's 95 % half-width is below it (``1%`` or ``0.01``).
    engine : str
        :data:`ENGINES`.
    spice_samples : int, str or None
        With ``engine="both"`` and limits: SPICE on the tails plus this many random builds.

    Returns
    -------
    MonteCarloSpec
        Its fields normalised: numbers as numbers, tuples as tuples.

    Raises
    ------
    DesignError
        One line naming the parameter at fault and what is allowed.
    """

    n: int
    seed: int = 0
    sampler: str = "random"
    dist: str = "uniform"
    tol: tuple = ()
    limits: tuple = ()
    target_ci: float | None = None
    engine: str = "analytic"
    spice_samples: int | None = None

    def __post_init__(self):
        def put(name, value):
            object.__setattr__(self, name, value)   # frozen: normalised once, here
        put("n", _whole(self.n, "n", MIN_SAMPLES, MAX_SAMPLES))
        put("seed", _whole(self.seed, "seed", 0, None))
        for name, allowed in (("sampler", SAMPLERS), ("dist", DISTRIBUTIONS), ("engine", ENGINES)):
            if getattr(self, name) not in allowed:
                raise DesignError(f"{name} {str(getattr(self, name))[:40]!r} unknown; allowed: {', '.join(allowed)}",
                                  param=name)
        for name in ("tol", "limits"):
            items = getattr(self, name)
            items = (items,) if isinstance(items, str) else tuple(items or ())
            if not all(isinstance(t, str) for t in items):
                raise DesignError(f"{name} takes texts such as R=1% or fn_hz=3.3k:3.7k", param=name)
            put(name, items)
        if self.target_ci is not None:
            from .montecarlo import parse_target_ci
            try:
                value = parse_target_ci(self.target_ci)
            except DesignError as exc:
                raise DesignError(str(exc).replace("--target-ci", "target_ci", 1), param="target_ci") from None
            if not self.limits:
                raise ParamError("{target_ci} sets the yield's interval: it needs {limits}", _PARAMS)
            if self.sampler == "lhs":
                raise ParamError("{target_ci} draws in rounds, and a Latin hypercube's strata depend on the final "
                                 "number of builds: use the random or sobol {sampler}", _PARAMS)
            put("target_ci", value)
        if self.spice_samples is not None:
            if self.engine != "both":
                raise ParamError("{spice_samples} goes with the engine both", _PARAMS)
            if not self.limits:
                raise ParamError("{spice_samples} needs {limits}: its samples are the tails of each limited figure",
                                 _PARAMS)
            put("spice_samples", _whole(self.spice_samples, "spice_samples", 1, self.n))


def plant_tolerance(result, mc: MonteCarloSpec | None, worst_case: bool = False, tol=(), simulator: str = "pyspice",
                    scale=None):
    """The tolerance analysis of a plant design's parts as built, attached to it.

    Parameters
    ----------
    result : designer.plant.result.PlantResult
        The design (its parts, series, op-amp and deck).
    mc : MonteCarloSpec or None
        The Monte Carlo to run (None: none).
    worst_case : bool
        Also the true extremes of the figures over the tolerance box.
    tol : tuple of str
        The tolerances of the worst case when there is no Monte Carlo (else ``mc.tol``).
    simulator : str
        The SPICE engine's backend.
    scale : designer.tolerance.runner.Scale, optional
        Where the builds run (default: this process).

    Returns
    -------
    PlantResult
        ``result``, with ``worst_case`` and ``monte_carlo`` set as asked.
    """
    s = result.sourcing
    series = {"R": s.r_series, "C": s.c_series}
    tol = mc.tol if mc is not None else tuple(tol or ())
    if worst_case:
        from .montecarlo import plant_worst_case
        result.worst_case = plant_worst_case(result.built, series, result.opamp, tol)
    if mc is None:
        return result
    if mc.engine != "analytic":
        from .spice_mc import plant_monte_carlo_engine
        result.monte_carlo = plant_monte_carlo_engine(result, series, mc.n, mc.seed, mc.sampler, mc.dist, mc.tol,
                                                      mc.limits, mc.engine, mc.spice_samples, simulator, scale=scale,
                                                      target_ci=mc.target_ci)
        return result
    from .montecarlo import plant_monte_carlo
    result.monte_carlo = plant_monte_carlo(result.built, series, result.opamp, mc.n, mc.seed, mc.sampler, mc.dist,
                                           mc.tol, mc.limits, scale=scale, target_ci=mc.target_ci)
    return result


def loop_tolerance(result, mc: MonteCarloSpec | None, worst_case: bool = False, tol=(), simulator: str = "pyspice",
                   scale=None):
    """The tolerance analysis of a PID loop as built (the plant's parts and the controller's), attached to it,
    as design-pid runs it (:func:`designer.tolerance.loop.loop_worst_case`,
    :func:`designer.tolerance.spice_loop_mc.loop_monte_carlo_engine`).

    Parameters
    ----------
    result : designer.pid.result.PidResult
        The design.
    mc : MonteCarloSpec or None
        The Monte Carlo to run (None: none); its engine analytic, spice or both.
    worst_case : bool
        Also the extremes of the margins and the overshoot (and every limited figure) over the tolerance box.
    tol : tuple of str
        The tolerances of the worst case when there is no Monte Carlo (else ``mc.tol``).
    simulator : str
        The SPICE engine's backend.
    scale : designer.tolerance.runner.Scale, optional
        Where the builds run (default: this process).

    Returns
    -------
    PidResult
        ``result``, with ``worst_case`` and ``monte_carlo`` set as asked.
    """
    from .loop import loop_series, loop_worst_case
    series = loop_series(result)
    if worst_case:
        result.worst_case = loop_worst_case(result, series, mc.tol if mc is not None else tuple(tol or ()),
                                            mc.limits if mc is not None else ())
    if mc is None:
        return result
    from .spice_loop_mc import loop_monte_carlo_engine
    result.monte_carlo = loop_monte_carlo_engine(result, series, mc.n, mc.seed, mc.sampler, mc.dist, mc.tol,
                                                 mc.limits, mc.engine, mc.spice_samples, simulator, scale=scale,
                                                 target_ci=mc.target_ci)
    return result


def section_tolerance(result, mc: MonteCarloSpec | None, worst_case: bool = False, tol=(),
                      simulator: str = "ngspice-cli", scale=None):
    """The tolerance analysis of a plant on a registered section, its parts as built, attached to it: the
    worst case over its declared parts (and the op-amp's GBW when ``tol`` spreads it) and the Monte Carlo (the
    analytic engine, or every build in ngspice: a low-pass's step, another section's ``.ac``,
    :func:`designer.tolerance.spice_mc.section_monte_carlo_engine`); what the command line's
    ``design-plant --topology`` and the page run.

    Parameters
    ----------
    result : designer.plant.circuit_design.CircuitPlantResult
        The design (its section, values, series and op-amp).
    mc : MonteCarloSpec or None
        The Monte Carlo to run (None: none).
    worst_case : bool
        Also the true extremes of the figures over the tolerance box.
    tol : tuple of str
        The tolerances of the worst case when there is no Monte Carlo (else ``mc.tol``).
    simulator : str
        The SPICE engine's backend.
    scale : designer.tolerance.runner.Scale, optional
        Where the builds run (default: this process).

    Returns
    -------
    CircuitPlantResult
        ``result``, with ``worst_case`` and ``monte_carlo`` set as asked.

    Raises
    ------
    DesignError
        ``SR`` in the tolerances where no engine simulates the op-amp's slew (the analytic model, the worst
        case's search of it, an ``.ac`` sweep).
    """
    from ..plant import circuit
    from ..plant.circuit_design import tolerance_nominal
    from .montecarlo import check_section_spread
    from .parts import opamp_nominal, resolve
    from .spice_mc import section_analysis
    s = result.sourcing
    series = {"R": s.r_series, "C": s.c_series}
    tol = mc.tol if mc is not None else tuple(tol or ())
    # only a low-pass's SPICE step slews: SR elsewhere would be silently ignored
    slews = mc is not None and mc.engine != "analytic" and section_analysis(result.section) == "step"
    check_section_spread(tol, slews=slews and not worst_case)
    if worst_case:
        from .worstcase import worst_case as search
        nominal = {**tolerance_nominal(result), **opamp_nominal(tol, result.opamp)}   # GBW: the op-amp's
        context = (result.topology, result.opamp)
        result.worst_case = search(lambda v: circuit.evaluate(context, v), nominal, resolve(tol, nominal, series).of)
    if mc is None:
        return result
    from .spice_mc import section_monte_carlo_engine
    result.monte_carlo = section_monte_carlo_engine(result, series, mc.n, mc.seed, mc.sampler, mc.dist, mc.tol,
                                                    mc.limits, mc.engine, mc.spice_samples, simulator, scale=scale,
                                                    target_ci=mc.target_ci)
    return result
