"""The PID build sheet: bill of materials for every part, target vs achieved,
the checks, closed-loop figures (analytic, ideal PID, SPICE), the expected
scope waveform and levels at every op-amp output (as the seed photographs
them, Figures 80-89), and the plots. Rendered as Markdown, self-contained
HTML and terminal text from one description (:mod:`designer.report`)."""

from __future__ import annotations

import math
import time

import numpy as np

from ..core import eseries
from ..core.units import format_eng
from ..report import document as R
from ..report.bundle import bundle_paths, write_bundle
from ..report.plots import png_bytes, step_plot
from .model import OPAMP_OUTPUTS
from .tuning import MODEL_NAMES

#: what each block's output looks like on the scope for a square-wave reference
SHAPES = {
    "difference": "error y - r: a spike of -step at each rising edge that decays as the plant catches up "
                  "(seed Fig. 79/88)",
    "inverter": "the error inverted: r - y (seed Fig. 81)",
    "differentiator": "short spikes at the edges of the error, decaying with R12 C3 (seed Fig. 85)",
    "integrator": "ramps while the error is large, then flattens at the level that holds the output "
                  "(seed Fig. 83)",
    "summer": "the three actions added (and inverted): a kick at each edge, then a level (seed Fig. 86)",
    "gain": "the controller output u = Kp (...): the summer's waveform times R3/R4 (seed Fig. 87)",
    "plant": "the controlled output y (seed Fig. 89/90)",
}
METRICS = (("overshoot_pct", "overshoot Mp", lambda v: "n/a" if v is None else f"{v:.4g} %"),
           ("peak_time_s", "peak time tp", R.fmt_time),
           ("rise_time_s", "rise time tr (10-90 %)", R.fmt_time),
           ("settling_time_s", "settling time ts (2 %)", R.fmt_time),
           ("final_value", "final value", lambda v: "n/a" if v is None else f"{v:.4g} V"))


def title_of(result) -> str:
    t = result.tuning
    return (f"Op-amp PID ({t.method}: Kp {t.kp:.4g}, Ti {format_eng(t.ti_s, 's')}, "
            f"Td {format_eng(t.td_s, 's')}) for the plant fn {result.plant.fn_hz:.5g} Hz, "
            f"zeta {result.plant.zeta:.3g}, with {result.opamp.name}")


def _v(x, unit="V", digits=4):
    return "n/a" if x is None or (isinstance(x, float) and not math.isfinite(x)) else format_eng(x, unit, digits)


def verdict_text(result) -> str:
    d = result.to_dict()
    failed = [c["name"] for c in d["checks"] if not c["ok"]]
    a = d["closed_loop"]["analytic"]
    s = d["closed_loop"]["spice"]
    parts = []
    if a.get("stable") is False:
        parts.append("the analytic loop with the op-amp poles is UNSTABLE")
    elif a.get("overshoot_pct") is not None:
        parts.append(f"analytic: {a['overshoot_pct']:.3g} % overshoot, settles (2 %) in "
                     f"{_v(a['settling_time_s'], 's')}")
    if s is not None:
        what = []
        if s.get("saturated"):
            what.append("op-amps saturate")
        if not s.get("stable", True):
            what.append("the loop oscillates or latches")
        if s.get("overshoot_pct") is not None and not what:
            what.append(f"{s['overshoot_pct']:.3g} % overshoot, nrms {s['nrms']:.3g}" if s.get("nrms") is not None
                        else f"{s['overshoot_pct']:.3g} % overshoot")
        parts.append("SPICE: " + ", ".join(what))
    parts.append("all checks pass" if not failed else "failed checks: " + ", ".join(failed))
    return "; ".join(parts) + "."


