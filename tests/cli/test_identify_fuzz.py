"""CLI fuzzing of ``identify`` and ``identify-freq`` (issue 7: make the classes impossible).

Hypothesis drives both commands in-process with generated argument values
(numbers across 600 orders of magnitude, odd strings, odd paths) and generated
small files (numbers up to 1e+-300, NaN text, empty, BOM, UTF-16, binary bytes,
ragged rows, plausible step responses and Bode tables at every scale), and
asserts the one-line contract:

- exit status 0 or 2, nothing else, and no exception escapes;
- on 2: exactly one line on stderr, starting ``<prog>: error:``, no traceback,
  nothing on stdout, no numpy repr;
- no warning is issued (recorded as production sees them: a warning the suite
  turned into an exception could be swallowed by a method's own error handling);
- nothing on the file descriptors but our own output (LAPACK's ``DLASCL`` lines
  are written straight to fd 1, hence ``capfd``);
- a refused run leaves no file behind (the ``--plot`` target is not created).

A few subprocess checks of the installed console scripts cover what only a real
process shows: ``/dev/zero``, a directory, a FIFO, a huge number.
"""

from __future__ import annotations

import json
import math
import os
import subprocess
import tempfile
import warnings
from pathlib import Path

import numpy as np
import pytest
from helpers import script
from hypothesis import HealthCheck, assume, event, example, given, settings
from hypothesis import strategies as st

from designer.cli.identify import identify_freq_main, identify_main
from designer.identify.bode_readings import model_phase, model_response
from designer.identify.structures import model_step

#: examples per property; IDENTIFY_FUZZ_EXAMPLES=2000 for a deep local run
EXAMPLES = int(os.environ.get("IDENTIFY_FUZZ_EXAMPLES", "30"))
FUZZ = settings(max_examples=EXAMPLES, deadline=None,
                suppress_health_check=[HealthCheck.function_scoped_fixture,
                                       HealthCheck.too_slow])
