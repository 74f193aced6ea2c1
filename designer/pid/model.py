"""Analytic closed loop of the op-amp PID controller and its plant.

Each op-amp stage is an inverting amplifier with feedback impedance Zf and
input admittances Y_k; with the single-pole op-amp A(s) = A0/(1 + s/wp) its
output is

    v_out = -Zf sum(Y_k v_k) / (1 + NG(s)/A(s)),   NG = 1 + Zf sum(Y_k)

(the difference amplifier likewise, with NG = 1 + R16/R15). So the realised
controller has a leaky integrator (corner 1/(2 pi R13 C4)), a filtered
derivative (corner 1/(2 pi R12 C3)) and one extra pole per stage near
GBW/NG. The blocks are assembled into one state-space model whose outputs
are every op-amp's output, so the same simulation gives the plant output and
the levels and slew rates each op-amp must deliver. An ideal op-amp
(catalogue ``ideal``) is taken as infinite gain, not as a very fast pole.

All transfer functions are (num, den) in descending powers of s (seconds).
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

from ..core.errors import DesignError
from ..core.opamps import OpAmp
from .blocks import PidParts
from .sensitivity import sensitivity_peak

__all__ = ["SLEW_DELAY_FRACTION", "assemble", "controller_tf", "dc_gain", "ideal_loop", "inverting_stage",
           "loop_gain", "margins", "reference", "slew_delay", "waveform_limits"]

SIGNALS = ("ve", "vp", "vd", "vi", "vs", "u", "y")
#: op-amp designator, role and output signal, in signal order; U1 is the plant's Sallen-Key
#: op-amp, as on the plant's own sheet (one designator scheme: :mod:`designer.pid.netlist`)
OPAMP_OUTPUTS = (("U2", "difference", "ve"), ("U3", "inverter", "vp"),
                 ("U4", "differentiator", "vd"), ("U5", "integrator", "vi"),
                 ("U6", "summer", "vs"), ("U7", "gain", "u"), ("U1", "plant", "y"))


def _opamp_inv(opamp: OpAmp | None):
    """1/A(s) as (num, den), or None for an ideal op-amp."""
    if opamp is None or opamp.ideal:
        return None
    tau = opamp.a0 / (2 * math.pi * opamp.gbw_hz)
    return np.array([tau, 1.0]) / opamp.a0, np.array([1.0])


def inverting_stage(p, q, g, opamp):
    """Transfer function -(p/q) / (1 + (g/q)/A) of an inverting stage whose
    ideal gain is -p/q and whose noise gain is g/q (same denominator).

    Parameters
    ----------
    p, q, g : array_like
        Numerator, common denominator and noise-gain numerator (descending powers of s).
    opamp : OpAmp or None
        The stage's op-amp (None: ideal).

    Returns
    -------
    tuple
        (num, den), descending powers of s.
    """
    p, q, g = (np.atleast_1d(np.asarray(x, float)) for x in (p, q, g))
    inv = _opamp_inv(opamp)
    if inv is None:
        return -p, q
    ia_n, _ = inv
    den = np.polyadd(q, np.polymul(g, ia_n))
    return -p, den


def stage_tfs(parts: PidParts, opamp: OpAmp | None) -> dict:
    """Transfer function of every controller stage from its input node.

    Keys: ``ve`` (difference amp, applied to the weighted sum g_y y - g_r r;
    see :func:`difference_weights`), ``vp``, ``vd``, ``vi`` (from ve), ``vs``
    (applied to the weighted sum of vp, vd, vi; see :func:`summer_weights`),
    ``u`` (from vs). The summer and difference entries are the closed-loop
    factor 1/(1 + NG/A) with sign, the weights carry the resistor ratios.
    """
    pr = parts
    out = {}
    ng_diff = 1 + pr.r16 / pr.r15
    # difference: v = (g_y y - g_r r) * 1/(1 + NG/A) -> a stage with p = -1, q = 1
    out["ve"] = inverting_stage([-1.0], [1.0], [ng_diff], opamp)
    out["vp"] = inverting_stage([pr.r9 / pr.r10], [1.0], [1 + pr.r9 / pr.r10], opamp)
    if pr.has_derivative:
        t12, t11 = pr.r12 * pr.c3, pr.r11 * pr.c3
        out["vd"] = inverting_stage([t11, 0.0], [t12, 1.0], [t12 + t11, 1.0], opamp)
    t13 = pr.r13 * pr.c4
    k = pr.r13 / pr.r14
    out["vi"] = inverting_stage([k], [t13, 1.0], [t13, 1.0 + k], opamp)
    ysum = 1 / pr.r6 + 1 / pr.r8 + (1 / pr.r7 if pr.has_derivative else 0.0)
    out["vs"] = inverting_stage([-1.0], [1.0], [1 + pr.r5 * ysum], opamp)  # weights carry -R5/Rk
    out["u"] = inverting_stage([pr.r3 / pr.r4], [1.0], [1 + pr.r3 / pr.r4], opamp)
    return out


def difference_weights(parts: PidParts):
    """(g_y, g_r): the difference amplifier's ideal output is g_y y - g_r r."""
    g_r = parts.r16 / parts.r15
    g_y = (1 + g_r) * parts.r18 / (parts.r17 + parts.r18)
    return g_y, g_r


