"""The plant wing's conformance over the registry (:data:`designer.filters.REGISTRY`): every
registered topology, picked up without editing this file, through the plant's generic
search (:mod:`designer.plant.circuit`) against brute force, its op-amp-aware polynomials
against the nodal analysis, its vectorised figures against the scalar ones. The design from
the CLI, the check-design spec and the Monte Carlo rows are in ``tests/cli/test_plant_topology.py``.
"""

import dataclasses
import math

import numpy as np
import pytest

from designer.core import eseries
from designer.core.errors import DesignError
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
    assert list(sens) == list(topology.designators) + list(topology.sensitivity_parameters())
    sens = {ref: sens[ref] for ref in topology.designators}
    r_sum = sum(s["wn"] for ref, s in sens.items() if ref[0] == "R")
    c_sum = sum(s["wn"] for ref, s in sens.items() if ref[0] == "C")
    assert r_sum == pytest.approx(c_sum, abs=1e-6)
    # wn = 1/sqrt(prod RC) scaled: the total over all parts is -1 for wn of a second-order section
    assert r_sum + c_sum == pytest.approx(-2.0 if topology.order == 2 else -2.0, abs=1e-6)


def _log_difference(f_up: float, f_down: float, h: float) -> float:
    return math.log(f_up / f_down) / math.log((1 + h) / (1 - h))


@pytest.mark.parametrize("amp", ["LM741", "TL072", "NE5532"])
@pytest.mark.parametrize("topology", TOPOLOGIES, ids=IDS)
def test_op_amp_rows_are_finite_differences_of_the_sections_own_figures(topology, amp):
    """GBW's and A0's rows (the op-amp-aware model's only) against a central difference of the section's own
    circuit_figures, one op-amp moved at a time, at an independent step (1e-3: its truncation ~1e-7 relative,
    its rounding ~1e-10). The rows' step, 1e-6 (the plant's JSON's bits), resolves a sensitivity to ~3e-8 with
    a closed-form model and ~2e-7 with the nodal one (its Cramer determinants' ~1e-13 rounding over 2e-6,
    measured over the registry with LM741, TL072, NE5532 and LM358): A0's row of wn, itself 1e-8 to 1e-7,
    is noise at that level, which is why the sheets show the op-amp's rows to four decimals."""
    opamp = get_opamp(amp)
    values = topology.synthesize(topology.example)
    sens = circuit.sensitivities(topology, values, opamp)
    assert list(sens)[-2:] == list(circuit.OPAMP_PARAMETERS)
    h = 1e-3
    for label, field in circuit.OPAMP_PARAMETERS.items():
        up, down = (circuit.circuit_figures(topology, values,
                                            dataclasses.replace(opamp, **{field: getattr(opamp, field) * m}))
                    for m in (1 + h, 1 - h))
        for key, figure in (("wn", "fn_hz"), ("zeta", "zeta")):
            if topology.order == 1 and key == "zeta":
                assert sens[label][key] is None
                continue
            want = _log_difference(float(up[figure]), float(down[figure]), h)
            assert sens[label][key] == pytest.approx(want, rel=1e-5, abs=3e-7), (label, key)


@pytest.mark.parametrize("topology", TOPOLOGIES, ids=IDS)
def test_the_ideal_rows_and_figures_are_the_sections_ideal_pair(topology):
    """The ideal sensitivities and circuit_figures' ideal_* are the section's one ideal pair
    (:meth:`~designer.filters.topology.Topology.ideal_wn_zeta`, issue 26): each row the log difference of the
    hook's wn and zeta at the part moved by 1 +- 1e-6, to the bit; ideal_fn_hz and ideal_zeta its pair
    (NaN zeta for a first-order section)."""
    values = topology.synthesize(topology.example)
    sens = circuit.sensitivities(topology, values)
    h = 1e-6
    for ref in topology.designators:
        (w_up, z_up), (w_dn, z_dn) = (topology.ideal_wn_zeta({**values, ref: values[ref] * m}) for m in (1 + h, 1 - h))
        assert sens[ref]["wn"] == _log_difference(float(w_up), float(w_dn), h)
        assert sens[ref]["zeta"] == (None if topology.order == 1 else _log_difference(float(z_up), float(z_dn), h))
    fig = circuit.circuit_figures(topology, values)
    fn, zeta = topology.ideal_pair(values)
    assert float(fig["ideal_fn_hz"]) == fn
    assert math.isnan(fig["ideal_zeta"]) if topology.order == 1 else float(fig["ideal_zeta"]) == zeta


@pytest.mark.parametrize("topology", TOPOLOGIES, ids=IDS)
def test_without_a_real_op_amp_there_are_no_op_amp_rows(topology):
    values = topology.synthesize(topology.example)
    ideal = circuit.sensitivities(topology, values)
    assert not set(circuit.OPAMP_PARAMETERS) & set(ideal)
    assert circuit.sensitivities(topology, values, get_opamp("ideal")) == ideal


GAIN_SECTIONS = [t for t in TOPOLOGIES if t.sensitivity_parameters()]


