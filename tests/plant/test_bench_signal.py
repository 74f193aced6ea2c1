"""The op-amp's checks under the bench's square wave (designer.plant.bench.signal_checks, ids
``slew_rate`` and ``output_swing``) on a plant of every registered section (a new section is picked up
without editing this file): the output's extremes over the whole period against brute force (scipy's step
of the op-amp-aware model, the falling edge by superposition), the largest slope against the closed form
(2 zeta wn x the jump after a second-order high-pass's edge), the verdicts where a student's bench clips or
slews, and in SPICE the square-wave test failing where output_swing does."""

import math

import numpy as np
import pytest
import scipy.signal as sig

from designer.filters import REGISTRY
from designer.plant.bench import SIGNAL_CHECKS, period_extremes, signal_checks
from designer.plant.circuit_design import design_circuit_plant, with_bench
from designer.plant.spec import PlantSpec

TOPOLOGIES = list(REGISTRY.values())
IDS = list(REGISTRY)


def design(topology, opamp="LM741", amplitude_v=2.0, fc_hz=None, zeta=None, gain=None, **kw):
    topo = REGISTRY[topology] if isinstance(topology, str) else topology
    ex = topo.example
    zeta = zeta if zeta is not None else None if ex.q is None else 1 / (2 * ex.q)
    return design_circuit_plant(PlantSpec(fc_hz=fc_hz or ex.fn_hz, zeta=zeta, gain=gain or ex.gain, opamp=opamp,
                                          amplitude_v=amplitude_v, topology=topo.name, **kw), simulate=False)


def check(result, cid):
    (c,) = [c for c in result.checks if c.id == cid]
    return c


def values(c) -> dict:
    return dict(c.values)


def brute_extremes(result, n=400001):
    """(lo, hi) in volts over the period: scipy's step of the op-amp-aware model on the rising half period
    (at most 4 response spans, as the bench reads it), the falling edge by superposition."""
    from designer.plant.circuit_design import step_span
    num, den = result.models["opamp"]
    t = np.linspace(0.0, min(result.test.half_period_s, 4 * step_span(result.figures)), n)
    s = sig.step((num, den), T=t)[1]
    fall = s[-1] - s
    a = result.amplitude_v
    return a * min(0.0, s.min(), fall.min()), a * max(0.0, s.max(), fall.max())


@pytest.mark.parametrize("topology", TOPOLOGIES, ids=IDS)
def test_every_section_has_the_op_amp_checks_in_its_json_and_sheet(topology):
    from designer.core.i18n import language
    from designer.plant import circuit_report as rep
    from designer.report.document import to_html
    r = design(topology)
    ids = [c.id for c in r.checks]
    assert [i for i in ids if i in SIGNAL_CHECKS] == list(SIGNAL_CHECKS)
    assert [c["id"] for c in r.to_dict()["checks"]][:2] == list(SIGNAL_CHECKS)
    with language("en"):
        page = to_html(rep.title_of(r), rep.sections(r), {})
    for c in r.checks[:2]:
        assert c.detail in page
    # set again (check-design sets the bench for its square-wave test): replaced, not added
    with_bench(r)
    assert [c.id for c in r.checks] == ids


@pytest.mark.parametrize("topology", TOPOLOGIES, ids=IDS)
def test_the_swing_is_the_period_s_extremes_by_brute_force(topology):
    r = design(topology)
    c = values(check(r, "output_swing"))
    lo, hi = brute_extremes(r)
    a = r.amplitude_v
    assert float(c["lo"]) == pytest.approx(lo, rel=5e-3, abs=1e-3 * a)
    assert float(c["hi"]) == pytest.approx(hi, rel=5e-3, abs=1e-3 * a)


@pytest.mark.parametrize("topology", [t for t in TOPOLOGIES if t.kind == "highpass"],
                         ids=[t.name for t in TOPOLOGIES if t.kind == "highpass"])
def test_a_high_pass_s_slope_is_its_response_s_after_the_edge(topology):
    """Ideal op-amp: the output jumps by gain x amplitude, then moves at most as fast as the impulse response
    of the strictly proper part (num/den - K: scipy's, brute force over the half period); 2 zeta wn x K at 0+
    for a second-order high-pass from zeta 1/2 up, wn x K for a first-order one."""
    from designer.plant.circuit_design import step_span
    r = design(topology, "ideal")
    c = values(check(r, "slew_rate"))
    num, den = (np.asarray(x, float) for x in r.models["ideal"])
    k = num[0] / den[0]
    rest = (num - k * den)[1:]
    t = np.linspace(0.0, min(r.test.half_period_s, 4 * step_span(r.figures)), 400001)
    h = sig.impulse((rest, den), T=t)[1]
    a = r.amplitude_v
    assert float(c["jump"]) == pytest.approx(abs(k) * a, rel=5e-3)
    assert float(c["need"]) * 1e6 == pytest.approx(np.max(np.abs(h)) * a, rel=5e-3)
    fig = r.figures["ideal"]
    wn = 2 * math.pi * fig["fn_hz"]
    if topology.order == 1 or fig["zeta"] >= 0.5:
        want = wn if topology.order == 1 else 2 * fig["zeta"] * wn
        assert abs(h[0]) == pytest.approx(want * abs(k), rel=1e-6)
        assert float(c["need"]) * 1e6 == pytest.approx(want * abs(k) * a, rel=5e-3)


