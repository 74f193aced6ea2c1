"""One corner of one spec, run and judged: the design (or the analysis of the
parts as built, or the user's deck) simulated with that corner's op-amp, its
figures (:mod:`.figures`) held to the spec's limits, the design's own checks,
the SPICE agreement, the tolerance band, the Monte Carlo yield and the golden waveforms, each as a
:class:`~designer.check.result.Case`. With an output folder (the spec's own:
``check-design`` stages it, and swaps it in whole when every corner is done)
the corner's build sheet and, for every failing golden signal, a plot of gold,
test and their normalised error are written there.

Errors become cases, never exceptions: a :class:`~designer.core.errors.SimulatorError`
an ERROR case of the simulator (exit 3), any other
:class:`~designer.core.errors.DesignError` (a deck ngspice cannot read, a
design the spec's numbers cannot give, a missing golden signal) an ERROR case
of the spec (exit 2).
"""

from __future__ import annotations

import time
from pathlib import Path

import numpy as np

from ..core.compare import nrms
from ..core.errors import DesignError, SimulatorError
from ..core.fileio import atomic_write
from ..core.i18n import N_, Message
from ..plant.circuit import DEFAULT_TOPOLOGY
from . import figures as F
from . import golden as G
from .result import ERROR, FAIL, PASS, SIM_ERROR, SKIP, SPEC_ERROR, Case, CornerOutcome
from .spec import CheckSpec

__all__ = ["corner_task", "run_corner"]


def run_corner(spec: CheckSpec, index: int, simulator: str, *, update_golden: bool = False,
               out_dir=None) -> CornerOutcome:
    """Run and judge corner ``index`` of ``spec`` (see the module docstring); ``out_dir``
    is the spec's own output folder (its files go there), None for none.

    Parameters
    ----------
    spec : CheckSpec
        The spec.
    index : int
        The corner's index in ``spec``.
    simulator : str
        The backend's name.
    update_golden : bool
        Record the golden waveforms instead of comparing with them.
    out_dir : path-like or None
        The spec's output folder.

    Returns
    -------
    CornerOutcome
        The corner's checks and what became of them.
    """
    from ..spice.simulate import tool_info
    corner = spec.corners[index]
    tick = time.perf_counter()
    tool = tool_info(simulator)
    try:
        ran = _simulate(spec, index, simulator)
        figures, res, design, waves = ran
        cases, warnings, files = _judge(spec, corner, figures, res, waves, tool, update_golden, out_dir)
        if spec.yield_spec is not None and res is not None:
            design = res.to_dict()   # with the yield's Monte Carlo (monte_carlo)
        if out_dir is not None and res is not None:
            files.update(_write_design(spec, corner, res, out_dir))
    except SimulatorError as exc:
        return _failed(corner, SIM_ERROR, exc, tool, tick)
    except DesignError as exc:
        return _failed(corner, SPEC_ERROR, exc, tool, tick)
    return CornerOutcome(corner, tuple(cases), design, tool, tuple(warnings), files, time.perf_counter() - tick)


def corner_task(spec: CheckSpec, index: int, simulator: str, update_golden: bool, out_dir, timeout: float):
    """:func:`run_corner` as a task of a Dask worker (``check-design --dask``): its ``ngspice -b``
    runs get the command's ``--timeout`` (a cluster cannot kill a running task).

    Parameters
    ----------
    spec : CheckSpec
        The spec.
    index : int
        The corner's index in ``spec``.
    simulator : str
        The backend's name.
    update_golden : bool
        Record the golden waveforms instead of comparing with them.
    out_dir : path-like or None
        The spec's output folder.
    timeout : float
        Seconds each ``ngspice -b`` run may take.

    Returns
    -------
    CornerOutcome
        As :func:`run_corner`.
    """
    from ..spice import simulate
    simulate.DEFAULT_TIMEOUT_S = float(timeout)
    return run_corner(spec, index, simulator, update_golden=update_golden, out_dir=out_dir)