def summer_weights(parts: PidParts) -> dict:
    """The summer's ideal output is -R5 (vp/R6 + vd/R7 + vi/R8)."""
    w = {"vp": -parts.r5 / parts.r6, "vi": -parts.r5 / parts.r8}
    if parts.has_derivative:
        w["vd"] = -parts.r5 / parts.r7
    return w


def controller_tf(parts: PidParts, opamp: OpAmp | None):
    """The realised controller u/(r - y) as (num, den): difference amplifier,
    the three paths (leaky integrator, filtered derivative), summer and final
    gain, each with its op-amp's finite gain-bandwidth. (The difference
    amplifier's two weights are taken equal, as with R15 = R16 = R17 = R18.)

    Parameters
    ----------
    parts : PidParts
        The controller's parts.
    opamp : OpAmp or None
        The op-amp of every stage (None: ideal op-amps).

    Returns
    -------
    tuple
        (num, den), descending powers of s.
    """
    tfs = stage_tfs(parts, opamp)
    sw = summer_weights(parts)
    num, den = np.array([0.0]), np.array([1.0])
    for sig in ("vp", "vd", "vi"):
        if sig not in tfs:
            continue
        n, d = tfs[sig]
        num = np.polyadd(np.polymul(num, d), np.polymul(n * sw[sig], den))
        den = np.polymul(den, d)
    for sig in ("vs", "u", "ve"):
        n, d = tfs[sig]
        num, den = np.polymul(num, n), np.polymul(den, d)
    g_y, g_r = difference_weights(parts)
    # ve = F (g_y y - g_r r) = -F g_r (r - y) when g_y = g_r
    return trim_leading(-g_r * num), trim_leading(den)


