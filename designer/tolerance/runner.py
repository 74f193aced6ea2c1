"""Runs an engine over the samples of a Monte Carlo, chunk by chunk, in this
process, in ``--jobs N`` local processes or on a Dask cluster (``--dask
ADDRESS``, ``--dask local``): one code path, the same chunks, the same results.

A chunk is a sample range [start, stop). Its task draws those samples
(:func:`designer.tolerance.sampling.values`: sample i is a function of (seed, i)
alone) and evaluates the engine on them; the results are concatenated in chunk
order. So the figures, and everything computed from them, are the same whatever
the workers and whatever the chunking (tested): only the draw settings and the
seed travel, never the samples ("send chunks, not samples": /work/shared/FACTS.md
measured Dask at about 4 ms a task).

An engine is a pure, picklable function ``evaluate(context, values) -> {figure:
array}`` (``values``: designator -> array over the chunk's samples) with a
picklable ``context`` (the op-amp, the loop's test, a deck): the analytic plant
(:func:`designer.tolerance.plant.evaluate`), the PID loop
(:func:`designer.tolerance.loop.evaluate`), the SPICE engine.

Failures: a chunk whose worker dies (or, in a local process, raises) is run once
more; a second loss is a :class:`~designer.core.errors.SimulatorError` naming the
chunk (exit status 3). A Dask scheduler that does not answer within
:data:`CONNECT_TIMEOUT` seconds is one too. An interruption (Ctrl-C, SIGTERM)
kills the local workers, cancels the cluster's tasks and closes a LocalCluster
before it propagates (:mod:`designer.core.lifetime`).

``--target-ci``: :meth:`Runner.run` draws in rounds; after each round ``until``
(a function of the figures so far) gives the next total or None to stop. The
rounds' ends depend on the figures only, so they too are the same whatever the
workers.
"""

from __future__ import annotations

import contextlib
import math
import os
import re
import sys
from dataclasses import dataclass

import numpy as np

from ..core.errors import DesignError, SimulatorError
from . import sampling

#: the most local worker processes
MAX_JOBS = 64
#: seconds a Dask scheduler has to answer
CONNECT_TIMEOUT = 3.0
#: the fewest samples in a chunk (a task's overhead is about 4 ms on Dask)
MIN_CHUNK = 16
#: chunks per worker (a finer split evens the workers' ends and moves the progress bar)
CHUNKS_PER_WORKER = 8
#: the fewest builds in a chunk of the SPICE engines (:data:`SPICE_WORK`): each chunk starts a
#: simulator and loads its deck, about 18 ms against about 5 ms a build of the plant's deck
#: (measured), so a chunk of 128 keeps that start near 3 % of its time; there are still at
#: least as many chunks as workers
SPICE_MIN_CHUNK = 128
#: seconds before the progress bar appears (a shorter run shows none)
PROGRESS_DELAY = 1.0
_ADDRESS = re.compile(r"^(?:(tcp|tls|ws|wss|ucx)://)?(\[[0-9A-Fa-f:.]+\]|[A-Za-z0-9_.-]+):(\d{1,5})$")


@dataclass(frozen=True)
class Draw:
    """How the samples are drawn: sample i of ``n`` is a function of these and i alone."""

    nominal: dict        #: designator -> nominal value
    tol: dict            #: designator -> tolerance (fraction)
    n: int               #: the samples the draw is defined over (the most that may be drawn)
    seed: int
    sampler: str = "random"
    dist: str = "uniform"

    def values(self, start: int = 0, stop: int | None = None) -> dict:
        return sampling.values(self.nominal, self.tol, self.n, self.seed, self.sampler, self.dist, start, stop)


@dataclass(frozen=True)
class Picked(Draw):
    """Builds already drawn and picked out of a run (``--spice-samples``: the ones SPICE checks),
    chunked by the runner as any draw (``n``: how many)."""

    picked: dict = None      #: designator -> the chosen builds' values

    def values(self, start: int = 0, stop: int | None = None) -> dict:
        return {k: v[start:stop] for k, v in self.picked.items()}


