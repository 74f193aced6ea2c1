"""The plant's build sheet, terminal summary and files (netlist, report folder),
rendered from the typed :class:`~designer.plant.result.PlantResult` as it is:
nothing here computes a figure of the design."""

from __future__ import annotations

import io
import time

import numpy as np

from ..core.units import format_eng
from ..report import document as R
from ..report.bundle import bundle_paths, write_bundle
from ..report.plots import bode_plot, step_plot

METRIC_ROWS = (("overshoot_pct", "overshoot Mp", lambda v: "n/a" if v is None else f"{v:.4g} %"),
               ("peak_time_s", "peak time tp", R.fmt_time),
               ("rise_time_s", "rise time tr (10-90 %)", R.fmt_time),
               ("settling_time_s", "settling time ts (2 %)", R.fmt_time))


def title_of(result) -> str:
    s = result.target
    if result.mode == "analyze":
        return f"Sallen-Key plant as built: fn {result.built.fn_hz:.5g} Hz, zeta {result.built.zeta:.4g}"
    return f"Sallen-Key plant: fc {s.fc_hz:g} Hz, zeta {s.zeta:g}, gain {s.gain:g}"


def sections(result, with_images: bool = True) -> list:
    """The build sheet as (heading, blocks) sections (see :mod:`designer.report.document`)."""
    out = [("Bill of materials", [_bill(result)]),
           ("Wiring", [R.table(["from", "to", "part"], wiring(result.built, result.opamp))]),
           ("Target and achieved", _targets(result)),
           ("Bench test", _bench(result)),
           ("Checks", [R.table(["check", "result", "detail"],
                               [[c.title, "ok" if c.ok else "FAILED", c.detail] for c in result.checks])]),
           ("Sensitivity", _sensitivity(result))]
    if result.alternatives:
        out.append(("Alternatives (best first)", [_alternatives(result.alternatives)]))
    if result.spice is not None:
        out.append(("SPICE against the analytic models", _spice(result)))
    if result.notes:
        out.append(("Notes", [R.text(n) for n in result.notes]))
    if with_images:
        out.append(("Plots", [R.image("step.png", "step response: analytic and SPICE"),
                              R.image("bode.png", "Bode plot")]))
    return out


def _bill(result):
    b, amp, lab = result.built, result.opamp, result.sourcing.parts
    where = {"R1": "input resistor", "R2": "to the non-inverting input", "C1": "non-inverting input to ground",
             "C2": "R1-R2 node to the output (feedback)", "R3": "gain: inverting input to ground",
             "R4": "gain: output to inverting input"}
    bom = [R.part_row(ref, getattr(b, ref.lower()), "Ohm" if ref[0] == "R" else "F", role,
                      lab[ref].series, lab[ref].tolerance_pct)
           for ref, role in where.items() if ref in lab]
    bom.append(["U1", amp.name, "", "", "", f"op-amp on {amp.vcc:g} V / {amp.vee:g} V"
                + (" (follower: output to inverting input)" if b.r3 is None else "")])
    return R.table(["Ref", "Value", "Code", "Series", "Tolerance", "Where"], bom)


def _targets(result):
    s, ideal = result.target, result.ideal
    fig, opa = result.analytic.figures, result.analytic_opamp.figures
    rows = [["fn", _f(s.fc_hz, "Hz"), _f(ideal and ideal.fn_hz, "Hz"), _f(fig.fn_hz, "Hz"),
             R.fmt_pct(fig.fn_error_pct), _f(opa.fn_hz, "Hz"), R.fmt_pct(opa.fn_error_pct)],
            ["zeta", _n(s.zeta), _n(ideal and ideal.zeta), _n(fig.zeta), R.fmt_pct(fig.zeta_error_pct),
             _n(opa.zeta), R.fmt_pct(opa.zeta_error_pct)],
            ["Q", _n(s.q), _n(ideal and ideal.q), _n(result.built.q), "", _n(opa.q), ""]]
    blocks = [R.table(["", "target", "exact parts", "built (ideal op-amp)", "error",
                       f"built with {result.opamp.name}", "error"], rows)]
    if result.ratios.m is not None:
        blocks.append(R.text(f"Ratios: m = R1/R2 = {result.ratios.m:.4g}, n = C2/C1 = {result.ratios.n:.4g}."))
    return blocks


