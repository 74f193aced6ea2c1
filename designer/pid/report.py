"""The PID build sheet: the whole loop's schematic (seed 001, Figure 66 with
the plant of Figures 43-45) beside the bill of materials and the bench
settings, the pin-level wiring in the chosen packages, target vs achieved,
the checks, closed-loop figures (analytic, ideal PID, SPICE), the scope
settings and expected levels at every op-amp output (as the seed photographs
them, Figures 79-90), and the plots. Rendered as Markdown, self-contained
HTML and terminal text from one description (:mod:`designer.report`), plus
``bom.csv``; the part and net table is the deck's (:mod:`designer.pid.netlist`).

One sheet for every plant. A model plant's (G(s) = N(s)/D(s) e^(-theta s):
identified from a scope capture, typed, or a designed circuit read as its
model; issue 16) has the same controller, and its plant is not on the board
unless a circuit realises it: the schematic draws it as a block labelled with
its G(s) (:func:`designer.pid.schematic.draw_model_loop`) and the wiring table
says where its input, output and ground go. Then the model and where it came
from (its 95 % intervals, its input and output ranges, the model the rules
used), every rule side by side on it (gains, margins, Ms, IAE, overshoot),
target against achieved, the checks, the loop as built against the ideal PID
and SPICE, the worst case over the model's 95 % corners, and the scope
readings. Everything is read from the typed
:class:`~designer.pid.result.PidResult`: nothing is computed here."""

from __future__ import annotations

import math

import numpy as np

from ..core import eseries
from ..core.i18n import N_, language, translated
from ..core.i18n import gettext as _
from ..core.units import format_eng
from ..report import document as R
from ..report.bundle import draw_early as bundle_early, write_design
from ..report.plots import decimate, figure, loop_gain_plot, png_bytes, step_plot, time_unit
from ..report.tolerance import csv_texts, histogram_plots
from ..report.tolerance import section as tolerance_section
from ..report.tolerance import title as tolerance_title
from ..report.wiring import bench_rows, bom_csv, bom_rows, net_text, wiring_rows
from ..spice.deck import board
from .model import OPAMP_OUTPUTS
from .netlist import NET_LABELS, loop_netlist, plant_circuit, plant_ref_prefix
from .plant import PLANT_PREFIX
from .tuning import MODEL_NAMES

__all__ = ["MODEL_PLOTS", "PLOTS", "bom", "build_board", "draw_early", "plots", "plots_of", "schematic", "sections",
           "summary_text", "title_of", "write_outputs"]

#: what each block's output looks like on the scope for a square-wave reference
SHAPES = {
    "difference": N_("error y - r: a spike of -step at each rising edge that decays as the plant catches up "
                  "(seed Fig. 79/88)"),
    "inverter": N_("the error inverted: r - y (seed Fig. 81)"),
    "differentiator": N_("short spikes at the edges of the error, decaying with R12 C3 (seed Fig. 85)"),
    "integrator": N_("ramps while the error is large, then flattens at the level that holds the output "
                  "(seed Fig. 83)"),
    "summer": N_("the three actions added (and inverted): a kick at each edge, then a level (seed Fig. 86)"),
    "gain": N_("the controller output u = Kp (...): the summer's waveform times R3/R4 (seed Fig. 87)"),
    "plant": N_("the controlled output y (seed Fig. 89/90)"),
}
METRICS = (("overshoot_pct", N_("overshoot Mp"), lambda v: _("n/a") if v is None else f"{v:.4g} %"),
           ("peak_time_s", N_("peak time tp"), R.fmt_time),
           ("rise_time_s", N_("rise time tr (10-90 %)"), R.fmt_time),
           ("settling_time_s", N_("settling time ts (2 %)"), R.fmt_time),
           ("final_value", N_("final value"), lambda v: _("n/a") if v is None else f"{v:.4g} V"))


#: words the sheet shows from data (the loop table's booleans, the stages' names), for the catalogue
SHOWN_WORDS = (N_("True"), N_("False"), N_("difference"), N_("inverter"), N_("differentiator"), N_("integrator"),
               N_("summer"), N_("gain"),
               # where a model plant came from, as the library writes it (designer.core.process, pid.plant)
               N_("typed"), N_("parts"), N_("circuit"), N_("design-filter result"),
               # a model plant's kinds (designer.core.process)
               N_("rational"), N_("integrating"))


def title_of(result) -> str:
    """The sheet's title: the tuning, the gains, the plant and the op-amp.

    Parameters
    ----------
    result : designer.pid.result.PidResult
        The design, either kind of plant.

    Returns
    -------
    str
    """
    if result.model is not None:
        return _model_title_of(result)
    t = result.tuning
    return _("Op-amp PID ({method}: Kp {kp}, Ti {ti}, Td {td}) for the plant fn {fn} Hz, zeta {zeta}, "
             "with {opamp}").format(method=t.method, kp=f"{t.kp:.4g}", ti=format_eng(t.ti_s, 's'),
                                    td=format_eng(t.td_s, 's'), fn=f"{result.plant.fn_hz:.5g}",
                                    zeta=f"{result.plant.zeta:.3g}", opamp=result.opamp.name)


def _known(x):
    """None for a figure that is undefined (None, nan or inf), else the figure."""
    return None if x is None or (isinstance(x, float) and not math.isfinite(x)) else x


def _v(x, unit="V", digits=4):
    return _("n/a") if _known(x) is None else format_eng(x, unit, digits)


def verdict_text(result) -> str:
    if result.model is not None:
        return _model_verdict_text(result)
    return verdict_of(result.analytic.stable, result.analytic.figures, result.spice, result.checks)


def verdict_of(stable, figures, s, checks) -> str:
    """The verdict line: the analytic loop (``stable``, its step ``figures``), the
    SPICE run ``s`` (or None) and the failed ``checks``."""
    failed = [c.id for c in checks if not c.ok]
    parts = []
    if stable is False:
        parts.append(_("the analytic loop with the op-amp poles is UNSTABLE"))
    elif _known(figures.overshoot_pct) is not None:
        parts.append(_("analytic: {os} % overshoot, settles (2 %) in {ts}").format(
            os=f"{figures.overshoot_pct:.3g}", ts=_v(figures.settling_time_s, 's')))
    if s is not None:
        what = []
        if s.saturated:
            what.append(_("op-amps saturate"))
        if not s.stable:
            what.append(_("the loop oscillates or latches"))
        os_pct = _known(s.figures.overshoot_pct)
        if os_pct is not None and not what:
            what.append(_("{os} % overshoot, nrms {nrms}").format(os=f"{os_pct:.3g}", nrms=f"{s.nrms:.3g}")
                        if _known(s.nrms) is not None else _("{os} % overshoot").format(os=f"{os_pct:.3g}"))
        parts.append("SPICE: " + ", ".join(what))
    parts.append(_("all checks pass") if not failed else _("failed checks: ") + ", ".join(failed))
    return "; ".join(parts) + "."


