"""The normalised step response (:class:`PreparedStep`) and one step's
normalisation, shared by :mod:`designer.identify.preprocess` (a single step)
and :mod:`designer.identify.averaging` (a square wave's one full edge, or the
average of all of them).

A step at ``t_step`` becomes ``t`` (time since the step), ``y`` (deviation
from the pre-step baseline divided by the input step amplitude) and ``yf``
(its settled value = static gain): :func:`single_step` takes the baseline from the
output's rest before the step and the final value from its settled tail
(:mod:`designer.identify.settle`), and refuses a step lost in the noise
(:data:`~designer.identify.edges.MIN_STEP_SNR`) or outside its physical range
(:func:`check_step`, :func:`check_amplitude`).
"""

from __future__ import annotations

import math
from dataclasses import dataclass, field

import numpy as np

from ..core.errors import DesignError
from ..core.ranges import RANGES
from ..core.waveform import noise_sigma
from .edges import MIN_SAMPLES, MIN_STEP_SNR, number_text
from .settle import SETTLE_TOL, Rest, block_mean, final_value, settled_before

__all__ = []

#: Fewest samples at rest before a step for a baseline.
MIN_REST = 3


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


def check_step(y0, yf, sigma, what="the response"):
    span = yf - y0
    if span == 0 or abs(span) < MIN_STEP_SNR * sigma:
        ratio = abs(span) / sigma if sigma > 0 else 0.0
        raise DesignError(
            f"no usable step in {what}: the change from the baseline ({y0:.4g}) to the final "
            f"value ({yf:.4g}) is {ratio:.1f} noise standard deviations; at least "
            f"{MIN_STEP_SNR:.0f} are needed (use a larger step or average captures)")
    RANGES["output_step"].check(abs(span), f"the size of the step in {what} (final value - "
                                "baseline)", shown=number_text(span))


def check_amplitude(amp: float, what: str) -> float:
    """``amp`` if its size is inside ``RANGES["step_amplitude"]`` (either sign)."""
    if not (math.isfinite(amp) and amp != 0):
        raise DesignError(f"{what} must be a non-zero number; got {number_text(amp)}")
    RANGES["step_amplitude"].check(abs(amp), f"the size of {what} (either sign)",
                                   shown=number_text(amp))
    return float(amp)


def single_step(t, y, t_step, i0, amp, end, notes, rest: Rest | None = None) -> PreparedStep:
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
    check_step(y0, yf, sigma)
    yn = (yp - y0) / amp
    tw, yw = block_mean(tp, yn)
    return PreparedStep(t=tw, y=yw, yf=(yf - y0) / amp, t_step=t_step, amplitude=float(amp),
                        y0=y0, y_final=yf, sigma=sigma, t_raw=t[:end], y_raw=y[:end],
                        notes=notes, dt=sample_interval(t), work_sigma=noise_sigma(yw),
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


def sample_interval(t) -> float:
    """The sample interval: the median spacing (of at most 10000 samples)."""
    return float(np.median(np.diff(t[:10001]))) if t.size > 1 else math.nan
