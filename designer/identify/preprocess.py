"""From a raw capture to the normalised step response the methods work on.

The methods of seeds 000-003 all assume a clean unit step applied at t = 0
to a system at rest. A real capture has an offset, a trigger somewhere in the
record, noise, sometimes a whole square wave. This module turns it into
``t`` (time since the step), ``y`` (deviation from the pre-step baseline
divided by the input step amplitude) and ``yf`` (its settled value = static
gain), and provides the robust primitives the methods share (the waveform
readings, noise, crossing times, derivatives, are :mod:`designer.core.waveform`):

- :func:`find_edges`: step times and amplitude from the input;
- :func:`baseline` and :func:`final_value`: y0 from pre-step samples, yf from a
  settled tail (and a clear error when the record ends before settling);
- :func:`prepare_step`: all of the above, including square-wave captures
  split into their steps and averaged;
- :func:`check_samples`: the one check that a record is usable at all
  (finite, enough samples, increasing time, every value inside its physical
  range from :data:`designer.core.ranges.RANGES`), so no method ever meets an
  overflow, a NaN or a time scale of 1e-300 s.
"""

from __future__ import annotations

import math
from dataclasses import dataclass, field

import numpy as np

from ..core.errors import DesignError
from ..core.ranges import RANGES
from ..core.waveform import crossing_time, noise_sigma, quantum

#: Fraction of the post-step record used as the settled tail for yf.
TAIL_FRACTION = 0.1
#: Steps smaller than this many noise standard deviations are refused.
MIN_STEP_SNR = 8.0
#: A tail drifting by more than this fraction of the step is "not settled".
SETTLE_TOL = 0.02
#: Methods and least squares run on at most this many samples (block means).
MAX_WORK_SAMPLES = 40000
#: Fewest samples a step response may have.
MIN_SAMPLES = 10
#: Fewest samples at rest before a step for a baseline.
MIN_REST = 3


def number_text(v) -> str:
    """A number for a message: plain digits, never a numpy repr."""
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


def baseline(t, y, t_step: float) -> tuple:
    """Pre-step level y0: mean of the samples before the step.

    Returns ``(y0, n_used)``; with no pre-step sample the first sample is used
    (``n_used`` = 0 tells the caller to say so).
    """
    t = np.asarray(t, float)
    y = np.asarray(y, float)
    pre = y[t < t_step]
    if pre.size == 0:
        return float(y[0]), 0
    return float(np.mean(pre)), int(pre.size)


@dataclass(frozen=True)
class Rest:
    """The settled stretch of the output just before a step: its ``level``
    (the baseline), its ``samples``, and how far the whole pre-step record
    strays from that level (``moved``, output units)."""

    level: float
    samples: int
    moved: float


def settled_before(y_pre, sigma: float, span: float) -> Rest | None:
    """The settled stretch at the end of the pre-step samples ``y_pre``.

    Walking back from the edge, the stretch lasts while a 5-sample moving mean
    stays within max(4 sigma, :data:`SETTLE_TOL` of the step) of the level of
    the last samples: a pre-trigger record that rings or drifts earlier (a
    switching node, the previous half period) does not move the baseline.
    None when there is no sample.
    """
    y_pre = np.asarray(y_pre, float)
    n = y_pre.size
    if n == 0:
        return None
    tol = max(4.0 * sigma, SETTLE_TOL * abs(span))
    ref = float(np.median(y_pre[-min(n, 5):]))
    m = min(5, n)
    c = np.concatenate(([0.0], np.cumsum(y_pre - ref)))
    ma = (c[m:] - c[:-m]) / m                      # mean of samples i .. i+m-1
    off = np.abs(ma) > tol
    k = _last_true(off)
    start = 0 if k < 0 else k + m
    start = min(start, n - 1)
    level = float(np.mean(y_pre[start:]))
    moved = float(np.max(np.abs(ma))) if ma.size else 0.0
    return Rest(level=level, samples=n - start, moved=moved)


def _last_true(mask) -> int:
    """Index of the last True of a boolean array, -1 if none."""
    if not mask.size:
        return -1
    k = int(np.argmax(mask[::-1]))
    return mask.size - 1 - k if mask[mask.size - 1 - k] else -1


