"""A whole ``check-design`` run, as a library call: every spec loaded (all refusals before any
run), each spec's corners run in worker processes (or as tasks of a Dask cluster), the output
folder written, and the outcomes handed back typed (:class:`CheckRun`). The command line
(:mod:`designer.cli.check`) and the web page's Check (:mod:`designer.web.jobs`) both call
:func:`check_specs`, so a spec runs the same way from either; each front end then renders the
run in its own words (the terminal's lines, the page's table) and writes or answers the JUnit
XML (:mod:`.junit`) and the Markdown summary (:mod:`.summary`) the run renders.

Each spec's output folder is written aside and swapped in whole once its run is done (a run killed
half-way leaves the old folder; a rerun with fewer corners leaves none of the old corners):
:func:`designer.core.fileio.new_folder_beside` and :func:`~designer.core.fileio.publish_folder`.
"""

from __future__ import annotations

import json
import time
from dataclasses import dataclass
from pathlib import Path

from ..core.errors import DesignError
from ..core.i18n import N_, Message
from .result import ERROR, FAIL, SpecOutcome, exit_status, headline

__all__ = ["CheckRun", "check_specs", "load_specs", "run_specs"]


@dataclass
class CheckRun:
    """A ``check-design`` run: each spec's outcome, in the order given, and the seconds it took."""

    outcomes: list   #: :class:`~designer.check.result.SpecOutcome` per spec
    seconds: float

    @property
    def status(self) -> int:
        """The run's exit status (:func:`~designer.check.result.exit_status`): 0, 1, 2 or 3."""
        return exit_status(self.outcomes)

    def junit(self) -> str:
        """The run's JUnit XML (:func:`designer.check.junit.junit_xml`).

        Returns
        -------
        str
            The XML document.
        """
        from .junit import junit_xml
        return junit_xml(self.outcomes, self.seconds)

    def summary(self) -> str:
        """The run's Markdown summary (:func:`designer.check.summary.summary_markdown`).

        Returns
        -------
        str
            The Markdown text.
        """
        from .summary import summary_markdown
        return summary_markdown(self.outcomes, self.seconds)

    def lines(self) -> list:
        """One line per spec: its verdict and its counts (``rc_ladder: pass (2 passed, 0 failed, ...)``).

        Returns
        -------
        list of str
            The lines.
        """
        out = []
        shout = {"pass": N_("pass"), FAIL: N_("FAIL"), ERROR: N_("ERROR")}
        for o in self.outcomes:
            n = o.counts()
            # a typed message: the text is the English, a page shows it in its language
            out.append(Message(N_("{spec}: {status} ({passed} passed, {failed} failed, {errors} errors, {skipped} "
                                  "report-only)"), spec=o.name, status=shout[o.status], passed=str(n["pass"]),
                               failed=str(n[FAIL]), errors=str(n[ERROR]), skipped=str(n["skipped"])))
        return out

    def messages(self, prog: str = "check-design") -> list:
        """One line per failed check, error and warning, each naming the spec and the corner.

        Parameters
        ----------
        prog : str
            The name each line starts with.

        Returns
        -------
        list of str
            ``check-design: failed: lab3 [LM741]: overshoot_pct = ...``, errors and warnings alike.
        """
        out = []
        for o in self.outcomes:
            for c in o.cases:
                if c.status in (FAIL, ERROR):
                    out.append(f"{prog}: {'error' if c.status == ERROR else 'failed'}: {headline(o, c)}")
            for w in o.warnings:
                out.append(f"{prog}: warning: {o.name}: {w}")
        return out

    def results(self) -> list:
        """Each spec's ``result.json`` (as written under the output folder).

        Returns
        -------
        list of dict
            :meth:`designer.check.result.SpecOutcome.to_dict` per spec, JSON-ready.
        """
        return [json.loads(json.dumps(o.to_dict())) for o in self.outcomes]


def load_specs(paths, *, update_golden: bool = False, root=None, allow_outside: bool = False) -> list:
    """Every spec of ``paths`` loaded and checked (:func:`designer.check.spec.load_spec`), before any
    runs; two specs of one name refused (the name names the JUnit suite and the output folder).

    Parameters
    ----------
    paths : list of path-like
        The spec files.
    update_golden : bool
        The golden files are to be recorded (they need not exist).
    root : path-like, optional
        The folder every path of a spec must resolve inside; None: each spec's own folder.
    allow_outside : bool
        Let a spec's paths go anywhere (trusted specs only).

    Returns
    -------
    list of CheckSpec
        The specs, in the order given.
    """
    from .spec import load_spec
    specs = [load_spec(p, update_golden=update_golden, root=root, allow_outside=allow_outside) for p in paths]
    names = {}
    for s in specs:
        if s.name in names:
            raise DesignError(f"{s.path}: name {s.name!r} is also the name of {names[s.name]}; names must differ "
                              "(they name the JUnit suites and the --out folders)")
        names[s.name] = s.path
    return specs


