"""The build sheet of a plant on a registered section (designer/plant/circuit_report.py): in its two languages
(issue 29: in Spanish no English word is left, in English it is the code's own text), and over the registry (a
new section is picked up without editing this file) its schematic, the filter cascade's drawing of one stage, is
its deck (designer.report.schematic.check_connectivity), and the bundle holds schematic.png and shows it."""

import pickle
from copy import deepcopy

import pytest
from helpers import english_left, foreign, sheet_text_nodes, vocabulary

from designer.core.i18n import Message, catalogue, language, translated
from designer.filters import REGISTRY, registry
from designer.plant import circuit
from designer.plant import circuit_report as rep
from designer.plant.circuit_design import design_circuit_plant
from designer.plant.circuit_report import schematic, summary_text, write_outputs
from designer.plant.spec import PlantSpec
from designer.report.document import to_html
from designer.report.schematic import check_connectivity


def _sheet(result, lang):
    with language(lang):
        return rep.title_of(result), to_html(rep.title_of(result), rep.sections(result), {})


def _plant(topology, simulate=False):
    topo = registry.get(topology)
    zeta = 0.7 if topo.order == 2 else None
    return design_circuit_plant(PlantSpec(fc_hz=1000, zeta=zeta, gain=topo.example.gain, topology=topology),
                                simulate=simulate)


@pytest.mark.parametrize("topology", [n for n in registry.names() if registry.get(n).kind == "lowpass"])
def test_the_spanish_sheet_of_every_low_pass_section_leaves_no_english_word(topology):
    result = _plant(topology)
    title, page = _sheet(result, "es")
    english, _spanish = vocabulary()
    nodes = sheet_text_nodes(page)
    assert english_left(page) == [] and foreign(nodes, english) == []
    assert title.startswith("Planta: " + catalogue("es")[registry.get(topology).title])
    # every declared part's role in the catalogue's Spanish (the BOM's role column, the notes)
    for part in registry.get(topology).parts:
        assert catalogue("es")[part.role] in page
    en_title, en_page = _sheet(result, "en")
    assert en_title.startswith(registry.get(topology).title + " plant: fc 1000 Hz")
    assert all(p.role in en_page for p in registry.get(topology).parts)


@pytest.mark.spice
def test_the_spice_check_s_detail_reads_in_the_sheet_s_language():
    result = _plant("mfb-lowpass", simulate=True)
    check = result.checks[-1]
    assert check.detail.startswith("SPICE .ac against the op-amp-aware model")
    with language("es"):
        assert check.shown().startswith("SPICE .ac frente al modelo")
    _title, page = _sheet(result, "es")
    english, _spanish = vocabulary()
    assert foreign(sheet_text_nodes(page), english) == []


def test_a_message_is_its_english_text_and_keeps_its_values_through_copies():
    """A note is a ``str`` (result.json's English) that a sheet shows in its language, its values too."""
    topo = registry.get("mfb-lowpass")
    part = topo.parts[0]
    note = Message("{section}: parts {parts}", section=Message(topo.title),
                   parts=Message.joined(", ", [Message("{ref} ({role})", ref=part.ref, role=Message(part.role))] * 2))
    assert note == f"{topo.title}: parts {part.ref} ({part.role}), {part.ref} ({part.role})"
    for copy in (deepcopy(note), pickle.loads(pickle.dumps(note))):
        assert isinstance(copy, Message) and copy == note and copy.values.keys() == note.values.keys()
    es = catalogue("es")
    with language("es"):
        assert translated(note) == es["{section}: parts {parts}"].format(
            section=es[topo.title], parts=", ".join([es["{ref} ({role})"].format(ref=part.ref, role=es[part.role])] * 2))
    assert translated(note) == note


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
    # the schematic, and the bench's tolerance band (band.png)
    assert sorted(files["plots"]) == sorted([str(png), str(png.with_name("band.png"))])
    assert png.read_bytes()[:8] == b"\x89PNG\r\n\x1a\n"
    assert "schematic.png" in (tmp_path / "reports" / "mfb" / "build-sheet.md").read_text()
    assert "<svg" in (tmp_path / "reports" / "mfb" / "build-sheet.html").read_text()
    # the terminal summary is the sheet's text without the picture
    text = summary_text(result)
    assert "R1" in text and "<svg" not in text and "schematic" not in text


def test_a_sections_monte_carlo_is_on_its_sheet_and_in_its_summary(tmp_path):
    """A bug: the section plant's sheet showed the Monte Carlo only for a replayed build (--replay I), so a
    Monte Carlo of an MFB low-pass wrote monte-carlo.csv but no tolerance section, no histogram and no summary
    lines (the Sallen-Key plant's have all three)."""
    from designer.tolerance.spice_mc import section_monte_carlo_engine
    from designer.tolerance.worstcase import worst_case
    from designer.plant.circuit_design import tolerance_nominal
    from designer.tolerance.parts import resolve
    result = _plant("mfb-lowpass")
    series = {"R": result.sourcing.r_series, "C": result.sourcing.c_series}
    result.monte_carlo = section_monte_carlo_engine(result, series, 60, seed=5, limit_items=("fn_hz=950:1050",))
    nominal = tolerance_nominal(result)
    result.worst_case = worst_case(lambda v: circuit.evaluate((result.topology, result.opamp), v), nominal,
                                   resolve((), nominal, series).of)
    files = write_outputs(result, tmp_path, "mfb")
    sheet = (tmp_path / "reports" / "mfb" / "build-sheet.md").read_text()
    assert "Tolerance analysis (Monte Carlo)" in sheet and "60 builds drawn" in sheet and "mc-fn_hz.png" in sheet
    assert str(tmp_path / "reports" / "mfb" / "mc-fn_hz.png") in files["plots"]
    text = summary_text(result)
    assert "Monte Carlo: 60 samples" in text and "natural frequency fn (fn_hz): nominal" in text
    assert "Worst case over the tolerance box" in text


def test_a_step_without_a_peak_words_its_peak_time():
    """A first-order section's step has no peak: its sheet says "peak time n/a", as the seed plant's sheet
    says it (it showed a bare "-")."""
    result = _plant("rc-lowpass")
    assert result.steps["opamp"]["peak_time_s"] is None
    _title, page = _sheet(result, "en")
    assert "peak time n/a," in page and "peak time -," not in page
    _title, page = _sheet(result, "es")
    assert f"{catalogue('es')['n/a']}," in page
