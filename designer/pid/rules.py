"""PID tuning rules applied to a plant MODEL, each to the model its author
derived it on.

The one implementation of the rules for every plant (:func:`designer.pid.tuning.tune`
hands it the FOPDT of a reaction curve, a Sallen-Key plant's included). It takes a model of
:mod:`.reduction` (:class:`~.reduction.ModelFopdt`,
:class:`~.reduction.ModelSopdt`, :class:`~.reduction.ModelIntegrating`,
:class:`~.reduction.ModelTf`) or the project's
:class:`designer.core.process.ProcessModel` (through
:func:`~.reduction.from_process`). Each rule gets the model it was written
for, and :class:`ModelUsed` says how it was obtained:

* ``"given"``: the model is already of the rule's form.
* ``"tangent of the model's step"``: the reaction-curve construction on the
  model's own exact step (:func:`~.reduction.model_tangent`): the tangent at
  the steepest point crosses the initial value at L and reaches the final
  value K at L + T (on an integrating plant, the ramp asymptote).
* ``"tangent and 63 % point of the model's step"``: L from the tangent and
  T = t63 - L, the FOTD model of Astrom & Hagglund's step-response method.
* ``"Skogestad half rule"``: Skogestad (2003) section 2's model reduction
  (:func:`~.reduction.half_rule`).

The rules (K static gain, L dead time, T time constant; Kv velocity gain of an
integrating plant; output Kp (1 + 1/(Ti s) + Td s), the ideal parallel form):

* zn (Ziegler & Nichols 1942, "Optimum settings for automatic controllers",
  Trans. ASME 64, 759-768, reaction curve): Kp = 1.2/a with a = K L/T (the
  unit reaction rate times L), Ti = 2 L, Td = 0.5 L. The rule needs only the
  steepest slope and L, so it applies to integrating plants too (a = Kv L).
* cohen-coon (Cohen & Coon 1953, "Theoretical consideration of retarded
  control", Trans. ASME 75, 827-834): Kp = (T/(K L)) (4/3 + L/(4 T)),
  Ti = L (32 + 6 L/T)/(13 + 8 L/T), Td = 4 L/(11 + 2 L/T).
* chr0, chr20 (Chien, Hrones & Reswick 1952, "On the automatic control of
  generalized passive systems", Trans. ASME 74, 175-185, set-point response,
  0 % and 20 % overshoot): Kp = 0.6 T/(K L), Ti = T, Td = 0.5 L; and
  Kp = 0.95 T/(K L), Ti = 1.4 T, Td = 0.47 L.
* amigo (Astrom & Hagglund 2004, "Revisiting the Ziegler-Nichols step response
  method for PID control", J. Process Control 14, 635-650; Advanced PID Control,
  ISA 2006): Kp = (0.2 + 0.45 T/L)/K, Ti = L (0.4 L + 0.8 T)/(L + 0.1 T),
  Td = 0.5 L T/(0.3 L + T); for an integrating plant its T -> infinity limit,
  Kp = 0.45/(Kv L), Ti = 8 L, Td = 0.5 L, the form the book gives for
  integrating processes.
* simc (Skogestad 2003, "Simple analytic rules for model reduction and PID
  controller tuning", J. Process Control 13, 291-309), in the series form
  Kc (1 + 1/(tauI s))(1 + tauD s): FOPDT -> PI Kc = tau/(K (tauc + theta)),
  tauI = min(tau, 4 (tauc + theta)); SOPDT -> the same with tau1 and
  tauD = tau2; integrating K' e^(-theta s)/s -> PI Kc = 1/(K' (tauc + theta)),
  tauI = 4 (tauc + theta); with a lag tau -> tauD = tau. Default tauc = theta
  (Skogestad's choice for tight control with good robustness); with theta = 0
  that is no default and tauc_s must be given. A general model goes through the
  half rule to the SOPDT when its tau2 > theta (derivative action pays: the
  paper's recommendation) and to the FOPDT otherwise.
* imc (Rivera, Morari & Skogestad 1986, "Internal model control. 4. PID
  controller design", Ind. Eng. Chem. Process Des. Dev. 25, 252-265): the
  FOPDT PID of their table, from the first-order Pade approximation of the
  delay: Kp = (2 tau + theta)/(2 K (lambda + theta)), Ti = tau + theta/2,
  Td = tau theta/(2 tau + theta), which comes with a first-order filter
  tau_F = lambda theta/(2 (lambda + theta)) (reported in the notes, not part of
  Kp, Ti, Td). The PI forms of the same table (Kp = tau/(K lambda), Ti = tau;
  or Kp = (2 tau + theta)/(2 K lambda), Ti = tau + theta/2, for lambda > 1.7
  theta) are not implemented. Default lambda = max(0.25 theta, 0.2 tau): the
  table's lower bound lambda/theta > 0.25 for this PID, and lambda > 0.2 tau
  (asking for a loop no more than five times faster than the plant, the bound
  usually quoted with IMC tuning after Morari & Zafiriou 1989, Robust Process
  Control). Other models go through the half rule to an FOPDT first (as
  Skogestad 2003 proposes for the IMC-derived rules); an integrating plant is
  refused (the table gives it no integral action).

:func:`applicable` says which rules apply to a model and why the others do
not; :func:`tune_model` refuses an inapplicable rule with that one line. All
the rules assume an S-shaped, non-oscillatory step: on an underdamped model
they still give numbers, with a note.
"""

