"""Frequency domain of any rational plant with dead time under a rational
controller: the loop gain with the exact delay, its continuous phase, margins,
sensitivity peak and closed-loop stability. The closed-loop step response in
time, and the PID as a transfer function, are :mod:`designer.pid.delayloop`'s.

The plant is ``(num, den, theta_s)``: P(s) = Np(s)/Dp(s) e^(-theta s), the
rational part in descending powers of s (a pole at 0 is an integrating plant);
the controller is ``(num, den)``: C(s) = Nc(s)/Dc(s), with any extra factors
(op-amp poles) already multiplied in (:func:`parse_loop` reads both once, into
:class:`LoopParts`). No Pade approximation anywhere.

* :func:`loop_response`: L(jw) = C(jw) Np(jw)/Dp(jw) e^(-j w theta).
* :func:`loop_phase`: the continuous (unwrapped) phase
  arg L(jw) = arg K0 - m pi/2 + sum_z arg(jw - z) - sum_p arg(jw - p) - w theta,
  each root's angle on a branch continuous in w (m: poles minus zeros at 0, K0
  the low-frequency gain of s^m L), so the delay's phase never wraps.
* :func:`frequency_band`: the default band searched, two decades either side of
  the loop's corners, widened until every gain crossover is inside.
* :func:`loop_margins`: gain crossovers |L| = 1 (PM = 180 + arg L, the smallest
  reported), phase crossovers arg L = -180 - 360 k (GM = -20 log10 |L|), the delay
  margin PM/wc (the extra dead time the loop tolerates), Ms = max |1/(1 + L)|
  (:func:`designer.pid.sensitivity.sensitivity_peak`);
  crossings found on a dense grid, refined with brentq (:class:`DelayLoopMargins`).
* :func:`closed_loop_rhp_roots`: closed-loop roots with Re s > 0 by the argument
  principle on the characteristic quasi-polynomial
  Delta(s) = Dc Dp + Nc Np e^(-theta s) (entire, so no indentation at integrators):
  pi Z = sum_p arg(j wb - p) + arg(1 + L(j wb)) - [arg Delta(j wb) - arg Delta(0)],
  with wb above the last gain crossover (|L| < 1 beyond it and on the right
  half-plane arc: :func:`_magnitude_bound`).

Frequencies are rad/s on input (``w``, ``w_min``, ``w_max``) and Hz in results.
"""

from __future__ import annotations

import math
from dataclasses import asdict, dataclass

import numpy as np

from ..core.errors import DesignError
from ..core.jsonio import json_safe
from .model import trim_leading
from .sensitivity import sensitivity_peak

__all__ = ["loop_margins", "loop_response"]

#: log-grid density (points per decade) of the crossing search
POINTS_PER_DECADE = 200
#: the delay turns the phase by at most this much between neighbouring grid points (rad)
PHASE_STEP = math.pi / 8
#: phase crossovers and the delay's dense grid are kept to where |L| >= this
#: (a gain margin under 80 dB): beyond, the delay's phase turns ever faster
#: and the crossings no longer matter
LOOP_FLOOR = 1e-4
#: at most this many phase crossovers are reported, the lowest (with a delay they never end)
MAX_PHASE_CROSSOVERS = 10
#: most points of the dense grid
MAX_GRID = 2_000_000
#: a dead time counts as a corner only within this factor above the loop's fastest other corner (:func:`corner_frequencies`)
DELAY_CORNER_SPAN = 1e8


@dataclass(frozen=True)
class LoopParts:
    """The loop C(s) P(s) e^(-theta s), its roots and low-frequency asymptote, parsed once."""

    nc: np.ndarray
    dc: np.ndarray
    np_: np.ndarray
    dp: np.ndarray
    theta: float
    zeros: np.ndarray     #: of Nc Np
    poles: np.ndarray     #: of Dc Dp
    lead: float           #: ratio of the leading coefficients (L ~ lead s^(nz - np) at high frequency)
    k0: float             #: low-frequency gain of s^m L
    m: int                #: poles minus zeros at s = 0

    @property
    def degree_gap(self) -> int:
        """deg(Dc Dp) - deg(Nc Np): > 0 strictly proper, 0 biproper, < 0 improper."""
        return self.poles.size - self.zeros.size