def build_board(result):
    """The loop as built on the bench: its part and net table (the deck's) in the result's package
    (a model plant's: the controller, and a circuit plant's own sections when a circuit realises it).

    Parameters
    ----------
    result : designer.pid.result.PidResult
        The design, either kind of plant.

    Returns
    -------
    designer.spice.deck.Board
    """
    if result.model is not None:
        return _model_board(result)
    return board(loop_netlist(result.parts, result.plant), result.opamp, result.package)


def sections(result, with_images: bool = True, schematic_svg: str = "") -> list:
    """The build sheet as (heading, blocks) sections (:mod:`designer.report.document`).

    Parameters
    ----------
    result : designer.pid.result.PidResult
        The design, either kind of plant.
    with_images : bool
        Place the schematic and the plots (False: the terminal's text).
    schematic_svg : str
        The schematic drawn as SVG, inlined in the HTML sheet.

    Returns
    -------
    list
        (heading, blocks) pairs.
    """
    if result.model is not None:
        return _model_sections(result, with_images, schematic_svg)
    b = build_board(result)
    out = [(_("Verdict"), [R.text(verdict_text(result))] + [R.text(translated(n)) for n in result.notes])]
    out.append((_("Build"), _build_blocks(result, b, bom(result, b), with_images, schematic_svg)))
    out.append((_("Wiring"), _wiring_blocks(result, b)))
    if result.seed_bench is not None:
        out.append((_("The seed's bench: predicted against measured (001, V.13, Figures 88-90)"),
                    _seed_bench_blocks(result)))
    elif result.diff_amp is not None:
        out.append((_("Difference amplifier as built"), _diff_amp_blocks(result)))
    out.append((_("Tuning"), _tuning_blocks(result)))
    out.append((_("Target and achieved"), _achieved_blocks(result)))
    return out + _closing_sections(result, _loop_blocks(result, with_images), with_images,
                                   _scope_blocks(result, with_images, b))


def _closing_sections(result, loop_blocks, with_images, scope_blocks) -> list:
    """The sheet's last sections, the same for every plant: the checks, the closed loop
    (``loop_blocks``), the tolerance analysis when there is one, the scope readings (``scope_blocks``)."""
    out = [(_("Checks"), [R.table([_("check"), _("result"), _("detail")],
                                  [[c.id, _("ok") if c.ok else _("FAILED"), c.shown()] for c in result.checks])]),
           (_("Closed loop"), loop_blocks)]
    heading = tolerance_title(result, worst=True)
    if heading is not None:
        out.append((heading, tolerance_section(result, with_images, worst=True)))
    out.append((_("Expected scope readings"), scope_blocks))
    return out


def _build_blocks(result, b, rows, with_images, schematic_svg) -> list:
    """The schematic, the bill of materials ``rows`` and the bench settings."""
    first = [R.subhead(_("Bill of materials")),
             R.table([_("Ref"), _("Value"), _("Code"), _("Qty"), _("Series"), _("Tol.")], [r[:6] for r in rows],
                     "compact"),
             R.subhead(_("Generator and scope")), *_settings(result, b)]
    fig = [R.figure("schematic.png", schematic_svg, _("schematic of the loop"))] if with_images else []
    # the loop is wide: the schematic spans the page, the parts and the settings sit under it
    return fig + [R.columns(first[:2], first[2:])] if with_images else first


def _wiring_blocks(result, b, first_rows=(), after: str = "") -> list:
    """The packages and the pin-level wiring table of board ``b``; ``first_rows``
    (part, code, from, to) go before the board's rows, ``after`` closes the intro."""
    return [R.text(_("{part} in {pinout} packages: ").format(part=b.package.part, pinout=_(b.package.pinout))
                   + ", ".join(f"{u.designator} {_(a.role)}" for a, u in zip(b.netlist.amps, b.units))
                   + ". Kp = R5 R3/(R6 R4), Ti = R8 R14 C4/R6, Td = R6 R11 C3/R7." + after),
            R.table([_("part"), _("code"), _("from"), _("to")],
                    [*first_rows, *wiring_rows(b, NET_LABELS, (result.opamp.vcc, result.opamp.vee))])]


def controller_source(sel):
    """``source_of`` for :func:`designer.report.wiring.bom_rows` of the controller's
    parts chosen by ``sel`` (a :class:`~designer.pid.selection.Selection`, None for
    given parts): (series, tolerance %) by kind, None for the decoupling."""
    r_series, c_series = (sel.r_series, sel.c_series) if sel is not None else (_("as given"), _("as given"))
    rt, ct = sel.tolerances_pct if sel is not None else (None, None)

    def source(ref):
        if len(ref) == 4 and ref[0] == "C":     # decoupling
            return None
        return (r_series, rt) if ref[0] == "R" else (c_series, ct)
    return source


def bom(result, b=None) -> list:
    """The bill of materials rows (:data:`designer.report.wiring.BOM_HEADER`): the
    controller's parts from its series, the plant's from the plant's.

    Parameters
    ----------
    result : designer.pid.result.PidResult
        The design, either kind of plant.
    b : designer.spice.deck.Board, optional
        The board (default :func:`build_board` of ``result``).

    Returns
    -------
    list
        One row per value and kind.
    """
    if result.model is not None:
        return _model_bom(result, b)
    b = b or build_board(result)
    controller = controller_source(result.selection)
    prs, pcs = result.plant_series or (None, None)
    prt, pct = ((100 * eseries.TOLERANCE[prs], 100 * eseries.TOLERANCE[pcs]) if prs else (None, None))
    plant_refs = {p.ref for p in plant_circuit(result.plant)[0].netlist("u", "y").parts}

    def source(ref):
        if ref in plant_refs:
            return (prs or _("as given"), prt) if ref[0] == "R" else (pcs or _("as given"), pct)
        return controller(ref)
    return bom_rows(b, source, result.opamp.name)


def _settings(result, b) -> list:
    rows = bench_rows(result.test, result.scope, "R15 (r)", channels=2)
    return [R.table([_("set"), _("to")], rows, "compact"),
            R.text(_("Generator output in High-Z mode (in 50-ohm mode it shows half the amplitude it gives into "
                     "R15); check the level on CH1. Move CH2 to each TP in turn with its settings below."))]


