"""Choosing the four Sallen-Key parts jointly from E-series values.

The objective is the worse of the two relative errors,
``max(|fn/fn0 - 1|, |zeta/zeta0 - 1|)``. Rounding each part on its own is
typically 1-7 % off; searching the candidate grid jointly finds combinations
well under 1 %.

The search is exact over its candidate set (the series values inside the
bounds), without visiting all of it:

1. seed: for every capacitor pair, the exact resistor solution's nearest
   series neighbours give a good set of candidates and so an error bound eps
   (the k-th best found);
2. enumerate: every combination within eps must have ``|fn error| <= eps``,
   i.e. R1 R2 in a narrow window for each (C1, C2, R2); ``searchsorted``
   enumerates exactly those and all are evaluated.

Nothing better than the k-th best seed can lie outside the window, so the top
k equal those of brute force (a test checks it against :func:`brute_force`).
"""

from __future__ import annotations

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


def _score(r1, r2, c1, c2, fn0, zeta0, gain):
    fn, z = fn_zeta(r1, r2, c1, c2, gain)
    efn = fn / fn0 - 1.0
    ez = z / zeta0 - 1.0
    worst = np.maximum(np.abs(efn), np.abs(ez))
    return fn, z, efn, ez, worst


def _rank(r1, r2, c1, c2, fn0, zeta0, gain, top):
    fn, z, efn, ez, worst = _score(r1, r2, c1, c2, fn0, zeta0, gain)
    # deterministic order: worse error, then summed error, then values
    secondary = np.abs(efn) + np.abs(ez)
    order = np.lexsort((c2, c1, r2, r1, secondary, np.round(worst, 12)))[:top]
    return [Candidate(float(r1[i]), float(r2[i]), float(c1[i]), float(c2[i]), float(fn[i]),
                      float(z[i]), float(efn[i]), float(ez[i])) for i in order]


def _neighbours(sorted_vals, x):
    """Indices of the series values just below and above x (clipped)."""
    hi = np.searchsorted(sorted_vals, x)
    n = len(sorted_vals)
    return np.clip(hi - 1, 0, n - 1), np.clip(hi, 0, n - 1)


def joint_search(fn0: float, zeta0: float, r_values, c_values, gain: float = 1.0,
                 top: int = 5) -> list:
    """Best ``top`` combinations of R1, R2 (from ``r_values``) and C1, C2
    (from ``c_values``) for the targets, best first.

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
    """
    rv = np.unique(np.asarray(r_values, float))
    cv = np.unique(np.asarray(c_values, float))
    if rv.size == 0 or cv.size == 0:
        return []
    c1g, c2g = (g.ravel() for g in np.meshgrid(cv, cv, indexing="ij"))

    # 1. seeds: nearest series neighbours of the exact solution for each cap pair
    lo_root, hi_root = resistors_for_caps(fn0, zeta0, c1g, c2g, gain)
    wn = 2 * np.pi * fn0
    prod = 1.0 / (wn * wn * c1g * c2g)          # R1 R2 for exact fn
    geo = np.sqrt(prod)                          # the nearest one can get when no root
    s1, s2, s3, s4 = [], [], [], []
    for root in (lo_root, hi_root, geo):
        r1x = np.where(np.isnan(root), geo, root)
        for i1 in _neighbours(rv, r1x):
            r1c = rv[i1]
            for i2 in _neighbours(rv, prod / r1c):
                s1.append(r1c), s2.append(rv[i2]), s3.append(c1g), s4.append(c2g)
    # the same combination can be seeded several times: count it once
    seeds = np.unique(np.column_stack([np.concatenate(a) for a in (s1, s2, s3, s4)]), axis=0)
    r1s, r2s, c1s, c2s = seeds.T
    worst = _score(r1s, r2s, c1s, c2s, fn0, zeta0, gain)[4]
    k = min(top, worst.size)
    eps = float(np.partition(worst, k - 1)[k - 1]) * (1 + 1e-9) + 1e-15

    # 2. every combination with |fn error| <= eps: R1 R2 within [P/(1+eps)^2, P/(1-eps)^2]
    plo = prod / (1 + eps) ** 2
    phi = prod / (1 - eps) ** 2 if eps < 1 else np.inf * prod
    pair = np.repeat(np.arange(c1g.size), rv.size)
    r2all = np.tile(rv, c1g.size)
    lo = np.searchsorted(rv, plo[pair] / r2all, side="left")
    hi = np.searchsorted(rv, phi[pair] / r2all, side="right")
    count = hi - lo
    keep = count > 0
    pair, r2all, lo, count = pair[keep], r2all[keep], lo[keep], count[keep]
    total = int(count.sum())
    starts = np.repeat(lo - np.cumsum(count) + count, count)
    r1_idx = starts + np.arange(total)
    rep = np.repeat(np.arange(count.size), count)
    return _rank(rv[r1_idx], r2all[rep], c1g[pair[rep]], c2g[pair[rep]], fn0, zeta0, gain, top)


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
