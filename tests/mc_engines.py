"""Engines for the Monte Carlo runner's tests that must be importable by name in a Dask
worker (tests/ is on the path of every process pytest spawns): one that kills its worker
the first time, one that always does."""

import os
import signal


def dies_once(marker, values):
    """The analytic plant's figures, after killing this worker once (the marker file remembers)."""
    from designer.core import opamps
    from designer.tolerance import plant
    if not os.path.exists(marker):
        open(marker, "w").close()
        os.kill(os.getpid(), signal.SIGKILL)
    return plant.evaluate(opamps.get("LM741"), values)


def always_dies(_context, _values):
    os.kill(os.getpid(), signal.SIGKILL)