@dataclass(frozen=True)
class Scale:
    """Where the chunks run: ``jobs`` local processes, or ``dask`` (an address, or
    ``"local"`` for a LocalCluster of ``jobs`` workers, default 2); a progress bar or not;
    ``work``, what the chunks do (a key of :data:`WORKERS`: how a LocalCluster's workers start)."""

    jobs: int = 1
    dask: str | None = None
    progress: bool = False
    chunk: int | None = None     #: samples per chunk (None: chosen from the samples and the workers)
    work: str | None = None      #: a key of :data:`WORKERS` (None: worker processes that import nothing ahead)

    @property
    def workers(self) -> int:
        if self.dask == "local":
            return self.jobs if self.jobs > 1 else 2
        return self.jobs

    def chunk_size(self, n: int) -> int:
        if self.chunk is not None:
            return self.chunk
        size = max(MIN_CHUNK, min(sampling.CHUNK, math.ceil(n / (CHUNKS_PER_WORKER * self.workers))))
        if self.work in SPICE_WORK:     # fewer, longer chunks, but every worker gets one
            size = max(MIN_CHUNK, min(max(size, SPICE_MIN_CHUNK), math.ceil(n / self.workers)))
        return size


def parse_jobs(text) -> int:
    """``--jobs N``: a whole number, 1 to :data:`MAX_JOBS`."""
    try:
        jobs = int(str(text).strip())
    except ValueError:
        jobs = None
    if jobs is None or not 1 <= jobs <= MAX_JOBS:
        raise DesignError(f"--jobs {text!r}: give a whole number of worker processes, 1 to {MAX_JOBS}")
    return jobs


def parse_dask(text) -> str:
    """``--dask ADDRESS``: ``local``, or a scheduler's ``[tcp://]host:port``."""
    t = str(text).strip()
    if t.lower() == "local":
        return "local"
    m = _ADDRESS.match(t)
    if not m or not 0 < int(m.group(3)) < 65536:
        raise DesignError(f"--dask {text!r}: give a scheduler's address, such as tcp://10.0.0.5:8786 or "
                          "host:8786, or 'local' for a LocalCluster on this machine")
    return t if m.group(1) else f"tcp://{t}"


def run_chunk(evaluate, context, draw: Draw, start: int, stop: int) -> dict:
    """One chunk's task: samples start .. stop - 1 drawn, then evaluated.
    Returns ``{"values": {designator: array}, "figures": {figure: array}}``."""
    values = draw.values(start, stop)
    return {"values": values, "figures": evaluate(context, values)}


def _die_twice(start: int, stop: int, why: str):
    return SimulatorError(f"Monte Carlo: the chunk of samples {start}..{stop - 1} was lost twice ({why})")


class _Lost:
    def __init__(self, reason: str):
        self.reason = reason


def _progress(total: int, show: bool):
    if not show:
        return None
    from tqdm import tqdm
    try:
        width, height = os.get_terminal_size(sys.stderr.fileno())
    except (OSError, ValueError, AttributeError):
        width = height = 0
    # a terminal that gives no size (a bare pseudo-terminal) would get no bar at all from tqdm
    return tqdm(total=total, unit="build", file=sys.stderr, delay=PROGRESS_DELAY, leave=False,
                ncols=width if width > 0 else 80, nrows=height if height > 0 else 24, desc="Monte Carlo")


class Runner:
    """A pool the chunks run on (a context manager: a LocalCluster starts once and is closed
    at the end, whatever ends the run).

    Parameters
    ----------
    scale : Scale
        Where the chunks run.
    """

    def __init__(self, scale: Scale = Scale()):
        self.scale = scale
        self._pool = None

    def __enter__(self):
        if self.scale.dask is not None:
            self._pool = DaskPool(self.scale.dask, self.scale.workers, self.scale.work)
        elif self.scale.jobs > 1:
            self._pool = _ProcessPool(self.scale.jobs)
        else:
            self._pool = _LocalPool()
        return self

    def __exit__(self, *exc):
        pool, self._pool = self._pool, None
        if pool is not None:
            pool.close()
        return False

    def run(self, evaluate, context, draw: Draw, n: int | None = None, until=None, progress: bool | None = None):
        """The values and figures of samples 0 .. ``n`` - 1 (default ``draw.n``).

        Parameters
        ----------
        evaluate, context
            The engine and what it needs besides the values (both picklable).
        draw : Draw
        n : int, optional
            The samples of the first round (all of them without ``until``).
        until : callable, optional
            ``until(figures) -> int | None``: after each round, the total to reach next (at
            most ``draw.n``), or None to stop.
        progress : bool, optional
            A progress bar (default: the scale's).

        Returns
        -------
        (values, figures, ends)
            designator -> array, figure -> array over the samples drawn, and each round's end.
        """
        if self._pool is None:
            with self:
                return self.run(evaluate, context, draw, n, until, progress)
        total = draw.n if n is None else n
        bar = _progress(draw.n if until is not None else total,
                        self.scale.progress if progress is None else progress)
        parts, ends, done = [], [], 0
        try:
            while True:
                # each round split for the workers by its own size (a --target-ci round of 500 of
                # 10^5 builds is as many chunks as a whole run of 500): the samples are the same
                # whatever the chunking, only the split changes
                size = self.scale.chunk_size(total - done)
                tasks = [(a, min(a + size, total)) for a in range(done, total, size)]
                parts += self._pool.map(evaluate, context, draw, tasks, bar)
                done = total
                ends.append(done)
                nxt = None if until is None else until(_concat([p["figures"] for p in parts]))
                if nxt is None or done >= draw.n:
                    break
                total = min(draw.n, max(int(nxt), done + 1))
        finally:
            if bar is not None:
                bar.close()
        return _concat([p["values"] for p in parts]), _concat([p["figures"] for p in parts]), ends


