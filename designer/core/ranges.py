"""The physical range of every numeric input, in one table, and how errors
name the inputs.

Each command's ``--help`` states these ranges and every spec checks them when
it is built, so a value outside them ends in one line naming the input and the
allowed range, before any work is done (no overflow, no NaN deep inside a
solver, no eight-second wait to be told no). The ranges are generous
engineering limits, not design advice: a value inside a range may still be
refused later, with a reason, by the design itself (e.g. no E-series parts
within the bounds).

Keys are the library's parameter names, and so are the names in its messages
(``fc_hz must be ...``); the command line shows its options instead
(``--fc must be ...``) from one table, :data:`designer.cli.common.FLAGS`. A
message about one parameter starts with its name (:attr:`DesignError.param`);
a message about several writes them as ``{name}`` markers (:class:`ParamError`).
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

from .errors import DesignError
from .i18n import gettext as _
from .units import format_eng, parse_value

__all__ = ["RANGES", "Range", "help_range", "parse_in_range"]


@dataclass(frozen=True)
class Range:
    """A closed (or half-open) interval of allowed values with its unit."""

    lo: float
    hi: float
    unit: str = ""
    lo_open: bool = False   #: lo itself is not allowed (e.g. a time > 0)
    zero_ok: bool = False   #: 0 is allowed besides [lo, hi] (e.g. Td = 0 for a PI)

    def text(self) -> str:
        """``"1 mHz to 10 MHz"``, for messages and --help."""
        lo, hi = _fmt(self.lo, self.unit), _fmt(self.hi, self.unit)
        # (in the language of the request that is refused: the web page's; the command line's is English)
        core = (_("above {lo} up to {hi}") if self.lo_open else _("{lo} to {hi}")).format(lo=lo, hi=hi)
        return _("0 or {range}").format(range=core) if self.zero_ok else core

    def contains(self, value: float) -> bool:
        if self.zero_ok and value == 0:
            return True
        above = value > self.lo if self.lo_open else value >= self.lo - 1e-12 * abs(self.lo)
        return math.isfinite(value) and above and value <= self.hi + 1e-12 * abs(self.hi)

    def check(self, value, name: str, shown=None) -> float:
        """``value`` as a float if it is a real number inside the range, else a
        :class:`DesignError` starting with ``name`` (its ``param``)."""
        if isinstance(value, (bool, np.bool_)) or not isinstance(value, (int, float, np.integer, np.floating)):
            raise DesignError(_("{name} must be a number, got {got}").format(name=name, got=_short(value)), param=name)
        if not self.contains(value):
            got = shown if shown is not None else _show(value)
            raise DesignError(_("{name} must be {range}, got {got}").format(name=name, range=self.text(), got=got),
                              param=name)
        return float(value)


def _fmt(v: float, unit: str) -> str:
    if unit in ("", "%", "dB") or v == 0 or (unit == "s" and abs(v) >= 1e3):   # "10000 s", not "10 ks"
        return f"{v:g}" + (f" {unit}" if unit else "")
    return format_eng(v, unit, 4)


def _show(value) -> str:
    return f"{float(value):g}"


def _short(value) -> str:
    """A value of the wrong type, for a one-line message: short text, else its type."""
    if isinstance(value, str) and len(value) <= 40:
        return repr(value)
    return type(value).__name__


#: Every numeric input of every command (library parameter name -> range).
RANGES = {
    # plant targets and test signal
    "fc_hz": Range(0.01, 10e6, "Hz"),
    "zeta": Range(0.01, 10.0),
    "gain": Range(1.0, 100.0),
    "amplitude_v": Range(1e-3, 100.0, "V"),
    "square_hz": Range(1e-3, 100e6, "Hz"),
    # parts
    "resistor_ohm": Range(0.1, 1e9, "Ohm"),
    "capacitor_f": Range(1e-13, 1.0, "F"),
    "alternatives": Range(1, 50),
    # PID
    "kp": Range(1e-4, 1e4),
    "ti_s": Range(1e-9, 1e4, "s"),
    "td_s": Range(1e-10, 1e4, "s", zero_ok=True),
    "step_v": Range(1e-3, 100.0, "V"),
    "edge_s": Range(1e-12, 1.0, "s", zero_ok=True),
    "target_overshoot_pct": Range(0.0, 100.0, "%"),
    "target_settling_s": Range(1e-9, 1e4, "s"),
    "f_integrator_hz": Range(1e-4, 10e6, "Hz"),
    "f_differentiator_hz": Range(0.01, 1e9, "Hz"),
    # PID for a model plant (--plant-tf, --plant-model, --plant-capture)
    "simc_tauc_s": Range(1e-12, 1e6, "s"),
    "imc_lambda_s": Range(1e-12, 1e6, "s"),
    "min_phase_margin_deg": Range(0.0, 89.0, "deg"),
    "min_gain_margin_db": Range(0.0, 40.0, "dB"),
    "max_ms": Range(1.05, 10.0),
    "plant_voltage_v": Range(-100.0, 100.0, "V"),
    # identify and identify-freq (add their inputs here)
    # every time in a capture and --step-time: +-10 Gs covers Unix timestamps
    "capture_time_s": Range(-1e10, 1e10, "s"),
    # last time - first time: 1 ps (10 samples at 10 GS/s) up to the whole time range
    "capture_span_s": Range(1e-12, 2e10, "s"),
    # every output and input sample, in the file's own units
    "capture_value": Range(-1e15, 1e15),
    # size of the input step (--step-amplitude, or measured on the input column), either sign
    "step_amplitude": Range(1e-12, 1e12),
    # identify --segment-length: a noise input's Welch segment (samples)
    "segment_length": Range(16, 1 << 20),
    # size of the output's change from baseline to final value, in the file's units
    "output_step": Range(1e-15, 2e15),
    # a capture without a time column (--sample-time): the interval between its rows
    "sample_time_s": Range(1e-12, 1e6, "s"),
    # simulate-capture (its --step is step_v, --duration capture_span_s, --step-time capture_time_s)
    "capture_points": Range(10, 1e6),
    "noise_v": Range(0.0, 100.0, "V"),
    "lsb_v": Range(0.0, 100.0, "V"),
    "seed": Range(0, 1e9),
    # simulate-capture --input random-binary: the chance of a switch at each clock tick
    "switch_probability": Range(0.01, 1.0),
    # simulate-capture --input chirp: --f-start, --f-stop
    "chirp_hz": Range(1e-9, 1e9, "Hz"),
    # frequency-response tables (identify-freq): every row
    "freq_hz": Range(1e-9, 1e11, "Hz"),
    "gain_db": Range(-400.0, 400.0, "dB"),
    "gain_ratio": Range(1e-20, 1e20),
    "phase_deg": Range(-1e5, 1e5),   # degrees
    # make-prbs: the sequence's clock (--clock, or 1/--dt), levels and periods
    "prbs_clock_hz": Range(1e-6, 1e9, "Hz"),
    "prbs_amplitude_v": Range(1e-6, 100.0, "V"),
    "prbs_offset_v": Range(-100.0, 100.0, "V"),
    "prbs_periods": Range(1, 1000),
    # design-filter (designer.filters.spec): the mask's edges use fc_hz's range
    "filter_order": Range(1, 10),
    "ripple_db": Range(0.01, 3.0, "dB"),
    "max_loss_db": Range(0.01, 20.0, "dB"),
    "min_attenuation_db": Range(1.0, 200.0, "dB"),
    "max_delay_error_pct": Range(0.01, 50.0, "%"),
    "gbw_margin": Range(1.0, 1000.0),
    "impedance_ohm": Range(10.0, 1e8, "Ohm"),
}


def parse_in_range(value, name: str, key: str) -> float:
    """``value`` (a number, or text in engineering notation: see
    :func:`designer.core.units.parse_value`) as a float inside ``RANGES[key]``.

    What a user typed is handed over as typed, so that a refusal quotes it
    (``fc_hz must be 10 mHz to 10 MHz, got '1e-300'``); errors start with
    ``name`` and carry it as their ``param``.

    Parameters
    ----------
    value : float or str
        The value as given.
    name : str
        The parameter's name, for the message (and the error's ``param``).
    key : str
        The range's key in ``RANGES``.

    Returns
    -------
    float
        The value.
    """
    if isinstance(value, str):
        return RANGES[key].check(parse_value(value, name), name, shown=repr(value))
    return RANGES[key].check(value, name)


def help_range(key: str) -> str:
    """``"(1 mHz to 10 MHz)"`` for a --help line.

    Parameters
    ----------
    key : str
        The range's key in ``RANGES``.

    Returns
    -------
    str
        The text.
    """
    return f"({RANGES[key].text()})"
