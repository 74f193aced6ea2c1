"""Command-line layer of ``design-plant`` and ``analyze-plant``: parse, call
:func:`designer.plant.design.design_plant` / ``analyze_plant``, print."""

from __future__ import annotations

import argparse
import dataclasses
import sys

from .. import __version__
from ..core.errors import DesignError
from ..core.ranges import help_range
from ..filters import registry
from ..filters.sallen_key_lowpass_parts import FIELD_OF, refs
from ..plant.circuit import DEFAULT_TOPOLOGY
from .common import (
    ExtendList,
    OneLineParser,
    add_opamp_option,
    add_output_options,
    add_part_options,
    check_output,
    emit,
    part_options,
    run_cli,
)

__all__ = ["analyze_plant_main", "analyze_plant_parser", "design_plant_main", "design_plant_parser"]


def design_plant_parser():
    """The ``design-plant`` command line.

    Returns
    -------
    OneLineParser
        The parser of ``design-plant``'s options.
    """
    p = OneLineParser(
        prog="design-plant",
        description="Design a unity-gain (or gain K) Sallen-Key low-pass that realises the second-order plant "
                    "T(s) = K wn^2 / (s^2 + 2 zeta wn s + wn^2), pick all four parts jointly from E-series values, "
                    "and verify it in ngspice. Values accept engineering notation: 4k7, 820, 10n, 2u2, 3.5k.",
        epilog="""examples:
  design-plant --fc 3500 --zeta 0.2                  the seed's plant, E24 resistors, E12 capacitors
  design-plant --fc 3500 --zeta 0.2 --r 1k --c 10n   the seed's procedure: fix R and C, solve m and n
  design-plant --fc 1k --zeta 0.05 --gain 2          low damping needs a gain K > 1 (C2/C1 >= 1/zeta^2 at K = 1)
  design-plant --fc 20k --zeta 0.5 --opamp LM358 --compensate-gbw
  design-plant --fc 3500 --zeta 0.2 --json --no-sim
  design-plant --fc 3500 --zeta 0.2 --stimulus prbs  also the bench's PRBS in ngspice: prbs.csv, waveforms.csv
  design-plant --fc 1k --zeta 0.5 --gain 2 --topology mfb-lowpass   the same target on an inverting MFB section
  design-plant --fc 1k --topology rc-lowpass          a first-order section takes no --zeta
  design-plant --fc 1k --zeta 0.5 --topology sallen-key-highpass --r 10k --c 10n   fix R and C on a section

Outputs: netlists/<name>.cir (run it alone with `ngspice -b`), reports/<name>/build-sheet.md and .html,
result.json, step.png, bode.png. Exit status 2 on bad input.

topologies (--topology NAME):
""" + "".join(f"  {t.name:26s}{t.title}\n" for t in registry.REGISTRY.values()),
        formatter_class=argparse.RawDescriptionHelpFormatter)
    p.add_argument("--version", action="version", version=f"%(prog)s {__version__}")
    t = p.add_argument_group("target")
    # --fc and --zeta are required (checked in _design: a first-order --topology takes no --zeta)
    t.add_argument("--fc", metavar="HZ",
                   help=f"natural frequency fn = wn / 2 pi, Hz (e.g. 3500, 3.5k) {help_range('fc_hz')} (required)")
    t.add_argument("--zeta", metavar="Z",
                   help=f"damping ratio (>= 1 is overdamped) {help_range('zeta')} (required, but for a "
                        "first-order --topology)")
    t.add_argument("--gain", default="1", metavar="K",
                   help=f"DC gain K = 1 + R4/R3 (default 1: follower) {help_range('gain')}")
    t.add_argument("--topology", default=DEFAULT_TOPOLOGY, metavar="NAME",
                   help=f"the section that realises the plant (default {DEFAULT_TOPOLOGY}, the seed's; the "
                        "registered ones are listed below); each is designed by the joint E-series search over "
                        "its declared parts (the default's exact whole-grid search its fast path) and checked in "
                        "ngspice: the default by its bench's square wave, every other by its deck's .ac (and the "
                        "square wave with --square-freq)")
    t.add_argument("--compensate-gbw", action="store_true",
                   help="pre-distort the targets so the circuit lands on them with the op-amp's finite GBW")
    sel = p.add_argument_group("parts")
    sel.add_argument("--r", metavar="OHM", help="the seed's procedure: fix R (R2 = R, R1 = m R) ... "
                                                "(resistors: " + help_range("resistor_ohm")[1:])
    sel.add_argument("--c", metavar="F", help="... and C (C1 = C, C2 = n C), solve m and n, round the parts "
                                              "jointly to the series; with --topology the section's own "
                                              "procedure (its module's equations; a first-order section has one "
                                              "time constant, so R C must be 1/(2 pi fc)) "
                                              "(capacitors: " + help_range("capacitor_f")[1:])
    add_part_options(sel)
    sel.add_argument("--alternatives", default="5",
                     help=f"how many best combinations to list (default 5) {help_range('alternatives')}")
    _add_bench_options(add_output_options(p, "plant_fc3500_z0.2"))
    _add_tolerance_options(p)
    _add_stimulus_options(p)
    return p


