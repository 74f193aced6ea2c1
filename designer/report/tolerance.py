"""The tolerance analysis on a build sheet and in its bundle (issue 17), for any
wing's Monte Carlo (a plant's or a loop's: :class:`designer.tolerance.montecarlo.MonteCarlo`,
read as it is, nothing recomputed): a histogram per limited figure and of the
headline figure (``mc-<figure>.png``, the limits and the nominal marked), and
the sheet's section: the yield with its interval, the headline's histogram, the
part to buy tighter and, for a loop, the probabilities of instability,
saturation and of failing the slew check; and, where asked (the PID sheet), the
worst case (``--worst-case``, :class:`designer.tolerance.worstcase.WorstCase`): each
figure's extremes over the tolerance box and the corner (or the point inside the
box) that gives each, as one compact table.

Every figure is named by its title, with the unit on its values (issue 29;
:mod:`designer.core.figure_titles`, the table the web page reads): ``natural
frequency fn`` and ``3.3 kHz to 3.7 kHz``, never ``fn_hz``; the file names and the
JSON keep the ids."""

from __future__ import annotations

import functools

from ..core.i18n import N_
from ..core.figure_titles import figure_label, figure_shown
from ..core.i18n import gettext as _
from ..core.i18n import translated
from ..core.units import format_figure
from . import document as R
from .plots import histogram_plot

__all__ = ["csv_texts", "histogram_plots", "histogram_words", "limit_text", "section", "title"]


def histogram_name(figure: str) -> str:
    return f"mc-{figure}.png"


def histogram_png(result, figure: str) -> bytes:
    """The histogram of ``figure`` over ``result.monte_carlo``'s samples, its limit and nominal marked."""
    mc = result.monte_carlo
    lim = next((lim for lim in mc.limits if lim.figure == figure), None)
    title, label = histogram_words(mc, figure)
    return histogram_plot(mc.figures[figure], figure, mc.nominal_figures.get(figure),
                          None if lim is None else lim.min, None if lim is None else lim.max, title, label=label)


def histogram_words(mc, figure: str) -> tuple:
    """A histogram's title and x-axis label in the current language: the figure by its title, never its id
    (``natural frequency fn over 5000 builds, 1112 outside the limits``; ``natural frequency fn (Hz)``).

    Parameters
    ----------
    mc : designer.tolerance.montecarlo.MonteCarlo
        The Monte Carlo (its count of builds, limits and builds outside each).
    figure : str
        The figure's id.

    Returns
    -------
    tuple of str
        (title, label).
    """
    lim = next((lim for lim in mc.limits if lim.figure == figure), None)
    inside = "" if lim is None else _(", {count} outside the limits").format(count=mc.failing[figure]['count'])
    return _("{figure} over {n} builds").format(figure=_name(figure), n=mc.n) + inside, figure_label(figure)


def histogram_plots(result) -> tuple:
    """(file name, draw(result)) of every histogram of the result's Monte Carlo (none without one):
    the headline figure's, then each limited figure's.

    Parameters
    ----------
    result
        A design's typed result.

    Returns
    -------
    tuple
        (file name, draw(result)) pairs.
    """
    mc = result.monte_carlo
    if mc is None or mc.headline is None:   # none, or one build replayed: no spread
        return ()
    names = dict.fromkeys([mc.headline, *(lim.figure for lim in mc.limits)])
    return tuple((histogram_name(f), functools.partial(histogram_png, figure=f)) for f in names)


def _samples_csv(result) -> str:
    return result.monte_carlo.csv_text()


def csv_texts(result) -> dict:
    """The bundle's ``monte-carlo.csv`` (one row per build: every varied part, every figure), as
    :func:`designer.report.bundle.write_design` takes its texts; none without a Monte Carlo.

    Parameters
    ----------
    result
        A design's typed result.

    Returns
    -------
    dict
        Key -> (file name, text(result)); empty without a Monte Carlo.
    """
    return {} if result.monte_carlo is None else {"monte_carlo_csv": ("monte-carlo.csv", _samples_csv)}


