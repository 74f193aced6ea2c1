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
    record_of,
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


@pytest.mark.parametrize("with_gain", [False, True], ids=["follower", "gain"])
def test_the_sections_ideal_pair_is_its_parts_records_bit_for_bit(with_gain):
    """The Sallen-Key low-pass overrides :meth:`~designer.filters.topology.Topology.ideal_pair` with its
    parts record's arithmetic (wn = 1/sqrt(a), then fn): the PID's references are named and sized by the
    record's fn and zeta, and a PID plant carried as the section and its values gives them bit for bit."""
    from designer.filters.sallen_key_lowpass_synthesis import check_parts
    section = section_of(with_gain=with_gain)
    pairs = ((10e3, 5e3), (10e3, 8.2e3), (4.7e3, 1.8e3), (10e3, 1.2e3)) if with_gain else ((None, None),)
    networks = (((10e3, 10e3, 10e-9, 10e-9), (4.7e3, 12e3, 10e-9, 4.7e-9), (1.6e3, 3.9e3, 33e-9, 10e-9))
                if with_gain else ((1.6e3, 3.9e3, 3.3e-9, 100e-9), (805.0, 1e3, 10e-9, 220e-9),
                                   (4.7e3, 12e3, 2.2e-9, 47e-9)))
    for r1, r2, c1, c2 in networks:
        for r3, r4 in pairs:
            rec = check_parts(SallenKeyParts(r1, r2, c1, c2, None, r3, r4))   # the gain the resistors'
            values = part_values(rec)
            assert record_of(section, values) == rec
            assert section.ideal_pair(values) == (rec.fn_hz, rec.zeta)
            assert type(section.ideal_pair(values)[0]) is float
            # the one hook: the section's figures and its wn are the record's too (wn = 1/sqrt(a))
            fig = section.figures(values)
            assert (fig.fn_hz, fig.zeta) == (rec.fn_hz, rec.zeta) and float(section.ideal_wn_zeta(values)[0]) == rec.wn


@pytest.mark.parametrize("with_gain", [False, True], ids=["follower", "gain"])
def test_the_sections_batch_pair_is_the_records_element_by_element(with_gain):
    """The hook on arrays (the sensitivities' and the search's batches) gives each element the record's
    pair to the bit: 200 networks around the seed plant's, moved by up to 20 %."""
    from designer.filters.sallen_key_lowpass_synthesis import check_parts
    section = section_of(with_gain=with_gain)
    rng = np.random.default_rng(26)
    base = part_values(GAIN2 if with_gain else UNITY)
    batch = {r: v * rng.uniform(0.8, 1.2, 200) for r, v in base.items()}
    fn, zeta = section.ideal_pair(batch)
    wn, _ = section.ideal_wn_zeta(batch)
    for i in range(200):
        rec = check_parts(parts_of({r: float(v[i]) for r, v in batch.items()}, gain=None))
        assert (fn[i], zeta[i], wn[i]) == (rec.fn_hz, rec.zeta, rec.wn)


def test_a_result_json_record_reads_into_values_by_designator():
    from designer.filters.sallen_key_lowpass_parts import KEY_OF, json_values, ratio_pair
    record = GAIN2.as_dict()
    assert {KEY_OF[r] for r in refs()} == {JSON_KEYS[FIELD_OF[r]] for r in refs()}
    assert json_values(record) == {r: v for r, v in part_values(GAIN2).items() if r in refs(with_gain=False)}
    assert json_values(record, with_gain=True) == part_values(GAIN2)
    # a record without every network part, or with one that is no number, has no values
    missing = dict(record)
    del missing[KEY_OF[refs()[0]]]
    assert json_values(missing) is None
    assert json_values({**record, KEY_OF[refs()[1]]: "1k"}) is None
    # the ratio pair gives the gain it is asked for, by its ratio
    pair = ratio_pair(2.5)
    assert set(pair) == set(gain_refs()) and float(gain_of(pair | part_values(UNITY))) == 2.5
