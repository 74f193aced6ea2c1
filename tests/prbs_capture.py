"""Simulated PRBS experiments for the broadband identification tests: a known
plant driven by an m-sequence, sampled as a scope samples it (halfway between
the generator's clock edges), with white noise at a given SNR and an 8-bit
quantiser on both channels. The plant is simulated exactly for a
piecewise-constant input (zero-order-hold discretisation at half the sample
interval); a dead time is a whole number of samples."""

from __future__ import annotations

import numpy as np
import scipy.signal as sig

from designer.core.prbs import mls


def prbs_capture(num, den, *, bits, per_bit, periods, ts, amplitude=1.0, offset=0.0,
                 delay_samples=0, snr_db=None, adc_bits=None, seed=1, y_offset=0.0, flip=()):
    """(t, u, y) of a PRBS experiment on N(s)/D(s) (see the module docstring);
    the values at the indices ``flip`` of every period inverted (a corrupted sequence)."""
    one = mls(bits).astype(float)
    one[list(flip)] *= -1.0
    seq = np.tile(one, periods)
    u2 = offset + amplitude * np.repeat(seq, 2 * per_bit)
    b, a, _ = sig.cont2discrete((num, den), ts / 2, method="zoh")
    y2 = sig.lfilter(np.squeeze(b), a, u2 - offset)
    u, y = u2[1::2].copy(), y2[1::2].copy()
    if delay_samples:
        y = np.concatenate((np.zeros(delay_samples), y[:-delay_samples]))
    y = y + y_offset
    rng = np.random.default_rng(seed)
    if snr_db is not None:
        y = y + rng.normal(0.0, np.std(y) / 10 ** (snr_db / 20), y.size)
    if adc_bits:
        u, y = quantise(u, adc_bits), quantise(y, adc_bits)
    return np.arange(u.size) * ts, u, y


def quantise(x, bits):
    """``x`` on a grid of (max - min)/2^bits, as an ADC spanning the record reads it."""
    q = (x.max() - x.min()) / 2 ** bits
    return np.round(x / q) * q


def capture_csv(path, t, u, y, header="t,CH1,CH2"):
    """Write a generic scope-like CSV of the two channels."""
    with open(path, "w") as fh:
        fh.write(header + "\n")
        for row in zip(t, u, y):
            fh.write(",".join(f"{v:.9g}" for v in row) + "\n")
    return path


def noise_identify_json(folder, seed=2):
    """identify's own ``--json`` of a PRBS capture (7 bits, 10 samples a bit, 2 periods, 0.1 ms apart)
    whose output is white noise alone (``seed``): a broadband result that identified nothing, its best
    none (seed 2). Returns the JSON file's path (``noise.json`` in ``folder``)."""
    import subprocess

    from helpers import script
    u = np.repeat(np.tile(mls(7).astype(float), 2), 10)
    y = np.random.default_rng(seed).standard_normal(u.size)
    capture = folder / "noise.csv"
    np.savetxt(capture, np.c_[np.arange(u.size) * 1e-4, u, y], delimiter=",", header="t,u,y", comments="")
    out = subprocess.run([script("identify"), str(capture), "--json"], capture_output=True, text=True,
                         check=True, cwd=folder).stdout
    path = folder / "noise.json"
    path.write_text(out)
    return path
