"""PID tuning rules from a plant's step response.

The reaction curve (Ziegler-Nichols' first method, seed 001 section V.8) is
read from a step-response ARRAY: the inflection point is where a smoothed
derivative peaks, the tangent there gives L (where it crosses the initial
value) and T (from L to where it reaches the final value). The seed reads T as
the absolute time at which the tangent reaches the final value (81.75 us for
its plant); the time constant is that time minus L (60.14 us).

The same K, L, T are a first-order-plus-dead-time (FOPDT) model
K e^(-L s)/(T s + 1), from which the other rules work:

* zn:         Kp = 1.2 T/(K L),                 Ti = 2 L,                        Td = 0.5 L
* cohen-coon: Kp = (T/(K L)) (4/3 + L/(4 T)),   Ti = L (32 + 6 L/T)/(13 + 8 L/T), Td = 4 L/(11 + 2 L/T)
* chr0:       Kp = 0.6 T/(K L),                 Ti = T,                          Td = 0.5 L
* chr20:      Kp = 0.95 T/(K L),                Ti = 1.4 T,                      Td = 0.47 L
* amigo:      Kp = (0.2 + 0.45 T/L)/K,          Ti = L (0.4 L + 0.8 T)/(L + 0.1 T), Td = 0.5 L T/(0.3 L + T)
* simc:       Kp = T/(K (tc + L)), tc = L,      Ti = min(T, 4 (tc + L)),         Td = 0 (a PI)

(Ziegler & Nichols 1942; Cohen & Coon 1953; Chien, Hrones & Reswick 1952,
set-point response; Astrom & Hagglund 2004, AMIGO; Skogestad 2003, SIMC, which
for an FOPDT model is a PI controller.) All rules assume an S-shaped,
non-oscillatory response; for an underdamped plant they still give numbers,
with a warning, rather than refuse.
"""

from __future__ import annotations

import math
from dataclasses import asdict, dataclass, field

import numpy as np
from scipy.signal import savgol_filter

from ..errors import DesignError

RULES = ("zn", "cohen-coon", "chr0", "chr20", "amigo", "simc")


@dataclass(frozen=True)
class ReactionCurve:
    """What the tangent at the inflection point says about a step response.

    Times are measured from the step. ``t_tangent_final_s`` is where the
    tangent reaches the final value (the seed's "T" = 81.75 us); the time
    constant is ``T_s = t_tangent_final_s - L_s``.
    """

    K: float                  #: static gain, (final - initial) / input step
    L_s: float                #: apparent dead time
    T_s: float                #: apparent time constant
    t_inflection_s: float
    y_inflection: float
    slope_per_s: float        #: tangent slope in output units per second
    t_tangent_final_s: float
    overshoot_pct: float      #: of the plant response itself (0 for an S curve)

    def to_dict(self) -> dict:
        return asdict(self)


@dataclass(frozen=True)
class Tuning:
    """Ideal parallel PID gains Kp (1 + 1/(Ti s) + Td s) and where they came from."""

    method: str
    kp: float
    ti_s: float
    td_s: float
    curve: ReactionCurve | None = None
    notes: tuple = field(default_factory=tuple)

    def to_dict(self) -> dict:
        d = {"method": self.method, "kp": self.kp, "ti_s": self.ti_s, "td_s": self.td_s}
        if self.curve is not None:
            d.update(K=self.curve.K, L_s=self.curve.L_s, T_s=self.curve.T_s,
                     t_inflection_s=self.curve.t_inflection_s,
                     y_inflection=self.curve.y_inflection,
                     slope_per_s=self.curve.slope_per_s,
                     t_tangent_final_s=self.curve.t_tangent_final_s)
        d["notes"] = list(self.notes)
        return d


def smooth_derivative(t, y, window: int | None = None) -> np.ndarray:
    """dy/dt of uniformly sampled data with a Savitzky-Golay filter (cubic).

    ``window`` (odd, samples) defaults to about 0.5 % of the record, at least 5:
    it removes sample-to-sample noise of measured data and leaves a dense
    analytic curve essentially untouched.
    """
    t = np.asarray(t, float)
    y = np.asarray(y, float)
    dt = np.diff(t)
    if dt.size < 4:
        raise DesignError("reaction curve: need at least 5 samples")
    if not np.allclose(dt, dt[0], rtol=1e-6, atol=0):
        raise DesignError("reaction curve: samples must be uniformly spaced in time (resample first)")
    if window is None:
        window = max(5, int(0.005 * t.size) | 1)
    window = min(window, t.size - (1 - t.size % 2))
    return savgol_filter(y, window, 3, deriv=1, delta=float(dt[0]))


