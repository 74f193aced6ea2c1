"""Time domain of the loop of a plant with exact dead time under a rational
controller: the PID as a transfer function, the closed-loop step response
simulated with the delay as an exact delay line, and the step's figures. The
loop's frequency response, margins and stability are
:mod:`designer.pid.delaymargins`'s (which also parses the loop).

The plant is ``(num, den, theta_s)``: P(s) = Np(s)/Dp(s) e^(-theta s), the
rational part in descending powers of s (a pole at 0 is an integrating plant);
the controller is ``(num, den)``: C(s) = Nc(s)/Dc(s), with any extra factors
(op-amp poles) already multiplied in. No Pade approximation anywhere.

* :func:`pid_tf`: the parallel PID with a filtered derivative,
  C = Kp (1 + 1/(Ti s) + Td s/(Td/N s + 1))
  = Kp [Ti Td (1 + 1/N) s^2 + (Ti + Td/N) s + 1] / [Ti s (Td/N s + 1)].
* :func:`closed_loop_step`: the step response, with the delay moved to the plant
  output (y(t) = y~(t - theta), the same loop: LTI blocks commute), the controller
  and rational plant one state-space model discretised with a first-order hold
  (matrix exponential), and dt = theta/M so that the delay is a whole number
  of steps (the delay line exact; only the hold's O(dt^2) error is left). The
  step dt is set from the loop's gain crossovers and corners
  (:func:`_simulation_step`), and never below the record over
  :data:`STEP_BUDGET` steps (fast modes are integrated exactly: only the delayed
  plant output must be followed, and the plant's lag smooths it).
* :func:`step_figures`: the classical figures (:func:`designer.core.metrics.step_metrics`),
  IAE = integral |r - y| dt and the steady-state error.
"""

from __future__ import annotations

import math
from dataclasses import asdict, dataclass

import numpy as np

from ..core.errors import DesignError
from ..core.jsonio import json_safe
from ..core.metrics import step_metrics
from .delaymargins import LoopParts, loop_band, corner_frequencies, gain_crossovers, log_grid, parse_loop
from .model import LoopModel, balanced_expm, tf_to_ss

__all__ = ["MAX_STEPS", "STEP_BUDGET", "closed_loop_step", "parse_loop", "pid_tf", "step_figures"]

#: derivative filter N to simulate an ideal PID with (an ideal PID is improper,
#: so :func:`closed_loop_step` refuses it): ``pid_tf(kp, ti, td, SIM_N_FILTER)``
SIM_N_FILTER = 10.0
#: time step of the simulation: this fraction of 1/w_ref, w_ref the fastest
#: of the gain crossovers and the plant's and controller's corners within
#: 100 times the crossover (faster modes are integrated exactly)
STEP_FRACTION = 0.02
#: no simulation takes more steps than this
MAX_STEPS = 2_000_000
#: the time step is never below the record's length over this many steps: the
#: matrix exponential integrates the loop's fast modes (op-amp poles, the
#: derivative filter) exactly whatever the step, and the step only has to follow
#: the delayed plant output, which the plant's own lag smooths; so an op-amp pole
#: 100 times the crossover does not need 1e7 steps (issue 25: K=2 tau=20m
#: theta=50u, whose crossover of 2.6e4 rad/s let the LM741's 2.3e6 rad/s zero in)
STEP_BUDGET = 100_000
#: the closed-loop recursion is solved this many steps at a time (at most the delay)
BLOCK_MAX = 256
#: a delay of at most this many steps is simulated as a delay line of states (:func:`_delay_line_states`)
SHORT_DELAY = 32
#: samples evaluated at once from the powers of the augmented state matrix
CHUNK = 4096


