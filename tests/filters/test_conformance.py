"""The conformance suite: every registered topology (:data:`designer.filters.REGISTRY`),
one new registration picked up without editing this file, run through

(a) synthesis from targets, then the figures recomputed from the parts equal the
    target (fn, Q, gain, 1e-9 relative);
(b) the analytic ideal response against scipy.signal.freqs of its coefficients;
(c) the analytic response against a real ngspice ``.ac`` of the topology's own
    netlist: the ideal response with the project's ideal op-amp (``OPAMP_IDEAL``,
    A0 = 1e7), the op-amp-aware one with the LM741's behavioural model (A0, GBW
    from the catalogue), within 0.05 dB and 0.5 degrees over three decades
    around fn;
(d) the vectorised response and figures equal the scalar ones element by element, and the
    op-amp-aware model (:meth:`Topology.opamp_model`, a section's closed form where it has one)
    equals the nodal solution;
(f) refusals (wrong kind, bad numbers, unknown choices, each realisability limit
    the topology declares) are one line naming the parameter.

(e), the cascade, is in ``test_cascade.py``.
"""

import dataclasses

import numpy as np
import pytest
from hypothesis import HealthCheck, assume, given, settings
from hypothesis import strategies as st
from scipy import signal

from designer.core.errors import DesignError
from designer.core.opamps import get as get_opamp
from designer.filters import REGISTRY, PartSpec, SectionTarget, Topology, polynomial, simulate_ac
from designer.spice.deck import GROUND, Amp

TOPOLOGIES = list(REGISTRY.values())
IDS = list(REGISTRY)
#: three decades around fn (a decade and a half either side)
SPAN = 10 ** 1.5
DB_TOL, DEG_TOL = 0.05, 0.5


def targets(topology):
    """The topology's example and variants of it: other frequencies, a given capacitor, an impedance."""
    ex = topology.example
    return [ex, dataclasses.replace(ex, fn_hz=37.0), dataclasses.replace(ex, fn_hz=23e3, impedance_ohm=4.7e3),
            dataclasses.replace(ex, fn_hz=440.0, c_f=22e-9)]


def errors_db_deg(h_sim, h_model):
    """The largest gain (dB) and phase (degrees) difference of two responses."""
    ratio = h_sim / h_model
    return float(np.max(np.abs(20 * np.log10(np.abs(ratio))))), float(np.max(np.abs(np.degrees(np.angle(ratio)))))


@pytest.mark.parametrize("topology", TOPOLOGIES, ids=IDS)
def test_synthesis_meets_the_target(topology):
    for target in targets(topology):
        values = topology.synthesize(target)
        assert set(values) == set(topology.designators)
        assert all(v > 0 and np.isfinite(v) for v in values.values()), values
        fig = topology.figures(values)
        assert fig.fn_hz == pytest.approx(target.fn_hz, rel=1e-9)
        assert fig.gain == pytest.approx(target.gain, rel=1e-9)
        if topology.order == 2:
            assert fig.q == pytest.approx(target.q, rel=1e-9)
        else:
            assert fig.q is None
        if target.c_f is not None:
            assert target.c_f in values.values()


@pytest.mark.parametrize("topology", TOPOLOGIES, ids=IDS)
@settings(max_examples=60, suppress_health_check=[HealthCheck.filter_too_much])
@given(fn=st.floats(0.5, 2e6), q=st.floats(0.2, 30), gain=st.one_of(st.just(1.0), st.floats(1.01, 20)),
       stretch=st.floats(1.0, 10.0), scale=st.sampled_from([None, ("c_f", 1e-9), ("impedance_ohm", 1e5)]))