def _poly(p, what):
    p = trim_leading(np.asarray(p, float))
    if not np.all(np.isfinite(p)):
        raise DesignError(f"{what} has non-finite coefficients")
    return p


def parse_loop(plant, controller) -> LoopParts:
    """:class:`LoopParts` of ``plant = (num, den, theta_s)`` and ``controller = (num, den)``."""
    try:
        pn, pd, theta = plant
        cn, cd = controller
    except (TypeError, ValueError):
        raise DesignError("plant must be (num, den, theta_s) and controller (num, den)") from None
    pn, pd, cn, cd = (_poly(p, w) for p, w in ((pn, "plant numerator"), (pd, "plant denominator"),
                                               (cn, "controller numerator"), (cd, "controller denominator")))
    theta = float(theta)
    if not (math.isfinite(theta) and theta >= 0):
        raise DesignError(f"theta_s must be finite and >= 0, got {theta}", "theta_s")
    for p, what in ((pd, "plant denominator"), (cd, "controller denominator"),
                    (pn, "plant numerator"), (cn, "controller numerator")):
        if np.all(p == 0):
            raise DesignError(f"{what} is zero")
    num, den = np.polymul(cn, pn), np.polymul(cd, pd)
    # trailing zero coefficients are roots at s = 0 (np.roots returns them exactly)
    zn = len(num) - len(np.trim_zeros(num, "b"))
    zd = len(den) - len(np.trim_zeros(den, "b"))
    k0 = float(np.trim_zeros(num, "b")[-1] / np.trim_zeros(den, "b")[-1])
    zeros = np.concatenate([np.roots(cn), np.roots(pn)]).astype(complex)
    poles = np.concatenate([np.roots(cd), np.roots(pd)]).astype(complex)
    return LoopParts(cn, cd, pn, pd, theta, zeros, poles, float(num[0] / den[0]), k0, zd - zn)


def loop_response(plant, controller, w) -> np.ndarray:
    """L(jw) = C(jw) Np(jw)/Dp(jw) e^(-j w theta) at ``w`` (rad/s), the delay exact.

    Parameters
    ----------
    plant : tuple
        (num, den, theta_s) of the plant (:func:`designer.pid.modelloop.plant_of`).
    controller : tuple
        The controller's (num, den).
    w : array_like
        Angular frequencies (rad/s).

    Returns
    -------
    numpy.ndarray
        Complex L(jw).
    """
    return _response(parse_loop(plant, controller), np.asarray(w, float))


def _response(lp: LoopParts, w):
    s = 1j * w
    # the four factors evaluated apart: no coefficient products to lose digits in
    with np.errstate(divide="ignore", invalid="ignore"):
        return (np.polyval(lp.nc, s) * np.polyval(lp.np_, s) / (np.polyval(lp.dc, s) * np.polyval(lp.dp, s))
                * np.exp(-1j * w * lp.theta))


def _root_angles(roots, w):
    """sum over ``roots`` of arg(jw - p), each on a branch continuous in w.

    Left half-plane root: atan2(w - Im p, -Re p), in (-pi/2, pi/2). Right half-plane:
    pi - atan2(w - Im p, Re p), in (pi/2, 3 pi/2). On the axis: -pi/2 below Im p,
    pi/2 from Im p on (the w > 0 side at a root at 0: an integrator's -90 deg).
    """
    w = np.asarray(w, float)[..., None]
    if roots.size == 0:
        return np.zeros(w.shape[:-1])
    re, im = roots.real, roots.imag
    axis = np.abs(re) <= 1e-10 * np.abs(roots)
    ang = np.where(axis, np.where(w >= im, math.pi / 2, -math.pi / 2),
                   np.where(re < 0, np.arctan2(w - im, -re), math.pi - np.arctan2(w - im, np.abs(re))))
    return ang.sum(axis=-1)


