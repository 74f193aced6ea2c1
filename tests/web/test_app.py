"""The JSON API of designer-web against a real server (its workers run ngspice):
the same JSON as each command's --json, the CLI's one line as a 400, 413s at the
CLI's file limits, check-design's trust boundary, twenty requests at once, a run
killed at its deadline."""

import io
import json
import zipfile
from concurrent.futures import ThreadPoolExecutor

import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

from webserver import Server, cli
from helpers import EXT_CAPTURES, FIXTURES, ROOT

pytestmark = pytest.mark.spice

CAPTURE = FIXTURES / "identify" / "tektronix_mso.csv"


def cli_json(*argv) -> dict:
    """What a console script prints with --json."""
    out = cli(*argv)
    assert out.returncode == 0, out.stderr
    return json.loads(out.stdout)


def cli_error(*argv) -> str:
    """A console script's one-line refusal."""
    out = cli(*argv)
    assert out.returncode == 2
    return out.stderr.strip()


def without_run_details(d: dict) -> dict:
    """A result without what differs from run to run (timings, the tool's argv)."""
    d = json.loads(json.dumps(d))
    d.pop("timings_s", None)
    d.get("tool", {}).pop("argv", None)
    return d


def test_plant_answers_design_plants_json(server):
    status, got = server.post_json("/api/plant", {"fc": 3500, "zeta": "0.2", "opamp": "TL072"})
    assert status == 200
    want = cli_json("design-plant", "--fc", "3500", "--zeta", "0.2", "--opamp", "TL072", "--json", "--no-files")
    assert without_run_details(got) == without_run_details(want)
    assert (got["built"]["R1_ohm"], got["built"]["R2_ohm"], got["built"]["C1_f"], got["built"]["C2_f"]) == \
        (1600.0, 3900.0, 3.3e-9, 1e-7)


def test_identify_answers_identifys_json_body_or_multipart(server):
    want = cli_json("identify", str(CAPTURE), "--json")
    status, _, raw = server.post("/api/identify?filename=tektronix_mso.csv", CAPTURE.read_bytes())
    assert status == 200
    got = json.loads(raw)
    for d in (got, want):
        d["capture"].pop("source")
    assert without_run_details(got) == without_run_details(want)
    assert got["capture"]["format"] == "tektronix-mso"
    # the same capture as a form's file, an option beside it
    boundary = "----designer-test"
    body = (f"--{boundary}\r\nContent-Disposition: form-data; name=\"no-refine\"\r\n\r\ntrue\r\n"
            f"--{boundary}\r\nContent-Disposition: form-data; name=\"capture\"; filename=\"scope.csv\"\r\n"
            "Content-Type: text/csv\r\n\r\n").encode() + CAPTURE.read_bytes() + f"\r\n--{boundary}--\r\n".encode()
    status, form = server.post_json("/api/identify", body,
                                    headers={"Content-Type": f"multipart/form-data; boundary={boundary}"})
    assert status == 200, form
    assert form["capture"]["source"] == "scope.csv"   # its own name, never the server's private folder
    assert not any(m["name"] == "least-squares" for m in form["methods"])   # --no-refine reached identify


def test_identify_takes_a_frequency_table_as_identify_does(server):
    table = FIXTURES / "identify_freq" / "seed003_table31.csv"
    status, got = server.post_json("/api/identify?filename=table31.csv", table.read_bytes())
    assert status == 200
    want = cli_json("identify", str(table), "--json")
    assert got["format"] == want["format"] == "frequency-table"
    assert got["data"].pop("source") == "table31.csv"   # its own name, not the server's folder
    want["data"].pop("source")
    assert without_run_details(got) == without_run_details(want)


