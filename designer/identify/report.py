"""What ``identify`` and ``identify-freq`` print and draw: the ranked methods
table of each command, the comparison with a design, and the PNG plots of the
data against the best models. Everything here reads the typed results
(:class:`~.step.IdentifyResult`, :class:`~.frequency.FreqIdentifyResult`,
:class:`~.against.Comparison`) and recomputes nothing but the models' curves."""

from __future__ import annotations

import math

import numpy as np

from ..core.units import format_eng
from ..report.plots import png_bytes

__all__ = ["bode_fit_plot", "broadband_plot", "broadband_text", "fit_plot", "freq_text", "ranked_candidates", "record_axes",
           "step_text"]


def format_params(p: dict, corners: bool = False) -> str:
    """Parameters with units: K 2, tau 1.5 ms, theta 200 us, wn 2.2e4 rad/s (3.5 kHz), zeta 0.21;
    with ``corners``, each time constant also as the corner frequency a Bode plot shows."""
    out = []
    for k, v in p.items():
        if v is None or (isinstance(v, float) and not math.isfinite(v)):
            out.append(f"{k} n/a")
        elif k.endswith("_rad_s"):
            out.append(f"{k[:-6]} {v:.4g} rad/s ({format_eng(v / (2 * math.pi), 'Hz')})")
        elif corners and k.startswith("tau") and v > 0:
            out.append(f"{k[:-2]} {format_eng(v, 's')} (corner {format_eng(1 / (2 * math.pi * v), 'Hz')})")
        elif k.endswith("_s"):
            out.append(f"{k[:-2]} {format_eng(v, 's')}")
        else:
            out.append(f"{k} {v:.4g}")
    return ", ".join(out)


def _g(v) -> str:
    return "n/a" if v is None or not math.isfinite(v) else f"{v:.4g}"


def _pct(v) -> str:
    return "n/a" if v is None or not math.isfinite(v) else f"{100.0 * v:.3g} %"


def methods_table(methods, *, name_width: int, params_width: int, corners: bool,
                  scores) -> list:
    """The ranked methods, one row each (and its note below it): rank, name,
    model, parameters, then ``scores``, a list of ``(title, width, text(m))``."""
    head = (f"{'#':>2}  {'method':<{name_width}} {'model':<12} {'parameters':<{params_width}} "
            + " ".join(f"{title:>{w}}" for title, w, _ in scores) + "  ok")
    lines = [head, "-" * len(head)]
    for i, m in enumerate(methods, 1):
        lines.append(f"{i:>2}  {m.name:<{name_width}} {m.model:<12} "
                     f"{format_params(m.params, corners):<{params_width}} "
                     + " ".join(f"{text(m):>{w}}" for _, w, text in scores)
                     + f"  {'yes' if m.valid else 'NO'}")
        if m.note:
            lines.append(f"{'':>4}{m.note}")
    return lines


def _best_line(best, corners: bool = False) -> str:
    if best is None:
        return "Best: none of the methods is valid for these data"
    return f"Best: {best.name} ({best.model}): {format_params(best.params, corners)}"


def _capture_line(cap) -> str:
    return (f"Capture: {cap.source} ({cap.fmt}, {cap.samples} samples, output {cap.output_name!r}"
            + (f", input {cap.input_name!r}" if cap.input_name else "") + ")")


