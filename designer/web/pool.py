"""The web page's worker processes: every command runs in one of them,
queued, each run within a deadline.

The server (an asyncio event loop) never forks: at start-up, before it binds
its socket or starts a thread, it forks one *pool* process
(:func:`start`), which owns ``jobs`` :class:`designer.core.workers.Worker`
processes (the workers check-design uses) and forks their replacements. A
worker runs one task at a time (:func:`designer.web.jobs.run`); one that
passes its deadline is killed with its process group (an ``ngspice -b``
included) and replaced, and its request answered "timed out"; one that dies
is replaced too. Requests beyond the workers wait in the pool's queue, in
order: none is lost, and each answer carries its request's number, so none is
mixed with another's. The pool and the workers die with the server
(:func:`designer.core.lifetime.die_with_parent`).

The pool warms up itself (ngspice loaded, every module imported, schemdraw's fonts measured: ``work``'s
:data:`WARM_UP` task, run once in the pool) before it forks its first worker, so that every worker, the
first ones and every replacement, is a fork of a warm process, ready in milliseconds (copy-on-write: its pages
shared with the pool's). A killed worker (past its deadline, or a superseded run: its client gone) is replaced
at once by a spare, a worker forked beforehand and kept idle (:data:`SPARE`), and the spare by a new fork, so
that the next request waits neither for a warm-up nor for a fork.

A superseded run (:meth:`Pool.cancel`: the page typed on while it ran) is stopped where it is: the pool
signals its worker (SIGUSR1, :class:`designer.web.jobs.Superseded`), which unwinds, an ``ngspice -b`` it
waits for killed, and keeps its warm caches; a run inside ngspice's shared library unwinds as soon as the
library's current command returns. One that has not answered within :data:`SUPERSEDED_GRACE_S` is killed
with its worker's process group, and the spare takes its place.

A worker that has served ``recycle`` requests (:data:`RECYCLE_AFTER`) is replaced by a fresh
one between two requests, so that what a long-lived process accumulates (each request left
40-80 kB in a worker: caches of the libraries it runs) stays bounded. When the server stops
(:meth:`Pool.stop_now`, from its signal handler), the pool kills every worker with its process
group (its ngspice) at once and exits: every request still waiting, queued or running, is
answered "stopped" (a 503) in the same instant.
"""

from __future__ import annotations

import asyncio
import itertools
import multiprocessing
import os
import signal
import time
from collections import deque
from multiprocessing.connection import wait

from ..core import lifetime
from ..core.workers import Worker, close_all, death_of

__all__ = ["DEFAULT_TIMEOUT_S", "MAX_WAITING", "RECYCLE_AFTER", "SPARE", "STOPPED", "SUPERSEDED_GRACE_S", "WARM_UP",
           "Busy", "Pool"]

#: seconds a worker may take over one request before it is killed (design-pid's optimiser takes a few)
DEFAULT_TIMEOUT_S = 120.0
#: the task the pool runs once in its own process before it forks its workers (:func:`designer.web.jobs.run`
#: warms up: ngspice loaded, modules imported), so that each worker is a fork of a warm process
WARM_UP = {"prog": "warm-up"}
#: most requests queued or running at once (each a message of ~100 bytes to the pool: 64 KiB of pipe holds them)
MAX_WAITING = 256
#: requests a worker serves before a fresh one replaces it (designer-web --recycle)
RECYCLE_AFTER = 200
#: seconds a superseded run has to unwind (keeping its warm worker) before its worker is killed and replaced
SUPERSEDED_GRACE_S = 0.1
#: workers forked ahead and kept idle to replace a killed one at once (designer-web's workers plus these)
SPARE = 1
#: what a request still waiting when the server stops is answered
STOPPED = "the server is stopping: the request was cancelled; send it again once the server is back"


class Busy(Exception):
    """More requests than :data:`MAX_WAITING` at once, or the server stopping: answered 503."""


