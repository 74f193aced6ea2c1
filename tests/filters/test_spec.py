"""FilterSpec: a band-pass's mask (two passband edges inside two stopband edges) parsed, checked in one
line, and the order, band edges and split it picks."""

import math

import pytest
from hypothesis import given, settings
from hypothesis import strategies as hst

from designer.core.errors import DesignError
from designer.filters.prototype import bandpass_from_mask
from designer.filters.spec import FilterSpec

BAND = dict(filter_type="bandpass", max_loss_db=1.0, min_attenuation_db=30.0)


def test_band_mask_picks_order_edges_and_split():
    s = FilterSpec(passband_hz="900,1.1k", stopband_hz="600,1.7k", **BAND)
    assert s.passband_edges == (900.0, 1100.0) and s.stopband_edges == (600.0, 1700.0)
    n, fl, fh, method = bandpass_from_mask("butterworth", (900.0, 1100.0), 1.0, (600.0, 1700.0), 30.0)
    assert (s.order, s.f_low_hz, s.f_high_hz, s.bandpass_method) == (n, fl, fh, method) and method == "narrow"
    assert s.mask_phrases() == ("from 900 Hz to 1.1 kHz", "below 600 Hz and above 1.7 kHz")
    wide = FilterSpec(passband_hz=(300, 3e3), stopband_hz=(100, 9e3), family="chebyshev", **BAND)
    assert wide.bandpass_method == "wide" and wide.ripple_db == 1.0


@pytest.mark.parametrize("kw, words", [
    (dict(passband_hz="1.1k,900", stopband_hz="600,1.7k"), "passband_hz's edges cross: 1100 Hz is not below 900 Hz"),
    (dict(passband_hz="900,1.1k", stopband_hz="1.7k,600"), "stopband_hz's edges cross"),
    (dict(passband_hz="900,1.1k", stopband_hz="950,1.7k"), "the stopband is not outside the passband"),
    (dict(passband_hz="900,1.1k", stopband_hz="600,1k"), "the stopband is not outside the passband"),
    (dict(passband_hz="900,1.1k", stopband_hz="600"), "stopband_hz: a band-pass mask takes two edges F1,F2"),
    (dict(passband_hz="900,1.1k,2k", stopband_hz="600,3k"), "passband_hz: a band-pass mask takes two edges"),
    (dict(passband_hz="900,1.1k", stopband_hz="600,1.7k", order=3), "order: give either a band-pass's order"),
    (dict(passband_hz="900,1.1k", stopband_hz="600,1.7k", f_low_hz=900), "f_low_hz: give either"),
    (dict(passband_hz="900,1.1k"), "missing stopband_hz"),
    (dict(passband_hz="900,1.1k", stopband_hz="880,1.15k"), "prototype of order 21 (a band-pass of order 42)"),
])
def test_band_mask_refusals_are_one_line(kw, words):
    with pytest.raises(DesignError) as exc:
        FilterSpec(**BAND, **kw)
    assert words in str(exc.value) and "\n" not in str(exc.value)


@pytest.mark.parametrize("kw", [dict(passband_hz=1e3, stopband_hz=2e3),
                                dict(filter_type="bandpass", passband_hz="900,1.1k", stopband_hz="600,1.7k")])
def test_a_chebyshev_masks_loss_beyond_the_ripple_range_names_the_loss(kw):
    """The ripple of a Chebyshev from a mask is the mask's loss: a loss outside the ripple's range is refused
    naming max_loss_db (what was given), never ripple_db (which was not)."""
    with pytest.raises(DesignError) as exc:
        FilterSpec(family="chebyshev", max_loss_db=3.5, min_attenuation_db=60, **kw)
    assert exc.value.param == "max_loss_db" and "\n" not in str(exc.value)
    assert str(exc.value).startswith("max_loss_db: a chebyshev mask's passband loss is its ripple, which must be "
                                     "0.01 dB to 3 dB, got 3.5 dB")
    # at the range's end it is a design (the ripple is the loss)
    assert FilterSpec(family="chebyshev", max_loss_db=3, min_attenuation_db=60, **kw).ripple_db == 3.0


