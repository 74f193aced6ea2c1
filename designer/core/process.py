"""Process (plant) models G(s) = N(s)/D(s) e^(-theta s) for PID design: the
model of a plant, however it arrived (typed by hand, identified from a
capture, or a designed circuit), with its exact step and frequency responses.

Forms (:class:`ProcessModel`, ``kind``; parameter names as in ``params``):

- ``fopdt``        K, tau_s, theta_s          K e^(-theta s) / (tau s + 1)
- ``sopdt``        K, tau1_s, tau2_s, theta_s K e^(-theta s) / ((tau1 s + 1)(tau2 s + 1)),
  tau1 >= tau2 (the slow time constant first; :mod:`designer.core.stepfit`'s
  ``overdamped`` writes the fast one first, and the constructor sorts)
- ``underdamped``  K, fn_hz, zeta, theta_s    K wn^2 e^(-theta s) / (s^2 + 2 zeta wn s + wn^2),
  wn = 2 pi fn, 0 < zeta < 1
- ``integrating``  K, tau_s, theta_s          K e^(-theta s) / (s (tau s + 1)) (tau = 0: K/s);
  K is the velocity gain (output per unit input per second)
- ``rational``     theta_s (and num, den)     N(s) e^(-theta s) / D(s), proper (deg N <= deg D)
  and strictly stable (every pole with negative real part)

``num`` and ``den`` hold the rational part without the delay, highest power
first, scaled so that D's constant term is 1 (so N(0) is the static gain; an
integrating plant has the s in D: ``den = (tau, 1, 0)``).

Responses are exact: the rational part's step from its partial fractions
(:func:`designer.core.lti.step_response`, repeated poles included), shifted by
theta (zero before it); the frequency response N(jw)/D(jw) e^(-j w theta).

Built, and every value checked against its valid range, by the constructors of
:mod:`designer.core.process_build` (:func:`~designer.core.process_build.fopdt`,
:func:`~designer.core.process_build.sopdt`, :func:`~designer.core.process_build.underdamped`,
:func:`~designer.core.process_build.rational`, :func:`~designer.core.process_build.integrating`,
:func:`~designer.core.process_build.model_from_dict`) or, typed by hand, by
:func:`designer.core.process_text.parse_tf`. This module holds the model
itself: its figures, responses, text and JSON, and the corners of its ci95
box (:meth:`ProcessModel.corners`, built unchecked: they bound a fit).
"""

from __future__ import annotations

import itertools
import math
from dataclasses import dataclass
from functools import cached_property

import numpy as np

from .errors import DesignError
from .lti import pole_clusters, step_response
from .units import format_eng

__all__ = ["ProcessModel"]

KINDS = ("fopdt", "sopdt", "underdamped", "rational", "integrating")
#: the parameters each kind records (``params``), in this order
PARAMS = {
    "fopdt": ("K", "tau_s", "theta_s"),
    "sopdt": ("K", "tau1_s", "tau2_s", "theta_s"),
    "underdamped": ("K", "fn_hz", "zeta", "theta_s"),
    "rational": ("theta_s",),
    "integrating": ("K", "tau_s", "theta_s"),
}

#: the settling band of :attr:`ProcessModel.settling_time_s`, of the final value
SETTLING_BAND = 0.02
#: samples of the step used to find the settling time (then interpolated)
SETTLING_SAMPLES = 20001
#: a corner (:meth:`ProcessModel.corners`) keeps each time constant, fn, zeta and
#: |K| at least this fraction of its nominal value (a 95 % interval wider than
#: the value would otherwise cross zero)
CORNER_MIN_FRACTION = 1e-3
#: the largest zeta of a corner (the model stays underdamped)
CORNER_MAX_ZETA = 0.999


# --------------------------------------------------------------------------- text

def format_g(v: float, unit: str = "") -> str:
    return format_eng(v, unit) if unit else f"{v:.4g}"


# --------------------------------------------------------------------------- the model

