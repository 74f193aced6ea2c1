"""The renderer: a process that draws a build sheet's pictures, started ahead
of the drawing so that it is ready when the design is.

matplotlib's import alone (about 0.25 s) takes longer than a plant's design
and its SPICE runs, and the drawing takes as long again. :func:`start` forks
a :class:`~designer.core.workers.Worker` that imports the plotting libraries
and draws a throw-away text (the font cache) while the caller designs and
simulates on the other core; :func:`submit` sends it ``fn(*args)`` (a
module-level function and picklable arguments) and returns at once, and
:meth:`Pending.result` waits for the answer, so the caller writes its sheet
text meanwhile. Without a started renderer, or when it fails (a task that
raises, a renderer that died or passed :data:`TIMEOUT_S`), ``fn`` runs in the
caller: the pictures are the same either way, only where they are drawn
differs, and a real error surfaces in the caller with its own type.
"""

from __future__ import annotations

import functools
import importlib
import itertools
import multiprocessing
import os
import pickle
import time
import warnings
from contextlib import contextmanager

from ..core import lifetime
from ..core.i18n import current, language
from ..core.workers import Worker

__all__ = ["ahead", "running", "start", "stop", "submit", "submit_many"]

#: the longest the caller waits for one picture before drawing it itself
TIMEOUT_S = 60.0

_worker = None
_replies: dict = {}
_ids = itertools.count()
_sent: list = []   # ids sent to the worker and not yet answered, in order
_in_renderer = False   # set in the renderer itself: it may fork helpers for submit_many


def _warm(preload=()) -> None:
    """The renderer's setup: the imports and the font cache a first picture would pay for,
    and the ``preload`` modules (by name) whose functions and results it will be sent."""
    global _in_renderer
    _in_renderer = True
    # the terminal is the command's: nothing from here (matplotlib building its font cache on a
    # fresh machine, a warning) may add a line to a one-line error; what fails is redone there
    devnull = os.open(os.devnull, os.O_WRONLY)
    os.dup2(devnull, 1)
    os.dup2(devnull, 2)
    os.close(devnull)
    for name in preload:
        importlib.import_module(name)
    import matplotlib
    matplotlib.use("Agg")   # files only: never a desktop's GUI backend in a forked process
    from matplotlib.backends.backend_agg import FigureCanvasAgg
    from matplotlib.figure import Figure
    import matplotlib.pyplot  # noqa: F401  (schemdraw's matplotlib canvas)
    import schemdraw.elements  # noqa: F401
    fig = Figure(figsize=(1, 1))
    FigureCanvasAgg(fig)
    fig.text(0.5, 0.5, "1k6")
    fig.canvas.draw()


def _call(task):
    fn, args = task
    return fn(*args)


def start(preload=()) -> None:
    """Fork the renderer (once; a failure to fork leaves drawing in the caller). It
    imports the ``preload`` modules (names) before the plotting libraries.

    Parameters
    ----------
    preload : iterable of str
        Names of the modules the renderer imports first.
    """
    global _worker
    if _worker is not None:
        return
    try:
        # queued: the caller sends its pictures without reading the answers in between
        _worker = Worker(multiprocessing.get_context("fork"), _call, functools.partial(_warm, tuple(preload)),
                         queued=True)
    except OSError:
        _worker = None
    else:
        lifetime.on_exit(stop)   # a command ended inside ngspice's library still kills it


def stop() -> None:
    """End the renderer at once (unanswered tasks are dropped: their callers draw in-process)."""
    global _worker
    w, _worker = _worker, None
    _sent.clear()
    _replies.clear()
    lifetime.forget(stop)
    if w is not None:
        w.kill()   # it holds nothing to keep, and may still be importing: no waiting for it


@contextmanager
def ahead(enabled: bool = True, preload=()):
    """``with ahead():`` the renderer runs for the block (started when ``enabled``), then ends.

    Parameters
    ----------
    enabled : bool
        Start the renderer (else the block runs without one).
    preload : iterable of str
        Modules the renderer imports first (:func:`start`).
    """
    if enabled:
        start(preload)
    try:
        yield
    finally:
        stop()


def running() -> bool:
    """Whether a renderer is started (tasks go to it).

    Returns
    -------
    bool
        A renderer is started.
    """
    return _worker is not None


