"""A simulated step capture of a model (:mod:`designer.spice.model_step`):
noiseless, ngspice's step is the model's exact one (:meth:`ProcessModel.step`)
within 0.1 % of the step under both backends; the noise and quantisation are
the seeded generator's; every input is checked in one line naming it."""

import numpy as np
import pytest

from designer.core.errors import DesignError
from designer.core.process_build import fopdt, integrating, sopdt, underdamped
from designer.spice.model_step import (DURATION_SETTLING_TIMES, MAX_POINTS, default_duration_s,
                                       default_step_time_s, simulate_step, step_deck)

BACKENDS = ("pyspice", "ngspice-cli")
#: the accuracy asked of a noiseless capture: a fraction of the step's largest magnitude
TOL = 1e-3

MODELS = {
    "fopdt_dead_time": fopdt(2.0, 1e-3, 200e-6),
    "sopdt": sopdt(1.5, 1e-3, 0.3e-3, 300e-6),
    "underdamped": underdamped(1.0, 500.0, 0.3, 300e-6),
    "integrating": integrating(50.0, 10e-3, 1e-3),
    # seed 000's DC motor: Km = 1.25, tau_m = 0.1246 s (a = 2 V, W(inf) = 2.5, w(0.15 s) = 1.75)
    "motor_seed000": fopdt(1.25, 0.1246),
}


def _exact(model, t, t0, step_v):
    return step_v * model.step(t - t0)


@pytest.mark.spice
@pytest.mark.parametrize("backend", BACKENDS)
@pytest.mark.parametrize("name", MODELS)
def test_noiseless_step_is_the_models_exact_step(name, backend):
    model = MODELS[name]
    t, u, y = simulate_step(model, step_v=2.0, simulator=backend)
    duration = default_duration_s(model)
    t0 = default_step_time_s(duration)
    assert t.size == u.size == y.size == 2001
    assert t[0] == 0.0 and t[-1] == pytest.approx(duration, rel=1e-12)
    assert np.allclose(np.diff(t), duration / 2000, rtol=1e-9, atol=0)    # uniform
    assert np.array_equal(u, np.where(t > t0 + 1e-9 * duration, 2.0, 0.0))   # the step, to the grid
    ye = _exact(model, t, t0, 2.0)
    assert np.max(np.abs(y - ye)) <= TOL * np.max(np.abs(ye)), name


@pytest.mark.spice
def test_seed_motor_passes_the_seeds_own_points():
    """W(inf) = Km a = 2.5 and w(t0 = 0.15 s) = 1.75, as seed 000 reads them off its step."""
    model = MODELS["motor_seed000"]
    t0 = 0.2
    t, u, y = simulate_step(model, step_v=2.0, step_time_s=t0, duration_s=2.0, points=20001)
    assert y[-1] == pytest.approx(2.5, rel=1e-4)
    assert np.interp(t0 + 0.15, t, y) == pytest.approx(1.75, abs=2e-3)   # the seed's 1.75 is rounded


@pytest.mark.spice
@pytest.mark.parametrize("backend", BACKENDS)
def test_a_step_at_zero_and_a_few_points(backend):
    model = MODELS["fopdt_dead_time"]
    t, u, y = simulate_step(model, step_v=-1.0, step_time_s=0.0, duration_s=5e-3, points=11, simulator=backend)
    assert u[0] == 0.0 and np.all(u[1:] == -1.0)
    assert np.max(np.abs(y - _exact(model, t, 0.0, -1.0))) <= TOL * 2.0


@pytest.mark.spice
def test_noise_and_quantisation_are_the_seeded_generators():
    model = MODELS["sopdt"]
    clean = simulate_step(model)
    a = simulate_step(model, noise_v=0.01, seed=3)
    b = simulate_step(model, noise_v=0.01, seed=3)
    c = simulate_step(model, noise_v=0.01, seed=4)
    for x, y in zip(a, b):
        assert np.array_equal(x, y)
    assert not np.array_equal(a[2], c[2])
    # the input's draws first, then the output's, from default_rng(seed)
    rng = np.random.default_rng(3)
    du, dy = rng.standard_normal(2001), rng.standard_normal(2001)
    assert np.allclose(a[1] - clean[1], 0.01 * du, atol=1e-12)
    assert np.allclose(a[2] - clean[2], 0.01 * dy, atol=1e-12)
    q = simulate_step(model, noise_v=0.01, lsb_v=0.02, seed=3)
    for ch in (1, 2):
        k = q[ch] / 0.02
        assert np.allclose(k, np.round(k), atol=1e-9)
        assert np.max(np.abs(q[ch] - a[ch])) <= 0.01 + 1e-12   # rounded to the nearest step


