"""The build sheet of a plant on a registered topology (designer.plant.circuit_report), over
the registry (a new section is picked up without editing this file): its schematic is the
filter cascade's drawing of one stage and is its deck (every drawn terminal on the deck's
net, checked by designer.report.schematic.check_connectivity), and the bundle holds
schematic.png and shows it on build-sheet.md and .html."""

import pytest

from designer.filters import REGISTRY
from designer.plant import circuit
from designer.plant.circuit_design import design_circuit_plant
from designer.plant.circuit_report import schematic, summary_text, write_outputs
from designer.plant.spec import PlantSpec
from designer.report.schematic import check_connectivity

TOPOLOGIES = [t for t in REGISTRY.values() if t.name != circuit.DEFAULT_TOPOLOGY]
IDS = [t.name for t in TOPOLOGIES]


def design_of(topology, opamp="TL072"):
    """The topology's example designed as a plant (no SPICE run: the drawing reads none of it)."""
    ex = topology.example
    spec = PlantSpec(fc_hz=ex.fn_hz, zeta=None if ex.q is None else 1 / (2 * ex.q), gain=ex.gain, opamp=opamp,
                     topology=topology.name)
    return design_circuit_plant(spec, simulate=False)


@pytest.fixture(scope="module", params=TOPOLOGIES, ids=IDS)
def result(request):
    return design_of(request.param)


def test_the_schematic_is_the_deck(result):
    sheet = schematic(result)
    assert check_connectivity(sheet, result.netlist.terminals()) == []
    drawn = {ref for ref, _ in sheet.pins}
    assert drawn == {p.ref for p in result.netlist.parts} | {a.ref for a in result.netlist.amps}


def test_a_wrong_drawing_is_caught(result):
    # the check is not vacuous: one part's end moved onto another net is reported
    sheet = schematic(result)
    terms = dict(result.netlist.terminals())
    p = result.netlist.parts[0]
    terms[(p.ref, "a")] = "vout" if p.a != "vout" else "vin"
    assert check_connectivity(sheet, terms)


def test_the_bundle_shows_the_schematic(tmp_path):
    result = design_of(REGISTRY["mfb-lowpass"], opamp="LM741")
    files = write_outputs(result, tmp_path, "mfb")
    png = tmp_path / "reports" / "mfb" / "schematic.png"
    assert files["plots"] == [str(png)] and png.read_bytes()[:8] == b"\x89PNG\r\n\x1a\n"
    assert "schematic.png" in (tmp_path / "reports" / "mfb" / "build-sheet.md").read_text()
    assert "<svg" in (tmp_path / "reports" / "mfb" / "build-sheet.html").read_text()
    # the terminal summary is the sheet's text without the picture
    text = summary_text(result)
    assert "R1" in text and "<svg" not in text and "schematic" not in text
