"""A request's options as a command line (designer.web.request): pure, no server."""

import os

import pytest
from hypothesis import given
from hypothesis import strategies as st

from designer.core.errors import DesignError
from designer.web.request import FILE_OPTIONS, REFUSED, SERVERS_OWN, build_argv, option_name, parser_traits


def traits():
    from designer.cli import plant
    return parser_traits(plant.design_plant_parser())


def test_options_become_the_command_line_a_user_types():
    t = traits()
    argv = build_argv({"fc": 3500, "zeta": "0.2", "r_series": "E24", "no-sim": True, "compensate-gbw": False,
                       "limit": ["fn_hz=3.3k:3.7k", "overshoot_pct=0:55"], "gain": 1.5, "tol": ["R=1%", "C=5%"]},
                      None, t)
    assert argv == ["--fc=3500", "--zeta=0.2", "--r-series=E24", "--no-sim",
                    "--limit=fn_hz=3.3k:3.7k", "--limit=overshoot_pct=0:55", "--gain=1.5",
                    "--tol", "R=1%", "C=5%"]
    # the command's parser reads it back as typed
    from designer.cli import plant
    args = plant.design_plant_parser().parse_args(argv)
    assert (args.fc, args.r_series, args.no_sim, args.limit) == ("3500", "E24", True,
                                                                 ["fn_hz=3.3k:3.7k", "overshoot_pct=0:55"])


def test_switches_in_words_as_forms_send_them():
    t = traits()
    assert build_argv({"no-sim": "on"}, None, t) == ["--no-sim"]
    assert build_argv({"no-sim": "false"}, None, t) == []
    with pytest.raises(DesignError, match="--no-sim is a switch"):
        build_argv({"no-sim": 2}, None, t)


@pytest.mark.parametrize("key", ["o", "ou", "no-f", "js", "plo"])
def test_an_abbreviation_argparse_would_complete_is_refused(key):
    """argparse takes --o for --out: a request names every option in full, so none reaches a refused one."""
    with pytest.raises(DesignError, match="unrecognized arguments"):
        build_argv({key: "x"}, None, traits())


def test_one_value_options_take_one_value():
    """A second value would be a positional argument (another file for check-design, another capture)."""
    with pytest.raises(DesignError, match="--fc takes one value, got 2"):
        build_argv({"fc": [3500, "/etc/passwd"]}, None, traits())
    from designer.cli import check
    with pytest.raises(DesignError, match="--simulator takes one value"):
        build_argv({"simulator": ["pyspice", "evil.yaml"]}, None, parser_traits(check.check_parser()))


@pytest.mark.parametrize("name", REFUSED)
def test_what_the_server_sets_is_refused(name):
    words = "is the server's own setting" if name in SERVERS_OWN else "is set by the web page itself"
    with pytest.raises(DesignError, match=f"--{name} {words}"):
        option_name(name)


def all_traits() -> dict:
    return {prog: parser_traits(build()) for prog, build in command_parsers().items()}


def test_the_server_builds_argument_lists_only_for_the_commands_not_yet_the_librarys():
    """Issue 26: the commands the page runs through the library (design-plant, design-filter, design-pid,
    check-design, identify) have no entry point nor parser traits left in the server."""
    from designer.web.app import _parsers
    from designer.web.jobs import LIBRARY, MAINS
    assert set(_parsers()) == set(MAINS)
    assert not set(LIBRARY) & set(MAINS)
    for prog, traits in _parsers().items():
        assert traits == all_traits()[prog]


def command_parsers() -> dict:
    from designer.cli import check, identify, pid, plant
    return {"design-plant": plant.design_plant_parser, "analyze-plant": plant.analyze_plant_parser, "design-pid": pid.pid_parser,
            "analyze-pid": pid.analyze_pid_parser, "identify": identify.build_parser,
            "identify-freq": identify.build_freq_parser, "check-design": check.check_parser}


#: the metavars of an option that names a file or folder on the command line
PATH_METAVARS = {"DIR", "FILE", "CSV", "OUT_PNG", "RESULT_JSON"}


@pytest.mark.parametrize("prog", sorted(command_parsers()))
def test_no_option_of_any_command_takes_a_path_process_or_address_from_a_request(prog, tmp_path):
    """Every option that names a path is refused or takes the file's content; --jobs, --dask, --timeout are
    the server's (issue 25: "dask": "tcp://HOST:PORT" made the worker a port scanner)."""
    parser = command_parsers()[prog]()
    seen = 0
    for action in parser._actions:
        for opt in action.option_strings:
            if not opt.startswith("--"):
                continue
            name = opt[2:]
            pathlike = action.metavar in PATH_METAVARS or name in ("root", "junit", "summary", "plot", "out")
            if pathlike or name in ("jobs", "dask", "timeout", "help", "version"):
                seen += 1
                if name in FILE_OPTIONS:
                    argv = build_argv({name: "/etc/passwd"}, str(tmp_path), all_traits()[prog])
                    assert argv == [f"{opt}={tmp_path / FILE_OPTIONS[name]}"]
                else:
                    with pytest.raises(DesignError, match=f"--{name} is"):
                        build_argv({name: "x"}, str(tmp_path), all_traits()[prog])
    assert seen >= 2