def sections(result, with_images: bool = True) -> list:
    d = result.to_dict()
    p = result.parts
    amp = result.opamp
    tun = d["tuning"]
    ser = d["series"] or {"r": "as given", "c": "as given", "r_tolerance_pct": None, "c_tolerance_pct": None}
    out = [("Verdict", [R.text(verdict_text(result))] + [R.text(n) for n in d["notes"]])]

    # tuning
    blocks = [R.text(f"Method: {tun['method']}. Kp = {tun['kp']:.4g}, Ti = {_v(tun['ti_s'], 's')}, "
                     f"Td = {_v(tun['td_s'], 's')}.")]
    rc, fit = tun.get("reaction_curve"), tun.get("fopdt_fit")
    if rc is not None:
        blocks.append(R.text(
            f"Reaction curve of the plant as built: inflection at {_v(rc['t_inflection_s'], 's')} "
            f"(y = {rc['y_inflection']:.4g}), tangent slope {rc['slope_per_s']:.5g} /s, K = {rc['K']:.4g}, "
            f"L = {_v(rc['L_s'], 's')}, T = {_v(rc['T_s'], 's')} (the tangent reaches the final value at "
            f"{_v(rc['t_tangent_final_s'], 's')}; T is measured from L). ZN's rule uses this tangent."))
    if fit is not None:
        how = ""
        if not fit["valid"]:
            how = (f" The step overshoots {rc['overshoot_pct']:.3g} %, which no FOPDT model can follow: treat "
                   "the rules below as starting points." if rc is not None and rc["overshoot_pct"] > 2.0
                   else f" The fit is poor: {fit['note']}.")
        blocks.append(R.text(
            f"Least-squares FOPDT K e^(-L s)/(T s + 1) of the same step (the model Cohen-Coon, CHR, AMIGO and "
            f"SIMC were derived for): K = {fit['K']:.4g}, L = {_v(fit['L_s'], 's')}, T = {_v(fit['T_s'], 's')}"
            + ("" if fit.get("rms_residual") is None else f", rms residual {fit['rms_residual']:.3g}") + "."
            + how))
    if d["rules"]:
        rows = [[r["method"], _model_cell(r.get("model")), f"{r['kp']:.4g}", _v(r["ti_s"], "s"),
                 _v(r["td_s"], "s")] for r in d["rules"]]
        blocks.append(R.table(["rule", "model it uses (K, L, T)", "Kp", "Ti", "Td"], rows))
    if d.get("optimizer"):
        b = d["optimizer"]["best"]
        blocks.append(R.text(
            f"Optimiser: {d['optimizer']['message']} ({d['optimizer']['evaluations']} evaluations); predicted "
            f"overshoot {_fmt(b['overshoot_pct'], '%')}, settling {_v(b['settling_time_s'], 's')}, worst swing "
            f"{_fmt(_pct(b['swing_ratio']), '%')} of the rails, worst slew delay {_fmt(_pct(b['slew_ratio']), '%')} "
            "of its budget" + ("" if b["stable"] else " (the best point found is an unstable loop)") + "."))
    out.append(("Tuning", blocks))

    # BOM
    rt, ct = ser.get("r_tolerance_pct"), ser.get("c_tolerance_pct")
    roles = {"R3": "U6 feedback (final gain)", "R4": "U6 input (from the summer)", "R5": "U5 feedback (summer)",
             "R6": "U5 input from U2 (proportional)", "R7": "U5 input from U3 (derivative)",
             "R8": "U5 input from U4 (integral)", "R9": "U2 feedback (unity inverter)", "R10": "U2 input",
             "R11": "U3 feedback (differentiator)", "R12": "U3 input, in series with C3",
             "R13": "U4 feedback, parallel to C4 (integrator leak)", "R14": "U4 input (integrator)",
             "R15": "U1 from the reference r to the inverting input", "R16": "U1 feedback",
             "R17": "U1 from the plant output y to the non-inverting input",
             "R18": "U1 non-inverting input to ground"}
    rows = []
    for ref, v in p.resistors().items():
        rows.append(R.part_row(ref, v, "Ohm", roles[ref], ser["r"], rt))
    for ref, v, role in (("C3", p.c3, "U3 input, in series with R12 (derivative)"),
                         ("C4", p.c4, "U4 feedback (integrator)")):
        if v is not None:
            rows.append(R.part_row(ref, v, "F", role, ser["c"], ct))
    for ref, role, _ in OPAMP_OUTPUTS:
        if (ref == "U3" and not p.has_derivative) or role == "plant":
            continue  # the plant's op-amp is listed with the plant's parts
        rows.append([ref, amp.name, "", "", "", f"{role} op-amp, {amp.vcc:g} V / {amp.vee:g} V"])
    pl = result.plant
    # a plant designed here comes from the spec's series (whatever the controller's parts are)
    designed = result.plant_source.startswith("design-plant")
    prs, pcs = (result.spec.r_series, result.spec.c_series) if designed else (None, None)
    prt, pct = ((100 * eseries.TOLERANCE[prs], 100 * eseries.TOLERANCE[pcs]) if designed else (None, None))
    rows += [R.part_row("R1 (plant)", pl.r1, "Ohm", "Sallen-Key input resistor", prs, prt),
             R.part_row("R2 (plant)", pl.r2, "Ohm", "Sallen-Key, to the non-inverting input", prs, prt),
             R.part_row("C1 (plant)", pl.c1, "F", "Sallen-Key, non-inverting input to ground", pcs, pct),
             R.part_row("C2 (plant)", pl.c2, "F", "Sallen-Key, feedback from the R1-R2 node", pcs, pct)]
    if pl.r3 is not None:
        rows += [R.part_row("R3 (plant)", pl.r3, "Ohm", "Sallen-Key gain, to ground", prs, prt),
                 R.part_row("R4 (plant)", pl.r4, "Ohm", "Sallen-Key gain, feedback", prs, prt)]
    rows.append(["U7", amp.name, "", "", "", "plant op-amp (Sallen-Key)"])
    out.append(("Bill of materials", [
        R.table(["Ref", "Value", "Code", "Series", "Tolerance", "Where"], rows),
        R.text("Signal path: r -> U1 (ve = y - r) -> U2 / U3 / U4 in parallel -> U5 summer -> U6 -> u -> "
               "plant -> y, fed back to U1. Kp = R5 R3/(R6 R4), Ti = R8 R14 C4/R6, Td = R6 R11 C3/R7.")]))

    # target vs achieved
    ach = d["achieved"]
    err = ach["errors_pct"]
    rows = [["Kp", f"{tun['kp']:.4g}", f"{ach['kp']:.4g}", R.fmt_pct(err["kp"])],
            ["Ti", _v(tun["ti_s"], "s"), _v(ach["ti_s"], "s"), R.fmt_pct(err["ti"])],
            ["Td", _v(tun["td_s"], "s"), _v(ach["td_s"], "s"), R.fmt_pct(err.get("td"))],
            ["integrator corner 1/(2 pi R13 C4)", "", _v(ach["f_integrator_hz"], "Hz"), ""],
            ["derivative filter 1/(2 pi R12 C3)", "", _v(ach["f_differentiator_hz"], "Hz"), ""]]
    for stage, ng in ach["noise_gains"].items():
        rows.append([f"{stage} stage: noise gain, bandwidth", "", f"{ng:.3g}, "
                     f"{_v(ach['stage_bandwidths_hz'][stage], 'Hz')}", ""])
    out.append(("Target and achieved", [R.table(["", "target", "achieved", "error"], rows)]))

    out.append(("Checks", [R.table(["check", "result", "detail"],
                                   [[c["name"], "ok" if c["ok"] else "FAILED", c["detail"]] for c in d["checks"]])]))

    # closed loop
    cl = d["closed_loop"]
    a, i, s = cl["analytic"], cl["ideal_pid"], cl["spice"] or {}
    rows = []
    for key, label, f in METRICS:
        rows.append([label, f(i.get(key)), f(a.get(key)), f(s.get(key)) if s else "not simulated"])
    rows.append(["stable", "", str(a.get("stable")), str(s.get("stable")) if s else ""])
    rows.append(["saturated", "", "", str(s.get("saturated")) if s else ""])
    blocks = [R.table(["", "ideal PID + ideal plant", f"realised (with {amp.name})", "SPICE"], rows)]
    mg = cl["margins"]
    blocks.append(R.text(
        f"Loop with the op-amp poles: phase margin {_fmt(mg.get('phase_margin_deg'), 'deg')} at "
        f"{_v(mg.get('crossover_hz'), 'Hz')}, gain margin {_fmt(mg.get('gain_margin_db'), 'dB')}. "
        f"Closed-loop DC gain {a.get('dc_gain', float('nan')):.4g} (steady-state error "
        f"{_fmt(a.get('steady_state_error_pct'), '%')})."))
    if s:
        v = cl["verdict"]
        blocks.append(R.text(
            f"SPICE vs analytic: overshoot {_fmt(v.get('overshoot_delta_pp'), 'pp', signed=True)}, nrms "
            f"{_fmt(s.get('nrms'), '')} (below 1 is agreement); "
            + ("they agree." if v["agree"] else
               ("the difference is explained by the failed checks: " + ", ".join(v["explained_by"]) + "."
                if v["explained_by"] else "they disagree and no check explains it."))))
    if with_images:
        blocks += [R.image("closed-loop.png", "closed-loop step"), R.image("controller.png", "controller output"),
                   R.image("loop-bode.png", "loop gain")]
    out.append(("Closed loop", blocks))

    # expected scope readings
    tsig = d["test_signal"]
    la, ls = d["levels"]["analytic"] or {}, d["levels"]["spice"] or {}
    rows = []
    for ref, role, sig in OPAMP_OUTPUTS:
        if role not in la and role not in ls:
            continue
        x, y = la.get(role, {}), ls.get(role, {})
        sat = y.get("time_high_s", 0) + y.get("time_low_s", 0) if y else None
        rows.append([ref, role, sig, f"{_v(x.get('v_min'))} .. {_v(x.get('v_max'))}",
                     f"{_v(y.get('v_min'))} .. {_v(y.get('v_max'))}" if y else "",
                     "" if not x else f"{x['slope_v_per_s'] / 1e6:.3g} V/us",
                     "" if sat is None else _v(sat, "s"), SHAPES[role]])
    blocks = [R.text(f"Bench test: square wave 0 -> {tsig['high_v']:g} V at {tsig['frequency_hz']:g} Hz "
                     f"(edges {_v(tsig['edge_s'], 's')}); the output should settle near "
                     f"{tsig['expected_final_v']:.4g} V. Probe each op-amp output against ground; levels cover the "
                     "whole period (the falling half mirrors the rising one)."),
              R.table(["op-amp", "block", "node", "expected (analytic)", "SPICE", "fastest slope",
                       "time at a rail (SPICE)", "what the scope shows"], rows)]
    if with_images:
        blocks.append(R.image("blocks.png", "every op-amp output"))
        blocks.append(R.image("reaction-curve.png", "plant reaction curve"))
    out.append(("Expected scope readings", blocks))
    return out


