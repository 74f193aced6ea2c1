"""The seed's op-amp PID controller (seed 001, Figures 65-66): its parts, the
formulas that tie them to Kp, Ti and Td, a joint E-series selection, and the
static checks (corners, stage bandwidths, bounds, accuracy).

Topology and part names follow the seed; the difference amplifier's four
resistors are not named in the text, so this project fixes them as:

* U1 difference amplifier: R15 from the reference r to the inverting input,
  R16 feedback, R17 from the plant output y to the non-inverting input, R18
  from there to ground. With all four equal, v_e = y - r.
* U2 unity inverter: R10 in, R9 feedback (R9 = R10): v_p = -v_e.
* U3 differentiator: R12 in series with C3 in, R11 feedback:
  v_d = -R11 C3 s / (R12 C3 s + 1) v_e.
* U4 integrator: R14 in, R13 || C4 feedback: v_i = -(R13/R14) / (R13 C4 s + 1) v_e.
* U5 summer: R6 (from v_p), R7 (from v_d), R8 (from v_i) in, R5 feedback.
* U6 final inverting gain: R4 in, R3 feedback; its output u drives the plant.

Three inversions after v_e = y - r make u = Kp (1 + 1/(Ti s) + Td s)(r - y) with

    Kp = R5 R3 / (R6 R4),  Ti = R8 R14 C4 / R6,  Td = R6 R11 C3 / R7

and the realisation's own corners: integrator leak 1/(2 pi R13 C4), derivative
filter 1/(2 pi R12 C3). A PI controller (Td = 0) leaves out U3, R7, R11, R12, C3.
"""

from __future__ import annotations

import math
from dataclasses import dataclass, field

import numpy as np

from .. import eseries
from ..errors import DesignError
from ..units import format_eng

#: "Well below / well above" the plant's fn for the check (factor).
CORNER_MARGIN = 5.0
#: Default corner targets relative to fn (the seed used 130 Hz and 33 kHz for fn = 3.5 kHz).
F_INTEGRATOR_RATIO = 1.0 / 100.0
F_DIFFERENTIATOR_RATIO = 10.0
#: R12 and R13 (set only by the corners) stay at or below this: with bipolar
#: op-amps (LM741 bias current ~80 nA) larger feedback resistors add offsets.
R_CORNER_MAX = 100e3


@dataclass(frozen=True)
class PidParts:
    """Component values of the controller (ohms and farads).

    ``r7``, ``r11``, ``r12`` and ``c3`` are None for a PI controller.
    """

    r3: float
    r4: float
    r5: float
    r6: float
    r7: float | None
    r8: float
    r9: float
    r10: float
    r11: float | None
    r12: float | None
    r13: float
    r14: float
    r15: float
    r16: float
    r17: float
    r18: float
    c3: float | None
    c4: float

    @property
    def has_derivative(self) -> bool:
        return self.c3 is not None

    @property
    def kp(self) -> float:
        return self.r5 * self.r3 / (self.r6 * self.r4) * (self.r9 / self.r10)

    @property
    def ti_s(self) -> float:
        return self.r8 * self.r14 * self.c4 / self.r6

    @property
    def td_s(self) -> float:
        return self.r6 * self.r11 * self.c3 / self.r7 if self.has_derivative else 0.0

    @property
    def f_integrator_hz(self) -> float:
        return 1.0 / (2 * math.pi * self.r13 * self.c4)

    @property
    def f_differentiator_hz(self) -> float:
        return 1.0 / (2 * math.pi * self.r12 * self.c3) if self.has_derivative else math.inf

    @property
    def integrator_dc_gain(self) -> float:
        """DC gain of the integral path relative to the proportional one,
        R13 C4 / Ti: the leak bounds the loop's DC gain to Kp (1 + this)."""
        return self.r13 * self.c4 / self.ti_s

    def noise_gains(self) -> dict:
        """High-frequency noise gain 1 + Zf/Zin of each op-amp stage (the
        integrator's is 1 there; its DC value 1 + R13/R14 is given too)."""
        y_sum = 1 / self.r6 + 1 / self.r8 + (1 / self.r7 if self.has_derivative else 0.0)
        ng = {"difference": 1 + self.r16 / self.r15,
              "inverter": 1 + self.r9 / self.r10,
              "integrator": 1.0,
              "summer": 1 + self.r5 * y_sum,
              "gain": 1 + self.r3 / self.r4}
        if self.has_derivative:
            ng["differentiator"] = 1 + self.r11 / self.r12
        return ng

    def stage_bandwidths(self, gbw_hz: float) -> dict:
        """Closed-loop bandwidth GBW / noise gain of each stage (Hz)."""
        return {k: gbw_hz / v for k, v in self.noise_gains().items()}

    def resistors(self) -> dict:
        out = {}
        for i in range(3, 19):
            v = getattr(self, f"r{i}")
            if v is not None:
                out[f"R{i}"] = v
        return out

    def capacitors(self) -> dict:
        return {k: v for k, v in (("C3", self.c3), ("C4", self.c4)) if v is not None}

    def to_dict(self) -> dict:
        d = {f"{k}_ohm": v for k, v in self.resistors().items()}
        d.update({f"{k}_f": v for k, v in self.capacitors().items()})
        return d

    @classmethod
    def from_dict(cls, d: dict) -> "PidParts":
        kw = {f"r{i}": d.get(f"R{i}_ohm") for i in range(3, 19)}
        kw.update(c3=d.get("C3_f"), c4=d.get("C4_f"))
        return cls(**kw)


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

    @property
    def worst_error_pct(self) -> float:
        return max(abs(v) for v in self.errors_pct.values())

    def objective(self) -> tuple:
        return objective(self.parts, self.targets, self.best_possible_pct / 100, self.tol)

    tol: float = 0.01