def test_synthesis_of_any_realisable_target_meets_it(topology, fn, q, gain, stretch, scale):
    """Any target the topology accepts (and any choice above its bound) is met to 1e-9."""
    target = SectionTarget(topology.kind, fn, q=q if topology.order == 2 else None, gain=gain,
                           **({scale[0]: scale[1]} if scale else {}))
    try:
        topology.check_realisable(target)
    except DesignError:
        assume(False)
    choices = {n.removesuffix("_min"): stretch * b for n, b in topology.limits(target).items()
               if n.endswith("_min") and n.removesuffix("_min") in topology.choices}
    values = topology.synthesize(target, **choices)
    assert all(v > 0 and np.isfinite(v) for v in values.values()), values
    fig = topology.figures(values)
    assert (fig.fn_hz, fig.gain) == pytest.approx((fn, gain), rel=1e-9)
    if topology.order == 2:
        assert fig.q == pytest.approx(q, rel=1e-9)


@pytest.mark.parametrize("topology", TOPOLOGIES, ids=IDS)
def test_synthesis_at_and_above_each_bound_meets_the_target(topology):
    target = topology.example
    for name, bound in topology.limits(target).items():
        choice = name.removesuffix("_min")
        if not name.endswith("_min") or choice not in topology.choices:
            continue
        for ratio in (bound, 3 * bound):
            fig = topology.figures(topology.synthesize(target, **{choice: ratio}))
            assert (fig.fn_hz, fig.q, fig.gain) == pytest.approx((target.fn_hz, target.q, target.gain), rel=1e-9)


@pytest.mark.parametrize("topology", TOPOLOGIES, ids=IDS)
def test_ideal_response_is_scipy_freqs_of_the_coefficients(topology):
    values = topology.synthesize(topology.example)
    num, den = topology.coefficients(values)
    assert num.shape == den.shape == (topology.order + 1,)
    w = 2 * np.pi * np.geomspace(topology.example.fn_hz / SPAN, topology.example.fn_hz * SPAN, 61)
    _, h_ref = signal.freqs(num, den, worN=w)
    np.testing.assert_allclose(topology.response(values, 1j * w), h_ref, rtol=1e-12)
    sign = -1 if topology.inverting else 1
    pass_s = {"lowpass": 0.0, "highpass": 1e9 * w[-1], "bandpass": 1j * 2 * np.pi * topology.example.fn_hz}
    assert np.real(topology.response(values, 1j * pass_s[topology.kind] if topology.kind == "highpass"
                                     else pass_s[topology.kind])) * sign > 0


@pytest.mark.parametrize("topology", TOPOLOGIES, ids=IDS)
def test_opamp_aware_response_tends_to_the_ideal_one(topology):
    """The nodal analysis of the netlist with A0 -> 1e12 and GBW -> 1e15 Hz is the
    closed form of the coefficients (two derivations of one circuit)."""
    values = topology.synthesize(topology.example)
    huge = dataclasses.replace(get_opamp("LM741"), a0=1e12, gbw_hz=1e15)
    s = 2j * np.pi * np.geomspace(topology.example.fn_hz / SPAN, topology.example.fn_hz * SPAN, 31)
    np.testing.assert_allclose(topology.response(values, s, huge), topology.response(values, s), rtol=1e-8)


