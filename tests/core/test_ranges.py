"""The one table of input ranges: its checks, and that the README states every range."""


import pytest
from helpers import ROOT
from hypothesis import given
from hypothesis import strategies as st

from designer.core.errors import DesignError
from designer.core.ranges import RANGES, Range, parse_in_range

README = ROOT / "README.md"


def test_readme_states_every_range():
    text = README.read_text()
    for key, r in RANGES.items():
        assert f"| {r.text()}" in text, key


@given(st.sampled_from(sorted(RANGES)), st.floats(allow_nan=True, allow_infinity=True))
def test_check_accepts_exactly_the_range(key, value):
    r = RANGES[key]
    inside = value == value and abs(value) != float("inf") and (
        (r.zero_ok and value == 0) or ((value > r.lo if r.lo_open else value >= r.lo) and value <= r.hi))
    if inside:
        assert r.check(value, "--x") == value
    else:
        with pytest.raises(DesignError, match=r"^--x must be "):
            r.check(value, "--x")


def test_messages_name_input_range_and_value():
    with pytest.raises(DesignError) as e:
        parse_in_range("1e-300", "--fc", "fc_hz")
    assert str(e.value) == "--fc must be 10 mHz to 10 MHz, got '1e-300'"
    assert Range(0, 1, "s", zero_ok=True, lo_open=True).text() == "0 or above 0 s up to 1 s"


def test_bounds_themselves_are_inside_whatever_their_sign():
    """Regression: for a negative lower bound the rounding slack pointed inward."""
    r = RANGES["capture_time_s"]
    assert r.lo < 0 and r.contains(r.lo) and r.contains(r.hi)
    assert not r.contains(r.lo * (1 + 1e-9))
