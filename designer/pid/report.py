"""The PID build sheet: the whole loop's schematic (seed 001, Figure 66 with
the plant of Figures 43-45) beside the bill of materials and the bench
settings, the pin-level wiring in the chosen packages, target vs achieved,
the checks, closed-loop figures (analytic, ideal PID, SPICE), the scope
settings and expected levels at every op-amp output (as the seed photographs
them, Figures 79-90), and the plots. Rendered as Markdown, self-contained
HTML and terminal text from one description (:mod:`designer.report`), plus
``bom.csv``; the part and net table is the deck's (:mod:`designer.pid.netlist`)."""

from __future__ import annotations

import math

import numpy as np

from ..core import eseries
from ..core.i18n import N_, language
from ..core.i18n import gettext as _
from ..core.units import format_eng
from ..filters.sallen_key_lowpass_parts import section_of
from ..report import document as R
from ..report.bundle import write_design
from ..report.plots import decimate, figure, loop_gain_plot, png_bytes, step_plot, time_unit
from ..report.tolerance import csv_texts, histogram_plots
from ..report.tolerance import section as tolerance_section
from ..report.tolerance import title as tolerance_title
from ..report.wiring import bench_rows, bom_csv, bom_rows, wiring_rows
from ..spice.deck import board
from .model import OPAMP_OUTPUTS
from .netlist import NET_LABELS, loop_netlist, plant_ref_prefix
from .tuning import MODEL_NAMES

__all__ = ["bom", "build_board", "plots", "schematic", "sections", "summary_text", "title_of", "write_outputs"]

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
               N_("summer"), N_("gain"))


def title_of(result) -> str:
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
    """The loop as built on the bench: its part and net table (the deck's) in the result's package."""
    return board(loop_netlist(result.parts, result.plant), result.opamp, result.package)


def sections(result, with_images: bool = True, schematic_svg: str = "") -> list:
    """The build sheet as (heading, blocks) sections (:mod:`designer.report.document`)."""
    b = build_board(result)
    out = [(_("Verdict"), [R.text(verdict_text(result))] + [R.text(n) for n in result.notes])]
    out.append((_("Build"), _build_blocks(result, b, bom(result, b), with_images, schematic_svg)))
    out.append((_("Wiring"), _wiring_blocks(result, b)))
    if result.seed_bench is not None:
        out.append(("The seed's bench: predicted against measured (001, V.13, Figures 88-90)",
                    _seed_bench_blocks(result)))
    elif result.diff_amp is not None:
        out.append((_("Difference amplifier as built"), _diff_amp_blocks(result)))
    out.append((_("Tuning"), _tuning_blocks(result)))
    out.append((_("Target and achieved"), _achieved_blocks(result)))
    out.append((_("Checks"), [R.table([_("check"), _("result"), _("detail")],
                                      [[c.id, _("ok") if c.ok else _("FAILED"), c.shown()] for c in result.checks])]))
    out.append((_("Closed loop"), _loop_blocks(result, with_images)))
    heading = tolerance_title(result, worst=True)
    if heading is not None:
        out.append((heading, tolerance_section(result, with_images, worst=True)))
    out.append((_("Expected scope readings"), _scope_blocks(result, with_images, b)))
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
    controller's parts from its series, the plant's from the plant's."""
    b = b or build_board(result)
    controller = controller_source(result.selection)
    prs, pcs = result.plant_series or (None, None)
    prt, pct = ((100 * eseries.TOLERANCE[prs], 100 * eseries.TOLERANCE[pcs]) if prs else (None, None))
    section, prefix = section_of(result.plant), plant_ref_prefix(result.plant)
    plant_refs = {section.prefixed(ref, prefix) for ref in section.designators}

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
        blocks.append(R.text(
            f"Reaction curve of the plant as built: inflection at {_v(rc.t_inflection_s, 's')} "
            f"(y = {rc.y_inflection:.4g}), tangent slope {rc.slope_per_s:.5g} /s, K = {rc.K:.4g}, "
            f"L = {_v(rc.L_s, 's')}, T = {_v(rc.T_s, 's')} (the tangent reaches the final value at "
            f"{_v(rc.t_tangent_final_s, 's')}; T is measured from L). ZN's rule uses this tangent."))
    if fit is not None:
        how = ""
        if not fit.valid:
            how = (f" The step overshoots {rc.overshoot_pct:.3g} %, which no FOPDT model can follow: treat "
                   "the rules below as starting points." if rc.overshoot_pct > 2.0
                   else f" The fit is poor: {fit.note}.")
        blocks.append(R.text(
            f"Least-squares FOPDT K e^(-L s)/(T s + 1) of the same step (the model Cohen-Coon, CHR, AMIGO and "
            f"SIMC were derived for): K = {fit.K:.4g}, L = {_v(fit.L_s, 's')}, T = {_v(fit.T_s, 's')}"
            + ("" if fit.rms_residual is None else f", rms residual {fit.rms_residual:.3g}") + "."
            + how))
    if result.rules:
        rows = [[r.method, _model_cell(r.model), f"{r.kp:.4g}", _v(r.ti_s, "s"), _v(r.td_s, "s")]
                for r in result.rules]
        blocks.append(R.table([_("rule"), _("model it uses (K, L, T)"), "Kp", "Ti", "Td"], rows))
    opt = result.optimizer
    if opt is not None:
        b = opt.best
        blocks.append(R.text(
            f"Optimiser: {opt.message} ({opt.evaluations} evaluations); predicted "
            f"overshoot {_fmt(b.overshoot_pct, '%')}, settling {_v(b.settling_time_s, 's')}, worst swing "
            f"{_fmt(_pct(b.swing_ratio), '%')} of the rails, worst slew delay {_fmt(_pct(b.slew_ratio), '%')} "
            "of its budget" + ("" if b.stable else " (the best point found is an unstable loop)") + "."))
    return blocks


