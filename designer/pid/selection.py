"""Joint E-series selection of the seed's op-amp PID controller's parts (seed 001,
Figures 65-66; its topology, part names and formulas are in :mod:`designer.pid.blocks`).

:func:`select_parts` chooses every part at once so that

    Kp = R5 R3 / (R6 R4),  Ti = R8 R14 C4 / R6,  Td = R6 R11 C3 / R7

come as close to their targets as the series allow (the worst of the three
relative errors), then, among the choices as close, the one with the most
bandwidth (:func:`objective`). R6 is shared by the three; for a fixed R6 the
groups (R5, R3, R4), (R8, R14, C4) and (R11, R7, C3) are independent, so the
search (:func:`_search`) works on sorted tables of what each group can make and
minimises over R6. R13 and R12 follow from the integrator-leak 1/(2 pi R13 C4)
and derivative-filter 1/(2 pi R12 C3) corners, R9 = R10 and R15..R18 from
:func:`designer.pid.blocks.unity_resistor`. :func:`brute_force`, every
combination, is the reference the search is checked against on small sets.

See Also
--------
designer.pid.blocks : the parts, their formulas and the static checks.
designer.plant.selection : the joint search of the plant's parts.
"""

from __future__ import annotations

import math
from dataclasses import dataclass, field

import numpy as np

from ..core import eseries
from ..core.errors import DesignError
from ..core.i18n import N_, Message
from .blocks import F_DIFFERENTIATOR_RATIO, F_INTEGRATOR_RATIO, PidParts, check_targets, unity_resistor

__all__ = ["R_CORNER_MAX", "brute_force", "objective", "select_parts"]


#: R12 and R13 (set only by the corners) stay at or below this: with bipolar
#: op-amps (LM741 bias current ~80 nA) larger feedback resistors add offsets.
R_CORNER_MAX = 100e3


@dataclass
class Selection:
    """Chosen parts and how well they hit the targets."""

    parts: PidParts
    targets: dict                 #: kp, ti_s, td_s, f_integrator_hz, f_differentiator_hz
    errors_pct: dict              #: kp, ti, td relative errors in percent
    best_possible_pct: float      #: smallest worst-of-three error the series allow
    r_series: str
    c_series: str
    candidates: int               #: size of the searched candidate set
    notes: list = field(default_factory=list)

    tol: float = 0.01             #: errors up to this fraction count as equal (see :func:`objective`)

    @property
    def worst_error_pct(self) -> float:
        return max(abs(v) for v in self.errors_pct.values())

    @property
    def tolerances_pct(self) -> tuple:
        """The resistor and the capacitor series' tolerances, percent (E24: 5, E12: 10)."""
        return tuple(100 * eseries.TOLERANCE[s] for s in (self.r_series, self.c_series))

    def to_dict(self) -> dict:
        """The ``series`` object of result.json."""
        rt, ct = self.tolerances_pct
        return {"r": self.r_series, "c": self.c_series, "r_tolerance_pct": rt, "c_tolerance_pct": ct,
                "best_possible_error_pct": self.best_possible_pct, "candidates": self.candidates}


def objective(parts: PidParts, targets: dict, best: float, tol: float) -> tuple:
    """The quantity the selection minimises, lexicographically: the worst
    relative error of Kp, Ti, Td (errors at or below max(best, tol) count as
    equal), then the largest high-frequency noise gain of the summer, final
    gain and differentiator stages (smaller = more bandwidth).

    Parameters
    ----------
    parts : PidParts
        A candidate controller.
    targets : dict
        ``kp``, ``ti_s``, ``td_s``.
    best : float
        The smallest worst error found.
    tol : float
        Errors at or below max(best, tol) count as equal.

    Returns
    -------
    tuple
    """
    err = worst_error(parts, targets)
    level = max(best, tol) * (1 + 1e-9)
    ng = parts.noise_gains()
    ngmax = max(ng["summer"], ng["gain"], ng.get("differentiator", 0.0))
    return (max(err, level) if err > level else level, ngmax)


