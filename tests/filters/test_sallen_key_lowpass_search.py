
import numpy as np
import pytest
from helpers import peak_bytes
from hypothesis import given, settings
from hypothesis import strategies as st

from designer.core.eseries import nearest, values
from designer.core.ranges import RANGES
from designer.filters import sallen_key_lowpass_search as selection
from designer.filters.sallen_key_lowpass_synthesis import SallenKeyParts, ratios_from_rc
from designer.filters.sallen_key_lowpass_search import brute_force, joint_search

#: Peak numpy memory the search may use, whatever the series and bounds (the
#: benchmark's goal is 300 MB for the whole design-plant process).
SEARCH_MEMORY_BYTES = 64e6


def parts(cands):
    return [(c.r1, c.r2, c.c1, c.c2) for c in cands]


@settings(max_examples=60, deadline=None)
@given(fc=st.floats(10.0, 1e5), zeta=st.floats(0.05, 5.0), gain=st.sampled_from([1.0, 1.5, 2.2]),
       rs=st.sampled_from(["E6", "E12"]), cs=st.sampled_from(["E3", "E6"]))
def test_joint_search_equals_brute_force(fc, zeta, gain, rs, cs):
    rv = values(rs, 1e3, 1e5)
    cv = values(cs, 1e-9, 1e-6)
    fast = joint_search(fc, zeta, rv, cv, gain, top=4)
    slow = brute_force(fc, zeta, rv, cv, gain, top=4)
    assert [c.worst for c in fast] == pytest.approx([c.worst for c in slow], rel=1e-12, abs=1e-15)
    assert fast[0].worst == slow[0].worst


def test_seed_spec_joint_search_beats_rounding_each_part():
    rv, cv = values("E24", 1e3, 1e6), values("E12", 1e-9, 1e-5)
    best = joint_search(3500, 0.2, rv, cv)[0]
    # the issue: a joint E24/E12 search finds about 0.2 % for the seed's spec
    assert best.worst < 0.0025
    # rounding the seed's exact design part by part is several percent off
    m, n = ratios_from_rc(3500, 0.2, 1e3, 10e-9)
    r = SallenKeyParts(nearest(m * 1e3, "E24"), 1e3, 10e-9, nearest(n * 10e-9, "E12"))
    rounded = max(abs(r.fn_hz / 3500 - 1), abs(r.zeta / 0.2 - 1))
    assert rounded > 10 * best.worst
    assert best.fn_hz == pytest.approx(SallenKeyParts(best.r1, best.r2, best.c1, best.c2).fn_hz)


def test_joint_search_matches_brute_force_on_the_full_default_grid():
    # E24 resistors 1k..1M and E12 capacitors 1n..10u: 12.8 million combinations, chunked
    rv, cv = values("E24", 1e3, 1e6), values("E12", 1e-9, 1e-5)
    fast = joint_search(3500, 0.2, rv, cv, top=3)
    best = np.inf
    for c1 in cv:
        r1, r2, c2 = np.meshgrid(rv, rv, cv, indexing="ij")
        a = r1 * r2 * c1 * c2
        fn = 1 / (2 * np.pi * np.sqrt(a))
        z = c1 * (r1 + r2) / (2 * np.sqrt(a))
        best = min(best, float(np.max([np.abs(fn / 3500 - 1), np.abs(z / 0.2 - 1)], axis=0).min()))
    assert fast[0].worst == pytest.approx(best, rel=1e-12)


def test_results_are_sorted_and_unique():
    res = joint_search(1000, 0.7, values("E12", 1e3, 1e5), values("E6", 1e-9, 1e-6), top=10)
    worst = [c.worst for c in res]
    assert worst == sorted(worst)
    assert len({(c.r1, c.r2, c.c1, c.c2) for c in res}) == len(res)


@settings(max_examples=80, deadline=None)
@given(fc=st.floats(1e-2, 1e7), zeta=st.floats(0.01, 10.0), gain=st.sampled_from([1.0, 1.5, 2.0, 10.0, 100.0]),
       rs=st.sampled_from(["E3", "E6", "E12"]), cs=st.sampled_from(["E3", "E6"]),
       r_lo=st.floats(-1, 6), r_span=st.floats(0, 2.5), c_lo=st.floats(-13, -3), c_span=st.floats(0, 3),
       top=st.sampled_from([1, 4, 20, 200]))