def add_monte_carlo_options(p, what: str):
    """--monte-carlo, --seed, --tol, --dist, --sampler, --target-ci, and where the builds run (--jobs, --dask)
    (the plant's and the loop's); returns the Monte Carlo's group."""
    from ..tolerance.montecarlo import MAX_SAMPLES, MIN_SAMPLES
    from ..tolerance.cluster import CONNECT_TIMEOUT
    g = p.add_argument_group("tolerance analysis (Monte Carlo of the parts as built, analytic)")
    g.add_argument("--monte-carlo", metavar="N",
                   help=f"draw N builds within the parts' tolerances ({MIN_SAMPLES} to {MAX_SAMPLES:.0e}) and report "
                        f"{what}; adds monte_carlo to result.json and monte-carlo.csv (one row per build) to the "
                        "bundle")
    g.add_argument("--seed", default="0", metavar="S", help="the draw's seed (default 0): build i depends on (seed, i) "
                                                            "alone")
    g.add_argument("--tol", nargs="+", metavar="ITEM",
                   help="tolerances (default: the series', E24 5 %%, E12 10 %%...): R=1%% C=5%% (a class) or "
                        "C2=2%% (a part), GBW=30%% (the op-amps' gain-bandwidth) and SR=20%% (their slew rate: a loop's "
                        "slew check; a plant's with --engine spice or both), one per build, the slew rate following "
                        "the gain-bandwidth unless spread itself; each above 0 and at most 50 %%")
    g.add_argument("--dist", default="uniform", choices=("uniform", "normal"),
                   help="uniform in nominal (1 +- tol) (default), or normal with sigma = tol/3 truncated at +- tol")
    g.add_argument("--sampler", default="random", choices=("random", "lhs", "sobol"),
                   help="random (default), lhs (Latin hypercube) or sobol (scrambled)")
    g.add_argument("--target-ci", metavar="PCT",
                   help="draw in rounds until the yield's 95 %% Wilson half-width is below PCT (above 0, at most "
                        "50 %%, e.g. 1%%), --monte-carlo N builds at most; needs --limit, and random or sobol "
                        "(result.json records the builds drawn)")
    s = p.add_argument_group("where the builds run (the same result wherever they run)")
    s.add_argument("--jobs", metavar="N", help="local worker processes, 1 to 64 (default 1: this process); with "
                                               "--dask local, the LocalCluster's workers (default 2)")
    s.add_argument("--dask", metavar="ADDRESS",
                   help="send the builds, in chunks, to a running dask.distributed scheduler (tcp://host:8786; "
                        "see the README for starting one), or 'local' for a LocalCluster on this machine; a "
                        f"scheduler that does not answer within {CONNECT_TIMEOUT:g} s is exit status 3")
    g.set_defaults(limit=None, worst_case=False)
    return g


def scale_settings(args):
    """--jobs, --dask, --target-ci checked (before any work): (Scale, target half-width or None).
    A progress bar on stderr when it is a terminal and the output is not --json."""
    from ..tolerance.cluster import parse_dask
    from ..tolerance.runner import Scale, parse_jobs
    if args.monte_carlo is None:
        given = [f for f, v in (("--jobs", args.jobs), ("--dask", args.dask), ("--target-ci", args.target_ci))
                 if v is not None]
        if given:
            raise DesignError(f"{given[0]} goes with --monte-carlo N")
        return None, None
    jobs = 1 if args.jobs is None else parse_jobs(args.jobs)
    dask = None if args.dask is None else parse_dask(args.dask)
    target = None
    if args.target_ci is not None:
        from ..tolerance.montecarlo import check_target_ci, parse_target_ci
        target = parse_target_ci(args.target_ci)
        check_target_ci(target, args.limit, args.sampler)
    try:
        tty = sys.stderr.isatty()
    except (AttributeError, ValueError):
        tty = False
    return Scale(jobs=jobs, dask=dask, progress=tty and not getattr(args, "json", False), work=_work(args)), target


def _work(args) -> str:
    """What the Monte Carlo's chunks do (:data:`designer.tolerance.cluster.WORKERS`: how a LocalCluster's
    workers start): the plant's commands have --engine; the PID commands' Monte Carlo is the loop's."""
    engine = getattr(args, "engine", None)
    if engine is None or engine == "analytic":
        return engine or "loop"
    from ..spice.simulate import get_simulator
    return "ngspice-cli" if get_simulator(args.simulator).name == "ngspice-cli" else "spice"


