"""The tolerance analysis of ``design-pid`` and ``analyze-pid``: ``--monte-carlo``, ``--limit``,
``--worst-case``, and the loop's SPICE engine ``--engine spice|both``, ``--spice-samples K`` and
``--replay I`` (:mod:`designer.tolerance.spice_loop_mc`), as the plant's commands have them
(:mod:`designer.cli.plant`)."""

from __future__ import annotations

from ..core.errors import DesignError
from ..filters.sallen_key_lowpass_parts import refs

__all__ = []

#: the controller's parts a --tol may name
CONTROLLER_PARTS = (*(f"R{i}" for i in range(3, 19)), "C3", "C4")
#: the loop's parts a --tol may name: the plant's and the controller's
LOOP_PARTS = (*refs(with_gain=False), *CONTROLLER_PARTS)


def add_monte_carlo(p):
    """--monte-carlo and its settings, --limit, --worst-case, --engine, --spice-samples, --replay."""
    from ..tolerance.loop import LIMITABLE
    from .plant import add_monte_carlo_options
    g = add_monte_carlo_options(p, "the probability that the loop is unstable or an op-amp leaves its swing, with "
                                   "95 %% intervals, the spread of its gains, margins and step figures, the yield "
                                   "within --limit and the part to buy tighter (a Sallen-Key plant's parts and "
                                   "the controller's vary together; a model plant's parameters stay as given)")
    g.add_argument("--limit", action="append", metavar="FIGURE=MIN:MAX",
                   help="the window the yield counts (repeatable, both bounds, engineering notation): "
                        "phase_margin_deg=45:90, overshoot_pct=0:15; a build counts when its loop is stable "
                        "and inside every window; figures (check-design's names) " + ", ".join(LIMITABLE)
                        + ", overshoot_pct, peak_time_s, rise_time_s, settling_time_s (SPICE's with --engine "
                          "spice or both; the analytic loop's model_* stand in with the analytic engine)")
    g.add_argument("--worst-case", action="store_true",
                   help="the extremes of phase_margin_deg, gain_margin_db, model_overshoot_pct (and every --limit "
                        "figure) over the tolerance box: each part alone at +-tol, the corners its slopes point to, "
                        "then a bounded search (22 parts: 4 million corners are too many); adds worst_case to "
                        "result.json (about a minute)")
    g.add_argument("--engine", default="analytic", choices=("analytic", "spice", "both"),
                   help="analytic (default: the loop as built, op-amp poles, leak and filter, one state-space "
                        "model per build), spice (every build's closed loop simulated in ngspice with "
                        "--simulator's backend, many builds per ngspice process: overshoot_pct, peak_time_s, "
                        "rise_time_s, settling_time_s measured, slewing and clamping included; the margins and "
                        "gains stay the analytic loop's) or both (SPICE and the analytic loop on every build, "
                        "their disagreement per step figure and the yield each gives)")
    g.add_argument("--spice-samples", metavar="K",
                   help="with --engine both and --limit: the analytic loop on every build, SPICE only on the K "
                        "nearest each limit (the tails) plus K random ones; reports the verdicts SPICE flips and "
                        "the yield with them (K from 1 to N)")
    g.add_argument("--replay", metavar="I",
                   help="re-run build I (0 to N-1) of --monte-carlo N (same --seed, --sampler, --dist, --tol) "
                        "alone in SPICE and write its bundle, <name>_sample<I>: sheet, deck with its exact "
                        "values, waveforms")


def monte_carlo_settings(args, spec):
    """The Monte Carlo's options checked before any work: (the library's
    :class:`~designer.tolerance.mcspec.MonteCarloSpec` or None, the build I to replay or None)."""
    from ..tolerance.loop import parse_loop_limit
    from ..tolerance.spice_loop_mc import parse_limit
    from .plant import monte_carlo_settings as checked, spice_settings
    # a model plant's parameters stay as identified: only the controller's parts vary
    parse = parse_loop_limit if args.engine == "analytic" else parse_limit
    settings = checked(args, LOOP_PARTS if spec.process is None else CONTROLLER_PARTS, parse)
    if args.tol:      # the op-amps' spread (GBW, SR): the ideal op-amp has none, refused before any work
        from ..core import opamps
        from ..tolerance.parts import opamp_nominal
        opamp_nominal(args.tol, opamps.get(spec.opamp))
    mc, i = spice_settings(args, settings, plant=False)
    if i is not None and getattr(args, "rules_spice", False):
        raise DesignError("--rules-spice does not go with --replay (a replayed build is analysed as built)")
    return mc, i


def loop_monte_carlo(result, args, mc):
    """The loop's tolerance analysis (--monte-carlo with its engine, --worst-case), attached to the result: the
    library's :func:`designer.tolerance.mcspec.loop_tolerance`, as the page runs it."""
    from ..tolerance.mcspec import loop_tolerance
    from .plant import scale_settings
    return loop_tolerance(result, mc, args.worst_case, args.tol or (), args.simulator, scale=scale_settings(args)[0])


def replay(spec, result, args, mc, i):
    """--replay I: the build's own analyze-pid result (its exact values, in SPICE), its
    ``monte_carlo`` the replayed row (:func:`designer.tolerance.spice_loop_mc.replay_result`)."""
    from ..tolerance.loop import loop_series
    from ..tolerance.spice_loop_mc import replay as replay_build, replay_result
    rep = replay_build(result, loop_series(result), i, mc.n, mc.seed, mc.sampler, mc.dist, mc.tol, args.simulator)
    return replay_result(spec, result, rep, args.simulator)


def replay_name(name: str, i) -> str:
    """The bundle's name: the run's, with ``_sample<I>`` when build ``i`` is replayed."""
    return name if i is None else f"{name}_sample{i}"