def objective(parts: PidParts, targets: dict, best: float, tol: float) -> tuple:
    """The quantity the selection minimises, lexicographically: the worst
    relative error of Kp, Ti, Td (errors at or below max(best, tol) count as
    equal), then the largest high-frequency noise gain of the summer, final
    gain and differentiator stages (smaller = more bandwidth)."""
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


def unity_resistor(series: str, lo: float, hi: float) -> float:
    """The value used where only equality matters (R9 = R10, R15..R18): 10 kOhm
    when the bounds allow it, else the series value nearest their geometric mean."""
    vals = eseries.values(series, lo, hi)
    if vals.size == 0:
        raise DesignError(f"no {series} resistor between {lo:g} and {hi:g} Ohm")
    target = 10e3 if lo <= 10e3 <= hi else math.sqrt(lo * hi)
    return float(vals[np.argmin(np.abs(np.log(vals / target)))])


def _check_targets(kp, ti, td):
    if not (math.isfinite(kp) and kp > 0):
        raise DesignError(f"Kp must be a finite number greater than 0, got {kp!r}")
    if not (math.isfinite(ti) and ti > 0):
        raise DesignError(f"Ti must be a finite time greater than 0 s, got {ti!r}")
    if not (math.isfinite(td) and td >= 0):
        raise DesignError(f"Td must be a finite time of 0 s or more, got {td!r}")


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