@dataclass(frozen=True)
class ProcessModel:
    """A plant G(s) = N(s)/D(s) e^(-theta s): build it with a constructor
    (:func:`fopdt`, :func:`sopdt`, :func:`underdamped`, :func:`rational`,
    :func:`integrating`) or :func:`~designer.core.process_text.parse_tf`,
    which check every value.

    Attributes
    ----------
    kind : str
        One of :data:`KINDS`.
    params : dict
        What was given (:data:`PARAMS` of the kind): seconds, hertz, zeta, K.
    num, den : tuple of float
        The rational part, highest power first, D's constant term 1 (an
        integrating plant: D = s (tau s + 1)).
    theta_s : float
        Dead time, >= 0.
    source : str
        ``"typed"``, or where the model came from.
    ci95 : dict or None
        95 % confidence half-widths by parameter name (an identified model's).
    """

    kind: str
    params: dict
    num: tuple
    den: tuple
    theta_s: float = 0.0
    source: str = "typed"
    ci95: dict | None = None

    def __post_init__(self):
        if self.kind not in KINDS:
            raise DesignError(f"kind {self.kind!r} unknown; allowed: {', '.join(KINDS)}")
        object.__setattr__(self, "num", tuple(float(c) for c in self.num))
        object.__setattr__(self, "den", tuple(float(c) for c in self.den))
        object.__setattr__(self, "theta_s", float(self.theta_s))

    # ----------------------------------------------------------------- figures

    @property
    def integrating(self) -> bool:
        """True for an integrating plant (a pole at s = 0)."""
        return self.kind == "integrating"

    @property
    def gain(self) -> float:
        """The static gain N(0)/D(0); for an integrating plant its velocity gain
        K = lim s->0 of s G(s) (output per unit input per second)."""
        if self.integrating:
            return self.num[-1] / self.den[-2]
        return self.num[-1] / self.den[-1]

    @cached_property
    def poles(self) -> np.ndarray:
        """The poles of the rational part (rad/s, complex), the integrator's 0 included."""
        with np.errstate(all="ignore"):
            return np.roots(self.den)

    @property
    def time_constants_s(self) -> tuple:
        """One time constant per pole but the integrator's, slowest first:
        1/|p| (= 1/|Re p| for a real pole, 1/wn for a complex pair)."""
        p = self.poles
        p = p[np.abs(p) > 0]
        return tuple(sorted((float(1.0 / abs(x)) for x in p), reverse=True))

    @property
    def time_scale_s(self) -> float:
        """The slowest time constant; without one (a pure integrator) the dead
        time, or else the integration time 1/|K|."""
        tc = self.time_constants_s
        if tc:
            return tc[0]
        return self.theta_s if self.theta_s > 0 else 1.0 / abs(self.gain)

    @cached_property
    def settling_time_s(self) -> float:
        """2 % settling time of the open-loop unit step, from the step itself:
        the last time the exact response (:meth:`step`) is outside
        SETTLING_BAND of its final value, interpolated between samples, dead
        time included. An integrating plant never settles: the settling time of
        its non-integrating part K e^(-theta s)/(tau s + 1) (theta + tau ln 50)."""
        num, den = self._lag_part()
        poles = np.roots(den) if len(den) > 1 else np.array([])
        if poles.size == 0:
            return self.theta_s
        # long enough for the slowest mode, times t^(m-1) of a repeated pole, to die out
        slow = 1.0 / float(np.min(np.abs(poles.real)))
        m = max(mult for _, mult in pole_clusters(poles))
        t = np.linspace(0.0, (20.0 + 10.0 * (m - 1)) * slow, SETTLING_SAMPLES)
        y = step_response(num, den, t)
        yf = num[-1] / den[-1]
        level = SETTLING_BAND * abs(yf)
        err = np.abs(y - yf)
        outside = np.nonzero(err > level)[0]
        if outside.size == 0:
            return self.theta_s
        i = int(outside[-1])
        if i + 1 >= t.size:
            return self.theta_s + float(t[-1])
        e0, e1 = err[i], err[i + 1]
        frac = (e0 - level) / (e0 - e1) if e0 != e1 else 0.0
        return self.theta_s + float(t[i] + frac * (t[i + 1] - t[i]))

    def _lag_part(self):
        """(num, den) of the rational part without the integrator's pole."""
        den = self.den[:-1] if self.integrating else self.den
        return self.num, den

    # ----------------------------------------------------------------- responses

    def freq(self, w_rad_s) -> np.ndarray:
        """Complex G(j w) = N(jw)/D(jw) e^(-j w theta), dead time exact (an
        integrating plant is infinite at w = 0)."""
        s = 1j * np.asarray(w_rad_s, float)
        with np.errstate(divide="ignore", invalid="ignore"):
            g = np.polyval(self.num, s) / np.polyval(self.den, s) * np.exp(-s * self.theta_s)
        if self.integrating:
            g = np.where(s == 0, complex(np.inf, 0.0), g)   # not inf * e^0 = inf + nan j
        return g

    def step(self, t) -> np.ndarray:
        """Response to a unit step at t = 0: the rational part's exact step
        (:func:`~designer.core.lti.step_response`) delayed by theta, 0 before it."""
        t = np.asarray(t, float)
        return step_response(self.num, self.den, t - self.theta_s)

    # ----------------------------------------------------------------- text and JSON

    def text(self) -> str:
        """One line, with units: ``G(s) = 2 e^(-200 us s) / (1 ms s + 1)``."""
        p = self.params
        delay = f" e^(-{format_g(self.theta_s, 's')} s)" if self.theta_s > 0 else ""
        if self.kind == "fopdt":
            return f"G(s) = {p['K']:.4g}{delay} / ({format_g(p['tau_s'], 's')} s + 1)"
        if self.kind == "sopdt":
            return (f"G(s) = {p['K']:.4g}{delay} / (({format_g(p['tau1_s'], 's')} s + 1)"
                    f"({format_g(p['tau2_s'], 's')} s + 1))")
        if self.kind == "underdamped":
            return (f"G(s) = {p['K']:.4g} wn^2{delay} / (s^2 + 2 zeta wn s + wn^2), "
                    f"fn = {format_g(p['fn_hz'], 'Hz')}, zeta = {p['zeta']:.4g}")
        if self.kind == "integrating":
            lag = f"(s ({format_g(p['tau_s'], 's')} s + 1))" if p["tau_s"] > 0 else "s"
            return f"G(s) = {p['K']:.4g}{delay} / {lag}"
        num, den = _poly_text(self.num), _poly_text(self.den)
        num = num if len(self.num) == 1 else f"({num})"
        return f"G(s) = {num}{delay} / ({den})"

    def to_dict(self) -> dict:
        """JSON-ready: kind, params, num, den, theta_s, source, ci95, and the
        derived gain, integrating flag and :meth:`text`."""
        return {"kind": self.kind, "params": dict(self.params), "num": list(self.num), "den": list(self.den),
                "theta_s": self.theta_s, "source": self.source,
                "ci95": None if self.ci95 is None else dict(self.ci95),
                "gain": self.gain, "integrating": self.integrating, "text": self.text()}

    # ----------------------------------------------------------------- uncertainty

    def corners(self) -> list:
        """The models at the 2^n corners of the ci95 box of the n parameters
        that have a half-width (nominal +- half-width; [] without ci95).

        Each corner stays physical: time constants, fn and |K| at least
        :data:`CORNER_MIN_FRACTION` of nominal (K keeps its sign), theta >= 0,
        zeta inside (0, :data:`CORNER_MAX_ZETA`]. Corners are not checked
        against the dead-time ratio (they bound a fit, they are not typed).
        Each has ``ci95`` None and its ``source`` names the corner
        (``"... corner K+ tau_s-"``)."""
        if not self.ci95:
            return []
        keys = [k for k in self.params if self.ci95.get(k)]
        out = []
        for signs in itertools.product((1.0, -1.0), repeat=len(keys)):
            p = dict(self.params)
            for k, sg in zip(keys, signs):
                p[k] = _clip(k, self.params[k], self.params[k] + sg * self.ci95[k])
            label = " ".join(f"{k}{'+' if sg > 0 else '-'}" for k, sg in zip(keys, signs))
            out.append(_unchecked(self, p, f"{self.source} corner {label}"))
        return out


