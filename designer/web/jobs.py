"""What a worker process does for one request of the web page: call the
library with the request's fields, and hand back what the page shows.

Every task is the library's (:data:`LIBRARY`: design-plant, analyze-plant, design-filter, design-pid,
analyze-pid, check-design, identify; issue 26): the request's fields become the library's specs through
the page's name tables (:mod:`.forms`), the library runs in this process, and the typed result is
rendered: its JSON (what the command's ``--json`` prints), and what a terminal cannot show: plot
traces, the schematic as SVG, the bill of materials, the build sheet. No command line is built, no
console script run, no printed JSON parsed back.

Nothing here computes a figure of a design: the traces are the result's own
arrays (decimated for the browser), and the frequency responses the models'
transfer functions evaluated on a grid, as the sheet's plots do
(:mod:`designer.report.plots`).
"""

from __future__ import annotations

import io
import json
import math
import os
import signal
import tempfile
from contextlib import contextmanager

import numpy as np

from ..core import lifetime
from ..core.i18n import N_, Message, current, language, localise, translated
from ..core.i18n import gettext as _
from ..core.jsonio import json_safe
from ..core.units import format_eng
# the filter stack (scipy.signal's prototypes, the sheet) imported here, in the server process before it forks the
# pool: every worker has it, and a worker's first filter request does not pay ~2 s of imports
from ..filters import report as filter_report
from ..filters.alternatives import design_alternatives
from ..filters.design import design as design_filter
from ..tolerance import filter as filter_tolerance
from ..core.figure_titles import figure_shown
from ..spice.simulate import recorded_command

__all__ = ["AXES", "BODE_POINTS", "BOM_COLUMNS", "LIBRARY", "SWALLOWING_MODULES", "Superseded", "TRACES",
           "TRACE_POINTS", "analyze_pid_task", "analyze_plant_task", "bom_shown", "bundle_zip", "check_task",
           "checks_shown", "circuit_plant_page", "design_filter_task", "design_pid_task", "design_plant_task",
           "files_in", "filter_page", "histograms", "identify_page", "identify_task", "pid_page", "plant_page", "run",
           "run_task", "series_text", "temporaries_in", "warm_up", "written_since"]

#: points of a trace sent to the browser (uPlot draws thousands in a frame; the sheet's PNGs use fewer)
TRACE_POINTS = 1500
#: frequency points of a Bode trace
BODE_POINTS = 300


class Superseded(BaseException):
    """The page typed on: the request under way is of inputs nobody will see (the pool's SIGUSR1, raised
    between two bytecodes of the run, or as ngspice's shared library returns; a BaseException, so that no
    ``except Exception`` of the library keeps it). Whatever it runs unwinds: ``subprocess.run`` kills an
    ``ngspice -b`` it waits for, the ``with`` blocks close, and the worker takes the next request."""


#: whether a task is running in this process (a cancel that comes after it ended is ignored)
_RUNNING = False


#: modules whose functions the interpreter calls where an exception is printed and swallowed, not raised: the
#: at-fork hooks (logging takes and releases its lock around every fork, each ``subprocess.run`` of
#: ``ngspice -b`` among them): a cancel landing there would be a traceback on the server's stderr, the run going on
SWALLOWING_MODULES = ("logging",)


def _starting_a_child(frame) -> bool:
    """Whether ``frame`` runs inside :class:`subprocess.Popen`'s constructor (its ``_execute_child``): an
    exception raised there leaves the process it forked (an ``ngspice -b``) running, its Popen never returned,
    so nothing kills or reaps it (Python warns "subprocess N is still running" when the object goes)."""
    while frame is not None:
        if frame.f_globals.get("__name__") == "subprocess" and frame.f_code.co_name in ("__init__", "_execute_child"):
            return True
        frame = frame.f_back
    return False


def _cancel(signum, frame) -> None:
    if not _RUNNING:
        return
    # inside ngspice's callbacks cffi would swallow it: raised as the library's command returns (a signal
    # handled only in those callbacks, as in a SPICE Monte Carlo's loop, would otherwise wait for the whole
    # loop); inside an at-fork hook the interpreter would swallow it, inside Popen's start the child it forked
    # would be left running with no one to kill and reap it: again in 5 ms
    if lifetime.in_native():
        lifetime.after_native(_superseded)
        return
    if (frame is not None and frame.f_globals.get("__name__") in SWALLOWING_MODULES) or _starting_a_child(frame):
        signal.signal(signal.SIGALRM, _cancel)
        signal.setitimer(signal.ITIMER_REAL, 0.005)
        return
    raise Superseded()


def _superseded() -> None:
    if _RUNNING:
        raise Superseded()


def run(task: dict) -> dict:
    """Run one task in this (worker) process; a SIGUSR1 while it runs (:class:`Superseded`: the pool's
    cancel of a request whose client left) ends it at once, answered ``{"status": "superseded"}``.

    Parameters
    ----------
    task : dict
        As :func:`run_task`'s.

    Returns
    -------
    dict
        :func:`run_task`'s answer.
    """
    global _RUNNING
    if signal.getsignal(signal.SIGUSR1) is not _cancel:
        try:
            signal.signal(signal.SIGUSR1, _cancel)
        except ValueError:   # not the main thread (a caller's own thread): no cancel, the run goes on
            pass
    _RUNNING = True
    try:
        return run_task(task)
    except Superseded:
        return {"status": "superseded", "error": None, "json": None}
    finally:
        _RUNNING = False


def run_task(task: dict) -> dict:
    """Run one task in this (worker) process.

    Parameters
    ----------
    task : dict
        ``task_file`` (the name of a JSON file holding the task, as the server sends it), or the
        task itself: ``prog`` (a command of :data:`LIBRARY`), ``fields`` (the request's fields, the
        page's language ``lang`` among them), ``want``: "page" (the JSON and the page's
        extras), "json", "sheet" (the printable build sheet), "bundle" (the
        design's files as a zip) or "check" (check-design's answer); ``tmp``:
        the request's private folder (files written there), or None; identify's ``capture`` (the uploaded
        file's path).

    Returns
    -------
    dict
        ``status`` (the command's exit status), ``error`` (its one-line refusal in the page's words, or
        None), ``json`` (what the command's ``--json`` prints), and per ``want``:
        ``page``, ``body`` (bytes) with ``media`` and ``filename``.
    """
    if "task_file" in task:   # the server's requests come as a file in their private folder (see .app)
        with open(task["task_file"], encoding="utf-8") as fh:
            task = json.load(fh)
    if task["prog"] == "warm-up":
        return warm_up()
    # the request's fields (and an identify request's uploaded capture)
    return LIBRARY[task["prog"]](task["fields"], task.get("want", "json"), task.get("tmp"),
                                 **({"capture": task["capture"]} if "capture" in task else {}))