def _model_cell(m) -> str:
    if not m:
        return ""
    return (f"{MODEL_NAMES.get(m['source'], m['source'])}: {m['K']:.4g}, {_v(m['L_s'], 's')}, "
            f"{_v(m['T_s'], 's')}")


def _pct(ratio):
    return None if ratio is None else 100 * ratio


def _fmt(v, unit, signed=False):
    if v is None or (isinstance(v, float) and not math.isfinite(v)):
        return "n/a"
    return (f"{v:+.3g}" if signed else f"{v:.3g}") + (f" {unit}" if unit else "")


def summary_text(result) -> str:
    return R.to_text(title_of(result), sections(result, with_images=False))


# ---- plots -------------------------------------------------------------------

def _plt():
    import matplotlib
    matplotlib.use("Agg")
    import matplotlib.pyplot as plt
    return plt


def plots(result) -> dict:
    w = result.waveforms
    t = w["t"]
    a = w["analytic"]
    sp = w.get("spice")
    amp = result.opamp.name
    curves = {f"realised loop, analytic ({amp})": a["y"], "ideal PID, ideal plant": w["ideal_pid"]}
    if sp is not None:
        curves["SPICE (ngspice)"] = sp["y"]
    curves["plant alone (open loop)"] = w["open_loop"]
    images = {"closed-loop.png": step_plot(t, curves, f"Closed-loop step, 0 -> {result.test.amplitude_v:g} V")}
    cu = {"u analytic": a["u"]}
    if sp is not None:
        cu["u SPICE"] = sp["u"]
    images["controller.png"] = step_plot(t, cu, "Controller output u (plant input)", "u (V)")
    images["blocks.png"] = _blocks_plot(result)
    images["loop-bode.png"] = _bode_plot(result)
    images["reaction-curve.png"] = _reaction_plot(result)
    return images


