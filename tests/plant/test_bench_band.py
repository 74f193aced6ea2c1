"""The tolerance band written once against the Topology (:func:`designer.plant.bench.tolerance_band`):
over the registry, each section's band holds its nominal step and its corners' steps are the steps of
the corner values computed here independently; the Sallen-Key plant's band is, bit for bit, the one
its parts record used to give (the old function, kept below as the test's oracle)."""

import itertools
import json
import math
from dataclasses import replace
from pathlib import Path

import numpy as np
import pytest
import scipy.signal as sig

from designer.core import eseries

from designer.core.lti import dense_time, step_response
from designer.core.metrics import step_metrics
from designer.filters import REGISTRY
from designer.filters.sallen_key_lowpass_parts import part_values, section_of
from designer.plant.bench import Band, ToleranceBand, corner_tolerances, tolerance_band
from designer.plant.model import plant_tf
from designer.plant.sallenkey import SallenKeyParts

ROOT = Path(__file__).resolve().parents[2]
TOPOLOGIES = list(REGISTRY.values())
IDS = list(REGISTRY)
TOL = {"R": 0.05, "C": 0.10}


def old_sallen_key_band(parts: SallenKeyParts, r_tol: float, c_tol: float, t_end: float) -> ToleranceBand:
    """The Sallen-Key plant's band as designer.plant.bench computed it before it was written against the
    Topology: 16 corners of R1 R2 C1 C2, the parts record's fn, zeta and transfer function."""
    t = dense_time(t_end, 8001)
    rows, lo, hi = [], None, None
    for s in itertools.product((-1, 1), repeat=4):
        p = replace(parts, r1=parts.r1 * (1 + s[0] * r_tol), r2=parts.r2 * (1 + s[1] * r_tol),
                    c1=parts.c1 * (1 + s[2] * c_tol), c2=parts.c2 * (1 + s[3] * c_tol))
        y = step_response(*plant_tf(p), t)
        lo = y if lo is None else np.minimum(lo, y)
        hi = y if hi is None else np.maximum(hi, y)
        m = step_metrics(t, y, final=p.gain)
        rows.append((p.fn_hz, p.zeta, m.overshoot_pct, m.peak_time_s, m.rise_time_s, m.settling_time_s))
    bands = []
    for column in zip(*rows):
        vals = [v for v in column if v is not None and not math.isnan(v)]
        bands.append(Band(min(vals), max(vals)) if vals else Band(None, None))
    return ToleranceBand(*bands, r_tolerance_pct=100 * r_tol, c_tolerance_pct=100 * c_tol, t_s=t, lo=lo, hi=hi)


def sallen_key_band(parts: SallenKeyParts, r_tol: float, c_tol: float, t_end: float) -> ToleranceBand:
    """The plant's call (designer.plant.design._analyse): the RC network's corners, the gain pair held."""
    section = section_of(parts)
    tol = {r: r_tol if r[0] == "R" else c_tol for r in section.designators if r not in section.choice_parts}
    return tolerance_band(section, part_values(parts), tol, t_end)


def same_bits(a: ToleranceBand, b: ToleranceBand) -> None:
    assert a.to_dict() == b.to_dict()
    assert json.dumps(a.to_dict()) == json.dumps(b.to_dict())
    for f in ("t_s", "lo", "hi"):
        assert np.array_equal(getattr(a, f), getattr(b, f))


def test_the_seed_plant_s_band_is_the_old_function_s_bit_for_bit():
    """The committed reference plant's parts (reports/plant_fc3500_z0.2) and its series' tolerances."""
    data = json.loads((ROOT / "reports" / "plant_fc3500_z0.2" / "result.json").read_text())
    b = data["built"]
    parts = SallenKeyParts(b["R1_ohm"], b["R2_ohm"], b["C1_f"], b["C2_f"])
    band = data["built"]["tolerance_band"]
    r_tol, c_tol = band["r_tolerance_pct"] / 100, band["c_tolerance_pct"] / 100
    t_end = 4e-3
    same_bits(sallen_key_band(parts, r_tol, c_tol, t_end), old_sallen_key_band(parts, r_tol, c_tol, t_end))


