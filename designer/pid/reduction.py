"""Plant models for the tuning rules of :mod:`.rules`, and their reduction to
the model a rule was derived on.

A model here is plain numbers: an FOPDT :class:`ModelFopdt`, an SOPDT
:class:`ModelSopdt`, an integrating plant :class:`ModelIntegrating`, or any
rational model with dead time :class:`ModelTf` (polynomials in s, highest
power first). :func:`from_process` makes one from the project's plant model,
:class:`designer.core.process.ProcessModel`, by its ``kind``;
:func:`model_step` is a model's exact step.

Every reduction first refuses what no rule takes, in one line: poles in the
right half-plane or on the imaginary axis, more than one integrator, a zero at
s = 0, a negative gain. Then:

* :func:`model_tangent`: the reaction-curve construction on the model's own
  exact step (:func:`designer.core.lti.step_response`): the tangent at the
  steepest point (the inflection point) crosses the initial value at L and
  reaches the final value K at L + T. On an FOPDT the tangent is the model
  itself (L = theta, T = tau). On an integrating plant the steepest slope is
  the final one: the tangent is the ramp asymptote, L = theta + tau. It also
  gives t63, when the step reaches 63.2 % of K: T = t63 - L is the FOTD model
  of Astrom & Hagglund's step-response method (Astrom & Hagglund 2004,
  "Revisiting the Ziegler-Nichols step response method for PID control",
  J. Process Control 14, 635-650).
* :func:`half_rule`: the model reduction of Skogestad (2003, "Simple analytic
  rules for model reduction and PID controller tuning", J. Process Control 13,
  291-309, section 2), to an FOPDT or an SOPDT. The largest neglected
  denominator time constant is split evenly between the effective delay and
  the smallest retained time constant; smaller ones go into the delay whole.
  An inverse-response zero (-T0 s + 1) is approximated as e^(-T0 s) (delay +=
  T0). A left-half-plane zero (T0 s + 1) is cancelled against the denominator
  time constant tau0 next above it (the nearest one below if none is above) by
  the paper's rules, theta being the final effective delay (found by
  iteration): T1: T0/tau0 for T0 >= tau0 >= theta; T1a: T0/theta for T0 >=
  theta >= tau0; T1b: 1 for theta >= T0 >= tau0; T2: T0/tau0 for tau0 >= T0 >=
  5 theta; T3: (tau0~/tau0)/((tau0~ - T0) s + 1) with tau0~ = min(tau0,
  5 theta) >= T0. Complex poles or zeros are outside the rule: refused.
"""

from __future__ import annotations

import math
from dataclasses import asdict, dataclass
from functools import lru_cache
from typing import ClassVar

import numpy as np

from ..core.errors import DesignError
from ..core.i18n import N_, Message
from ..core.lti import StepTerms, coefficients, pole_clusters, step_response
from ..core.process import ProcessModel
from ..core.units import format_eng

__all__ = ["ModelFopdt", "ModelIntegrating", "ModelSopdt", "ModelTf", "from_process", "half_rule", "model_step",
           "model_tangent"]

#: 1 - 1/e: the fraction of the final value an FOPDT reaches one time constant after L
F63 = 1.0 - math.exp(-1.0)


def format_seconds(x: float) -> str:
    return format_eng(x, "s")


def format_number(x: float) -> str:
    return f"{x:.4g}"


def check_number(what: str, name: str, v, *, positive: bool = False, nonzero: bool = False) -> float:
    if isinstance(v, bool) or not isinstance(v, (int, float, np.floating, np.integer)):
        raise DesignError(f"{what}: {name} must be a number (got {v!r})", param=name)
    v = float(v)
    if not math.isfinite(v):
        raise DesignError(f"{what}: {name} must be finite (got {v:g})", param=name)
    if positive and v <= 0:
        raise DesignError(f"{what}: {name} must be positive (got {v:g})", param=name)
    if nonzero and v == 0:
        raise DesignError(f"{what}: {name} must be non-zero (a plant with no gain cannot be tuned)", param=name)
    if not positive and not nonzero and v < 0:
        raise DesignError(f"{what}: {name} must be zero or positive (got {v:g})", param=name)
    return v


