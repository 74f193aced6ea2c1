"""check-design ``kind: filter`` (designer.check.filter_kind): a filter designed from
``filter:`` or as built from ``stages:``, in every op-amp corner, its mask as checks
on the op-amp model and on SPICE's .ac; the figures against brute force on the
response and against the design's own; a Bessel's group-delay target (delay:) on
the model, on SPICE and in the yield; the refusals one line at the key's line."""

import json
import math

import numpy as np
import pytest
from helpers import ROOT
from specfiles import refusal, write

from designer.check.filter_kind import filter_figures, run_filter
from designer.check.run import run_corner
from designer.check.spec import load_spec
from designer.core import opamps
from designer.filters import get

DESIGNED = """\
    name: f4
    kind: filter
    filter: {type: lowpass, family: butterworth, order: 4, fc: 1k}
    opamp: [TL072, NE5532]
    mask: {passband: 500, max_loss: 0.5, stopband: 4k, min_attenuation: 40}
    checks:
      f3_hz: {min: 950, max: 1050}
    """

REF = ROOT / "reports" / "filter_butterworth_lp4_sk_1k" / "result.json"


def as_built_text():
    stages = json.loads(REF.read_text())["stages"]
    lines = [f"  - {{topology: {s['topology']}, parts: {{{', '.join(f'{k}: {v!r}' for k, v in s['parts'].items())}}}}}"
             for s in stages]
    return "name: built\nkind: filter\nopamp: TL072\nstages:\n" + "\n".join(lines) + \
        "\nmask: {passband: 500, max_loss: 0.5, stopband: 4k, min_attenuation: 40}\n"


def test_designed_spec_loads_a_design_per_corner_and_the_mask_as_checks(tmp_path):
    spec = load_spec(write(tmp_path, DESIGNED))
    assert spec.corners == ("TL072", "NE5532") and not spec.analyze
    assert [d.spec.opamp for d in spec.designs] == ["TL072", "NE5532"]
    figs = [c.figure for c in spec.checks]
    assert figs == ["f3_hz", "passband_loss_db", "stopband_attenuation_db", "spice_passband_loss_db",
                    "spice_stopband_attenuation_db"]
    limits = {c.figure: c for c in spec.checks}
    assert limits["passband_loss_db"].max == 0.5 and limits["stopband_attenuation_db"].min == 40


