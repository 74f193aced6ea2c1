"""CSV readers: real-format fixtures, round trips and bad files."""

import json
from pathlib import Path

import numpy as np
import pytest

from designer.errors import DesignError
from designer.identify.core import model_step
from designer.identify.csvio import format_generic, parse_capture_text, read_capture

FIX = Path(__file__).parent / "fixtures" / "identify"
TRUTH = json.loads((FIX / "truth.json").read_text())


def _expected(name, t):
    s = TRUTH[name]
    return s["y0"] + s["amplitude"] * model_step(s["model"], s["params"], t - s["step_time_s"])


@pytest.mark.parametrize("name, fmt, out, inp, n", [
    ("generic_ty.csv", "generic", "y", None, 1601),
    ("generic_tuy_semicolon.csv", "generic", "y", "u", 4001),
    ("waveform.csv", "waveform", "vout", "vin", 4001),
    ("tektronix_tds.csv", "tektronix-tds", "CH2", None, 2500),
    ("tektronix_mso.csv", "tektronix-mso", "CH2", "CH1", 5000),
    ("rigol_square.csv", "rigol", "CH2", "CH1", 12000),
])
def test_fixture_layouts(name, fmt, out, inp, n):
    cap = read_capture(FIX / name)
    assert cap.fmt == fmt
    assert cap.output_name == out and cap.input_name == inp
    assert cap.t.size == n == cap.y.size
    assert np.all(np.diff(cap.t) > 0)
    assert (cap.u is None) == (inp is None)


@pytest.mark.parametrize("name", ["generic_ty.csv", "generic_tuy_semicolon.csv", "waveform.csv",
                                  "tektronix_tds.csv", "tektronix_mso.csv"])
def test_fixture_values_match_the_generating_model(name):
    """The parsed output is the generating model's response, within noise and 8-bit steps."""
    cap = read_capture(FIX / name)
    s = TRUTH[name]
    span = abs(s["amplitude"] * s["params"]["K"])
    err = cap.y - _expected(name, cap.t)
    # 5 sigma of the added noise plus one 8-bit step of a 0.5 V/div screen.
    assert np.max(np.abs(err)) <= 5 * s["noise"] * span + 5.0 / 256 + 1e-6 * span


def test_rigol_time_axis_from_start_and_increment():
    cap = read_capture(FIX / "rigol_square.csv")
    second = (FIX / "rigol_square.csv").read_text().splitlines()[1].split(",")
    start, inc = float(second[3]), float(second[4])
    assert cap.t[0] == pytest.approx(start)
    assert np.allclose(np.diff(cap.t), inc, rtol=1e-9)


def test_tektronix_tds_time_axis_and_source():
    cap = read_capture(FIX / "tektronix_tds.csv")
    assert cap.columns == ["TIME", "CH2"]
    assert np.allclose(np.diff(cap.t), 1e-6, rtol=1e-6)


@pytest.mark.parametrize("delim, header, comma", [(",", True, False), (",", False, False),
                                                  (";", True, True), (";", False, True),
                                                  ("\t", True, False), ("\t", False, False)])
def test_generic_round_trip(delim, header, comma):
    t = np.linspace(0, 1e-3, 200)
    u = np.where(t > 2e-4, 1.5, 0.0)
    y = 0.3 + model_step("fopdt", {"K": 2.0, "tau_s": 1e-4, "theta_s": 1e-5}, t - 2e-4)
    text = format_generic(t, y, u, delimiter=delim, header=header, decimal_comma=comma)
    cap = parse_capture_text(text)
    assert np.allclose(cap.t, t, rtol=1e-8, atol=0)
    assert np.allclose(cap.y, y, rtol=1e-8)
    assert np.allclose(cap.u, u)
    two = parse_capture_text(format_generic(t, y, delimiter=delim, header=header,
                                            decimal_comma=comma))
    assert two.u is None and np.allclose(two.y, y, rtol=1e-8)


