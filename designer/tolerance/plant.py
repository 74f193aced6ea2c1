"""The analytic engine for a Sallen-Key plant: every figure of every sample at
once, vectorised in numpy.

Per sample (arrays of R1, R2, C1, C2, for a gain above 1 R3, R4, and optionally
GBW, the op-amp's gain-bandwidth in Hz):

- ``ideal_fn_hz``, ``ideal_zeta``, ``ideal_q``: K/(a s^2 + b s + 1) of the parts alone
  (:func:`designer.plant.sallenkey.fn_zeta`, seed 001's formulas);
- ``fn_hz``, ``zeta``, ``q``: the dominant pair with the op-amp's finite
  gain-bandwidth, the third-order D(s) of :func:`designer.plant.model.plant_tf_opamp`
  written out coefficient by coefficient, its poles the eigenvalues of a stack of
  3 x 3 companion matrices (:func:`designer.core.lti.dominant_pair`'s definition);
- ``overshoot_pct``, ``peak_time_s``: the first peak of the exact step of that
  third-order model, y = G(0) (1 + sum_i e^(p_i t) / (p_i D'(p_i))), where its
  derivative vanishes (Newton's method from the dominant pair's pi/wd);
- ``gain``: G(0).
"""

from __future__ import annotations

import math

import numpy as np

from ..filters.sallen_key_lowpass_parts import gain_of, network
from ..plant.sallenkey import coefficients, fn_zeta

__all__ = ["FIGURES", "evaluate", "plant_figures"]

FIGURES = ("fn_hz", "zeta", "q", "ideal_fn_hz", "ideal_zeta", "ideal_q", "overshoot_pct", "peak_time_s", "gain")
#: Newton steps on the first peak of the step (quadratic convergence from pi/wd)
NEWTON_STEPS = 8


def _gain(v: dict):
    return gain_of(v)


def _cubic(v: dict, opamp):
    """(d3, d2, d1, d0) of D(s) with the op-amp (ideal: d3 = 0, the quadratic)."""
    r1, r2, c1, c2 = network(v)
    k = _gain(v)
    i2 = r2 * c1 * r1 * c2
    i1 = r2 * c1 * (1 + r1 / r2) + r1 * c2
    if opamp is None or opamp.ideal:
        # K/(a s^2 + b s + 1): D = (a s^2 + b s + 1)/K
        b = coefficients(r1, r2, c1, c2, k)[1]
        return np.zeros_like(r1), i2 / k, b / k, 1 / k
    a0 = opamp.a0
    # the op-amp's own spread (--tol GBW=30%): a gain-bandwidth per sample
    wp = 2 * math.pi * v.get("GBW", opamp.gbw_hz) / a0
    n1, n0 = 1.0 / (wp * a0), (1.0 + a0 / k) / a0
    return n1 * i2, n1 * i1 + n0 * i2, n1 + n0 * i1 - r1 * c2, n0 * np.ones_like(r1)


def _poles(d3, d2, d1, d0):
    """Poles of each sample's D (N x 3, or N x 2 for the ideal quadratic)."""
    if np.all(d3 == 0):
        disc = np.sqrt((d1 * d1 - 4 * d2 * d0).astype(complex))
        return np.stack([(-d1 + disc) / (2 * d2), (-d1 - disc) / (2 * d2)], axis=1)
    comp = np.zeros((d3.size, 3, 3))
    comp[:, 0, 0], comp[:, 0, 1], comp[:, 0, 2] = -d2 / d3, -d1 / d3, -d0 / d3
    comp[:, 1, 0] = comp[:, 2, 1] = 1.0
    return np.linalg.eigvals(comp)


