"""A designer-web server for the tests (tests/web/): started on a free local port
(``--port 0``: the server says which it took), stopped with SIGINT as a user's
Ctrl-C, its pipes closed."""

import json
import os
import signal
import subprocess
import sys
import urllib.error
import urllib.request

#: the environment as the run started: the servers simulate, whatever a test's own fixtures take away
ENV = dict(os.environ)


def cli(prog, *argv):
    """A console script run as a user runs it (beside this interpreter), with the run's environment."""
    from helpers import ROOT, script
    return subprocess.run([script(prog), *argv], capture_output=True, text=True, env=ENV, cwd=ROOT)


class Server:
    """A running ``designer-web`` and the way to talk to it."""

    def __init__(self, *args, env=None):
        # -W error: a warning in the server, its pool or a worker is an error there, as in the tests themselves
        self.proc = subprocess.Popen([sys.executable, "-W", "error", "-m", "designer.web.server", "--port", "0", *args],
                                     stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True,
                                     env={**ENV, **(env or {})})
        line = self.proc.stdout.readline()
        if "serving on" not in line:
            self.stop()
            raise RuntimeError(f"designer-web did not start: {line!r}")
        self.url = line.split("serving on ")[1].split()[0].rstrip("/")
        self.first_line = line
        # the workers warm up (one plant designed and simulated) before they take requests: wait for one
        try:
            status, _, _ = self.post("/api/plant", {"fc": 1000, "zeta": 0.5, "no-sim": True})
            assert status == 200
        except BaseException:
            self.stop()
            raise

    def post(self, path, body=None, headers=None, timeout=180):
        """(status, headers, body bytes) of a POST as the page sends it: a dict or list body as JSON
        (``Content-Type: application/json``), bytes as a file (``application/octet-stream``), the
        page's ``X-Designer`` header; ``headers`` add to or replace those (a None value: left out)."""
        data = json.dumps(body).encode() if isinstance(body, (dict, list)) else body
        sent = {"Content-Type": "application/json" if isinstance(body, (dict, list)) else "application/octet-stream",
                "X-Designer": "1"}
        sent.update(headers or {})
        sent = {k: v for k, v in sent.items() if v is not None}   # (urllib gives a body without a type a form's)
        req = urllib.request.Request(self.url + path, data=data if data is not None else b"", method="POST",
                                     headers=sent)
        try:
            with urllib.request.urlopen(req, timeout=timeout) as r:
                return r.status, dict(r.headers), r.read()
        except urllib.error.HTTPError as e:
            with e:
                return e.code, dict(e.headers), e.read()

    def post_json(self, path, body=None, **kw):
        status, _, raw = self.post(path, body, **kw)
        return status, json.loads(raw)

    def stop(self) -> str:
        """Ctrl-C, as a user stops it; returns what it printed on stderr."""
        if self.proc.poll() is None:
            self.proc.send_signal(signal.SIGINT)
            try:
                self.proc.wait(30)
            except subprocess.TimeoutExpired:
                self.proc.kill()
                self.proc.wait()
        err = self.proc.stderr.read()
        self.proc.stdout.close()
        self.proc.stderr.close()
        return err