@pytest.mark.parametrize("text, words", [
    ("kind: filter\nopamp: TL072\nchecks: {f3_hz: {max: 1k}}\n", "filter: {type, family, order, fc, ..} (designed)"),
    ("kind: filter\nfilter: {order: 4, fc: 1k, famly: bessel}\nchecks: {f3_hz: {max: 1k}}\n", "closest: 'family'"),
    ("kind: filter\nfilter: {order: 4, fc: abc}\nchecks: {f3_hz: {max: 1k}}\n", "filter.fc"),
    ("kind: filter\nfilter: {order: 12, fc: 1k}\nchecks: {f3_hz: {max: 1k}}\n", "filter.order must be 1 to 10"),
    ("kind: filter\nfilter: {order: 4, fc: 1k}\nmask: {passband: 1k}\n", "mask needs passband, max_loss"),
    ("kind: filter\nfilter: {order: 4, fc: 1k}\n", "nothing to check"),
    ("kind: filter\nfilter: {order: 4, fc: 1k}\nchecks: {f3: {max: 1k}}\n", "closest: 'f3_hz'"),
    ("kind: filter\nstages:\n  - {topology: sallen-key-lowpas, parts: {R1: 1k}}\nchecks: {f3_hz: {max: 1k}}\n",
     "unknown section 'sallen-key-lowpas'"),
    ("kind: filter\nstages:\n  - {topology: rc-lowpass, parts: {R1: 1k}}\nchecks: {f3_hz: {max: 1k}}\n",
     "missing C1"),
    ("kind: filter\nstages:\n  - {topology: rc-lowpass, parts: {R1: 1k, C1: -1n}}\nchecks: {f3_hz: {max: 1k}}\n",
     "must be positive"),
    ("kind: filter\nfilter: {order: 4, fc: 1k}\nstages: []\nchecks: {f3_hz: {max: 1k}}\n", "one of them"),
    ("kind: filter\nfilter: {order: 4, fc: 1k}\nchecks: {f3_hz: {max: 1k}}\nyield: {min: 95%, engine: spice}\n",
     "a filter's yield has the analytic engine only"),
    ("kind: filter\nfilter: {order: 4, fc: 1k}\nchecks: {spice_f3_hz: {max: 1k}}\nyield: {min: 95%}\n",
     "none of them limits a figure the analytic engine computes"),
    ("kind: filter\nfilter: {order: 4, fc: 1k}\nchecks: {f3_hz: {max: 1k}}\ntolerances: {R: 1%}\n",
     "give yield: {min: 95%} too"),
    ("kind: filter\nfilter: {order: 4, fc: 1k}\nchecks: {f3_hz: {max: 1k}}\nyield: {min: 95%}\n"
     "tolerances: {R1: 1%}\n", "tolerances"),
    ("kind: filter\nstages:\n  - {topology: rc-lowpass, parts: {R1: 1k, C1: 1n}}\nchecks: {f3_hz: {max: 1k}}\n"
     "yield: {min: 95%}\n", "stages: (as built) are checked as they are"),
    # a group-delay target: a Bessel low-pass's, both keys, joining the mask in picking the order when designed
    ("kind: filter\nfilter: {family: butterworth}\nmask: {passband: 1k, max_loss: 3, stopband: 10k, "
     "min_attenuation: 30}\ndelay: {max_error_pct: 1, to: 1k}\n", "delay: a group-delay target is for a bessel filter"),
    ("kind: filter\nfilter: {type: highpass, family: bessel, order: 3, fc: 1k}\ndelay: {max_error_pct: 1, to: 1k}\n",
     "delay: a group-delay target is for a lowpass (its delay at DC); this filter is a highpass"),
    ("kind: filter\nfilter: {family: bessel}\nmask: {passband: 1k, max_loss: 3, stopband: 10k, "
     "min_attenuation: 30}\ndelay: {max_error_pct: 1}\n", "delay needs max_error_pct and to"),
    ("kind: filter\nfilter: {family: bessel, order: 4, fc: 1k}\ndelay: {max_error_pct: 1, to: 1k}\n",
     "delay: a designed filter's group-delay target joins mask: in picking the order"),
    ("kind: filter\nfilter: {family: bessel}\nmask: {passband: 1k, max_loss: 3, stopband: 10k, "
     "min_attenuation: 30}\ndelay: {max_error_pct: 1, to: 1k, upto: 2k}\n", "upto"),
    ("kind: filter\nfilter: {family: bessel}\nmask: {passband: 1k, max_loss: 3, stopband: 10k, "
     "min_attenuation: 30}\ndelay: {max_error_pct: 99, to: 1k}\n", "delay.max_error_pct"),
    ("kind: filter\nfilter: {family: bessel}\nmask: {passband: 1k, max_loss: 3, stopband: 10k, "
     "min_attenuation: 30}\ndelay: {max_error_pct: 1, to: -1k}\n", "delay.to"),
    ("kind: filter\nstages:\n  - {topology: rc-highpass, parts: {R1: 1k, C1: 1n}}\ndelay: {max_error_pct: 1, to: 1k}\n",
     "this filter is a highpass"),
])
def test_refusals_are_one_line(tmp_path, text, words):
    msg = refusal(write(tmp_path, text))
    assert words in msg, msg
    assert msg.startswith(str(tmp_path / "spec.yaml") + ":")


def test_figures_by_brute_force():
    # a Butterworth-like as-built cascade: the -3 dB point and the mask figures from a dense grid
    stages = [("sallen-key-lowpass", {"R1": 10e3, "R2": 10e3, "C1": 10e-9, "C2": 22e-9}),
              ("rc-lowpass", {"R1": 15e3, "C1": 10e-9})]
    mask = {"passband": 300.0, "max_loss": 1.0, "stopband": 5e3, "min_attenuation": 20.0}
    amp = opamps.get("TL072")
    figs = filter_figures(stages, amp, None, mask, None)
    f = np.logspace(0, 6, 600_001)
    h = np.ones_like(f, dtype=complex)
    for t, v in stages:
        h = h * get(t).response(v, 2j * math.pi * f, amp)
    g = 20 * np.log10(np.abs(h))
    assert figs["passband_gain_db"] == pytest.approx(0.0, abs=1e-12)   # DC gain 1 (ideal coefficients)
    f3 = f[np.flatnonzero(g >= -10 * math.log10(2))[-1]]
    assert figs["f3_hz"] == pytest.approx(f3, rel=1e-4)
    assert figs["passband_loss_db"] == pytest.approx(-g[f <= 300].min(), abs=1e-4)
    assert figs["stopband_attenuation_db"] == pytest.approx(-g[(f >= 5e3) & (f <= figs_hi(stages))].max(), abs=1e-3)


