"""The square-wave bench test of a plant on a registered section (designer.plant.circuit_design,
``design-plant --topology NAME --square-freq HZ``), over the registry (a new section is picked up
without editing this file): one period in ngspice against the op-amp-aware model by the project's
NRMS rule (Xyce's, reltol 1 %, abstol 1 % of gain x amplitude, below 1 agrees); the model's
response is the closed form where there is one."""

import math

import numpy as np
import pytest

from designer.filters import REGISTRY
from designer.plant import circuit
from designer.plant.circuit_design import SQUARE_NRMS_PASS, design_circuit_plant
from designer.plant.spec import PlantSpec

TOPOLOGIES = [t for t in REGISTRY.values() if t.name != circuit.DEFAULT_TOPOLOGY]
IDS = [t.name for t in TOPOLOGIES]

pytestmark = pytest.mark.spice


def design_of(topology, opamp, square_ratio):
    ex = topology.example
    spec = PlantSpec(fc_hz=ex.fn_hz, zeta=None if ex.q is None else 1 / (2 * ex.q), gain=ex.gain, opamp=opamp,
                     square_hz=ex.fn_hz / square_ratio, topology=topology.name)
    return design_circuit_plant(spec, simulator="ngspice-cli")


@pytest.mark.parametrize("topology", TOPOLOGIES, ids=IDS)
def test_spice_under_the_square_wave_is_the_model(topology):
    """With a TL072 (13 V/us) every section follows its linear model (NRMS below 1); a low- or band-pass,
    whose output never jumps, to 1e-2 (measured: 3e-4 at most)."""
    r = design_of(topology, "TL072", 3)
    sq = r.square
    assert sq.nrms < SQUARE_NRMS_PASS and sq.check.ok and sq.check in r.checks
    if topology.kind in ("lowpass", "bandpass"):
        assert sq.nrms < 1e-2
    d = r.to_dict()["square_test"]
    assert d["pass"] and d["nrms"] == sq.nrms and d["generator"]["frequency_hz"] == pytest.approx(
        topology.example.fn_hz / 3)


def test_the_model_under_the_square_wave_is_the_closed_form():
    """rc-lowpass with the ideal op-amp: A (1 - exp(-t'/tau)) from the rising edge's middle, and its decay
    from the falling one's (tau = R1 C1)."""
    r = design_of(REGISTRY["rc-lowpass"], "ideal", 10)
    sq, test = r.square, r.square.test
    tau = r.values["R1"] * r.values["C1"]
    rise = test.delay_s + test.edge_s / 2
    a = test.amplitude_v
    step = lambda x: np.where(x > 0, 1 - np.exp(-np.clip(x, 0, None) / tau), 0.0)  # noqa: E731
    want = a * (step(sq.t - rise) - step(sq.t - rise - test.half_period_s))
    np.testing.assert_allclose(sq.y_model, want, atol=1e-5 * a)
    assert sq.nrms < 1e-2
    assert math.isclose(sq.abstol_v, 0.01 * a)


def test_a_slew_limited_edge_fails_the_check_with_a_note():
    """A high-pass's output jumps by the amplitude at each edge: the LM741 (0.5 V/us) slews it, the linear
    model does not."""
    r = design_of(REGISTRY["mfb-highpass"], "LM741", 10)
    assert not r.square.check.ok and r.square.nrms >= SQUARE_NRMS_PASS
    assert any("slew-limited" in n and "LM741" in n for n in r.notes)


def test_the_ideal_model_under_the_square_wave_is_the_closed_form_too():
    """rc-lowpass with an LM741: ``y_ideal`` is A (1 - exp(-t'/tau)) of the parts alone (tau = R1 C1, the
    op-amp's pole absent), and ``nrms_ideal`` the project's rule of SPICE against it."""
    from designer.core.compare import nrms
    r = design_of(REGISTRY["rc-lowpass"], "LM741", 10)
    sq, test = r.square, r.square.test
    tau = r.values["R1"] * r.values["C1"]
    rise = test.delay_s + test.edge_s / 2
    step = lambda x: np.where(x > 0, 1 - np.exp(-np.clip(x, 0, None) / tau), 0.0)  # noqa: E731
    want = test.amplitude_v * (step(sq.t - rise) - step(sq.t - rise - test.half_period_s))
    np.testing.assert_allclose(sq.y_ideal, want, atol=1e-5 * test.amplitude_v)
    assert sq.nrms_ideal == nrms(sq.y_ideal, sq.y_spice, sq.abstol_v, t=sq.t)
    t, waves = sq.waves()
    assert t is sq.t and waves["output_v"] is sq.y_spice and waves["analytic_v"] is sq.y_ideal


@pytest.mark.parametrize("topology", TOPOLOGIES, ids=IDS)
def test_the_default_square_wave_leaves_the_slowest_pole_1_5_settling_times(topology):
    """default_square_hz: the Sallen-Key plant's rule (recommend_square_wave) on the 2 % settling time
    ln(50)/sigma of the op-amp-aware model's slowest pole: the half period at least 1.5 of it."""
    from designer.plant.bench import recommend_square_wave
    from designer.plant.circuit_design import default_square_hz
    ex = topology.example
    r = design_circuit_plant(PlantSpec(fc_hz=ex.fn_hz, zeta=None if ex.q is None else 1 / (2 * ex.q), gain=ex.gain,
                                       opamp="TL072", topology=topology.name), simulate=False)
    den = circuit.opamp_tf(topology, r.values, r.opamp)[1]
    settle = math.log(50) / np.min(np.abs(np.roots(den).real))
    f = default_square_hz(r)
    assert f == recommend_square_wave(settle, 1.0).frequency_hz
    assert 0.5 / f >= 1.5 * settle
