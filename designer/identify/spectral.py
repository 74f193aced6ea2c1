"""The frequency response from a broadband input by spectral analysis (seed 003,
section 3.2): H(j w) = S_yu(j w) / S_uu(w), with the coherence
gamma^2 = |S_yu|^2 / (S_uu S_yy) at each frequency. Small pure functions on arrays.

Two estimates:

- :func:`periodic_response`: a periodic input (a PRBS) over whole periods:
  the spectra of each period at the harmonics of 1/period, averaged over the
  periods (the plant's transient, the first period, left out by the caller).
  No leakage: every harmonic the input excites is exact, noise aside.
- :func:`welch_response`: a random input (noise): Welch's averaged,
  windowed segments (:func:`scipy.signal.csd`, :func:`scipy.signal.welch`).

Either keeps the frequencies where the input has power (within
:data:`INPUT_DB` of its low-frequency level: a PRBS's spectrum falls as
sinc^2 and is zero at multiples of the clock) and the coherence is at least
:data:`MIN_COHERENCE`, then :func:`log_bands` averages them into bands equally
spaced in log frequency (gain as the mean of log|H|, the unwrapped phase as
its mean, weighted by the input's power), so that identify-freq's fits see a
table shaped as a swept measurement would be (:func:`to_freq_data`).
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

__all__ = ["BANDS_PER_DECADE", "MAX_REL_ERROR", "MIN_COHERENCE", "log_bands", "periodic_response", "table_text",
           "to_freq_data", "welch_response"]

#: keep frequencies where the input's power is within this of its low-frequency level
INPUT_DB = 10.0
#: and where the coherence is at least this
MIN_COHERENCE = 0.5
#: a band whose standard error exceeds this fraction of its |H| is left out
MAX_REL_ERROR = 0.05
#: bands per decade of the table given to identify-freq (20 flattened a zeta = 0.2
#: peak by 3 %: a band then spans a third of its half-power width)
BANDS_PER_DECADE = 40


@dataclass
class Spectrum:
    """``f`` (Hz), the complex response ``h``, the coherence ``coh`` and the
    input's power ``suu`` at each kept frequency; ``how`` says which estimate."""

    f: np.ndarray
    h: np.ndarray
    coh: np.ndarray
    suu: np.ndarray
    how: str = ""
    #: variance of each point's h from the output's noise (nan: unknown)
    var: np.ndarray | None = None

    def to_dict(self) -> dict:
        return {"estimate": self.how, "points": int(self.f.size),
                "f_min_hz": float(self.f[0]) if self.f.size else None,
                "f_max_hz": float(self.f[-1]) if self.f.size else None,
                "min_coherence": float(self.coh.min()) if self.f.size else None}


def _keep(f, h, coh, suu, f_max, how, var) -> Spectrum:
    ok = np.isfinite(h) & (f > 0) & (f <= f_max) & (coh >= MIN_COHERENCE)
    if np.any(ok):
        low = float(np.median(suu[ok][:max(3, int(0.05 * np.count_nonzero(ok)))]))
        ok &= suu >= low * 10.0 ** (-INPUT_DB / 10.0)
    return Spectrum(f[ok], h[ok], coh[ok], suu[ok], how, var[ok])


def periodic_response(u, y, *, start: int, period: int, count: int, ts: float,
                      f_max: float) -> Spectrum:
    """H at the harmonics of 1/(period ts) from ``count`` whole periods of
    ``period`` samples from ``start``; the coherence across periods (1 for one).

    Parameters
    ----------
    u, y : array_like
        Input and output samples.
    start : int
        Index of the first sample used.
    period : int
        Samples per period.
    count : int
        Whole periods used.
    ts : float
        Sample period in s.
    f_max : float
        Highest frequency kept, in Hz.

    Returns
    -------
    Spectrum
        The estimate at the harmonics the input excites.
    """
    seg_u = np.asarray(u, float)[start:start + period * count].reshape(count, period)
    seg_y = np.asarray(y, float)[start:start + period * count].reshape(count, period)
    U = np.fft.rfft(seg_u, axis=1)
    Y = np.fft.rfft(seg_y, axis=1)
    suy = np.mean(np.conj(U) * Y, axis=0)
    suu = np.mean(np.abs(U) ** 2, axis=0)
    syy = np.mean(np.abs(Y) ** 2, axis=0)
    with np.errstate(divide="ignore", invalid="ignore"):
        h = suy / suu
        coh = np.abs(suy) ** 2 / (suu * syy) if count > 1 else np.ones(suu.size)
        # the output's noise at each harmonic, from the spread of the periods' spectra
        noise = (np.sum(np.abs(Y - Y.mean(axis=0)) ** 2, axis=0) / (count - 1)
                 if count > 1 else np.full(suu.size, np.nan))
        var = noise / (count * suu)
    coh = np.nan_to_num(coh)
    f = np.fft.rfftfreq(period, ts)
    return _keep(f, h, coh, suu, f_max, f"over {count} whole period(s) of {period} samples", var)