def cluster_ahead(args):
    """A context: with ``--dask local`` (checked), the LocalCluster starts now, in its thread, while
    the command designs and simulates; the Monte Carlo takes it (:func:`designer.tolerance.cluster.cluster_ahead`)."""
    from ..tolerance.cluster import cluster_ahead as ahead
    return ahead(scale_settings(args)[0])


def _add_tolerance_options(p):
    """--monte-carlo and its settings, --limit and --worst-case (design-plant and analyze-plant)."""
    g = add_monte_carlo_options(p, "every figure's spread, the yield within --limit and the part to buy tighter")
    g.add_argument("--worst-case", action="store_true",
                   help="the true extremes of fn_hz, zeta, q, overshoot_pct and peak_time_s over the tolerance box "
                        "(every corner, then a bounded search from the worst: an extreme can lie inside); adds "
                        "worst_case to result.json")
    g.add_argument("--limit", action="append", metavar="FIGURE=MIN:MAX",
                   help="the window the yield counts (repeatable, both bounds): fn_hz=3.3k:3.7k, "
                        "overshoot_pct=0:55; figures fn_hz, zeta, q, ideal_fn_hz, ideal_zeta, ideal_q, "
                        "overshoot_pct, peak_time_s, gain")
    _add_spice_options(g)


def _add_spice_options(g):
    """--engine, --spice-samples and --replay (the plant Monte Carlo in SPICE)."""
    g.add_argument("--engine", default="analytic", choices=("analytic", "spice", "both"),
                   help="analytic (default: the op-amp-aware model, vectorised), spice (every build simulated in "
                        "ngspice with --simulator's backend, many builds per ngspice process: fn_hz, zeta, q from "
                        "the step's overshoot and peak time, rise_time_s and settling_time_s too) or both (SPICE "
                        "and the model on every build, their disagreement per figure and the yield each gives). "
                        "The step is the bench square wave's rising half, on the seed's plant and on every "
                        "low-pass --topology; a high- or band-pass --topology, whose step settles to 0, runs each "
                        "build's .ac instead (fn_hz, zeta, q, gain fitted to it); result.json's "
                        "monte_carlo.spice.analysis says which: step or ac")
    g.add_argument("--spice-samples", metavar="K",
                   help="with --engine both and --limit: the model on every build, SPICE only on the K nearest "
                        "each limit (the tails) plus K random ones; reports the verdicts SPICE flips and the "
                        "yield with them (K from 1 to N)")
    g.add_argument("--replay", metavar="I",
                   help="re-run build I (0 to N-1) of --monte-carlo N (same --seed, --sampler, --dist, --tol) "
                        "alone in SPICE and write its bundle: sheet, deck with its exact values, waveforms")


#: the designators a plant's --tol may name
PLANT_PARTS = refs()      # the Sallen-Key low-pass section's, with its gain pair


def monte_carlo_settings(args, designators=PLANT_PARTS, parse_limit_item=None):
    """The Monte Carlo's options checked before any work, as the library's spec
    (:class:`designer.tolerance.mcspec.MonteCarloSpec`; None without --monte-carlo; its engine set by
    :func:`spice_settings`); ``parse_limit_item(text)`` checks a --limit (default: a plant figure's)."""
    given = [f for f, v in (("--tol", args.tol), ("--limit", args.limit)) if v]
    if args.monte_carlo is None:
        if args.limit or (args.tol and not args.worst_case):
            raise DesignError(f"{'--limit' if args.limit else given[0]} goes with --monte-carlo N"
                              + ("" if args.limit else " (or --worst-case)"))
        if args.tol:
            from ..tolerance.parts import check_items
            check_items(args.tol, designators)
        scale_settings(args)
        return None
    from ..tolerance.montecarlo import MAX_SAMPLES, MIN_SAMPLES
    from ..tolerance.plant import FIGURES
    from ..tolerance.stats import parse_limit
    try:
        n = int(str(args.monte_carlo).strip())
    except ValueError:
        raise DesignError(f"--monte-carlo {args.monte_carlo!r}: give a whole number of builds, {MIN_SAMPLES} to "
                          f"{MAX_SAMPLES:.0e}") from None
    if not MIN_SAMPLES <= n <= MAX_SAMPLES:
        raise DesignError(f"--monte-carlo must be {MIN_SAMPLES} to {MAX_SAMPLES:.0e} builds, got {n}")
    try:
        seed = int(str(args.seed).strip())
        if seed < 0:
            raise ValueError
    except ValueError:
        raise DesignError(f"--seed {args.seed!r}: give a whole number >= 0") from None
    for item in args.limit or ():
        parse_limit(item, FIGURES) if parse_limit_item is None else parse_limit_item(item)
    from ..tolerance.parts import check_items
    check_items(args.tol or (), designators)
    scale_settings(args)
    from ..tolerance.mcspec import MonteCarloSpec
    return MonteCarloSpec(n, seed, args.sampler, args.dist, tuple(args.tol or ()), tuple(args.limit or ()),
                          args.target_ci)


