"""Runs an engine over the samples of a Monte Carlo, chunk by chunk, in this
process, in ``--jobs N`` local processes or on a Dask cluster (``--dask
ADDRESS``, ``--dask local``): one code path, the same chunks, the same results.

A chunk is a sample range [start, stop). Its task draws those samples
(:func:`designer.tolerance.sampling.values`: sample i is a function of (seed, i)
alone) and evaluates the engine on them; the results are concatenated in chunk
order. So the figures, and everything computed from them, are the same whatever
the workers and whatever the chunking (tested): only the draw settings and the
seed travel, never the samples ("send chunks, not samples": the shared FACTS.md
measured Dask at about 4 ms a task).

An engine is a pure, picklable function ``evaluate(context, values) -> {figure:
array}`` (``values``: designator -> array over the chunk's samples) with a
picklable ``context`` (the op-amp, the loop's test, a deck): the analytic plant
(:func:`designer.tolerance.plant.evaluate`), the PID loop
(:func:`designer.tolerance.loop.evaluate`), the SPICE engine.

Failures: a chunk whose worker dies (or, in a local process, raises) is run once
more; a second loss is a :class:`~designer.core.errors.SimulatorError` naming the
chunk (exit status 3). An interruption (Ctrl-C, SIGTERM) kills the local
workers, cancels the cluster's tasks and closes a LocalCluster before it
propagates (:mod:`designer.core.lifetime`). The Dask side (the client, a
LocalCluster and its workers) is :mod:`designer.tolerance.cluster`.

``--target-ci``: :meth:`Runner.run` draws in rounds; after each round ``until``
(a function of the figures so far) gives the next total or None to stop. The
rounds' ends depend on the figures only, so they too are the same whatever the
workers.
"""

from __future__ import annotations

import math
import os
import sys
from dataclasses import dataclass

import numpy as np

from ..core.errors import DesignError
from . import sampling
from .chunks import lost_twice, run_chunk

__all__ = ["CHUNKS_PER_WORKER", "Draw", "MAX_JOBS", "MIN_CHUNK", "Runner", "SPICE_MIN_CHUNK", "SPICE_WORK", "Scale",
           "parse_jobs"]

#: the most local worker processes
MAX_JOBS = 64
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
    ``work``, what the chunks do (a key of :data:`designer.tolerance.cluster.WORKERS`: how a
    LocalCluster's workers start; :data:`SPICE_WORK`: longer chunks)."""

    jobs: int = 1
    dask: str | None = None
    progress: bool = False
    chunk: int | None = None     #: samples per chunk (None: chosen from the samples and the workers)
    work: str | None = None      #: what the chunks do (None: worker processes that import nothing ahead)

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
    """``--jobs N``: a whole number, 1 to :data:`MAX_JOBS`.

    Parameters
    ----------
    text : str
        ``--jobs``'s value.

    Returns
    -------
    int
        The worker processes.
    """
    try:
        jobs = int(str(text).strip())
    except ValueError:
        jobs = None
    if jobs is None or not 1 <= jobs <= MAX_JOBS:
        raise DesignError(f"--jobs {text!r}: give a whole number of worker processes, 1 to {MAX_JOBS}")
    return jobs


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
            from .cluster import DaskPool     # imports distributed: only for --dask
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
                    raise lost_twice(*tasks[i], r.reason)
                out[i] = r
        return out

    def close(self):
        pass


def result_size(result: dict) -> int:
    return len(next(iter(result["values"].values()))) if result["values"] else 0


#: the works (:data:`designer.tolerance.cluster.WORKERS`) whose chunks run a simulator
SPICE_WORK = ("spice", "ngspice-cli")