from __future__ import annotations

import math
from dataclasses import dataclass, field

from ..core.errors import DesignError
from ..core.i18n import N_, Message
from ..core.process import ProcessModel
from ..core.units import format_eng
from .reduction import (MODEL_TYPES, ModelFopdt, ModelIntegrating, ModelSopdt, ModelTangent, check_plant,
                        Factors, half_rule_of, format_number, check_number, format_seconds, from_process, model_tangent)

__all__ = ["GIVEN", "HALF_RULE", "REACTION_CURVE_RULES", "RULES", "RuleTuning", "TANGENT", "TANGENT_T63", "all_rules",
           "applicable", "parallel_to_series", "series_to_parallel", "tune_model"]

RULES = ("zn", "cohen-coon", "chr0", "chr20", "amigo", "simc", "imc")
#: the rules read off the reaction curve (K, L and T of the tangent)
REACTION_CURVE_RULES = ("zn", "cohen-coon", "chr0", "chr20")

GIVEN = N_("given")
TANGENT = N_("tangent of the model's step")
TANGENT_T63 = N_("tangent and 63 % point of the model's step")
HALF_RULE = N_("Skogestad half rule")


# ----------------------------------------------------------------------------- results


@dataclass(frozen=True)
class ModelUsed:
    """The model a rule's formulas were applied to and how it was obtained."""

    model: object             #: ModelFopdt, ModelSopdt or ModelIntegrating
    source: str               #: GIVEN, TANGENT, TANGENT_T63 or HALF_RULE
    steps: tuple = ()         #: how, with numbers

    def describe(self) -> str:
        return Message("{model} ({source})", model=self.model.describe(), source=self.source)

    def to_dict(self) -> dict:
        return {"model": self.model.to_dict(), "source": self.source, "steps": list(self.steps)}


@dataclass(frozen=True)
class RuleTuning:
    """Ideal parallel PID Kp (1 + 1/(Ti s) + Td s) from one rule on one model.

    ``series`` is (Kc, tauI, tauD) of the series form Kc (1 + 1/(tauI s))(1 + tauD s)
    for the rules that give it (SIMC), with ``conversion`` the line that turns
    it into Kp, Ti, Td. ``setting`` holds the rule's tuning parameter
    (``tauc_s`` or ``lambda_s``) as used.
    """

    rule: str
    kp: float
    ti_s: float
    td_s: float
    model_used: ModelUsed
    formulas: list = field(default_factory=list)
    notes: list = field(default_factory=list)
    series: tuple | None = None
    conversion: str | None = None
    setting: dict | None = None

    def to_dict(self) -> dict:
        return {"rule": self.rule, "kp": self.kp, "ti_s": self.ti_s, "td_s": self.td_s,
                "series": None if self.series is None else list(self.series),
                "conversion": self.conversion, "setting": self.setting,
                "model_used": self.model_used.to_dict(),
                "formulas": list(self.formulas), "notes": list(self.notes)}


def series_to_parallel(kc: float, tau_i: float, tau_d: float) -> tuple:
    """Kc (1 + 1/(tauI s))(1 + tauD s) as Kp (1 + 1/(Ti s) + Td s):
    Kp = Kc (1 + tauD/tauI), Ti = tauI + tauD, Td = tauI tauD/(tauI + tauD).

    Parameters
    ----------
    kc : float
        Series gain.
    tau_i : float
        Series integral time (s).
    tau_d : float
        Series derivative time (s).

    Returns
    -------
    tuple
        (Kp, Ti, Td).
    """
    ti = tau_i + tau_d
    return kc * (1.0 + tau_d / tau_i), ti, tau_i * tau_d / ti


