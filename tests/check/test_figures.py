"""check.figures: a plant's unprefixed fn_hz, zeta and q are the corner's own,
with its op-amp; ideal_fn_hz, ideal_zeta and ideal_q the parts alone, the same
in every corner; fn_opamp_hz and zeta_opamp still read as the corner's; the
tolerance band of fn_hz and zeta follows the corner (no SPICE here)."""

import math
import re

import pytest
from helpers import ROOT

from designer.check import figures as F
from designer.check.spec import load_spec
from designer.plant.design import analyze_plant
from designer.plant.sallenkey import SallenKeyParts
from designer.plant.spec import AnalysisSpec

#: a 22.9 kHz plant: the 700 kHz LM358 pulls its fn about 5 % down, the ideal op-amp not at all
PARTS = SallenKeyParts(1e3, 1e3, 2.2e-9, 22e-9)


def _corner(opamp, **kw):
    return analyze_plant(AnalysisSpec(parts=PARTS, opamp=opamp, **kw), simulate=False)


@pytest.fixture(scope="module")
def corners():
    return {amp: _corner(amp, target_fc_hz=23e3, target_zeta=0.3) for amp in ("ideal", "LM358", "TL072")}


def test_unprefixed_figures_are_the_corners_own(corners):
    figs = {amp: F.plant_figures(res) for amp, res in corners.items()}
    ideal_fn = 1 / (2 * math.pi * math.sqrt(1e3 * 1e3 * 2.2e-9 * 22e-9))
    for amp, f in figs.items():
        o = corners[amp].analytic_opamp.figures
        assert f["fn_hz"] == o.fn_hz and f["zeta"] == o.zeta and f["q"] == pytest.approx(1 / (2 * o.zeta))
        assert f["ideal_fn_hz"] == pytest.approx(ideal_fn) and f["ideal_zeta"] == pytest.approx(PARTS.zeta)
        assert f["ideal_q"] == pytest.approx(PARTS.q)
        assert f["fn_opamp_hz"] == f["fn_hz"] and f["zeta_opamp"] == f["zeta"]     # the earlier names
        # the error against the target is that of the corner's fn and zeta
        assert f["fn_error_pct"] == pytest.approx(100 * (f["fn_hz"] / 23e3 - 1))
        assert f["zeta_error_pct"] == pytest.approx(100 * (f["zeta"] / 0.3 - 1))
        assert all(type(f[k]) is float for k in ("fn_hz", "zeta", "q", "fn_error_pct", "zeta_error_pct"))
    assert figs["LM358"]["fn_hz"] < 0.97 * figs["LM358"]["ideal_fn_hz"]
    assert figs["LM358"]["fn_hz"] < figs["TL072"]["fn_hz"] < figs["ideal"]["fn_hz"]
    assert figs["ideal"]["fn_hz"] == pytest.approx(ideal_fn, rel=1e-6)


def test_every_plant_figure_is_listed_and_given(corners):
    assert set(F.plant_figures(corners["LM358"])) == set(F.PLANT)
    assert set(F.ALIASES) <= set(F.PLANT) and set(F.ALIASES.values()) <= set(F.PLANT)
    assert "corner's" in F.PLANT["fn_error_pct"][1] and "ideal op-amp" in F.PLANT["ideal_fn_hz"][1]