def _bench(result):
    ts, tol, spice = result.test, result.tolerance, result.spice
    expected = result.analytic_opamp.step
    rows = []
    for key, label, f in METRIC_ROWS:
        band = getattr(tol, key)
        rows.append([label, f(_value(expected, key)), f(_value(spice.step, key)) if spice else "not simulated",
                     f"{f(band.lo)} .. {f(band.hi)}"])
    amp_v = ts.amplitude_v
    rows.append(["peak output", format_eng(expected.peak_value * amp_v, "V"),
                 format_eng(spice.step.peak_value * amp_v, "V") if spice else "", ""])
    return [R.text(f"Function generator: square wave {format_eng(ts.frequency_hz, 'Hz')}, "
                   f"{format_eng(amp_v, 'V')} peak-to-peak with {format_eng(amp_v / 2, 'V')} "
                   f"offset (0 V to {format_eng(amp_v, 'V')}), into R1. Scope channel 1 on the input, "
                   f"channel 2 on the op-amp output; trigger on the rising edge, "
                   f"{format_eng(ts.half_period_s / 10, 's')}/div."),
            R.table(["reading (rising edge)", f"expected ({result.opamp.name} model)", "SPICE",
                     f"band from tolerances (R {tol.r_tolerance_pct:g} %, C {tol.c_tolerance_pct:g} %)"], rows)]


def _sensitivity(result):
    amp = result.opamp.name
    sens, sens_o = result.analytic.sensitivity, result.analytic_opamp.sensitivity
    rows = [[k, f"{v.wn:+.3f}", f"{v.zeta:+.3f}",
             f"{sens_o[k].wn:+.3f}" if k in sens_o else "", f"{sens_o[k].zeta:+.3f}" if k in sens_o else ""]
            for k, v in sens.items()]
    rows += [[k, "", "", f"{v.wn:+.4f}", f"{v.zeta:+.4f}"] for k, v in sens_o.items() if k not in sens]
    return [R.text("Relative sensitivity S = d ln(y) / d ln(x): a 1 % change in the part changes y by S %."),
            R.table(["part", "S(wn)", "S(zeta)", f"S(wn) with {amp}", f"S(zeta) with {amp}"], rows)]


def _alternatives(alternatives):
    rows = [[i + 1, " / ".join(format_eng(v, u, 3) for v, u in ((a.r1, "Ohm"), (a.r2, "Ohm"), (a.c1, "F"),
                                                                (a.c2, "F"))),
             _f(a.figures.fn_hz, "Hz"), _n(a.figures.zeta), R.fmt_pct(a.figures.fn_error_pct),
             R.fmt_pct(a.figures.zeta_error_pct)]
            for i, a in enumerate(alternatives)]
    return R.table(["#", "R1 / R2 / C1 / C2", "fn", "zeta", "fn error", "zeta error"], rows)


def _spice(result):
    spice, amp = result.spice, result.opamp.name
    cmp_ = spice.comparison

    def delta(x, key):
        if x["delta"] is None:
            return "n/a"
        if key == "overshoot_pct":
            return f"{x['delta']:+.3g} pp"
        return f"{format_eng(x['delta'], 's', 3)} ({R.fmt_pct(x['delta_pct'])})"

    rows = [[label, delta(cmp_.vs_ideal[key], key), delta(cmp_.vs_opamp[key], key)] for key, label, _ in METRIC_ROWS]
    rows.append(["normalised RMS waveform error", f"{spice.nrms_ideal:.3g}", f"{spice.nrms:.3g}"])
    return [R.text(f"ngspice ({spice.simulator} backend), {amp} behavioural model. Deltas are SPICE minus "
                   f"model; NRMS = RMS of (model - SPICE) / (1 % of |model| + {format_eng(cmp_.nrms_abstol_v, 'V')})"
                   ". SPICE agrees with the op-amp-aware model when NRMS is below 1 and overshoot is within 1 pp, "
                   "peak and rise time within 2 %, settling time within 5 % (or half a ringing period): "
                   + ("it does." if cmp_.passed else "it does NOT (" + "; ".join(cmp_.disagreements) + ").")),
            R.table(["metric", "vs ideal model", f"vs {amp}-aware model"], rows)]