def step_text(result) -> str:
    """The ``identify`` table of an :class:`~.step.IdentifyResult`.

    Parameters
    ----------
    result : IdentifyResult
        The step identification.

    Returns
    -------
    str
        The table's text.
    """
    s, cap = result.step, result.capture
    lines = []
    if cap is not None:
        lines.append(_capture_line(cap))
    span = s.y_final - s.y0
    noise = f"{100 * s.sigma / abs(span):.2g} %" if span else "n/a"
    lines.append(f"Step at {format_eng(s.t_step, 's')}, amplitude {s.amplitude:.4g}; "
                 f"baseline y0 = {s.y0:.4g}, final value {s.y_final:.4g}, "
                 f"static gain K = {s.yf:.4g}")
    edges = (f"{s.n_steps} edges averaged (full edges in the record: {s.rising} rising, "
             f"{s.falling} falling; one way averaged, the other kept apart)"
             if s.n_steps > 1 else "one edge")
    lines.append(f"Noise {s.sigma:.3g} ({noise} of the step)"
                 + (f", quantisation step {s.lsb:.3g}" if s.lsb else "")
                 + f"; {edges}; sample interval {format_eng(s.dt, 's')}")
    if s.nonlinear:
        lines.append(f"NON-LINEAR: {s.nonlinear}; no linear model is marked valid")
    for n in (list(cap.notes) if cap is not None else []) + s.notes:
        lines.append(f"  note: {n}")
    m = result.measured
    if m is not None:
        lines.append("Measured: overshoot "
                     + (f"{m.overshoot_pct:.2f} %" if not math.isnan(m.overshoot_pct) else "n/a")
                     + f", peak time {format_eng(m.peak_time_s, 's')}"
                     + f", rise time (10-90 %) {format_eng(m.rise_time_s, 's')}"
                     + ", (0-100 %) " + (format_eng(m.rise_time_0_100_s, 's')
                                         if math.isfinite(m.rise_time_0_100_s) else "n/a")
                     + f", settling (2 %) {format_eng(m.settling_time_s, 's')}")
    lines += ["", ("Methods ranked by IAE (integral of |data - model| over the response; "
                   "lower is better)")]
    lines += methods_table(result.methods, name_width=24, params_width=52, corners=False,
                           scores=[("IAE", 10, lambda r: _g(r.iae)), ("ISE", 10, lambda r: _g(r.ise))])
    lines += ["", "IAE in output units x s, ISE in output units^2 x s.", _best_line(result.best)]
    if result.comparison is not None:
        lines.append("")
        lines.extend(comparison_text(result.comparison))
    if getattr(result, "assessment", None) is not None:
        lines += [""] + validation_text(result.assessment)
    return "\n".join(lines)


def _verdict(c) -> str:
    if c.validation is None:
        return "-"
    w, x = c.validation.whiteness, c.validation.cross
    return f"{'white' if w.inside else f'{w.worst:.1f}x'}/{'ok' if x.inside else f'{x.worst:.1f}x'}"


def ranked_candidates(a) -> list:
    """The candidates of an :class:`~.assess.Assessment` as its tables list them:
    the best first (a tie within the margin can put it after a better fit,
    :mod:`.ranking`), then the valid ones, each group by validation fit.

    Parameters
    ----------
    a : Assessment

    Returns
    -------
    list of Candidate
    """
    best = a.best_candidate
    return sorted(a.candidates, key=lambda c: (c is not best, not c.valid,
                                               -c.fit_percent if math.isfinite(c.fit_percent) else math.inf))


def validation_text(a) -> list:
    """The validation table of an :class:`~.assess.Assessment`: the split, each
    route's models by validation fit, the residual tests' verdicts, the skipped
    routes and why, the best across routes."""
    lines = [f"== validation: every route's models simulated under the recorded input ({a.scope}) ==",
             f"Data: {a.note}; simulated with a {'first' if a.hold == 'foh' else 'zero'}-order hold "
             f"({a.hold}, the better of the two for the output-error FOPDT)"]
    for route, why in a.skipped.items():
        lines.append(f"  skipped: {route}: {why}")
    lines.append("Fit % = 100 (1 - |y - yhat| / |y - mean y|) on the validation data (MATLAB compare); "
                 "residuals: autocorrelation / cross-correlation with past input inside the 99 % band "
                 "('white'/'ok', else the worst lag over the band)")
    lines.append(f"{'route':13s} {'method':24s} {'model':12s} {'fit %':>8s} {'residuals':>11s} {'ok':3s} "
                 "parameters")
    for c in ranked_candidates(a):
        fit = f"{c.fit_percent:8.2f}" if math.isfinite(c.fit_percent) else f"{'-':>8s}"
        lines.append(f"{c.route:13s} {c.name[:24]:24s} {c.kind[:12]:12s} {fit} {_verdict(c):>11s} "
                     f"{'yes' if c.valid else 'no ':3s} {format_params(c.params, False)}"
                     + (f"  ({c.note})" if c.note and not c.valid else ""))
    best = a.best_candidate
    lines.append("Best by validation fit: " + (f"{best.label}, fit {best.fit_percent:.2f} %"
                                                + (f" ({a.ranking})" if getattr(a, "ranking", "") else "")
                                                + f": {format_params(best.params, False)}" if best else
                                                "none valid"))
    return lines