@contextmanager
def temporaries_in(folder: str | None):
    """Every temporary file of the block (the simulator's ``designer-sim-*``, ``ngspice -b``'s own,
    through ``TMPDIR``) made in ``folder`` (the request's private folder; None: where they were), so
    that removing the folder removes them, a run killed at its deadline included.

    Parameters
    ----------
    folder : str or None
        The request's private folder.
    """
    if folder is None:
        yield
        return
    before, env = tempfile.tempdir, os.environ.get("TMPDIR")
    tempfile.tempdir = os.environ["TMPDIR"] = folder
    try:
        yield
    finally:
        tempfile.tempdir = before
        if env is None:
            os.environ.pop("TMPDIR", None)
        else:
            os.environ["TMPDIR"] = env


def _read(path) -> bytes:
    with open(path, "rb") as fh:
        return fh.read()


# --------------------------------------------------------------------------- library-first commands

def design_plant_task(fields: dict, want: str = "json", tmp: str | None = None) -> dict:
    """design-plant for the page, the library called directly: the request's fields as the specs
    (:func:`designer.web.forms.plant_request`), :func:`designer.plant.design.design_plant`, the PRBS
    bench test and the tolerance analysis asked for, and the typed result rendered.

    Parameters
    ----------
    fields : dict
        The request's JSON object (the plant page's fields, :data:`designer.web.forms.PLANT`).
    want : str
        As :func:`run`'s.
    tmp : str or None
        The request's private folder (the files of a sheet or bundle; every temporary file).

    Returns
    -------
    dict
        As :func:`run`'s; a refusal's ``field`` and ``label`` name the page's field at fault.
    """
    from .forms import PLANT

    def work(fields, lang):
        from ..plant.circuit import DEFAULT_TOPOLOGY
        from ..plant.circuit_design import design_circuit_plant
        from ..plant.design import design_plant
        from .forms import plant_request
        rq = plant_request(fields)
        if rq.spec.topology != DEFAULT_TOPOLOGY:   # another registered section: the generic plant pipeline
            return _circuit_plant(design_circuit_plant(rq.spec, simulate=rq.simulate, simulator=rq.simulator), rq,
                                  want, tmp, lang)
        return _sallen_key_plant(design_plant(rq.spec, simulate=rq.simulate, simulator=rq.simulator), rq, want,
                                 tmp, lang)
    return _library_task("design-plant", PLANT, fields, work, want, tmp)


def analyze_plant_task(fields: dict, want: str = "json", tmp: str | None = None) -> dict:
    """analyze-plant for the page, the library called directly: the request's fields as the specs
    (:func:`designer.web.forms.analyze_plant_request`), :func:`designer.plant.design.analyze_plant` (another
    section's parts: :func:`designer.plant.circuit_design.analyze_circuit_plant`), the PRBS bench test, the
    tolerance analysis or the replayed build asked for, and the typed result rendered as design-plant's.

    Parameters
    ----------
    fields : dict
        The request's JSON object (the analysis's fields, :data:`designer.web.forms.ANALYZE_PLANT`).
    want : str
        As :func:`run`'s.
    tmp : str or None
        The request's private folder (the files of a sheet or bundle; every temporary file).

    Returns
    -------
    dict
        As :func:`run`'s (the JSON as ``analyze-plant --json`` prints it); a refusal's ``field`` and ``label``
        name the page's field at fault.
    """
    from .forms import ANALYZE_PLANT

    def work(fields, lang):
        from ..plant.circuit_design import analyze_circuit_plant
        from ..plant.design import analyze_plant
        from .forms import analyze_plant_request
        rq = analyze_plant_request(fields)
        if rq.circuit is not None and rq.replay is not None:   # a section's build replayed, as the Sallen-Key's
            from ..tolerance.spice_mc import replay, replay_result
            result, mc = analyze_circuit_plant(**rq.circuit, simulate=False), rq.monte_carlo
            s = result.sourcing
            build = replay(result, {"R": s.r_series, "C": s.c_series}, rq.replay, mc.n, mc.seed, mc.sampler, mc.dist,
                           mc.tol, rq.simulator)
            result = replay_result(result, build, rq.simulator, square_hz=rq.circuit.get("square_hz"))
            return _circuit_answer(result, rq, want, tmp, lang, f"{rq.name}_sample{rq.replay}")
        if rq.circuit is not None:   # another registered section's parts
            return _circuit_plant(analyze_circuit_plant(**rq.circuit, simulate=rq.simulate, simulator=rq.simulator),
                                  rq, want, tmp, lang)
        if rq.replay is not None:   # the build's own bundle: analyze-plant of its exact values, in SPICE
            from ..tolerance.spice_mc import replay, replay_result
            result, mc = analyze_plant(rq.spec, simulate=False), rq.monte_carlo
            s = result.sourcing
            build = replay(result, {"R": s.r_series, "C": s.c_series}, rq.replay, mc.n, mc.seed, mc.sampler, mc.dist,
                           mc.tol, rq.simulator)
            result = replay_result(result, build, rq.simulator, s.r_series, s.c_series, rq.spec.package)
            return _plant_answer(result, rq, want, tmp, lang, f"{rq.name}_sample{rq.replay}")
        return _sallen_key_plant(analyze_plant(rq.spec, simulate=rq.simulate, simulator=rq.simulator), rq, want, tmp,
                                 lang)
    return _library_task("analyze-plant", ANALYZE_PLANT, fields, work, want, tmp)


def _sallen_key_plant(result, rq, want: str, tmp: str | None, lang: str | None) -> tuple:
    """A Sallen-Key low-pass plant (designed or as built) with the PRBS bench test and the tolerance analysis
    ``rq`` asks for; as :func:`_library_task`'s ``work`` answers."""
    from ..tolerance.mcspec import plant_tolerance
    if rq.stimulus is not None:
        from ..plant.prbs import with_prbs
        result = with_prbs(result, result.test.amplitude_v, rq.stimulus[0], rq.stimulus[1], rq.simulate,
                           rq.simulator)
    result = plant_tolerance(result, rq.monte_carlo, rq.worst_case, rq.tol, rq.simulator)
    return _plant_answer(result, rq, want, tmp, lang, rq.name)


def _plant_answer(result, rq, want: str, tmp: str | None, lang: str | None, name: str) -> tuple:
    """A Sallen-Key low-pass plant's result as the page takes it: its files written under ``name`` for a sheet
    or bundle, its JSON with the command line ``rq`` stands for, its page."""
    from ..plant.report import write_outputs
    if want in ("sheet", "bundle"):
        write_outputs(result, tmp, name)
    data = json.loads(json.dumps(result.to_dict()))
    # the command line this request stands for: a record, never parsed
    data["tool"]["argv"] = rq.argv + ([f"--lang={lang}"] if lang else [])
    return data, lambda: plant_page(result), name