def wiring(b, amp) -> list:
    """Point-to-point wiring for the breadboard, with the op-amp's DIP-8 pin numbers."""
    pins = amp.pins or {}
    def pin(name, label):
        return f"U1 pin {pins[name]} ({label})" if name in pins else f"U1 {label}"
    rows = [["generator output", "node A", f"R1 {R.value_code(b.r1)}"],
            ["node A", pin("inp", "+ input"), f"R2 {R.value_code(b.r2)}"],
            [pin("inp", "+ input"), "ground", f"C1 {R.value_code(b.c1)}"],
            ["node A", pin("out", "output"), f"C2 {R.value_code(b.c2)}"]]
    if b.r3 is None:
        rows.append([pin("inn", "- input"), pin("out", "output"), "wire (voltage follower)"])
    else:
        rows += [[pin("inn", "- input"), "ground", f"R3 {R.value_code(b.r3)}"],
                 [pin("out", "output"), pin("inn", "- input"), f"R4 {R.value_code(b.r4)}"]]
    rows += [[pin("vcc", "V+"), f"{amp.vcc:+g} V supply", "100n decoupling to ground"],
             [pin("vee", "V-"), f"{amp.vee:+g} V supply", "100n decoupling to ground"],
             ["generator ground, scope grounds", "ground", "wire"]]
    if pins.get("package"):
        rows.append(["", "", f"{amp.name}: {pins['package']} pinout"])
    return rows


def _f(v, unit):
    return "" if v is None else format_eng(v, unit, 5)


def _value(metrics, key):
    """A step metric for the sheet: None where the response has none (nan)."""
    v = getattr(metrics, key)
    return None if v != v else v


def _n(v):
    return "" if v is None else f"{v:.4g}"


def summary_text(result) -> str:
    """The terminal summary: the build sheet without plots."""
    return R.to_text(title_of(result), sections(result, with_images=False))


def plots(result) -> dict:
    ideal, real = result.analytic, result.analytic_opamp
    amp = result.opamp.name
    curves = {"analytic (ideal op-amp)": ideal.response, f"analytic ({amp} model)": real.response}
    if result.spice is not None:
        curves["SPICE (ngspice)"] = result.spice.response
    fn = result.built.fn_hz
    return {"step.png": step_plot(result.time_s, curves, f"Step response, 0 -> {result.test.amplitude_v:g} V"),
            "bode.png": bode_plot({"ideal op-amp": (ideal.num, ideal.den), f"{amp} model": (real.num, real.den)},
                                  fn / 100, fn * 100, "Plant frequency response")}


def waveforms_csv(result) -> str:
    """The bench period as CSV (``time_s,input_v,output_v,...``; output is SPICE when
    simulated), the format ``identify`` reads: the tool's own scope capture."""
    cols = result.bench.columns()
    buf = io.StringIO()
    np.savetxt(buf, np.column_stack(list(cols.values())), delimiter=",", header=",".join(cols), comments="",
               fmt="%.9g")
    return buf.getvalue()


def write_outputs(result, out_dir, name: str) -> dict:
    """Write ``netlists/<name>.cir`` and ``reports/<name>/`` under ``out_dir``.

    Every file goes through a temporary file and a rename; the paths are
    recorded in ``result.files`` before result.json is written, so it lists itself.
    """
    tick = time.perf_counter()
    images = plots(result)
    result.files = bundle_paths(out_dir, name, images, {"waveforms_csv": "waveforms.csv"})
    write_bundle(result.files, result.deck, images, title_of(result), sections(result), result.to_dict(),
                   {"waveforms_csv": waveforms_csv(result)})
    result.timings["report_s"] = time.perf_counter() - tick
    return result.files
