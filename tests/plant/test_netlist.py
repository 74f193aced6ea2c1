"""The plant's netlist is its Sallen-Key section's: the gain pair is R3/R4 on the plant's own deck, as on the
command line and in check-design (issue 26: it was R19/R20 in the deck)."""

import re

from designer.core import opamps
from designer.filters.sallen_key_lowpass_parts import part_values, section_of
from designer.plant.netlist import plant_ac_deck, plant_deck, plant_netlist
from designer.plant.sallenkey import SallenKeyParts
from designer.spice.deck import SINE_POINTS_PER_DECADE, SquareTest, ac_lines

UNITY = SallenKeyParts(1.6e3, 3.9e3, 3.3e-9, 100e-9)
GAIN2 = SallenKeyParts(10e3, 10e3, 10e-9, 10e-9, 2.0, 10e3, 10e3)
TEST = SquareTest(amplitude_v=2.0, frequency_hz=330.0, delay_s=1e-5)


def test_the_designators_and_roles_are_the_sections():
    for parts in (UNITY, GAIN2):
        net, section = plant_netlist(parts), section_of(parts)
        assert tuple(p.ref for p in net.parts) == section.designators
        assert [p.role for p in net.parts] == [s.role for s in section.parts]
        assert {p.ref: p.value for p in net.parts} == part_values(parts)


def test_the_gain_pair_is_r3_and_r4_in_the_deck():
    # regression: the deck called the gain pair R19 (to ground) and R20 (feedback)
    amp = opamps.get("LM741")
    for deck in (plant_deck(GAIN2, amp, TEST, "t"), plant_ac_deck(GAIN2, amp, 10.0, 1e5, "t")):
        assert re.search(r"^R3 vn 0 ", deck, re.M) and re.search(r"^R4 out vn ", deck, re.M)
        assert "R19" not in deck and "R20" not in deck
    assert not re.search(r"^R[34] ", plant_deck(UNITY, amp, TEST, "t"), re.M)     # a follower has no gain pair


def test_a_designator_prefix_for_a_shared_sheet_moves_every_part_and_no_net():
    plain, shared = plant_netlist(GAIN2, "u", "y", prefix="p"), plant_netlist(GAIN2, "u", "y", prefix="p",
                                                                            ref_prefix="P")
    assert [p.ref for p in shared.parts] == ["RP1", "RP2", "CP1", "CP2", "RP3", "RP4"]
    assert [(p.a, p.b, p.value) for p in shared.parts] == [(p.a, p.b, p.value) for p in plain.parts]


def test_the_sine_checks_deck_is_the_sections_ac_deck_of_the_plant():
    # the plant's .ac deck is the generic one (designer.filters.deck.ac_deck) of its netlist, driven at the plant's
    # own input net at the sine check's density: every element and the sweep as the plant's deck had them
    amp = opamps.get("LM741")
    for parts in (UNITY, GAIN2):
        deck = plant_ac_deck(parts, amp, 10.0, 1e5, "t").splitlines()
        lines = [str(line) for line in ac_lines(10.0, 1e5)]
        assert deck[-1 - len(lines):-1] == lines and lines[0].split()[:2] == [".ac", "dec"]
        assert lines[0].split()[2] == str(SINE_POINTS_PER_DECADE)
        assert "Vin input 0 DC 0 AC 1" in deck
        net = plant_netlist(parts)
        for p in net.parts:
            assert any(line.split()[:3] == [p.ref, p.a, p.b] for line in deck), p.ref