def check_specs(paths, simulator: str = "pyspice", *, jobs: int = 1, timeout: float = 600,
                update_golden: bool = False, root=None, allow_outside: bool = False, out=None,
                dask: str | None = None) -> CheckRun:
    """A whole ``check-design`` run (see the module docstring): the specs loaded (:func:`load_specs`),
    run (:func:`run_specs`), and with ``out`` each spec's files (its ``result.json``, build sheets,
    plots of failing golden waveforms) under ``out/<spec>/``.

    Parameters
    ----------
    paths : list of path-like
        The spec files.
    simulator : str
        The backend: ``pyspice`` or ``ngspice-cli``.
    jobs : int
        Worker processes, one ngspice each.
    timeout : float
        Seconds one corner may take before it is killed (a simulator error).
    update_golden : bool
        Record the golden waveforms instead of comparing with them.
    root : path-like, optional
        The folder every path of a spec must resolve inside; None: each spec's own folder.
    allow_outside : bool
        Let a spec's paths go anywhere (trusted specs only).
    out : path-like, optional
        The output folder (None: no files).
    dask : str, optional
        A Dask scheduler's address, or ``"local"``: the corners run as its tasks.

    Returns
    -------
    CheckRun
        The outcomes and the seconds the run took.

    Raises
    ------
    DesignError
        A bad spec (one line naming its file and line), before anything runs.
    """
    from ..core import fileio
    specs = load_specs(paths, update_golden=update_golden, root=root, allow_outside=allow_outside)
    out_dir = None if out is None else fileio.check_can_create(out)
    stages = {}
    try:
        if out_dir is not None:
            fileio.ensure_dir(out_dir)
            fileio.clean_stale(out_dir)
            stages = {s.name: fileio.new_folder_beside(out_dir / s.name) for s in specs}
        tick = time.perf_counter()
        outcomes = run_specs(specs, simulator, jobs=jobs, timeout=timeout, update_golden=update_golden,
                             out_dirs=stages, dask=dask)
        seconds = time.perf_counter() - tick
        for o in outcomes if out_dir is not None else ():
            _publish(o, stages[o.name], Path(out_dir) / o.name)
    finally:
        for stage in stages.values():   # published ones are gone already
            fileio.remove_tree(stage)
    return CheckRun(outcomes, seconds)


def _publish(outcome: SpecOutcome, stage: Path, final: Path) -> None:
    """A spec's staged folder, its ``result.json`` written, swapped in as ``final``."""
    from ..core import fileio
    _relocate(outcome, stage, final)
    outcome.files["result_json"] = str(final / "result.json")
    fileio.atomic_write(stage / "result.json", json.dumps(outcome.to_dict(), indent=2) + "\n")
    fileio.publish_folder(stage, final)


def run_specs(specs, simulator: str, *, jobs: int = 1, timeout: float = 600, update_golden: bool = False,
              out_dirs=None, dask: str | None = None) -> list:
    """Every corner of every spec in worker processes (or as tasks of a Dask cluster).

    Parameters
    ----------
    specs : list of CheckSpec
        The loaded specs.
    simulator : str
        The backend's name.
    jobs : int
        Worker processes.
    timeout : float
        Seconds one corner may take.
    update_golden : bool
        Record the golden waveforms instead of comparing with them.
    out_dirs : dict, optional
        Spec name -> the folder its files are written in (none without).
    dask : str, optional
        A Dask scheduler's address, or ``"local"``.

    Returns
    -------
    list of SpecOutcome
        One per spec, in the order given.
    """
    from ..core.workers import run_tasks
    from ..spice import simulate
    from ..spice.simulate import tool_info
    from .result import SIM_ERROR, Case, CornerOutcome
    from .run import run_corner
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
    from ..tolerance.cluster import DaskPool
    from .run import corner_task
    order = sorted(range(len(tasks)), key=lambda j: -cost(tasks[j]))
    calls = [(specs[tasks[j][0]], tasks[j][1], simulator, update_golden, (out_dirs or {}).get(specs[tasks[j][0]].name),
              timeout) for j in order]
    with DaskPool(address, jobs if jobs > 1 else 2) as pool:
        got = pool.calls(corner_task, calls, lambda i, why: lost(tasks[order[i]], why))
    results = [None] * len(tasks)
    for pos, j in enumerate(order):
        results[j] = got[pos]
    return results


def _relocate(outcome, stage: Path, final: Path) -> None:
    """The paths a spec's run recorded under its staging folder, as they will be once it
    is swapped in: in the outcome, and in the design bundles' own result.json files."""
    from ..core.fileio import atomic_write
    old, new = str(stage), str(final)

    def moved(value):
        if isinstance(value, str):
            return new + value[len(old):] if value.startswith(old) else value
        if isinstance(value, list):
            return [moved(v) for v in value]
        if isinstance(value, dict):
            return {k: moved(v) for k, v in value.items()}
        return value

    for corner in outcome.corners:
        corner.files = moved(corner.files)
    for path in stage.glob("reports/*/result.json"):
        data = json.loads(path.read_text(encoding="utf-8"))
        if "files" in data:
            data["files"] = moved(data["files"])
            atomic_write(path, json.dumps(data, indent=2) + "\n")