def parallel_to_series(kp: float, ti: float, td: float) -> tuple:
    """The inverse of :func:`series_to_parallel`, tauI >= tauD; it exists only for
    Ti >= 4 Td (real controller zeros).

    Parameters
    ----------
    kp : float
        Proportional gain.
    ti : float
        Integral time (s).
    td : float
        Derivative time (s).

    Returns
    -------
    tuple
        (Kc, tauI, tauD).
    """
    if td == 0:
        return kp, ti, 0.0
    disc = 1.0 - 4.0 * td / ti
    if -1e-12 < disc < 0:   # Ti = 4 Td (tauI = tauD) up to rounding: a double real zero
        disc = 0.0
    if disc < 0:
        raise DesignError(f"series form: Ti = {format_seconds(ti)} < 4 Td = {format_seconds(4 * td)}: the controller's zeros are "
                          "complex, there is no series (interacting) form")
    r = math.sqrt(disc)
    return kp * (1.0 + r) / 2.0, ti * (1.0 + r) / 2.0, ti * (1.0 - r) / 2.0


def _conversion(kc, tau_i, tau_d):
    kp, ti, td = series_to_parallel(kc, tau_i, tau_d)
    return Message(N_("series -> parallel: Kp = Kc (1 + tauD/tauI) = {kc} x (1 + {tau_d} / {tau_i}) = {kp}; Ti = tauI + "
                      "tauD = {tau_i} + {tau_d} = {ti}; Td = tauI tauD/(tauI + tauD) = {tau_i} x {tau_d} / {ti} = {td}"),
                   kc=format_number(kc), tau_d=format_seconds(tau_d), tau_i=format_seconds(tau_i), kp=format_number(kp),
                   ti=format_seconds(ti), td=format_seconds(td))


# ----------------------------------------------------------------------------- rules


def _no_L(rule, formula):
    return DesignError(f"{rule}: L = 0 (no dead time and no inflection point) and {formula} divides by L; "
                       "use simc with tauc_s, or imc")


def _oscillation_notes(rule, tg: ModelTangent | None, f: Factors | None):
    out = []
    if tg is not None and tg.overshoot_pct > 2.0:
        what = N_("slope") if tg.integrating else N_("step")
        out.append(Message(N_("{rule}: the model's own {what} overshoots {os} %; the rule assumes an S-shaped, "
                              "non-oscillatory response, so the loop will be more oscillatory than it intends"),
                           rule=rule, what=what, os=f"{tg.overshoot_pct:.1f}"))
    elif f is not None and f.complex_poles:
        z = min(z for _, z in f.complex_poles)
        out.append(Message(N_("{rule}: the model has complex poles (zeta {z}); the rule assumes a non-oscillatory "
                              "plant"), rule=rule, z=f"{z:.3g}"))
    return out


def _reaction_model(model, rule, f):
    """(K, L, T or None, ModelUsed, tangent or None) for the reaction-curve rules."""
    if isinstance(model, ModelFopdt):
        used = ModelUsed(model, GIVEN, (N_("the tangent of an FOPDT's step is the model itself: L = theta, T = tau"),))
        return model.K, model.theta_s, model.tau_s, used, None
    tg = model_tangent(model)
    if tg.integrating:
        m = ModelIntegrating(tg.K, 0.0, tg.L_s)
        src = GIVEN if isinstance(model, ModelIntegrating) and model.tau_s == 0 else TANGENT
        return tg.K, tg.L_s, None, ModelUsed(m, src, tuple(tg.steps())), tg
    m = ModelFopdt(tg.K, tg.T_s, max(tg.L_s, 0.0))
    return tg.K, max(tg.L_s, 0.0), tg.T_s, ModelUsed(m, TANGENT, tuple(tg.steps())), tg


def _range_note(rule, L, T):
    r = L / T
    if not 0.1 <= r <= 1.0:
        if rule == "cohen-coon":
            return [Message(N_("{rule}: L/T = {r} is outside 0.1..1 where the rule is reliable"), rule=rule, r=f"{r:.3g}")]
        return [Message(N_("{rule}: L/T = {r} is outside 0.1..1 where the rule was derived"), rule=rule, r=f"{r:.3g}")]
    return []