def _tuning_blocks(result) -> list:
    tun = result.tuning
    blocks = [R.text(_("Method: {method}. Kp = {kp}, Ti = {ti}, Td = {td}.").format(
        method=tun.method, kp=f"{tun.kp:.4g}", ti=_v(tun.ti_s, 's'), td=_v(tun.td_s, 's')))]
    rc = tun.curve
    fit = None if rc is None else rc.fit
    if rc is not None:
        blocks.append(R.text(_(
            "Reaction curve of the plant as built: inflection at {t} (y = {y}), tangent slope {slope} /s, K = {k}, "
            "L = {l}, T = {tt} (the tangent reaches the final value at {t_final}; T is measured from L). ZN's rule "
            "uses this tangent.").format(t=_v(rc.t_inflection_s, 's'), y=f"{rc.y_inflection:.4g}",
                                         slope=f"{rc.slope_per_s:.5g}", k=f"{rc.K:.4g}", l=_v(rc.L_s, 's'),
                                         tt=_v(rc.T_s, 's'), t_final=_v(rc.t_tangent_final_s, 's'))))
    if fit is not None:
        how = ""
        if not fit.valid:
            how = " " + (_("The step overshoots {os} %, which no FOPDT model can follow: treat the rules below as "
                           "starting points.").format(os=f"{rc.overshoot_pct:.3g}") if rc.overshoot_pct > 2.0
                         else _("The fit is poor: {note}.").format(note=translated(fit.note)))
        blocks.append(R.text(
            _("Least-squares FOPDT K e^(-L s)/(T s + 1) of the same step (the model Cohen-Coon, CHR, AMIGO and "
              "SIMC were derived for): K = {k}, L = {l}, T = {t}").format(k=f"{fit.K:.4g}", l=_v(fit.L_s, 's'),
                                                                          t=_v(fit.T_s, 's'))
            + ("" if fit.rms_residual is None else _(", rms residual {rms}").format(rms=f"{fit.rms_residual:.3g}"))
            + "." + how))
    if result.rules:
        rows = [[r.method, _model_cell(r.model), f"{r.kp:.4g}", _v(r.ti_s, "s"), _v(r.td_s, "s")]
                for r in result.rules]
        blocks.append(R.table([_("rule"), _("model it uses (K, L, T)"), "Kp", "Ti", "Td"], rows))
    opt = result.optimizer
    if opt is not None:
        b = opt.best
        blocks.append(R.text(
            _("Optimiser: {message} ({n} evaluations); predicted overshoot {os}, settling {ts}, worst swing {swing} of "
              "the rails, worst slew delay {slew} of its budget").format(
                message=translated(opt.message), n=opt.evaluations, os=_fmt(b.overshoot_pct, '%'),
                ts=_v(b.settling_time_s, 's'), swing=_fmt(_pct(b.swing_ratio), '%'), slew=_fmt(_pct(b.slew_ratio), '%'))
            + ("" if b.stable else _(" (the best point found is an unstable loop)")) + "."))
    return blocks


def _diff_amp_blocks(result) -> list:
    d = result.diff_amp
    sw = d.swapped
    other = N_("feedback") if d.attenuated == "reference" else N_("reference")
    return [R.text(_(
        "U2 weighs the plant output y by g_y = (1 + R16/R15) R18/(R17 + R18) = {g_y} and the reference r by "
        "g_r = R16/R15 = {g_r}: it attenuates the {attenuated} input against the {other}. The loop gain is scaled by "
        "g_y ({db} dB against a balanced amplifier) and the integrator settles the loop where g_y y = g_r r: y = "
        "{ratio} r (the analytic DC gain). With R17 and R18 the other way round (the divider on the other side), "
        "g_y = {sw_g_y} ({sw_db} dB), phase margin {sw_pm} at {sw_fc}, {sw_stable}, y = {sw_ratio} r.").format(
            g_y=f"{d.g_y:.4g}", g_r=f"{d.g_r:.4g}", attenuated=_(d.attenuated), other=_(other),
            db=f"{d.loop_gain_db:+.3g}", ratio=f"{d.final_ratio:.4g}", sw_g_y=f"{sw['g_y']:.4g}",
            sw_db=f"{sw['loop_gain_db']:+.3g}", sw_pm=_fmt(sw['phase_margin_deg'], 'deg'),
            sw_fc=_v(sw['crossover_hz'], 'Hz'), sw_stable=_("stable") if sw['stable'] else _("unstable"),
            sw_ratio=f"{sw['final_ratio']:.4g}"))]


def _seed_bench_blocks(result) -> list:
    sb, d = result.seed_bench, result.diff_amp
    # the thesis's words are data (result.json keeps them in English): translated where they are shown
    th = {k: _(v) if isinstance(v, str) else v for k, v in sb.thesis.items()}
    sw = d.swapped
    a, s = result.analytic, result.spice
    amp = result.opamp.name

    def stable(ok):
        return _("stable") if ok else _("unstable")

    def ratio(r):
        return _("y = {ratio} r ({side})").format(ratio=f"{r:.3g}", side=_("larger") if r > 1 else _("smaller"))

    def spice(settles, saturated):
        return (_("settles") if settles else _("oscillates")) + (_(", saturated") if saturated else "")
    spice_txt = _("not simulated") if s is None else spice(False, s.saturated) if not s.stable else _("settles")
    rows = [[_("loop"), stable(th["stable"]),
             _("{verdict} (phase margin {pm}); SPICE {spice}").format(
                 verdict=_("stable") if a.stable else _("UNSTABLE"), pm=_fmt(result.margins.phase_margin_deg, "deg"),
                 spice=spice_txt),
             _("{verdict} (phase margin {pm})").format(verdict=stable(sw["stable"]),
                                                      pm=_fmt(sw["phase_margin_deg"], "deg"))],
            [_("output against the reference"), th["output_vs_reference"], ratio(d.final_ratio),
             ratio(sw["final_ratio"])],
            [_("loop gain against a balanced U2"), "", f"{d.loop_gain_db:+.3g} dB", f"{sw['loop_gain_db']:+.3g} dB"],
            [_("overshoot"), th["overshoot"], "", ""]]
    runs = [[_("{opamp}, {step} V step").format(opamp=k[0], step=f"{k[1]:g}"), stable(v[0]), _fmt(v[1], "deg"),
             spice(v[2], v[3]), _("{final} (expected {expected})").format(final=_v(v[4]), expected=_v(v[5]))]
            for k, v in sb.runs.items()]
    ok_small = [k for k, v in sb.runs.items() if v[2]]
    settled = (" (" + _("{runs} settles in SPICE").format(
        runs=", ".join(_("{step} V with {opamp}").format(step=f"{k[1]:g}", opamp=k[0]) for k in ok_small)) + ")"
               if ok_small else "")
    return [
        R.text(_("The thesis built this controller with {opamp} and trimmed U2 on the bench; it reports a stable loop "
                 "with the overshoot suppressed and the output larger than the reference. Its plant: {plant}. Its "
                 "scope: {scope}. Test amplitude: {amplitude}.").format(
                     opamp=th["opamp"], plant=th["plant"], scope=th["scope"], amplitude=th["amplitude"])),
        R.table(["", _("thesis measured"), _("predicted, parts as named here ({opamp})").format(opamp=amp),
                 _("predicted, divider on y (R17, R18 exchanged)")], rows),
        R.text(_("Why they disagree. (1) Which input is attenuated: read with this project's names (R17 from y, R18 "
                 "to ground) the trimmed values attenuate the REFERENCE (g_r = {g_r}, g_y = {g_y}): the loop gain "
                 "does not fall ({db} dB), the loop stays unstable, and it would settle at {ratio} r, below the "
                 "reference, against both of the thesis's observations. With the 9.98k/1.716k divider on the FEEDBACK "
                 "input instead (y through 9.98k, 1.716k to ground), y is attenuated to g_y = {sw_g_y}: the loop gain "
                 "falls by {sw_db} dB (Kp = {kp} acts as {kp_eff}), the crossover drops to {sw_fc}, and the loop "
                 "settles at y = {sw_ratio} r, larger than the reference as the thesis saw: the thesis's figures fit "
                 "this wiring, which its text does not name. (2) The op-amp model and (3) the test amplitude decide "
                 "the rest, as the runs below show: with that wiring the loop sits at the edge of stability, stable "
                 "only with the seed's faster LM741 figures, and then only for a step small enough that no stage "
                 "saturates or slews.").format(
                     g_r=f"{d.g_r:.3g}", g_y=f"{d.g_y:.3g}", db=f"{d.loop_gain_db:+.2g}", ratio=f"{d.final_ratio:.2g}",
                     sw_g_y=f"{sw['g_y']:.3g}", sw_db=f"{-sw['loop_gain_db']:.3g}", kp=f"{result.achieved.kp:.3g}",
                     kp_eff=f"{result.achieved.kp * sw['g_y']:.3g}", sw_fc=_v(sw["crossover_hz"], "Hz"),
                     sw_ratio=f"{sw['final_ratio']:.3g}")),
        R.table([_("divider on y, run"), _("analytic loop"), _("phase margin"), "SPICE", _("SPICE final value")], runs),
        R.text(_("So the bench result is reproduced only by the divider on the feedback input, an LM741 near the "
                 "seed's 1.5 MHz, and a small test amplitude{settled}; at the seed's 2 V the stages saturate and the "
                 "loop oscillates in SPICE.").format(settled=settled))]


