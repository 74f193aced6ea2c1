"""designer.tolerance.chunks: the task every pool runs, and the error of a chunk lost twice."""

import numpy as np

from designer.core.errors import SimulatorError
from designer.tolerance.chunks import lost_twice, run_chunk
from designer.tolerance.runner import Draw

NOMINAL = {"R1": 1e3, "C1": 1e-8}
TOL = {"R1": 0.01, "C1": 0.05}


def _tau(context, values):
    return {"tau_s": context * values["R1"] * values["C1"]}


def test_a_chunk_is_its_samples_drawn_then_evaluated():
    draw = Draw(NOMINAL, TOL, 100, 5)
    out = run_chunk(_tau, 2.0, draw, 10, 30)
    whole = draw.values()
    for k in NOMINAL:
        assert np.array_equal(out["values"][k], whole[k][10:30])
    assert np.array_equal(out["figures"]["tau_s"], 2.0 * whole["R1"][10:30] * whole["C1"][10:30])


def test_a_chunk_lost_twice_is_a_simulator_error_naming_its_samples():
    err = lost_twice(16, 32, "its worker died")
    assert isinstance(err, SimulatorError)
    assert str(err) == "Monte Carlo: the chunk of samples 16..31 was lost twice (its worker died)"