def _tune_reaction(model, rule, f):
    K, L, T, used, tg = _reaction_model(model, rule, f)
    if T is None and rule != "zn":
        raise DesignError(f"{rule}: an integrating plant has no final value, so the reaction curve has no "
                          "K and T for this rule; use zn, amigo or simc")
    if L <= 0:
        names = {"zn": "Kp = 1.2 T/(K L)", "cohen-coon": "Kp = (T/(K L)) (4/3 + L/(4 T))",
                 "chr0": "Kp = 0.6 T/(K L)", "chr20": "Kp = 0.95 T/(K L)"}
        raise _no_L(rule, names[rule])
    notes = _oscillation_notes(rule, tg, f)
    if T is None:   # zn on an integrating plant: a = Kv L
        a = K * L
        kp, ti, td = 1.2 / a, 2.0 * L, 0.5 * L
        formulas = [f"a = Kv L = {format_eng(K, '/s')} x {format_seconds(L)} = {format_number(a)}",
                    f"Kp = 1.2/a = 1.2 / {format_number(a)} = {format_number(kp)}",
                    f"Ti = 2 L = 2 x {format_seconds(L)} = {format_seconds(ti)}", f"Td = 0.5 L = 0.5 x {format_seconds(L)} = {format_seconds(td)}"]
        notes.append(N_("zn: Ziegler-Nichols' reaction curve needs only the steepest slope and L (a = slope x L), "
                        "so it applies to an integrating plant"))
        return RuleTuning(rule, kp, ti, td, used, formulas, notes)
    r = L / T
    kl = f"({format_number(K)} x {format_seconds(L)})"
    if rule == "zn":
        kp, ti, td = 1.2 * T / (K * L), 2.0 * L, 0.5 * L
        formulas = [f"Kp = 1.2 T/(K L) = 1.2 x {format_seconds(T)} / {kl} = {format_number(kp)}",
                    f"Ti = 2 L = 2 x {format_seconds(L)} = {format_seconds(ti)}", f"Td = 0.5 L = 0.5 x {format_seconds(L)} = {format_seconds(td)}"]
    elif rule == "cohen-coon":
        kp = (T / (K * L)) * (4.0 / 3.0 + r / 4.0)
        ti = L * (32.0 + 6.0 * r) / (13.0 + 8.0 * r)
        td = 4.0 * L / (11.0 + 2.0 * r)
        formulas = [f"Kp = (T/(K L)) (4/3 + L/(4 T)) = ({format_seconds(T)} / {kl}) x (4/3 + {format_number(r)}/4) = {format_number(kp)}",
                    f"Ti = L (32 + 6 L/T)/(13 + 8 L/T) = {format_seconds(L)} x (32 + 6 x {format_number(r)}) / (13 + 8 x {format_number(r)}) "
                    f"= {format_seconds(ti)}",
                    f"Td = 4 L/(11 + 2 L/T) = 4 x {format_seconds(L)} / (11 + 2 x {format_number(r)}) = {format_seconds(td)}"]
    elif rule == "chr0":
        kp, ti, td = 0.6 * T / (K * L), T, 0.5 * L
        formulas = [f"Kp = 0.6 T/(K L) = 0.6 x {format_seconds(T)} / {kl} = {format_number(kp)}",
                    f"Ti = T = {format_seconds(ti)}", f"Td = 0.5 L = 0.5 x {format_seconds(L)} = {format_seconds(td)}"]
    else:
        kp, ti, td = 0.95 * T / (K * L), 1.4 * T, 0.47 * L
        formulas = [f"Kp = 0.95 T/(K L) = 0.95 x {format_seconds(T)} / {kl} = {format_number(kp)}",
                    f"Ti = 1.4 T = 1.4 x {format_seconds(T)} = {format_seconds(ti)}", f"Td = 0.47 L = 0.47 x {format_seconds(L)} = {format_seconds(td)}"]
    notes.extend(_range_note(rule, L, T))
    return RuleTuning(rule, kp, ti, td, used, formulas, notes)