def comparison_text(c) -> list:
    """The lines of an :class:`~.against.Comparison`."""
    lines = [(f"Against the design (identified with {c.model or 'n/a'}; "
              f"tolerances: {c.tolerance_basis}):")]
    fmt = {"fn_hz": lambda v: format_eng(v, "Hz"), "zeta": lambda v: f"{v:.4g}",
           "gain": lambda v: f"{v:.4g}", "overshoot_pct": lambda v: f"{v:.2f} %"}
    for k, q in c.quantities.items():
        f = fmt[k]
        ident = "n/a" if q.identified is None or not math.isfinite(q.identified) else f(q.identified)
        diff = "" if q.difference_pct is None else f" ({q.difference_pct:+.1f} %)"
        lo, hi = q.band
        band = "n/a" if not math.isfinite(lo) else f"{f(lo)} .. {f(hi)}"
        inside = {True: "inside", False: "OUTSIDE", None: "-"}[q.within_tolerance]
        lines.append(f"  {k:<14} design {f(q.design):>12}  identified {ident:>12}{diff}  "
                     f"band {band}  {inside}")
    lines.append(f"  verdict: {c.verdict}")
    return lines


def freq_text(result) -> str:
    """The ``identify-freq`` table of a :class:`~.frequency.FreqIdentifyResult`.

    Parameters
    ----------
    result : FreqIdentifyResult
        The frequency identification.

    Returns
    -------
    str
        The table's text.
    """
    d = result.data
    lines = [f"Table: {d.source or 'data'}: {d.w.size} points, "
             f"{format_eng(d.f_hz[0], 'Hz')} to {format_eng(d.f_hz[-1], 'Hz')}, "
             f"gain in {d.units['gain']}, "
             + (f"phase in {d.units['phase']}" if d.phase is not None else "no phase")
             + (" (inverting: K < 0)" if d.sign < 0 else "")]
    lines += [f"  note: {n}" for n in d.notes]
    lp = result.loop
    if lp is not None:
        lines.append(f"Open loop: low-frequency slope {lp.lf_slope_db_dec:+.1f} dB/decade, "
                     f"crossover {format_eng(lp.crossover_hz, 'Hz')}, phase margin "
                     + (f"{lp.phase_margin_deg:.1f} deg" if lp.phase_margin_deg is not None
                        else "n/a")
                     + ", gain margin "
                     + (f"{lp.gain_margin_db:.1f} dB at {format_eng(lp.phase_crossover_hz, 'Hz')}"
                        if lp.gain_margin_db is not None else "n/a")
                     + (f" ({lp.note})" if lp.note else ""))
    lines += ["", ("Methods ranked by fit error (mean |G_model/G_data - 1| over the table; "
                   "lower is better)")]
    lines += methods_table(result.methods, name_width=15, params_width=84, corners=True,
                           scores=[("error", 9, lambda r: _pct(r.iae))])
    lines += ["", _best_line(result.best, corners=True)]
    return "\n".join(lines)


def _pyplot():
    import matplotlib
    matplotlib.use("Agg")
    import matplotlib.pyplot as plt
    return plt


