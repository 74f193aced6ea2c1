"""What each Monte Carlo figure is called where people read it (issue 29: "units on values, not on names";
figures shown by title, not by id): the one table of every engine's figure ids (:data:`.plant.FIGURES`,
:data:`.spice_engine.FIGURES`, :data:`.loop.FIGURES`, :data:`.spice_loop.FIGURES`, :data:`.filter.LOWHIGH_FIGURES`,
:data:`.filter.BANDPASS_FIGURES`) -> a title and the unit its values carry, marked for translation. The ids stay
what ``--limit`` takes and what the JSON keys say; only the pages show these titles. The units are those the
ids' suffixes name (:func:`designer.core.units.figure_unit`).

The table lives in ``core`` (not beside the engines in ``tolerance``) because every layer that shows a figure
reads it: the web page's panels, and the build sheets' tolerance sections and histograms
(:mod:`designer.report.tolerance`), which may import nothing above ``core``."""

from __future__ import annotations

from .i18n import N_
from .i18n import gettext as _
from .units import format_figure

__all__ = ["FIGURE_TITLES", "PREFIX_TITLES", "figure_label", "figure_range", "figure_shown", "figure_spread"]

#: figure id (without an engine's prefix) -> (title, unit of its values)
FIGURE_TITLES = {
    "fn_hz": (N_("natural frequency fn"), "Hz"),
    "zeta": (N_("damping ratio zeta"), ""),
    "q": (N_("quality factor Q"), ""),
    "gain": (N_("DC gain"), ""),
    "overshoot_pct": (N_("step overshoot"), "%"),
    "peak_time_s": (N_("time to the first peak"), "s"),
    "rise_time_s": (N_("step rise time"), "s"),
    "settling_time_s": (N_("step settling time"), "s"),
    "stable": (N_("loop stable (1) or not (0)"), ""),
    "saturated": (N_("output saturated (1) or not (0)"), ""),
    "slewing": (N_("slewing (1) or not (0)"), ""),
    "kp": (N_("Kp as built"), ""),
    "ti_s": (N_("Ti as built"), "s"),
    "td_s": (N_("Td as built"), "s"),
    "phase_margin_deg": (N_("phase margin"), "deg"),
    "crossover_hz": (N_("crossover frequency"), "Hz"),
    "gain_margin_db": (N_("gain margin"), "dB"),
    "steady_state_error_pct": (N_("steady-state error"), "%"),
    "slew_delay_s": (N_("slew delay of the worst stage"), "s"),
    "passband_loss_db": (N_("largest passband loss"), "dB"),
    "ripple_db": (N_("passband ripple"), "dB"),
    "f3_hz": (N_("-3 dB frequency"), "Hz"),
    "f3_low_hz": (N_("lower -3 dB frequency"), "Hz"),
    "f3_high_hz": (N_("upper -3 dB frequency"), "Hz"),
    "stopband_attenuation_db": (N_("least stopband attenuation"), "dB"),
    "group_delay_s": (N_("group delay at DC"), "s"),
    "delay_error_pct": (N_("group delay error"), "%"),
}

#: an engine's prefix on a figure id -> how the title says whose figure it is
PREFIX_TITLES = {
    "ideal_": N_("{figure}, ideal op-amp"),
    "model_": N_("{figure}, analytic model"),
    "spice_": N_("{figure}, SPICE"),
}


def figure_shown(name: str) -> tuple:
    """A Monte Carlo figure's title in the current language and the unit of its values.

    Parameters
    ----------
    name : str
        The figure's id (``fn_hz``, ``model_overshoot_pct``, ``spice_rise_time_s``).

    Returns
    -------
    tuple of str
        (title, unit); an id the table lacks shows as itself with no unit.
    """
    prefix = next((p for p in PREFIX_TITLES if name.startswith(p) and name[len(p):] in FIGURE_TITLES), "")
    title, unit = FIGURE_TITLES.get(name[len(prefix):], (None, ""))
    if title is None:
        return name, ""
    return (_(PREFIX_TITLES[prefix]).format(figure=_(title)) if prefix else _(title)), unit


def figure_label(name: str) -> str:
    """A Monte Carlo figure's title with its unit in brackets, as an axis or a table names it
    (``natural frequency fn (Hz)``; ``damping ratio zeta`` without a unit), in the current language.

    Parameters
    ----------
    name : str
        The figure's id.

    Returns
    -------
    str
        The label.
    """
    title, unit = figure_shown(name)
    return f"{title} ({unit})" if unit else title


def _headed(name: str, title: str) -> str:
    # the id after the title (what --limit takes), unless the title already ends with it (damping ratio zeta)
    return title if name in (title, title.split()[-1]) else f"{title} ({name})"


def figure_range(name: str, lo: float, hi: float, digits: int = 5) -> str:
    """A figure's title, its id (what ``--limit`` takes) and a range of its values with units, as the
    command line's summaries print them (``natural frequency fn (fn_hz): 3.2392 kHz to 3.7705 kHz``).

    Parameters
    ----------
    name : str
        The figure's id.
    lo, hi : float or None
        The range's ends; None when nothing has the figure (``... zeta: no value``).
    digits : int
        Significant digits.

    Returns
    -------
    str
        The line's text.
    """
    title, _unit = figure_shown(name)
    head = _headed(name, title)
    if lo is None or hi is None:
        return f"{head}: no value"
    return f"{head}: {format_figure(name, lo, digits)} to {format_figure(name, hi, digits)}"


def figure_spread(name: str, nominal: float, mean: float, std: float, lo: float, hi: float,
                  digits: int = 5) -> str:
    """A Monte Carlo figure's statistics with units, as the command line's summaries print them
    (``natural frequency fn (fn_hz): nominal 3.4858 kHz, mean 3.5075 kHz, std 140.4 Hz, 95 % of builds
    3.2392 kHz to 3.7705 kHz``): the title says what it is, the id is what ``--limit`` takes.

    Parameters
    ----------
    name : str
        The figure's id.
    nominal, mean, std : float
        The nominal build's value, the builds' mean and standard deviation.
    lo, hi : float or None
        The 2.5 % and 97.5 % percentiles; None when no build has the figure (every build's NaN).
    digits : int
        Significant digits (the standard deviation's: four).

    Returns
    -------
    str
        The line's text.
    """
    title, _unit = figure_shown(name)
    head = _headed(name, title)
    def shown(v, d=digits):
        return format_figure(name, v, d)
    if lo is None or hi is None:
        # no build has the figure (a SPICE step clipped at the op-amp's swing never settles to its gain, so
        # every build's fn, zeta and times are NaN): say so rather than print a mean and percentiles of nothing
        return f"{head}: nominal {shown(nominal)}, no build has this figure"
    return (f"{head}: nominal {shown(nominal)}, mean {shown(mean)}, std {shown(std, 4)}, "
            f"95 % of builds {shown(lo)} to {shown(hi)}")