@pytest.mark.parametrize("topology", TOPOLOGIES, ids=IDS)
def test_opamp_model_is_the_nodal_solution(topology):
    """The section's op-amp-aware model (:meth:`Topology.opamp_model`, a closed form where the
    section overrides it) equals the nodal solution, as polynomials (:meth:`Topology.nodal_model`)
    and as the response solved directly (:meth:`Topology.response`), to 1e-9 relative, on the
    example's parts and on targets a decade away, for two op-amps; batched as one by one, with
    one gain-bandwidth per build too."""
    for target in targets(topology):
        values = topology.synthesize(target)
        s = 2j * np.pi * np.geomspace(target.fn_hz / SPAN, target.fn_hz * SPAN, 13)
        for name in ("LM741", "NE5532"):
            amp = get_opamp(name)
            num, den = topology.opamp_model(values, amp)
            n_ref, d_ref = topology.nodal_model(values, amp)
            assert den.shape == d_ref.shape and num.shape == n_ref.shape and den[-1] == 1.0
            # each coefficient against the polynomial's size at |s| = wn (the terms are of very different scales)
            at = (2 * np.pi * target.fn_hz) ** np.arange(den.size)[::-1]
            size = np.max(np.abs(d_ref * at))
            assert np.max(np.abs((den - d_ref) * at)) < 1e-9 * size
            assert np.max(np.abs((num - n_ref) * at)) < 1e-9 * size
            h = np.polyval(num, s) / np.polyval(den, s)
            np.testing.assert_allclose(h, topology.response(values, s, amp), rtol=1e-9)
    rng = np.random.default_rng(20261204)
    arrays = {r: v * rng.uniform(0.9, 1.1, size=5) for r, v in topology.synthesize(topology.example).items()}
    amp = get_opamp("TL072")
    num, den = topology.opamp_model(arrays, amp)
    # one gain-bandwidth per build (the Monte Carlo's op-amp spread), shaped as the batch
    gbw = amp.gbw_hz * np.array([0.5, 0.8, 1.0, 1.2, 1.5])
    num_g, den_g = topology.opamp_model(arrays, dataclasses.replace(amp, gbw_hz=gbw))
    assert den_g.shape == den.shape
    for i in range(5):
        one = {r: float(a[i]) for r, a in arrays.items()}
        n1, d1 = topology.opamp_model(one, amp)
        np.testing.assert_allclose(den[i], d1, rtol=1e-12)
        np.testing.assert_allclose(num[i], n1, rtol=1e-12, atol=1e-300)
        n1, d1 = topology.opamp_model(one, dataclasses.replace(amp, gbw_hz=float(gbw[i])))
        np.testing.assert_allclose(den_g[i], d1, rtol=1e-12)
        np.testing.assert_allclose(num_g[i], n1, rtol=1e-12, atol=1e-300)


@pytest.mark.parametrize("topology", TOPOLOGIES, ids=IDS)
def test_step_final_is_the_opamp_models_dc_gain(topology):
    """What a step settles to (:meth:`Topology.step_final`, a closed form where the section overrides it: the
    Sallen-Key low-pass's K A0/(K + A0)) is the amplitude times the op-amp-aware model's DC gain, num(0)/den(0)
    of :meth:`Topology.opamp_model`, and the base class's nodal solution at s = 0, to 1e-12 relative (0 for a
    high-pass or a band-pass); the ideal op-amp's finite A0 counts (the deck simulates it); batched as one by one."""
    for target in targets(topology):
        values = topology.synthesize(target)
        for name in ("ideal", "LM741"):
            amp = get_opamp(name)
            num, den = topology.opamp_model(values, amp)
            got = topology.step_final(values, amp, 2.5)
            np.testing.assert_allclose(got, 2.5 * num[-1] / den[-1], rtol=1e-9, atol=1e-12)
            np.testing.assert_allclose(got, Topology.step_final(topology, values, amp, 2.5), rtol=1e-12, atol=1e-12)
            if topology.kind == "lowpass":
                sign = -1 if topology.inverting else 1
                assert sign * got > 2.5 * abs(target.gain) * (1 - 1e-3)       # A0 costs a little of the gain
    rng = np.random.default_rng(20261204)
    arrays = {r: v * rng.uniform(0.9, 1.1, size=5) for r, v in topology.synthesize(topology.example).items()}
    amp = get_opamp("TL072")
    batch = topology.step_final(arrays, amp, 2.0)
    assert batch.shape == (5,)
    for i in range(5):
        one = topology.step_final({r: float(a[i]) for r, a in arrays.items()}, amp, 2.0)
        assert float(one) == batch[i]


def _moved_batch(topology, n: int = 64, seed: int = 26) -> dict:
    """Part sets around each target's synthesis (every part moved by up to 5 %, as E-series rounding
    and tolerances move them), as arrays: designator -> shape (n * len(targets),)."""
    rng = np.random.default_rng(seed)
    sets = [topology.synthesize(t) for t in targets(topology)]
    return {r: np.concatenate([s[r] * rng.uniform(0.95, 1.05, n) for s in sets]) for r in topology.designators}


