"""designer.plant.circuit: the plant on any topology. The Sallen-Key low-pass's generic search
against its own parallelogram search (the fast path), the op-amp-aware polynomials against the
seed plant's closed form, the vectorised dominant pair against core.lti's, the refusals."""

import numpy as np
import pytest
from hypothesis import example, given, settings
from hypothesis import strategies as st

from designer.core import eseries
from designer.core.errors import DesignError
from designer.core.lti import dominant_pair
from designer.core.opamps import get as get_opamp
from designer.filters import registry
from designer.plant import circuit, selection
from designer.plant.model import plant_tf_opamp
from designer.plant.sallenkey import SallenKeyParts

SK = registry.get(circuit.DEFAULT_TOPOLOGY)


@settings(max_examples=6, deadline=None)
@given(fc=st.floats(50.0, 20e3), zeta=st.floats(0.15, 1.5))
@example(fc=212.0, zeta=0.998046875)   # C1 = C2 just under the ratio bound 4 Q^2: left out before
@example(fc=185.0, zeta=1.09375)       # C2/C1 = 0.833 just under the bound 0.836: left out before
def test_generic_search_equals_the_sallen_key_fast_path(fc, zeta):
    """On the default bounds' E24/E12 grid the generic search finds the fast path's best error."""
    rv, cv = eseries.values("E24", 100, 1e6), eseries.values("E12", 100e-12, 10e-6)
    generic = circuit.search(SK, circuit.plant_target(SK, fc, zeta), rv, cv, top=1, fast=False)[0]
    fast = selection.joint_search(fc, zeta, rv, cv, 1.0, top=1)[0]
    assert generic.worst == pytest.approx(fast.worst, rel=1e-9, abs=1e-15)


def test_generic_search_equals_the_fast_path_on_a_small_grid():
    """Exhaustive on a grid small enough to enumerate: the fast path's brute force, the generic search
    with every resistor value a candidate."""
    rv, cv = eseries.values("E6", 1e3, 10e3), eseries.values("E6", 1e-9, 100e-9)
    for fc, zeta in ((3500.0, 0.2), (12e3, 0.7), (8e3, 1.1)):
        generic = circuit.search(SK, circuit.plant_target(SK, fc, zeta), rv, cv, top=1, width=20, fast=False)[0]
        exhaustive = selection.brute_force(fc, zeta, rv, cv, 1.0, top=1)[0]
        assert generic.worst == pytest.approx(exhaustive.worst, rel=1e-9)


def test_opamp_aware_polynomials_equal_the_seed_plant_closed_form():
    """Cramer's rule on the netlist gives plant_tf_opamp's third-order polynomials (seed 001's plant, LM741)."""
    values = {"R1": 820.0, "R2": 1e3, "C1": 10e-9, "C2": 220e-9}
    amp = get_opamp("LM741")
    num, den = circuit.opamp_tf(SK, values, amp)
    num_ref, den_ref = plant_tf_opamp(SallenKeyParts(820.0, 1e3, 10e-9, 220e-9), amp)
    assert den.shape == den_ref.shape
    assert np.allclose(den, den_ref, rtol=1e-8)
    assert num[-1] == pytest.approx(num_ref[-1], rel=1e-9)
    assert np.allclose(num[:-1], 0.0)


def test_vectorised_dominant_pair_is_core_lti_s():
    rng = np.random.default_rng(7)
    dens = np.column_stack([rng.uniform(1e-12, 1e-9, 50), rng.uniform(1e-8, 1e-5, 50), rng.uniform(1e-4, 1e-2, 50),
                            np.ones(50)])
    fn, z = circuit.dominant_pairs(dens)
    for i in range(50):
        f1, z1 = dominant_pair(dens[i])
        assert fn[i] == pytest.approx(f1, rel=1e-9)
        assert z[i] == pytest.approx(z1, rel=1e-9)


def test_vectorised_dominant_pair_is_core_lti_s_to_the_bit_on_complex_pairs():
    """|p| as hypot(Re, Im), the scalar abs() of dominant_pair: numpy's vectorised complex abs differed in the last
    bit on a third of these (the Sallen-Key plant's sensitivities, finite differences at 1e-6 of it, moved by
    up to 1e-8 relative)."""
    rng = np.random.default_rng(11)
    n = 400
    dens = np.column_stack([rng.uniform(1e-13, 1e-11, n), rng.uniform(1e-9, 1e-8, n), rng.uniform(1e-6, 1e-4, n),
                            np.ones(n)])
    fn, z = circuit.dominant_pairs(dens)
    assert all((fn[i], z[i]) == dominant_pair(dens[i]) for i in range(n))


