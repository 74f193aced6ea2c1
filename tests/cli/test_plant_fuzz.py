"""Property tests of the plant commands' input handling (issue 7): whatever a user
types, design-plant and analyze-plant end with exit status 0, 1 or 2; a refusal is
exactly one line on stderr, never a traceback, a warning or a numpy repr, and
leaves no file behind. The commands run in-process (fast); warnings are errors
in this suite, so a leaked RuntimeWarning fails here too."""

from pathlib import Path

import pytest
from hypothesis import HealthCheck, assume, given, settings
from hypothesis import strategies as st

from designer.cli.plant import analyze_plant_main, design_plant_main

# numbers across 600 orders of magnitude, in every spelling a user might type
exponents = st.integers(-320, 320)
numbers = st.one_of(
    st.builds(lambda m, e: f"{m}e{e}", st.integers(-9, 9), exponents),
    st.builds(lambda m, e: f"{m:.3g}e{e}", st.floats(-10, 10, allow_nan=False), exponents),
    st.sampled_from(["0", "-0", "1", "4k7", "2u2", "10f", "100fF", "3.5MEG", "1.6 kOhm", "nan", "inf", "-inf",
                     "1e999", "", " ", "k", "1..2", "0x10", "1_000", "½", "1e-9F", "3500Hz", "0.2", "1e308",
                     "-1e308", "5e-324", "1k1k"]),
    st.text(max_size=12),
)
sane = {"--fc": st.sampled_from(["3500", "1k", "20k", "150"]), "--zeta": st.sampled_from(["0.2", "0.7", "1", "2"])}
plant_options = ["--fc", "--zeta", "--gain", "--amplitude", "--square-freq", "--r-min", "--r-max", "--c-min",
                 "--c-max", "--alternatives", "--r", "--c"]
analyze_options = ["--r1", "--r2", "--c1", "--c2", "--gain", "--r3", "--r4", "--fc", "--zeta", "--amplitude",
                   "--square-freq"]
names = st.one_of(st.none(), st.sampled_from(["", "a\nb", "a\tb", ".hidden", "a/b", "ok_name", "x" * 300, "é"]),
                  st.text(max_size=10))


def _check(main, argv, capsys, out_dir: Path):
    before = set(out_dir.rglob("*")) if out_dir.exists() else set()
    status = main(argv)
    captured = capsys.readouterr()
    assert status in (0, 1, 2), (argv, status, captured.err)
    assert "Traceback" not in captured.err and "Warning" not in captured.err, (argv, captured.err)
    assert "np.float64" not in captured.err + captured.out, (argv, captured.err)
    if status == 2:
        lines = captured.err.strip().splitlines()
        assert len(lines) == 1, (argv, captured.err)
        assert lines[0].startswith(("design-plant: error: ", "analyze-plant: error: ")), lines[0]
        after = set(out_dir.rglob("*")) if out_dir.exists() else set()
        assert after == before, (argv, after - before)
    return status


@settings(max_examples=150, suppress_health_check=[HealthCheck.function_scoped_fixture])
@given(st.dictionaries(st.sampled_from(plant_options), numbers, max_size=4),
       st.fixed_dictionaries({}, optional=sane), st.sampled_from(["E3", "E6", "E12", "E24", "E7", "e24", "24", "x"]),
       st.sampled_from(["LM741", "ideal", "tl072", "uA709", ""]), names)
def test_design_plant_never_crashes(capsys, tmp_path_factory, opts, base, series, opamp, name):
    out = tmp_path_factory.mktemp("out")
    args = {**base, **opts}
    argv = [x for k, v in args.items() for x in (k, v)] + ["--r-series", series, "--opamp", opamp,
                                                          "--no-sim", "--no-files", "--out", str(out)]
    if name is not None:
        argv += ["--name", name]
    _check(design_plant_main, argv, capsys, out)


@settings(max_examples=120, suppress_health_check=[HealthCheck.function_scoped_fixture])
@given(st.dictionaries(st.sampled_from(analyze_options), numbers, max_size=4), names)
def test_analyze_plant_never_crashes(capsys, tmp_path_factory, opts, name):
    out = tmp_path_factory.mktemp("out")
    args = {"--r1": "820", "--r2": "1k", "--c1": "10n", "--c2": "220n", **opts}
    argv = [x for k, v in args.items() for x in (k, v)] + ["--no-sim", "--no-files", "--out", str(out)]
    if name is not None:
        argv += ["--name", name]
    _check(analyze_plant_main, argv, capsys, out)


@settings(max_examples=12, deadline=None, suppress_health_check=[HealthCheck.function_scoped_fixture])
@given(st.sampled_from(["file", "missing/deeper", "netlists-is-file", "reports-is-file", "plain"]),
       st.sampled_from([["--fc", "3500", "--zeta", "0.2"], ["--fc", "3500", "--zeta", "1e-300"],
                        ["--fc", "1e308", "--zeta", "0.2"], ["--fc", "1592", "--zeta", "1", "--gain", "1e308"]]))
