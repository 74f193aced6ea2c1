"""Step-response metrics for any waveform: analytic, simulated or measured.

One pure function, :func:`step_metrics`, takes time and output arrays and
returns a :class:`StepMetrics`. Crossing times are linearly interpolated
between samples and the peak is refined with a parabola through its three
samples (:mod:`designer.core.waveform`), so a dense grid gives figures accurate to a small fraction of the
sample spacing (python-control's automatic grid can be ~4 % off on rise time).
"""

from __future__ import annotations

import math
from dataclasses import asdict, dataclass

import numpy as np

from .errors import DesignError
from .jsonio import json_safe
from .waveform import crossing_time, normalised_step, refine_peak

__all__ = ["Overshoot", "StepMetrics", "measure_step", "step_metrics"]

#: Slope noise of the smoothing before figures are measured on noisy data (see
#: :func:`measure_step`): a value needs less smoothing than a slope's maximum.
MEASURE_SLOPE_NOISE = 0.02
#: A ripple under this fraction of the step is left to the smoothing.
RIPPLE_FLOOR = 1e-3
#: Standard uncertainties an overshoot may differ by from a model's (or from 0)
#: and still be the same (see :meth:`Overshoot.differs`).
OVERSHOOT_SIGMAS = 4.0
#: A model's overshoot may differ from the measured one by this much (% of the
#: step) plus :data:`OVERSHOOT_SIGMAS` uncertainties plus
#: :data:`OVERSHOOT_REL` of the larger of the two: the classical correlations'
#: own error (a first-order method allows 2 % overshoot, seed 000).
OVERSHOOT_ABS_PCT = 2.0
#: See :data:`OVERSHOOT_ABS_PCT`.
OVERSHOOT_REL = 0.25


@dataclass(frozen=True)
class StepMetrics:
    """Classical step-response figures; times are measured from the step."""

    final_value: float
    overshoot_pct: float
    peak_time_s: float
    peak_value: float
    rise_time_s: float            #: 10 % to 90 %
    rise_time_0_100_s: float      #: 0 % to first reaching 100 % (nan if never overshoots)
    settling_time_s: float        #: 2 % band
    settling_time_5pct_s: float   #: 5 % band

    def to_dict(self) -> dict:
        return json_safe(asdict(self))


@dataclass(frozen=True)
class Overshoot:
    """The overshoot measured on a record (% of the change) and its standard
    uncertainty: the noise left on the record it was measured on (after the
    smoothing and the ripple removal of :func:`measure_step`), % of the change.

    The one figure every validity check of a model against the data uses."""

    pct: float
    sigma_pct: float

    def text(self) -> str:
        """``"9.09 % (noise ±0.15 %)"``."""
        return f"{self.pct:.2f} % (noise ±{self.sigma_pct:.2g} %)"

    def tolerance(self, model_pct: float = 0.0) -> float:
        """How far (% of the step) a model's overshoot may lie from this one."""
        return (OVERSHOOT_ABS_PCT + OVERSHOOT_SIGMAS * self.sigma_pct
                + OVERSHOOT_REL * max(self.pct, model_pct))

    def differs(self, model_pct: float) -> bool:
        """True when a model overshooting ``model_pct`` % cannot have made these data."""
        return abs(model_pct - self.pct) > self.tolerance(model_pct)

    def above_noise(self) -> bool:
        """True when the overshoot is clearly there (over 4 uncertainties and 0.2 %)."""
        return self.pct > OVERSHOOT_SIGMAS * self.sigma_pct + 0.2

    def to_dict(self) -> dict:
        return json_safe(asdict(self))


def settling_time(t, y, final, span, band) -> float:
    """Last time ``y`` is outside ``final +/- band*|span|``, interpolated onto the band edge."""
    t = np.asarray(t, float)
    err = np.abs(np.asarray(y, float) - final)
    tol = band * abs(span)
    outside = np.nonzero(err > tol)[0]
    if outside.size == 0:
        return float(t[0])
    i = outside[-1]
    if i == len(t) - 1:
        return math.nan  # never settles inside the record
    e0, e1 = err[i], err[i + 1]
    frac = (e0 - tol) / (e0 - e1) if e0 != e1 else 0.0
    return float(t[i] + frac * (t[i + 1] - t[i]))


