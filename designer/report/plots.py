"""Plots for the build sheets and the identification results: matplotlib
figures rendered to PNG bytes (matplotlib is imported only when a plot is
drawn, through its object API: pyplot's import and state are not needed).

Curves are decimated to what a sheet's figure can show (:data:`MAX_POINTS`
per curve): a 7.5-inch plot at 110 dpi has under a thousand pixel columns, and
drawing 20 000-point curves only costs time. The step plot has a residual
panel under it (SPICE minus model: the two overlap to the pixel otherwise)
and the parts' tolerance band shaded; the Bode plot marks the resonance peak
and the -3 dB point, measured in SPICE's ``.ac`` run beside the model's; the
loop-gain plot marks the gain and phase margins.

Every plot speaks the sheet's language (:mod:`designer.core.i18n`): its axis labels, legends, titles and marks
through the catalogue (a caller's label too, when it is one of its messages), and, outside English, its numbers
with the language's decimal symbol: the tick labels through :class:`_LocalisedFormatter` (an explicit formatter,
never the machine's locale) and every text through :func:`designer.core.i18n.localise` (:func:`png_bytes`).
"""

from __future__ import annotations

import io
import math

import numpy as np

from ..core.i18n import N_, current, localise
from ..core.i18n import gettext as _

__all__ = ["bode_plot", "decimate", "figure", "histogram_plot", "localise_figure", "loop_gain_plot", "png_bytes",
           "step_plot", "time_unit"]

#: the most points a curve is drawn with
MAX_POINTS = 1500


def decimate(x, *ys, n: int = MAX_POINTS):
    """``x`` and the ``ys`` at most ``n`` evenly spaced samples (the ends kept).

    Parameters
    ----------
    x : array_like
        The abscissa.
    *ys : array_like
        The ordinates on ``x``.
    n : int
        The most samples kept.

    Returns
    -------
    tuple
        ``x`` and each of ``ys``, decimated alike.
    """
    x = np.asarray(x)
    if x.size <= n:
        return (x, *[None if y is None else np.asarray(y) for y in ys])
    idx = np.unique(np.linspace(0, x.size - 1, n).round().astype(int))
    return (x[idx], *[None if y is None else np.asarray(y)[idx] for y in ys])


def figure(w: float, h: float, rows: int = 1, cols: int = 1, **kw):
    """A figure and its axes without pyplot (Agg canvas), with fixed margins: a
    "tight" bounding box would draw every figure twice to measure it.

    Parameters
    ----------
    w, h : float
        The size (inches).
    rows, cols : int
        The grid of axes.
    **kw
        Passed to ``Figure.subplots``.

    Returns
    -------
    tuple
        (figure, axes).
    """
    from matplotlib.backends.backend_agg import FigureCanvasAgg
    from matplotlib.figure import Figure
    fig = Figure(figsize=(w, h))
    FigureCanvasAgg(fig)
    axes = fig.subplots(rows, cols, **kw)
    fig.subplots_adjust(left=0.1, right=0.98, top=0.93, bottom=0.1, hspace=0.28)
    return fig, axes


def log_frequency_axis(ax) -> None:
    """A log frequency axis labelled in plain engineering text (``100``, ``1k``,
    ``10k``), minor ticks at 2 and 5 of each decade. matplotlib's default labels
    are mathtext (``$10^{3}$``), whose parser is a large part of a plot's cost,
    and its default minor ticks (eight a decade) are a Tick object each."""
    from matplotlib.ticker import FuncFormatter, LogLocator, NullFormatter
    from ..core.units import value_code
    ax.set_xscale("log")
    ax.xaxis.set_major_locator(LogLocator(base=10.0))
    ax.xaxis.set_major_formatter(FuncFormatter(lambda v, _pos: value_code(v)))
    ax.xaxis.set_minor_locator(LogLocator(base=10.0, subs=(2.0, 5.0)))
    ax.xaxis.set_minor_formatter(NullFormatter())


def png_bytes(fig, dpi: int = 110, tight: bool = True) -> bytes:
    """A matplotlib figure as PNG bytes (the figure is closed if pyplot owns it);
    ``tight`` crops to what is drawn (one more drawing pass).

    Parameters
    ----------
    fig : matplotlib.figure.Figure
        The figure.
    dpi : int
        The resolution.
    tight : bool
        Crop to what is drawn.

    Returns
    -------
    bytes
        The PNG.
    """
    localise_figure(fig)
    buf = io.BytesIO()
    fig.savefig(buf, format="png", dpi=dpi, bbox_inches="tight" if tight else None)
    import sys
    if "matplotlib.pyplot" in sys.modules:
        sys.modules["matplotlib.pyplot"].close(fig)
    return buf.getvalue()


