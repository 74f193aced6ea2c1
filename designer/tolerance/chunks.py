"""A chunk of a Monte Carlo, the unit every pool runs (:mod:`designer.tolerance.runner`'s local and
process pools, :mod:`designer.tolerance.cluster`'s Dask pool): the task that draws and evaluates
samples start .. stop - 1, and the error a chunk lost twice is. Its own module so that the pools
share it without importing one another."""

from __future__ import annotations

from ..core.errors import SimulatorError

__all__ = ["run_chunk", "lost_twice"]


def run_chunk(evaluate, context, draw, start: int, stop: int) -> dict:
    """One chunk's task: samples start .. stop - 1 drawn, then evaluated.

    Parameters
    ----------
    evaluate : callable
        The engine, ``evaluate(context, values) -> {figure: array}``.
    context
        What the engine needs besides the values (picklable).
    draw : designer.tolerance.runner.Draw
        How the samples are drawn.
    start, stop : int
        The chunk's sample range [start, stop).

    Returns
    -------
    dict
        ``{"values": {designator: array}, "figures": {figure: array}}``.
    """
    values = draw.values(start, stop)
    return {"values": values, "figures": evaluate(context, values)}


def lost_twice(start: int, stop: int, why: str) -> SimulatorError:
    """The error of a chunk whose worker was lost on its second run too.

    Parameters
    ----------
    start, stop : int
        The chunk's sample range [start, stop).
    why : str
        What ended the second run.

    Returns
    -------
    SimulatorError
        The error to raise (exit status 3).
    """
    return SimulatorError(f"Monte Carlo: the chunk of samples {start}..{stop - 1} was lost twice ({why})")
