"""``designer-web``: the lab's page on this machine.

One process keeps the library imported and answers the pages and the API
(:mod:`.app`); its commands run in worker processes started before it
serves (:mod:`.pool`), warm (ngspice loaded), so an answer has no start-up
cost. It binds to 127.0.0.1 unless told otherwise, and says so when it is
reachable from other machines.

Its temporary files live in one folder of its own, ``designer-web-PID-*`` in the
temporary folder (each request's private folder inside it, and each run's
temporary files inside that: :mod:`.jobs`), removed when it stops; those of a
server that was SIGKILLed are removed by the next one
(:func:`designer.core.lifetime.remove_stale`). SIGTERM and SIGINT answer every
request still waiting 503, kill the runs, and end it within seconds, with the
status a shell reports for the signal (143, 130: :mod:`.connections`).
"""

from __future__ import annotations

import ipaddress
import os
import sys

from ..cli.common import OneLineParser, run_cli

__all__ = ["exposure_warning", "is_local", "main"]

EPILOG = """examples:
  designer-web                          http://127.0.0.1:8000/ on this machine only
  designer-web --port 8080 --jobs 2     another port; two designs at once (one per core)
  designer-web --host 0.0.0.0           the lab's network too: anyone who reaches it can run designs here
  designer-web --host 0.0.0.0 --allow-origin http://lab-pc.example.edu:8000
                                        ... and its page opened by the lab's own name for this machine

Pages: /plant, /pid, /identify, /check. API: POST /api/plant, /api/pid, /api/identify, /api/check with
the commands' options by name (see the README); the JSON ones take Content-Type: application/json. A request
is answered only when its Host is this server's address (on 127.0.0.1 also localhost) or a name given with
--allow-origin, and its Origin, when a browser sends one, is this server's page: no other site's page can use
it. Stop it with Ctrl-C."""


def _parser():
    from .. import __version__
    p = OneLineParser(prog="designer-web", description="Serve the design, PID, identify and check pages and their "
                      "JSON API to a browser.", epilog=EPILOG)
    import argparse
    p.formatter_class = argparse.RawDescriptionHelpFormatter
    p.add_argument("--version", action="version", version=f"%(prog)s {__version__}")
    p.add_argument("--host", default="127.0.0.1", help="address to bind (default 127.0.0.1: this machine only)")
    p.add_argument("--port", default="8000", help="TCP port, 1 to 65535 (default 8000; 0: any free one)")
    p.add_argument("--jobs", default="2", help="worker processes running the commands, 1 to 16 (default 2)")
    p.add_argument("--timeout", default="120", help="seconds one run may take before it is killed and reported, "
                                                    "1 to 3600 (default 120)")
    p.add_argument("--recycle", default="200", help="requests a worker serves before a fresh one replaces it "
                                                    "(its memory stays bounded), 1 to 1000000 (default 200)")
    p.add_argument("--allow-origin", action="append", default=[], metavar="URL",
                   help="a page origin to answer besides this server's own address, e.g. http://lab-pc:8000 or "
                        "https://lab.example.edu behind a proxy: its name is then accepted as Host too "
                        "(repeatable; for --host 0.0.0.0, which otherwise accepts this machine's own names and "
                        "addresses only)")
    return p


def _whole(text, option: str, lo: int, hi: int) -> int:
    from ..core.errors import DesignError
    try:
        n = int(str(text).strip())
    except ValueError:
        raise DesignError(f"{option} {text!r}: give a whole number, {lo} to {hi}") from None
    if not lo <= n <= hi:
        raise DesignError(f"{option} must be {lo} to {hi}, got {n}")
    return n


def is_local(host: str) -> bool:
    """Whether ``host`` is a loopback address (only this machine can connect).

    Parameters
    ----------
    host : str
        A host name or address.

    Returns
    -------
    bool
        True for ``localhost`` or a loopback address.
    """
    if host == "localhost":
        return True
    try:
        return ipaddress.ip_address(host).is_loopback
    except ValueError:
        return False


