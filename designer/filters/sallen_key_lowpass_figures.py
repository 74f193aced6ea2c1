"""The Sallen-Key low-pass's own figures for a batch of sampled builds (the Monte Carlo's analytic
engine for this section, :meth:`~designer.filters.topology.Topology.sample_figures`): every figure at
once, vectorised in numpy, with the exact step of the third-order model.

Per sample (arrays of R1, R2, C1, C2, with gain R3, R4; the op-amp's gain-bandwidth a number or an
array shaped as the samples, the Monte Carlo's ``--tol GBW``):

- ``ideal_fn_hz``, ``ideal_zeta``, ``ideal_q``: K/(a s^2 + b s + 1) of the parts alone
  (:func:`~designer.filters.sallen_key_lowpass_synthesis.fn_zeta`, seed 001's formulas, IV.3-IV.9);
- ``fn_hz``, ``zeta``, ``q``: the dominant pair with the op-amp's finite gain-bandwidth, the
  third-order D(s) of :func:`~designer.filters.sallen_key_lowpass_synthesis.opamp_denominator`
  written out coefficient by coefficient, its poles the eigenvalues of a stack of 3 x 3 companion
  matrices (:func:`designer.core.lti.dominant_pair`'s definition);
- ``overshoot_pct``, ``peak_time_s``: the first peak of the exact step of that third-order model,
  y = G(0) (1 + sum_i e^(p_i t) / (p_i D'(p_i))), where its derivative vanishes (Newton's method from
  the dominant pair's pi/wd), where the generic figures
  (:func:`designer.plant.circuit.circuit_figures`) take the dominant pair's second-order formulas
  (7.8e-6 relative apart on the seed's plant with an LM741, its peak time 0.12 %);
- ``gain``: G(0), the op-amp-aware model's DC gain K A0 / (A0 + K) (the generic figures' is the ideal K).

This is the engine the Sallen-Key plant's Monte Carlo has always had (the reference outputs'
statistics and samples, bit for bit).
"""

from __future__ import annotations

import dataclasses
import math

import numpy as np

from .sallen_key_lowpass_synthesis import coefficients, fn_zeta

__all__ = ["sample_figures"]

#: Newton steps on the first peak of the step (quadratic convergence from pi/wd)
NEWTON_STEPS = 8


def _cubic(v: dict, opamp):
    """(d3, d2, d1, d0) of D(s) with the op-amp (ideal: d3 = 0, the quadratic)."""
    r1, r2, c1, c2 = v["R1"], v["R2"], v["C1"], v["C2"]
    k = _gain(v)
    i2 = r2 * c1 * r1 * c2
    i1 = r2 * c1 * (1 + r1 / r2) + r1 * c2
    if opamp is None or opamp.ideal:
        # K/(a s^2 + b s + 1): D = (a s^2 + b s + 1)/K
        b = coefficients(r1, r2, c1, c2, k)[1]
        return np.zeros_like(r1), i2 / k, b / k, 1 / k
    a0 = opamp.a0
    # the op-amp's own spread (--tol GBW=30%): a gain-bandwidth per sample, shaped as the parts
    wp = 2 * math.pi * opamp.gbw_hz / a0
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


def _gain(v: dict):
    """K = 1 + R4/R3 (ones shaped as the parts without the gain pair)."""
    return 1.0 + v["R4"] / v["R3"] if "R3" in v else np.ones_like(v["R1"])


def _figures(v: dict, opamp) -> dict:
    k = _gain(v)
    fn_i, z_i = fn_zeta(v["R1"], v["R2"], v["C1"], v["C2"], k)
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


def sample_figures(values: dict, opamp=None) -> dict:
    """Every figure of :data:`designer.plant.circuit.FIGURES` for sampled part values.

    Parameters
    ----------
    values : dict
        Designator -> value, numbers or arrays (one batch shape).
    opamp : designer.core.opamps.OpAmp, optional
        The op-amp (None or the ideal one: the ideal model); its gain-bandwidth a number or an
        array shaped as the batch.

    Returns
    -------
    dict
        Figure -> array shaped as the batch.
    """
    shape = np.broadcast_shapes(*(np.shape(x) for x in values.values()))
    flat = {r: np.broadcast_to(np.asarray(x, float), shape).ravel() for r, x in values.items()}
    if opamp is not None and not opamp.ideal and np.ndim(opamp.gbw_hz):
        opamp = dataclasses.replace(opamp, gbw_hz=np.broadcast_to(np.asarray(opamp.gbw_hz, float), shape).ravel())
    return {k: np.asarray(x).reshape(shape) for k, x in _figures(flat, opamp).items()}
