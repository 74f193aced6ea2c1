"""The schematics show the decks: every part's terminals in the drawing land on
the nets the deck uses (a connectivity check, as SOFIA does), for the plant
with K = 1 and K > 1 and for the whole PID loop in each package option."""

import re

import pytest
from helpers import deck_terminals

from designer.core import opamps
from designer.core.errors import DesignError
from designer.pid.blocks import seed_parts
from designer.pid.netlist import closed_loop_deck, loop_netlist
from designer.pid.schematic import draw_loop
from designer.plant.netlist import plant_deck, plant_netlist
from designer.pid.plant import sallen_key_circuit
from designer.plant.sallenkey import SallenKeyParts
from designer.plant.schematic import draw_plant
from designer.report.schematic import check_connectivity
from designer.spice.deck import SquareTest, board

UNITY = SallenKeyParts(1.6e3, 3.9e3, 3.3e-9, 100e-9)
GAIN2 = SallenKeyParts(10e3, 10e3, 10e-9, 10e-9, 2.0, 10e3, 10e3)
TEST = SquareTest(amplitude_v=2.0, frequency_hz=330.0, delay_s=1e-5)
#: the op-amp pins of a deck's X line, in the subcircuit's order


def drawn_terminals(b, deck: str) -> dict:
    """The deck's terminals plus the board's decoupling (between nets the deck has)."""
    terms = deck_terminals(deck)
    nets = set(terms.values())
    for p in b.decoupling:
        assert {p.a, p.b} <= nets, f"{p.ref} is on a net the deck does not have"
        terms[(p.ref, "a")], terms[(p.ref, "b")] = p.a, p.b
    return terms


def package_options():
    for name in opamps.names():
        amp = opamps.get(name)
        for kind in opamps.PACKAGE_KINDS:
            try:
                amp.package(kind)
            except DesignError:
                continue
            yield name, kind


@pytest.mark.parametrize("parts", [UNITY, GAIN2], ids=["K=1", "K=2"])
@pytest.mark.parametrize("name,kind", list(package_options()))
def test_the_plant_drawing_is_its_deck(parts, name, kind):
    amp = opamps.get(name)
    deck = plant_deck(parts, amp, TEST, "t")
    b = board(plant_netlist(parts), amp, kind)
    sheet = draw_plant(b, amp)
    terms = drawn_terminals(b, deck)
    assert check_connectivity(sheet, terms) == []
    # every part of the deck is drawn, with every terminal
    nets, _ = sheet.connectivity()
    assert {k for k in terms if k[0][0] in "RC"} <= set(nets)
    if parts.r3 is not None:
        assert ("R3", "a") in nets and ("R4", "b") in nets   # the gain pair as on the command line


@pytest.mark.parametrize("derivative", [True, False], ids=["PID", "PI"])
@pytest.mark.parametrize("name,kind", list(package_options()))
def test_the_loop_drawing_is_its_deck(derivative, name, kind):
    from dataclasses import replace
    amp = opamps.get(name)
    parts = seed_parts() if derivative else replace(seed_parts(), r7=None, r11=None, r12=None, c3=None)
    plant = sallen_key_circuit(SallenKeyParts(820, 1e3, 10e-9, 220e-9))   # the flags' record, converted once
    deck = closed_loop_deck(parts, plant, amp, TEST, "t", 2.0)
    b = board(loop_netlist(parts, plant), amp, kind)
    sheet = draw_loop(b, amp)
    terms = drawn_terminals(b, deck)
    assert check_connectivity(sheet, terms) == []
    nets, _ = sheet.connectivity()
    deck_parts = {k for k in deck_terminals(deck) if k[0][0] in "RC"}
    assert deck_parts <= set(nets)
    amps = {k[0] for k in deck_terminals(deck) if k[0].startswith("U")}
    assert amps == {a.ref for a in b.netlist.amps}
    assert all((a, "out") in nets for a in amps)


def test_a_gain_plant_in_the_loop_is_drawn_with_its_prefixed_designators():
    # the controller owns R3, R4: the plant's section comes in with the chaining prefix (RP1 .. RP4), and the
    # drawing finds its parts by the same prefix
    from designer.pid.netlist import plant_ref_prefix
    amp = opamps.get("LM741")
    plant = sallen_key_circuit(SallenKeyParts(10e3, 10e3, 10e-9, 10e-9, 1.5, 10e3, 5e3))
    deck = closed_loop_deck(seed_parts(), plant, amp, TEST, "t", 2.0)
    b = board(loop_netlist(seed_parts(), plant), amp)
    sheet = draw_loop(b, amp, plant_prefix=plant_ref_prefix(plant))
    terms = drawn_terminals(b, deck)
    assert check_connectivity(sheet, terms) == []
    nets, _ = sheet.connectivity()
    assert {("RP3", "a"), ("RP4", "b"), ("RP1", "a"), ("R3", "a"), ("R4", "a")} <= set(nets)


def test_a_miswired_drawing_is_caught():
    amp = opamps.get("LM741")
    deck = plant_deck(UNITY, amp, TEST, "t")
    b = board(plant_netlist(UNITY), amp)
    sheet = draw_plant(b, amp)
    terms = drawn_terminals(b, deck)
    wrong = dict(terms)
    wrong[("C1", "b")] = "out"          # as if C1 went to the output instead of ground
    assert any("C1" in p or "joins" in p or "separate" in p for p in check_connectivity(sheet, wrong))
    swapped = dict(terms)
    swapped[("U1", "inp")], swapped[("U1", "inn")] = terms[("U1", "inn")], terms[("U1", "inp")]
    assert check_connectivity(sheet, swapped)


def test_the_drawing_shows_designators_codes_pins_and_probes():
    amp = opamps.get("TL072")
    b = board(loop_netlist(seed_parts(), sallen_key_circuit(SallenKeyParts(820, 1e3, 10e-9, 220e-9))), amp, "quad")
    svg = draw_loop(b, amp).svg()
    texts = set(re.findall(r"<tspan[^>]*>([^<]+)<", svg))
    joined = " ".join(texts)
    for s in ("R15", "10k", "C4", "47n", "U1A", "U2C", "TL074", "CH1", "CH2", "TP ve", "TP vi"):
        assert s in joined, s
    # TL074 pins: unit C's output is pin 8, unit D's inputs 13 and 12
    assert " 8 " in f" {joined} " and " 13 " in f" {joined} "


def test_a_package_the_opamp_does_not_come_in_is_refused():
    with pytest.raises(DesignError, match="NE5532 has no quad package"):
        opamps.get("NE5532").package("quad")
    with pytest.raises(DesignError, match="unknown package"):
        opamps.get("TL072").package("octal")