def spice_settings(args, mc, plant: bool = True):
    """--engine, --spice-samples and --replay checked before any work: (the Monte Carlo ``mc`` with its engine
    and K, or None; the build I to replay, or None); ``plant``: the plant's op-amp spread checked too (a loop's
    analytic engine has a slew check)."""
    def whole(opt, text, lo, hi):
        try:
            v = int(str(text).strip())
        except ValueError:
            v = None
        if v is None or not lo <= v <= hi:
            raise DesignError(f"{opt} {text!r}: give a whole number from {lo} to {hi}")
        return v
    k = i = None
    if args.replay is not None:
        if mc is None:
            raise DesignError("--replay I goes with --monte-carlo N (and the run's --seed, --sampler, --dist, --tol)")
        if args.no_sim:
            raise DesignError("--replay simulates the build in SPICE: drop --no-sim")
        i = whole("--replay", args.replay, 0, mc.n - 1)
    if args.spice_samples is not None:
        if args.engine != "both":
            raise DesignError("--spice-samples K goes with --engine both")
        if mc is None:
            raise DesignError("--spice-samples K goes with --monte-carlo N")
        if not args.limit:
            raise DesignError("--spice-samples needs --limit: its samples are the tails of each limited figure")
        k = whole("--spice-samples", args.spice_samples, 1, mc.n)
    if args.engine != "analytic" and mc is None:
        raise DesignError(f"--engine {args.engine} goes with --monte-carlo N")
    if plant:
        _check_opamp_spread(args, i)
    return (None if mc is None else dataclasses.replace(mc, engine=args.engine, spice_samples=k)), i


def _check_opamp_spread(args, replay) -> None:
    """``--tol GBW``/``SR`` before any work: the ideal op-amp has neither, and the plant's analytic model
    (the analytic engine, --worst-case) has no slew rate in it."""
    if not args.tol:
        return
    from ..core import opamps
    from ..tolerance.montecarlo import NO_SLEW
    from ..tolerance.parts import opamp_nominal
    spread = opamp_nominal(args.tol, opamps.get(args.opamp))
    if "SR" in spread and (args.worst_case or (args.engine == "analytic" and replay is None)):
        raise DesignError(NO_SLEW if not args.worst_case else NO_SLEW.split(";")[0] + ", and --worst-case "
                          "searches that model: drop SR from --tol")


def _replay(result, args, mc, i, name):
    """--replay I: the sample's own bundle (analyze-plant of its exact values), written under ``name``_sample<I>."""
    from ..tolerance.spice_mc import replay, replay_result
    s = result.sourcing
    rep = replay(result, {"R": s.r_series, "C": s.c_series}, i, mc.n, mc.seed, mc.sampler, mc.dist, mc.tol,
                 args.simulator)
    out = replay_result(result, rep, args.simulator, s.r_series, s.c_series, args.package)
    return _emit(out, args, f"{name}_sample{i}")


def _with_monte_carlo(result, args, mc):
    """The tolerance analysis of the result's parts as built (--monte-carlo, --worst-case), attached to it: the
    library's :func:`designer.tolerance.mcspec.plant_tolerance`, as the page runs it."""
    from ..tolerance.mcspec import plant_tolerance
    return plant_tolerance(result, mc, args.worst_case, args.tol or (), args.simulator, scale=scale_settings(args)[0])


def _add_bench_options(group):
    """The op-amp and the bench's square wave (design-plant and analyze-plant)."""
    add_opamp_option(group)
    group.add_argument("--amplitude", default="2", metavar="V",
                       help="bench square wave goes 0 -> V volts (default 2, as the seed's bench test) "
                            + help_range("amplitude_v"))
    group.add_argument("--square-freq", metavar="HZ",
                       help="bench square-wave frequency (default: a round value whose half period is "
                            "1.5x the 2 %% settling time; 330 Hz for the seed's plant) " + help_range("square_hz"))
    group.add_argument("--package", choices=("single", "dual", "quad"), metavar="KIND",
                       help="the op-amp's package on the build sheet: single (DIP-8), dual (DIP-8, the other "
                            "half tied off) or quad (DIP-14); default: the op-amp's first (LM741 single, the "
                            "others dual)")


