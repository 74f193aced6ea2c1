"""The Dask side of the Monte Carlo's runner (:mod:`designer.tolerance.runner`):
``--dask ADDRESS`` (a running scheduler's client) and ``--dask local`` (a
LocalCluster started by the command, ahead of its Monte Carlo while it designs).

A LocalCluster's workers are threads of the command where a chunk's work is a
simulator subprocess, else processes forked from a fork server that imported
the engine once (:data:`WORKERS`); they are adopted so that nothing of the
cluster outlives the command. Tasks are the runner's chunks
(:func:`designer.tolerance.chunks.run_chunk`): a chunk whose worker dies is
submitted once more, then it is a :class:`~designer.core.errors.SimulatorError`
naming it. An address where no Dask scheduler answers within :data:`CONNECT_TIMEOUT`
seconds is one too (:func:`probe`: nothing listening, nothing answering, or something else, such
as a web server, answering), said in one line within those seconds.
"""

from __future__ import annotations

import contextlib
import os
import re
import socket
import struct
import time

from ..core.errors import DesignError, SimulatorError
from .chunks import lost_twice, run_chunk

__all__ = ["CONNECT_TIMEOUT", "ClusterStart", "DaskPool", "WORKERS", "cluster_ahead", "parse_dask", "probe"]

#: seconds a Dask scheduler has to answer
CONNECT_TIMEOUT = 3.0
_ADDRESS = re.compile(r"^(?:([A-Za-z][A-Za-z0-9+.-]*)://)?(\[[0-9A-Fa-f:.]+\]|[A-Za-z0-9_.-]+):(\d{1,5})$")
#: the largest first message a scheduler's handshake can be (its settings: a few hundred bytes)
_HANDSHAKE_MAX = 1 << 20


def parse_dask(text) -> str:
    """``--dask ADDRESS``: ``local``, or a scheduler's ``[tcp://]host:port``. Other schemes
    (``tls://`` needs certificates, ``ws://``, ``ucx://`` other transports: none of them is
    given to this command) are refused in one line.

    Parameters
    ----------
    text : str
        ``--dask``'s value.

    Returns
    -------
    str
        ``local`` or the address.
    """
    t = str(text).strip()
    if t.lower() == "local":
        return "local"
    m = _ADDRESS.match(t)
    if not m or not 0 < int(m.group(3)) < 65536:
        raise DesignError(f"--dask {text!r}: give a scheduler's address, such as tcp://10.0.0.5:8786 or "
                          "host:8786, or 'local' for a LocalCluster on this machine")
    if m.group(1) is not None and m.group(1).lower() != "tcp":
        raise DesignError(f"--dask {text!r}: only a tcp:// scheduler address is taken (a {m.group(1)}:// one "
                          "needs certificates or a transport this command has no options for)")
    return f"tcp://{m.group(2)}:{m.group(3)}"


def _recv_exactly(sock, n: int, deadline: float) -> bytes:
    """``n`` bytes from ``sock`` before ``deadline`` (monotonic); fewer if it closed; TimeoutError."""
    data = b""
    while len(data) < n:
        left = deadline - time.monotonic()
        if left <= 0:
            raise TimeoutError
        sock.settimeout(left)
        chunk = sock.recv(min(n - len(data), 65536))
        if not chunk:
            break
        data += chunk
    return data


