"""Forked worker processes: :class:`Worker` (one process that runs the tasks
sent to it, in order) and :func:`run_tasks` (a batch over N of them, with
deadlines). Every worker dies with the process that started it, however that
dies (:mod:`.lifetime`), and an interrupted batch kills its workers at once.

``check-design --jobs N`` runs each corner in a worker (one ngspice per
process, and a crash of the simulator's shared library takes down that
worker, not the checker); the build sheets' renderer
(:mod:`designer.report.render`) is one worker started ahead of its drawing.

In :func:`run_tasks`, a worker that passes its deadline is killed with its whole process group
(``ngspice -b`` children included) and replaced; one that dies is replaced
too; either way its task gets the caller's ``lost(task, reason)`` result.
Results come back in task order whatever order they finish in, so the
output is deterministic. Workers are forked from the caller, which has
already loaded the specs and imported the design code, so a worker starts in
milliseconds and shares those pages.
"""

from __future__ import annotations

import multiprocessing
import os
import signal
import time
from collections import deque
from multiprocessing.connection import wait

from . import lifetime

__all__ = ["Worker", "close_all", "death_of", "run_tasks"]


def _serve(conn, other_end, parent_pid, work, setup, queued: bool = False) -> None:
    """A worker's loop: receive a task, send back its result; None ends it. ``queued``: the results go
    out from a thread of their own (:func:`_sender`), so that the loop keeps reading tasks while a
    result waits for the parent to read it."""
    os.setpgrp()   # its own process group: the parent kills it with any ngspice it started
    lifetime.die_with_parent(parent_pid)   # and SIGKILLed with the parent, whatever kills that
    lifetime.reset_in_child()
    other_end.close()   # the parent's end: held here too, its closing at the parent's death would go unseen
    if setup is not None:
        setup()
    send = _sender(conn) if queued else conn.send
    while True:
        try:
            task = conn.recv()
        except (EOFError, KeyboardInterrupt):
            return
        if task is None:
            return
        try:
            result = ("ok", work(task))
        except Exception as exc:   # a bug, not a verdict: reported as this task's error, the worker lives on
            result = ("crash", f"{type(exc).__name__}: {exc}")
        send(result)


def _sender(conn):
    """``send(obj)`` for a worker whose parent sends it tasks without waiting for their answers (the
    renderer's pictures): the object is pickled here and its bytes written by a thread of their own.

    A pipe holds some 200 kB each way: a parent sending a large task (a cascade plant's loop waveforms)
    while the worker sends a large answer (a sheet's pictures) once left both blocked in ``send`` for good,
    each waiting for the other to read (design-pid on a 4th-order cascade hung at its sheet). The thread
    blocks instead, and the loop reads on.

    Parameters
    ----------
    conn : multiprocessing.connection.Connection
        The worker's end.

    Returns
    -------
    callable
        ``send(obj)``, which never blocks.
    """
    import queue
    import threading

    from multiprocessing.reduction import ForkingPickler
    out = queue.SimpleQueue()

    def write():
        while True:
            data = out.get()
            try:
                conn.send_bytes(data)
            except OSError:   # the parent is gone: nothing to answer
                return

    threading.Thread(target=write, name="worker-replies", daemon=True).start()
    # pickled here, in the loop's thread (as Connection.send pickles): the thread only writes bytes
    return lambda obj: out.put(bytes(ForkingPickler.dumps(obj)))


class Worker:
    """One forked process running ``work(task)`` for each task sent to it, in
    order, after ``setup()``; in its own process group (:meth:`kill` takes any
    ``ngspice -b`` it started with it). ``daemon=False`` lets a task start
    workers of its own (the web page's workers run check-design, which does);
    it dies with its parent all the same (:func:`.lifetime.die_with_parent`)."""

    def __init__(self, ctx, work, setup=None, daemon: bool = True, queued: bool = False):
        self.conn, child = ctx.Pipe()
        self.proc = ctx.Process(target=_serve, args=(child, self.conn, os.getpid(), work, setup, queued),
                                daemon=daemon)
        self.proc.start()
        child.close()
        self.task = None
        self.deadline = None

    def give(self, index: int, task, timeout: float) -> None:
        self.task, self.deadline = index, time.monotonic() + timeout
        self.conn.send(task)

    def kill(self) -> None:
        try:
            os.killpg(self.proc.pid, signal.SIGKILL)
        except (ProcessLookupError, PermissionError):
            pass
        self.proc.kill()   # not yet in its own group (just forked): the process itself
        self.proc.join(5)
        self.conn.close()


