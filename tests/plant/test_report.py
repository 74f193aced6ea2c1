"""The plant's build sheet (designer/plant/report.py) in its two languages: Spanish with no English message
left and decimal commas, English byte for byte the committed reference (reports/plant_fc3500_z0.2)."""

import re

import pytest
from helpers import REPORTS, foreign, sheet_command, spanish_sheet, vocabulary

#: the Makefile demo's plant (reports/plant_fc3500_z0.2): a Monte Carlo with limits and the worst case
DEMO = ["--fc", "3500", "--zeta", "0.2", "--monte-carlo", "5000", "--seed", "1", "--limit", "fn_hz=3.3k:3.7k",
        "--limit", "overshoot_pct=0:55", "--worst-case", "--name", "plant_fc3500_z0.2"]
#: a number written with a decimal point (not a file name's dot, nor a dotted run)
DECIMAL_POINT = re.compile(r"(?<![\w.])\d+\.\d+\b(?!\.\d)")
DECIMAL_COMMA = re.compile(r"(?<![\w,])\d+,\d+\b")


def design_plant(out, *args):
    return sheet_command("design-plant", DEMO, out, *args)


@pytest.mark.spice
def test_the_spanish_sheet_leaves_no_english_message_and_writes_decimal_commas(tmp_path):
    summary, rep, page, nodes = spanish_sheet("design-plant", DEMO, tmp_path)
    assert [n for n in nodes if DECIMAL_POINT.search(n)] == []
    assert sum(len(DECIMAL_COMMA.findall(n)) for n in nodes) > 50
    assert "<html lang='es'>" in page and "Planta Sallen-Key: fc 3500 Hz, zeta 0,2, ganancia 1" in page
    assert "1,6 kΩ" in page   # R1, as the BOM and the alternatives give it
    # no English word anywhere on it: the check details, the packages and the pins' notes included (issue 29)
    english, _spanish = vocabulary()
    assert foreign(nodes, english) == []
    # the Markdown and the terminal summary are the same sheet
    md = (rep / "build-sheet.md").read_text()
    assert "\n### Lista de materiales\n" in md and "\n## Cableado\n" in md and "Bill of materials" not in md
    assert "Lista de materiales:" in summary and "Bill of materials" not in summary
    # the data files keep their columns: a CSV is read by programs, in any language
    assert (rep / "bom.csv").read_text().startswith("Ref,Value,Code,Qty,Series,Tolerance,Package,Description\n")


@pytest.mark.spice
def test_the_english_sheet_is_byte_identical_to_the_reference(tmp_path):
    _, rep = design_plant(tmp_path, "--lang", "en")
    for name in ("build-sheet.md", "build-sheet.html"):
        assert (rep / name).read_bytes() == (REPORTS / "plant_fc3500_z0.2" / name).read_bytes(), name


def test_the_library_writes_a_sheet_in_the_language_it_is_given(tmp_path):
    from designer.core.i18n import current
    from designer.plant.design import design_plant as design
    from designer.plant.report import summary_text, write_outputs
    from designer.plant.spec import PlantSpec
    result = design(PlantSpec(fc_hz=3500, zeta=0.2), simulate=False)
    write_outputs(result, tmp_path, "es", lang="es")
    md = (tmp_path / "reports" / "es" / "build-sheet.md").read_text()
    assert md.startswith("# Planta Sallen-Key: fc 3500 Hz, zeta 0,2, ganancia 1\n") and "no simulado" in md
    assert current() == "en" and summary_text(result).startswith("Sallen-Key plant: fc 3500 Hz, zeta 0.2, gain 1\n")
    assert summary_text(result, lang="es").startswith("Planta Sallen-Key")