@dataclass
class LoopModel:
    """State-space model of the whole loop: input r, outputs :data:`SIGNALS`."""

    a: np.ndarray
    b: np.ndarray
    c: np.ndarray
    d: np.ndarray
    outputs: tuple

    def poles(self) -> np.ndarray:
        return np.linalg.eigvals(self.a) if self.a.size else np.array([])

    def stable(self) -> bool:
        p = self.poles()
        return bool(np.all(p.real < 0)) if p.size else True

    def propagator(self, dt: float) -> np.ndarray:
        """The first-order-hold discretisation over ``dt``: expm of [[A dt, B dt, 0], [0, 0, 1], [0, 0, 0]]
        (exact for a piecewise-linear reference)."""
        n = self.a.shape[0]
        m = np.zeros((n + 2, n + 2))
        m[:n, :n] = self.a * dt
        m[:n, n:n + 1] = self.b * dt
        m[n, n + 1] = 1.0
        return balanced_expm(m)

    def simulate_with_kick(self, t, r, t_fine, r_fine) -> tuple:
        """(:meth:`simulate` on ``t``, on ``t_fine``) with one matrix exponential: the fine grid's step is
        the coarse one's / 2^j, and the coarse propagator is the fine one to the 2^j (j squarings) with
        the ramp's increment rescaled by 2^j: expm(M_c) = D expm(M_f)^(2^j) D^-1, D = diag(1.., 1, 2^j)."""
        ratio = (t[1] - t[0]) / (t_fine[1] - t_fine[0])
        j = int(round(math.log2(ratio)))
        if j < 0 or abs(ratio - 2 ** j) > 1e-6 * ratio:
            raise ValueError("the fine grid's step must be the coarse one's over a power of two")
        fine = self.propagator(t_fine[1] - t_fine[0])
        em = fine
        for _ in range(j):
            em = em @ em
        em = em.copy()
        em[:, -1] *= 2.0 ** -j
        em[-1, :] *= 2.0 ** j
        return self.simulate(t, r, em), self.simulate(t_fine, r_fine, fine)

    def simulate(self, t, r, em=None) -> dict:
        """Outputs for the reference samples ``r`` at uniform times ``t`` (from rest); ``em``: the
        step's :meth:`propagator`, when known."""
        t = np.asarray(t, float)
        r = np.asarray(r, float)
        n = self.a.shape[0]
        if em is None:
            em = self.propagator(t[1] - t[0])
        phi, g1, g2 = em[:n, :n], em[:n, n:n + 1], em[:n, n + 1:n + 2]
        bd0 = (g1 - g2).ravel()
        bd1 = g2.ravel()
        x = np.zeros((t.size, n))
        xk = np.zeros(n)
        # step through the samples while the reference moves; once it is
        # constant the response is a sum of modes, evaluated all at once
        moving = np.nonzero(np.diff(r) != 0)[0]
        k0 = int(moving[-1]) + 1 if moving.size else 0
        for k in range(1, k0 + 1):
            xk = phi @ xk + bd0 * r[k - 1] + bd1 * r[k]
            x[k] = xk
        if k0 < t.size - 1 and n:
            x[k0:] = _constant_tail(phi, bd0 + bd1, xk, r[k0], t.size - k0)
        y = x @ self.c.T + np.outer(r, self.d.ravel())
        return {name: y[:, i] for i, name in enumerate(self.outputs)}



def _constant_tail(phi, bsum, x0, rc, count):
    """States x_k = phi^k (x0 - xss) + xss, k = 0..count-1, for a constant
    input, by doubling: the block of k in [m, 2m) is phi^m times the block of
    [0, m), so about log2(count) matrix products instead of a Python loop."""
    n = phi.shape[0]
    try:
        xss = np.linalg.solve(np.eye(n) - phi, bsum * rc)
    except np.linalg.LinAlgError:
        xss = None
    if xss is None or not np.all(np.isfinite(xss)):
        out = np.empty((count, n))
        xk = x0
        for k in range(count):
            out[k] = xk
            xk = phi @ xk + bsum * rc
        return out
    blk = (x0 - xss)[:, None]
    p = phi.copy()
    while blk.shape[1] < count:
        blk = np.concatenate([blk, p @ blk], axis=1)
        p = p @ p
    return blk[:, :count].T + xss


def balanced_expm(m):
    """expm with diagonal balancing first: companion-form blocks with poles
    from 1e2 to 1e7 rad/s make badly scaled matrices that expm squares many
    times (slow and less accurate)."""
    from scipy.linalg import expm, matrix_balance
    # scipy casts the balancing's scale factors to int for the permutation it also
    # returns (unused here: permute=False); a factor of 2^63 or more overflows that
    # cast and numpy warns "invalid value encountered in cast", though the scale
    # factors themselves are right (a loop with op-amp poles 1e5 times the plant's)
    with np.errstate(invalid="ignore"):
        b, tr = matrix_balance(m, permute=False, separate=True)
    scale = tr[0]
    return (expm(b) * scale[:, None]) / scale[None, :]


def tf_to_ss(num, den):
    """(A, B, C, D) of num/den in controller canonical form, as ``scipy.signal.tf2ss``
    gives it (same arithmetic, so the same numbers), without importing scipy.signal."""
    num = np.atleast_1d(np.asarray(num, float))
    den = np.atleast_1d(np.asarray(den, float))
    num, den = trim_leading(num), trim_leading(den)
    if np.all(num == 0) or den.size == 1:   # a static gain has no states
        k = 0.0 if np.all(num == 0) else num[-1] / den[0]
        return np.zeros((0, 0)), np.zeros((0, 1)), np.zeros((1, 0)), np.full((1, 1), k)
    num, den = num / den[0], den / den[0]
    lead = np.flatnonzero(np.abs(num) > 1e-14)
    num = num[lead[0] if lead.size else num.size - 1:]   # tf2ss drops negligible leading terms too
    if num.size > den.size:
        raise DesignError("improper transfer function (numerator of higher degree than the denominator)")
    num = np.concatenate([np.zeros(den.size - num.size), num])
    n = den.size - 1
    a = np.vstack([-den[None, 1:], np.eye(n - 1, n)])
    b = np.eye(n, 1)
    c = num[None, 1:] - np.outer(num[:1], den[1:])
    return a, b, c, np.array([[num[0]]])


