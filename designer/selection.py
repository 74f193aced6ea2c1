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

1. bound: for capacitor pairs spread over the grid (all of them on small
   grids), the exact resistor solution's nearest series neighbours give
   distinct candidates, and so an error bound eps (the k-th best found);
2. enumerate: for every capacitor pair, every R1 inside the parallelogram for
   eps and, for each, the R2 range that satisfies both bands; all are
   evaluated and ranked, and the running k-th best tightens eps as it goes.

Nothing better than the k-th best found so far lies outside the
parallelograms, so the top k equal those of brute force (tests check it
against :func:`brute_force`). Capacitor pairs, rows (pair, R1) and candidates
are handled in chunks of fixed size, so memory stays bounded (tens of MB) for
any series and bounds; time grows with the number of capacitor pairs (a
fraction of a second for E192/E192 with the default bounds, one to two
seconds for the widest bounds the CLI accepts).
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

from .sallenkey import fn_zeta, resistors_for_caps


@dataclass(frozen=True)
class Candidate:
    """One combination of parts and how close it lands."""

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
ROWS_PER_BATCH = 1 << 18
#: Capacitor pairs that seed the first error bound (the enumeration tightens it).
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
    fn, z, efn, ez, _ = _score(r1[order], r2[order], c1[order], c2[order], fn0, zeta0, gain)
    return [Candidate(float(r1[i]), float(r2[i]), float(c1[i]), float(c2[i]), float(fn[j]),
                      float(z[j]), float(efn[j]), float(ez[j])) for j, i in enumerate(order)]


def _bound(kth_worst):
    """eps that keeps every combination tied with the k-th best after the ranking's
    rounding to 1e-12 (anything worse than eps ranks strictly after it). A margin
    relative to eps itself would not do: near 100 % off (targets out of reach)
    1e-9 of eps is more than what separates the best combinations."""
    return kth_worst * (1 + 1e-12) + 2e-12


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