def probe(address: str, timeout: float = CONNECT_TIMEOUT) -> str | None:
    """Why no Dask scheduler answers at ``address`` (``tcp://host:port``), or None when one does,
    told within ``timeout`` seconds. A scheduler speaks first: on each connection it sends its
    handshake, one message of distributed's TCP framing (an 8-byte little-endian length, then
    that many bytes: ``distributed/comm/tcp.py``, ``TCP.read``). Anything else is not a scheduler:
    a web server waits for a request (silent), others send text (an implausible length) or
    close. Distributed's own client, given such a peer, reads the text as a length (MemoryError)
    or waits for ever; this probe is asked first.

    Parameters
    ----------
    address : str
        ``tcp://host:port``.
    timeout : float
        Seconds to tell.

    Returns
    -------
    str or None
        Why not, or None.
    """
    m = _ADDRESS.match(address)
    host, port = m.group(2).strip("[]"), int(m.group(3))
    deadline = time.monotonic() + timeout
    try:
        sock = socket.create_connection((host, port), timeout=timeout)
    except socket.gaierror:
        return f"the host {host!r} is unknown"
    except ConnectionRefusedError:
        return "nothing listens there (connection refused)"
    except (TimeoutError, socket.timeout):
        return f"nothing answered within {timeout:g} s"
    except OSError as exc:
        return f"it cannot be reached ({exc.strerror or exc})"
    with sock:
        try:
            head = _recv_exactly(sock, 8, deadline)
            if len(head) < 8:
                return "something else answered: it closed the connection without a scheduler's handshake"
            (size,) = struct.unpack("<Q", head)
            if not 0 < size <= _HANDSHAKE_MAX:
                return "something else answered: what it sent is not a scheduler's handshake"
            if len(_recv_exactly(sock, size, deadline)) < size:
                return "something else answered: it closed the connection within a scheduler's handshake"
        except (TimeoutError, socket.timeout):
            return f"something else answered: it accepted the connection but sent no handshake within {timeout:g} s"
        except OSError as exc:
            return f"something else answered: the connection failed ({exc.strerror or exc})"
    return None


def _adopt(command_pid: int) -> None:
    """In a LocalCluster's worker: its own process group (a terminal's Ctrl-C reaches only
    the command, which stops the cluster itself) and killed with the command, however it dies:
    its parent is the fork server (:func:`_fork_server`), which ends when the command does
    (multiprocessing's "alive" pipe reads its end), and the worker asks for SIGKILL when its
    parent dies; a command already gone is noticed here."""
    from ..core import lifetime
    try:
        os.setpgrp()
    except OSError:
        pass
    lifetime.die_with_parent(os.getppid())
    try:
        os.kill(command_pid, 0)
    except ProcessLookupError:
        os._exit(1)
    except OSError:     # alive, owned by another user: not ours to judge
        pass


#: A LocalCluster's workers for what the chunks do (:attr:`Scale.work`): ``threads`` (bool), and the
#: modules worker processes start with, imported once in the fork server (:func:`_fork_server`)
#: instead of by each worker at its first task (the loop's take about 1 s of a core). Threads of
#: this process where a chunk's work is a subprocess (``ngspice -b``: the SPICE engine with the
#: ngspice-cli backend; Python only writes its commands and reads its output): processes would only
#: add their start and their messages (bench_tolerance measured 1.66x the wall of --jobs 2 with them).
#: Processes for Python's own work (the analytic and loop engines hold the GIL) and for the shared
#: library (ngspice's, one instance per process, not thread-safe).
WORKERS = {
    "analytic": (False, ("designer.plant.circuit", "designer.tolerance.montecarlo")),
    "loop": (False, ("designer.tolerance.loop", "designer.pid.model", "designer.pid.blocks", "designer.pid.verify",
                     "designer.plant.model", "scipy.linalg")),
    "spice": (False, ("designer.tolerance.spice_mc", "designer.tolerance.montecarlo", "designer.spice.simulate",
                      "designer.core.opamps")),
    "ngspice-cli": (True, ()),
}


#: the warning filter the resource tracker starts with: its "leaked semaphore objects" lines after a
#: SIGKILL of the command are its own clean-up, done, not the user's business (:func:`_fork_server`)
QUIET_TRACKER = "ignore::UserWarning:multiprocessing.resource_tracker"


