"""How a command and the processes it starts end: nothing outlives it,
however it is stopped.

- **Signals** (:func:`install`, done first by every console script): SIGINT,
  SIGTERM and SIGHUP are handled alike: the first raises :class:`Interrupted`
  (a :class:`KeyboardInterrupt`, so every ``finally`` on the way removes its
  temporaries and kills its workers) and the command ends with one line and
  the status a shell reports for that signal, 128 + its number (130, 143,
  129). Later signals are ignored while that clean-up runs. A handler that
  ran where Python cannot raise (a weakref callback inside the import
  machinery: Python prints "Exception ignored" and goes on) delivers the
  signal again a millisecond later, through SIGALRM (:func:`_unraisable`).
- **Inside native code** (:func:`native`): ngspice's shared library calls back
  into Python while it simulates, and an exception raised in such a callback is
  printed and swallowed by cffi, so the run would go on to write its bundle. A
  signal that arrives there ends the process at once instead
  (:func:`emergency`): the one line, the registered clean-ups (:func:`on_exit`:
  the renderer, worker processes), then ``os._exit``. Nothing is half-written
  then: no file is being written while ngspice runs. A handler that must raise
  something else there (the web worker's cancel) leaves it for the block's end
  (:func:`after_native`): raised as the library's current command returns.
- **Children die with their parent** (:func:`die_with_parent`, :func:`preexec`
  for a subprocess): every worker, renderer, drawing helper and
  ``ngspice -b`` asks Linux for SIGKILL when its parent dies
  (``prctl(PR_SET_PDEATHSIG)``, kept across ``exec``), so a SIGKILLed command
  leaves no process behind either; a parent that died before the request is
  noticed by the child, which exits.
- **Temporary folders name their owner** (:func:`owned_prefix`): ``designer-sim-PID-*``,
  ``designer-web-PID-*``; a SIGKILLed process cannot remove its own, so the next
  ``designer-web`` removes those of processes that are gone (:func:`remove_stale`), never a
  live process's or another user's.
- **A short end** (:func:`finish`, every console script once its command returned): the
  streams flushed, Python's own exit steps (threads joined, ``atexit``), then ``os._exit``,
  without the teardown of every imported module (0.12 s of a short run after ``import
  distributed``; bench_tolerance).
"""

from __future__ import annotations

import ctypes
import functools
import os
import re
import shutil
import signal
import sys
from contextlib import contextmanager

__all__ = ["Interrupted", "WORDS", "after_native", "die_with_parent", "finish", "forget", "install", "interruption",
           "native", "on_exit", "owned_prefix", "preexec", "quiet", "remove_stale", "reset_in_child", "status_of",
           "to_devnull", "words_of"]

SIGNALS = (signal.SIGINT, signal.SIGTERM, signal.SIGHUP)
#: what the one line says for each signal
WORDS = {signal.SIGINT: "interrupted", signal.SIGTERM: "terminated (SIGTERM)", signal.SIGHUP: "hung up (SIGHUP)"}
_PR_SET_PDEATHSIG = 1


class Interrupted(KeyboardInterrupt):
    """The command was told to stop by ``signum``; :attr:`status` is 128 + it."""

    def __init__(self, signum: int = signal.SIGINT):
        super().__init__(WORDS.get(signum, f"signal {signum}"))
        self.signum = signum

    @property
    def status(self) -> int:
        return 128 + self.signum


def interruption(exc: BaseException):
    """The :class:`KeyboardInterrupt` that ``exc`` is or stands for, or None: after a stop
    signal, an error raised by C code the signal interrupted (numpy's extension import
    fails with ImportError) is the signal in disguise.

    Parameters
    ----------
    exc : BaseException
        What was raised.

    Returns
    -------
    KeyboardInterrupt or None
        The interruption.
    """
    if isinstance(exc, KeyboardInterrupt):
        return exc
    return Interrupted(_received) if _received is not None else None


def status_of(exc: BaseException) -> int:
    """The exit status for an interruption (a plain KeyboardInterrupt is Ctrl-C: 130).

    Parameters
    ----------
    exc : BaseException
        The interruption.

    Returns
    -------
    int
        The exit status (128 + the signal's number).
    """
    return exc.status if isinstance(exc, Interrupted) else 128 + signal.SIGINT


def words_of(exc: BaseException) -> str:
    """How an interruption is told: the stop signal's words (``interrupted`` for Ctrl-C).

    Parameters
    ----------
    exc : BaseException
        The interruption.

    Returns
    -------
    str
        The words.
    """
    return WORDS.get(getattr(exc, "signum", signal.SIGINT), "interrupted")