# ----------------------------------------------------------------------------- models


@dataclass(frozen=True)
class ModelFopdt:
    """K e^(-theta s)/(tau s + 1)."""

    K: float
    tau_s: float
    theta_s: float = 0.0
    kind: ClassVar[str] = "fopdt"

    def __post_init__(self):
        object.__setattr__(self, "K", check_number("fopdt", "K", self.K, nonzero=True))
        # a pure delay (tau = 0) has no FOPDT lag for the rules to divide by
        object.__setattr__(self, "tau_s", check_number("fopdt", "tau_s", self.tau_s, positive=True))
        object.__setattr__(self, "theta_s", check_number("fopdt", "theta_s", self.theta_s))

    def tf(self):
        """(num, den, theta_s)."""
        return (self.K,), (self.tau_s, 1.0), self.theta_s

    def describe(self) -> str:
        return f"FOPDT K {format_number(self.K)}, tau {format_seconds(self.tau_s)}, theta {format_seconds(self.theta_s)}"

    def to_dict(self) -> dict:
        return {"kind": self.kind, **asdict(self)}


@dataclass(frozen=True)
class ModelSopdt:
    """K e^(-theta s)/((tau1 s + 1)(tau2 s + 1)), tau1 >= tau2 >= 0."""

    K: float
    tau1_s: float
    tau2_s: float
    theta_s: float = 0.0
    kind: ClassVar[str] = "sopdt"

    def __post_init__(self):
        object.__setattr__(self, "K", check_number("sopdt", "K", self.K, nonzero=True))
        object.__setattr__(self, "tau1_s", check_number("sopdt", "tau1_s", self.tau1_s, positive=True))
        object.__setattr__(self, "tau2_s", check_number("sopdt", "tau2_s", self.tau2_s))
        object.__setattr__(self, "theta_s", check_number("sopdt", "theta_s", self.theta_s))
        if self.tau2_s > self.tau1_s:
            raise DesignError(f"sopdt: tau1_s must be the larger time constant (got tau1 {format_seconds(self.tau1_s)} "
                              f"< tau2 {format_seconds(self.tau2_s)}); swap them", param="tau1_s")

    def tf(self):
        return (self.K,), tuple(np.polymul([self.tau1_s, 1.0], [self.tau2_s, 1.0]).tolist()), self.theta_s

    def describe(self) -> str:
        return (f"SOPDT K {format_number(self.K)}, tau1 {format_seconds(self.tau1_s)}, tau2 {format_seconds(self.tau2_s)}, "
                f"theta {format_seconds(self.theta_s)}")

    def to_dict(self) -> dict:
        return {"kind": self.kind, **asdict(self)}


@dataclass(frozen=True)
class ModelIntegrating:
    """K e^(-theta s)/(s (tau s + 1)); K is the velocity gain (per second), tau may be 0."""

    K: float
    tau_s: float = 0.0
    theta_s: float = 0.0
    kind: ClassVar[str] = "integrating"

    def __post_init__(self):
        object.__setattr__(self, "K", check_number("integrating", "K", self.K, nonzero=True))
        object.__setattr__(self, "tau_s", check_number("integrating", "tau_s", self.tau_s))
        object.__setattr__(self, "theta_s", check_number("integrating", "theta_s", self.theta_s))

    def tf(self):
        den = np.polymul([self.tau_s, 1.0], [1.0, 0.0]) if self.tau_s > 0 else np.array([1.0, 0.0])
        return (self.K,), tuple(den.tolist()), self.theta_s

    def describe(self) -> str:
        return Message(N_("integrating K {k}, tau {tau}, theta {theta}"), k=format_eng(self.K, '/s'),
                       tau=format_seconds(self.tau_s), theta=format_seconds(self.theta_s))

    def to_dict(self) -> dict:
        return {"kind": self.kind, **asdict(self)}