def _diff_amp_blocks(result) -> list:
    d = result.diff_amp
    sw = d.swapped
    other = "feedback" if d.attenuated == "reference" else "reference"
    return [R.text(
        f"U2 weighs the plant output y by g_y = (1 + R16/R15) R18/(R17 + R18) = {d.g_y:.4g} and the reference r by "
        f"g_r = R16/R15 = {d.g_r:.4g}: it attenuates the {d.attenuated} input against the {other}. The loop gain "
        f"is scaled by g_y ({d.loop_gain_db:+.3g} dB against a balanced amplifier) and the integrator settles the "
        f"loop where g_y y = g_r r: y = {d.final_ratio:.4g} r (the analytic DC gain). With R17 and R18 the other way "
        f"round (the divider on the other side), g_y = {sw['g_y']:.4g} ({sw['loop_gain_db']:+.3g} dB), phase "
        f"margin {_fmt(sw['phase_margin_deg'], 'deg')} at {_v(sw['crossover_hz'], 'Hz')}, "
        f"{'stable' if sw['stable'] else 'unstable'}, y = {sw['final_ratio']:.4g} r.")]


def _seed_bench_blocks(result) -> list:
    sb, d = result.seed_bench, result.diff_amp
    th = sb.thesis
    sw = d.swapped
    a, s = result.analytic, result.spice
    amp = result.opamp.name
    spice_txt = "not simulated" if s is None else ("oscillates" + (", saturated" if s.saturated else "")
                                                   if not s.stable else "settles")
    rows = [["loop", "stable" if th["stable"] else "unstable",
             ("stable" if a.stable else "UNSTABLE") + f" (phase margin {_fmt(result.margins.phase_margin_deg, 'deg')}"
             f"); SPICE {spice_txt}",
             ("stable" if sw["stable"] else "unstable") + f" (phase margin {_fmt(sw['phase_margin_deg'], 'deg')})"],
            ["output against the reference", th["output_vs_reference"], f"y = {d.final_ratio:.3g} r ({'larger' if d.final_ratio > 1 else 'smaller'})",
             f"y = {sw['final_ratio']:.3g} r ({'larger' if sw['final_ratio'] > 1 else 'smaller'})"],
            ["loop gain against a balanced U2", "", f"{d.loop_gain_db:+.3g} dB", f"{sw['loop_gain_db']:+.3g} dB"],
            ["overshoot", th["overshoot"], "", ""]]
    runs = [[f"{k[0]}, {k[1]:g} V step", "stable" if v[0] else "unstable", _fmt(v[1], "deg"),
             ("settles" if v[2] else "oscillates") + (", saturated" if v[3] else ""),
             f"{_v(v[4])} (expected {_v(v[5])})"] for k, v in sb.runs.items()]
    ok_small = [k for k, v in sb.runs.items() if v[2]]
    return [
        R.text(f"The thesis built this controller with {th['opamp']} and trimmed U2 on the bench; it reports "
               f"a stable loop with the overshoot suppressed and the output larger than the reference. Its plant: "
               f"{th['plant']}. Its scope: {th['scope']}. Test amplitude: {th['amplitude']}."),
        R.table(["", "thesis measured", f"predicted, parts as named here ({amp})",
                 "predicted, divider on y (R17, R18 exchanged)"], rows),
        R.text(f"Why they disagree. (1) Which input is attenuated: read with this project's names (R17 from y, R18 "
               f"to ground) the trimmed values attenuate the REFERENCE (g_r = {d.g_r:.3g}, g_y = {d.g_y:.3g}): "
               f"the loop gain does not fall ({d.loop_gain_db:+.2g} dB), the loop stays unstable, and it would settle "
               f"at {d.final_ratio:.2g} r, below the reference, against both of the thesis's observations. With the "
               f"9.98k/1.716k divider on the FEEDBACK input instead (y through 9.98k, 1.716k to ground), y is "
               f"attenuated to g_y = {sw['g_y']:.3g}: the loop gain falls by {-sw['loop_gain_db']:.3g} dB (Kp = "
               f"{result.achieved.kp:.3g} acts as {result.achieved.kp * sw['g_y']:.3g}), the crossover drops to {_v(sw['crossover_hz'], 'Hz')}, and the loop "
               f"settles at y = {sw['final_ratio']:.3g} r, larger than the reference as the thesis saw: the thesis's "
               "figures fit this wiring, which its text does not name. (2) The op-amp model and (3) the test "
               "amplitude decide the rest, as the runs below show: with that wiring the loop sits at the edge of "
               "stability, stable only with the seed's faster LM741 figures, and then only for a step small enough "
               "that no stage saturates or slews."),
        R.table(["divider on y, run", "analytic loop", "phase margin", "SPICE", "SPICE final value"], runs),
        R.text("So the bench result is reproduced only by the divider on the feedback input, an LM741 near the "
               "seed's 1.5 MHz, and a small test amplitude"
               + (f" ({', '.join(f'{k[1]:g} V with {k[0]}' for k in ok_small)} settles in SPICE)" if ok_small
                  else "") + "; at the seed's 2 V the stages saturate and the loop oscillates in SPICE.")]


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
    if with_images:
        blocks.append(R.columns([R.image("closed-loop.png", _("closed-loop step and controller output"))],
                                [R.image("loop-bode.png", _("loop gain with its margins"))]))
    return blocks


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
    return (f"{MODEL_NAMES.get(m.source, m.source)}: {m.K:.4g}, {_v(m.L_s, 's')}, "
            f"{_v(m.T_s, 's')}")