def _achieved_blocks(result, target=None) -> list:
    """Target against achieved gains and the stages' corners; ``target`` has the
    targets' kp, ti_s, td_s (default ``result.tuning``)."""
    tun, ach = result.tuning if target is None else target, result.achieved
    err = ach.errors_pct
    rows = [["Kp", f"{tun.kp:.4g}", f"{ach.kp:.4g}", R.fmt_pct(err["kp"])],
            ["Ti", _v(tun.ti_s, "s"), _v(ach.ti_s, "s"), R.fmt_pct(err["ti"])],
            ["Td", _v(tun.td_s, "s"), _v(ach.td_s, "s"), R.fmt_pct(err["td"])],
            [_("integrator corner 1/(2 pi R13 C4)"), "", _v(ach.f_integrator_hz, "Hz"), ""],
            [_("derivative filter 1/(2 pi R12 C3)"), "", _v(ach.f_differentiator_hz, "Hz"), ""]]
    for stage, ng in ach.noise_gains.items():
        rows.append([_("{stage} stage: noise gain, bandwidth").format(stage=_(stage)), "", f"{ng:.3g}, "
                     f"{_v(ach.stage_bandwidths_hz[stage], 'Hz')}", ""])
    return [R.table(["", _("target"), _("achieved"), _("error")], rows)]


def _loop_blocks(result, with_images) -> list:
    a, i, s, amp = result.analytic, result.ideal_pid, result.spice, result.opamp
    rows = [[_(label), f(_known(getattr(i, key))), f(_known(getattr(a.figures, key))),
             f(_known(getattr(s.figures, key))) if s else _("not simulated")] for key, label, f in METRICS]
    rows.append([_("stable"), "", _(str(a.stable)), _(str(s.stable)) if s else ""])
    rows.append([_("saturated"), "", "", _(str(s.saturated)) if s else ""])
    blocks = [R.table(["", _("ideal PID + ideal plant"), _("realised (with {opamp})").format(opamp=amp.name), "SPICE"],
                      rows)]
    mg = result.margins
    blocks.append(R.text(
        _("Loop with the op-amp poles: phase margin {pm} at {fc}, gain margin {gm}. Closed-loop DC gain {dc} "
          "(steady-state error {sse}).").format(pm=_fmt(mg.phase_margin_deg, 'deg'), fc=_v(mg.crossover_hz, 'Hz'),
                                                 gm=_fmt(mg.gain_margin_db, 'dB'), dc=f"{a.dc_gain:.4g}",
                                                 sse=_fmt(a.steady_state_error_pct, '%'))))
    if s:
        blocks.append(R.text(_spice_agreement(result)))
    return blocks + _loop_images(with_images)


def _loop_images(with_images: bool) -> list:
    """The closed-loop step beside the loop gain (none without images)."""
    return [R.columns([R.image("closed-loop.png", _("closed-loop step and controller output"))],
                      [R.image("loop-bode.png", _("loop gain with its margins"))])] if with_images else []


def _spice_agreement(result) -> str:
    v, s = result.verdict, result.spice
    return (_("SPICE vs analytic: overshoot {os}, nrms {nrms} (below 1 is agreement); ").format(
        os=_fmt(v.overshoot_delta_pp, 'pp', signed=True), nrms=_fmt(s.nrms, ''))
            + (_("they agree.") if v.agree else
               (_("the difference is explained by the failed checks: ") + ", ".join(v.explained_by) + "."
                if v.explained_by else _("they disagree and no check explains it."))))


def _scope_blocks(result, with_images, b=None, levels=None) -> list:
    """The bench test and, per op-amp of board ``b``, its probe, CH2 setting and
    levels; ``levels``: role -> analytic levels (default ``result.analytic.levels``)."""
    test = result.test
    b = b or build_board(result)
    la = result.analytic.levels if levels is None else levels
    ls = {} if result.spice is None else result.spice.stages
    sc = result.scope
    vdiv = {} if sc is None else {c.node: c for c in sc.channels}
    rows = []
    for ref, role, sig in OPAMP_OUTPUTS:
        x, y = la.get(role), ls.get(role)
        if x is None and y is None:
            continue
        amp = next((a for a in b.netlist.amps if a.role == role), None)
        if amp is None:      # a PI has no differentiator
            continue
        unit = b.unit_of(amp.ref)
        rail = None if y is None else y.time_high_s + y.time_low_s if y.time_high_s is not None else 0
        ch = vdiv.get(sig)
        rows.append([_("{unit} pin {pin}").format(unit=unit.designator, pin=unit.pins['out']), _(role), sig,
                     "" if ch is None else _("{v}/div, 0 V {div} div down").format(
                         v=format_eng(ch.volts_per_div, 'V'), div=f"{ch.zero_div_below_centre:g}"),
                     _("n/a") + " .. " + _("n/a") if x is None else f"{_v(x.v_min)} .. {_v(x.v_max)}",
                     "" if y is None else f"{_v(y.v_min)} .. {_v(y.v_max)}",
                     "" if x is None else f"{x.slope_v_per_s / 1e6:.3g} V/us",
                     "" if rail is None else _v(rail, "s"), _(SHAPES[role])])
    blocks = [R.text(_("Bench test: square wave 0 -> {a} V at {f} Hz (edges {edge}); the output should settle near "
                       "{final} V. Probe each op-amp output against ground; levels cover the whole period (the "
                       "falling half mirrors the rising one).").format(
                           a=f"{test.amplitude_v:g}", f=f"{test.frequency_hz:g}", edge=_v(test.edge_s, 's'),
                           final=f"{result.expected_final_v:.4g}")),
              R.table([_("probe"), _("block"), _("node"), _("CH2 setting"), _("expected (analytic)"), "SPICE",
                       _("fastest slope"), _("at a rail (SPICE)"), _("what the scope shows")], rows)]
    if with_images:
        blocks.append(R.columns([R.image("blocks.png", _("every op-amp output"))],
                                [R.image("reaction-curve.png", _("plant reaction curve"))]))
    return blocks


