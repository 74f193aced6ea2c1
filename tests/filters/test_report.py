"""The filter's build sheet (designer.filters.report): the cascade's schematic is
its deck (every drawn terminal on the deck's net, for Sallen-Key, MFB, first-order,
band-pass sections, in dual and single packages), the decoupling never takes a
stage's designator, the bill of materials lists every part once, and
``design-filter --out`` / ``--name`` write the whole sheet (or nothing)."""

import csv
import io
import json
import os
import subprocess

import pytest
from helpers import script

from designer.cli.filter import design_filter_main
from designer.core import opamps
from designer.filters import Cascade, get
from designer.filters.design import design
from designer.filters.report import build_board, draw_cascade, sheet_of, sections
from designer.filters.spec import FilterSpec
from designer.report.document import to_text
from designer.report.schematic import check_connectivity
from designer.spice.deck import board

SPECS = {
    "sk-lp4-dual": dict(family="butterworth", order=4, fc_hz=1000, opamp="TL072"),
    "mfb-cheb-lp5": dict(family="chebyshev", ripple_db=0.5, order=5, fc_hz=1000, topology="mfb", opamp="TL072"),
    "sk-hp3-single": dict(filter_type="highpass", family="bessel", order=3, fc_hz=1000, opamp="LM741-seed"),
    "bp-narrow": dict(filter_type="bandpass", family="butterworth", order=2, f_low_hz=900, f_high_hz=1100,
                      opamp="TL072"),
    "bp-wide-gain": dict(filter_type="bandpass", family="butterworth", order=2, f_low_hz=300, f_high_hz=3000,
                         gain=4, opamp="TL072"),
}


@pytest.fixture(scope="module", params=list(SPECS))
def result(request):
    return design(FilterSpec(**SPECS[request.param]), simulate=False)


def test_schematic_is_the_deck(result):
    b = build_board(result)
    sheet = draw_cascade(b, result)
    assert check_connectivity(sheet, b.netlist.terminals()) == []
    drawn = {ref for ref, _ in sheet.pins}
    assert drawn == {p.ref for p in b.netlist.parts} | {a.ref for a in b.netlist.amps}


def test_a_wrong_drawing_is_caught(result):
    # the check is not vacuous: one part's ends swapped onto other nets is reported
    b = build_board(result)
    sheet = draw_cascade(b, result)
    terms = dict(b.netlist.terminals())
    p = b.netlist.parts[0]
    terms[(p.ref, "a")] = "vout" if p.a != "vout" else "vin"
    assert check_connectivity(sheet, terms)


