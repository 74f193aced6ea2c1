"""The build sheet of a PID controller for a plant known only as a model
(G(s) = N(s)/D(s) e^(-theta s): identified from a scope capture, typed, or a
designed circuit read as its model; issue 16).

The controller is the seed's six op-amps (001, Figure 66) as on the Sallen-Key
plant's sheet (:mod:`designer.pid.report`, whose blocks this sheet shares);
the plant is not on the board: the schematic draws it as a block labelled with
its G(s) (:func:`designer.pid.schematic.draw_model_loop`) and the wiring table
says where its input, output and ground go. Then the model and where it came
from (its 95 % intervals, its input and output ranges, the model the rules
used), every rule side by side on it (gains, margins, Ms, IAE, overshoot),
target against achieved, the checks, the loop as built against the ideal PID
and SPICE, the worst case over the model's 95 % corners, and the scope
readings. Everything is read from the typed
:class:`~designer.pid.result.PidResult`: nothing is computed here.
"""

from __future__ import annotations

import math

import numpy as np

from ..core.i18n import gettext as _
from ..core.units import format_eng
from ..report import document as R
from ..report.bundle import draw_early as bundle_early, write_design
from ..report.plots import decimate, figure, png_bytes
from ..report.tolerance import csv_texts, histogram_plots
from ..report.tolerance import section as tolerance_section
from ..report.tolerance import title as tolerance_title
from ..report.wiring import bom_csv, bom_rows, net_text
from ..spice.deck import board
from .netlist import NET_LABELS
from .plant import PLANT_PREFIX
from .report import (METRICS, _achieved_blocks, _blocks_plot, _build_blocks, _closed_loop_plot, _known,
                     _loop_gain_plot, _scope_blocks, _spice_agreement, _v, _wiring_blocks, controller_source,
                     verdict_of)

__all__ = ["PLOTS", "draw_early", "plots", "schematic", "summary_text", "write_outputs"]

#: the rule table's columns
RULE_HEADER = ("rule", "Kp", "Ti", "Td", "phase margin", "gain margin", "delay margin", "Ms", "crossover", "IAE",
               "overshoot", "SPICE overshoot", "note")


def title_of(result) -> str:
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


def verdict_text(result) -> str:
    return verdict_of(result.stable, result.analytic.figures, result.spice, result.checks)


def build_board(result):
    """The loop as built on the bench: the controller's part and net table
    (the plant off the board), or with a circuit plant's own sections on it
    (:func:`~designer.pid.process_loop.loop_netlist_of`), in the result's package."""
    from .process_loop import loop_netlist_of
    return board(loop_netlist_of(result.spec, result.parts), result.opamp, result.package)


def bom(result, b=None) -> list:
    """The bill of materials rows (:data:`designer.report.wiring.BOM_HEADER`): the
    controller's parts from its series, the decoupling, the op-amps."""
    b = b or build_board(result)
    return bom_rows(b, controller_source(result.selection), result.opamp.name)


def _shown_elsewhere(result) -> set:
    """The notes the Tuning section prints (the rule's and the optimiser's)."""
    out = set(result.rule.notes) if result.rule is not None else set()
    if result.optimizer is not None:
        out.add(result.optimizer.message)
    return out


def sections(result, with_images: bool = True, schematic_svg: str = "") -> list:
    """The build sheet as (heading, blocks) sections (:mod:`designer.report.document`)."""
    b = build_board(result)
    elsewhere = _shown_elsewhere(result)
    out = [(_("Verdict"), [R.text(verdict_text(result))] + [R.text(n) for n in result.notes if n not in elsewhere])]
    out.append((_("Build"), _build_blocks(result, b, bom(result, b), with_images, schematic_svg)))
    circuit = getattr(result.spec, "circuit", None)
    if circuit is not None:   # the plant's own sections are on the board, wired as the rest
        out.append((_("Wiring"), _wiring_blocks(result, b, (), " The plant's sections are on this board (their parts "
                                                                f"prefixed {PLANT_PREFIX}: RP1, CP1, op-amp UP).")))
    else:
        out.append((_("Wiring"), _wiring_blocks(
            result, b, plant_rows(b),
            " The plant is not on this board: its input takes u, its output y goes to R17 and to CH2, and its "
            "ground joins the common ground (the first rows).")))
    out.append((_("The plant"), _plant_blocks(result)))
    out.append((_("Tuning"), _tuning_blocks(result)))
    out.append((_("Target and achieved"), _achieved_blocks(result, result) + [R.text(
        f"The integrator leak (R13) and the derivative filter (R12) are placed from fc = "
        f"{_v(result.fc_ref_hz, 'Hz')}, the crossover of the ideal PID around the model (near fc/100 and "
        "10 fc unless set).")]))
    out.append((_("Checks"), [R.table([_("check"), _("result"), _("detail")],
                                      [[c.id, _("ok") if c.ok else _("FAILED"), c.detail] for c in result.checks])]))
    out.append((_("Closed loop"), _loop_blocks(result, with_images)))
    heading = tolerance_title(result, worst=True)
    if heading is not None:
        out.append((heading, tolerance_section(result, with_images, worst=True)))
    out.append((_("Expected scope readings"), _scope(result, with_images, b)))
    return out