class Pending:
    """A picture being drawn; :meth:`result` gives it."""

    def __init__(self, fn, args):
        # drawn in the language of the sheet asking (the renderer is another process: no context of ours)
        self.fn, self.args = _in_language, (current(), fn, args)
        fn, args = self.fn, self.args
        self.id = None
        if _worker is not None:
            try:
                _worker.conn.send((fn, args))
                self.id = next(_ids)
                _sent.append(self.id)
            except (OSError, ValueError):
                _lost()

    def result(self):
        """The return value of ``fn(*args)``, from the renderer or computed here."""
        reply = _await(self.id) if self.id is not None else None
        if reply is not None and reply[0] == "ok":
            return reply[1]
        return self.fn(*self.args)


def _in_language(lang, fn, args):
    """``fn(*args)`` with the sheets' language ``lang`` in force (:func:`designer.core.i18n.language`)."""
    with language(lang):
        return fn(*args)


def submit(fn, *args) -> Pending:
    """``fn(*args)`` in the renderer when one is started; :meth:`Pending.result` gives it.

    Parameters
    ----------
    fn : callable
        What draws (picklable).
    *args
        Its arguments.

    Returns
    -------
    Pending
        The picture being drawn.
    """
    return Pending(fn, args)


def submit_many(calls) -> Pending:
    """``[(fn, args), ...]`` drawn side by side: the renderer, already warm, forks a
    helper for every call but the first (the pictures of one sheet then take the
    longest one's time on two cores, not their sum). :meth:`Pending.result` gives
    the list of return values, in order.

    Parameters
    ----------
    calls : list of tuple
        ``(fn, args)`` pairs.

    Returns
    -------
    Pending
        The pictures being drawn.
    """
    return Pending(_many, (tuple(calls),))


def _many(calls) -> list:
    if not _in_renderer or len(calls) < 2:   # in the caller: one after the other
        return [fn(*args) for fn, args in calls]
    helpers = []
    me = os.getpid()
    for fn, args in calls[1:]:
        r, w = os.pipe()
        with warnings.catch_warnings():
            # the renderer's answers go out from a thread of their own (core.workers, queued): Python 3.12+
            # warns at any fork of a process with threads, for locks a thread may hold; that thread only
            # writes bytes to the pipe, which the helper never touches
            warnings.simplefilter("ignore", DeprecationWarning)
            pid = os.fork()
        if pid == 0:   # the helper: its answer through its own pipe, then gone
            os.close(r)
            try:
                lifetime.die_with_parent(me)   # never outlives the renderer
                for _, other, _, _ in helpers:   # the other helpers' pipes are theirs
                    os.close(other)
                data = pickle.dumps(fn(*args), protocol=pickle.HIGHEST_PROTOCOL)
                with os.fdopen(w, "wb") as f:
                    f.write(data)
            finally:
                os._exit(0)
        os.close(w)
        helpers.append((pid, r, fn, args))
    fn, args = calls[0]
    try:
        out = [fn(*args)]
    finally:   # the helpers are read and reaped even when the first call raises
        answers = []
        for pid, r, _, _ in helpers:
            with os.fdopen(r, "rb") as f:
                answers.append(f.read())
            os.waitpid(pid, 0)
    for (_, _, fn, args), data in zip(helpers, answers):
        try:
            out.append(pickle.loads(data))
        except Exception:   # the helper failed (empty or cut answer): the call again here, errors included
            out.append(fn(*args))
    return out


def _await(task_id):
    """The worker's reply to ``task_id``, or None when the renderer is gone."""
    deadline = time.monotonic() + TIMEOUT_S
    while task_id not in _replies:
        if _worker is None or not _sent:
            return None
        left = deadline - time.monotonic()
        try:
            if left <= 0 or not _worker.conn.poll(left):
                _lost()
                return None
            _replies[_sent.pop(0)] = _worker.conn.recv()
        except (EOFError, OSError):
            _lost()
            return None
    return _replies.pop(task_id)


def _lost() -> None:
    """The renderer died or hung: kill it; what it owed is drawn in the caller."""
    global _worker
    w, _worker = _worker, None
    _sent.clear()
    if w is not None:
        w.kill()