def _fork_server(preload=()) -> None:
    """Start multiprocessing's fork server (once per process: later calls find it running; the
    preload is the first start's) with ``distributed``, this module and ``preload`` imported in
    it. A LocalCluster's worker processes are forked from it
    (``distributed.worker.multiprocessing-method: forkserver``): Dask's default, spawn, starts
    each worker as a new interpreter that imports ``distributed`` and, at its first task, the
    engine (about 0.6 s of a core each for the SPICE engine, 1 s for the loop's), which on a
    machine of two cores lengthened a short run by more than a second (bench_tolerance). Forking
    from the fork server, a process of one thread, is safe where forking this one (its cluster
    and design threads) is not.

    Started from the main thread with SIGINT ignored: a terminal's Ctrl-C reaches the command's
    process group, and the server (and the workers it forks, which keep its handlers) leave
    stopping to the command. It would end by itself when the command does, but only after
    tearing down its imports (0.3 s), holding the command's stdout and stderr meanwhile (a
    pipe's reader waits for it): the command kills it as it exits (:func:`_stop_fork_server`).

    The fork server needs multiprocessing's resource tracker, started here too: a process of
    its own that unlinks the semaphores the workers made once every holder is gone. After a
    SIGKILL of the command (its workers die with it) it still does that, but says so in two
    warning lines on the command's stderr; it is started with those warnings ignored
    (:data:`QUIET_TRACKER`: the tracker takes its warning options from this process's)."""
    import atexit
    import signal
    import sys
    import threading
    from multiprocessing import forkserver, get_context
    if QUIET_TRACKER not in sys.warnoptions:
        sys.warnoptions.append(QUIET_TRACKER)   # read when the tracker starts (multiprocessing.util)
    get_context("forkserver").set_forkserver_preload(["__main__", "distributed", __name__, *preload])
    main = threading.current_thread() is threading.main_thread()
    previous = signal.signal(signal.SIGINT, signal.SIG_IGN) if main else None
    try:
        forkserver.ensure_running()
    finally:
        if main:
            signal.signal(signal.SIGINT, previous)
    atexit.unregister(_stop_fork_server)
    atexit.register(_stop_fork_server)


def _stop_fork_server() -> None:
    """At exit: the fork server killed (it holds nothing: its workers went with their cluster)."""
    import signal
    from multiprocessing import forkserver
    pid = getattr(forkserver._forkserver, "_forkserver_pid", None)   # CPython's, since 3.4
    if pid:
        try:
            os.kill(pid, signal.SIGKILL)
            os.waitpid(pid, 0)
        except OSError:   # gone already, or reaped
            pass


def _dask(**settings):
    """``dask.distributed``, imported (about 0.35 s), with the Monte Carlo's setting entered
    (returned: left on closing): a killed worker's task is not retried by the scheduler, the
    runner retries it once itself; and ``settings`` (more configuration). The cluster's own log
    lines are silenced: our one-line errors say what went wrong."""
    import logging
    import warnings
    with warnings.catch_warnings():
        warnings.simplefilter("ignore", DeprecationWarning)   # a third party's, at import
        import dask
        import distributed
    for name in ("distributed", "tornado", "asyncio"):
        logging.getLogger(name).setLevel(logging.CRITICAL)
    config = dask.config.set({"distributed.scheduler.allowed-failures": 0, **settings})
    config.__enter__()
    return distributed, config


#: A LocalCluster's settings: worker processes forked from the fork server (:func:`_fork_server`);
#: no statistical profiler sampling the workers' threads every 10 ms, no system monitor polling
#: the host every 0.5 s, the event loop's health checked every second, not 50 times: they feed
#: a dashboard this command has none of, and took CPU from the chunks on a machine of two cores
LOCAL_CONFIG = {
    "distributed.worker.multiprocessing-method": "forkserver",
    "distributed.worker.profile.enabled": False,
    "distributed.admin.system-monitor.interval": "60s",
    "distributed.admin.system-monitor.disk": False,
    "distributed.admin.tick.interval": "1s",
}


