"""design-filter: the summary with units, JSON, the deck and result.json
written, and bad input as one line with exit status 2."""

import json
import subprocess
from pathlib import Path

import pytest
from helpers import script

from designer.cli.filter import design_filter_main


@pytest.mark.parametrize("argv, words", [
    (["--order", "11", "--fc", "1k"], "--order must be 1 to 10"),
    (["--order", "2.5", "--fc", "1k"], "--order must be a whole number"),
    (["--order", "4", "--fc", "1k", "--family", "elliptic"], "allowed: butterworth, bessel, chebyshev"),
    (["--order", "4", "--fc", "1k", "--topology", "tow-thomas"], "allowed: sallen-key, mfb, auto"),
    (["--order", "4", "--fc", "1k", "--type", "notch"], "allowed: lowpass, highpass, bandpass"),
    (["--order", "4", "--fc", "1k", "--family", "chebyshev", "--ripple", "5"], "--ripple must be 0.01 dB to 3 dB"),
    (["--order", "4", "--fc", "1k", "--ripple", "1"], "only a chebyshev filter has a ripple"),
    (["--order", "4"], "give --order and --fc"),
    (["--passband", "3k", "--max-loss", "1", "--stopband", "2k", "--min-attenuation", "40"],
     "must be below its stopband edge"),
    (["--passband", "3k", "--max-loss", "1", "--stopband", "3.3k", "--min-attenuation", "80"],
     "order 104, above the limit 10"),
    (["--passband", "3k", "--max-loss", "1"], "a mask needs all of"),
    (["--order", "10", "--fc", "1k", "--family", "chebyshev", "--ripple", "3"], "too slow for stage 5"),
    (["--order", "4", "--fc", "1M", "--opamp", "ideal"], "not realisable within the part bounds"),
    (["--order", "4", "--fc", "1k", "--opamp", "uA709"], "uA709"),
    (["--order", "4", "--fc", "abc"], "--fc"),
    (["--order", "4", "--fc", "1k", "--bogus"], "unrecognized arguments"),
    (["--type", "bandpass", "--order", "2", "--f-low", "1.1k", "--f-high", "900"],
     "the band's edges cross: --f-low (1100 Hz) is not below --f-high (900 Hz)"),
    (["--type", "bandpass", "--order", "2", "--fc", "1k"], "a bandpass takes its edges"),
    (["--order", "2", "--fc", "1k", "--f-low", "900"], "band edges are for a bandpass"),
])
def test_bad_input_is_one_line_exit_2(argv, words, capsys):
    assert design_filter_main(argv + ["--no-sim"]) == 2
    err = capsys.readouterr().err
    assert err.count("\n") == 1 and err.startswith("design-filter: error: ")
    assert words in err, err


def test_summary_in_engineering_notation(capsys):
    assert design_filter_main(["--order", "4", "--fc", "1k", "--no-sim"]) == 0
    out = capsys.readouterr().out
    for words in ("4th-order Butterworth low-pass, fc 1 kHz (-3 dB)", "sallen-key-lowpass", "Q 0.5412",
                  "Q 1.307", "kOhm", "nF", "max passband deviation", "-3 dB frequency", "joint across the stages",
                  "per-stage rounding", "peak gain"):
        assert words in out, words


def test_help_teaches_each_input():
    out = subprocess.run([script("design-filter"), "--help"], capture_output=True, text=True, timeout=60)
    assert out.returncode == 0
    for words in ("--order", "1 to 10", "--ripple", "0.01 dB to 3 dB", "--passband", "--min-attenuation",
                  "--topology", "sallen-key, mfb", "--gain", "--opamp", "--amplitude", "--series", "--json", "--out"):
        assert words in out.stdout, words


@pytest.mark.spice
def test_json_deck_and_result_written(tmp_path):
    out = subprocess.run([script("design-filter"), "--type", "highpass", "--family", "chebyshev", "--ripple", "0.5",
                          "--order", "5", "--fc", "1k", "--json", "--out", str(tmp_path / "hp")],
                         capture_output=True, text=True, timeout=300)
    assert out.returncode == 0, out.stderr
    d = json.loads(out.stdout)
    assert d["spec"]["order"] == 5 and len(d["stages"]) == 3
    assert d["spice"]["max_deviation_passband_db"] < 0.05
    assert d["figures"]["error_joint_db"] <= d["figures"]["error_per_stage_db"] + 1e-12
    deck = Path(d["files"]["deck"]).read_text()
    assert "\nac dec" in deck and deck.rstrip().endswith(".end")
    assert json.loads(Path(d["files"]["result_json"]).read_text()) == d
    # the deck stands alone: ngspice -b runs it
    run = subprocess.run(["ngspice", "-b", d["files"]["deck"]], capture_output=True, text=True, timeout=120)
    assert run.returncode == 0, run.stderr
    meas = {k.strip(): float(v.split()[0]) for k, v in (line.split("=", 1) for line in run.stdout.splitlines()
                                                        if line.startswith(("f3db_hz", "passband_db")))}
    f3 = meas["f3db_hz"]
    assert f3 == pytest.approx(d["figures"]["f3_hz"], rel=0.01)
