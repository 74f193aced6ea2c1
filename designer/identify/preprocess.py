"""From a raw capture to the normalised step response the methods work on.

The methods of seeds 000-003 all assume a clean unit step applied at t = 0
to a system at rest. A real capture has an offset, a trigger somewhere in the
record, noise, sometimes a whole square wave. :func:`prepare_step` turns it into
``t`` (time since the step), ``y`` (deviation from the pre-step baseline
divided by the input step amplitude) and ``yf`` (its settled value = static
gain), a :class:`~designer.identify.normalise.PreparedStep`, with the robust
primitives of its stages (the waveform readings, noise, crossing times,
derivatives, are :mod:`designer.core.waveform`):

- :mod:`designer.identify.edges`: ``check_samples``, the one check that a
  record is usable at all, and ``find_edges``, step times and amplitude from
  the input;
- :mod:`designer.identify.settle`: ``baseline`` and ``final_value``, y0 from
  pre-step samples, yf from a settled tail (and a clear error when the record
  ends before settling);
- :mod:`designer.identify.normalise`: one step normalised;
- :mod:`designer.identify.averaging`: square-wave captures split into their
  steps and averaged;
- here, :func:`prepare_step`: all of the above, the step given (its time, its
  amplitude), found in the input, in the output, or at the scope's trigger;
  :func:`check_window` checks the ``--window`` it may be limited to.
"""

from __future__ import annotations

import math

import numpy as np

from ..core.errors import DesignError
from ..core.ranges import RANGES
from ..core.waveform import crossing_time, noise_sigma, quantum
from .averaging import check_periodic_steps, from_edges
from .edges import MIN_SAMPLES, MIN_STEP_SNR, check_samples, find_edges, number_text
from .normalise import PreparedStep, check_amplitude, single_step
from .settle import nonlinearity

__all__ = ["check_window", "prepare_step"]


def check_window(window, t=None) -> tuple:
    """``(t0, t1)`` of ``--window``: both inside ``RANGES["capture_time_s"]``,
    t0 < t1, and (given the record's times ``t``) holding at least
    :data:`MIN_SAMPLES` samples.

    Parameters
    ----------
    window : tuple of float
        ``(t0, t1)`` in s.
    t : array_like, optional
        The record's times in s.

    Returns
    -------
    tuple of float
        ``(t0, t1)``.

    Raises
    ------
    DesignError
        When a bound is out of range, t0 >= t1, or too few samples lie inside.
    """
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

    Returns
    -------
    PreparedStep
        The normalised step response and how it was obtained.
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
        check_amplitude(step_amplitude, "the step amplitude")
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
        prep = from_edges(t, y, edges, step_amplitude, notes, source="input",
                           first_sample_ok=False)
    else:
        edges = find_edges(t, y, plateaus=True)
        if edges:
            try:
                prep = from_edges(t, y, edges, step_amplitude, notes, source="output",
                                   first_sample_ok=window is None)
            except DesignError:
                if len(edges) >= 2:
                    check_periodic_steps(y)
                raise
        else:
            prep = single_step(t, y, *_trigger_step(t, notes), _amp_or_one(step_amplitude, notes),
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
        amp = check_amplitude(_amplitude_from_u(t, u, t_step), "the input column's step")
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
    return single_step(t, y, t_step, i0, amp, end, notes)


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
