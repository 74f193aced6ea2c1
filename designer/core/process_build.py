"""Building a process model (:class:`~designer.core.process.ProcessModel`)
from its parameters, every value checked: the constructors :func:`fopdt`,
:func:`sopdt`, :func:`underdamped`, :func:`rational`, :func:`integrating`,
and :func:`model_from_dict` (the model a ``to_dict`` wrote); the forms they
build are listed in :mod:`designer.core.process`.

Valid ranges (module constants, checked by every constructor and by
:func:`designer.core.process_text.parse_tf`, which reads a model typed by hand;
each refusal one :class:`~designer.core.errors.DesignError` line naming the
parameter):

- time constants (tau, tau1, tau2, 1/|p| of every pole): :data:`TAU_RANGE`
- |K| (either sign: a negative K is an inverting plant): :data:`GAIN_RANGE`
- fn: :data:`FN_RANGE` (the time-constant range as 1/(2 pi tau))
- zeta: :data:`ZETA_MIN` up to (not including) 1 (zeta >= 1 is the SOPDT form)
- theta: 0 to :data:`MAX_DEAD_TIME_RATIO` times the slowest time constant
  (a pure integrator, with none: up to :data:`MAX_DEAD_TIME_S`)
- a rational plant's order: at most :data:`MAX_ORDER`
"""

from __future__ import annotations

import math

import numpy as np

from .errors import DesignError
from .process import KINDS, PARAMS, ProcessModel, format_g, integ_den, pair_den, sopdt_den
from .ranges import Range

__all__ = ["MAX_DEAD_TIME_RATIO", "ZETA_MIN", "fopdt", "integrating", "model_from_dict", "rational", "sopdt", "underdamped"]

#: every time constant (tau, tau1, tau2; 1/|p| of a rational plant's poles): 1 ps
#: (a 160 GHz pole) to 1e6 s (eleven days): beyond either, the numbers are a typo
TAU_RANGE = Range(1e-12, 1e6, "s")
#: |K|, the static gain (the velocity gain of an integrating plant, 1/s); either sign
GAIN_RANGE = Range(1e-9, 1e9)
#: natural frequency of an underdamped pair: the time-constant range as 1/(2 pi tau)
FN_RANGE = Range(1e-7, 1e11, "Hz")
#: the least damping ratio of an underdamped pair: below it the pair rings for thousands of cycles (Q above
#: 5000), a typo or an oscillator rather than a plant, and the tangent rules' step reaches 63 % after ~1e236 s
#: (scipy's bounded search overflows: zeta 1.3e-262 at 251.82 MHz, found by the typed-model fuzz)
ZETA_MIN = 1e-4
#: a dead time at most this many times the slowest time constant: beyond it the
#: plant is a pure delay for any controller, and a typo (ms for us) is likelier
MAX_DEAD_TIME_RATIO = 100.0
#: the longest dead time of a plant without a time constant (a pure integrator)
MAX_DEAD_TIME_S = 1e6
#: highest degree of a rational plant's numerator and denominator (roots of
#: higher-degree polynomials from typed coefficients are not trustworthy)
MAX_ORDER = 10
#: a pole whose real part is within this fraction of its size of the imaginary
#: axis is on it (np.roots leaves ~1e-16 |p| of noise on the real part of s = +-j w)
AXIS_TOL = 1e-12


# --------------------------------------------------------------------------- checks

def _real(value, name: str) -> float:
    """``value`` as a float if it is a real number (not a bool), else a refusal."""
    if isinstance(value, (bool, np.bool_)) or not isinstance(value, (int, float, np.integer, np.floating)):
        shown = repr(value) if isinstance(value, str) and len(value) <= 40 else type(value).__name__
        raise DesignError(f"{name} must be a number, got {shown}")
    value = float(value)
    if not math.isfinite(value):
        raise DesignError(f"{name} must be a finite number, got {value}")
    return value


def _check_gain(K, name: str) -> float:
    K = _real(K, name)
    if not GAIN_RANGE.contains(abs(K)):
        raise DesignError(f"{name} must be non-zero, |{name}| {GAIN_RANGE.text()} (negative for an inverting "
                          f"plant), got {K:.4g}")
    return K