def _model_cell(m) -> str:
    if m is None:
        return ""
    return (f"{_(MODEL_NAMES.get(m.source, m.source))}: {m.K:.4g}, {_v(m.L_s, 's')}, "
            f"{_v(m.T_s, 's')}")


def _pct(ratio):
    return None if ratio is None else 100 * ratio


def _fmt(v, unit, signed=False):
    if _known(v) is None:
        return _("n/a")
    return (f"{v:+.3g}" if signed else f"{v:.3g}") + (f" {unit}" if unit else "")


def summary_text(result, lang=None) -> str:
    """The sheet as terminal text, with the Monte Carlo's and the worst case's summary lines.

    Parameters
    ----------
    result : designer.pid.result.PidResult
        The design, either kind of plant.
    lang : str, optional
        The sheet's language (None: the current one, :mod:`designer.core.i18n`).

    Returns
    -------
    str
    """
    with language(lang):   # None: the current language (designer.core.i18n)
        text = R.to_text(title_of(result), sections(result, with_images=False))
    for extra in (result.monte_carlo, result.worst_case):
        if extra is not None:
            text += "\n" + "\n".join(extra.summary_lines()) + "\n"
    return text


# ---- plots -------------------------------------------------------------------

def plots(result) -> dict:
    """The sheet's plots, by file name (:func:`plots_of`): the closed-loop step (SPICE minus
    the analytic loop below it), every op-amp output, the loop gain with its margins,
    the reaction curve.

    Parameters
    ----------
    result : designer.pid.result.PidResult
        The design, either kind of plant.

    Returns
    -------
    dict
        File name -> PNG bytes.
    """
    return {name: draw(result) for name, draw in plots_of(result)}


def _closed_loop_plot(result, open_loop: bool = True) -> bytes:
    """The closed-loop step; ``open_loop``: the plant alone too (not for a ramp)."""
    w = result.waveforms
    a = w.analytic
    sp = None if result.spice is None else result.spice.waves
    amp = result.opamp.name
    curves = {}
    if sp is not None:
        curves["SPICE (ngspice)"] = sp["y"]
    curves[_("realised loop, analytic ({opamp})").format(opamp=amp)] = a["y"]
    curves[N_("ideal PID, ideal plant")] = w.ideal_pid
    if open_loop:
        curves[N_("plant alone (open loop)")] = w.open_loop
    resid = None if sp is None else (N_("residual: SPICE minus the analytic loop"), sp["y"], a["y"])
    return step_plot(w.t, curves, _("Closed-loop step, 0 -> {v} V").format(v=f"{result.test.amplitude_v:g}"),
                     residual=resid)


def _loop_gain_plot(result) -> bytes:
    w, mg = result.waveforms, result.margins
    return loop_gain_plot(w.bode_w / (2 * np.pi), w.loop_gain, _("Loop gain with {opamp} poles").format(
                              opamp=result.opamp.name),
                          mg.crossover_hz, mg.phase_margin_deg, mg.phase_crossover_hz, mg.gain_margin_db)


def _blocks_plot(result) -> bytes:
    w = result.waveforms
    scale, unit = time_unit(float(w.t[-1]))
    t = w.t * scale
    sp = None if result.spice is None else result.spice.waves
    amp = result.opamp
    sigs = [(ref, role, s) for ref, role, s in OPAMP_OUTPUTS if s in w.analytic]
    fig, axes = figure(7.5, 0.85 * len(sigs) + 0.6, len(sigs), 1, sharex=True)
    for ax, (ref, role, s) in zip(axes, sigs):
        ax.plot(*decimate(t, w.analytic[s]), "-", lw=1.2, label=_("analytic"))
        if sp is not None and s in sp:
            ax.plot(*decimate(t, sp[s]), "--", lw=1.2, label="SPICE")
        peak = max(np.nanmax(np.abs(w.analytic[s])),
                   np.nanmax(np.abs(sp[s])) if sp is not None and s in sp else 0.0)
        if not amp.ideal and peak > 0.5 * amp.vout_max:   # rails only when the signal gets near them
            for lvl in (amp.vout_max, amp.vout_min):
                ax.axhline(lvl, color="r", lw=0.6, alpha=0.5)
        # an unstable analytic loop runs away: keep the axis on what a scope shows
        lim = 1.15 * max(abs(amp.vcc), abs(amp.vee))
        if np.nanmax(np.abs(w.analytic[s])) > lim:
            ax.set_ylim(-lim, lim)
        ax.set_ylabel(f"{ref} {s}", fontsize=8)
        ax.grid(True, alpha=0.3)
    axes[0].legend(fontsize=7, loc="upper right")
    axes[0].set_title(_("Every op-amp output (red: output limits, drawn when reached)"))
    axes[-1].set_xlabel(f"{_('time after the step')} ({unit})")
    return png_bytes(fig, dpi=90, tight=False)


def _reaction_plot(result) -> bytes:
    w = result.waveforms
    tp, yp = w.reaction_t, w.reaction_y
    c = result.tuning.curve
    fig, ax = figure(7.5, 3.6)
    ax.plot(*decimate(tp * 1e6, yp), label=_("plant step response"))
    if c is not None:
        tt = np.linspace(c.L_s, c.t_tangent_final_s, 50)
        ax.plot(tt * 1e6, c.slope_per_s * (tt - c.t_inflection_s) + c.y_inflection, "--", label=_("tangent"))
        ax.plot([c.t_inflection_s * 1e6], [c.y_inflection], "o", label=_("inflection"))
        ax.axhline(c.K, color="k", lw=0.6)
        if w.fopdt_y is not None:
            ax.plot(*decimate(tp * 1e6, w.fopdt_y), ":", label=_("least-squares FOPDT"))
        ax.set_xlim(0, min(tp[-1], 6 * c.t_tangent_final_s) * 1e6)
        ax.set_title(_("Reaction curve: L = {l}, T = {t}").format(l=format_eng(c.L_s, 's'), t=format_eng(c.T_s, 's')))
    ax.set_xlabel(_("time (us)"))
    ax.set_ylabel(_("output per volt of step"))
    ax.grid(True, alpha=0.3)
    ax.legend()
    return png_bytes(fig, dpi=90, tight=False)


def schematic(result):
    """The loop's schematic (:mod:`designer.pid.schematic`) as a drawing: a model plant a
    block labelled with its G(s), a circuit plant its own sections.

    Parameters
    ----------
    result : designer.pid.result.PidResult
        The design, either kind of plant.

    Returns
    -------
    designer.report.schematic.Sheet
    """
    if result.model is not None:
        return _model_schematic(result)
    from .schematic import draw_loop
    return draw_loop(build_board(result), result.opamp, plant_prefix=plant_ref_prefix(result.plant))


#: the sheet's plots: (file name, drawing function of the result)
PLOTS = (("closed-loop.png", _closed_loop_plot), ("blocks.png", _blocks_plot),
         ("loop-bode.png", _loop_gain_plot), ("reaction-curve.png", _reaction_plot))