def pid_tf(kp: float, ti_s: float, td_s: float, n_filter: float | None = None):
    """Parallel PID Kp (1 + 1/(Ti s) + Td s/(Td/N s + 1)) as (num, den).

    Parameters
    ----------
    kp : float
        Proportional gain.
    ti_s : float
        Integral time (s); ``math.inf`` for no integral action.
    td_s : float
        Derivative time (s); 0 for no derivative action.
    n_filter : float, optional
        Derivative filter N (the derivative's gain at high frequency is Kp N).
        None gives the ideal PID Kp (1 + 1/(Ti s) + Td s), improper when Td > 0:
        fine for :func:`~designer.pid.delaymargins.loop_response` and
        :func:`~designer.pid.delaymargins.loop_margins`, refused by
        :func:`closed_loop_step`, which needs a filter (:data:`SIM_N_FILTER`).

    Returns
    -------
    (num, den) : tuple of ndarray
        Descending powers of s.
    """
    kp, ti, td = float(kp), float(ti_s), float(td_s)
    if not math.isfinite(kp):
        raise DesignError(f"kp must be finite, got {kp}", "kp")
    if not ti > 0:
        raise DesignError(f"ti_s must be > 0 (math.inf for no integral action), got {ti}", "ti_s")
    if not (math.isfinite(td) and td >= 0):
        raise DesignError(f"td_s must be finite and >= 0, got {td}", "td_s")
    if n_filter is not None and not (math.isfinite(n_filter) and n_filter > 0):
        raise DesignError(f"n_filter must be > 0 (or None for the ideal PID), got {n_filter}", "n_filter")
    integral = math.isfinite(ti)
    if td == 0:
        num, den = ([ti, 1.0], [ti, 0.0]) if integral else ([1.0], [1.0])
    elif n_filter is None:
        num, den = ([ti * td, ti, 1.0], [ti, 0.0]) if integral else ([td, 1.0], [1.0])
    else:
        tf = td / n_filter
        if integral:
            num, den = [ti * (td + tf), ti + tf, 1.0], [ti * tf, ti, 0.0]
        else:
            num, den = [td + tf, 1.0], [tf, 1.0]
    return kp * np.array(num), np.array(den)


# --------------------------------------------------------------------------- the closed-loop step


def _series(lp: LoopParts):
    """State space of the controller followed by the plant's rational part,
    input e, outputs y~ = P C e (before the delay) and u = C e:
    (A, B, Cy, Dy, Cu, Du). Block by block, not one companion form of the product
    (whose poles would spread over decades)."""
    if lp.nc.size > lp.dc.size:
        raise DesignError("the controller is improper (an ideal PID): simulate it with a derivative filter, "
                          f"pid_tf(kp, ti, td, n_filter={SIM_N_FILTER:g})", "n_filter")
    if lp.np_.size > lp.dp.size:
        raise DesignError("the plant's rational part is improper (numerator of higher degree)")
    ac, bc, cc, dc = tf_to_ss(lp.nc, lp.dc)
    ap, bp, cp, dp = tf_to_ss(lp.np_, lp.dp)
    nc_, np_ = ac.shape[0], ap.shape[0]
    a = np.zeros((nc_ + np_, nc_ + np_))
    a[:nc_, :nc_] = ac
    a[nc_:, :nc_] = bp @ cc
    a[nc_:, nc_:] = ap
    b = np.vstack([bc, bp * dc.item()]).ravel()
    cy = np.concatenate([(dp.item() * cc).ravel(), cp.ravel()])
    cu = np.concatenate([cc.ravel(), np.zeros(np_)])
    return a, b, cy, dp.item() * dc.item(), cu, dc.item()


def _simulation_step(lp: LoopParts, fraction: float = STEP_FRACTION) -> float:
    """Largest time step (s) for a response accurate to about 1e-4 of the step:
    :data:`STEP_FRACTION`/w_ref (see there; ``fraction`` instead of it: the
    error goes as its square); the delay itself needs no resolution."""
    lo, hi = loop_band(lp)
    wc = gain_crossovers(lp, log_grid(lp, lo, hi))
    c = corner_frequencies(lp)
    rates = np.abs(np.concatenate([lp.zeros, lp.poles]))
    rates = rates[rates > 0]
    base = float(wc.max()) if wc.size else float(c.min())
    cand = np.concatenate([[base], rates[rates <= 100 * base]])
    return fraction / float(cand.max())


def _foh(a, b, dt):
    """x_{k+1} = Phi x_k + G0 e_k + G1 e_{k+1}: exact for an input linear over the step."""
    n = a.shape[0]
    m = np.zeros((n + 2, n + 2))
    m[:n, :n] = a * dt
    m[:n, n] = b * dt
    m[n, n + 1] = 1.0
    em = balanced_expm(m)
    g1, g2 = em[:n, n], em[:n, n + 1]
    return em[:n, :n], g1 - g2, g2