def _seed_bound(fn0, zeta0, rv, cv, gain, top):
    """An upper bound on the ``top``-th best worst error (inf with fewer distinct seeds).

    Seeds: for each capacitor pair, R1 next to each exact root (or to sqrt(R1 R2)
    when there is none) and R2 next to the product's partner; ``width``
    neighbours on each side, more when there are few capacitor pairs, so
    that the seeds outnumber ``top`` many times over.
    """
    n_pairs = cv.size * cv.size
    width = int(min(rv.size, np.ceil(np.sqrt(64.0 * top / (8.0 * n_pairs)))))
    per_pair = 8 * width ** 2
    # a combination is seeded at most per_pair times: so many times top smallest
    # entries hold top distinct combinations, and only they need deduplicating
    keep = top * per_pair
    wn = 2 * np.pi * fn0
    kept = np.empty((0, 3))  # worst, combination code, pair
    for i1, i2 in _pair_chunks(cv.size, max(1, PAIRS_PER_CHUNK // width ** 2), _seed_stride(cv.size)):
        c1, c2 = cv[i1], cv[i2]
        lo_root, hi_root = resistors_for_caps(fn0, zeta0, c1, c2, gain)
        prod = 1.0 / (wn * wn * c1 * c2)           # R1 R2 for exact fn
        geo = np.sqrt(prod)                         # the nearest one can get when no root
        roots = np.stack([np.where(np.isnan(r), geo, r) for r in (lo_root, hi_root)], axis=1)
        j1 = _neighbours(rv, roots, width)                        # (pair, root, 2w)
        j2 = _neighbours(rv, prod[:, None, None] / rv[j1], width)  # (pair, root, 2w, 2w)
        j1 = np.broadcast_to(j1[..., None], j2.shape).reshape(i1.size, -1)
        j2 = j2.reshape(i1.size, -1)
        worst = _score(rv[j1], rv[j2], c1[:, None], c2[:, None], fn0, zeta0, gain)[4].ravel()
        code = (j1 * rv.size + j2).ravel()
        pair = np.repeat(i1 * cv.size + i2, per_pair)
        if worst.size > keep:
            sel = np.argpartition(worst, keep - 1)[:keep]
            worst, code, pair = worst[sel], code[sel], pair[sel]
        kept = np.concatenate([kept, np.column_stack([worst, code, pair])])
        if kept.shape[0] > keep:
            kept = kept[np.argpartition(kept[:, 0], keep - 1)[:keep]]
    worst = np.unique(kept, axis=0)[:, 0]   # the same combination can be seeded several times
    worst = worst[np.isfinite(worst)]
    return _bound(float(np.partition(worst, top - 1)[top - 1])) if worst.size >= top else np.inf


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


def _zeta_parts(zeta0, eps, c1, c2, gain, lo, hi):
    """The parts of the intervals [lo, hi] of u = sqrt(R1/R2) (one per entry)
    where |zeta/zeta0 - 1| <= eps, with the slack.

    zeta is (alpha u + C1/u) / (2 sqrt(C1 C2)): the set is {zeta <= zhi} (one
    interval) minus {zeta < zlo} (one interval inside it, or none), so each
    entry has at most two disjoint parts. Returns (entry index, lo, hi) of the
    non-empty parts.
    """
    (a_lo, a_hi, a_empty), (b_lo, b_hi, b_empty) = _zeta_sets(zeta0, eps, c1, c2, gain)
    b_empty = b_empty | ~(b_hi > b_lo * (1 + 1e-6))       # too thin to take out: keep one part
    lo = np.maximum(lo, a_lo)
    hi = np.where(a_empty, -np.inf, np.minimum(hi, a_hi))
    lo2 = np.concatenate([lo, np.where(b_empty, np.inf, np.maximum(lo, b_hi))])
    hi2 = np.concatenate([np.where(b_empty, hi, np.minimum(hi, b_lo)), hi])
    keep = (lo2 <= hi2) & (lo2 < np.inf)
    return np.flatnonzero(keep) % c1.size, lo2[keep], hi2[keep]


def _r2_range(rv, r1, plo, phi, ulo, uhi):
    """First index and count of the R2 values with R1 R2 in [plo, phi] and sqrt(R1/R2) in [ulo, uhi]."""
    with np.errstate(divide="ignore", invalid="ignore"):  # u from 0 or to inf: no bound that side
        lo = np.maximum(plo / r1, r1 / (uhi * uhi))
        hi = np.minimum(phi / r1, r1 / (ulo * ulo))
    start = np.searchsorted(rv, lo, side="left")
    count = np.searchsorted(rv, hi, side="right") - start
    count[~(ulo <= uhi) | (count < 0)] = 0
    return start, count


def _r1_rows(rv, plo, phi, ulo, uhi):
    """First index and count of the R1 values that can have an R2 in ``rv`` for each
    band [plo, phi] of R1 R2 and interval [ulo, uhi] of sqrt(R1/R2).

    R1 = sqrt(R1 R2) u, and R2 = R1 R2 / R1 = R1 / u^2 must lie between rv's ends.
    """
    rmin, rmax = rv[0], rv[-1]
    with np.errstate(invalid="ignore", over="ignore"):  # u = 0 with p = inf and the like: no bound
        lo = np.maximum(np.maximum(np.sqrt(plo) * ulo, plo / rmax), ulo * ulo * rmin)
        hi = np.minimum(np.minimum(np.sqrt(phi) * uhi, phi / rmin), uhi * uhi * rmax)
    first = np.searchsorted(rv, lo * (1 - 1e-12), side="left")
    rows = np.maximum(np.searchsorted(rv, hi * (1 + 1e-12), side="right") - first, 0)
    return first, rows


class _Best:
    """The best ``top`` combinations so far and the error bound eps they set."""

    def __init__(self, fn0, zeta0, gain, top, eps):
        self.args = (fn0, zeta0, gain)
        self.top = top
        self.eps = eps
        self.parts = np.empty((4, 0))  # rows r1, r2, c1, c2

    def add(self, r1, r2, c1, c2):
        cand = np.concatenate([self.parts, np.stack([r1, r2, c1, c2])], axis=1)
        order, worst = _order(*cand, *self.args)
        self.parts = cand[:, order[:self.top]]
        if order.size >= self.top:
            self.eps = min(self.eps, _bound(float(worst[order[self.top - 1]])))


def _search_pairs(zeta0, rv, c1, c2, best):
    """Evaluate every combination within ``best.eps`` for the pairs (c1[i], c2[i]).

    Pairs go in groups of at most ROWS_PER_BATCH rows (pair, zeta part, R1),
    rows in batches of at most ROWS_PER_BATCH combinations; the bands are
    recomputed with the tightened eps before each group and each batch, so a
    loose first bound costs one batch, not the whole grid.
    """
    fn0, _, gain = best.args
    while c1.size:
        pair, ulo, uhi = _zeta_parts(zeta0, best.eps, c1, c2, gain, 0.0, np.inf)
        plo, phi = _fn_band(fn0, best.eps, c1[pair], c2[pair])
        first, rows = _r1_rows(rv, plo, phi, ulo, uhi)
        group = next(_batches(np.bincount(pair, rows, c1.size).astype(int)))
        mine = pair < group.stop
        part, i1 = _expand(first[mine], rows[mine])
        pair, lo_u, hi_u = pair[mine][part], ulo[mine][part], uhi[mine][part]
        g1, g2, r1 = c1[pair], c2[pair], rv[i1]
        while r1.size:
            # the row's u interval, within the zeta band for the current eps
            keep, lo_u, hi_u = _zeta_parts(zeta0, best.eps, g1, g2, gain, lo_u, hi_u)
            g1, g2, r1 = g1[keep], g2[keep], r1[keep]
            pl, ph = _fn_band(fn0, best.eps, g1, g2)
            start, count = _r2_range(rv, r1, pl, ph, lo_u, hi_u)
            live = count > 0
            g1, g2, r1, lo_u, hi_u, start, count = (x[live] for x in (g1, g2, r1, lo_u, hi_u, start, count))
            if not r1.size:
                break
            sl = next(_batches(count))
            row, i2 = _expand(start[sl], count[sl])
            best.add(r1[sl][row], rv[i2], g1[sl][row], g2[sl][row])
            g1, g2, r1, lo_u, hi_u = (x[sl.stop:] for x in (g1, g2, r1, lo_u, hi_u))
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
    best = _Best(fn0, zeta0, gain, top, _seed_bound(fn0, zeta0, rv, cv, gain, top))
    for i1, i2 in _pair_chunks(cv.size):
        _search_pairs(zeta0, rv, cv[i1], cv[i2], best)
    return _rank(*best.parts, fn0, zeta0, gain, top)


def brute_force(fn0: float, zeta0: float, r_values, c_values, gain: float = 1.0,
                top: int = 5) -> list:
    """Every combination, evaluated: the reference :func:`joint_search` must match."""
    rv = np.unique(np.asarray(r_values, float))
    cv = np.unique(np.asarray(c_values, float))
    r1, r2, c1, c2 = (g.ravel() for g in np.meshgrid(rv, rv, cv, cv, indexing="ij"))
    return _rank(r1, r2, c1, c2, fn0, zeta0, gain, top)


def around(value: float, series_values, k: int = 2) -> np.ndarray:
    """The ``k`` series values on each side of ``value`` (for rounding a fixed design jointly)."""
    v = np.unique(np.asarray(series_values, float))
    i = int(np.searchsorted(v, value))
    return v[max(0, i - k): i + k]