def figs_hi(stages):
    from designer.check.filter_kind import _grid
    return _grid(stages)[-1]


@pytest.mark.spice
def test_as_built_reference_equals_its_design(tmp_path):
    if not REF.exists():
        pytest.skip(f"{REF} not generated (run make demo)")
    built = load_spec(write(tmp_path, as_built_text(), "built.yaml"))
    designed = load_spec(write(tmp_path, DESIGNED.replace("[TL072, NE5532]", "TL072")))
    assert built.analyze and built.corners == ("TL072",)
    a = run_filter(built.designs[0], "ngspice-cli").figures
    b = run_filter(designed.designs[0], "ngspice-cli").figures
    for k in ("f3_hz", "passband_loss_db", "stopband_attenuation_db", "spice_f3_hz"):
        assert a[k] == pytest.approx(b[k], rel=1e-9), k
    ref = json.loads(REF.read_text())
    assert a["f3_hz"] == pytest.approx(ref["figures"]["f3_hz"], rel=1e-3)
    # SPICE's .ac agrees with the model: the same figures within a hundredth of a dB
    assert a["spice_passband_loss_db"] == pytest.approx(a["passband_loss_db"], abs=0.01)
    assert a["spice_max_deviation_db"] < 0.01


@pytest.mark.spice
def test_a_broken_mask_fails_on_the_model_and_on_spice(tmp_path):
    spec = load_spec(write(tmp_path, DESIGNED.replace("min_attenuation: 40", "min_attenuation: 60")))
    out = run_corner(spec, 0, "ngspice-cli")
    status = {c.id: c.status for c in out.cases}
    assert status["stopband_attenuation_db"] == "fail" and status["spice_stopband_attenuation_db"] == "fail"
    assert status["passband_loss_db"] == "pass" and status["f3_hz"] == "pass"
    assert out.design["figures"]["stopband_attenuation_db"] < 60


YIELD = DESIGNED.replace("[TL072, NE5532]", "TL072") + """tolerances: {R: 1%, C: 5%}
    yield: {min: 99%, samples: 300, seed: 7}
    """


def _build(res, values, i) -> list:
    """Build ``i``'s stages (topology, parts) from the cascade designators' draws (R101 is stage 1's R1)."""
    out = []
    for k, st in enumerate(res.stages, 1):
        topo = get(st.topology)
        out.append((st.topology, {r: float(values[topo.prefixed(r, f"{k}0")][i]) for r in topo.designators}))
    return out


@pytest.mark.spice
def test_yield_counts_the_builds_inside_the_checks_and_the_mask(tmp_path):
    from designer.tolerance import runner
    from designer.tolerance.filter import nominal_parts, series_of
    from designer.tolerance.parts import resolve
    spec = load_spec(write(tmp_path, YIELD))
    y = spec.yield_spec
    assert (y.min, y.samples, y.seed, y.tolerances) == (0.99, 300, 7, ("R=1.0%", "C=5.0%"))
    out = run_corner(spec, 0, "ngspice-cli")
    case = next(c for c in out.cases if c.id == "yield")
    mc = out.design["monte_carlo"]
    assert mc["yield"]["samples"] == 300 and case.value == mc["yield"]["fraction"]
    lo, hi = mc["yield"]["ci95"]
    assert lo <= case.value <= hi
    # brute force: every build's figures from the check's own dense-grid model with the exact op-amp
    # response, judged against the same limits, agree with the engine's verdict build by build
    res = run_filter(spec.designs[0], "ngspice-cli").design
    nominal = nominal_parts(res)
    tol = resolve(y.tolerances, nominal, series_of(res))
    values = runner.Draw(nominal, tol.of, y.samples, y.seed, y.sampler, y.dist).values()
    amp = opamps.get("TL072")
    mask = spec.designs[0].mask
    checks = [c for c in spec.checks if not c.figure.startswith("spice_")]
    passed = 0
    for i in range(y.samples):
        figs = filter_figures(_build(res, values, i), amp, 0.0, mask, None)
        passed += all(c.judge(figs[c.figure])[0] for c in checks)
    assert passed / y.samples == pytest.approx(case.value, abs=2 / y.samples)
    assert 0 < case.value < 1   # the f3_hz window cuts some builds: not trivially all or none
    assert case.status == ("pass" if case.value >= 0.99 else "fail")
    assert "95 % Wilson interval" in case.message and "not counted, no engine figure: spice_passband_loss_db" \
        in case.message


