"""The plant's build sheet, terminal summary and files (netlist, report folder,
``bom.csv``), rendered from the typed :class:`~designer.plant.result.PlantResult`
as it is: nothing here computes a figure of the design.

The sheet opens with what a student builds from (seed 001, IV.9, the bench test
of Figures 46-48): the schematic, drawn from the part and net table the deck is
written from (:mod:`designer.plant.schematic`), beside the bill of materials and
the generator and scope settings; then the pin-level wiring, the readings to
expect, the sine check, the checks and the comparisons."""

from __future__ import annotations

import io
import math

import numpy as np

from ..core.i18n import N_, language, translated
from ..core.i18n import gettext as _
from ..filters.sallen_key_lowpass_parts import refs, section_of
from ..core.units import format_eng
from ..report import document as R
from ..report.bundle import write_design
from ..report.plots import bode_plot, step_plot
from ..report.tolerance import csv_texts, histogram_plots
from ..report.tolerance import section as tolerance_section
from ..report.wiring import bench_rows, bom_csv, bom_rows, wiring_rows
from ..spice.deck import board
from .netlist import plant_netlist

__all__ = ["bode_png", "prbs_blocks", "prbs_png", "prbs_texts", "prbs_waveforms_csv", "schematic", "sine_text", "step_png", "summary_text", "waveforms_csv", "write_outputs"]

METRIC_ROWS = (("overshoot_pct", N_("overshoot Mp"), lambda v: _("n/a") if v is None else f"{v:.4g} %"),
               ("peak_time_s", N_("peak time tp"), R.fmt_time),
               ("rise_time_s", N_("rise time tr (10-90 %)"), R.fmt_time),
               ("settling_time_s", N_("settling time ts (2 %)"), R.fmt_time))


def title_of(result) -> str:
    s = result.target
    if result.mode == "analyze":
        return _("Sallen-Key plant as built: fn {fn} Hz, zeta {zeta}").format(fn=f"{result.built.fn_hz:.5g}",
                                                                             zeta=f"{result.built.zeta:.4g}")
    return _("Sallen-Key plant: fc {fc} Hz, zeta {zeta}, gain {gain}").format(fc=f"{s.fc_hz:g}", zeta=f"{s.zeta:g}",
                                                                           gain=f"{s.gain:g}")


def build_board(result):
    """The plant as built on the bench: its part and net table (the deck's) in the result's package."""
    return board(plant_netlist(result.built), result.opamp, result.package)


#: what the plant's nets are called on the sheet
NET_LABELS = {"input": N_("generator (CH1)"), "v1": N_("node A (R1-R2-C2)"), "out": N_("output (CH2)"),
              "0": N_("ground")}


def sections(result, with_images: bool = True, schematic_svg: str = "") -> list:
    """The build sheet as (heading, blocks) sections (see :mod:`designer.report.document`)."""
    b = build_board(result)
    first = [R.subhead(_("Bill of materials")),
             R.table([_("Ref"), _("Value"), _("Code"), _("Qty"), _("Series"), _("Tol."), _("Package")],
                     # the package by its name in the sheet's language (designer.report.wiring.CATALOGUE_WORDS)
                     [[*r[:6], _(r[6])] for r in bom(result, b)], "compact"),
             R.subhead(_("Generator and scope")), *_settings(result)]
    fig = [R.figure("schematic.png", schematic_svg, _("schematic"))] if with_images else []
    out = [(_("Build"), [R.columns(fig, first)] if with_images else first),
           (_("Wiring"), [R.table([_("part"), _("code"), _("from"), _("to")],
                                  wiring_rows(b, NET_LABELS, (result.opamp.vcc, result.opamp.vee)))]),
           (_("Bench test: what the scope shows"), _bench(result)),
           *([(_("Bench test under a PRBS (--stimulus prbs)"), prbs_blocks(result))] if result.prbs is not None else []),
           (_("Target and achieved"), _targets(result)),
           (_("Checks"), [R.table([_("check"), _("result"), _("detail")],
                                  [[_(c.title), _("ok") if c.ok else _("FAILED"), c.shown()] for c in result.checks])])]
    if result.spice is not None:
        out.append((_("SPICE against the analytic models"), _spice(result)))
    if with_images:
        out.append((_("Plots"), [R.columns([R.image("step.png", _("step response: analytic and SPICE, residual"))],
                                           [R.image("bode.png", _("Bode plot with the sine check's points"))])]))
        if result.prbs is not None:
            out[-1][1].append(R.image("prbs.png", _("the last period of the PRBS: generator, SPICE and the model")))
    if result.monte_carlo is not None:
        out.append((_("Tolerance analysis (Monte Carlo)"), tolerance_section(result, with_images)))
    out.append((_("Sensitivity"), _sensitivity(result)))
    if result.alternatives:
        out.append((_("Alternatives (best first)"), [_alternatives(result.alternatives), R.text(_(ALTERNATIVES_NOTE))]))
    if result.notes:
        out.append((_("Notes"), [R.text(n) for n in result.notes]))
    return out


