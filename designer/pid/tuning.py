"""The reaction curve of a plant's step and the FOPDT each reaction-curve
rule is applied to; the rules themselves are :mod:`designer.pid.rules`'.

The reaction curve (Ziegler-Nichols' first method, seed 001 section V.8) is
the tangent at the inflection point of the step: it gives L (where it crosses
the initial value) and T (from L to where it reaches the final value). The seed
reads T as the absolute time at which the tangent reaches the final value
(81.75 us for its plant); the time constant is that time minus L (60.14 us).
A plant known as a transfer function (the Sallen-Key plant as built, its
op-amp included) gets it from its exact step by
:func:`designer.pid.reduction.model_tangent`, the construction the rules of
:mod:`designer.pid.rules` use on every model (:func:`model_reaction_curve`);
a measured step ARRAY gets it where a smoothed derivative peaks
(:func:`reaction_curve`, :func:`designer.core.waveform.inflection_tangent`,
the same tangent identification's ``ziegler-nichols`` reads).

The tangent's K, L, T are the model ZN's rule was derived on. The other rules
were derived for a *fitted* first-order-plus-dead-time (FOPDT) model
K e^(-L s)/(T s + 1): they get the least-squares FOPDT of the whole step
(:func:`designer.core.stepfit.fit_step`, seed 000's FOPDT model). On Skogestad's
example E1 the tangent's T is 67 % long and would make SIMC's Kc 91 % high.
Each :class:`Tuning` records the model it used (:class:`Fopdt`, ``source``
``"tangent"`` or ``"least-squares"``); :data:`RULE_MODEL` says which.

:func:`tune` applies :func:`designer.pid.rules.tune_model` to that FOPDT (as
a given model: the tangent of an FOPDT's step is the model itself), so one
implementation of zn, cohen-coon, chr0, chr20, amigo and simc (their formulas
and sources: :mod:`designer.pid.rules`) serves every plant; simc on an FOPDT
is a PI controller with tau_c = L. All rules assume an S-shaped,
non-oscillatory response; for an underdamped plant they still give numbers,
with a note, rather than refuse.
"""

from __future__ import annotations

import math
from dataclasses import asdict, dataclass, field

import numpy as np

from ..core.errors import DesignError
from ..core.i18n import N_, Message
from ..core.stepfit import fit_step, model_step
from ..core.waveform import inflection_tangent, normalised_step
from . import rules
from .reduction import ModelFopdt, ModelTf, model_tangent

__all__ = ["Fopdt", "RULES", "RULE_MODEL", "all_rules", "model_reaction_curve", "reaction_curve", "tune"]

#: the model each rule was derived on: the ZN tangent, or a fitted FOPDT
RULE_MODEL = {"zn": "tangent", "cohen-coon": "least-squares", "chr0": "least-squares",
              "chr20": "least-squares", "amigo": "least-squares", "simc": "least-squares"}
#: the rules read off a reaction curve (those of :data:`designer.pid.rules.RULES` with an FOPDT of the step)
RULES = tuple(r for r in rules.RULES if r in RULE_MODEL)
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


def model_reaction_curve(num, den, t, y) -> ReactionCurve:
    """The reaction curve of a transfer function's exact step
    (:func:`designer.pid.reduction.model_tangent`, the tangent construction of
    :mod:`designer.pid.rules`), and the least-squares FOPDT of its step ``y``.

    Parameters
    ----------
    num, den : array_like
        The plant's transfer function (highest power of s first), proper,
        stable, with a positive static gain and an inflection point.
    t : array_like
        A uniform time grid from the step (t[0] = 0), long enough to see the
        step settle: the grid of the fit.
    y : array_like
        The plant's unit step on ``t`` (the fit's data, and the plot's).

    Returns
    -------
    ReactionCurve
        K, L, T, the steepest point and the overshoot of the exact step; ``fit``
        the least-squares FOPDT of ``y``, started from the tangent's K, L, T.
    """
    tg = model_tangent(ModelTf(tuple(num), tuple(den)))
    t, z, _y0, _yf = normalised_step(t, y, final=tg.K, what="reaction curve")
    fit = fit_fopdt(t, z * tg.K, tg.K, start=Fopdt(tg.K, tg.L_s, tg.T_s, "tangent"))
    return ReactionCurve(K=tg.K, L_s=tg.L_s, T_s=tg.T_s, t_inflection_s=tg.t_steepest_s,
                         y_inflection=tg.y_steepest, slope_per_s=tg.slope_per_s,
                         t_tangent_final_s=tg.L_s + tg.T_s, overshoot_pct=tg.overshoot_pct, fit=fit)


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


def _curve_notes(rule: str, curve: ReactionCurve | None, model: Fopdt, ruled: list) -> list:
    """The rule's own notes (``ruled``, from :mod:`.rules`: the L/T range) between what the
    reaction curve adds: the plant's overshoot first, the model used and SIMC's PI form after."""
    notes = []
    if curve is not None and curve.overshoot_pct > 2.0:
        notes.append(Message(N_("{rule}: the plant's own step response overshoots {os} %; reaction-curve rules "
                                "assume an S-shaped, non-oscillatory plant, so the loop will be more oscillatory "
                                "than the rule intends (check the closed-loop figures)"),
                             rule=rule, os=f"{curve.overshoot_pct:.1f}"))
    notes += ruled
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
    # the one implementation of the rule (designer.pid.rules), on the FOPDT as a given model
    rt = rules.tune_model(ModelFopdt(model.K, model.T_s, model.L_s), rule)
    return Tuning(rule, rt.kp, rt.ti_s, rt.td_s, curve, tuple(_curve_notes(rule, curve, model, list(rt.notes))),
                  model)


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