def test_an_mfb_low_pass_with_gain_10_clips_a_2_v_square_wave_on_an_lm741():
    """-20 V and its overshoot, beyond the LM741's -14 V on +-15 V; at 0.5 V it fits."""
    r = design("mfb-lowpass", fc_hz=1000, zeta=0.5, gain=10, amplitude_v=2.0)
    c = check(r, "output_swing")
    lo, _ = brute_extremes(r)
    assert not c.ok and lo < r.opamp.vout_min and float(values(c)["lo"]) < -20
    assert "LM741 on 15/-15 V reaches -14 V to 14 V" in c.detail
    assert r.to_dict()["checks"][1] == {"id": "output_swing", "name": "output_swing", "ok": False,
                                        "detail": c.detail}
    assert check(r, "slew_rate").ok
    low = design("mfb-lowpass", fc_hz=1000, zeta=0.5, gain=10, amplitude_v=0.5)
    assert check(low, "output_swing").ok and check(low, "slew_rate").ok


def test_a_fast_high_pass_on_a_slow_op_amp_fails_the_slew_rate():
    """30 kHz: after its jump (2 V, 1.6 V with the LM741's pole) the output falls at about 2 zeta wn x the
    jump (0.53 V/us with an ideal op-amp), over half the LM741's 0.5 V/us; a TL072 (13 V/us) follows it, and
    the LM741 a 1 kHz high-pass (0.018 V/us)."""
    fast = check(design("sallen-key-highpass", fc_hz=30e3, zeta=0.707), "slew_rate")
    assert not fast.ok and "lower the amplitude" in fast.detail
    need = float(values(fast)["need"])
    assert need > 0.25
    assert check(design("sallen-key-highpass", "TL072", fc_hz=30e3, zeta=0.707), "slew_rate").ok
    assert check(design("sallen-key-highpass", fc_hz=1e3, zeta=0.707), "slew_rate").ok


@pytest.mark.parametrize("y, want", [
    ([0.0, 0.5, 1.3, 1.0], (-0.30000000000000004, 1.3)),      # a low-pass overshoot: the falling edge undershoots
    ([0.0, -5.0, -11.0, -10.0], (-11.0, 1.0)),               # inverting: to -gain, and back above 0 V by the overshoot
    ([0.0, 1.0, 0.2, -0.1, 0.0], (-1.0, 1.0)),               # a high-pass: a jump each way
])
def test_period_extremes_take_both_edges(y, want):
    assert period_extremes(np.array(y)) == pytest.approx(want)


def test_a_step_that_never_overshoots_keeps_the_seed_s_minus_zero():
    """The seed's sheet prints "-0 V" for an overdamped plant (bytes kept): rounding below 0 is not an undershoot."""
    lo, hi = period_extremes(np.array([1e-16, 0.5, 0.9, 1.0]))
    assert math.copysign(1.0, lo) == -1.0 and lo == 0.0 and hi == 1.0
    lo, _ = period_extremes(np.array([-2e-16, 0.5, 0.9, 1.0]))
    assert lo == 0.0


def test_the_ideal_op_amp_passes_saying_what_the_output_needs():
    from designer.core.opamps import get
    t = np.linspace(0, 1e-3, 1001)
    slew, swing = signal_checks(t, 50 * (1 - np.exp(-t / 1e-4)), 2.0, get("ideal"))
    assert slew.ok and swing.ok and "ideal op-amp" in swing.detail and "100 V" in swing.detail


@pytest.mark.spice
def test_in_spice_the_square_wave_departs_from_the_model_where_the_output_swing_fails():
    """The MFB low-pass with gain 10 on an LM741 in ngspice: at 2 V its output clips at the rail and the
    square-wave test's NRMS fails with output_swing; at 0.5 V both pass."""
    from designer.plant.circuit_design import SQUARE_NRMS_PASS, with_square_test
    for amplitude_v, ok in ((2.0, False), (0.5, True)):
        r = design("mfb-lowpass", fc_hz=1000, zeta=0.5, gain=10, amplitude_v=amplitude_v)
        with_square_test(r, amplitude_v, 220.0)
        with_bench(r)
        assert check(r, "output_swing").ok is ok
        assert (r.square.nrms < SQUARE_NRMS_PASS) is ok
        if not ok:
            # the rail: SPICE's output stops near the LM741's -14 V where the model goes past -20 V
            assert r.square.y_model.min() < -20 and r.square.y_spice.min() > r.opamp.vout_min - 0.5


@pytest.mark.parametrize("name", sorted(REGISTRY))
def test_a_square_wave_too_fast_to_settle_fails_the_period_check_on_every_section(name):
    """The seed's square_wave_period for every section: a --square-freq whose half period is shorter than the
    op-amp-aware response's 2 % settling time fails (the scope would never show a settled step), the recommended
    square wave has no such check, and setting the bench again says it once."""
    from designer.plant.bench import PERIOD_CHECK
    result = design(name)
    assert PERIOD_CHECK not in [c.id for c in result.checks]
    settling = 1.0 / (2 * 1.5 * result.test.frequency_hz)      # the recommendation's 1.5 settling times a half
    fast = 1.0 / (2 * 0.25 * settling)                          # a half period of a quarter of it
    result = with_bench(result, fast)
    result = with_bench(result, fast)
    late = [c for c in result.checks if c.id == PERIOD_CHECK]
    assert len(late) == 1 and not late[0].ok and "settling time" in late[0].shown()
