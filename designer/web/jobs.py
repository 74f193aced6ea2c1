"""What a worker process does for one request of the web page: run the
command as its console script does, and hand back what the page shows.

A task names the command (``design-plant``, ``design-pid``, ``identify``,
``check-design`` ...) and its argument list, built by :mod:`.request` from the
request's option names. The command's own entry point runs it
(``design_plant_main(argv)``...: the same parser, the same checks, the same
one-line refusal and exit status), with stdout and stderr taken into strings;
this process runs one task at a time, so that is safe. Its ``--json`` output
is the answer's JSON, word for word. The typed result the command printed
(:data:`designer.cli.common.RESULT_HOOK`) gives the page what a terminal
cannot show: plot traces, the schematic as SVG, the bill of materials, the
build sheet.

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
import sys
import tempfile
from contextlib import contextmanager, redirect_stderr, redirect_stdout

import numpy as np

from ..cli import check as cli_check
from ..cli import identify as cli_identify
from ..cli import pid as cli_pid
from ..cli import plant as cli_plant
from ..cli.common import RESULT_HOOK, run_cli
from ..core import lifetime
from ..core.jsonio import json_safe

__all__ = ["BODE_POINTS", "LIBRARY", "MAINS", "TRACE_POINTS", "Superseded", "bundle_zip", "check_files",
           "design_plant_task", "files_in", "histograms", "identify_page", "pid_page", "plant_page", "run",
           "run_task", "temporaries_in", "warm_up", "written_since"]

#: points of a trace sent to the browser (uPlot draws thousands in a frame; the sheet's PNGs use fewer)
TRACE_POINTS = 1500
#: frequency points of a Bode trace
BODE_POINTS = 300

#: the commands a task may name, and their console entry points (called as functions: argv in, status out)
MAINS = {
    "design-plant": cli_plant.design_plant_main,
    "analyze-plant": cli_plant.analyze_plant_main,
    "design-pid": cli_pid.design_pid_main,
    "analyze-pid": cli_pid.analyze_pid_main,
    "check-design": cli_check.check_design_main,
}


class Superseded(BaseException):
    """The page typed on: the request under way is of inputs nobody will see (the pool's SIGUSR1, raised
    between two bytecodes of the run; a BaseException, so that no ``except Exception`` of the library keeps
    it). Whatever it runs unwinds: ``subprocess.run`` kills an ``ngspice -b`` it waits for, the
    ``with`` blocks close, and the worker takes the next request."""


#: whether a task is running in this process (a cancel that comes after it ended is ignored)
_RUNNING = False


def _cancel(signum, frame) -> None:
    if not _RUNNING:
        return
    if lifetime.in_native():   # inside ngspice's callbacks cffi would swallow it: again in 5 ms
        signal.signal(signal.SIGALRM, _cancel)
        signal.setitimer(signal.ITIMER_REAL, 0.005)
        return
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
        task itself: ``prog`` (a command), ``argv`` (its arguments, ``--json`` among them
        for the designing commands), ``want``: "page" (the JSON and the page's
        extras), "json", "sheet" (the printable build sheet), "bundle" (the
        design's files as a zip) or "check" (check-design's files); ``tmp``:
        the request's private folder (files written there), or None.

    Returns
    -------
    dict
        ``status`` (the command's exit status), ``error`` (its one line on
        stderr, or None), ``json`` (what ``--json`` printed), and per ``want``:
        ``page``, ``body`` (bytes) with ``media`` and ``filename``.
    """
    if "task_file" in task:   # the server's requests come as a file in their private folder (see .app)
        with open(task["task_file"], encoding="utf-8") as fh:
            task = json.load(fh)
    if task["prog"] == "warm-up":
        return warm_up()
    if "fields" in task:
        return LIBRARY[task["prog"]](task["fields"], task.get("want", "json"), task.get("tmp"))
    prog, argv, want, tmp = task["prog"], list(task["argv"]), task.get("want", "json"), task.get("tmp")
    seen = {}
    out, err = io.StringIO(), io.StringIO()
    token = RESULT_HOOK.set(lambda result, name: seen.update(result=result, name=name))
    before = files_in(os.path.join(tmp, "in")) if prog == "check-design" and tmp else {}
    argv0 = sys.argv
    sys.argv = [prog, *argv]   # the JSON's tool.argv: the command line this request stands for
    try:
        with redirect_stdout(out), redirect_stderr(err), temporaries_in(tmp):
            if prog in ("identify", "identify-freq"):
                status = _identify(prog, argv, seen)
            else:
                status = MAINS[prog](argv)
    finally:
        RESULT_HOOK.reset(token)
        sys.argv = argv0
    answer = {"status": status, "error": _error_line(err.getvalue(), status), "json": None,
              "stderr": err.getvalue()}
    if status not in (0, 1):
        return answer
    if prog in ("identify", "identify-freq"):
        answer["json"] = seen["json"]
        if want == "page":
            answer["page"] = identify_page(seen["result"])
        return answer
    if prog == "check-design":
        answer.update(check_files(tmp))
        answer["golden"] = written_since(os.path.join(tmp, "in"), before) if "--update-golden" in argv else {}
        answer["stdout"] = out.getvalue()
        return answer
    answer["json"] = json.loads(out.getvalue())
    result, name = seen["result"], seen["name"]
    if want == "page":
        answer["page"] = plant_page(result) if prog.endswith("plant") else pid_page(result)
    elif want == "sheet":
        answer.update(body=_read(os.path.join(tmp, "reports", name, "build-sheet.html")),
                      media="text/html; charset=utf-8", filename="build-sheet.html")
    elif want == "bundle":
        answer.update(body=bundle_zip(tmp, name), media="application/zip", filename=f"{name}.zip")
    return answer