def _add_stimulus_options(p):
    """--stimulus and the PRBS's --prbs-bits, --prbs-clock (design-plant and analyze-plant)."""
    from ..core.prbs import MAX_BITS, MIN_BITS
    g = p.add_argument_group("stimulus (what the bench plays besides the square wave)")
    g.add_argument("--stimulus", default="step", choices=("step", "prbs"),
                   help="step (default): the square-wave bench test alone; prbs: also a pseudo-random binary "
                        "sequence (seed 003) between 0 V and --amplitude, 4 periods, simulated in ngspice: adds "
                        "prbs.csv and prbs_awg.csv (the generator's files, as make-prbs writes them), "
                        "prbs-test.cir, and waveforms.csv becomes that run (input, SPICE output, model), which "
                        "identify reads")
    g.add_argument("--prbs-bits", metavar="N",
                   help=f"with --stimulus prbs: the sequence's bits, {MIN_BITS} to {MAX_BITS} (default: the fewest "
                        "whose period outlasts 1.2x the plant's 2 %% settling time and holds 10 spectral lines "
                        "of its bandwidth)")
    g.add_argument("--prbs-clock", metavar="HZ",
                   help="with --stimulus prbs: the generator's clock (sample rate), Hz "
                        + help_range("prbs_clock_hz") + " (default: a 1-2-5 interval whose half-power band "
                        "covers 3x the plant's bandwidth)")


def stimulus_settings(args):
    """--stimulus and its PRBS options checked before any work: None (the square
    wave alone) or (bits or None, clock Hz or None)."""
    given = [o for o, v in (("--prbs-bits", args.prbs_bits), ("--prbs-clock", args.prbs_clock)) if v is not None]
    if args.stimulus != "prbs":
        if given:
            raise DesignError(f"{given[0]} goes with --stimulus prbs")
        return None
    if args.replay is not None:
        raise DesignError("--stimulus prbs does not go with --replay (a replayed build plays the square wave)")
    from ..core.prbs import check_bits
    from ..core.ranges import parse_in_range
    bits = None
    if args.prbs_bits is not None:
        try:
            bits = check_bits(args.prbs_bits)
        except DesignError as exc:
            raise DesignError(str(exc).replace("--bits", "--prbs-bits", 1)) from None
    clock = None if args.prbs_clock is None else parse_in_range(args.prbs_clock, "--prbs-clock", "prbs_clock_hz")
    return bits, clock


def _with_stimulus(result, args, stim):
    """The result with its PRBS bench test when --stimulus prbs (``stim``)."""
    if stim is None:
        return result
    from ..plant.prbs import with_prbs
    return with_prbs(result, result.test.amplitude_v, stim[0], stim[1], not args.no_sim, args.simulator)


def _required(args, topology: str) -> None:
    """--fc and --zeta as argparse would require them (--zeta not for a first-order topology)."""
    order = registry.get(topology).order
    missing = [f for f, v, need in (("--fc", args.fc, True), ("--zeta", args.zeta, order == 2))
               if need and v is None]
    if missing:
        raise DesignError(f"the following arguments are required: {', '.join(missing)} (see design-plant --help)")


def _design(args) -> int:
    from ..plant.spec import PlantSpec
    topology = registry.get(args.topology).name   # an unknown one refused first, with the registered ones
    _required(args, topology)
    if topology != DEFAULT_TOPOLOGY:
        return _design_circuit(args, registry.get(topology))
    # the spec parses and checks what was typed (once); its errors name parameters, shown as options
    spec = PlantSpec(fc_hz=args.fc, zeta=args.zeta, gain=args.gain, **part_options(args), r=args.r, c=args.c,
                     opamp=args.opamp, compensate_gbw=args.compensate_gbw, amplitude_v=args.amplitude,
                     square_hz=args.square_freq, alternatives=args.alternatives, package=args.package)
    name = args.name if args.name is not None else (
        f"plant_fc{spec.fc_hz:g}_z{spec.zeta:g}" + ("" if spec.gain == 1 else f"_k{spec.gain:g}"))
    mc, i = spice_settings(args, monte_carlo_settings(args))
    stim = stimulus_settings(args)
    check_output(args, name if i is None else f"{name}_sample{i}")
    from ..plant.design import design_plant
    if i is not None:     # the design is the draw's nominal; the sample's own run is the simulation
        return _replay(design_plant(spec, simulate=False), args, mc, i, name)
    with cluster_ahead(args):
        result = _with_stimulus(design_plant(spec, simulate=not args.no_sim, simulator=args.simulator), args, stim)
        result = _with_monte_carlo(result, args, mc)
    return _emit(result, args, name)