def localise_figure(fig) -> None:
    """Outside English, the numbers of ``fig`` as the current language writes them: each axis' tick labels
    (its formatters wrapped in :class:`_LocalisedFormatter`) and every other text (titles, labels, legends,
    marks) through :func:`~designer.core.i18n.localise`; an English figure is left as it is.

    Parameters
    ----------
    fig : matplotlib.figure.Figure
        The figure, drawn but not yet saved.

    Returns
    -------
    None
    """
    if current() == "en":
        return
    from matplotlib.text import Text
    for ax in fig.axes:
        for axis in (ax.xaxis, ax.yaxis):
            for get, put in ((axis.get_major_formatter, axis.set_major_formatter),
                             (axis.get_minor_formatter, axis.set_minor_formatter)):
                inner = get()
                if not isinstance(inner, _formatter_class()):
                    put(_formatter_class()(inner))
    for t in fig.findobj(Text):
        t.set_text(localise(t.get_text()))


def _formatter_class():
    """:class:`_LocalisedFormatter`, made when first needed (matplotlib is imported only when a plot is drawn)."""
    global _LocalisedFormatter
    if _LocalisedFormatter is None:
        from matplotlib.ticker import Formatter

        class _LocalisedFormatter(Formatter):   # noqa: F811
            """A tick formatter that writes ``inner``'s labels in the current language (the decimal symbol)."""

            def __init__(self, inner):
                self.inner = inner

            def set_axis(self, axis):
                super().set_axis(axis)
                self.inner.set_axis(axis)

            def set_locs(self, locs):
                self.locs = locs
                self.inner.set_locs(locs)

            def __call__(self, x, pos=None):
                return localise(self.inner(x, pos))

            def format_ticks(self, values):
                return [localise(v) for v in self.inner.format_ticks(values)]

            def get_offset(self):
                return localise(self.inner.get_offset())

    return _LocalisedFormatter


#: the tick formatter of a non-English figure (a matplotlib ``Formatter``; made by :func:`_formatter_class`)
_LocalisedFormatter = None


def time_unit(span_s: float) -> tuple:
    """(scale, unit) of a time axis: microseconds below 100 ms (every sheet so far), milliseconds below
    100 s, else seconds (a slow model plant's loop).

    Parameters
    ----------
    span_s : float
        The axis' span (s).

    Returns
    -------
    tuple
        (scale, unit): seconds times scale in unit.
    """
    if span_s < 0.1:
        return 1e6, "us"
    return (1e3, "ms") if span_s < 100 else (1.0, "s")


def step_plot(t, curves: dict, title: str, ylabel: str = N_("output (V)"), residual: tuple | None = None,
              band: tuple | None = None, xlabel: str = N_("time after the step")) -> bytes:
    """Overlaid step responses; ``curves`` maps a label to an array on ``t``.

    ``residual``: (label, measured, model) drawn as measured - model in a panel
    below; ``band``: (t, lo, hi, label) shaded behind the curves; ``xlabel``: what
    the time axis counts (its unit is added).

    Parameters
    ----------
    t : array_like
        Time points (s).
    curves : dict
        Label -> samples on ``t``.
    title : str
        The plot's title.
    ylabel : str
        The vertical axis' label.
    residual : tuple, optional
        (label, measured, model).
    band : tuple, optional
        (t, lo, hi, label).
    xlabel : str
        What the time axis counts.

    Returns
    -------
    bytes
        The PNG.
    """
    if residual is not None:
        fig, (ax, ar) = figure(7.5, 4.6, 2, 1, sharex=True, gridspec_kw={"height_ratios": [3, 1.1]})
    else:
        fig, ax = figure(7.5, 3.8)
    scale, unit = time_unit(float(np.nanmax(np.asarray(t, float))) if np.size(t) else 0.0)
    tus = np.asarray(t) * scale
    if band is not None:
        bt, lo, hi, label = band
        bt, lo, hi = decimate(bt, lo, hi)
        ax.fill_between(np.asarray(bt) * scale, lo, hi, color="#f4c27a", alpha=0.45, lw=0, label=_(label))
    styles = ["-", "--", ":", "-."]
    widths = [2.6, 1.4, 1.4, 1.2]
    for i, (label, y) in enumerate(curves.items()):
        if y is not None:
            x, yy = decimate(tus, y)
            ax.plot(x, yy, styles[i % 4], label=_(label), lw=widths[i % 4])
    ax.set_ylabel(_(ylabel))
    ax.set_title(_(title), fontsize=10)
    ax.grid(True, alpha=0.3)
    ax.legend(fontsize=8)
    last = ax
    if residual is not None:
        label, meas, model = residual
        x, r = decimate(tus, np.asarray(meas) - np.asarray(model))
        ar.plot(x, r * 1e3, color="C2", lw=1.1)
        ar.axhline(0, color="k", lw=0.6)
        ar.set_ylabel("mV", fontsize=8)
        ar.set_title(_(label), fontsize=8, loc="left")
        ar.grid(True, alpha=0.3)
        last = ar
    last.set_xlabel(f"{_(xlabel)} ({unit})")
    return png_bytes(fig, dpi=100, tight=False)


