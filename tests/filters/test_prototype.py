"""The prototypes (designer.filters.prototype): the ideal cascade of the
synthesised sections equals scipy's own analog designs (butter, bessel,
cheby1 with freqs) for every order 1..10; the conventions; the section tables
of TI SLOA088 reproduced; the mask's order equals buttord/cheb1ord."""

import math
import re

import numpy as np
import pytest
from hypothesis import given
from hypothesis import strategies as st
from scipy import signal

from designer.core.errors import DesignError
from designer.filters import Cascade, SectionTarget, get
from designer.filters.design import section_name
from designer.filters.prototype import (BESSEL_SEARCH_ORDER, DELAY_POINTS, bandpass_from_mask, chebyshev_3db_factor, delay_error_pct,
                                        group_delay, order_from_mask, plan_bandpass, plan_sections, prototype_zpk, reference_ba, reference_bandpass,
                                        reference_response)


def scipy_design(kind, family, order, fc, ripple=1.0, norm="mag"):
    wc = 2 * math.pi * fc
    btype = "low" if kind == "lowpass" else "high"
    if family == "butterworth":
        return signal.butter(order, wc, btype, analog=True)
    if family == "bessel":
        return signal.bessel(order, wc, btype, analog=True, norm=norm)
    return signal.cheby1(order, ripple, wc, btype, analog=True)


def ideal_cascade(kind, family, order, fc, ripple=1.0, norm="mag"):
    stages = []
    for p in plan_sections(kind, family, order, fc, ripple, norm):
        topo = get(section_name(kind, p.order, "sallen-key", 1.0))
        stages.append((topo, topo.synthesize(SectionTarget(kind, p.fn_hz, p.q, 1.0))))
    return Cascade(stages)


@given(order=st.integers(1, 10), fc=st.floats(10.0, 1e5), family=st.sampled_from(["butterworth", "bessel", "chebyshev"]),
       kind=st.sampled_from(["lowpass", "highpass"]), ripple=st.sampled_from([0.1, 0.5, 1.0, 2.0, 3.0]),
       norm=st.sampled_from(["mag", "delay"]))
def test_ideal_cascade_equals_scipy_design(order, fc, family, kind, ripple, norm):
    b, a = scipy_design(kind, family, order, fc, ripple, norm)
    f = fc * np.geomspace(0.05, 20, 200)
    _, h_ref = signal.freqs(b, a, 2 * math.pi * f)
    h = ideal_cascade(kind, family, order, fc, ripple, norm).response(2j * math.pi * f)
    # unity-gain sections: the cascade's passband gain is 1, scipy's b[-1]/a[-1] (low-pass) or b[0]/a[0]
    passband = b[-1] / a[-1] if kind == "lowpass" else b[0] / a[0] if len(b) == len(a) else None
    np.testing.assert_allclose(h * passband, h_ref, rtol=1e-7, atol=1e-12)


@pytest.mark.parametrize("order", range(1, 11))
@pytest.mark.parametrize("kind", ["lowpass", "highpass"])
def test_chebyshev_3db_convention_puts_minus_3db_at_fc(order, kind):
    h = reference_response([1e3], kind, "chebyshev", order, 1e3, 0.5, chebyshev_cutoff="3db")
    # -3 dB below the ripple's peak; the reference is normalised to its DC (or high-frequency) gain, which an
    # even order puts 0.5 dB below the peak
    peak_over_passband = 0.5 if order % 2 == 0 else 0.0
    assert 20 * math.log10(abs(h[0])) == pytest.approx(-10 * math.log10(2) + peak_over_passband, abs=1e-9)
    assert chebyshev_3db_factor(order, 0.5) > 1


@pytest.mark.parametrize("order", range(1, 11))
def test_bessel_delay_norm_gives_the_delay_at_dc(order):
    f = np.array([1.0, 2.0])   # far below fc = 1 kHz: the group delay is flat there
    h = reference_response(f, "lowpass", "bessel", order, 1e3, bessel_norm="delay")
    delay = -np.diff(np.unwrap(np.angle(h))) / (2 * math.pi * np.diff(f))
    assert delay[0] == pytest.approx(1 / (2 * math.pi * 1e3), rel=1e-5)