@pytest.mark.parametrize("topology", TOPOLOGIES, ids=IDS)
def test_one_ideal_pair_hook_behind_the_figures_and_the_scalar_pair(topology):
    """Every ideal pair is the hook's (:meth:`Topology.ideal_wn_zeta`, issue 26: written once): on a batch of
    part sets the figures' fn and Q are its wn / (2 pi) and 1 / (2 zeta) and their zeta its zeta, to the bit;
    :meth:`Topology.ideal_pair` is (wn / (2 pi), zeta), arrays for arrays and, for each element called alone,
    floats equal to the batch's element to the bit (the vectorised hook gives a number's pair as a 0-d one)."""
    batch = _moved_batch(topology)
    n = len(next(iter(batch.values())))
    wn, zeta = topology.ideal_wn_zeta(batch)
    assert np.shape(wn) == np.shape(zeta) == (n,)
    fig = topology.figures(batch)
    assert np.array_equal(fig.fn_hz, wn / (2 * np.pi))
    fn, z = topology.ideal_pair(batch)
    assert np.array_equal(fn, fig.fn_hz) and np.array_equal(z, zeta)
    if topology.order == 2:
        assert np.array_equal(fig.zeta, zeta) and np.array_equal(fig.q, 1 / (2 * zeta))
    else:
        assert fig.q is None and fig.zeta is None and np.array_equal(zeta, np.ones(n))
    for i in range(n):
        one = {r: float(v[i]) for r, v in batch.items()}
        pair = topology.ideal_pair(one)
        assert all(type(x) is float for x in pair)
        assert pair == (fn[i], z[i])
        w1, z1 = topology.ideal_wn_zeta(one)
        assert np.ndim(w1) == np.ndim(z1) == 0 and (float(w1), float(z1)) == (wn[i], zeta[i])
        f1 = topology.figures(one)
        assert f1.fn_hz == fn[i] and (f1.q is None or f1.q == fig.q[i])


@pytest.mark.parametrize("topology", TOPOLOGIES, ids=IDS)
def test_ideal_pair_is_the_coefficients_pair(topology):
    """The ideal (fn, zeta) a PID's plant is named and sized by (:meth:`Topology.ideal_pair`, a section's own
    arithmetic where it has one: the Sallen-Key low-pass's) is the pair of its ideal coefficients: fn of
    :meth:`Topology.figures` and zeta = 1/(2 Q) within 1e-15 relative (a first-order section: its pole and
    zeta 1), and the slowest pole pair of the denominator's roots (:func:`designer.core.lti.dominant_pair`)."""
    from designer.core.lti import dominant_pair
    for target in targets(topology):
        values = topology.synthesize(target)
        fn, zeta = topology.ideal_pair(values)
        fig = topology.figures(values)
        assert isinstance(fn, float) and isinstance(zeta, float)
        assert fn == pytest.approx(fig.fn_hz, rel=1e-15, abs=0)
        if topology.order == 1:
            assert zeta == 1.0
            continue
        assert zeta == pytest.approx(1 / (2 * fig.q), rel=1e-15, abs=0)
        assert (fn, zeta) == pytest.approx(dominant_pair(topology.coefficients(values)[1]), rel=1e-9)


