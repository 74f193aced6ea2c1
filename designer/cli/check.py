"""Command-line layer of ``check-design``: its options checked, the run
(:func:`designer.check.batch.check_specs`: every spec loaded, all refusals before any run, each
spec's corners in worker processes, the ``--out`` folder) called as the web page's Check calls it,
then a line per spec and per failure printed, the JUnit file and the Markdown summary written, and
the run's exit status."""

from __future__ import annotations

import sys
from pathlib import Path

from .common import command_parser, print_output, run_cli

__all__ = ["check_design_main", "check_parser"]

EPILOG = """spec file (YAML; numbers in engineering notation, paths relative to the spec):
  name: lab3-plant                      # default: the file's stem
  kind: plant                           # plant | pid | netlist | filter
  target: {fc: 3.5k, zeta: 0.2}         # designed as design-plant does; or parts: {R1: 1k6, R2: 3k9, ...}
  opamp: [LM741, TL072]                 # the corners: every check runs for each
  stimulus: {amplitude: 2}              # square wave 0 -> amplitude V (frequency: default as design-plant)
  checks:                               # figure: {min, typ, max, fail}; min/max absolute or "-1%" of typ
    fn_hz: {typ: 3500, min: "-2%", max: "+2%"}
    overshoot_pct: {max: 60}
    zeta_opamp: {min: 0.15, fail: false}    # report only
  design_checks: all                    # or [slew_rate, output_swing, ...]
  spice_agreement: {nrms_max: 1, against: opamp_model}   # or ideal
  tolerance: [fn_hz]                    # the part-tolerance band must stay inside the limits too
  tolerances: {R: 1%, C: 5%, C2: 2%}    # a class or a part, GBW or SR (default: the series', E24 5 %) ...
  yield: {min: 95%, samples: 2000, seed: 1, engine: analytic}   # ... that fraction of builds inside checks:
                                        # (samples 10 to 1e6; sampler: random|lhs|sobol, dist: uniform|normal;
                                        # engine: analytic, the models, or spice, every build in ngspice, SPICE's
                                        # step figures counted); the failure names the figure losing most
  golden: {file: "golden/lab3-{corner}.csv", signals: {output_v: {reltol: 0.01, abstol: 1m}}}

  kind: pid     plant: {fc: 3.5k, zeta: 0.2} (or R1..C2, or json: result.json); tuning: zn (a rule),
                {kp: 3.3, ti: 43u, td: 11u} or {rule: optimize, target_overshoot: 10}; controller: {R3: 12k,
                .., C4: 47n} or {json: result.json} (the parts as built, checked with analyze-pid)
  kind: netlist deck: my_filter.cir (your own ngspice deck with .tran or .ac); checks: its .meas names
  kind: filter  filter: {type: lowpass, family: chebyshev, ripple: 0.5, order: 5, fc: 1k, topology: mfb}
                (design-filter's options) or stages: [{topology: sallen-key-lowpass, parts: {R1: 6k2, ..}}]
                (as built); mask: {passband: 1k, max_loss: 1, stopband: 2k, min_attenuation: 40} (checked on
                the op-amp model and on SPICE's .ac); checks: f3_hz, spice_f3_hz, spice_max_deviation_db, ..

examples:
  check-design specs/*.yaml --junit junit.xml --summary summary.md --out check-out --jobs 2
  check-design specs/lab3.yaml --simulator ngspice-cli       (as CI runs it, with Debian's ngspice)
  check-design specs/lab3.yaml --update-golden               (record the golden waveforms on purpose)
  check-design specs/*.yaml --no-fail --summary "$GITHUB_STEP_SUMMARY"

Exit status: 0 every check passed; 1 a check failed; 2 a bad spec or usage (one line: file, line, what is
allowed); 3 a simulator error or timeout; --no-fail makes it 0 whatever happened (the files say what)."""