def _tune_amigo(model, f):
    tg = None
    if isinstance(model, ModelFopdt):
        K, L, T = model.K, model.theta_s, model.tau_s
        used = ModelUsed(model, GIVEN)
    else:
        tg = model_tangent(model)
        if tg.integrating:
            K, L, T = tg.K, tg.L_s, None
            src = GIVEN if isinstance(model, ModelIntegrating) and model.tau_s == 0 else TANGENT
            used = ModelUsed(ModelIntegrating(K, 0.0, L), src, tuple(tg.steps()))
        else:
            K, L, T = tg.K, max(tg.L_s, 0.0), tg.t63_s - max(tg.L_s, 0.0)
            if T <= 0:
                raise DesignError(f"amigo: the step reaches 63 % (t = {format_seconds(tg.t63_s)}) before the tangent's L "
                                  f"= {format_seconds(L)}: no FOTD model for the rule")
            steps = tuple(tg.steps()[:2]) + (
                Message(N_("t63 = {t63} (63.2 % of K), T = t63 - L = {t63} - {l} = {t}"), t63=format_seconds(tg.t63_s),
                        l=format_seconds(L), t=format_seconds(T)),)
            used = ModelUsed(ModelFopdt(K, T, L), TANGENT_T63, steps)
    if L <= 0:
        raise _no_L("amigo", "Kp = 0.45/(Kv L)" if T is None else "Kp = (0.2 + 0.45 T/L)/K")
    notes = _oscillation_notes("amigo", tg, f)
    if T is None:
        kp, ti, td = 0.45 / (K * L), 8.0 * L, 0.5 * L
        formulas = [f"Kp = 0.45/(Kv L) = 0.45 / ({format_eng(K, '/s')} x {format_seconds(L)}) = {format_number(kp)}",
                    f"Ti = 8 L = 8 x {format_seconds(L)} = {format_seconds(ti)}", f"Td = 0.5 L = 0.5 x {format_seconds(L)} = {format_seconds(td)}"]
        notes.append(N_("amigo: the integrating-process form (the T -> infinity limit of the FOTD rule)"))
    else:
        kp = (0.2 + 0.45 * T / L) / K
        ti = L * (0.4 * L + 0.8 * T) / (L + 0.1 * T)
        td = 0.5 * L * T / (0.3 * L + T)
        formulas = [f"Kp = (0.2 + 0.45 T/L)/K = (0.2 + 0.45 x {format_seconds(T)} / {format_seconds(L)}) / {format_number(K)} = {format_number(kp)}",
                    f"Ti = L (0.4 L + 0.8 T)/(L + 0.1 T) = {format_seconds(L)} x (0.4 x {format_seconds(L)} + 0.8 x {format_seconds(T)}) / "
                    f"({format_seconds(L)} + 0.1 x {format_seconds(T)}) = {format_seconds(ti)}",
                    f"Td = 0.5 L T/(0.3 L + T) = 0.5 x {format_seconds(L)} x {format_seconds(T)} / (0.3 x {format_seconds(L)} + {format_seconds(T)}) = {format_seconds(td)}"]
    return RuleTuning("amigo", kp, ti, td, used, formulas, notes)


def _simc_model(model):
    """The model SIMC is applied to: given, or the half rule's (SOPDT when tau2 > theta)."""
    if isinstance(model, (ModelFopdt, ModelSopdt, ModelIntegrating)):
        return ModelUsed(model, GIVEN), []
    hr2 = half_rule_of(model, 2, "simc")
    m2 = hr2.model
    tau2 = m2.tau2_s if isinstance(m2, ModelSopdt) else m2.tau_s
    if tau2 > m2.theta_s:
        why = Message(N_("simc: the half rule's second-order model has tau2 = {tau2} > theta = {theta}, so derivative "
                         "action pays (Skogestad 2003): PID on it"), tau2=format_seconds(tau2),
                      theta=format_seconds(m2.theta_s))
        return ModelUsed(m2, HALF_RULE, hr2.steps), [why]
    hr1 = half_rule_of(model, 1, "simc")
    why = Message(N_("simc: the half rule's second-order model has tau2 = {tau2} <= theta = {theta}: PI on the "
                     "first-order model (Skogestad 2003)"), tau2=format_seconds(tau2), theta=format_seconds(m2.theta_s))
    return ModelUsed(hr1.model, HALF_RULE, hr1.steps), [why]