@pytest.mark.parametrize("path, body, argv", [
    ("/api/plant", {"fc": 3500, "zeta": -1}, ["design-plant", "--fc", "3500", "--zeta", "-1"]),
    ("/api/plant", {"fc": "3.5q", "zeta": 0.2}, ["design-plant", "--fc", "3.5q", "--zeta", "0.2"]),
    ("/api/plant", {"zeta": 0.2}, ["design-plant", "--zeta", "0.2"]),
    ("/api/plant", {"fc": 3500, "zeta": 0.2, "opamp": "LM999"}, ["design-plant", "--fc", "3500", "--zeta", "0.2",
                                                                  "--opamp", "LM999"]),
    ("/api/pid", {"plant-fc": 3500}, ["design-pid", "--plant-fc", "3500"]),
    ("/api/pid", {"plant-fc": 3500, "plant-zeta": 0.2, "tuning": "magic"},
     ["design-pid", "--plant-fc", "3500", "--plant-zeta", "0.2", "--tuning", "magic"]),
])
def test_bad_input_is_a_400_with_the_clis_one_line(server, path, body, argv):
    status, got = server.post_json(path, body)
    assert status == 400
    assert got["error"] == cli_error(*argv, "--json", "--no-files")
    assert "\n" not in got["error"] and "Traceback" not in got["error"]


@pytest.mark.parametrize("body, words", [
    ({"fc": 3500, "zeta": 0.2, "out": "/etc"}, "--out is set by the web page"),
    ({"fc": 3500, "zeta": 0.2, "json": True}, "--json is set by the web page"),
    ({"fc": 3500, "zeta": 0.2, "no-sim": "yes"}, "--no-sim is a switch"),
    ({"fc": [1, 2], "zeta": 0.2}, "--fc takes one value"),
    ({"o": "x", "fc": 3500, "zeta": 0.2}, "unrecognized arguments: --o"),
    ({"fc": {"a": 1}, "zeta": 0.2}, "--fc takes a number"),
    ({"../../x": 1}, "is not an option name"),
    ([1, 2], "must be a JSON object"),
])
def test_what_a_request_may_not_choose_is_refused(server, body, words):
    status, got = server.post_json("/api/plant", body)
    assert status == 400 and words in got["error"], got


@settings(max_examples=25)
@given(st.dictionaries(st.sampled_from(["fc", "zeta", "gain", "r-series", "opamp", "amplitude", "alternatives",
                                        "r", "c", "package", "fcx", "out"]),
                       st.one_of(st.integers(-10**6, 10**6), st.floats(allow_nan=True), st.text(max_size=8),
                                 st.booleans(), st.none(), st.lists(st.integers(), max_size=2)), max_size=5))
def test_any_body_is_answered_or_refused_in_one_line_never_a_500(server, body):
    status, got = server.post_json("/api/plant", {**body, "no-sim": True})
    assert status in (200, 400), got
    if status == 400:
        assert got["error"].startswith("design-plant: error: ") and "\n" not in got["error"]


def test_not_json_is_a_400_not_a_500(server):
    status, got = server.post_json("/api/plant", b"{not json", headers={"Content-Type": "application/json"})
    assert status == 400 and "not JSON" in got["error"]


def declared(server, path: str, length: int) -> tuple:
    """A request whose headers declare ``length`` bytes, of which a few are sent: (status, JSON answer).
    (A client sending the whole body would see the server close the connection under it.)"""
    import socket
    import urllib.parse
    u = urllib.parse.urlsplit(server.url)
    with socket.create_connection((u.hostname, u.port), timeout=60) as sock:
        sock.sendall(f"POST {path} HTTP/1.1\r\nHost: {u.netloc}\r\nContent-Type: text/csv\r\n"
                     f"Content-Length: {length}\r\nConnection: close\r\n\r\n".encode() + b"t,y\n" * 10)
        raw = b""
        while chunk := sock.recv(65536):
            raw += chunk
    head, _, body = raw.partition(b"\r\n\r\n")
    return int(head.split()[1]), json.loads(body)