def _pct(ratio):
    return None if ratio is None else 100 * ratio


def _fmt(v, unit, signed=False):
    if _known(v) is None:
        return _("n/a")
    return (f"{v:+.3g}" if signed else f"{v:.3g}") + (f" {unit}" if unit else "")


def summary_text(result, lang=None) -> str:
    with language(lang):   # None: the current language (designer.core.i18n)
        text = R.to_text(title_of(result), sections(result, with_images=False))
    for extra in (result.monte_carlo, result.worst_case):
        if extra is not None:
            text += "\n" + "\n".join(extra.summary_lines()) + "\n"
    return text


# ---- plots -------------------------------------------------------------------

def plots(result) -> dict:
    """The sheet's plots, by file name (:data:`PLOTS`): the closed-loop step (SPICE minus
    the analytic loop below it), every op-amp output, the loop gain with its margins,
    the reaction curve."""
    return {name: draw(result) for name, draw in PLOTS}


def _closed_loop_plot(result, open_loop: bool = True) -> bytes:
    """The closed-loop step; ``open_loop``: the plant alone too (not for a ramp)."""
    w = result.waveforms
    a = w.analytic
    sp = None if result.spice is None else result.spice.waves
    amp = result.opamp.name
    curves = {}
    if sp is not None:
        curves["SPICE (ngspice)"] = sp["y"]
    curves[f"realised loop, analytic ({amp})"] = a["y"]
    curves["ideal PID, ideal plant"] = w.ideal_pid
    if open_loop:
        curves["plant alone (open loop)"] = w.open_loop
    resid = None if sp is None else ("residual: SPICE minus the analytic loop", sp["y"], a["y"])
    return step_plot(w.t, curves, f"Closed-loop step, 0 -> {result.test.amplitude_v:g} V", residual=resid)