def _tune_simc(model, f, tauc_s):
    used, notes = _simc_model(model)
    m = used.model
    theta = m.theta_s
    if tauc_s is None:
        if theta <= 0:
            raise DesignError("simc: theta = 0, so the default tau_c = theta is 0 and Kc = tau1/(K (tau_c + "
                              "theta)) divides by zero; give tauc_s (the closed-loop time constant wanted), "
                              "or use imc", param="tauc_s")
        tc = theta
        tc_line = Message(N_("tauc = theta = {tc} (Skogestad's default: tight control, good robustness)"),
                          tc=format_seconds(tc))
    else:
        tc = check_number("simc", "tauc_s", tauc_s, positive=True)
        tc_line = Message(N_("tauc = {tc} (given)"), tc=format_seconds(tc))
    s = tc + theta
    formulas = [tc_line]
    if isinstance(m, ModelIntegrating):
        kc, tau_i = 1.0 / (m.K * s), 4.0 * s
        tau_d = m.tau_s
        formulas += [f"Kc = 1/(K' (tauc + theta)) = 1 / ({format_eng(m.K, '/s')} x ({format_seconds(tc)} + {format_seconds(theta)})) "
                     f"= {format_number(kc)}",
                     f"tauI = 4 (tauc + theta) = 4 x ({format_seconds(tc)} + {format_seconds(theta)}) = {format_seconds(tau_i)}"]
        formulas.append(f"tauD = tau = {format_seconds(tau_d)}" if tau_d > 0 else N_("tauD = 0 (a PI)"))
    else:
        tau1 = m.tau1_s if isinstance(m, ModelSopdt) else m.tau_s
        tau_d = m.tau2_s if isinstance(m, ModelSopdt) else 0.0
        kc, tau_i = tau1 / (m.K * s), min(tau1, 4.0 * s)
        t1 = "tau1" if isinstance(m, ModelSopdt) else "tau"
        formulas += [f"Kc = {t1}/(K (tauc + theta)) = {format_seconds(tau1)} / ({format_number(m.K)} x ({format_seconds(tc)} + {format_seconds(theta)})) "
                     f"= {format_number(kc)}",
                     f"tauI = min({t1}, 4 (tauc + theta)) = min({format_seconds(tau1)}, {format_seconds(4.0 * s)}) = {format_seconds(tau_i)}"]
        formulas.append(f"tauD = tau2 = {format_seconds(tau_d)}" if isinstance(m, ModelSopdt) else N_("tauD = 0 (a PI)"))
    kp, ti, td = series_to_parallel(kc, tau_i, tau_d)
    notes += _oscillation_notes("simc", None, f)
    return RuleTuning("simc", kp, ti, td, used, formulas, notes, (kc, tau_i, tau_d),
                      _conversion(kc, tau_i, tau_d), {"tauc_s": tc})


def _tune_imc(model, f, lambda_s):
    if isinstance(model, ModelIntegrating) or f.integrators:
        raise DesignError("imc: Rivera, Morari & Skogestad's table gives an integrating plant no integral "
                          "action (P or PD only); use simc or amigo")
    if isinstance(model, ModelFopdt):
        used = ModelUsed(model, GIVEN)
    else:
        hr = half_rule_of(model, 1, "imc")
        used = ModelUsed(hr.model, HALF_RULE, hr.steps)
    m = used.model
    K, tau, theta = m.K, m.tau_s, m.theta_s
    if lambda_s is None:
        lam = max(0.25 * theta, 0.2 * tau)
        lam_line = Message(N_("lambda = max(0.25 theta, 0.2 tau) = max({a}, {b}) = {lam} (default)"),
                           a=format_seconds(0.25 * theta), b=format_seconds(0.2 * tau), lam=format_seconds(lam))
    else:
        lam = check_number("imc", "lambda_s", lambda_s, positive=True)
        lam_line = Message(N_("lambda = {lam} (given)"), lam=format_seconds(lam))
    kp = (2.0 * tau + theta) / (2.0 * K * (lam + theta))
    ti = tau + theta / 2.0
    td = tau * theta / (2.0 * tau + theta)
    formulas = [lam_line,
                f"Kp = (2 tau + theta)/(2 K (lambda + theta)) = (2 x {format_seconds(tau)} + {format_seconds(theta)}) / (2 x {format_number(K)} x "
                f"({format_seconds(lam)} + {format_seconds(theta)})) = {format_number(kp)}",
                f"Ti = tau + theta/2 = {format_seconds(tau)} + {format_seconds(theta)}/2 = {format_seconds(ti)}",
                f"Td = tau theta/(2 tau + theta) = {format_seconds(tau)} x {format_seconds(theta)} / (2 x {format_seconds(tau)} + {format_seconds(theta)}) "
                f"= {format_seconds(td)}"]
    notes = _oscillation_notes("imc", None, f)
    if theta > 0:
        tf_ = lam * theta / (2.0 * (lam + theta))
        notes.append(Message(N_("imc: the rule's PID comes with a filter 1/(tauF s + 1), tauF = lambda theta/(2 "
                                "(lambda + theta)) = {tf}, not part of Kp, Ti, Td"), tf=format_seconds(tf_)))
        if lam < 0.25 * theta:
            notes.append(Message(N_("imc: lambda = {lam} is below 0.25 theta = {bound}, the table's bound for this PID: "
                                    "expect a poorly damped loop"), lam=format_seconds(lam),
                                 bound=format_seconds(0.25 * theta)))
    else:
        notes.append(N_("imc: theta = 0, so the PID is a PI (Td = 0) with Kp = tau/(K lambda), Ti = tau"))
    return RuleTuning("imc", kp, ti, td, used, formulas, notes, setting={"lambda_s": lam})


