"""Console entry points of every command.

Each first takes over SIGINT, SIGTERM and SIGHUP (:func:`designer.core.lifetime.install`:
one line and exit 130, 143 or 129 at any instant, the imports included), then
runs the command's ``main``. The commands that draw build sheets
(design-plant, analyze-plant, design-pid, analyze-pid) fork the renderer
(:mod:`designer.report.render`) before numpy, the design code and PySpice are
imported, so that matplotlib's import (longer than a plant's design and
simulation) runs on the other core from the start. Called as functions
(``design_plant_main(argv)``) the commands draw in-process and leave the
signals alone: the files are the same. A command that returned ends through
:func:`designer.core.lifetime.finish` (the interpreter's teardown skipped).
"""

import importlib
import sys

__all__ = ["analyze_pid", "analyze_plant", "check_design", "design_filter", "design_pid", "design_plant", "draws",
           "identify", "identify_freq", "make_prbs", "simulate_capture"]

#: the report module whose pictures each command's renderer draws
_REPORTS = {"plant": ("designer.plant.report",), "pid": ("designer.pid.report",)}


def draws(argv) -> bool:
    """Whether a command line will draw a sheet: not with ``--no-files`` (or an
    abbreviation argparse accepts), ``--help`` or ``--version``.

    Parameters
    ----------
    argv : sequence of str
        The command's arguments, without the program name.

    Returns
    -------
    bool
        True when the command will draw.
    """
    for a in argv:
        if a in ("-h", "--help", "--version") or (len(a) > len("--no-") and "--no-files".startswith(a)):
            return False
    return True


def _run(prog: str, module: str, main: str, wing: str | None = None) -> int:
    from ..core import lifetime
    lifetime.install(prog)
    try:
        if wing is None:
            status = getattr(importlib.import_module(module), main)()
        else:
            from ..report import render
            with render.ahead(draws(sys.argv[1:]), preload=_REPORTS[wing]):
                status = getattr(importlib.import_module(module), main)()
    except BaseException as exc:   # before the command's own handling: an import, the renderer's start
        exc = lifetime.interruption(exc)
        if exc is None:
            raise
        try:
            print(f"{prog}: error: {lifetime.words_of(exc)}", file=sys.stderr)
        except OSError:
            pass
        return lifetime.status_of(exc)
    lifetime.quiet()
    lifetime.finish(status)     # never returns: exits with the status, without the modules' teardown


def design_plant() -> int:
    """Console script ``design-plant``: its main on ``sys.argv``, the sheet renderer forked first.

    Returns
    -------
    int
        The exit status when the command is stopped before its own handling
        (an interruption); otherwise the process exits with the command's status.
    """
    return _run("design-plant", "designer.cli.plant", "design_plant_main", "plant")


def analyze_plant() -> int:
    """Console script ``analyze-plant``: its main on ``sys.argv``, the sheet renderer forked first.

    Returns
    -------
    int
        The exit status when the command is stopped before its own handling
        (an interruption); otherwise the process exits with the command's status.
    """
    return _run("analyze-plant", "designer.cli.plant", "analyze_plant_main", "plant")


def design_pid() -> int:
    """Console script ``design-pid``: its main on ``sys.argv``, the sheet renderer forked first.

    Returns
    -------
    int
        The exit status when the command is stopped before its own handling
        (an interruption); otherwise the process exits with the command's status.
    """
    return _run("design-pid", "designer.cli.pid", "design_pid_main", "pid")


def analyze_pid() -> int:
    """Console script ``analyze-pid``: its main on ``sys.argv``, the sheet renderer forked first.

    Returns
    -------
    int
        The exit status when the command is stopped before its own handling
        (an interruption); otherwise the process exits with the command's status.
    """
    return _run("analyze-pid", "designer.cli.pid", "analyze_pid_main", "pid")


def check_design() -> int:
    """Console script ``check-design``: its main on ``sys.argv``.

    Returns
    -------
    int
        The exit status when the command is stopped before its own handling
        (an interruption); otherwise the process exits with the command's status.
    """
    return _run("check-design", "designer.cli.check", "check_design_main")


def identify() -> int:
    """Console script ``identify``: its main on ``sys.argv``.

    Returns
    -------
    int
        The exit status when the command is stopped before its own handling
        (an interruption); otherwise the process exits with the command's status.
    """
    return _run("identify", "designer.cli.identify", "identify_main")


def identify_freq() -> int:
    """Console script ``identify-freq``: its main on ``sys.argv``.

    Returns
    -------
    int
        The exit status when the command is stopped before its own handling
        (an interruption); otherwise the process exits with the command's status.
    """
    return _run("identify-freq", "designer.cli.identify", "identify_freq_main")


def simulate_capture() -> int:
    """Console script ``simulate-capture``: its main on ``sys.argv``.

    Returns
    -------
    int
        The exit status when the command is stopped before its own handling
        (an interruption); otherwise the process exits with the command's status.
    """
    return _run("simulate-capture", "designer.cli.capture", "simulate_capture_main")


def design_filter() -> int:
    """Console script ``design-filter``: its main on ``sys.argv``.

    Returns
    -------
    int
        The exit status when the command is stopped before its own handling
        (an interruption); otherwise the process exits with the command's status.
    """
    return _run("design-filter", "designer.cli.filter", "design_filter_main")


def analyze_filter() -> int:
    return _run("analyze-filter", "designer.cli.filter", "analyze_filter_main")


def make_prbs() -> int:
    """Console script ``make-prbs``: its main on ``sys.argv``.

    Returns
    -------
    int
        The exit status when the command is stopped before its own handling
        (an interruption); otherwise the process exits with the command's status.
    """
    return _run("make-prbs", "designer.cli.prbs", "make_prbs_main")