def test_defaults():
    model = MODELS["motor_seed000"]
    # tau ln 50 for a first-order lag, five of them
    assert default_duration_s(model) == pytest.approx(DURATION_SETTLING_TIMES * 0.1246 * np.log(50), rel=1e-3)
    # 10 % of the record, then half a sample later: between two samples, where identify puts the edge
    assert default_step_time_s(2.0) == pytest.approx(0.2 + 0.5e-3)
    assert default_step_time_s(1.0, points=11) == pytest.approx(0.15)
    # a pure integrator has no settling time: five of its time scales 1/|K|
    assert default_duration_s(integrating(50.0)) == pytest.approx(DURATION_SETTLING_TIMES / 50.0)


def test_the_deck_marks_the_delayed_edge():
    deck = step_deck(MODELS["fopdt_dead_time"], step_v=1.0, step_time_s=1e-3, duration_s=10e-3, points=1001)
    src = next(ln for ln in deck.splitlines() if ln.startswith("Vu "))
    # time points where the line's output steps: the integrators see no corner there
    assert "PWL(0 0 0.001 0 " in src and " 0.0012 1 " in src
    assert deck.rstrip().endswith(".end") and ".control" not in deck
    tran = next(ln for ln in deck.splitlines() if ln.startswith(".tran"))
    assert float(tran.split()[1]) <= 10e-6   # at most the sample interval


@pytest.mark.parametrize("kwargs,param,words", [
    ({"step_v": 0.0}, "step_v", "non-zero"),
    ({"step_v": float("nan")}, "step_v", "finite"),
    ({"step_v": "1"}, "step_v", "must be a number"),
    ({"points": 9}, "points", "10 to 1000000"),
    ({"points": MAX_POINTS + 1}, "points", "10 to 1000000"),
    ({"points": 100.0}, "points", "whole number"),
    ({"duration_s": 0.0}, "duration_s", "above 0 s"),
    ({"duration_s": 1e3}, "duration_s", "simulation steps"),
    ({"step_time_s": -1e-3}, "step_time_s", "0 or later"),
    ({"step_time_s": 1.0}, "step_time_s", "before the end of the record"),
    ({"noise_v": -1e-3}, "noise_v", "0 to"),
    ({"lsb_v": float("inf")}, "lsb_v", "finite"),
    ({"seed": -1}, "seed", "whole number"),
    ({"seed": 1.5}, "seed", "whole number"),
    ({"seed": True}, "seed", "whole number"),
])
def test_bad_inputs_are_one_line_naming_the_parameter(kwargs, param, words):
    with pytest.raises(DesignError) as e:
        simulate_step(MODELS["fopdt_dead_time"], **kwargs)
    assert e.value.param == param and str(e.value).startswith(param)
    assert words in str(e.value) and "\n" not in str(e.value)


def test_a_model_is_required():
    with pytest.raises(DesignError, match="model must be a ProcessModel"):
        simulate_step("K=1 tau=1m")


@pytest.mark.parametrize("kw, what", [
    ({"step_v": 1.0, "lsb_v": 10.0}, "the input's step"),
    ({"step_v": -2.0, "lsb_v": 0.6}, "the input's step"),
])
def test_an_lsb_too_coarse_for_the_step_names_the_parameter(kw, what):
    from designer.core.errors import ParamError
    from designer.spice.model_step import MIN_CODES
    with pytest.raises(ParamError) as exc:
        simulate_step(MODELS["motor_seed000"], **kw)
    msg = str(exc.value)
    assert exc.value.param == "lsb_v" and msg.startswith("lsb_v ") and what in msg
    swing = abs(kw["step_v"])
    assert f"{swing / kw['lsb_v']:.3g} quantisation steps" in msg and f"at least {MIN_CODES}" in msg
