"""The public API, as the README's library section uses it."""

import math

import numpy as np

import designer


def test_the_public_names_resolve_and_stay_lazy():
    for name in designer.__all__:
        assert getattr(designer, name) is not None
    try:
        designer.not_a_name
    except AttributeError as exc:
        assert "not_a_name" in str(exc)
    else:
        raise AssertionError("unknown names must raise AttributeError")


def test_library_use_from_the_readme():
    from designer import PlantSpec, design_plant, identify_step
    plant = design_plant(PlantSpec(fc_hz=3500, zeta=0.2), simulate=False)
    assert abs(plant.built.fn_hz / 3500 - 1) < 0.005
    # identify the plant's own analytic step (ideal op-amp) and find it again
    from designer.core.lti import step_response
    from designer.plant.model import plant_tf
    t = np.linspace(0, 3e-3, 3001)
    y = step_response(*plant_tf(plant.built), t)
    found = identify_step(t, y, step_time=0.0, step_amplitude=1.0)
    wn = found.best.params["wn_rad_s"]
    assert abs(wn / (2 * math.pi) / plant.built.fn_hz - 1) < 0.005
