"""Console entry points of the commands that draw build sheets (design-plant,
analyze-plant, design-pid, analyze-pid).

Each forks the renderer (:mod:`designer.report.render`) first, before numpy,
the design code and PySpice are imported, so that matplotlib's import (longer
than a plant's design and simulation) runs on the other core from the start;
then it runs the command's ``main``. Called as functions (``design_plant_main(argv)``)
the commands draw in-process instead: the files are the same.
"""

import importlib
import sys

#: the report module whose pictures each command's renderer draws
_REPORTS = {"plant": "designer.plant.report", "pid": "designer.pid.report"}


def draws(argv) -> bool:
    """Whether a command line will draw a sheet: not with ``--no-files`` (or an
    abbreviation argparse accepts), ``--help`` or ``--version``."""
    for a in argv:
        if a in ("-h", "--help", "--version") or (len(a) > len("--no-") and "--no-files".startswith(a)):
            return False
    return True


def _launch(wing: str, main: str) -> int:
    from ..report import render
    with render.ahead(draws(sys.argv[1:]), preload=(_REPORTS[wing],)):
        return getattr(importlib.import_module(f"designer.cli.{wing}"), main)()


def design_plant() -> int:
    return _launch("plant", "design_plant_main")


def analyze_plant() -> int:
    return _launch("plant", "analyze_plant_main")


def design_pid() -> int:
    return _launch("pid", "design_pid_main")


def analyze_pid() -> int:
    return _launch("pid", "analyze_pid_main")