def final_value(t, y, y0: float, *, sigma: float | None = None) -> float:
    """Settled value: mean of the last ``TAIL_FRACTION`` of the record.

    Raises DesignError when the tail still drifts: its two halves differ, or
    a straight line through it changes, by more than ``SETTLE_TOL`` of the
    step (beyond what the noise explains). ``t`` and ``y`` are the post-step
    samples.
    """
    t = np.asarray(t, float)
    y = np.asarray(y, float)
    n = y.size
    m = max(4, int(n * TAIL_FRACTION))
    tail = y[-m:]
    yf = float(np.mean(tail))
    span = yf - y0
    if sigma is None:
        sigma = noise_sigma(y)
    h = m // 2
    drift = abs(float(np.mean(tail[h:]) - np.mean(tail[:h])))
    # Two earlier windows as well: a response still rising shows a larger
    # change there; noise alone gives about sigma * 2 / sqrt(m).
    prev = y[-2 * m:-m] if n >= 2 * m else y[:max(1, n - m)]
    drift_prev = abs(float(np.mean(prev)) - yf)
    allowed = SETTLE_TOL * abs(span) + 6.0 * sigma / math.sqrt(max(h, 1))
    if abs(span) > 0 and (drift > allowed or drift_prev > 2.0 * allowed):
        pct = 100.0 * max(drift, drift_prev / 2.0) / abs(span)
        raise DesignError(
            f"the record ends before the response settles: its last {100 * TAIL_FRACTION:.0f} % "
            f"still moves by {pct:.1f} % of the step (allowed {100 * SETTLE_TOL:.0f} %); "
            "capture a longer record after the step (at least 5 settling times)")
    return yf


def block_mean(t, y, max_samples: int = MAX_WORK_SAMPLES) -> tuple:
    """Reduce a long record by averaging blocks of samples (anti-aliased decimation).

    Block means of time keep the samples centred, so no delay is introduced.
    """
    t = np.asarray(t, float)
    y = np.asarray(y, float)
    n = t.size
    if n <= max_samples:
        return t, y
    m = int(math.ceil(n / max_samples))
    k = n // m
    tb = t[:k * m].reshape(k, m).mean(axis=1)
    yb = y[:k * m].reshape(k, m).mean(axis=1)
    return tb, yb


@dataclass
class PreparedStep:
    """The normalised step response and how it was obtained.

    ``t`` is time since the step (s), ``y`` the response deviation divided by
    the input amplitude (so it settles at ``yf`` = static gain), both possibly
    block-averaged to at most MAX_WORK_SAMPLES. ``t_raw``/``y_raw`` are the
    full-resolution data the IAE/ISE are computed against (original units, the
    step at ``t_step``).

    ``sigma`` is the noise of the output (its units): at least the rounding
    noise of its quantisation step ``lsb``, and for an averaged square wave
    the spread of the averaged plateaus (switching ripple, hum).
    ``work_sigma`` is the noise of ``y`` as the methods must assume it.
    ``dt`` is the record's sample interval. ``n_steps`` edges were averaged
    (``rising`` and ``falling`` say which way they went; only one way is
    averaged, the other is compared with it). ``nonlinear`` says why the
    record is not a linear plant's response ("" when nothing says so).
    """

    t: np.ndarray
    y: np.ndarray
    yf: float
    t_step: float
    amplitude: float
    y0: float
    y_final: float
    sigma: float
    t_raw: np.ndarray
    y_raw: np.ndarray
    n_steps: int = 1
    notes: list = field(default_factory=list)
    dt: float = math.nan
    work_sigma: float = 0.0
    lsb: float = 0.0
    nonlinear: str = ""
    rising: int = 0
    falling: int = 0
    window: tuple | None = None

    @property
    def gain(self) -> float:
        return self.yf

    def to_dict(self) -> dict:
        return {"step_time_s": self.t_step, "step_amplitude": self.amplitude,
                "y0": self.y0, "y_final": self.y_final, "gain": self.yf,
                "noise_sigma": self.sigma,
                "noise_pct_of_step": (100.0 * self.sigma / abs(self.y_final - self.y0)
                                      if self.y_final != self.y0 else None),
                "quantisation_step": self.lsb or None,
                "sample_interval_s": self.dt,
                "samples": int(self.t_raw.size), "work_samples": int(self.t.size),
                "steps_averaged": self.n_steps, "edges_averaged": self.n_steps,
                "rising_edges": self.rising, "falling_edges": self.falling,
                "window_s": list(self.window) if self.window else None,
                "nonlinear": self.nonlinear or None, "notes": list(self.notes)}


