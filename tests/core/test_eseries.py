import numpy as np
import pytest

from designer.core import eseries
from designer.core.errors import DesignError, ParamError


def test_series_sizes_and_ordering():
    for name, vals in eseries.SERIES.items():
        assert len(vals) == int(name[1:])
        assert all(a < b for a, b in zip(vals, vals[1:]))


def test_e12_is_every_other_e24_and_e48_every_other_e96():
    assert eseries.SERIES["E12"] == eseries.SERIES["E24"][::2]
    assert eseries.SERIES["E48"] == eseries.SERIES["E96"][::2]


def test_e192_exception_and_geometric_steps():
    e192 = eseries.SERIES["E192"]
    assert e192[185] == 9.20  # the standard's one deviation from round(10**(i/192), 2)
    formula = [round(10 ** (i / 192), 2) for i in range(192)]
    assert [i for i, (a, b) in enumerate(zip(e192, formula)) if a != b] == [185]
    # E96 as printed on 1 % resistors: a few spot checks from the standard's table
    assert {1.02, 4.99, 9.76} <= set(eseries.SERIES["E96"])


def test_values_in_bounds_include_the_bounds():
    v = eseries.values("E24", 1e3, 1e6)
    assert v[0] == 1e3 and v[-1] == 1e6 and v.size == 3 * 24 + 1
    c = eseries.values("E12", 1e-9, 1e-5)
    assert c.size == 4 * 12 + 1


def test_nearest_by_log_distance():
    assert eseries.nearest(819.1, "E24") == 820.0
    assert eseries.nearest(252.445e-9, "E12") == pytest.approx(270e-9)
    # log distance, not linear: 1.48 is nearer 1.5 than 1.2 either way, 1.35 goes to 1.5 in log (1.342 is the mid)
    assert eseries.nearest(1.35, "E12") == 1.5


def test_unknown_series_is_a_clear_error():
    with pytest.raises(DesignError, match="allowed: E3"):
        eseries.series_name("E25")
    assert eseries.series_name("e96") == "E96"


def test_part_bounds_are_checked_once_and_name_the_parameter():
    b = eseries.PartBounds(r_series="e24", c_series="12", r_min="1k", c_max=np.float64(1e-5))
    assert (b.r_series, b.c_series, b.r_min, b.c_max) == ("E24", "E12", 1e3, 1e-5)
    assert type(b.c_max) is float
    assert eseries.check_bounds("e24", "12", 1e3, 1e6, 1e-9, 1e-5) == ("E24", "E12")
    with pytest.raises(ParamError) as e:
        eseries.PartBounds(r_min=1e6, r_max=1e3)
    assert str(e.value) == "r_min (1e+06 Ohm) is above r_max (1000 Ohm)" and e.value.param == "r_min"
    assert e.value.naming({"r_min": "--r-min", "r_max": "--r-max"}).startswith("--r-min (1e+06 Ohm) is above --r-max")
    with pytest.raises(DesignError, match="^c_max must be 100 fF to 1 F, got inf"):
        eseries.PartBounds(c_max=float("inf"))
    with pytest.raises(DesignError, match="^r_min: 'x' is not a number"):
        eseries.PartBounds(r_min="x")


def test_smallest_series_holds_the_value_and_is_the_coarsest():
    """Brute force over every value of every series, in several decades."""
    from designer.core.eseries import SERIES, smallest_series
    order = list(SERIES)
    for name, vals in SERIES.items():
        for v in vals:
            for dec in (1e-12, 1e-3, 1.0, 1e3, 1e6):
                found = smallest_series(v * dec)
                assert order.index(found) <= order.index(name)
                assert v in SERIES[found]
                assert all(v not in SERIES[coarser] for coarser in order[:order.index(found)])
    assert smallest_series(1234.0) is None and smallest_series(0.0) is None