def _failed(corner, kind, exc, tool, tick) -> CornerOutcome:
    what = N_("simulator error") if kind == SIM_ERROR else N_("bad spec")
    said = exc.args[0] if exc.args and isinstance(exc.args[0], Message) else " ".join(str(exc).split())
    # a typed message (one carrying a parameter) stays typed: each front end names the parameter its own way
    message = Message(N_("simulation: {what}: {error}"), what=what, error=said) if isinstance(said, Message) else \
        f"simulation: {what}: {said}"
    case = Case("simulation", corner, ERROR, message, error_kind=kind)
    return CornerOutcome(corner, (case,), None, tool, (), {}, time.perf_counter() - tick)


def _simulate(spec: CheckSpec, index: int, simulator: str):
    """(figures, typed result or None, the design's JSON, (t, {signal: samples}))."""
    design = spec.designs[index]
    if spec.kind == "netlist":
        from ..spice.simulate import get_simulator
        r = get_simulator(simulator).run(design)
        vectors = {k: np.real(v) for k, v in r.vectors.items() if k not in ("time", "frequency")}
        waves = (r.vectors["time"], vectors) if "time" in r.vectors else (None, {})
        return dict(r.measurements), None, {"measurements": r.measurements, "simulator": r.backend}, waves
    if spec.kind == "filter":
        from .filter_kind import run_filter
        res = run_filter(design, simulator)
        return res.figures, res, res.to_dict(), (None, {})
    if spec.kind == "plant" and hasattr(design, "topology") and design.topology != DEFAULT_TOPOLOGY:
        from ..plant.circuit_design import (analyze_circuit_spec, default_square_hz, design_circuit_plant,
                                            with_bench, with_square_test)
        res = (analyze_circuit_spec if spec.analyze else design_circuit_plant)(design, simulate=True,
                                                                                simulator=simulator)
        if res.square is None and (spec.agreement is not None or spec.golden is not None):
            # the SPICE agreement and the golden waveforms are the square-wave test's, as the Sallen-Key plant's;
            # the bench (test signal, scope, tolerance band) is then set for that test, as the seed plant's is for
            # its own, not for the square wave recommended before it ran
            with_square_test(res, design.amplitude_v, default_square_hz(res), simulator)
            with_bench(res, None, True, simulator)
        return F.circuit_plant_figures(res), res, res.to_dict(), (None, {}) if res.square is None else \
            res.square.waves()
    if spec.kind == "plant":
        from ..plant.design import analyze_plant, design_plant
        res = (analyze_plant if spec.analyze else design_plant)(design, simulate=True, simulator=simulator)
        cols = res.bench.columns()
        t = cols.pop("time_s")
        return F.plant_figures(res), res, res.to_dict(), (t, cols)
    from ..pid.design import analyze_pid, design_pid
    res = (analyze_pid if spec.analyze else design_pid)(design, simulate=True, simulator=simulator)
    waves = {f"{k}_v": v for k, v in res.spice.waves.items()}
    return F.pid_figures(res), res, res.to_dict(), (res.waveforms.t, waves)