def bom(result, b=None) -> list:
    """The bill of materials rows (:data:`designer.report.wiring.BOM_HEADER`)."""
    return bom_rows(b or build_board(result), result.sourcing.source, result.opamp.name)


def _settings(result) -> list:
    """The generator and the scope as set (1-2-5 steps), and the sine check."""
    sine = result.sine
    rows = bench_rows(result.test, result.scope, section_of(result.built).designators[0])   # the input resistor
    if sine is not None:
        rows.append([_("sine check"), sine_text(sine)])
    return [R.table([_("set"), _("to")], rows, "compact"),
            R.text(_("Set the generator's output to High-Z (not 50 ohm): in 50-ohm mode it shows half the amplitude "
                     "it really gives into this circuit's high input impedance; check the level on CH1."))]


def sine_text(sine) -> str:
    """The sine check in one line, as the sheet's settings table and the page give it: the amplitude,
    the peak (its gain over DC, its frequency; SPICE's when it ran) or why there is none, and the
    -3 dB frequency.

    Parameters
    ----------
    sine : designer.plant.bench.SineCheck
        The sine check.

    Returns
    -------
    str
        The line.
    """
    head = _("sine {amplitude} pk").format(amplitude=format_eng(sine.amplitude_v, 'V'))
    parts = []
    if sine.f_peak_hz is not None:
        g = sine.spice_peak_gain if sine.spice_peak_gain is not None else sine.peak_gain
        f = sine.spice_f_peak_hz if sine.spice_f_peak_hz is not None else sine.f_peak_hz
        parts.append(_("peak x{gain} at {f}").format(gain=f"{g / sine.dc_gain:.3g}", f=format_eng(f, 'Hz', 3)))
    elif sine.no_peak:
        parts.append(translated(sine.no_peak))
    f3 = sine.spice_f_3db_hz if sine.spice_f_3db_hz is not None else sine.f_3db_hz
    if f3 is not None:
        parts.append(_("-3 dB (x0.707) at {f}").format(f=format_eng(f3, 'Hz', 3)))
    return head + ": " + ", ".join(parts)


def _targets(result):
    s, ideal = result.target, result.ideal
    fig, opa = result.analytic.figures, result.analytic_opamp.figures
    rows = [["fn", _f(s.fc_hz, "Hz"), _f(ideal and ideal.fn_hz, "Hz"), _f(fig.fn_hz, "Hz"),
             R.fmt_pct(fig.fn_error_pct), _f(opa.fn_hz, "Hz"), R.fmt_pct(opa.fn_error_pct)],
            ["zeta", _n(s.zeta), _n(ideal and ideal.zeta), _n(fig.zeta), R.fmt_pct(fig.zeta_error_pct),
             _n(opa.zeta), R.fmt_pct(opa.zeta_error_pct)],
            ["Q", _n(s.q), _n(ideal and ideal.q), _n(result.built.q), "", _n(opa.q), ""]]
    blocks = [R.table(["", _("target"), _("exact parts"), _("built (ideal op-amp)"), _("error"),
                       _("built with {opamp}").format(opamp=result.opamp.name), _("error")], rows)]
    if result.ratios.m is not None:
        blocks.append(R.text(_("Ratios: m = R1/R2 = {m}, n = C2/C1 = {n}.").format(m=f"{result.ratios.m:.4g}",
                                                                                 n=f"{result.ratios.n:.4g}")))
    return blocks