def _value(figure: str, v) -> str:
    return format_figure(figure, v)


def _name(figure: str) -> str:
    return figure_shown(figure)[0]


def _sentence(text: str) -> str:
    return text[:1].upper() + text[1:]


#: the draw's distribution and sampler as the sheet words them (the JSON and --dist/--sampler keep the ids)
DRAW_WORDS = {"uniform": N_("uniform"), "normal": N_("normal"), "random": N_("random"), "lhs": N_("lhs"),
              "sobol": N_("sobol")}


def limit_text(lim) -> str:
    """A limit as the sheet words it: the figure's title and its window, units on the values
    (``natural frequency fn 3.3 kHz to 3.7 kHz``, ``phase margin at least 45 deg``).

    Parameters
    ----------
    lim : designer.tolerance.stats.Limit
        The limit (its figure id, ``min`` and ``max``; either may be None).

    Returns
    -------
    str
        The text in the current language.
    """
    f = lim.figure
    if lim.min is not None and lim.max is not None:
        window = _("{lo} to {hi}").format(lo=_value(f, lim.min), hi=_value(f, lim.max))
    elif lim.min is not None:
        window = _("at least {value}").format(value=_value(f, lim.min))
    else:
        window = _("at most {value}").format(value=_value(f, lim.max))
    return f"{_name(f)} {window}"


def _pct(x: float) -> str:
    return f"{100 * x:.3g} %" if x < 0.9995 or x == 1 else f"{100 * x:.4g} %"


def title(result, worst: bool = False) -> str | None:
    """The tolerance section's heading (None: no section): what the result carries, the Monte Carlo
    and (with ``worst``) the worst case.

    Parameters
    ----------
    result
        A design's typed result.
    worst : bool
        Count the worst case.

    Returns
    -------
    str or None
        The heading.
    """
    what = [w for w, x in (("Monte Carlo", result.monte_carlo),
                           (_("worst case"), getattr(result, "worst_case", None) if worst else None)) if x is not None]
    return _("Tolerance analysis ({what})").format(what=", ".join(what)) if what else None


#: a part at its bound: the deviation (in tolerances) at least this far out
AT_BOUND = 0.995


def corner_text(deviations: dict) -> str:
    """Where an extreme is reached: each part's sign at its bound (``R1+ C2-``), a part inside the box
    with its deviation in tolerances (``R7 +0.43``); the parts grouped by sign."""
    up = [r for r, d in deviations.items() if d >= AT_BOUND]
    down = [r for r, d in deviations.items() if d <= -AT_BOUND]
    inside = [f"{r} {d:+.2f}" for r, d in deviations.items() if -AT_BOUND < d < AT_BOUND]
    out = ([f"+tol: {' '.join(up)}"] if up else []) + ([f"-tol: {' '.join(down)}"] if down else [])
    return "; ".join(out + ([_("inside: {parts}").format(parts=", ".join(inside))] if inside else []))


def worst_case_blocks(wc) -> list:
    """The worst case as the sheet shows it: how it was searched, and per figure its lowest and
    highest value and the corner that gives each (:func:`corner_text`)."""
    rows = []
    for fig, (lo, hi) in wc.extremes.items():
        for which, e in ((N_("lowest"), lo), (N_("highest"), hi)):
            rows.append([_name(fig) if which == "lowest" else "", _(which), _value(fig, e.value),
                         (_("corner: ") if e.at_corner else _("inside the box: ")) + corner_text(e.deviations)])
    head = _("Worst case over the tolerance box: {corners} corners evaluated ({method}); each part at "
             "+tol or -tol of its nominal, in tolerances where an extreme lies inside.").format(corners=wc.corners,
                                                                                                method=translated(wc.method))
    blocks = [R.text(head), R.table([_("figure"), _("extreme"), _("value"), _("where (parts)")], rows)]
    missing = wc.missing
    if missing:
        # a figure missing at some corners (no peak where a build is overdamped) has extremes only over the
        # builds that have it: near the others it may go further (a peak time grows without bound as zeta nears 1)
        blocks.append(R.text(_("No value at some corners ({figures}): those extremes are over the builds that have "
                               "the figure, and may be exceeded near the others.").format(
            figures=", ".join(_("{figure} at {n} of {corners}").format(figure=_name(k), n=n, corners=wc.corners)
                              for k, n in missing.items()))))
    return blocks


