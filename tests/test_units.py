import math

import pytest
from hypothesis import given, strategies as st

from designer.errors import DesignError
from designer.units import format_eng, parse_positive, parse_value, value_code


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


def test_parse_positive_rejects_zero_and_negative():
    for text in ("0", "-1k"):
        with pytest.raises(DesignError, match="greater than 0"):
            parse_positive(text, "--fc")


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