def fit_plot(result, n_models: int = 3) -> bytes:
    """PNG of the step data against the best ``n_models`` valid models, with the residuals.

    Parameters
    ----------
    result : IdentifyResult
        The step identification.
    n_models : int, optional
        How many valid models to draw.

    Returns
    -------
    bytes
        The PNG file's content.
    """
    from .settle import block_mean
    from .structures import model_step
    plt = _pyplot()
    s = result.step
    t, y = block_mean(s.t_raw, s.y_raw, 20000)
    fig, (ax, axr) = plt.subplots(2, 1, figsize=(8, 6), dpi=110, sharex=True,
                                  gridspec_kw={"height_ratios": [3, 1]})
    tt = t - s.t_step
    ax.plot(tt, y, color="k", lw=2.2, alpha=0.35, label="data")
    shown = [m for m in result.methods if m.valid][:n_models]
    for m, style in zip(shown, ("-", "--", ":")):
        ym = s.y0 + s.amplitude * model_step(m.model, m.params, tt)
        line, = ax.plot(tt, ym, lw=1.2, ls=style, label=f"{m.name} ({m.model}), IAE {m.iae:.3g}")
        axr.plot(tt, y - ym, lw=0.8, ls=style, color=line.get_color())
    for a in (ax, axr):
        a.axvline(0.0, color="k", lw=0.6, ls=":")
        a.grid(True, alpha=0.3)
    axr.set_xlabel("time since the step (s)")
    axr.set_ylabel("data - model")
    ax.set_ylabel(result.capture.output_name if result.capture else "output")
    ax.set_title("Step response: data and best identified models")
    ax.legend(fontsize=8, loc="best")
    fig.tight_layout()
    return png_bytes(fig)


def bode_fit_plot(result, n_models: int = 3) -> bytes:
    """PNG Bode plot of a frequency table and the best ``n_models`` valid models.

    Parameters
    ----------
    result : FreqIdentifyResult
        The frequency identification.
    n_models : int, optional
        How many valid models to draw.

    Returns
    -------
    bytes
        The PNG file's content.
    """
    from .bode_readings import model_phase, model_response
    plt = _pyplot()
    d = result.data
    w = np.geomspace(d.w[0] / 2.0, d.w[-1] * 2.0, 400)
    f = w / (2 * math.pi)
    has_phase = d.phase is not None
    fig, axes = plt.subplots(2 if has_phase else 1, 1, sharex=True,
                             figsize=(8, 6 if has_phase else 4), dpi=110, squeeze=False)
    ax_g = axes[0][0]
    ax_g.semilogx(d.f_hz, d.gain_db, "o", color="k", ms=4, label="data")
    for m in [m for m in result.methods if m.valid][:n_models]:
        g = model_response(m.model, m.params, w)
        ax_g.semilogx(f, 20 * np.log10(np.abs(g)), lw=1.2,
                      label=f"{m.name} ({m.model}), error {100 * m.iae:.2g} %")
        if has_phase:
            axes[1][0].semilogx(f, np.rad2deg(model_phase(m.model, dict(m.params), w)), lw=1.2)
    ax_g.set_ylabel("gain (dB)")
    ax_g.set_title("Frequency response: data and identified models")
    ax_g.grid(True, which="both", alpha=0.3)
    ax_g.legend(fontsize=8, loc="lower left")
    if has_phase:
        ax_p = axes[1][0]
        ax_p.semilogx(d.f_hz, np.rad2deg(d.phase), "o", color="k", ms=4)
        ax_p.set_ylabel("phase (deg)")
        ax_p.grid(True, which="both", alpha=0.3)
    axes[-1][0].set_xlabel("frequency (Hz)")
    fig.tight_layout()
    return png_bytes(fig)


# --------------------------------------------------------------------------- broadband

