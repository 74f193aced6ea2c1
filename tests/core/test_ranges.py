"""The one table of input ranges: its checks, and that the README states every range."""


import pytest
from helpers import ROOT
from hypothesis import given
from hypothesis import strategies as st

from designer.core.errors import DesignError, ParamError
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


def test_values_of_the_wrong_type_are_refused_in_one_line():
    for value, shown in (("3500", "'3500'"), (True, "bool"), ([1.0], "list"), (None, "NoneType")):
        with pytest.raises(DesignError) as e:
            RANGES["fc_hz"].check(value, "fc_hz")
        assert str(e.value) == f"fc_hz must be a number, got {shown}" and e.value.param == "fc_hz"
    # text is what parse_in_range takes; a refusal quotes it as typed
    assert parse_in_range("3.5k", "fc_hz", "fc_hz") == 3500.0
    with pytest.raises(DesignError) as e:
        parse_in_range("abc", "fc_hz", "fc_hz")
    assert e.value.param == "fc_hz"


def test_a_message_about_several_parameters_reads_in_either_naming():
    e = ParamError("{r} and {c} go together; see {file}.json", params=("r", "c"))
    assert str(e) == "r and c go together; see {file}.json" and e.param == "r"
    assert e.naming({"r": "--r", "c": "--c"}) == "--r and --c go together; see {file}.json"
    # a marker the library spells differently, e.g. a keyword argument
    e = ParamError("use {square_hz} above 1 Hz, or {no_sim}")
    assert str(e) == "use square_hz above 1 Hz, or simulate=False"
    assert e.naming({"square_hz": "--square-freq", "no_sim": "--no-sim"}) == "use --square-freq above 1 Hz, or --no-sim"