def _bench(result):
    ts, tol, spice = result.test, result.tolerance, result.spice
    expected = result.analytic_opamp.step
    rows = []
    for key, label, f in METRIC_ROWS:
        band = getattr(tol, key)
        rows.append([_(label), f(_value(expected, key)), f(_value(spice.step, key)) if spice else _("not simulated"),
                     f"{f(band.lo)} .. {f(band.hi)}"])
    amp_v = ts.amplitude_v
    rows.append([_("peak output"), format_eng(expected.peak_value * amp_v, "V"),
                 format_eng(spice.step.peak_value * amp_v, "V") if spice else "", ""])
    blocks = [R.table([_("reading (rising edge)"), _("expected ({opamp} model)").format(opamp=result.opamp.name),
                       "SPICE", _("band (R {r} %, C {c} %)").format(r=f"{tol.r_tolerance_pct:g}",
                                                                    c=f"{tol.c_tolerance_pct:g}")], rows)]
    sine = result.sine
    if sine is not None:
        srows = [[_("resonance peak"), _fg(sine.f_peak_hz, sine.peak_gain, sine.dc_gain, sine.no_peak),
                  _fg(sine.spice_f_peak_hz, sine.spice_peak_gain, sine.dc_gain, sine.spice_no_peak)
                  if spice else _("not simulated")],
                 [_("-3 dB point"), _f(sine.f_3db_hz, "Hz"), _f(sine.spice_f_3db_hz, "Hz") if spice else ""]]
        blocks += [R.text(_("Sine check: a {amplitude} peak sine, no offset; sweep the frequency and read the "
                            "output's amplitude on CH2 against CH1 (gain relative to the DC gain). SPICE's figures "
                            "come from an .ac run of the same circuit.").format(
                                amplitude=format_eng(sine.amplitude_v, 'V'))),
                   R.table([_("sine"), _("{opamp} model").format(opamp=result.opamp.name), "SPICE (.ac)"], srows)]
    return blocks


def prbs_blocks(result):
    """The generator's settings for the sequence, why they were chosen, and what to compare (any plant's
    ``prbs``: the Sallen-Key plant's and a section plant's sheet).

    Parameters
    ----------
    result : PlantResult or designer.plant.circuit_design.CircuitPlantResult
        The plant, with its PRBS run.

    Returns
    -------
    list
        The sheet's blocks.
    """
    run = result.prbs
    p = run.plan
    lo, hi = p.offset - p.amplitude, p.offset + p.amplitude
    y = run.capture.output_v
    rows = [["waveform", "arbitrary: prbs.csv (time_s,value) or prbs_awg.csv (one value per clock interval)"],
            ["sequence", f"maximum-length, {p.bits} bits (N = {p.n} intervals a period)"],
            ["clock (sample rate)", f"{format_eng(p.clock_hz, 'Hz')} (Dt = {format_eng(p.dt_s, 's')})"],
            ["levels", f"{format_eng(lo, 'V')} and {format_eng(hi, 'V')}"],
            ["amplitude", f"{format_eng(p.amplitude, 'V')} (+-, {format_eng(2 * p.amplitude, 'V')} pk-pk)"],
            ["offset", format_eng(p.offset, "V")],
            ["period", f"{format_eng(p.period_s, 's')}; play {p.periods} ({format_eng(p.periods * p.period_s, 's')})"],
            ["output range", f"{format_eng(float(y.min()), 'V')} to {format_eng(float(y.max()), 'V')}"
                             + ("" if run.simulator is None else " (SPICE)")]]
    blocks = [R.table(["set", "to"], rows, "compact")]
    blocks += [R.text("Why: " + r) for r in p.reasons]
    pred = ("ngspice's output, and the op-amp-aware model's" if run.simulator is not None
            else "the op-amp-aware model's output (not simulated)")
    blocks.append(R.text(f"waveforms.csv holds the prediction: the sequence (input_v), {pred}, sampled every "
                         f"{format_eng(float(run.capture.time_s[1] - run.capture.time_s[0]), 's')}. Capture "
                         "CH1 (generator) and CH2 (output) for all the periods and compare, or run identify on "
                         "the capture: it uses the periods after the first."))
    return blocks