def _dominant(poles):
    """(wn, zeta) of each sample's slowest pair (as :func:`designer.core.lti.dominant_pair`)."""
    mag = np.abs(poles)
    is_c = np.abs(poles.imag) > 1e-9 * mag
    big = np.where(is_c, mag, np.inf)
    k = np.argmin(big, axis=1)
    pc = poles[np.arange(poles.shape[0]), k]
    wn_c, z_c = np.abs(pc), -pc.real / np.maximum(np.abs(pc), 1e-300)
    re = np.sort(np.abs(poles.real), axis=1)[:, :2]
    wn_r = np.sqrt(re[:, 0] * re[:, 1])
    z_r = (re[:, 0] + re[:, 1]) / (2 * np.maximum(wn_r, 1e-300))
    any_c = np.any(is_c, axis=1)
    return np.where(any_c, wn_c, wn_r), np.where(any_c, z_c, z_r)


def _step_peak(poles, dcoef, wn, zeta):
    """(overshoot %, peak time) of y/G(0) = 1 + sum r_i e^(p_i t), r_i = 1/(p_i D'(p_i)), D
    normalised to D(0) = 1: the first peak, where y' = sum r_i p_i e^(p_i t) = 0, by Newton's
    method from the dominant pair's pi/wd (all the samples at once). Real poles only (no zeros):
    a cascade of lags, monotone, no overshoot."""
    d = [c / dcoef[-1] for c in dcoef]            # normalised: constant term 1
    p = poles
    if p.shape[1] == 3:
        dprime = 3 * d[0][:, None] * p ** 2 + 2 * d[1][:, None] * p + d[2][:, None]
    else:
        dprime = 2 * d[0][:, None] * p + d[1][:, None]
    r = 1.0 / (p * dprime)
    oscill = np.any(np.abs(p.imag) > 1e-9 * np.abs(p), axis=1)
    wd = wn * np.sqrt(np.maximum(1 - zeta ** 2, 1e-12))
    t = np.pi / np.maximum(wd, 1e-300)
    for _ in range(NEWTON_STEPS):
        e = np.exp(p * t[:, None])
        d1 = np.real(np.sum(r * p * e, axis=1))
        d2 = np.real(np.sum(r * p * p * e, axis=1))
        step = np.where(d2 < 0, d1 / np.where(d2 < 0, d2, -1.0), 0.0)
        t = np.clip(t - step, 0.2 * np.pi / wd, 1.8 * np.pi / wd)
    y = 1.0 + np.real(np.sum(r * np.exp(p * t[:, None]), axis=1))
    over = np.where(oscill, np.maximum(0.0, 100 * (y - 1.0)), 0.0)
    return over, np.where(oscill & (y > 1.0), t, np.nan)


def plant_figures(v: dict, opamp=None) -> dict:
    """Every figure of :data:`FIGURES` for the sampled parts ``v`` (designator -> array).

    Parameters
    ----------
    v : dict
        Designator -> array over the samples.
    opamp : designer.core.opamps.OpAmp, optional
        The op-amp (None: ideal).

    Returns
    -------
    dict
        Figure -> array over the samples.
    """
    k = _gain(v)
    fn_i, z_i = fn_zeta(*network(v), k)
    d3, d2, d1, d0 = _cubic(v, opamp)
    ideal = opamp is None or opamp.ideal
    dcoef = (d2, d1, d0) if ideal else (d3, d2, d1, d0)
    poles = _poles(np.zeros_like(d2) if ideal else d3, d2, d1, d0)
    wn, z = _dominant(poles)
    over, tpk = _step_peak(poles, dcoef, wn, z)
    with np.errstate(divide="ignore"):
        return {"fn_hz": wn / (2 * np.pi), "zeta": z, "q": 1 / (2 * z), "ideal_fn_hz": np.asarray(fn_i, float),
                "ideal_zeta": np.asarray(z_i, float), "ideal_q": 1 / (2 * np.asarray(z_i, float)),
                "overshoot_pct": over, "peak_time_s": tpk, "gain": 1.0 / d0}


def evaluate(opamp, values: dict) -> dict:
    """The engine's chunk function (:mod:`.runner`): :func:`plant_figures` of ``values`` with ``opamp``.

    Parameters
    ----------
    opamp : designer.core.opamps.OpAmp or None
        The op-amp (None: ideal).
    values : dict
        Designator -> array over the chunk's samples.

    Returns
    -------
    dict
        Figure -> array over the samples.
    """
    return plant_figures(values, opamp)
