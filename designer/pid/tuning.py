"""PID tuning rules from a plant's step response.

The reaction curve (Ziegler-Nichols' first method, seed 001 section V.8) is
read from a step-response ARRAY: the inflection point is where a smoothed
derivative peaks (:func:`designer.core.waveform.inflection_tangent`, the same
tangent identification's ``ziegler-nichols`` reads), the tangent there gives L
(where it crosses the initial value) and T (from L to where it reaches the
final value). The seed reads T as
the absolute time at which the tangent reaches the final value (81.75 us for
its plant); the time constant is that time minus L (60.14 us).

The tangent's K, L, T are the model ZN's rule was derived on. The other rules
were derived for a *fitted* first-order-plus-dead-time (FOPDT) model
K e^(-L s)/(T s + 1): they get the least-squares FOPDT of the whole step
(:func:`designer.core.stepfit.fit_step`, seed 000's FOPDT model). On Skogestad's
example E1 the tangent's T is 67 % long and would make SIMC's Kc 91 % high.
Each :class:`Tuning` records the model it used (:class:`Fopdt`, ``source``
``"tangent"`` or ``"least-squares"``); :data:`RULE_MODEL` says which.

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

from ..core.errors import DesignError
from ..core.i18n import N_, Message
from ..core.stepfit import fit_step, model_step
from ..core.waveform import inflection_tangent, normalised_step

__all__ = ["Fopdt", "RULES", "RULE_MODEL", "all_rules", "reaction_curve", "tune"]

RULES = ("zn", "cohen-coon", "chr0", "chr20", "amigo", "simc")
#: the model each rule was derived on: the ZN tangent, or a fitted FOPDT
RULE_MODEL = {"zn": "tangent", "cohen-coon": "least-squares", "chr0": "least-squares",
              "chr20": "least-squares", "amigo": "least-squares", "simc": "least-squares"}
#: how the build sheet names each model source
MODEL_NAMES = {"tangent": N_("ZN tangent"), "least-squares": N_("least-squares FOPDT")}


@dataclass(frozen=True)
class Fopdt:
    """A first-order-plus-dead-time model K e^(-L s)/(T s + 1) and how it was
    obtained (``source``: ``"tangent"`` or ``"least-squares"``)."""

    K: float
    L_s: float
    T_s: float
    source: str
    valid: bool = True        #: False when the fit says the data do not fit an FOPDT (e.g. they overshoot)
    note: str = ""            #: why not, when it does not
    rms_residual: float | None = None   #: of the least-squares fit, in output units per unit input
    ci95: dict | None = None  #: the fit's 95 % confidence half-widths (K, tau_s, theta_s)

    def to_dict(self) -> dict:
        return asdict(self)

    def describe(self) -> str:
        """``"least-squares FOPDT: K 1.02, L 34.8 us, T 17.5 us"``."""
        from ..core.units import format_eng
        return Message("{name}: K {k}, L {l}, T {t}", name=Message(MODEL_NAMES.get(self.source, self.source)),
                       k=f"{self.K:.4g}", l=format_eng(self.L_s, 's'), t=format_eng(self.T_s, 's'))

    def step(self, t) -> np.ndarray:
        """The model's response to a unit step at t = 0: K (1 - e^(-(t - L)/T)) from t = L."""
        return model_step("fopdt", {"K": self.K, "tau_s": self.T_s, "theta_s": self.L_s}, t)


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
    fit: Fopdt | None = None  #: least-squares FOPDT of the same step (for every rule but ZN)

    @property
    def tangent(self) -> Fopdt:
        """The tangent's K, L, T as a model (what ZN's rule uses)."""
        return Fopdt(self.K, self.L_s, self.T_s, "tangent")

    def to_dict(self) -> dict:
        d = asdict(self)
        d["fit"] = None if self.fit is None else self.fit.to_dict()
        return d


@dataclass(frozen=True)
class Tuning:
    """Ideal parallel PID gains Kp (1 + 1/(Ti s) + Td s) and where they came from:
    ``model`` is the FOPDT the rule was applied to (None for given or optimised
    gains), ``curve`` the plant's reaction curve (with its fit)."""

    method: str
    kp: float
    ti_s: float
    td_s: float
    curve: ReactionCurve | None = None
    notes: tuple = field(default_factory=tuple)
    model: Fopdt | None = None

    def to_dict(self, brief: bool = False) -> dict:
        """The gains, the model used and the notes; unless ``brief`` (a row of
        the rules table), also the reaction curve and the least-squares fit."""
        d = {"method": self.method, "kp": self.kp, "ti_s": self.ti_s, "td_s": self.td_s,
             "model": None if self.model is None else self.model.to_dict()}
        if not brief and self.curve is not None:
            c = self.curve.to_dict()
            d["fopdt_fit"] = c.pop("fit")
            d["reaction_curve"] = c
        d["notes"] = list(self.notes)
        return d


