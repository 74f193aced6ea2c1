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


def test_section_tolerance_is_the_libraries_monte_carlo_and_worst_case_with_the_opamps_gbw():
    """One tolerance analysis of a section plant for the command line and the page (issue 26): the worst case
    spreads the op-amp's GBW when the tolerances name it (the page's own copy refused it: "this design has no part
    GBW"), the Monte Carlo is the section engine's."""
    from designer.plant import circuit
    from designer.plant.circuit_design import design_circuit_plant, tolerance_nominal
    from designer.plant.spec import PlantSpec
    from designer.tolerance.mcspec import section_tolerance
    from designer.tolerance.parts import opamp_nominal, resolve
    from designer.tolerance.spice_mc import section_monte_carlo_engine
    from designer.tolerance.worstcase import worst_case
    result = design_circuit_plant(PlantSpec(fc_hz=1000, zeta=0.3, topology="mfb-lowpass"), simulate=False)
    tol = ("R=1%", "GBW=30%")
    got = section_tolerance(dataclasses.replace(result), None, worst_case=True, tol=tol)
    series = {"R": result.sourcing.r_series, "C": result.sourcing.c_series}
    nominal = {**tolerance_nominal(result), **opamp_nominal(tol, result.opamp)}
    want = worst_case(lambda v: circuit.evaluate((result.topology, result.opamp), v), nominal,
                      resolve(tol, nominal, series).of)
    assert got.worst_case.to_dict() == want.to_dict() and "GBW" in got.worst_case.to_dict()["fn_hz"]["min"][
        "deviations"]
    mc = MonteCarloSpec(n=200, seed=3, tol=tol, limits=("fn_hz=900:1.1k",))
    got = section_tolerance(dataclasses.replace(result), mc)
    want = section_monte_carlo_engine(result, series, 200, 3, "random", "uniform", tol, ("fn_hz=900:1.1k",))
    assert got.monte_carlo.to_dict() == want.to_dict()


def test_section_tolerance_refuses_a_slew_rate_spread_no_engine_simulates():
    """--tol SR on a section: the analytic model and an .ac sweep have no slew in them; refused (param SR), not
    silently ignored."""
    from designer.plant.circuit_design import design_circuit_plant
    from designer.plant.spec import PlantSpec
    from designer.tolerance.mcspec import section_tolerance
    for topology in ("mfb-lowpass", "mfb-highpass"):
        result = design_circuit_plant(PlantSpec(fc_hz=1000, zeta=0.3, topology=topology), simulate=False)
        with pytest.raises(DesignError) as e:
            section_tolerance(result, MonteCarloSpec(n=20, tol=("SR=20%",)))
        assert e.value.param == "SR"
        with pytest.raises(DesignError):
            section_tolerance(result, None, worst_case=True, tol=("SR=20%",))