@dataclass(frozen=True)
class ModelTf:
    """num(s)/den(s) e^(-theta s), coefficients highest power of s first."""

    num: tuple
    den: tuple
    theta_s: float = 0.0
    kind: ClassVar[str] = "tf"

    def __post_init__(self):
        num = tuple(coefficients(self.num, "num", "tf").tolist())
        den = tuple(coefficients(self.den, "den", "tf").tolist())
        if len(num) > len(den):
            raise DesignError(f"tf: num has degree {len(num) - 1} > den's {len(den) - 1}; "
                              "a plant model must be proper", param="num")
        object.__setattr__(self, "num", num)
        object.__setattr__(self, "den", den)
        object.__setattr__(self, "theta_s", check_number("tf", "theta_s", self.theta_s))

    @classmethod
    def from_factors(cls, K: float, den_tc, num_tc=(), theta_s: float = 0.0,
                     integrator: bool = False) -> "ModelTf":
        """K prod(T s + 1)/prod(tau s + 1) e^(-theta s), times 1/s if ``integrator``.

        A negative numerator time constant is an inverse-response zero: -0.3
        stands for (-0.3 s + 1).
        """
        num = np.array([float(K)])
        for T in num_tc:
            num = np.polymul(num, [float(T), 1.0])
        den = np.array([1.0])
        for tau in den_tc:
            den = np.polymul(den, [float(tau), 1.0])
        if integrator:
            den = np.polymul(den, [1.0, 0.0])
        return cls(tuple(num.tolist()), tuple(den.tolist()), theta_s)

    def tf(self):
        return self.num, self.den, self.theta_s

    def describe(self) -> str:
        return Message(N_("model num {num}, den {den}, theta {theta}"), num=str(list(self.num)), den=str(list(self.den)),
                       theta=format_seconds(self.theta_s))

    def to_dict(self) -> dict:
        return {"kind": self.kind, "num": list(self.num), "den": list(self.den), "theta_s": self.theta_s}


MODEL_TYPES = (ModelFopdt, ModelSopdt, ModelIntegrating, ModelTf)


def model_step(model, t) -> np.ndarray:
    """The model's exact response to a unit step at t = 0.

    Parameters
    ----------
    model : designer.core.process.ProcessModel
        The plant.
    t : array_like
        Times (s).

    Returns
    -------
    numpy.ndarray
    """
    num, den, theta = model.tf()
    return step_response(num, den, np.asarray(t, float) - theta)



def from_process(model: ProcessModel) -> ModelFopdt | ModelSopdt | ModelIntegrating | ModelTf:
    """The model of this module equivalent to a
    :class:`~designer.core.process.ProcessModel`, by its ``kind``.

    Parameters
    ----------
    model : ProcessModel

    Returns
    -------
    ModelFopdt, ModelSopdt, ModelIntegrating or ModelTf
        fopdt: ``ModelFopdt(K, tau_s, theta_s)``; sopdt: ``ModelSopdt(K,
        tau1_s, tau2_s, theta_s)``; integrating: ``ModelIntegrating(K, tau_s,
        theta_s)``; underdamped and rational: ``ModelTf(num, den, theta_s)``,
        the rational part as the ProcessModel holds it (D(0) = 1).

    Raises
    ------
    DesignError
        Not a ProcessModel, or a kind with no model here.
    """
    if not isinstance(model, ProcessModel):
        raise DesignError(f"not a ProcessModel ({type(model).__name__})")
    p = model.params
    if model.kind == "fopdt":
        return ModelFopdt(p["K"], p["tau_s"], p["theta_s"])
    if model.kind == "sopdt":
        return ModelSopdt(p["K"], p["tau1_s"], p["tau2_s"], p["theta_s"])
    if model.kind == "integrating":
        return ModelIntegrating(p["K"], p["tau_s"], p["theta_s"])
    if model.kind in ("underdamped", "rational"):
        return ModelTf(model.num, model.den, model.theta_s)
    raise DesignError(f"a {model.kind!r} ProcessModel has no tuning-rule model", param="kind")


# ----------------------------------------------------------------------------- factors