def _circuit_plant(result, rq, want: str, tmp: str | None, lang: str | None) -> tuple:
    """A plant on a registered topology other than the seed's (designed, :func:`designer.plant.circuit_design.
    design_circuit_plant`, or as built), with the PRBS bench test and the tolerance analysis
    (:func:`designer.tolerance.mcspec.section_tolerance`, as design-plant --topology runs it); as
    :func:`_library_task`'s ``work`` answers."""
    from ..tolerance.mcspec import section_tolerance
    if rq.stimulus is not None:
        from ..plant.circuit_prbs import with_section_prbs
        result = with_section_prbs(result, result.amplitude_v, rq.stimulus[0], rq.stimulus[1], rq.simulate,
                                   rq.simulator)
    result = section_tolerance(result, rq.monte_carlo, rq.worst_case, rq.tol, rq.simulator)
    return _circuit_answer(result, rq, want, tmp, lang, rq.name)


def _circuit_answer(result, rq, want: str, tmp: str | None, lang: str | None, name: str) -> tuple:
    """A section plant's result as the page takes it: its files written under ``name`` for a sheet or bundle,
    its JSON with the command line ``rq`` stands for, its page."""
    from ..plant.circuit_report import write_outputs
    if want in ("sheet", "bundle"):
        write_outputs(result, tmp, name)
    data = json.loads(json.dumps(result.to_dict()))
    data["tool"]["argv"] = rq.argv + ([f"--lang={lang}"] if lang else [])
    return data, lambda: circuit_plant_page(result), name


def circuit_plant_page(result) -> dict:
    """A plant on a registered topology, for the page: its declared parts (designator, role, value), the Bode
    plot of both models (the section's transfer function with the parts as built, ideal and with the op-amp's
    model, evaluated on a grid as the sheet's plots are), the BOM and the sheet's content (the wiring, target
    and achieved, sensitivities, alternatives) and its schematic (the one-stage drawing of the sheet).

    Parameters
    ----------
    result : CircuitPlantResult
        The design on a registered topology
        (:func:`designer.plant.circuit_design.design_circuit_plant`).

    Returns
    -------
    dict
        The page's JSON-ready content.
    """
    from ..plant import circuit_report as rep
    from ..report.document import to_html
    topo, amp = result.section, result.opamp
    fn = result.figures["opamp"]["fn_hz"]
    f = np.geomspace(fn / 100, fn * 100, BODE_POINTS)
    s = 2j * np.pi * f
    resp = {"ideal op-amp": topo.response(result.values, s), f"{amp.name} model": topo.response(result.values, s, amp)}
    sine = result.sine
    if sine is not None and sine.h_spice is not None:
        resp["SPICE .ac"] = _complex_on_grid(sine.spice_f_hz, sine.h_spice, f)
    bom = rep.bom(result)
    bench = rep.bench_settings(result)
    return {"parts": [{"ref": p.ref, "role": p.role, "value": result.values[p.ref], "kind": p.kind}
                      for p in topo.parts],
            "bode": _bode(f, resp), "histograms": histograms(result.monte_carlo), **bom_shown(bom),
            "bench": [[localise(c) for c in row] for row in bench],
            **({} if result.tolerance is None or result.tolerance.t_s is None else {"step": _section_step(result)}),
            "checks": checks_shown(result.checks), "notes": [localise(translated(n)) for n in result.notes],
            "schematic_svg": _schematic_svg(rep, result, [topo.name, dict(result.values), result.package]),
            "sheet_html": to_html(rep.title_of(result), rep.sections(result), {}),
            "title": localise(rep.title_of(result))}


def _section_step(result) -> dict:
    """A section plant's output after the bench square wave's rising edge, as the seed plant's page shows it:
    both models (the section's transfer function with the parts as built, ideal and with the op-amp's model),
    the tolerance band of the builds over the parts' tolerance corners and, when the square-wave test ran,
    SPICE's output; on the band's grid (the rising half period, at most four response spans)."""
    from ..core.lti import step_response
    from ..plant import circuit
    topo, amp, tol = result.section, result.opamp, result.tolerance
    a, t = result.test.amplitude_v, np.asarray(tol.t_s, float)
    step = {}
    sq = result.square
    if sq is not None:   # its period's rising edge (its middle: the models' step is taken there)
        step["SPICE (ngspice)"] = np.interp(t + sq.test.delay_s + sq.test.edge_s / 2, sq.t, sq.y_spice)
    for label, (num, den) in ((f"analytic ({amp.name} model)", circuit.opamp_tf(topo, result.values, amp)),
                              ("analytic (ideal op-amp)", topo.coefficients(result.values))):
        num, den = np.asarray(num, float), np.asarray(den, float)
        num = np.trim_zeros(num, "f") if np.any(num) else num
        step[label] = a * step_response(num, den, t)
    step["tolerance band low"], step["tolerance band high"] = tol.lo * a, tol.hi * a
    return _trace(t, step, "time from the edge (s)")


def design_filter_task(fields: dict, want: str = "json", tmp: str | None = None) -> dict:
    """design-filter for the page, the library called directly: the request's fields as the specs
    (:func:`designer.web.forms.filter_request`), :func:`designer.filters.design.design` (with its SPICE
    proof), the Monte Carlo against the mask and the worst case asked for
    (:mod:`designer.tolerance.filter`), and the typed result rendered (the sheet design-filter writes).

    Parameters
    ----------
    fields : dict
        The request's JSON object (the filter page's fields, :data:`designer.web.forms.FILTER`).
    want : str
        As :func:`run`'s.
    tmp : str or None
        The request's private folder (the files of a sheet or bundle; every temporary file).

    Returns
    -------
    dict
        As :func:`run`'s (the JSON as ``design-filter --json`` prints it); a refusal's ``field`` and
        ``label`` name the page's field at fault.
    """
    from .forms import FILTER

    def work(fields, lang):
        from .forms import filter_request
        tf = filter_tolerance
        rq = filter_request(fields)
        result = design_filter(rq.spec, simulate=rq.simulate, simulator=rq.simulator)
        mc = rq.monte_carlo
        extras = {}
        if mc is not None:
            extras["monte_carlo"] = tf.filter_monte_carlo(result, mc.n, mc.seed, mc.sampler, mc.dist, mc.tol,
                                                          mc.limits)
        if rq.worst_case:
            extras["worst_case"] = tf.filter_worst_case(result, mc.tol if mc is not None else rq.tol)
        extra = json_safe({k: v.to_dict() for k, v in extras.items()})
        sheet = filter_report.sheet_of(result)
        sheet.extra = extra
        # design-filter --alternatives N: the joint search's best part sets, on the sheet and in the JSON
        sheet.alternatives = design_alternatives(result, rq.alternatives) if rq.alternatives is not None else []
        if want in ("sheet", "bundle"):
            filter_report.write_outputs(sheet, tmp, rq.name, lang)
        # as design-filter --json prints it
        data = json_safe({**result.to_dict(), **extra, **filter_report.alternatives_json(sheet.alternatives),
                          "files": {}})
        return data, lambda: filter_page(sheet, extras.get("monte_carlo")), rq.name
    return _library_task("design-filter", FILTER, fields, work, want, tmp)


