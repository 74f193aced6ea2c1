"""Readers: scope CSV captures (real-format fixtures, round trips, bad files) and
frequency-response tables."""

import json
import math
import re

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st
from helpers import FIXTURES

from designer.core.errors import DesignError
from designer.identify import io as tio
from designer.identify.broadband import positional_input
from designer.identify.io import format_generic, parse_capture_text, read_capture
from designer.identify.structures import model_step

FIX = FIXTURES / "identify"
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
    # the reader keeps it, marked; the analysis decides it is no input
    assert cap.input_by_position and cap.input_name == "analytic" and not cap.notes
    cap = positional_input(cap)
    assert cap.u is None and cap.output_name == "spice" and "does not look like" in cap.notes[0]
    tuy = "".join(f"{a},{b},{c}\n" for a, b, c in zip(t, u, y2))
    cap = positional_input(parse_capture_text(tuy))
    assert cap.input_name == "u" and np.array_equal(cap.u, u)


def test_quoted_cells_and_a_units_row():
    t = np.linspace(0, 1e-3, 50)
    y = model_step("fopdt", {"K": 1.0, "tau_s": 2e-4, "theta_s": 0.0}, t)
    quoted = '"Time (s)","Vout (V)"\n' + "".join(f'"{a:.6e}","{b:.6f}"\n' for a, b in zip(t, y))
    cap = parse_capture_text(quoted)
    assert cap.output_name == "Vout (V)" and np.allclose(cap.y, y, atol=1e-6)
    # Keysight: a label row and a units row before the samples
    units = "x-axis,1\nsecond,Volt\n" + "".join(f"{a:.6e},{b:.6f}\n" for a, b in zip(t, y))
    cap = parse_capture_text(units)
    assert cap.fmt == "keysight" and cap.columns == ["TIME", "CH1"]
    assert np.allclose(cap.t, t, rtol=1e-6)


# ------------------------------------------------------- issue 7: files, encodings, columns

def _capture_text(n, *, u=True):
    """A t,u,y capture of a first-order step, n rows, and its arrays."""
    t = np.linspace(-1e-3, 9e-3, n)
    y = model_step("fopdt", {"K": 2.0, "tau_s": 1e-3, "theta_s": 1e-4}, t)
    uu = np.where(t >= 0, 1.0, 0.0)
    return format_generic(t, y, uu if u else None), t, y


def test_utf16_and_binary_files_are_named(tmp_path):
    text, _, _ = _capture_text(50)
    for enc, bom in (("utf-16", True), ("utf-16-le", False), ("utf-16-be", False),
                     ("utf-32", True)):
        p = tmp_path / f"{enc}.csv"
        p.write_text(text, encoding=enc)
        label = "UTF-32" if "32" in enc else "UTF-16"
        with pytest.raises(DesignError, match=f"is {label} text, not UTF-8") as exc:
            read_capture(p)
        assert "\\x00" not in str(exc.value)
    (tmp_path / "bin.csv").write_bytes(bytes(range(256)) * 4)
    with pytest.raises(DesignError, match="not a text file"):
        read_capture(tmp_path / "bin.csv")
    # a UTF-8 BOM and a Latin-1 degree sign in a header cell are fine
    (tmp_path / "bom.csv").write_bytes(b"\xef\xbb\xbft,temp \xb0C\n" + "".join(
        f"{k},{min(k, 5)}\n" for k in range(20)).encode())
    cap = read_capture(tmp_path / "bom.csv")
    assert cap.columns[0] == "t" and cap.t.size == 20


def test_same_column_as_input_and_output_is_refused():
    text = "time_s,vout,vin\n" + "".join(f"{a},{2 * a},{3 * a}\n" for a in range(20))
    for inp, out in (("2", "2"), ("vout", "2"), ("VIN", "vin")):
        with pytest.raises(DesignError, match="both the input and the output"):
            parse_capture_text(text, input_column=inp, output_column=out)
    one = "t,y\n" + "".join(f"{a},{a}\n" for a in range(20))
    with pytest.raises(DesignError, match="cannot be both the input and the output"):
        parse_capture_text(one, input_column="2")