def _check_step(y0, yf, sigma, what="the response"):
    span = yf - y0
    if span == 0 or abs(span) < MIN_STEP_SNR * sigma:
        ratio = abs(span) / sigma if sigma > 0 else 0.0
        raise DesignError(
            f"no usable step in {what}: the change from the baseline ({y0:.4g}) to the final "
            f"value ({yf:.4g}) is {ratio:.1f} noise standard deviations; at least "
            f"{MIN_STEP_SNR:.0f} are needed (use a larger step or average captures)")
    RANGES["output_step"].check(abs(span), f"the size of the step in {what} (final value - "
                                "baseline)", shown=number_text(span))


def _check_amplitude(amp: float, what: str) -> float:
    """``amp`` if its size is inside ``RANGES["step_amplitude"]`` (either sign)."""
    if not (math.isfinite(amp) and amp != 0):
        raise DesignError(f"{what} must be a non-zero number; got {number_text(amp)}")
    RANGES["step_amplitude"].check(abs(amp), f"the size of {what} (either sign)",
                                   shown=number_text(amp))
    return float(amp)


def check_window(window, t=None) -> tuple:
    """``(t0, t1)`` of ``--window``: both inside ``RANGES["capture_time_s"]``,
    t0 < t1, and (given the record's times ``t``) holding at least
    :data:`MIN_SAMPLES` samples."""
    t0, t1 = (float(v) for v in window)
    for v, what in ((t0, "start"), (t1, "end")):
        RANGES["capture_time_s"].check(v, f"the window's {what} (s)", shown=number_text(v))
    if not t0 < t1:
        raise DesignError(f"the window must start before it ends; got {number_text(t0)} s to "
                          f"{number_text(t1)} s")
    if t is not None:
        n = int(np.searchsorted(t, t1, "right") - np.searchsorted(t, t0, "left"))
        if n < MIN_SAMPLES:
            raise DesignError(f"the window {number_text(t0)} s to {number_text(t1)} s holds "
                              f"{n} samples of the record [{t[0]:.6g}, {t[-1]:.6g}] s; at least "
                              f"{MIN_SAMPLES} are needed")
    return t0, t1


def prepare_step(t, y, u=None, *, step_time: float | None = None,
                 step_amplitude: float | None = None, window=None) -> PreparedStep:
    """Normalise a capture to a unit step response (see module docstring).

    Parameters
    ----------
    t, y : array_like
        Time (s, strictly increasing) and output.
    u : array_like, optional
        Input; its edges give the step time(s) and amplitude. Several edges (a
        square wave) are averaged coherently, rising and falling apart.
    step_time, step_amplitude : float, optional
        When there is no input column (or to override it). Without a step
        time, the output's own edges give it: the last sample at rest before
        the output moves, or t = 0 when the output is still at rest there (the
        scope's trigger); the amplitude defaults to 1.
    window : (float, float), optional
        Use only the samples from ``window[0]`` to ``window[1]`` seconds.
    """
    t = np.asarray(t, float)
    y = np.asarray(y, float)
    check_samples(t, y, *([] if u is None else [u]))
    notes = []
    if window is not None:
        t0, t1 = check_window(window, t)
        keep = slice(int(np.searchsorted(t, t0, "left")), int(np.searchsorted(t, t1, "right")))
        t, y = t[keep], y[keep]
        u = None if u is None else np.asarray(u, float)[keep]
        window = (t0, t1)
        notes.append(f"window {t0:.6g} s to {t1:.6g} s: {t.size} samples used")
    if step_amplitude is not None:
        _check_amplitude(step_amplitude, "the step amplitude")
    if step_time is not None:
        RANGES["capture_time_s"].check(step_time, "the step time", shown=number_text(step_time))
    lsb = quantum(y)
    if step_time is not None:
        prep = _given_step(t, y, u, float(step_time), step_amplitude, notes)
    elif u is not None:
        edges = find_edges(t, u)
        if not edges:
            raise DesignError("no step in the input column: it never moves between two levels "
                              "by more than the noise; give --step-time (and --step-amplitude) "
                              "or check the column order (t,u,y)")
        prep = _from_edges(t, y, edges, step_amplitude, notes, source="input",
                           first_sample_ok=False)
    else:
        edges = find_edges(t, y, plateaus=True)
        if edges:
            try:
                prep = _from_edges(t, y, edges, step_amplitude, notes, source="output",
                                   first_sample_ok=window is None)
            except DesignError:
                if len(edges) >= 2:
                    _check_periodic_steps(y)
                raise
        else:
            prep = _single(t, y, *_trigger_step(t, notes), _amp_or_one(step_amplitude, notes),
                           t.size, notes)
    prep.lsb, prep.window = lsb, window
    if lsb:
        prep.notes.append(f"quantised output: one step (LSB) is {lsb:.4g}; noise taken as at "
                          f"least LSB/sqrt(12) = {lsb / math.sqrt(12.0):.3g}")
    # white noise only: a ripple's spread would pass any shape for a straight line
    prep.nonlinear = nonlinearity(prep.t, prep.y, prep.yf, noise_sigma(prep.y), prep.lsb
                                  / abs(prep.amplitude))
    if prep.nonlinear:
        prep.notes.append(f"non-linear record: {prep.nonlinear}")
    return prep