def _blocks_plot(result) -> bytes:
    plt = _plt()
    w = result.waveforms
    t = w["t"] * 1e6
    sp = w.get("spice")
    sigs = [(ref, role, s) for ref, role, s in OPAMP_OUTPUTS if s in w["analytic"]]
    fig, axes = plt.subplots(len(sigs), 1, figsize=(7.5, 1.5 * len(sigs)), sharex=True)
    for ax, (ref, role, s) in zip(axes, sigs):
        ax.plot(t, w["analytic"][s], "-", lw=1.2, label="analytic")
        if sp is not None and s in sp:
            ax.plot(t, sp[s], "--", lw=1.2, label="SPICE")
        amp = result.opamp
        peak = max(np.nanmax(np.abs(w["analytic"][s])),
                   np.nanmax(np.abs(sp[s])) if sp is not None and s in sp else 0.0)
        if not amp.ideal and peak > 0.5 * amp.vout_max:   # rails only when the signal gets near them
            for lvl in (amp.vout_max, amp.vout_min):
                ax.axhline(lvl, color="r", lw=0.6, alpha=0.5)
        # an unstable analytic loop runs away: keep the axis on what a scope shows
        lim = 1.15 * max(abs(amp.vcc), abs(amp.vee))
        if np.nanmax(np.abs(w["analytic"][s])) > lim:
            ax.set_ylim(-lim, lim)
        ax.set_ylabel(f"{ref} {s}", fontsize=8)
        ax.grid(True, alpha=0.3)
    axes[0].legend(fontsize=7, loc="upper right")
    axes[0].set_title("Every op-amp output (red: output limits, drawn when reached)")
    axes[-1].set_xlabel("time after the step (us)")
    return png_bytes(fig)