def test_a_low_pass_takes_one_edge():
    with pytest.raises(DesignError, match="two edges F1,F2 are for a bandpass"):
        FilterSpec(passband_hz="900,1.1k", stopband_hz="3k", max_loss_db=1, min_attenuation_db=30)


edge = hst.floats(10.0, 1e6)


@settings(max_examples=40, deadline=None)
@given(p1=edge, p2=edge, s1=edge, s2=edge, family=hst.sampled_from(["butterworth", "chebyshev", "bessel"]),
       as_text=hst.booleans())
def test_band_mask_parsing_accepts_or_refuses_in_one_line(p1, p2, s1, s2, family, as_text):
    pb, sb = (f"{p1!r},{p2!r}", f"{s1!r},{s2!r}") if as_text else ((p1, p2), (s1, s2))
    try:
        s = FilterSpec(family=family, passband_hz=pb, stopband_hz=sb, **BAND)
    except DesignError as exc:
        msg = str(exc)
        assert "\n" not in msg
        if p1 >= p2:
            assert "passband_hz's edges cross" in msg
        elif s1 >= s2:
            assert "stopband_hz's edges cross" in msg
        elif not (s1 < p1 and s2 > p2):
            assert "the stopband is not outside the passband" in msg
        else:
            assert "order" in msg and "above" in msg
        return
    assert p1 < p2 and s1 < p1 and s2 > p2
    assert s.passband_edges == (p1, p2) and 1 <= s.order <= 10 and s.f_low_hz < s.f_high_hz
    assert s.bandpass_method == ("wide" if p2 / p1 >= 2 else "narrow")
    assert math.isfinite(s.f_low_hz) and math.isfinite(s.f_high_hz)


BESSEL_MASK = dict(family="bessel", passband_hz=1e3, max_loss_db=3, stopband_hz=10e3, min_attenuation_db=30)


@pytest.mark.parametrize("kw, words", [
    (dict(BESSEL_MASK, family="butterworth", max_delay_error_pct=1, delay_to_hz=1e3),
     "max_delay_error_pct: a group-delay target is for a bessel filter"),
    (dict(family="bessel", order=4, fc_hz=1e3, max_delay_error_pct=1, delay_to_hz=1e3),
     "a group-delay target joins a mask in picking the order"),
    (dict(BESSEL_MASK, max_delay_error_pct=1), "delay_to_hz: a group-delay target needs both"),
    (dict(BESSEL_MASK, delay_to_hz=1e3), "max_delay_error_pct: a group-delay target needs both"),
    (dict(BESSEL_MASK, max_delay_error_pct=60, delay_to_hz=1e3), "max_delay_error_pct must be 0.01 % to 50 %"),
    (dict(family="bessel", filter_type="highpass", passband_hz=10e3, max_loss_db=3, stopband_hz=1e3,
          min_attenuation_db=30, max_delay_error_pct=1, delay_to_hz=1e3), "is for a lowpass (its delay at DC)"),
])
def test_delay_target_refusals_are_one_line(kw, words):
    with pytest.raises(DesignError) as exc:
        FilterSpec(**kw)
    assert words in str(exc.value) and "\n" not in str(exc.value)


@settings(max_examples=30, deadline=None)
@given(pct=hst.one_of(hst.floats(0.0, 100.0), hst.sampled_from(["1", "0.5%", "abc", "1e-3"])),
       to=hst.one_of(hst.floats(1e-3, 1e8), hst.sampled_from(["1k", "500", "x"])))
def test_delay_target_parsing_accepts_or_refuses_in_one_line(pct, to):
    try:
        s = FilterSpec(**BESSEL_MASK, max_delay_error_pct=pct, delay_to_hz=to)
    except DesignError as exc:
        assert "\n" not in str(exc)
        return
    assert 0.01 <= s.max_delay_error_pct <= 50 and 0.01 <= s.delay_to_hz <= 10e6 and s.has_delay_target