# TI SLOA088 ("Op Amps for Everyone", ch. 16), the coefficient tables: each second-order section as
# 1 + a s + b s^2 in s normalised to the cut-off, so fn/fc = 1/sqrt(b) and Q = sqrt(b)/a (Bessel at -3 dB);
# for the Chebyshev tables, whose frequency normalisation differs between sources, the Q only
SLOA088 = {
    ("butterworth", 4, None): [(0.7654, 1.0), (1.8478, 1.0)],
    ("butterworth", 6, None): [(0.5176, 1.0), (1.4142, 1.0), (1.9319, 1.0)],
    ("bessel", 2, None): [(1.3617, 0.6180)],
    ("bessel", 4, None): [(1.3397, 0.4889), (0.7743, 0.3890)],
}
SLOA088_CHEBYSHEV_Q = {(2, 1.0): [0.9565], (4, 1.0): [0.7845, 3.5590], (4, 3.0): [1.0765, 5.5797]}


@pytest.mark.parametrize("key", list(SLOA088))
def test_sections_reproduce_sloa088_tables(key):
    family, order, _ = key
    plans = [p for p in plan_sections("lowpass", family, order, 1.0) if p.order == 2]
    want = sorted(((1 / math.sqrt(b), math.sqrt(b) / a) for a, b in SLOA088[key]), key=lambda x: x[1])
    assert len(plans) == len(want)
    for p, (fn, q) in zip(plans, want):
        assert p.fn_hz == pytest.approx(fn, rel=5e-4) and p.q == pytest.approx(q, rel=5e-4)


@pytest.mark.parametrize("key", list(SLOA088_CHEBYSHEV_Q))
def test_chebyshev_q_reproduces_sloa088(key):
    order, ripple = key
    qs = [p.q for p in plan_sections("lowpass", "chebyshev", order, 1.0, ripple) if p.order == 2]
    assert qs == pytest.approx(SLOA088_CHEBYSHEV_Q[key], rel=5e-4)


@pytest.mark.parametrize("family", ["butterworth", "bessel", "chebyshev"])
@pytest.mark.parametrize("order", range(1, 11))
def test_stages_in_rising_q_first_order_first(family, order):
    plans = plan_sections("lowpass", family, order, 1e3, 0.5)
    qs = [p.q for p in plans if p.order == 2]
    assert qs == sorted(qs)
    assert sum(p.order for p in plans) == order
    assert all(p.order == 2 for p in plans[1:])


MASKS = [("lowpass", 3e3, 1.0, 12e3, 40.0), ("lowpass", 1e3, 0.5, 2e3, 60.0), ("highpass", 10e3, 1.0, 2e3, 50.0),
         ("highpass", 500.0, 3.0, 100.0, 30.0)]


@pytest.mark.parametrize("mask", MASKS)
def test_mask_order_equals_buttord_and_cheb1ord(mask):
    kind, fp, ap, fs, as_ = mask
    for family, fn in (("butterworth", signal.buttord), ("chebyshev", signal.cheb1ord)):
        n, wn = fn(2 * math.pi * fp, 2 * math.pi * fs, ap, as_, analog=True)
        if n > 10:
            with pytest.raises(DesignError, match=f"order {n}"):
                order_from_mask(kind, family, fp, ap, fs, as_)
            continue
        order, fc = order_from_mask(kind, family, fp, ap, fs, as_)
        assert order == n and fc == pytest.approx(wn / (2 * math.pi))


@pytest.mark.parametrize("mask", [("lowpass", 1e3, 3.0, 10e3, 40.0), ("highpass", 10e3, 1.0, 1e3, 50.0),
                                  ("lowpass", 1e3, 0.5, 8e3, 30.0)])
