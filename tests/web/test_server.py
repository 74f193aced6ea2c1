"""designer-web's command line: its options checked in one line before anything
starts, and what it says about who can reach it; its lifetime against a real server:
a stop answers every request 503 and ends within 5 s, no temporary folder outlives a
run or a server, slow clients are closed, workers are recycled."""

import json
import os
import signal
import socket
import subprocess
import threading
import time
import urllib.error
import urllib.request
from pathlib import Path

import pytest
from hypothesis import given
from hypothesis import strategies as st

from designer.web.connections import BODY_GRACE_S, HEADER_TIMEOUT_S
from designer.web.server import exposure_warning, is_local, main
from webserver import Server


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


# --------------------------------------------------------------------------- lifetime (issue 25, item 9)


JSON = {"Content-Type": "application/json"}
#: a run that takes far longer than any test waits (a three-million-build Monte Carlo)
LONG = {"fc": 3500, "zeta": 0.2, "no-sim": True, "monte-carlo": 3000000}


def post(url, body, answers, key):
    """POST ``body`` as JSON; ``answers[key]`` = (status, error line or None, seconds)."""
    req = urllib.request.Request(url + "/api/plant", data=json.dumps(body).encode(), method="POST", headers=JSON)
    tick = time.monotonic()
    try:
        with urllib.request.urlopen(req, timeout=120) as r:
            answers[key] = (r.status, None, time.monotonic() - tick)
    except urllib.error.HTTPError as e:
        with e:
            answers[key] = (e.code, json.loads(e.read())["error"], time.monotonic() - tick)
    except OSError as e:   # no answer at all: the failure this test is for
        answers[key] = (None, repr(e), time.monotonic() - tick)


def everything_under(folder: Path) -> list:
    return sorted(str(p.relative_to(folder)) for p in folder.rglob("*"))


def children(pid: int) -> set:
    """The live processes whose parent is ``pid`` (from /proc)."""
    found = set()
    for d in Path("/proc").iterdir():
        if d.name.isdigit():
            try:
                fields = (d / "stat").read_text().rsplit(")", 1)[1].split()
            except OSError:
                continue
            if fields[0] != "Z" and int(fields[1]) == pid:
                found.add(int(d.name))
    return found


def descendants(pid: int) -> set:
    found, todo = set(), [pid]
    while todo:
        for c in children(todo.pop()):
            found.add(c)
            todo.append(c)
    return found


@pytest.mark.parametrize("sig", [signal.SIGTERM, signal.SIGINT], ids=lambda s: signal.Signals(s).name)
def test_a_stop_answers_every_request_503_and_ends_within_5_s(tmp_path, sig):
    """SIGTERM with a run under way took 58 s (the run's end) and the queued client got no answer."""
    s = Server("--jobs", "1", env={"TMPDIR": str(tmp_path)})
    answers, clients = {}, []
    try:
        family = descendants(s.proc.pid)
        clients.append(threading.Thread(target=post, args=(s.url, LONG, answers, "running")))
        clients[0].start()
        time.sleep(1.0)   # it has reached the one worker
        for i in range(3):
            clients.append(threading.Thread(target=post, args=(s.url, {"fc": 3000 + i, "zeta": 0.3}, answers, i)))
            clients[-1].start()
        time.sleep(1.0)   # they wait in the queue
        family |= descendants(s.proc.pid)
        tick = time.monotonic()
        s.proc.send_signal(sig)
        code = s.proc.wait(10)
        took = time.monotonic() - tick
        for c in clients:
            c.join(30)
    finally:
        err = s.stop()
    print(f"stopped by {signal.Signals(sig).name} in {took:.2f} s")
    assert code == 128 + sig and took < 5
    assert err.splitlines() == ["designer-web: error: " + ("terminated (SIGTERM)" if sig == signal.SIGTERM
                                                           else "interrupted")], err
    assert set(answers) == {"running", 0, 1, 2}
    for status, error, _ in answers.values():
        assert status == 503 and error == ("design-plant: error: the server is stopping: the request was cancelled; "
                                           "send it again once the server is back")
    time.sleep(0.5)
    assert not [p for p in family if Path(f"/proc/{p}").exists()], "a worker outlived the server"
    assert everything_under(tmp_path) == []


def test_the_folders_of_gone_servers_and_commands_are_removed_at_start(tmp_path):
    """Request folders of a SIGKILLed server were never removed, not even by a restart."""
    gone = subprocess.Popen(["true"])
    gone.wait()
    dead = gone.pid
    left = [f"designer-web-{dead}-abc/designer-web-x", f"designer-sim-{dead}-def", f"designer-init-{dead}-ghi"]
    kept = [f"designer-web-{os.getpid()}-alive", "designer-web-oldstyle", f"designer-sim-{dead}-a-file"]
    for name in left + kept[:2]:
        (tmp_path / name).mkdir(parents=True)
        (tmp_path / name / "deck.cir").write_text("* a deck\n")
    (tmp_path / kept[2]).write_text("not a folder")
    if os.getuid() == 0:   # another user's folder: never ours to remove
        other = tmp_path / f"designer-web-{dead}-nobody"
        other.mkdir()
        os.chown(other, 65534, 65534)
        kept.append(other.name)
    s = Server("--jobs", "1", env={"TMPDIR": str(tmp_path)})
    try:
        names = {p.name for p in tmp_path.iterdir()}
        own = [n for n in names if n.startswith(f"designer-web-{s.proc.pid}-")]
        assert names == set(kept) | set(own) and len(own) == 1
    finally:
        s.stop()
    assert {p.name for p in tmp_path.iterdir()} == set(kept)   # its own folder went with it