def worst_error(parts: PidParts, targets: dict) -> float:
    e = [abs(parts.kp / targets["kp"] - 1), abs(parts.ti_s / targets["ti_s"] - 1)]
    if targets["td_s"] > 0:
        e.append(abs(parts.td_s / targets["td_s"] - 1))
    return max(e)


def _corner_resistor(f_hz, caps, rvals, lo, hi):
    """For each capacitor, the series resistor nearest 1/(2 pi f C), or nan
    when the exact value falls outside the bounds. If no capacitor allows the
    corner at all, the one that comes closest is kept with the resistor at
    its bound (the corner check then reports the miss)."""
    exact = 1.0 / (2 * np.pi * f_hz * caps)
    inside = (exact >= lo * 0.999) & (exact <= hi * 1.001)
    if not np.any(inside):
        keep = rvals[(rvals >= lo * 0.999) & (rvals <= hi * 1.001)]
        if keep.size == 0 or caps.size == 0:
            return np.full_like(exact, np.nan)
        clipped = np.clip(exact, keep[0], keep[-1])
        miss = np.abs(np.log(clipped / exact))
        out = np.full_like(exact, np.nan)
        best = np.nonzero(miss <= miss.min() * (1 + 1e-9))[0]
        for i in best:
            out[i] = keep[0] if exact[i] < keep[0] else keep[-1]
        return out
    idx = np.clip(np.searchsorted(np.log(rvals), np.log(exact)), 1, rvals.size - 1)
    lo_v, hi_v = rvals[idx - 1], rvals[idx]
    pick = np.where(np.abs(np.log(exact / lo_v)) <= np.abs(np.log(hi_v / exact)), lo_v, hi_v)
    if rvals.size == 1:
        pick = np.full_like(exact, rvals[0])
    return np.where((exact >= lo * 0.999) & (exact <= hi * 1.001), pick, np.nan)


def _search_sorted(table, x, side="left"):
    """``np.searchsorted`` for many needles: searching them in order keeps the
    binary searches in cache (twice as fast for millions of needles)."""
    x = np.asarray(x)
    order = np.argsort(x, axis=None, kind="stable")
    out = np.empty(x.size, np.intp)
    out[order] = np.searchsorted(table, x.ravel()[order], side=side)
    return out.reshape(x.shape)


def _nearest_error(sorted_vals, targets):
    """Smallest |v/t - 1| over sorted_vals for each target."""
    idx = _search_sorted(sorted_vals, targets)
    i0 = np.clip(idx - 1, 0, sorted_vals.size - 1)
    i1 = np.clip(idx, 0, sorted_vals.size - 1)
    return np.minimum(np.abs(sorted_vals[i0] / targets - 1), np.abs(sorted_vals[i1] / targets - 1))