def test_columns_by_name_and_number():
    t = np.arange(20.0)
    text = "time_s,vout,vin\n" + "".join(f"{a},{2 * a},{3 * a}\n" for a in t)
    cap = parse_capture_text(text)
    assert cap.output_name == "vout" and cap.input_name == "vin"
    assert np.allclose(cap.y, 2 * t) and np.allclose(cap.u, 3 * t)
    cap = parse_capture_text(text, output_column=3, input_column="vout")
    assert np.allclose(cap.y, 3 * t) and np.allclose(cap.u, 2 * t)
    cap = parse_capture_text(text, input_column="none")
    assert cap.u is None
    with pytest.raises(DesignError, match="no output column named 'foo'"):
        parse_capture_text(text, output_column="foo")
    with pytest.raises(DesignError, match="column 7 does not exist"):
        parse_capture_text(text, output_column=7)


def _bad(text, match):
    with pytest.raises(DesignError, match=match):
        parse_capture_text(text, name="cap.csv")


def test_bad_files_name_the_problem():
    good = "".join(f"{i * 1e-3},{i}\n" for i in range(20))
    _bad("", "empty")
    _bad("\n\n  \n", "empty")
    _bad("t,y\n", "header but no data")
    _bad("t,y\n" + good.replace("5,5", "5,abc", 1), r"line 7.*'abc' is not a number")
    _bad(good.replace("0.005,5", "0.005,nan"), r"line 6, column 2 .*NaN")
    _bad(good.replace("0.005,5", "0.005,inf"), r"NaN and infinite")
    _bad(good.replace("0.005,5", "0.003,5"), r"time is not increasing at line 6")
    _bad("0,1\n1,2\n2,3\n", "only 3 samples")
    _bad("1\n2\n3\n4\n", "at least two columns")
    _bad("X,CH1,Start,Increment,\nSequence,Volt,0,0,\n0,1,\n1,2,\n", "increment must be a positive number")


def test_missing_file(tmp_path):
    with pytest.raises(DesignError, match="does not exist"):
        read_capture(tmp_path / "nope.csv")


def test_input_by_position_only_when_it_looks_like_a_step():
    t = np.linspace(-1e-3, 9e-3, 2001)
    y1 = model_step("underdamped", {"K": 1, "wn_rad_s": 6e3, "zeta": 0.3}, t)
    y2 = model_step("fopdt", {"K": 1, "tau_s": 1e-3, "theta_s": 0.0}, t)
    u = np.where(t >= 0, 1.0, 0.0)
    waves = "time_s,analytic,spice\n" + "".join(f"{a},{b},{c}\n" for a, b, c in zip(t, y1, y2))
    cap = parse_capture_text(waves)
    assert cap.u is None and cap.output_name == "spice" and "does not look like" in cap.notes[0]
    tuy = "".join(f"{a},{b},{c}\n" for a, b, c in zip(t, u, y2))
    cap = parse_capture_text(tuy)
    assert cap.input_name == "u" and np.array_equal(cap.u, u)


def test_quoted_cells_and_a_units_row():
    t = np.linspace(0, 1e-3, 50)
    y = model_step("fopdt", {"K": 1.0, "tau_s": 2e-4, "theta_s": 0.0}, t)
    quoted = '"Time (s)","Vout (V)"\n' + "".join(f'"{a:.6e}","{b:.6f}"\n' for a, b in zip(t, y))
    cap = parse_capture_text(quoted)
    assert cap.output_name == "Vout (V)" and np.allclose(cap.y, y, atol=1e-6)
    # Keysight-style: a label row and a units row before the samples
    units = "x-axis,1\nsecond,Volt\n" + "".join(f"{a:.6e},{b:.6f}\n" for a, b in zip(t, y))
    cap = parse_capture_text(units)
    assert cap.columns == ["second", "Volt"] and np.allclose(cap.t, t, rtol=1e-6)