def _local_cluster(workers: int, box: dict, threads: bool = False) -> None:
    """A LocalCluster of ``workers`` workers of one thread each and its client, into ``box``
    (``config``, ``cluster``, ``client``, each as it is made). The workers are processes forked
    from the fork server (:func:`_fork_server`, started already) and adopted at once
    (:func:`_adopt`), or with ``threads`` threads of this process. No dashboard; the scheduler's
    HTTP server (health routes) on a free local port: its default, 8787, may be another
    cluster's, and taking another port prints a warning."""
    import logging
    distributed, box["config"] = _dask(**LOCAL_CONFIG)
    box["cluster"] = distributed.LocalCluster(
        n_workers=workers, threads_per_worker=1, processes=not threads, silence_logs=logging.CRITICAL,
        dashboard_address=None, scheduler_kwargs={"dashboard_address": "127.0.0.1:0"})
    box["client"] = distributed.Client(box["cluster"])
    if not threads:
        box["client"].run(_adopt, os.getpid())


def _close(client=None, cluster=None, config=None) -> None:
    """Close what a pool holds (any may be None: half started, or gone)."""
    try:
        if client is not None:
            client.close(timeout=CONNECT_TIMEOUT)
        if cluster is not None and getattr(cluster, "processes", True) is False:
            # thread workers closed without waiting for a chunk still running (interrupted): its
            # ngspice would hold the command up to a chunk's end (40 s for 1250 builds); at exit
            # the thread goes with the process, and its ngspice with it (PR_SET_PDEATHSIG)
            for worker in list(cluster.workers.values()):
                cluster.sync(worker.close, executor_wait=False, timeout=CONNECT_TIMEOUT)
        if cluster is not None:
            cluster.close(timeout=CONNECT_TIMEOUT)
    except Exception:   # noqa: BLE001 - an interruption or another error may have brought us here: it wins
        pass
    finally:
        if config is not None:
            config.__exit__(None, None, None)


class ClusterStart:
    """A LocalCluster of ``workers`` for the chunks' ``work`` (a key of :data:`WORKERS`) starting
    in a thread of its own (importing ``distributed``, starting the scheduler and the workers:
    about a second). An interruption reaches the main thread only, so the cluster is never left
    half started: :meth:`close` waits for the start (a few seconds at most) and closes what it
    started, unless :meth:`take` handed it over. For worker processes, the fork server they come
    from starts first, in the caller's thread."""

    def __init__(self, workers: int, work: str | None = None):
        import threading
        self.workers, self.work = workers, work
        self._threads, preload = WORKERS.get(work, (False, ()))
        self._box = {}
        if not self._threads:
            _fork_server(preload)
        self._thread = threading.Thread(target=self._run, name="start-local-cluster", daemon=True)
        self._thread.start()

    def _run(self):
        try:
            _local_cluster(self.workers, self._box, self._threads)
        except BaseException as exc:   # noqa: BLE001 - handed to the main thread
            self._box["error"] = exc

    def take(self) -> tuple:
        """``(client, cluster, config)`` once started, now the caller's to close; the start's
        error raised."""
        while self._thread.is_alive():
            self._thread.join(0.05)
        if "error" in self._box:
            raise self._box["error"]
        box, self._box = self._box, {}
        return box["client"], box["cluster"], box["config"]

    def close(self) -> None:
        """Wait for the start and close what it started, unless it was taken."""
        self._thread.join(60)
        box, self._box = self._box, {}
        _close(box.get("client"), box.get("cluster"), box.get("config"))


#: the LocalCluster :func:`cluster_ahead` started, for the next ``--dask local`` pool to take
_ahead = None


@contextlib.contextmanager
def cluster_ahead(scale):
    """For ``--dask local`` (``scale``, a :class:`~designer.tolerance.runner.Scale`; anything else: nothing), start the LocalCluster now, in
    its thread, while the command does other work (its design, its SPICE run), so that the
    Monte Carlo's :class:`Runner` finds it started (``bench_tolerance``: the start is most of
    what a LocalCluster adds to a short run). Whatever ends the block, a cluster no runner took
    is waited for and closed.

    Parameters
    ----------
    scale : designer.tolerance.runner.Scale or None
        Where the Monte Carlo will run.
    """
    global _ahead
    if scale is None or scale.dask != "local" or _ahead is not None:
        yield
        return
    start = _ahead = ClusterStart(scale.workers, scale.work)
    try:
        yield
    finally:
        _ahead = None
        start.close()


