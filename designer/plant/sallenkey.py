"""The Sallen-Key plant's parts record and closed forms (seed 001, sections
IV.3-IV.9), as the plant wing has always imported them: they live with the
Sallen-Key low-pass section, in
:mod:`designer.filters.sallen_key_lowpass_synthesis` (the one place that
names its parts, issue 26); this module keeps the old import path working,
and gives the parts' own accessors (:mod:`designer.filters.sallen_key_lowpass_parts`:
the section of a record, the values by designator of a result.json's record)
to the modules that may reach the plant wing and not the circuit layer
(identify's comparison with a design)."""

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
from ..filters.sallen_key_lowpass_parts import KEY_OF, json_values, ratio_pair, section_of

__all__ = ["DEFAULT_R3_OHM", "GAIN_TOLERANCE", "JSON_KEYS", "KEY_OF", "NETWORK_KEYS", "SallenKeyParts", "check_parts",
           "coefficients", "fn_zeta", "json_values", "ratio_pair", "ratios_from_rc", "realizability_notes",
           "resistors_for_caps", "section_of"]