def _fg(f, g, dc, why=None):
    if f is None or g is None:
        return translated(why) if why else _("none (no peak)")
    return _("x{gain} ({db} dB) at {f}").format(gain=f"{g / dc:.4g}", db=f"{20 * math.log10(g / dc):+.2f}",
                                                 f=format_eng(f, 'Hz', 4))


def _sensitivity(result):
    amp = result.opamp.name
    sens, sens_o = result.analytic.sensitivity, result.analytic_opamp.sensitivity
    rows = [[k, f"{v.wn:+.3f}", f"{v.zeta:+.3f}",
             f"{sens_o[k].wn:+.3f}" if k in sens_o else "", f"{sens_o[k].zeta:+.3f}" if k in sens_o else ""]
            for k, v in sens.items()]
    rows += [[k, "", "", f"{v.wn:+.4f}", f"{v.zeta:+.4f}"] for k, v in sens_o.items() if k not in sens]
    return [R.text(_("Relative sensitivity S = d ln(y) / d ln(x): a 1 % change in the part changes y by S %.")),
            R.table([_("part"), "S(wn)", "S(zeta)", _("S(wn) with {opamp}").format(opamp=amp),
                     _("S(zeta) with {opamp}").format(opamp=amp)], rows)]


#: how the alternatives are chosen (designer.plant.design's module docstring has the sources)
ALTERNATIVES_NOTE = N_("Each response is listed once (the same parts at ten times the resistance and a tenth of "
                     "the capacitance give the same fn and zeta), with resistors from 1 kOhm to 100 kOhm where it "
                     "can: below, they load the op-amp's output and the generator's 50 Ohm adds to R1; above, "
                     "their thermal noise (41 nV/sqrt(Hz) at 100 kOhm) and the op-amp's input bias current "
                     "through them (LM741: 80 nA, 8 mV at 100 kOhm) grow. Builds within 0.5 % of the target "
                     "with resistors in that band come first.")


def _alternatives(alternatives):
    rows = [[i + 1, " / ".join(format_eng(v, "Ohm" if r[0] == "R" else "F", 3) for r, v in a.values.items()),
             _f(a.figures.fn_hz, "Hz"), _n(a.figures.zeta), R.fmt_pct(a.figures.fn_error_pct),
             R.fmt_pct(a.figures.zeta_error_pct)]
            for i, a in enumerate(alternatives)]
    return R.table(["#", " / ".join(refs(with_gain=False)), "fn", "zeta", _("fn error"), _("zeta error")], rows)


def _spice(result):
    spice, amp = result.spice, result.opamp.name
    cmp_ = spice.comparison

    def delta(x, key):
        if x["delta"] is None:
            return _("n/a")
        if key == "overshoot_pct":
            return f"{x['delta']:+.3g} pp"
        return f"{format_eng(x['delta'], 's', 3)} ({R.fmt_pct(x['delta_pct'])})"

    rows = [[_(label), delta(cmp_.vs_ideal[key], key), delta(cmp_.vs_opamp[key], key)]
            for key, label, _fmt in METRIC_ROWS]
    rows.append([_("normalised RMS waveform error"), f"{spice.nrms_ideal:.3g}", f"{spice.nrms:.3g}"])
    return [R.text(_("ngspice ({simulator} backend), {opamp} behavioural model. Deltas are SPICE minus "
                     "model; NRMS = RMS of (model - SPICE) / (1 % of |model| + {abstol}). SPICE agrees with the "
                     "op-amp-aware model when NRMS is below 1 and overshoot is within 1 pp, peak and rise time "
                     "within 2 %, settling time within 5 % (or half a ringing period): ").format(
                         simulator=spice.simulator, opamp=amp, abstol=format_eng(cmp_.nrms_abstol_v, 'V'))
                   + (_("it does.") if cmp_.passed else _("it does NOT ({reasons}).").format(
                       reasons="; ".join(cmp_.disagreements)))),
            R.table([_("metric"), _("vs ideal model"), _("vs {opamp}-aware model").format(opamp=amp)], rows)]


def _f(v, unit):
    return "" if v is None else format_eng(v, unit, 5)


def _value(metrics, key):
    """A step metric for the sheet: None where the response has none (nan)."""
    v = getattr(metrics, key)
    return None if v != v else v


def _n(v):
    return "" if v is None else f"{v:.4g}"


