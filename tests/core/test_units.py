import math

import pytest
from hypothesis import given
from hypothesis import strategies as st

from designer.core.errors import DesignError
from designer.core.ranges import parse_in_range
from designer.core.units import format_eng, parse_value, value_code


@pytest.mark.parametrize("text,expected", [
    ("4k7", 4700.0), ("820", 820.0), ("10n", 10e-9), ("2u2", 2.2e-6), ("3.5k", 3500.0),
    ("1e-9", 1e-9), ("220nF", 220e-9), ("1M5", 1.5e6), ("4R7", 4.7), ("1meg", 1e6), ("3500Hz", 3500.0),
    ("10µ", 10e-6), (" 47k ", 47e3), ("-2.5m", -2.5e-3), ("1k", 1e3), ("100p", 100e-12),
])
def test_parse_engineering_notation(text, expected):
    assert parse_value(text) == pytest.approx(expected, rel=1e-12)


@pytest.mark.parametrize("text", ["", "abc", "nan", "inf", "1x", "k", "4k7k", "--1"])
def test_parse_rejects_non_numbers(text):
    with pytest.raises(DesignError, match="--fc"):
        parse_value(text, "--fc")


def test_parse_errors_name_the_parameter():
    with pytest.raises(DesignError) as e:
        parse_value("abc", "fc_hz")
    assert e.value.param == "fc_hz" and str(e.value).startswith("fc_hz: 'abc' is not a number")


@pytest.mark.parametrize("value,code", [(4700, "4k7"), (820, "820"), (10e-9, "10n"), (2.2e-6, "2u2"),
                                        (4.7, "4R7"), (1e6, "1M"), (1e3, "1k"), (220e-9, "220n")])
def test_value_code(value, code):
    assert value_code(value) == code


@given(st.sampled_from([1.0, 1.2, 1.5, 2.2, 3.3, 4.7, 6.8, 8.2]), st.integers(-12, 6))
def test_value_code_round_trips(mant, exp):
    v = float(f"{mant * 10 ** exp:.3g}")
    assert parse_value(value_code(v)) == pytest.approx(v, rel=1e-9)


def test_format_eng_has_units():
    assert format_eng(3500, "Hz") == "3.5 kHz"
    assert format_eng(145.8e-6, "s") == "145.8 us"
    assert format_eng(math.nan, "s") == "n/a"


@pytest.mark.parametrize("text,expected", [
    # regressions (issue 7.5): 10f was read as 10 farads, 3.5MEG and our own "1.6 kOhm" refused
    ("10f", 10e-15), ("100f", 100e-15), ("100fF", 100e-15), ("10pf", 10e-12), ("10F", 10.0),
    ("3.5MEG", 3.5e6), ("3.5Meg", 3.5e6), ("1meg5", 1.5e6), ("1.6 kOhm", 1600.0), ("4.7kΩ", 4700.0),
    ("100 ohms", 100.0), ("5ms", 5e-3), ("2 mV", 2e-3), ("330 Hz", 330.0), ("1 GHz", 1e9),
])
def test_parse_units_and_spice_prefixes(text, expected):
    assert parse_value(text) == pytest.approx(expected, rel=1e-12)


def test_femto_bound_is_not_farads():
    assert parse_in_range("100f", "c_min", "capacitor_f") == pytest.approx(1e-13)


@given(st.integers(1000, 9999), st.integers(-18, 12), st.sampled_from(["Ohm", "F", "Hz", "s", "V", ""]),
       st.booleans())
def test_what_we_print_reads_back(mant, exp, unit, negative):
    """parse(format(x, unit)) == x for every unit the tool prints (x with 4 significant digits)."""
    x = (-1 if negative else 1) * float(f"{mant}e{exp}")
    assert parse_value(format_eng(x, unit)) == pytest.approx(x, rel=1e-12)


def test_messages_are_short_and_plain():
    with pytest.raises(DesignError) as e:
        parse_value("x" * 500 + "\n", "--fc")
    msg = str(e.value)
    assert "\n" not in msg and len(msg) < 200
