"""Shared test helpers. ngspice is a hard requirement (make test installs it):
a missing simulator fails loudly here instead of skipping SPICE tests."""

import os
import shutil
import sys
from pathlib import Path

import pytest
from hypothesis import settings

# No per-example deadline: machines here are shared and noisy (speed goals live in
# benchmarks/). In CI the examples are derandomised so that a run is reproducible.
settings.register_profile("project", deadline=None, derandomize=bool(os.environ.get("CI")))
settings.load_profile("project")

ROOT = Path(__file__).resolve().parents[1]
BIN = Path(sys.executable).parent
os.environ.setdefault("MPLBACKEND", "Agg")


def script(name: str) -> str:
    """Path of an installed console script in this environment."""
    path = BIN / name
    assert path.exists(), f"console script {name} not installed in {BIN} (run make setup)"
    return str(path)


@pytest.fixture(scope="session", autouse=True)
def _ngspice_present():
    assert shutil.which("ngspice"), "ngspice is not installed: run `make setup` (apt-get install ngspice)"