def select_parts(kp: float, ti_s: float, td_s: float, fn_hz: float, *,
                 r_series: str = "E24", c_series: str = "E12",
                 r_min: float = 1e3, r_max: float = 1e6,
                 c_min: float = 1e-9, c_max: float = 10e-6,
                 f_integrator_hz: float | None = None,
                 f_differentiator_hz: float | None = None,
                 tol: float = 0.01) -> Selection:
    """Choose every part of the controller from E-series values, jointly.

    R6 is shared by Kp, Ti and Td; for a fixed R6 the three groups (R5, R3,
    R4), (R8, R14, C4) and (R11, R7, C3) are independent, so the exact
    smallest worst-of-three error is found group by group and minimised over
    R6. Among the choices within max(that error, ``tol``), the one with the
    smallest largest noise gain of the summer, final gain and differentiator
    wins (most bandwidth). R13 and R12 set the integrator-leak and
    derivative-filter corners (defaults fn/100 and 10 fn) and are the series
    values nearest to them, at most :data:`R_CORNER_MAX`. :func:`brute_force`
    checks the search on small sets.

    Ties among the choices go, in order: to R5 with the smallest final-stage
    noise gain, then R4 nearest 10 kOhm; the largest R8, then R14 and R13 nearest
    10 kOhm; R11 nearest 10 kOhm; the smallest R6, R5, R7. The search works on
    tables of n^2 entries (n resistor values), never on the n^3 Kp triples, in
    fixed-size chunks: E192/E192 takes under a second and tens of MB.

    Parameters
    ----------
    kp : float
        Proportional gain.
    ti_s : float
        Integral time (s).
    td_s : float
        Derivative time (s; 0 for a PI).
    fn_hz : float
        The plant's natural frequency (a model plant: the loop's crossover) the corners are set from.
    r_series, c_series : str
        The E-series of the resistors and of the capacitors.
    r_min, r_max : float
        The resistors' bounds (Ohm).
    c_min, c_max : float
        The capacitors' bounds (F).
    tol : float
        Errors of Kp, Ti and Td at or below this count as equal.
    f_integrator_hz : float, optional
        The integrator leak's corner (default fn/100).
    f_differentiator_hz : float, optional
        The derivative filter's corner (default 10 fn).

    Returns
    -------
    Selection
    """
    check_targets(kp, ti_s, td_s)
    r_series = eseries.series_name(r_series)
    c_series = eseries.series_name(c_series)
    if not (0 < r_min <= r_max) or not (0 < c_min <= c_max):
        raise DesignError("part bounds must be positive with min <= max")
    rv = eseries.values(r_series, r_min, r_max)
    cv = eseries.values(c_series, c_min, c_max)
    if rv.size == 0 or cv.size == 0:
        raise DesignError(f"no {r_series} resistor in {r_min:g}..{r_max:g} Ohm or no {c_series} "
                          f"capacitor in {c_min:g}..{c_max:g} F; widen the bounds")
    f_i = fn_hz * F_INTEGRATOR_RATIO if f_integrator_hz is None else float(f_integrator_hz)
    f_d = fn_hz * F_DIFFERENTIATOR_RATIO if f_differentiator_hz is None else float(f_differentiator_hz)
    has_d = td_s > 0
    unity = unity_resistor(r_series, r_min, r_max)
    targets = {"kp": kp, "ti_s": ti_s, "td_s": td_s,
               "f_integrator_hz": f_i, "f_differentiator_hz": f_d if has_d else None}
    parts, best, ncand = _search(kp, ti_s, td_s, rv, cv, f_i, f_d, has_d, unity, tol)
    errs = {"kp": (parts.kp / kp - 1) * 100, "ti": (parts.ti_s / ti_s - 1) * 100}
    if has_d:
        errs["td"] = (parts.td_s / td_s - 1) * 100
    sel = Selection(parts, targets, errs, best * 100, r_series, c_series, ncand, tol=tol)
    if best > tol:
        sel.notes.append(Message(N_("{r_series}/{c_series} within the bounds cannot hit all of Kp, Ti, Td within "
                                    "{tol} %; the best possible worst error is {best} %"), r_series=r_series,
                                 c_series=c_series, tol=f"{tol * 100:g}", best=f"{best * 100:.3g}"))
    return sel


#: (R6 x part) windows handled at once: bounds the search's memory.
QUERIES_PER_CHUNK = 1 << 18