_prog = None
_received = None
_native = 0
_cleanups: list = []
_after_native: list = []


def install(prog: str) -> None:
    """Handle SIGINT, SIGTERM and SIGHUP as described above, for command ``prog``.

    Parameters
    ----------
    prog : str
        The command's name, for the message.
    """
    global _prog
    _prog = prog
    _resolve_prctl()   # before any fork: a child then only calls it
    for s in SIGNALS:
        signal.signal(s, _handler)
    sys.unraisablehook = functools.partial(_unraisable, sys.unraisablehook)


def _unraisable(previous, unraisable) -> None:
    """A stop signal whose handler ran where Python cannot raise (a weakref callback of the
    import machinery, a ``__del__``): printed as "Exception ignored" and lost. Deliver it
    again instead, to be raised at the next ordinary instruction; anything else as before."""
    exc = unraisable.exc_value
    if not isinstance(exc, Interrupted):
        previous(unraisable)
        return
    # a timer, not the signal itself: raised now it would land in this hook again
    signal.signal(signal.SIGALRM, functools.partial(_redeliver, exc.signum))
    signal.setitimer(signal.ITIMER_REAL, 0.001)


def _redeliver(signum, _alarm, _frame):
    raise Interrupted(signum)


def quiet() -> None:
    """The command's work is done: block the signals for the last instants (its files
    are whole; a signal now changes nothing, and must not print a traceback)."""
    try:
        signal.pthread_sigmask(signal.SIG_BLOCK, SIGNALS)
    except (AttributeError, OSError, ValueError):   # pragma: no cover - not POSIX
        pass


def finish(status: int):
    """End the process with ``status`` once the command returned: its files are whole (written
    to temporaries and renamed) and closed. Does what a normal exit does that matters (flush
    stdout and stderr, join the threads that are not daemons and the thread pools, run the
    ``atexit`` handlers: multiprocessing's children, the fork server's kill), then ``os._exit``,
    skipping only the interpreter's teardown of its modules and objects. A reader that closed
    the pipe early (``| head``) is their choice: stdout goes to /dev/null first, as at a
    normal exit.

    Parameters
    ----------
    status : int
        The exit status.
    """
    import atexit
    import threading

    def flush():
        for stream in (sys.stdout, sys.stderr):
            try:
                stream.flush()
            except (OSError, ValueError):   # a closed pipe or stream: nothing more can reach it
                to_devnull(stream)

    flush()
    shutdown = getattr(threading, "_shutdown", None)    # what Python runs first at exit (CPython's)
    if shutdown is not None and threading.current_thread() is threading.main_thread():
        shutdown()
    atexit._run_exitfuncs()     # prints a failing handler's error, as Python does, and goes on
    flush()                     # what the handlers printed
    os._exit(status)


def to_devnull(stream) -> None:
    """Point ``stream``'s file descriptor at /dev/null: its reader left (``| head``), and a later
    flush (Python's own at exit) must not print "Exception ignored".

    Parameters
    ----------
    stream : file object
        ``sys.stdout`` or ``sys.stderr``.
    """
    try:
        os.dup2(os.open(os.devnull, os.O_WRONLY), stream.fileno())
    except (OSError, ValueError):
        pass


def _handler(signum, frame):
    global _received
    _received = signum
    for s in SIGNALS:   # one stop: the clean-up that follows runs undisturbed
        signal.signal(s, signal.SIG_IGN)
    if _native:
        emergency(signum)
    raise Interrupted(signum)


def on_exit(fn) -> None:
    """Run ``fn()`` when :func:`emergency` ends the process (kill a renderer, workers).

    Parameters
    ----------
    fn : callable
        Called without arguments.
    """
    if fn not in _cleanups:
        _cleanups.append(fn)


def forget(fn) -> None:
    """No longer run ``fn`` at an emergency exit (:func:`on_exit`).

    Parameters
    ----------
    fn : callable
        A function :func:`on_exit` was given.
    """
    if fn in _cleanups:
        _cleanups.remove(fn)


@contextmanager
def native():
    """The block runs native code that may call back into Python (ngspice's shared library)."""
    global _native
    _native += 1
    try:
        yield
    finally:
        _native -= 1
        if not _native and _after_native:   # what a signal that landed inside it left to do (after_native)
            todo = list(_after_native)
            _after_native.clear()
            for fn in todo:
                fn()


