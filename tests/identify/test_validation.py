"""Validation on data a model was not fitted to (designer.identify.validation):
MATLAB compare's fit, the residual tests of resid against their 99 % bands,
the ARX least-squares reference, the split of a record."""

import json

import numpy as np
import pytest
from scipy.signal import lfilter

from designer.core.errors import DesignError
from designer.identify import outputerror as oe
from designer.identify import validation as va
from oe_captures import PLANTS, T, capture, random_binary


def test_compare_fit_is_one_minus_the_normalised_error():
    rng = np.random.default_rng(0)
    y = rng.standard_normal(500).cumsum()
    assert va.compare_fit(y, y) == 100.0
    assert va.compare_fit(y, np.full_like(y, y.mean())) == pytest.approx(0.0, abs=1e-12)
    yhat = y + rng.standard_normal(500)
    want = 100 * (1 - np.sqrt(np.sum((y - yhat) ** 2)) / np.sqrt(np.sum((y - y.mean()) ** 2)))
    assert va.compare_fit(y, yhat) == pytest.approx(want, rel=1e-12)
    with pytest.raises(DesignError, match="never moves"):
        va.compare_fit(np.ones(10), np.zeros(10))


def test_split_record():
    s = va.split_record(1000)
    assert (s.estimation, s.validation) == (slice(0, 500), slice(500, 1000))
    assert va.split_record(900, 2 / 3).n_est == 600
    for bad in (0.0, 1.0, 1.5):
        with pytest.raises(DesignError, match="fraction"):
            va.split_record(100, bad)
    with pytest.raises(DesignError, match="too short"):
        va.split_record(30)


def test_the_whiteness_band_holds_99_percent_per_lag():
    # white noise: each lag inside with probability 0.99, all 25 with 0.99^25
    # (the per-lag band ``resid`` draws); over 300 records, within 4 binomial sigmas
    inside = [va.whiteness(np.random.default_rng(1000 + i).standard_normal(2000)).inside for i in range(300)]
    p = 0.99 ** va.RESID_LAGS
    assert abs(np.mean(inside) - p) <= 4 * np.sqrt(p * (1 - p) / 300)
    w = va.whiteness(np.random.default_rng(0).standard_normal(2000))
    assert list(w.lags) == list(range(1, va.RESID_LAGS + 1))
    assert w.band == pytest.approx(va.Z99 / np.sqrt(2000))
    coloured = lfilter([1.0], [1.0, -0.3], np.random.default_rng(1).standard_normal(2000))
    assert not va.whiteness(coloured).inside


def test_cross_correlation_finds_a_residual_that_follows_the_input():
    rng = np.random.default_rng(5)
    u = rng.standard_normal(4000)
    e = rng.standard_normal(4000)
    assert va.cross_correlation(u, e).inside
    leaked = e + 0.2 * np.roll(u, 3)   # an unmodelled path from u 3 samples back
    c = va.cross_correlation(u, leaked)
    assert not c.inside
    assert c.lags[np.argmax(np.abs(c.r))] == 3


def test_cross_correlation_with_an_input_that_does_not_move_is_zero():
    """The validation part of a step capture, after its edge: no deviation of the
    input, nothing correlates with it (and no 0/0 warning)."""
    c = va.cross_correlation(np.full(500, 2.0), np.random.default_rng(5).standard_normal(500))
    assert c.inside and not np.any(c.r)


def test_arx_recovers_a_discrete_system():
    rng = np.random.default_rng(6)
    a, b = [1.0, -1.2, 0.5], [0.0, 0.0, 0.0, 0.4, 0.25]   # ARX[2 2 3]
    u = rng.standard_normal(3000)
    y = lfilter(b, a, u) + 2.0
    m = va.arx_fit(u, y, 2, 2, 3)
    # on deviations from the means (the toolbox's detrend, then arx): exact
    # but for the sample means' own small mismatch with the operating point
    assert np.allclose(m.a, a, rtol=0, atol=1e-5) and np.allclose(m.b, b, rtol=0, atol=1e-5)
    assert m.static_gain == pytest.approx(sum(b) / sum(a), rel=1e-5)
    assert np.allclose(m.response(u), lfilter(b, a, u), rtol=0, atol=1e-4 * np.ptp(y))
    json.dumps(m.to_dict())
    with pytest.raises(DesignError, match="orders"):
        va.arx_fit(u, y, 2, 0, 1)


def test_the_true_structure_validates_as_white_as_the_noise():
    # the right structure on a white-noise capture: its validation residuals are
    # as white as the noise itself and its fit as good as the noiseless output's
    kind, model = PLANTS["fopdt"]
    u, y, clean = capture(model, random_binary(np.random.default_rng(13)), snr_db=15.0, seed=14)
    res = oe.identify_output_error(u, y, T, kinds=(kind,))
    v = res.validations[0]
    val = res.split.validation
    noise = va.whiteness(y[val] - clean[val])
    assert np.max(np.abs(v.whiteness.r - noise.r)) <= 0.25 * noise.band
    assert np.max(np.abs(v.cross.r - va.cross_correlation(u[val], y[val] - clean[val]).r)) <= v.cross.band
    assert v.how == "detrend" and v.samples == res.split.n - res.split.n_est
    ceiling = va.compare_fit(y[val] - y[val].mean(), clean[val] - clean[val].mean())
    assert abs(v.fit_percent - ceiling) <= 0.5
    cont = va.validate(res.fits[0], u, y, res.split, how="continue")
    assert abs(cont.fit_percent - va.compare_fit(y[val], clean[val])) <= 0.5
    d = json.loads(json.dumps(res.to_dict()))
    assert d["split"] == {"samples": res.split.n, "estimation": [0, res.split.n_est],
                          "validation": [res.split.n_est, res.split.n]}
    with pytest.raises(DesignError, match="how"):
        va.validate(res.fits[0], u, y, res.split, how="sideways")


