"""Stability margins read from a loop-gain (open-loop) Bode table (seed 001 section V).

The loop is a plant and its controller's. :func:`loop_margins` reads the gain
crossover (|L| = 1) and the phase margin there, 180 + phase(L) in (-180, 180],
and the phase crossover (phase -180 deg) and the gain margin there,
-20 log |L|, by linear interpolation in log f between the table's rows
(:func:`_cross_log`), with the low-frequency slope of
:func:`~.bode_readings.low_frequency_slope`. A table whose gain does not start
above 0 dB and fall through it is not an open loop's: no margins.
:func:`designer.identify.frequency.identify_freq` reads them on every table
(``FreqIdentifyResult.loop``). The margins of a modelled loop with its exact
dead time are :mod:`designer.pid.delaymargins`.

"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

from .bode_readings import low_frequency_slope
from .io import FreqData

__all__ = []


@dataclass(frozen=True)
class LoopMargins:
    """Stability margins of an open-loop (loop-gain) table: the gain
    crossover (|L| = 1) and the phase margin there, 180 + phase(L) in
    (-180, 180]; the phase crossover (phase -180 deg) and the gain margin there,
    -20 log |L|. ``None`` where the table does not reach the crossing."""

    crossover_hz: float
    phase_margin_deg: float | None
    phase_crossover_hz: float | None
    gain_margin_db: float | None
    lf_slope_db_dec: float
    note: str = ""

    def to_dict(self) -> dict:
        return {"crossover_hz": self.crossover_hz, "phase_margin_deg": self.phase_margin_deg,
                "phase_crossover_hz": self.phase_crossover_hz,
                "gain_margin_db": self.gain_margin_db,
                "lf_slope_db_dec": self.lf_slope_db_dec, "note": self.note}


def _cross_log(f, v, level, start=0):
    """First f (interpolated in log f) from index ``start`` where ``v`` passes
    ``level`` (either way), and its index; (nan, -1) if never."""
    d = v[start:] - level
    k = np.nonzero(np.sign(d[1:]) != np.sign(d[:-1]))[0]
    if not k.size:
        return math.nan, -1
    i = start + int(k[0])
    frac = 0.0 if v[i + 1] == v[i] else (level - v[i]) / (v[i + 1] - v[i])
    return float(10.0 ** (math.log10(f[i]) + frac * (math.log10(f[i + 1]) - math.log10(f[i])))), i


def loop_margins(data: FreqData) -> LoopMargins | None:
    """Crossover, phase margin and gain margin of a loop-gain table (seed 001
    section V: the loop of a plant and its controller), or None when the gain
    does not start above 0 dB and fall through it (not an open-loop table).

    The phase is the table's own (an inverting table's 180 deg put back); the
    margins are read by linear interpolation in log f between the rows."""
    db = data.gain_db
    f = data.f_hz
    if not (db[0] > 0.0 and np.any(db <= 0.0)):
        return None
    fc, i = _cross_log(f, db, 0.0)
    lf = low_frequency_slope(data)
    if data.phase is None:
        return LoopMargins(fc, None, None, None, lf, "no phase in the table: margins unknown")
    ph = np.rad2deg(data.phase) + (180.0 if data.sign < 0 else 0.0)
    frac = math.log10(fc / f[i]) / math.log10(f[i + 1] / f[i])
    ph_c = float(ph[i] + frac * (ph[i + 1] - ph[i]))
    pm = (180.0 + ph_c + 180.0) % 360.0 - 180.0
    # the phase crossover: where the phase passes -180 deg (mod 360)
    turns = np.round((ph[0] + 180.0) / 360.0)
    fp, j = _cross_log(f, ph, -180.0 + 360.0 * turns)
    gm = None
    note = ""
    if j >= 0:
        gfrac = math.log10(fp / f[j]) / math.log10(f[j + 1] / f[j])
        gm = float(-(db[j] + gfrac * (db[j + 1] - db[j])))
    else:
        fp = None
        note = "the phase never reaches -180 deg in the table: gain margin beyond it"
    return LoopMargins(fc, float(pm), fp, gm, lf, note)
