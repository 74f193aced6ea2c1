"""The impulse response from the input-output cross-correlation (seed 003,
section 2.4): small pure functions on arrays.

For a maximum-length sequence of levels +-a, N intervals of Dt per period,
the circular autocorrelation over a whole period is an impulse of area
(N + 1) a^2 Dt / N on a floor of -a^2/N (eq. 2.4.6), so the cross-correlation
of input and output over whole periods (eq. 2.4.9, here with the sum of eq.
2.4.18 over every sample of a period, computed by FFT) is

    phi_xy(tau) = a^2 (N + 1) Dt / N h(tau) - a^2/N int_0^T h(s) ds    (2.4.7)

and the impulse response (eq. 2.4.19)

    h(tau) = N / (a^2 (N + 1) Dt) [phi_xy(tau) - phi_xy((N - 1) Dt)]

where phi_xy late in the period, once h has died out, is the constant
("DC") term. Here that constant is the mean of phi_xy over the last stretch of
the period (:data:`TAIL_FRACTION`, at least one interval) rather than the one
point the seed takes, so the noise of one sample does not shift the whole
curve; an output offset, and the input's offset, only add constants and are
removed with it. (Seed misprints: eq. 2.4.13 writes N - 1 for N + 1, and eq.
2.4.14 phi_xx for phi_xy; the seed's own program used N = 33, which is no
m-sequence length.)

The sequence is a zero-order hold of the bits, so its true autocorrelation
is a triangle of half-width Dt, not an impulse: the estimate is h smoothed by
that triangle (a jump of h at t = 0 is spread over +-Dt, the first interval
before t = 0 included: the estimate starts at t = -Dt).

Settling (:func:`settling_check`): a period shorter than the response's
settling time wraps the impulse response around (its tail is added to its
head, and the DC term then removes part of the response): said so, with the
bits or clock that would have been enough, estimated from the decay of the
tail (a wrapped exponential keeps its time constant). The test is on the
slowest mode, not on the step's 2 % settling nor on the impulse response's
peak: a slow mode of small amplitude can hold much of the gain (the seed's
furnace: 0.877 e^(-t/105) against 43.9 e^(-t/18.5), 10 % of the static gain
for 2 % of the peak), so its e^(-t/tau) must itself decay to 2 % within the
period, with plan_for_plant's margin: period >= 1.2 ln(50) tau (FACTS.md:
the furnace's 105 min mode needs about 500 min, N = 255 at Dt = 3 min; the
step's 2 % settling, 175 min, would pass 6 bits, whose late response is
5-20 % short and gain 4 % short).
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

from ..core.prbs import SETTLE_MARGIN

__all__ = ["DECAY", "circular_xcorr", "mls_impulse", "rms_error", "settling_check", "settling_time"]

#: the DC term is the mean of phi_xy over this last fraction of the period
TAIL_FRACTION = 0.1
#: the step response counts as settled inside +-this fraction of its final value
SETTLE_BAND = 0.02
#: the impulse response must be flat over this last fraction of the period
TAIL_CHECK = 0.3
#: within this fraction of its peak
FLAT_FRACTION = 0.005
#: time constants a mode takes to decay to SETTLE_BAND of itself: ln(1/0.02) = 3.9
DECAY = math.log(1.0 / SETTLE_BAND)
#: a tail drifting by less than this fraction of the peak is settled whatever its shape
TAIL_FLOOR = 1e-4


def period_mean(x, start: int, period: int, count: int) -> np.ndarray:
    """Mean of ``count`` consecutive periods of ``period`` samples from ``start``."""
    seg = np.asarray(x, float)[start:start + period * count]
    return seg.reshape(count, period).mean(axis=0)


def circular_xcorr(x, y) -> np.ndarray:
    """phi[k] = (1/P) sum_i x[i] y[(i + k) mod P] over one period (eq. 2.4.18), by FFT.

    Parameters
    ----------
    x, y : array_like
        One period of the input and of the output, of the same length P.

    Returns
    -------
    numpy.ndarray
        phi[k] for k = 0 .. P - 1.
    """
    x = np.asarray(x, float)
    y = np.asarray(y, float)
    p = x.size
    return np.fft.irfft(np.conj(np.fft.rfft(x)) * np.fft.rfft(y), n=p) / p


@dataclass
class ImpulseEstimate:
    """The impulse response ``h`` (output units per input unit per second) at
    times ``t`` (from -Dt), the step response ``step`` (its running integral),
    the DC term removed, the settling time of ``step`` and the period."""

    t: np.ndarray
    h: np.ndarray
    step: np.ndarray
    dc: float
    period_s: float
    dt_s: float
    settling_s: float
    wrapped: bool = False
    tail_tau_s: float = math.nan

    def to_dict(self) -> dict:
        return {"dt_s": self.dt_s, "period_s": self.period_s, "dc_term": self.dc,
                "settling_time_s": self.settling_s, "wrapped": self.wrapped,
                "tail_time_constant_s": self.tail_tau_s, "samples": int(self.t.size),
                "peak": float(self.h[np.argmax(np.abs(self.h))]),
                "gain": float(self.step[-1])}


def mls_impulse(x, y, *, n: int, dt_s: float, ts: float, amplitude: float) -> ImpulseEstimate:
    """The impulse response from one period (averaged) of an MLS input ``x``
    (offset removed: +-``amplitude``) and the output ``y``, sampled every
    ``ts`` with ``dt_s`` = m ts per interval and ``n`` intervals per period.

    Eq. 2.4.19 with the DC term from the tail (see the module docstring).

    Parameters
    ----------
    x : array_like
        One period of the input, offset removed.
    y : array_like
        The output over the same samples.
    n : int
        Intervals (bits) per MLS period.
    dt_s : float
        Length of one interval in s.
    ts : float
        Sample period in s.
    amplitude : float
        The input's half swing.

    Returns
    -------
    ImpulseEstimate
        The impulse and step responses on lags from -dt_s, the DC term, the
        period, and the settling check's fields.
    """
    x = np.asarray(x, float)
    y = np.asarray(y, float)
    p = x.size
    m = max(int(round(dt_s / ts)), 1)
    phi = circular_xcorr(x, y - y.mean())
    # lags from -Dt: the triangle's leading half sits at the end of the period
    phi = np.roll(phi, m)
    t = (np.arange(p) - m) * ts
    w = max(m, int(TAIL_FRACTION * p))
    tail = slice(max(p - w, m + 1), p)
    dc = float(phi[tail].mean())
    scale = n / (amplitude * amplitude * (n + 1) * dt_s)
    h = scale * (phi - dc)
    step = np.cumsum(h) * ts
    est = ImpulseEstimate(t, h, step, dc * scale, p * ts, dt_s, math.nan)
    settling_check(est, m)
    return est


def white_impulse(x, y, *, ts: float, max_lag: int) -> ImpulseEstimate:
    """The impulse response for a white (noise) input of variance s^2: phi_xy = s^2 ts h
    (eq. 2.4.4 with k = s^2 ts), over lags 0..``max_lag`` (linear, not circular)."""
    x = np.asarray(x, float) - np.mean(x)
    y = np.asarray(y, float) - np.mean(y)
    n = x.size
    nfft = 1 << int(math.ceil(math.log2(2 * n)))
    phi = np.fft.irfft(np.conj(np.fft.rfft(x, nfft)) * np.fft.rfft(y, nfft), nfft)[:max_lag] / n
    var = float(np.mean(x * x))
    h = phi / (var * ts)
    t = np.arange(max_lag) * ts
    step = np.cumsum(h) * ts
    est = ImpulseEstimate(t, h, step, 0.0, max_lag * ts, ts, math.nan)
    settling_check(est)
    return est


def wiener_impulse(x, y, *, ts: float, max_lag: int) -> ImpulseEstimate:
    """The impulse response for a coloured (not white) input: the Wiener-Hopf
    equations sum_j r_xx(k - j) g_j = r_xy(k), k = 0..``max_lag`` - 1 (Ljung,
    *System Identification*, 2nd ed., section 6.1, the correlation analysis
    with a prewhitening filter; Box and Jenkins' prewhitening in its
    finite-lag form), solved with the input's own autocorrelation by
    Levinson's recursion (``scipy.linalg.solve_toeplitz``); g is the pulse
    response per sample, h = g / ts. A white input gives r_xx = s^2 delta
    and :func:`white_impulse` back.

    Parameters
    ----------
    x, y : array_like
        Input and output (means removed here).
    ts : float
        Sample interval (s).
    max_lag : int
        Lags of the impulse response.

    Returns
    -------
    ImpulseEstimate
        Linear (not circular) correlations, no DC term.
    """
    from scipy.linalg import solve_toeplitz
    x = np.asarray(x, float) - np.mean(x)
    y = np.asarray(y, float) - np.mean(y)
    n = x.size
    nfft = 1 << int(math.ceil(math.log2(2 * n)))
    fx = np.fft.rfft(x, nfft)
    rxy = np.fft.irfft(np.conj(fx) * np.fft.rfft(y, nfft), nfft)[:max_lag] / n
    rxx = np.fft.irfft(np.abs(fx) ** 2, nfft)[:max_lag] / n
    g = solve_toeplitz(rxx, rxy)
    h = g / ts
    t = np.arange(max_lag) * ts
    est = ImpulseEstimate(t, h, np.cumsum(h) * ts, 0.0, max_lag * ts, ts, math.nan)
    settling_check(est)
    return est


@dataclass(frozen=True)
class InputWhiteness:
    """What the correlation route may assume of the input.

    Attributes
    ----------
    kind : str
        ``"m-sequence"`` (its periodic autocorrelation is the seed's impulse),
        ``"white"`` (every lag of its normalised autocorrelation inside
        :data:`WHITE_MARGIN` times the 99 % band) or ``"coloured"``.
    lags : numpy.ndarray
        Lags 1.. (samples).
    r : numpy.ndarray
        The normalised autocorrelation at those lags.
    band : float
        The 99 % band of a white sequence, 2.576/sqrt(N) (Ljung section 16.6).
    """

    kind: str
    lags: np.ndarray
    r: np.ndarray
    band: float

    def text(self) -> str:
        """One line: the verdict and the largest lag's correlation."""
        i = int(np.argmax(np.abs(self.r)))
        return (f"input {self.kind}: autocorrelation at lag {int(self.lags[i])} {self.r[i]:+.3f} "
                f"(white: inside +-{self.band:.3f})")

    def to_dict(self) -> dict:
        """JSON-ready.

        Returns
        -------
        dict
            ``kind``, ``lags``, ``r``, ``band``.
        """
        return {"kind": self.kind, "lags": [int(k) for k in self.lags], "r": [float(v) for v in self.r],
                "band": self.band}


#: a white input's autocorrelation stays inside this many times its 99 % band at every lag
#: (25 lags of a white sequence: each beyond 1.5 x 2.576 sigma with probability 1e-4)
WHITE_MARGIN = 1.5
#: lags of the input's whiteness check (``resid``'s 25)
WHITE_LAGS = 25


def input_whiteness(x, mls: bool = False) -> InputWhiteness:
    """The input's normalised autocorrelation at lags 1..:data:`WHITE_LAGS`
    against the 99 % band of a white sequence.

    Parameters
    ----------
    x : array_like
        The input.
    mls : bool
        The input is a clean maximum-length sequence (its verdict, whatever the
        clock's hold does to the lags).

    Returns
    -------
    InputWhiteness
    """
    x = np.asarray(x, float) - np.mean(x)
    n = x.size
    lags = np.arange(1, min(WHITE_LAGS, n - 1) + 1)
    var = float(x @ x) / n
    r = np.array([x[:n - k] @ x[k:] / n for k in lags]) / var if var > 0 else np.zeros(lags.size)
    band = 2.5758293035489004 / math.sqrt(n)
    kind = "m-sequence" if mls else "white" if np.all(np.abs(r) <= WHITE_MARGIN * band) else "coloured"
    return InputWhiteness(kind, lags, r, band)


def settling_time(t, step, band: float = SETTLE_BAND) -> float:
    """The last time ``step`` is outside +-band of its final value (the mean of its last tenth).

    Parameters
    ----------
    t : array_like
        Times in s.
    step : array_like
        Step response at ``t``.
    band : float, optional
        Relative band around the final value.

    Returns
    -------
    float
        Settling time in s (``t[0]`` if the response never leaves the band).
    """
    k = max(int(0.1 * step.size), 1)
    final = float(np.mean(step[-k:]))
    out = np.nonzero(np.abs(step - final) > band * abs(final))[0]
    if out.size == 0 or final == 0:
        return float(t[0])
    i = int(out[-1])
    return float(t[min(i + 1, t.size - 1)])


def _window_means(h, start: int, parts: int = 3) -> list:
    w = max((h.size - start) // parts, 1)
    return [float(np.mean(h[start + i * w:start + (i + 1) * w])) for i in range(parts)], w


def tail_time_constant(t, h, start: int) -> float:
    """The time constant of the decay of ``h`` from sample ``start`` on, from three
    window means (a wrapped exponential plus a constant keeps its time
    constant); nan when the tail does not decay monotonically."""
    (m1, m2, m3), w = _window_means(h, start)
    d1, d2 = m1 - m2, m2 - m3
    if d1 == 0 or d2 == 0 or (d1 > 0) != (d2 > 0) or abs(d2) >= abs(d1):
        return math.nan
    return float(w * (t[1] - t[0]) / math.log(d1 / d2))


def tail_drift(h, start: int, per_bit: int) -> tuple:
    """(change of ``h`` across its tail from sample ``start``, the noise of that
    change): the first and last of three window means, and their standard
    error from the tail's sample-to-sample noise (correlated over ``per_bit``
    samples, the sequence's interval)."""
    (m1, _, m3), w = _window_means(h, start)
    tail = h[start:]
    d2 = np.diff(tail, 2)
    sigma = float(np.std(d2) / math.sqrt(6.0)) if d2.size > 2 else 0.0
    se = sigma * math.sqrt(2.0 * max(per_bit, 1) / w)
    return m1 - m3, se


def settling_check(est: ImpulseEstimate, per_bit: int = 1) -> None:
    """Fill ``settling_s``, ``wrapped`` and ``tail_tau_s`` of an estimate: it has
    wrapped around when the impulse response still drifts over the period's
    last :data:`TAIL_CHECK` (by more than :data:`FLAT_FRACTION` of its peak and
    three times its noise). (The step response's own settling time is no test:
    its noise is the running sum of h's, a random walk that leaves a 2 % band
    on a noisy record however long the period.)

    Parameters
    ----------
    est : ImpulseEstimate
        The estimate to fill in place.
    per_bit : int, optional
        Samples per MLS interval.
    """
    est.settling_s = settling_time(est.t, est.step)
    start = int((1.0 - TAIL_CHECK) * est.h.size)
    drift, se = tail_drift(est.h, start, per_bit)
    peak = float(np.max(np.abs(est.h)))
    flat = abs(drift) <= max(FLAT_FRACTION * peak, 3.0 * se)
    # a tail still decaying above its noise: its mode must die out within the period (module docstring)
    tau = (tail_time_constant(est.t, est.h, start) if abs(drift) > max(TAIL_FLOOR * peak, 3.0 * se)
           else math.nan)
    short = math.isfinite(tau) and SETTLE_MARGIN * DECAY * tau > est.period_s
    est.wrapped = not flat or short
    if est.wrapped:
        est.tail_tau_s = tau


def needed_period(est: ImpulseEstimate) -> tuple:
    """(the period a wrapped estimate needs, whether that is only a lower bound),
    before plan_for_plant's margin.

    When the tail's own time constant tau explains the wrap (its mode has not
    decayed to 2 %, ln(50) tau, within the period) the tail shows the slow
    mode: ln(50) tau is what it needs. Else the tail may hide a slower mode
    (a period too short to show it: the furnace's 105 min mode under the
    18.5 min one in a 93 min period): at least the period plus ln(50) tau
    (what is left at the period's end dies out in about that), a lower bound
    on the safe side; a run with it measures again. Never less than the step's
    settling time."""
    tau = est.tail_tau_s
    if not math.isfinite(tau):
        return max(est.settling_s, est.period_s), True
    if DECAY * tau > est.period_s:
        return max(est.settling_s, DECAY * tau), False
    return max(est.settling_s, est.period_s + DECAY * tau), True


def rms_error(t, h_est, h_true, t0: float, t1: float) -> float:
    """RMS of ``h_est - h_true`` over t0 <= t <= t1, relative to the peak of |h_true|.

    Parameters
    ----------
    t : array_like
        Times of the samples in s.
    h_est, h_true : array_like
        The estimated and the true impulse response at ``t``.
    t0, t1 : float
        The time window compared, in s.

    Returns
    -------
    float
        Relative RMS error.
    """
    sel = (t >= t0) & (t <= t1)
    err = np.asarray(h_est)[sel] - np.asarray(h_true)[sel]
    return float(np.sqrt(np.mean(err * err)) / np.max(np.abs(np.asarray(h_true)[sel])))
