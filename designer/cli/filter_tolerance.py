"""The tolerance analysis of ``design-filter`` and ``analyze-filter``: ``--monte-carlo N``
against the mask (or ``--limit``), ``--worst-case``, ``--spice-samples K`` (the SPICE
engine on the same first K builds, the engines' disagreement), ``--jobs``/``--dask``,
and design-filter's ``--optimize yield`` (:mod:`designer.tolerance.filter`)."""

from __future__ import annotations

from ..core.errors import DesignError

__all__ = ["OPTIMIZE_DEFAULT_BUILDS", "add_filter_tolerance", "tolerance_settings", "run_tolerance",
           "tolerance_lines", "tolerance_json"]

#: the builds of --optimize yield without --monte-carlo
OPTIMIZE_DEFAULT_BUILDS = 2000


def add_filter_tolerance(p, optimize: bool = False):
    """The tolerance options (and ``--optimize yield`` for design-filter).

    Parameters
    ----------
    p : argparse.ArgumentParser
        The command's parser.
    optimize : bool
        Add ``--optimize``.

    Returns
    -------
    argparse._ArgumentGroup
        The group.
    """
    from ..tolerance.cluster import CONNECT_TIMEOUT
    from ..tolerance.filter import BANDPASS_FIGURES, LOWHIGH_FIGURES
    from ..tolerance.montecarlo import MAX_SAMPLES, MIN_SAMPLES
    figs = ", ".join(dict.fromkeys(LOWHIGH_FIGURES + BANDPASS_FIGURES)) + ", delay_error_pct (with --max-delay-error)"
    g = p.add_argument_group("tolerance against the mask (every part of every stage; analytic, vectorised)")
    g.add_argument("--monte-carlo", metavar="N",
                   help=f"draw N builds within the parts' tolerances ({MIN_SAMPLES} to {MAX_SAMPLES:.0e}): each "
                        "figure's spread, the yield against the mask (or --limit) with its 95 %% Wilson interval, "
                        "the stage and the part to buy tighter")
    g.add_argument("--seed", default="0", metavar="S", help="the draw's seed (default 0): build i depends on (seed, i) "
                                                            "alone")
    g.add_argument("--tol", nargs="+", metavar="ITEM",
                   help="tolerances (default: the series', E24 5 %%, E12 10 %%...): R=1%% C=5%% (a class) or "
                        "C201=2%% (one part: stage 2's C1), each above 0 and at most 50 %%")
    g.add_argument("--dist", default="uniform", choices=("uniform", "normal"),
                   help="uniform in nominal (1 +- tol) (default), or normal with sigma = tol/3 truncated at +- tol")
    g.add_argument("--sampler", default="random", choices=("random", "lhs", "sobol"),
                   help="random (default), lhs (Latin hypercube) or sobol (scrambled)")
    g.add_argument("--limit", action="append", metavar="FIGURE=MIN:MAX",
                   help=f"the window the yield counts instead of the mask (repeatable, both bounds): figures {figs}")
    g.add_argument("--worst-case", action="store_true",
                   help="the extremes of every figure over the tolerance box (the corners the parts' slopes "
                        "point to, then a bounded search)")
    g.add_argument("--spice-samples", metavar="K",
                   help="also simulate builds 0..K-1 in ngspice (the same draws: every part altered by its "
                        "designator) and report both engines' yields on them and their disagreement (1 to N)")
    if optimize:
        g.add_argument("--optimize", choices=("yield",),
                       help="yield: among each stage's E-series candidates, the set with the highest yield against "
                            f"the mask, both sets' yields from the same --monte-carlo N builds (default "
                            f"{OPTIMIZE_DEFAULT_BUILDS}); reported beside the joint choice, which stays the one "
                            "built unless --apply-optimum")
        g.add_argument("--apply-optimum", action="store_true",
                       help="with --optimize yield: build the yield-optimal set instead (the deck, result.json's "
                            "stages, the sheet, the SPICE proof and --monte-carlo use it; the joint choice's parts "
                            "and yield are reported beside it)")
    s = p.add_argument_group("where the builds run (the same result wherever they run)")
    s.add_argument("--jobs", metavar="N", help="local worker processes, 1 to 64 (default 1: this process); with "
                                               "--dask local, the LocalCluster's workers (default 2)")
    s.add_argument("--dask", metavar="ADDRESS",
                   help="send the builds, in chunks, to a running dask.distributed scheduler (tcp://host:8786), or "
                        f"'local' for a LocalCluster on this machine; one that does not answer within "
                        f"{CONNECT_TIMEOUT:g} s is exit status 3")
    return g


def _whole(text, flag: str, lo: int, hi: int) -> int:
    try:
        v = int(str(text).strip())
    except ValueError:
        v = None
    if v is None or not lo <= v <= hi:
        raise DesignError(f"{flag} {text!r}: give a whole number, {lo} to {hi:g}")
    return v


