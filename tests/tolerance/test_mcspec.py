"""MonteCarloSpec (designer.tolerance.mcspec): a Monte Carlo request checked once, its refusals naming its
parameters; plant_tolerance runs the same analysis the library's functions give."""

import dataclasses

import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

from designer.core.errors import DesignError
from designer.tolerance.mcspec import ENGINES, MonteCarloSpec, plant_tolerance
from designer.tolerance.montecarlo import MAX_SAMPLES, MIN_SAMPLES


def test_values_as_typed_become_numbers_and_tuples():
    mc = MonteCarloSpec(n="200", seed="7", tol="R=1%", limits=["fn_hz=3.3k:3.7k"], target_ci="1%")
    assert (mc.n, mc.seed, mc.tol, mc.limits) == (200, 7, ("R=1%",), ("fn_hz=3.3k:3.7k",))
    assert mc.target_ci == pytest.approx(0.01)


@pytest.mark.parametrize("kw, param", [
    ({"n": MIN_SAMPLES - 1}, "n"), ({"n": MAX_SAMPLES + 1}, "n"), ({"n": "2k"}, "n"), ({"n": 1.5}, "n"),
    ({"n": 100, "seed": -1}, "seed"), ({"n": 100, "sampler": "halton"}, "sampler"),
    ({"n": 100, "dist": "beta"}, "dist"), ({"n": 100, "engine": "magic"}, "engine"),
    ({"n": 100, "target_ci": "1%"}, "target_ci"), ({"n": 100, "target_ci": "x"}, "target_ci"),
    ({"n": 100, "limits": ("fn_hz=1:2",), "target_ci": "1%", "sampler": "lhs"}, "target_ci"),
    ({"n": 100, "spice_samples": 3}, "spice_samples"),
    ({"n": 100, "engine": "both", "limits": ("fn_hz=1:2",), "spice_samples": 101}, "spice_samples"),
    ({"n": 100, "tol": (3,)}, "tol"),
])
def test_a_refusal_names_the_parameter(kw, param):
    with pytest.raises(DesignError) as exc:
        MonteCarloSpec(**kw)
    assert exc.value.param == param and str(exc.value).startswith(param) and "\n" not in str(exc.value)
    assert "--" not in exc.value.naming({})


@settings(max_examples=60)
@given(st.one_of(st.integers(-10, 10 ** 8), st.text(max_size=6), st.floats(allow_nan=True)))
def test_any_count_is_taken_in_range_or_refused_in_one_line(n):
    try:
        mc = MonteCarloSpec(n=n)
    except DesignError as exc:
        assert exc.param == "n"
        return
    assert MIN_SAMPLES <= mc.n <= MAX_SAMPLES and mc.engine in ENGINES


def test_plant_tolerance_is_the_libraries_monte_carlo_and_worst_case():
    from designer.plant.design import design_plant
    from designer.plant.spec import PlantSpec
    from designer.tolerance.montecarlo import plant_monte_carlo, plant_worst_case
    result = design_plant(PlantSpec(fc_hz=3500, zeta=0.2), simulate=False)
    mc = MonteCarloSpec(n=300, seed=4, tol=("R=1%",), limits=("fn_hz=3.3k:3.7k",))
    got = plant_tolerance(dataclasses.replace(result), mc, worst_case=True)
    s = result.sourcing
    series = {"R": s.r_series, "C": s.c_series}
    want = plant_monte_carlo(result.built, series, result.opamp, 300, 4, "random", "uniform", ("R=1%",),
                             ("fn_hz=3.3k:3.7k",))
    assert got.monte_carlo.to_dict() == want.to_dict()
    assert got.worst_case.to_dict() == plant_worst_case(result.built, series, result.opamp, ("R=1%",)).to_dict()