#: An output that spends more than this fraction of a periodic record between
#: the quarter and three-quarter levels of its swing is no step response.
MAX_TRANSITION_FRACTION = 0.25


def _check_periodic_steps(y) -> None:
    """Refuse an output whose repeated swings are not step responses (a sine,
    a triangle; a sine spends a third of its time there) when none of its
    edges settles: a square wave's response sits on its plateaus most of the time."""
    lo, hi = np.percentile(y, [1, 99])
    span = hi - lo
    if span <= 0:
        return
    between = np.count_nonzero((y > lo + 0.25 * span) & (y < lo + 0.75 * span)) / y.size
    if between > MAX_TRANSITION_FRACTION:
        raise DesignError(
            f"no step found: the output swings back and forth but spends {100 * between:.0f} % "
            "of the record between a quarter and three quarters of its swing (a sine or a "
            "triangle wave, not the response to a step or a square wave); capture a step "
            "response, or give --step-time")


def _amp_or_one(step_amplitude, notes) -> float:
    if step_amplitude is not None:
        return float(step_amplitude)
    notes.append("no input amplitude: gain is per unit input (pass --step-amplitude)")
    return 1.0


def _trigger_step(t, notes) -> tuple:
    """(step time, index) by the scope convention: t = 0, else the first sample."""
    if t[0] < 0.0 <= t[-1]:
        notes.append("no input column: step assumed at t = 0 (the trigger); "
                     "pass --step-time otherwise")
        return 0.0, int(np.searchsorted(t, 0.0, "left"))
    notes.append(f"no input column: step assumed at the first sample, t = {t[0]:.6g} s; "
                 "pass --step-time otherwise")
    return float(t[0]), 0


def _given_step(t, y, u, t_step, step_amplitude, notes) -> PreparedStep:
    """A step at a given time: the amplitude given, or from the input around it,
    or 1; without an input the record is cut where the output's next opposite
    edge starts."""
    if not (math.isfinite(t_step) and t[0] <= t_step < t[-1]):
        raise DesignError(f"step time {number_text(t_step)} s is outside the record "
                          f"[{t[0]:.6g}, {t[-1]:.6g}] s")
    if step_amplitude is not None:
        amp = float(step_amplitude)
    elif u is not None:
        amp = _check_amplitude(_amplitude_from_u(t, u, t_step), "the input column's step")
    else:
        amp = _amp_or_one(None, notes)
    i0 = int(np.searchsorted(t, t_step, "left"))
    end = t.size
    if u is None:
        edges = [e for e in find_edges(t, y, plateaus=True) if e.time > t_step]
        if len(edges) >= 2:
            # a linear plant's return mirrors its rise: the next input edge is
            # as far before the return's 50 % crossing as the step is before
            # the rise's
            e = edges[0]
            sgn = 1.0 if e.amplitude > 0 else -1.0
            i = int(np.searchsorted(t, t_step))
            # 50 % of the levels actually reached: before the step, and the plateau
            base = float(np.median(y[:i])) if i else float(y[0])
            top = float(np.median(y[(e.index + edges[1].rest) // 2:max(edges[1].rest,
                                                                       e.index + 1)]))
            half = sgn * 0.5 * (base + top)
            rise = crossing_time(t, sgn * y, half, start=i)
            j = int(np.searchsorted(t, rise))
            back = crossing_time(t, -sgn * y, -half, start=max(j, edges[1].rest))
            cut = t_step + (back - rise) if math.isfinite(back - rise) else \
                t_step + (edges[1].time - e.time)
            end = int(np.searchsorted(t, cut, "left"))
            notes.append(f"the output returns to its baseline: another input edge near "
                         f"t = {cut:.6g} s (a square wave?); the record is cut there "
                         "(give the input column to average every step)")
            if end - i0 < MIN_SAMPLES:
                raise DesignError("fewer than 10 samples between the step and the next edge")
    return _single(t, y, t_step, i0, amp, end, notes)