def tolerance_settings(args) -> dict | None:
    """The tolerance options checked before any work (None when none is asked).

    Parameters
    ----------
    args : argparse.Namespace
        The parsed options.

    Returns
    -------
    dict or None
        ``n``, ``seed``, ``spice``, ``scale``, ``optimize``, ``worst_case``.

    Raises
    ------
    DesignError
        One line naming the option and what is allowed.
    """
    from ..tolerance.cluster import parse_dask
    from ..tolerance.filter import BANDPASS_FIGURES, LOWHIGH_FIGURES
    from ..tolerance.montecarlo import MAX_SAMPLES, MIN_SAMPLES
    from ..tolerance.parts import split_items, parse_tolerance
    from ..tolerance.runner import Scale, parse_jobs
    from ..tolerance.stats import parse_limit
    optimize = getattr(args, "optimize", None)
    asked = args.monte_carlo is not None or optimize or args.worst_case
    if not asked:
        given = [f for f, v in (("--tol", args.tol), ("--limit", args.limit), ("--spice-samples", args.spice_samples),
                                ("--jobs", args.jobs), ("--dask", args.dask)) if v]
        if given:
            raise DesignError(f"{given[0]} goes with --monte-carlo N (or --worst-case, --optimize yield)")
        return None
    n = None if args.monte_carlo is None else _whole(args.monte_carlo, "--monte-carlo", MIN_SAMPLES, MAX_SAMPLES)
    seed = _whole(args.seed, "--seed", 0, 2 ** 63 - 1)
    for key, value in split_items(args.tol):
        parse_tolerance(value, f"--tol {key}")
    for item in args.limit or ():
        parse_limit(item, tuple(dict.fromkeys(LOWHIGH_FIGURES + BANDPASS_FIGURES + ("delay_error_pct",))))
    spice = None
    if args.spice_samples is not None:
        if n is None:
            raise DesignError("--spice-samples K goes with --monte-carlo N")
        spice = _whole(args.spice_samples, "--spice-samples", 1, n)
    if (args.jobs or args.dask) and n is None:
        raise DesignError(f"{'--jobs' if args.jobs else '--dask'} goes with --monte-carlo N")
    jobs = 1 if args.jobs is None else parse_jobs(args.jobs)
    dask = None if args.dask is None else parse_dask(args.dask)
    return {"n": n, "seed": seed, "spice": spice, "optimize": optimize, "worst_case": args.worst_case,
            "scale": Scale(jobs=jobs, dask=dask, work="analytic")}


def run_tolerance(result, args, settings: dict | None, apply=None) -> dict:
    """The analyses asked for ``result`` (a FilterDesign).

    Parameters
    ----------
    result : designer.filters.FilterDesign
        The design (or the parts as built).
    args : argparse.Namespace
        The options (``--tol``, ``--limit``, ``--dist``, ``--sampler``, ``--simulator``).
    settings : dict or None
        :func:`tolerance_settings`'s.

    apply : callable, optional
        ``apply(result, choice)`` -> the design built with the yield-optimal set (``--apply-optimum``):
        the Monte Carlo and the worst case then run on it.

    Returns
    -------
    dict
        ``monte_carlo``, ``worst_case``, ``optimize``: the results asked (objects); ``built``: the
        design applied (only with ``apply``).
    """
    from ..tolerance import filter as tf
    out = {}
    if not settings:
        return out
    tol, limits = tuple(args.tol or ()), tuple(args.limit or ())
    if settings["optimize"] == "yield":
        out["optimize"] = tf.optimize_yield(result, settings["n"] or OPTIMIZE_DEFAULT_BUILDS, settings["seed"],
                                            args.sampler, args.dist, tol, limits)
        if apply is not None:
            out["optimize"].joint_values = [dict(st.values) for st in result.stages]
            result = out["built"] = apply(result, out["optimize"].choice)
    if settings["n"] is not None:
        out["monte_carlo"] = tf.filter_monte_carlo(result, settings["n"], settings["seed"], args.sampler, args.dist,
                                                   tol, limits, scale=settings["scale"],
                                                   spice_samples=settings["spice"] or 0,
                                                   simulator=getattr(args, "simulator", "ngspice-cli"))
    if settings["worst_case"]:
        out["worst_case"] = tf.filter_worst_case(result, tol)
    return out


def tolerance_lines(extras: dict) -> list:
    """The summary's lines of :func:`run_tolerance`'s results.

    Parameters
    ----------
    extras : dict
        Its results.

    Returns
    -------
    list of str
        Lines.
    """
    out = []
    if "monte_carlo" in extras:
        out += extras["monte_carlo"].lines()
    if "worst_case" in extras:
        out += extras["worst_case"].summary_lines()
    if "optimize" in extras:
        out += extras["optimize"].lines()
    return out


def tolerance_json(extras: dict) -> dict:
    """:func:`run_tolerance`'s results as JSON keys (``monte_carlo``, ``worst_case``, ``optimize_yield``).

    Parameters
    ----------
    extras : dict
        Its results.

    Returns
    -------
    dict
        JSON-ready.
    """
    from ..core.jsonio import json_safe
    names = {"monte_carlo": "monte_carlo", "worst_case": "worst_case", "optimize": "optimize_yield"}
    return json_safe({names[k]: v.to_dict() for k, v in extras.items() if k in names})