def design_pid_task(fields: dict, want: str = "json", tmp: str | None = None) -> dict:
    """design-pid for the page, the library called directly: the request's fields as the specs
    (:func:`designer.web.forms.pid_request`, through :func:`designer.pid.spec.pid_spec`, the command line's
    mapping), :func:`designer.pid.design.design_pid`, the loop's tolerance analysis asked for
    (:func:`designer.tolerance.mcspec.loop_tolerance`), and the typed result rendered (the sheet and bundle
    :func:`designer.pid.report.write_outputs` writes).

    Parameters
    ----------
    fields : dict
        The request's JSON object (the PID page's fields, :data:`designer.web.forms.PID`).
    want : str
        As :func:`run`'s.
    tmp : str or None
        The request's private folder (a file field's content, the files of a sheet or bundle; every
        temporary file).

    Returns
    -------
    dict
        As :func:`run`'s (the JSON as ``design-pid --json`` prints it); a refusal's ``field`` and ``label``
        name the page's field at fault.
    """
    from .forms import PID

    def work(fields, lang):
        from ..pid.design import design_pid
        from ..pid.spec import default_name
        from .forms import pid_request

        def run(spec, simulate, simulator):
            return design_pid(spec, simulate=simulate, simulator=simulator, rules_spice=rq.rules_spice)
        rq = pid_request(fields, tmp)
        return _loop_answer(rq, run, default_name, want, tmp, lang)
    return _library_task("design-pid", PID, fields, work, want, tmp)


def analyze_pid_task(fields: dict, want: str = "json", tmp: str | None = None) -> dict:
    """analyze-pid for the page, the library called directly: the request's fields as the specs
    (:func:`designer.web.forms.analyze_pid_request`: the controller's parts as built through
    :func:`designer.pid.spec.controller_as_built`, the rest through :func:`designer.pid.spec.pid_spec`, the command
    line's mappings), :func:`designer.pid.design.analyze_pid`, the loop's tolerance analysis or the replayed build
    asked for, and the typed result rendered as design-pid's.

    Parameters
    ----------
    fields : dict
        The request's JSON object (the analysis's fields, :data:`designer.web.forms.ANALYZE_PID`).
    want : str
        As :func:`run`'s.
    tmp : str or None
        The request's private folder (a file field's content, the files of a sheet or bundle; every
        temporary file).

    Returns
    -------
    dict
        As :func:`run`'s (the JSON as ``analyze-pid --json`` prints it); a refusal's ``field`` and ``label``
        name the page's field at fault.
    """
    from .forms import ANALYZE_PID

    def work(fields, lang):
        from ..pid.design import analyze_pid
        from ..pid.spec import analyzed_name
        from .forms import analyze_pid_request
        rq = analyze_pid_request(fields, tmp)
        return _loop_answer(rq, lambda spec, simulate, simulator: analyze_pid(spec, simulate=simulate,
                                                                             simulator=simulator),
                            analyzed_name, want, tmp, lang)
    return _library_task("analyze-pid", ANALYZE_PID, fields, work, want, tmp)


def _loop_answer(rq, run, default_name, want: str, tmp: str | None, lang: str | None) -> tuple:
    """A PID loop (``run(spec, simulate, simulator)``: designed or as built) with the tolerance analysis ``rq``
    asks for, or its replayed build (``--replay I``: the run without SPICE is the draw's nominal, the build's
    own run the simulation, :func:`designer.tolerance.spice_loop_mc.replay`); its files named by ``rq`` or
    ``default_name(spec, result)``; as :func:`_library_task`'s ``work`` answers."""
    from ..pid.report import write_outputs
    from ..tolerance.mcspec import loop_tolerance
    if rq.replay is not None:
        from ..tolerance.loop import loop_series
        from ..tolerance.spice_loop_mc import replay, replay_result
        nominal, mc = run(rq.spec, False, rq.simulator), rq.monte_carlo
        build = replay(nominal, loop_series(nominal), rq.replay, mc.n, mc.seed, mc.sampler, mc.dist, mc.tol,
                       rq.simulator)
        result = replay_result(rq.spec, nominal, build, rq.simulator)
        name = f"{rq.name or default_name(rq.spec, nominal)}_sample{rq.replay}"
    else:
        result = loop_tolerance(run(rq.spec, rq.simulate, rq.simulator), rq.monte_carlo, rq.worst_case, rq.tol,
                                rq.simulator)
        name = rq.name or default_name(rq.spec, result)
    if want in ("sheet", "bundle"):
        write_outputs(result, tmp, name)
    data = json.loads(json.dumps(result.to_dict()))
    # the command line this request stands for: a record, never parsed
    data["tool"]["argv"] = rq.argv + ([f"--lang={lang}"] if lang else [])
    return data, lambda: pid_page(result), name


def _library_task(prog: str, table: dict, fields: dict, work, want: str, tmp: str | None) -> dict:
    """One library-first task: the request's language taken from ``fields``, then ``work(fields, lang)`` (in
    ``tmp``, every temporary file there) gives (the JSON, a function drawing the page, the design's name: its
    files, written there for a sheet or bundle); a refusal in the page's words and language (the field of
    ``table`` at fault), the simulator's failure exit status 3."""
    from ..core.errors import DesignError
    from .request import split_language
    try:
        fields, lang = split_language(fields)
    except DesignError as exc:
        return {"status": 2, "error": f"{prog}: error: {exc}", "json": None, "field": None, "label": None}
    with language(lang):   # the refusals, the page's words and the sheet in the request's language
        return _library_work(prog, table, fields, lang, work, want, tmp)


def _library_work(prog: str, table: dict, fields: dict, lang: str | None, work, want: str, tmp: str | None) -> dict:
    """:func:`_library_task`'s work, in the request's language."""
    from ..core.errors import DesignError, SimulatorError
    from .forms import page_message
    try:
        with temporaries_in(tmp):
            data, page, name = work(fields, lang)
    except SimulatorError as exc:
        return {"status": 3, "error": f"{prog}: error: simulator error: {exc}", "json": None}
    except DesignError as exc:
        text, field = page_message(exc, table)
        return {"status": 2, "error": f"{prog}: error: {text}", "json": None, "field": field,
                "label": _(table[field].label) if field else None}
    answer = {"status": 0, "error": None, "json": data}
    if want == "page":
        answer["page"] = page()
    elif want == "sheet":
        answer.update(body=_read(os.path.join(tmp, "reports", name, "build-sheet.html")),
                      media="text/html; charset=utf-8", filename="build-sheet.html")
    elif want == "bundle":
        answer.update(body=bundle_zip(tmp, name), media="application/zip", filename=f"{name}.zip")
    return answer