@pytest.mark.spice
def test_a_yield_below_its_minimum_names_the_figure_that_loses_most(tmp_path):
    text = YIELD.replace("f3_hz: {min: 950, max: 1050}", "f3_hz: {min: 995, max: 1005}")
    out = run_corner(load_spec(write(tmp_path, text)), 0, "ngspice-cli")
    case = next(c for c in out.cases if c.id == "yield")
    assert case.status == "fail" and "below min 99 %" in case.message
    assert "f3_hz loses most" in case.message and "outside 995 Hz to 1.005 kHz" in case.message
    assert "the corner (build " in case.message and "R101 " in case.message


def test_stage_gain_in_a_spec(tmp_path):
    text = DESIGNED.replace("order: 4, fc: 1k}", "order: 6, fc: 1k, gain: 4, stage_gain: '2,2,1'}").replace(
        "[TL072, NE5532]", "TL072")
    spec = load_spec(write(tmp_path, text))
    assert spec.designs[0].spec.stage_gains == (2.0, 2.0, 1.0)
    msg = refusal(write(tmp_path, text.replace("'2,2,1'", "'2,3,1'"), "bad.yaml"))
    assert "filter.stage_gain: 2 x 3 x 1 = 6 is not filter.gain 4" in msg, msg


BAND = """\
    name: bp
    kind: filter
    filter: {type: bandpass, family: butterworth}
    opamp: TL072
    mask: {passband: [900, 1.1k], max_loss: 1, stopband: [600, 1.7k], min_attenuation: 30}
    """


@pytest.mark.spice
def test_bandpass_mask_picks_the_design_and_is_checked_on_model_and_spice(tmp_path):
    from designer.filters.spec import FilterSpec
    spec = load_spec(write(tmp_path, BAND))
    want = FilterSpec(filter_type="bandpass", passband_hz=(900, 1100), stopband_hz=(600, 1700), max_loss_db=1,
                      min_attenuation_db=30, opamp="TL072")
    got = spec.designs[0].spec
    assert (got.order, got.f_low_hz, got.f_high_hz) == (want.order, want.f_low_hz, want.f_high_hz)
    out = run_corner(spec, 0, "ngspice-cli")
    status = {c.id: c.status for c in out.cases}
    assert set(status.values()) == {"pass"} and len(status) == 4
    f = out.design["figures"]
    # the model's figures against the design's own margins; SPICE's (a denser sweep) against the model's
    assert f["passband_loss_db"] == pytest.approx(1 - out.design["design"]["figures"]["mask_passband_margin_db"],
                                                  abs=0.01)
    assert f["spice_passband_loss_db"] == pytest.approx(f["passband_loss_db"], abs=0.01)
    assert f["spice_stopband_attenuation_db"] == pytest.approx(f["stopband_attenuation_db"], abs=0.01)


@pytest.mark.parametrize("mask, words", [
    ("{passband: [900, 1.1k], max_loss: 1, stopband: 600, min_attenuation: 30}", "gives passband and stopband both"),
    ("{passband: [900, 1.1k, 2k], max_loss: 1, stopband: [600, 3k], min_attenuation: 30}", "got 3 values"),
    ("{passband: [900, abc], max_loss: 1, stopband: [600, 3k], min_attenuation: 30}", "positive numbers"),
    ("{passband: [1.1k, 900], max_loss: 1, stopband: [600, 3k], min_attenuation: 30}", "edges cross"),
])
def test_bandpass_mask_refusals(tmp_path, mask, words):
    msg = refusal(write(tmp_path, BAND.replace(BAND.splitlines()[4].strip(), f"mask: {mask}")))
    assert words in msg and "\n" not in msg, msg