def test_messages_show_plain_numbers():
    text, t, y = _capture_text(30, u=False)
    lines = text.splitlines()
    lines[5], lines[6] = lines[6], lines[5]           # time goes back at line 7
    with pytest.raises(DesignError) as exc:
        parse_capture_text("\n".join(lines), name="cap.csv")
    msg = str(exc.value)
    assert "np." not in msg and "line 7" in msg
    assert f"{float(lines[5].split(',')[0]):.10g} then {float(lines[6].split(',')[0]):.10g}" in msg


@pytest.mark.parametrize("cell, row, column, key", [
    ("1e300", -1, 1, "capture_time_s"), ("-1e300", 1, 1, "capture_time_s"),
    ("1e300", 7, 2, "capture_value"), ("-1e300", -1, 2, "capture_value")])
def test_values_outside_their_physical_range_name_the_line(cell, row, column, key):
    from designer.core.ranges import RANGES
    text, t, y = _capture_text(40, u=False)
    lines = text.splitlines()          # a header, then the samples
    cells = lines[row].split(",")
    cells[column - 1] = cell
    lines[row] = ",".join(cells)
    with pytest.raises(DesignError) as exc:
        parse_capture_text("\n".join(lines), name="cap.csv")
    assert f"line {row % len(lines) + 1}, column {column}" in str(exc.value)
    assert RANGES[key].text() in str(exc.value)


def test_record_too_short_in_time_is_refused():
    from designer.core.ranges import RANGES
    t = np.linspace(0, 1e-300, 20)
    text = "".join(f"{a!r},{min(k, 10)}\n" for k, a in enumerate(t.tolist()))
    with pytest.raises(DesignError, match="duration") as exc:
        parse_capture_text(text)
    assert RANGES["capture_span_s"].text() in str(exc.value)


