"""designer-web's command line: its options checked in one line before anything
starts, and what it says about who can reach it."""

import pytest
from hypothesis import given
from hypothesis import strategies as st

from designer.web.server import exposure_warning, is_local, main


@pytest.mark.parametrize("argv, words", [
    (["--port", "http"], "--port 'http': give a whole number, 0 to 65535"),
    (["--port", "70000"], "--port must be 0 to 65535, got 70000"),
    (["--jobs", "0"], "--jobs must be 1 to 16, got 0"),
    (["--timeout", "1.5"], "--timeout '1.5': give a whole number, 1 to 3600"),
    (["--bogus"], "unrecognized arguments: --bogus"),
])
def test_bad_options_are_one_line_and_status_2(argv, words, capsys):
    assert main(argv) == 2
    err = capsys.readouterr().err
    assert err.count("\n") == 1 and err.startswith("designer-web: error: ") and words in err


def test_help_teaches_the_pages_and_the_default_host(capsys):
    with pytest.raises(SystemExit) as stop:
        main(["--help"])
    assert stop.value.code == 0
    out = capsys.readouterr().out
    assert "default 127.0.0.1" in out and "/api/plant" in out


def test_it_says_so_when_other_machines_can_reach_it():
    assert exposure_warning("127.0.0.1", 8000) is None and exposure_warning("::1", 8000) is None
    line = exposure_warning("0.0.0.0", 8000)
    assert line.startswith("designer-web: warning: 0.0.0.0") and "anyone who can reach port 8000" in line
    assert is_local("localhost") and is_local("127.0.0.5") and not is_local("192.0.2.1")


@given(st.lists(st.text(max_size=12), max_size=4))
def test_any_value_of_the_numeric_options_is_served_or_one_line(values):
    from designer.core.errors import DesignError
    from designer.web.server import _whole
    for v in values:
        try:
            n = _whole(v, "--port", 0, 65535)
        except DesignError as exc:
            assert "\n" not in str(exc) and str(exc).startswith("--port")
        else:
            assert 0 <= n <= 65535