def _check_tau(tau, name: str, zero_ok: bool = False) -> float:
    tau = _real(tau, name)
    if zero_ok and tau == 0:
        return 0.0
    if not TAU_RANGE.contains(tau):
        why = " (a time constant is positive)" if tau <= 0 else ""
        zero = "0 (none) or " if zero_ok else ""
        raise DesignError(f"{name} must be {zero}{TAU_RANGE.text()}{why}, got {format_g(tau, 's')}")
    return tau


def _check_theta(theta, slowest: float, name: str) -> float:
    """0 <= theta <= MAX_DEAD_TIME_RATIO x the slowest time constant (``slowest``;
    0 for none: then MAX_DEAD_TIME_S)."""
    theta = _real(theta, name)
    if slowest > 0:
        limit = MAX_DEAD_TIME_RATIO * slowest
        why = f"{MAX_DEAD_TIME_RATIO:g} times the slowest time constant, {format_g(slowest, 's')}"
    else:
        limit, why = MAX_DEAD_TIME_S, "a plant without a time constant"
    if not 0.0 <= theta <= limit * (1 + 1e-12):
        raise DesignError(f"{name} (dead time) must be 0 to {format_g(limit, 's')} ({why}), got {format_g(theta, 's')}")
    if 0.0 < theta < TAU_RANGE.lo:
        # as short as the shortest time constant at least: a 1e-144 s delay is a typing slip, and the rules
        # that divide by it give gains of 1e143
        raise DesignError(f"{name} (dead time) must be 0 or at least {format_g(TAU_RANGE.lo, 's')}, got {format_g(theta, 's')}")
    return theta


def _check_fn(fn, name: str) -> float:
    fn = _real(fn, name)
    if not FN_RANGE.contains(fn):
        raise DesignError(f"{name} must be {FN_RANGE.text()}, got {format_g(fn, 'Hz')}")
    return fn


def _check_zeta(zeta, fn: float, names: dict) -> float:
    name = names["zeta"]
    zeta = _real(zeta, name)
    if not ZETA_MIN <= zeta < 1.0:
        hint = ""
        if 1.0 <= zeta <= 1e6:
            # the same pair as two real poles (tau1 s + 1)(tau2 s + 1), tau = 1/(wn (zeta -+ sqrt(zeta^2 - 1))):
            # tau1 = (zeta + r)/wn, as 1/(zeta - r) cancels for a large zeta
            wn, r = 2 * math.pi * fn, math.sqrt(zeta * zeta - 1.0)
            t1, t2 = (zeta + r) / wn, 1.0 / (wn * (zeta + r))
            hint = (f"; for zeta >= 1 use the SOPDT form, here {names['tau1_s']} = {format_g(t1, 's')} and "
                    f"{names['tau2_s']} = {format_g(t2, 's')}")
        raise DesignError(f"{name} must be {ZETA_MIN:g} or more and below 1 (an underdamped pair), got {zeta:.4g}{hint}")
    return zeta


def _check_ci95(ci95, kind: str) -> dict | None:
    """The half-widths of named parameters, finite and >= 0 (None values dropped)."""
    if ci95 is None:
        return None
    out = {}
    for k, v in dict(ci95).items():
        if k not in PARAMS[kind]:
            raise DesignError(f"ci95 key {k!r} is not a parameter of the {kind} model "
                              f"({', '.join(PARAMS[kind])})")
        if v is None:
            continue
        v = _real(v, f"ci95 {k}")
        if v < 0:
            raise DesignError(f"ci95 {k} must be a half-width >= 0, got {v:.4g}")
        out[k] = v
    return out or None


_LIB_NAMES = {k: k for k in ("K", "tau_s", "tau1_s", "tau2_s", "fn_hz", "zeta", "theta_s", "num", "den")}


# --------------------------------------------------------------------------- builders
# shared by the constructors (``_LIB_NAMES``) and designer.core.process_text.parse_tf
# (its typed keys): ``names`` maps each parameter to the name its refusal uses

def build_fopdt(K, tau, theta, names, source, ci95) -> ProcessModel:
    K = _check_gain(K, names["K"])
    tau = _check_tau(tau, names["tau_s"])
    theta = _check_theta(theta, tau, names["theta_s"])
    return ProcessModel("fopdt", {"K": K, "tau_s": tau, "theta_s": theta}, (K,), (tau, 1.0), theta, source,
                        _check_ci95(ci95, "fopdt"))