def _judge(spec, corner, figures, res, waves, tool, update_golden, out_dir):
    cases = []
    for lim in spec.checks:
        value = figures.get(lim.figure)
        ok, text = lim.judge(value)
        status = (PASS if ok else FAIL) if lim.fail else SKIP
        cases.append(Case(lim.figure, corner, status, text if lim.fail else Message(N_("report only: {text}"), text=text),
                          _num(value), lim.text(), would_pass=None if lim.fail else ok))
    if spec.design_checks is not None:
        cases += _design_cases(spec, corner, res)
    if spec.agreement is not None:
        cases.append(_agreement_case(spec, corner, res, figures))
    if spec.tolerance:
        band = F.band_of(res)
        limits = {lim.figure: lim for lim in spec.checks}
        for fig in spec.tolerance:
            lo, hi = band[fig]
            lim = limits[fig]
            ok = lim.inside(lo, hi)
            span = N_("none") if lo is None else f"{lim.fmt(lo)} .. {lim.fmt(hi)}"
            said = N_("{id}: the part-tolerance band {span} is inside {limits}") if ok else \
                N_("{id}: the part-tolerance band {span} is outside {limits}")
            cases.append(Case(f"tolerance_{fig}", corner, PASS if ok else FAIL,
                              Message(said, id=f"tolerance_{fig}", span=span, limits=lim.text()), None, lim.text()))
    if spec.yield_spec is not None:
        cases.append(_yield_case(spec, corner, res, tool["simulator"]))
    warnings, files = [], {}
    if spec.golden is not None:
        g_cases, warnings, files = _golden_cases(spec, corner, waves, tool, update_golden, out_dir)
        cases += g_cases
    return cases, warnings, files


def _yield_case(spec, corner, res, simulator: str) -> Case:
    """The yield over the spec's checks (:func:`designer.tolerance.yields.spec_yield`, with the spec's
    engine; the SPICE engine on the backend ``simulator``); its Monte Carlo goes on the result (the
    corner's sheet and result.json show it)."""
    from ..tolerance.yields import spec_yield
    y = spec.yield_spec
    try:
        v = spec_yield(spec.kind, res, spec.checks, y.min, y.samples, y.seed, y.tolerances, y.sampler, y.dist,
                       y.engine, simulator)
    except DesignError as exc:   # a part the spec's tolerances name that this design has not, say
        raise DesignError(f"{spec.name}: yield: {str(exc).replace('--tol', 'tolerances:')}") from None
    res.monte_carlo = v.mc
    return Case("yield", corner, PASS if v.ok else FAIL, v.message(), v.fraction, f">= {100 * y.min:g} %")


def _num(value):
    return None if value is None else float(value)


def _design_cases(spec, corner, res) -> list:
    checks = {c.id: c for c in res.checks}
    wanted = list(checks) if spec.design_checks == "all" else spec.design_checks
    out = []
    for cid in wanted:
        c = checks.get(cid)
        if c is None:   # e.g. square_wave_period, reported only when the period is too short
            out.append(Case(cid, corner, PASS, Message(N_("{id}: not reported by this design (nothing to flag)"),
                                                       id=cid)))
        else:
            out.append(Case(cid, corner, PASS if c.ok else FAIL, Message(N_("{id}: {detail}"), id=cid,
                                                                         detail=_detail(c))))
    return out


def _detail(check):
    """A design check's detail as a typed message (its message and values, a list among them as its items),
    the text its English ``detail``; the detail itself when it has no message."""
    def value(v):
        if isinstance(v, tuple) and v[:1] == ("parts",):
            return Message.joined(v[1], [Message(m, **{k: value(x) for k, x in vals}) for m, vals in v[2]])
        return v
    if check.message is None:
        return check.detail
    typed = Message(check.message, **{k: value(v) for k, v in check.values})
    return typed if str(typed) == check.detail else check.detail


def _agreement_case(spec, corner, res, figures) -> Case:
    a = spec.agreement
    if a.against == "opamp_model":
        value = figures.get("nrms")
    elif spec.kind == "plant":
        value = figures.get("nrms_ideal")
    else:   # the loop with the ideal PID and plant, against SPICE's plant output, on the same grid
        s = res.spice
        value = nrms(res.waveforms.ideal_pid, s.waves["y"], s.nrms_abstol_v, t=res.waveforms.t)
    model = N_("op-amp-aware model") if a.against == "opamp_model" else N_("ideal model")
    if value is None or not np.isfinite(value):
        return Case("spice_agreement", corner, FAIL, Message(N_("spice_agreement: no nrms against the {model}"),
                                                             model=model), None, f"< {a.nrms_max:g}")
    ok = value < a.nrms_max
    said = N_("spice_agreement: nrms = {nrms} against the {model} below nrms_max {max}") if ok else \
        N_("spice_agreement: nrms = {nrms} against the {model} not below nrms_max {max}")
    return Case("spice_agreement", corner, PASS if ok else FAIL,
                Message(said, nrms=f"{value:.4g}", model=model, max=f"{a.nrms_max:g}"), float(value),
                f"< {a.nrms_max:g}")