def test_uploads_over_the_clis_limits_are_413(server):
    from designer.core.fileio import MAX_CAPTURE_BYTES
    # declared too large: refused before the body is read
    status, got = declared(server, "/api/identify", MAX_CAPTURE_BYTES + 10**6)
    assert status == 413 and "256 MiB" in got["error"]
    status, got = declared(server, "/api/check", 40 * 1024 * 1024)
    assert status == 413 and "check-design" in got["error"]
    status, got = declared(server, "/api/plant", 40 * 1024 * 1024)
    assert status == 413
    # a frequency table over identify-freq's 16 MiB: the command's own refusal, as a 413
    table = b"f_hz,gain_db\n" + b"1000,0\n" * (17 * 1024 * 1024 // 7)
    status, got = server.post_json("/api/identify?filename=big.csv", table)
    assert status == 413 and "cut or decimate it" in got["error"], got


def test_an_identify_path_option_is_content_never_a_path(server):
    status, got = server.post_json("/api/identify?against=/etc/passwd", CAPTURE.read_bytes())
    assert status == 400 and "/etc/passwd" not in got["error"], got


def test_twenty_requests_at_once_are_all_answered_none_mixed(server):
    fcs = [1000 + 250 * i for i in range(20)]

    def one(fc):
        return fc, server.post_json("/api/plant", {"fc": fc, "zeta": 0.3})

    with ThreadPoolExecutor(20) as ex:
        answers = list(ex.map(one, fcs))
    for fc, (status, got) in answers:
        assert status == 200
        assert got["spec"]["fc_hz"] == fc
        assert abs(got["built"]["fn_hz"] / fc - 1) < 0.05   # its own design, not a neighbour's


def test_bundle_has_the_files_design_plant_writes(server, tmp_path):
    status, headers, raw = server.post("/api/plant/bundle", {"fc": 3500, "zeta": 0.2})
    assert status == 200 and headers["content-type"] == "application/zip"
    names = set(zipfile.ZipFile(io.BytesIO(raw)).namelist())
    out = cli("design-plant", "--fc", "3500", "--zeta", "0.2", "--out", str(tmp_path))
    assert out.returncode == 0, out.stderr
    written = {p.relative_to(tmp_path).as_posix() for p in tmp_path.rglob("*") if p.is_file() or p.is_symlink()}
    assert names == written


def multipart(fields: dict, files: dict) -> tuple:
    """(body, headers) of a multipart form: ``fields`` name -> text, ``files`` field -> (file name, bytes)."""
    boundary = "----designer-test-7d1"
    parts = [f"--{boundary}\r\nContent-Disposition: form-data; name=\"{k}\"\r\n\r\n{v}\r\n".encode()
             for k, v in fields.items()]
    for field, (name, data) in files.items():
        parts.append(f"--{boundary}\r\nContent-Disposition: form-data; name=\"{field}\"; filename=\"{name}\"\r\n"
                     "Content-Type: application/octet-stream\r\n\r\n".encode() + data + b"\r\n")
    headers = {"Content-Type": f"multipart/form-data; boundary={boundary}"}
    return b"".join(parts) + f"--{boundary}--\r\n".encode(), headers


def test_check_takes_a_form_too(server):
    deck = (ROOT / "specs" / "decks" / "rc_ladder.cir").read_bytes()
    spec = b"name: ladder2\nkind: netlist\ndeck: rc_ladder.cir\nchecks:\n  v_final: {min: 0.99, max: 1.01}\n"
    body, headers = multipart({"simulator": "ngspice-cli"}, {"spec": ("ladder2.yaml", spec),
                                                             "deck": ("rc_ladder.cir", deck)})
    status, got = server.post_json("/api/check", body, headers=headers)
    assert status == 200, got
    assert got["specs"][0]["status"] == "pass" and got["specs"][0]["tool"]["simulator"] == "ngspice-cli"


def test_analyze_plant_and_the_pid_sheet(server):
    status, got = server.post_json("/api/analyze-plant", {"r1": 820, "r2": "1k", "c1": "10n", "c2": "220n",
                                                          "no-sim": True})
    want = cli_json("analyze-plant", "--r1", "820", "--r2", "1k", "--c1", "10n", "--c2", "220n", "--no-sim", "--json",
                    "--no-files")
    assert status == 200 and without_run_details(got) == without_run_details(want)
    status, headers, raw = server.post("/api/pid/sheet", {"plant-fc": 3500, "plant-zeta": 0.2, "no-sim": True})
    assert status == 200 and headers["content-type"].startswith("text/html")
    assert raw.startswith(b"<!DOCTYPE html>") and b"Op-amp PID" in raw


def test_check_runs_a_spec_and_its_deck(server):
    deck = (ROOT / "specs" / "decks" / "rc_ladder.cir").read_text()
    spec = "name: ladder\nkind: netlist\ndeck: rc_ladder.cir\nchecks:\n  v_final: {min: 0.99, max: 1.01}\n"
    status, got = server.post_json("/api/check", {"spec": spec, "files": {"rc_ladder.cir": deck}})
    assert status == 200, got
    assert got["status"] == 0 and got["specs"][0]["status"] == "pass"
    assert "<testsuite name=\"ladder\"" in got["junit"]
    assert "designer-web-" not in json.dumps(got)   # the private folder is not shown


@pytest.mark.untrusted
@pytest.mark.parametrize("deck, spec_deck, words", [
    ("* x\nV1 1 0 1\nR1 1 0 1k\n.control\nshell touch /tmp/pwned\n.endc\n.tran 1u 1m\n.end\n", "d.cir",
     "a .control block"),
    (None, "../../../etc/passwd", "outside"),
    ("* x\n.include /etc/passwd\nV1 1 0 1\n.tran 1u 1m\n.end\n", "d.cir", "/etc/passwd"),
])
def test_check_design_trust_boundary_applies_unchanged(server, deck, spec_deck, words):
    spec = f"name: evil\nkind: netlist\ndeck: {spec_deck}\nchecks:\n  v: {{max: 1}}\n"
    status, got = server.post_json("/api/check", {"spec": spec, "files": {"d.cir": deck} if deck else {}})
    assert status == 400 and words in got["error"], got


def test_a_run_past_its_deadline_is_killed_and_reported_then_the_next_is_answered():
    s = Server("--timeout", "1", "--jobs", "1")
    try:
        # a million-build Monte Carlo takes seconds on any machine
        status, got = s.post_json("/api/plant", {"fc": 3500, "zeta": 0.2, "no-sim": True, "monte-carlo": 1000000})
        assert status == 504 and "timed out after 1 s (killed)" in got["error"]
        status, got = s.post_json("/api/plant", {"fc": 2000, "zeta": 0.5, "no-sim": True})
        assert status == 200 and got["spec"]["fc_hz"] == 2000
    finally:
        err = s.stop()
    assert "Traceback" not in err


def test_a_queued_request_whose_client_left_is_never_run():
    """A page typing on aborts its older requests: those still queued are dropped, not run."""
    import socket
    import threading
    import time
    import urllib.parse
    import urllib.request
    s = Server("--jobs", "1")
    try:
        # the slow one reaches the one worker first and holds it for seconds (a million-build Monte Carlo),
        # far longer than the server takes to see the three clients below go (it looks every 0.25 s)
        slow = threading.Thread(target=s.post_json, args=("/api/plant", {"fc": 3500, "zeta": 0.2, "no-sim": True,
                                                                          "monte-carlo": 1000000}))
        slow.start()
        time.sleep(0.5)
        u = urllib.parse.urlsplit(s.url)
        body = json.dumps({"fc": 3500, "zeta": 0.2}).encode()
        for _ in range(3):   # sent while the one worker is busy, then the client goes away
            with socket.create_connection((u.hostname, u.port)) as sock:
                sock.sendall(f"POST /api/plant HTTP/1.1\r\nHost: {u.netloc}\r\nContent-Length: {len(body)}\r\n"
                             "Content-Type: application/json\r\n\r\n".encode() + body)
        slow.join()
        with urllib.request.urlopen(s.url + "/api/health", timeout=60) as r:
            health = json.loads(r.read())
        assert health["dropped"] == 3
    finally:
        s.stop()


def test_binds_to_localhost_unless_told_and_says_so(server):
    assert server.url.startswith("http://127.0.0.1:")
    assert "warning" not in server.first_line
    from designer.web.server import is_local
    assert is_local("127.0.0.1") and is_local("::1") and is_local("localhost")
    assert not is_local("0.0.0.0") and not is_local("192.0.2.1")


@pytest.mark.skipif(not (EXT_CAPTURES / "tom2718_TEK0001.CSV").exists(),
                    reason="../shared/ext-captures (real scope exports) is not beside this clone")
def test_a_real_tbs1022_capture_gives_a_first_order_model(server):
    raw = (EXT_CAPTURES / "tom2718_TEK0001.CSV").read_bytes()
    status, got = server.post_json("/api/identify?filename=TEK0001.CSV&step-amplitude=1.72", raw)
    assert status == 200
    assert got["capture"]["format"] == "tektronix-tds" and got["best"]["model"] == "fopdt"