def _design_circuit(args, topo) -> int:
    """design-plant --topology NAME (not the default): the plant on a registered section."""
    from ..plant.spec import PlantSpec
    spec = PlantSpec(fc_hz=args.fc, zeta=args.zeta, gain=args.gain, **part_options(args), r=args.r, c=args.c,
                     opamp=args.opamp, compensate_gbw=args.compensate_gbw, amplitude_v=args.amplitude,
                     square_hz=args.square_freq, alternatives=args.alternatives, package=args.package,
                     topology=topo.name)
    _circuit_unsupported(args, topo)
    _check_section_spread(args, topo)
    name = args.name if args.name is not None else (
        f"plant_{topo.name}_fc{spec.fc_hz:g}" + ("" if spec.zeta is None else f"_z{spec.zeta:g}")
        + ("" if spec.gain == 1 else f"_k{spec.gain:g}"))
    mc, i = spice_settings(args, monte_carlo_settings(args, topo.designators), plant=False)
    stim = stimulus_settings(args)
    check_output(args, name if i is None else f"{name}_sample{i}")
    from ..plant.circuit_design import design_circuit_plant
    from ..plant.circuit_report import summary_text, write_outputs
    if i is not None:     # the design is the draw's nominal; the build's own run the simulation
        return _circuit_replay(design_circuit_plant(spec, simulate=False), args, mc, i, name)
    with cluster_ahead(args):
        result = _circuit_stimulus(design_circuit_plant(spec, simulate=not args.no_sim, simulator=args.simulator),
                                   args, stim)
        result = _circuit_tolerance(result, args, mc)
    return emit(result, args, name, write_outputs, summary_text)


def _check_section_spread(args, topo) -> None:
    """``--tol SR`` on a section before any work: only where ngspice's op-amp slews, a low-pass's step (--engine
    spice or both, or --replay), not on the analytic model (nor --worst-case, which searches it) or an .ac sweep."""
    from ..tolerance.montecarlo import check_section_spread
    from ..tolerance.spice_mc import section_analysis
    slews = section_analysis(topo) == "step" and (args.engine != "analytic" or args.replay is not None)
    check_section_spread(args.tol, slews=slews and not args.worst_case)


def _circuit_replay(result, args, mc, i, name) -> int:
    """--replay I on a section plant: the build's values drawn again, through its SPICE engine (the engine's row
    I: a low-pass's step, another section's .ac), and its bundle (analyze-plant --topology of its exact values)
    written under ``name``_sample<I>: the seed plant's replay, one function (designer.tolerance.spice_mc.replay)."""
    from ..plant.circuit_report import summary_text, write_outputs
    from ..tolerance.spice_mc import replay, replay_result
    s = result.sourcing
    rep = replay(result, {"R": s.r_series, "C": s.c_series}, i, mc.n, mc.seed, mc.sampler, mc.dist, mc.tol,
                 args.simulator)
    out = replay_result(result, rep, args.simulator, square_hz=args.square_freq)
    return emit(out, args, f"{name}_sample{i}", write_outputs, summary_text)


def _circuit_stimulus(result, args, stim):
    """A section plant with its PRBS bench test when --stimulus prbs (``stim``)."""
    if stim is None:
        return result
    from ..plant.circuit_prbs import with_section_prbs
    return with_section_prbs(result, result.amplitude_v, stim[0], stim[1], not args.no_sim, args.simulator)


def _circuit_unsupported(args, topo, options=()) -> None:
    """The options the plant on another topology has not (yet): refused in one line."""
    unsupported = [f for f, v in options
                   if v]
    if unsupported:
        raise DesignError(f"{unsupported[0].split()[0]}: {unsupported[0]} is the {DEFAULT_TOPOLOGY}'s for now; "
                          f"--topology {topo.name} has the .ac check, the --square-freq test and the Monte Carlo "
                          "(--engine analytic, spice or both: a low-pass's step per build, another section's .ac)")


def _analyze_circuit(args, topo) -> int:
    """analyze-plant --topology NAME (not the default) --part REF=VALUE ..: a section's parts as built."""
    named = [n for n in (*FIELD_OF.values(), "gain") if getattr(args, n) is not None]
    if named:
        raise DesignError(f"--{named[0]} is the {DEFAULT_TOPOLOGY}'s; give {topo.name}'s parts as --part REF=VALUE "
                          f"({', '.join(topo.designators)})")
    _circuit_unsupported(args, topo)
    _check_section_spread(args, topo)
    from ..plant.circuit_design import analyze_circuit_plant, built_name
    from ..plant.circuit_report import summary_text, write_outputs
    parts = part_values(args.part)
    bad = [r for r in parts if r not in topo.designators]
    missing = [r for r in topo.designators if r not in parts]
    if bad or missing:
        what = f"has no part {bad[0]}" if bad else f"needs {', '.join(missing)} too"
        raise DesignError(f"--part: {topo.name} {what}; its parts are {', '.join(topo.designators)}")
    mc, i = spice_settings(args, monte_carlo_settings(args, topo.designators), plant=False)
    from ..core.ranges import parse_in_range
    values = {r: parse_in_range(v, f"--part {r}", "resistor_ohm" if r[0] == "R" else "capacitor_f")
              for r, v in parts.items()}
    stim = stimulus_settings(args)
    name = args.name if args.name is not None else built_name(topo.name, values)
    check_output(args, name if i is None else f"{name}_sample{i}")
    if i is not None:
        return _circuit_replay(analyze_circuit_plant(
            topo.name, values, args.opamp, args.fc, args.zeta, args.r_series, args.c_series, args.package,
            simulate=False, amplitude_v=args.amplitude, square_hz=args.square_freq), args, mc, i, name)
    with cluster_ahead(args):
        result = _circuit_stimulus(analyze_circuit_plant(
            topo.name, values, args.opamp, args.fc, args.zeta, args.r_series, args.c_series, args.package,
            simulate=not args.no_sim, simulator=args.simulator, amplitude_v=args.amplitude,
            square_hz=args.square_freq), args, stim)
        result = _circuit_tolerance(result, args, mc)
    return emit(result, args, name, write_outputs, summary_text)