def test_chunked_search_lists_exactly_the_brute_force_ranking(fc, zeta, gain, rs, cs, r_lo, r_span, c_lo,
                                                              c_span, top):
    # chunks of a few pairs, rows and candidates, and a seed from 2 pairs: every chunk
    # boundary and the bound's tightening are exercised, including unreachable targets
    # (errors above 100 %) and ties
    rv = values(rs, 10 ** r_lo, 10 ** (r_lo + r_span))
    cv = values(cs, 10 ** c_lo, 10 ** (c_lo + c_span))
    if rv.size == 0 or cv.size == 0:
        return
    with pytest.MonkeyPatch.context() as mp:
        mp.setattr(selection, "PAIRS_PER_CHUNK", 3)
        mp.setattr(selection, "ROWS_PER_BATCH", 7)
        mp.setattr(selection, "SEED_PAIRS", 2)
        fast = joint_search(fc, zeta, rv, cv, gain, top=top)
    assert parts(fast) == parts(brute_force(fc, zeta, rv, cv, gain, top=top))


def test_fine_series_search_memory_is_bounded():
    # issue 7: E96/E96 took 1.8 GB (capacitor pairs x resistors materialised at once)
    rv, cv = values("E96", 1e3, 1e6), values("E96", 1e-9, 1e-5)
    peak, res = peak_bytes(joint_search, 3500, 0.2, rv, cv, top=20)
    assert peak < SEARCH_MEMORY_BYTES and len(res) == 20


def test_widest_bounds_search_memory_is_bounded():
    # every E192 resistor the CLI accepts, E192 capacitors over the default decades
    r = RANGES["resistor_ohm"]
    rv, cv = values("E192", r.lo, r.hi), values("E192", 1e-9, 1e-5)
    peak, res = peak_bytes(joint_search, 3500, 0.2, rv, cv, top=20)
    assert peak < SEARCH_MEMORY_BYTES
    # the same best as on the default bounds, or better (more resistors to choose from)
    assert res[0].worst <= joint_search(3500, 0.2, values("E192", 1e3, 1e6), cv, top=1)[0].worst
    # a target out of reach of narrow capacitor bounds: the error bound starts loose
    # (every combination is above 100 % off) and still the memory stays bounded
    peak, res = peak_bytes(joint_search, 3500, 0.01, rv, values("E192", 1e-9, 1e-8), top=200)
    assert peak < SEARCH_MEMORY_BYTES
    assert len(res) == 200 and res[0].worst > 1


@pytest.mark.parametrize("fc,zeta,gain,r_bounds,c_bounds", [
    # fn five decades below the target, the damping out of reach too: an error bound with a
    # margin relative to itself went above 100 %, opened the fn band and evaluated 1.9
    # billion combinations (8 minutes)
    (833, 5.8, 100.0, (33e6, 1e9), (1.27e-3, 1.0)),
    # fn twelve decades below: every error is within 1e-12 of 100 %, the ranking's rounding
    # ties them all and the summed error decides; the tie class was enumerated (25 s)
    (7.15e6, 0.129, 1.5, (4.29e6, 1e9), (4.3e-3, 1.0)),
    (1e7, 10.0, 100.0, (1e6, 1e9), (1e-3, 1.0)),
])
def test_targets_far_out_of_reach_evaluate_few_combinations(fc, zeta, gain, r_bounds, c_bounds):
    rv, cv = values("E96", *r_bounds), values("E96", *c_bounds)
    evaluated = []
    real_add = selection._Best.add

    def counting_add(self, r1, r2, c1, c2):
        evaluated.append(r1.size)
        assert sum(evaluated) <= rv.size * cv.size * 50, "the search enumerates far more than the best few"
        return real_add(self, r1, r2, c1, c2)

    with pytest.MonkeyPatch.context() as mp:
        mp.setattr(selection._Best, "add", counting_add)
        res = joint_search(fc, zeta, rv, cv, gain, top=200)
    assert len(res) == 200 and all(0.99 < c.worst < 1 for c in res)
    # the same ranking on a grid small enough for brute force
    rv, cv = rv[::8], cv[::8]
    assert parts(joint_search(fc, zeta, rv, cv, gain, top=50)) == parts(brute_force(fc, zeta, rv, cv, gain, top=50))