def test_bessel_mask_order_is_the_least_that_meets_it(mask):
    kind, fp, ap, fs, as_ = mask
    order, fc = order_from_mask(kind, "bessel", fp, ap, fs, as_)
    assert _bessel_loss(kind, order, fp, fc) == pytest.approx(ap, abs=1e-6)
    assert _bessel_loss(kind, order, fs, fc) >= as_
    if order > 1:   # one order less cannot: with its loss at fp set to the limit, fs is not attenuated enough
        assert _bessel_attenuation(kind, order - 1, fp, ap, fs) < as_


def _bessel_loss(kind, n, f, fc):
    return -20 * math.log10(abs(reference_response([f], kind, "bessel", n, fc)[0]))


def _bessel_attenuation(kind, n, fp, ap, fs):
    """The attenuation at fs of the order-n Bessel whose loss at fp is ap (its cut-off by bisection on
    scipy's response)."""
    lo, hi = math.log(fp) - 12, math.log(fp) + 12
    for _ in range(100):
        mid = 0.5 * (lo + hi)
        if (_bessel_loss(kind, n, fp, math.exp(mid)) > ap) == (kind == "lowpass"):
            lo = mid
        else:
            hi = mid
    return _bessel_loss(kind, n, fs, math.exp(hi if kind == "lowpass" else lo))


@pytest.mark.parametrize("mask", [("lowpass", 1e3, 3.0, 4e3, 60.0), ("highpass", 4e3, 3.0, 1e3, 60.0)])
def test_bessel_mask_beyond_order_10_names_the_order_it_needs(mask):
    """As Butterworth's and Chebyshev's, a Bessel mask above order 10 is refused naming the order it needs:
    that order meets it on scipy's response, one less does not."""
    kind, fp, ap, fs, as_ = mask
    with pytest.raises(DesignError, match=r"needs a Bessel filter of order (\d+), above the limit 10 \(order 10 "
                                          r"gives .* dB") as exc:
        order_from_mask(kind, "bessel", fp, ap, fs, as_)
    n = int(re.search(r"of order (\d+)", str(exc.value)).group(1))
    assert 10 < n <= BESSEL_SEARCH_ORDER
    assert _bessel_attenuation(kind, n, fp, ap, fs) >= as_ > _bessel_attenuation(kind, n - 1, fp, ap, fs)


def test_bessel_mask_no_order_meets_says_so():
    """A Bessel's attenuation at an edge peaks at some order and falls towards the Gaussian's: a mask no
    order up to the search's end meets is refused saying so (brute force over those orders agrees)."""
    kind, fp, ap, fs, as_ = "lowpass", 3e3, 1.0, 12e3, 40.0
    with pytest.raises(DesignError, match=r"above order 10, and no order up to 25 meets it: .*\(order 10 gives "
                                          r".* dB at the stopband edge, 40 dB asked\)"):
        order_from_mask(kind, "bessel", fp, ap, fs, as_)
    assert max(_bessel_attenuation(kind, n, fp, ap, fs) for n in range(1, BESSEL_SEARCH_ORDER + 1)) < as_


@given(order=st.integers(1, 5), f_low=st.floats(50.0, 5e4), ratio=st.floats(1.05, 1.9),
       family=st.sampled_from(["butterworth", "bessel", "chebyshev"]), ripple=st.sampled_from([0.1, 0.5, 1.0, 3.0]))