def _rational_phase(lp: LoopParts, w):
    """Continuous phase of the rational part, offset so that it starts at arg K0 - m pi/2
    (with arg K0 = -pi for a negative gain: a reverse-acting loop reads -180 deg)."""
    raw = lambda x: (_root_angles(lp.zeros, x) - _root_angles(lp.poles, x)  # noqa: E731
                     + (0.0 if lp.lead > 0 else math.pi))
    start = (0.0 if lp.k0 > 0 else -math.pi) - lp.m * math.pi / 2
    offset = 2 * math.pi * round((start - float(raw(0.0))) / (2 * math.pi))
    return raw(w) + offset


def loop_phase(plant, controller, w) -> np.ndarray:
    """Continuous phase of L(jw) (rad) at ``w`` (rad/s): the rational part's, from its
    roots (:func:`_root_angles`), minus w theta; never wrapped."""
    return _phase(parse_loop(plant, controller), np.asarray(w, float))


def _phase(lp: LoopParts, w):
    return _rational_phase(lp, w) - w * lp.theta


def _magnitude_bound(lp: LoopParts, w):
    """U(w) >= |L(s)| for every |s| = w > max|p| with Re s >= 0:
    |lead| w^(nz - np) prod(1 + |z|/w) / prod(1 - |p|/w) (|e^(-theta s)| <= 1
    there); it decreases with w."""
    pmax = float(np.max(np.abs(lp.poles))) if lp.poles.size else 0.0
    if w <= pmax:
        return math.inf
    return float(abs(lp.lead) * w ** (-lp.degree_gap) * np.prod(1 + np.abs(lp.zeros) / w)
                 / np.prod(1 - np.abs(lp.poles) / w))


def corner_frequencies(lp: LoopParts) -> np.ndarray:
    """Frequencies (rad/s) where the loop's shape changes: |roots| (not at 0), 1/theta,
    and the crossover of the low-frequency asymptote |K0|/w^m."""
    r = np.abs(np.concatenate([lp.zeros, lp.poles]))
    c = list(r[r > 0])
    # a dead time whose 1/theta lies beyond DELAY_CORNER_SPAN x the fastest other corner turns the phase by
    # under 1e-6 rad anywhere in the band: no corner (1/theta of a 1e-144 s delay overflowed the band's polyval)
    if lp.theta > 0 and (not c or 1 / lp.theta <= DELAY_CORNER_SPAN * max(c)):
        c.append(1 / lp.theta)
    if lp.m > 0:
        c.append(abs(lp.k0) ** (1 / lp.m))
    return np.array(c) if c else np.array([1.0])


def frequency_band(plant, controller) -> tuple:
    """Default band (w_lo, w_hi) in rad/s: two decades either side of the loop's
    corners (:func:`corner_frequencies`), widened until every gain crossover is inside
    (above w_hi the bound :func:`_magnitude_bound` is below 1; below w_lo the
    low-frequency asymptote is above 1)."""
    return loop_band(parse_loop(plant, controller))


def loop_band(lp: LoopParts):
    c = corner_frequencies(lp)
    lo, hi = float(c.min()) / 100, float(c.max()) * 100
    for _ in range(30):
        if lp.degree_gap < 0 or (lp.degree_gap == 0 and abs(lp.lead) >= 1) or _magnitude_bound(lp, hi) < 1:
            break   # a loop whose |L(j inf)| >= 1 never falls below 1: its band stays the corners'
        hi *= 10
    for _ in range(30):
        if lp.m <= 0 or abs(_response(lp, np.array([lo]))[0]) >= 1:
            break
        lo /= 10
    return lo, hi


def _extra_frequencies(lp: LoopParts, lo, hi):
    """The roots' frequencies |p| and |Im p| in the band (a light resonance's peak
    falls between log-grid points), never a root on the axis (|L| infinite there)."""
    r = np.concatenate([lp.zeros, lp.poles])
    r = r[np.abs(r.real) > 1e-10 * np.abs(r)]
    f = np.concatenate([np.abs(r), np.abs(r.imag)])
    return f[(f > lo) & (f < hi)]