def broadband_text(result) -> str:
    """The ``identify`` text of a :class:`~.broadband.BroadbandResult`: the
    excitation, the impulse estimate, then the correlation's step methods and
    the spectral estimate's frequency methods, each table as it is for a step
    or a frequency table.

    Parameters
    ----------
    result : BroadbandResult
        The broadband identification.

    Returns
    -------
    str
        The text, one line per row.
    """
    ex, cap = result.excitation, result.capture
    lines = []
    if cap is not None:
        lines.append(_capture_line(cap))
    lines.append(f"{'Input' if ex.kind == 'other' else 'Broadband input'}: {ex.text()}")
    for n in (list(cap.notes) if cap is not None else []) + list(result.notes):
        lines.append(f"  note: {n}")
    est = result.impulse
    if est is not None:
        k = int(np.argmax(np.abs(est.h)))
        lines.append(f"Impulse response (correlation, seed 003 eq. 2.4.19): peak {est.h[k]:.4g} /s "
                     f"at {format_eng(est.t[k], 's')}, step response's final value "
                     f"(static gain) {est.step[-1]:.4g}, settling (2 %) "
                     f"{format_eng(est.settling_s, 's')}, period {format_eng(est.period_s, 's')}"
                     + (" - WRAPPED AROUND" if est.wrapped else ""))
    if result.step_result is not None:
        lines += ["", "== correlation: step methods on the integrated impulse response =="]
        lines += step_text(result.step_result).splitlines()[2:]
    if result.freq_result is not None:
        sp = result.spectrum
        lines += ["", f"== spectral: H = S_yu/S_uu ({sp.how}), coherence "
                      f"{sp.coh.min():.2f} .. {sp.coh.max():.2f} ==",
                  freq_text(result.freq_result)]
    best = result.best
    if ex.kind != "other":      # an input only the output-error route reads: its best is the validation's
        lines += ["", f"Best ({result.method}): " + (f"{best.name} ({best.model}): "
                                                     f"{format_params(best.params, True)}"
                                                     if best else "none valid")]
    if result.segment_length:
        lines.append(f"Welch segment: {result.segment_note}")
    if result.assessment is not None:
        lines += [""] + validation_text(result.assessment)
    return "\n".join(lines)


def residual_axes(pair, models) -> None:
    """The residual tests of validated models on two axes (as ``resid`` draws
    them): the residuals' autocorrelation and their cross-correlation with the
    input, each lag against its 99 % band; each model's stems beside the
    others' (a third of a lag apart), in its own colour, its band as dashed
    lines (the first model's also shaded).

    Parameters
    ----------
    pair : sequence of two matplotlib.axes.Axes
        Autocorrelation, cross-correlation.
    models : sequence of Candidate
        Validated candidates (``validation`` set), the best first.

    Returns
    -------
    None
    """
    models = list(models)
    n = len(models)
    for ax, what, title in ((pair[0], "whiteness", "Residuals: autocorrelation"),
                            (pair[1], "cross", "Residuals: cross-correlation with the input")):
        for i, c in enumerate(models):
            corr_, colour = getattr(c.validation, what), f"C{i}"
            # side by side: every model's lag k stays within a lag's width of k
            shift = (i - (n - 1) / 2) / 3 if n > 1 else 0.0
            ax.vlines(np.asarray(corr_.lags) + shift, 0, corr_.r, color=colour if n > 1 else "k", lw=1,
                      label=f"{c.route} {c.name} {c.kind}, fit {c.validation.fit_percent:.1f} %")
            if i == 0:
                ax.axhspan(-corr_.band, corr_.band, color="tab:blue", alpha=0.15, label="99 % band")
            if n > 1:
                ax.hlines([-corr_.band, corr_.band], corr_.lags[0], corr_.lags[-1], colors=colour, lw=0.8, ls="--")
        ax.set_title(f"{title} ({'the best' if n == 1 else f'the {n} best'} by validation fit)", fontsize=8)
        ax.set_xlabel("lag (samples)")
        ax.legend(fontsize=7)


def record_axes(ax, view) -> None:
    """The record with its models (:class:`~.recordview.RecordView`) on one
    axis: the recorded output, the validation part shaded from its start, each
    model as simulated under the recorded input, labelled with its route,
    method, model and validation fit.

    Parameters
    ----------
    ax : matplotlib.axes.Axes
        Where to draw.
    view : RecordView
        :attr:`~.assess.Assessment.view`.

    Returns
    -------
    None
    """
    ax.plot(view.t, view.y, color="k", lw=2.2, alpha=0.35, label="recorded output")
    for m, style in zip(view.models, ("-", "--", ":")):
        ax.plot(view.t, m.y, lw=1.1, ls=style, label=m.label)
    if view.validation_start_s is not None:
        ax.axvspan(view.validation_start_s, view.t[-1], color="tab:orange", alpha=0.08,
                   label="validation part" + (" (separate record)" if view.scope == "separate" else ""))
        ax.axvline(view.validation_start_s, color="tab:orange", lw=1, ls="--")
    ax.set_title("Record and models simulated under the recorded input"
                 + ("" if view.models else ": no valid model")
                 + ("" if view.validation_start_s is not None else " (scored on the data fitted)"), fontsize=9)
    ax.set_xlabel("time (s)")
    ax.legend(fontsize=7, loc="best")