def summary_text(result, lang: str | None = None) -> str:
    """The terminal summary: the build sheet without plots (and the Monte Carlo's lines when run).

    Parameters
    ----------
    result : PlantResult
        The plant.
    lang : str or None
        The language (:data:`designer.core.i18n.LANGUAGES`); None: the current one (English unless a
        :func:`designer.core.i18n.language` block says otherwise).

    Returns
    -------
    str
        The summary.
    """
    with language(lang):
        text = R.to_text(title_of(result), sections(result, with_images=False))
    for extra in (result.monte_carlo, result.worst_case):
        if extra is not None:
            text += "\n" + "\n".join(extra.summary_lines()) + "\n"
    return text


def plots(result) -> dict:
    """The sheet's plots, by file name (:data:`PLOTS`): the step response and the Bode plot."""
    return {name: draw(result) for name, draw in PLOTS}


def step_png(result) -> bytes:
    """The curves, the tolerance band shaded, SPICE minus the op-amp-aware model below.

    Parameters
    ----------
    result : PlantResult
        The plant.

    Returns
    -------
    bytes
        The PNG.
    """
    ideal, real = result.analytic, result.analytic_opamp
    amp = result.opamp.name
    a = result.test.amplitude_v
    curves = {}
    if result.spice is not None:
        curves["SPICE (ngspice)"] = result.spice.response
    curves[_("analytic ({opamp} model)").format(opamp=amp)] = real.response
    curves[N_("analytic (ideal op-amp)")] = ideal.response
    tol = result.tolerance
    band = None if tol.t_s is None else (tol.t_s, tol.lo * a, tol.hi * a,
                                         _("tolerance band (R {r} %, C {c} %)").format(
                                             r=f"{tol.r_tolerance_pct:g}", c=f"{tol.c_tolerance_pct:g}"))
    resid = None if result.spice is None else (_("residual: SPICE minus the {opamp} model").format(opamp=amp),
                                               result.spice.response, real.response)
    return step_plot(result.time_s, curves, _("Step response, 0 -> {v} V").format(v=f"{a:g}"), residual=resid,
                     band=band)


def prbs_png(result) -> bytes:
    """The last period of the PRBS run: the generator, the output (SPICE when
    simulated) and the op-amp-aware model, their difference below.

    Parameters
    ----------
    result : PlantResult or designer.plant.circuit_design.CircuitPlantResult
        The plant, with its PRBS run.

    Returns
    -------
    bytes
        The PNG.
    """
    run = result.prbs
    c, p = run.capture, run.plan
    last = c.time_s >= (p.periods - 1) * p.period_s
    t = c.time_s[last]
    model = _("analytic ({opamp} model)").format(opamp=result.opamp.name)
    out = "SPICE (ngspice)" if run.simulator is not None else model
    curves = {out: c.output_v[last], N_("generator (CH1)"): c.input_v[last]}
    if run.simulator is not None:
        curves[model] = c.analytic_opamp_v[last]
    resid = None if run.simulator is None else (_("residual: SPICE minus the {opamp} model").format(
        opamp=result.opamp.name), c.output_v[last], c.analytic_opamp_v[last])
    return step_plot(t, curves, _("PRBS of {bits} bits at {clock}: its last period").format(
                         bits=p.bits, clock=format_eng(p.clock_hz, 'Hz')),
                     ylabel=N_("voltage (V)"), residual=resid, xlabel=N_("time from the start of the sequence"))


def bode_png(result) -> bytes:
    """The models, SPICE's .ac points, the peak and -3 dB markers.

    Parameters
    ----------
    result : PlantResult
        The plant.

    Returns
    -------
    bytes
        The PNG.
    """
    ideal, real = result.analytic, result.analytic_opamp
    amp = result.opamp.name
    fn = result.built.fn_hz
    sine = result.sine
    measured, marks = {}, []
    if sine is not None:
        if sine.h_spice is not None:
            measured["SPICE .ac"] = (sine.spice_f_hz, sine.h_spice)
        marks += [(sine.f_peak_hz, sine.peak_gain, N_("peak"), "kv"), (sine.f_3db_hz,
                  None if sine.f_3db_hz is None else sine.dc_gain / math.sqrt(2), "-3 dB", "ks")]
        if sine.spice_f_peak_hz is not None:
            marks.append((sine.spice_f_peak_hz, sine.spice_peak_gain, "", "rv"))
        if sine.spice_f_3db_hz is not None:
            marks.append((sine.spice_f_3db_hz, sine.dc_gain / math.sqrt(2), "", "rs"))
    return bode_plot({N_("ideal op-amp"): (ideal.num, ideal.den),
                      _("{opamp} model").format(opamp=amp): (real.num, real.den)},
                     fn / 100, fn * 100, N_("Plant frequency response"), measured, marks)


