"""A request's options as a command line (designer.web.request): pure, no server."""

import os

import pytest
from hypothesis import given
from hypothesis import strategies as st

from designer.core.errors import DesignError
from designer.web.request import FILE_OPTIONS, REFUSED, build_argv, option_name, parser_traits


def traits():
    from designer.cli import plant
    return parser_traits(plant._design_parser())


def test_options_become_the_command_line_a_user_types():
    t = traits()
    argv = build_argv({"fc": 3500, "zeta": "0.2", "r_series": "E24", "no-sim": True, "compensate-gbw": False,
                       "limit": ["fn_hz=3.3k:3.7k", "overshoot_pct=0:55"], "gain": 1.5, "tol": ["R=1%", "C=5%"]},
                      None, t)
    assert argv == ["--fc", "3500", "--zeta", "0.2", "--r-series", "E24", "--no-sim",
                    "--limit", "fn_hz=3.3k:3.7k", "--limit", "overshoot_pct=0:55", "--gain", "1.5",
                    "--tol", "R=1%", "C=5%"]
    # the command's parser reads it back as typed
    from designer.cli import plant
    args = plant._design_parser().parse_args(argv)
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
        build_argv({"simulator": ["pyspice", "evil.yaml"]}, None, parser_traits(check._parser()))


@pytest.mark.parametrize("name", REFUSED)
def test_what_the_server_sets_is_refused(name):
    with pytest.raises(DesignError, match=f"--{name} is set by the web page itself"):
        option_name(name)


@pytest.mark.parametrize("key", ["", "-", "../x", "a b", "--fc;rm", "x" * 60, "Ärger"])
def test_a_key_that_is_no_option_name_is_refused(key):
    with pytest.raises(DesignError, match="is not an option name"):
        option_name(key)


def test_a_file_option_takes_content_written_under_a_fixed_name(tmp_path):
    argv = build_argv({"plant-model": {"best": {"model": "fopdt"}}}, str(tmp_path))
    assert argv == ["--plant-model", os.path.join(str(tmp_path), FILE_OPTIONS["plant-model"])]
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
