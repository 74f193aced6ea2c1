"""Command-line layer of ``check-design``: load every spec (all refusals before
any run), run each spec's corners in worker processes, print a line per
failure, write the JUnit file, the Markdown summary and the ``--out`` folder,
and exit with the run's status."""

from __future__ import annotations

import sys
import time
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
    from ..check.spec import load_spec
    from ..core.errors import EXIT_OK, DesignError
    jobs = _whole(args.jobs, "--jobs", 1, 64)
    timeout = _whole(args.timeout, "--timeout", 1, 86400)
    from ..tolerance.cluster import parse_dask
    dask = None if args.dask is None else parse_dask(args.dask)
    from ..core.fileio import check_output_file
    for value, what in ((args.junit, "--junit"), (args.summary, "--summary")):
        if value is not None:   # before any work: never a link, FIFO or device, never after the run
            check_output_file(value, what)
    if args.root is not None and not Path(args.root).is_dir():
        raise DesignError(f"--root {args.root!r} is not a folder")
    specs = [load_spec(p, update_golden=args.update_golden, root=args.root, allow_outside=args.allow_outside)
             for p in args.specs]
    names = {}
    for s in specs:
        if s.name in names:
            raise DesignError(f"{s.path}: name {s.name!r} is also the name of {names[s.name]}; names must differ "
                              "(they name the JUnit suites and the --out folders)")
        names[s.name] = s.path
    from ..core import fileio
    out_dir = None if args.out is None else fileio.check_can_create(args.out)
    stages = {}
    try:
        if out_dir is not None:
            # each spec's folder is written aside and swapped in whole once its run is done: a killed
            # run leaves the old folder, a rerun with fewer corners leaves none of the old corners
            fileio.ensure_dir(out_dir)
            fileio.clean_stale(out_dir)
            stages = {s.name: fileio.new_folder_beside(out_dir / s.name) for s in specs}
        tick = time.perf_counter()
        outcomes = run_specs(specs, args.simulator, jobs=jobs, timeout=timeout, update_golden=args.update_golden,
                             out_dirs=stages, dask=dask)
        seconds = time.perf_counter() - tick
        _report(outcomes, args, seconds, out_dir, stages)
    finally:
        for stage in stages.values():   # published ones are gone already
            fileio.remove_tree(stage)
    from ..check.result import exit_status
    return EXIT_OK if args.no_fail else exit_status(outcomes)


def run_specs(specs, simulator: str, *, jobs: int = 1, timeout: float = 600, update_golden: bool = False,
              out_dirs=None, dask: str | None = None) -> list:
    """Every corner of every spec in worker processes (or as tasks of a Dask cluster: ``dask``, an
    address or ``"local"``); a :class:`~designer.check.result.SpecOutcome` per spec, in the order given.
    ``out_dirs``: spec name -> the folder its files are written in (none without)."""
    from ..core.workers import run_tasks
    from ..check.result import ERROR, SIM_ERROR, Case, CornerOutcome, SpecOutcome
    from ..check.run import run_corner
    from ..spice import simulate
    from ..spice.simulate import tool_info
    kinds = {s.kind for s in specs}
    # imported here, once: the forked workers share them instead of importing each
    if "plant" in kinds:
        import designer.plant.design  # noqa: F401
        import designer.plant.report  # noqa: F401
    if "pid" in kinds:
        import designer.pid.design  # noqa: F401
        import designer.pid.report  # noqa: F401
    if "filter" in kinds:
        import designer.filters.design  # noqa: F401
        import designer.filters.report  # noqa: F401
    tasks = [(i, k) for i, s in enumerate(specs) for k in range(len(s.corners))]

    def work(task):
        i, k = task
        return run_corner(specs[i], k, simulator, update_golden=update_golden,
                          out_dir=(out_dirs or {}).get(specs[i].name))

    def lost(task, reason):
        i, k = task
        corner = specs[i].corners[k]
        return CornerOutcome(corner, (Case("simulation", corner, ERROR, f"simulation: simulator error: {reason}",
                                           error_kind=SIM_ERROR),), None, tool_info(simulator), (), {}, timeout)

    def setup():
        simulate.DEFAULT_TIMEOUT_S = float(timeout)   # each `ngspice -b` run gets the same deadline

    def cost(task):
        # a closed loop (seven op-amps and the plant) simulates several times
        # longer than a plant; a user's deck is unknown, taken as a plant
        return 4.0 if specs[task[0]].kind == "pid" else 1.0

    if dask is None:
        results = run_tasks(tasks, work, jobs, timeout, lost, setup, cost)
    else:
        results = _on_dask(dask, jobs, tasks, specs, simulator, update_golden, out_dirs, timeout, lost, cost)
    outcomes, at = [], 0
    for s in specs:
        corners = results[at: at + len(s.corners)]
        at += len(s.corners)
        tool = next((c.tool for c in corners if c.tool.get("ngspice")), corners[0].tool)
        outcomes.append(SpecOutcome(s.name, str(s.path), s.kind, list(corners), tool))
    return outcomes