@pytest.mark.parametrize("seed", range(6))
def test_sallen_key_bands_with_and_without_gain_equal_the_old_function(seed):
    """Random builds, the follower and the section with gain (its gain pair held, as before)."""
    rng = np.random.default_rng(seed)
    r1, r2 = 10 ** rng.uniform(3, 5, 2)
    c1 = 10 ** rng.uniform(-9, -7)
    c2 = c1 * 10 ** rng.uniform(0.5, 1.5)
    if seed % 2:
        r3, r4 = 10e3, float(10 ** rng.uniform(3, 4.3))
        parts = SallenKeyParts(r1, r2, c1, c2, 1 + r4 / r3, r3, r4)
    else:
        parts = SallenKeyParts(r1, r2, c1, c2)
    t_end = 20 / (2 * math.pi * parts.fn_hz * parts.zeta)
    same_bits(sallen_key_band(parts, 0.01, 0.05, t_end), old_sallen_key_band(parts, 0.01, 0.05, t_end))


@pytest.mark.parametrize("topology", TOPOLOGIES, ids=IDS)
def test_a_section_s_band_holds_its_nominal_step_and_its_corners_steps(topology):
    """The envelope holds the nominal step; each corner's step (scipy's, of the corner values' coefficients)
    lies inside it, and the envelope is made of them (at every time one corner's step touches each edge)."""
    values = topology.synthesize(topology.example)
    fn = topology.figures(values).fn_hz
    band = tolerance_band(topology, values, TOL, 30 / (2 * math.pi * fn))
    tol = corner_tolerances(topology, TOL)
    assert list(tol) == list(topology.designators)
    assert band.r_tolerance_pct == pytest.approx(100 * TOL["R"]) and band.c_tolerance_pct == pytest.approx(100 * TOL["C"])
    scale = max(np.max(np.abs(band.hi)), np.max(np.abs(band.lo)))
    steps = []
    for signs in itertools.product((-1, 1), repeat=len(tol)):
        corner = {r: values[r] * (1 + s * TOL[r[0]]) for r, s in zip(topology.designators, signs)}
        num, den = (np.asarray(c, float) for c in topology.coefficients(corner))
        num = num[int(np.argmax(np.abs(num) > 0)):]
        steps.append(sig.step((num, den), T=band.t_s)[1])
    steps = np.array(steps)
    assert np.allclose(band.lo, steps.min(axis=0), atol=1e-9 * scale)
    assert np.allclose(band.hi, steps.max(axis=0), atol=1e-9 * scale)
    num, den = (np.asarray(c, float) for c in topology.coefficients(values))
    nominal = sig.step((num[int(np.argmax(np.abs(num) > 0)):], den), T=band.t_s)[1]
    assert np.all(band.lo <= nominal + 1e-9 * scale) and np.all(nominal <= band.hi + 1e-9 * scale)
    # fn and zeta: the section's ideal pair at the corners
    pairs = np.array([topology.ideal_pair({r: values[r] * (1 + s * TOL[r[0]]) for r, s in
                                           zip(topology.designators, signs)})
                      for signs in itertools.product((-1, 1), repeat=len(tol))])
    assert (band.fn_hz.lo, band.fn_hz.hi) == (pairs[:, 0].min(), pairs[:, 0].max())
    assert (band.zeta.lo, band.zeta.hi) == (pairs[:, 1].min(), pairs[:, 1].max())
    assert band.fn_hz.lo < topology.ideal_pair(values)[0] < band.fn_hz.hi
    if topology.kind != "lowpass":
        assert band.overshoot_pct == Band(None, None)


def test_per_designator_tolerances_hold_the_parts_not_named():
    """A designator left out of the tolerances does not vary: a band over R1 alone is the band of its two values."""
    topology = REGISTRY["sallen-key-lowpass"]
    values = topology.synthesize(topology.example)
    fn = topology.figures(values).fn_hz
    band = tolerance_band(topology, values, {"R1": 0.05}, 30 / (2 * math.pi * fn))
    fns = [topology.ideal_pair({**values, "R1": values["R1"] * (1 + s * 0.05)})[0] for s in (-1, 1)]
    assert (band.fn_hz.lo, band.fn_hz.hi) == (min(fns), max(fns))
    assert band.c_tolerance_pct == 0.0