def test_the_band_of_fn_and_zeta_follows_the_corner(corners):
    bands = {amp: F.band_of(res) for amp, res in corners.items()}
    passive = corners["LM358"].tolerance
    for amp, band in bands.items():
        assert set(band) == set(F.BAND)
        assert band["ideal_fn_hz"] == (passive.fn_hz.lo, passive.fn_hz.hi)
        assert band["ideal_zeta"] == (passive.zeta.lo, passive.zeta.hi)
        assert band["fn_opamp_hz"] == band["fn_hz"] and band["zeta_opamp"] == band["zeta"]
        fn = F.plant_figures(corners[amp])["fn_hz"]
        assert band["fn_hz"][0] < fn < band["fn_hz"][1]
    # the ideal op-amp's band is the passive one; the slow op-amp's moves down with its fn
    assert bands["ideal"]["fn_hz"] == pytest.approx(bands["ideal"]["ideal_fn_hz"], rel=1e-6)
    assert bands["ideal"]["zeta"] == pytest.approx(bands["ideal"]["ideal_zeta"], rel=1e-5)
    ratio = F.plant_figures(corners["LM358"])["fn_hz"] / F.plant_figures(corners["LM358"])["ideal_fn_hz"]
    lo, hi = bands["LM358"]["fn_hz"]
    assert lo == pytest.approx(ratio * passive.fn_hz.lo, rel=0.01) and lo < 0.97 * passive.fn_hz.lo
    assert hi == pytest.approx(ratio * passive.fn_hz.hi, rel=0.01) and hi < 0.97 * passive.fn_hz.hi


def test_specs_read_the_new_names_and_the_earlier_ones(tmp_path):
    path = tmp_path / "s.yaml"
    path.write_text("kind: plant\nparts: {R1: 1k, R2: 1k, C1: 2n2, C2: 22n}\nopamp: [LM358, TL072]\nchecks:\n"
                    "  fn_hz: {min: 20k, max: 26k}\n  ideal_fn_hz: {min: 19k, max: 27k}\n"
                    "  zeta_opamp: {min: 0.2}\n  ideal_q: {max: 2}\ntolerance: [fn_hz, ideal_fn_hz, zeta_opamp]\n")
    spec = load_spec(path)
    assert [c.figure for c in spec.checks] == ["fn_hz", "ideal_fn_hz", "zeta_opamp", "ideal_q"]
    assert spec.tolerance == ("fn_hz", "ideal_fn_hz", "zeta_opamp")
    assert next(c for c in spec.checks if c.figure == "ideal_fn_hz").unit == "Hz"


def test_the_readme_example_checks_each_figure_once_per_corner():
    readme = (ROOT / "README.md").read_text()
    example = re.search(r"```yaml\n# specs/lab3-plant.yaml\n(.*?)```", readme, re.S).group(1)
    figures = re.findall(r"^  (\w+): \{", example.split("checks:", 1)[1].split("design_checks:")[0], re.M)
    # no figure and its alias, nor a figure that is the same number in every corner
    named = [F.ALIASES.get(f, f) for f in figures]
    assert len(named) == len(set(named)) and not any(f.startswith("ideal_") for f in figures)


def test_the_band_is_the_op_amp_model_s_pair_over_the_network_s_corners(corners):
    """Brute force: the op-amp model's dominant pair (seed 001's D(s), core.lti.dominant_pair) at each of
    the 16 corners of R1 R2 C1 C2, as band_of's generic corner_band on the section gives it, to the bit
    (the ideal op-amp's too: the plant's own figures take its model with its finite A0 and GBW)."""
    import itertools

    from designer.core.lti import dominant_pair
    from designer.filters.sallen_key_lowpass_synthesis import opamp_denominator
    for amp, res in corners.items():
        t, p, a = res.tolerance, res.built, res.opamp
        rt, ct = t.r_tolerance_pct / 100, t.c_tolerance_pct / 100
        pairs = []
        for s in itertools.product((-1, 1), repeat=4):
            d = opamp_denominator(p.r1 * (1 + s[0] * rt), p.r2 * (1 + s[1] * rt), p.c1 * (1 + s[2] * ct),
                                  p.c2 * (1 + s[3] * ct), p.gain, a.a0, a.gbw_hz)
            pairs.append(dominant_pair(d / d[-1]))
        fns, zetas = zip(*pairs)
        band = F.band_of(res)
        assert band["fn_hz"] == (min(fns), max(fns)) and band["zeta"] == (min(zetas), max(zetas)), amp
