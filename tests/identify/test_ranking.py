"""The best of the scored models (designer.identify.ranking): the standard
error of two models' validation loss difference covers as a standard error
should, autocorrelated residuals included; a model tied with the best fit
within one standard error and with fewer parameters wins, and says why."""

import math
from types import SimpleNamespace

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st
from scipy.signal import lfilter

from designer.identify import ranking as rk


def test_nw_lags_is_newey_wests_rule_of_thumb():
    for n in (100, 372, 1000, 4388, 20_000):
        assert rk.nw_lags(n) == math.floor(4 * (n / 100) ** (2 / 9))
    assert rk.nw_lags(4388) == 9 and rk.nw_lags(1) == 0


def test_the_standard_error_covers_a_zero_mean_difference_as_one_sigma():
    """Two models of equal expected loss whose residuals are AR(1) (phi 0.7, so
    their squares' difference is correlated at lag k by 0.49^k): over 400 records
    the mean difference lies within one Newey-West standard error with the
    normal probability 0.683 (four binomial sigmas; measured 0.67); the naive
    error, the differences read as independent, covers far less (0.44
    expected, 0.46 measured)."""
    inside = naive = 0
    runs, n = 400, 2000
    for i in range(runs):
        rng = np.random.default_rng(100 + i)
        ea, eb = (lfilter([1.0], [1.0, -0.7], rng.standard_normal(n)) for _ in range(2))
        dbar, se = rk.loss_difference(ea, eb)
        d = ea ** 2 - eb ** 2
        assert dbar == pytest.approx(d.mean(), rel=1e-12)
        inside += abs(dbar) <= se
        naive += abs(dbar) <= d.std() / math.sqrt(n)
    p = math.erf(1 / math.sqrt(2))
    sigma = math.sqrt(p * (1 - p) / runs)
    assert abs(inside / runs - p) <= 4 * sigma, inside / runs
    assert naive / runs < p - 4 * sigma, naive / runs


def _orthogonal(v, *others):
    """``v`` with its components along ``others`` removed (Gram-Schmidt)."""
    v = np.array(v, float)
    for o in others:
        v -= (v @ o) / (o @ o) * o
    return v


def _candidate(label, kind, e, spread, valid=True):
    fit = 100.0 * (1.0 - np.linalg.norm(e) / spread)
    return SimpleNamespace(label=label, kind=kind, params={}, valid=valid, fit_percent=fit,
                           validation=SimpleNamespace(residuals=np.asarray(e, float), spread=spread))


def test_a_tie_within_the_margin_goes_to_fewer_parameters():
    """A lead-lag (5 parameters) fitting best, an SOPDT (4) whose residual is
    the lead-lag's plus a part 0.2 % of the noise (the synthetic SOPDT's case:
    0.002 point apart), an FOPDT (3) 0.3 of the noise worse and an invalid model
    fitting better than all: the SOPDT wins, said so with the margin, and the
    fit it gives up is within that margin; without the SOPDT the lead-lag wins
    (the FOPDT's difference is resolved), and nothing valid gives None."""
    rng = np.random.default_rng(7)
    n = 3000
    t = np.arange(n)
    noise = rng.standard_normal(n)
    slow, other = np.sin(2 * np.pi * t / 300), np.cos(2 * np.pi * t / 170)
    signal = 4.0 * slow
    spread = float(np.linalg.norm(signal + noise - (signal + noise).mean()))
    small = _orthogonal(slow, noise)
    big = _orthogonal(other, noise, small)
    cands = [_candidate("output-error oe fopdt", "fopdt", noise + 0.3 * big / np.std(big), spread),
             _candidate("output-error oe lead-lag", "lead-lag", noise, spread),
             _candidate("output-error oe sopdt", "sopdt", noise + 0.002 * small / np.std(small), spread),
             _candidate("spectral asymptotes double-pole", "double-pole", 0.5 * noise, spread, valid=False)]
    r = rk.rank(cands)
    assert (r.top, r.best) == (1, 2) and r.tied == (1, 2)
    assert cands[1].fit_percent - cands[2].fit_percent <= r.margin
    assert r.note.startswith("tied with output-error oe lead-lag within the margin (fit ")
    assert r.note.endswith("fewer parameters (4 against 5)")
    r2 = rk.rank(cands[:2] + cands[3:])
    assert (r2.top, r2.best, r2.tied, r2.note, r2.margin) == (1, 1, (1,), "", 0.0)
    assert rk.rank([cands[3]]) is None and rk.rank([]) is None


def test_parameter_count():
    assert [rk.parameter_count(k, {}) for k in ("fopdt", "double-pole", "overdamped", "sopdt", "underdamped",
                                                 "integrating", "lead-lag")] == [3, 3, 4, 4, 4, 2, 5]
    assert rk.parameter_count("other", {"K": 1.0, "a": 2, "name": "x", "flag": True}) == 2


@settings(max_examples=60, deadline=None)
@given(st.lists(st.tuples(st.sampled_from(sorted(rk.PARAMETERS)), st.floats(0.0, 0.05), st.booleans()),
                min_size=1, max_size=6),
       st.integers(0, 2 ** 16))
def test_the_choice_is_a_valid_model_with_no_more_parameters_within_the_margin(models, seed):
    """Any set of candidates (structure, how far from a common residual, valid):
    the choice is valid, has no more parameters than the best fit, and when it is
    not the best fit it is within the margin of it and says so."""
    rng = np.random.default_rng(seed)
    n = 500
    base = rng.standard_normal(n)
    spread = 5.0 * math.sqrt(n)
    cands = [_candidate(f"m{i}", kind, base + scale * rng.standard_normal(n), spread, valid)
             for i, (kind, scale, valid) in enumerate(models)]
    r = rk.rank(cands)
    ok = [c for c in cands if c.valid]
    if not ok:
        assert r is None
        return
    best, top = cands[r.best], cands[r.top]
    assert best.valid and top.fit_percent == max(c.fit_percent for c in ok)
    assert rk.parameter_count(best.kind, {}) <= rk.parameter_count(top.kind, {})
    assert r.best in r.tied and r.top in r.tied
    if r.best != r.top:
        assert rk.parameter_count(best.kind, {}) < rk.parameter_count(top.kind, {})
        assert 0.0 <= top.fit_percent - best.fit_percent <= r.margin and r.note
    else:
        assert r.note == "" and r.margin == 0.0
