"""The SPICE proof of a cascade (designer.filters.verify): the standalone deck's
measurements against the analytic cascade, NRMS of .ac and .tran against the
ideal and op-amp-aware models, the mask on SPICE's .ac, the op-amp-aware stage
fit against the nodal response, the analytic transient against scipy's step of
the whole cascade, and slew and swing per stage with the catalogue's op-amp
that can."""

import math
import subprocess

import numpy as np
import pytest
from scipy import signal

from designer.core.opamps import get as get_opamp
from designer.filters import REGISTRY, FilterSpec
from designer.filters.bench import bench_of
from designer.filters.design import design
from designer.filters.verify import (NRMS_PASS, analytic_tran, bench_signal, opamp_aware_polys, proof_deck, prove,
                                     stage_drive, stage_polys)

LP = dict(order=4, fc_hz=1e3)
HP = dict(order=5, fc_hz=1e3, family="chebyshev", ripple_db=0.5, filter_type="highpass", topology="mfb")
BP = dict(filter_type="bandpass", order=2, f_low_hz=900.0, f_high_hz=1.1e3, family="bessel", opamp="TL072")
MASK = dict(family="chebyshev", passband_hz=3e3, max_loss_db=1.0, stopband_hz=12e3, min_attenuation_db=40.0)


@pytest.mark.parametrize("name", list(REGISTRY))
@pytest.mark.parametrize("opamp", ["LM741", "NE5532"])
def test_opamp_aware_fit_is_the_nodal_response(name, opamp):
    """The fitted rational function of degree order + 1 is the nodal analysis' response (1e-6 of its peak)."""
    topo = REGISTRY[name]
    values = topo.synthesize(topo.example)
    num, den, err = opamp_aware_polys(topo, values, get_opamp(opamp))
    assert err < 1e-6
    fn = topo.figures(values).fn_hz
    f = np.geomspace(fn / 30, fn * 300, 97)          # not the fit's grid
    s = 2j * math.pi * f
    h = topo.response(values, s, get_opamp(opamp))
    fit = np.polyval(num, s) / np.polyval(den, s)
    assert np.max(np.abs(fit - h)) < 1e-6 * np.max(np.abs(h))


def test_analytic_transient_is_scipys_lsim_of_the_whole_cascade():
    d = design(FilterSpec(order=6, fc_hz=1e3, family="chebyshev", ripple_db=1.0))
    polys, err = stage_polys(d)
    assert err == 0.0
    t = np.linspace(0, 10e-3, 4001)
    x = np.clip(t / 25e-6, 0.0, 1.0)        # the bench's step: a ramp over ten samples from 0 V
    y = analytic_tran(polys, t, x)[-1]
    num, den = d.cascade().coefficients()
    _, ref, _ = signal.lsim((num, den), x, t)
    # stage by stage by the bilinear transform: about (w dt)^2 / 12 of the response at 400 points per
    # period of fc, a few hundredths of the NRMS rule's 1 %
    assert np.max(np.abs(y - ref)) < 5e-4


def test_stage_drive_names_an_op_amp_that_can():
    """A 5th-order high-pass at 20 kHz, 10 V bench sine: the LM741 (0.5 V/us) cannot slew it; the named one can."""
    d = design(FilterSpec(order=5, fc_hz=20e3, filter_type="highpass", opamp="LM741", amplitude_v=5.0,
                          gbw_margin=1.0, impedance_ohm=10e3))
    sig = bench_signal(d)
    t = np.linspace(0, sig.t_stop_s, 4001)
    polys, _ = stage_polys(d, d.opamp)
    drives = stage_drive(d, sig, t, analytic_tran(polys, t, sig.waveform(t)))
    bad = [s for s in drives if not s.ok]
    assert bad, [s.to_dict() for s in drives]
    for s in bad:
        need = max(s.bench_slew_v_per_s, s.peak_slew_v_per_s)
        assert need > get_opamp("LM741").slew_v_per_s
        name = s.instead.split()[1]
        assert get_opamp(name).slew_v_per_s >= need
        assert "too much; use" in s.text()
    # a sine of amplitude A at f slews at 2 pi f A: the closed form at the stage's peak
    for s in drives:
        assert s.peak_slew_v_per_s == pytest.approx(2 * math.pi * s.peak_hz * s.peak_swing_v)


@pytest.mark.spice
@pytest.mark.parametrize("kw", [LP, HP, BP, MASK], ids=["lowpass", "highpass", "bandpass", "mask"])
def test_proof_agrees_with_the_op_amp_aware_cascade(kw):
    d = design(FilterSpec(**kw))
    p = prove(d)
    assert p.nrms["ac_opamp"] < 1e-3 and p.nrms["tran_opamp"] < 0.1
    # the op-amp-aware model is at least as close to SPICE as the ideal one
    assert p.nrms["ac_opamp"] <= p.nrms["ac_ideal"] and p.nrms["tran_opamp"] <= p.nrms["tran_ideal"] + 1e-9
    assert p.fit_error < 1e-6
    assert p.signal.kind == ("step" if d.spec.filter_type == "lowpass" else "burst")
    # every measurement at the edges against the analytic op-amp-aware response
    fp = d.spec.passband_hz if d.spec.has_mask else d.figures["passband_edge_hz"]
    fp = fp if isinstance(fp, list) else [fp]
    for i, f in enumerate(fp, 1):
        h = complex(d.cascade().response(2j * math.pi * f, d.opamp))
        assert p.measurements[f"pass{i}_db"] == pytest.approx(20 * math.log10(abs(h)), abs=0.01)
        dphi = (p.measurements[f"pass{i}_deg"] - math.degrees(np.angle(h)) + 180) % 360 - 180
        assert abs(dphi) < 0.5
    assert p.passed == (p.mask is None or p.mask["met"])
    assert p.to_dict()["nrms_pass_below"] == NRMS_PASS


