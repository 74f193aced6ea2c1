"""The first-order sections: RC and CR with a follower, and the inverting low-pass."""

import math

import pytest

from designer.core.errors import DesignError
from designer.filters import SectionTarget, get


@pytest.mark.parametrize("name, kind", [("rc-lowpass", "lowpass"), ("rc-highpass", "highpass")])
def test_followers_put_r_at_the_impedance_and_refuse_a_gain(name, kind):
    values = get(name).synthesize(SectionTarget(kind, 1e3, impedance_ohm=4.7e3))
    assert values["R1"] == pytest.approx(4.7e3)
    assert values["R1"] * values["C1"] == pytest.approx(1 / (2 * math.pi * 1e3))
    with pytest.raises(DesignError, match=f"^gain: {name} is a follower .* add the gain in another stage$"):
        get(name).synthesize(SectionTarget(kind, 1e3, gain=2.0))


def test_inverting_lowpass_gain_and_corner():
    values = get("inverting-lowpass").synthesize(SectionTarget("lowpass", 500.0, gain=3.0, c_f=100e-9))
    assert values["C1"] == 100e-9
    assert values["R2"] / values["R1"] == pytest.approx(3.0)
    assert values["R2"] * values["C1"] == pytest.approx(1 / (2 * math.pi * 500.0))
    assert get("inverting-lowpass").response(values, 0.0).real == pytest.approx(-3.0)


def test_inverting_highpass_gain_and_corner():
    """H(s) = -(R2/R1) R1 C1 s / (R1 C1 s + 1): the corner 1/(2 pi R1 C1), the passband gain -R2/R1 (s -> inf)."""
    topology = get("inverting-highpass")
    values = topology.synthesize(SectionTarget("highpass", 500.0, gain=3.0, c_f=100e-9))
    assert values["C1"] == 100e-9
    assert values["R2"] / values["R1"] == pytest.approx(3.0)
    assert values["R1"] * values["C1"] == pytest.approx(1 / (2 * math.pi * 500.0))
    assert topology.response(values, 0.0).real == 0.0
    wc = 2 * math.pi * 500.0
    assert abs(topology.response(values, 1j * wc)) == pytest.approx(3.0 / math.sqrt(2))
    assert topology.response(values, 1e12).real == pytest.approx(-3.0, rel=1e-6)


@pytest.mark.spice
def test_a_first_order_highpass_stage_with_gain_is_the_inverting_section(tmp_path):
    """A 1st-order high-pass with gain 3 was refused (the follower's CR has unity gain); it is the inverting
    section now, its gain and -3 dB point the target's within the E-series error the design reports."""
    import json
    import subprocess
    import sys
    out = subprocess.run([sys.executable, "-m", "designer.cli.filter", "--type", "highpass", "--order", "1",
                          "--fc", "1k", "--gain", "3", "--opamp", "TL072", "--json", "--out", str(tmp_path)],
                         capture_output=True, text=True)
    assert out.returncode == 0, out.stderr
    d = json.loads(out.stdout)
    assert [s["topology"] for s in d["stages"]] == ["inverting-highpass"]
    values = d["stages"][0]["parts"]
    assert values["R2"] / values["R1"] == pytest.approx(3.0, rel=0.1)
    assert 1 / (2 * math.pi * values["R1"] * values["C1"]) == pytest.approx(1e3, rel=0.1)
    assert d["spice"]["passed"] and d["spice"]["max_deviation_passband_db"] < 0.1