def _clip(key: str, nominal: float, value: float) -> float:
    if key == "theta_s":
        return max(value, 0.0)
    floor = CORNER_MIN_FRACTION * abs(nominal)
    if key == "K":
        mag = abs(value) if value * nominal > 0 else 0.0   # K keeps its sign
        return math.copysign(max(mag, floor), nominal)
    if key == "zeta":
        return min(max(value, floor), max(CORNER_MAX_ZETA, nominal))
    return max(value, floor)   # time constants, fn


def _unchecked(model: ProcessModel, p: dict, source: str) -> ProcessModel:
    """``model``'s kind with the parameters ``p`` (already physical), unchecked."""
    kind, th = model.kind, p["theta_s"]
    if kind == "fopdt":
        num, den = (p["K"],), (p["tau_s"], 1.0)
    elif kind == "sopdt":
        t1, t2 = sorted((p["tau1_s"], p["tau2_s"]), reverse=True)
        p = {"K": p["K"], "tau1_s": t1, "tau2_s": t2, "theta_s": th}
        num, den = (p["K"],), sopdt_den(t1, t2)
    elif kind == "underdamped":
        num, den = (p["K"],), pair_den(p["fn_hz"], p["zeta"])
    elif kind == "integrating":
        num, den = (p["K"],), integ_den(p["tau_s"])
    else:
        num, den = model.num, model.den
    return ProcessModel(kind, p, num, den, th, source, None)


def sopdt_den(t1: float, t2: float) -> tuple:
    return (t1 * t2, t1 + t2, 1.0)


def pair_den(fn: float, zeta: float) -> tuple:
    # K wn^2/(s^2 + 2 zeta wn s + wn^2) = K/(s^2/wn^2 + 2 zeta s/wn + 1)
    wn = 2 * math.pi * fn
    return (1.0 / (wn * wn), 2.0 * zeta / wn, 1.0)


def integ_den(tau: float) -> tuple:
    return (tau, 1.0, 0.0) if tau > 0 else (1.0, 0.0)


def _poly_text(c) -> str:
    """``1e-06 s^2 + 0.001 s + 1``."""
    n = len(c) - 1
    terms = []
    for i, a in enumerate(c):
        if a == 0:
            continue
        k = n - i
        power = "" if k == 0 else (" s" if k == 1 else f" s^{k}")
        mag = f"{abs(a):.4g}"
        sign = "-" if a < 0 else "+"
        terms.append((sign, mag + power))
    if not terms:
        return "0"
    first = ("-" if terms[0][0] == "-" else "") + terms[0][1]
    return " ".join([first] + [f"{sg} {t}" for sg, t in terms[1:]])
