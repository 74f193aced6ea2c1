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