def test_narrow_bandpass_sections_equal_scipy_bandpass_design(order, f_low, ratio, family, ripple):
    f_high = f_low * ratio
    wn = [2 * math.pi * f_low, 2 * math.pi * f_high]
    if family == "butterworth":
        b, a = signal.butter(order, wn, "bandpass", analog=True)
    elif family == "bessel":
        b, a = signal.bessel(order, wn, "bandpass", analog=True, norm="mag")
    else:
        b, a = signal.cheby1(order, ripple, wn, "bandpass", analog=True)
    f0 = math.sqrt(f_low * f_high)
    f = f0 * np.geomspace(0.3, 3, 120)
    _, h_ref = signal.freqs(b, a, 2 * math.pi * np.append(f, f0))
    plans = plan_bandpass(family, order, f_low, f_high, ripple, method="narrow")
    assert len(plans) == order and all(p.kind == "bandpass" for p in plans)
    topo = get("mfb-bandpass")
    # each section's gain well inside the MFB band-pass's bound 2 Q^2 (the comparison is normalised at f0)
    cascade = Cascade([(topo, topo.synthesize(SectionTarget("bandpass", p.fn_hz, p.q, min(1.0, p.q ** 2))))
                       for p in plans])
    h = cascade.response(2j * math.pi * np.append(f, f0))
    np.testing.assert_allclose(h[:-1] / h[-1], h_ref[:-1] / h_ref[-1], rtol=1e-6, atol=1e-9)
    np.testing.assert_allclose(reference_bandpass(f, family, order, f_low, f_high, ripple, method="narrow"),
                               h_ref[:-1] / abs(h_ref[-1]), rtol=1e-6, atol=1e-9)


def test_wide_bandpass_is_the_highpass_then_lowpass():
    plans = plan_bandpass("butterworth", 4, 300.0, 3e3)
    assert sorted(p.kind for p in plans) == ["highpass"] * 2 + ["lowpass"] * 2
    f = np.geomspace(30, 30e3, 50)
    want = reference_response(f, "highpass", "butterworth", 4, 300.0) * reference_response(f, "lowpass", "butterworth",
                                                                                          4, 3e3)
    np.testing.assert_allclose(reference_bandpass(f, "butterworth", 4, 300.0, 3e3), want, rtol=1e-12)


BAND_MASKS = [((900.0, 1100.0), 1.0, (600.0, 1700.0), 30.0), ((9e3, 11e3), 0.5, (7e3, 14e3), 40.0),
              ((300.0, 3000.0), 1.0, (100.0, 9000.0), 30.0), ((300.0, 3000.0), 1.0, (30.0, 30e3), 30.0)]


def _band_loss(f, family, n, fl, fh, method, loss_db):
    return -20 * np.log10(np.abs(reference_bandpass(np.asarray(f, float), family, n, fl, fh, loss_db, "mag",
                                                    "ripple", method)))


@pytest.mark.parametrize("mask", BAND_MASKS)
@pytest.mark.parametrize("family", ["butterworth", "chebyshev", "bessel"])
def test_bandpass_mask_is_met_by_the_least_order(mask, family):
    pb, ap, sb, as_ = mask
    try:
        n, fl, fh, method = bandpass_from_mask(family, pb, ap, sb, as_)
    except DesignError as exc:   # a Bessel's slow skirt: say so, naming what order 10 reaches
        assert family == "bessel" and "above order 10" in str(exc)
        return
    assert method == ("wide" if pb[1] / pb[0] >= 2 else "narrow")
    inside = np.geomspace(*pb, 41)   # the loss is held over the whole passband, its edges among the points
    loss = _band_loss([*pb, *sb], family, n, fl, fh, method, ap)
    assert max(_band_loss(inside, family, n, fl, fh, method, ap)) <= ap + 1e-6
    assert min(loss[2:]) >= as_ * (1 - 1e-6)
    if method == "narrow" and family != "bessel":
        # scipy's own order functions with the band-pass edges, and their edges the scipy design's
        fn, design = (signal.buttord, signal.butter) if family == "butterworth" else (signal.cheb1ord, None)
        n_scipy, wn = fn(2 * math.pi * np.array(pb), 2 * math.pi * np.array(sb), ap, as_, analog=True)
        assert n == n_scipy and (fl, fh) == pytest.approx(wn / (2 * math.pi))
        if design is not None:
            b, a = design(n, wn, "bandpass", analog=True)
            h = signal.freqs(b, a, 2 * math.pi * np.array([*pb, *sb]))[1]
            assert loss == pytest.approx(-20 * np.log10(np.abs(h)), abs=1e-9)
    if n > 1:
        # one order less: no edges that hold the passband loss (brute force over a grid of edges for a wide
        # band, of bandwidths about the passband's centre for a narrow one) reach the stopband attenuation
        assert _best_attenuation(family, n - 1, pb, ap, sb, method) < as_


