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


@pytest.mark.parametrize("url", ["evil.example", "ftp://lab.example", "http://lab.example/page", "http://",
                                 "http://lab.example:99999", "http://user@lab.example", "http://lab.example?x=1"])
def test_allow_origin_takes_an_origin_or_says_so_in_one_line(url, capsys):
    assert main(["--allow-origin", url]) == 2
    err = capsys.readouterr().err
    assert err.count("\n") == 1 and "--allow-origin" in err and "http://NAME:PORT" in err


def test_help_states_the_trust_rules(capsys):
    with pytest.raises(SystemExit):
        main(["--help"])
    out = " ".join(capsys.readouterr().out.split())
    assert "--allow-origin URL" in out and "Content-Type: application/json" in out and "Origin" in out


def test_origins_are_written_as_a_browser_sends_them():
    from designer.web.guard import origin_of
    assert origin_of("HTTP://Lab-PC.example:8000/") == "http://lab-pc.example:8000"
    assert origin_of("https://lab.example:443") == "https://lab.example"
    assert origin_of("http://[::1]:8000") == "http://[::1]:8000"


def test_which_hosts_a_server_answers():
    """A loopback bind: its address and the loopback names at its port; a wildcard bind: this machine's names
    and addresses too; --allow-origin: that name, as the browser sends it and at this port."""
    import socket

    from designer.web.guard import Guard, trust_for
    t = trust_for("127.0.0.1", 8123)
    assert {"127.0.0.1:8123", "localhost:8123", "[::1]:8123"} <= t.hosts and not t.any_local_address
    g = Guard(None, t)
    assert g.host_ok("LOCALHOST:8123") and not g.host_ok("localhost:8124") and not g.host_ok("evil.example:8123")
    assert not g.host_ok("127.0.0.2:8123")   # not a wildcard bind: its own address only
    wild = Guard(None, trust_for("0.0.0.0", 8123, ["https://lab.example.edu", "http://lab-pc:9000"]))
    assert wild.host_ok(f"{socket.gethostname()}:8123") and wild.host_ok("127.0.0.2:8123")
    assert wild.host_ok("lab.example.edu") and wild.host_ok("lab.example.edu:8123") and wild.host_ok("lab-pc:9000")
    assert not wild.host_ok("192.0.2.1:8123")      # TEST-NET-1: no address of this machine
    assert not wild.host_ok("evil.example:8123") and not wild.host_ok("127.0.0.1:8124")


def guard_answer(trust, method="POST", path="/api/plant", headers=()) -> tuple:
    """(status, headers) of the guard alone for one request (the application behind it answers 200)."""
    import asyncio

    from designer.web.guard import Guard

    async def app(scope, receive, send):
        await send({"type": "http.response.start", "status": 200, "headers": [(b"content-type", b"text/plain")]})
        await send({"type": "http.response.body", "body": b"ok"})

    sent = []

    async def send(message):
        sent.append(message)

    async def receive():
        return {"type": "http.request", "body": b"", "more_body": False}

    scope = {"type": "http", "method": method, "path": path,
             "headers": [(k.lower().encode(), v.encode()) for k, v in headers]}
    asyncio.run(Guard(app, trust)(scope, receive, send))
    return sent[0]["status"], dict(sent[0]["headers"])


@pytest.mark.parametrize("headers, status", [
    ([("Host", "127.0.0.1:8123"), ("Content-Type", "application/json")], 200),
    ([("Host", "127.0.0.1:8123"), ("Content-Type", "application/json; charset=utf-8"),
      ("Origin", "http://localhost:8123")], 200),
    ([("Host", "lab.example.edu"), ("Content-Type", "application/json"), ("Origin", "https://lab.example.edu")], 200),
    ([("Content-Type", "application/json")], 403),                              # no Host (HTTP/1.0)
    ([("Host", "127.0.0.1:8123"), ("Content-Type", "application/json"), ("Origin", "https://127.0.0.1:8123")], 403),
    ([("Host", "127.0.0.1:8123"), ("Content-Type", "application/json"), ("Origin", "http://lab.example.edu")], 403),
    ([("Host", "127.0.0.1:8123"), ("Content-Type", "application/json"), ("Origin", "null")], 403),
    ([("Host", "127.0.0.1:8123")], 415),
    ([("Host", "127.0.0.1:8123"), ("Content-Type", "Text/Plain; charset=utf-8")], 415),
])
def test_the_guard_alone(headers, status):
    from designer.web.guard import SECURITY_HEADERS, trust_for
    got, sent_headers = guard_answer(trust_for("127.0.0.1", 8123, ["https://lab.example.edu"]), headers=headers)
    assert got == status
    assert all(sent_headers[k] == v for k, v in SECURITY_HEADERS)