def test_a_separate_validation_record_is_simulated_from_rest():
    kind, model = PLANTS["fopdt"]
    u1, y1, _ = capture(model, random_binary(np.random.default_rng(1)), snr_db=15.0, seed=2)
    u2, y2, clean2 = capture(model, random_binary(np.random.default_rng(3)), snr_db=15.0, seed=4)
    res = oe.identify_output_error(u1, y1, T, kinds=(kind,), validation=(u2, y2))
    assert res.split is None and res.fits[0].samples == u1.size
    v = res.validations[0]
    assert v.samples == u2.size
    ceiling = va.compare_fit(y2 - y2.mean(), clean2 - clean2.mean())
    assert abs(v.fit_percent - ceiling) <= 1.0


def test_a_record_scored_whole_fits_the_level_it_rested_at():
    """``how="rest"``: a plant at rest at input 0 whose record starts at the
    sequence's first level (+1): scored from rest at that level the true model
    misses the whole transient; with the rest level fitted it is exact, and
    the fitted shift is the jump, u[0] - 0."""
    b, a = [0.0, 0.02], [1.0, -0.98]           # a lag of 50 samples, gain 1

    class Model:
        def response(self, x):
            return lfilter(b, a, np.asarray(x, float))

    flips = np.random.default_rng(21).random(400) < 0.1
    flips[0] = False
    u = np.where(np.cumsum(flips) % 2 == 0, 1.0, -1.0)   # +-1, from +1 at the first sample
    y = lfilter(b, a, u) + 3.0                   # from rest at input 0, output level 3
    first = va.validate(Model(), u, y)
    fitted = va.validate(Model(), u, y, how="rest")
    assert first.fit_percent < 90.0 and first.rest_shift == 0.0
    assert fitted.fit_percent == pytest.approx(100.0, abs=1e-6)
    assert fitted.rest_shift == pytest.approx(u[0] - 0.0, rel=1e-6)
    assert fitted.how == "rest" and not np.any(np.abs(fitted.whiteness.r) > 1.0)
    with pytest.raises(DesignError, match="scored whole"):
        va.validate(Model(), u, y, va.split_record(u.size), how="rest")


def test_block_means_score_the_simulation_at_the_records_own_rate():
    """``block`` = k: the model is simulated on every sample and the block
    means of its simulation scored against the output's (a trailing partial
    block dropped): the true model's residuals are then the noise's block
    means alone, under every way of scoring, where simulated on the input's
    block means (as a record of their own, every k-th interval) it misses;
    block 1 is the unblocked score, and a block that is not a whole number
    from 1 is refused."""
    b, a = [0.0, 0.0, 0.2], [1.0, -0.8]      # a lag of 4.5 samples, gain 1, one sample of dead time

    class Model:
        def response(self, x):
            return lfilter(b, a, np.asarray(x, float))

        def simulate(self, x):
            return self.response(np.asarray(x, float) - x[0]) + 3.0

    rng = np.random.default_rng(22)
    flips = rng.random(4003) < 0.05
    flips[0] = False
    u = np.where(np.cumsum(flips) % 2 == 0, 1.0, -1.0)
    noise = 0.05 * rng.standard_normal(u.size)
    y = Model().simulate(u) + noise
    k = 3
    ub, yb, nb = (x[:4002].reshape(-1, k).mean(axis=1) for x in (u, y, noise))
    assert np.array_equal(va.block_means(u, k), ub)
    assert np.array_equal(va.block_means(np.column_stack((u, y)), k), np.column_stack((ub, yb)))
    assert np.array_equal(va.block_means(u, 1), u)
    split = va.split_record(ub.size)
    val = split.validation
    yv, nv = yb[val] - yb[val].mean(), nb[val] - nb[val].mean()
    want = {"detrend": va.compare_fit(yv, yv - nv), "continue": va.compare_fit(yb[val], yb[val] - nb[val])}
    for how in want:
        v = va.validate(Model(), u, y, split, how=how, block=k)
        assert v.fit_percent == pytest.approx(want[how], abs=1e-9), how
        assert v.samples == ub.size - split.n_est and v.residuals.size == v.samples
    whole = va.validate(Model(), u, y, None, block=k)
    assert whole.fit_percent == pytest.approx(va.compare_fit(yb - yb.mean(), yb - nb - (yb - nb).mean()), abs=1e-9)
    assert whole.spread == pytest.approx(np.linalg.norm(yb - yb.mean()))

    class Coarse(Model):      # the former way: the same lag sampled every k samples, on the input's means
        def response(self, x):
            return lfilter([0.0, 1 - 0.8 ** k], [1.0, -0.8 ** k], np.asarray(x, float))

    assert va.validate(Coarse(), ub, yb, split).fit_percent < want["detrend"] - 1.0
    plain = va.validate(Model(), u, y, va.split_record(u.size))
    same = va.validate(Model(), u, y, va.split_record(u.size), block=1)
    assert (plain.fit_percent, plain.samples) == (same.fit_percent, same.samples)
    for bad in (0, -2, 1.5, True, "3"):
        with pytest.raises(DesignError, match="block must be a whole number"):
            va.validate(Model(), u, y, split, block=bad)