@contextmanager
def temporaries_in(folder: str | None):
    """Every temporary file of the block (the simulator's ``designer-sim-*``, ``ngspice -b``'s own,
    through ``TMPDIR``) made in ``folder`` (the request's private folder; None: where they were), so
    that removing the folder removes them, a run killed at its deadline included."""
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


def _error_line(stderr: str, status: int) -> str | None:
    """The command's one-line refusal (its last line on stderr), or None when it did its work."""
    if status in (0, 1):
        return None
    lines = [ln for ln in stderr.splitlines() if ln.strip()]
    return lines[-1] if lines else f"failed with exit status {status}"


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
    from ..core.errors import DesignError, SimulatorError
    from ..plant.design import design_plant
    from ..plant.report import write_outputs
    from ..tolerance.mcspec import plant_tolerance
    from .forms import PLANT, page_message, plant_request
    prog = "design-plant"
    try:
        with temporaries_in(tmp):
            rq = plant_request(fields)
            result = design_plant(rq.spec, simulate=rq.simulate, simulator=rq.simulator)
            if rq.stimulus is not None:
                from ..plant.prbs import with_prbs
                result = with_prbs(result, result.test.amplitude_v, rq.stimulus[0], rq.stimulus[1], rq.simulate,
                                   rq.simulator)
            result = plant_tolerance(result, rq.monte_carlo, rq.worst_case, rq.tol, rq.simulator)
            if want in ("sheet", "bundle"):
                write_outputs(result, tmp, rq.name)
    except SimulatorError as exc:
        return {"status": 3, "error": f"{prog}: error: simulator error: {exc}", "json": None}
    except DesignError as exc:
        text, field = page_message(exc, PLANT)
        return {"status": 2, "error": f"{prog}: error: {text}", "json": None, "field": field,
                "label": PLANT[field].label if field else None}
    data = json.loads(json.dumps(result.to_dict()))
    data["tool"]["argv"] = rq.argv   # the command line this request stands for: a record, never parsed
    answer = {"status": 0, "error": None, "json": data}
    if want == "page":
        answer["page"] = plant_page(result)
    elif want == "sheet":
        answer.update(body=_read(os.path.join(tmp, "reports", rq.name, "build-sheet.html")),
                      media="text/html; charset=utf-8", filename="build-sheet.html")
    elif want == "bundle":
        answer.update(body=bundle_zip(tmp, rq.name), media="application/zip", filename=f"{rq.name}.zip")
    return answer