@dataclass(frozen=True)
class Factors:
    gain: float               # static gain, or the velocity gain with one integrator
    integrators: int
    lags: tuple               # real stable time constants, descending, with multiplicity
    complex_poles: tuple      # (wn_rad_s, zeta) of each stable complex pair
    unstable: int             # poles with Re >= 0 (besides exact integrators)
    lhp_zeros: tuple          # numerator time constants T0 > 0 of (T0 s + 1)
    rhp_zeros: tuple          # inverse-response time constants of (-T0 s + 1)
    complex_zeros: int
    zeros_at_origin: int


@lru_cache(maxsize=512)
def _factors(num: tuple, den: tuple) -> Factors:
    num_a, den_a = np.array(num), np.array(den)
    # exact trailing zeros are integrators (a typed 1/s), never a rounding artefact
    m = len(den_a) - len(np.trim_zeros(den_a, "b"))
    z0 = len(num_a) - len(np.trim_zeros(num_a, "b"))
    den_r, num_r = den_a[: len(den_a) - m], num_a[: len(num_a) - z0]
    gain = float(num_r[-1] / den_r[-1])
    lags, cplx, unstable = [], [], 0
    if den_r.size > 1:
        for p, mult in pole_clusters(np.roots(den_r)):
            if p.real >= 0:
                unstable += mult
            elif p.imag > 0:
                cplx.extend([(abs(p), -p.real / abs(p))] * mult)
            elif p.imag == 0:
                lags.extend([-1.0 / p.real] * mult)
    lhp, rhp, czero = [], [], 0
    if num_r.size > 1:
        for z, mult in pole_clusters(np.roots(num_r)):
            if z.imag != 0:
                czero += mult
            elif z.real < 0:
                lhp.extend([-1.0 / z.real] * mult)
            else:
                rhp.extend([1.0 / z.real] * mult)
    return Factors(gain, m, tuple(sorted(lags, reverse=True)), tuple(cplx), unstable,
                    tuple(sorted(lhp, reverse=True)), tuple(sorted(rhp, reverse=True)), czero, z0)


def check_plant(model, what: str) -> Factors:
    """Refusals that hold for every rule: unstable, double integrator, no gain, negative gain."""
    num, den, _ = model.tf()
    f = _factors(tuple(num), tuple(den))
    if f.unstable:
        raise DesignError(f"{what}: the model has {f.unstable} pole(s) in the right half-plane or on the "
                          "imaginary axis; these rules are for stable or integrating plants")
    if f.integrators > 1:
        raise DesignError(f"{what}: the model has {f.integrators} integrators; the rules take at most one")
    if f.zeros_at_origin:
        raise DesignError(f"{what}: the model has a zero at s = 0 (no static gain): nothing to regulate")
    if f.gain < 0:
        raise DesignError(f"{what}: the model's gain {format_number(f.gain)} is negative; the rules are written for "
                          "K > 0: tune the model with -K and reverse the controller's action")
    return f


# ----------------------------------------------------------------------------- tangent


@dataclass(frozen=True)
class ModelTangent:
    """The reaction-curve tangent of a model's exact step (per unit input).

    For a self-regulating model: the tangent at the steepest point
    (``t_steepest_s``, ``y_steepest``, ``slope_per_s``) crosses 0 at ``L_s``
    and reaches the static gain ``K`` at ``L_s + T_s``; ``t63_s`` is when the
    step reaches 63.2 % of K. For an integrating model (``integrating``) the
    steepest slope is the final one, ``K`` is the velocity gain, the tangent is
    the ramp asymptote K (t - L), and ``T_s``, ``t63_s`` are None. Times
    include the model's dead time.
    """

    K: float
    L_s: float
    T_s: float | None
    slope_per_s: float
    t_steepest_s: float | None
    y_steepest: float | None
    t63_s: float | None
    overshoot_pct: float      #: of the step (of the slope, for an integrating model)
    integrating: bool = False

    def steps(self) -> list:
        """How L and T were read, with numbers."""
        if self.integrating:
            return [Message(N_("the steepest slope of an integrating step is its final one, Kv = {kv}: the tangent is "
                               "the ramp asymptote Kv (t - L), L = {l}"), kv=format_eng(self.K, '/s'),
                            l=format_seconds(self.L_s))]
        out = [Message(N_("steepest point of the step at t = {t}, y = {y}, slope {slope}"),
                       t=format_seconds(self.t_steepest_s), y=format_number(self.y_steepest),
                       slope=format_eng(self.slope_per_s, '/s')),
               Message(N_("L = t - y/slope = {t} - {y} / {slope} = {l}"), t=format_seconds(self.t_steepest_s),
                       y=format_number(self.y_steepest), slope=format_eng(self.slope_per_s, '/s'),
                       l=format_seconds(self.L_s)),
               Message(N_("T = K/slope = {k} / {slope} = {t}"), k=format_number(self.K),
                       slope=format_eng(self.slope_per_s, '/s'), t=format_seconds(self.T_s))]
        return out

    def to_dict(self) -> dict:
        return asdict(self)


