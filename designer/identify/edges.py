"""A raw record checked, and its steps found: the first stage of
:mod:`designer.identify.preprocess` (from a capture to the normalised step).

- :func:`check_samples`: the one check that a record is usable at all
  (finite, enough samples, increasing time, every value inside its physical
  range from :data:`designer.core.ranges.RANGES`), so no method ever meets an
  overflow, a NaN or a time scale of 1e-300 s; :func:`number_text` writes the
  numbers of its messages (and of the readers' in :mod:`designer.identify.io`);
- :func:`find_edges`: step times and amplitude from the input (with
  ``plateaus``, from the output's own levels), one :class:`Edge` a transition.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from ..core.errors import DesignError
from ..core.ranges import RANGES
from ..core.waveform import noise_sigma

__all__ = ["check_samples", "find_edges", "number_text"]

#: Steps smaller than this many noise standard deviations are refused.
MIN_STEP_SNR = 8.0
#: Fewest samples a step response may have.
MIN_SAMPLES = 10


def number_text(v) -> str:
    """A number for a message: plain digits, never a numpy repr.

    Parameters
    ----------
    v : float
        The number.

    Returns
    -------
    str
        Up to 10 significant digits.
    """
    return f"{float(v):.10g}"


def _first_outside(x, rng) -> int | None:
    """Index of the first value of ``x`` outside ``rng`` (a :class:`~designer.ranges.Range`),
    or None; min and max first, so a valid record costs no temporary array."""
    if rng.contains(float(np.min(x))) and rng.contains(float(np.max(x))):
        return None
    bad = np.nonzero((x < rng.lo) | (x > rng.hi))[0]
    if bad.size:
        return int(bad[0])
    return int(np.argmin(x)) if not rng.contains(float(np.min(x))) else int(np.argmax(x))


def check_samples(t, *signals, name: str = "capture", what=("time", "output", "input"),
                  where=None) -> None:
    """Refuse, with one line, a record no method can use.

    Checks, in this order: every value finite; at least :data:`MIN_SAMPLES`
    samples; time strictly increasing; every time inside
    ``RANGES["capture_time_s"]`` and the record's duration inside
    ``RANGES["capture_span_s"]``; every signal value inside
    ``RANGES["capture_value"]``.

    Parameters
    ----------
    t : array_like
        Time, seconds.
    *signals : array_like
        Output (and input) samples, as long as ``t``.
    name : str
        The record's name for messages (a file name).
    what : sequence of str
        What ``t`` and each signal are, for messages.
    where : callable, optional
        ``where(i, k)`` names sample ``i`` of array ``k`` (0 is ``t``), e.g.
        ``"line 12, column 2"``; default ``"sample i+1 of the <what>"``.
    """
    arrays = [np.asarray(t, float)] + [np.asarray(s, float) for s in signals]
    if where is None:
        def where(i, k):
            return f"sample {i + 1} of the {what[k]}"
    n = arrays[0].size
    if any(a.ndim != 1 or a.size != n for a in arrays):
        raise DesignError(f"{name}: time and signals must be 1-D arrays of the same length")
    for k, a in enumerate(arrays):
        if not np.isfinite(a).all():
            i = int(np.argmin(np.isfinite(a)))
            raise DesignError(f"{name}: {where(i, k)} is {number_text(a[i])}; NaN and infinite "
                              "values are not allowed (remove or interpolate those samples)")
    if n < MIN_SAMPLES:
        raise DesignError(f"{name}: only {n} samples; a step response needs at least "
                          f"{MIN_SAMPLES} (a few hundred is better)")
    t = arrays[0]
    if not (np.diff(t) > 0).all():
        i = int(np.argmin(np.diff(t) > 0))
        raise DesignError(f"{name}: time is not increasing at {where(i + 1, 0)} "
                          f"({number_text(t[i])} then {number_text(t[i + 1])}); the first "
                          "column must be time in seconds, strictly increasing")
    i = _first_outside(t, RANGES["capture_time_s"])
    if i is not None:
        RANGES["capture_time_s"].check(t[i], f"{name}: {where(i, 0)}: {what[0]} (s)",
                                       shown=number_text(t[i]))
    RANGES["capture_span_s"].check(t[-1] - t[0], f"{name}: the record's duration (last "
                                   "time - first time)", shown=number_text(t[-1] - t[0]) + " s")
    for k, a in enumerate(arrays[1:], 1):
        i = _first_outside(a, RANGES["capture_value"])
        if i is not None:
            RANGES["capture_value"].check(a[i], f"{name}: {where(i, k)}: {what[k]} value",
                                          shown=number_text(a[i]))


@dataclass
class Edge:
    """One transition of the input: time (mid-level crossing), levels before and after."""

    time: float
    index: int
    before: float
    after: float
    rest: int = 0     #: the last sample still at the level before the edge (below 25 %)

    @property
    def amplitude(self) -> float:
        return self.after - self.before


def find_edges(t, u, *, plateaus: bool = False) -> list:
    """Transitions of a two-level signal (a step or a square wave).

    Levels are the record's two ends when they differ (a single step), else
    the 1st and 99th percentiles (an input's square wave); with ``plateaus``
    (an output), the ends only when they differ by over half the record's
    swing (one step, however much it overshoots), else the medians of the
    samples below and above the midrange (a square wave, whose overshoot
    would stretch percentiles past its plateaus, or a record that ends in the
    middle of its next edge). A transition is counted when the signal moves from
    below 25 % to above 75 % of the span (or back), so noise near a level
    never makes a false edge. Each edge's time is the interpolated 50 %
    crossing; its levels are the means of the settled parts of the
    neighbouring plateaus.

    Parameters
    ----------
    t : array_like
        Times in s.
    u : array_like
        The signal at ``t``.
    plateaus : bool, optional
        The signal is an output (levels from its plateaus, see above).

    Returns
    -------
    list of Edge
        The edges found, in time order (empty when the signal does not move
        between two levels).
    """
    t = np.asarray(t, float)
    u = np.asarray(u, float)
    sigma = noise_sigma(u)
    # Levels: the record's two ends when they differ (a single step, however
    # close to either end), else robust extremes (a square wave).
    k = max(3, u.size // 200)
    a, b = float(np.median(u[:k])), float(np.median(u[-k:]))
    ends = abs(b - a) > MIN_STEP_SNR * sigma
    if plateaus and not (ends and abs(b - a) > 0.5 * float(np.ptp(u))):
        lo, hi = np.percentile(u, [1, 99])
        if hi > lo:
            mid = 0.5 * (lo + hi)
            lo, hi = float(np.median(u[u < mid])), float(np.median(u[u >= mid]))
    elif ends and abs(b - a) > 0.1 * float(np.ptp(u)):
        lo, hi = min(a, b), max(a, b)
    else:
        lo, hi = np.percentile(u, [1, 99])
    span = hi - lo
    if span <= max(MIN_STEP_SNR * sigma, 1e-12 * max(abs(lo), abs(hi), 1e-300)):
        return []
    state = np.full(u.shape, -1, dtype=np.int8)
    state[u >= lo + 0.75 * span] = 1
    state[u <= lo + 0.25 * span] = 0
    known = np.nonzero(state >= 0)[0]
    if known.size == 0:
        return []
    s = state[known]
    change = np.nonzero(np.diff(s) != 0)[0]
    mid = lo + 0.5 * span
    edges = []
    bounds = [0] + [int(known[c + 1]) for c in change] + [u.size]
    for k, c in enumerate(change):
        i_last, i_next = int(known[c]), int(known[c + 1])
        seg = u[i_last:i_next + 1]
        rising = s[c + 1] == 1
        rel = np.nonzero(seg >= mid)[0] if rising else np.nonzero(seg <= mid)[0]
        j = i_last + int(rel[0]) if rel.size else i_next
        j = max(j, 1)
        a, b = u[j - 1], u[j]
        frac = 0.5 if a == b else min(max((mid - a) / (b - a), 0.0), 1.0)
        te = float(t[j - 1] + frac * (t[j] - t[j - 1]))
        prev = u[bounds[k]:i_last + 1]
        nxt = u[i_next:bounds[k + 2]]
        # Plateau levels from their second halves, where the input has settled.
        before = float(np.mean(prev[prev.size // 2:])) if prev.size else float(a)
        after = float(np.mean(nxt[nxt.size // 2:])) if nxt.size else float(b)
        edges.append(Edge(time=te, index=j, before=before, after=after, rest=i_last))
    return edges
