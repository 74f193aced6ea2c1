"""check.golden: a golden file that cannot be compared (no samples, one row, a
sample that is no finite number, a time span the run does not share) is
refused in one line naming the file, never a numpy warning or a comparison of
nothing; and through check-design that is exit 2."""

import subprocess

import numpy as np
import pytest
from helpers import script

from designer.check.golden import compare, read_golden, write_golden
from designer.core.errors import DesignError

TOL = {"out": (0.01, 1e-3)}


def golden_file(tmp_path, text, name="g.csv"):
    path = tmp_path / name
    path.write_text(text)
    return path


def refused(fn, *args, **kw) -> str:
    with pytest.raises(DesignError) as info:
        fn(*args, **kw)
    msg = str(info.value)
    assert "\n" not in msg and "np.float64" not in msg and "array(" not in msg
    return msg


def test_a_recorded_file_reads_back_and_compares_to_zero(tmp_path):
    t = np.linspace(0, 1e-3, 11)
    path = tmp_path / "g.csv"
    write_golden(path, t, {"out": 1 - np.exp(-t / 2e-4)}, {"tool": "designer 0", "spec": "s", "corner": "-"})
    header, t_gold, gold = read_golden(path)
    assert header["spec"] == "s" and np.allclose(t_gold, t) and set(gold) == {"out"}
    assert compare(t, {"out": 1 - np.exp(-t / 2e-4)}, t_gold, gold, TOL, path=path)["out"] < 1e-6
    # a run with a sample that is no number is not recorded: the file could never compare
    bad = tmp_path / "bad.csv"
    msg = refused(write_golden, bad, t, {"out": np.where(t > 5e-4, np.nan, 1.0)}, {})
    assert msg.startswith(f"golden file {bad}: the run's out is nan at 600 us") and not bad.exists()


@pytest.mark.parametrize("text, words", [
    ("", "is not a golden waveform"),
    ("# designer golden waveform\n", "is not a golden waveform"),
    ("time_s,out\n", "0 rows of samples; a golden waveform has at least 2"),
    ("# tool: designer\ntime_s,out\n0,1\n", "1 row of samples; a golden waveform has at least 2"),
    ("time_s,out\n0,1\n1,2,3\n", "unreadable samples"),
    ("time_s,out\n0,1\n1,abc\n", "unreadable samples"),
    ("time_s,out\n0,1\n1e-3,1\n1e-3,1\n", "time_s must increase"),
    ("time_s,out,in\n0,1\n1e-3,1\n", "2 columns of samples under the 3 names of its header line"),
])
def test_a_file_without_two_samples_is_refused(tmp_path, text, words):
    path = golden_file(tmp_path, text)
    msg = refused(read_golden, path)
    assert f"golden file {path}" in msg and words in msg, msg


@pytest.mark.parametrize("rows, line, column, value, row", [
    ("0,1\n1e-3,nan\n2e-3,1\n", 4, "out", "nan", 2),
    ("0,1\n1e-3,1\n2e-3,inf\n", 5, "out", "inf", 3),
    ("0,1\n1e-3,-Infinity\n", 4, "out", "-inf", 2),
    ("nan,1\n1e-3,1\n", 3, "time_s", "nan", 1),
    ("0,1\n1e999,1\n", 4, "time_s", "inf", 2),
])
def test_a_sample_that_is_no_finite_number_is_refused_naming_column_and_row(tmp_path, rows, line, column, value,
                                                                            row):
    path = golden_file(tmp_path, "# spec: s\ntime_s,out\n" + rows)
    msg = refused(read_golden, path)
    assert msg.startswith(f"golden file {path}:{line}: {column} is {value} in sample row {row}; "), msg
    assert "finite numbers only" in msg


def test_a_run_that_does_not_overlap_the_golden_span_is_refused_naming_both_spans(tmp_path):
    path = tmp_path / "g.csv"
    t_gold, gold = np.linspace(0, 5e-4, 6), {"out": np.ones(6)}
    late = np.linspace(1e-3, 2e-3, 5)
    msg = refused(compare, late, {"out": np.ones(5)}, t_gold, gold, TOL, path=path)
    assert msg == (f"golden file {path} covers 0 s to 500 us; the run covers 1 ms to 2 ms: fewer than 2 of the run's "
                   "time points lie in the golden span, nothing to compare (record it with check-design "
                   "--update-golden)")
    # one shared point is no waveform either; two are
    touch = np.array([5e-4, 1e-3, 2e-3])
    assert "fewer than 2" in refused(compare, touch, {"out": np.ones(3)}, t_gold, gold, TOL, path=path)
    two = np.array([4e-4, 5e-4, 1e-3])
    assert compare(two, {"out": np.ones(3)}, t_gold, gold, TOL, path=path) == {"out": 0.0}


@pytest.mark.parametrize("where", ["signal", "time", "gold"])
def test_a_run_or_gold_that_is_no_finite_number_is_refused(tmp_path, where):
    path = tmp_path / "g.csv"
    t, y, g = np.linspace(0, 1e-3, 5), np.ones(5), np.ones(5)
    if where == "signal":
        y[2] = np.nan
    elif where == "time":
        t[3] = np.inf
    else:
        g[1] = -np.inf
    msg = refused(compare, t, {"out": y}, np.linspace(0, 1e-3, 5), {"out": g}, TOL, path=path)
    assert msg.startswith(f"golden file {path}: ") and "only finite samples can be compared" in msg
    assert {"signal": "the run's out is nan at 500 us", "time": "the run's time is inf at sample 4",
            "gold": "its out is -inf at 250 us"}[where] in msg, msg


RC = "rc\nV1 in 0 PULSE(0 1 1u 1n 1n 1 2)\nR1 in out 1k\nC1 out 0 1n\n.tran 10n 20u\n.meas tran vmax MAX v(out)\n.end\n"


@pytest.mark.spice
def test_check_design_refuses_a_golden_file_of_another_time_span_in_one_line(tmp_path):
    (tmp_path / "rc.cir").write_text(RC)
    (tmp_path / "g.csv").write_text("time_s,out\n1,0\n1.5,0.5\n2,1\n")   # the run covers 0 to 20 us
    spec = tmp_path / "rc.yaml"
    spec.write_text("kind: netlist\ndeck: rc.cir\ngolden: {file: g.csv, signals: [out]}\n")
    out = subprocess.run([script("check-design"), str(spec), "--simulator", "ngspice-cli"], capture_output=True,
                         text=True, timeout=120)
    assert out.returncode == 2, out.stderr
    lines = out.stderr.splitlines()
    assert len(lines) == 1 and "Warning" not in out.stderr and "Traceback" not in out.stderr
    assert f"golden file {tmp_path / 'g.csv'} covers 1 s to 2 s; the run covers 0 s to 20 us" in lines[0], lines[0]


@pytest.mark.parametrize("aside", [False, True])
def test_the_record_advice_carries_its_parameter_and_reads_as_the_command_line(aside):
    """Issue 29: the advice is a typed message whose update_golden value a front end names its own way; its
    text is check-design's words, as before (the CLI, its JUnit file and result.json unchanged)."""
    from designer.check.golden import RECORD_GOLDEN, record_advice
    from designer.core.errors import DesignError
    from designer.cli.common import flag_message
    advice = record_advice("golden file g.csv: 1 row of samples", aside=aside)
    assert advice.values["update_golden"] == RECORD_GOLDEN == "check-design --update-golden"
    want = "golden file g.csv: 1 row of samples" + (" (record it with check-design --update-golden)" if aside
                                                    else "; record it with check-design --update-golden")
    assert str(advice) == want and flag_message(DesignError(advice)) == want