def state_space(num, den, output: str = "y") -> LoopModel:
    """One transfer function as a :class:`LoopModel` with one output (for
    responses to the edged reference, which a closed-form step does not give)."""
    return LoopModel(*tf_to_ss(num, den), (output,))


def assemble(parts: PidParts, opamp: OpAmp | None, plant_num, plant_den) -> LoopModel:
    """The closed loop as one state-space model.

    Each block is y_k = H_k(s) (sum of weighted signals); the signal vector
    z = (ve, vp, vd, vi, vs, u, y) satisfies z = C x + Dz z + Dr r, solved once.

    Parameters
    ----------
    parts : PidParts
        The controller's parts.
    opamp : OpAmp or None
        The op-amp of every stage (None: ideal op-amps).
    plant_num, plant_den : array_like
        The plant's transfer function (descending powers of s).

    Returns
    -------
    LoopModel
    """
    tfs = stage_tfs(parts, opamp)
    g_y, g_r = difference_weights(parts)
    sw = summer_weights(parts)
    names = list(SIGNALS)
    idx = {n: i for i, n in enumerate(names)}
    # block: output signal -> (tf, {input signal or 'r': weight})
    blocks = {"ve": (tfs["ve"], {"y": g_y, "r": -g_r}),
              "vp": (tfs["vp"], {"ve": 1.0}),
              "vi": (tfs["vi"], {"ve": 1.0}),
              "vs": (tfs["vs"], {k: v for k, v in sw.items()}),
              "u": (tfs["u"], {"vs": 1.0}),
              "y": ((plant_num, plant_den), {"u": 1.0})}
    if parts.has_derivative:
        blocks["vd"] = (tfs["vd"], {"ve": 1.0})
    nz = len(names)
    mats = []
    nx = 0
    for name in names:
        if name not in blocks:
            mats.append((name, *tf_to_ss([0.0], [1.0]), {}))
            continue
        (num, den), ins = blocks[name]
        a, b, c, d = tf_to_ss(num, den)
        mats.append((name, a, b, c, d, ins))
        nx += a.shape[0]
    A = np.zeros((nx, nx))
    Bz = np.zeros((nx, nz))
    Br = np.zeros((nx, 1))
    C = np.zeros((nz, nx))
    Dz = np.zeros((nz, nz))
    Dr = np.zeros((nz, 1))
    o = 0
    for name, a, b, c, d, ins in mats:
        k = a.shape[0]
        i = idx[name]
        A[o:o + k, o:o + k] = a
        C[i, o:o + k] = c.ravel()
        for src, w in ins.items():
            if src == "r":
                Br[o:o + k, 0] += b.ravel() * w
                Dr[i, 0] += d.item() * w
            else:
                Bz[o:o + k, idx[src]] += b.ravel() * w
                Dz[i, idx[src]] += d.item() * w
        o += k
    try:
        M = np.linalg.inv(np.eye(nz) - Dz)
    except np.linalg.LinAlgError:  # pragma: no cover - needs a plant with direct feedthrough
        raise DesignError("the loop has an algebraic loop (no dynamics around it)") from None
    Acl = A + Bz @ M @ C
    Bcl = Br + Bz @ M @ Dr
    return LoopModel(Acl, Bcl, M @ C, M @ Dr, tuple(names))