@pytest.mark.spice
@pytest.mark.parametrize("opamp", ["ideal", "LM741"])
@pytest.mark.parametrize("topology", TOPOLOGIES, ids=IDS)
def test_analytic_response_matches_ngspice_ac(topology, opamp):
    amp = get_opamp(opamp)
    target = topology.example
    values = topology.synthesize(target)
    f, h_sim = simulate_ac(topology.netlist(values), amp, target.fn_hz / SPAN, target.fn_hz * SPAN)
    assert f[0] == pytest.approx(target.fn_hz / SPAN) and f[-1] == pytest.approx(target.fn_hz * SPAN)
    h_model = topology.response(values, 2j * np.pi * f, None if amp.ideal else amp)
    db, deg = errors_db_deg(h_sim, h_model)
    print(f"{topology.name} {opamp}: {db:.2e} dB, {deg:.2e} deg")
    assert db < DB_TOL and deg < DEG_TOL
    if not amp.ideal:   # the bound tells the models apart: the ideal one misses the LM741's deck
        db_ideal, deg_ideal = errors_db_deg(h_sim, topology.response(values, 2j * np.pi * f))
        assert db_ideal > DB_TOL or deg_ideal > DEG_TOL


@pytest.mark.parametrize("topology", TOPOLOGIES, ids=IDS)
def test_vectorised_response_and_figures_equal_the_scalar_ones(topology):
    rng = np.random.default_rng(20261203)
    nominal = topology.synthesize(topology.example)
    arrays = {r: v * rng.uniform(0.9, 1.1, size=(7, 1)) for r, v in nominal.items()}
    s = 2j * np.pi * np.geomspace(topology.example.fn_hz / 10, topology.example.fn_hz * 10, 5)
    amp = get_opamp("TL072")
    for opamp in (None, amp):
        h = topology.response(arrays, s, opamp)
        assert h.shape == (7, 5)
        for i in range(7):
            one = {r: float(a[i, 0]) for r, a in arrays.items()}
            for j in range(5):
                assert h[i, j] == pytest.approx(complex(topology.response(one, s[j], opamp)), rel=1e-12)
    fig = topology.figures(arrays)
    for i in range(7):
        one = topology.figures({r: float(a[i, 0]) for r, a in arrays.items()})
        assert float(fig.fn_hz[i, 0]) == pytest.approx(one.fn_hz, rel=1e-14)
        assert float(fig.gain[i, 0]) == pytest.approx(one.gain, rel=1e-14)
        if topology.order == 2:
            assert float(fig.q[i, 0]) == pytest.approx(one.q, rel=1e-14)


@pytest.mark.parametrize("topology", TOPOLOGIES, ids=IDS)
def test_netlist_declares_its_parts_once_prefixed_for_chaining(topology):
    values = topology.synthesize(topology.example)
    net = topology.netlist(values, prefix="30", amp_ref="U3", inp="a", out="b")
    assert [p.ref for p in net.parts] == [r[0] + "30" + r[1:] for r in topology.designators]
    assert [p.role for p in net.parts] == [p.role for p in topology.parts]
    assert [p.kind for p in net.parts] == [p.kind for p in topology.parts]
    assert [p.value for p in net.parts] == [values[r] for r in topology.designators]
    assert [a.ref for a in net.amps] == ["U3"] and net.amps[0].out == "b"
    nets = {p.a for p in net.parts} | {p.b for p in net.parts} | {net.amps[0].inp, net.amps[0].inn}
    assert "a" in nets and "b" in nets | {net.amps[0].out}
    assert all(n in ("a", "b", GROUND) or n.startswith("u3_") for n in nets)


def one_line_refusal(call, param):
    with pytest.raises(DesignError) as err:
        call()
    msg = str(err.value)
    assert "\n" not in msg and msg.startswith(param), msg
    assert err.value.param == param
    return msg