def tune_model(model, rule: str, *, tauc_s: float | None = None,
               lambda_s: float | None = None) -> RuleTuning:
    """Apply one rule of :data:`RULES` to a plant model, on the model the rule intends.

    Parameters
    ----------
    model : ModelFopdt, ModelSopdt, ModelIntegrating, ModelTf or ProcessModel
        A :class:`~designer.core.process.ProcessModel` is tuned as its
        :func:`~.reduction.from_process` model.
    rule : str
        One of :data:`RULES`.
    tauc_s : float, optional
        SIMC's closed-loop time constant (default theta; required when theta = 0).
        Ignored by the other rules.
    lambda_s : float, optional
        IMC's closed-loop time constant (default max(0.25 theta, 0.2 tau)).
        Ignored by the other rules.

    Returns
    -------
    RuleTuning

    Raises
    ------
    DesignError
        An unknown rule, or one that does not apply to the model (the reason
        :func:`applicable` gives).
    """
    key = str(rule).strip().lower()
    if key not in RULES:
        raise DesignError(f"unknown tuning rule {rule!r}; allowed: {', '.join(RULES)}", param="rule")
    if isinstance(model, ProcessModel):
        model = from_process(model)
    if not isinstance(model, MODEL_TYPES):
        raise DesignError(f"{key}: not a plant model ({type(model).__name__}); use ModelFopdt, ModelSopdt, "
                          "ModelIntegrating, ModelTf or a ProcessModel")
    f = check_plant(model, key)
    if key in REACTION_CURVE_RULES:
        return _tune_reaction(model, key, f)
    if key == "amigo":
        return _tune_amigo(model, f)
    if key == "simc":
        return _tune_simc(model, f, tauc_s)
    return _tune_imc(model, f, lambda_s)


def applicable(model, *, tauc_s: float | None = None, lambda_s: float | None = None) -> dict:
    """``{rule: None}`` for each rule that applies to ``model`` (any model
    :func:`tune_model` takes, a ProcessModel included), ``{rule: reason}`` (the
    one-line refusal of :func:`tune_model`) for each that does not.

    Parameters
    ----------
    model : object
        Any model :func:`tune_model` takes.
    tauc_s : float, optional
        SIMC's closed-loop time constant (s).
    lambda_s : float, optional
        IMC's lambda (s).

    Returns
    -------
    dict
    """
    out = {}
    for r in RULES:
        try:
            tune_model(model, r, tauc_s=tauc_s, lambda_s=lambda_s)
            out[r] = None
        except DesignError as e:
            out[r] = str(e)
    return out


def all_rules(model, *, tauc_s: float | None = None, lambda_s: float | None = None) -> list:
    """Every rule of :data:`RULES` on ``model`` (any model :func:`tune_model`
    takes, a ProcessModel included), for the side-by-side table: a
    :class:`RuleTuning`, or ``(rule, reason)`` where the rule does not apply.

    Parameters
    ----------
    model : object
        Any model :func:`tune_model` takes.
    tauc_s : float, optional
        SIMC's closed-loop time constant (s).
    lambda_s : float, optional
        IMC's lambda (s).

    Returns
    -------
    list
    """
    out = []
    for r in RULES:
        try:
            out.append(tune_model(model, r, tauc_s=tauc_s, lambda_s=lambda_s))
        except DesignError as e:   # its message as raised: a Message reads in the sheet's language
            out.append((r, e.args[0] if e.args and isinstance(e.args[0], str) else str(e)))
    return out