def log_grid(lp: LoopParts, lo, hi):
    n = max(2, int(math.ceil(math.log10(hi / lo) * POINTS_PER_DECADE)) + 1)
    return np.unique(np.concatenate([np.geomspace(lo, hi, n), _extra_frequencies(lp, lo, hi)]))


def _dense_grid(lp: LoopParts, lo, hi, lin_top):
    """Log grid on [lo, hi] and, with a delay, a linear grid up to ``lin_top`` fine
    enough that the delay turns the phase by at most :data:`PHASE_STEP` per step."""
    w = log_grid(lp, lo, hi)
    if lp.theta > 0 and lin_top > lo:
        top = min(lin_top, hi)
        n = int(math.ceil(top * lp.theta / PHASE_STEP)) + 1
        if n > MAX_GRID:
            raise DesignError(f"the loop's delay turns {top * lp.theta:.3g} rad below |L| = {LOOP_FLOOR}: "
                              "too many points to resolve (is the gain far too high?)")
        lin = np.linspace(0.0, top, n)
        w = np.unique(np.concatenate([w, lin[lin >= lo]]))
    return w


def _brentq(f, a, b):
    from scipy.optimize import brentq
    return brentq(f, a, b, xtol=1e-14 * b, rtol=1e-13)


def gain_crossovers(lp: LoopParts, w) -> np.ndarray:
    """Every w (rad/s) in the grid's span where |L(jw)| = 1: sign changes of log|L|
    on ``w``, refined with brentq (|L| does not depend on the delay)."""
    with np.errstate(divide="ignore"):
        f = np.log(np.abs(_response(lp, w)))
    up = f >= 0
    out = []
    for i in np.nonzero(up[:-1] != up[1:])[0]:
        g = lambda x: float(np.log(np.abs(_response(lp, np.array([x]))[0])))  # noqa: E731
        out.append(_brentq(g, w[i], w[i + 1]))
    return np.array(out)


def _phase_crossovers(lp: LoopParts, w) -> np.ndarray:
    """Every w (rad/s) on the grid's span where the continuous phase is
    -180 - 360 k deg (any integer k): the Nyquist curve crosses the negative real
    axis. Found where floor((phase + pi)/(2 pi)) changes between grid points,
    refined with brentq; the lowest :data:`MAX_PHASE_CROSSOVERS`."""
    ph = _phase(lp, w)
    k = np.floor((ph + math.pi) / (2 * math.pi))
    out = []
    for i in np.nonzero(k[:-1] != k[1:])[0]:
        if abs(k[i + 1] - k[i]) != 1:
            continue   # several turns in one step: a grid too coarse there (beyond LOOP_FLOOR)
        n = max(k[i], k[i + 1])
        g = lambda x: float(_phase(lp, np.array([x]))[0] + math.pi - 2 * math.pi * n)  # noqa: E731
        out.append(_brentq(g, w[i], w[i + 1]))
        if len(out) == MAX_PHASE_CROSSOVERS:
            break
    return np.array(out)


def closed_loop_rhp_roots(plant, controller) -> float:
    """Number of closed-loop roots with Re s > 0 (nan: a root on the axis, the loop
    marginal; inf: infinitely many, see below). The loop is stable when it is 0.

    Without delay: the roots of Dc Dp + Nc Np. With a delay: the argument principle
    on the entire function Delta(s) = Dc Dp + Nc Np e^(-theta s) along the imaginary
    axis and a right half-plane arc of radius R where |L| < 1 (so Delta's angle
    there follows Dc Dp's, sum_p arg(s - p)). By conjugate symmetry only w >= 0 is
    needed, and with wb above the last gain crossover (|L(jw)| < 1 for w >= wb, the
    arc's part cancelling) the count is

        pi Z = sum_p arg(j wb - p) + arg(1 + L(j wb)) - [arg Delta(j wb) - arg Delta(0)]

    with arg(j wb - p) on the branches of :func:`_root_angles` and the change of
    arg Delta tracked on a grid on [0, wb]: the linear grid of :data:`PHASE_STEP`
    and log grid, refined where one step turns more than pi/4. Integrators
    need no indentation: Delta(0) = Nc(0) Np(0) is finite.

    With a delay, a biproper loop with |L(j inf)| >= 1 (a neutral equation) or
    an improper one has infinitely many roots at or right of the axis: inf.
    """
    return _rhp_roots(parse_loop(plant, controller))