def check_task(fields: dict, want: str = "check", tmp: str | None = None) -> dict:
    """check-design for the Check page, the library called directly: the spec files the server wrote in the
    request's folder (``tmp/in``, each under its relative path), the page's options as
    :func:`designer.web.forms.check_request` takes them, and :func:`designer.check.batch.check_specs` run
    with that folder as the root every path of a spec must stay inside (check-design's trust boundary, as
    ``--root``), its output folder ``tmp/out``.

    Parameters
    ----------
    fields : dict
        ``specs`` (the specs' paths relative to ``tmp/in``, ``/``-separated, as the server checked them) and
        ``options`` (the page's fields, :data:`designer.web.forms.CHECK`; ``lang`` among them).
    want : str
        ``check`` (the only answer Check gives).
    tmp : str
        The request's private folder.

    Returns
    -------
    dict
        ``status`` (the run's exit status), ``error`` (a refusal in the page's words, with its ``field`` and
        ``label``; or the run's last error line when a spec proved bad or the simulator failed), ``json``
        (``{"specs": [each spec's result.json]}``), ``junit``, ``summary``, ``golden`` (the golden files
        recorded: their paths relative to the folder chosen -> text), ``lines`` and ``messages`` (what
        check-design prints on stdout and stderr).
    """
    from ..check.batch import check_specs
    from ..core.errors import DesignError
    from .forms import CHECK, check_message, check_request, page_text
    from .request import split_language
    inside = os.path.join(tmp, "in")
    specs = [os.path.join(inside, *rel.split("/")) for rel in fields["specs"]]
    try:
        options, lang = split_language(fields.get("options") or {})
    except DesignError as exc:
        return {"status": 2, "error": f"check-design: error: {exc}", "json": None, "field": None, "label": None}
    with language(lang), temporaries_in(tmp):
        try:
            rq = check_request(options)
            # each result's tool.argv: the command line this request stands for (a record, never parsed)
            argv = [rq.argv[0], *specs, *rq.argv[1:], "--junit", os.path.join(tmp, "junit.xml"), "--summary",
                    os.path.join(tmp, "summary.md"), "--out", os.path.join(tmp, "out"), "--root", inside]
            before = files_in(inside)
            with recorded_command(argv):
                run = check_specs(specs, rq.simulator, update_golden=rq.update_golden, root=inside,
                                  out=os.path.join(tmp, "out"))
        except DesignError as exc:
            text, field = check_message(exc)
            return {"status": 2, "error": f"check-design: error: {text}", "json": None, "field": field,
                    "label": _(CHECK[field].label) if field else None}
        # the cases' typed messages (a parameter they carry) in the page's words; the junit.xml as check-design's
        results, said = run.results(), {}
        for spec, outcome in zip(results, run.outcomes):
            for corner, outcome_corner in zip(spec["corners"], outcome.corners):
                for case, c in zip(corner["cases"], outcome_corner.cases):
                    if isinstance(c.message, Message):
                        case["message"] = said[str(c.message)] = page_text(c.message, CHECK)
        messages, summary = _said(run.messages(), said), _said([run.summary()], said)[0]
        lines = [page_text(line, CHECK) for line in run.lines()]   # in the request's language, as the cases
        status = run.status
        error = None
        if status not in (0, 1):   # a spec that proved bad while running, or the simulator: its last line
            error = check_message(DesignError(messages[-1]))[0] if messages else f"failed with exit status {status}"
    return {"status": status, "error": error, "json": {"specs": results}, "junit": run.junit(),
            "summary": summary, "golden": written_since(inside, before) if rq.update_golden else {},
            "lines": lines, "messages": messages}


def _said(lines: list, said: dict) -> list:
    """``lines`` with each English text of ``said`` as the page words it (text -> page text)."""
    for english, page in said.items():
        lines = [line.replace(english, page) for line in lines]
    return lines


def identify_task(fields: dict, want: str = "json", tmp: str | None = None, capture: str | None = None) -> dict:
    """identify for the page, the library called directly: the request's fields as the library's request
    (:func:`designer.web.forms.identify_request`, through :func:`designer.identify.spec.identify_spec`, the
    command line's mapping), :func:`designer.identify.spec.identify_file`, and the typed result rendered
    (:func:`identify_page`).

    Parameters
    ----------
    fields : dict
        The request's fields (the identify page's, :data:`designer.web.forms.IDENTIFY`).
    want : str
        As :func:`run`'s (``json`` or ``page``).
    tmp : str or None
        The request's private folder (a file field's content; every temporary file).
    capture : str or None
        The uploaded capture's path (in ``tmp``).

    Returns
    -------
    dict
        As :func:`run`'s (the JSON as ``identify --json`` prints it); a refusal's ``field`` and ``label``
        name the page's field at fault.
    """
    from .forms import IDENTIFY

    def work(fields, lang):
        from ..identify.spec import identify_dict, identify_file
        from .forms import identify_request
        result = identify_file(identify_request(fields, capture, tmp))
        return json_safe(identify_dict(result)), lambda: identify_page(result), None
    return _library_task("identify", IDENTIFY, fields, work, want, tmp)


#: the commands the page runs through the library (no console script, no argv, no printed JSON)
LIBRARY = {"design-plant": design_plant_task, "analyze-plant": analyze_plant_task, "design-pid": design_pid_task,
           "analyze-pid": analyze_pid_task, "design-filter": design_filter_task, "check-design": check_task,
           "identify": identify_task}


# --------------------------------------------------------------------------- identify

def identify_page(result) -> dict:
    """The data with the best three valid models over them (a step capture: time
    since the step; a frequency table: gain and phase against frequency; a
    broadband capture, PRBS or noise: the step its impulse estimate integrates
    to, and its spectral estimate's gain, each with its own ranking's models).

    Parameters
    ----------
    result : IdentifyResult, FreqIdentifyResult or BroadbandResult
        The identification.

    Returns
    -------
    dict
        The page's JSON-ready content (``kind`` and its plots).
    """
    if hasattr(result, "excitation"):
        return _broadband_page(result)
    shown = [m for m in result.methods if m.valid][:3]
    if hasattr(result, "step"):
        from ..core.stepfit import model_step
        from ..identify.settle import block_mean
        s = result.step
        t, y = block_mean(s.t_raw, s.y_raw, TRACE_POINTS)
        tt = np.asarray(t) - s.t_step
        series = {"data": y}
        for m in shown:
            series[f"{m.name} ({m.model})"] = s.y0 + s.amplitude * model_step(m.model, m.params, tt)
        return {"kind": "step", "plot": _trace(tt, series, "time since the step (s)")}
    from ..identify.bode_readings import model_phase, model_response
    d = result.data
    w = np.geomspace(d.w[0] / 2.0, d.w[-1] * 2.0, BODE_POINTS)
    models = {f"{m.name} ({m.model})": model_response(m.model, m.params, w) for m in shown}
    gain = {"data": _on_grid(d.f_hz, d.gain_db, w / (2 * math.pi))}
    gain.update({k: 20 * np.log10(np.abs(h)) for k, h in models.items()})
    page = {"kind": "frequency", "plot": _trace(w / (2 * math.pi), gain, "frequency (Hz)", log_x=True)}
    if d.phase is not None:
        phase = {"data": _on_grid(d.f_hz, np.rad2deg(d.phase), w / (2 * math.pi))}
        phase.update({f"{m.name} ({m.model})": np.rad2deg(model_phase(m.model, dict(m.params), w)) for m in shown})
        page["phase"] = _trace(w / (2 * math.pi), phase, "frequency (Hz)", log_x=True)
    return page