@pytest.mark.spice
@pytest.mark.parametrize("kw", [HP, BP], ids=["highpass", "bandpass"])
def test_spice_runs_the_bench_sheets_burst(kw):
    """The proof's transient of a high- or band-pass is the sheet's tone burst (its tone, cycles, window and
    input samples; the proof's analytic ideal burst is the sheet's output), gated in the deck by a B-source
    beside the .ac source, and ngspice's burst agrees with the analytic op-amp-aware cascade's (NRMS)."""
    d = design(FilterSpec(**kw))
    sheet = bench_of(d).time_test
    sig = bench_signal(d)
    assert (sig.kind, sig.f_hz, sig.cycles) == ("burst", sheet.frequency_hz, sheet.cycles)
    assert sig.t_stop_s == pytest.approx(sheet.t_s[-1], rel=1e-12)
    assert np.array_equal(sig.waveform(sheet.t_s), sheet.input_v)
    assert sig.to_dict()["cycles"] == sheet.cycles
    # the proof's analytic burst (bilinear, stage by stage) is the sheet's (exact for a piecewise-linear input)
    y = analytic_tran(stage_polys(d)[0], sheet.t_s, sheet.input_v)[-1]
    assert np.max(np.abs(y - sheet.output_v)) < 1e-3 * sheet.amplitude_v
    deck = proof_deck(d)
    assert "\nVin vin_ac 0 DC 0 AC 1\nBburst vin vin_ac V = time <= " in deck and " SIN(" not in deck
    p = prove(d)
    assert p.signal == sig and p.nrms["tran_opamp"] < 0.1 and p.nrms["ac_opamp"] < 1e-3


def test_only_a_burst_has_cycles_in_its_json():
    """The low-pass's step keeps the earlier JSON keys (the committed references'); a burst adds ``cycles``."""
    lp, hp = (bench_signal(design(FilterSpec(**kw))) for kw in (LP, HP))
    assert set(lp.to_dict()) == {"kind", "amplitude_v", "f_hz", "t_stop_s", "rise_s"}
    assert set(hp.to_dict()) == set(lp.to_dict()) | {"cycles"}
    # the burst ends after whole cycles: the input is back at 0 V, continuous, when the gate closes
    t = np.array([hp.burst_s * (1 - 1e-9), hp.burst_s * (1 + 1e-9)])
    assert np.max(np.abs(hp.waveform(t))) < 1e-6 * hp.amplitude_v


@pytest.mark.spice
def test_mask_on_spices_ac_is_the_analytic_mask():
    d = design(FilterSpec(**MASK))
    m = prove(d).mask
    f = np.geomspace(300.0, 3e3, 2001)
    db = 20 * np.log10(np.abs(d.cascade().response(2j * math.pi * f, d.opamp)))
    assert m["passband_loss_db"] == pytest.approx(-np.min(db), abs=0.02)
    f = np.geomspace(12e3, 120e3, 2001)
    db = 20 * np.log10(np.abs(d.cascade().response(2j * math.pi * f, d.opamp)))
    assert m["stopband_attenuation_db"] == pytest.approx(-np.max(db), abs=0.02)
    assert m["met"] == (m["passband_loss_db"] <= 1.0 and m["stopband_attenuation_db"] >= 40.0)


@pytest.mark.spice
def test_the_deck_stands_alone(tmp_path):
    """ngspice -b of the deck prints every measurement: the -3 dB point, the edges, the transient's extremes."""
    d = design(FilterSpec(**MASK))
    deck = tmp_path / "proof.cir"
    deck.write_text(proof_deck(d))
    run = subprocess.run(["ngspice", "-b", str(deck)], capture_output=True, text=True, timeout=120, cwd=tmp_path)
    assert run.returncode == 0, run.stderr
    meas = {k.strip(): float(v.split()[0]) for k, v in (ln.split("=", 1) for ln in run.stdout.splitlines()
                                                        if "=" in ln and ln.split("=")[0].strip().isidentifier())
            if v.split() and _number(v.split()[0])}
    assert meas["f3db_hz"] == pytest.approx(d.figures["f3_hz"], rel=0.01)
    assert -meas["stopmax1_db"] >= 40.0 - 0.05 or not prove(d).mask["met"]
    # the step's final value is the DC gain (odd order: 1), its peak the overshoot above it
    assert meas["vout_max_v"] > 1.0 and meas["s1_max_v"] == pytest.approx(1.0, abs=0.01)


def _number(text):
    try:
        float(text)
        return True
    except ValueError:
        return False
