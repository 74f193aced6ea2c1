"""Test configuration.

ngspice is a hard requirement of ``make test`` (it installs it): a test marked
``spice`` fails loudly when ngspice is missing instead of skipping. Every other
test runs with ngspice out of reach (not on PATH, no shared library, both
simulator backends refusing), so a test that simulates without the marker fails
here too, and ``pytest -m "not spice"`` runs on a machine without ngspice.
"""

import os
import shutil
import sys
from pathlib import Path

import pytest
from hypothesis import settings

from designer.core.errors import SimulatorError
from designer.spice.simulate import NgspiceCli, PySpiceShared

# No per-example deadline: machines here are shared and noisy (speed goals live in
# benchmarks/). In CI the examples are derandomised so that a run is reproducible.
settings.register_profile("project", deadline=None, derandomize=bool(os.environ.get("CI")))
settings.load_profile("project")
os.environ.setdefault("MPLBACKEND", "Agg")


@pytest.fixture(scope="session")
def _path_without_ngspice(tmp_path_factory):
    """PATH for subprocesses with every program but ngspice (links to the real ones)."""
    folder = tmp_path_factory.mktemp("path-without-ngspice")
    for d in os.environ.get("PATH", "").split(os.pathsep):
        if not os.path.isdir(d):
            continue
        for entry in os.scandir(d):
            target = folder / entry.name
            if entry.name != "ngspice" and not os.path.lexists(target):
                target.symlink_to(entry.path)
    return os.pathsep.join([str(Path(sys.executable).parent), str(folder)])


def _no_simulator(self, deck):
    raise SimulatorError("this test simulates: mark it with @pytest.mark.spice")


@pytest.fixture(autouse=True)
def _ngspice_only_for_spice_tests(request, monkeypatch):
    if request.node.get_closest_marker("spice"):
        assert shutil.which("ngspice"), "ngspice is not installed: run `make setup` (apt-get install ngspice)"
        return
    monkeypatch.setenv("PATH", request.getfixturevalue("_path_without_ngspice"))
    monkeypatch.setenv("NGSPICE_LIBRARY_PATH", "/nonexistent/libngspice.so")
    monkeypatch.setattr(NgspiceCli, "run", _no_simulator)
    monkeypatch.setattr(PySpiceShared, "run", _no_simulator)
