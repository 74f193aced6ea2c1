"""What the second-order step methods share (seeds 000, 002 and 003).

The methods are in :mod:`.underdamped`, :mod:`.overdamped` and
:mod:`.dc_motor`; their list, in the order the step identification runs
them, is :data:`designer.identify.second_order.STEP_METHODS`.

Every method has the signature ``method(t, y, yf, sigma=None) -> MethodResult``:

- ``t``  time since the step, seconds (t >= 0, increasing);
- ``y``  the response's deviation from its pre-step baseline divided by the
  input step amplitude (starts near 0, settles at ``yf``);
- ``yf`` its settled value, i.e. the static gain K;
- ``sigma`` the noise of ``y`` when the caller measured it (the spread of an
  averaged square wave's plateaus), else estimated here.

They work on the normalised response ``z = y / yf`` (0 -> 1, :func:`prepare`),
so a plant with a negative gain is handled like a positive one. They never
raise on data outside their range: they return ``valid=False`` with a note
naming the range and why (:func:`fail`, :func:`guarded`).
``iae``/``ise`` are left nan (the orchestrator computes them against the data).
A method that assumes no dead time has its result refused when the data start
later than its model (:func:`flag_late`).

Overdamped results name the *fast* time constant ``tau1_s`` and the slow one
``tau2_s`` (tau1 <= tau2), as seed 003 (tau1 = 5, tau2 = 100) and seed 002
(p1 fast, p2 slow) do (:func:`second_order_params`).

Crossing times are robust on noisy data: the samples within a few noise
standard deviations of the level are fitted with a straight line, which on
clean data reduces to linear interpolation between the two bracketing samples
(:func:`designer.core.waveform.crossing_time`).
"""

from __future__ import annotations

import functools
import math

import numpy as np

from ..core.waveform import crossing_time, noise_sigma
from .structures import MethodResult, model_step

__all__ = []


def prepare(t, y, yf, sigma=None):
    """Normalised arrays and noise (``sigma`` of ``y`` when given), or an error note."""
    t = np.asarray(t, float)
    y = np.asarray(y, float)
    if t.ndim != 1 or t.shape != y.shape or t.size < 5:
        return None, None, 0.0, "needs at least 5 samples of time and response"
    if not (math.isfinite(yf) and yf != 0.0):
        return None, None, 0.0, "the final value is zero or not finite"
    z = y / yf
    if not (np.all(np.isfinite(z)) and np.all(np.isfinite(t))):
        return None, None, 0.0, "the record has non-finite samples"
    return t, z, (noise_sigma(z) if sigma is None else sigma / abs(yf)), ""


def _nan_params(model):
    names = {"fopdt": ("K", "tau_s", "theta_s"), "double-pole": ("K", "tau_s", "theta_s"),
             "underdamped": ("K", "wn_rad_s", "zeta", "theta_s"),
             "overdamped": ("K", "tau1_s", "tau2_s", "theta_s")}[model]
    return {k: math.nan for k in names}


def fail(name, model, note, yf=math.nan, points=None):
    p = _nan_params(model)
    p["K"] = float(yf) if yf is not None else math.nan
    return MethodResult(name, model, p, valid=False, note=note, points=points or {})


def second_order_params(K, wn, zeta, theta):
    """(model, params) for a K wn^2 e^{-theta s}/(s^2 + 2 zeta wn s + wn^2):
    underdamped below zeta = 1, otherwise two real time constants."""
    if zeta < 1.0:
        return "underdamped", {"K": K, "wn_rad_s": wn, "zeta": zeta, "theta_s": theta}
    r = math.sqrt(zeta * zeta - 1.0)
    return "overdamped", {"K": K, "tau1_s": 1.0 / (wn * (zeta + r)),
                          "tau2_s": 1.0 / (wn * (zeta - r)), "theta_s": theta}


def _late_start(t, z, sigma, model, params):
    """For the methods that assume no dead time: how much later than the
    identified model the data leave zero (time to 5 %), or 0. A lag over a
    tenth of the time to 50 % means a dead time the method cannot represent."""
    t05 = crossing_time(t, z, 0.05, sigma=sigma)
    t50 = crossing_time(t, z, 0.5, sigma=sigma)
    if not (math.isfinite(t05) and math.isfinite(t50)) or t50 <= 0.0:
        return 0.0
    p = dict(params, K=1.0, theta_s=0.0)
    try:
        tm = np.linspace(0.0, 2.0 * t50, 4001)
        m05 = crossing_time(tm, model_step(model, p, tm), 0.05)
    except (ValueError, KeyError, ZeroDivisionError, OverflowError):
        return 0.0
    lag = t05 - m05 if math.isfinite(m05) else 0.0
    return lag if lag > 0.1 * t50 else 0.0


def flag_late(result, t, z, sigma):
    """Mark a no-dead-time method's result invalid when the data start late
    (the dead time is then the first thing to tell, before any range note)."""
    if not all(math.isfinite(v) for v in result.params.values()):
        return result
    lag = _late_start(t, z, sigma, result.model, result.params)
    if lag > 0.0:
        result.valid = False
        result.note = (f"the data leave zero {lag:.3g} s later than this model: a dead time, "
                       "which this method assumes absent (use chen, stark-mollenkamp, "
                       "jahanmiri-fallahi or least-squares)")
    return result


_POSITIVE = ("tau_s", "tau1_s", "tau2_s", "wn_rad_s", "zeta")


def guarded(name, model):
    """Decorator: run a method with numpy's warnings silenced (degenerate data
    give inf/nan, handled here), turn an arithmetic failure on degenerate data
    into valid=False, and likewise any non-finite or non-physical parameter
    of a "valid" result."""
    def wrap(method):
        @functools.wraps(method)
        def run(t, y, yf, *args, **kwargs):
            try:
                with np.errstate(all="ignore"):
                    r = method(t, y, yf, *args, **kwargs)
            except (ArithmeticError, ValueError, np.linalg.LinAlgError) as exc:
                return fail(name, model, "the data do not have this method's shape "
                             f"({type(exc).__name__}: {exc})",
                             math.nan if name == "dc-motor-position" else yf)
            bad = [k for k, v in r.params.items()
                   if not math.isfinite(v) or (k in _POSITIVE and v <= 0.0)
                   or (k == "theta_s" and v < 0.0)]
            if r.valid and bad:
                r.valid = False
                r.note = "; ".join(x for x in (r.note, "degenerate result (" + ", ".join(bad)
                                              + " not a positive finite number): the data do "
                                              "not have this method's shape") if x)
            return r
        return run
    return wrap

