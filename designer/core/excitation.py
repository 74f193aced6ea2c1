"""Inputs other than a step for a simulated capture (``simulate-capture
--input``): the identification experiments of issue 28, each as the corners of
a piecewise-linear source (ngspice's PWL) that the simulation plays and the
record samples.

- ``prbs``: a maximum-length sequence (:func:`designer.core.prbs.mls`,
  scipy's m-sequence; seed 003 section 2.4), its clock and bits chosen for the
  plant by make-prbs' own rules (:func:`designer.core.prbs.plan_for_plant`)
  unless given;
- ``random-binary``: a random binary signal (the DaISy dryer's input: at each
  clock tick it switches with probability ``p``), its switches drawn from
  ``numpy.random.default_rng([seed, 1])`` (the noise uses ``default_rng(seed)``:
  independent streams from the one recorded seed);
- ``chirp``: a logarithmic sine sweep from ``f_start`` to ``f_stop`` over the
  record, u = A (1 - cos phi(t)) / 2 (at rest at 0 with zero slope when it
  starts), phi(t) = 2 pi f0 T (e^(t ln(f1/f0)/T) - 1) / ln(f1/f0)
  (the exponential sweep of Farina, AES 108th convention, 2000);
- a recorded input: ``time,value`` rows, each value held from its time on
  (make-prbs' ``prbs.csv`` reads as it plays).

A held level changes in :data:`EDGE_FRACTION` of the sample interval, ending on
its clock tick; every input starts from 0 (the plant at rest), a clocked one's
first level reached at the second sample, and its ticks fall on samples when
the clock is a whole number of sample intervals (the default): each sample of
u is the level held from it on, the zero-order hold an output-error fit
assumes (:func:`designer.identify.outputerror.simulate`). The chirp's corners
are its samples (a first-order hold between them).
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from .errors import DesignError
from .prbs import mls
from .units import format_eng

__all__ = ["INPUT_KINDS", "EDGE_FRACTION", "MAX_CORNERS", "Excitation", "held", "prbs_input",
           "random_binary_input", "chirp_input", "file_input"]

#: the inputs simulate-capture makes (a file name is the fifth)
INPUT_KINDS = ("step", "prbs", "random-binary", "chirp")
#: a held level's change, as a fraction of the sample interval
EDGE_FRACTION = 1e-3
#: the most corners of one source (a deck of about 40 bytes each)
MAX_CORNERS = 1_000_000


@dataclass(frozen=True)
class Excitation:
    """An input as a piecewise-linear source: corners ``t`` (s, increasing) and
    ``v`` (V); ``text`` says what it is (a capture's ``#`` line), ``kind`` one of
    :data:`INPUT_KINDS` or ``file``."""

    kind: str
    t: np.ndarray
    v: np.ndarray
    text: str

    def at(self, t) -> np.ndarray:
        """The input at times ``t`` (the PWL's own interpolation; the last level held after it)."""
        return np.interp(t, self.t, self.v)


def held(levels, starts, edge_s: float, end_s: float) -> tuple:
    """Corners ``(t, v)`` of levels held from their start times, from 0 V at t = 0.

    Parameters
    ----------
    levels : array_like
        Each level, volts.
    starts : array_like
        When each is reached, seconds, increasing, the first at ``edge_s`` or later.
    edge_s : float
        How long a change takes (it ends at the level's start).
    end_s : float
        The end of the record (the last level held to it).

    Returns
    -------
    t, v : ndarray
        The corners.
    """
    lv = np.asarray(levels, float)
    st = np.asarray(starts, float)
    prev = np.r_[0.0, lv[:-1]]
    k = np.flatnonzero(lv != prev)
    t = np.empty(2 * k.size + 2)
    v = np.empty(2 * k.size + 2)
    t[0], v[0] = 0.0, 0.0
    t[1:-1:2], v[1:-1:2] = st[k] - edge_s, prev[k]
    t[2:-1:2], v[2:-1:2] = st[k], lv[k]
    t[-1], v[-1] = max(end_s, t[-2] + edge_s), lv[-1] if lv.size else 0.0
    return t, v


def _clocked(levels, clock_s: float, duration_s: float, points: int) -> tuple:
    dt = duration_s / (points - 1)
    n = min(levels.size, int(np.ceil((duration_s - dt) / clock_s)))
    if 2 * n + 2 > MAX_CORNERS:
        raise DesignError(f"the input changes up to {n:,} times in the record, more than a source of "
                          f"{MAX_CORNERS:,} corners holds: a shorter record or a slower clock")
    return held(levels[:n], dt + clock_s * np.arange(n), EDGE_FRACTION * dt, duration_s)


def prbs_input(plan, level_v: float, duration_s: float, points: int) -> Excitation:
    """The m-sequence of ``plan`` (a :class:`~designer.core.prbs.PrbsPlan`) between 0 and
    ``level_v``, repeated over the record.

    Parameters
    ----------
    plan : PrbsPlan
        Bits and clock (its levels are not used).
    level_v, duration_s, points : float, float, int
        The high level (V; the low one is 0), the record (s) and its samples.

    Returns
    -------
    Excitation
    """
    one = (mls(plan.bits).astype(float) + 1.0) * 0.5 * level_v
    reps = int(np.ceil(duration_s / plan.period_s)) + 1
    t, v = _clocked(np.tile(one, reps), plan.dt_s, duration_s, points)
    return Excitation("prbs", t, v, f"prbs: maximum-length sequence of {plan.bits} bits (N = {plan.n}), clock "
                                    f"{format_eng(plan.clock_hz, 'Hz')}, levels 0 V and {format_eng(level_v, 'V')}")


def random_binary_input(p_switch: float, clock_s: float, level_v: float, duration_s: float, points: int,
                        seed: int) -> Excitation:
    """A random binary signal between 0 and ``level_v``: at every clock tick it switches with
    probability ``p_switch`` (the first tick always, from rest to ``level_v``).

    Parameters
    ----------
    p_switch : float
        Switching probability per tick, 0 < p <= 1.
    clock_s : float
        The tick interval, seconds.
    level_v : float
        The high level, volts.
    duration_s : float
        The record, seconds.
    points : int
        Its samples.
    seed : int
        The recorded seed: the switches are ``default_rng([seed, 1])``'s draws.

    Returns
    -------
    Excitation
    """
    n = int(np.ceil(duration_s / clock_s)) + 1
    flips = np.random.default_rng([int(seed), 1]).random(n) < p_switch
    flips[0] = True
    levels = level_v * (np.cumsum(flips) % 2)
    t, v = _clocked(levels, clock_s, duration_s, points)
    return Excitation("random-binary", t, v,
                      f"random-binary: levels 0 V and {format_eng(level_v, 'V')}, switching with probability "
                      f"{p_switch:g} every {format_eng(clock_s, 's')} (numpy default_rng([{seed}, 1]))")


def chirp_input(f_start_hz: float, f_stop_hz: float, level_v: float, duration_s: float, points: int) -> Excitation:
    """A logarithmic sine sweep between 0 and ``level_v`` (see the module docstring), its corners
    on the sample grid from half a sample interval on.

    Parameters
    ----------
    f_start_hz, f_stop_hz : float
        The sweep's first and last frequency, Hz (f_start < f_stop).
    level_v, duration_s, points : float, float, int
        Its peak (V), the record (s) and its samples (the corners).

    Returns
    -------
    Excitation
    """
    tau = np.linspace(0.0, duration_s, points)
    rate = np.log(f_stop_hz / f_start_hz)
    phase = 2 * np.pi * f_start_hz * duration_s * np.expm1(tau * rate / duration_s) / rate
    v = 0.5 * level_v * (1.0 - np.cos(phase))
    return Excitation("chirp", tau, v,
                      f"chirp: logarithmic sweep {format_eng(f_start_hz, 'Hz')} to {format_eng(f_stop_hz, 'Hz')} "
                      f"over the record, between 0 V and {format_eng(level_v, 'V')} (linear between samples)")


def file_input(t, v, name: str, max_v: float) -> Excitation:
    """A recorded input: samples ``(t, v)`` of a ``time,value`` file (read by the capture reader,
    :func:`designer.identify.io.read_capture`), each value held from its time on.

    Parameters
    ----------
    t, v : array_like
        Times (s, increasing, checked by the reader) and values (V).
    name : str
        The file, for messages.
    max_v : float
        The largest |value| allowed, volts.

    Returns
    -------
    Excitation
        Its corners; the record's default length is the file's last time.

    Raises
    ------
    DesignError
        A first time below 0, a value beyond ``max_v``, a signal that never moves, too many rows.
    """
    t, v = np.asarray(t, float), np.asarray(v, float)
    if t[0] < 0:
        raise DesignError(f"{name}: the input starts at t = {t[0]:.6g} s; its times must be 0 or later (the record "
                          "starts at 0)")
    big = np.flatnonzero(np.abs(v) > max_v)
    if big.size:
        raise DesignError(f"{name}: the input's value {v[big[0]]:.6g} at t = {t[big[0]]:.6g} s is beyond "
                          f"+-{max_v:g} V")
    if np.ptp(v) == 0:
        raise DesignError(f"{name}: the input never moves (every value {v[0]:.6g}): nothing to identify from it")
    if 2 * t.size + 2 > MAX_CORNERS:
        raise DesignError(f"{name}: {t.size:,} rows, more than a source of {MAX_CORNERS:,} corners holds")
    edge = EDGE_FRACTION * float(np.min(np.diff(t)))
    starts = np.maximum(t, edge)   # the first level from rest at 0, as every other input
    ct, cv = held(v, starts, edge, float(t[-1]))
    return Excitation("file", ct, cv, f"file: {name}, {t.size} rows of time,value, each value held from its time "
                                      f"on, {t[0]:.6g} s to {t[-1]:.6g} s")