def _rhp_roots(lp: LoopParts) -> float:
    if lp.theta == 0:
        r = np.roots(np.polyadd(np.polymul(lp.dc, lp.dp), np.polymul(lp.nc, lp.np_)))
        if np.any(np.abs(r.real) <= 1e-9 * np.abs(r)):   # a root on the axis (at 0 included)
            return math.nan
        return float(np.sum(r.real > 0))
    if lp.degree_gap < 0 or (lp.degree_gap == 0 and abs(lp.lead) >= 1):
        return math.inf
    lo, hi = loop_band(lp)
    # a top where |L| < 1 for good (the bound on the axis and the arc), then the last crossing below it
    top = max(hi, 2 * float(np.max(np.abs(lp.poles))) if lp.poles.size else hi)
    for _ in range(200):
        if _magnitude_bound(lp, top) < 1:
            break
        top *= 2
    w = log_grid(lp, lo, top)
    big = np.nonzero(np.abs(_response(lp, w)) >= 1)[0]
    wb = float(w[big[-1] + 1]) if big.size else lo
    grid = _dense_grid(lp, lo, wb, wb)
    grid = np.concatenate([[0.0], grid[grid <= wb]])
    if grid[-1] < wb:
        grid = np.append(grid, wb)

    def delta(x):
        s = 1j * x
        return (np.polyval(lp.dc, s) * np.polyval(lp.dp, s)
                + np.polyval(lp.nc, s) * np.polyval(lp.np_, s) * np.exp(-1j * x * lp.theta))

    d = delta(grid)
    for _ in range(60):
        if np.any(d == 0):
            return math.nan
        turn = np.angle(d[1:] / d[:-1])
        bad = np.nonzero(np.abs(turn) > math.pi / 4)[0]
        if bad.size == 0:
            break
        if np.any(grid[bad + 1] - grid[bad] <= 1e-12 * grid[bad + 1]):
            return math.nan   # Delta turns abruptly at one frequency: a root on the axis
        mid = 0.5 * (grid[bad] + grid[bad + 1])
        order = np.argsort(np.concatenate([grid, mid]), kind="stable")
        grid = np.concatenate([grid, mid])[order]
        d = np.concatenate([d, delta(mid)])[order]
    else:
        raise DesignError("the closed loop's stability count did not converge")
    swing = float(np.sum(turn))
    lb = _response(lp, np.array([wb]))[0]
    z = (float(_root_angles(lp.poles, wb)) + float(np.angle(1 + lb)) - swing) / math.pi
    if abs(z - round(z)) > 0.05:
        raise DesignError(f"the closed loop's stability count is not a whole number ({z:.3f})")
    return float(round(z))


@dataclass(frozen=True)
class DelayLoopMargins:
    """Margins of the loop C P e^(-theta s) (inf where there is no crossing, nan for its frequency)."""

    crossover_hz: float                #: the gain crossover with the smallest phase margin
    phase_margin_deg: float            #: 180 + arg L there (continuous phase: negative when the delay is too long)
    crossovers_hz: tuple               #: every gain crossover in the band
    phase_margins_deg: tuple           #: the phase margin at each
    phase_crossover_hz: float          #: the first (lowest) phase crossover
    gain_margin_db: float              #: -20 log10 |L| there
    phase_crossovers_hz: tuple         #: the lowest phase crossovers where |L| >= LOOP_FLOOR
    gain_margins_db: tuple             #: the gain margin at each
    delay_margin_s: float              #: min over crossovers of PM/wc: the extra dead time the loop tolerates
    ms: float                          #: max |1/(1 + L(jw))|
    ms_hz: float                       #: where it peaks
    rhp_roots: float                   #: closed-loop roots with Re s > 0 (:func:`closed_loop_rhp_roots`)
    stable: bool                       #: rhp_roots == 0

    def to_dict(self) -> dict:
        return json_safe(asdict(self))