def reaction_curve(t, y, *, u_step: float = 1.0, t_step: float | None = None,
                   initial: float | None = None, final: float | None = None,
                   window: int | None = None) -> ReactionCurve:
    """Tangent at the inflection point of a step response (ZN reaction curve).

    Parameters
    ----------
    t, y : array_like
        Uniformly sampled time and plant output; the step may go up or down.
    u_step : float
        Size of the input step (for K).
    t_step : float, optional
        When the step was applied (default ``t[0]``).
    initial, final : float, optional
        Output before the step and settled output (defaults: first and last samples).
    window : int, optional
        Savitzky-Golay window for the derivative (see :func:`smooth_derivative`).

    Returns
    -------
    ReactionCurve
    """
    t = np.asarray(t, float)
    y = np.asarray(y, float)
    if t.shape != y.shape or t.ndim != 1:
        raise DesignError("reaction curve: time and output must be 1-D arrays of the same length")
    if u_step == 0 or not math.isfinite(u_step):
        raise DesignError("reaction curve: the input step must be a finite non-zero number")
    ts0 = float(t[0]) if t_step is None else float(t_step)
    keep = t >= ts0
    t, y = t[keep] - ts0, y[keep]
    y0 = float(y[0]) if initial is None else float(initial)
    yf = float(y[-1]) if final is None else float(final)
    span = yf - y0
    if span == 0:
        raise DesignError("reaction curve: the output does not change")
    z = (y - y0) / span                      # rising 0 -> 1 whatever the sign
    dz = smooth_derivative(t, z, window)
    i = int(np.argmax(dz))
    if i == 0 or i == len(z) - 1:
        raise DesignError("reaction curve: the steepest point is at the edge of the record; "
                          "no inflection point (is this a first-order response or a truncated record?)")
    # refine the slope peak with a parabola through its three samples
    a, b, c = dz[i - 1], dz[i], dz[i + 1]
    h = t[i] - t[i - 1]
    den = a - 2 * b + c
    d = 0.5 * (a - c) / den if den < 0 else 0.0
    ti = float(t[i] + d * h)
    slope = float(b - 0.25 * (a - c) * d)
    zi = float(np.interp(ti, t, z))
    L = ti - zi / slope
    t_end = ti + (1.0 - zi) / slope
    os_pct = max(0.0, (float(np.max(z)) - 1.0) * 100.0)
    return ReactionCurve(K=span / u_step, L_s=L, T_s=t_end - L, t_inflection_s=ti,
                         y_inflection=y0 + zi * span, slope_per_s=slope * span,
                         t_tangent_final_s=t_end, overshoot_pct=os_pct)


def _gains(rule: str, K: float, L: float, T: float):
    r = L / T
    if rule == "zn":
        return 1.2 * T / (K * L), 2.0 * L, 0.5 * L
    if rule == "cohen-coon":
        return ((T / (K * L)) * (4.0 / 3.0 + L / (4.0 * T)),
                L * (32.0 + 6.0 * r) / (13.0 + 8.0 * r),
                4.0 * L / (11.0 + 2.0 * r))
    if rule == "chr0":
        return 0.6 * T / (K * L), T, 0.5 * L
    if rule == "chr20":
        return 0.95 * T / (K * L), 1.4 * T, 0.47 * L
    if rule == "amigo":
        return ((0.2 + 0.45 * T / L) / K,
                L * (0.4 * L + 0.8 * T) / (L + 0.1 * T),
                0.5 * L * T / (0.3 * L + T))
    if rule == "simc":
        tc = L
        return T / (K * (tc + L)), min(T, 4.0 * (tc + L)), 0.0
    raise DesignError(f"unknown tuning rule {rule!r}; allowed: {', '.join(RULES)}")


def _rule_notes(rule: str, curve: ReactionCurve) -> list:
    notes = []
    r = curve.L_s / curve.T_s
    if curve.overshoot_pct > 2.0:
        notes.append(
            f"{rule}: the plant's own step response overshoots {curve.overshoot_pct:.1f} %; "
            "reaction-curve rules assume an S-shaped, non-oscillatory plant, so the loop will be "
            "more oscillatory than the rule intends (check the closed-loop figures)")
    if rule in ("zn", "chr0", "chr20") and not 0.1 <= r <= 1.0:
        notes.append(f"{rule}: L/T = {r:.3g} is outside 0.1..1 where the rule was derived")
    if rule == "cohen-coon" and not 0.1 <= r <= 1.0:
        notes.append(f"cohen-coon: L/T = {r:.3g} is outside 0.1..1 where the rule is reliable")
    if rule == "simc":
        notes.append("simc: for an FOPDT model SIMC is a PI controller (Td = 0), tuned with tau_c = L")
    return notes


def tune(rule: str, curve: ReactionCurve) -> Tuning:
    """Apply a named rule (see :data:`RULES`) to a reaction curve."""
    rule = str(rule).strip().lower()
    if rule not in RULES:
        raise DesignError(f"unknown tuning rule {rule!r}; allowed: {', '.join(RULES)}, optimize")
    if not (curve.K > 0 and curve.L_s > 0 and curve.T_s > 0):
        raise DesignError(
            f"reaction curve gives K = {curve.K:.4g}, L = {curve.L_s:.4g} s, T = {curve.T_s:.4g} s; "
            "the rules need all three positive (a rising response with a visible delay)")
    kp, ti, td = _gains(rule, curve.K, curve.L_s, curve.T_s)
    return Tuning(rule, kp, ti, td, curve, tuple(_rule_notes(rule, curve)))


def all_rules(curve: ReactionCurve) -> list:
    """Every rule of :data:`RULES` applied to one reaction curve."""
    return [tune(r, curve) for r in RULES]


def explicit(kp: float, ti_s: float, td_s: float) -> Tuning:
    """Gains given by the user, validated (Kp > 0, Ti > 0, Td >= 0)."""
    for name, v in (("kp", kp), ("ti", ti_s), ("td", td_s)):
        if v is None or not math.isfinite(v):
            raise DesignError(f"--{name}: must be a finite number, got {v!r}")
    if kp <= 0:
        raise DesignError(f"--kp: must be greater than 0, got {kp:g}")
    if ti_s <= 0:
        raise DesignError(f"--ti: must be a time greater than 0 s, got {ti_s:g}")
    if td_s < 0:
        raise DesignError(f"--td: must be a time of 0 s or more, got {td_s:g}")
    return Tuning("explicit", float(kp), float(ti_s), float(td_s))