def _best_attenuation(family, n, pb, ap, sb, method):
    """The most stopband attenuation of an order-n band-pass over a grid of its edges that hold the loss over
    the passband (scipy's normalised designs, each side's or the prototype's computed once)."""
    f = np.array([*np.geomspace(*pb, 41), *sb])
    if method == "wide":
        fls, fhs = np.geomspace(pb[0] / 4, pb[0] * 1.1, 150), np.geomspace(pb[1] / 1.1, pb[1] * 4, 150)
        side = {k: reference_ba(k, family, n, 1 / (2 * math.pi), ap) for k in ("lowpass", "highpass")}
        hp = np.array([-20 * np.log10(np.abs(signal.freqs(*side["highpass"], f / c)[1])) for c in fls])
        lp = np.array([-20 * np.log10(np.abs(signal.freqs(*side["lowpass"], f / c)[1])) for c in fhs])
        loss = (hp[:, None, :] + lp[None, :, :]).reshape(-1, f.size)
    else:
        f0 = math.sqrt(pb[0] * pb[1])
        z, p, k = prototype_zpk(family, n, ap)
        rows = []
        for bw in np.geomspace((pb[1] - pb[0]) / 2, (pb[1] - pb[0]) * 8, 3000):
            h = np.abs(signal.freqs_zpk(*signal.lp2bp_zpk(z, p, k, 2 * math.pi * f0, 2 * math.pi * bw),
                                        2 * math.pi * np.append(f, f0))[1])
            rows.append(-20 * np.log10(h[:-1] / h[-1]))
        loss = np.array(rows)
    ok = loss[:, :-2].max(axis=1) <= ap
    return float(loss[ok, -2:].min(axis=1).max()) if ok.any() else -np.inf


def test_bandpass_mask_beyond_order_10_names_the_order():
    with pytest.raises(DesignError, match=r"order 21 \(a band-pass of order 42\), above the limit 10"):
        bandpass_from_mask("butterworth", (900.0, 1100.0), 1.0, (880.0, 1150.0), 30.0)


@pytest.mark.parametrize("mask, method", [(((300.0, 3000.0), 3.0, (60.0, 15e3), 80.0), "wide"),
                                          (((900.0, 1100.0), 3.0, (400.0, 2500.0), 150.0), "narrow")])
def test_bessel_bandpass_mask_beyond_order_10_names_the_order_it_needs(mask, method):
    """As the Bessel low- and high-pass's, a Bessel band-pass mask above order 10 is refused naming the prototype
    order it needs: that order's edges reach the attenuation, one less's do not (brute force over the edges)."""
    pb, ap, sb, as_ = mask
    with pytest.raises(DesignError, match=r"needs a bessel prototype of order (\d+) \(a band-pass of order \d+\), "
                                          rf"above the limit 10 \({method} band-pass: order 10 gives .* dB") as exc:
        bandpass_from_mask("bessel", pb, ap, sb, as_)
    n = int(re.search(r"of order (\d+)", str(exc.value)).group(1))
    assert f"a band-pass of order {2 * n})" in str(exc.value) and 10 < n <= BESSEL_SEARCH_ORDER
    assert _best_attenuation("bessel", n, pb, ap, sb, method) >= as_ > _best_attenuation("bessel", n - 1, pb, ap, sb,
                                                                                          method)


def test_bessel_bandpass_mask_no_order_meets_says_so():
    """A band-pass Bessel's attenuation at the edges falls with the order here: refused saying no order up to the
    search's end meets it (brute force over those orders' edges agrees)."""
    pb, ap, sb, as_ = (900.0, 1100.0), 3.0, (800.0, 1250.0), 20.0
    with pytest.raises(DesignError, match=r"above order 10, and no order up to 25 meets it: .*\(narrow band-pass: "
                                          r"order 10 gives .* dB at the stopband edges, 20 dB asked\)"):
        bandpass_from_mask("bessel", pb, ap, sb, as_)
    assert max(_best_attenuation("bessel", n, pb, ap, sb, "narrow") for n in range(11, BESSEL_SEARCH_ORDER + 1)) < as_