@pytest.mark.spice
def test_a_run_killed_at_its_deadline_leaves_nothing(tmp_path):
    """Its simulator's designer-sim-* folder (a 320 KB deck) was left in the temporary folder."""
    s = Server("--jobs", "1", "--timeout", "4", env={"TMPDIR": str(tmp_path)})
    answers, seen = {}, set()
    try:
        body = {"fc": 3500, "zeta": 0.2, "monte-carlo": 100000, "engine": "spice", "simulator": "ngspice-cli"}
        client = threading.Thread(target=post, args=(s.url, body, answers, "long"))
        client.start()
        while client.is_alive():   # where the run's temporaries are made while it runs
            seen |= {str(p.relative_to(tmp_path)) for p in tmp_path.rglob("designer-sim-*")}
            time.sleep(0.05)
        # the next request waits for the killed worker's replacement to warm up (its own simulation)
        status, _ = s.post_json("/api/plant", {"fc": 2000, "zeta": 0.5, "no-sim": True}, headers=JSON)
        after = everything_under(tmp_path)
    finally:
        s.stop()
    assert answers["long"][0] == 504 and status == 200, answers
    assert seen, "no simulator folder was seen: the run did not simulate"
    # each inside a request's private folder (server folder / request folder / designer-sim-*)
    assert all(len(Path(p).parts) == 3 and Path(p).parts[1].startswith("designer-web-") for p in seen), seen
    assert len(after) == 1 and after[0].startswith("designer-web-"), after   # the server's own, empty
    assert everything_under(tmp_path) == []


def _closed(sock) -> bool:
    sock.settimeout(0.01)
    try:
        return sock.recv(1) == b""
    except socket.timeout:
        return False
    except OSError:
        return True


def test_slow_headers_and_bodies_are_closed_and_others_still_served():
    """500 sockets sending half a header were held 25 s and more, none closed."""
    s = Server("--jobs", "1")
    try:
        host, port = s.url.split("//")[1].rsplit(":", 1)
        tick = time.monotonic()
        socks = [socket.create_connection((host, int(port))) for _ in range(50)]
        for sock in socks:
            sock.sendall(b"POST /api/plant HTTP/1.1\r\nHost: " + host.encode() + b"\r\n")   # half a header
        socks.append(socket.create_connection((host, int(port))))                         # nothing at all
        slow = socket.create_connection((host, int(port)))                                 # a byte a quarter second
        slow.sendall(f"POST /api/plant HTTP/1.1\r\nHost: {host}\r\nContent-Type: application/json\r\n"
                     "Content-Length: 1000\r\n\r\n{".encode())
        status, got = s.post_json("/api/plant", {"fc": 2000, "zeta": 0.5, "no-sim": True}, headers=JSON)
        assert status == 200 and got["spec"]["fc_hz"] == 2000   # served meanwhile
        closed = {}
        while len(closed) < len(socks) + 1 and time.monotonic() - tick < 20:
            for i, sock in enumerate(socks + [slow]):
                if i not in closed and _closed(sock):
                    closed[i] = time.monotonic() - tick
            if len(socks) not in closed:
                try:
                    slow.send(b" ")
                except OSError:   # closed by the server between the look above and this byte
                    closed[len(socks)] = time.monotonic() - tick
            time.sleep(0.25)
        for sock in socks + [slow]:
            sock.close()
        print(f"{len(closed)} slow sockets closed after {min(closed.values()):.2f} to {max(closed.values()):.2f} s")
        assert len(closed) == len(socks) + 1
        assert max(closed.values()) < max(HEADER_TIMEOUT_S, BODY_GRACE_S) + 3
    finally:
        err = s.stop()
    assert "Traceback" not in err and "ERROR" not in err, err


def test_a_worker_is_replaced_after_recycle_requests_and_answers_stay_right():
    """A worker's memory grew 40-80 kB a request, for ever: now it serves --recycle requests, then a fresh one."""
    s = Server("--jobs", "1", "--recycle", "2")
    try:
        (pool,) = children(s.proc.pid)
        seen = []
        for fc in (1100, 1200, 1300, 1400, 1500):   # the server's first request (Server waits for it) was one
            status, got = s.post_json("/api/plant", {"fc": fc, "zeta": 0.5, "no-sim": True}, headers=JSON)
            assert status == 200 and got["spec"]["fc_hz"] == fc
            time.sleep(0.3)
            seen.append(children(pool))
    finally:
        s.stop()
    # six requests, two a worker: the first worker and fresh ones (the warmed-up spare when it is ready), each
    # in turn the pool's only worker beside its spare
    from designer.web.pool import SPARE
    assert all(len(w) == 1 + SPARE for w in seen) and len(set.union(*seen)) >= 3 + SPARE, seen
    assert seen[0] != seen[2] != seen[4], seen


def test_bad_recycle_is_one_line(capsys):
    assert main(["--recycle", "0"]) == 2
    assert capsys.readouterr().err == "designer-web: error: --recycle must be 1 to 1000000, got 0\n"

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