def _circuit_tolerance(result, args, mc):
    """--worst-case and --monte-carlo of a plant on another topology: the library's
    :func:`designer.tolerance.mcspec.section_tolerance` (the analytic engine over its parts; --engine
    spice|both, --spice-samples: every build in ngspice, a low-pass's step on its bench's square wave as the
    seed plant's, another section's .ac), as the page runs it."""
    from ..tolerance.mcspec import section_tolerance
    return section_tolerance(result, mc, args.worst_case, args.tol or (), args.simulator,
                             scale=scale_settings(args)[0])


def _emit(result, args, name) -> int:
    from ..plant.report import summary_text, write_outputs
    return emit(result, args, name, write_outputs, summary_text)


def analyze_plant_parser():
    """The ``analyze-plant`` command line.

    Returns
    -------
    OneLineParser
        The parser of ``analyze-plant``'s options.
    """
    p = OneLineParser(
        prog="analyze-plant",
        description="Analyse a Sallen-Key low-pass as built from its parts: fn, zeta and Q it really gives, step "
                    "metrics with the op-amp model, tolerance band, sensitivity, and an ngspice check.",
        epilog="""examples:
  analyze-plant --r1 820 --r2 1k --c1 10n --c2 220n                 the seed's rounded parts
  analyze-plant --r1 820 --r2 1k --c1 10n --c2 220n --fc 3500 --zeta 0.2   errors against the seed's target
  analyze-plant --r1 10k --r2 10k --c1 10n --c2 10n --gain 2.5      equal-component design with gain
  analyze-plant --r1 10k --r2 10k --c1 10n --c2 10n --r3 10k --r4 15k  gain from its resistors
  analyze-plant --topology mfb-lowpass --part R1=1k1 --part R2=2k2 --part R3=43k --part C1=1n2 --part C2=220n

topologies (--topology NAME):
""" + "".join(f"  {t.name:26s}{t.title}: {', '.join(t.designators)}\n" for t in registry.REGISTRY.values()),
        formatter_class=argparse.RawDescriptionHelpFormatter)
    p.add_argument("--version", action="version", version=f"%(prog)s {__version__}")
    g = p.add_argument_group("parts")
    # required for the Sallen-Key low-pass unless given as --part (checked in _analyze)
    for n, what, key in (("r1", "input resistor, ohms", "resistor_ohm"),
                         ("r2", "resistor to the non-inverting input, ohms", "resistor_ohm"),
                         ("c1", "non-inverting input to ground, farads", "capacitor_f"),
                         ("c2", "feedback capacitor, farads", "capacitor_f")):
        g.add_argument(f"--{n}", help=f"{what} {help_range(key)} (required, or --part {n.upper()}=VALUE)")
    g.add_argument("--topology", default=DEFAULT_TOPOLOGY, metavar="NAME",
                   help=f"the section the parts are (default {DEFAULT_TOPOLOGY}, the seed's, whose parts are "
                        "also --r1 .. --r4; the registered ones are listed below)")
    # a list as design-pid's --plant-part takes it, and repeatable (the two accumulate): --part R1=1k6 R2=3k9
    # was refused as "unrecognized arguments" where design-pid takes the same words
    g.add_argument("--part", nargs="+", action=ExtendList, metavar="REF=VALUE",
                   help="parts by their designators: --part R1=1k6 C2=220n, or repeated: --part R1=1k6 --part "
                        "C2=220n (a designator given twice is refused); every part of --topology")
    g.add_argument("--gain", default=None, metavar="K", help=f"gain K = 1 + R4/R3 (default 1) {help_range('gain')}")
    g.add_argument("--r3", help="gain resistor to ground (with --r4, instead of --gain)")
    g.add_argument("--r4", help="gain feedback resistor")
    g.add_argument("--fc", help=f"target fn, Hz, to report errors against (optional) {help_range('fc_hz')}")
    g.add_argument("--zeta", help=f"target damping, to report errors against (optional) {help_range('zeta')}")
    g.add_argument("--r-series", default=None, help="series the resistors come from, for the tolerance band "
                                                    "(default: the smallest series that holds each value)")
    g.add_argument("--c-series", default=None, help="series the capacitors come from, for the tolerance band "
                                                    "(default: the smallest series that holds each value)")
    _add_bench_options(add_output_options(p, "built_r1820_r21k_c110n_c2220n"))
    _add_tolerance_options(p)
    _add_stimulus_options(p)
    return p