def test_bandpass_mask_chebyshev_3db_edges_are_minus_3db():
    n, fl, fh, _ = bandpass_from_mask("chebyshev", (900.0, 1100.0), 1.0, (600.0, 1700.0), 30.0,
                                      chebyshev_cutoff="3db")
    h = reference_bandpass(np.array([fl, fh]), "chebyshev", n, fl, fh, 1.0, "mag", "3db", "narrow")
    # relative to the passband's peak (an odd order's centre is the peak)
    assert 20 * np.log10(np.abs(h)) == pytest.approx([-10 * math.log10(2)] * 2, abs=1e-6)


@pytest.mark.parametrize("norm", ["mag", "delay"])
@pytest.mark.parametrize("order", [1, 2, 3, 5, 8, 10])
def test_group_delay_equals_scipys_of_the_prototype(order, norm):
    # scipy's group_delay of the prototype through the bilinear transform: the digital frequency f is the analog
    # F = (fs / pi) tan(pi f / fs), and the delays are tau_d(f) = tau_a(F) dF/df = tau_a(F) / cos^2(pi f / fs)
    fc, fs = 1e3, 20e3
    zpk = prototype_zpk("bessel", order, bessel_norm=norm)
    b, a = signal.zpk2tf(*signal.lp2lp_zpk(*zpk, 2 * math.pi * fc))
    bd, ad = signal.bilinear(b, a, fs)
    f = np.linspace(0.0, 2 * fc, 41)
    _, gd_samples = signal.group_delay((bd, ad), w=f, fs=fs)
    analog_f = fs / math.pi * np.tan(math.pi * f / fs)
    np.testing.assert_allclose(group_delay(zpk, analog_f, fc), gd_samples / fs * np.cos(math.pi * f / fs) ** 2,
                               rtol=1e-7)
    if norm == "delay":   # the delay normalisation: 1 / (2 pi fc) at DC
        assert group_delay(zpk, [0.0], fc)[0] == pytest.approx(1 / (2 * math.pi * fc), rel=1e-12)


@pytest.mark.parametrize("pct, to", [(1.0, 1e3), (0.1, 1e3), (5.0, 2e3), (0.5, 500.0)])
def test_delay_target_order_is_the_least_meeting_mask_and_target(pct, to):
    mask = ("lowpass", "bessel", 1e3, 3.0, 10e3, 30.0)
    order, fc = order_from_mask(*mask, "mag", pct, to)
    plain, _ = order_from_mask(*mask)
    f = np.linspace(0.0, to, DELAY_POINTS)

    def err(n, c):
        tau = group_delay(prototype_zpk("bessel", n), f, c)
        return delay_error_pct(tau, tau[0])

    assert order >= plain and err(order, fc) <= pct
    if order > plain:   # one order less meets the mask (order >= plain) but not the target
        n1, fc1 = order - 1, None
        lo, hi = math.log(1e3) - 12, math.log(1e3) + 12
        for _ in range(100):   # its cut-off: the loss at the passband edge at the limit
            mid = 0.5 * (lo + hi)
            loss = -20 * math.log10(abs(reference_response([1e3], "lowpass", "bessel", n1, math.exp(mid))[0]))
            lo, hi = (mid, hi) if loss > 3.0 else (lo, mid)
        fc1 = math.exp(hi)
        assert err(n1, fc1) > pct


def test_delay_target_beyond_order_10_says_both():
    with pytest.raises(DesignError, match=r"above order 10, and no order up to 25 meets them.*the delay within .* % "
                                          r"up to 5000 Hz, 0.01 % asked"):
        order_from_mask("lowpass", "bessel", 1e3, 3.0, 2e3, 30.0, "mag", 0.01, 5e3)