def _single(t, y, t_step, i0, amp, end, notes, rest: Rest | None = None) -> PreparedStep:
    """One step at ``t_step`` (first sample after it ``i0``), the record used up
    to index ``end``: baseline, final value, normalisation."""
    sigma = noise_sigma(y[i0:end])
    if rest is None:
        pre = y[:i0]
        if pre.size == 0:
            notes.append("no samples before the step: baseline taken from the first sample")
            y0 = float(y[0])
        else:
            span = float(np.mean(y[max(i0, end - max(4, (end - i0) // 10)):end])) - pre[-1]
            rest = settled_before(pre, sigma, span)
    if rest is not None:
        y0 = rest.level
        _rest_note(rest, y[:i0].size, t[i0] - t[max(i0 - rest.samples, 0)], notes,
                   y[i0:end], sigma)
    tp, yp = t[i0:end] - t_step, y[i0:end]
    if tp.size < MIN_SAMPLES:
        raise DesignError("fewer than 10 samples after the step; capture more of the response")
    yf = final_value(tp, yp, y0, sigma=sigma)
    _check_step(y0, yf, sigma)
    yn = (yp - y0) / amp
    tw, yw = block_mean(tp, yn)
    return PreparedStep(t=tw, y=yw, yf=(yf - y0) / amp, t_step=t_step, amplitude=float(amp),
                        y0=y0, y_final=yf, sigma=sigma, t_raw=t[:end], y_raw=y[:end],
                        notes=notes, dt=_interval(t), work_sigma=noise_sigma(yw),
                        rising=int(amp * (yf - y0) > 0), falling=int(amp * (yf - y0) < 0))


def _rest_note(rest: Rest, n_pre: int, duration: float, notes, yp, sigma) -> None:
    """Say so when the pre-step record is not flat, refuse when no stretch of it is."""
    span = abs(float(np.mean(yp[-max(4, yp.size // 10):])) - rest.level) or 1.0
    if rest.samples < MIN_REST and n_pre >= MIN_REST:
        raise DesignError(f"the output is still moving just before the step (no {MIN_REST} "
                          "samples at rest before it): no settled baseline; start the step "
                          "from rest, or choose the stretch with --window")
    if rest.samples < n_pre and rest.moved > max(4.0 * sigma, SETTLE_TOL * span):
        notes.append(f"the output before the step is not flat (it strays by "
                     f"{100 * rest.moved / span:.0f} % of the step): baseline from the "
                     f"{rest.samples} samples ({duration:.3g} s) at rest just before the edge")


def _interval(t) -> float:
    """The sample interval: the median spacing (of at most 10000 samples)."""
    return float(np.median(np.diff(t[:10001]))) if t.size > 1 else math.nan


@dataclass
class _Step:
    """One edge of a square wave: where its response starts (``i0``, at
    ``t_step``), where the next edge's starts (``end``), its input amplitude
    (signed), and ``align``, the time it is aligned on for averaging."""

    edge: Edge
    i0: int
    end: int
    amp: float
    align: float
    t_step: float
    rising: bool


def _from_edges(t, y, edges, step_amplitude, notes, *, source, first_sample_ok) -> PreparedStep:
    """One edge or a square wave, from the input's edges or the output's own."""
    steps = _steps(t, y, edges, step_amplitude, source)
    if source == "output" and step_amplitude is None:
        notes.append("no input amplitude: gain is per unit input, the input taken to step the "
                     "way the output went (pass --step-amplitude)")
    if len(edges) == 1:
        s = steps[0]
        return _single_edge(t, y, s, source, notes, first_sample_ok, t.size)
    spacing = float(np.median(np.diff([e.time for e in edges])))
    full = [s for s in steps if _complete(t, s, spacing)]
    rising = [s for s in full if s.rising]
    falling = [s for s in full if not s.rising]
    chosen = rising or falling
    if not chosen:
        raise DesignError("the square-wave capture has no complete step with a settled "
                          "level before it; capture at least one full period")
    if len(chosen) == 1:
        s = chosen[0]
        prep = _single_edge(t, y, s, source, notes, first_sample_ok, s.end)
        if s.end < t.size:
            notes.append(f"the record is cut at the next edge, t = {t[s.end]:.6g} s")
        return prep
    other = falling if chosen is rising else rising
    return _average(t, y, chosen, other, source, spacing, notes)


def _steps(t, y, edges, step_amplitude, source) -> list:
    """Every edge as a :class:`_Step`: from the input, the step starts at the
    edge; from the output, at its last sample at rest before it moves."""
    out = []
    for k, e in enumerate(edges):
        nxt = edges[k + 1] if k + 1 < len(edges) else None
        if source == "input":
            amp = (math.copysign(step_amplitude, e.amplitude) if step_amplitude is not None
                   else e.amplitude)
            i0, t_step = e.index, e.time
            end = nxt.index if nxt else t.size
        else:
            # no input: a given amplitude as given, else a unit step the way the output went
            amp = (float(step_amplitude) if step_amplitude is not None
                   else math.copysign(1.0, e.amplitude))
            i0 = _departure(t, y, e, edges[k - 1].index if k else 0)
            t_step = float(t[max(i0 - 1, 0)])
            end = _departure(t, y, nxt, e.index) if nxt else t.size
        out.append(_Step(e, i0, end, amp, e.time, t_step, e.amplitude > 0))
    return out


#: Windows (of blocks) compared to find where the output leaves its rest.
REST_WINDOW = 10
#: Blocks per 25 %-to-50 % stretch of an edge: the block size scales with the edge.
BLOCKS_PER_EDGE = 20


def _departure(t, y, e: Edge, lo: int) -> int:
    """The first sample of the output's move at edge ``e`` (searching from ``lo``).

    The samples up to the edge's last one below 25 % are averaged in blocks
    (a twentieth of the edge's 25-50 % time each, so a slow, noisy edge is
    judged on a scale where it moves); walking back from the edge, the rest
    is the last window of :data:`REST_WINDOW` blocks whose mean the next
    window's does not exceed by 4 noise deviations (of a window's mean, plus
    half an LSB), and the move starts at the first block after it beyond that
    rest level. A record that moves all the way back to ``lo`` starts its move there.
    """
    sgn = 1.0 if e.amplitude > 0 else -1.0
    hi = max(e.rest + 1, lo + 1)
    seg = sgn * y[lo:hi]
    m = max(1, (e.index - e.rest) // BLOCKS_PER_EDGE)
    nb = seg.size // m
    if nb < 4:
        return lo
    off = seg.size - nb * m
    b = seg[off:].reshape(nb, m).mean(axis=1)
    sigma = noise_sigma(y[lo:hi])
    q = quantum(y[lo:hi])
    c = np.concatenate(([0.0], np.cumsum(b)))
    # windows as long as the rest allows: a short pre-step record gets short ones
    for f in (REST_WINDOW, REST_WINDOW // 2):
        if nb < 2 * f:
            continue
        w = (c[f:] - c[:-f]) / f                    # mean of blocks k .. k+f-1
        d = w[f:] - w[:-f]
        band_w = 4.0 * sigma * math.sqrt(2.0 / (f * m)) + 0.5 * q
        k = _last_true(d <= band_w)
        if k >= 0:
            break
    else:
        return lo
    level = float(w[k])
    band_b = 4.0 * sigma / math.sqrt(m) + 0.5 * q
    moved = np.nonzero(b[k:] > level + band_b)[0]
    j = k + int(moved[0]) if moved.size else nb
    if m > 1 and j < nb:
        # to the sample: the first one of the block before and this block that
        # leaves the rest level by 4 deviations (of one sample)
        a0 = off + max(j - 1, 0) * m
        first = np.nonzero(seg[a0:off + (j + 1) * m] > level + 4.0 * sigma + 0.5 * q)[0]
        if first.size:
            return min(lo + a0 + int(first[0]), e.index)
    return min(lo + off + j * m, e.index)


def _complete(t, s: _Step, spacing: float) -> bool:
    """A full edge: a half period after it in the record, and some rest before it."""
    after = (t[s.end - 1] if s.end > s.i0 else t[s.i0]) - s.align
    before = s.align - t[0]
    return after >= 0.9 * spacing - 2 * _interval(t) and before >= 0.05 * spacing


def _single_edge(t, y, s: _Step, source, notes, first_sample_ok, end) -> PreparedStep:
    """The one step of a record (or the one full edge of a square wave)."""
    if source == "input":
        amp = _check_amplitude(s.amp, "the input column's step")
        notes.append(f"step detected in the input at t = {s.t_step:.6g} s, amplitude {amp:.6g}")
        return _single(t, y, s.t_step, s.i0, amp, end, notes)
    # from the output: the trigger (t = 0) when the output is still at rest there
    amp = s.amp
    if first_sample_ok and t[0] <= 0.0 <= s.t_step:
        t_step = 0.0
        i0 = int(np.searchsorted(t, 0.0, "left"))
        notes.append("no input column: step assumed at t = 0 (the trigger), where the output "
                     "is still at rest; pass --step-time otherwise")
    else:
        t_step, i0 = s.t_step, s.i0
        notes.append(f"no input column: step found in the output at t = {t_step:.6g} s (its "
                     "last sample at rest); pass --step-time otherwise")
    return _single(t, y, t_step, i0, amp, end, notes)


def _average(t, y, chosen, other, source, spacing, notes) -> PreparedStep:
    """Average the normalised responses of every full edge of one direction,
    aligned on their input edges (or the output's 50 % crossings), on a
    common grid; the noise is the spread of the averaged plateau."""
    dt = _interval(t)
    length = min(t[s.end - 1] - s.align for s in chosen)
    pre = 0.0
    if source == "output":
        pre = min(min(s.align - t[max(s.i0 - 1, 0)] for s in chosen) * 4.0, 0.25 * spacing,
                  min(s.align - t[0] for s in chosen))
    n = int((length + pre) / dt) + 1
    grid = np.linspace(-pre, length, n)
    avg, levels = _mean_response(t, y, chosen, grid, spacing)
    amp0 = chosen[0].amp
    y0_0 = levels[0]
    # noise: the spread of the averaged plateau about a straight line
    tail = avg[-max(8, n // 4):]
    x = np.arange(tail.size, dtype=float)
    resid = tail - np.polyval(np.polyfit(x, tail, 1), x)
    sig_plateau = float(np.std(resid))
    sig_n = max(noise_sigma(avg), sig_plateau)
    if source == "output":
        # the step starts where the average leaves zero
        i50 = int(np.searchsorted(grid, 0.0))
        k = _last_true(np.abs(avg[:i50]) <= 4.0 * sig_n)
        t0 = float(grid[k]) if k >= 0 else float(grid[0])
    else:
        t0 = 0.0
    keep = grid >= t0
    tp, yn = grid[keep] - t0, avg[keep]
    try:
        yf_n = final_value(tp, yn, 0.0, sigma=sig_n)
    except DesignError:
        raise DesignError(
            f"the square wave is too fast: the response averaged over {len(chosen)} edges has "
            "not settled before the next edge; use a lower frequency (half period >= 5 "
            "settling times)") from None
    sigma = sig_n * abs(amp0)
    _check_step(y0_0, y0_0 + yf_n * amp0, sigma)
    up = chosen[0].rising
    kind = "rising" if up else "falling"
    notes.append(f"square wave: {len(chosen)} {kind} edges aligned on the "
                 f"{'input edges' if source == 'input' else 'output'} and averaged "
                 f"({len(other)} {'falling' if up else 'rising'} edges kept apart); "
                 "IAE/ISE are against the average, scaled to the first edge")
    if len(other) >= 1:
        o_avg, _ = _mean_response(t, y, other, grid, spacing)
        o = o_avg[keep]
        diff = float(np.sqrt(np.mean((o - yn) ** 2)))
        if diff > 0.05 * abs(yf_n) + 3.0 * sig_n:
            notes.append(f"the {'falling' if up else 'rising'} edges' average differs "
                         f"from this one by {100 * diff / abs(yf_n):.0f} % of the step (rms): "
                         "the plant is not the same both ways (slew, saturation, asymmetric "
                         "drive?)")
    t_step = chosen[0].align + t0
    t_raw = t_step + tp
    y_raw = y0_0 + yn * amp0
    tw, yw = block_mean(tp, yn)
    work = max(noise_sigma(yw), sig_plateau)
    return PreparedStep(t=tw, y=yw, yf=yf_n, t_step=t_step, amplitude=float(amp0), y0=y0_0,
                        y_final=y0_0 + yf_n * amp0, sigma=sigma, t_raw=t_raw, y_raw=y_raw,
                        n_steps=len(chosen), notes=notes, dt=float(grid[1] - grid[0]),
                        work_sigma=work, rising=len(chosen) if up else len(other),
                        falling=len(other) if up else len(chosen))


def _mean_response(t, y, steps, grid, spacing) -> tuple:
    """Mean over ``steps`` of (y - y0) / amp interpolated at align + ``grid``;
    y0 is each edge's level over the last fifth of the half period before it.
    Returns (mean, the y0 of each step)."""
    acc = np.zeros(grid.size)
    levels = []
    for s in steps:
        a = int(np.searchsorted(t, s.align - min(0.2 * spacing, s.align - t[0]), "left"))
        b = max(min(s.i0, s.edge.index), a + 1)
        y0 = float(np.mean(y[a:b]))
        levels.append(y0)
        lo = int(np.searchsorted(t, s.align + grid[0], "left"))
        hi = min(int(np.searchsorted(t, s.align + grid[-1], "right")) + 1, t.size)
        acc += (np.interp(s.align + grid, t[max(lo - 1, 0):hi], y[max(lo - 1, 0):hi]) - y0) \
            / s.amp
    return acc / len(steps), levels


def nonlinearity(t, y, yf, sigma: float = 0.0, lsb: float = 0.0) -> str:
    """Why a normalised step response (``y`` settling at ``yf``) cannot be a
    linear plant's, or "".

    - A straight ramp: from 10 % to 90 % the response stays within 1 % (rms,
      plus the noise) of a straight line, does not overshoot, and reaches
      98 % no slower than the ramp would: an output slewing into its final
      level (or a rail). No linear response of the models here is that
      straight without overshooting (FOPDT: 6 % rms; an underdamped response
      straighter than 1 % overshoots over 12 %).
    - A flat top: the response overshoots and stays at its maximum (within
      the noise and one LSB) for over twice as long as a smooth peak of that
      height would (and 15 % of the time to it): clipped at a rail.
    """
    t = np.asarray(t, float)
    z = np.asarray(y, float) / yf if yf else np.asarray(y, float)
    sig = sigma / abs(yf) if yf else sigma
    q = lsb / abs(yf) if yf else lsb
    if z.size < 20:
        return ""
    t10, t90 = crossing_time(t, z, 0.1, sigma=sig), crossing_time(t, z, 0.9, sigma=sig)
    t98 = crossing_time(t, z, 0.98, sigma=sig)
    peak = float(np.max(z))
    over = peak - 1.0 > 0.02 + 4.0 * sig + q
    if all(math.isfinite(v) for v in (t10, t90, t98)) and t90 > t10 and not over:
        sel = (t >= t10) & (t <= t90)
        if np.count_nonzero(sel) >= 10:
            tt, zz = t[sel], z[sel]
            c = np.polyfit(tt - tt[0], zz, 1)
            rms = float(np.sqrt(np.mean((zz - np.polyval(c, tt - tt[0])) ** 2)))
            ramp_98 = 0.08 / c[0] if c[0] > 0 else math.inf
            if rms < 0.01 + 2.0 * sig and (t98 - t90) <= 2.0 * ramp_98:
                return (f"the response rises in a straight line from 10 % to 90 % ({rms:.2%} rms "
                        f"from it, {100 * c[0]:.4g} % of the step per second) and stops: a "
                        "slew-rate limit or a ramp into a rail, not a linear plant")
    if over:
        ip = int(np.argmax(z))
        band = max(2.0 * sig, q) + 1e-12
        top = z >= peak - band
        k0 = _last_true(~top[:ip])
        k1 = ip + int(np.argmax(~top[ip:])) if not top[ip:].all() else z.size
        held = t[min(k1, z.size - 1)] - t[k0 + 1]
        # a smooth peak of this height (curvature of an underdamped one,
        # overshoot (pi / tp)^2 / 2) stays within the band about
        # 0.9 sqrt(band / overshoot) tp: a clipped one much longer
        smooth = 0.9 * math.sqrt(band / (peak - 1.0)) * t[ip]
        if k1 - k0 - 1 >= 5 and held > max(2.0 * smooth, 0.15 * t[ip]):
            return (f"the response stays at its maximum ({100 * (peak - 1):.0f} % over the final "
                    f"value) for {held:.3g} s: clipped at a rail (a flat top), not a linear plant")
    return ""


def _amplitude_from_u(t, u, t_step):
    u = np.asarray(u, float)
    pre, post = u[t < t_step], u[t >= t_step]
    if pre.size == 0 or post.size == 0:
        raise DesignError("cannot measure the step amplitude from the input around "
                          f"t = {t_step:.6g} s; give --step-amplitude")
    amp = float(np.mean(post[post.size // 2:]) - np.mean(pre))
    if amp == 0 or abs(amp) < MIN_STEP_SNR * noise_sigma(u):
        raise DesignError(f"the input does not step at t = {t_step:.6g} s; give --step-amplitude")
    return amp