#: the commands the page runs through the library (no console script, no argv, no printed JSON)
LIBRARY = {"design-plant": design_plant_task}


# --------------------------------------------------------------------------- identify

def _identify(prog: str, argv: list, seen: dict) -> int:
    """``identify`` (or ``identify-freq``) as its console script runs it, the result kept:
    the CLI's parser and its own functions (a frequency table recognised and
    analysed as identify-freq does, as :func:`designer.cli.identify.identify_run`)."""
    ident = cli_identify

    def step_or_table(args):
        header = ident.frequency_table_header(args.capture)
        if header is None:
            result = ident.identify_capture(args)
            data = result.to_dict()
        else:
            result = ident.identify_frequency_table(args, header)
            data = {"format": ident.FREQUENCY_TABLE, **result.to_dict()}
        seen.update(result=result, json=json_safe(data))

    def table(args):
        result = ident.identify_table(args)
        seen.update(result=result, json=json_safe(result.to_dict()))

    if prog == "identify":
        return run_cli(prog, ident.build_parser, step_or_table, argv)
    return run_cli(prog, ident.build_freq_parser, table, argv)


def identify_page(result) -> dict:
    """The data with the best three valid models over them (a step capture: time
    since the step; a frequency table: gain and phase against frequency; a
    broadband capture, PRBS or noise: the step its impulse estimate integrates
    to, and its spectral estimate's gain, each with its own ranking's models)."""
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
    """A broadband identification's two views (as ``identify --plot`` draws them)."""
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
    band) and Bode (both models, SPICE's .ac points), schematic, BOM, bench."""
    from ..core.lti import freq_response
    from ..plant import report as rep
    from ..report.document import to_html
    from ..report.wiring import BOM_HEADER, bench_rows, bom_csv
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
    bench = bench_rows(result.test, result.scope, "R1")
    if result.sine is not None:   # as the sheet's settings table gives it
        bench.append(["sine check", rep.sine_text(result.sine)])
    return {"step": _trace(result.time_s, step, "time from the edge (s)"),
            "bode": _bode(f, resp), "histograms": histograms(result.monte_carlo),
            "schematic_svg": _schematic_svg(rep, result, (result.built.as_dict(), result.package)),
            "bom": {"header": list(BOM_HEADER), "rows": bom}, "bom_csv": bom_csv(bom),
            "bench": bench,
            # the sheet's content (wiring, expected readings and their band, target and achieved, sensitivity,
            # alternatives) without its pictures: the page draws those itself
            "sheet_html": to_html(rep.title_of(result), rep.sections(result, with_images=False), {}),
            "title": rep.title_of(result)}


def pid_page(result) -> dict:
    """A loop's page: the closed-loop step (SPICE, the analytic loop, the ideal
    PID, the plant alone), the loop gain, the schematic and the build sheet
    without its pictures (verdict, BOM, settings, wiring, block checks)."""
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
            "schematic_svg": _schematic_svg(rep, result, None),
            "sheet_html": to_html(rep.title_of(result), rep.sections(result, with_images=False), {}),
            "histograms": histograms(getattr(result, "monte_carlo", None)),
            "title": rep.title_of(result)}


#: the last schematics drawn, by what they show: typing a new fc often lands on the same parts
_SCHEMATICS: dict = {}