def loop_gain(parts: PidParts, opamp: OpAmp | None, plant_num, plant_den, w) -> np.ndarray:
    """Loop gain L(jw), signed so that the loop is the usual 1 + L(s) = 0
    negative-feedback loop (the three inversions are accounted for).

    Parameters
    ----------
    parts : PidParts
        The controller's parts.
    opamp : OpAmp or None
        The op-amp of every stage (None: ideal op-amps).
    plant_num, plant_den : array_like
        The plant's transfer function (descending powers of s).
    w : array_like
        Angular frequencies (rad/s).

    Returns
    -------
    numpy.ndarray
        Complex L(jw).
    """
    s = 1j * np.asarray(w, float)
    tfs = stage_tfs(parts, opamp)
    ev = lambda tf: np.polyval(tf[0], s) / np.polyval(tf[1], s)  # noqa: E731
    g_y, _ = difference_weights(parts)
    sw = summer_weights(parts)
    paths = sw["vp"] * ev(tfs["vp"]) + sw["vi"] * ev(tfs["vi"])
    if parts.has_derivative:
        paths = paths + sw["vd"] * ev(tfs["vd"])
    chain = ev(tfs["ve"]) * g_y * paths * ev(tfs["vs"]) * ev(tfs["u"]) * ev((plant_num, plant_den))
    return -chain


@dataclass(frozen=True)
class Margins:
    """Stability margins of the loop gain (inf where there is no crossing, nan for its frequency)."""

    phase_margin_deg: float
    crossover_hz: float
    gain_margin_db: float
    phase_crossover_hz: float
    ms: float = math.nan          #: the sensitivity peak max |1/(1 + L(jw))| (:mod:`designer.pid.sensitivity`)
    ms_hz: float = math.nan       #: where it peaks

    def to_dict(self) -> dict:
        # Ms stays out of the result's JSON: design-pid's reports/ references keep their bytes (the web page
        # takes Ms from its own part of the answer, designer.web.jobs.pid_page)
        return {"phase_margin_deg": self.phase_margin_deg, "crossover_hz": self.crossover_hz,
                "gain_margin_db": self.gain_margin_db, "phase_crossover_hz": self.phase_crossover_hz}


def margins(w, L, loop=None) -> Margins:
    """Phase margin (deg) at every gain crossover (the smallest is reported),
    gain margin (dB) at the first -180 deg crossing, from samples of L(jw); the
    sensitivity peak Ms (:func:`designer.pid.sensitivity.sensitivity_peak`).

    Parameters
    ----------
    w : array_like
        Angular frequencies (rad/s), ascending.
    L : array_like
        The loop gain at ``w``.
    loop : callable, optional
        ``loop(w)`` -> L(jw): the loop's transfer function, which refines Ms
        between the grid's points (without it, the grid's largest 1/|1 + L|).

    Returns
    -------
    Margins
    """
    w = np.asarray(w, float)
    mag = np.abs(L)
    ph = np.unwrap(np.angle(L))
    pm, wc = math.inf, math.nan
    above = mag >= 1.0
    for i in np.nonzero(above[:-1] != above[1:])[0]:
        f = (0 - math.log(mag[i])) / (math.log(mag[i + 1]) - math.log(mag[i]))
        phase = ph[i] + f * (ph[i + 1] - ph[i])
        m = (math.degrees(phase) + 180.0) % 360.0
        m = m - 360.0 if m > 180.0 else m
        if m < pm:
            pm, wc = m, w[i] + f * (w[i + 1] - w[i])
    gm, w180 = math.inf, math.nan
    wrapped = (np.degrees(ph) + 360.0) % 360.0 - 180.0   # 0 at -180 deg (mod 360)
    for i in np.nonzero(np.sign(wrapped[:-1]) != np.sign(wrapped[1:]))[0]:
        if abs(wrapped[i] - wrapped[i + 1]) > 180:  # wrap jump, not a crossing
            continue
        f = wrapped[i] / (wrapped[i] - wrapped[i + 1])
        mg = math.exp(math.log(mag[i]) + f * (math.log(mag[i + 1]) - math.log(mag[i])))
        if mg > 0:
            gm, w180 = -20 * math.log10(mg), w[i] + f * (w[i + 1] - w[i])
            break
    ms, w_ms = sensitivity_peak(w, L, loop)
    return Margins(pm, wc / (2 * math.pi) if math.isfinite(wc) else math.nan,
                   gm, w180 / (2 * math.pi) if math.isfinite(w180) else math.nan, ms, w_ms / (2 * math.pi))


def ideal_pid_tf(kp: float, ti: float, td: float):
    """Ideal parallel PID Kp (1 + 1/(Ti s) + Td s) as (num, den) (improper when Td > 0)."""
    return kp * np.array([ti * td, ti, 1.0]), np.array([ti, 0.0])