def _nearest_error(sorted_vals, targets):
    """Smallest |v/t - 1| over sorted_vals for each target."""
    idx = np.searchsorted(sorted_vals, targets)
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

    Returns
    -------
    Selection
    """
    _check_targets(kp, ti_s, td_s)
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
        sel.notes.append(f"{r_series}/{c_series} within the bounds cannot hit all of Kp, Ti, Td within "
                         f"{tol * 100:g} %; the best possible worst error is {best * 100:.3g} %")
    return sel


def _search(kp, ti, td, rv, cv, f_i, f_d, has_d, unity, tol):
    lo, hi = rv[0], min(rv[-1], max(R_CORNER_MAX, rv[0]))
    r13 = _corner_resistor(f_i, cv, rv, lo, hi)
    c4s, r13s = cv[~np.isnan(r13)], r13[~np.isnan(r13)]
    if c4s.size == 0:
        raise DesignError(f"no capacitor in the bounds gives an integrator corner of {f_i:.4g} Hz "
                          "with a resistor in the bounds; widen --r-min/--r-max or --c-min/--c-max")
    n = rv.size
    # Kp group: R5 R3 / R4 = Kp R6
    g5, g3, g4 = np.meshgrid(rv, rv, rv, indexing="ij")
    vk = (g5 * g3 / g4).ravel()
    ok = np.argsort(vk, kind="stable")
    vk_s = vk[ok]
    k5, k3, k4 = g5.ravel()[ok], g3.ravel()[ok], g4.ravel()[ok]
    # Ti group: R8 R14 C4 = Ti R6
    g8, g14, gc4 = np.meshgrid(rv, rv, np.arange(c4s.size), indexing="ij")
    vi = (g8 * g14 * c4s[gc4]).ravel()
    oi = np.argsort(vi, kind="stable")
    vi_s = vi[oi]
    i8, i14, ic4 = g8.ravel()[oi], g14.ravel()[oi], gc4.ravel()[oi]
    ncand = vk.size + vi.size
    if has_d:
        r12 = _corner_resistor(f_d, cv, rv, lo, hi)
        c3s, r12s = cv[~np.isnan(r12)], r12[~np.isnan(r12)]
        if c3s.size == 0:
            raise DesignError(f"no capacitor in the bounds gives a differentiator corner of {f_d:.4g} Hz "
                              "with a resistor in the bounds; widen the part bounds")
        # Td group: R11 C3 / R7 = Td / R6
        g11, g7, gc3 = np.meshgrid(rv, rv, np.arange(c3s.size), indexing="ij")
        vd = (g11 * c3s[gc3] / g7).ravel()
        od = np.argsort(vd, kind="stable")
        vd_s = vd[od]
        d11, d7, dc3 = g11.ravel()[od], g7.ravel()[od], gc3.ravel()[od]
        ngd_all = 1 + d11 / r12s[dc3]
        ncand += vd.size
    ek = _nearest_error(vk_s, kp * rv)
    ei = _nearest_error(vi_s, ti * rv)
    ed = _nearest_error(vd_s, td / rv) if has_d else np.zeros(n)
    worst = np.maximum(np.maximum(ek, ei), ed)
    best = float(np.min(worst))
    level = max(best, tol) * (1 + 1e-9)

    def window(sorted_vals, target):
        a = np.searchsorted(sorted_vals, target * (1 - level), "left")
        b = np.searchsorted(sorted_vals, target * (1 + level), "right")
        return slice(a, b)

    winner = None
    for j6, r6 in enumerate(rv):
        if worst[j6] > level:
            continue
        sk, si = window(vk_s, kp * r6), window(vi_s, ti * r6)
        # Kp options: for each R5 the smallest final-stage noise gain
        r5o, ngf = k5[sk], 1 + k3[sk] / k4[sk]
        if r5o.size == 0 or si.stop <= si.start:
            continue
        keep = _min_per_key(r5o, ngf, np.abs(np.log(k4[sk] / 1e4)))
        r5u, ngfu, kidx = r5o[keep], ngf[keep], np.arange(sk.start, sk.stop)[keep]
        # Ti: the largest R8 (it only enters the summer's noise gain)
        r8cand = i8[si]
        r8 = r8cand.max()
        # free choice among (R14, C4) for that R8: resistors nearest 10 kOhm
        cand = np.arange(si.start, si.stop)[r8cand == r8]
        spread = np.maximum(np.abs(np.log(i14[cand] / 1e4)), np.abs(np.log(r13s[ic4[cand]] / 1e4)))
        imax = int(cand[np.argmin(spread)])
        if has_d:
            sd = window(vd_s, td / r6)
            if sd.stop <= sd.start:
                continue
            r7o, ngdo = d7[sd], ngd_all[sd]
            keepd = _min_per_key(r7o, ngdo, np.abs(np.log(d11[sd] / 1e4)))
            r7u, ngdu, didx = r7o[keepd], ngdo[keepd], np.arange(sd.start, sd.stop)[keepd]
            inv7 = 1.0 / r7u
        else:
            r7u, ngdu, didx, inv7 = np.array([np.inf]), np.array([0.0]), np.array([-1]), np.array([0.0])
        ngs = 1 + r5u[:, None] * (1 / r6 + 1 / r8 + inv7[None, :])
        cost = np.maximum(np.maximum(ngs, ngfu[:, None]), ngdu[None, :])
        a, b = np.unravel_index(np.argmin(cost), cost.shape)
        c = float(cost[a, b])
        if winner is None or c < winner[0] * (1 - 1e-12):
            winner = (c, r6, kidx[a], imax, didx[b])
    if winner is None:  # pragma: no cover - best <= level guarantees a candidate
        raise DesignError("no part combination found; widen the bounds")
    _, r6, ik, ii, idd = winner
    c4 = float(c4s[ic4[ii]])
    parts = PidParts(
        r3=float(k3[ik]), r4=float(k4[ik]), r5=float(k5[ik]), r6=float(r6),
        r7=float(d7[idd]) if has_d else None, r8=float(i8[ii]), r9=unity, r10=unity,
        r11=float(d11[idd]) if has_d else None,
        r12=float(r12s[dc3[idd]]) if has_d else None,
        r13=float(r13s[ic4[ii]]), r14=float(i14[ii]),
        r15=unity, r16=unity, r17=unity, r18=unity,
        c3=float(c3s[dc3[idd]]) if has_d else None, c4=c4)
    return parts, best, ncand


def _min_per_key(keys, vals, tie):
    """Indices of the smallest ``vals`` entry for each distinct key (ties: smallest ``tie``)."""
    order = np.lexsort((tie, vals, keys))
    k = keys[order]
    first = np.ones(k.size, bool)
    first[1:] = k[1:] != k[:-1]
    return order[first]


def brute_force(kp: float, ti_s: float, td_s: float, fn_hz: float, *, r_series: str, c_series: str,
                r_min: float, r_max: float, c_min: float, c_max: float, tol: float = 0.01,
                f_integrator_hz=None, f_differentiator_hz=None):
    """Exhaustive reference for :func:`select_parts` on small candidate sets:
    every combination of R3, R4, R5, R6, R7, R8, R11, R14, C3, C4 (R12, R13 follow
    from the capacitors as in the search). Returns (best worst-error, best objective)."""
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


def static_checks(parts: PidParts, fn_hz: float, gbw_hz: float, targets: dict, *,
                  r_min: float, r_max: float, c_min: float, c_max: float, tol: float = 0.01) -> list:
    """Checks that need only the part values: accuracy of Kp/Ti/Td, the
    integrator and differentiator corners against fn, each stage's bandwidth
    against the highest frequency the controller handles, and the bounds.

    Returns a list of {name, ok, detail} dicts.
    """
    checks = []
    for key, label, unit in (("kp", "Kp", ""), ("ti_s", "Ti", "s"), ("td_s", "Td", "s")):
        want = targets[key]
        if key == "td_s" and not want:
            continue
        got = getattr(parts, key)
        e = got / want - 1
        checks.append({"name": f"{label.lower()}_accuracy", "ok": abs(e) <= tol * (1 + 1e-9),
                       "detail": f"{label} = {format_eng(got, unit)} for {format_eng(want, unit)} "
                                 f"({e * 100:+.2f} %, allowed +/-{tol * 100:g} %)"})
    fi = parts.f_integrator_hz
    checks.append({"name": "integrator_corner", "ok": fi <= fn_hz / CORNER_MARGIN,
                   "detail": f"1/(2 pi R13 C4) = {format_eng(fi, 'Hz')}, must be below fn/{CORNER_MARGIN:g} = "
                             f"{format_eng(fn_hz / CORNER_MARGIN, 'Hz')} (fn = {format_eng(fn_hz, 'Hz')})"})
    if parts.has_derivative:
        fd = parts.f_differentiator_hz
        checks.append({"name": "differentiator_corner", "ok": fd >= fn_hz * CORNER_MARGIN,
                       "detail": f"1/(2 pi R12 C3) = {format_eng(fd, 'Hz')}, must be above "
                                 f"{CORNER_MARGIN:g} fn = {format_eng(fn_hz * CORNER_MARGIN, 'Hz')}"})
        f_need, why = fd, "the differentiator corner"
    else:
        f_need, why = CORNER_MARGIN * fn_hz, f"{CORNER_MARGIN:g} fn"
    ng = parts.noise_gains()
    for stage, bw in parts.stage_bandwidths(gbw_hz).items():
        checks.append({"name": f"bandwidth_{stage}", "ok": bw >= f_need,
                       "detail": f"GBW/noise gain = {format_eng(gbw_hz, 'Hz')}/{ng[stage]:.3g} = "
                                 f"{format_eng(bw, 'Hz')}, must be above {why} ({format_eng(f_need, 'Hz')})"})
    rs, cs = parts.resistors(), parts.capacitors()
    bad_r = [f"{k} = {format_eng(v, 'Ohm')}" for k, v in rs.items()
             if not r_min * (1 - 1e-9) <= v <= r_max * (1 + 1e-9)]
    bad_c = [f"{k} = {format_eng(v, 'F')}" for k, v in cs.items()
             if not c_min * (1 - 1e-9) <= v <= c_max * (1 + 1e-9)]
    checks.append({"name": "resistor_bounds", "ok": not bad_r,
                   "detail": (f"all resistors within {format_eng(r_min, 'Ohm')}..{format_eng(r_max, 'Ohm')} "
                              f"(smallest {format_eng(min(rs.values()), 'Ohm')}, largest "
                              f"{format_eng(max(rs.values()), 'Ohm')})") if not bad_r
                   else "outside the bounds: " + ", ".join(bad_r)})
    checks.append({"name": "capacitor_bounds", "ok": not bad_c,
                   "detail": (f"all capacitors within {format_eng(c_min, 'F')}..{format_eng(c_max, 'F')}")
                   if not bad_c else "outside the bounds: " + ", ".join(bad_c)})
    return checks


def seed_parts() -> PidParts:
    """The seed's own controller (lines ~3263-3330), with the difference
    amplifier as designed (all 10 kOhm) rather than the bench-trimmed values."""
    return PidParts(r3=12e3, r4=1.777e3, r5=22e3, r6=3.3e3, r7=14.356e3, r8=1.2e3, r9=10e3,
                    r10=10e3, r11=10e3, r12=1.026e3, r13=26.048e3, r14=2.528e3, r15=10e3,
                    r16=10e3, r17=10e3, r18=10e3, c3=4.7e-9, c4=47e-9)


def continuous_parts(kp: float, ti_s: float, td_s: float, fn_hz: float, *,
                     f_integrator_hz: float | None = None, f_differentiator_hz: float | None = None,
                     r: float = 10e3) -> PidParts:
    """Exact (unrounded) parts with a fixed, balanced structure, for searching
    gains before any part is chosen: R6 = R7 = R8 = R9 = R10 = R14 = R15..R18 = r,
    R11 C3 = Td, R14 C4 = Ti, corners as in :func:`select_parts`, and Kp split
    between the summer and the final gain so that their noise gains match
    (1 + 3 g = 1 + Kp/g, g = sqrt(Kp/3); 1 + 2 g and g = sqrt(Kp/2) for a PI)."""
    _check_targets(kp, ti_s, td_s)
    f_i = fn_hz * F_INTEGRATOR_RATIO if f_integrator_hz is None else f_integrator_hz
    f_d = fn_hz * F_DIFFERENTIATOR_RATIO if f_differentiator_hz is None else f_differentiator_hz
    has_d = td_s > 0
    g = math.sqrt(kp / (3.0 if has_d else 2.0))
    c4 = ti_s / r
    c3 = td_s / r if has_d else None
    return PidParts(r3=r * kp / g, r4=r, r5=g * r, r6=r, r7=r if has_d else None, r8=r, r9=r, r10=r,
                    r11=r if has_d else None,
                    r12=1.0 / (2 * math.pi * f_d * c3) if has_d else None,
                    r13=1.0 / (2 * math.pi * f_i * c4), r14=r, r15=r, r16=r, r17=r, r18=r,
                    c3=c3, c4=c4)