def test_unrealisable_in_the_capacitor_range_is_one_line_naming_the_limit():
    """MFB low-pass at Q 5, gain 2: C2/C1 >= 4 Q^2 (1 + 2) = 300, beyond a decade of capacitors."""
    mfb = registry.get("mfb-lowpass")
    target = circuit.plant_target(mfb, 1e3, 0.1, 2.0)
    with pytest.raises(DesignError) as exc:
        circuit.search(mfb, target, eseries.values("E24", 100, 1e6), eseries.values("E12", 1e-9, 10e-9))
    msg = str(exc.value)
    assert "\n" not in msg and "capacitor ratio must be at least 300" in msg and exc.value.param == "c_max"
    # the numbers in engineering notation with their units (they were "1e-09 to 1e-08 F")
    assert "fn 1 kHz" in msg and "capacitors from 1 nF to 10 nF" in msg, msg


def test_a_damping_for_a_first_order_section_is_refused():
    with pytest.raises(DesignError) as exc:
        circuit.plant_target(registry.get("rc-lowpass"), 1e3, 0.5)
    assert exc.value.param == "zeta" and "first-order" in str(exc.value)
    with pytest.raises(DesignError):
        circuit.plant_target(registry.get("mfb-lowpass"), 1e3, None)


def test_a_section_beyond_the_op_amp_names_the_catalogue_op_amp_fast_enough():
    """An MFB low-pass at 50 kHz, Q 2.5, gain 3 needs 10 x 50k x 2.5 x 4 = 5 MHz: the LM741 (1 MHz) is
    refused and the slowest catalogue op-amp with 5 MHz named (core.opamps.fast_enough)."""
    from designer.core import opamps
    from designer.plant.circuit_design import GBW_MARGIN, check_opamp_reach
    mfb = registry.get("mfb-lowpass")
    target = circuit.plant_target(mfb, 50e3, 0.2, 3.0)
    need = GBW_MARGIN * 50e3 * 2.5 * 4
    with pytest.raises(DesignError) as exc:
        check_opamp_reach(mfb, target, get_opamp("LM741"))
    fast = opamps.fast_enough(need)
    assert exc.value.param == "opamp" and "\n" not in str(exc.value)
    assert fast is not None and fast.gbw_hz >= need and f"use --opamp {fast.name}" in str(exc.value)
    assert all(a.gbw_hz < need or a.gbw_hz >= fast.gbw_hz for a in map(opamps.get, opamps.names()) if not a.ideal)
    check_opamp_reach(mfb, target, fast)     # fast enough: no refusal


def test_generic_search_reaches_a_ratio_just_below_the_bound():
    """Bug fixed (hypothesis, the test above): the generic search left out capacitor ratios under the topology's
    continuous bound (4 Q^2 at unity gain), where rounded resistors still come nearer: at fc 212 Hz, zeta 0.998
    the fast path's C1 = C2 (zeta 1.0) against the generic search's best above the bound (0.314 % off)."""
    rv, cv = eseries.values("E24", 100, 1e6), eseries.values("E12", 100e-12, 10e-6)
    fc, zeta = 212.0, 0.998046875
    generic = circuit.search(SK, circuit.plant_target(SK, fc, zeta), rv, cv, top=1, fast=False)[0]
    fast = selection.joint_search(fc, zeta, rv, cv, 1.0, top=1)[0]
    assert generic.worst == pytest.approx(fast.worst, rel=1e-9, abs=1e-15)


@pytest.mark.parametrize("topology", list(registry.REGISTRY.values()), ids=registry.names())
def test_rounded_is_the_brute_force_over_each_part_s_series_neighbours(topology):
    """circuit.rounded (the seed's procedure's rounding on a section) ranks every combination of each part's
    two E-series values a side of the exact design as the scalar brute force does."""
    rv, cv = eseries.values("E24", 100, 1e6), eseries.values("E12", 100e-12, 10e-6)
    target = topology.example
    exact = topology.synthesize(target)
    got = circuit.rounded(topology, target, exact, rv, cv, top=3, fast=False)
    block = {}
    for p in topology.parts:
        series = rv if p.kind == "R" else cv
        lo, hi = series[series < exact[p.ref]][-2:], series[series >= exact[p.ref]][:2]
        block[p.ref] = np.concatenate([lo, hi])
    want = circuit.brute_force(topology, target, [block], top=3)
    assert [c.values for c in got] == [c.values for c in want]
    assert [c.worst for c in got] == pytest.approx([c.worst for c in want], rel=1e-12)


# --------------------------------------------------------------------------- the fast path (Topology.fast_search)

def _whole_grid(topology, target, rv, cv):
    """The whole grid as circuit.brute_force's one block; with gain, the pair the fast path takes (the series
    values nearest the ratio K - 1)."""
    block = {p.ref: (rv if p.kind == "R" else cv) for p in topology.parts}
    if topology.choice_parts:
        r4, r3 = eseries.nearest_ratio_of(target.gain - 1.0, rv)
        block.update(R3=np.array([r3]), R4=np.array([r4]))
    return [block]