def _delay_line_states(a, b, cy, cu, dt, m_delay, n_steps, r, frac=0.0):
    """The sampled loop of :func:`_delay_loop` for a short delay and no direct path
    (Dy = 0, so e is continuous after t = 0): the last samples of y~ become
    states, z_k = (x_k, y~_(k-1), ..., y~_(k-M), 1), with

        x_(k+1) = Phi x_k + G0 (r - y~_(k-M)) + G1 (r - y~_(k+1-M)),

    one constant matrix F (the constant 1 carries r), so z_k = F^k z_0. The outputs
    C F^j are formed for j < :data:`CHUNK` by doubling (F^m squared), and each
    chunk of samples is those times the chunk's first state: no per-step loop
    however short the delay (a block of :func:`_delay_loop` would be one step).

    A delay shorter than one step (``m_delay`` 0, theta = ``frac`` dt) is read by
    linear interpolation, y~(t_k - theta) = (1 - frac) y~_k + frac y~_(k-1) (an
    error of order dt^2, as the hold's); x_(k+1) is then implicit, solved once:
    (I + (1 - frac) G1 Cy) x_(k+1) = (Phi - (1 - frac) G0 Cy - frac G1 Cy) x_k
    - frac G0 y~_(k-1) + (G0 + G1) r.

    Returns (e(t_k+), C_u x_k) for k < n_steps.
    """
    n, m = a.shape[0], max(m_delay, 1)
    phi, g0, g1 = _foh(a, b, dt)
    nz = n + m + 1
    f = np.zeros((nz, nz))
    out = np.zeros((2, nz))                     # e_k and C_u x_k from z_k
    out[1, :n] = cu
    out[0, -1] = r
    if m_delay == 0:
        g = 1 - frac
        w = np.linalg.inv(np.eye(n) + g * np.outer(g1, cy))
        f[:n, :n] = w @ (phi - g * np.outer(g0, cy) - frac * np.outer(g1, cy))
        f[:n, n] = -frac * (w @ g0)
        f[:n, -1] = (w @ (g0 + g1)) * r
        out[0, :n], out[0, n] = -g * cy, -frac
    else:
        f[:n, :n] = phi
        f[:n, n + m - 1] -= g0
        if m == 1:
            f[:n, :n] -= np.outer(g1, cy)          # y~_(k+1-M) = y~_k = Cy x_k
        else:
            f[:n, n + m - 2] -= g1
        f[:n, -1] = (g0 + g1) * r
        out[0, n + m - 1] = -1.0
    f[n, :n] = cy                               # the delay line shifts y~_k in
    f[n + 1:n + m, n:n + m - 1] = np.eye(m - 1)
    f[-1, -1] = 1.0
    count = min(CHUNK, n_steps)
    obs = out[None]
    p = f
    while obs.shape[0] < count:
        obs = np.concatenate([obs, obs @ p])
        p = p @ p
    obs = obs[:count]                          # (count, 2, nz): out F^j
    step = np.linalg.matrix_power(f, count)
    z = np.zeros(nz)
    z[-1] = 1.0
    res = np.empty((n_steps, 2))
    for k0 in range(0, n_steps, count):
        c = min(count, n_steps - k0)
        res[k0:k0 + c] = obs[:c] @ z
        z = step @ z
    return res[:, 0], res[:, 1]