# ---- the sine check of a high- and a band-pass (closed forms), and the section plant's bench ---------------

def test_a_high_pass_sine_check_is_the_low_pass_mirrored():
    """H = s^2 / (s^2 + 2 zeta wn s + wn^2): the peak Mr = 1/(2 zeta sqrt(1 - zeta^2)) at fn / sqrt(1 - 2 zeta^2)
    (the low-pass's, f -> fn^2 / f), the gain read against the high-frequency end; Butterworth's -3 dB at fn."""
    from designer.core.opamps import get as get_opamp
    from designer.plant.bench import sine_check
    ideal = get_opamp("ideal")
    fn = 1e3
    wn = 2 * math.pi * fn
    zeta = 0.3
    s = sine_check([1.0, 0.0, 0.0], [1.0, 2 * zeta * wn, wn ** 2], ideal, 2.0, fn, kind="highpass")
    assert s.f_peak_hz == pytest.approx(fn / math.sqrt(1 - 2 * zeta ** 2), rel=1e-3)
    assert s.peak_gain / s.dc_gain == pytest.approx(1 / (2 * zeta * math.sqrt(1 - zeta ** 2)), rel=1e-4)
    assert s.dc_gain == pytest.approx(1.0, rel=1e-3) and s.f_3db_hz < fn
    assert s.to_dict()["kind"] == "highpass"
    b = sine_check([1.0, 0.0, 0.0], [1.0, math.sqrt(2) * wn, wn ** 2], ideal, 2.0, fn, kind="highpass")
    assert b.f_peak_hz is None and b.no_peak == "no resonance peak (zeta >= 0.707)"
    assert b.f_3db_hz == pytest.approx(fn, rel=1e-4)


def test_a_band_pass_sine_check_is_read_at_its_centre():
    """H = K (wn/Q) s / (s^2 + (wn/Q) s + wn^2): the centre fn with gain K, the -3 dB points
    fn (sqrt(1 + 1/(4 Q^2)) -/+ 1/(2 Q))."""
    from designer.core.opamps import get as get_opamp
    from designer.plant.bench import sine_check
    fn, q, k = 1e3, 5.0, 4.0
    wn = 2 * math.pi * fn
    s = sine_check([0.0, k * wn / q, 0.0], [1.0, wn / q, wn ** 2], get_opamp("ideal"), 2.0, fn, kind="bandpass")
    assert s.f_peak_hz == pytest.approx(fn, rel=1e-4) and s.peak_gain == pytest.approx(k, rel=1e-5)
    root = math.sqrt(1 + 1 / (4 * q * q))
    assert s.f_3db_low_hz == pytest.approx(fn * (root - 1 / (2 * q)), rel=1e-4)
    assert s.f_3db_hz == pytest.approx(fn * (root + 1 / (2 * q)), rel=1e-4)
    assert s.no_peak is None


def _section_plant(name, simulate=False):
    from designer.plant.circuit_design import design_circuit_plant
    from designer.plant.spec import PlantSpec
    topology = REGISTRY[name]
    ex = topology.example
    return design_circuit_plant(PlantSpec(fc_hz=ex.fn_hz, zeta=None if ex.q is None else 1 / (2 * ex.q),
                                          gain=ex.gain, opamp="TL072", topology=name), simulate=simulate)


