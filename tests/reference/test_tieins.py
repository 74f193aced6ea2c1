"""The capabilities together: design-plant writes the bench waveform that
identify reads, and identify compares what it finds with the design."""

import json
import math
import subprocess

from helpers import ROOT, script

REF = ROOT / "reports" / "plant_fc3500_z0.2"


def test_identify_recovers_the_reference_design_from_its_spice_waveform():
    out = subprocess.run([script("identify"), str(REF / "waveforms.csv"), "--against", str(REF / "result.json"),
                          "--json"], capture_output=True, text=True, timeout=300)
    assert out.returncode == 0, out.stderr
    found = json.loads(out.stdout)
    design = json.loads((REF / "result.json").read_text())
    best = found["best"]
    assert best["model"] == "underdamped"
    fn = best["params"]["wn_rad_s"] / (2 * math.pi)
    # the SPICE circuit has the LM741's finite GBW: identify must find the op-amp-aware figures
    assert abs(fn / design["built"]["fn_opamp_hz"] - 1) < 0.005
    assert abs(best["params"]["zeta"] / design["built"]["zeta_opamp"] - 1) < 0.005
    assert "tolerances explain" in json.dumps(found["comparison"])


def test_waveform_csv_columns_agree_with_the_result():
    import numpy as np
    data = np.genfromtxt(REF / "waveforms.csv", delimiter=",", names=True)
    assert set(data.dtype.names) == {"time_s", "input_v", "output_v", "analytic_v", "analytic_opamp_v"}
    design = json.loads((REF / "result.json").read_text())
    peak = design["spice"]["peak_value"] * design["test_signal"]["high_v"]
    assert abs(data["output_v"].max() - peak) < 0.01 * peak