@pytest.mark.parametrize("name, fc, zeta, gain", [
    ("sallen-key-lowpass", 3500.0, 0.2, 1.0), ("sallen-key-lowpass", 12e3, 0.7, 1.0),
    ("sallen-key-lowpass", 8e3, 1.1, 1.0), ("sallen-key-lowpass", 212.0, 0.998046875, 1.0),
    ("sallen-key-lowpass-gain", 3500.0, 0.2, 2.0), ("sallen-key-lowpass-gain", 1e3, 0.5, 1.47),
    ("sallen-key-lowpass-gain", 20e3, 1.4, 3.0)])
def test_the_sallen_key_fast_path_is_brute_force_over_the_whole_grid(name, fc, zeta, gain):
    """circuit.search through the section's fast path (its parallelogram search) ranks as the scalar brute
    force over every combination of a small grid (the gain pair: the nearest ratio, K - 1 exact here)."""
    topo = registry.get(name)
    rv, cv = eseries.values("E6", 1e3, 10e3), eseries.values("E6", 1e-9, 100e-9)
    target = circuit.plant_target(topo, fc, zeta, gain)
    got = circuit.search(topo, target, rv, cv, top=6)
    want = circuit.brute_force(topo, target, _whole_grid(topo, target, rv, cv), top=6)
    assert [c.values for c in got] == [c.values for c in want]
    assert [c.worst for c in got] == pytest.approx([c.worst for c in want], rel=1e-9)
    # the candidate set's search (nearest neighbours) can only do as well
    generic = circuit.search(topo, target, rv, cv, top=1, fast=False)[0]
    assert got[0].worst <= generic.worst * (1 + 1e-9)


@pytest.mark.parametrize("name, gain", [("sallen-key-lowpass", 1.0), ("sallen-key-lowpass-gain", 2.0)])
def test_the_fast_path_rounds_an_exact_design_over_each_kind_s_pooled_neighbours(name, gain):
    """circuit.rounded through the fast path: brute force over every combination of the R1/R2 neighbours pooled
    and the C1/C2 neighbours pooled (the seed plant's joint rounding), the gain pair the nearest ratio."""
    topo = registry.get(name)
    rv, cv = eseries.values("E24", 100, 1e6), eseries.values("E12", 100e-12, 10e-6)
    target = circuit.plant_target(topo, 3500.0, 0.2, gain)
    exact = topo.synthesize_rc(target, 1e3, 10e-9)
    got = circuit.rounded(topo, target, exact, rv, cv, top=5)

    def pool(refs, series):
        near = [np.concatenate([series[series < exact[r]][-2:], series[series >= exact[r]][:2]]) for r in refs]
        return np.unique(np.concatenate(near))
    block = _whole_grid(topo, target, pool(("R1", "R2"), rv), pool(("C1", "C2"), cv))[0]
    if topo.choice_parts:
        r4, r3 = eseries.nearest_ratio_of(gain - 1.0, rv)
        block.update(R3=np.array([r3]), R4=np.array([r4]))
    want = circuit.brute_force(topo, target, [block], top=5)
    assert [c.values for c in got] == [c.values for c in want]


def test_a_section_without_a_fast_path_says_so():
    """The hook's default: None (the generic candidate set)."""
    rv, cv = eseries.values("E6", 1e3, 10e3), eseries.values("E6", 1e-9, 100e-9)
    for name in registry.names():
        topo = registry.get(name)
        fast = topo.fast_search(topo.example, rv, cv, 3)
        assert (fast is None) == (not name.startswith("sallen-key-lowpass")), name


# --------------------------------------------------------------------------- the builds listed (every section)

def _cand(topology, values, worst):
    f = topology.figures(values)
    return circuit.Candidate(values, f.fn_hz, 1 / (2 * f.q), f.gain, worst)