def _concat(dicts: list) -> dict:
    if len(dicts) == 1:
        return dict(dicts[0])
    return {k: np.concatenate([d[k] for d in dicts]) for k in dicts[0]}


class _LocalPool:
    """In this process, chunk after chunk (``--jobs 1``)."""

    def map(self, evaluate, context, draw, tasks, bar):
        out = []
        for a, b in tasks:
            out.append(run_chunk(evaluate, context, draw, a, b))
            if bar is not None:
                bar.update(b - a)
        return out

    def close(self):
        pass


def _run_task(job, task):
    evaluate, context, draw = job
    return run_chunk(evaluate, context, draw, *task)


class _ProcessPool:
    """``--jobs N`` forked worker processes (:func:`designer.core.workers.run_tasks`: they die
    with this process, and an interruption kills them)."""

    #: seconds a chunk may take (a hung simulator is the SPICE engine's own timeout)
    TIMEOUT = 24 * 3600.0

    def __init__(self, jobs: int):
        self.jobs = jobs

    def map(self, evaluate, context, draw, tasks, bar):
        import functools

        from ..core.workers import run_tasks
        work = functools.partial(_run_task, (evaluate, context, draw))

        def done(_i, result):
            if bar is not None and not isinstance(result, _Lost):
                bar.update(result_size(result))

        out = run_tasks(tasks, work, self.jobs, self.TIMEOUT, lambda _t, why: _Lost(why), done=done)
        again = [i for i, r in enumerate(out) if isinstance(r, _Lost)]
        if again:   # once more, each lost chunk (a worker killed by the system, a crash of the simulator)
            redo = run_tasks([tasks[i] for i in again], work, self.jobs, self.TIMEOUT,
                             lambda _t, why: _Lost(why), done=done)
            for i, r in zip(again, redo):
                if isinstance(r, _Lost):
                    raise _die_twice(*tasks[i], r.reason)
                out[i] = r
        return out

    def close(self):
        pass


def result_size(result: dict) -> int:
    return len(next(iter(result["values"].values()))) if result["values"] else 0


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
    "analytic": (False, ("designer.tolerance.plant", "designer.tolerance.montecarlo")),
    "loop": (False, ("designer.tolerance.loop", "designer.pid.model", "designer.pid.blocks", "designer.pid.verify",
                     "designer.plant.model", "scipy.linalg")),
    "spice": (False, ("designer.tolerance.spice_mc", "designer.tolerance.montecarlo", "designer.spice.simulate",
                      "designer.core.opamps")),
    "ngspice-cli": (True, ()),
}
#: the :data:`WORKERS` whose chunks run a simulator
SPICE_WORK = ("spice", "ngspice-cli")


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
    pipe's reader waits for it): the command kills it as it exits (:func:`_stop_fork_server`)."""
    import atexit
    import signal
    import threading
    from multiprocessing import forkserver, get_context
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
def cluster_ahead(scale: Scale | None):
    """For ``--dask local`` (``scale``; anything else: nothing), start the LocalCluster now, in
    its thread, while the command does other work (its design, its SPICE run), so that the
    Monte Carlo's :class:`Runner` finds it started (``bench_tolerance``: the start is most of
    what a LocalCluster adds to a short run). Whatever ends the block, a cluster no runner took
    is waited for and closed."""
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
                self._distributed, self._config = _dask()
                try:
                    self.client = self._distributed.Client(address, timeout=CONNECT_TIMEOUT)
                except Exception as exc:   # noqa: BLE001 - refused, timed out, or something else answered
                    what = (f"nothing answered within {CONNECT_TIMEOUT:g} s" if isinstance(exc, (OSError, TimeoutError))
                            else f"something else answered: {type(exc).__name__}")
                    raise SimulatorError(f"--dask {address}: no Dask scheduler there ({what})") from None
        except BaseException:
            self.close()
            raise

    def map(self, evaluate, context, draw, tasks, bar):
        def lost(i, why):
            raise _die_twice(*tasks[i], why)

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