def _on_dask(address, jobs, tasks, specs, simulator, update_golden, out_dirs, timeout, lost, cost) -> list:
    """The corners as tasks of a Dask cluster, longest first (:class:`designer.tolerance.cluster.DaskPool`:
    a corner whose worker dies runs once more, then is ``lost``); results in task order."""
    from ..check.run import corner_task
    from ..tolerance.cluster import DaskPool
    order = sorted(range(len(tasks)), key=lambda j: -cost(tasks[j]))
    calls = [(specs[tasks[j][0]], tasks[j][1], simulator, update_golden, (out_dirs or {}).get(specs[tasks[j][0]].name),
              timeout) for j in order]
    with DaskPool(address, jobs if jobs > 1 else 2) as pool:
        got = pool.calls(corner_task, calls, lambda i, why: lost(tasks[order[i]], why))
    results = [None] * len(tasks)
    for pos, j in enumerate(order):
        results[j] = got[pos]
    return results


def _report(outcomes, args, seconds: float, out_dir, stages: dict) -> None:
    from ..check.junit import junit_xml
    from ..check.result import ERROR, FAIL, headline
    from ..check.summary import summary_markdown
    from ..core import fileio
    from ..core.fileio import atomic_write
    if out_dir is not None:
        import json
        for o in outcomes:
            final, stage = Path(out_dir) / o.name, stages[o.name]
            _relocate(o, stage, final)
            o.files["result_json"] = str(final / "result.json")
            atomic_write(stage / "result.json", json.dumps(o.to_dict(), indent=2) + "\n")
            fileio.publish_folder(stage, final)
    if args.junit:
        atomic_write(args.junit, junit_xml(outcomes, seconds))
    if args.summary:
        atomic_write(args.summary, summary_markdown(outcomes, seconds))
    lines = []
    for o in outcomes:
        n = o.counts()
        lines.append(f"{o.name}: {o.status.upper() if o.status != 'pass' else 'pass'} ({n['pass']} passed, "
                     f"{n[FAIL]} failed, {n[ERROR]} errors, {n['skipped']} report-only)")
    print_output("\n".join(lines))
    for o in outcomes:
        for c in o.cases:
            if c.status in (FAIL, ERROR):
                print(f"check-design: {'error' if c.status == ERROR else 'failed'}: {headline(o, c)}",
                      file=sys.stderr)
        for w in o.warnings:
            print(f"check-design: warning: {o.name}: {w}", file=sys.stderr)


def _relocate(outcome, stage: Path, final: Path) -> None:
    """The paths a spec's run recorded under its staging folder, as they will be once it
    is swapped in: in the outcome, and in the design bundles' own result.json files."""
    import json
    old, new = str(stage), str(final)

    def moved(value):
        if isinstance(value, str):
            return new + value[len(old):] if value.startswith(old) else value
        if isinstance(value, list):
            return [moved(v) for v in value]
        if isinstance(value, dict):
            return {k: moved(v) for k, v in value.items()}
        return value

    from ..core.fileio import atomic_write
    for corner in outcome.corners:
        corner.files = moved(corner.files)
    for path in stage.glob("reports/*/result.json"):
        data = json.loads(path.read_text(encoding="utf-8"))
        if "files" in data:
            data["files"] = moved(data["files"])
            atomic_write(path, json.dumps(data, indent=2) + "\n")


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