def ideal_closed_loop(kp, ti, td, plant_num, plant_den):
    """y/r of the ideal PID with the plant: PC/(1 + PC) (proper for a 2nd-order plant)."""
    cn, cd = ideal_pid_tf(kp, ti, td)
    n = np.polymul(cn, plant_num)
    d = np.polyadd(np.polymul(cd, plant_den), n)
    return trim_leading(n), trim_leading(d)


def trim_leading(p):
    p = np.atleast_1d(np.asarray(p, float))
    nz = np.nonzero(np.abs(p) > 1e-300)[0]
    return p[nz[0]:] if nz.size else np.array([0.0])


def reference(t, step: float, t0: float, edge: float) -> np.ndarray:
    """A step of ``step`` volts starting at ``t0`` with a linear edge of ``edge`` seconds.

    Parameters
    ----------
    t : array_like
        Times (s).
    step : float
        Height (V).
    t0 : float
        Start (s).
    edge : float
        Rise time of the edge (s; 0: a jump).

    Returns
    -------
    numpy.ndarray
    """
    t = np.asarray(t, float)
    if edge <= 0:
        return np.where(t >= t0, step, 0.0)
    return step * np.clip((t - t0) / edge, 0.0, 1.0)


def ideal_loop(kp, ti, td, plant_num, plant_den) -> LoopModel:
    """The ideal-PID loop y/r as a :class:`LoopModel` (output ``y``).

    Parameters
    ----------
    kp : float
        Proportional gain.
    ti : float
        Integral time (s).
    td : float
        Derivative time (s; 0 for a PI).
    plant_num, plant_den : array_like
        The plant's transfer function (descending powers of s).

    Returns
    -------
    LoopModel
    """
    n, d = ideal_closed_loop(kp, ti, td, plant_num, plant_den)
    if len(n) >= len(d):
        raise DesignError("ideal closed loop is improper (plant of order < 2 with Td > 0)")
    return state_space(n, d)


#: slewing may delay a stage by at most this fraction of the closed-loop rise time
SLEW_DELAY_FRACTION = 0.05


def slew_delay(t, v, slew_v_per_s: float) -> float:
    """Extra time a slew-limited op-amp needs to follow the linear waveform
    ``v``: the part of its excursions faster than the slew rate, divided by
    the slew rate, sum(max(0, |dv| - SR dt)) / SR (0 when it never slews).

    Parameters
    ----------
    t : array_like
        Times (s).
    v : array_like
        The linear waveform (V).
    slew_v_per_s : float
        The op-amp's slew rate.

    Returns
    -------
    float
        The delay (s).
    """
    dv = np.abs(np.diff(np.asarray(v, float)))
    dt = np.diff(np.asarray(t, float))
    return float(np.sum(np.maximum(0.0, dv - slew_v_per_s * dt)) / slew_v_per_s)


@dataclass(frozen=True)
class StageLevels:
    """What one op-amp output does in the analytic loop over the square wave's period."""

    opamp: str
    signal: str
    v_max: float
    v_min: float
    slope_v_per_s: float   #: fastest slope of the linear waveform
    slew_delay_s: float    #: extra time slewing costs (:func:`slew_delay`)
    swing_ok: bool
    slew_ok: bool

    def to_dict(self) -> dict:
        return {"opamp": self.opamp, "signal": self.signal, "v_max": self.v_max, "v_min": self.v_min,
                "slope_v_per_s": self.slope_v_per_s, "slew_delay_s": self.slew_delay_s,
                "swing_ok": self.swing_ok, "slew_ok": self.slew_ok}