@pytest.mark.parametrize("amp", [None, "LM741"])
@pytest.mark.parametrize("topology", GAIN_SECTIONS, ids=[t.name for t in GAIN_SECTIONS])
def test_the_gain_row_is_the_chain_rule_through_each_gain_resistor(topology, amp):
    """K's row (the section moves its gain pair so that K alone changes) against the gain resistors' rows:
    wn and zeta depend on R3 and R4 only through K, so S_y^K = S_y^x / S_K^x for each x of the pair, S_K^x
    a central difference of the passband gain (the figures' K). With the op-amp, to the rows' resolution
    (the op-amp rows' test)."""
    assert topology.sensitivity_parameters() == ("K",)
    opamp = None if amp is None else get_opamp(amp)
    values = topology.synthesize(topology.example)
    sens = circuit.sensitivities(topology, values, opamp)
    h = 1e-4
    for ref in topology.choice_parts:
        gains = [topology.figures({**values, ref: values[ref] * m}).gain for m in (1 + h, 1 - h)]
        s_gain = _log_difference(*gains, h)
        for key in ("wn", "zeta"):
            assert sens["K"][key] == pytest.approx(sens[ref][key] / s_gain, rel=1e-6, abs=1e-9 if amp is None else 5e-7), \
                (ref, key)


@pytest.mark.parametrize("topology", GAIN_SECTIONS, ids=[t.name for t in GAIN_SECTIONS])
def test_moving_the_gain_leaves_the_network_and_names_unknown_parameters(topology):
    values = topology.synthesize(topology.example)
    moved = topology.with_parameter(values, "K", 1.5)
    assert topology.figures(moved).gain == pytest.approx(1.5 * topology.figures(values).gain, rel=1e-14)
    changed = [r for r in topology.designators if moved[r] != values[r]]
    assert len(changed) == 1 and changed[0] in topology.choice_parts
    with pytest.raises(DesignError, match="has no parameter 'Q'; it has K"):
        topology.with_parameter(values, "Q", 1.5)
    follower = next(t for t in TOPOLOGIES if not t.sensitivity_parameters())
    with pytest.raises(DesignError, match="it has none"):
        follower.with_parameter(follower.synthesize(follower.example), "K", 1.5)


@pytest.mark.parametrize("topology", TOPOLOGIES, ids=IDS)
def test_corner_frequencies_are_at_the_passband_gain_over_root_two(topology):
    values = topology.synthesize(topology.example)
    gain = topology.figures(values).gain
    corners = circuit.corner_frequencies(topology, values)
    assert len(corners) == (2 if topology.kind == "bandpass" else 1)
    for f in corners:
        assert abs(topology.response(values, 2j * np.pi * f)) == pytest.approx(gain / np.sqrt(2), rel=1e-9)


OWN_FIGURES = [t for t in TOPOLOGIES if t.sample_figures(t.synthesize(t.example)) is not None]


@pytest.mark.parametrize("amp", [None, "LM741", "TL072"])
@pytest.mark.parametrize("topology", OWN_FIGURES, ids=[t.name for t in OWN_FIGURES])
def test_a_sections_own_sample_figures_are_the_generic_ones_but_for_their_definitions(topology, amp):
    """A section's own Monte Carlo figures (Topology.sample_figures; circuit.evaluate takes them) against the
    generic circuit_figures over sampled builds: fn, zeta and the ideal figures to rounding; the step's
    overshoot (the exact model's first peak, not the dominant pair's formula) within 1e-4 relative and its
    peak time within 1 %; the gain the op-amp-aware model's at DC, K A0 / (A0 + K), where the generic one is K."""
    opamp = None if amp is None else get_opamp(amp)
    nominal = topology.synthesize(topology.example)
    rng = np.random.default_rng(7)
    values = {r: v * (1 + 0.05 * rng.uniform(-1, 1, 64)) for r, v in nominal.items()}
    own, generic = topology.sample_figures(values, opamp), circuit.circuit_figures(topology, values, opamp)
    assert own.keys() == set(circuit.FIGURES)
    assert circuit.evaluate((topology.name, opamp), values).keys() == own.keys()
    for k in ("fn_hz", "zeta", "q", "ideal_fn_hz", "ideal_zeta", "ideal_q"):
        np.testing.assert_allclose(own[k], generic[k], rtol=1e-12, err_msg=k)
    np.testing.assert_allclose(own["overshoot_pct"], generic["overshoot_pct"], rtol=1e-4)
    np.testing.assert_allclose(own["peak_time_s"], generic["peak_time_s"], rtol=1e-2)
    a0 = np.inf if opamp is None or opamp.ideal else opamp.a0
    k = np.asarray(generic["gain"])
    np.testing.assert_allclose(own["gain"], k * a0 / (a0 + k) if np.isfinite(a0) else k, rtol=1e-12)
    one = {r: v[5] for r, v in values.items()}     # a number for numbers
    assert {f: float(x) for f, x in topology.sample_figures(one, opamp).items()} == \
        {f: float(x[5]) for f, x in own.items()}