def waveforms_csv(result) -> str:
    """The bench period as CSV (``time_s,input_v,output_v,...``; output is SPICE when
    simulated), the format ``identify`` reads: the tool's own scope capture.

    Parameters
    ----------
    result : PlantResult
        The plant.

    Returns
    -------
    str
        The CSV text.
    """
    return _columns_csv(result.bench.columns())


def prbs_waveforms_csv(result) -> str:
    """The plant under the PRBS as CSV (``time_s,input_v,output_v,analytic_opamp_v``;
    output is SPICE when simulated): what ``identify`` reads and a capture is compared with.

    Parameters
    ----------
    result : PlantResult or designer.plant.circuit_design.CircuitPlantResult
        The plant, with its PRBS run.

    Returns
    -------
    str
        The CSV text.
    """
    return _columns_csv(result.prbs.capture.columns())


def _columns_csv(cols: dict) -> str:
    buf = io.StringIO()
    np.savetxt(buf, np.column_stack(list(cols.values())), delimiter=",", header=",".join(cols), comments="",
               fmt="%.9g")
    return buf.getvalue()


def schematic(result):
    """The plant's schematic (:mod:`designer.plant.schematic`) as a drawing.

    Parameters
    ----------
    result : PlantResult
        The plant.

    Returns
    -------
    designer.report.schematic.Sheet
        The drawing.
    """
    from .schematic import draw_plant
    return draw_plant(build_board(result), result.opamp)


def prbs_texts(result) -> dict:
    """The bundle's files of a PRBS run (none without one): the generator's (prbs.csv, prbs_awg.csv, as
    make-prbs writes them), its deck (prbs-test.cir) and the run as waveforms.csv (what identify reads).

    Parameters
    ----------
    result : PlantResult or designer.plant.circuit_design.CircuitPlantResult
        The plant.

    Returns
    -------
    dict
        Key -> (file name, text of the result), :func:`designer.report.bundle.write_design`'s form.
    """
    if result.prbs is None:
        return {}
    from ..core.prbs import awg_csv, time_value_csv
    return {"waveforms_csv": ("waveforms.csv", prbs_waveforms_csv),
            "prbs_csv": ("prbs.csv", lambda r: time_value_csv(r.prbs.plan)),
            "prbs_awg_csv": ("prbs_awg.csv", lambda r: awg_csv(r.prbs.plan)),
            "prbs_deck": ("prbs-test.cir", lambda r: r.prbs.deck)}


#: the sheet's plots: (file name, drawing function of the result)
PLOTS = (("step.png", step_png), ("bode.png", bode_png))


def write_outputs(result, out_dir, name: str, lang: str | None = None) -> dict:
    """Write ``netlists/<name>.cir`` and ``reports/<name>/`` under ``out_dir``.

    Every file goes through a temporary file and a rename; the paths are
    recorded in ``result.files`` before result.json is written, so it lists itself.

    Parameters
    ----------
    result : PlantResult
        The plant.
    out_dir : path-like
        The folder.
    name : str
        The design's name.
    lang : str or None
        The build sheet's language (None: the current one, see :func:`summary_text`).

    Returns
    -------
    dict
        The files written.
    """
    texts = {"waveforms_csv": ("waveforms.csv", waveforms_csv), "bom_csv": ("bom.csv", lambda r: bom_csv(bom(r)))}
    texts.update(prbs_texts(result))
    texts.update(csv_texts(result))   # monte-carlo.csv: one row per sample, every varied part and figure
    prbs_plots = (("prbs.png", prbs_png),) if result.prbs is not None else ()
    with language(lang):
        return write_design(result, out_dir, name, PLOTS + prbs_plots + histogram_plots(result), schematic,
                            lambda svg: sections(result, schematic_svg=svg), title_of(result), texts)
