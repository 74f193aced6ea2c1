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