def step_metrics(t, y, *, t_step: float | None = None, initial: float | None = None,
                 final: float | None = None) -> StepMetrics:
    """Metrics of a step response.

    Parameters
    ----------
    t, y : array_like
        Time (increasing) and response. Works for steps up or down.
    t_step : float, optional
        When the step was applied; default ``t[0]``. Samples before it are ignored
        and times are reported from it.
    initial : float, optional
        Output before the step; default the first sample at or after ``t_step``.
    final : float, optional
        Settled output; default the last sample.

    Returns
    -------
    StepMetrics
    """
    t = np.asarray(t, float)
    y = np.asarray(y, float)
    if t.ndim != 1 or t.shape != y.shape or t.size < 3:
        raise DesignError("step metrics need matching 1-D time and output arrays of 3+ samples")
    if not (np.all(np.isfinite(t)) and np.all(np.isfinite(y))):
        raise DesignError("step metrics: the waveform contains NaN or infinite samples")
    if np.any(np.diff(t) <= 0):
        raise DesignError("step metrics: time must be strictly increasing")
    # normalised to a rising 0 -> 1 step so one code path handles steps down
    t, z, y0, yf = normalised_step(t, y, t_step=t_step, initial=initial, final=final,
                                   what="step metrics")
    span = yf - y0
    ip = int(np.argmax(z))
    zp, tp = float(z[ip]), float(t[ip])
    # refined between evenly spaced samples only (SPICE's own time steps are
    # not: there the sample is the figure, as the committed references have it)
    if 0 < ip < len(z) - 1 and np.isclose(t[ip + 1] - t[ip], t[ip] - t[ip - 1], rtol=1e-6):
        tp, zp, _ = refine_peak(t, z, ip)
    overshoot = max(0.0, (zp - 1.0) * 100.0)
    t10 = crossing_time(t, z, 0.1)
    t90 = crossing_time(t, z, 0.9)
    t100 = crossing_time(t, z, 1.0) if zp > 1.0 else math.nan
    if overshoot == 0.0:
        # monotone response: "peak" is where it gets to its final value
        tp = math.nan
    return StepMetrics(
        final_value=yf,
        overshoot_pct=overshoot,
        peak_time_s=tp,
        peak_value=float(y0 + zp * span),
        rise_time_s=t90 - t10,
        rise_time_0_100_s=t100,
        settling_time_s=settling_time(t, z, 1.0, 1.0, 0.02),
        settling_time_5pct_s=settling_time(t, z, 1.0, 1.0, 0.05),
    )


def measure_step(t, y, *, t_step: float | None = None, initial: float | None = None,
                 final: float | None = None, lsb: float = 0.0, sigma: float = 0.0) -> tuple:
    """Step-response figures of a measured record, and its :class:`Overshoot`.

    Noise spikes and switching ripple would read as overshoot, so on a noisy
    record (``sigma`` > 0) the figures are measured on a cleaned copy: a
    periodic ripple found on the settled last quarter
    (:func:`~designer.core.waveform.periodic_ripple`) is subtracted and what is
    left of it averaged over one of its periods, then a
    Savitzky-Golay filter smooths what is left (the window of a 2 % slope
    noise, :data:`MEASURE_SLOPE_NOISE`). The overshoot's uncertainty is the
    spread of that cleaned record over its settled last quarter, at least the
    white noise the filter lets through. An overshoot within one quantisation
    step ``lsb`` is none.

    Parameters
    ----------
    t, y : array_like
        Time (increasing; resampled when not uniform) and response, from the step on.
    t_step, initial, final : float, optional
        As for :func:`step_metrics`.
    lsb : float
        Quantisation step of ``y`` (0 when it is not quantised).
    sigma : float
        Noise of ``y``; 0 measures the record as it is (the uncertainty is then 0).

    Returns
    -------
    (StepMetrics, Overshoot)
    """
    from .waveform import (moving_average, noise_sigma, periodic_ripple, savgol, spread, tangent_window,
                           uniform)
    t = np.asarray(t, float)
    y = np.asarray(y, float)
    y0 = float(y[0]) if initial is None else float(initial)
    yf = float(y[-1]) if final is None else float(final)
    span = yf - y0
    sig_pct = 0.0
    if sigma > 0 and t.size > 50 and span:
        t, y = uniform(t, y)
        tail = t.size - t.size // 4
        dt = float((t[-1] - t[0]) / (t.size - 1))
        ripple = periodic_ripple(t, y, tail, floor=RIPPLE_FLOOR * abs(span))
        if ripple is not None:
            # what the settled stretch's fit leaves during the transient (the
            # ripple changes with the duty cycle) averages out over one period
            y = moving_average(y - ripple[0], max(1, round(ripple[1] / dt)))
        white = noise_sigma(y)
        w = tangent_window(dt, t.size, sigma=white, span=span, slope_noise=MEASURE_SLOPE_NOISE)
        y = savgol(y, w, 2)
        # white noise through the filter: sqrt(sum of the centre kernel's squares)
        h = w // 2
        x = np.arange(-h, h + 1, dtype=float)
        gain = math.sqrt(float(np.sum(np.linalg.pinv(np.vander(x, 3, increasing=True))[0] ** 2)))
        sig_pct = 100.0 * max(spread(y[tail:]), white * gain) / abs(span)
    m = step_metrics(t, y, t_step=t_step, initial=initial, final=final)
    # an overshoot within one quantisation step is not one: an 8-bit trace
    # sitting one LSB above its mean
    if m.overshoot_pct > 0 and abs(m.peak_value - m.final_value) <= lsb:
        from dataclasses import replace
        m = replace(m, overshoot_pct=0.0, rise_time_0_100_s=math.nan)
    return m, Overshoot(m.overshoot_pct, sig_pct)
