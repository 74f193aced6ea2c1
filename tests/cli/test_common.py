"""What every command shares (designer/cli/common.py): no option given twice is
silently dropped (a single-valued one is refused in one line, a list's values
accumulate), and a library parameter's name inside a message is shown as the
option the user types."""

import json
import subprocess
import tomllib

import pytest
from helpers import ROOT, script
from hypothesis import HealthCheck, given, settings
from hypothesis import strategies as st

from designer.cli import capture, check, filter as filter_cli, identify, pid, plant, prbs
from designer.cli.common import ExtendList, StoreOnce
from designer.core.errors import DesignError
from designer.web import server

#: every console script's parser (pyproject's [project.scripts])
PARSERS = {"design-plant": plant.design_plant_parser, "analyze-plant": plant.analyze_plant_parser,
           "design-pid": pid.pid_parser, "analyze-pid": pid.analyze_pid_parser, "check-design": check.check_parser,
           "identify": identify.build_parser, "identify-freq": identify.build_freq_parser,
           "simulate-capture": capture.build_parser, "make-prbs": prbs.build_parser, "designer-web": server._parser,
           "design-filter": filter_cli._parser, "analyze-filter": filter_cli._analyze_parser}


def run(exe, *args):
    return subprocess.run([script(exe), *map(str, args)], capture_output=True, text=True, timeout=300)


def one_line(proc, status=2) -> str:
    assert proc.returncode == status, (proc.returncode, proc.stdout, proc.stderr)
    lines = proc.stderr.strip().splitlines()
    assert len(lines) == 1 and "Traceback" not in proc.stderr and "Warning" not in proc.stderr, proc.stderr
    return lines[0]


def test_every_console_script_has_its_parser_here():
    scripts = tomllib.loads((ROOT / "pyproject.toml").read_text())["project"]["scripts"]
    assert set(PARSERS) == set(scripts)


def _valued(parser):
    """The options of ``parser`` that take values (not switches, --help, --version)."""
    return [a for a in parser._actions if a.option_strings and a.nargs != 0]


@pytest.mark.parametrize("prog", sorted(PARSERS))
def test_no_option_keeps_only_its_last_value(prog):
    """The audit: every option that takes a value is refused when given twice (StoreOnce), adds up
    (ExtendList, the lists) or is repeatable by design (append: --limit); none is argparse's store."""
    import argparse
    for a in _valued(PARSERS[prog]()):
        assert isinstance(a, (StoreOnce, ExtendList, argparse._AppendAction)), (prog, a.option_strings, type(a))
        if isinstance(a, ExtendList):
            assert a.nargs in ("+", "*"), a.option_strings


def _value(action, draw):
    """A value the option accepts as a word (one of its choices, else plain text)."""
    if action.choices:
        return draw(st.sampled_from(sorted(action.choices)))
    return draw(st.from_regex(r"\A[A-Za-z0-9][A-Za-z0-9.%=]{0,9}\Z"))


@st.composite
def twice(draw):
    prog = draw(st.sampled_from(sorted(PARSERS)))
    parser = PARSERS[prog]()
    action = draw(st.sampled_from(_valued(parser)))
    count = action.nargs if isinstance(action.nargs, int) else 1
    first = [_value(action, draw) for _ in range(count)]
    second = [_value(action, draw) for _ in range(count)]
    return parser, action, first, second


@settings(max_examples=300, deadline=None, suppress_health_check=[HealthCheck.too_slow])
@given(twice())
def test_an_option_given_twice_is_refused_or_accumulates(case):
    parser, action, first, second = case
    flag = action.option_strings[-1]
    argv = [flag, *first, flag, *second]
    if isinstance(action, StoreOnce):
        with pytest.raises(DesignError) as exc:
            parser.parse_args(argv)
        msg = str(exc.value)
        assert msg.startswith(f"{flag} given twice: {' '.join(first)} and {' '.join(second)}"), msg
        assert "\n" not in msg
        return
    try:
        args = parser.parse_args(argv)
    except DesignError as exc:   # a required option or positional missing: the repeat itself was taken
        assert "given twice" not in str(exc) and "required" in str(exc), str(exc)
        return
    got = getattr(args, action.dest)
    assert got == (first + second if isinstance(action, ExtendList) else [first[0], second[0]])