def part_values(items) -> dict:
    """``--part REF=VALUE`` items (argparse's append: repeatable) as {designator: value as typed};
    a malformed item or a designator given twice refused in one line.

    Parameters
    ----------
    items : list of str or None
        The items as typed.

    Returns
    -------
    dict
        Designator (upper case) -> value text.
    """
    parts = {}
    for item in items or ():
        ref, eq, value = str(item).partition("=")
        ref = ref.strip().upper()
        if not eq or not ref or not value.strip():
            raise DesignError(f"--part {item!r}: give REF=VALUE, e.g. --part R1=1k6")
        if ref in parts:
            raise DesignError(f"--part {ref} given twice: {parts[ref]} and {value.strip()}; give it once")
        parts[ref] = value.strip()
    return parts


#: the default section's parts (its gain resistors too: the gain K) as the command line names them (--r1 ..)
SK_PART_OPTIONS = {r: FIELD_OF[r] for r in refs()}


def _sk_parts(args) -> None:
    """--part on the Sallen-Key low-pass: its designators into --r1 .. --r4 (a part given both ways refused),
    then --r1, --r2, --c1, --c2 required as argparse would."""
    for ref, value in part_values(args.part).items():
        dest = SK_PART_OPTIONS.get(ref)
        if dest is None:
            raise DesignError(f"--part {ref}: {DEFAULT_TOPOLOGY} has no part {ref}; its parts are "
                              f"{', '.join(SK_PART_OPTIONS)}")
        if getattr(args, dest) is not None:
            raise DesignError(f"--part {ref} and --{dest} name the same part; give it once")
        setattr(args, dest, value)
    missing = [f"--{FIELD_OF[r]}" for r in refs(with_gain=False) if getattr(args, FIELD_OF[r]) is None]
    if missing:
        raise DesignError(f"the following arguments are required: {', '.join(missing)} (see analyze-plant --help)")


def _analyze(args) -> int:
    from ..plant.circuit_design import built_name
    from ..plant.design import analyze_plant
    from ..plant.sallenkey import SallenKeyParts
    from ..plant.spec import AnalysisSpec
    topo = registry.get(args.topology)
    if topo.name != DEFAULT_TOPOLOGY:
        return _analyze_circuit(args, topo)
    _sk_parts(args)
    if args.r3 is not None and args.gain is not None:
        raise DesignError("give either --gain or --r3/--r4, not both")
    # the spec parses and checks what was typed (once): the parts through the plant check,
    # which derives R3/R4 for a bare --gain and refuses unstable parts
    spec = AnalysisSpec(SallenKeyParts(args.r1, args.r2, args.c1, args.c2, args.gain, args.r3, args.r4),
                        opamp=args.opamp, target_fc_hz=args.fc, target_zeta=args.zeta, r_series=args.r_series,
                        c_series=args.c_series, amplitude_v=args.amplitude, square_hz=args.square_freq,
                        package=args.package)
    p = spec.parts
    name = args.name if args.name is not None else built_name(DEFAULT_TOPOLOGY, {
        r: getattr(p, FIELD_OF[r]) for r in refs(with_gain=False)})
    mc, i = spice_settings(args, monte_carlo_settings(args))
    stim = stimulus_settings(args)
    check_output(args, name if i is None else f"{name}_sample{i}")
    if i is not None:
        return _replay(analyze_plant(spec, simulate=False), args, mc, i, name)
    with cluster_ahead(args):
        result = _with_stimulus(analyze_plant(spec, simulate=not args.no_sim, simulator=args.simulator), args, stim)
        result = _with_monte_carlo(result, args, mc)
    return _emit(result, args, name)


def design_plant_main(argv=None) -> int:
    """Console entry point ``design-plant``.

    Parameters
    ----------
    argv : list of str, optional
        The arguments; None reads ``sys.argv[1:]``.

    Returns
    -------
    int
        The exit status (see :func:`~designer.cli.common.run_cli`).
    """
    return run_cli("design-plant", design_plant_parser, _design, argv)


def analyze_plant_main(argv=None) -> int:
    """Console entry point ``analyze-plant``.

    Parameters
    ----------
    argv : list of str, optional
        The arguments; None reads ``sys.argv[1:]``.

    Returns
    -------
    int
        The exit status (see :func:`~designer.cli.common.run_cli`).
    """
    return run_cli("analyze-plant", analyze_plant_parser, _analyze, argv)


if __name__ == "__main__":  # pragma: no cover
    sys.exit(design_plant_main())