def _broadband_page(result) -> dict:
    """A broadband identification's views (as ``identify --plot`` draws them): the integrated impulse
    response, the spectral estimate's gain, the record with its best models (``record``; the ``plot`` of an
    input only the output-error route reads), and every route's candidate with its validation fit and why
    it is not valid (``candidates``)."""
    from ..core.stepfit import model_step
    from ..identify.bode_readings import model_response
    page = {"kind": "broadband"}
    est = result.impulse
    if est is not None:
        series = {"integrated impulse response": est.step}
        for m in [m for m in (result.step_result.methods if result.step_result else []) if m.valid][:3]:
            series[f"{m.name} ({m.model})"] = model_step(m.model, m.params, est.t)
        page["plot"] = _trace(est.t, series, "time (s)")
    sp = result.spectrum
    if sp is not None and sp.f.size:
        gain = {"data": 20 * np.log10(np.abs(sp.h))}
        for m in [m for m in (result.freq_result.methods if result.freq_result else []) if m.valid][:3]:
            gain[f"{m.name} ({m.model})"] = 20 * np.log10(np.abs(model_response(m.model, m.params,
                                                                                2 * math.pi * sp.f)))
        page["plot" if "plot" not in page else "second"] = _trace(sp.f, gain, "frequency (Hz)", log_x=True)
    a = result.assessment
    view = getattr(a, "view", None)
    if view is not None:    # the record with its best models (an input only output error reads: the plot)
        series = {"recorded output": view.y, **{m.label: m.y for m in view.models}}
        record = {**_trace(view.t, series, "time (s)"), "validation_start_s": view.validation_start_s}
        page["plot" if "plot" not in page else "record"] = record
    if a is not None:
        from ..identify.report import ranked_candidates
        page["candidates"] = [{"route": c.route, "method": c.name, "model": c.kind, "valid": c.valid,
                               "fit_percent": c.fit_percent if math.isfinite(c.fit_percent) else None,
                               "note": c.note} for c in ranked_candidates(a)]
    return page


def _on_grid(x_data, y_data, grid) -> np.ndarray:
    """Measured points on a model's grid (uPlot shares one x): each point at its
    nearest grid frequency, gaps (NaN, sent as null) elsewhere."""
    out = np.full(len(grid), np.nan)
    idx = np.abs(np.log(grid)[:, None] - np.log(np.asarray(x_data, float))[None, :]).argmin(axis=0)
    out[idx] = y_data
    return out


# --------------------------------------------------------------------------- plant and PID

def plant_page(result) -> dict:
    """A plant design's page: step (SPICE, both analytic models, the tolerance
    band) and Bode (both models, SPICE's .ac points), schematic, BOM, bench.

    Parameters
    ----------
    result : PlantResult
        The Sallen-Key plant's design or analysis.

    Returns
    -------
    dict
        The page's JSON-ready content.
    """
    from ..core.lti import freq_response
    from ..filters.sallen_key_lowpass_parts import section_of
    from ..plant import report as rep
    from ..report.document import to_html
    from ..report.wiring import bench_rows
    a = result.test.amplitude_v
    amp = result.opamp.name
    step = {}
    if result.spice is not None:
        step["SPICE (ngspice)"] = result.spice.response
    step[f"analytic ({amp} model)"] = result.analytic_opamp.response
    step["analytic (ideal op-amp)"] = result.analytic.response
    tol = result.tolerance
    if tol.t_s is not None:   # the band on its own grid: onto the step's (uPlot shares one x)
        step["tolerance band low"] = np.interp(result.time_s, tol.t_s, tol.lo * a)
        step["tolerance band high"] = np.interp(result.time_s, tol.t_s, tol.hi * a)
    fn = result.built.fn_hz
    f = np.geomspace(fn / 100, fn * 100, BODE_POINTS)
    systems = {"ideal op-amp": result.analytic, f"{amp} model": result.analytic_opamp}
    resp = {k: freq_response(m.num, m.den, f) for k, m in systems.items()}
    sine = result.sine
    if sine is not None and sine.h_spice is not None:
        resp["SPICE .ac"] = _complex_on_grid(sine.spice_f_hz, sine.h_spice, f)
    bom = rep.bom(result)
    # the generator drives the section's input resistor, as its declaration names it (the sheet's settings table)
    bench = bench_rows(result.test, result.scope, section_of(result.built).designators[0])
    if result.sine is not None:   # as the sheet's settings table gives it
        bench.append([_("sine check"), rep.sine_text(result.sine)])
    return {"step": _trace(result.time_s, step, "time from the edge (s)"),
            "bode": _bode(f, resp), "histograms": histograms(result.monte_carlo),
            "schematic_svg": _schematic_svg(rep, result, (result.built.as_dict(), result.package)),
            **bom_shown(bom), "bench": [[localise(c) for c in row] for row in bench],
            "checks": checks_shown(result.checks),
            # the sheet's content (wiring, expected readings and their band, target and achieved, sensitivity,
            # alternatives) without its pictures: the page draws those itself
            "sheet_html": to_html(rep.title_of(result), rep.sections(result, with_images=False), {}),
            "title": rep.title_of(result)}


def checks_shown(checks) -> list:
    """The checks as the page shows them: id, title and detail in the current language, pass or fail.

    Parameters
    ----------
    checks : list of designer.core.checks.Check
        The result's checks.

    Returns
    -------
    list
        ``{"id", "title", "ok", "detail"}`` per check.
    """
    return [{"id": c.id, "title": _(c.title), "ok": bool(c.ok), "detail": localise(c.shown())} for c in checks]


def bom_shown(bom) -> dict:
    """A bill of materials for the page: its rows as bom.csv has them (English columns: programs read it) and as
    the page's language writes them (its columns, the packages' names, the numbers).

    Parameters
    ----------
    bom : list of list
        The rows (:data:`designer.report.wiring.BOM_HEADER`'s columns).

    Returns
    -------
    dict
        ``bom`` (``header``, ``rows``), ``bom_csv``, ``bom_header`` and ``bom_text`` (in the current language).
    """
    from ..report.wiring import BOM_HEADER, bom_csv
    return {"bom": {"header": list(BOM_HEADER), "rows": bom}, "bom_csv": bom_csv(bom),
            "bom_header": [_(h) for h in BOM_HEADER],
            "bom_text": [[localise(_(c)) if isinstance(c, str) and c else c for c in row] for row in bom]}