#: for the properties that identify a full record every time (~0.2 s each)
FUZZ_SLOW = settings(FUZZ, max_examples=max(EXAMPLES // 3, 5))

# ----------------------------------------------------------------------- strategies

#: m * 10^e over 600 orders of magnitude, as the text a user types
numbers = st.builds(lambda m, e: f"{m:.6g}e{e}", st.floats(-9.99, 9.99, allow_nan=False),
                    st.integers(-300, 300))
#: what argv can carry: no NUL, no lone surrogates
odd_text = st.text(st.characters(blacklist_categories=("Cs",), blacklist_characters="\x00"),
                   max_size=12)
number_args = st.one_of(numbers, odd_text,
                        st.sampled_from(["nan", "inf", "-inf", "0", "-0", "1e999", "1e-320",
                                         "4k7", "10f", "1meg", "", " ", "0x10", "--", "1_0"]))
cells = st.one_of(
    st.floats(allow_nan=False, allow_infinity=False).map(repr),
    numbers,
    st.sampled_from(["nan", "NaN", "inf", "", "abc", "1,5", '"1"', "1e999", "-0", "#", "\t"]),
)


@st.composite
def ragged_csv(draw) -> bytes:
    """Random small tables: any cells, any row lengths, any delimiter, odd encodings."""
    delim = draw(st.sampled_from([",", ";", "\t", " "]))
    rows = draw(st.lists(st.lists(cells, min_size=0, max_size=4), min_size=0, max_size=30))
    text = "\n".join(delim.join(r) for r in rows)
    if draw(st.booleans()):
        text = "t" + delim + "y\n" + text
    return _encode(draw, text)


@st.composite
def step_csv(draw) -> bytes:
    """A plausible step response (FOPDT or second order, with or without input
    column and noise) scaled in time and value by 10^-300 .. 10^300."""
    model = draw(st.sampled_from(["fopdt", "underdamped", "overdamped"]))
    params = {"fopdt": {"K": 1.5, "tau_s": 0.05, "theta_s": 0.02},
              "underdamped": {"K": -1.0, "wn_rad_s": 60.0, "zeta": 0.2, "theta_s": 0.0},
              "overdamped": {"K": 2.0, "tau1_s": 0.01, "tau2_s": 0.08, "theta_s": 0.01}}[model]
    n = draw(st.integers(5, 300))
    # mostly inside the physical ranges (the numeric pipeline must then work),
    # else anywhere in 1e-300..1e300 (one line must say which value is out)
    ts = 10.0 ** draw(st.integers(-11, 9) | st.integers(-11, 9) | st.integers(-300, 300))
    ys = 10.0 ** draw(st.integers(-14, 14) | st.integers(-14, 14) | st.integers(-300, 300))
    offset = draw(st.sampled_from([0.0, 0.0, 1.0, 1e9, -1e300]))
    t = np.linspace(-0.1, 1.0, n)
    y = model_step(model, params, t)
    if draw(st.booleans()):
        y = y + 0.01 * np.random.default_rng(n).standard_normal(n)
    u = np.where(t >= 0, 1.0, 0.0)
    cols = [t * ts + offset * ts] + ([u * ys] if draw(st.booleans()) else []) + [y * ys]
    text = "\n".join(",".join(repr(float(v)) for v in row) for row in zip(*cols)) + "\n"
    return _encode(draw, text)


@st.composite
def bode_csv(draw) -> bytes:
    """A plausible Bode table (or a wrong reading of one) at any frequency and gain scale."""
    model = draw(st.sampled_from(["fopdt", "underdamped", "overdamped"]))
    params = {"fopdt": {"K": 2.0, "tau_s": 1e-3, "theta_s": 1e-4},
              "underdamped": {"K": 1.0, "wn_rad_s": 6e3, "zeta": 0.3, "theta_s": 0.0},
              "overdamped": {"K": 0.5, "tau1_s": 1e-4, "tau2_s": 1e-3, "theta_s": 0.0}}[model]
    n = draw(st.integers(5, 40) | st.integers(0, 4))
    fs = 10.0 ** draw(st.integers(-8, 4) | st.integers(-8, 4) | st.integers(-300, 300))
    w = np.geomspace(10, 1e6, max(n, 1))[:n]
    g = np.abs(model_response(model, params, w)) * 10.0 ** draw(st.integers(-10, 10)
                                                                 | st.integers(-30, 30))
    ph = np.degrees(model_phase(model, params, w)) * draw(st.sampled_from([1, 1, 1, -1, 1e300]))
    gain = draw(st.sampled_from(["db", "ratio"]))
    gcol = 20 * np.log10(g) if gain == "db" else g
    header = draw(st.sampled_from(["", f"f_hz,gain_{gain},phase_deg\n", "f,g,p\n"]))
    with np.errstate(over="ignore"):   # an out-of-range row is part of the fuzz
        rows = zip((w / (2 * math.pi) * fs).tolist(), gcol.tolist(), ph.tolist())
    text = header + "".join(f"{a!r},{b!r},{c!r}\n" for a, b, c in rows)
    return _encode(draw, text)


def _encode(draw, text: str) -> bytes:
    how = draw(st.sampled_from(["utf-8"] * 6 + ["bom", "utf-16", "binary", "crlf"]))
    if how == "bom":
        return b"\xef\xbb\xbf" + text.encode()
    if how == "utf-16":
        return text.encode("utf-16")
    if how == "binary":
        return bytes(draw(st.binary(min_size=1, max_size=64))) + text.encode()
    if how == "crlf":
        return text.replace("\n", "\r\n").encode()
    return text.encode()


# ----------------------------------------------------------------------- harness

def _files(root: Path) -> set:
    return {p.relative_to(root) for p in root.rglob("*")}


def run_in_process(main, prog, argv, capfd, root: Path, stats: bool = True):
    """Run a command's main in-process; check the one-line contract; return (status, out)."""
    capfd.readouterr()
    before = _files(root)
    with warnings.catch_warnings(record=True) as caught:
        warnings.simplefilter("always")
        try:
            status = main([str(a) for a in argv])
        except SystemExit as exc:          # --help and argparse's own exits
            status = exc.code
    out, err = capfd.readouterr()
    if stats:
        event(f"{prog} exit {status}")   # --hypothesis-show-statistics: how many got through
    assert not caught, [f"{w.category.__name__}: {w.message}" for w in caught]
    assert status in (0, 2), (status, err)
    assert "Traceback" not in err and "DLASCL" not in out + err
    assert "np.float" not in out + err and "np.int" not in out + err
    if status == 2:
        lines = err.splitlines()
        assert len(lines) == 1 and lines[0].startswith(f"{prog}: error: "), err
        assert out == ""
        assert _files(root) == before, "a refused run left a file behind"
    else:
        assert err == "", err
    return status, out


# ----------------------------------------------------------------------- identify

@FUZZ
@given(content=st.one_of(step_csv(), step_csv(), ragged_csv()), plot=st.booleans(),
       as_json=st.booleans())
def test_identify_any_file(capfd, content, plot, as_json):
    with tempfile.TemporaryDirectory() as tmp:
        root = Path(tmp)
        cap = root / "capture.csv"
        cap.write_bytes(content)
        # a plot target in a folder that does not exist yet: a refusal must not create it
        argv = [cap] + (["--plot", root / "out" / "fit.png"] if plot else [])
        argv += ["--json"] if as_json else []
        status, _ = run_in_process(identify_main, "identify", argv, capfd, root)
        if status == 0 and plot:
            assert (root / "out" / "fit.png").read_bytes()[:4] == b"\x89PNG"
            assert not list(root.rglob(".*.tmp"))


@FUZZ
@given(opts=st.lists(st.sampled_from(["--step-time", "--step-amplitude", "--input-column",
                                      "--output-column", "--methods"]), min_size=1,
                     max_size=3, unique=True),
       values=st.lists(number_args, min_size=3, max_size=3))
def test_identify_any_option(capfd, opts, values):
    with tempfile.TemporaryDirectory() as tmp:
        root = Path(tmp)
        cap = root / "capture.csv"
        t = np.linspace(-0.1, 1.0, 200)
        y = model_step("fopdt", {"K": 1.5, "tau_s": 0.05, "theta_s": 0.02}, t)
        cap.write_text("t,u,y\n" + "".join(f"{a!r},{float(a >= 0)},{b!r}\n"
                                          for a, b in zip(t.tolist(), y.tolist())))
        argv = [cap] + [x for o, v in zip(opts, values) for x in (o, v)]
        run_in_process(identify_main, "identify", argv, capfd, root)


@FUZZ
@given(path=st.one_of(odd_text, st.sampled_from(["", ".", "/", "/dev/null", "/dev/zero",
                                                 "/proc/self/status", "-", "no such.csv",
                                                 "a\nb.csv", "x" * 300])),
       plot=st.one_of(st.none(), odd_text, st.sampled_from([".", "/", "capture.csv/x.png"])))
def test_identify_odd_paths(capfd, path, plot):
    with tempfile.TemporaryDirectory() as tmp:
        root = Path(tmp)
        (root / "capture.csv").write_text("t,y\n" + "".join(f"{k},{min(k, 5)}\n"
                                                            for k in range(30)))
        cwd = os.getcwd()
        os.chdir(root)
        try:
            argv = [path] + (["--plot", plot] if plot is not None else [])
            run_in_process(identify_main, "identify", argv, capfd, root)
        finally:
            os.chdir(cwd)


@FUZZ_SLOW
@given(model=st.sampled_from(["fopdt", "underdamped", "overdamped"]),
       t_exp=st.integers(-11, 9), y_exp=st.integers(-14, 14),
       u_exp=st.one_of(st.none(), st.integers(-12, 12)), t0=st.sampled_from([0.0, 1e9]))
# hypothesis found them once every route was validated (issue 28): a gain of 1.5e-10 V/V left no candidate a
# process model and the step capture was refused as "too short"; the output-error fit, on the record's own
# amplitudes and sample interval, made scipy's tf2ss warn, an ARX start take log(0) and a fit go singular (it
# now works on powers-of-two-scaled amplitudes and times)
@example(model="fopdt", t_exp=0, y_exp=-10, u_exp=0, t0=0.0)
@example(model="fopdt", t_exp=3, y_exp=-9, u_exp=0, t0=0.0)
@example(model="fopdt", t_exp=0, y_exp=-10, u_exp=8, t0=0.0)
@example(model="fopdt", t_exp=7, y_exp=-2, u_exp=0, t0=0.0)
@example(model="fopdt", t_exp=0, y_exp=2, u_exp=-12, t0=0.0)
@example(model="underdamped", t_exp=-11, y_exp=0, u_exp=0, t0=0.0)
# an overdamped fit at 1e-8 s scale: the sampled model's tf2ss warned BadCoefficients (identify.outputerror)
@example(model="overdamped", t_exp=-8, y_exp=0, u_exp=0, t0=0.0)
def test_identify_in_range_scales_give_the_right_model(capfd, model, t_exp, y_exp, u_exp, t0):
    """Inside the physical ranges the answer is right at any scale: the best
    model's step response, scaled back, is the truth's within 1 % of K (with an
    input column of step 10^u_exp, or none and --step-time)."""
    params = {"fopdt": {"K": 1.5, "tau_s": 0.05, "theta_s": 0.02},
              "underdamped": {"K": -1.0, "wn_rad_s": 60.0, "zeta": 0.2, "theta_s": 0.0},
              "overdamped": {"K": 2.0, "tau1_s": 0.01, "tau2_s": 0.08, "theta_s": 0.01}}[model]
    ts, ys = 10.0 ** t_exp, 10.0 ** y_exp
    assume(t0 == 0.0 or ts >= 1.0)   # else the samples are closer than 1e9's float spacing
    amp = 1.0 if u_exp is None else 10.0 ** u_exp
    t = np.linspace(-0.1, 1.0, 400)
    # an input edge between two samples is read at its 50 % crossing: the truth steps there
    i = int(np.argmax(t >= 0))
    edge = 0.0 if u_exp is None else 0.5 * (t[i - 1] + t[i])
    y = model_step(model, params, t - edge)
    cols = [t0 + t * ts] + ([] if u_exp is None else [np.where(t >= 0, amp, 0.0)]) + [y * ys]
    with tempfile.TemporaryDirectory() as tmp:
        root = Path(tmp)
        cap = root / "c.csv"
        cap.write_text("".join(",".join(repr(float(v)) for v in row) + "\n"
                               for row in zip(*cols)))
        argv = [cap, "--json"] + (["--step-time", repr(t0)] if u_exp is None else [])
        status, out = run_in_process(identify_main, "identify", argv, capfd, root)
    assert status == 0
    res = json.loads(out)
    best = res["best"]
    back = {k: v / ys * amp if k == "K" else v * ts if k == "wn_rad_s"
            else v / ts if k.endswith("_s") else v for k, v in best["params"].items()}
    # to the float resolution of the file's times (1.2e-7 s at t0 = 1e9 s)
    resolution = max(8 * float(np.spacing(abs(t0) + ts)) / ts, 1e-9)
    assert (res["preprocessing"]["step_time_s"] - t0) / ts == pytest.approx(edge, abs=resolution)
    err = np.max(np.abs(model_step(best["model"], back, t - edge) - y)) / abs(params["K"])
    assert err < 0.01, best


json_values = st.recursive(
    st.none() | st.booleans() | st.floats() | st.integers() | st.text(max_size=5),
    lambda inner: st.lists(inner, max_size=3) | st.dictionaries(st.text(max_size=5), inner,
                                                                max_size=3),
    max_leaves=8)


@FUZZ
@given(built=st.dictionaries(st.sampled_from(["fn_hz", "zeta", "R1_ohm", "R2_ohm", "C1_f",
                                              "C2_f", "tolerance_band"]), json_values),
       spec=json_values, spice=json_values)
def test_identify_against_any_json(capfd, built, spec, spice):
    with tempfile.TemporaryDirectory() as tmp:
        root = Path(tmp)
        cap = root / "c.csv"
        t = np.linspace(-1e-3, 9e-3, 300)
        y = model_step("underdamped", {"K": 1.0, "wn_rad_s": 6e3, "zeta": 0.3}, t)
        cap.write_text("".join(f"{a!r},{b!r}\n" for a, b in zip(t.tolist(), y.tolist())))
        design = root / "result.json"
        design.write_text(json.dumps({"built": {"fn_hz": 955.0, "zeta": 0.3, **built},
                                      "spec": spec, "spice": spice}))
        run_in_process(identify_main, "identify", [cap, "--against", design], capfd, root)


# ----------------------------------------------------------------------- identify-freq

@FUZZ
@given(content=st.one_of(bode_csv(), ragged_csv()),
       gain=st.one_of(st.none(), st.sampled_from(["db", "dB", "DB", "ratio", "Ratio", "np"]),
                      odd_text),
       phase=st.one_of(st.none(), st.sampled_from(["deg", "RAD", "s", "S"])),
       freq=st.one_of(st.none(), st.sampled_from(["hz", "Hz", "rad/s", "RAD/S"])),
       plot=st.booleans(), as_json=st.booleans())
def test_identify_freq_any_table_any_units(capfd, content, gain, phase, freq, plot, as_json):
    with tempfile.TemporaryDirectory() as tmp:
        root = Path(tmp)
        table = root / "bode.csv"
        table.write_bytes(content)
        argv = [table]
        for opt, v in (("--gain-units", gain), ("--phase-units", phase), ("--freq-units", freq)):
            argv += [opt, v] if v is not None else []
        argv += ["--plot", root / "out" / "bode.png"] if plot else []
        argv += ["--json"] if as_json else []
        status, _ = run_in_process(identify_freq_main, "identify-freq", argv, capfd, root)
        if status == 0 and plot:
            assert (root / "out" / "bode.png").read_bytes()[:4] == b"\x89PNG"


def test_units_any_case_and_the_same_column_twice(tmp_path, capfd):
    w = np.geomspace(10, 1e5, 20)
    g = model_response("fopdt", {"K": 1.0, "tau_s": 1e-3, "theta_s": 0.0}, w)
    table = tmp_path / "t.csv"
    table.write_text("".join(f"{a!r},{b!r}\n" for a, b in
                             zip((w / (2 * math.pi)).tolist(), (20 * np.log10(abs(g))).tolist())))
    status, out = run_in_process(identify_freq_main, "identify-freq",
                                 [table, "--gain-units", "dB", "--freq-units", "Hz"],
                                 capfd, tmp_path, stats=False)
    assert status == 0 and "gain in db" in out
    cap = tmp_path / "c.csv"
    cap.write_text("t,u,y\n" + "".join(f"{k},{int(k > 5)},{min(k, 9)}\n" for k in range(40)))
    for inp, outp in (("2", "2"), ("u", "2"), ("Y", "y")):
        capfd.readouterr()
        assert identify_main([str(cap), "--input-column", inp, "--output-column", outp]) == 2
        err = capfd.readouterr().err
        assert "both the input and the output" in err and len(err.splitlines()) == 1


# ----------------------------------------------------------------------- real processes



def _one_line(proc, prog):
    assert proc.returncode == 2, (proc.returncode, proc.stderr[-500:])
    lines = proc.stderr.splitlines()
    assert len(lines) == 1 and lines[0].startswith(f"{prog}: error: "), proc.stderr[-500:]
    assert proc.stdout == ""
    return lines[0]


def test_worst_inputs_through_the_console_scripts(tmp_path):
    """/dev/zero (was killed after 74 s), a directory, a huge number, an empty name."""
    ident, freq = script("identify"), script("identify-freq")
    good = tmp_path / "good.csv"
    good.write_text("".join(f"{k},{min(k, 5)}\n" for k in range(30)))
    cases = [
        ([ident, "/dev/zero"], "identify", "is a character device"),
        ([ident, str(tmp_path)], "identify", "is a directory"),
        ([freq, "/dev/zero"], "identify-freq", "is a character device"),
        ([freq, str(tmp_path)], "identify-freq", "is a directory"),
        ([ident, str(good), "--step-time", "1e300"], "identify", "--step-time must be"),
        ([ident, str(good), "--step-amplitude", "-1e-300"], "identify", "--step-amplitude"),
        ([ident, str(good), "--plot", str(tmp_path)], "identify", "is a directory"),
        ([ident, str(good), "--against", "/dev/zero"], "identify", "is a character device"),
        ([ident, ""], "identify", "the name is empty"),
    ]
    for argv, prog, words in cases:
        proc = subprocess.run(argv, capture_output=True, text=True, timeout=120)
        assert words in _one_line(proc, prog), argv
    assert sorted(p.name for p in tmp_path.iterdir()) == ["good.csv"]


def test_times_near_1e300_are_one_line_and_no_lapack_noise(tmp_path):
    """Times near 1e300 printed LAPACK's DLASCL complaints on stdout before the line."""
    t = np.linspace(-0.1, 1.0, 200)
    y = model_step("underdamped", {"K": 1.0, "wn_rad_s": 60.0, "zeta": 0.2}, t)
    path = tmp_path / "far.csv"
    path.write_text("".join(f"{a!r},{b!r}\n" for a, b in zip((t * 1e300).tolist(), y.tolist())))
    proc = subprocess.run([script("identify"), str(path)], capture_output=True, text=True,
                          timeout=120)
    from designer.core.ranges import RANGES
    assert RANGES["capture_time_s"].text() in _one_line(proc, "identify")


def test_a_fifo_is_refused_before_it_is_opened(tmp_path):
    """A FIFO (with no writer: opening it would block forever) is refused from
    its stat in one line, at once; more commands in tests/cli/test_fifo_inputs.py."""
    fifo = tmp_path / "pipe.csv"
    os.mkfifo(fifo)
    proc = subprocess.run([script("identify"), str(fifo)], capture_output=True, text=True, timeout=60)
    assert "is a FIFO (named pipe); a regular file is needed" in _one_line(proc, "identify")
