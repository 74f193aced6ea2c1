"""A step response's levels, and the readings of the normalised one: robust
primitives of :mod:`designer.identify.preprocess` (the waveform readings,
noise, crossing times, derivatives, are :mod:`designer.core.waveform`).

- :func:`baseline` and :func:`final_value`: y0 from pre-step samples, yf from a
  settled tail (and a clear error when the record ends before settling);
  :func:`settled_before`: the output's :class:`Rest` just before a step, so a
  pre-trigger record that rings or drifts earlier does not move the baseline;
- :func:`block_mean`: a long record reduced to at most
  :data:`MAX_WORK_SAMPLES` samples for the methods (block means, no delay);
- :func:`nonlinearity`: why a normalised response cannot be a linear plant's
  (a slew-rate ramp, a flat top clipped at a rail), or "".
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

from ..core.errors import DesignError
from ..core.waveform import crossing_time, noise_sigma

__all__ = ["block_mean", "final_value"]

#: Fraction of the post-step record used as the settled tail for yf.
TAIL_FRACTION = 0.1
#: A tail drifting by more than this fraction of the step is "not settled".
SETTLE_TOL = 0.02
#: Methods and least squares run on at most this many samples (block means).
MAX_WORK_SAMPLES = 40000


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
    k = last_true(off)
    start = 0 if k < 0 else k + m
    start = min(start, n - 1)
    level = float(np.mean(y_pre[start:]))
    moved = float(np.max(np.abs(ma))) if ma.size else 0.0
    return Rest(level=level, samples=n - start, moved=moved)


def last_true(mask) -> int:
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

    Parameters
    ----------
    t, y : array_like
        The post-step times (s) and samples.
    y0 : float
        The value before the step.
    sigma : float, optional
        Noise standard deviation of ``y``; estimated from ``y`` when None.

    Returns
    -------
    float
        The settled value.
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

    Parameters
    ----------
    t, y : array_like
        Times (s) and samples.
    max_samples : int, optional
        Most samples kept.

    Returns
    -------
    tuple of numpy.ndarray
        ``(t, y)`` reduced, or unchanged when short enough.
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
        k0 = last_true(~top[:ip])
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