def _schematic_svg(rep, result, key) -> str:
    """The wing's schematic of ``result`` as SVG; ``key`` (the parts and the package, with the op-amp
    added here; None: not cached) names what it shows."""
    if key is None:
        return rep.schematic(result).svg()
    key = json.dumps([key, result.opamp.name], sort_keys=True, default=str)
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
    its nominal value and its limits; none without a Monte Carlo (or one build replayed)."""
    if mc is None or mc.headline is None:
        return []
    out = []
    for name in dict.fromkeys([mc.headline, *(lim.figure for lim in mc.limits)]):
        v = np.asarray(mc.figures[name], float)
        v = v[np.isfinite(v)]
        if not v.size:
            continue
        k = int(np.clip(2 * math.sqrt(v.size), 10, 60)) if np.ptp(v) > 0 else 1
        counts, edges = np.histogram(v, bins=k)
        lim = next((lim for lim in mc.limits if lim.figure == name), None)
        out.append({"figure": name, "edges": _list(edges), "counts": [int(c) for c in counts],
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
    decimated to :data:`TRACE_POINTS`, NaN as null."""
    from ..report.plots import decimate
    names = list(series)
    x, *ys = decimate(np.asarray(x, float), *[np.asarray(series[k], float) for k in names], n=TRACE_POINTS)
    return {"x": _list(x), "x_label": x_label, "log_x": log_x,
            "series": [{"label": k, "y": _list(y)} for k, y in zip(names, ys)]}


def _list(a) -> list:
    return [None if not math.isfinite(v) else float(f"{v:.6g}") for v in np.asarray(a, float).tolist()]


# --------------------------------------------------------------------------- files

def bundle_zip(tmp: str, name: str) -> bytes:
    """The files design-plant (or design-pid) wrote under ``tmp``, as a zip in
    memory: ``reports/<name>/...`` and ``netlists/<name>.cir``."""
    import zipfile
    buf = io.BytesIO()
    with zipfile.ZipFile(buf, "w", zipfile.ZIP_DEFLATED) as z:
        rep = os.path.join(tmp, "reports", name)
        for fname in sorted(os.listdir(rep)):
            z.writestr(f"reports/{name}/{fname}", _read(os.path.join(rep, fname)))
        z.writestr(f"netlists/{name}.cir", _read(os.path.join(tmp, "netlists", f"{name}.cir")))
    return buf.getvalue()


def check_files(tmp: str) -> dict:
    """check-design's files of one run in ``tmp``: the JUnit XML, the Markdown
    summary and each spec's result.json (as check-design writes them)."""
    out = os.path.join(tmp, "out")
    results = []
    if os.path.isdir(out):
        for name in sorted(os.listdir(out)):
            path = os.path.join(out, name, "result.json")
            if os.path.isfile(path):
                results.append(json.loads(_read(path)))
    junit = os.path.join(tmp, "junit.xml")
    summary = os.path.join(tmp, "summary.md")
    return {"json": {"specs": results},
            "junit": _read(junit).decode("utf-8") if os.path.isfile(junit) else None,
            "summary": _read(summary).decode("utf-8") if os.path.isfile(summary) else None}


def files_in(folder: str) -> dict:
    """Every file under ``folder``: its path relative to it (``/``-separated) -> (size, modification time)."""
    out = {}
    for base, _dirs, names in os.walk(folder):
        for name in names:
            path = os.path.join(base, name)
            st = os.stat(path)
            out[os.path.relpath(path, folder).replace(os.sep, "/")] = (st.st_size, st.st_mtime_ns)
    return out


def written_since(folder: str, before: dict) -> dict:
    """The files under ``folder`` made or changed since ``before`` (:func:`files_in`): relative path -> text
    (what check-design ``--update-golden`` recorded: the golden waveforms, CSV)."""
    return {rel: _read(os.path.join(folder, *rel.split("/"))).decode("utf-8", "replace")
            for rel, stamp in sorted(files_in(folder).items()) if before.get(rel) != stamp}


def warm_up() -> None:
    """A worker's first task: one plant designed, simulated and drawn for the page, so that the
    first request finds ngspice loaded, every module imported and schemdraw's fonts measured."""
    design_plant_task({"fc": 3500, "zeta": 0.2}, "page")