def test_bom_lists_every_part_once_and_decoupling_apart(result):
    b = build_board(result)
    refs = [p.ref for p in b.parts()]
    assert len(refs) == len(set(refs))
    text = to_text("t", sections(sheet_of(result), with_images=False))
    for p in b.parts():
        assert p.ref in text
    n_ics = len(b.ics)
    per = b.package.per_package
    assert n_ics == -(-len(result.stages) // per)   # stages share dual and quad packages


def test_decoupling_names_clear_of_ten_stages():
    rc = get("rc-lowpass")
    cascade = Cascade([(rc, {"R1": 1e4, "C1": 1e-8})] * 10)
    for kind in ("single", "dual", "quad"):
        b = board(cascade.netlist(), opamps.get("TL072"), kind, decoupling_digit="9")
        refs = [p.ref for p in b.parts()]
        assert len(refs) == len(set(refs)), kind
    # the plant's and the PID's boards keep their names
    assert [p.ref for p in board(cascade.netlist(), opamps.get("TL072"), "dual").decoupling][-2:] == ["C901", "C902"]


def test_out_folder_holds_the_sheet(tmp_path):
    out = tmp_path / "lp"
    (tmp_path / "lp").mkdir()
    (out / "mine.txt").write_text("kept")
    run = subprocess.run([script("design-filter"), "--family", "bessel", "--order", "3", "--fc", "1k", "--opamp",
                          "TL072", "--no-sim", "--json", "--out", str(out)], capture_output=True, text=True, timeout=300)
    assert run.returncode == 0, run.stderr
    d = json.loads(run.stdout)
    for key in ("deck", "result_json", "build_sheet_md", "build_sheet_html", "bom_csv", "schematic", "bode",
                "time_test", "group_delay"):
        assert os.path.getsize(d["files"][key]) > 0, key
    assert (out / "mine.txt").read_text() == "kept"
    assert not [p for p in tmp_path.iterdir() if p.name.startswith(".")]   # no staging folder left
    saved = json.loads((out / "result.json").read_text())
    assert saved["bench"]["sweep"] and saved["bench"]["group_delay"]["dc_delay_s"] > 0
    html = (out / "build-sheet.html").read_text()
    for words in ("Bench test: sine sweep", "Bench test: step", "Why the values differ from a table", "<svg",
                  "Wiring", "pin"):
        assert words in html, words
    rows = list(csv.reader(io.StringIO((out / "bom.csv").read_text())))
    assert rows[0][0] == "Ref" and any("TL072" in r for r in rows)


def test_name_writes_the_bundle(tmp_path):
    assert design_filter_main(["--order", "2", "--fc", "1k", "--no-sim", "--opamp", "TL072", "--name", "f2",
                               "--out", str(tmp_path)]) == 0
    rep = tmp_path / "reports" / "f2"
    for f in ("build-sheet.html", "build-sheet.md", "result.json", "bode.png", "time-test.png", "schematic.png",
              "bom.csv", "f2.cir"):
        assert (rep / f).stat().st_size > 0, f
    assert (tmp_path / "netlists" / "f2.cir").read_text() == (rep / "f2.cir").read_text()


def test_bad_name_writes_nothing(tmp_path, capsys):
    assert design_filter_main(["--order", "2", "--fc", "1k", "--no-sim", "--name", "../x", "--out",
                               str(tmp_path)]) == 2
    err = capsys.readouterr().err
    assert err.count("\n") == 1 and "--name" in err
    assert list(tmp_path.iterdir()) == []


def _print_helpers():
    """tests/report/test_print.py's headless Chromium and page count (one way to print, shared)."""
    import importlib.util

    from helpers import TESTS
    spec = importlib.util.spec_from_file_location("report_print_helpers", TESTS / "report" / "test_print.py")
    mod = importlib.util.module_from_spec(spec)
    spec.loader.exec_module(mod)
    return mod


@pytest.mark.chromium
@pytest.mark.parametrize("paper", ["A4", "letter"])
@pytest.mark.parametrize("name", ["filter_butterworth_lp4_sk_1k", "filter_chebyshev0.5_lp5_mfb_mask1k"])
def test_reference_sheet_prints_on_three_pages(name, paper, tmp_path):
    from helpers import REPORTS
    path = REPORTS / name / "build-sheet.html"
    if not path.exists():
        pytest.skip(f"{path} not generated (run make demo)")
    h = _print_helpers()
    page = tmp_path / f"{paper}.html"
    page.write_text(path.read_text().replace("<style>", f"<style>@page{{size:{paper}}}", 1))
    pdf = tmp_path / f"{paper}.pdf"
    out = h.chromium(tmp_path, f"--print-to-pdf={pdf}", "--no-pdf-header-footer", page.as_uri())
    assert pdf.exists() and pdf.stat().st_size > 0, out.stderr[-2000:]
    assert 1 <= h.pages(pdf) <= 3


SPANISH = {
    "bessel-delay": ["--family", "bessel", "--passband", "1k", "--max-loss", "3", "--stopband", "10k",
                     "--min-attenuation", "30", "--max-delay-error", "1", "--delay-to", "1k", "--opamp", "TL072",
                     "--name", "bessel_delay"],
    "bandpass-mask": ["--type", "bandpass", "--passband", "900,1.1k", "--max-loss", "1", "--stopband", "600,1.7k",
                      "--min-attenuation", "30", "--opamp", "TL072", "--name", "bp_mask", "--no-sim"],
}


@pytest.mark.spice
@pytest.mark.parametrize("key", sorted(SPANISH))
def test_the_spanish_sheet_leaves_no_english_message(key, tmp_path):
    from helpers import sheet_command, spanish_sheet
    summary, rep, page, nodes = spanish_sheet("design-filter", SPANISH[key], tmp_path / "es")
    assert "<html lang='es'>" in page and "Lista de materiales" in page and "Bill of materials" not in page
    md = (rep / "build-sheet.md").read_text()
    assert "Prueba en banco: barrido senoidal" in md and "Target and achieved" not in md
    if key == "bessel-delay":
        assert "retardo de grupo de DC a 1 kHz" in md and "Prueba en banco: escalón" in md
    else:
        assert "pérdida <= 1 dB de 900 Hz a 1,1 kHz" in md and "por debajo de 600 Hz y por encima de 1,7 kHz" in md
    # English is the code's own text: the same sheet without --lang; the data files keep their columns
    _, rep_en = sheet_command("design-filter", SPANISH[key], tmp_path / "en")
    en = (rep_en / "build-sheet.md").read_text()
    assert "Target and achieved" in en and "Prueba" not in en
    bom_en, bom_es = ((r / "bom.csv").read_text().splitlines() for r in (rep_en, rep))
    assert bom_en[0] == bom_es[0] and len(bom_en) == len(bom_es)


def test_the_spanish_sheet_names_the_package_and_the_schematics_stages_in_spanish():
    """Issue 29 (the Filter page in Spanish): the sheet's BOM gives the op-amp's package in the sheet's language,
    and the schematic's stage labels (the page draws it too) are the catalogue's, numbers with a decimal comma;
    in English both stay the code's own text."""
    import re

    from designer.core.i18n import catalogue, language
    from designer.filters.report import schematic, title_of
    es = catalogue("es")
    r = design(FilterSpec(**SPECS["sk-hp3-single"]), simulate=False)   # order 3: a first-order stage; DIP-8 single
    sheet = sheet_of(r)
    for lang, words, point in (("es", es, ","), ("en", {}, ".")):
        with language(lang):
            text = to_text(title_of(r), sections(sheet, with_images=False))
            svg = schematic(sheet).svg()
        t = {m: words.get(m, m) for m in ("DIP-8 single", "first order", "Stage {number}: {topology}")}
        assert t["DIP-8 single"] in text
        assert t["first order"] in svg and t["Stage {number}: {topology}"].format(number=1, topology="") in svg
        assert re.search(rf"fn \d+[{point}]\d+ Hz, Q 0[{point}]\d+", svg), svg


def test_the_sheet_shows_the_delay_per_stage_rounding_would_give():
    # a delay target's design: the sheet names the joint choice's delay error beside the per-stage rounding's and
    # the all-nearest's, as it does for the dB deviation (the figures design() computed)
    r = design(FilterSpec(family="bessel", passband_hz=1e3, max_loss_db=3, stopband_hz=10e3, min_attenuation_db=30,
                          max_delay_error_pct=1, delay_to_hz=1e3, opamp="TL072"), simulate=False)
    f = r.figures
    text = to_text("sheet", sections(sheet_of(r), with_images=False))
    assert (f"the delay departs {f['delay_error_pct']:.3g} % from its DC value (at most 1 % asked), against "
            f"{f['delay_error_per_stage_pct']:.3g} % when each stage is rounded on its own and "
            f"{f['delay_error_nearest_pct']:.3g} % with every part") in " ".join(text.split())
    # without a target the sheet says nothing of it
    plain = design(FilterSpec(**SPECS["sk-lp4-dual"]), simulate=False)
    assert "group-delay target" not in to_text("sheet", sections(sheet_of(plain), with_images=False))


def test_the_sheet_lists_the_alternatives_only_when_asked(tmp_path, capsys):
    """Issue 27: design-filter --alternatives N puts the joint search's best part sets on the build sheet (a table:
    rank, deviation, the mask met or broken, every part), the same sets as the JSON's (design_alternatives'); in
    Spanish its words are the catalogue's; without --alternatives the sheet has no such section (the reference
    sheets under reports/ keep theirs)."""
    from designer.core.i18n import catalogue
    from designer.filters.alternatives import design_alternatives
    from designer.report.document import to_text as text_of
    argv = ["--family", "chebyshev", "--passband", "1k", "--max-loss", "1", "--stopband", "3k", "--min-attenuation",
            "30", "--opamp", "TL072", "--no-sim"]
    assert design_filter_main(argv + ["--alternatives", "3", "--json", "--out", str(tmp_path / "en")]) == 0
    printed = json.loads(capsys.readouterr().out)
    saved = json.loads((tmp_path / "en" / "result.json").read_text())
    r = design(FilterSpec(family="chebyshev", passband_hz=1e3, max_loss_db=1, stopband_hz=3e3, min_attenuation_db=30,
                          opamp="TL072"), simulate=False)
    want = design_alternatives(r, 3)
    assert printed["alternatives"] == saved["alternatives"] == [a.to_dict() for a in want]
    md = (tmp_path / "en" / "build-sheet.md").read_text()
    table = md.split("## Alternatives (best first)")[1].split("\n## ")[0]
    rows = [line for line in table.splitlines() if line.startswith("| ") and line[2].isdigit()]
    assert len(rows) == 3 and "| rank | worst deviation from the ideal | limits | parts |" in table
    for row, a in zip(rows, want):
        cells = [c.strip() for c in row.strip("|").split("|")]
        assert cells[:2] == [str(a.rank), f"{a.error_db:.3g} dB"]
        assert cells[2] == ("meets the limits" if a.violation <= 0 else f"breaks the limits by {a.violation:.3g}")
        for ref in a.parts:
            assert f"{ref} " in cells[3]
    assert "Alternatives (best first)" in (tmp_path / "en" / "build-sheet.html").read_text()
    # in Spanish: the section's words from the catalogue
    es = catalogue("es")
    assert design_filter_main(argv + ["--alternatives", "2", "--lang", "es", "--out", str(tmp_path / "es")]) == 0
    md_es = (tmp_path / "es" / "build-sheet.md").read_text()
    for m in ("Alternatives (best first)", "worst deviation from the ideal", "meets the limits", "rank"):
        assert es[m] in md_es and m not in md_es, m
    # not asked: no section, no key (the sheet of sheet_of alone)
    assert "Alternatives" not in text_of("sheet", sections(sheet_of(r), with_images=False))
    assert "alternatives" not in sheet_of(r).to_dict()
