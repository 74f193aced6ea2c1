"""DC motor from its step response to an armature voltage (seed 000 section 4, eqs 45-57).

The motor is Theta/U = Km/(s (tau_m s + 1)) in position (seed 000 eq 45) and
W/U = Km/(tau_m s + 1) in velocity (eq 46); both methods report the velocity
model (``fopdt`` with no dead time).

Methods
-------
- ``dc-motor``: the velocity response, Km = W(inf)/a,
  tau_m = -t0 / ln(1 - w(t0)/W(inf)) (seed 000 eqs 52-55).
- :func:`dc_motor_position`: the shaft position, an integrating, never-settling
  response (seed 000 eq 45/57). It is not in
  :data:`designer.identify.second_order.STEP_METHODS` because the step
  orchestrator needs a settled final value.

:func:`dc_motor_velocity` is seed 000 eqs 52 and 55 on the figures read off a
record (the seed's worked example). The signature and the ``valid=False``
notes are those of every second-order step method (:mod:`._step_methods`).
"""

from __future__ import annotations

import math

import numpy as np

from ..core.waveform import crossing_time
from ._step_methods import fail, guarded, prepare
from .structures import MethodResult

__all__ = ["dc_motor", "dc_motor_position", "dc_motor_velocity"]


def dc_motor_velocity(a, w_inf, t0, w_t0):
    """Seed 000 eqs 52 and 55: ``(Km, tau_m)`` from the step size ``a``, the final
    velocity ``w_inf`` and one transient sample ``w_t0`` at ``t0``.

    Parameters
    ----------
    a : float
        The voltage step's size.
    w_inf : float
        Final velocity.
    t0 : float
        Time of the transient sample in s.
    w_t0 : float
        Velocity at ``t0``.

    Returns
    -------
    tuple of float
        ``(Km, tau_m)``, tau_m in s.
    """
    km = w_inf / a
    tau = -t0 / math.log(1.0 - w_t0 / w_inf)
    return km, tau



@guarded("dc-motor", "fopdt")
def dc_motor(t, y, yf, sigma=None) -> MethodResult:
    """DC motor velocity from a step of armature voltage (seed 000 eqs 46-55).

    Km = W(inf)/a is the final value of the normalised response, and
    tau_m = -t0 / ln(1 - w(t0)/W(inf)); the seed uses one point t0, here the
    median over every sample between 20 % and 80 % (robust to noise; on a
    clean first-order response every sample gives the same value). Valid for
    a delay-free first-order lag: the spread of those estimates says whether
    the data are one.

    Parameters
    ----------
    t : array_like
        Times after the step in s.
    y : array_like
        The measured velocity at ``t``.
    yf : float
        Its final value.
    sigma : float, optional
        Noise standard deviation of ``y``; estimated from ``y`` when None.

    Returns
    -------
    MethodResult
        The ``fopdt`` model K/(tau s + 1) without dead time, or an invalid
        result with the reason.
    """
    name, model = "dc-motor", "fopdt"
    t, z, sigma, err = prepare(t, y, yf, sigma)
    if err:
        return fail(name, model, err, yf)
    sel = (z >= 0.2) & (z <= 0.8) & (t > 0.0)
    # only the first rise: a later return into the band (oscillation) is not first order
    if sel.any():
        first_out = np.nonzero((z > 0.8) & (t > 0.0))[0]
        if first_out.size:
            sel[first_out[0]:] = False
    if sel.sum() < 2:
        return fail(name, model, "too few samples between 20 % and 80 % of the final value", yf)
    taus = -t[sel] / np.log(1.0 - z[sel])
    tau = float(np.median(taus))
    q10, q90 = np.percentile(taus, [10, 90])
    spread = float((q90 - q10) / tau)
    t0 = crossing_time(t, z, 1.0 - math.exp(-1.0), sigma=sigma)
    pts = {"t0_s": t0, "w_t0": (1.0 - math.exp(-1.0)) * yf, "tau_spread": spread}
    valid = bool(spread <= 0.1)
    note = ("" if valid else f"tau_m from the 20-80 % samples varies by {spread:.0%}: not a "
            "delay-free first-order lag (the method's model)")
    # (a dead time already shows as the spread: no separate late-start check)
    return MethodResult(name, model, {"K": float(yf), "tau_s": tau, "theta_s": 0.0},
                        valid=valid, note=note, points=pts)


@guarded("dc-motor-position", "fopdt")
def dc_motor_position(t, theta, a: float = 1.0, tail: float = 0.3) -> MethodResult:
    """DC motor from its shaft *position* step response (seed 000 eq 45/57).

    theta(t) = a Km (t - tau_m (1 - e^{-t/tau_m})) tends to the line
    a Km (t - tau_m): a straight-line fit to the last ``tail`` fraction of the
    record gives Km = slope/a and tau_m = -intercept/slope. The result is
    reported as the velocity model W/U = Km/(tau_m s + 1) (``fopdt`` with no
    dead time); the position model is Km/(s (tau_m s + 1)).

    Parameters
    ----------
    t : array_like
        Times after the step in s.
    theta : array_like
        The shaft position at ``t``.
    a : float, optional
        The voltage step's size.
    tail : float, optional
        Fraction of the record (its end) the straight line is fitted to.

    Returns
    -------
    MethodResult
        The velocity model as ``fopdt`` (K = Km, tau_s = tau_m, no dead time),
        or an invalid result with the reason.
    """
    name, model = "dc-motor-position", "fopdt"
    t = np.asarray(t, float)
    th = np.asarray(theta, float) / a
    n = len(t)
    if n < 10 or not (np.all(np.isfinite(t)) and np.all(np.isfinite(th))):
        return fail(name, model, "needs at least 10 finite samples", math.nan)
    k0 = int(n * (1.0 - tail))
    slope, icpt = np.polyfit(t[k0:], th[k0:], 1)
    if slope == 0.0:
        return fail(name, model, "the position does not ramp: not an integrating response", 0.0)
    tau = -icpt / slope
    # the asymptote is reached only if the fitted tail starts several tau_m after the step
    valid = tau > 0.0 and t[k0] >= 5.0 * tau
    note = "velocity model W/U = K/(tau s + 1); position Theta/U = K/(s (tau s + 1))"
    if not valid:
        note = ("the record is too short: the ramp's tail must start 5 tau_m after the step "
                "(or tau_m <= 0: not a motor position response); " + note)
    return MethodResult(name, model, {"K": float(slope), "tau_s": float(tau), "theta_s": 0.0},
                        valid=valid, note=note, points={"tail_from_s": float(t[k0])})