def plant_rows(b) -> list:
    """Wiring rows (part, code, from, to) of the plant, which is off the board."""
    r17 = b.netlist.part("R17")
    return [["plant in", "", net_text(b, "u", NET_LABELS), "the plant's input"],
            ["plant out", "", "the plant's output y", f"R17 (to {net_text(b, r17.b, NET_LABELS)}) and scope CH2"],
            ["plant ground", "", "the plant's ground (its input's and output's reference)",
             "ground (the star point)"]]


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
    blocks = [R.text(f"{m.text()} ({m.kind}); the controller's output u is its input, its output y is fed back."),
              R.text(f"Where it came from: {m.source}.")]
    plant = getattr(spec, "circuit", None)
    if plant is not None:
        c = plant.circuit
        stages = "; ".join(f"{st['title']}: " + ", ".join(f"{k} {format_eng(v, 'Ohm' if k[0] == 'R' else 'F')}"
                                                           for k, v in st["parts"].items())
                           for st in c.to_dict()["stages"])
        blocks.append(R.text(f"The plant is a circuit ({c.topology}), built on the board and simulated as built: "
                             f"{stages}. Its own transfer function is {plant.model.text()}"
                             + ("; it inverts, so the controller's action is reversed (r and y exchanged at the "
                                "difference amplifier) and the gains are chosen for -G(s), the model above."
                                if plant.reversed_action else ".")))
    if m.ci95:
        rows = [[_param_name(k), _param(m.kind, k, v),
                 "not given" if not m.ci95.get(k) else "+/- " + _param(m.kind, k, m.ci95[k]),
                 "" if not m.ci95.get(k) else f"{_param(m.kind, k, v - m.ci95[k])} .. "
                                              f"{_param(m.kind, k, v + m.ci95[k])}"]
                for k, v in m.params.items()]
        blocks += [R.text("Its 95 % intervals (the loop is checked at every corner of this box: Closed loop):"),
                   R.table(["parameter", "value", "95 % half-width", "interval"], rows, "compact")]
    else:
        blocks.append(R.text("No 95 % intervals were given: the loop is checked on the nominal model only."))
    ranges = []
    for rng, what in ((spec.plant_input, "accepts u from"), (spec.plant_output, "delivers y from")):
        if rng is not None:
            ranges.append(f"{what} {format_eng(rng[0], 'V')} to {format_eng(rng[1], 'V')}")
    blocks.append(R.text("The plant " + " and ".join(ranges) + " (checked over the square wave)." if ranges else
                         "Its input and output ranges were not given: only the op-amps' swing is checked."))
    blocks.append(R.text(f"The rules see it as {result.reduced.describe()} (each rule's own model: Tuning)."))
    return blocks


# ---- tuning ----------------------------------------------------------------------

def _tuning_blocks(result) -> list:
    pi = not result.parts.has_derivative
    blocks = [R.text(f"Method: {result.method}. Kp = {result.kp:.4g}, Ti = {_v(result.ti_s, 's')}, "
                     f"Td = {_v(result.td_s, 's')}, in the ideal parallel form Kp (1 + 1/(Ti s) + Td s)"
                     + (": a PI (the differentiator, its R7, R11, R12 and C3 are left out)." if pi else "."))]
    rt = result.rule
    if rt is not None:
        used = rt.model_used
        blocks.append(R.text(f"{rt.rule} on {used.describe()}" + (": " + "; ".join(used.steps) if used.steps else "")
                             + "."))
        blocks += [R.text(f) for f in rt.formulas]
        if rt.series is not None and rt.series[2] > 0:
            kc, ti, td = rt.series
            blocks.append(R.text(f"Series form Kc (1 + 1/(tauI s))(1 + tauD s): Kc = {kc:.4g}, tauI = {_v(ti, 's')}, "
                                 f"tauD = {_v(td, 's')}; {rt.conversion}."))
        blocks += [R.text(n) for n in rt.notes]
    opt = result.optimizer
    if opt is not None:
        blocks.append(R.text(
            f"Optimiser (started from {opt.start_rule}): {opt.message}; predicted overshoot "
            f"{_dash(opt.overshoot_pct, '%')}" + ("" if opt.met else "; the limits are NOT all met")
            + (", limits held at every 95 % corner" if opt.robust else "") + "."))
    pm, gm, ms = result.limits
    blocks.append(R.text(
        f"Every rule on this model, each loop as it would be built (its gains, the op-amp poles, leak and filter, "
        f"the exact dead time), for a {format_eng(result.spec.step_v, 'V')} step; the limits are phase margin >= "
        f"{pm:g} deg, gain margin >= {gm:g} dB, Ms <= {ms:g}."))
    blocks.append(R.table(RULE_HEADER, [_rule_row(result, r) for r in result.rules]))
    return blocks