def _bode_plot(result) -> bytes:
    from .design import plant_model
    from .model import loop_gain
    plt = _plt()
    w = result.waveforms["bode_w"]
    pn, pd = plant_model(result.plant, result.opamp)
    L = loop_gain(result.parts, result.opamp, pn, pd, w)
    f = w / (2 * np.pi)
    fig, (a1, a2) = plt.subplots(2, 1, figsize=(7.5, 5.5), sharex=True)
    a1.semilogx(f, 20 * np.log10(np.abs(L)))
    a1.axhline(0, color="k", lw=0.6)
    a2.semilogx(f, np.degrees(np.unwrap(np.angle(L))))
    a2.axhline(-180, color="k", lw=0.6)
    mg = result.margins
    if math.isfinite(mg.get("crossover_hz", math.nan)):
        for ax in (a1, a2):
            ax.axvline(mg["crossover_hz"], color="r", lw=0.8, ls="--")
    a1.set_title(f"Loop gain with {result.opamp.name} poles: phase margin "
                 f"{_fmt(mg.get('phase_margin_deg'), 'deg')}")
    a1.set_ylabel("gain (dB)")
    a2.set_ylabel("phase (deg)")
    a2.set_xlabel("frequency (Hz)")
    for ax in (a1, a2):
        ax.grid(True, which="both", alpha=0.3)
    return png_bytes(fig)


def _reaction_plot(result) -> bytes:
    plt = _plt()
    tp, yp = result.waveforms["reaction_curve"]
    c = result.tuning.curve
    fig, ax = plt.subplots(figsize=(7.5, 4))
    ax.plot(tp * 1e6, yp, label="plant step response")
    if c is not None:
        tt = np.linspace(c.L_s, c.t_tangent_final_s, 50)
        ax.plot(tt * 1e6, c.slope_per_s * (tt - c.t_inflection_s) + c.y_inflection, "--", label="tangent")
        ax.plot([c.t_inflection_s * 1e6], [c.y_inflection], "o", label="inflection")
        ax.axhline(c.K, color="k", lw=0.6)
        if c.fit is not None:
            f = c.fit
            ax.plot(tp * 1e6, f.K * (1 - np.exp(-np.clip(tp - f.L_s, 0.0, None) / f.T_s)), ":",
                    label="least-squares FOPDT")
        ax.set_xlim(0, min(tp[-1], 6 * c.t_tangent_final_s) * 1e6)
        ax.set_title(f"Reaction curve: L = {format_eng(c.L_s, 's')}, T = {format_eng(c.T_s, 's')}")
    ax.set_xlabel("time (us)")
    ax.set_ylabel("output per volt of step")
    ax.grid(True, alpha=0.3)
    ax.legend()
    return png_bytes(fig)


def write_outputs(result, out_dir, name: str) -> dict:
    """``netlists/<name>.cir`` and ``reports/<name>/`` (build sheet, result.json,
    plots) under ``out_dir``, each written atomically."""
    tick = time.perf_counter()
    images = plots(result)
    result.files = bundle_paths(out_dir, name, images)
    write_bundle(result.files, result.deck, images, title_of(result), sections(result), result.to_dict())
    result.timings["report_s"] = time.perf_counter() - tick
    return result.files
