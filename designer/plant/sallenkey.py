"""The Sallen-Key plant's parts record and closed forms (seed 001, sections
IV.3-IV.9), as the plant wing has always imported them: they live with the
Sallen-Key low-pass section, in
:mod:`designer.filters.sallen_key_lowpass_synthesis` (the one place that
names its parts, issue 26); this module keeps the old import path working."""

from ..filters.sallen_key_lowpass_synthesis import (
    DEFAULT_R3_OHM,
    GAIN_TOLERANCE,
    JSON_KEYS,
    NETWORK_KEYS,
    SallenKeyParts,
    check_parts,
    coefficients,
    fn_zeta,
    ratios_from_rc,
    realizability_notes,
    resistors_for_caps,
)

__all__ = ["DEFAULT_R3_OHM", "GAIN_TOLERANCE", "JSON_KEYS", "NETWORK_KEYS", "SallenKeyParts", "check_parts", "coefficients", "fn_zeta",
           "ratios_from_rc", "realizability_notes", "resistors_for_caps"]