def _rule_row(result, r) -> list:
    t, f = r.tuning, r.figures
    if t is None:
        return [r.rule] + ["-"] * 11 + [f"does not apply: {r.reason}"]
    gains = [f"{t.kp:.4g}", _v(t.ti_s, "s"), _v(t.td_s, "s")]
    note = r.reason or ""
    if r.rule == result.method:
        note = "built" + (f"; {note}" if note else "")
    if f is None:
        return [r.rule, *gains] + ["-"] * 8 + [note]
    m, st = f.margins, f.step
    if not m.stable:
        note = "unstable loop" + (f"; {note}" if note else "")
    return [r.rule, *gains, _dash(m.phase_margin_deg, "deg"), _dash(m.gain_margin_db, "dB"),
            _dash(m.delay_margin_s, "s"), _dash(m.ms), _dash(m.crossover_hz, "Hz"),
            "-" if st is None else _dash(st.iae, "V s"), "-" if st is None else _dash(st.overshoot_pct, "%"),
            _dash(r.spice_overshoot_pct, "%"), note]


# ---- closed loop -----------------------------------------------------------------

def _margin_rows(ideal, built) -> list:
    rows = []
    for key, label, unit in (("phase_margin_deg", "phase margin", "deg"), ("crossover_hz", "gain crossover", "Hz"),
                             ("gain_margin_db", "gain margin", "dB"), ("delay_margin_s", "delay margin", "s"),
                             ("ms", "Ms (max sensitivity)", "")):
        rows.append([label, _dash(getattr(ideal, key), unit), _dash(getattr(built, key), unit), "-"])
    return rows


def _loop_blocks(result, with_images) -> list:
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
              R.text(f"The loop as built (op-amp poles, integrator leak, derivative filter, exact dead time): phase "
                     f"margin {_dash(mg.phase_margin_deg, 'deg')} at {_dash(mg.crossover_hz, 'Hz')}, gain margin "
                     f"{_dash(mg.gain_margin_db, 'dB')} at {_dash(mg.phase_crossover_hz, 'Hz')}, delay margin "
                     f"{_dash(mg.delay_margin_s, 's')}, Ms {_dash(mg.ms)} at {_dash(mg.ms_hz, 'Hz')} (limits: "
                     f"{pm:g} deg, {gm:g} dB, Ms {ms:g}). Closed-loop DC gain {result.dc_gain:.4g}; the step "
                     "figures are for the rising edge of the bench test.")]
    if s:
        blocks.append(R.text(_spice_agreement(result)))
    if result.robust is not None:
        blocks += _robust_blocks(result.robust)
    if with_images:
        blocks.append(R.columns([R.image("closed-loop.png", _("closed-loop step and controller output"))],
                                [R.image("loop-bode.png", _("loop gain with its margins"))]))
    return blocks


def _robust_blocks(rb) -> list:
    pm_at, pm = rb.worst("phase_margin_deg")
    gm_at, gm = rb.worst("gain_margin_db")
    ms_at, ms = rb.worst("ms", -1.0)
    os_at, os_ = rb.worst("overshoot_pct", -1.0)
    n = len(rb.corners)
    head = (f"Worst case over the {n} corners of the model's 95 % intervals (the loop as built at each): "
            + (f"stable at every corner; phase margin {_dash(pm, 'deg')} at {pm_at}, gain margin {_dash(gm, 'dB')} "
               f"at {gm_at}, Ms {_dash(ms)} at {ms_at}, overshoot {_dash(os_, '%')} at {os_at} (limits: "
               f"{rb.min_phase_margin_deg:g} deg, {rb.min_gain_margin_db:g} dB, Ms {rb.max_ms:g})."
               if rb.all_stable else f"UNSTABLE at the corner {pm_at}."))
    rows = []
    for label, f in rb.corners:
        m, st = f.margins, f.step
        rows.append([label, "yes" if m.stable else "NO", _dash(m.phase_margin_deg, "deg"),
                     _dash(m.gain_margin_db, "dB"), _dash(m.delay_margin_s, "s"), _dash(m.ms),
                     "-" if st is None else _dash(st.overshoot_pct, "%"),
                     "-" if st is None else _dash(st.settling_time_s, "s")])
    return [R.text(head), R.table(["corner", "stable", "phase margin", "gain margin", "delay margin", "Ms",
                                   "overshoot", "settling (2 %)"], rows, "compact")]