def check_parser():
    """The ``check-design`` command line.

    Returns
    -------
    argparse.ArgumentParser
        The parser of ``check-design``'s options.
    """
    p = command_parser(
        "check-design",
        "SPICE regression checks of your own analog designs, for CI: each spec file names a design (a Sallen-Key "
        "plant, a PID controller in its loop, an active filter, or your own ngspice deck), its op-amp corners and the limits it "
        "must meet; every check runs for every corner in ngspice.", EPILOG)
    p.add_argument("specs", nargs="+", metavar="SPEC.yaml", help="spec files (YAML)")
    p.add_argument("--junit", metavar="FILE", help="write a JUnit XML report (one testsuite per spec, one "
                                                  "testcase per check and corner)")
    p.add_argument("--summary", metavar="FILE", help="write a Markdown summary (e.g. $GITHUB_STEP_SUMMARY)")
    p.add_argument("--out", metavar="DIR", help="write each spec's result.json, build sheets, and a plot for "
                                                "every failing golden waveform under DIR/<spec>/")
    p.add_argument("--jobs", default="1", metavar="N", help="worker processes, one ngspice each (1 to 64, "
                                                            "default 1); the output order stays the same")
    p.add_argument("--dask", metavar="ADDRESS",
                   help="run each corner as a task of a running dask.distributed scheduler (tcp://host:8786), or "
                        "'local' for a LocalCluster of --jobs workers (default 2); the workers need this package, "
                        "ngspice, and the specs' files and --out at the same paths (a shared folder); a corner "
                        "running on a cluster cannot be killed: --timeout bounds each `ngspice -b` run "
                        "(--simulator ngspice-cli); a scheduler that does not answer within 3 s is exit status 3")
    p.add_argument("--simulator", default="pyspice", choices=("pyspice", "ngspice-cli"),
                   help="pyspice: ngspice's shared library (default); ngspice-cli: `ngspice -b`")
    p.add_argument("--timeout", default="600", metavar="S",
                   help="seconds one corner (its design and SPICE run) may take before it is killed and "
                        "reported as a simulator error (1 to 86400, default 600)")
    p.add_argument("--update-golden", action="store_true",
                   help="record the golden waveform files from this run (on purpose: they are then the reference)")
    p.add_argument("--no-fail", action="store_true", help="exit status 0 whatever the checks say")
    p.add_argument("--root", metavar="DIR",
                   help="the folder every path of a spec (deck, its includes, golden files, json) must resolve "
                        "inside, links followed (default: each spec's own folder; e.g. the repository: --root .)")
    p.add_argument("--allow-outside", action="store_true",
                   help="trusted specs only: let a spec's paths go anywhere; decks still may not hold .control "
                        "blocks or other ngspice commands")
    return p


def _whole(text, name: str, lo: int, hi: int) -> int:
    import math

    from ..core.errors import DesignError
    try:
        n = float(text)
    except ValueError:
        n = None
    # nan and inf (1e400 reads as inf) have no int(): refused before it is asked
    if n is None or not math.isfinite(n) or n != int(n) or not lo <= n <= hi:
        raise DesignError(f"{name} must be a whole number from {lo} to {hi}, got {text!r}")
    return int(n)


def _run(args) -> int:
    from ..check.batch import check_specs
    from ..core.errors import EXIT_OK, DesignError
    jobs = _whole(args.jobs, "--jobs", 1, 64)
    timeout = _whole(args.timeout, "--timeout", 1, 86400)
    from ..tolerance.cluster import parse_dask
    dask = None if args.dask is None else parse_dask(args.dask)
    from ..core.fileio import atomic_write, check_output_file
    for value, what in ((args.junit, "--junit"), (args.summary, "--summary")):
        if value is not None:   # before any work: never a link, FIFO or device, never after the run
            check_output_file(value, what)
    if args.root is not None and not Path(args.root).is_dir():
        raise DesignError(f"--root {args.root!r} is not a folder")
    run = check_specs(args.specs, args.simulator, jobs=jobs, timeout=timeout, update_golden=args.update_golden,
                      root=args.root, allow_outside=args.allow_outside, out=args.out, dask=dask)
    if args.junit:
        atomic_write(args.junit, run.junit())
    if args.summary:
        atomic_write(args.summary, run.summary())
    print_output("\n".join(run.lines()))
    for line in run.messages():
        print(line, file=sys.stderr)
    return EXIT_OK if args.no_fail else run.status


def check_design_main(argv=None) -> int:
    """Console entry point ``check-design``.

    Parameters
    ----------
    argv : list of str, optional
        The arguments; None reads ``sys.argv[1:]``.

    Returns
    -------
    int
        The exit status (see :func:`~designer.cli.common.run_cli`).
    """
    return run_cli("check-design", check_parser, _run, argv)


if __name__ == "__main__":  # pragma: no cover
    sys.exit(check_design_main())