def run_tasks(tasks: list, work, jobs: int, timeout: float, lost, setup=None, cost=None, done=None) -> list:
    """``work(task)`` for every task, at most ``jobs`` at a time, each within
    ``timeout`` seconds; results in task order.

    Parameters
    ----------
    tasks : list
        The tasks (sent to the workers by pickling).
    work : callable
        Runs one task in a worker; its result is pickled back.
    jobs : int
        Worker processes (at most one per task).
    timeout : float
        Seconds a task may take before its worker is killed.
    lost : callable
        ``lost(task, reason)``: the result of a task whose worker timed out,
        died or raised (``reason`` says which).
    setup : callable, optional
        Run once in each worker before its first task.
    cost : callable, optional
        ``cost(task)``: a task's expected run time (any scale). Tasks start
        longest first, so the last to finish is a short one and the workers
        end close together (results keep the task order).
    done : callable, optional
        ``done(index, result)``, called as each task's result arrives (a progress bar).

    Returns
    -------
    list
        The results, in task order.
    """
    ctx = multiprocessing.get_context("fork")
    results = [None] * len(tasks)
    order = range(len(tasks)) if cost is None else sorted(range(len(tasks)), key=lambda i: -cost(tasks[i]))
    queue = deque(order)
    workers = []
    try:
        workers = [Worker(ctx, work, setup) for _ in range(max(1, min(jobs, len(tasks))))]
        for w in workers:
            if queue:
                i = queue.popleft()
                w.give(i, tasks[i], timeout)
        while any(w.task is not None for w in workers):
            busy = [w for w in workers if w.task is not None]
            left = min(w.deadline for w in busy) - time.monotonic()
            ready = wait([w.conn for w in busy], timeout=max(0.0, left))
            for k, w in enumerate(workers):
                if w.task is None:
                    continue
                i = w.task
                if w.conn in ready:
                    try:
                        kind, value = w.conn.recv()
                    except (EOFError, OSError):
                        kind, value = "dead", death_of(w)
                    results[i] = value if kind == "ok" else lost(tasks[i], value)
                    w.task = None
                    if done is not None:
                        done(i, results[i])
                    if kind == "dead":
                        w.kill()
                        workers[k] = w = Worker(ctx, work, setup)
                elif time.monotonic() >= w.deadline:
                    w.kill()
                    results[i] = lost(tasks[i], f"timed out after {timeout:g} s (killed)")
                    workers[k] = w = Worker(ctx, work, setup)
                    if done is not None:
                        done(i, results[i])
                if w.task is None and queue:
                    j = queue.popleft()
                    w.give(j, tasks[j], timeout)
    except BaseException:   # interrupted, or a bug: the workers and their simulations end now
        for w in workers:
            w.kill()
        raise
    finally:
        close_all(workers)
    return results


def death_of(worker: Worker) -> str:
    """What a task is answered when its worker died under it (its pipe closed): how it died.

    Parameters
    ----------
    worker : Worker
        The worker, its pipe found closed.

    Returns
    -------
    str
        The words, with the signal or exit status.
    """
    worker.proc.join(5)
    code = worker.proc.exitcode
    why = f"signal {-code}" if code is not None and code < 0 else f"exit status {code}"
    return f"the worker running it died ({why}): the simulator crashed"


def close_all(workers) -> None:
    """Ask every worker to end, give them two seconds, then kill what is left.

    Parameters
    ----------
    workers : iterable
        The worker processes.
    """
    for w in workers:
        try:
            w.conn.send(None)
        except (OSError, ValueError):
            pass
    for w in workers:
        w.proc.join(2)
        if w.proc.is_alive():
            w.kill()