def model_tangent(model) -> ModelTangent:
    """The tangent at the inflection point of ``model``'s own exact step.

    On an FOPDT it is the model itself (L = theta, T = tau, exactly); on an
    integrating plant, the ramp asymptote (L = theta + tau). Otherwise the
    steepest point of the exact step is found on a dense grid and refined by
    maximising the impulse response (the step's slope) between its neighbours.

    Parameters
    ----------
    model : designer.core.process.ProcessModel
        The plant.

    Returns
    -------
    ModelTangent

    Raises
    ------
    DesignError
        An unstable model, a double integrator, one whose step jumps at t = 0
        (as many zeros as poles), or a negative gain.
    """
    if not isinstance(model, MODEL_TYPES):
        raise DesignError(f"tangent: not a plant model ({type(model).__name__})")
    f = check_plant(model, "tangent")
    if isinstance(model, ModelFopdt):
        K, tau, th = model.K, model.tau_s, model.theta_s
        return ModelTangent(K, th, tau, K / tau, th, 0.0, th + tau, 0.0)
    if isinstance(model, ModelIntegrating):
        return ModelTangent(model.K, model.theta_s + model.tau_s, None, model.K, None, None, None, 0.0, True)
    num, den, theta = model.tf()
    return _tangent(tuple(num), tuple(den), float(theta), f.integrators)


@lru_cache(maxsize=256)
def _tangent(num: tuple, den: tuple, theta: float, integrators: int) -> ModelTangent:
    num_a, den_a = np.array(num), np.array(den)
    if integrators:
        den_r = den_a[:-1]
        kv = float(num_a[-1] / den_r[-1])
        # y -> Kv (t - theta - d1 + n1): d1, n1 the s-coefficients of den/den(0) and num/num(0)
        n1 = num_a[-2] / num_a[-1] if num_a.size > 1 else 0.0
        d1 = den_r[-2] / den_r[-1] if den_r.size > 1 else 0.0
        t = _grid(den_r)
        slope = step_response(num_a, den_r, t) / kv if den_r.size > 1 else np.ones(1)
        os_pct = max(0.0, (float(np.max(slope)) - 1.0) * 100.0)
        return ModelTangent(kv, float(theta + d1 - n1), None, kv, None, None, None, os_pct, True)
    if len(num_a) == len(den_a):
        raise DesignError("tangent: the model's step jumps at t = 0 (as many zeros as poles): "
                          "it has no reaction curve")
    K = float(num_a[-1] / den_a[-1])
    t = _grid(den_a)
    # the step's slope is the step response of s G(s); both steps' poles and residues
    # found once, for the grid and the refining searches' single points alike
    slope_of = StepTerms.of(np.polymul(num_a, [1.0, 0.0]), den_a)
    step_of = StepTerms.of(num_a, den_a)

    def slope(x):
        return float(slope_of([x])[0]) / K

    exps = step_of.exponentials(t)        # one denominator: the two steps share their poles
    h = slope_of(t, exps) / K
    y = step_of(t, exps) / K
    i = int(np.argmax(h))
    ts = float(t[i])
    if 0 < i < t.size - 1:
        from scipy.optimize import minimize_scalar
        r = minimize_scalar(lambda x: -slope(x), bounds=(float(t[i - 1]), float(t[i + 1])),
                            method="bounded", options={"xatol": 1e-13 * float(t[-1])})
        if -r.fun >= h[i]:
            ts = float(r.x)
    hs = slope(ts)
    ys = float(step_of([ts])[0]) / K
    L = theta + ts - ys / hs
    T = 1.0 / hs
    j = int(np.argmax(y >= F63))
    from scipy.optimize import brentq
    t63 = brentq(lambda x: float(step_of([x])[0]) / K - F63,
                 float(t[j - 1]), float(t[j]), xtol=1e-15 * float(t[-1])) if j > 0 else float(t[0])
    os_pct = max(0.0, (float(np.max(y)) - 1.0) * 100.0)
    return ModelTangent(K, float(L), float(T), K * hs, theta + ts, K * ys, theta + t63, os_pct)