def build_sopdt(K, tau1, tau2, theta, names, source, ci95) -> ProcessModel:
    K = _check_gain(K, names["K"])
    tau1 = _check_tau(tau1, names["tau1_s"])
    tau2 = _check_tau(tau2, names["tau2_s"])
    ci = _check_ci95(ci95, "sopdt")
    if tau1 < tau2:
        # the slow one first; its half-width goes with it
        tau1, tau2 = tau2, tau1
        if ci:
            a, b = ci.pop("tau1_s", None), ci.pop("tau2_s", None)
            ci.update({k: v for k, v in (("tau1_s", b), ("tau2_s", a)) if v is not None})
    theta = _check_theta(theta, tau1, names["theta_s"])
    params = {"K": K, "tau1_s": tau1, "tau2_s": tau2, "theta_s": theta}
    return ProcessModel("sopdt", params, (K,), sopdt_den(tau1, tau2), theta, source,
                        {k: ci[k] for k in PARAMS["sopdt"] if k in ci} if ci else None)


def build_underdamped(K, fn, zeta, theta, names, source, ci95) -> ProcessModel:
    K = _check_gain(K, names["K"])
    fn = _check_fn(fn, names["fn_hz"])
    zeta = _check_zeta(zeta, fn, names)
    theta = _check_theta(theta, 1.0 / (2 * math.pi * fn), names["theta_s"])
    params = {"K": K, "fn_hz": fn, "zeta": zeta, "theta_s": theta}
    return ProcessModel("underdamped", params, (K,), pair_den(fn, zeta), theta, source,
                        _check_ci95(ci95, "underdamped"))


def build_integrating(K, tau, theta, names, source, ci95) -> ProcessModel:
    K = _check_gain(K, names["K"])
    tau = _check_tau(tau, names["tau_s"], zero_ok=True)
    theta = _check_theta(theta, tau, names["theta_s"])
    return ProcessModel("integrating", {"K": K, "tau_s": tau, "theta_s": theta}, (K,), integ_den(tau), theta,
                        source, _check_ci95(ci95, "integrating"))


def _coefficients(c, name: str) -> np.ndarray:
    """A polynomial's coefficients as floats, leading zeros dropped."""
    if isinstance(c, (str, bytes)) or not hasattr(c, "__len__"):
        c = [c]
    if len(c) == 0:
        raise DesignError(f"{name} is empty: give its coefficients, highest power of s first, as {name}=[1m 1]")
    arr = np.array([_real(v, f"{name}[{i}]") for i, v in enumerate(c)], float)
    arr = np.trim_zeros(arr, "f")
    if arr.size == 0:
        raise DesignError(f"{name} is all zeros: give its coefficients, highest power of s first")
    if arr.size - 1 > MAX_ORDER:
        raise DesignError(f"{name} has degree {arr.size - 1}; at most {MAX_ORDER} is allowed")
    return arr


def _pole_text(p: complex) -> str:
    if abs(p.imag) > 0:
        re_ = 0.0 if abs(p.real) <= AXIS_TOL * abs(p) else p.real   # np.roots' noise on the axis
        return f"s = {re_:.4g} {'+' if p.imag > 0 else '-'} {abs(p.imag):.4g}j rad/s"
    return f"s = {p.real:+.4g} rad/s"


