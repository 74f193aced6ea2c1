"""The plant wing's conformance over the registry (:data:`designer.filters.REGISTRY`): every
registered topology, picked up without editing this file, through the plant's generic
search (:mod:`designer.plant.circuit`) against brute force, its op-amp-aware polynomials
against the nodal analysis, its vectorised figures against the scalar ones. The design from
the CLI, the check-design spec and the Monte Carlo rows are in ``tests/cli/test_plant_topology.py``.
"""

import numpy as np
import pytest

from designer.core import eseries
from designer.core.opamps import get as get_opamp
from designer.filters import REGISTRY
from designer.plant import circuit

TOPOLOGIES = list(REGISTRY.values())
IDS = list(REGISTRY)


def plant_target_of(topology):
    """The topology's example as a plant target (fn, zeta, gain)."""
    ex = topology.example
    return circuit.plant_target(topology, ex.fn_hz, None if ex.q is None else 1 / (2 * ex.q), ex.gain)


def small_grid():
    """A small grid: E3 resistors over a decade, E3 capacitors over two decades."""
    return eseries.values("E3", 1e3, 10e3), eseries.values("E3", 1e-9, 100e-9)


@pytest.mark.parametrize("width", [1, 20])
@pytest.mark.parametrize("topology", TOPOLOGIES, ids=IDS)
def test_search_is_brute_force_over_its_candidate_set(topology, width):
    """The vectorised search ranks as one-at-a-time enumeration of the same set; with a width
    wider than the series every resistor takes every series value (the whole grid). The candidate
    set's search on every section (``fast=False``); a section's own fast path is held to brute force
    over the whole grid below."""
    target = plant_target_of(topology)
    rv, cv = small_grid()
    blocks = circuit.candidate_set(topology, target, rv, cv, width)
    if width == 20:
        for block in blocks:
            for p in topology.parts:
                if p.kind == "R":
                    assert np.array_equal(block[p.ref], rv)
    got = circuit.search(topology, target, rv, cv, top=4, width=width, fast=False)
    ref = circuit.brute_force(topology, target, blocks, top=4)
    assert [c.values for c in got] == [c.values for c in ref]
    assert [c.worst for c in got] == pytest.approx([c.worst for c in ref], rel=1e-12)
    # the figures of the best recomputed from its values
    f = topology.figures(got[0].values)
    assert got[0].fn_hz == pytest.approx(f.fn_hz, rel=1e-12)


@pytest.mark.parametrize("topology", TOPOLOGIES, ids=IDS)
def test_opamp_aware_polynomials_equal_the_nodal_response(topology):
    """det Y_out / det Y interpolated from n + 1 points equals the solved nodal system at other points."""
    opamp = get_opamp("LM741")
    values = topology.synthesize(topology.example)
    num, den = circuit.opamp_tf(topology, values, opamp)
    f = np.logspace(np.log10(topology.example.fn_hz) - 2, np.log10(topology.example.fn_hz) + 2, 41)
    s = 2j * np.pi * f
    h_poly = np.polyval(num, s) / np.polyval(den, s)
    h_nodal = topology.response(values, s, opamp)
    assert np.allclose(h_poly, h_nodal, rtol=1e-7, atol=1e-12 * np.max(np.abs(h_nodal)))


@pytest.mark.parametrize("topology", TOPOLOGIES, ids=IDS)
def test_vectorised_plant_figures_equal_the_scalar_ones(topology):
    """circuit_figures over arrays of values (the Monte Carlo's engine) equals it element by element."""
    opamp = get_opamp("LM741")
    nominal = topology.synthesize(topology.example)
    rng = np.random.default_rng(26)
    batch = {r: v * (1 + 0.1 * rng.uniform(-1, 1, 7)) for r, v in nominal.items()}
    arrays = circuit.circuit_figures(topology, batch, opamp)
    for i in range(7):
        one = circuit.circuit_figures(topology, {r: float(v[i]) for r, v in batch.items()}, opamp)
        for k in circuit.FIGURES:
            assert np.asarray(arrays[k])[i] == pytest.approx(float(one[k]), rel=1e-9, nan_ok=True), k


@pytest.mark.parametrize("topology", TOPOLOGIES, ids=IDS)
def test_sensitivities_cover_the_declared_parts_and_scale_invariance(topology):
    """One entry per declared part; an impedance scaling (every R times s, every C over s) leaves
    wn and zeta unchanged, so the R sensitivities sum to the C ones (ideal model, closed form)."""
    values = topology.synthesize(topology.example)
    sens = circuit.sensitivities(topology, values)
    assert list(sens) == list(topology.designators)
    r_sum = sum(s["wn"] for ref, s in sens.items() if ref[0] == "R")
    c_sum = sum(s["wn"] for ref, s in sens.items() if ref[0] == "C")
    assert r_sum == pytest.approx(c_sum, abs=1e-6)
    # wn = 1/sqrt(prod RC) scaled: the total over all parts is -1 for wn of a second-order section
    assert r_sum + c_sum == pytest.approx(-2.0 if topology.order == 2 else -2.0, abs=1e-6)


@pytest.mark.parametrize("topology", TOPOLOGIES, ids=IDS)
def test_corner_frequencies_are_at_the_passband_gain_over_root_two(topology):
    values = topology.synthesize(topology.example)
    gain = topology.figures(values).gain
    corners = circuit.corner_frequencies(topology, values)
    assert len(corners) == (2 if topology.kind == "bandpass" else 1)
    for f in corners:
        assert abs(topology.response(values, 2j * np.pi * f)) == pytest.approx(gain / np.sqrt(2), rel=1e-9)
