"""The sheets' languages (designer/core/i18n.py): the Spanish catalogue translates every message the code
marks (Babel's extractor over the package), numbers take CLDR's decimal symbol, English is the code's own
text, and a language outside the list is refused naming the ones there are."""

import re

import pytest
from babel.numbers import get_decimal_symbol
from hypothesis import given
from hypothesis import strategies as st

from designer.core import i18n
from designer.core.errors import DesignError


def test_the_spanish_catalogue_translates_every_marked_message():
    lack = i18n.missing("es")
    assert not lack, "\n".join(f"{where[0]}: {msg!r}" for msg, where in sorted(lack.items()))


def test_the_catalogue_keeps_every_placeholder():
    """A translation that drops or renames a {field} would raise (or lose a figure) when formatted."""
    fields = re.compile(r"\{(\w*)\}")
    bad = [m for m, t in i18n.catalogue("es").items() if sorted(fields.findall(m)) != sorted(fields.findall(t))]
    assert not bad, bad


def test_english_is_the_code_s_own_text_and_spanish_the_catalogue_s():
    msg = "Bill of materials"
    assert i18n.gettext(msg) == msg
    with i18n.language("es"):
        assert i18n.gettext(msg) == i18n.catalogue("es")[msg] != msg
        assert i18n.current() == "es"
    assert i18n.current() == "en" and i18n.gettext(msg) == msg


@given(st.floats(min_value=-1e6, max_value=1e6, allow_nan=False).filter(lambda x: x != int(x)),
       st.integers(min_value=2, max_value=6))
def test_a_number_takes_the_language_s_decimal_symbol(x, digits):
    text = f"{x:.{digits}f} V"
    assert i18n.localise(text) == text
    with i18n.language("es"):
        assert i18n.localise(text) == text.replace(".", get_decimal_symbol("es"))


def test_names_and_dotted_runs_keep_their_dots():
    with i18n.language("es"):
        assert i18n.localise("v1.5, 1.2.3, IV.9, file2.3.csv, prbs.csv") == "v1.5, 1.2.3, IV.9, file2.3.csv, prbs.csv"
        assert i18n.localise("x2.57 at 1.6 kOhm; n = 30.3.") == "x2,57 at 1,6 kΩ; n = 30,3."
        assert i18n.localise("43.2 us, 10 uF, 50 Ohm") == "43,2 µs, 10 µF, 50 Ω"


@pytest.mark.parametrize("bad", ["fr", "EN", "", "es_ES"])
def test_a_language_outside_the_list_is_refused_naming_the_list(bad):
    with pytest.raises(DesignError) as info:
        i18n.check_language(bad)
    assert info.value.param == "lang" and "en, es" in str(info.value)


def test_the_pages_messages_are_its_scripts_calls_and_its_htmls_words():
    """Issue 29: the page's words are the catalogue's: D.t and D.N_ calls (one nested in another's arguments too),
    the HTML's text and the attributes a reader sees or hears; an element marked translate="no" is left out."""
    from pathlib import Path
    static = Path(i18n.__file__).resolve().parent.parent / "web" / "static"
    found = i18n.page_messages()
    words = dict((t, line) for line, t in i18n.html_words((static / "plant.html").read_text()))
    h1 = re.search(r"<h1>([^<]+)</h1>", (static / "plant.html").read_text()).group(1)
    assert h1 in found and h1 in words
    placeholder = re.search(r'name="r-min" placeholder="([^"]+)"', (static / "plant.html").read_text()).group(1)
    assert placeholder in found   # "1k": a letter in it
    spec = re.search(r'<textarea translate="no"[^>]*placeholder="([^"]+)"', (static / "check.html").read_text())
    assert spec and " ".join(spec.group(1).replace("&#10;", " ").split()) not in found
    script = (static / "identify.js").read_text()
    nested = re.search(r'D\.t\("its margins above; best model \{model\}",[^;]*D\.t\("([^"]+)"\)', script)
    assert nested and nested.group(1) in found and "its margins above; best model {model}" in found
    # every message found is in the catalogue (make i18n's check covers the page)
    assert set(found) <= set(i18n.extract())


@pytest.mark.parametrize("header, lang", [("es-ES,es;q=0.9,en;q=0.8", "es"), ("en-US,en;q=0.9,es;q=0.8", "en"),
                                          ("fr-FR,fr;q=0.9", "en"), ("fr;q=1, es;q=0.5", "es"), ("es;q=0", "en"),
                                          ("", "en"), (None, "en"), ("es;q=bad, es-MX", "es")])
def test_the_browsers_preference_chooses_a_language_of_the_list(header, lang):
    assert i18n.negotiate(header) == lang


def test_the_pages_catalogue_has_the_languages_decimal_symbol():
    assert i18n.page_catalogue("es") == {"lang": "es", "decimal": get_decimal_symbol("es"),
                                         "messages": i18n.catalogue("es")}
    assert i18n.page_catalogue(None) == {"lang": "en", "decimal": get_decimal_symbol("en"), "messages": {}}
    with pytest.raises(DesignError, match="lang must be one of en, es"):
        i18n.page_catalogue("../es")


def test_a_range_refusal_reads_in_the_language_in_force():
    """The library's range refusal goes through the catalogue (the web page's request in Spanish); English is the
    code's own text, the message starts with the parameter in both (so each front end names it its own way)."""
    from designer.core.ranges import RANGES
    r = RANGES["zeta"]
    with pytest.raises(DesignError) as en:
        r.check(-1.0, "zeta")
    assert str(en.value) == f"zeta must be {r.text()}, got -1" and en.value.param == "zeta"
    with i18n.language("es"):
        with pytest.raises(DesignError) as es:
            r.check(-1.0, "zeta")
        spanish = r.text()
    assert str(es.value).startswith("zeta ") and str(es.value) != str(en.value) and spanish in str(es.value)
    assert es.value.naming({"zeta": '"zeta"'}).startswith('"zeta" ')


def test_a_message_s_values_may_take_any_name_and_read_in_the_language_in_force():
    """A note's value named ``message`` (the optimiser's, inside design-pid's note) is a value like any other."""
    import pickle

    from designer.core.i18n import Message, catalogue, language, translated
    es = catalogue("es")
    note = Message("optimize: {message} after {n} closed-loop evaluations", message=Message("targets met"), n="12")
    assert note == "optimize: targets met after 12 closed-loop evaluations"
    assert pickle.loads(pickle.dumps(note)) == note
    with language("es"):
        assert translated(note) == es["optimize: {message} after {n} closed-loop evaluations"].format(
            message=es["targets met"], n="12")