def plots_of(result) -> tuple:
    """The (file name, drawing function) pairs of ``result``'s sheet: :data:`PLOTS`, or
    :data:`MODEL_PLOTS` for a model plant.

    Parameters
    ----------
    result : designer.pid.result.PidResult
        The design, either kind of plant.

    Returns
    -------
    tuple
    """
    return MODEL_PLOTS if result.model is not None else PLOTS


def write_outputs(result, out_dir, name: str, lang=None, early=None) -> dict:
    """``netlists/<name>.cir`` and ``reports/<name>/`` (build sheet, result.json,
    plots, schematic, bom.csv, and the Monte Carlo's files) under ``out_dir``, each written
    atomically; the sheet in ``lang`` (None: the current language, :mod:`designer.core.i18n`);
    the pictures ``early`` (:func:`draw_early`) started are not drawn again.

    Parameters
    ----------
    result : designer.pid.result.PidResult
        The design, either kind of plant.
    out_dir : str or Path
        Where ``netlists/`` and ``reports/`` go.
    name : str
        The bundle's name.
    lang : str, optional
        The sheet's language.
    early : object, optional
        What :func:`draw_early` returned.

    Returns
    -------
    dict
        What was written, by kind (the result's ``files``).
    """
    with language(lang):
        return write_design(result, out_dir, name, plots_of(result) + histogram_plots(result), schematic,
                            lambda svg: sections(result, schematic_svg=svg), title_of(result),
                            {"bom_csv": ("bom.csv", lambda r: bom_csv(bom(r))), **csv_texts(result)}, early)


# ==== a model plant's sheet =========================================================

#: the rule table's columns
RULE_HEADER = (N_("rule"), "Kp", "Ti", "Td", N_("phase margin"), N_("gain margin"), N_("delay margin"), "Ms",
               N_("crossover"), "IAE", N_("overshoot"), N_("SPICE overshoot"), N_("note"))


def _model_title_of(result) -> str:
    return _("Op-amp PID ({method}: Kp {kp}, Ti {ti}, Td {td}) for the model plant {model}, with {opamp}").format(
        method=result.method, kp=f"{result.kp:.4g}", ti=format_eng(result.ti_s, 's'), td=format_eng(result.td_s, 's'),
        model=result.model.text(), opamp=result.opamp.name)


def _dash(v, unit: str = "", digits: int = 4) -> str:
    """A figure with its unit: "-" when absent, "inf" when infinite, "n/a" when undefined."""
    if v is None:
        return "-"
    if isinstance(v, float) and not math.isfinite(v):
        return "n/a" if math.isnan(v) else ("inf" if v > 0 else "-inf")
    if unit in ("s", "Hz", "V s"):
        return format_eng(v, unit, digits)
    return f"{v:.3g}" + (f" {unit}" if unit else "")


def _model_verdict_text(result) -> str:
    return verdict_of(result.stable, result.analytic.figures, result.spice, result.checks)


def _model_board(result):
    """The loop as built on the bench: the controller's part and net table
    (the plant off the board), or with a circuit plant's own sections on it
    (:func:`~designer.pid.design.loop_netlist_of`), in the result's package."""
    from .design import loop_netlist_of
    return board(loop_netlist_of(result.spec, result.parts), result.opamp, result.package)


def _model_bom(result, b=None) -> list:
    """The bill of materials rows (:data:`designer.report.wiring.BOM_HEADER`): the
    controller's parts from its series, the decoupling, the op-amps."""
    b = b or _model_board(result)
    return bom_rows(b, controller_source(result.selection), result.opamp.name)


def _shown_elsewhere(result) -> set:
    """The notes the Tuning section prints (the rule's and the optimiser's)."""
    out = set(result.rule.notes) if result.rule is not None else set()
    if result.optimizer is not None:
        out.add(result.optimizer.message)
    return out


def _model_sections(result, with_images: bool = True, schematic_svg: str = "") -> list:
    """The build sheet as (heading, blocks) sections (:mod:`designer.report.document`)."""
    b = _model_board(result)
    elsewhere = _shown_elsewhere(result)
    out = [(_("Verdict"), [R.text(_model_verdict_text(result))]
            + [R.text(translated(n)) for n in result.notes if n not in elsewhere])]
    out.append((_("Build"), _build_blocks(result, b, _model_bom(result, b), with_images, schematic_svg)))
    circuit = getattr(result.spec, "circuit", None)
    if circuit is not None:   # the plant's own sections are on the board, wired as the rest
        out.append((_("Wiring"), _wiring_blocks(result, b, (), " " + _(
            "The plant's sections are on this board (their parts prefixed {prefix}: RP1, CP1, op-amp UP).").format(
                prefix=PLANT_PREFIX))))
    else:
        out.append((_("Wiring"), _wiring_blocks(
            result, b, plant_rows(b),
            " " + _("The plant is not on this board: its input takes u, its output y goes to R17 and to CH2, and its "
                    "ground joins the common ground (the first rows)."))))
    out.append((_("The plant"), _plant_blocks(result)))
    out.append((_("Tuning"), _model_tuning_blocks(result)))
    out.append((_("Target and achieved"), _achieved_blocks(result, result) + [R.text(_(
        "The integrator leak (R13) and the derivative filter (R12) are placed from fc = {fc}, the crossover of the "
        "ideal PID around the model (near fc/100 and 10 fc unless set).").format(fc=_v(result.fc_ref_hz, 'Hz')))]))
    return out + _closing_sections(result, _model_loop_blocks(result, with_images), with_images,
                                   _scope(result, with_images, b))


def plant_rows(b) -> list:
    """Wiring rows (part, code, from, to) of the plant, which is off the board."""
    r17 = b.netlist.part("R17")
    return [[_("plant in"), "", net_text(b, "u", NET_LABELS), _("the plant's input")],
            [_("plant out"), "", _("the plant's output y"),
             _("R17 (to {net}) and scope CH2").format(net=net_text(b, r17.b, NET_LABELS))],
            [_("plant ground"), "", _("the plant's ground (its input's and output's reference)"),
             _("ground (the star point)")]]


# ---- the plant ------------------------------------------------------------------

def _param(kind: str, key: str, v) -> str:
    """A model parameter with its unit (K of an integrating plant is per second)."""
    if key.endswith("_s"):
        return format_eng(v, "s")
    if key.endswith("_hz"):
        return format_eng(v, "Hz")
    if key == "K" and kind == "integrating":
        return format_eng(v, "/s")
    return f"{v:.4g}"


def _param_name(key: str) -> str:
    return key.rsplit("_", 1)[0] if key.endswith(("_s", "_hz")) else key


