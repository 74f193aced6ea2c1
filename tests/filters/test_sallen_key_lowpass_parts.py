"""The Sallen-Key low-pass's part names in one place: the section's designators, the plant record's fields
and the conversions between them."""

import numpy as np
import pytest

from designer.filters import registry
from designer.filters.sallen_key_lowpass_parts import (
    FIELD_OF,
    REF_OF,
    gain_of,
    gain_refs,
    network,
    part_values,
    parts_of,
    refs,
    section_of,
)
from designer.filters.sallen_key_lowpass_synthesis import JSON_KEYS, SallenKeyParts

UNITY = SallenKeyParts(1.6e3, 3.9e3, 3.3e-9, 100e-9)
GAIN2 = SallenKeyParts(10e3, 10e3, 10e-9, 10e-9, 2.0, 10e3, 10e3)


def test_the_names_are_the_registered_sections():
    assert section_of(UNITY) is registry.get("sallen-key-lowpass")
    assert section_of(GAIN2) is registry.get("sallen-key-lowpass-gain")
    assert refs() == registry.get("sallen-key-lowpass-gain").designators
    assert refs(with_gain=False) == registry.get("sallen-key-lowpass").designators
    assert set(FIELD_OF) == set(refs()) and REF_OF == {f: r for r, f in FIELD_OF.items()}
    assert set(FIELD_OF.values()) == set(JSON_KEYS)      # every field has its JSON key
    assert gain_refs() == tuple(r for r in refs() if r not in refs(with_gain=False))


@pytest.mark.parametrize("parts", [UNITY, GAIN2], ids=["K=1", "K=2"])
def test_values_and_record_round_trip(parts):
    values = part_values(parts)
    assert tuple(values) == section_of(parts).designators
    assert parts_of(values, gain=parts.gain) == parts
    assert all(values[r] == getattr(parts, FIELD_OF[r]) for r in values)
    assert all(getattr(parts, f) is None for r, f in FIELD_OF.items() if r not in values)   # a follower's gain pair


def test_the_gain_and_the_network_as_the_closed_forms_take_them():
    v = {r: np.full(3, x) for r, x in part_values(GAIN2).items()}
    assert np.allclose(gain_of(v), 1 + GAIN2.r4 / GAIN2.r3)
    assert np.array_equal(gain_of(part_values(UNITY)), 1.0)
    assert network(part_values(UNITY)) == (UNITY.r1, UNITY.r2, UNITY.c1, UNITY.c2)
    # a gain pair missing from the values comes from a base record
    rebuilt = parts_of({r: x for r, x in part_values(GAIN2).items() if r in refs(False)}, base=GAIN2, gain=None)
    assert (rebuilt.r3, rebuilt.r4, rebuilt.gain) == (GAIN2.r3, GAIN2.r4, None)