def pid_page(result) -> dict:
    """A loop's page: the closed-loop step (SPICE, the analytic loop, the ideal
    PID, the plant alone), the loop gain, the sensitivity peak Ms and its
    frequency (for either plant kind: the Sallen-Key plant's result JSON leaves
    them out, :class:`designer.pid.model.Margins`), the schematic and the build
    sheet without its pictures (verdict, BOM, settings, wiring, block checks).

    Parameters
    ----------
    result : PidResult
        The loop's design or analysis.

    Returns
    -------
    dict
        The page's JSON-ready content.
    """
    from ..report.document import to_html
    from ..pid import report as rep
    open_loop = result.model is None or not result.model.integrating
    w = result.waveforms
    curves = {}
    if result.spice is not None:
        curves["SPICE (ngspice)"] = result.spice.waves["y"]
    curves[f"realised loop, analytic ({result.opamp.name})"] = w.analytic["y"]
    curves["ideal PID, ideal plant"] = w.ideal_pid
    if open_loop:
        curves["plant alone (open loop)"] = w.open_loop
    return {"closed_loop": _trace(w.t, curves, "time from the edge (s)"),
            "loop_gain": _bode(np.asarray(w.bode_w) / (2 * math.pi), {"loop gain L(jw)": w.loop_gain}),
            "sensitivity": json_safe({"ms": result.margins.ms, "ms_hz": result.margins.ms_hz}),
            "schematic_svg": _schematic_svg(rep, result, None),
            "sheet_html": to_html(rep.title_of(result), rep.sections(result, with_images=False), {}),
            "histograms": histograms(getattr(result, "monte_carlo", None)),
            "title": rep.title_of(result)}


def filter_page(sheet, mc=None) -> dict:
    """A filter design's page, from its sheet (:class:`designer.filters.report.FilterSheet`) as the build sheet
    has it: the Bode plot of the chosen parts with the op-amp's model, the bench band of the builds and the mask
    (its forbidden edges: the largest loss over the passband, the least attenuation over the stopband), the
    stages with their op-amp checks, the schematic, the BOM, the part sets of ``--alternatives`` (the sheet's
    :attr:`~designer.filters.report.FilterSheet.alternatives`) and the sheet's content; ``mc`` a Monte Carlo
    against the mask (:class:`designer.tolerance.filter.FilterMonteCarlo`) for the histograms.

    Parameters
    ----------
    sheet : FilterSheet
        The filter design's sheet.
    mc : FilterMonteCarlo, optional
        The Monte Carlo against the mask.

    Returns
    -------
    dict
        The page's JSON-ready content.
    """
    from ..filters.registry import get as get_topology
    from ..report.document import to_html
    rep = filter_report
    r, bench = sheet.design, sheet.bench
    s = r.spec
    f = np.asarray(bench.f_hz, float)
    h = np.asarray(bench.h)
    gain = {f"chosen parts, {r.opamp.name} model": 20 * np.log10(np.abs(h)),
            "tolerance band low": bench.h_lo_db, "tolerance band high": bench.h_hi_db}
    if s.has_mask and s.filter_type != "bandpass":
        ref = 20 * math.log10(s.gain)
        low = s.filter_type == "lowpass"
        passing = f <= s.passband_hz if low else f >= s.passband_hz
        stopping = f >= s.stopband_hz if low else f <= s.stopband_hz
        gain["mask: largest passband loss"] = np.where(passing, ref - s.max_loss_db, np.nan)
        gain["mask: least stopband attenuation"] = np.where(stopping, ref - s.min_attenuation_db, np.nan)
    phase = {f"chosen parts, {r.opamp.name} model": np.degrees(np.unwrap(np.angle(h)))}
    stages = []
    for st, c in zip(r.stages, bench.checks):
        topo = get_topology(st.topology)
        parts = ", ".join(f"{topo.prefixed(ref, f'{st.number}0')} "
                          f"{format_eng(st.values[ref], 'Ohm' if ref.startswith('R') else 'F', 3)}"
                          for ref in topo.designators)
        stages.append({"stage": st.number, "topology": st.topology, "fn_hz": st.plan.fn_hz, "q": st.plan.q,
                       "gain": st.gain, "peak_gain_db": 20 * math.log10(st.peak_gain), "parts": parts,
                       "out_peak_v": c.out_peak_v, "swing_v": c.swing_v, "gbw_needed_hz": c.gbw_needed_hz,
                       "gbw_hz": c.gbw_hz, "slew_needed_v_per_s": c.slew_needed_v_per_s,
                       "slew_v_per_s": c.slew_v_per_s, "ok": c.ok})
    b = rep.build_board(r)
    bom = rep.bom(r, b)
    return json_safe({"bode": {"gain": _trace(f, gain, "frequency (Hz)", log_x=True),
                               "phase": _trace(f, phase, "frequency (Hz)", log_x=True)},
                      "stages": stages, "histograms": histograms(mc),
                      "alternatives": [dict(zip(("rank", "error_db", "limits", "parts"),
                                                (a.rank, a.error_db, *rep.alternative_words(a))))
                                        for a in sheet.alternatives],
                      "schematic_svg": rep.schematic(sheet).svg(),
                      **bom_shown(bom),
                      "sheet_html": to_html(rep.title_of(r), rep.sections(sheet, with_images=False), {}),
                      "title": rep.title_of(r)})


#: the last schematics drawn, by what they show: typing a new fc often lands on the same parts
_SCHEMATICS: dict = {}


def _schematic_svg(rep, result, key) -> str:
    """The wing's schematic of ``result`` as SVG; ``key`` (the parts and the package, with the op-amp and
    the language of its labels added here; None: not cached) names what it shows."""
    if key is None:
        return rep.schematic(result).svg()
    key = json.dumps([key, result.opamp.name, current()], sort_keys=True, default=str)
    svg = _SCHEMATICS.get(key)
    if svg is None:
        svg = rep.schematic(result).svg()
        if len(_SCHEMATICS) >= 64:
            _SCHEMATICS.pop(next(iter(_SCHEMATICS)))
        _SCHEMATICS[key] = svg
    return svg


def histograms(mc) -> list:
    """A Monte Carlo's histograms for the page, as the sheet draws them (:mod:`designer.report.tolerance`: the
    headline figure's, then each limited figure's; 2 sqrt(n) bins, 10 to 60): each figure's bin edges and counts,
    its nominal value and its limits; none without a Monte Carlo (or one build replayed).

    Parameters
    ----------
    mc : object or None
        The Monte Carlo result.

    Returns
    -------
    list of dict
        Per figure: ``figure`` (its id), ``title`` (in the current language), ``unit`` (its values'),
        ``edges``, ``counts``, ``nominal``, ``min``, ``max``, ``n``.
    """
    if mc is None or (hasattr(mc, "headline") and mc.headline is None):
        return []
    headline = getattr(mc, "headline", None)   # a filter's Monte Carlo has none: its limited figures alone
    out = []
    for name in dict.fromkeys([x for x in (headline, *(lim.figure for lim in mc.limits)) if x is not None]):
        v = np.asarray(mc.figures[name], float)
        v = v[np.isfinite(v)]
        if not v.size:
            continue
        k = int(np.clip(2 * math.sqrt(v.size), 10, 60)) if np.ptp(v) > 0 else 1
        counts, edges = np.histogram(v, bins=k)
        lim = next((lim for lim in mc.limits if lim.figure == name), None)
        title, unit = figure_shown(name)   # the page shows the title, the unit on the values (issue 29)
        out.append({"figure": name, "title": title, "unit": unit, "edges": _list(edges), "counts": [int(c) for c in counts],
                    "nominal": mc.nominal_figures.get(name), "min": None if lim is None else lim.min,
                    "max": None if lim is None else lim.max, "n": int(v.size)})
    return json_safe(out)