def build_rational(num, den, theta, names, source, ci95) -> ProcessModel:
    nn, dn = names["num"], names["den"]
    n = _coefficients(num, nn)
    d = _coefficients(den, dn)
    if d.size == 1:
        raise DesignError(f"{dn} is a constant: a plant needs at least one pole ({dn} of degree 1 or more, "
                          f"e.g. {dn}=[1m 1])")
    if n.size > d.size:
        raise DesignError(f"{nn} has degree {n.size - 1} and {dn} degree {d.size - 1}: the plant must be proper "
                          f"(degree of {nn} <= degree of {dn})")
    if d[-1] == 0:
        raise DesignError(f"{dn} has a pole at s = 0 (its constant term is 0): that is an integrating plant; "
                          "give it as K, tau and the word integrator (a rational plant must be strictly stable)")
    if n[-1] == 0:
        raise DesignError(f"{nn} has a zero at s = 0 (its constant term is 0): the static gain is 0, which no "
                          "PID can set; a plant needs a non-zero gain")
    with np.errstate(all="ignore"):
        scaled = d / np.max(np.abs(d))   # roots of well-scaled coefficients
        try:
            poles = np.roots(scaled)
        except (np.linalg.LinAlgError, ValueError):
            poles = np.array([np.nan])
    if not np.all(np.isfinite(poles)):
        raise DesignError(f"{dn}: its poles cannot be found (coefficients too far apart in size); "
                          f"time constants must be {TAU_RANGE.text()}")
    for p in sorted(poles, key=lambda x: -x.real):
        if not p.real < -AXIS_TOL * abs(p):
            where = "on the imaginary axis (undamped)" if abs(p.real) <= AXIS_TOL * abs(p) else "in the right half plane"
            raise DesignError(f"{dn} has a pole at {_pole_text(p)}, {where}: a rational plant must be stable, "
                              "every pole with a negative real part")
    for p in poles:
        tc = 1.0 / abs(p)
        if not TAU_RANGE.contains(tc):
            raise DesignError(f"{dn} has a pole at {_pole_text(p)}: its time constant 1/|p| = {format_g(tc, 's')} "
                              f"must be {TAU_RANGE.text()}")
    with np.errstate(all="ignore"):
        n, d = n / d[-1], d / d[-1]
    if not (np.all(np.isfinite(n)) and np.all(np.isfinite(d))):
        raise DesignError(f"{nn} and {dn}: coefficients too far apart in size to be a plant")
    k = float(n[-1])
    if not GAIN_RANGE.contains(abs(k)):
        raise DesignError(f"the static gain {nn}(0)/{dn}(0) must be non-zero, |K| {GAIN_RANGE.text()}, "
                          f"got {k:.4g}")
    slowest = max(1.0 / abs(p) for p in poles)
    theta = _check_theta(theta, slowest, names["theta_s"])
    return ProcessModel("rational", {"theta_s": theta}, tuple(n), tuple(d), theta, source,
                        _check_ci95(ci95, "rational"))


# --------------------------------------------------------------------------- constructors

def fopdt(K, tau_s, theta_s=0.0, *, source: str = "typed", ci95=None) -> ProcessModel:
    """First order plus dead time, K e^(-theta s) / (tau s + 1).

    Parameters
    ----------
    K : float
        Static gain, |K| in :data:`GAIN_RANGE` (negative: an inverting plant).
    tau_s : float
        Time constant (s), in :data:`TAU_RANGE`.
    theta_s : float
        Dead time (s), 0 to :data:`MAX_DEAD_TIME_RATIO` tau.
    source : str
        Where the model came from (``"typed"``).
    ci95 : dict, optional
        95 % half-widths by parameter name (``K``, ``tau_s``, ``theta_s``).

    Returns
    -------
    ProcessModel

    Raises
    ------
    DesignError
        A value outside its range, in one line naming the parameter.
    """
    return build_fopdt(K, tau_s, theta_s, _LIB_NAMES, source, ci95)


def sopdt(K, tau1_s, tau2_s, theta_s=0.0, *, source: str = "typed", ci95=None) -> ProcessModel:
    """Second order (overdamped) plus dead time, K e^(-theta s) / ((tau1 s + 1)(tau2 s + 1)).

    The time constants are sorted, tau1 >= tau2 (their ``ci95`` with them);
    tau1 = tau2 is a double pole. Ranges and refusals as :func:`fopdt`, theta
    against tau1.

    Parameters
    ----------
    K : float
        The static gain.
    tau1_s, tau2_s : float
        The time constants (s).
    theta_s : float
        The dead time (s).
    source : str
        ``"typed"``, or where the model came from.
    ci95 : dict, optional
        95 % confidence half-widths by parameter name (an identified model's).

    Returns
    -------
    ProcessModel
        The model.
    """
    return build_sopdt(K, tau1_s, tau2_s, theta_s, _LIB_NAMES, source, ci95)