@settings(max_examples=100, deadline=None)
@given(st.lists(st.sampled_from(["R", "C", "R1", "R2", "C1", "C2"]), min_size=1, max_size=6, unique=True),
       st.integers(1, 5))
def test_tol_items_split_over_repeats_equal_one_list(keys, cut):
    """--tol K1=.. --tol K2=.. parses to the same list as --tol K1=.. K2=.. (however it is split)."""
    items = [f"{k}={i + 1}%" for i, k in enumerate(keys)]
    cut = min(cut, len(items))
    split = ["--tol", *items[:cut]] + (["--tol", *items[cut:]] if items[cut:] else [])
    base = ["--fc", "1k", "--zeta", "0.5"]
    p = plant.design_plant_parser()
    assert p.parse_args(base + split).tol == p.parse_args(base + ["--tol", *items]).tol == items


#: the seed's controller parts (seed 001, V.13), as analyze-pid takes them
SEED_PARTS = {"--r3": "12k", "--r4": "1.777k", "--r5": "22k", "--r6": "3.3k", "--r7": "14.356k", "--r8": "1.2k",
              "--r9": "10k", "--r10": "10k", "--r11": "10k", "--r12": "1.026k", "--r13": "26.048k",
              "--r14": "2.528k", "--r15": "10k", "--r16": "10k", "--r17": "10k", "--r18": "10k", "--c3": "4.7n",
              "--c4": "47n"}


def _tolerances(proc):
    assert proc.returncode == 0, proc.stderr
    return json.loads(proc.stdout)["monte_carlo"]["settings"]["tolerances_pct"]


def test_design_plant_tol_repeated_is_every_item():
    """The bug: --tol R=1% --tol C=5% ran R at the series' 5 %; each given item now counts."""
    base = ["--fc", "1k", "--zeta", "0.5", "--no-sim", "--no-files", "--json", "--monte-carlo", "100"]
    split = _tolerances(run("design-plant", *base, "--tol", "R=1%", "--tol", "C=2%"))
    joined = _tolerances(run("design-plant", *base, "--tol", "R=1%", "C=2%"))
    assert split == joined
    assert {k: v for k, v in split.items() if k.startswith("R")} == {"R1": 1.0, "R2": 1.0}
    assert {k: v for k, v in split.items() if k.startswith("C")} == {"C1": 2.0, "C2": 2.0}


def test_design_pid_tol_repeated_is_every_item():
    base = ["--plant-fc", "3500", "--plant-zeta", "0.2", "--kp", "2", "--ti", "1m", "--td", "10u", "--no-sim",
            "--no-files", "--json", "--monte-carlo", "30"]
    split = json.loads(run("design-pid", *base, "--tol", "R=1%", "--tol", "C4=2%").stdout)["monte_carlo"]
    joined = json.loads(run("design-pid", *base, "--tol", "R=1%", "C4=2%").stdout)["monte_carlo"]
    assert split == joined
    tol = split["settings"]["tolerances_pct"]
    assert tol["C4"] == 2.0 and all(v == 1.0 for k, v in tol.items() if k.startswith("R"))