def test_a_lowpass_refuses_a_two_edge_mask(tmp_path):
    text = DESIGNED.replace("passband: 500", "passband: [500, 600]").replace("stopband: 4k", "stopband: [100, 4k]")
    assert "a lowpass's mask takes one edge each" in refusal(write(tmp_path, text))


DELAY = """\
    name: bessel-delay
    kind: filter
    filter: {type: lowpass, family: bessel}
    opamp: TL072
    mask: {passband: 1k, max_loss: 3, stopband: 10k, min_attenuation: 30}
    delay: {max_error_pct: 1, to: 1k}
    tolerances: {R: 1%, C: 5%}
    yield: {min: 10%, samples: 300, seed: 7}
    """


@pytest.mark.spice
def test_a_delay_target_is_checked_on_the_model_on_spice_and_in_the_yield(tmp_path):
    from designer.filters import FilterSpec
    from designer.filters.design import design
    from designer.tolerance.filter import filter_monte_carlo, mask_limits
    spec = load_spec(write(tmp_path, DELAY))
    limits = {c.figure: c for c in spec.checks}
    assert limits["delay_error_pct"].max == 1 and limits["spice_delay_error_pct"].max == 1
    # the target joins the mask in picking the order and the parts: design-filter's with --max-delay-error
    res = design(FilterSpec(family="bessel", passband_hz=1e3, max_loss_db=3, stopband_hz=10e3, min_attenuation_db=30,
                            max_delay_error_pct=1, delay_to_hz=1e3, opamp="TL072"))
    assert spec.designs[0].spec.max_delay_error_pct == 1 and spec.designs[0].spec.delay_to_hz == 1e3
    out = run_corner(spec, 0, "ngspice-cli")
    cases = {c.id: c for c in out.cases}
    assert cases["delay_error_pct"].value == pytest.approx(res.figures["delay_error_pct"], abs=1e-6)
    # SPICE's .ac phase (differences between its points) against the model's central difference
    assert cases["spice_delay_error_pct"].value == pytest.approx(res.figures["delay_error_pct"], abs=0.02)
    assert all(cases[k].status == "pass" for k in ("delay_error_pct", "spice_delay_error_pct"))
    # the yield counts the mask and the delay target: the tolerance engine's on the same draws; the mask alone more
    mc = filter_monte_carlo(res, 300, 7, tol_items=("R=1%", "C=5%"), tighten=False)
    assert cases["yield"].value == mc.yield_count / 300
    plain = filter_monte_carlo(res, 300, 7, tol_items=("R=1%", "C=5%"), limit_items=mask_limits(res)[:2],
                               tighten=False)
    assert plain.yield_count > mc.yield_count
    assert "delay_error_pct" in cases["yield"].message and out.design["delay"] == {"max_error_pct": 1.0, "to": 1e3}


def test_an_as_built_lowpass_takes_a_delay_target(tmp_path):
    # as built (no family known): any low-pass cascade; the model's figure is the central difference's
    from designer.filters import Cascade
    from designer.filters.prototype import DELAY_POINTS, delay_error_pct
    text = as_built_text().replace("\nmask:", "\ndelay: {max_error_pct: 5, to: 300}\nmask:")
    spec = load_spec(write(tmp_path, text))
    case = spec.designs[0]
    assert case.delay == {"max_error_pct": 5.0, "to": 300.0}
    figs = run_filter(case, None).figures
    cascade = Cascade([(get(t), v) for t, v in case.stages])
    amp = opamps.get("TL072")
    f = np.linspace(0.0, 300.0, DELAY_POINTS)
    w = 2 * math.pi * f
    dw = 2 * math.pi * 300.0 * 1e-3   # a step 10 x the figure's: the difference is second order
    tau = -np.angle(cascade.response(1j * (w + dw), amp) / cascade.response(1j * (w - dw), amp)) / (2 * dw)
    assert figs["delay_error_pct"] == pytest.approx(delay_error_pct(tau, tau[0]), rel=1e-3)
    assert "spice_delay_error_pct" not in figs   # not simulated here
