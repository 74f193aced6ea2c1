"""The cascade of sections: a circuit of its own (designators unique per stage,
op-amps U1..Un, stage outputs chained), its response the product of the stages'
and its polynomials their products, proven against ngspice's ``.ac`` of its deck.
"""

import math

import numpy as np
import pytest
from scipy import signal

from designer.core.errors import DesignError
from designer.core.opamps import get as get_opamp
from designer.filters import Cascade, SectionTarget, Stage, get, simulate_ac


def butterworth4(fc=1e3):
    """A 4th-order Butterworth low-pass at ``fc``: its two sections' Q from scipy's
    prototype, a unity-gain Sallen-Key then an MFB section of gain 2."""
    _, poles, _ = signal.buttap(4)
    qs = sorted({round(abs(p) / (-2 * p.real), 12) for p in poles})
    sk, mfb = get("sallen-key-lowpass"), get("mfb-lowpass")
    return Cascade([(sk, sk.synthesize(SectionTarget("lowpass", fc, q=qs[0]))),
                    Stage(mfb, mfb.synthesize(SectionTarget("lowpass", fc, q=qs[1], gain=2.0)))])


def mixed():
    """One stage of every registered kind of order: a band-pass made of a
    high-pass, a low-pass and an RC pole, with an inverting first-order stage."""
    names = ("rc-highpass", "sallen-key-highpass-gain", "mfb-bandpass", "sallen-key-lowpass-gain",
             "inverting-lowpass")
    stages = []
    for name in names:
        t = get(name)
        stages.append((t, t.synthesize(t.example)))
    return Cascade(stages)


def test_butterworth_cascade_is_scipys_butterworth():
    cascade = butterworth4()
    num, den = cascade.coefficients()
    b, a = signal.butter(4, 2 * math.pi * 1e3, analog=True)
    w = 2 * math.pi * np.geomspace(10, 1e5, 101)
    np.testing.assert_allclose(signal.freqs(num, den, w)[1], -2 * signal.freqs(b, a, w)[1], rtol=1e-9)
    assert cascade.order == 4


@pytest.mark.parametrize("make", [butterworth4, mixed])
def test_response_is_the_product_of_the_stages(make):
    cascade = make()
    s = 2j * math.pi * np.geomspace(10, 1e5, 41)
    for opamp in (None, get_opamp("TL072")):
        product = np.prod([st.topology.response(st.values, s, opamp) for st in cascade.stages], axis=0)
        np.testing.assert_allclose(cascade.response(s, opamp), product, rtol=1e-13)
    num, den = cascade.coefficients()
    np.testing.assert_allclose(signal.freqs(num, den, s.imag)[1], cascade.response(s), rtol=1e-9)


def test_netlist_designators_unique_per_stage_and_stages_chained():
    cascade = mixed()
    net = cascade.netlist(inp="vin", out="vout")
    refs = [p.ref for p in net.parts]
    assert len(refs) == len(set(refs))
    assert [a.ref for a in net.amps] == [f"U{i}" for i in range(1, len(cascade.stages) + 1)]
    assert refs[:2] == ["R101", "C101"] and "R304" not in refs and "R303" in refs
    assert set(cascade.values) == set(refs)
    assert all(net.part(r).value == v for r, v in cascade.values.items())
    outs = [a.out for a in net.amps]
    assert outs == ["s1", "s2", "s3", "s4", "vout"]
    for i, out in enumerate(outs[:-1], 2):   # each stage output feeds (only) the next stage
        users = ({p.ref[1] for p in net.parts if out in (p.a, p.b)}
                 | {a.ref[1] for a in net.amps if out in (a.inp, a.inn)})
        assert str(i) in users, (out, users)


def test_a_cascade_needs_stages_whose_values_match():
    with pytest.raises(DesignError, match="^stages"):
        Cascade([])
    with pytest.raises(DesignError, match="^values: rc-lowpass has missing C1"):
        Cascade([(get("rc-lowpass"), {"R1": 1e3})])


@pytest.mark.spice
@pytest.mark.parametrize("make", [butterworth4, mixed])
@pytest.mark.parametrize("opamp", ["ideal", "LM741"])
def test_cascade_response_matches_ngspice_ac(make, opamp):
    cascade = make()
    amp = get_opamp(opamp)
    f, h_sim = simulate_ac(cascade.netlist(), amp, 1e3 / 10 ** 1.5, 1e3 * 10 ** 1.5)
    h_model = cascade.response(2j * math.pi * f, None if amp.ideal else amp)
    ratio = h_sim / h_model
    db, deg = np.max(np.abs(20 * np.log10(np.abs(ratio)))), np.max(np.abs(np.degrees(np.angle(ratio))))
    print(f"cascade {make.__name__} {opamp}: {db:.2e} dB, {deg:.2e} deg")
    assert db < 0.05 and deg < 0.5