def waveform_limits(wave: dict, t, opamp: OpAmp, delay_budget_s: float) -> dict:
    """Per op-amp role, a :class:`StageLevels`: peak output, peak slope and slew delay of the linear
    waveforms, and whether they stay within the op-amp's swing and slew
    rate (slewing is accepted while it delays the stage by less than
    ``delay_budget_s``). ``wave`` is the rising half of the square wave, from
    rest; the extremes cover the falling half too.

    Parameters
    ----------
    wave : dict
        Signal name -> waveform (V) on ``t``.
    t : array_like
        Times (s).
    opamp : OpAmp
        The op-amp of every stage.
    delay_budget_s : float
        The slew delay a stage may have.

    Returns
    -------
    dict
        Role -> :class:`StageLevels`.
    """
    t = np.asarray(t, float)
    out = {}
    for ref, role, sig in OPAMP_OUTPUTS:
        if sig not in wave:
            continue
        v = np.asarray(wave[sig], float)
        slope = float(np.max(np.abs(np.diff(v)) / np.diff(t))) if v.size > 1 else 0.0
        # the falling edge of the square wave mirrors the rising one about the
        # settled level (linear superposition), so the period's extremes are:
        vf = float(v[-1])
        vmax = max(float(v.max()), vf - float(v.min()))
        vmin = min(float(v.min()), vf - float(v.max()))
        delay = 0.0 if opamp.ideal else slew_delay(t, v, opamp.slew_v_per_s)
        out[role] = StageLevels(ref, sig, vmax, vmin, slope, delay,
                                bool(opamp.ideal or (vmax <= opamp.vout_max and vmin >= opamp.vout_min)),
                                bool(opamp.ideal or delay <= delay_budget_s))
    return out


@dataclass(frozen=True)
class DiffAmpBalance:
    """The difference amplifier as built, when its two weights differ (trimmed
    resistors, seed 001 V.13): U2's output is g_y y - g_r r, so the loop gain is
    scaled by g_y and the loop settles where g_y y = g_r r (an integrator that
    holds the error at zero), y = (g_r/g_y) r. ``swapped`` is the same loop with
    R17 and R18 exchanged (the divider's two resistors the other way round,
    which the seed's text does not fix): its weights, margins, stability and
    final ratio, from the same model."""

    g_y: float
    g_r: float
    loop_gain_db: float          #: 20 log10 g_y: the loop gain's change against a balanced amplifier
    final_ratio: float           #: y/r at DC of the loop as built (the analytic DC gain)
    swapped: dict                #: g_y, g_r, loop_gain_db, phase_margin_deg, crossover_hz, gain_margin_db,
    #: stable, final_ratio

    @property
    def attenuated(self) -> str:
        """Which input the amplifier weighs less: ``reference`` or ``feedback``."""
        return "reference" if self.g_r < self.g_y else "feedback"

    def to_dict(self) -> dict:
        return {"g_y": self.g_y, "g_r": self.g_r, "loop_gain_db": self.loop_gain_db,
                "final_ratio": self.final_ratio, "attenuated": self.attenuated, "swapped": self.swapped}


def dc_gain(lm: LoopModel, output: str = "y") -> float:
    """The closed loop's DC gain from r to ``output`` (nan when singular).

    Parameters
    ----------
    lm : LoopModel
        The closed loop.
    output : str
        One of its signals (:data:`SIGNALS`).

    Returns
    -------
    float
    """
    i = lm.outputs.index(output)
    try:
        return float(-(lm.c[i] @ np.linalg.solve(lm.a, lm.b)).item() + lm.d[i, 0])
    except np.linalg.LinAlgError:
        return math.nan


def diff_amp_balance(parts: PidParts, opamp: OpAmp, plant_num, plant_den, w, dc: float):
    """A :class:`DiffAmpBalance` when the difference amplifier's weights differ by
    more than 0.1 %, else None; ``dc`` is the loop's DC gain y/r as built, ``w`` the
    frequencies (rad/s) the margins are read on."""
    from dataclasses import replace as _replace
    g_y, g_r = difference_weights(parts)
    if abs(g_y / g_r - 1) <= 1e-3:
        return None
    other = _replace(parts, r17=parts.r18, r18=parts.r17)
    oy, orr = difference_weights(other)
    m = margins(w, loop_gain(other, opamp, plant_num, plant_den, w))
    lm = assemble(other, opamp, plant_num, plant_den)
    swapped = {"g_y": oy, "g_r": orr, "loop_gain_db": 20 * math.log10(oy), "phase_margin_deg": m.phase_margin_deg,
               "crossover_hz": m.crossover_hz, "gain_margin_db": m.gain_margin_db, "stable": lm.stable(),
               "final_ratio": dc_gain(lm)}
    return DiffAmpBalance(g_y, g_r, 20 * math.log10(g_y), dc, swapped)