def _unique_outer(op, a, b):
    """Sorted distinct values of ``op.outer(a, b)``, a block of rows at a time
    (E-series products and ratios repeat across decades: the result is a few
    times smaller than the table, and the table is never whole in memory)."""
    out = np.empty(0)
    step = max(1, QUERIES_PER_CHUNK // max(1, b.size))
    for s in range(0, a.size, step):
        out = np.union1d(out, op.outer(a[s:s + step], b))
    return out


def _smallest_in(table, lo, hi):
    """Smallest value of the sorted ``table`` in [lo, hi] for each pair of bounds (inf where none)."""
    i = _search_sorted(table, lo, side="left")
    v = table[np.minimum(i, table.size - 1)]
    return np.where((i < table.size) & (v <= hi), v, np.inf)


def _range_min(values, start, stop):
    """``min(values[start[i]:stop[i]])`` for each i (inf where the range is empty).

    A sparse table built one level at a time, in place: level k holds the
    minima of the runs of 2**k values (its first N - 2**k + 1 entries), and a
    range of length L is two overlapping runs of the level floor(log2 L).
    Memory: one copy of ``values``.
    """
    out = np.full(start.shape, np.inf)
    length = stop - start
    live = length > 0
    start, stop, length = start[live], stop[live], length[live]
    level = np.frexp(length.astype(float))[1] - 1      # floor(log2 L), exact
    res = np.empty(start.shape)
    table, run = values.copy(), 1
    for k in range(int(level.max()) + 1 if level.size else 0):
        if k:
            # minima of 2 run values from two of run values; front to back, every value
            # read is still the previous level's
            for s in range(0, table.size - run, QUERIES_PER_CHUNK):
                e = min(s + QUERIES_PER_CHUNK, table.size - run)
                np.minimum(table[s:e], table[s + run:e + run], out=table[s:e])
            run *= 2
        sel = level == k
        res[sel] = np.minimum(table[start[sel]], table[stop[sel] - run])
    out[live] = res
    return out


def _r6_chunks(n):
    """Slices of the R6 indices, each with its windows over all n values of a part in memory at once."""
    step = max(1, QUERIES_PER_CHUNK // n)
    return [slice(s, min(n, s + step)) for s in range(0, n, step)]


def _min_cost(r6, r8, rv, ngf, ngd, has_d):
    """Smallest max(summer, final gain, differentiator noise gain) for one R6,
    over R5 (final-stage noise gain ``ngf`` per R5) and R7 (``ngd`` per R7).

    The summer's noise gain 1 + R5 (1/R6 + 1/R8 + 1/R7) rises with R5 while the
    best final-stage one for each R5 falls (its window R3/R4 = Kp R6/R5 moves
    down), so for each R7 only the two R5 around the crossing can be best.
    """
    ok5 = np.isfinite(ngf)
    r5, f5 = rv[ok5], ngf[ok5]
    if has_d:
        ok7 = np.isfinite(ngd)
        inv7, d7 = 1.0 / rv[ok7], ngd[ok7]
    else:
        inv7, d7 = np.array([0.0]), np.array([0.0])
    if not r5.size or not d7.size:
        return np.inf
    b = 1 / r6 + 1 / r8 + inv7                   # the summer's noise gain is 1 + R5 b
    cross = np.searchsorted(-(f5 - 1) / r5, -b, side="left")
    # the crossing found from the thresholds may be one off in floating point: look around it
    near = np.clip(cross[:, None] + np.arange(-2, 2), 0, r5.size - 1)
    cost = np.maximum(1 + r5[near] * b[:, None], f5[near]).min(axis=1)
    return float(np.maximum(cost, d7).min())


def _search(kp, ti, td, rv, cv, f_i, f_d, has_d, unity, tol):
    """The selection of :func:`select_parts` (see there for the rules).

    Per group, a sorted table of what the non-R6 parts can make (R3/R4 for Kp,
    R14 C4 for Ti, R11 C3 for Td; at most n^2 or n x caps entries), and for
    every R6 the windows into it: the nearest entries give the group's error,
    the window's smallest entry its smallest noise gain (a range minimum for
    Td). Memory is that of the tables and of fixed-size chunks of R6.
    """
    lo, hi = rv[0], min(rv[-1], max(R_CORNER_MAX, rv[0]))
    r13 = _corner_resistor(f_i, cv, rv, lo, hi)
    c4s, r13s = cv[~np.isnan(r13)], r13[~np.isnan(r13)]
    if c4s.size == 0:
        raise DesignError(f"no capacitor in the bounds gives an integrator corner of {f_i:.4g} Hz "
                          "with a resistor in the bounds; widen --r-min/--r-max or --c-min/--c-max")
    n = rv.size
    # Kp group: R5 R3 / R4 = Kp R6, i.e. R3/R4 = Kp R6 / R5
    ratios = _unique_outer(np.divide, rv, rv)
    # Ti group: R8 R14 C4 = Ti R6, i.e. R14 C4 = Ti R6 / R8
    times_i = _unique_outer(np.multiply, rv, c4s)
    ncand = n ** 3 + n * n * c4s.size
    if has_d:
        r12 = _corner_resistor(f_d, cv, rv, lo, hi)
        c3s, r12s = cv[~np.isnan(r12)], r12[~np.isnan(r12)]
        if c3s.size == 0:
            raise DesignError(f"no capacitor in the bounds gives a differentiator corner of {f_d:.4g} Hz "
                              "with a resistor in the bounds; widen the part bounds")
        # Td group: R11 C3 / R7 = Td / R6, i.e. R11 C3 = Td R7 / R6; noise gain 1 + R11/R12
        times_d = np.multiply.outer(rv, c3s).ravel()
        order = np.argsort(times_d, kind="stable")
        times_d, q_d = times_d[order], np.divide.outer(rv, r12s).ravel()[order]
        del order
        ncand += n * n * c3s.size
    # 1. the smallest worst-of-three error for each R6
    worst = np.zeros(n)
    for sl in _r6_chunks(n):
        r6 = rv[sl, None]
        ek = _nearest_error(ratios, kp * r6 / rv).min(axis=1)
        ei = _nearest_error(times_i, ti * r6 / rv).min(axis=1)
        ed = _nearest_error(times_d, td * rv / r6).min(axis=1) if has_d else 0.0
        worst[sl] = np.maximum(np.maximum(ek, ei), ed)
    best = float(np.min(worst))
    level = max(best, tol) * (1 + 1e-9)

    def windows(sl):
        """For the R6 of ``sl``: final-stage noise gain per R5, the largest R8, and
        the differentiator's noise gain per R7, within ``level`` of the targets."""
        r6 = rv[sl, None]
        ngf = 1 + _smallest_in(ratios, kp * r6 * (1 - level) / rv, kp * r6 * (1 + level) / rv)
        has_i = np.isfinite(_smallest_in(times_i, ti * r6 * (1 - level) / rv, ti * r6 * (1 + level) / rv))
        r8 = np.where(has_i.any(axis=1), rv[n - 1 - np.argmax(has_i[:, ::-1], axis=1)], np.nan)
        if not has_d:
            return ngf, r8, None
        t = td * rv / r6
        a = _search_sorted(times_d, t * (1 - level), side="left")
        z = _search_sorted(times_d, t * (1 + level), side="right")
        return ngf, r8, 1 + _range_min(q_d, a, z)

    # 2. for each R6 within the level the smallest noise-gain cost; the first
    #    (smallest) R6 that is better by more than rounding wins
    cost = np.full(n, np.inf)
    for sl in _r6_chunks(n):
        ngf, r8, ngd = windows(sl)
        for k, j6 in enumerate(range(sl.start, sl.stop)):
            if worst[j6] <= level and np.isfinite(r8[k]):
                cost[j6] = _min_cost(rv[j6], r8[k], rv, ngf[k], ngd[k] if has_d else None, has_d)
    win = None
    for j6 in np.flatnonzero(np.isfinite(cost)):
        if win is None or cost[j6] < cost[win] * (1 - 1e-12):
            win = j6
    if win is None:  # pragma: no cover - best <= level guarantees a candidate
        raise DesignError("no part combination found; widen the bounds")
    # 3. the winner's parts, with the tie-breaks of the rules
    r6 = float(rv[win])
    ngf, r8, ngd = windows(slice(win, win + 1))
    r8 = float(r8[0])
    r5, r7 = _cost_argmin(r6, r8, rv, ngf[0], ngd[0] if has_d else None, has_d)
    # (the windows as ``windows`` computes them, so the pick is among what it counted)
    r3, r4 = _pick_kp(rv, r5, kp * r6 * (1 - level) / r5, kp * r6 * (1 + level) / r5)
    r14, c4, r13v = _pick_ti(rv, c4s, r13s, r8, ti * r6 * (1 - level) / r8, ti * r6 * (1 + level) / r8)
    if has_d:
        t = td * r7 / r6
        r11, c3, r12v = _pick_td(rv, c3s, r12s, r7, t * (1 - level), t * (1 + level))
    parts = PidParts(
        r3=r3, r4=r4, r5=r5, r6=r6, r7=r7 if has_d else None, r8=r8, r9=unity, r10=unity,
        r11=r11 if has_d else None, r12=r12v if has_d else None, r13=r13v, r14=r14,
        r15=unity, r16=unity, r17=unity, r18=unity, c3=c3 if has_d else None, c4=c4)
    return parts, best, ncand


def _cost_argmin(r6, r8, rv, ngf, ngd, has_d):
    """(R5, R7) of the smallest cost for one R6 (:func:`_min_cost`'s arguments), the
    first in R5 then R7 order among equals; the cost matrix goes a few rows at a time."""
    ok5 = np.isfinite(ngf)
    r5, f5 = rv[ok5], ngf[ok5]
    if has_d:
        ok7 = np.isfinite(ngd)
        r7, inv7, d7 = rv[ok7], 1.0 / rv[ok7], ngd[ok7]
    else:
        r7, inv7, d7 = np.array([np.inf]), np.array([0.0]), np.array([0.0])
    b = 1 / r6 + 1 / r8 + inv7
    rows = max(1, QUERIES_PER_CHUNK // r7.size)
    best, at = np.inf, (0, 0)
    for s in range(0, r5.size, rows):
        cost = np.maximum(np.maximum(1 + r5[s:s + rows, None] * b, f5[s:s + rows, None]), d7)
        i = int(np.argmin(cost))
        if cost.flat[i] < best:
            best, at = float(cost.flat[i]), (s + i // r7.size, i % r7.size)
    return float(r5[at[0]]), float(r7[at[1]])


def _pick_kp(rv, r5, lo, hi):
    """R3, R4 for the chosen R5, among R3/R4 in [lo, hi]: the smallest final-stage
    noise gain 1 + R3/R4, then R4 nearest 10 kOhm, then the smaller R5 R3/R4, then
    the order of the values."""
    ratio = rv[:, None] / rv
    i3, i4 = np.nonzero((ratio >= lo) & (ratio <= hi))
    k = np.lexsort(((r5 * rv[i3]) / rv[i4], np.abs(np.log(rv[i4] / 1e4)), 1 + ratio[i3, i4]))[0]
    return float(rv[i3[k]]), float(rv[i4[k]])


def _pick_ti(rv, c4s, r13s, r8, lo, hi):
    """R14, C4 (and its R13) for the chosen R8, among R14 C4 in [lo, hi]: R14 and R13
    nearest 10 kOhm (the larger of the two log distances), then the smaller
    R8 R14 C4, then the order of the values."""
    prod = rv[:, None] * c4s
    i14, ic4 = np.nonzero((prod >= lo) & (prod <= hi))
    spread = np.maximum(np.abs(np.log(rv[i14] / 1e4)), np.abs(np.log(r13s[ic4] / 1e4)))
    k = np.lexsort(((r8 * rv[i14]) * c4s[ic4], spread))[0]
    return float(rv[i14[k]]), float(c4s[ic4[k]]), float(r13s[ic4[k]])


def _pick_td(rv, c3s, r12s, r7, lo, hi):
    """R11, C3 (and its R12) for the chosen R7, among R11 C3 in [lo, hi]: the smallest
    differentiator noise gain 1 + R11/R12, then R11 nearest 10 kOhm, then the
    smaller R11 C3/R7, then the order of the values."""
    prod = rv[:, None] * c3s
    i11, ic3 = np.nonzero((prod >= lo) & (prod <= hi))
    k = np.lexsort((prod[i11, ic3] / r7, np.abs(np.log(rv[i11] / 1e4)), 1 + rv[i11] / r12s[ic3]))[0]
    return float(rv[i11[k]]), float(c3s[ic3[k]]), float(r12s[ic3[k]])


def brute_force(kp: float, ti_s: float, td_s: float, fn_hz: float, *, r_series: str, c_series: str,
                r_min: float, r_max: float, c_min: float, c_max: float, tol: float = 0.01,
                f_integrator_hz=None, f_differentiator_hz=None):
    """Exhaustive reference for :func:`select_parts` on small candidate sets:
    every combination of R3, R4, R5, R6, R7, R8, R11, R14, C3, C4 (R12, R13 follow
    from the capacitors as in the search). Returns (best worst-error, best objective).

    Parameters
    ----------
    kp : float
        Proportional gain.
    ti_s : float
        Integral time (s).
    td_s : float
        Derivative time (s).
    fn_hz : float
        The plant's natural frequency (a model plant: the loop's crossover) the corners are set from.
    r_series, c_series : str
        The E-series of the resistors and of the capacitors.
    r_min, r_max : float
        The resistors' bounds (Ohm).
    c_min, c_max : float
        The capacitors' bounds (F).
    tol : float
        Errors of Kp, Ti and Td at or below this count as equal.
    f_integrator_hz : float, optional
        The integrator leak's corner (default fn/100).
    f_differentiator_hz : float, optional
        The derivative filter's corner (default 10 fn).

    Returns
    -------
    tuple
        (best worst-error, best objective).
    """
    rv = eseries.values(r_series, r_min, r_max)
    cv = eseries.values(c_series, c_min, c_max)
    f_i = fn_hz * F_INTEGRATOR_RATIO if f_integrator_hz is None else f_integrator_hz
    f_d = fn_hz * F_DIFFERENTIATOR_RATIO if f_differentiator_hz is None else f_differentiator_hz
    hi = min(rv[-1], max(R_CORNER_MAX, rv[0]))
    r13 = _corner_resistor(f_i, cv, rv, rv[0], hi)
    r12 = _corner_resistor(f_d, cv, rv, rv[0], hi)
    c4s = cv[~np.isnan(r13)]
    c3s, r12s = cv[~np.isnan(r12)], r12[~np.isnan(r12)]
    best_err = math.inf
    rows = []
    for r6 in rv:
        R3, R4, R5, R7, R8, R11, R14 = np.meshgrid(rv, rv, rv, rv, rv, rv, rv, indexing="ij", sparse=True)
        ek = np.abs(R5 * R3 / (r6 * R4) / kp - 1)
        for c4 in c4s:
            ei = np.abs(R8 * R14 * c4 / r6 / ti_s - 1)
            for c3, r12v in zip(c3s, r12s):
                ed = np.abs(r6 * R11 * c3 / R7 / td_s - 1)
                err = np.maximum(np.maximum(ek, ei), ed)
                ngs = 1 + R5 * (1 / r6 + 1 / R7 + 1 / R8)
                ng = np.maximum(np.maximum(ngs, 1 + R3 / R4), 1 + R11 / r12v)
                err, ng = np.broadcast_arrays(err, ng)
                best_err = min(best_err, float(err.min()))
                rows.append((err.ravel().copy(), ng.ravel().copy()))
    level = max(best_err, tol) * (1 + 1e-9)
    best_ng = min(float(ng[err <= level].min()) for err, ng in rows if np.any(err <= level))
    return best_err, (level, best_ng)
