"""The filter's bench test (designer.filters.bench): the sweep's expected gain and
phase are the chosen cascade's response with the op-amp's model, the band holds
the nominal, the scope settings are 1-2-5 steps, the step settles at the DC gain,
the burst reaches |H(f0)| A, the slew figure is 2 pi fn Vpk, the tables' Q are the
stages', and the Bessel's delay at DC is the closed form d1/d0 - n1/n0."""

import math

import numpy as np
import pytest
from hypothesis import given
from hypothesis import strategies as st

from designer.filters.bench import bench_of, nice_down, nice_up
from designer.filters.design import design
from designer.filters.spec import FilterSpec

SPECS = {
    "sk-butter-lp4": dict(family="butterworth", order=4, fc_hz=1000, opamp="TL072"),
    "mfb-cheb-hp5": dict(filter_type="highpass", family="chebyshev", ripple_db=0.5, order=5, fc_hz=1000,
                         topology="mfb", opamp="TL072"),
    "bessel-lp3": dict(family="bessel", order=3, fc_hz=2000, opamp="TL072"),
    "bp-wide": dict(filter_type="bandpass", family="butterworth", order=2, f_low_hz=300, f_high_hz=3000,
                    opamp="TL072"),
}


@pytest.fixture(scope="module", params=list(SPECS))
def made(request):
    r = design(FilterSpec(**SPECS[request.param]), simulate=False)
    return r, bench_of(r)


def brute_125(x, up):
    vals = [m * 10.0 ** e for e in range(-15, 16) for m in (1, 2, 5)]
    return min(v for v in vals if v >= x * (1 - 1e-12)) if up else max(v for v in vals if v <= x * (1 + 1e-12))


@given(st.floats(1e-12, 1e12))
def test_nice_steps_equal_brute_force(x):
    assert nice_up(x) == pytest.approx(brute_125(x, True), rel=1e-12)
    assert nice_down(x) == pytest.approx(brute_125(x, False), rel=1e-12)


def test_sweep_is_the_cascade_with_its_opamp(made):
    r, b = made
    f = np.array([p.f_hz for p in b.sweep])
    h = r.cascade().response(2j * math.pi * f, r.opamp)
    assert [p.gain_db for p in b.sweep] == pytest.approx(20 * np.log10(np.abs(h)), abs=1e-9)
    assert [p.phase_deg for p in b.sweep] == pytest.approx(np.degrees(np.angle(h)), abs=1e-9)
    for p in b.sweep:
        assert p.gain_lo_db <= p.gain_db + 1e-9 and p.gain_db <= p.gain_hi_db + 1e-9
        assert p.phase_lo_deg <= p.phase_deg + 1e-9 and p.phase_deg <= p.phase_hi_deg + 1e-9
        assert p.out_pk_v == pytest.approx(r.spec.amplitude_v * 10 ** (p.gain_db / 20), rel=1e-9)
        # two periods fit in ten divisions, the input's pk-pk in six, each the least 1-2-5 step that does
        assert p.time_per_div_s == nice_up(2 / (10 * p.f_hz))
        assert p.ch1_v_per_div == nice_up(2 * r.spec.amplitude_v / 6)
        assert 10 * p.time_per_div_s >= 2 / p.f_hz * (1 - 1e-9)
    assert f.tolist() == sorted(f.tolist())


def test_time_test_settles_where_the_transfer_function_says(made):
    r, b = made
    tt = b.time_test
    num, den = r.cascade().coefficients()
    if tt.kind == "step":
        assert tt.metrics["final_v"] == pytest.approx(tt.amplitude_v * num[-1] / den[-1], rel=1e-3)
        # the square wave's half period holds five settling times
        assert 0.5 / tt.frequency_hz >= 4.99 * tt.metrics["settling_time_s"]
    else:
        steady = tt.amplitude_v * abs(r.cascade().response(2j * math.pi * tt.frequency_hz))
        assert tt.metrics["steady_pk_v"] == pytest.approx(steady, rel=1e-12)
        last = (tt.t_s > (tt.cycles - 1) / tt.frequency_hz) & (tt.t_s <= tt.cycles / tt.frequency_hz)
        assert np.max(np.abs(tt.output_v[last])) == pytest.approx(steady, rel=0.03)


def test_stage_checks_and_tables(made):
    r, b = made
    for stage, c in zip(r.stages, b.checks):
        assert c.slew_needed_v_per_s == pytest.approx(2 * math.pi * stage.plan.fn_hz * stage.node_peak_v, rel=1e-12)
        assert c.gbw_hz == r.opamp.gbw_hz and c.ok
    for stage, t in zip(r.stages, b.tables):
        if t.table_q is not None:
            assert t.table_q == pytest.approx(stage.plan.q, rel=1e-9)
        if r.spec.filter_type == "lowpass" and r.spec.family != "chebyshev" and t.table_fn_ratio is not None:
            assert t.table_fn_ratio == pytest.approx(t.design_fn_ratio, rel=1e-9)


def test_bessel_group_delay_at_dc_is_the_closed_form():
    r = design(FilterSpec(**SPECS["bessel-lp3"]), simulate=False)
    b = bench_of(r)
    num, den = r.cascade().coefficients()
    num = np.concatenate([np.zeros(2), num])   # a low-pass: its numerator may be one constant
    tau0 = den[-2] / den[-1] - num[-2] / num[-1]
    assert b.group_delay[1][0] == pytest.approx(tau0, rel=2e-3)
    assert b.to_dict()["group_delay"]["dc_delay_s"] == pytest.approx(tau0, rel=2e-3)


def test_bench_is_repeatable():
    r = design(FilterSpec(**SPECS["sk-butter-lp4"]), simulate=False)
    assert bench_of(r).to_dict() == bench_of(r).to_dict()