def loop_margins(plant, controller, w_min: float | None = None, w_max: float | None = None) -> DelayLoopMargins:
    """Margins, sensitivity peak and closed-loop stability of C(s) P(s) e^(-theta s).

    Parameters
    ----------
    plant : (num, den, theta_s)
        The plant's rational part and dead time (s).
    controller : (num, den)
        The controller's transfer function.
    w_min, w_max : float, optional
        Band searched (rad/s); default :func:`frequency_band`. The stability
        verdict does not depend on it.

    Returns
    -------
    DelayLoopMargins

    Notes
    -----
    Crossings are found on a log grid (:data:`POINTS_PER_DECADE`, plus the roots'
    frequencies) joined, with a delay, by a linear grid on which the delay turns
    the phase by at most :data:`PHASE_STEP` (up to where |L| falls below
    :data:`LOOP_FLOOR`), and refined with brentq. The phase is continuous
    (:func:`loop_phase`): a phase margin under 0 or beyond 180 deg is reported as
    it is, never wrapped. The delay margin is min_i PM_i/wc_i over the gain
    crossovers (PM_i taken in [0, 360) deg when the loop is stable: added delay
    only lags).
    """
    lp = parse_loop(plant, controller)
    lo, hi = loop_band(lp)
    lo = float(w_min) if w_min is not None else lo
    hi = float(w_max) if w_max is not None else hi
    if not (0 < lo < hi and math.isfinite(hi)):
        raise DesignError(f"the band must satisfy 0 < w_min < w_max, got {lo}, {hi}", "w_min")
    wl = log_grid(lp, lo, hi)
    live = wl[np.abs(_response(lp, wl)) >= LOOP_FLOOR]
    lin_top = min(hi, 1.05 * float(live.max())) if live.size else lo
    w = _dense_grid(lp, lo, hi, lin_top)
    rhp = _rhp_roots(lp)
    stable = rhp == 0
    wc = gain_crossovers(lp, w)
    if wc.size:
        pm = np.degrees(math.pi + _phase(lp, wc))
        i = int(np.argmin(pm))
        pm_dm = np.mod(pm, 360.0) if stable else pm
        dm = float(np.min(np.radians(pm_dm) / wc))
        crossover_hz, phase_margin = float(wc[i] / (2 * math.pi)), float(pm[i])
    else:
        pm, dm, crossover_hz, phase_margin = np.array([]), math.inf, math.nan, math.inf
    wp = _phase_crossovers(lp, w[w <= lin_top] if lp.theta > 0 else w)
    gms = -20 * np.log10(np.abs(_response(lp, wp))) if wp.size else np.array([])
    ms, w_ms = sensitivity_peak(w, _response(lp, w), lambda x: _response(lp, x))
    return DelayLoopMargins(
        crossover_hz=crossover_hz, phase_margin_deg=phase_margin,
        crossovers_hz=tuple(float(x) for x in wc / (2 * math.pi)), phase_margins_deg=tuple(float(x) for x in pm),
        phase_crossover_hz=float(wp[0] / (2 * math.pi)) if wp.size else math.nan,
        gain_margin_db=float(gms[0]) if wp.size else math.inf,
        phase_crossovers_hz=tuple(float(x) for x in wp / (2 * math.pi)), gain_margins_db=tuple(float(x) for x in gms),
        delay_margin_s=dm, ms=ms, ms_hz=w_ms / (2 * math.pi), rhp_roots=rhp, stable=bool(stable))