def _delay_loop(a, b, cy, dy, cu, du, dt, m_delay, n_steps, r):
    """The sampled loop e = r - y~(t - theta), y~ = P C e, theta = m_delay dt, from rest.

    Both one-sided limits of e are kept at every sample (e jumps at 0 and, with a
    direct path through P C, at every multiple of theta): the step from k to k+1
    takes e(t_k+) and e(t_{k+1}-). Over a block of b <= m_delay steps the inputs
    are already known (they are outputs at least theta old), so a block is one
    linear map: states x_{k0+j} = Phi^j x_k0 + sum_i Phi^(j-1-i) (G0 ep_i + G1 em_i+1),
    as matrices precomputed once (no per-step Python loop).

    Returns (e(t_k+), C_u x_k) for k < n_steps.
    """
    n = a.shape[0]
    phi, g0, g1 = _foh(a, b, dt)
    blk = max(1, min(m_delay, BLOCK_MAX))
    pw = np.empty((blk + 1, n, n))
    pw[0] = np.eye(n)
    for j in range(1, blk + 1):
        pw[j] = phi @ pw[j - 1]
    rows = np.stack([cy, cu])                                   # outputs C x for y~ and u
    obs = np.einsum("on,jnk->jok", rows, pw[1:])                # (blk, 2, n): C Phi^j
    mk0 = np.einsum("on,lnk,k->lo", rows, pw[:blk], g0)         # (blk, 2): C Phi^l G0
    mk1 = np.einsum("on,lnk,k->lo", rows, pw[:blk], g1)
    jj, ii = np.meshgrid(np.arange(blk), np.arange(blk), indexing="ij")
    lag = jj - ii                                               # row j (state k0+j+1), column i
    # (blk, 2, blk): output o of state k0+j+1 from input i, lower triangular Toeplitz
    t0 = np.where(lag[:, None, :] >= 0, mk0[np.clip(lag, 0, None)].transpose(0, 2, 1), 0.0)
    t1 = np.where(lag[:, None, :] >= 0, mk1[np.clip(lag, 0, None)].transpose(0, 2, 1), 0.0)
    t01 = np.concatenate([t0, t1], axis=2).reshape(2 * blk, 2 * blk)   # one matrix for (e0, e1)
    r0 = np.einsum("ink,k->ni", pw[blk - 1::-1], g0)            # Phi^(blk-1-i) G0
    r1 = np.einsum("ink,k->ni", pw[blk - 1::-1], g1)
    ep = np.zeros(n_steps)   # e(t_k+)
    em = np.zeros(n_steps)   # e(t_k-); e(0-) = 0, before the step
    cx = np.zeros((n_steps, 2))
    x = np.zeros(n)
    k0 = 0
    while k0 < n_steps - 1:
        b_ = min(blk, n_steps - 1 - k0)
        # inputs of the block from outputs theta old: y~(t_j +-) = Cy x_j + Dy e(t_j +-)
        k = np.arange(k0, k0 + b_ + 1)
        j = k - m_delay
        old = j >= 0
        jo = np.where(old, j, 0)
        ep[k] = r - np.where(old, cx[jo, 0] + dy * ep[jo], 0.0)
        em[k[1:]] = r - np.where(old[1:], cx[jo[1:], 0] + dy * em[jo[1:]], 0.0)
        e0, e1 = ep[k0:k0 + b_], em[k0 + 1:k0 + b_ + 1]
        if b_ == blk:
            forced = (t01 @ np.concatenate([e0, e1])).reshape(blk, 2)
        else:   # the last, shorter block: the leading rows and columns of the same Toeplitz matrices
            forced = t0[:b_, :, :b_] @ e0 + t1[:b_, :, :b_] @ e1
        cx[k0 + 1:k0 + b_ + 1] = obs[:b_] @ x + forced
        if b_ == blk:
            x = pw[blk] @ x + r0 @ e0 + r1 @ e1
        k0 += b_
    return ep, cx[:, 1]


