"""check.limits: min/typ/max, absolute or relative to typ, report-only."""

import math

import pytest

from designer.check.limits import limit_from
from designer.core.errors import DesignError


def test_relative_bounds_resolve_against_typ():
    lim = limit_from("fn_hz", {"typ": "3.5k", "min": "-1%", "max": "+2%"}, "checks.fn_hz", "Hz")
    assert lim.min == pytest.approx(3500 * 0.99) and lim.max == pytest.approx(3500 * 1.02)
    # a negative typ: the percentage is of its magnitude, min stays below max
    neg = limit_from("x", {"typ": -2, "min": "-10%", "max": "+10%"}, "checks.x")
    assert neg.min == pytest.approx(-2.2) and neg.max == pytest.approx(-1.8)


def test_judge_says_the_value_against_the_limit():
    lim = limit_from("overshoot_pct", {"max": 55}, "checks.overshoot_pct")
    ok, text = lim.judge(60.0)
    assert not ok and "60" in text and "above max 55" in text
    assert lim.judge(50.0)[0]
    assert not lim.judge(None)[0] and "not measured" in lim.judge(math.nan)[1]


def test_band_inside():
    lim = limit_from("fn_hz", {"min": 3000, "max": 4200}, "checks.fn_hz")
    assert lim.inside(3100.0, 4100.0)
    assert not lim.inside(2900.0, 4100.0) and not lim.inside(None, None)


@pytest.mark.parametrize("entry, words", [
    ({"min": "abc"}, "is not a number"),
    ({"min": "-1%"}, "relative to typ, and there is no typ"),
    ({"min": 4, "max": 3}, "above max"),
    ({"typ": 5}, "needs min or max"),
    ({"typ": 5, "min": 1, "max": 2}, "typ 5 is outside"),
    ({"max": "55%"}, "needs a sign"),
    ({"max": True}, "needs a number"),
    ({"max": 1, "fail": "no way"}, "true or false"),
])
def test_bad_limits_are_one_line(entry, words):
    with pytest.raises(DesignError, match=words):
        limit_from("f", entry, "checks.f")