@pytest.mark.parametrize("exe, args", [
    ("design-plant", ["--fc", "1k", "--zeta", "0.5"]),
    ("analyze-plant", ["--r1", "10k", "--r2", "10k", "--c1", "10n", "--c2", "22n", "--r-series", "E24",
                       "--c-series", "E12"]),
    ("design-pid", ["--plant-fc", "3500", "--plant-zeta", "0.2", "--kp", "2", "--ti", "1m", "--td", "10u"]),
    ("analyze-pid", ["--plant-fc", "3500", "--plant-zeta", "0.2", *[w for k, v in SEED_PARTS.items() for w in (k, v)]]),
])
def test_the_same_tol_key_twice_is_refused(exe, args, tmp_path):
    for tol in (["--tol", "R=1%", "--tol", "R=2%"], ["--tol", "R=1%", "r=2%"]):
        proc = subprocess.run([script(exe), *args, "--no-sim", "--out", str(tmp_path), "--monte-carlo", "100",
                               *tol], capture_output=True, text=True, timeout=300)
        line = one_line(proc)
        assert line.startswith(f"{exe}: error: --tol R given twice: 1% and 2%"), line
    assert list(tmp_path.iterdir()) == []


@pytest.mark.parametrize("exe, args, flag", [
    ("design-plant", ["--fc", "1k", "--fc", "2k", "--zeta", "0.5"], "--fc given twice: 1k and 2k"),
    ("design-pid", ["--plant-fc", "3500", "--plant-zeta", "0.2", "--tuning", "zn", "--tuning", "amigo"],
     "--tuning given twice: zn and amigo"),
    ("make-prbs", ["--bits", "7", "--bits", "8", "--clock", "1k"], "--bits given twice: 7 and 8"),
    ("simulate-capture", ["--plant-tf", "K=1 tau=1m", "--lsb", "1m", "--lsb", "2m"], "--lsb given twice: 1m and 2m"),
    ("identify", ["x.csv", "--window", "0", "1", "--window", "0", "2"], "--window given twice: 0 1 and 0 2"),
    ("check-design", ["x.yaml", "--jobs", "1", "--jobs", "2"], "--jobs given twice: 1 and 2"),
    ("designer-web", ["--port", "0", "--port", "1"], "--port given twice: 0 and 1"),
])
def test_a_single_valued_option_twice_is_one_line(exe, args, flag, tmp_path):
    proc = subprocess.run([script(exe), *args, "--out" if exe != "designer-web" else "--host",
                           str(tmp_path / "o") if exe != "designer-web" else "127.0.0.1"],
                          capture_output=True, text=True, timeout=60, cwd=tmp_path)
    assert flag in one_line(proc)
    assert list(tmp_path.iterdir()) == []


def test_simc_refusal_names_the_option_not_the_library_parameter():
    """SIMC on a model without dead time needs tau_c: the command line's name for it is --simc-tauc."""
    for rule, words in (("simc", "give --simc-tauc"), ("zn", "use simc with --simc-tauc")):
        line = one_line(run("design-pid", "--plant-tf", "K=2 tau=1m", "--tuning", rule, "--no-sim", "--no-files"))
        assert words in line and "tauc_s" not in line, line
    # the library keeps its own name
    from designer.core.process_build import fopdt
    from designer.pid.rules import tune_model
    with pytest.raises(DesignError, match="give tauc_s"):
        tune_model(fopdt(2.0, 1e-3), "simc")


#: the commands that write a build sheet, and so take --lang
SHEET_COMMANDS = ("design-plant", "analyze-plant", "design-pid", "analyze-pid")


@pytest.mark.parametrize("exe", SHEET_COMMANDS)
def test_a_bad_language_is_one_line_listing_the_languages(exe, tmp_path):
    line = one_line(run(exe, "--lang", "fr", "--out", tmp_path))
    assert "--lang" in line and "'fr'" in line and "'en'" in line and "'es'" in line, line
    assert list(tmp_path.iterdir()) == []


@pytest.mark.parametrize("exe", SHEET_COMMANDS)
def test_every_sheet_command_offers_the_languages_with_english_by_default(exe):
    from designer.core.i18n import LANGUAGES
    p = PARSERS[exe]()
    (action,) = [a for a in p._actions if "--lang" in a.option_strings]
    assert tuple(action.choices) == LANGUAGES and action.default == "en" and "LANG" in action.help