def _pool_main(conn, other_end, parent_pid: int, jobs: int, timeout: float, work,
               recycle: int = RECYCLE_AFTER, spare: int = SPARE) -> None:
    """The pool process: requests ``(id, task)`` in from the server, ``(id, kind, value)`` out; ``(-id, None)``
    in: request ``id``'s client has gone."""
    lifetime.die_with_parent(parent_pid)
    lifetime.reset_in_child()
    # a Ctrl-C in the terminal reaches the whole process group: the server stops this pool itself, once the
    # requests under way are answered (or this pool dies with it)
    signal.signal(signal.SIGINT, signal.SIG_IGN)
    other_end.close()
    # warm up here, once, before the first fork: every worker (and every replacement) is then ready at once.
    # Before the SIGTERM handler: a stop during the warm-up (seconds, partly inside ngspice's library, where a
    # Python handler would wait for it to return) ends this process at once, no worker forked yet
    try:
        work(WARM_UP)
    except Exception:   # noqa: BLE001 - a warm-up that fails costs speed only: each worker loads on its first task
        pass
    ctx = multiprocessing.get_context("fork")

    def fresh():
        w = Worker(ctx, work, None, daemon=False)
        w.superseded = False   # its run's client gone (its answer, whatever it is, is "superseded")
        return w

    workers = [fresh() for _ in range(jobs)]
    # forked ahead and idle: one takes a killed worker's place at once (a superseded run, a run past its
    # deadline), so that the next request waits for no fork
    spares = [fresh() for _ in range(spare)]
    served = {}   # requests each worker (by pid) has answered

    def replace(k):
        # a spare that died while idle (killed from outside) is no replacement: its pipe is closed
        while spares:
            ready = spares.pop(0)
            if ready.proc.is_alive():
                workers[k] = ready
                return
            ready.kill()
        workers[k] = fresh()

    def stop(_signum, _frame):
        # the server stops (Pool.stop_now): every run ends now, with its ngspice; the server answers
        # everything it waits for when this process's end of the pipe closes
        for w in workers + spares:
            w.kill()
        os._exit(0)
    signal.signal(signal.SIGTERM, stop)
    queue = deque()
    try:
        while True:
            busy = [w for w in workers if w.task is not None]
            left = None if not busy else max(0.0, min(w.deadline for w in busy) - time.monotonic())
            ready = wait([conn] + [w.conn for w in busy], timeout=left)
            if conn in ready:
                try:
                    msg = conn.recv()
                except (EOFError, OSError):
                    return
                if msg is None:
                    return
                if msg[0] < 0:   # (-id, None): its client has gone; dropped (and so answered) if not started
                    if any(m[0] == -msg[0] for m in queue):
                        queue = deque(m for m in queue if m[0] != -msg[0])
                        conn.send((-msg[0], "cancelled", None))
                    for w in workers:   # under way: stopped where it is (designer.web.jobs.Superseded)
                        if w.task == -msg[0] and not w.superseded:
                            w.superseded = True
                            try:
                                os.kill(w.proc.pid, signal.SIGUSR1)
                            except ProcessLookupError:
                                pass
                            # a run that does not come back (a long call into C) is killed as at its deadline
                            w.deadline = min(w.deadline, time.monotonic() + SUPERSEDED_GRACE_S)
                else:
                    queue.append(msg)
            for k, w in enumerate(workers):
                if w.task is None:
                    continue
                if w.conn in ready:
                    try:
                        kind, value = w.conn.recv()
                    except (EOFError, OSError):
                        kind, value = "dead", death_of(w)
                    # a superseded run's answer, whatever it was (or its death): nobody reads it
                    conn.send((w.task, "superseded", None) if w.superseded else (w.task, kind, value))
                    served[w.proc.pid] = served.get(w.proc.pid, 0) + 1
                    w.task = None
                    if kind == "dead" or served[w.proc.pid] >= recycle:   # dead, or recycled
                        served.pop(w.proc.pid, None)
                        w.kill()
                        replace(k)
                elif time.monotonic() >= w.deadline:
                    served.pop(w.proc.pid, None)
                    w.kill()
                    conn.send((w.task, "superseded", None) if w.superseded else
                              (w.task, "timeout", f"timed out after {timeout:g} s (killed)"))
                    replace(k)
            for w in workers:
                if w.task is None and queue:
                    rid, task = queue.popleft()
                    w.superseded = False
                    w.give(rid, task, timeout)
            while len(spares) < spare:   # after the queue is served: the next request waits for no fork
                spares.append(fresh())
    finally:
        close_all(workers + spares)


