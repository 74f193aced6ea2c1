"""Choosing the four Sallen-Key parts jointly from E-series values.

The objective is the worse of the two relative errors,
``max(|fn/fn0 - 1|, |zeta/zeta0 - 1|)``. Rounding each part on its own is
typically 1-7 % off; searching the candidate grid jointly finds combinations
well under 1 %.

The search is exact over its candidate set (the series values inside the
bounds), without visiting all of it. With ``p = R1 R2`` and
``u = sqrt(R1/R2)`` the two figures separate:

    fn = 1 / (2 pi sqrt(p C1 C2)),  zeta = (alpha u + C1/u) / (2 sqrt(C1 C2)),
    alpha = C1 + C2 (1 - K),

so for one capacitor pair the resistors within ``eps`` of both targets are
those with ``p`` in a band (fn) and ``u`` in at most two intervals (zeta; the
roots of a quadratic in ``u``): a thin parallelogram in (log R1, log R2),
enumerated in closed form.

1. seed: for capacitor pairs spread over the grid (all of them on small
   grids), the exact resistor solution's nearest series neighbours (moved
   into the bounds along R1/R2 when outside them) are ranked, and the k-th
   best gives an error bound eps;
2. enumerate: for every capacitor pair, every R1 inside the parallelogram for
   eps and, for each, the R2 range that satisfies both bands; all are
   evaluated and ranked, and the running k-th best tightens eps as it goes.

The ranking is by the worse error rounded to 1e-12, then the summed error,
then the values. Near 100 % off (fn decades below its target) a great many
combinations round to the same worse error and the summed error ranks them;
there the parallelogram becomes three (the better rounding classes, and the
k-th's class with the other error bounded by the summed error), see
``_Best.boxes``.

Nothing that ranks before the k-th best found so far lies outside the
parallelograms, so the top k equal those of brute force (tests check it
against :func:`brute_force`). Capacitor pairs, rows (pair, R1) and candidates
are handled in chunks of fixed size, so memory stays bounded (tens of MB) for
any series and bounds; time grows with the number of capacitor pairs (a
fraction of a second for E192/E192 with the default bounds, about one second
for the widest bounds the CLI accepts).
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

from .sallen_key_lowpass_synthesis import fn_zeta, resistors_for_caps

__all__ = ["Candidate", "around", "brute_force", "joint_search", "scored"]


@dataclass(frozen=True)
class Candidate:
    """One combination of parts and how close it lands.

    Parameters
    ----------
    r1, r2 : float
        The input resistor and the resistor to the non-inverting input (ohm).
    c1, c2 : float
        The capacitor to ground and the feedback capacitor (farad).
    fn_hz, zeta : float
        What the combination gives.
    fn_error, zeta_error : float
        Relative, signed, against the target.
    """

    r1: float
    r2: float
    c1: float
    c2: float
    fn_hz: float
    zeta: float
    fn_error: float    #: relative, signed
    zeta_error: float  #: relative, signed

    @property
    def worst(self) -> float:
        return max(abs(self.fn_error), abs(self.zeta_error))


#: Capacitor pairs, rows (pair, R1) and candidates handled at once: these bound
#: the search's memory (each array of a chunk is at most a few MB).
PAIRS_PER_CHUNK = 1 << 13
ROWS_PER_BATCH = 1 << 17
#: Capacitor pairs that seed the first ranking (the enumeration tightens its bound).
SEED_PAIRS = 1 << 15
#: Relative widening of every band and interval, and absolute widening of eps
#: in them (errors are computed as x/x0 - 1: their rounding is absolute): float
#: rounding must never drop a combination that belongs (extra ones are just
#: evaluated and ranked).
_SLACK = 1e-9
_ABS_SLACK = 1e-13


def _score(r1, r2, c1, c2, fn0, zeta0, gain):
    fn, z = fn_zeta(r1, r2, c1, c2, gain)
    efn = fn / fn0 - 1.0
    ez = z / zeta0 - 1.0
    worst = np.maximum(np.abs(efn), np.abs(ez))
    return fn, z, efn, ez, worst


def _order(r1, r2, c1, c2, fn0, zeta0, gain):
    """Indices of the combinations, best first, and their worst errors.

    The order is total (worse error rounded to 1e-12, summed error, then the
    values), so the best k of a union are the best k of the parts' best k.
    """
    _, _, efn, ez, worst = _score(r1, r2, c1, c2, fn0, zeta0, gain)
    secondary = np.abs(efn) + np.abs(ez)
    return np.lexsort((c2, c1, r2, r1, secondary, np.round(worst, 12))), worst


def _rank(r1, r2, c1, c2, fn0, zeta0, gain, top):
    order = _order(r1, r2, c1, c2, fn0, zeta0, gain)[0][:top]
    return scored(r1[order], r2[order], c1[order], c2[order], fn0, zeta0, gain)


def scored(r1, r2, c1, c2, fn0: float, zeta0: float, gain: float = 1.0) -> list:
    """Combinations as :class:`Candidate` (what each gives, its errors against the targets), in
    the order given (the plant's generic search ranks them: :func:`designer.plant.circuit.search`).

    Parameters
    ----------
    r1, r2, c1, c2 : array_like
        The parts of each combination (ohm, farad), one array each.
    fn0, zeta0 : float
        The targets: natural frequency (Hz) and damping ratio.
    gain : float
        The amplifier gain K.

    Returns
    -------
    list of Candidate
        One per combination, in the order given.
    """
    r1, r2, c1, c2 = (np.asarray(x, float) for x in (r1, r2, c1, c2))
    fn, z, efn, ez, _ = _score(r1, r2, c1, c2, fn0, zeta0, gain)
    return [Candidate(float(r1[i]), float(r2[i]), float(c1[i]), float(c2[i]), float(fn[i]),
                      float(z[i]), float(efn[i]), float(ez[i])) for i in range(r1.size)]


def _bound(kth_worst):
    """eps that keeps every combination in the k-th best's class of the ranking's
    rounding to 1e-12 or a better one (anything worse than eps ranks strictly
    after it): the class's upper edge, with a margin for the rounding's own
    floating point. (A margin relative to eps would not do: near 100 % off,
    1e-9 of eps is more than what separates the best combinations.)"""
    return float(np.round(kth_worst, 12)) + 0.5e-12 + 1e-14 * (1 + kth_worst)


def _neighbours(sorted_vals, x, width=1):
    """Indices of the ``width`` series values on each side of x (clipped), on a new last axis."""
    hi = np.searchsorted(sorted_vals, x)[..., None] + np.arange(-width, width)
    return np.clip(hi, 0, len(sorted_vals) - 1)


def _pair_chunks(n, per=None, stride=1):
    """Index arrays (i1, i2) over every ``stride``-th of the n x n capacitor pairs,
    ``per`` (default PAIRS_PER_CHUNK) at a time."""
    per = per or PAIRS_PER_CHUNK
    for start in range(0, n * n, per * stride):
        k = np.arange(start, min(start + per * stride, n * n), stride)
        yield k // n, k % n


def _seed_stride(n):
    """A stride through the n x n pairs that visits about SEED_PAIRS of them and, being
    prime to n, every C1 and every C2."""
    stride = max(1, -(-n * n // SEED_PAIRS))
    while math.gcd(stride, n) != 1:
        stride += 1
    return stride


def _batches(counts, budget=None):
    """Slices of consecutive entries whose counts sum to at most ``budget`` (default
    ROWS_PER_BATCH), or a single entry."""
    budget = budget or ROWS_PER_BATCH
    cum = np.cumsum(counts)
    start = 0
    while start < counts.size:
        base = cum[start - 1] if start else 0
        stop = max(int(np.searchsorted(cum, base + budget, side="right")), start + 1)
        yield slice(start, stop)
        start = stop


def _expand(starts, counts):
    """Each entry's run ``starts[i] .. starts[i] + counts[i] - 1``: (entry, value) arrays."""
    owner = np.repeat(np.arange(counts.size), counts)
    first = np.cumsum(counts) - counts
    return owner, starts[owner] + np.arange(owner.size) - first[owner]


def _seed(rv, cv, best):
    """Give ``best`` a first top: for capacitor pairs spread over the grid, R1 next
    to each exact resistor solution (R1 = R2 = sqrt(R1 R2) when there is none),
    moved into the bounds along its ratio R1/R2 when outside them, and R2 next
    to the partner for exact fn and to the one for the exact ratio; ``width``
    neighbours on each side, more when there are few capacitor pairs, so that
    the seeds outnumber ``top`` many times over.
    """
    fn0, zeta0, gain = best.args
    width = int(min(rv.size, np.ceil(np.sqrt(4.0 * best.top / cv.size ** 2))))
    wn = 2 * np.pi * fn0
    rmin, rmax = rv[0], rv[-1]
    for i1, i2 in _pair_chunks(cv.size, max(1, PAIRS_PER_CHUNK // width ** 2), _seed_stride(cv.size)):
        c1, c2 = cv[i1], cv[i2]
        prod = 1.0 / (wn * wn * c1 * c2)            # R1 R2 for exact fn
        geo = np.sqrt(prod)
        roots = np.stack([np.where(np.isnan(r), geo, r) for r in resistors_for_caps(fn0, zeta0, c1, c2, gain)],
                         axis=1)
        ratio = roots * roots / prod[:, None]       # R1/R2 of the exact solution
        lo, hi = np.maximum(rmin, rmin * ratio), np.minimum(rmax, rmax * ratio)
        roots = np.where(lo <= hi, np.clip(roots, lo, hi), roots)
        j1 = _neighbours(rv, roots, width)                                   # (pair, root, 2w)
        r1 = rv[j1][..., None]
        j2 = _neighbours(rv, np.concatenate([prod[:, None, None, None] / r1, r1 / ratio[..., None, None]],
                                            axis=-1), width)                 # (pair, root, 2w, 2, 2w)
        j1 = np.broadcast_to(j1[..., None, None], j2.shape)
        pair = np.broadcast_to(np.arange(i1.size)[:, None, None, None, None], j2.shape)
        best.add(rv[j1].ravel(), rv[j2].ravel(), c1[pair].ravel(), c2[pair].ravel())


def _fn_band(fn0, eps, c1, c2):
    """[plo, phi]: the products R1 R2 within eps of fn0 for each pair (widened by the slack)."""
    wn = 2 * np.pi * fn0
    prod = 1.0 / (wn * wn * c1 * c2)
    eps = eps + _ABS_SLACK
    plo = prod / (1 + eps) / (1 + eps) * (1 - _SLACK)   # (1 + eps)**2 could overflow a float
    phi = prod / (1 - eps) ** 2 * (1 + _SLACK) if eps < 1 else np.full_like(prod, np.inf)
    return plo, phi


def _below(z, alpha, c1, q):
    """The interval [lo, hi] of u > 0 where (alpha u + c1/u) / q <= z, and where it is empty.

    It is where alpha u^2 - q z u + c1 <= 0: between the two roots for alpha > 0,
    above the positive root otherwise (hi = inf). The small root is taken as
    2 c1 / (q z + sqrt(disc)), which does not cancel.
    """
    # z may be +-inf (eps = inf: no bound yet) and disc negative (no root):
    # the nan and inf that follow are masked out just below
    with np.errstate(invalid="ignore", divide="ignore", over="ignore"):
        qz = q * z
        disc = qz * qz - 4 * alpha * c1
        s = qz + np.sqrt(np.maximum(disc, 0.0))
        lo = 2 * c1 / s
        hi = np.where(alpha > 0, s / (2 * alpha), np.inf)
    empty = ~(s > 0) | (disc < 0) | ~(lo <= hi)
    return lo, hi, empty


def _zeta_sets(zeta0, eps, c1, c2, gain):
    """{u: zeta <= zeta0 (1 + eps)} and {u: zeta <= zeta0 (1 - eps)}, the
    first widened and the second narrowed by the slack, as (lo, hi, empty) each."""
    alpha = c1 + c2 * (1.0 - gain)
    q = 2 * np.sqrt(c1 * c2)
    eps = eps + _ABS_SLACK
    with np.errstate(invalid="ignore", over="ignore"):  # eps = inf: zhi = inf, zlo = -inf
        zhi = zeta0 * (1 + eps)
        zlo = zeta0 * (1 - eps)
    a_lo, a_hi, a_empty = _below(zhi + _SLACK * abs(zhi), alpha, c1, q)
    b_lo, b_hi, b_empty = _below(zlo - _SLACK * abs(zlo) if np.isfinite(zlo) else zlo, alpha, c1, q)
    return (a_lo * (1 - _SLACK), a_hi * (1 + _SLACK), a_empty), (b_lo * (1 + _SLACK), b_hi * (1 - _SLACK), b_empty)


def _zeta_parts(zeta0, eps, c1, c2, gain):
    """The intervals of u = sqrt(R1/R2) where |zeta/zeta0 - 1| <= eps for each
    pair (c1[i], c2[i]), with the slack.

    zeta is (alpha u + C1/u) / (2 sqrt(C1 C2)): the set is {zeta <= zhi} (one
    interval) minus {zeta < zlo} (one interval inside it, or none), so a pair
    has at most two disjoint parts. Returns (pair index, lo, hi) of the
    non-empty parts.
    """
    (a_lo, a_hi, a_empty), (b_lo, b_hi, b_empty) = _zeta_sets(zeta0, eps, c1, c2, gain)
    b_empty = b_empty | ~(b_hi > b_lo * (1 + 1e-6))       # too thin to take out: keep one part
    a_hi = np.where(a_empty, -np.inf, a_hi)
    lo = np.concatenate([a_lo, np.where(b_empty, np.inf, np.maximum(a_lo, b_hi))])
    hi = np.concatenate([np.where(b_empty, a_hi, np.minimum(a_hi, b_lo)), a_hi])
    keep = (lo <= hi) & (lo < np.inf)
    return np.flatnonzero(keep) % c1.size, lo[keep], hi[keep]


def _r2_range(rv, r1, plo, phi, ulo, uhi):
    """First index and end of the R2 values with R1 R2 in [plo, phi] and sqrt(R1/R2) in [ulo, uhi]."""
    with np.errstate(divide="ignore", invalid="ignore"):  # u from 0 or to inf: no bound that side
        lo = np.maximum(plo / r1, r1 / (uhi * uhi))
        hi = np.minimum(phi / r1, r1 / (ulo * ulo))
    return np.searchsorted(rv, lo, side="left"), np.searchsorted(rv, hi, side="right")


def _r1_range(rv, plo, phi, ulo, uhi):
    """First index and end of the R1 values that can have an R2 in ``rv``, for
    each band [plo, phi] of R1 R2 and interval [ulo, uhi] of sqrt(R1/R2).

    R1 = sqrt(R1 R2) u, and R2 = R1 R2 / R1 = R1 / u^2 must lie between rv's ends.
    """
    rmin, rmax = rv[0], rv[-1]
    with np.errstate(invalid="ignore", over="ignore"):  # u = 0 with p = inf and the like: no bound
        lo = np.maximum(np.maximum(np.sqrt(plo) * ulo, plo / rmax), ulo * ulo * rmin)
        hi = np.minimum(np.minimum(np.sqrt(phi) * uhi, phi / rmin), uhi * uhi * rmax)
    return np.searchsorted(rv, lo * (1 - 1e-12), side="left"), np.searchsorted(rv, hi * (1 + 1e-12), side="right")


def _union(owner, start, stop, n):
    """The union of the index ranges [start, stop) (values below n) of each owner,
    as disjoint ranges: (owner, start, count), empty ones dropped."""
    order = np.lexsort((start, owner))
    owner, start, stop = owner[order], start[order], stop[order]
    # how far the owner's earlier ranges reach (an owner's key is above every earlier owner's)
    reach = np.maximum.accumulate(owner * (n + 1) + stop) - owner * (n + 1)
    before = np.concatenate([[0], reach[:-1]])
    before[np.concatenate([[True], owner[1:] != owner[:-1]])] = 0
    start = np.maximum(start, before)
    live = stop > start
    return owner[live], start[live], (stop - start)[live]


def _ranges(rv, fn0, zeta0, gain, boxes, c1, c2, r1=None):
    """Index ranges of R1 (``r1`` None: per pair) or of R2 (per row: pair and R1)
    inside the union of the error boxes, as disjoint (owner, start, count)."""
    owner, start, stop = [], [], []
    for e_fn, e_z in boxes:
        i, ulo, uhi = _zeta_parts(zeta0, e_z, c1, c2, gain)
        plo, phi = _fn_band(fn0, e_fn, c1[i], c2[i])
        a, z = _r1_range(rv, plo, phi, ulo, uhi) if r1 is None else _r2_range(rv, r1[i], plo, phi, ulo, uhi)
        owner.append(i), start.append(a), stop.append(z)
    return _union(np.concatenate(owner), np.concatenate(start), np.concatenate(stop), rv.size)


class _Best:
    """The best ``top`` combinations so far, and the error boxes that hold every
    combination that can still rank among them."""

    def __init__(self, fn0, zeta0, gain, top):
        self.args = (fn0, zeta0, gain)
        self.top = top
        self.eps = np.inf              # every combination in the top has its errors within eps
        self.kth = None                # (worst, summed) errors of the top-th best
        self.parts = np.empty((4, 0))  # rows r1, r2, c1, c2

    def add(self, r1, r2, c1, c2):
        cand = np.concatenate([self.parts, np.stack([r1, r2, c1, c2])], axis=1)
        order, worst = _order(*cand, *self.args)
        cand, worst = cand[:, order], worst[order]
        # a combination can come twice (seeds, overlapping boxes): equal ones sort together
        new = np.concatenate([[True], np.any(cand[:, 1:] != cand[:, :-1], axis=0)])
        self.parts, worst = cand[:, new][:, :self.top], worst[new][:self.top]
        if worst.size == self.top:
            _, _, efn, ez, _ = _score(*self.parts[:, -1], *self.args)
            self.kth = (float(worst[-1]), abs(float(efn)) + abs(float(ez)))
            self.eps = min(self.eps, _bound(self.kth[0]))

    def boxes(self):
        """(fn error bound, zeta error bound) pairs; a combination outside all of them ranks after the top.

        One box, eps for both, except near 100 % off: there the errors saturate
        (fn far below its target gives |fn error| within 1e-12 of 1 for a great
        many combinations), the ranking's rounding to 1e-12 ties them and the
        summed error decides. Then a combination ranks before the k-th only if
        it is in a better rounding class (errors below W - 0.5e-12) or in the
        same one with a summed error at most S: the one error that is not the
        worse is then at most S - W + 0.5e-12.
        """
        if self.kth is None or abs(np.round(self.kth[0], 12) - 1) > 1e-6:
            return [(self.eps, self.eps)]
        w_k = float(np.round(self.kth[0], 12))
        better = w_k - 0.5e-12 + 2e-14                    # the better classes
        other = min(self.eps, self.kth[1] - w_k + 1e-12)
        return [(better, better), (self.eps, other), (other, self.eps)]


def _search_pairs(rv, c1, c2, best):
    """Evaluate every combination inside ``best``'s boxes for the pairs (c1[i], c2[i]).

    Pairs go in groups of at most ROWS_PER_BATCH R2 ranges (pair, R1, box,
    zeta part), rows in batches of at most ROWS_PER_BATCH combinations; the
    ranges are recomputed with the tightened boxes before each group and each
    batch, so a loose first bound costs one batch, not the whole grid.
    """
    fn0, zeta0, gain = best.args
    while c1.size:
        boxes = best.boxes()
        pair, first, rows = _ranges(rv, fn0, zeta0, gain, boxes, c1, c2)
        # a row has up to two ranges of R2 per box: the group's ranges fit in one batch
        group = next(_batches(np.bincount(pair, rows, c1.size).astype(int), ROWS_PER_BATCH // (2 * len(boxes))))
        mine = pair < group.stop
        row, i1 = _expand(first[mine], rows[mine])
        g1, g2, r1 = c1[pair[mine][row]], c2[pair[mine][row]], rv[i1]
        while r1.size:
            row, start, count = _ranges(rv, fn0, zeta0, gain, best.boxes(), g1, g2, r1)
            per_row = np.bincount(row, count, r1.size).astype(int)
            live = per_row > 0
            if not live.any():
                break
            # renumber the live rows, take those that fit in one batch
            number = np.cumsum(live) - 1
            g1, g2, r1, per_row = g1[live], g2[live], r1[live], per_row[live]
            keep = live[row]
            row, start, count = number[row[keep]], start[keep], count[keep]
            sl = next(_batches(per_row))
            mine = row < sl.stop
            k, i2 = _expand(start[mine], count[mine])
            take = row[mine][k]
            best.add(r1[take], rv[i2], g1[take], g2[take])
            g1, g2, r1 = g1[sl.stop:], g2[sl.stop:], r1[sl.stop:]
        c1, c2 = c1[group.stop:], c2[group.stop:]


def joint_search(fn0: float, zeta0: float, r_values, c_values, gain: float = 1.0,
                 top: int = 5) -> list:
    """Best ``top`` combinations of R1, R2 (from ``r_values``) and C1, C2
    (from ``c_values``) for the targets, best first.

    Exactly those of :func:`brute_force`, in bounded memory (see the module
    docstring for the method).

    Parameters
    ----------
    fn0, zeta0 : float
        Targets: natural frequency (Hz) and damping ratio.
    r_values, c_values : array_like
        Candidate resistor and capacitor values (any order).
    gain : float
        Achieved amplifier gain K.
    top : int
        How many combinations to return.

    Returns
    -------
    list of Candidate
    """
    rv = np.unique(np.asarray(r_values, float))
    cv = np.unique(np.asarray(c_values, float))
    if rv.size == 0 or cv.size == 0 or top < 1:
        return []
    best = _Best(fn0, zeta0, gain, top)
    _seed(rv, cv, best)
    for i1, i2 in _pair_chunks(cv.size):
        _search_pairs(rv, cv[i1], cv[i2], best)
    return _rank(*best.parts, fn0, zeta0, gain, top)


def brute_force(fn0: float, zeta0: float, r_values, c_values, gain: float = 1.0,
                top: int = 5) -> list:
    """Every combination, evaluated: the reference :func:`joint_search` must match.

    Parameters
    ----------
    fn0 : float
        The natural frequency wanted.
    zeta0 : float
        The damping wanted.
    r_values, c_values : array_like
        The candidate values.
    gain : float
        The gain K.
    top : int
        The best kept.

    Returns
    -------
    list of Candidate
        The best, ranked.
    """
    rv = np.unique(np.asarray(r_values, float))
    cv = np.unique(np.asarray(c_values, float))
    r1, r2, c1, c2 = (g.ravel() for g in np.meshgrid(rv, rv, cv, cv, indexing="ij"))
    return _rank(r1, r2, c1, c2, fn0, zeta0, gain, top)


def around(value: float, series_values, k: int = 2) -> np.ndarray:
    """The ``k`` series values on each side of ``value`` (for rounding a fixed design jointly).

    Parameters
    ----------
    value : float
        The continuous value.
    series_values : array_like
        The series values (any order).
    k : int
        How many on each side.

    Returns
    -------
    ndarray
        Ascending: the ``k`` below ``value`` and the ``k`` at or above it (fewer at the series' ends).
    """
    v = np.unique(np.asarray(series_values, float))
    i = int(np.searchsorted(v, value))
    return v[max(0, i - k): i + k]
