"""Reproducible samples of the parts: sample i is a function of (seed, i) alone,
whatever the number of workers or the chunking.

``random``: the samples of chunk c (samples c*CHUNK .. (c+1)*CHUNK - 1, a fixed
:data:`CHUNK`) come from ``numpy.random.default_rng(SeedSequence(seed, spawn_key=(c,)))``;
``sobol``: scrambled Sobol (scipy.stats.qmc, the seed scrambles), point i of the
sequence (``fast_forward``); ``lhs``: a Latin hypercube over all N samples (its
strata depend on N), drawn whole and sliced. Each sample is a point u of the unit
cube, one coordinate per part, mapped to a relative deviation in [-1, 1] of the
tolerance: uniform, or normal with sigma = tol/3 truncated at +- tol.
"""

from __future__ import annotations

import functools

import numpy as np

from ..core.errors import DesignError

__all__ = ["CHUNK", "SAMPLERS", "deviations", "unit_samples", "values"]

SAMPLERS = ("random", "lhs", "sobol")
#: samples per chunk of the random sampler (fixed: the chunks, and so the samples, do not depend on workers)
CHUNK = 4096


def unit_samples(n: int, dims: int, seed: int, sampler: str = "random", start: int = 0, stop: int | None = None):
    """Samples ``start`` .. ``stop`` - 1 (default all ``n``) of ``n``, points of [0, 1)^dims.

    Parameters
    ----------
    n : int
        The draw's samples.
    dims : int
        The dimensions (the parts varied).
    seed : int
        The seed.
    sampler : str
        ``random``, ``lhs`` or ``sobol``.
    start, stop : int
        The samples wanted.

    Returns
    -------
    numpy.ndarray
        (samples, dims).
    """
    stop = n if stop is None else stop
    if sampler not in SAMPLERS:
        raise DesignError(f"--sampler {sampler!r} unknown; allowed: {', '.join(SAMPLERS)}")
    if not 0 <= start <= stop <= n:
        raise DesignError(f"samples {start}..{stop} are outside 0..{n}")
    if sampler == "random":
        out = np.empty((stop - start, dims))
        for c in range(start // CHUNK, (stop - 1) // CHUNK + 1 if stop > start else start // CHUNK):
            rng = np.random.default_rng(np.random.SeedSequence(seed, spawn_key=(c,)))
            block = rng.random((CHUNK, dims))
            lo, hi = max(start, c * CHUNK), min(stop, (c + 1) * CHUNK)
            out[lo - start:hi - start] = block[lo - c * CHUNK:hi - c * CHUNK]
        return out
    from scipy.stats import qmc
    if sampler == "sobol":
        import warnings
        eng = qmc.Sobol(dims, scramble=True, seed=seed)
        if start:
            eng.fast_forward(start)
        with warnings.catch_warnings():
            # any n is allowed: a power of 2 balances the points best, which the benchmark measures
            warnings.filterwarnings("ignore", "The balance properties of Sobol", UserWarning)
            return eng.random(stop - start)
    return _hypercube(n, dims, seed)[start:stop]


@functools.lru_cache(maxsize=1)
def _hypercube(n: int, dims: int, seed: int) -> np.ndarray:
    """The whole Latin hypercube, drawn once per process for all its chunks (:mod:`.runner`)."""
    from scipy.stats import qmc
    u = qmc.LatinHypercube(dims, seed=seed).random(n)
    u.flags.writeable = False      # shared by every chunk's slice
    return u


def deviations(u, dist: str = "uniform") -> np.ndarray:
    """Relative deviations in [-1, 1] (times the tolerance) from unit samples.

    Parameters
    ----------
    u : array_like
        Unit samples in [0, 1).
    dist : str
        ``uniform`` or ``normal``.

    Returns
    -------
    numpy.ndarray
        The deviations.
    """
    u = np.asarray(u, float)
    if dist == "uniform":
        return 2.0 * u - 1.0
    if dist == "normal":
        from scipy.stats import truncnorm
        return truncnorm.ppf(u, -3.0, 3.0) / 3.0     # sigma = tol/3, truncated at +- tol
    raise DesignError(f"--dist {dist!r} unknown; allowed: uniform, normal")


def values(nominal: dict, tol: dict, n: int, seed: int, sampler: str = "random", dist: str = "uniform",
           start: int = 0, stop: int | None = None) -> dict:
    """Designator -> array of its sampled values (samples start .. stop - 1), each
    nominal x (1 + tol x deviation).

    Parameters
    ----------
    nominal : dict
        Designator -> nominal value.
    tol : dict
        Designator -> tolerance (fraction).
    n : int
        The draw's samples.
    seed : int
        The seed.
    sampler, dist : str
        How the samples are drawn.
    start, stop : int
        The samples wanted.

    Returns
    -------
    dict
        Designator -> array of values.
    """
    refs = list(tol)
    d = deviations(unit_samples(n, len(refs), seed, sampler, start, stop), dist)
    return {r: nominal[r] * (1.0 + tol[r] * d[:, k]) for k, r in enumerate(refs)}