def exposure_warning(host: str, port: int) -> str | None:
    """The line said at start-up when ``host`` lets other machines in (None for a loopback address).

    Parameters
    ----------
    host : str
        The address the server listens on.
    port : int
        Its port.

    Returns
    -------
    str or None
        The warning line.
    """
    if is_local(host):
        return None
    return (f"designer-web: warning: {host} is not this machine's loopback address: anyone who can reach port {port} "
            "on this network can use the page and run designs here")


def _serve(args) -> int:
    import shutil
    import tempfile

    from ..core import lifetime
    from .guard import origin_of
    port = _whole(args.port, "--port", 0, 65535)
    jobs = _whole(args.jobs, "--jobs", 1, 16)
    timeout = _whole(args.timeout, "--timeout", 1, 3600)
    recycle = _whole(args.recycle, "--recycle", 1, 1000000)
    allowed = [origin_of(u) for u in args.allow_origin]   # checked before anything starts
    lifetime.install("designer-web")   # a stop before uvicorn takes the signals over: one line, 128 + signal
    # what earlier servers and commands that were killed left, then this server's own folder: every
    # temporary file of a request or a run is made in it (TMPDIR, inherited by the pool and ngspice)
    lifetime.remove_stale(tempfile.gettempdir())
    root = tempfile.mkdtemp(prefix=lifetime.owned_prefix("web"))
    tempfile.tempdir = os.environ["TMPDIR"] = root
    try:
        return _serve_in(args, port, jobs, timeout, recycle, allowed)
    finally:
        shutil.rmtree(root, ignore_errors=True)


def _serve_in(args, port: int, jobs: int, timeout: int, recycle: int, allowed: list) -> int:
    import socket

    import uvicorn

    from .app import create_app
    from .connections import STOP_GRACE_S, GuardedH11, StoppingServer
    from .guard import trust_for
    from .pool import Pool
    family = socket.AF_INET6 if ":" in args.host else socket.AF_INET
    sock = socket.socket(family, socket.SOCK_STREAM)
    try:
        sock.setsockopt(socket.SOL_SOCKET, socket.SO_REUSEADDR, 1)
        sock.bind((args.host, port))
        sock.listen(2048)   # connections wait in the backlog from now on, until the server accepts them
    except OSError as exc:
        sock.close()
        from ..core.errors import DesignError
        raise DesignError(f"cannot listen on {args.host}:{port}: {exc.strerror or exc}") from None
    host, port = sock.getsockname()[:2]
    # the pool is forked before the server binds its connections or starts a thread: no socket of a
    # client and no lock of a thread is ever copied into a worker
    sock.set_inheritable(False)
    pool = Pool(jobs, float(timeout), recycle=recycle)
    shown = f"[{host}]" if family == socket.AF_INET6 else host
    print(f"designer-web: serving on http://{shown}:{port}/ ({jobs} worker{'s' if jobs != 1 else ''}, {timeout} s per run; Ctrl-C stops)",
          flush=True)
    warning = exposure_warning(args.host, port)
    if warning:
        print(warning, flush=True)
    also = " (and localhost)" if is_local(host) else \
        " (and this machine's other names and addresses)" if ipaddress.ip_address(host).is_unspecified else ""
    print(f"designer-web: answering pages at {', '.join([f'http://{shown}:{port}{also}'] + allowed)}; "
          "requests from any other site's pages are refused", flush=True)
    config = uvicorn.Config(create_app(pool, trust_for(host, port, allowed)), log_level="warning",
                            lifespan="on", http=GuardedH11, timeout_graceful_shutdown=STOP_GRACE_S)
    server = StoppingServer(config, pool)
    try:
        server.run(sockets=[sock])
    finally:
        sock.close()
        pool.close()
    return 0


def main(argv=None) -> int:
    """Console entry point ``designer-web``.

    Parameters
    ----------
    argv : list of str, optional
        The arguments; None reads ``sys.argv[1:]``.

    Returns
    -------
    int
        The exit status (see :func:`~designer.cli.common.run_cli`).
    """
    return run_cli("designer-web", _parser, _serve, argv)


if __name__ == "__main__":  # pragma: no cover
    sys.exit(main())