def _grid(den) -> np.ndarray:
    """Times that show the whole step settling (15 slowest decay times), dense at both ends."""
    poles = np.roots(den) if len(den) > 1 else np.array([-1.0])
    sigma = float(np.min(-poles.real))
    t_end = 15.0 / sigma
    return np.union1d(np.linspace(0.0, t_end, 20001), np.geomspace(t_end * 1e-9, t_end, 4001))


# ----------------------------------------------------------------------------- half rule


@dataclass(frozen=True)
class HalfRule:
    """The model Skogestad's half rule reduces a model to, and the steps with numbers."""

    model: object             #: ModelFopdt, ModelSopdt or ModelIntegrating
    order: int
    steps: tuple
    converged: bool = True    #: the effective delay the zero rules need settled


def _theta_of(lags, order, integrating, theta_x):
    keep = order - 1 if integrating else order
    if len(lags) <= keep:
        return theta_x
    return theta_x + lags[keep] / 2.0 + sum(lags[keep + 1:])


def _zero_rule(T0, tau0, theta):
    """Skogestad (2003) rules T1-T3 for (T0 s + 1)/(tau0 s + 1): (name, gain, new lag or None)."""
    if T0 >= tau0:
        if tau0 >= theta:
            return "T1", T0 / tau0, None
        if T0 >= theta:
            return "T1a", T0 / theta, None
        return "T1b", 1.0, None
    if T0 >= 5.0 * theta:
        return "T2", T0 / tau0, None
    tt = min(tau0, 5.0 * theta)
    return "T3", tt / tau0, tt - T0


def half_rule(model, order: int = 1) -> HalfRule:
    """Skogestad's (2003) half rule: reduce ``model`` to an FOPDT (``order`` 1)
    or an SOPDT (``order`` 2); an integrating model to K' e^(-theta s)/s or
    K' e^(-theta s)/(s (tau s + 1)).

    Parameters
    ----------
    model : ModelFopdt, ModelSopdt, ModelIntegrating or ModelTf
    order : {1, 2}

    Returns
    -------
    HalfRule

    Raises
    ------
    DesignError
        Complex poles or zeros (the rule takes real time constants), an
        unstable model, or nothing left after the cancellations.
    """
    return half_rule_of(model, order, "half rule")


def half_rule_of(model, order: int, what: str) -> HalfRule:
    if order not in (1, 2):
        raise DesignError(f"{what}: order must be 1 (FOPDT) or 2 (SOPDT), got {order!r}", param="order")
    if not isinstance(model, MODEL_TYPES):
        raise DesignError(f"{what}: not a plant model ({type(model).__name__})")
    f = check_plant(model, what)
    if f.complex_poles:
        wn, z = f.complex_poles[0]
        raise DesignError(Message(N_("{what}: the model has complex poles (zeta {z}, fn {fn}) and the half rule takes "
                                     "real time constants only; the tangent rules (zn, amigo) still apply"),
                                  what=what, z=f"{z:.3g}", fn=format_eng(wn / (2 * math.pi), 'Hz')))
    if f.complex_zeros:
        raise DesignError(Message(N_("{what}: the model has complex zeros and the half rule takes real time constants "
                                     "only"), what=what))
    num, den, theta0 = model.tf()
    return _half(f, float(theta0), order, what)


