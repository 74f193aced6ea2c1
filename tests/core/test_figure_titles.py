"""The Monte Carlo figures' titles (issue 29: figures by title, units on values): every engine's figure id has one,
in English and in Spanish, with the unit its id's suffix names."""

import pytest

from designer.core.i18n import catalogue, language
from designer.core.units import figure_unit
from designer.tolerance import filter as filter_tolerance
from designer.core import figure_titles as titles
from designer.tolerance import loop, plant, spice_ac, spice_engine, spice_loop


def every_figure() -> set:
    """Every figure id an engine writes into a Monte Carlo's figures (the SPICE engines' own as spice_<figure>,
    the analytic figures they replace as model_<figure>)."""
    return {*plant.FIGURES, *loop.FIGURES, *spice_loop.FIGURES, *filter_tolerance.LOWHIGH_FIGURES,
            *filter_tolerance.BANDPASS_FIGURES, "delay_error_pct", *spice_ac.FIGURES,
            *(f"spice_{f}" for f in spice_engine.FIGURES), *(f"model_{f}" for f in spice_engine.SHARED)}


@pytest.mark.parametrize("name", sorted(every_figure()))
def test_every_engines_figure_has_a_title_and_its_ids_unit(name):
    title, unit = titles.figure_shown(name)
    assert title != name and "_" not in title, title
    assert unit == figure_unit(name)


def test_every_title_has_a_spanish_translation_and_the_page_gets_it():
    es = catalogue("es")
    for msgid in [t for t, _ in titles.FIGURE_TITLES.values()] + list(titles.PREFIX_TITLES.values()):
        assert es.get(msgid), msgid
    with language("es"):
        title, unit = titles.figure_shown("model_overshoot_pct")
    assert title == es["{figure}, analytic model"].format(figure=es["step overshoot"]) and unit == "%"
    assert titles.figure_shown("fn_hz") == ("natural frequency fn", "Hz")   # English outside a language


def test_an_id_the_table_lacks_shows_as_itself():
    assert titles.figure_shown("spice_unknown_hz") == ("spice_unknown_hz", "")


def test_the_command_lines_statistics_name_the_figure_and_carry_units():
    # a frequency in engineering notation, a percentage with its sign, a ratio bare; the id after the title
    line = titles.figure_spread("fn_hz", 3485.8, 3507.5, 140.3, 3239.2, 3770.5)
    assert line == ("natural frequency fn (fn_hz): nominal 3.4858 kHz, mean 3.5075 kHz, std 140.3 Hz, "
                    "95 % of builds 3.2392 kHz to 3.7705 kHz")
    assert titles.figure_spread("overshoot_pct", 52.875, 52.853, 1.52, 50.047, 55.602).startswith(
        "step overshoot (overshoot_pct): nominal 52.875 %")
    # a title that already ends with the id does not repeat it
    assert titles.figure_range("zeta", 0.17894, 0.22083) == "damping ratio zeta: 0.17894 to 0.22083"
    assert titles.figure_range("peak_time_s", 130.66e-6, 162.67e-6) == \
        "time to the first peak (peak_time_s): 130.66 us to 162.67 us"
