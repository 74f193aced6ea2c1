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
from ..core.waveform import crossing_time, noise_sigma

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

    @property
    def amplitude(self) -> float:
        return self.after - self.before


def find_edges(t, u) -> list:
    """Transitions of a two-level input (a step or a square wave).

    Levels are the 5th and 95th percentiles; a transition is counted when the
    signal moves from below 25 % to above 75 % of the span (or back), so noise
    near a level never makes a false edge. Each edge's time is the interpolated
    50 % crossing; its levels are the means of the settled parts of the
    neighbouring plateaus.
    """
    t = np.asarray(t, float)
    u = np.asarray(u, float)
    sigma = noise_sigma(u)
    # Levels: the record's two ends when they differ (a single step, however
    # close to either end), else robust extremes (a square wave).
    k = max(3, u.size // 200)
    a, b = float(np.median(u[:k])), float(np.median(u[-k:]))
    if abs(b - a) > MIN_STEP_SNR * sigma and abs(b - a) > 0:
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
        edges.append(Edge(time=te, index=j, before=before, after=after))
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

    @property
    def gain(self) -> float:
        return self.yf

    def to_dict(self) -> dict:
        return {"step_time_s": self.t_step, "step_amplitude": self.amplitude,
                "y0": self.y0, "y_final": self.y_final, "gain": self.yf,
                "noise_sigma": self.sigma,
                "noise_pct_of_step": (100.0 * self.sigma / abs(self.y_final - self.y0)
                                      if self.y_final != self.y0 else None),
                "samples": int(self.t_raw.size), "work_samples": int(self.t.size),
                "steps_averaged": self.n_steps, "notes": list(self.notes)}


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


def prepare_step(t, y, u=None, *, step_time: float | None = None,
                 step_amplitude: float | None = None) -> PreparedStep:
    """Normalise a capture to a unit step response (see module docstring).

    Parameters
    ----------
    t, y : array_like
        Time (s, strictly increasing) and output.
    u : array_like, optional
        Input; its edges give the step time(s) and amplitude. Several edges (a
        square wave) are split into steps, normalised and averaged.
    step_time, step_amplitude : float, optional
        When there is no input column (or to override it). Without either,
        the step is taken at t = 0 when the record spans it (scope trigger
        convention), else at the first sample; the amplitude defaults to 1.
    """
    t = np.asarray(t, float)
    y = np.asarray(y, float)
    check_samples(t, y, *([] if u is None else [u]))
    notes = []
    if step_amplitude is not None:
        _check_amplitude(step_amplitude, "the step amplitude")
    if step_time is not None:
        RANGES["capture_time_s"].check(step_time, "the step time", shown=number_text(step_time))
    edges = []
    if u is not None and step_time is None:
        edges = find_edges(t, u)
        if not edges:
            raise DesignError("no step in the input column: it never moves between two levels "
                              "by more than the noise; give --step-time (and --step-amplitude) "
                              "or check the column order (t,u,y)")
    if len(edges) >= 2:
        return _prepare_square(t, y, edges, step_amplitude, notes)
    if edges:
        e = edges[0]
        t_step = e.time
        # A given amplitude is a size; the edge says which way it went.
        amp = math.copysign(step_amplitude, e.amplitude) if step_amplitude is not None \
            else _check_amplitude(e.amplitude, "the input column's step")
        notes.append(f"step detected in the input at t = {t_step:.6g} s, amplitude {amp:.6g}")
    else:
        if step_time is not None:
            if not (math.isfinite(step_time) and t[0] <= step_time < t[-1]):
                raise DesignError(f"step time {number_text(step_time)} s is outside the record "
                                  f"[{t[0]:.6g}, {t[-1]:.6g}] s")
            t_step = float(step_time)
        elif t[0] < 0.0 <= t[-1]:
            t_step = 0.0
            notes.append("no input column: step assumed at t = 0 (the trigger); "
                         "pass --step-time otherwise")
        else:
            t_step = float(t[0])
            notes.append(f"no input column: step assumed at the first sample, t = {t_step:.6g} s; "
                         "pass --step-time otherwise")
        if step_amplitude is not None:
            amp = float(step_amplitude)
        elif u is not None:
            amp = _check_amplitude(_amplitude_from_u(t, u, t_step), "the input column's step")
        else:
            amp = 1.0
            notes.append("no input amplitude: gain is per unit input (pass --step-amplitude)")
    y0, n_pre = baseline(t, y, t_step)
    if n_pre == 0:
        notes.append("no samples before the step: baseline taken from the first sample")
    post = t >= t_step
    tp, yp = t[post], y[post]
    tp -= t_step
    if tp.size < 10:
        raise DesignError("fewer than 10 samples after the step; capture more of the response")
    sigma = noise_sigma(yp)
    if u is None:
        cut = next_step_time(tp, yp, y0, sigma)
        if cut is not None:
            notes.append(f"the output returns to its baseline: another input edge near "
                         f"t = {t_step + cut:.6g} s (a square wave?); the record is cut there "
                         "(give the input column to average every step)")
            keep = tp < cut
            tp, yp = tp[keep], yp[keep]
            t, y = t[t < t_step + cut], y[t < t_step + cut]
            if tp.size < 10:
                raise DesignError("fewer than 10 samples between the step and the next edge")
    yf = final_value(tp, yp, y0, sigma=sigma)
    _check_step(y0, yf, sigma)
    yn = (yp - y0) / amp
    tw, yw = block_mean(tp, yn)
    return PreparedStep(t=tw, y=yw, yf=(yf - y0) / amp, t_step=t_step, amplitude=float(amp),
                        y0=y0, y_final=yf, sigma=sigma, t_raw=t, y_raw=y, notes=notes)


def next_step_time(t, y, y0: float, sigma: float = 0.0):
    """Time of the next (opposite) input edge in an output-only square-wave record, or None.

    After the response's main excursion (beyond half its largest deviation
    from ``y0``) the output coming back within 5 % of that deviation of the
    baseline means the input stepped back. For a linear plant the return
    mirrors the step response, so the edge is the return's 50 % crossing
    minus the step's own 50 % crossing time.
    """
    t = np.asarray(t, float)
    d = np.asarray(y, float) - y0
    peak = float(np.max(np.abs(d)))
    if peak <= MIN_STEP_SNR * sigma or peak == 0:
        return None
    sgn = 1.0 if abs(float(np.max(d))) >= abs(float(np.min(d))) else -1.0
    z = sgn * d / peak
    half = np.nonzero(z >= 0.5)[0]
    if half.size == 0:
        return None
    i1 = int(half[0])
    back = np.nonzero(z[i1:] <= 0.05 + 3 * sigma / peak)[0]
    if back.size == 0:
        return None
    i2 = i1 + int(back[0])
    # 50 % of the settled level (the median of the high plateau, not the
    # overshoot peak) on both the rise and the return.
    hi = float(np.median(z[i1:i2]))
    for _ in range(2):
        if hi <= 0.25:
            return None
        above = np.nonzero(z[:i2] >= 0.5 * hi)[0]
        j = int(above[-1])       # last sample above 50 % before the return
        # refine the level on the settled later part of the plateau
        a, b = i1 + (j - i1) // 2, j - (j - i1) // 10
        if b > a:
            hi = float(np.median(z[a:b]))
    z = z / hi
    above = np.nonzero(z[:i2] >= 0.5)[0]
    j = int(above[-1])
    t50_fall = crossing_time(t[j:i2 + 1], -z[j:i2 + 1], -0.5)
    t50_rise = crossing_time(t, z, 0.5, sigma=sigma / (peak * hi))
    edge = t50_fall - (t50_rise - float(t[0]))
    return edge if math.isfinite(edge) and edge > t[0] else None


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


def _prepare_square(t, y, edges, step_amplitude, notes) -> PreparedStep:
    """Split a square-wave capture into its steps, normalise each and average.

    Each step runs from one edge to the next; its baseline is the settled end
    of the step before it (so the first edge, without a settled history, is
    used only when it has pre-step samples). Every step must settle within
    its half period.
    """
    bounds = [0] + [e.index for e in edges] + [t.size]
    segs = []
    sigma_all = noise_sigma(y)
    first_valid = 0 if edges[0].index > 10 else 1
    for k in range(first_valid, len(edges)):
        e = edges[k]
        i0, i1 = e.index, bounds[k + 2]
        if k + 1 == len(edges) and (t[-1] - e.time) < 0.9 * (edges[k].time - edges[k - 1].time):
            break  # last step cut short by the end of the record
        prev = y[bounds[k]:i0]
        if prev.size < 4:
            continue
        m = max(2, int(prev.size * TAIL_FRACTION))
        y0 = float(np.mean(prev[-m:]))
        tp, yp = t[i0:i1] - e.time, y[i0:i1]
        try:
            yf = final_value(tp, yp, y0, sigma=sigma_all)
        except DesignError:
            raise DesignError(
                f"the square wave is too fast: the response to the edge at t = {e.time:.6g} s has "
                "not settled before the next edge; use a lower frequency (half period >= 5 "
                "settling times)") from None
        amp = math.copysign(step_amplitude, e.amplitude) if step_amplitude is not None \
            else _check_amplitude(e.amplitude, "the input column's step")
        segs.append((e, tp, (yp - y0) / amp, y0, yf, amp))
    if not segs:
        raise DesignError("the square-wave capture has no complete step with a settled "
                          "level before it; capture at least one full period")
    length = min(s[1][-1] for s in segs)
    dt = min(float(np.median(np.diff(s[1]))) for s in segs)
    n = int(length / dt) + 1
    grid = np.linspace(0.0, length, n)
    acc = np.zeros(n)
    for _, tp, yn, *_ in segs:
        acc += np.interp(grid, tp, yn)
    yavg = acc / len(segs)
    e0, _, _, y0, yfirst, amp0 = segs[0]
    sigma = noise_sigma(yavg) * abs(amp0)
    yf_n = final_value(grid, yavg, 0.0, sigma=sigma / abs(amp0))
    _check_step(y0, y0 + yf_n * amp0, sigma / math.sqrt(len(segs)) if len(segs) > 1 else sigma)
    notes.append(f"square wave: {len(segs)} steps (rising and falling) normalised and averaged; "
                 f"IAE/ISE are against the average, scaled to the first step")
    # The "raw" data for the indices: the averaged step in the first step's units.
    t_raw = e0.time + grid
    y_raw = y0 + yavg * amp0
    t_raw = np.concatenate([[t[max(e0.index - 1, 0)]], t_raw]) if e0.index > 0 else t_raw
    y_raw = np.concatenate([[y0], y_raw]) if e0.index > 0 else y_raw
    tw, yw = block_mean(grid, yavg)
    return PreparedStep(t=tw, y=yw, yf=yf_n, t_step=e0.time, amplitude=float(amp0), y0=y0,
                        y_final=y0 + yf_n * amp0, sigma=sigma, t_raw=t_raw, y_raw=y_raw,
                        n_steps=len(segs), notes=notes)