def closed_loop_step(plant, controller, t, r_step: float = 1.0, step_fraction: float = STEP_FRACTION) -> dict:
    """The loop's response to a reference step of ``r_step`` at t = 0, from rest.

    Parameters
    ----------
    plant : (num, den, theta_s)
    controller : (num, den)
        Proper (an ideal PID needs its derivative filter: :data:`SIM_N_FILTER`).
    t : array_like
        Uniform times from 0 (s).
    r_step : float
        The step.
    step_fraction : float
        The time step as a fraction of the loop's fastest relevant time
        (:data:`STEP_FRACTION`, about 1e-4 of the step; the error grows as its
        square: 0.1 is about 2.5e-3, enough for a search).

    Returns
    -------
    dict
        ``y`` (plant output), ``u`` (controller output), ``e`` (r - y), at ``t``;
        at a jump (u and e at t = 0) the value just after it.

    Notes
    -----
    The delay is moved to the plant's output (y(t) = y~(t - theta), the same
    loop), so the signal delayed is the plant's, smooth; controller and plant
    are one state-space model, discretised with a first-order hold (exact for an
    input linear over a step; its error goes as dt^2). Without delay the loop is
    closed algebraically and sampled exactly (the input is constant). With one,
    dt = theta/M, a whole number of steps: the delay line is exact. When theta is
    a whole number of the grid's steps the simulation runs on the grid, each
    step split into substeps to reach :func:`_simulation_step`; otherwise on its
    own grid (dt <= the grid's step), linearly interpolated onto ``t``. A delay
    shorter than one such substep is read between samples by linear
    interpolation instead (a direct path through P C excepted: its jumps
    would be smeared, so dt = theta then). The
    sampled loop is solved a block of steps at a time (:func:`_delay_loop`), or,
    for a delay of a few steps, as one augmented linear system
    (:func:`_delay_line_states`). Against a Heun integration of the delay
    equation at a fine step the response is within about 1e-4 of the step
    (1e-5 typical, :data:`STEP_FRACTION`).
    """
    lp = parse_loop(plant, controller)
    t = np.asarray(t, float)
    if t.ndim != 1 or t.size < 2 or not np.all(np.isfinite(t)):
        raise DesignError("t must be a 1-D array of 2+ finite times")
    h = float(t[1] - t[0])
    if abs(t[0]) > 1e-12 * h or h <= 0 or not np.allclose(np.diff(t), h, rtol=1e-6, atol=0):
        raise DesignError("t must be a uniform grid starting at 0 (the step's instant)")
    r = float(r_step)
    a, b, cy, dy, cu, du = _series(lp)
    if lp.theta == 0:
        if 1 + dy == 0:
            raise DesignError("the loop has an algebraic loop (1 + C P = 0 at high frequency)")
        k = 1 / (1 + dy)
        # e = k (r - Cy x): the loop closed on the state
        acl = a - k * np.outer(b, cy)
        bcl = (k * b)[:, None]
        c = np.stack([k * cy, cu - du * k * cy, -k * cy])
        d = np.array([[k * dy], [du * k], [k]])
        out = LoopModel(acl, bcl, c, d, ("y", "u", "e")).simulate(t, np.full(t.size, r))
        return {"y": out["y"], "u": out["u"], "e": out["e"]}
    if not 0 < step_fraction <= 1:
        raise DesignError(f"step_fraction must be in (0, 1], got {step_fraction}", "step_fraction")
    dt_max = max(_simulation_step(lp, step_fraction), float(t[-1]) / STEP_BUDGET)
    sub = max(1, int(math.ceil(h / dt_max)))          # substeps per step of t
    q = lp.theta / h
    frac = 0.0
    if lp.theta < h / sub and dy == 0:
        # a delay under one step: on the grid, the delay interpolated (no jump to smear)
        on_grid, dt, m_delay, frac = True, h / sub, 0, lp.theta / (h / sub)
    elif round(q) >= 1 and abs(q - round(q)) <= 1e-9 * q:
        on_grid, dt, m_delay = True, h / sub, int(round(q)) * sub
    else:
        on_grid, m_delay = False, int(math.ceil(lp.theta / min(h, dt_max)))
        dt = lp.theta / m_delay
    n_steps = (t.size - 1) * sub + 1 if on_grid else int(math.ceil(t[-1] / dt)) + 1
    if n_steps > MAX_STEPS:
        raise DesignError(f"the closed loop's step response would take {n_steps} simulation steps (over "
                          f"{MAX_STEPS}): a dead time of {lp.theta:.3g} s is too short against a response "
                          f"{t[-1]:.3g} s long to simulate exactly")
    if m_delay <= SHORT_DELAY and dy == 0:
        ep, cux = _delay_line_states(a, b, cy, cu, dt, m_delay, n_steps, r, frac)
    else:
        ep, cux = _delay_loop(a, b, cy, dy, cu, du, dt, m_delay, n_steps, r)
    e = ep
    u = cux + du * ep
    y = r - ep
    if on_grid:
        return {"y": y[::sub].copy(), "u": u[::sub].copy(), "e": e[::sub].copy()}
    ts = np.arange(n_steps) * dt
    return {"y": np.interp(t, ts, y), "u": np.interp(t, ts, u), "e": np.interp(t, ts, e)}


# --------------------------------------------------------------------------- figures


@dataclass(frozen=True)
class StepFigures:
    """Figures of a closed-loop step response (times from the step)."""

    overshoot_pct: float       #: over the final value, % of the change
    peak_time_s: float         #: nan for a monotone response
    rise_time_s: float         #: 10 % to 90 %
    settling_time_s: float     #: 2 % band about the final value
    iae: float                 #: integral of |r - y| dt (V s for a step in V)
    steady_state_error: float  #: r - y at the end of the record
    final_value: float

    def to_dict(self) -> dict:
        return json_safe(asdict(self))


def step_figures(t, y, r_step: float = 1.0) -> StepFigures:
    """Overshoot, peak time, rise time (10-90 %) and 2 % settling time from
    :func:`designer.core.metrics.step_metrics` (from rest, the final value the last
    sample), IAE = integral |r - y| dt (trapezoids) and the steady-state error
    r - y(end). A record that has not settled reads a settling time near its end.

    Parameters
    ----------
    t : array_like
        Times from the step (s).
    y : array_like
        The output.
    r_step : float
        The reference step.

    Returns
    -------
    StepFigures
    """
    t = np.asarray(t, float)
    y = np.asarray(y, float)
    m = step_metrics(t, y, initial=0.0)
    iae = float(np.trapezoid(np.abs(r_step - y), t))
    return StepFigures(m.overshoot_pct, m.peak_time_s, m.rise_time_s, m.settling_time_s, iae,
                       float(r_step - y[-1]), m.final_value)