def bode_plot(systems: dict, f_lo: float, f_hi: float, title: str, measured: dict | None = None,
              markers: list | None = None) -> bytes:
    """Magnitude (dB) and phase (deg) of transfer functions ``{label: (num, den)}``;
    ``measured``: {label: (f, complex H)} drawn as points (SPICE's .ac run);
    ``markers``: (f, gain V/V, text, style) points marked on the magnitude.

    Parameters
    ----------
    systems : dict
        Label -> (num, den), coefficients highest power first.
    f_lo, f_hi : float
        The frequency axis' ends (Hz).
    title : str
        The plot's title.
    measured : dict, optional
        Label -> (f, complex H): points drawn.
    markers : list, optional
        (f, gain V/V, text, style) points marked on the magnitude.

    Returns
    -------
    bytes
        The PNG.
    """
    from ..core.lti import freq_response
    f = np.logspace(np.log10(f_lo), np.log10(f_hi), 500)
    fig, (a1, a2) = figure(7.5, 4.6, 2, 1, sharex=True)
    for i, (label, (num, den)) in enumerate(systems.items()):
        h = freq_response(num, den, f)
        a1.plot(f, 20 * np.log10(np.abs(h)), ["-", "--", ":"][i % 3], label=_(label))
        a2.plot(f, np.degrees(np.unwrap(np.angle(h))), ["-", "--", ":"][i % 3], label=_(label))
    for label, (fm, hm) in (measured or {}).items():
        fm, hm = decimate(fm, hm, n=120)
        a1.plot(fm, 20 * np.log10(np.abs(hm)), "o", ms=2.5, mfc="none", color="C3", label=_(label))
        a2.plot(fm, np.degrees(np.unwrap(np.angle(hm))), "o", ms=2.5, mfc="none", color="C3", label=_(label))
    for fx, g, txt, style in markers or []:
        if fx is None or g is None:
            continue
        a1.plot([fx], [20 * math.log10(g)], style, ms=7, mfc="none", mew=1.5)
        a1.annotate(_(txt), (fx, 20 * math.log10(g)), textcoords="offset points", xytext=(6, 4), fontsize=7.5)
        a2.axvline(fx, color="0.5", lw=0.6, ls=":")
    log_frequency_axis(a2)   # sharex: one axis for both
    a1.set_ylabel(_("gain (dB)"))
    a2.set_ylabel(_("phase (deg)"))
    a2.set_xlabel(_("frequency (Hz)"))
    a1.set_title(_(title), fontsize=10)
    for a in (a1, a2):
        a.grid(True, which="both", alpha=0.3)
    a1.legend(fontsize=7.5, loc="lower left")
    return png_bytes(fig, dpi=100, tight=False)


def loop_gain_plot(f, L, title: str, crossover_hz: float, phase_margin_deg: float,
                   phase_crossover_hz: float, gain_margin_db: float) -> bytes:
    """Loop gain |L| (dB) and phase with the margins marked: the phase margin at
    the gain crossover, the gain margin at the -180 deg crossing.

    Parameters
    ----------
    f : array_like
        Frequencies (Hz).
    L : array_like
        The complex loop gain on ``f``.
    title : str
        The plot's title.
    crossover_hz : float
        The gain crossover.
    phase_margin_deg : float
        The phase margin there.
    phase_crossover_hz : float
        The -180 deg crossing.
    gain_margin_db : float
        The gain margin there.

    Returns
    -------
    bytes
        The PNG.
    """
    f, L = decimate(f, L)
    mag = 20 * np.log10(np.abs(L))
    ph = np.degrees(np.unwrap(np.angle(L)))
    fig, (a1, a2) = figure(7.5, 4.6, 2, 1, sharex=True)
    a1.plot(f, mag)
    a1.axhline(0, color="k", lw=0.6)
    a2.plot(f, ph)
    log_frequency_axis(a2)
    # the -180 deg line nearest the phase curve at the crossover (the phase may be unwrapped by 360)
    ref = -180.0
    if math.isfinite(crossover_hz):
        pc = float(np.interp(math.log(crossover_hz), np.log(f), ph))
        ref = -180.0 + 360.0 * round((pc + 180.0 - phase_margin_deg) / 360.0) if math.isfinite(phase_margin_deg) \
            else ref
        for ax in (a1, a2):
            ax.axvline(crossover_hz, color="r", lw=0.8, ls="--")
        a2.annotate("", xy=(crossover_hz, pc), xytext=(crossover_hz, ref),
                    arrowprops={"arrowstyle": "<->", "color": "r", "lw": 1.2})
        a2.text(crossover_hz * 1.1, (pc + ref) / 2, _("PM {pm} deg").format(pm=f"{phase_margin_deg:.3g}"), color="r",
                fontsize=8)
    a2.axhline(ref, color="k", lw=0.6)
    if math.isfinite(phase_crossover_hz) and math.isfinite(gain_margin_db):
        g = float(np.interp(math.log(phase_crossover_hz), np.log(f), mag))
        for ax in (a1, a2):
            ax.axvline(phase_crossover_hz, color="m", lw=0.8, ls=":")
        a1.annotate("", xy=(phase_crossover_hz, g), xytext=(phase_crossover_hz, 0),
                    arrowprops={"arrowstyle": "<->", "color": "m", "lw": 1.2})
        a1.text(phase_crossover_hz * 1.1, g / 2, _("GM {gm} dB").format(gm=f"{gain_margin_db:.3g}"), color="m",
                fontsize=8)
    a1.set_title(_(title), fontsize=10)
    a1.set_ylabel(_("gain (dB)"))
    a2.set_ylabel(_("phase (deg)"))
    a2.set_xlabel(_("frequency (Hz)"))
    for ax in (a1, a2):
        ax.grid(True, which="both", alpha=0.3)
    return png_bytes(fig, dpi=100, tight=False)