@pytest.mark.parametrize("topology", TOPOLOGIES, ids=IDS)
def test_a_section_plant_has_the_bench_in_its_json(topology):
    """The new keys (test_signal, tolerance_band, scope, sine_check) beside the old ones; the band is the bench
    function's over every declared part at its series' tolerance; CH2 holds the op-amp-aware step's swing."""
    from designer.plant.circuit import opamp_tf
    r = _section_plant(topology.name)
    d = r.to_dict()
    assert {"test_signal", "tolerance_band", "scope", "sine_check"} <= set(d)
    tol = {"R": eseries.TOLERANCE[r.sourcing.r_series], "C": eseries.TOLERANCE[r.sourcing.c_series]}
    band = tolerance_band(topology, r.values, tol, r.tolerance.t_s[-1])
    same_bits(band, r.tolerance)
    assert d["tolerance_band"]["fn_hz"]["min"] < r.figures["ideal"]["fn_hz"] < d["tolerance_band"]["fn_hz"]["max"]
    num, den = (np.asarray(c, float) for c in opamp_tf(topology, r.values, r.opamp))
    y = sig.step((num[int(np.argmax(np.abs(num) > 0)):], den), T=np.linspace(0, 40 * r.tolerance.t_s[-1], 40001))[1]
    ch2 = r.scope.channels[1]
    a = r.amplitude_v
    # the extremes read on the bench's grid: within 0.1 % of the swing of scipy's on its own grid
    swing = a * (y.max() - min(y.min(), 0.0))
    assert ch2.lo_v <= a * min(y.min(), 0.0) + 1e-3 * swing and ch2.hi_v >= a * y.max() - 1e-3 * swing
    assert 6 * ch2.volts_per_div >= ch2.hi_v - ch2.lo_v
    assert d["sine_check"]["amplitude_v"] > 0
    if topology.kind != "lowpass":
        assert d["sine_check"]["kind"] == topology.kind


@pytest.mark.spice
@pytest.mark.parametrize("name", ["mfb-bandpass", "sallen-key-highpass"])
def test_a_section_plant_s_sine_check_measures_spice_s_ac(name):
    """Simulated, the sine check's SPICE figures come from ngspice's .ac (fn/100 .. 100 fn) and agree with the
    op-amp-aware model's (the section plant's own rule, 0.05 dB: a -3 dB point within 0.5 %)."""
    r = _section_plant(name, simulate=True)
    s = r.sine
    # (the deck writes the sweep's ends to six digits)
    assert s.spice_f_hz[0] == pytest.approx(r.figures["ideal"]["fn_hz"] / 100, rel=1e-5)
    assert s.spice_f_3db_hz == pytest.approx(s.f_3db_hz, rel=5e-3)
    if name == "mfb-bandpass":
        assert s.spice_f_peak_hz == pytest.approx(s.f_peak_hz, rel=5e-3)
        assert s.spice_f_3db_low_hz == pytest.approx(s.f_3db_low_hz, rel=5e-3)


@pytest.mark.parametrize("name", ["mfb-bandpass", "sallen-key-highpass", "mfb-lowpass"])
def test_the_section_sheet_shows_the_bench_in_english_and_spanish(name):
    """The sheet's bench section: the band's heading and the sine check in English, and in Spanish with no
    English word left."""
    from helpers import english_left, foreign, sheet_text_nodes, vocabulary

    from designer.core.i18n import language
    from designer.plant import circuit_report as rep
    from designer.report.document import to_html
    r = _section_plant(name)
    with language("en"):
        en = to_html(rep.title_of(r), rep.sections(r), {})
    assert "Bench test: what the scope shows" in en and "band (R 5 %, C 10 %)" in en and "sine check" in en
    if name == "mfb-bandpass":
        assert "at the centre" in en
    with language("es"):
        es = to_html(rep.title_of(r), rep.sections(r), {})
    english, _spanish = vocabulary()
    assert english_left(es) == [] and foreign(sheet_text_nodes(es), english) == []
    assert "Bench test" not in es and "banda (R 5 %, C 10 %)" in es


def test_tolerance_corners_are_every_sign_combination_of_the_named_parts():
    from designer.plant.bench import tolerance_corners
    values = part_values(SallenKeyParts(10e3, 10e3, 10e-9, 10e-9, 2.0, 10e3, 10e3))
    tol = {"R1": 0.05, "C2": 0.1}
    corners = tolerance_corners(values, tol)
    want = [{**values, "R1": values["R1"] * (1 + a * 0.05), "C2": values["C2"] * (1 + b * 0.1)}
            for a, b in itertools.product((-1, 1), repeat=2)]
    assert corners == want and len(corners) == 4
    assert tolerance_corners(values, {}) == [values]
