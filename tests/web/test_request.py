"""A request's inputs checked before any is used (designer.web.request): pure, no server."""

import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

from designer.core.errors import DesignError
from designer.web.request import REFUSED, SERVERS_OWN, option_name, write_content


@pytest.mark.parametrize("name", REFUSED)
def test_what_the_server_sets_is_refused(name):
    words = "is the server's own setting" if name in SERVERS_OWN else "is set by the web page itself"
    with pytest.raises(DesignError, match=f"--{name} {words}"):
        option_name(name)


#: every command the page runs
COMMANDS = ("design-plant", "analyze-plant", "design-filter", "design-pid", "analyze-pid", "check-design", "identify")


def test_the_server_builds_argument_lists_for_no_command():
    """Issue 26: every command the page runs is the library's, called with the request's fields: no argument
    list is built, no parser traits read, no console entry point run in the worker."""
    from designer.web import app, jobs, request
    assert set(jobs.LIBRARY) == set(COMMANDS)
    assert not any(hasattr(request, n) for n in ("build_argv", "parser_traits", "Traits", "FILE_OPTIONS"))
    assert not any(hasattr(jobs, n) for n in ("MAINS", "CLI_ONLY", "through_library"))
    assert not hasattr(app, "_parsers")


def command_tables() -> dict:
    """Each command's parser and its page's name table."""
    from designer.cli import check, identify, pid, plant
    from designer.web import forms
    return {"design-plant": (plant.design_plant_parser, forms.PLANT),
            "analyze-plant": (plant.analyze_plant_parser, forms.ANALYZE_PLANT),
            "design-pid": (pid.pid_parser, forms.PID),
            "analyze-pid": (pid.analyze_pid_parser, forms.ANALYZE_PID), "identify": (identify.build_parser,
                                                                                     forms.IDENTIFY),
            "check-design": (check.check_parser, forms.CHECK)}


#: the metavars of an option that names a file or folder on the command line
PATH_METAVARS = {"DIR", "FILE", "CSV", "OUT_PNG", "RESULT_JSON"}


@pytest.mark.parametrize("prog", sorted(command_tables()))
def test_no_field_of_any_page_takes_a_path_process_or_address_from_a_request(prog):
    """Every option that names a path is no field of the page, or a file field taking the file's content; --jobs,
    --dask, --timeout are the server's (issue 25: "dask": "tcp://HOST:PORT" made the worker a port scanner)."""
    build, table = command_tables()[prog]
    assert not set(table) & set(REFUSED)
    seen = 0
    for action in build()._actions:
        for opt in action.option_strings:
            name = opt[2:]
            if not opt.startswith("--"):
                continue
            pathlike = action.metavar in PATH_METAVARS or name in ("root", "junit", "summary", "plot", "out")
            if pathlike or name in ("jobs", "dask", "timeout", "help", "version"):
                seen += 1
                assert name not in table or table[name].kind == "file", name
    assert seen >= 2


json_values = st.recursive(st.none() | st.booleans() | st.integers() | st.floats() | st.text(max_size=20),
                           lambda inner: st.lists(inner, max_size=3) | st.dictionaries(st.text(max_size=5), inner,
                                                                                         max_size=3), max_leaves=8)
#: field names a request may well send (each page's own among them)
field_names = st.sampled_from(["r1", "r2", "c1", "c2", "r3", "gain", "part", "topology", "fc", "zeta", "opamp",
                               "monte-carlo", "tol", "limit", "replay", "stimulus", "out", "jobs", "--help"]
                              ) | st.text(max_size=12)


@settings(max_examples=60, deadline=None)
@given(st.dictionaries(field_names, json_values, max_size=6) | json_values)
def test_any_json_is_an_analyze_plant_request_or_one_line(body):
    """Any JSON the analysis page may send is a request of the library's specs, or one line naming what is
    wrong."""
    from designer.web.forms import analyze_plant_request
    try:
        analyze_plant_request(body)
    except DesignError as exc:
        assert "\n" not in str(exc) and str(exc)


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


def test_a_file_field_takes_content_written_under_a_fixed_name(tmp_path):
    path = write_content(str(tmp_path), "plant-model.json", {"best": {"model": "fopdt"}}, "plant_model")
    assert path == str(tmp_path / "plant-model.json")
    assert (tmp_path / "plant-model.json").read_text() == '{"best": {"model": "fopdt"}}'
    # a path is never opened: it is the content
    write_content(str(tmp_path), "plant-result.json", "/etc/passwd", "plant_json")
    assert (tmp_path / "plant-result.json").read_text() == "/etc/passwd"
    with pytest.raises(DesignError, match="not taken by this request"):
        write_content(None, "plant-result.json", "{}", "plant_json")