def after_native(fn) -> None:
    """Call ``fn()`` as the :func:`native` block running now ends, before its caller goes on: a signal
    handler that runs inside ngspice's callbacks (where cffi would print and swallow what it raises) leaves
    its exception to be raised there (ngspice's shared library returns between the commands of a Monte
    Carlo's loop, a signal's handler may never run outside it).

    Parameters
    ----------
    fn : callable
        Called without arguments (it may raise).
    """
    if fn not in _after_native:
        _after_native.append(fn)


def in_native() -> bool:
    """Whether a :func:`native` block is running (an exception raised now may land in a callback of
    ngspice's, where cffi prints and swallows it).

    Returns
    -------
    bool
        True inside :func:`native`.
    """
    return _native > 0


def emergency(signum: int) -> None:
    """End the process now: the one line, the clean-ups, exit 128 + ``signum``."""
    try:
        os.write(2, f"{_prog or os.path.basename(sys.argv[0])}: error: {WORDS.get(signum, 'interrupted')}\n"
                 .encode())
    except OSError:
        pass
    for fn in list(_cleanups):
        try:
            fn()
        except BaseException:   # noqa: BLE001 - nothing may stop the exit
            pass
    os._exit(128 + signum)


def reset_in_child() -> None:
    """In a forked child: the default dispositions (a kill of the child kills it,
    without a line from a command it is not) and no inherited clean-ups."""
    global _native, _received
    _native, _received = 0, None
    _cleanups.clear()
    _after_native.clear()
    for s in (*SIGNALS, signal.SIGALRM):
        signal.signal(s, signal.SIG_DFL)
    try:
        signal.pthread_sigmask(signal.SIG_UNBLOCK, SIGNALS)
    except (AttributeError, OSError, ValueError):   # pragma: no cover
        pass


_prctl = None


def _resolve_prctl():
    global _prctl
    if _prctl is None and sys.platform.startswith("linux"):
        try:
            _prctl = ctypes.CDLL(None, use_errno=True).prctl
        except (OSError, AttributeError):   # pragma: no cover - no libc prctl
            _prctl = False
    return _prctl


def die_with_parent(parent_pid: int) -> None:
    """In a forked child: be killed when the parent dies; exit now if it already has.

    Parameters
    ----------
    parent_pid : int
        The parent's process id.
    """
    fn = _resolve_prctl()
    if fn:
        fn(_PR_SET_PDEATHSIG, signal.SIGKILL, 0, 0, 0)
    if os.getppid() != parent_pid:
        os._exit(1)


def preexec():
    """The ``preexec_fn`` of a subprocess (``ngspice -b``): :func:`die_with_parent`
    for this process, with the libc call resolved now, in the parent (the child
    only calls it).

    Returns
    -------
    callable or None
        The function the child calls, or None where the libc call is not found.
    """
    return functools.partial(die_with_parent, os.getpid()) if _resolve_prctl() else None


#: the temporary folders named by :func:`owned_prefix`: their kind and their owner's pid
_OWNED = re.compile(r"^designer-(?:web|sim|init)-(\d+)-")


def owned_prefix(kind: str) -> str:
    """The prefix of a temporary folder of this process (``tempfile.mkdtemp(prefix=...)``):
    ``designer-KIND-PID-``, so that :func:`remove_stale` can tell when its owner is gone.

    Parameters
    ----------
    kind : str
        What the folder is for.

    Returns
    -------
    str
        The prefix.
    """
    return f"designer-{kind}-{os.getpid()}-"


def _alive(pid: int) -> bool:
    try:
        os.kill(pid, 0)
    except ProcessLookupError:
        return False
    except OSError:   # alive, another user's
        return True
    return True


def remove_stale(folder: str) -> list:
    """Remove the folders of ``folder`` named by :func:`owned_prefix` whose owner process is gone
    (left by a SIGKILL, a crash, a power cut), this user's only; returns their names. A folder
    whose pid is alive is kept, whoever has that pid now: a reused pid keeps it until that
    process is gone too.

    Parameters
    ----------
    folder : str
        The folder (the system's temporary folder).

    Returns
    -------
    list of str
        The names of the folders removed.
    """
    removed = []
    try:
        entries = list(os.scandir(folder))
    except OSError:
        return removed
    for entry in entries:
        m = _OWNED.match(entry.name)
        if m is None or int(m.group(1)) == os.getpid():
            continue
        try:
            st = entry.stat(follow_symlinks=False)
        except OSError:
            continue
        import stat
        if not stat.S_ISDIR(st.st_mode) or st.st_uid != os.getuid() or _alive(int(m.group(1))):
            continue
        shutil.rmtree(entry.path, ignore_errors=True)
        removed.append(entry.name)
    return removed