def _plant_blocks(result) -> list:
    m, spec = result.model, result.spec
    blocks = [R.text(_("{model} ({kind}); the controller's output u is its input, its output y is fed back.").format(
                  model=m.text(), kind=_(m.kind))),
              R.text(_("Where it came from: {source}.").format(source=translated(m.source)))]
    plant = getattr(spec, "circuit", None)
    if plant is not None:
        c = plant.circuit
        stages = "; ".join(f"{_(st['title'])}: " + ", ".join(f"{k} {format_eng(v, 'Ohm' if k[0] == 'R' else 'F')}"
                                                           for k, v in st["parts"].items())
                           for st in c.to_dict()["stages"])
        blocks.append(R.text(_("The plant is a circuit ({topology}), built on the board and simulated as built: "
                               "{stages}. Its own transfer function is {model}").format(
                                   topology=c.topology, stages=stages, model=plant.model.text())
                             + (_("; it inverts, so the controller's action is reversed (r and y exchanged at the "
                                  "difference amplifier) and the gains are chosen for -G(s), the model above.")
                                if plant.reversed_action else ".")))
    if m.ci95:
        rows = [[_param_name(k), _param(m.kind, k, v),
                 _("not given") if not m.ci95.get(k) else "+/- " + _param(m.kind, k, m.ci95[k]),
                 "" if not m.ci95.get(k) else f"{_param(m.kind, k, v - m.ci95[k])} .. "
                                              f"{_param(m.kind, k, v + m.ci95[k])}"]
                for k, v in m.params.items()]
        blocks += [R.text(_("Its 95 % intervals (the loop is checked at every corner of this box: Closed loop):")),
                   R.table([_("parameter"), _("value"), _("95 % half-width"), _("interval")], rows, "compact")]
    else:
        blocks.append(R.text(_("No 95 % intervals were given: the loop is checked on the nominal model only.")))
    ranges = []
    for rng, what in ((spec.plant.plant_input, N_("accepts u from {lo} to {hi}")),
                      (spec.plant.plant_output, N_("delivers y from {lo} to {hi}"))):
        if rng is not None:
            ranges.append(_(what).format(lo=format_eng(rng[0], 'V'), hi=format_eng(rng[1], 'V')))
    blocks.append(R.text(_("The plant {ranges} (checked over the square wave).").format(ranges=_(" and ").join(ranges))
                         if ranges else
                         _("Its input and output ranges were not given: only the op-amps' swing is checked.")))
    blocks.append(R.text(_("The rules see it as {model} (each rule's own model: Tuning).").format(
        model=translated(result.reduced.describe()))))
    return blocks


# ---- tuning ----------------------------------------------------------------------

def _model_tuning_blocks(result) -> list:
    pi = not result.parts.has_derivative
    blocks = [R.text(_("Method: {method}. Kp = {kp}, Ti = {ti}, Td = {td}, in the ideal parallel form "
                       "Kp (1 + 1/(Ti s) + Td s)").format(method=result.method, kp=f"{result.kp:.4g}",
                                                          ti=_v(result.ti_s, 's'), td=_v(result.td_s, 's'))
                     + (_(": a PI (the differentiator, its R7, R11, R12 and C3 are left out).") if pi else "."))]
    rt = result.rule
    if rt is not None:
        used = rt.model_used
        blocks.append(R.text(_("{rule} on {model}").format(rule=rt.rule, model=translated(used.describe()))
                             + (": " + "; ".join(translated(st) for st in used.steps) if used.steps else "") + "."))
        blocks += [R.text(translated(f)) for f in rt.formulas]
        if rt.series is not None and rt.series[2] > 0:
            kc, ti, td = rt.series
            blocks.append(R.text(_("Series form Kc (1 + 1/(tauI s))(1 + tauD s): Kc = {kc}, tauI = {ti}, "
                                   "tauD = {td}; {conversion}.").format(kc=f"{kc:.4g}", ti=_v(ti, 's'), td=_v(td, 's'),
                                                                        conversion=translated(rt.conversion))))
        blocks += [R.text(translated(n)) for n in rt.notes]
    opt = result.optimizer
    if opt is not None:
        blocks.append(R.text(
            _("Optimiser (started from {rule}): {message}; predicted overshoot {os}").format(
                rule=opt.start_rule, message=translated(opt.message), os=_dash(opt.overshoot_pct, '%'))
            + ("" if opt.met else _("; the limits are NOT all met"))
            + (_(", limits held at every 95 % corner") if opt.robust else "") + "."))
    pm, gm, ms = result.limits
    blocks.append(R.text(_(
        "Every rule on this model, each loop as it would be built (its gains, the op-amp poles, leak and filter, "
        "the exact dead time), for a {step} step; the limits are phase margin >= {pm} deg, gain margin >= {gm} dB, "
        "Ms <= {ms}.").format(step=format_eng(result.spec.step_v, 'V'), pm=f"{pm:g}", gm=f"{gm:g}", ms=f"{ms:g}")))
    blocks.append(R.table([_(h) for h in RULE_HEADER], [_rule_row(result, r) for r in result.rules]))
    return blocks


def _rule_row(result, r) -> list:
    t, f = r.tuning, r.figures
    if t is None:
        return [r.rule] + ["-"] * 11 + [_("does not apply: {reason}").format(reason=translated(r.reason))]
    gains = [f"{t.kp:.4g}", _v(t.ti_s, "s"), _v(t.td_s, "s")]
    note = translated(r.reason) if r.reason else ""
    if r.rule == result.method:
        note = _("built") + (f"; {note}" if note else "")
    if f is None:
        return [r.rule, *gains] + ["-"] * 8 + [note]
    m, st = f.margins, f.step
    if not m.stable:
        note = _("unstable loop") + (f"; {note}" if note else "")
    return [r.rule, *gains, _dash(m.phase_margin_deg, "deg"), _dash(m.gain_margin_db, "dB"),
            _dash(m.delay_margin_s, "s"), _dash(m.ms), _dash(m.crossover_hz, "Hz"),
            "-" if st is None else _dash(st.iae, "V s"), "-" if st is None else _dash(st.overshoot_pct, "%"),
            _dash(r.spice_overshoot_pct, "%"), note]


# ---- closed loop -----------------------------------------------------------------

def _margin_rows(ideal, built) -> list:
    rows = []
    for key, label, unit in (("phase_margin_deg", N_("phase margin"), "deg"),
                             ("crossover_hz", N_("gain crossover"), "Hz"), ("gain_margin_db", N_("gain margin"), "dB"),
                             ("delay_margin_s", N_("delay margin"), "s"), ("ms", N_("Ms (max sensitivity)"), "")):
        rows.append([_(label), _dash(getattr(ideal, key), unit), _dash(getattr(built, key), unit), "-"])
    return rows