def _cluster_start(workers: int, work: str | None = None) -> ClusterStart:
    """The start :func:`cluster_ahead` began for as many workers and the same work, handed over;
    else a new one."""
    global _ahead
    ahead = _ahead is not None and (_ahead.workers, _ahead.work) == (workers, work)
    start, _ahead = (_ahead, None) if ahead else (None, _ahead)
    return start or ClusterStart(workers, work)


class DaskPool:
    """A dask.distributed client: of a running scheduler, or of a LocalCluster started here
    (``workers`` workers of one thread each, for the chunks' ``work``: :data:`WORKERS`), or
    ahead (:func:`cluster_ahead`). Imported only here: ``import dask.distributed`` takes about
    0.35 s."""

    def __init__(self, address: str, workers: int, work: str | None = None):
        self.cluster = self.client = None
        self.address = address
        try:
            if address == "local":
                start = _cluster_start(workers, work)
                try:
                    self.client, self.cluster, self._config = start.take()
                except BaseException:
                    start.close()
                    raise
                import distributed
                self._distributed = distributed
            else:
                tick = time.monotonic()
                why = probe(address)
                if why is None:
                    self._distributed, self._config = _dask()
                    left = max(0.5, CONNECT_TIMEOUT - (time.monotonic() - tick))
                    try:
                        self.client = self._distributed.Client(address, timeout=left)
                    except Exception as exc:   # noqa: BLE001 - it answered the probe, then failed the client
                        why = (f"nothing answered within {CONNECT_TIMEOUT:g} s" if isinstance(exc, (OSError, TimeoutError))
                               else f"something else answered: {type(exc).__name__}")
                if why is not None:
                    raise SimulatorError(f"--dask {address}: no Dask scheduler there ({why})")
        except BaseException:
            self.close()
            raise

    def map(self, evaluate, context, draw, tasks, bar):
        def lost(i, why):
            raise lost_twice(*tasks[i], why)

        def done(i, _result):
            if bar is not None:
                bar.update(tasks[i][1] - tasks[i][0])

        return self.calls(run_chunk, [(evaluate, context, draw, a, b) for a, b in tasks], lost, done, errors=False)

    def calls(self, fn, args: list, lost, done=None, errors: bool = True) -> list:
        """``fn(*a)`` for each ``a`` of ``args`` on the cluster, results in order. A call whose
        worker dies is submitted once more; lost again, its result is ``lost(index, reason)``
        (which may raise). ``errors``: an exception raised by ``fn`` is ``lost`` too (else it
        is raised here). ``done(index, result)`` as each arrives. An interruption cancels
        every call not yet done."""
        d = self._distributed
        futures, tries = {}, {}
        try:
            for i, a in enumerate(args):
                futures[self.client.submit(fn, *a, pure=False)] = i
                tries[i] = 1
            out = [None] * len(args)
            pending = d.as_completed(list(futures))
            for fut in pending:
                i = futures[fut]
                if fut.status == "error":
                    exc = fut.exception()
                    if not isinstance(exc, d.KilledWorker):
                        if not errors:
                            fut.result()          # the engine's own error, raised here
                        out[i] = lost(i, f"{type(exc).__name__}: {exc}")
                    elif tries[i] > 1:
                        out[i] = lost(i, f"its Dask worker died: {exc}")
                    else:
                        tries[i] += 1
                        again = self.client.submit(fn, *args[i], pure=False)
                        futures[again] = i
                        pending.add(again)
                        continue
                else:
                    out[i] = fut.result()
                if done is not None:
                    done(i, out[i])
            return out
        except BaseException:
            if futures:
                try:
                    self.client.cancel(list(futures), force=True)
                except Exception:   # noqa: BLE001 - the interruption or error that brought us here wins
                    pass
            raise
        finally:
            for fut in futures:
                fut.release()

    def __enter__(self):
        return self

    def __exit__(self, *exc):
        self.close()
        return False

    def close(self):
        held, (self.client, self.cluster, self._config) = (self.client, self.cluster, self._config), (None,) * 3
        _close(*held)

    _config = None