def test_listed_keeps_one_build_per_response_at_the_level_in_the_band():
    """Moved from the seed plant's own listing (plant.design) into the generic search: 30k/120k/1n5/4n7 and
    3k/12k/15n/47n are one response, listed once at the level in 1k..100k; a build in the band within 0.5 %
    ranks before a better one outside it; R1 and R2 swapped at unity gain are one build."""
    far = _cand(SK, {"R1": 30e3, "R2": 120e3, "C1": 1.5e-9, "C2": 4.7e-9}, 0.001)     # R2 above 100k
    near = _cand(SK, {"R1": 3e3, "R2": 12e3, "C1": 15e-9, "C2": 47e-9}, 0.001)        # the same response
    other = _cand(SK, {"R1": 18e3, "R2": 30e3, "C1": 4.7e-9, "C2": 10e-9}, 0.002)
    swapped = _cand(SK, {"R1": 30e3, "R2": 18e3, "C1": 4.7e-9, "C2": 10e-9}, 0.002)
    assert circuit.listed(SK, [far, near, other], 5) == [near, other]
    assert circuit.listed(SK, [far, other], 5) == [other, far]
    assert circuit.listed(SK, [far, other], 5, band=False) == [far, other]
    assert circuit.listed(SK, [other, swapped], 5) == [other]
    # with gain the swap is another response (alpha = C1 + C2 (1 - K) breaks the symmetry), and the gain pair
    # does not scale with the level
    gain = registry.get("sallen-key-lowpass-gain")
    pair = {"R3": 10e3, "R4": 10e3}
    a, b = (_cand(gain, {**c.values, **pair}, c.worst) for c in (other, swapped))
    assert circuit.listed(gain, [a, b], 5) == [a, b]
    lo, hi = (_cand(gain, {**c.values, **pair}, c.worst) for c in (near, far))
    assert circuit.listed(gain, [hi, lo], 5) == [lo]


@pytest.mark.parametrize("topology", list(registry.REGISTRY.values()), ids=registry.names())
def test_every_section_lists_each_response_once_in_the_band_when_it_can(topology):
    """The listing rule on every registered section: no listed build is an impedance-scaled copy of
    another (resistors but a gain pair times s, capacitors over s), and the first is in 1k..100k when a
    ranked build there is within 0.5 % of the target."""
    ex = topology.example
    target = circuit.plant_target(topology, ex.fn_hz, None if ex.q is None else 1 / (2 * ex.q), ex.gain)
    rv, cv = eseries.values("E24", 100, 1e6), eseries.values("E12", 100e-12, 10e-6)
    ranked = circuit.search(topology, target, rv, cv, top=20)
    shown = circuit.listed(topology, ranked, 5)
    scaled = [p.ref for p in topology.parts if p.ref not in topology.choice_parts]

    def gain_ratio(c):
        return [c.values[r] / c.values[topology.choice_parts[0]] for r in topology.choice_parts]
    for i, a in enumerate(shown):
        for b in shown[:i]:
            # R times s, C over s: every resistor's ratio s, every capacitor's 1/s
            level = [a.values[r] / b.values[r] if r[0] == "R" else b.values[r] / a.values[r] for r in scaled]
            copy = np.allclose(level, level[0], rtol=1e-9) and np.allclose(gain_ratio(a), gain_ratio(b), rtol=1e-9)
            assert not copy, (a, b)

    def in_band(c):
        return all(circuit.R_BAND[0] <= c.values[r] <= circuit.R_BAND[1] for r in scaled if r[0] == "R")
    if any(in_band(c) and c.worst <= circuit.BAND_ERROR for c in ranked):
        assert in_band(shown[0]) and shown[0].worst <= circuit.BAND_ERROR


# --------------------------------------------------------------------------- --compensate-gbw (every section)

def _landing(topology, target, values, amp):
    """The worse of the op-amp-aware dominant pair's fn and zeta errors against the spec."""
    f = circuit.circuit_figures(topology, values, amp)
    errs = [abs(float(f["fn_hz"]) / target.fn_hz - 1)]
    if target.q is not None:
        errs.append(abs(float(f["zeta"]) * 2 * target.q - 1))
    return max(errs)


@pytest.mark.parametrize("topology", list(registry.REGISTRY.values()), ids=registry.names())
def test_compensate_gbw_never_lands_further_than_the_spec_s_own_build(topology):
    """circuit.compensate_gbw (both plant pipelines' --compensate-gbw) on every section, an LM741 near its reach
    (GBW = 20 x fn x Q x noise gain): the build kept lands at least as near the spec as the spec's own build, and
    nearer where the op-amp moves it by more than the series' rounding."""
    amp = get_opamp("LM741")
    ex = topology.example
    noise_gain = 1 + ex.gain if topology.inverting else ex.gain
    fc = min(20e3, amp.gbw_hz / (20 * (ex.q or 1.0) * noise_gain))
    target = circuit.plant_target(topology, fc, None if ex.q is None else 1 / (2 * ex.q), ex.gain)
    rv, cv = eseries.values("E24", 100, 1e6), eseries.values("E12", 100e-12, 10e-6)

    def rank(aim):
        return circuit.listed(topology, circuit.search(topology, aim, rv, cv, top=20), 5)
    plain = _landing(topology, target, rank(target)[0].values, amp)
    aim, ranked = circuit.compensate_gbw(topology, target, amp, rank)
    kept = _landing(topology, target, ranked[0].values, amp)
    assert kept <= plain + 1e-12
    # the shift is the op-amp's: an ideal op-amp leaves the aim where it is
    aim_ideal, _ = circuit.compensate_gbw(topology, target, get_opamp("ideal"), rank)
    assert aim_ideal is target