def _loop_gain_plot(result) -> bytes:
    w, mg = result.waveforms, result.margins
    return loop_gain_plot(w.bode_w / (2 * np.pi), w.loop_gain, f"Loop gain with {result.opamp.name} poles",
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
        ax.plot(*decimate(t, w.analytic[s]), "-", lw=1.2, label="analytic")
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
    axes[0].set_title("Every op-amp output (red: output limits, drawn when reached)")
    axes[-1].set_xlabel(f"time after the step ({unit})")
    return png_bytes(fig, dpi=90, tight=False)


def _reaction_plot(result) -> bytes:
    w = result.waveforms
    tp, yp = w.reaction_t, w.reaction_y
    c = result.tuning.curve
    fig, ax = figure(7.5, 3.6)
    ax.plot(*decimate(tp * 1e6, yp), label="plant step response")
    if c is not None:
        tt = np.linspace(c.L_s, c.t_tangent_final_s, 50)
        ax.plot(tt * 1e6, c.slope_per_s * (tt - c.t_inflection_s) + c.y_inflection, "--", label="tangent")
        ax.plot([c.t_inflection_s * 1e6], [c.y_inflection], "o", label="inflection")
        ax.axhline(c.K, color="k", lw=0.6)
        if w.fopdt_y is not None:
            ax.plot(*decimate(tp * 1e6, w.fopdt_y), ":", label="least-squares FOPDT")
        ax.set_xlim(0, min(tp[-1], 6 * c.t_tangent_final_s) * 1e6)
        ax.set_title(f"Reaction curve: L = {format_eng(c.L_s, 's')}, T = {format_eng(c.T_s, 's')}")
    ax.set_xlabel("time (us)")
    ax.set_ylabel("output per volt of step")
    ax.grid(True, alpha=0.3)
    ax.legend()
    return png_bytes(fig, dpi=90, tight=False)


def schematic(result):
    """The loop's schematic (:mod:`designer.pid.schematic`) as a drawing."""
    from .schematic import draw_loop
    return draw_loop(build_board(result), result.opamp, plant_prefix=plant_ref_prefix(result.plant))


#: the sheet's plots: (file name, drawing function of the result)
PLOTS = (("closed-loop.png", _closed_loop_plot), ("blocks.png", _blocks_plot),
         ("loop-bode.png", _loop_gain_plot), ("reaction-curve.png", _reaction_plot))


def write_outputs(result, out_dir, name: str, lang=None) -> dict:
    """``netlists/<name>.cir`` and ``reports/<name>/`` (build sheet, result.json,
    plots, schematic, bom.csv) under ``out_dir``, each written atomically; the sheet in ``lang``
    (None: the current language, :mod:`designer.core.i18n`)."""
    with language(lang):
        return write_design(result, out_dir, name, PLOTS + histogram_plots(result), schematic,
                            lambda svg: sections(result, schematic_svg=svg), title_of(result),
                            {"bom_csv": ("bom.csv", lambda r: bom_csv(bom(r))), **csv_texts(result)})
