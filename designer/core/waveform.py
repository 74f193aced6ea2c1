"""Reading a sampled waveform: one implementation of each primitive that step
metrics, tuning and identification share.

- :func:`noise_sigma`: noise standard deviation of a record (at least the
  rounding noise of :func:`quantum`, an ADC's step); :func:`spread`, a
  robust standard deviation; :func:`periodic_ripple`, a switching ripple;
- :func:`normalised_step`: a step response as the fraction of its change;
- :func:`crossing_time`: when a record first rises through a level, robust to
  noise (a threshold is y0 + p (yf - y0), never p yf: seed 000's pitfall);
- :func:`savgol` and :func:`smooth_derivative`: Savitzky-Golay smoothing and
  derivative on a uniform grid;
- :func:`parabola_vertex` and :func:`refine_peak`: the extreme of a sampled
  peak, between the samples;
- :func:`inflection_tangent`: the tangent at the steepest point of a step
  response, Ziegler and Nichols' reaction curve (seed 001 section V.8, seed
  000 eq. 7), with :func:`tangent_window`, the one rule for its smoothing.

Nothing here knows about plants or methods: arrays in, numbers out.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

from .errors import DesignError

__all__ = ["crossing_time", "inflection_tangent", "moving_average", "noise_sigma", "normalised_step",
           "parabola_vertex", "peak_region", "quantum", "refine_peak", "savgol", "smooth_derivative",
           "tangent_window"]

# --------------------------------------------------------------------------- noise


#: Samples of the settled end examined for the quantisation step.
QUANTUM_SAMPLES = 50_000


def quantum(y) -> float:
    """The quantisation step (one LSB) of a record written by an ADC, 0 if it is not one.

    Over the same settled end as :func:`noise_sigma` (at most
    :data:`QUANTUM_SAMPLES` samples; the whole record, thinned, when that
    end sits on fewer than three levels): the values must repeat (at least three
    levels, no more than a quarter as many levels as samples) and every gap
    between neighbouring levels must be a whole number of the smallest gap
    (within 1 %, for values printed in decimal). An 8-bit scope's record
    passes; a simulated or averaged one, whose values never repeat, does not.

    Parameters
    ----------
    y : array_like
        The record.

    Returns
    -------
    float
        The step, or 0.
    """
    y = np.asarray(y, float)
    if y.size < 20:
        return 0.0
    end = y[-(y.size // 4):] if y.size >= 80 else y
    end = end[-QUANTUM_SAMPLES:]
    levels = np.unique(end)
    if levels.size < 3:
        # a trace settled on one or two levels: the whole record shows the step
        end = y[::max(1, y.size // (4 * QUANTUM_SAMPLES))]
        levels = np.unique(end)
    if levels.size < 3 or levels.size > end.size / 4:
        return 0.0
    gaps = np.diff(levels)
    q = float(gaps.min())
    if not q > 0:
        return 0.0
    r = gaps / q
    return q if float(np.max(np.abs(r - np.round(r)))) < 0.01 else 0.0


def noise_sigma(y) -> float:
    """Noise standard deviation of a record, from its settled end.

    1.4826 x the median absolute second difference / sqrt(6) over the last
    quarter of the record (the whole of a record under 80 samples). Second
    differences cancel a smooth signal's slope, so a densely sampled response,
    even an oscillating one, contributes almost nothing, and white noise of
    variance s^2 gives differences of variance 6 s^2; the median makes it
    robust to a step or a spike, and the last quarter, where a step response
    has settled, keeps the response's own curvature out. 0 for fewer than 5
    samples.

    A quantised record (:func:`quantum`) has at least the rounding noise of
    its step, LSB / sqrt(12): an 8-bit scope's settled trace often sits on one
    level, where the differences alone would say "no noise" and one LSB would
    pass for a signal.

    Parameters
    ----------
    y : array_like
        The record.

    Returns
    -------
    float
        The noise's standard deviation.
    """
    y = np.asarray(y, float)
    if y.size < 5:
        return 0.0
    lsb = quantum(y)
    if y.size >= 80:
        y = y[-(y.size // 4):]
    # in place: one temporary the size of the record, not four
    d2 = np.multiply(y[1:-1], -2.0)
    d2 += y[2:]
    d2 += y[:-2]
    np.abs(d2, out=d2)
    sigma = float(1.4826 * np.median(d2, overwrite_input=True) / math.sqrt(6.0))
    return max(sigma, lsb / math.sqrt(12.0))


#: A settled stretch whose spread exceeds this many white-noise sigmas carries
#: a smooth disturbance (switching ripple, hum) that :func:`periodic_ripple` looks for.
RIPPLE_SPREAD_RATIO = 3.0
#: Harmonics of the ripple's fundamental fitted (fewer when above Nyquist).
RIPPLE_HARMONICS = 5
#: The fitted ripple must leave at most this fraction of the stretch's variance.
RIPPLE_MAX_RESIDUAL = 0.25
#: A ripple's size over the two halves of the settled stretch differs by at most this factor.
RIPPLE_STEADY = 1.3


def spread(y) -> float:
    """Robust standard deviation of ``y`` about its median (1.4826 x the MAD)."""
    y = np.asarray(y, float)
    return float(1.4826 * np.median(np.abs(y - np.median(y)))) if y.size else 0.0


def _harmonic_basis(t, f0: float, h: int) -> np.ndarray:
    w = 2.0 * math.pi * f0 * np.asarray(t, float)
    cols = [np.ones_like(w)]
    for k in range(1, h + 1):
        cols += [np.cos(k * w), np.sin(k * w)]
    return np.column_stack(cols)


def periodic_ripple(t, y, start: int, floor: float = 0.0) -> tuple | None:
    """A periodic disturbance riding on a record, estimated on its settled
    stretch ``y[start:]`` and extended over the whole record: ``(ripple,
    period_s)``, or None.

    A switching converter's ripple is locked to its clock, so averaging edges
    aligned on a slower square wave keeps it; on the settled stretch it is the
    whole signal. The fundamental is the highest peak of the stretch's
    spectrum (Hann window, zero-padded four times), refined to the frequency
    whose :data:`RIPPLE_HARMONICS` harmonics fit the stretch best (least
    squares). Returned (without its mean) only when the stretch spreads over
    :data:`RIPPLE_SPREAD_RATIO` white-noise sigmas (:func:`noise_sigma`) and
    over ``floor``, the fit leaves at most :data:`RIPPLE_MAX_RESIDUAL` of its
    variance, and the ripple is as large over the stretch's second half as
    over its first (within :data:`RIPPLE_STEADY`): a response still ringing
    as it decays is the response, not a ripple. ``t`` must be uniform, and
    the stretch must hold three periods.
    """
    t = np.asarray(t, float)
    y = np.asarray(y, float)
    ts, ys = t[start:], y[start:]
    n = ys.size
    if n < 64:
        return None
    white = noise_sigma(ys)
    dev = ys - float(np.mean(ys))
    var = float(np.mean(dev * dev))
    if not var > max(RIPPLE_SPREAD_RATIO * white, floor) ** 2:
        return None
    dt = float((ts[-1] - ts[0]) / (n - 1))
    spec = np.abs(np.fft.rfft(dev * np.hanning(n), 4 * n))
    f = np.fft.rfftfreq(4 * n, dt)
    span_s = n * dt
    ok = f >= 3.0 / span_s
    if not ok.any():
        return None
    f0 = float(f[ok][int(np.argmax(spec[ok]))])
    h = max(1, min(RIPPLE_HARMONICS, int(0.5 / (dt * f0))))
    step = 0.25 / span_s          # a quarter of the spectrum's bin
    best = None
    for _ in range(2):
        for fc in f0 + step * np.arange(-8, 9):
            if fc <= 0:
                continue
            A = _harmonic_basis(ts, fc, h)
            c, *_ = np.linalg.lstsq(A, ys, rcond=None)
            r = A @ c - ys
            e = float(np.mean(r * r))
            if best is None or e < best[0]:
                best = (e, fc, c)
        f0, step = best[1], step / 8.0
    e, f0, c = best
    if e > RIPPLE_MAX_RESIDUAL * var:
        return None
    half = n // 2
    rms = []
    for a, b in ((0, half), (half, n)):
        A = _harmonic_basis(ts[a:b], f0, h)
        ch, *_ = np.linalg.lstsq(A, ys[a:b], rcond=None)
        rms.append(float(np.std(A[:, 1:] @ ch[1:])))
    if not (rms[0] > 0 and abs(math.log(max(rms[1], 1e-300) / rms[0])) <= math.log(RIPPLE_STEADY)):
        return None
    return _harmonic_basis(t, f0, h)[:, 1:] @ c[1:], 1.0 / f0


# --------------------------------------------------------------------------- steps


def normalised_step(t, y, *, t_step: float | None = None, initial: float | None = None,
                    final: float | None = None, what: str = "step response") -> tuple:
    """``(t, z, y0, yf)``: a step response as time since the step and the
    fraction ``z`` = (y - y0) / (yf - y0) of the change, rising 0 -> 1 whether
    the step goes up or down.

    ``t_step`` defaults to the first sample (samples before it are dropped; one
    a rounding error early counts as at the step), ``initial`` to the first
    sample kept, ``final`` to the last. A step that does not change the output
    is refused (:class:`~designer.core.errors.DesignError` naming ``what``).

    Parameters
    ----------
    t, y : array_like
        The step response.
    t_step : float, optional
        When the step is applied (s).
    initial, final : float, optional
        The output before and after the step.
    what : str
        What the record is, for the message.

    Returns
    -------
    tuple
        (t, z, y0, yf).
    """
    t = np.asarray(t, float)
    y = np.asarray(y, float)
    ts0 = float(t[0]) if t_step is None else float(t_step)
    keep = t >= ts0 - 1e-15 * max(1.0, abs(ts0))
    t, y = t[keep] - ts0, y[keep]
    y0 = float(y[0]) if initial is None else float(initial)
    yf = float(y[-1]) if final is None else float(final)
    if yf == y0:
        raise DesignError(f"{what}: the output does not change (initial equals final value)")
    return t, (y - y0) / (yf - y0), y0, yf


# --------------------------------------------------------------------------- crossings


def _interp_at(t, y, j: int, level: float) -> float:
    """Linear interpolation of the crossing of ``level`` between samples j-1 and j."""
    if j == 0:
        return float(t[0])
    y0, y1 = y[j - 1], y[j]
    frac = 0.0 if y1 == y0 else (level - y0) / (y1 - y0)
    return float(t[j - 1] + frac * (t[j] - t[j - 1]))


def _first(mask) -> int:
    """Index of the first True of a boolean array, -1 if none (argmax stops
    at it, where nonzero would list every True of a long record)."""
    k = int(np.argmax(mask)) if mask.size else 0
    return k if mask.size and mask[k] else -1


def crossing_time(t, y, level: float, *, sigma: float = 0.0, start: int = 0) -> float:
    """Time ``y`` first rises through ``level`` at or after index ``start``; nan if never.

    Without noise (``sigma`` = 0) this is linear interpolation between the last
    sample below the level and the first at or above it. With noise that
    first sample may be a spike: the samples from the last one clearly below
    (under level - 3 sigma) before it to the first one clearly above (over
    level + 3 sigma) after it are fitted with a straight line, which crosses
    the level at the time returned.

    Parameters
    ----------
    t, y : array_like
        The record.
    level : float
        The level crossed.
    sigma : float
        The noise's standard deviation (0: clean).
    start : int
        The first index searched.

    Returns
    -------
    float
        The time (s), or nan.
    """
    t = np.asarray(t, float)
    y = np.asarray(y, float)
    i = _first(y[start:] >= level)
    if i < 0:
        return math.nan
    i += start
    band = 3.0 * sigma
    if band == 0.0 or i == 0:
        return _interp_at(t, y, i, level)
    below = _first((y[start:i] < level - band)[::-1])
    over = _first(y[i:] > level + band)
    lo = min(i - 1 - below if below >= 0 else start, i - 1)
    hi = max(i + over if over >= 0 else y.size - 1, i)
    if hi - lo == 1:
        return _interp_at(t, y, i, level)
    tt = t[lo:hi + 1]
    tc = tt.mean()
    slope, icpt = np.polyfit(tt - tc, y[lo:hi + 1], 1)
    if slope <= 0.0:
        return _interp_at(t, y, i, level)
    return float(tc + (level - icpt) / slope)


# --------------------------------------------------------------------------- smoothing


def moving_average(y, m: int) -> np.ndarray:
    """Centred moving average of ``y`` over ``m`` samples (the ends over the
    samples that exist), from one cumulative sum.

    Parameters
    ----------
    y : array_like
        The record.
    m : int
        The samples averaged.

    Returns
    -------
    numpy.ndarray
        The averages.
    """
    y = np.asarray(y, float)
    if m <= 1:
        return y
    c = np.concatenate(([0.0], np.cumsum(y)))
    i = np.arange(y.size)
    lo = np.clip(i - m // 2, 0, y.size)
    hi = np.clip(i + (m - m // 2), 0, y.size)
    return (c[hi] - c[lo]) / (hi - lo)


def savgol(y, window: int, polyorder: int, deriv: int = 0, delta: float = 1.0) -> np.ndarray:
    """Savitzky-Golay filter (least-squares polynomial over a sliding window).

    Same result as ``scipy.signal.savgol_filter(..., mode="interp")``: interior
    samples by convolution, the first and last half-windows from one
    polynomial fitted to the edge window. Written here because importing
    scipy.signal costs about a second on every command-line run.

    Parameters
    ----------
    y : array_like
        The record.
    window : int
        The window's samples (odd).
    polyorder : int
        The polynomial's order.
    deriv : int
        The derivative's order (0: the smoothed record).
    delta : float
        The sample interval (for a derivative).

    Returns
    -------
    numpy.ndarray
        The filtered record.
    """
    y = np.asarray(y, float)
    w, p = int(window), int(polyorder)
    h = w // 2
    x = np.arange(-h, h + 1, dtype=float)
    A = np.vander(x, p + 1, increasing=True)           # columns x^0 .. x^p
    pinv = np.linalg.pinv(A)                            # rows: polynomial coefficients
    kernel = pinv[deriv] * (math.factorial(deriv) / delta ** deriv)   # the deriv at x = 0
    out = np.empty_like(y)
    out[h:y.size - h] = np.correlate(y, kernel, mode="valid")
    # Edges: derivative of the polynomial fitted to the first/last window.
    for seg, xs, dst in ((y[:w], x[:h], slice(0, h)), (y[-w:], x[h + 1:], slice(y.size - h, y.size))):
        c = pinv @ seg                                  # coefficients in x (samples)
        dc = np.polynomial.polynomial.polyder(c, deriv) if deriv else c
        out[dst] = np.polynomial.polynomial.polyval(xs, dc) / delta ** deriv
    return out


def is_uniform(t, rtol: float = 1e-3) -> bool:
    """True when the sample spacing varies by at most ``rtol`` of its mean."""
    dt = np.diff(np.asarray(t, float))
    return bool(dt.size and np.ptp(dt) <= rtol * np.mean(dt))


def uniform(t, y, n: int | None = None) -> tuple:
    """(t, y) on a uniform grid (linear interpolation) when they are not already."""
    t = np.asarray(t, float)
    y = np.asarray(y, float)
    if is_uniform(t):
        return t, y
    n = n or t.size
    tu = np.linspace(t[0], t[-1], n)
    return tu, np.interp(tu, t, y)


def odd_window(w: int, n: int) -> int:
    """``w`` made an odd Savitzky-Golay window of at least 5 and at most ``n`` samples."""
    w = max(5, int(w))
    if w % 2 == 0:
        w += 1
    if w > n:
        w = n if n % 2 else n - 1
    return w


def window_size(dt: float, n: int, *, window_s: float | None = None, sigma: float = 0.0,
                span: float = 1.0, rise_s: float | None = None) -> int:
    """The odd window (samples) :func:`smooth_derivative` uses: ``window_s``
    seconds when given, else :func:`tangent_window`."""
    if window_s is not None:
        return odd_window(round(window_s / dt), n)
    return tangent_window(dt, n, sigma=sigma, span=span, rise_s=rise_s)


def smooth_derivative(t, y, *, window_s: float | None = None, sigma: float = 0.0,
                      span: float = 1.0, rise_s: float | None = None,
                      polyorder: int = 2) -> tuple:
    """Smoothed record and its time derivative (Savitzky-Golay).

    The default quadratic fit gives the least-squares slope over the window,
    a positively weighted mean of the sample-to-sample slopes: it never
    exceeds the steepest true slope, even across the kink an FOPDT response
    has at its dead time (a cubic fit overshoots there).

    The window is ``window_s`` seconds when given, else :func:`tangent_window`
    (from the noise ``sigma``, the step ``span`` and the 10-90 % ``rise_s``).
    Returns ``(t, ys, dy)`` on a uniform grid (resampled when the input grid is
    not uniform).

    Parameters
    ----------
    t, y : array_like
        The record.
    window_s : float, optional
        The window (s).
    sigma : float
        The noise's standard deviation.
    span : float
        The step's change.
    rise_s : float, optional
        The 10-90 % rise time (s).
    polyorder : int
        The polynomial's order.

    Returns
    -------
    tuple of numpy.ndarray
        (t, ys, dy).
    """
    tu, yu = uniform(t, y)
    dt = float((tu[-1] - tu[0]) / max(tu.size - 1, 1))
    w = window_size(dt, tu.size, window_s=window_s, sigma=sigma, span=span, rise_s=rise_s)
    poly = min(polyorder, w - 1)
    return tu, savgol(yu, w, poly), savgol(yu, w, poly, deriv=1, delta=dt)


# --------------------------------------------------------------------------- peaks


def parabola_vertex(x, y) -> tuple:
    """Vertex of the parabola through three points, or of the least-squares
    parabola through more: ``(x_vertex, y_vertex, a)`` with ``a`` the
    coefficient of x^2 (negative for a maximum); nan, nan, 0 for a line.

    Parameters
    ----------
    x, y : array_like
        Three points or more.

    Returns
    -------
    tuple of float
        (x_vertex, y_vertex, a).
    """
    x = np.asarray(x, float)
    y = np.asarray(y, float)
    xc = float(x[x.size // 2])          # centred, so the fit stays well conditioned
    if x.size == 3:
        x0, x1, x2 = x - xc
        s01, s12 = (y[1] - y[0]) / (x1 - x0), (y[2] - y[1]) / (x2 - x1)
        a = (s12 - s01) / (x2 - x0)
        b = s01 - a * (x0 + x1)          # the slope at x = xc
        c = float(y[1])
    else:
        a, b, c = np.polyfit(x - xc, y, 2)
    if a == 0 or not math.isfinite(a):
        return math.nan, math.nan, 0.0
    return xc - b / (2.0 * a), float(c - b * b / (4.0 * a)), float(a)


def peak_region(y, i: int, drop: float, *, lo: int = 0, hi: int | None = None,
                min_half: int = 1) -> tuple:
    """``(j0, j1)``: the samples of ``y[lo:hi]`` around the peak sample ``i``
    that stay within ``drop`` of it (contiguous), widened to at least
    ``min_half`` each side (inside the record): the top of a noisy peak, which
    a least-squares parabola averages over.

    Parameters
    ----------
    y : array_like
        The record.
    i : int
        The peak sample.
    drop : float
        How far below the peak a sample of the top may be.
    lo, hi : int
        The part of the record searched (``hi`` None: its end).
    min_half : int
        The fewest samples each side.

    Returns
    -------
    tuple of int
        (j0, j1).
    """
    y = np.asarray(y, float)
    hi = y.size if hi is None else hi
    top = y[lo:hi] >= y[i] - drop
    k = i - lo
    left = np.nonzero(~top[:k])[0]
    right = np.nonzero(~top[k:])[0]
    j0 = lo + (int(left[-1]) + 1 if left.size else 0)
    j1 = i + (int(right[0]) - 1 if right.size else hi - 1 - i)
    return max(min(j0, i - min_half), 0), min(max(j1, i + min_half), y.size - 1)


def refine_peak(t, y, i: int, *, lo: int | None = None, hi: int | None = None,
                smooth_only: bool = False) -> tuple:
    """The maximum of a sampled peak whose highest sample is ``i``: ``(t, y, a)``.

    The vertex of the parabola through samples ``lo..hi`` (default: ``i`` and
    its two neighbours; a least-squares parabola through more, for a noisy
    peak), kept when it is a maximum inside them; else the sample itself
    (at either end of the record, on a flat top), with ``a`` = 0. ``a`` is the
    parabola's coefficient of t^2 (half the curvature of the peak).

    ``smooth_only`` also keeps the sample at a kink (a neighbour well below
    the top: an FOPDT's slope jumps at its dead time), where a parabola would
    overshoot the true maximum.

    Parameters
    ----------
    t, y : array_like
        The record.
    i : int
        The highest sample.
    lo, hi : int, optional
        The samples the parabola goes through.
    smooth_only : bool
        Keep the sample at a kink.

    Returns
    -------
    tuple of float
        (t, y, a).
    """
    lo = i - 1 if lo is None else lo
    hi = i + 1 if hi is None else hi
    keep = float(t[i]), float(y[i]), 0.0
    if lo < 0 or hi > len(y) - 1 or hi - lo < 2 or not lo < i < hi:
        return keep
    if smooth_only and not min(y[i - 1], y[i + 1]) > 0.99 * y[i]:
        return keep
    tv, yv, a = parabola_vertex(t[lo:hi + 1], y[lo:hi + 1])
    if a < 0 and t[lo] <= tv <= t[hi]:
        return float(tv), yv, a
    return keep


# --------------------------------------------------------------------------- tangent

#: The window's slope noise is kept under this fraction of the typical slope
#: span / rise (see :func:`tangent_window`) ...
SLOPE_NOISE = 0.005
#: ... with a window of at most this fraction of the 10-90 % rise time.
MAX_WINDOW_OF_RISE = 0.1
#: A derivative whose noise is under this fraction of its peak is clean: the
#: peak is refined through three samples, else over its noisy top.
CLEAN_SLOPE_NOISE = 1e-4


def tangent_window(dt: float, n: int, *, sigma: float = 0.0, span: float = 1.0,
                   rise_s: float | None = None, slope_noise: float = SLOPE_NOISE) -> int:
    """The one smoothing window (odd, samples) of the derivative a tangent is read on.

    The narrowest window that keeps the slope's noise, sigma sqrt(12 / w^3) / dt
    for w samples, under ``slope_noise`` (:data:`SLOPE_NOISE`) of the typical
    slope span / rise_s
    (10-90 % rise time; a tenth of the record if not given), and at most
    :data:`MAX_WINDOW_OF_RISE` of the rise time: a wider window flattens the
    corner an FOPDT response has at its dead time, whose slope the tangent
    needs (a smooth peak would take a wider one). Clean data get 5 samples,
    so tangents stay exact.

    Parameters
    ----------
    dt : float
        The sample interval (s).
    n : int
        The record's samples.
    sigma : float
        The noise's standard deviation.
    span : float
        The step's change.
    rise_s : float, optional
        The 10-90 % rise time (s).
    slope_noise : float
        The slope's noise allowed, as a fraction of the typical slope.

    Returns
    -------
    int
        The window (samples).
    """
    if sigma > 0 and span:
        if not (rise_s and math.isfinite(rise_s) and rise_s > 0):
            rise_s = n * dt / 10.0
        slope = abs(span) / rise_s
        w = math.ceil((12.0 * (sigma / (dt * slope_noise * slope)) ** 2) ** (1.0 / 3.0))
        w = min(w, max(5, int(MAX_WINDOW_OF_RISE * rise_s / dt)))
    else:
        w = 5
    return odd_window(w, n)


@dataclass(frozen=True)
class Tangent:
    """The tangent at the steepest point of a step response.

    ``t``, ``y`` and ``slope`` locate it (times as the record's); ``window_s``
    is the smoothing window of the derivative it was read on; ``interior`` is
    False when the steepest point is the record's first or last sample (no
    inflection: a first-order response, or a truncated record).
    """

    t: float
    y: float
    slope: float
    window_s: float = 0.0
    interior: bool = True

    @property
    def t_base(self) -> float:
        """Where the tangent meets y = 0 (the baseline of a response from 0)."""
        return self.t - self.y / self.slope

    def t_level(self, level: float) -> float:
        """Where the tangent meets ``level``."""
        return self.t + (level - self.y) / self.slope


def inflection_tangent(t, y, final: float, *, sigma: float | None = None,
                       window_s: float | None = None) -> Tangent:
    """Tangent at the point of maximum slope (towards ``final``) of a step response.

    Parameters
    ----------
    t, y : array_like
        Time since the step and the response, starting from 0 (a step up or
        down); resampled to a uniform grid when it is not one.
    final : float
        The settled value; only the rise up to where the smoothed response
        first reaches it is searched (later slopes, ringing, are not the
        reaction curve's).
    sigma : float, optional
        Noise standard deviation of ``y`` (default :func:`noise_sigma`).
    window_s : float, optional
        Smoothing window in seconds (default :func:`tangent_window`).

    Returns
    -------
    Tangent

    Notes
    -----
    The slope is the quadratic Savitzky-Golay derivative, the least-squares
    slope over the window. Its maximum is the vertex of a parabola: through
    the highest sample and its neighbours on a clean record (not across a
    kink), fitted over the peak's top (the samples within three noise
    deviations of the highest, at least half a window each side) on a noisy
    one, so that the noise's largest excursion does not pass for the slope.
    The window's own flattening of a smooth peak, a h^2 (3 m^2 + 3 m - 1) / 15
    for a parabola a t^2 + ... and a window of 2 m + 1 samples h apart (the
    least-squares slope's bias, f''' h^2 (3 m^2 + 3 m - 1) / 30), is taken
    back out. The level is the smoothed response there (unbiased at an
    inflection), so a dense noise-free record gives the analytic tangent.
    """
    y = np.asarray(y, float)
    sigma = noise_sigma(y) if sigma is None else sigma
    sgn = 1.0 if final >= 0 else -1.0
    ya = sgn * y
    rise = (crossing_time(t, ya, 0.9 * abs(final), sigma=sigma)
            - crossing_time(t, ya, 0.1 * abs(final), sigma=sigma))
    ts, ys, dy = smooth_derivative(t, y, window_s=window_s, sigma=sigma, span=final,
                                   rise_s=rise)
    h = float((ts[-1] - ts[0]) / max(ts.size - 1, 1))
    w = window_size(h, ts.size, window_s=window_s, sigma=sigma, span=final, rise_s=rise)
    d = sgn * dy
    reach = np.nonzero(sgn * ys >= abs(final))[0]
    stop = int(reach[0]) + 1 if reach.size else ts.size
    i = int(np.argmax(d[:stop]))
    m = w // 2
    noise = sigma * math.sqrt(12.0 / (w * (w * w - 1.0))) / h    # of one slope sample
    if noise <= CLEAN_SLOPE_NOISE * abs(d[i]):
        t_i, s_i, a = refine_peak(ts, d, i, smooth_only=True)
        # the flattening below assumes a peak smooth across the window: a kink
        # two samples off passes the three-sample test, not this one
        if a and 2 <= i < d.size - 2 and \
                abs(parabola_vertex(ts[i - 2:i + 3:2], d[i - 2:i + 3:2])[2] - a) > 0.25 * abs(a):
            a = 0.0
    else:
        j0, j1 = peak_region(d, i, 3.0 * noise, hi=stop, min_half=m)
        t_i, s_i, a = refine_peak(ts, d, i, lo=j0, hi=j1)
    s_i -= a * h * h * (3 * m * m + 3 * m - 1) / 15.0
    return Tangent(t=t_i, y=float(np.interp(t_i, ts, ys)), slope=sgn * s_i, window_s=w * h,
                   interior=0 < i < ts.size - 1)