def section(result, with_images: bool = True, worst: bool = False) -> list:
    """The sheet's tolerance section (blocks): the Monte Carlo's (empty without one) and, with
    ``worst``, the worst case's (:func:`worst_case_blocks`) when the result has one.

    Parameters
    ----------
    result
        A design's typed result.
    with_images : bool
        Show the histograms.
    worst : bool
        Add the worst case.

    Returns
    -------
    list
        The blocks.
    """
    wc = getattr(result, "worst_case", None) if worst else None
    tail = [] if wc is None else worst_case_blocks(wc)
    return _monte_carlo_blocks(result, with_images) + tail


def _monte_carlo_blocks(result, with_images: bool) -> list:
    mc = result.monte_carlo
    if mc is None:
        return []
    if mc.headline is None:   # one build replayed (--replay I): what it is, no spread
        return [R.text(" ".join(mc.summary_lines()))]
    head = _("{n} builds drawn within the parts' tolerances ({dist}, {sampler} sampler, seed {seed}; "
             "each build's parts are in monte-carlo.csv).").format(n=mc.n, dist=_(DRAW_WORDS.get(mc.dist, mc.dist)),
                                                                   sampler=_(DRAW_WORDS.get(mc.sampler, mc.sampler)),
                                                                   seed=mc.seed)
    lines = [head]
    if mc.limits:
        lo, hi = mc.yield_interval()
        lines.append(_("Yield {y} ({count} of {n}; 95 % Wilson interval {lo} to {hi}) within {limits}.").format(
            y=_pct(mc.yield_count / mc.n), count=mc.yield_count, n=mc.n, lo=_pct(lo), hi=_pct(hi),
            limits="; ".join(limit_text(lim) for lim in mc.limits)))
        lost = sorted(mc.failing.items(), key=lambda kv: -kv[1]["count"])
        if lost and lost[0][1]["count"]:
            lines.append(_("Lost builds: {lost} (the worst: build {worst}).").format(
                lost="; ".join(_("{count} on {figure}").format(count=v["count"], figure=_name(k))
                               for k, v in lost if v["count"]), worst=lost[0][1]['worst'][0]))
        if mc.tighten:
            t = mc.tighten
            better = t["yield"] > t["yield_now"]
            lines.append(_("Buy {part} tighter: at {tol} % the yield is {y}").format(
                part=t['part'], tol=f"{t['tolerance_pct']:g}", y=_pct(t['yield']))
                + ("." if better else _(" (no part tried raises it: the design, not the parts, limits it).")))
    else:
        lines.append(_("No limits given (--limit FIGURE=MIN:MAX), so no yield: the spread alone."))
    for key, what in (("p_unstable", _("Unstable")), ("p_saturated", _("An op-amp beyond its swing")),
                      ("p_slewing", _("Failing the slew check"))):
        p = getattr(mc, key, None)
        if p is not None:
            lines.append(_("{what}: {p} (95 % Wilson {lo} to {hi}).").format(
                what=what, p=_pct(p['fraction']), lo=_pct(p['ci95'][0]), hi=_pct(p['ci95'][1])))
    s = mc.stats.get(mc.headline)
    if s is not None and s.percentiles:
        p = s.percentiles
        h = mc.headline
        lines.append(_sentence(_("{figure}: nominal {nominal}, 95 % of builds {lo} to {hi}.").format(
            figure=_name(h), nominal=_value(h, s.nominal), lo=_value(h, p[2.5]), hi=_value(h, p[97.5]))))
    text = [R.text(" ".join(lines))]
    if not with_images:
        return text
    return [R.columns([R.image(histogram_name(mc.headline), _("histogram of {figure}").format(
        figure=_name(mc.headline)))],
                      text)]