def _complex_on_grid(f_data, h_data, grid) -> np.ndarray:
    """SPICE's .ac points onto a model's grid (nearest frequency; NaN elsewhere)."""
    out = np.full(len(grid), np.nan + 0j)
    f_data = np.asarray(f_data, float)
    inside = (f_data >= grid[0]) & (f_data <= grid[-1])
    idx = np.abs(np.log(grid)[:, None] - np.log(f_data[inside])[None, :]).argmin(axis=0)
    out[idx] = np.asarray(h_data)[inside]
    return out


def _bode(f, responses: dict) -> dict:
    """Gain (dB) and phase (degrees, unwrapped) traces of complex responses on ``f``."""
    gain = {k: 20 * np.log10(np.abs(h)) for k, h in responses.items()}
    phase = {}
    for k, h in responses.items():
        ph = np.full(len(h), np.nan)
        ok = np.isfinite(h)
        ph[ok] = np.degrees(np.unwrap(np.angle(h[ok])))
        phase[k] = ph
    return {"gain": _trace(f, gain, "frequency (Hz)", log_x=True),
            "phase": _trace(f, phase, "frequency (Hz)", log_x=True)}


def _trace(x, series: dict, x_label: str, log_x: bool = False) -> dict:
    """One plot's data for the browser: ``x`` and each named series on it,
    decimated to :data:`TRACE_POINTS`, NaN as null; each series' ``label`` (English: the page tells the kinds
    of trace apart by it) and ``text`` (in the current language: what the page shows)."""
    from ..report.plots import decimate
    names = list(series)
    x, *ys = decimate(np.asarray(x, float), *[np.asarray(series[k], float) for k in names], n=TRACE_POINTS)
    return {"x": _list(x), "x_label": _(x_label), "log_x": log_x,
            "series": [{"label": k, "text": series_text(k), "y": _list(y)} for k, y in zip(names, ys)]}


#: the plots' axes and traces, as the catalogue has them (the traces' English names are written where they are
#: drawn; those naming an op-amp or a model are read back through these patterns)
#: the bill of materials' columns as the page shows them (bom.csv keeps its English columns: programs read it)
BOM_COLUMNS = (N_("Ref"), N_("Value"), N_("Code"), N_("Qty"), N_("Series"), N_("Tolerance"), N_("Package"),
               N_("Description"))
AXES = (N_("time from the edge (s)"), N_("frequency (Hz)"), N_("time since the step (s)"), N_("time (s)"))
TRACES = (N_("SPICE (ngspice)"), N_("analytic (ideal op-amp)"), N_("tolerance band low"), N_("tolerance band high"),
          N_("ideal op-amp"), N_("SPICE .ac"), N_("ideal PID, ideal plant"), N_("plant alone (open loop)"),
          N_("loop gain L(jw)"), N_("data"), N_("integrated impulse response"), N_("mask: largest passband loss"),
          N_("mask: least stopband attenuation"), N_("recorded output"))
_TRACE_PATTERNS = ((r"(?P<name>.+), validation fit (?P<fit>\S+) %", N_("{name}, validation fit {fit} %")),
                   (r"analytic \((?P<name>.+) model\)", N_("analytic ({name} model)")),
                   (r"chosen parts, (?P<name>.+) model", N_("chosen parts, {name} model")),
                   (r"realised loop, analytic \((?P<name>.+)\)", N_("realised loop, analytic ({name})")),
                   (r"(?P<name>\S+) model", N_("{name} model")))


def series_text(label: str) -> str:
    """A trace's name in the current language (a model's own name, ``ARX (FOPDT)``, as it is).

    Parameters
    ----------
    label : str
        The English name it is drawn under.

    Returns
    -------
    str
        The name to show.
    """
    import re
    for pattern, message in _TRACE_PATTERNS:
        m = re.fullmatch(pattern, label)
        if m:
            return _(message).format(**m.groupdict())
    return _(label)


def _list(a) -> list:
    return [None if not math.isfinite(v) else float(f"{v:.6g}") for v in np.asarray(a, float).tolist()]


# --------------------------------------------------------------------------- files

def bundle_zip(tmp: str, name: str) -> bytes:
    """The files design-plant (or design-pid) wrote under ``tmp``, as a zip in
    memory: ``reports/<name>/...`` and ``netlists/<name>.cir``.

    Parameters
    ----------
    tmp : str
        The run's folder.
    name : str
        The design's name.

    Returns
    -------
    bytes
        The zip file's content.
    """
    import zipfile
    buf = io.BytesIO()
    with zipfile.ZipFile(buf, "w", zipfile.ZIP_DEFLATED) as z:
        rep = os.path.join(tmp, "reports", name)
        for fname in sorted(os.listdir(rep)):
            z.writestr(f"reports/{name}/{fname}", _read(os.path.join(rep, fname)))
        z.writestr(f"netlists/{name}.cir", _read(os.path.join(tmp, "netlists", f"{name}.cir")))
    return buf.getvalue()


def files_in(folder: str) -> dict:
    """Every file under ``folder``: its path relative to it (``/``-separated) -> (size, modification time).

    Parameters
    ----------
    folder : str
        The folder.

    Returns
    -------
    dict
        Relative path -> (size in bytes, modification time in ns).
    """
    out = {}
    for base, _dirs, names in os.walk(folder):
        for name in names:
            path = os.path.join(base, name)
            st = os.stat(path)
            out[os.path.relpath(path, folder).replace(os.sep, "/")] = (st.st_size, st.st_mtime_ns)
    return out


def written_since(folder: str, before: dict) -> dict:
    """The files under ``folder`` made or changed since ``before`` (:func:`files_in`): relative path -> text
    (what check-design ``--update-golden`` recorded: the golden waveforms, CSV).

    Parameters
    ----------
    folder : str
        The folder.
    before : dict
        :func:`files_in` of the folder before the run.

    Returns
    -------
    dict
        Relative path -> text.
    """
    return {rel: _read(os.path.join(folder, *rel.split("/"))).decode("utf-8", "replace")
            for rel, stamp in sorted(files_in(folder).items()) if before.get(rel) != stamp}


def warm_up() -> None:
    """A worker's first task: one plant designed, simulated and drawn for the page, so that the
    first request finds ngspice loaded, every module imported and schemdraw's fonts measured."""
    design_plant_task({"fc": 3500, "zeta": 0.2}, "page")