def broadband_plot(result, n_models: int = 3) -> bytes:
    """PNG of a broadband identification: the impulse response, the step it
    integrates to with the best step models, the spectral estimate (gain and
    phase) with the best frequency models, and its coherence; when validated,
    the residual tests of the best ``n_models`` valid models by validation fit
    and the record with them (:func:`record_axes`). An input only the output-error route
    reads (``excitation.kind == "other"``) has no estimates: the record with its
    models and the residual tests alone.

    Parameters
    ----------
    result : BroadbandResult
        The broadband identification.
    n_models : int, optional
        How many valid models to draw.

    Returns
    -------
    bytes
        The PNG file's content.
    """
    plt = _pyplot()
    a = result.assessment
    best = getattr(a, "best_candidate", None)
    view = getattr(a, "view", None)
    other = result.excitation.kind == "other"
    rows = (0 if other else 2) + (best is not None and best.validation is not None) + (view is not None)
    fig = plt.figure(figsize=(11, 3.5 * max(rows, 1)), dpi=100)
    grid = fig.add_gridspec(max(rows, 1), 2)
    axes = []
    row = 0
    if not other:
        axes += [fig.add_subplot(grid[r, c]) for r in (0, 1) for c in (0, 1)]
        _estimate_axes(result, axes, n_models)
        row = 2
    if view is not None:
        axes.append(fig.add_subplot(grid[row, :]))
        record_axes(axes[-1], view)
        row += 1
    if best is not None and best.validation is not None:
        pair = [fig.add_subplot(grid[row, c]) for c in (0, 1)]
        residual_axes(pair, [c for c in ranked_candidates(a) if c.valid and c.validation is not None
                             and math.isfinite(c.fit_percent)][:n_models])
        axes += pair
    for ax in axes:
        ax.grid(True, alpha=0.3)
    fig.tight_layout()
    return png_bytes(fig)


def _estimate_axes(result, axes, n_models: int) -> None:
    """The impulse response, its integral with the step models, the spectral gain
    with the frequency models and the coherence, on four axes."""
    from .bode_readings import model_response
    from .structures import model_step
    ax_h, ax_s, ax_g, ax_c = axes
    est = result.impulse
    if est is not None:
        ax_h.plot(est.t, est.h, color="k", lw=1)
        ax_s.plot(est.t, est.step, color="k", lw=2.2, alpha=0.35, label="integrated h")
        if result.step_result is not None:
            for m in [m for m in result.step_result.methods if m.valid][:n_models]:
                ax_s.plot(est.t, model_step(m.model, m.params, est.t), lw=1.1,
                          label=f"{m.name} ({m.model})")
    ax_h.set_title("Impulse response (cross-correlation)")
    ax_h.set_xlabel("time (s)")
    ax_s.set_title("Step response: its running integral, and step models")
    ax_s.set_xlabel("time (s)")
    if ax_s.get_legend_handles_labels()[0]:     # a spectral-only analysis has no impulse estimate to draw
        ax_s.legend(fontsize=7)
    sp = result.spectrum
    if sp is not None and sp.f.size:
        ax_g.semilogx(sp.f, 20 * np.log10(np.abs(sp.h)), "o", ms=3, color="k", label="S_yu/S_uu")
        ax_c.semilogx(sp.f, sp.coh, ".-", color="k")
        if result.freq_result is not None:
            for m in [m for m in result.freq_result.methods if m.valid][:n_models]:
                g = model_response(m.model, m.params, 2 * math.pi * sp.f)
                ax_g.semilogx(sp.f, 20 * np.log10(np.abs(g)), lw=1.1, label=f"{m.name} ({m.model})")
    ax_g.set_title("Spectral estimate: gain (dB)")
    ax_g.set_xlabel("frequency (Hz)")
    if ax_g.get_legend_handles_labels()[0]:
        ax_g.legend(fontsize=7)
    ax_c.set_title("Coherence")
    ax_c.set_ylim(0, 1.05)
    ax_c.set_xlabel("frequency (Hz)")