def test_streamed_file_equals_the_text_and_names_lines_across_blocks(tmp_path):
    """A file longer than one read block (with blank and comment lines in later
    blocks) gives the same samples as the text in memory, and a bad cell deep in
    it is reported at its own line."""
    from designer.core.fileio import BLOCK_BYTES
    text, t, y = _capture_text(20)
    body = text.splitlines()[1:]
    n = 2 * BLOCK_BYTES // len(body[0]) + 1000
    tt = np.linspace(-1e-3, 9e-3, n)
    rows = format_generic(tt, model_step("fopdt", {"K": 2.0, "tau_s": 1e-3, "theta_s": 0.0},
                                         tt), np.where(tt >= 0, 1.0, 0.0)).splitlines()
    rows[n // 2] += "\n\n# a note in the middle\n"
    path = tmp_path / "long.csv"
    path.write_text("\n".join(rows) + "\n")
    cap = read_capture(path)
    mem = parse_capture_text(path.read_text())
    assert cap.t.size == n and np.array_equal(cap.t, mem.t) and np.array_equal(cap.y, mem.y)
    assert np.array_equal(cap.u, mem.u)
    # the same file with a bad cell far into the second block
    k = n - 10
    lines = path.read_text().splitlines()
    line_no = next(i for i, ln in enumerate(lines) if ln == rows[k]) + 1
    lines[line_no - 1] = lines[line_no - 1].rsplit(",", 1)[0] + ",oops"
    path.write_text("\n".join(lines) + "\n")
    with pytest.raises(DesignError, match=f"line {line_no}, column 3: 'oops' is not a number"):
        read_capture(path)


def test_size_limit_refused_from_the_size(tmp_path):
    from designer.core.fileio import MAX_CAPTURE_BYTES, size_text
    big = tmp_path / "big.csv"
    with open(big, "wb") as fh:
        fh.truncate(MAX_CAPTURE_BYTES + 1)    # sparse: refused before a byte is read
    with pytest.raises(DesignError, match=f"at most {size_text(MAX_CAPTURE_BYTES)}"):
        read_capture(big)


def test_directory_and_devices(tmp_path):
    with pytest.raises(DesignError, match="is a directory"):
        read_capture(tmp_path)
    # refused from their stat, before they are opened
    with pytest.raises(DesignError, match="/dev/zero is a character device; a regular file is needed"):
        read_capture("/dev/zero")
    with pytest.raises(DesignError, match="/dev/null is a character device"):
        read_capture("/dev/null")


def test_reading_memory_is_bounded(tmp_path):
    """Peak memory of reading a capture stays within twice the samples kept plus
    a few read blocks (a block is held as bytes, as text and as one string per
    line while it is parsed). Reading the whole text and a Python string per
    line took 5 times the file: 260 MB here, for 24 MB of samples."""
    import subprocess
    import sys

    from designer.core.fileio import BLOCK_BYTES
    n = 1_000_000
    t = np.linspace(0.0, 1.0, n)
    path = tmp_path / "m.csv"
    with open(path, "w") as fh:
        fh.write("time_s,vin,vout\n")
        np.savetxt(fh, np.column_stack([t, t >= 0.1, np.exp(-t)]), delimiter=",", fmt="%.9e")
    # VmHWM, the new image's own peak: ru_maxrss would count the pages of this
    # (large) pytest process at fork time
    code = ("import sys\n"
            "from designer.identify.io import read_capture\n"
            "def hwm():\n"
            "    line = [x for x in open('/proc/self/status') if x.startswith('VmHWM')][0]\n"
            "    return int(line.split()[1]) * 1024\n"
            "r0 = hwm()\n"
            "c = read_capture(sys.argv[1])\n"
            "import resource\n"
            "child = resource.getrusage(resource.RUSAGE_CHILDREN).ru_maxrss * 1024\n"
            "print(c.t.size, hwm() - r0, child - r0)\n")
    out = subprocess.run([sys.executable, "-c", code, str(path)], capture_output=True,
                         text=True, check=True, timeout=300).stdout.split()
    samples_bytes = 3 * 8 * n
    assert int(out[0]) == n
    assert int(out[1]) < 2 * samples_bytes + 8 * BLOCK_BYTES, (int(out[1]) / 2**20,
                                                                path.stat().st_size / 2**20)
    # the helper that parses the second half on the other core (designer.identify.io.split), if
    # one ran, within the same bound: the pages it shares with the reader at its fork, its half
    # of the samples, the blocks it parses
    assert int(out[2]) < 2 * samples_bytes + 8 * BLOCK_BYTES, int(out[2]) / 2**20


# --------------------------------------------------------------------------- frequency tables

def test_header_hints_and_decimal_comma():
    d = tio.parse_freq_table("w_rad_s;gain_ratio;phase_rad\n1;1;0\n2;0,9;-0,1\n3;0,8;-0,2\n"
                            "4;0,7;-0,3\n5;0,6;-0,4\n")
    assert d.units == {"frequency": "rad/s", "gain": "ratio", "phase": "rad"}
    assert d.gain[1] == pytest.approx(0.9) and d.w[0] == 1.0
    # no header: defaults Hz, dB, degrees; whitespace separated; comments ignored
    d = tio.parse_freq_table("# bench\n10 0 0\n20 -1 -10\n40 -3 -45\n80 -7 -60\n160 -12 -75\n")
    assert d.units == {"frequency": "hz", "gain": "db", "phase": "deg"}
    assert d.w[0] == pytest.approx(2 * math.pi * 10)
    # options win over the header
    d = tio.parse_freq_table("f,g\n1,1\n2,0.9\n3,0.8\n4,0.7\n5,0.6\n", gain_units="ratio")
    assert d.gain[0] == 1.0 and d.phase is None


@pytest.mark.parametrize("text, words", [
    ("", "empty"),
    ("# only a comment\n\n", "empty"),
    ("f_hz,gain_db\n", "no data"),
    ("1,0\n2,abc\n3,-1\n4,-2\n5,-3\n", "'abc' is not a number"),
    ("1,0\n2,nan\n3,-1\n4,-2\n5,-3\n", "not a finite number"),
    ("1,0\n3,-1\n2,-2\n4,-3\n5,-4\n", "not increasing"),
    ("1,0\n2,-1\n2,-2\n4,-3\n5,-4\n", "not increasing"),
    ("1,0\n2,-1\n3,-2\n", "too few points"),
    ("1,0,0,0\n2,-1,0,0\n3,-2,0,0\n4,-3,0,0\n5,-4,0,0\n", "expected 2 or 3"),
    ("1,0,0\n2,-1\n3,-2,0\n4,-3,0\n5,-4,0\n", "columns where the table has 3"),
    ("0,0\n2,-1\n3,-2\n4,-3\n5,-4\n", "must be positive"),
    ("f,ratio\n1,1\n2,0\n3,0.5\n4,0.4\n5,0.3\n", "amplitude ratio must be positive"),
])
def test_bad_tables(text, words):
    with pytest.raises(DesignError, match=words):
        tio.parse_freq_table(text, source="t.csv")


def test_missing_table(tmp_path):
    with pytest.raises(DesignError, match="does not exist"):
        tio.read_freq_table(tmp_path / "nope.csv")
    (tmp_path / "bin.csv").write_bytes(b"\xff\xfe\x00\x81")
    with pytest.raises(DesignError):
        tio.read_freq_table(tmp_path / "bin.csv")



@pytest.mark.parametrize("row, key, what", [
    ("1e300,-1,-10", "freq_hz", "frequency"),
    ("30,-1e300,-10", "gain_db", "gain"),
    ("30,-1,-1e300", "phase_deg", "phase (in degrees)"),
    ("1e-300,-1,-10", "freq_hz", "frequency"),
])
def test_values_outside_their_physical_range_are_one_line(row, key, what):
    from designer.core.ranges import RANGES
    rows = ["1,0,0", "2,-0.1,-2", "3,-0.2,-4", row, "40,-3,-40", "50,-6,-50"]
    rows.sort(key=lambda r: float(r.split(",")[0]))
    text = "f_hz,gain_db,phase_deg\n" + "\n".join(rows)
    with pytest.raises(DesignError) as exc:
        tio.parse_freq_table(text, source="t.csv")
    msg = str(exc.value)
    assert "\n" not in msg and RANGES[key].text() in msg and "np." not in msg
    assert f"{what} at line {rows.index(row) + 2} " in msg     # the header is line 1


def test_time_shift_overflowing_the_phase_is_one_line():
    text = "f_khz;gain_ratio;shift_us\n" + "".join(
        f"{f};{g};{s}\n" for f, g, s in ((1, 1, 0), (2, 1, 1), (5, 0.9, 1), (10, 0.7, 1e300),
                                          (20, 0.4, 1)))
    with pytest.raises(DesignError, match=r"phase \(in degrees\) at line 5"):
        tio.parse_freq_table(text, source="t.csv")


def test_table_limits(tmp_path):
    from designer.core.fileio import MAX_TABLE_BYTES, size_text
    big = tmp_path / "big.csv"
    with open(big, "wb") as fh:
        fh.truncate(MAX_TABLE_BYTES + 1)       # sparse: refused from its size, never read
    with pytest.raises(DesignError, match=f"at most {size_text(MAX_TABLE_BYTES)}"):
        tio.read_freq_table(big)
    rows = "".join(f"{k + 1},0\n" for k in range(tio.MAX_POINTS + 1))
    with pytest.raises(DesignError, match=f"at most {tio.MAX_POINTS:,}"):
        tio.parse_freq_table(rows)
    with pytest.raises(DesignError, match="is a directory"):
        tio.read_freq_table(tmp_path)
    (tmp_path / "u16.csv").write_text("f,g\n1,0\n2,-1\n3,-2\n4,-3\n5,-4\n", encoding="utf-16")
    with pytest.raises(DesignError, match="UTF-16 text, not UTF-8"):
        tio.read_freq_table(tmp_path / "u16.csv")


# --------------------------------------------------------------------------- plain columns (issue 28)

from helpers import EXT_CAPTURES  # noqa: E402

from designer.cli.common import flag_message  # noqa: E402

DRYER = EXT_CAPTURES / "daisy_dryer.dat"


def _daisy_text(u, y):
    """Columns as DaISy writes them: right-aligned %.7e, tab separated, a trailing tab, no header."""
    return "".join(f"{a:15.7e}\t{b:15.7e}\t\n" for a, b in zip(u, y))


def _plain_data(n=400, seed=28):
    rng = np.random.default_rng(seed)
    flips = rng.random(n) < 0.2
    u = 3.41 + 3.0 * (np.cumsum(flips) % 2)
    y = np.round(4.0 + 0.1 * np.cumsum(rng.standard_normal(n)), 7)
    return u, y


def test_plain_columns_are_read_with_a_sample_time_by_order_or_by_name():
    u, y = _plain_data()
    text = _daisy_text(u, y)
    cap = parse_capture_text(text, name="dryer.dat", sample_time_s=0.08)
    assert np.array_equal(cap.t, np.arange(u.size) * 0.08)
    assert np.array_equal(cap.u, u) and np.array_equal(cap.y, y)
    assert (cap.input_name, cap.output_name, cap.fmt) == ("u", "y", "generic") and not cap.input_by_position
    assert "no time column" in cap.notes[0]
    swapped = parse_capture_text(text, name="dryer.dat", sample_time_s=0.08, column_names="y,u")
    assert np.array_equal(swapped.u, y) and np.array_equal(swapped.y, u)
    three = "".join(f"{a},{b},{c}\n" for a, b, c in zip(y, u, -y))
    cap3 = parse_capture_text(three, sample_time_s=1e-3, column_names=["y", "u", "other"])
    assert np.array_equal(cap3.u, u) and np.array_equal(cap3.y, y)
    headed = "heater temp\n" + "".join(f"{a} {b}\n" for a, b in zip(u, y))
    caph = parse_capture_text(headed, sample_time_s=0.5)
    assert (caph.input_name, caph.output_name) == ("heater", "temp") and np.array_equal(caph.u, u)


def test_plain_columns_without_a_sample_time_are_refused_naming_the_option():
    u, y = _plain_data()
    with pytest.raises(DesignError) as err:
        parse_capture_text(_daisy_text(u, y), name="dryer.dat")
    msg = str(err.value)
    assert "column 1 is not a time" in msg and "sample_time_s" in msg and "\n" not in msg
    shown = flag_message(err.value)
    assert "--sample-time" in shown and "--columns" in shown and "sample_time_s" not in shown
    # a time column with one glitch is still named as such (its line), not taken for a signal
    glitch = "".join(f"{i * 1e-3 if i != 60 else 0.0},{b}\n" for i, b in enumerate(y))
    with pytest.raises(DesignError, match="time is not increasing at line 61"):
        parse_capture_text(glitch)


@pytest.mark.parametrize("kwargs, text, words", [
    ({"column_names": "u,y"}, None, ("{column_names}", "give {sample_time_s}")),
    ({"sample_time_s": 0.08, "column_names": "u"}, None, ("names 1 column", "has 2", "e.g. u,y")),
    ({"sample_time_s": 0.08, "column_names": "u,U"}, None, ("two columns 'u'",)),
    ({"sample_time_s": 0.08, "column_names": "u,"}, None, ("an empty name",)),
    ({"sample_time_s": 0.0}, None, ("sample_time_s must be 1 ps to 1e+06 s",)),
    ({"sample_time_s": 2e6}, None, ("sample_time_s must be 1 ps to 1e+06 s",)),
    ({"sample_time_s": 0.08}, "t,u,y\n" + "".join(f"{i},{i % 2},{i}\n" for i in range(20)),
     ("first column ('t') is a time column", "drop it")),
    ({"sample_time_s": 0.08}, "Record Length,20,Points,0.0,0.5\n", ("Tektronix",)),
    ({"sample_time_s": 0.08}, "".join(f"{i % 2} {i}\n" for i in range(20)) + "1\n",
     ("line 21 has no value in column 2, nor any line after it", "different lengths")),
    ({"sample_time_s": 0.08}, "".join(f"{i % 2} {i}\n" for i in range(20)) + "1\n1\n1\n",
     ("line 21 has no value in column 2, nor any line after it", "different lengths")),
    ({}, "".join(f"{i},{i % 2},{i}\n" for i in range(20)) + "20,1\n21,1,2\n",
     ("line 21 has no value in column 3; every data row",)),
    ({"sample_time_s": 0.08, "column_names": "u,y"}, "".join(f"2.5 {i}\n" for i in range(20)),
     ("input column 'u' never moves", "every sample 2.5", "{input_column} none")),
])
def test_plain_column_refusals_are_one_line_naming_the_parameter(kwargs, text, words):
    u, y = _plain_data()
    if text is None:
        text = _daisy_text(u, y)
    elif text.startswith("Record Length"):
        text = "".join(f"Record Length,20,,{i * 0.1},{i % 2}\n" if i == 0 else f",,,{i * 0.1},{i % 2}\n"
                       for i in range(20))
    with pytest.raises(DesignError) as err:
        parse_capture_text(text, name="c.dat", **kwargs)
    marked = getattr(err.value, "marked", str(err.value))
    assert "\n" not in marked and all(w in marked for w in words), marked


def test_a_named_input_that_never_moves_is_refused_and_a_positional_one_dropped():
    t = np.arange(50) * 1e-3
    flat = "t,u,y\n" + "".join(f"{a},1.0,{np.tanh(a * 100)}\n" for a in t)
    with pytest.raises(DesignError, match="never moves"):
        parse_capture_text(flat)
    unnamed = "".join(f"{a},1.0,{np.tanh(a * 100)}\n" for a in t).replace("\n", "\n", 1)
    cap = parse_capture_text("t,a,b\n" + unnamed)
    assert cap.input_by_position and positional_input(cap).u is None
    cap = parse_capture_text(flat, input_column="none")
    assert cap.u is None


def test_the_dryer_data_set_reads_as_daisy_describes_it():
    if not DRYER.is_file():
        pytest.skip(f"the DaISy dryer data is not at {DRYER} (../shared/ext-captures beside the repository)")
    with pytest.raises(DesignError, match="column 1 is not a time"):
        read_capture(DRYER)
    cap = read_capture(DRYER, sample_time_s=0.08, column_names="u,y")
    assert cap.t.size == 1000 and cap.t[-1] == pytest.approx(999 * 0.08, rel=1e-12)
    assert sorted(set(np.round(cap.u, 6))) == [3.41, 6.41]   # SOURCES.md: between 3.41 and 6.41 V
    switch = np.mean(np.diff(cap.u) != 0)
    assert 0.15 < switch < 0.25                              # "switches with probability about 0.2"


@settings(max_examples=150, deadline=None)
@given(st.one_of(st.none(), st.text(max_size=20), st.lists(st.text(max_size=5), max_size=4)),
       st.one_of(st.none(), st.floats(allow_nan=True, allow_infinity=True), st.just(0.08)))
def test_plain_column_options_only_ever_refuse_in_one_line(names, dt):
    u, y = _plain_data(60)
    try:
        cap = parse_capture_text(_daisy_text(u, y), name="d.dat", sample_time_s=dt, column_names=names)
    except DesignError as exc:
        assert "\n" not in str(exc)
    else:
        assert cap.t.size == 60 and cap.t[1] == pytest.approx(dt)


@pytest.mark.parametrize("header, shift, words", [
    ("t_u,u,t_y,y", 2.0, "column 3 ('t_y') is a second time column"),
    ("time,u,time,y", 1.0, "from line 2 on"),
    ("time_in,vin,time_out,vout", 1.0, "sampled at different times or rates"),
])
def test_input_and_output_on_different_time_axes_are_refused(header, shift, words):
    t = np.arange(30) * 1e-3
    rows = "".join(f"{a},{i % 2},{a * shift + (0.5e-3 if shift == 1.0 else 0)},{i}\n" for i, a in enumerate(t))
    with pytest.raises(DesignError, match=re.escape(words)):
        parse_capture_text(header + "\n" + rows, name="two.csv")
    same = "".join(f"{a},{i % 2},{a},{i}\n" for i, a in enumerate(t))
    cap = parse_capture_text(header + "\n" + same)
    assert cap.u is not None and np.array_equal(cap.t, t)
    thermo = parse_capture_text("time,t1,t2\n" + "".join(f"{a},{20 + i},{21 + i}\n" for i, a in enumerate(t)))
    assert thermo.output_name == "t2"   # t1, t2: temperatures, not times
