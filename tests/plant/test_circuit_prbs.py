"""The PRBS bench test of a plant on a registered section (designer.plant.circuit_prbs,
``design-plant --topology NAME --stimulus prbs``), over the registry (a new section is picked up
without editing this file): ngspice's output under the sequence against the op-amp-aware model's
exact response to the held input by the project's NRMS rule (Xyce's, reltol 1 %, abstol 1 % of
gain x amplitude, below 1 agrees); the plan's two figures against their closed forms."""

import math

import numpy as np
import pytest

from designer.core.compare import nrms
from designer.core.prbs import BAND_FACTOR, HALF_POWER, SETTLE_MARGIN
from designer.filters import REGISTRY
from designer.plant import circuit
from designer.plant.circuit_design import design_circuit_plant
from designer.core.lti import slowest_settling_s
from designer.plant.circuit_prbs import band_edge_hz, section_plan, with_section_prbs
from designer.plant.spec import PlantSpec

TOPOLOGIES = [t for t in REGISTRY.values() if t.name != circuit.DEFAULT_TOPOLOGY]
IDS = [t.name for t in TOPOLOGIES]


def design_of(topology, opamp="TL072", simulate=False):
    ex = topology.example
    spec = PlantSpec(fc_hz=ex.fn_hz, zeta=None if ex.q is None else 1 / (2 * ex.q), gain=ex.gain, opamp=opamp,
                     topology=topology.name)
    return design_circuit_plant(spec, simulate=simulate, simulator="ngspice-cli")


@pytest.mark.spice
@pytest.mark.parametrize("topology", TOPOLOGIES, ids=IDS)
def test_spice_under_the_prbs_is_the_model(topology):
    """With a TL072 every section follows its op-amp-aware model under the sequence (NRMS below 1), and its
    JSON carries the run as the Sallen-Key plant's does."""
    r = with_section_prbs(design_of(topology), 2.0, simulator="ngspice-cli")
    run, c = r.prbs, r.prbs.capture
    gain = abs(r.figures["ideal"]["gain"])
    fit = nrms(c.analytic_opamp_v, c.output_v, 0.01 * gain * 2.0, t=c.time_s)
    assert fit < 1, (topology.name, fit)
    assert run.simulator == "ngspice-cli" and all(ch in r.checks for ch in run.checks)
    assert all(ch.ok for ch in run.checks)
    d = r.to_dict()
    assert list(d)[-2:] == ["prbs", "files"] and d["prbs"]["bits"] == run.plan.bits
    assert (d["prbs"]["low_v"], d["prbs"]["high_v"]) == (0.0, 2.0)
    # the input SPICE played is the plan's sequence, held
    assert np.allclose(c.input_v, np.repeat(run.plan.values(), c.input_v.size // run.plan.values().size), atol=1e-6)


@pytest.mark.parametrize("topology", TOPOLOGIES, ids=IDS)
def test_the_plan_covers_the_sections_band_and_slowest_mode(topology):
    """The clock's half-power band covers BAND_FACTOR x the band edge (a high-pass's corner, else the upper
    -3 dB frequency) and a period outlasts SETTLE_MARGIN x the slowest mode's 2 % time."""
    r = design_of(topology)
    plan = section_plan(r, 2.0)
    edges = r.figures["opamp"]["f3db_hz"]
    edge = band_edge_hz(r)
    assert edge == (min(edges) if topology.kind == "highpass" else max(edges))
    assert HALF_POWER / plan.dt_s >= BAND_FACTOR * edge * (1 - 1e-12)
    den = circuit.opamp_tf(topology, r.values, r.opamp)[1]
    sigma = min(abs(np.roots(den).real))
    assert plan.period_s >= SETTLE_MARGIN * math.log(50) / sigma * (1 - 1e-12)
    assert (plan.offset - plan.amplitude, plan.offset + plan.amplitude) == (0.0, 2.0)


def test_the_plan_of_an_rc_section_is_its_time_constants():
    """rc-lowpass with the ideal op-amp: the slowest mode is tau = R1 C1 (2 % after ln(50) tau), the band
    edge 1 / (2 pi tau)."""
    r = design_of(REGISTRY["rc-lowpass"], "ideal")
    tau = r.values["R1"] * r.values["C1"]
    den = circuit.opamp_tf(REGISTRY["rc-lowpass"], r.values, r.opamp)[1]
    assert slowest_settling_s(den) == pytest.approx(math.log(50) * tau, rel=1e-9)
    assert band_edge_hz(r) == pytest.approx(1 / (2 * math.pi * tau), rel=1e-6)


def test_without_spice_the_capture_is_the_model():
    r = with_section_prbs(design_of(REGISTRY["mfb-bandpass"]), 1.0, bits=6, clock_hz=20e3, simulate=False)
    c = r.prbs.capture
    assert r.prbs.simulator is None and r.prbs.nrms is None
    assert (r.prbs.plan.bits, r.prbs.plan.clock_hz) == (6, pytest.approx(20e3))
    assert np.array_equal(c.output_v, c.analytic_opamp_v)
    assert "Xgen vin prbs_source" in r.prbs.deck