def underdamped(K, fn_hz, zeta, theta_s=0.0, *, source: str = "typed", ci95=None) -> ProcessModel:
    """An underdamped pair plus dead time, K wn^2 e^(-theta s) / (s^2 + 2 zeta wn s + wn^2).

    wn = 2 pi fn, fn in :data:`FN_RANGE`, 0 < zeta < 1 (zeta >= 1 is refused
    with the equivalent :func:`sopdt` time constants,
    tau = 1/(wn (zeta -+ sqrt(zeta^2 - 1)))); theta against 1/wn.

    Parameters
    ----------
    K : float
        The static gain.
    fn_hz : float
        The natural frequency.
    zeta : float
        The damping ratio.
    theta_s : float
        The dead time (s).
    source : str
        ``"typed"``, or where the model came from.
    ci95 : dict, optional
        95 % confidence half-widths by parameter name (an identified model's).

    Returns
    -------
    ProcessModel
        The model.
    """
    return build_underdamped(K, fn_hz, zeta, theta_s, _LIB_NAMES, source, ci95)


def rational(num, den, theta_s=0.0, *, source: str = "typed", ci95=None) -> ProcessModel:
    """N(s) e^(-theta s) / D(s) from coefficients, highest power of s first.

    N and D of degree at most :data:`MAX_ORDER`, proper (deg N <= deg D, D of
    degree 1 or more), strictly stable (every pole's real part below
    -:data:`AXIS_TOL` |p|; a pole at 0 is :func:`integrating`'s), every pole's
    1/|p| in :data:`TAU_RANGE`, N(0) != 0. Stored scaled so that D(0) = 1;
    theta against the slowest 1/|p|. ``params`` holds theta_s only.

    Parameters
    ----------
    num, den : array_like
        N and D, highest power of s first.
    theta_s : float
        The dead time (s).
    source : str
        ``"typed"``, or where the model came from.
    ci95 : dict, optional
        95 % confidence half-widths by parameter name (an identified model's).

    Returns
    -------
    ProcessModel
        The model.
    """
    return build_rational(num, den, theta_s, _LIB_NAMES, source, ci95)


def integrating(K, tau_s=0.0, theta_s=0.0, *, source: str = "typed", ci95=None) -> ProcessModel:
    """An integrating plant, K e^(-theta s) / (s (tau s + 1)); tau = 0 is K/s.

    K is the velocity gain (1/s); tau 0 or in :data:`TAU_RANGE`; theta against
    tau (without it: up to :data:`MAX_DEAD_TIME_S`).

    Parameters
    ----------
    K : float
        The velocity gain (1/s).
    tau_s : float
        The lag's time constant (s), 0 for none.
    theta_s : float
        The dead time (s).
    source : str
        ``"typed"``, or where the model came from.
    ci95 : dict, optional
        95 % confidence half-widths by parameter name (an identified model's).

    Returns
    -------
    ProcessModel
        The model.
    """
    return build_integrating(K, tau_s, theta_s, _LIB_NAMES, source, ci95)


def model_from_dict(d: dict) -> ProcessModel:
    """The model :meth:`ProcessModel.to_dict` wrote, rebuilt (and checked) by its constructor.

    Parameters
    ----------
    d : dict
        What :meth:`ProcessModel.to_dict` wrote.

    Returns
    -------
    ProcessModel
        The model.
    """
    if not isinstance(d, dict) or not isinstance(d.get("params"), dict) or "kind" not in d:
        raise DesignError("a process model is an object with 'kind' and 'params'")
    kind, p = d["kind"], d["params"]
    kw = {"source": str(d.get("source", "typed")), "ci95": d.get("ci95")}
    if kind == "rational":
        return rational(d.get("num", ()), d.get("den", ()), p.get("theta_s", 0.0), **kw)
    if kind not in PARAMS:
        raise DesignError(f"kind {kind!r} unknown; allowed: {', '.join(KINDS)}")
    missing = [k for k in PARAMS[kind] if k not in p]
    if missing:
        raise DesignError(f"a {kind} model needs {', '.join(PARAMS[kind])}; {missing[0]} is missing")
    return _CONSTRUCTORS[kind](*(p[k] for k in PARAMS[kind]), **kw)


_CONSTRUCTORS = {"fopdt": fopdt, "sopdt": sopdt, "underdamped": underdamped, "integrating": integrating}
