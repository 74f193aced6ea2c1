"""Identification from a measured frequency response (seed 000 section 5, seed 003 section 3.1).

Input is a validated table, :class:`~designer.identify.io.freqtable.FreqData` (read
by :func:`designer.identify.io.read_freq_table`).

:func:`identify_freq` runs the methods (all return
:class:`~designer.identify.structures.MethodResult`) and ranks them:

- ``asymptotes`` and ``resonant-peak``, the classical readings, in
  :mod:`.bode_readings` with the model responses they share;
- ``least-squares``, the complex-response fits of ``fopdt``, ``underdamped``
  and ``overdamped`` with dead time started from the classical estimates, in
  :mod:`.freqfit`;

and, when the table is an open loop's, reads its margins (:mod:`.bode_margins`).

Results are ranked by their fit error ``iae``, the mean relative complex error
|G_model/G_data - 1| over the table (:func:`~.bode_readings.fit_error`), valid
first, as ``identify`` ranks by IAE.

Validity (:func:`judge`). A result is valid only if it describes the table:
finite parameters, a fit error of at most :data:`MAX_FIT_ERROR`, and every
corner frequency (1/tau of each time constant, wn) inside the measured band
widened :data:`BAND_FACTOR` times each way. A flat table, a ratio read as dB
or a phase of the wrong sign then has no valid model instead of one with
wn = 2e54 rad/s or a 47 % error marked "ok". The fits search a far wider band
(:data:`~.freqfit.FIT_BAND`), so every exponential of a log-parameter stays
finite.

"""

from __future__ import annotations

import math
from dataclasses import dataclass

from .bode_margins import LoopMargins, loop_margins
from .bode_readings import interp_logf, asymptotes, low_frequency_gain, resonant_peak
from .freqfit import start_points, least_squares_fit
from .io import FreqData
from .structures import MethodResult, rank_key

__all__ = ["BAND_FACTOR", "FreqIdentifyResult", "MAX_FIT_ERROR", "corner_frequencies", "identify_freq"]

ERROR_DEFINITION = ("iae = mean over the table's frequencies of |G_model/G_data - 1| "
                    "(relative complex error; gain only when there is no phase), "
                    "ise = mean of its square; dimensionless")

#: A model whose fit error (mean |G_model/G_data - 1|) exceeds this does not
#: describe the table: 0.2 is an average miss of about 1.6 dB or 11 degrees,
#: several times what the seeds' hand-read tables show against their own
#: second-order readings (7 %), and what a table read in the wrong units or
#: with the wrong phase sign gives (over 20 %).
MAX_FIT_ERROR = 0.2
#: Corner frequencies and wn must lie inside the measured band widened by this
#: factor each way: a pole ten times beyond the last point changes the table's
#: gain by under 0.05 dB and its phase by under 6 degrees, so the table cannot
#: place it (a flat table "fits" wn = 2e54 rad/s).
BAND_FACTOR = 10.0


@dataclass
class FreqIdentifyResult:
    """Every method's result, ranked by fit error (valid first), the best, and
    the loop margins when the table is an open loop's."""

    methods: list
    best: MethodResult | None
    data: FreqData
    loop: LoopMargins | None = None

    def to_dict(self) -> dict:
        return {"methods": [m.to_dict() for m in self.methods],
                "best": self.best.to_dict() if self.best else None,
                "data": self.data.to_dict(),
                "loop": self.loop.to_dict() if self.loop else None,
                "error_definition": ERROR_DEFINITION}


def corner_frequencies(model: str, params: dict) -> dict:
    """The model's corner frequencies (rad/s): 1/tau of each time constant, wn.

    Parameters
    ----------
    model : str
        The model's name.
    params : dict
        Its parameters.

    Returns
    -------
    dict
        Parameter name -> corner frequency in rad/s.
    """
    out = {}
    for k, v in params.items():
        if k.startswith("tau") and isinstance(v, float) and v > 0:
            out[k] = 1.0 / v
        elif k == "wn_rad_s":
            out[k] = v
    return out


def judge(m: MethodResult, data: FreqData) -> None:
    """Mark a result invalid, saying why, unless it describes the table: finite
    parameters and error, fit error at most MAX_FIT_ERROR, and every corner
    frequency inside the measured band widened BAND_FACTOR times."""
    if not m.valid:
        return
    why = None
    if not (all(math.isfinite(v) for v in m.params.values()) and math.isfinite(m.iae)):
        why = "degenerate result: the table does not have this model's shape"
    elif m.iae > MAX_FIT_ERROR:
        why = (f"fit error {100 * m.iae:.3g} % is above the {100 * MAX_FIT_ERROR:g} % a model "
               "must reach to describe the table (gain or phase in other units than read, "
               "or the phase sign flipped?)")
    else:
        w_lo, w_hi = data.w[0] / BAND_FACTOR, data.w[-1] * BAND_FACTOR
        for k, wc in corner_frequencies(m.model, m.params).items():
            if not w_lo <= wc <= w_hi:
                name = "wn" if k == "wn_rad_s" else f"the corner of {k[:-2]}"
                why = (f"{name} ({wc:.4g} rad/s, {wc / (2 * math.pi):.4g} Hz) lies outside the "
                       f"measured band widened {BAND_FACTOR:g} times ({w_lo:.4g} to "
                       f"{w_hi:.4g} rad/s): the table cannot place it")
                break
    if why is None:
        why = wide_interval(m)
    if why:
        m.valid = False
        m.note = "; ".join(x for x in (m.note, why) if x)


def wide_interval(m: MethodResult) -> str | None:
    """Why a result is not valid by its confidence intervals, or None: a 95 %
    half-width (``<param>_ci95`` in ``points``) not narrower than its parameter
    (a spectral fit whose tau is 0.187 s +-160,703 s says nothing about tau).
    The dead time is exempt: an interval reaching 0 says the plant has none
    that the data show.

    Parameters
    ----------
    m : MethodResult
        A least-squares result (others carry no intervals and pass).

    Returns
    -------
    str or None
        The sentence, or None when every interval is narrower than its parameter.
    """
    for key, h in m.points.items():
        k = key[:-5] if key.endswith("_ci95") else None
        v = m.params.get(k) if k else None
        if k == "theta_s":
            # a dead time whose interval reaches 0 is a plant without a measurable one (the nested model,
            # theta = 0, fits as well), not an undetermined model: its other parameters still hold
            continue
        if isinstance(v, (int, float)) and isinstance(h, (int, float)) and not h < abs(v):
            return f"{k}'s 95 % interval +-{h:.4g} is not narrower than {k} = {v:.4g}"
    return None


def identify_freq(data: FreqData) -> FreqIdentifyResult:
    """Run the classical readings and the least-squares fits; rank by fit error.

    Parameters
    ----------
    data : FreqData
        The frequency-response table.

    Returns
    -------
    FreqIdentifyResult
        Every method's result in rank order, the best valid one (or None), the
        data and the loop margins.
    """
    classical = [asymptotes(data), resonant_peak(data)]
    K, _ = low_frequency_gain(data)
    wc = interp_logf(data.w, data.gain_db, 20.0 * math.log10(K) - 3.0)
    if not math.isfinite(wc):
        wc = float(data.w[-1])
    fits = [least_squares_fit(data, model, start_points(model, classical, K, wc))
            for model in ("fopdt", "underdamped", "overdamped")]
    for m in classical + fits:
        judge(m, data)
    methods = sorted(classical + fits, key=rank_key)
    best = next((m for m in methods if m.valid and math.isfinite(m.iae)), None)
    return FreqIdentifyResult(methods, best, data, loop_margins(data))