@pytest.mark.parametrize("topology", TOPOLOGIES, ids=IDS)
def test_refusals_are_one_line_naming_the_parameter(topology):
    ex = topology.example
    other = next(k for k in ("lowpass", "highpass", "bandpass") if k != topology.kind)
    assert topology.kind in one_line_refusal(
        lambda: topology.synthesize(dataclasses.replace(ex, kind=other)), "kind")
    one_line_refusal(lambda: topology.synthesize(dataclasses.replace(ex, fn_hz=-1.0)), "fn_hz")
    one_line_refusal(lambda: topology.synthesize(dataclasses.replace(ex, fn_hz=float("nan"))), "fn_hz")
    one_line_refusal(lambda: topology.synthesize(dataclasses.replace(ex, gain=0.0)), "gain")
    one_line_refusal(lambda: topology.synthesize(dataclasses.replace(ex, c_f=-1e-9)), "c_f")
    one_line_refusal(lambda: topology.synthesize(dataclasses.replace(ex, q=None if topology.order == 2 else 0.7)),
                     "q")
    one_line_refusal(lambda: topology.synthesize(ex, wobble=2.0), "wobble")
    one_line_refusal(lambda: topology.coefficients({"R9": 1.0}), "values")
    for choice in topology.choices:
        one_line_refusal(lambda: topology.synthesize(ex, **{choice: -1.0}), choice)


@pytest.mark.parametrize("topology", TOPOLOGIES, ids=IDS)
def test_each_declared_limit_is_refused_in_one_line_saying_what_to_change(topology):
    ex = topology.example
    for name, bound in topology.limits(ex).items():
        if name.endswith("_min"):
            choice = name.removesuffix("_min")
            msg = one_line_refusal(lambda: topology.synthesize(ex, **{choice: 0.9 * bound}), choice)
        else:
            field = name.removesuffix("_max")
            msg = one_line_refusal(
                lambda: topology.synthesize(dataclasses.replace(ex, **{field: 1.1 * bound})), field)
        assert f"{bound:.4g}" in msg and "bound" in msg


def test_every_registered_example_is_a_target_of_its_own_kind():
    for topology in TOPOLOGIES:
        assert isinstance(topology.example, SectionTarget)
        assert topology.example.kind == topology.kind
        topology.check_realisable(topology.example)


class InvertingHighPass(Topology):
    """A section written outside the package (an inverting first-order high-pass:
    R1 and C1 in series from the input to the inverting input, R2 the feedback;
    H(s) = -R2 C1 s / (R1 C1 s + 1)): one class, nothing else."""

    name, title, kind, order, inverting = "test-inverting-highpass", "inverting high-pass", "highpass", 1, True
    parts = (PartSpec("R1", "R", "input resistor"), PartSpec("R2", "R", "feedback"),
             PartSpec("C1", "C", "input capacitor"))
    example = SectionTarget("highpass", 2e3, gain=5.0)

    def coefficients(self, values):
        v = self.values_of(values)
        return polynomial(-v["R2"] * v["C1"], 0.0), polynomial(v["R1"] * v["C1"], 1.0)

    def synthesize(self, target, **choices):
        self.check_realisable(target, **choices)
        c = self.scale(target)
        r1 = 1 / (target.wn * c)
        return {"R1": r1, "R2": target.gain * r1, "C1": c}

    def netlist(self, values, prefix="", amp_ref="U1", inp="vin", out="vout"):
        m, n = self.internal(amp_ref, "m", "n")
        return self.assemble(values, prefix, {"R1": (inp, m), "C1": (m, n), "R2": (n, out)},
                             Amp(amp_ref, self.title, GROUND, n, out))


@pytest.mark.spice
def test_a_new_section_is_one_class_and_passes_the_suite(monkeypatch):
    """What the parametrised tests above do for a registered section, for one registered here."""
    from designer.filters import registry
    topology = InvertingHighPass()
    monkeypatch.setitem(registry.REGISTRY, topology.name, topology)
    assert registry.get(topology.name) is topology
    test_synthesis_meets_the_target(topology)
    test_ideal_response_is_scipy_freqs_of_the_coefficients(topology)
    test_opamp_aware_response_tends_to_the_ideal_one(topology)
    test_opamp_model_is_the_nodal_solution(topology)
    for opamp in ("ideal", "LM741"):
        test_analytic_response_matches_ngspice_ac(topology, opamp)
    test_vectorised_response_and_figures_equal_the_scalar_ones(topology)
    test_netlist_declares_its_parts_once_prefixed_for_chaining(topology)
    test_refusals_are_one_line_naming_the_parameter(topology)