def _scope(result, with_images, b) -> list:
    blocks = _scope_blocks(result, with_images, b, result.levels)
    ch = next((c for c in (result.scope.channels if result.scope is not None else ()) if c.node == "y"), None)
    if ch is not None:
        blocks.insert(1, R.text(
            f"CH2 on the plant's output y first: {format_eng(ch.volts_per_div, 'V')}/div, 0 V "
            f"{ch.zero_div_below_centre:g} div below centre; it spans {_v(ch.lo_v)} .. {_v(ch.hi_v)} "
            f"({'SPICE' if result.spice is not None else 'analytic'}). Then each op-amp output:"))
    return blocks


def summary_text(result) -> str:
    text = R.to_text(title_of(result), sections(result, with_images=False))
    for extra in (result.monte_carlo, result.worst_case):
        if extra is not None:
            text += "\n" + "\n".join(extra.summary_lines()) + "\n"
    return text


# ---- plots -------------------------------------------------------------------

def plots(result) -> dict:
    """The sheet's plots, by file name (:data:`PLOTS`)."""
    return {name: draw(result) for name, draw in PLOTS}


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
    ax.plot(*decimate(w.reaction_t * k, w.reaction_y), label="the model's step")
    if m.theta_s > 0:
        ax.axvline(m.theta_s * k, color="r", lw=0.8, ls="--", label=f"dead time {format_eng(m.theta_s, 's')}")
    if not m.integrating and np.isfinite(m.gain):
        ax.axhline(m.gain, color="k", lw=0.6, label=f"final value K = {m.gain:.4g}")
    ax.set_title(f"The plant alone: {m.text()}", fontsize=10)
    ax.set_xlabel(f"time ({unit})")
    ax.set_ylabel("output per volt of input")
    ax.grid(True, alpha=0.3)
    ax.legend(fontsize=8)
    return png_bytes(fig, dpi=90, tight=False)


def schematic(result):
    """The loop's schematic: the controller, the plant a block (:func:`~designer.pid.schematic.draw_model_loop`)."""
    from .schematic import draw_circuit_loop, draw_model_loop
    plant = getattr(result.spec, "circuit", None)
    if plant is not None:   # the plant's own sections, as the deck has them
        return draw_circuit_loop(build_board(result), result.opamp, plant.circuit.netlist("u", "y"))
    return draw_model_loop(build_board(result), result.opamp, result.model.text())


#: the sheet's plots: (file name, drawing function of the result)
PLOTS = (("closed-loop.png", _closed_loop), ("blocks.png", _blocks_plot),
         ("loop-bode.png", _loop_gain_plot), ("reaction-curve.png", _model_step_plot))


#: the plots that read nothing of the SPICE run: drawn during it (:func:`draw_early`)
BEFORE_SPICE = ("loop-bode.png", "reaction-curve.png")


def draw_early(result):
    """Start drawing the schematic and :data:`BEFORE_SPICE` (``before_spice`` of
    :func:`~designer.pid.process_loop.design_model_pid`); give it to :func:`write_outputs`."""
    return bundle_early(result, PLOTS, schematic, BEFORE_SPICE)


def write_outputs(result, out_dir, name: str, early=None) -> dict:
    """``netlists/<name>.cir`` and ``reports/<name>/`` (build sheet, result.json,
    plots, schematic, bom.csv, and the Monte Carlo's files) under ``out_dir``, each written
    atomically; the pictures ``early`` (:func:`draw_early`) started are not drawn again."""
    return write_design(result, out_dir, name, PLOTS + histogram_plots(result), schematic,
                        lambda svg: sections(result, schematic_svg=svg), title_of(result),
                        {"bom_csv": ("bom.csv", lambda r: bom_csv(bom(r))), **csv_texts(result)}, early)