def test_output_paths_never_crash_and_refusals_write_nothing(capsys, tmp_path_factory, where, spec):
    """Odd --out targets: a file, a missing parent, netlists/ or reports/ taken by a file."""
    root = tmp_path_factory.mktemp("o")
    out = root / "out"
    if where == "file":
        out.write_text("x")
    elif where == "missing/deeper":
        out = out / "a" / "b"
    elif where in ("netlists-is-file", "reports-is-file"):
        out.mkdir()
        (out / where.split("-")[0]).write_text("x")
    status = _check(design_plant_main, spec + ["--no-sim", "--out", str(out)], capsys, root)
    assume(status == 0)
    assert (out / "reports").is_dir()


def test_one_line_names_the_input_and_the_range(capsys):
    """Regression (issue 7.7 and 7.12): extremes were tracebacks or RuntimeWarnings, slow to refuse."""
    cases = {("--fc", "1e-300"): "--fc must be 10 mHz to 10 MHz", ("--zeta", "1e-300"): "--zeta must be 0.01 to 10",
             ("--zeta", "1e300"): "--zeta", ("--fc", "1e308"): "--fc", ("--zeta", "0.001"): "--zeta",
             ("--gain", "1e308"): "--gain must be 1 to 100", ("--r-min", "1e-300"): "--r-min"}
    for (opt, val), needle in cases.items():
        args = {"--fc": "3500", "--zeta": "0.2", opt: val}
        assert design_plant_main([x for kv in args.items() for x in kv] + ["--no-sim", "--no-files"]) == 2
        err = capsys.readouterr().err
        assert needle in err and len(err.strip().splitlines()) == 1, err
    assert design_plant_main(["--fc", "3500", "--zeta", "0.2", "--r", "1e-300", "--c", "1e-300", "--no-files"]) == 2
    assert "--r must be" in capsys.readouterr().err
    for parts, needle in ((["--c1", "1e-300"], "--c1 must be"), (["--r1", "1e300"], "--r1 must be"),
                          (["--r1", "10", "--r2", "10", "--c1", "10p", "--c2", "10p"], "natural frequency")):
        args = {"--r1": "820", "--r2": "1k", "--c1": "10n", "--c2": "220n"}
        args.update(zip(parts[::2], parts[1::2]))
        assert analyze_plant_main([x for kv in args.items() for x in kv] + ["--no-sim", "--no-files"]) == 2
        err = capsys.readouterr().err
        assert needle in err and len(err.strip().splitlines()) == 1, err


@pytest.mark.parametrize("name,ok", [("", False), ("a\nb", False), ("a\tb", False), (".x", False), ("a/b", False),
                                     ("plant-1_a.b", True)])
def test_names_are_plain_file_names_in_both_commands(capsys, name, ok):
    """Regression (issue 7.13): newline/tab names were accepted; an empty name was silently
    replaced by design-plant and refused by design-pid."""
    from designer.cli.pid import design_pid_main
    for main, args in ((design_plant_main, ["--fc", "3500", "--zeta", "0.2"]),
                       (design_pid_main, ["--plant-fc", "3500", "--plant-zeta", "0.2"])):
        status = main(args + ["--no-sim", "--no-files", "--name", name])
        err = capsys.readouterr().err
        assert (status == 0) is ok, err
        if not ok:
            assert "--name" in err and len(err.strip().splitlines()) == 1


stimuli = st.one_of(st.sampled_from(["prbs", "prbs", "step", "PRBS", "noise", ""]), numbers)
prbs_bits = st.one_of(st.none(), st.integers(-1, 25).map(str), numbers)
prbs_clocks = st.one_of(st.none(), st.sampled_from(["50k", "1k", "1meg", "10", "2.5k"]), numbers)


@settings(max_examples=40, deadline=None, suppress_health_check=[HealthCheck.function_scoped_fixture])
@given(stimuli, prbs_bits, prbs_clocks, st.booleans())
def test_stimulus_options_never_crash(capsys, tmp_path_factory, stimulus, bits, clock, analyze):
    """Whatever is typed for --stimulus, --prbs-bits and --prbs-clock: exit 0, 1 or 2,
    a refusal one line and no file."""
    out = tmp_path_factory.mktemp("out")
    argv = (["--r1", "820", "--r2", "1k", "--c1", "10n", "--c2", "220n"] if analyze
            else ["--fc", "3500", "--zeta", "0.2"]) + ["--stimulus", stimulus]
    argv += [x for k, v in (("--prbs-bits", bits), ("--prbs-clock", clock)) if v is not None for x in (k, v)]
    _check(analyze_plant_main if analyze else design_plant_main,
           argv + ["--no-sim", "--no-files", "--out", str(out)], capsys, out)