def reaction_curve(t, y, *, u_step: float = 1.0, t_step: float | None = None,
                   initial: float | None = None, final: float | None = None,
                   window: int | None = None, fit: bool = True) -> ReactionCurve:
    """Tangent at the inflection point of a step response (ZN reaction curve),
    and the least-squares FOPDT of the same step (the model of the other rules).

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
        Smoothing window of the derivative, in samples (default: the rule of
        :func:`designer.core.waveform.tangent_window`, from the record's noise).
    fit : bool
        Also fit the FOPDT model by least squares (:func:`fit_fopdt`), started
        from the tangent's K, L, T.

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
    t, z, y0, yf = normalised_step(t, y, t_step=t_step, initial=initial, final=final,
                                   what="reaction curve")
    span = yf - y0
    dt = np.diff(t)
    if dt.size < 4:
        raise DesignError("reaction curve: need at least 5 samples")
    if not np.allclose(dt, dt[0], rtol=1e-6, atol=0):
        raise DesignError("reaction curve: samples must be uniformly spaced in time (resample first)")
    tg = inflection_tangent(t, z, 1.0, window_s=None if window is None else window * float(dt[0]))
    if not tg.interior:
        raise DesignError("reaction curve: the steepest point is at the edge of the record; "
                          "no inflection point (is this a first-order response or a truncated record?)")
    ti, zi, slope = tg.t, tg.y, tg.slope
    L = tg.t_base
    t_end = tg.t_level(1.0)
    os_pct = max(0.0, (float(np.max(z)) - 1.0) * 100.0)
    K = span / u_step
    model = fit_fopdt(t, z * K, K, start=Fopdt(K, L, t_end - L, "tangent")) if fit else None
    return ReactionCurve(K=K, L_s=L, T_s=t_end - L, t_inflection_s=ti,
                         y_inflection=y0 + zi * span, slope_per_s=slope * span,
                         t_tangent_final_s=t_end, overshoot_pct=os_pct, fit=model)


def fit_fopdt(t, y, K: float, start: Fopdt | None = None) -> Fopdt:
    """Least-squares FOPDT of a step response (:func:`designer.core.stepfit.fit_step`,
    seed 000's FOPDT model, the fit identification uses too).

    Parameters
    ----------
    t, y : array_like
        Time since the step and the response per unit input step (0 -> K).
    K : float
        The settled value of ``y`` (the static gain).
    start : Fopdt, optional
        Starting estimate (the tangent's), else the fit's own two-point start.

    Returns
    -------
    Fopdt
        ``source`` ``"least-squares"``; ``valid``, ``note`` and the confidence
        half-widths as the fit says (e.g. invalid for a response that overshoots).
    """
    guess = None
    if start is not None and start.T_s > 0:
        guess = {"model": "fopdt", "params": {"K": start.K, "tau_s": start.T_s, "theta_s": max(start.L_s, 0.0)}}
    f = fit_step("fopdt", t, y, K, guess)
    p = f.params
    rms = f.rms_residual
    return Fopdt(p["K"], p["theta_s"], p["tau_s"], "least-squares", bool(f.valid), f.note,
                 rms if math.isfinite(rms) else None, dict(f.ci95))


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


def _rule_notes(rule: str, curve: ReactionCurve | None, model: Fopdt) -> list:
    notes = []
    r = model.L_s / model.T_s
    if curve is not None and curve.overshoot_pct > 2.0:
        notes.append(Message(N_("{rule}: the plant's own step response overshoots {os} %; reaction-curve rules "
                                "assume an S-shaped, non-oscillatory plant, so the loop will be more oscillatory "
                                "than the rule intends (check the closed-loop figures)"),
                             rule=rule, os=f"{curve.overshoot_pct:.1f}"))
    if rule in ("zn", "chr0", "chr20") and not 0.1 <= r <= 1.0:
        notes.append(Message(N_("{rule}: L/T = {r} is outside 0.1..1 where the rule was derived"), rule=rule,
                             r=f"{r:.3g}"))
    if rule == "cohen-coon" and not 0.1 <= r <= 1.0:
        notes.append(Message(N_("cohen-coon: L/T = {r} is outside 0.1..1 where the rule is reliable"), r=f"{r:.3g}"))
    if model.source == "least-squares":
        notes.append(Message(N_("{rule}: applied to the {model} of the plant's step (the rule's model), not to the ZN "
                                "tangent"), rule=rule, model=model.describe()))
    if rule == "simc":
        notes.append(N_("simc: for an FOPDT model SIMC is a PI controller (Td = 0), tuned with tau_c = L"))
    return notes


def model_for(rule: str, curve: ReactionCurve) -> Fopdt:
    """The FOPDT ``rule`` is applied to (see :data:`RULE_MODEL`)."""
    if RULE_MODEL[rule] == "tangent":
        return curve.tangent
    if curve.fit is None:
        raise DesignError(f"{rule}: needs the least-squares FOPDT of the step (reaction_curve(..., fit=True))")
    return curve.fit


def tune(rule: str, source) -> Tuning:
    """Apply a named rule (see :data:`RULES`).

    ``source`` is a :class:`ReactionCurve` (the rule takes its model, tangent
    or fit, per :data:`RULE_MODEL`) or a :class:`Fopdt` (applied as given).

    Parameters
    ----------
    rule : str
        A name of :data:`RULES`.
    source : ReactionCurve or Fopdt
        What the rule is applied to.

    Returns
    -------
    Tuning
    """
    rule = str(rule).strip().lower()
    if rule not in RULES:
        raise DesignError(f"unknown tuning rule {rule!r}; allowed: {', '.join(RULES)}, optimize")
    curve = source if isinstance(source, ReactionCurve) else None
    model = model_for(rule, curve) if curve is not None else source
    if not all(math.isfinite(v) and v > 0 for v in (model.K, model.L_s, model.T_s)):
        raise DesignError(
            f"{rule}: the {MODEL_NAMES.get(model.source, model.source)} model has K = {model.K:.4g}, "
            f"L = {model.L_s:.4g} s, T = {model.T_s:.4g} s; the rule needs all three positive "
            "(a rising response with a visible delay)")
    kp, ti, td = _gains(rule, model.K, model.L_s, model.T_s)
    return Tuning(rule, kp, ti, td, curve, tuple(_rule_notes(rule, curve, model)), model)


def all_rules(curve: ReactionCurve) -> list:
    """Every rule of :data:`RULES` applied to one reaction curve (each to its model).

    Parameters
    ----------
    curve : ReactionCurve
        The plant's reaction curve.

    Returns
    -------
    list of Tuning
    """
    return [tune(r, curve) for r in RULES]
