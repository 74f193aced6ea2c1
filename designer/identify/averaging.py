"""Square-wave captures split into their steps and averaged (a stage of
:mod:`designer.identify.preprocess`).

:func:`from_edges` takes the edges of the input, or of the output when there
is no input column: one edge is a single step; of several, each becomes a
:class:`_Step` (from the output, starting at its last sample at rest before it
moves, :func:`_departure`), and every full edge of one direction (a half period
after it, some rest before it) is normalised and averaged on a common grid,
aligned on the input edges (or the output's 50 % crossings), the other
direction kept apart and compared with it (:func:`_average`); the noise is the
spread of the averaged plateau. An output that swings back and forth without a
settled edge, a sine or a triangle, is refused (:func:`check_periodic_steps`).
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

from ..core.errors import DesignError
from ..core.waveform import noise_sigma, quantum
from .edges import Edge
from .normalise import PreparedStep, check_amplitude, check_step, sample_interval, single_step
from .settle import last_true, block_mean, final_value

__all__ = []


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


def from_edges(t, y, edges, step_amplitude, notes, *, source, first_sample_ok) -> PreparedStep:
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
        k = last_true(d <= band_w)
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
    return after >= 0.9 * spacing - 2 * sample_interval(t) and before >= 0.05 * spacing


def _single_edge(t, y, s: _Step, source, notes, first_sample_ok, end) -> PreparedStep:
    """The one step of a record (or the one full edge of a square wave)."""
    if source == "input":
        amp = check_amplitude(s.amp, "the input column's step")
        notes.append(f"step detected in the input at t = {s.t_step:.6g} s, amplitude {amp:.6g}")
        return single_step(t, y, s.t_step, s.i0, amp, end, notes)
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
    return single_step(t, y, t_step, i0, amp, end, notes)


def _average(t, y, chosen, other, source, spacing, notes) -> PreparedStep:
    """Average the normalised responses of every full edge of one direction,
    aligned on their input edges (or the output's 50 % crossings), on a
    common grid; the noise is the spread of the averaged plateau."""
    dt = sample_interval(t)
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
        k = last_true(np.abs(avg[:i50]) <= 4.0 * sig_n)
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
    check_step(y0_0, y0_0 + yf_n * amp0, sigma)
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


#: An output that spends more than this fraction of a periodic record between
#: the quarter and three-quarter levels of its swing is no step response.
MAX_TRANSITION_FRACTION = 0.25


def check_periodic_steps(y) -> None:
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