class Pool:
    """The server's end of the pool process: :meth:`submit` a task, await its
    answer ``(kind, value)``: kind "ok" (value: what ``work`` returned),
    "crash" (a bug in the task, its words), "dead", "timeout", "cancelled" or "stopped" (the
    server is stopping: :meth:`stop_now`). A worker is replaced after ``recycle`` requests."""

    def __init__(self, jobs: int, timeout: float = DEFAULT_TIMEOUT_S, work=None, recycle: int = RECYCLE_AFTER,
                 spare: int = SPARE):
        from . import jobs as job
        ctx = multiprocessing.get_context("fork")
        self.conn, child = ctx.Pipe()
        self.timeout = timeout
        self.jobs = jobs
        self.proc = ctx.Process(target=_pool_main, args=(child, self.conn, os.getpid(), jobs, timeout,
                                                         work or job.run, recycle, spare))
        self.proc.start()
        child.close()
        self._ids = itertools.count(1)
        self._waiting = {}
        self._loop = None
        self.dropped = 0   #: requests whose client left while they were queued (never run)
        self.ran = 0       #: requests a worker ran (answered, whatever the answer): what a page's typing cost
        self.superseded = 0  #: requests stopped while they ran, their client gone (their worker freed at once)
        self.stopping = False

    def attach(self) -> None:
        """Read the pool's answers on the running event loop."""
        self._loop = asyncio.get_running_loop()
        self._loop.add_reader(self.conn.fileno(), self._answer)

    def _answer(self) -> None:
        try:
            rid, kind, value = self.conn.recv()
        except (EOFError, OSError):   # the pool is gone: every waiting request gets its answer
            self._loop.remove_reader(self.conn.fileno())
            answer = ("stopped", STOPPED) if self.stopping else ("dead", "the worker pool stopped")
            for fut in self._waiting.values():
                if not fut.done():
                    fut.set_result(answer)
            self._waiting.clear()
            return
        if kind == "cancelled":
            self.dropped += 1
        elif kind == "superseded":
            self.superseded += 1
        else:
            self.ran += 1
        fut = self._waiting.pop(rid, None)
        if fut is not None and not fut.done():
            fut.set_result((kind, value))

    def start(self, task) -> tuple:
        """Queue ``task``; returns (its id, the future of its answer). Refused (:class:`Busy`) past
        :data:`MAX_WAITING` requests: the messages on the pipe stay within its buffer."""
        if self.stopping:
            raise Busy(STOPPED)
        if len(self._waiting) >= MAX_WAITING:
            raise Busy(f"{MAX_WAITING} requests are already waiting for the workers; try again shortly")
        rid = next(self._ids)
        try:
            self.conn.send((rid, task))
        except (OSError, ValueError):   # the pool is gone (stopping, or killed)
            raise Busy(STOPPED if self.stopping else "the worker pool stopped") from None
        fut = self._loop.create_future()
        self._waiting[rid] = fut
        return rid, fut

    def stop_now(self) -> None:
        """The server is stopping (called from its signal handler: nothing here waits): the pool kills
        every worker with its process group and exits, and every request waiting for it, queued or
        running, is answered ("stopped", :data:`STOPPED`) as its end of the pipe closes; later ones
        are refused (:class:`Busy`)."""
        self.stopping = True
        try:
            os.kill(self.proc.pid, signal.SIGTERM)
        except (OSError, TypeError):   # gone already, or never started
            pass

    def cancel(self, rid: int) -> None:
        """Its client has gone: drop the task if it waits in the queue (answered "cancelled"); a run
        already started is stopped where it is (answered "superseded" as soon as it has unwound, its
        ngspice killed; killed with its worker's process group after :data:`SUPERSEDED_GRACE_S`, a spare
        taking its place)."""
        try:
            self.conn.send((-rid, None))
        except (OSError, ValueError):
            pass

    async def submit(self, task) -> tuple:
        rid, fut = self.start(task)
        try:
            return await fut
        finally:
            self._waiting.pop(rid, None)

    def close(self) -> None:
        """Stop the workers and the pool (they die with this process anyway)."""
        if self._loop is not None:
            try:
                self._loop.remove_reader(self.conn.fileno())
            except (ValueError, OSError):
                pass
        try:
            self.conn.send(None)
        except (OSError, ValueError):
            pass
        self.proc.join(10)
        if self.proc.is_alive():
            self.proc.kill()
            self.proc.join(5)
        self.conn.close()