#: request bodies that tried to put options on the command line (issue 25, item 3), and what the command's own
#: parser must read from what is let through (None: refused in one line before any parser sees it)
HOSTILE = [
    ("design-plant", {"tol": ["R=1%", "--jobs=3"]}, None),
    ("design-plant", {"tol": ["R=1%", "--help"]}, None),
    ("design-plant", {"tol": ["R=1%", "-h"]}, None),
    ("design-plant", {"tol": ["--version"]}, {"tol": ["--version"]}),
    ("design-plant", {"tol": "--dask=tcp://127.0.0.1:9"}, {"tol": ["--dask=tcp://127.0.0.1:9"]}),
    ("design-plant", {"zeta": "--help"}, {"zeta": "--help"}),
    ("design-plant", {"fc": "-h"}, {"fc": "-h"}),
    ("design-plant", {"fc": "--version", "zeta": "--jobs=64"}, {"fc": "--version", "zeta": "--jobs=64"}),
    ("design-plant", {"limit": ["--help", "--jobs=3"]}, {"limit": ["--help", "--jobs=3"]}),
    ("design-plant", {"name": "--out=/tmp"}, {"name": "--out=/tmp"}),
    ("design-plant", {"fc": -1e-5}, {"fc": "-0.00001"}),
    ("identify", {"window": ["-1m", -0.5]}, {"window": ["-1m", "-0.5"]}),
    ("identify", {"window": ["0", "--help"]}, None),
    ("identify", {"window": [0, 1, "extra.csv"]}, None),
    ("identify", {"methods": ["smith", "--plot=/tmp/x.png"]}, None),
    ("identify", {"methods": "--help"}, {"methods": ["--help"]}),
    ("check-design", {"simulator": "--update-golden"}, "the command's one line"),
    ("check-design", {"simulator": ["ngspice-cli", "x.yaml"]}, None),
    ("design-pid", {"dask": "local"}, None),
    ("design-pid", {"jobs": 1}, None),
    ("check-design", {"timeout": 1}, None),
    ("design-plant", {"spice-jobs": 2}, None),
    ("design-plant", {"fc": "3k\ud800"}, None),
    ("design-plant", {"fc": {"a": 1}}, None),
    ("design-plant", {"no-sim": ["true"]}, None),
    ("design-plant", {"fc": float("inf")}, None),
]


@pytest.mark.parametrize("prog, body, parsed", HOSTILE)
def test_a_value_never_becomes_an_option(prog, body, parsed, tmp_path):
    """A value beginning with "-" is a value (joined to its option, "--zeta=--help"), or refused where an option
    takes several words; the command's own parser reads it back as the value, and never exits."""
    try:
        argv = build_argv(body, str(tmp_path), all_traits()[prog])
    except DesignError as exc:
        assert parsed is None and "\n" not in str(exc), exc
        return
    assert parsed is not None, argv
    before = {"identify": ["capture.csv"], "identify-freq": ["table.csv"], "check-design": ["spec.yaml"],
              # the required options the body does not give (an option given twice is refused)
              "design-plant": [f"--{k}={v}" for k, v in (("fc", "1k"), ("zeta", "0.5")) if k not in body]
              }.get(prog, [])
    parser = command_parsers()[prog]()
    if isinstance(parsed, str):   # the command's parser refuses the value itself, in one line
        with pytest.raises(DesignError):
            parser.parse_args(before + argv)
        return
    args = parser.parse_args(before + argv)   # a SystemExit (--help, --version) fails the test
    for key, value in parsed.items():
        assert getattr(args, key.replace("-", "_")) == value
    for key in ("jobs", "dask", "timeout", "out", "plot", "root"):
        assert getattr(args, key, None) == parser.get_default(key)


def test_json_is_bounded_and_unicode():
    from designer.web.request import MAX_DEPTH, parse_json
    assert parse_json(b"") == {} and parse_json(b'{"a": [[1]]}') == {"a": [[1]]}
    assert parse_json(b"[" * MAX_DEPTH + b"]" * MAX_DEPTH) is not None
    for raw, words in [(b"[" * (MAX_DEPTH + 1) + b"]" * (MAX_DEPTH + 1), "nested too deeply"),
                       (b"[" * 100000 + b"]" * 100000, "nested too deeply"),   # Python's parser: RecursionError
                       (b'{"spec": "\\ud800"}', "lone surrogate"),
                       (b'{"\\udfff": 1}', "lone surrogate"),
                       (b'{"a": "\xff"}', "not UTF-8"),
                       (b"{not json", "not JSON")]:
        with pytest.raises(DesignError, match=words):
            parse_json(raw)


@pytest.mark.parametrize("key", ["", "-", "../x", "a b", "--fc;rm", "x" * 60, "Ärger"])
def test_a_key_that_is_no_option_name_is_refused(key):
    with pytest.raises(DesignError, match="is not an option name"):
        option_name(key)


def test_a_file_option_takes_content_written_under_a_fixed_name(tmp_path):
    argv = build_argv({"plant-model": {"best": {"model": "fopdt"}}}, str(tmp_path))
    assert argv == ["--plant-model=" + os.path.join(str(tmp_path), FILE_OPTIONS["plant-model"])]
    assert (tmp_path / FILE_OPTIONS["plant-model"]).read_text() == '{"best": {"model": "fopdt"}}'
    # a path is never opened: it is the content
    argv = build_argv({"plant-json": "/etc/passwd"}, str(tmp_path))
    assert (tmp_path / FILE_OPTIONS["plant-json"]).read_text() == "/etc/passwd"
    with pytest.raises(DesignError, match="not taken by this request"):
        build_argv({"plant-json": "{}"}, None)


json_values = st.recursive(st.none() | st.booleans() | st.integers() | st.floats() | st.text(max_size=20),
                           lambda inner: st.lists(inner, max_size=3) | st.dictionaries(st.text(max_size=5), inner,
                                                                                         max_size=3), max_leaves=8)


@given(st.dictionaries(st.text(max_size=12), json_values, max_size=6) | json_values)
def test_any_json_is_an_argument_list_or_one_line(body):
    t = traits()
    try:
        argv = build_argv(body, None, t)
    except DesignError as exc:
        assert "\n" not in str(exc)
        return
    assert all(isinstance(a, str) for a in argv)
