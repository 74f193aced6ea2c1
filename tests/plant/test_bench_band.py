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