def histogram_plot(values, name: str, nominal: float | None = None, lo: float | None = None,
                   hi: float | None = None, title: str = "", bins: int = 60, label: str | None = None) -> bytes:
    """A histogram of a figure over Monte Carlo samples (NaN left out), the limits ``lo``/``hi``
    drawn as red lines with the region outside shaded, the nominal design as a dashed line.

    Parameters
    ----------
    values : array_like
        The figure's value in each sample.
    name : str
        The figure's id (its unit; the axis label without ``label``).
    nominal : float, optional
        The nominal design's value.
    lo, hi : float, optional
        The limits.
    title : str
        The plot's title.
    bins : int
        The histogram's bins.
    label : str, optional
        The x axis's label (the figure's title with its unit, as the caller words it); default the
        id with its unit.

    Returns
    -------
    bytes
        The PNG.
    """
    from matplotlib.ticker import FuncFormatter

    from ..core.units import figure_unit, format_eng, value_code
    v = np.asarray(values, float)
    v = v[np.isfinite(v)]
    unit = figure_unit(name)
    fig, ax = figure(7.5, 3.0)
    fig.subplots_adjust(bottom=0.16, top=0.9)
    if v.size:
        k = int(np.clip(2 * math.sqrt(v.size), 10, bins)) if np.ptp(v) > 0 else 1
        ax.hist(v, bins=k, color="#6b8fc7", edgecolor="white", lw=0.3)
    shown = [x for x in (nominal, lo, hi) if x is not None and math.isfinite(x)] + ([v.min(), v.max()] if v.size else [])
    if shown:
        a, b = min(shown), max(shown)
        pad = 0.05 * (b - a) if b > a else 0.05 * max(abs(a), 1e-30)
        ax.set_xlim(a - pad, b + pad)
    left, right = ax.get_xlim()
    fmt = (lambda x: format_eng(x, unit, 4)) if unit in ("Hz", "s") else (lambda x: f"{x:.4g}{' ' + unit if unit else ''}")
    for x, side in ((lo, "min"), (hi, "max")):
        if x is not None and math.isfinite(x):
            ax.axvline(x, color="C3", lw=1.6, label=f"{_(side)} {fmt(x)}")
            ax.axvspan(*((left, x) if side == "min" else (x, right)), color="C3", alpha=0.08, lw=0)
    if nominal is not None and math.isfinite(nominal):
        ax.axvline(nominal, color="k", lw=1.2, ls="--", label=_("nominal {value}").format(value=fmt(nominal)))
    ax.set_xlim(left, right)
    if unit in ("Hz", "s"):
        ax.xaxis.set_major_formatter(FuncFormatter(lambda x, _pos: value_code(x) if x else "0"))
    ax.set_xlabel(label if label is not None else f"{_(name)} ({unit})" if unit else _(name))
    ax.set_ylabel(_("builds"))
    ax.set_title(_(title) if title else _("{name} over {n} builds").format(name=_(name), n=v.size), fontsize=10)
    ax.grid(True, alpha=0.3)
    if ax.get_legend_handles_labels()[0]:   # nothing to name without a limit or a nominal
        ax.legend(fontsize=7.5)
    return png_bytes(fig, dpi=100, tight=False)