def _golden_cases(spec, corner, waves, tool, update, out_dir):
    t, test = waves
    if t is None:
        raise DesignError(f"{spec.name}: golden: waveforms need a .tran analysis (the run has no time vector)")
    lower = spec.kind == "netlist"
    wanted = {(s.lower() if lower else s): tol for s, tol in spec.golden.signals.items()}
    missing = [s for s in wanted if s not in test]
    if missing:
        raise DesignError(f"{spec.name}: golden signal {missing[0]!r} is not in the run; it has: "
                          f"{', '.join(sorted(test))}")
    path = spec.golden.path(corner)
    header = G.header_of(tool, spec.name, corner)
    if update:
        G.write_golden(path, t, {s: test[s] for s in wanted}, header)
        return ([Case(f"golden_{s}", corner, PASS, Message(N_("golden_{signal}: recorded in {file} ({update_golden})"),
                                                            signal=s, file=path.name, update_golden="--update-golden"))
                 for s in wanted], [], {"golden": str(path)})
    recorded, t_gold, gold = G.read_golden(path)
    absent = [s for s in wanted if s not in gold]
    if absent:
        raise DesignError(G.record_advice(f"golden file {path}: no column {absent[0]!r}", switch="--update-golden"))
    warnings = G.version_warnings(recorded, header, path)
    errors = G.compare(t, test, t_gold, gold, wanted, path=path)
    cases, files = [], {"golden": str(path)}
    for sig, value in errors.items():
        reltol, abstol = wanted[sig]
        ok = bool(np.isfinite(value) and value < 1.0)
        said = N_("golden_{signal}: nrms = {nrms} below 1 (reltol {reltol}, abstol {abstol}, against {file})") if ok \
            else N_("golden_{signal}: nrms = {nrms} not below 1 (reltol {reltol}, abstol {abstol}, against {file})")
        cases.append(Case(f"golden_{sig}", corner, PASS if ok else FAIL,
                          Message(said, signal=sig, nrms=f"{value:.4g}", reltol=f"{reltol:g}", abstol=f"{abstol:g}",
                                  file=path.name), float(value), "< 1"))
        if not ok and out_dir is not None:
            png = G.error_plot(t, test[sig], t_gold, gold[sig], reltol, abstol,
                               f"{spec.classname(corner)} {sig}: nrms {value:.3g}")
            name = f"golden-{corner or spec.name}-{sig}.png"
            files[f"plot_{sig}"] = str(atomic_write(Path(out_dir) / name, png))
    return cases, warnings, files


def _write_design(spec, corner, res, out_dir) -> dict:
    """The corner's build sheet bundle in the spec's folder ``out_dir`` (reports/<corner>/, netlists/<corner>.cir)."""
    if spec.kind == "filter":
        if res.design is None:
            return {}   # as built: no design to draw a sheet from
        from ..filters.report import sheet_of
        from ..filters.report import write_outputs as write_filter
        files = write_filter(sheet_of(res.design), Path(out_dir), corner or spec.name)
        return {"build_sheet": files.get("build_sheet_md"), "design_result": files.get("result_json")}
    if spec.kind == "plant" and hasattr(res, "topology"):
        from ..plant.circuit_report import write_outputs
    elif spec.kind == "plant":
        from ..plant.report import write_outputs
    else:
        from ..pid.report import write_outputs
    files = write_outputs(res, Path(out_dir), corner or spec.name)
    return {"build_sheet": files.get("build_sheet_md"), "design_result": files.get("result_json")}