def _half(f: Factors, theta0: float, order: int, what: str) -> HalfRule:
    integ = f.integrators == 1
    steps = []
    lags = list(f.lags)
    if lags:
        steps.append("denominator time constants " + ", ".join(format_seconds(x) for x in lags)
                     + (" and an integrator" if integ else ""))
    theta_x = theta0 + sum(f.rhp_zeros)
    if f.rhp_zeros:
        steps.append("inverse-response zeros (-T0 s + 1) ~ e^(-T0 s): delay += "
                     + " + ".join(format_seconds(x) for x in f.rhp_zeros))
    gain = f.gain
    converged = True
    if f.lhp_zeros:
        theta = _theta_of(lags, order, integ, theta_x)
        for _ in range(60):
            cur, g, log = list(lags), 1.0, []
            for T0 in f.lhp_zeros:
                if not cur:
                    raise DesignError(f"{what}: the zero (T0 = {format_seconds(T0)}) has no denominator time "
                                      "constant left to cancel against")
                above = [x for x in cur if x >= T0]
                tau0 = min(above) if above else max(cur)
                cur.remove(tau0)
                name, k, new = _zero_rule(T0, tau0, theta)
                g *= k
                if new is not None:
                    cur.append(new)
                log.append(Message(N_("zero T0 = {t0} against the lag tau0 = {tau0}, rule {name}: {what}{gain}"),
                                   t0=format_seconds(T0), tau0=format_seconds(tau0), name=name,
                                   what=(Message(N_("lag {lag}"), lag=format_seconds(new)) if new is not None
                                         else N_("cancelled")),
                                   gain=Message(N_(", gain x {k}"), k=format_number(k)) if k != 1.0 else ""))
            cur.sort(reverse=True)
            new_theta = _theta_of(cur, order, integ, theta_x)
            if math.isclose(new_theta, theta, rel_tol=1e-12, abs_tol=1e-15):
                break
            theta = new_theta
        else:
            converged = False
        lags, gain = cur, gain * g
        steps.extend(log)
        steps.append(Message(N_("with the effective delay {theta} the zero rules use{why}"), theta=format_seconds(theta),
                             why="" if converged else N_(" (did not settle: the rules switch regime)")))
    if not lags and not integ:
        raise DesignError(f"{what}: after the half rule cancels the zeros no time constant is left: "
                          "a gain and a delay, no FOPDT")
    theta = _theta_of(lags, order, integ, theta_x)
    keep = order - 1 if integ else order
    neglected = lags[keep:]
    if neglected:
        steps.append(f"theta = {format_seconds(theta_x)} + {format_seconds(neglected[0])}/2"
                     + ("".join(f" + {format_seconds(x)}" for x in neglected[1:])) + f" = {format_seconds(theta)}")
    half = neglected[0] / 2.0 if neglected else 0.0
    if integ:
        if order == 1:
            m = ModelIntegrating(gain, 0.0, theta)
        else:
            tau = (lags[0] if lags else 0.0) + (half if lags else 0.0)
            if lags and len(lags) > 1:
                steps.append(f"tau = {format_seconds(lags[0])} + {format_seconds(lags[1])}/2 = {format_seconds(tau)}")
            m = ModelIntegrating(gain, tau, theta)
    elif order == 1:
        tau = lags[0] + half
        if len(lags) > 1:
            steps.append(f"tau = {format_seconds(lags[0])} + {format_seconds(lags[1])}/2 = {format_seconds(tau)}")
        m = ModelFopdt(gain, tau, theta)
    else:
        t1 = lags[0]
        t2 = (lags[1] if len(lags) > 1 else 0.0) + half
        if len(lags) > 2:
            steps.append(f"tau2 = {format_seconds(lags[1])} + {format_seconds(lags[2])}/2 = {format_seconds(t2)}")
        if t2 > t1:
            steps.append(N_("tau2 came out larger than tau1: swapped"))
            t1, t2 = t2, t1
        m = ModelSopdt(gain, t1, t2, theta)
    steps.append(Message("-> {model}", model=m.describe()))
    return HalfRule(m, order, tuple(steps), converged)