def _model_loop_blocks(result, with_images) -> list:
    a, s, amp, mg = result.analytic.figures, result.spice, result.opamp, result.margins
    rows = _margin_rows(result.ideal_margins, mg)
    i = result.ideal_pid
    rows += [[_(label), f(_known(getattr(i, key))) if i is not None else "-", f(_known(getattr(a, key))),
              f(_known(getattr(s.figures, key))) if s else _("not simulated")] for key, label, f in METRICS]
    rows.append([_("stable"), _(str(result.ideal_margins.stable)), _(str(result.stable)),
                 _(str(s.stable)) if s else ""])
    rows.append([_("saturated"), "", "", _(str(s.saturated)) if s else ""])
    pm, gm, ms = result.limits
    blocks = [R.table(["", _("ideal PID around the model"), _("realised (with {opamp})").format(opamp=amp.name),
                       "SPICE"], rows),
              R.text(_("The loop as built (op-amp poles, integrator leak, derivative filter, exact dead time): phase "
                       "margin {pm} at {fc}, gain margin {gm} at {f180}, delay margin {dm}, Ms {ms} at {ms_hz} (limits: "
                       "{pm_min} deg, {gm_min} dB, Ms {ms_max}). Closed-loop DC gain {dc}; the step figures are for "
                       "the rising edge of the bench test.").format(
                  pm=_dash(mg.phase_margin_deg, 'deg'), fc=_dash(mg.crossover_hz, 'Hz'), gm=_dash(mg.gain_margin_db, 'dB'),
                  f180=_dash(mg.phase_crossover_hz, 'Hz'), dm=_dash(mg.delay_margin_s, 's'), ms=_dash(mg.ms),
                  ms_hz=_dash(mg.ms_hz, 'Hz'), pm_min=f"{pm:g}", gm_min=f"{gm:g}", ms_max=f"{ms:g}",
                  dc=f"{result.dc_gain:.4g}"))]
    if s:
        blocks.append(R.text(_spice_agreement(result)))
    if result.robust is not None:
        blocks += _robust_blocks(result.robust)
    return blocks + _loop_images(with_images)


def _robust_blocks(rb) -> list:
    pm_at, pm = rb.worst("phase_margin_deg")
    gm_at, gm = rb.worst("gain_margin_db")
    ms_at, ms = rb.worst("ms", -1.0)
    os_at, os_ = rb.worst("overshoot_pct", -1.0)
    n = len(rb.corners)
    head = (_("Worst case over the {n} corners of the model's 95 % intervals (the loop as built at each): ").format(n=n)
            + (_("stable at every corner; phase margin {pm} at {pm_at}, gain margin {gm} at {gm_at}, Ms {ms} at "
                 "{ms_at}, overshoot {os} at {os_at} (limits: {pm_min} deg, {gm_min} dB, Ms {ms_max}).").format(
                   pm=_dash(pm, 'deg'), pm_at=pm_at, gm=_dash(gm, 'dB'), gm_at=gm_at, ms=_dash(ms), ms_at=ms_at,
                   os=_dash(os_, '%'), os_at=os_at, pm_min=f"{rb.min_phase_margin_deg:g}",
                   gm_min=f"{rb.min_gain_margin_db:g}", ms_max=f"{rb.max_ms:g}")
               if rb.all_stable else _("UNSTABLE at the corner {corner}.").format(corner=pm_at)))
    rows = []
    for label, f in rb.corners:
        m, st = f.margins, f.step
        rows.append([label, _("yes") if m.stable else _("NO"), _dash(m.phase_margin_deg, "deg"),
                     _dash(m.gain_margin_db, "dB"), _dash(m.delay_margin_s, "s"), _dash(m.ms),
                     "-" if st is None else _dash(st.overshoot_pct, "%"),
                     "-" if st is None else _dash(st.settling_time_s, "s")])
    return [R.text(head), R.table([_("corner"), _("stable"), _("phase margin"), _("gain margin"), _("delay margin"),
                                   "Ms", _("overshoot"), _("settling (2 %)")], rows, "compact")]


def _scope(result, with_images, b) -> list:
    blocks = _scope_blocks(result, with_images, b, result.levels)
    ch = next((c for c in (result.scope.channels if result.scope is not None else ()) if c.node == "y"), None)
    if ch is not None:
        blocks.insert(1, R.text(_(
            "CH2 on the plant's output y first: {v}/div, 0 V {div} div below centre; it spans {lo} .. {hi} ({by}). "
            "Then each op-amp output:").format(v=format_eng(ch.volts_per_div, 'V'), div=f"{ch.zero_div_below_centre:g}",
                                               lo=_v(ch.lo_v), hi=_v(ch.hi_v),
                                               by="SPICE" if result.spice is not None else _("analytic"))))
    return blocks


# ---- plots -------------------------------------------------------------------

def _closed_loop(result) -> bytes:
    # an integrating plant's open-loop step is a ramp: it would squash the loop's curves
    return _closed_loop_plot(result, open_loop=not result.model.integrating)


def _time_scale(t_end: float) -> tuple:
    """(factor, unit) for a time axis ending at ``t_end`` seconds."""
    for factor, unit in ((1e6, "us"), (1e3, "ms")):
        if t_end * factor <= 5e3:
            return factor, unit
    return 1.0, "s"


def _model_step_plot(result) -> bytes:
    """The model's own step (its reaction curve), the dead time and the final value marked."""
    w, m = result.waveforms, result.model
    k, unit = _time_scale(float(w.reaction_t[-1]))
    fig, ax = figure(7.5, 3.6)
    fig.subplots_adjust(bottom=0.14)
    ax.plot(*decimate(w.reaction_t * k, w.reaction_y), label=_("the model's step"))
    if m.theta_s > 0:
        ax.axvline(m.theta_s * k, color="r", lw=0.8, ls="--", label=_("dead time {theta}").format(theta=format_eng(m.theta_s, 's')))
    if not m.integrating and np.isfinite(m.gain):
        ax.axhline(m.gain, color="k", lw=0.6, label=_("final value K = {k}").format(k=f"{m.gain:.4g}"))
    ax.set_title(_("The plant alone: {model}").format(model=m.text()), fontsize=10)
    ax.set_xlabel(_("time ({unit})").format(unit=unit))
    ax.set_ylabel(_("output per volt of input"))
    ax.grid(True, alpha=0.3)
    ax.legend(fontsize=8)
    return png_bytes(fig, dpi=90, tight=False)


def _model_schematic(result):
    """The loop's schematic: the controller, the plant a block (:func:`~designer.pid.schematic.draw_model_loop`)."""
    from .schematic import draw_circuit_loop, draw_model_loop
    plant = getattr(result.spec, "circuit", None)
    if plant is not None:   # the plant's own sections, as the deck has them
        return draw_circuit_loop(_model_board(result), result.opamp, plant.circuit.netlist("u", "y"))
    return draw_model_loop(_model_board(result), result.opamp, result.model.text())


#: a model plant's sheet's plots: (file name, drawing function of the result)
MODEL_PLOTS = (("closed-loop.png", _closed_loop), ("blocks.png", _blocks_plot),
               ("loop-bode.png", _loop_gain_plot), ("reaction-curve.png", _model_step_plot))


#: the plots that read nothing of the SPICE run: drawn during it (:func:`draw_early`)
BEFORE_SPICE = ("loop-bode.png", "reaction-curve.png")


def draw_early(result):
    """Start drawing the schematic and :data:`BEFORE_SPICE` (``before_spice`` of
    :func:`~designer.pid.design.design_model_pid`); give it to :func:`write_outputs`.

    Parameters
    ----------
    result : designer.pid.result.PidResult
        A model plant's design, analysed but not yet simulated.

    Returns
    -------
    object
        The drawings under way (:func:`designer.report.bundle.draw_early`).
    """
    return bundle_early(result, MODEL_PLOTS, schematic, BEFORE_SPICE)