def welch_response(u, y, *, ts: float, nperseg: int, f_max: float) -> Spectrum:
    """H = S_yu / S_uu and the coherence by Welch's method (Hann, half overlap).

    Parameters
    ----------
    u, y : array_like
        Input and output samples.
    ts : float
        Sample period in s.
    nperseg : int
        Samples per segment.
    f_max : float
        Highest frequency kept, in Hz.

    Returns
    -------
    Spectrum
        The estimate.
    """
    from scipy.signal import csd, welch
    fs = 1.0 / ts
    u = np.asarray(u, float)
    y = np.asarray(y, float)
    f, suy = csd(u, y, fs=fs, nperseg=nperseg)
    _, suu = welch(u, fs=fs, nperseg=nperseg)
    _, syy = welch(y, fs=fs, nperseg=nperseg)
    segments = max(1, 2 * u.size // nperseg - 1)
    with np.errstate(divide="ignore", invalid="ignore"):
        h = suy / suu
        coh = np.nan_to_num(np.abs(suy) ** 2 / (suu * syy))
        # Bendat and Piersol: var|H| / |H|^2 = (1 - coh) / (2 coh n_d)
        var = np.abs(h) ** 2 * (1 - coh) / (2 * coh * segments)
    return _keep(f, h, coh, suu, f_max, f"Welch, {nperseg}-sample Hann segments, half overlap",
                 var)


def log_bands(sp: Spectrum, per_decade: int = BANDS_PER_DECADE) -> Spectrum:
    """The spectrum averaged in bands equally spaced in log f: per band
    H = sum S_uu H / sum S_uu (the band's S_yu over its S_uu: unbiased by the
    output's noise, as a mean of log|H| is not), f its power-weighted geometric
    mean, the coherence its power-weighted mean. Bands with one point keep it.

    Parameters
    ----------
    sp : Spectrum
        The estimate.
    per_decade : int, optional
        Bands per decade.

    Returns
    -------
    Spectrum
        The band-averaged estimate.
    """
    if sp.f.size == 0:
        return sp
    lf = np.log10(sp.f)
    edges = np.arange(math.floor(lf[0] * per_decade), math.ceil(lf[-1] * per_decade) + 2) / per_decade
    idx = np.searchsorted(edges, lf, side="right")
    w = sp.suu
    _, inv = np.unique(idx, return_inverse=True)
    tot = np.bincount(inv, weights=w)
    f = 10.0 ** (np.bincount(inv, weights=w * lf) / tot)
    h = (np.bincount(inv, weights=w * sp.h.real) + 1j * np.bincount(inv, weights=w * sp.h.imag)) / tot
    coh = np.bincount(inv, weights=w * sp.coh) / tot
    var = np.bincount(inv, weights=w * w * sp.var) / (tot * tot)
    out = Spectrum(f, h, coh, tot, sp.how, var)
    # a band whose noise exceeds MAX_REL_ERROR of its response does not describe the plant
    rel = np.sqrt(var) / np.abs(h)
    keep = ~(rel > MAX_REL_ERROR)
    return Spectrum(out.f[keep], out.h[keep], out.coh[keep], out.suu[keep], sp.how, var[keep])


def unwrapped_phase_deg(sp: Spectrum) -> np.ndarray:
    """The phase of ``sp.h`` in degrees, unwrapped, starting within +-180."""
    return np.rad2deg(np.unwrap(np.angle(sp.h)))


def to_freq_data(sp: Spectrum, source: str = ""):
    """The spectrum as identify-freq's :class:`~designer.identify.io.FreqData`
    (gain as a ratio, phase in degrees).

    Parameters
    ----------
    sp : Spectrum
        The estimate.
    source : str, optional
        Name for messages.

    Returns
    -------
    FreqData
        The validated table.
    """
    from .io import freq_data
    return freq_data(sp.f, np.abs(sp.h), unwrapped_phase_deg(sp), gain_units="ratio",
                     phase_units="deg", freq_units="hz", source=source)


def table_text(sp: Spectrum) -> str:
    """The spectrum as a table identify-freq reads: ``f_hz,gain_db,phase_deg``
    after a ``#`` line saying how it was estimated (the coherence is in the JSON).

    Parameters
    ----------
    sp : Spectrum
        The estimate.

    Returns
    -------
    str
        The CSV text.
    """
    ph = unwrapped_phase_deg(sp)
    rows = ["# spectral estimate H = S_yu/S_uu (" + sp.how + ")", "f_hz,gain_db,phase_deg"]
    rows += [f"{f:.9g},{20 * math.log10(abs(h)):.6f},{p:.4f}" for f, h, p in zip(sp.f, sp.h, ph)]
    return "\n".join(rows) + "\n"
