"""Simulated captures of known plants under any input, for the output-error and
validation tests: the input is what a DAC holds between samples (recorded as
sampled), the output the exact response of the process model -- a sum of the
model's own exact step responses (:meth:`ProcessModel.step`), one per change of
the input, so the data do not come from the code under test -- plus white
noise at a given SNR (of the output's variation) and an 8-bit quantiser on both
channels (each over its own range, as a scope set to fit the trace)."""

from __future__ import annotations

import numpy as np

from designer.core import process_build as pb

T = 0.05          #: sample interval (s)
N = 4000          #: samples per capture (200 s)
U_LOW, U_HIGH = 3.0, 5.0
Y_REST = 1.0

#: the known plants: name -> (fit kind, model)
PLANTS = {
    "fopdt": ("fopdt", pb.fopdt(2.0, 1.3, 0.437)),
    "sopdt": ("sopdt", pb.sopdt(1.5, 2.0, 0.5, 0.33)),
    "underdamped": ("underdamped", pb.underdamped(0.8, 0.3, 0.2, 0.21)),
    "integrating": ("integrating-lag", pb.integrating(0.5, 1.0, 0.6)),
}


def random_binary(rng, n=N, p_switch=0.2):
    """A random binary signal between U_LOW and U_HIGH switching with probability ``p_switch``
    at each sample, starting at U_LOW (the record at rest)."""
    flips = rng.random(n) < p_switch
    flips[0] = False
    return U_LOW + (U_HIGH - U_LOW) * (np.cumsum(flips) % 2)


def chirp(n=N, f0=0.01, f1=1.0):
    """A logarithmic sine sweep f0 -> f1 Hz over the record, around mid-range, starting at rest."""
    t = np.arange(n) * T
    k = np.log(f1 / f0) / t[-1]
    phase = 2 * np.pi * f0 * (np.exp(k * t) - 1.0) / k
    return 0.5 * (U_LOW + U_HIGH) + 0.5 * (U_HIGH - U_LOW) * np.sin(phase)


def step(n=N, at=0.1):
    """U_LOW, then U_HIGH from ``at`` of the record."""
    u = np.full(n, U_LOW)
    u[int(at * n):] = U_HIGH
    return u


def exact_response(model, u, ts=T, u_before=None):
    """The model's exact output deviation under ``u`` held between samples, from
    rest at ``u_before`` (default u[0]; an integrating plant's balance input)."""
    t = np.arange(u.size) * ts
    du = np.diff(u, prepend=u[0] if u_before is None else u_before)
    y = np.zeros(u.size)
    for j in np.nonzero(du)[0]:
        y[j:] += du[j] * model.step(t[j:] - t[j])
    return y


def quantise(x, bits=8):
    """``x`` on a grid of 2^bits levels spanning its range."""
    lo, hi = float(np.min(x)), float(np.max(x))
    q = (hi - lo) / (2 ** bits - 1)
    return lo + np.round((x - lo) / q) * q


def capture(model, u, *, snr_db=15.0, seed=0, bits=8, u_before=None):
    """(u recorded, y recorded, y noiseless) of ``model`` under ``u`` (from rest at ``u_before``)."""
    rng = np.random.default_rng(seed)
    clean = Y_REST + exact_response(model, u, u_before=u_before)
    noisy = clean + rng.standard_normal(u.size) * np.std(clean) / 10 ** (snr_db / 20)
    return quantise(u, bits), quantise(noisy, bits), clean
