"""The PID build sheet (designer.pid.report), for both kinds of plant: the Sallen-Key plant's bill of
materials and translated sheet, and a model plant's (issue 16): the bundle it writes, what the sheet says
(the model, every rule side by side, the margins and Ms with their units, the worst case over the 95 %
corners), that it only reads the result, and that the block schematic is the deck (every controller
terminal on the deck's net, the plant block between u, y and ground)."""

import json
import re
from dataclasses import replace

import pytest
from helpers import REPORTS, foreign, sheet_command, spanish_sheet, vocabulary
from helpers import deck_terminals as all_terminals

from designer.core import opamps
from designer.core.errors import DesignError
from designer.core.process_build import fopdt
from designer.pid import report as P
from designer.pid.blocks import seed_parts
from designer.pid.design import PidSpec, design_pid
from designer.pid.netlist import controller_netlist, model_loop_deck
from designer.pid.design import design_model_pid
from designer.pid.rules import RULES
from designer.pid.schematic import PLANT_BLOCK, draw_model_loop
from designer.report.schematic import check_connectivity
from designer.spice.deck import SquareTest, board

FOPDT = "K=2 tau=1m theta=200u"
IDENTIFIED = fopdt(2, 1e-3, 2e-4, source="identify least-squares fopdt (cap.csv)",
                   ci95={"K": 0.05, "tau_s": 5e-5, "theta_s": 2e-5})


def test_bill_of_materials_lists_every_part_once():
    # regression: the plant's op-amp was listed twice; one designator scheme with the plant's sheet
    from designer.pid.report import bom
    result = design_pid(PidSpec(plant_fc_hz=3500, plant_zeta=0.2), simulate=False)
    refs = [ref for row in bom(result) for ref in row[0].split(", ")]
    assert len(refs) == len(set(refs))
    assert {"U1", "U2", "U7", "R1", "R2", "C1", "C2", "R3", "R18", "C3", "C4"} <= set(refs)
    ics = [row for row in bom(result) if row[0].startswith("U")]
    assert len(ics) == 1 and ics[0][3] == 7 and "U1 plant" in ics[0][7] and "U2 difference" in ics[0][7]


def test_a_designed_plant_keeps_its_series_when_the_controller_uses_the_seed_parts():
    # regression: with --seed-parts the plant's parts were listed "as given"
    from designer.pid.report import bom
    result = design_pid(PidSpec(plant_fc_hz=3500, plant_zeta=0.2, kp=45, ti_s=43.215e-6, td_s=10.8037e-6,
                                controller_parts=seed_parts()), simulate=False)
    rows = {ref: row for row in bom(result) for ref in row[0].split(", ")}
    assert rows["R1"][4] == "E24" and rows["C2"][4] == "E12"
    assert rows["R5"][4] == "as given"


def test_a_gain_plants_parts_keep_the_plants_series_under_their_prefix():
    # regression: the BOM knew the plant's parts by a fixed list (R1 R2 C1 C2 R19 R20); the plant with gain is
    # its section prefixed (RP1 .. RP4) beside the controller's own R3, R4
    from designer.pid.report import bom
    from designer.plant.sallenkey import SallenKeyParts
    result = design_pid(PidSpec(plant_parts=SallenKeyParts(10e3, 10e3, 10e-9, 10e-9, 1.5, 10e3, 5e3),
                                opamp="ideal", tuning="simc"), simulate=False)
    rows = {ref: row for row in bom(result) for ref in row[0].split(", ")}
    assert {"RP1", "RP2", "CP1", "CP2", "RP3", "RP4", "R3", "R4"} <= set(rows)
    assert rows["RP3"][4] == rows["RP1"][4] and rows["CP1"][4] == rows["CP2"][4]
    assert "R1" not in rows and "R19" not in rows


def test_renderers_read_the_typed_result_and_compute_nothing(monkeypatch):
    # the build sheet and the plots take the result as it is: no JSON round trip, no design code
    from designer.pid import design, model, report
    from designer.pid.result import PidResult
    result = design_pid(PidSpec(plant_fc_hz=3500, plant_zeta=0.2, tuning="amigo"), simulate=False)
    expected = report.summary_text(result)

    def forbidden(*args, **kwargs):
        raise AssertionError("a renderer called back into the design or its JSON")

    monkeypatch.setattr(PidResult, "to_dict", forbidden)
    for name in ("plant_model", "design_pid", "resolve_plant"):
        monkeypatch.setattr(design, name, forbidden)
    for name in ("loop_gain", "assemble", "margins", "waveform_limits"):
        monkeypatch.setattr(model, name, forbidden)
    assert report.summary_text(result) == expected
    assert set(report.plots(result)) == {"closed-loop.png", "blocks.png", "loop-bode.png",
                                         "reaction-curve.png"}


def test_the_json_keeps_its_keys():
    # the keys of result.json as committed for the references are all there (additions allowed)
    import json

    from helpers import REPORTS
    result = design_pid(PidSpec(plant_fc_hz=3500, plant_zeta=0.2), simulate=False).to_dict()
    ref = json.loads((REPORTS / "pid_zn_lm741_fc3500_z0.2" / "result.json").read_text())
    assert set(ref) <= set(result)
    for key in ("plant", "opamp", "tuning", "components", "series", "achieved", "test_signal", "closed_loop"):
        assert set(ref[key]) <= set(result[key]), key
    assert set(ref["closed_loop"]["analytic"]) <= set(result["closed_loop"]["analytic"])
    assert set(ref["levels"]["analytic"]["gain"]) <= set(result["levels"]["analytic"]["gain"])
    assert [c["name"] for c in result["checks"]] == [c["name"] for c in ref["checks"]]
    assert all(c["id"] == c["name"] for c in result["checks"])
    assert result["closed_loop"]["spice"] is None and result["levels"]["spice"] is None


#: the Makefile demo's Ziegler-Nichols loop (reports/pid_zn_lm741_fc3500_z0.2)
ZN_DEMO = ["--plant-fc", "3500", "--plant-zeta", "0.2", "--opamp", "LM741", "--name", "pid_zn_lm741_fc3500_z0.2"]


@pytest.mark.spice
def test_the_spanish_pid_sheet_leaves_no_english_message_and_writes_decimal_commas(tmp_path):
    summary, _rep, page, nodes = spanish_sheet("design-pid", ZN_DEMO, tmp_path)
    # the verdict's and the tables' figures: a decimal comma, never a point (notes from the library aside)
    assert re.search(r"\d+,\d+ % de sobrepaso", page) and "Ti = 43,75 µs" in page
    headings = re.findall(r"<h2>([^<]*)</h2>", page)
    assert headings[:3] == ["Veredicto", "Montaje", "Cableado"] and "Lazo cerrado" in headings
    assert not any(re.search(r"(?<![\w.])\d+\.\d+\b(?!\.\d)", n) for n in nodes if n in headings)
    assert "Veredicto" in summary and "Verdict" not in summary
    # no English word left: the rules' reasoning (the reaction curve, the fit, the rules' notes) and the verdict's
    # advice included (issue 29)
    english, _spanish = vocabulary()
    assert foreign(nodes, english) == []
    assert "Curva de reacción de ZN: inflexión en" in page and "ZN reaction curve" not in page


#: a model plant (typed) and a plant that is a registered section's circuit (inverting: the action reversed)
MODEL_DEMO = ["--plant-tf", FOPDT, "--name", "model_es"]
MFB_DEMO = ["--plant-topology", "mfb-lowpass", "--plant-part", "R1=10k", "R2=20k", "R3=6k8", "C1=10n", "C2=100n",
            "--name", "mfb_es"]


#: the Makefile demo's seed bench (reports/pid_seed_bench_lm741): the seed's plant with the seed's parts as built,
#: which adds the section on the seed's bench (its thesis's measurements against the predictions)
SEED_BENCH_DEMO = ["--plant-r1", "805", "--plant-r2", "1k", "--plant-c1", "10n", "--plant-c2", "220n", "--opamp",
                   "LM741", "--step", "2", "--r3", "12k", "--r4", "1.777k", "--r5", "22k", "--r6", "3.3k", "--r7",
                   "14.356k", "--r8", "1.2k", "--r9", "10k", "--r10", "10k", "--r11", "10k", "--r12", "1.026k",
                   "--r13", "26.048k", "--r14", "2.528k", "--r15", "10k", "--r16", "3.279k", "--r17", "1.716k",
                   "--r18", "9.98k", "--c3", "4.7n", "--c4", "47n", "--kp", "45", "--ti", "43.215u", "--td",
                   "10.8037u", "--name", "seed_bench_es"]


@pytest.mark.spice
@pytest.mark.parametrize("exe, args", [("design-pid", MODEL_DEMO), ("design-pid", MFB_DEMO),
                                       ("analyze-pid", SEED_BENCH_DEMO)],
                         ids=["plant-tf", "plant-topology", "seed-bench"])
def test_the_spanish_model_plant_sheet_leaves_no_english_word(exe, args, tmp_path):
    """Issue 29: a model plant's sheet (the plant, the rules' models, steps, formulas and notes, the rule table,
    the margins, the scope) in Spanish, a circuit plant's (its sections' titles, where it came from), and the
    seed's bench (the thesis's measurements, the predictions, why they disagree, the runs)."""
    from designer.core.i18n import catalogue
    _summary, rep, page, nodes = spanish_sheet(exe, args, tmp_path)
    english, _spanish = vocabulary()
    assert foreign(nodes, english) == []
    es = catalogue("es")
    if exe == "design-pid":   # a plant given as a model or a section: where it came from
        assert es["Where it came from: {source}."].split("{")[0] in page
    if "mfb-lowpass" in args:   # the half rule's reason (complex poles) for simc and imc, and the section's title
        assert es["does not apply: {reason}"].split("{")[0] + "simc: " in page and "polos complejos" in page
        assert es["MFB low-pass (inverting)"] in page and "MFB low-pass (inverting)" not in page
    if exe == "analyze-pid":   # the seed bench's section, in Spanish; result.json keeps its English
        assert es["The seed's bench: predicted against measured (001, V.13, Figures 88-90)"] in page
        assert es["divider on y, run"] in page and "Why they disagree" not in page
        result = json.loads((rep / "result.json").read_text())
        assert result["seed_bench"]["thesis"]["overshoot"].startswith("suppressed")


@pytest.mark.spice
def test_the_english_pid_sheet_is_byte_identical_to_the_reference(tmp_path):
    _, rep = sheet_command("design-pid", ZN_DEMO, tmp_path)
    for name in ("build-sheet.md", "build-sheet.html"):
        assert (rep / name).read_bytes() == (REPORTS / "pid_zn_lm741_fc3500_z0.2" / name).read_bytes(), name


@pytest.fixture(scope="module")
def simulated():
    return design_model_pid(PidSpec(plant_tf=FOPDT, tuning="amigo"), simulate=True, simulator="ngspice-cli")


@pytest.fixture(scope="module")
def robust():
    return design_model_pid(PidSpec(plant_process=IDENTIFIED, tuning="simc"), simulate=False)


@pytest.mark.spice
def test_the_bundle_is_written(simulated, tmp_path):
    files = P.write_outputs(simulated, tmp_path, "model")
    rep = tmp_path / "reports" / "model"
    names = {p.name for p in rep.iterdir()}
    assert {"build-sheet.md", "build-sheet.html", "result.json", "bom.csv", "schematic.png", "model.cir",
            "closed-loop.png", "blocks.png", "loop-bode.png", "reaction-curve.png"} <= names
    assert (tmp_path / "netlists" / "model.cir").read_text() == simulated.deck
    assert all((rep / n).read_bytes().startswith(b"\x89PNG") for n in names if n.endswith(".png"))
    data = json.loads((rep / "result.json").read_text())
    assert data["plant"]["kind"] == "model" and data["files"]["bom_csv"] == files["bom_csv"]
    bom = (rep / "bom.csv").read_text().splitlines()
    assert bom[0].startswith("Ref,Value,Code") and any(r.startswith('"R15, R16') for r in bom)
    assert not any(r.startswith(("R1,", "C1,", "U7")) for r in bom)     # no Sallen-Key parts, six op-amps
    html = (rep / "build-sheet.html").read_text()
    assert "<svg" in html and "G(s) = 2 e^(-200 us s) / (1 ms s + 1)" in html


@pytest.mark.spice
def test_the_sheet_shows_the_model_every_rule_and_the_margins(simulated):
    md = P.summary_text(simulated)
    assert simulated.model.text() in md and "Where it came from: typed." in md
    assert "The rules see it as FOPDT K 2, tau 1 ms, theta 200 us" in md
    rows = {line.split()[0]: line for line in md.splitlines()
            if line.split() and line.split()[0] in RULES and " deg " in line}
    assert set(rows) == set(RULES)
    assert "built" in rows["amigo"] and " kHz " in rows["zn"] and " uV s " in rows["imc"]
    assert re.search(r"amigo\s+1\.225\s+586\.7 us\s+94\.34 us\s+59\.\d deg\s+9\.\d+ dB\s+40\d\.\d us\s+1\.55", md)
    # the chosen rule's formulas with their numbers, and the loop as built with units
    assert "Kp = (0.2 + 0.45 T/L)/K = (0.2 + 0.45 x 1 ms / 200 us) / 2 = 1.225" in md
    assert re.search(r"phase margin 59\.\d deg at 40\d\.\d Hz, gain margin 9\.\d+ dB at 1\.\d+ kHz, delay margin "
                     r"40\d\.\d us, Ms 1\.55 at 1\.5\d+ kHz", md)
    assert "SPICE vs analytic" in md and "SPICE" in md.split("Closed loop")[-1]
    # the plant's connections in the wiring table, the block in the schematic
    assert re.search(r"plant in\s+controller output u: U6 pin 6 \(out\)", md)
    assert re.search(r"plant out\s+the plant's output y\s+R17 \(to U1 pin 3 \(\+in\)\) and scope CH2", md)
    assert "plant ground" in md
    svg = P.schematic(simulated).svg()
    assert "G(s) = 2 e^(-200 us s) / (1 ms s + 1)" in " ".join(re.findall(r"<tspan[^>]*>([^<]+)<", svg))


def test_the_robust_worst_case_is_on_the_sheet(robust):
    text = P.summary_text(robust)
    assert "Where it came from: identify least-squares fopdt (cap.csv)." in text
    assert re.search(r"theta\s+200 us\s+\+/- 20 us\s+180 us \.\. 220 us", text)
    rb = robust.robust
    at, pm = rb.worst("phase_margin_deg")
    assert f"Worst case over the {len(rb.corners)} corners" in text and len(rb.corners) == 8
    assert f"phase margin {pm:.3g} deg at {at}" in text
    ms_at, ms = rb.worst("ms", -1.0)
    assert f"Ms {ms:.3g} at {ms_at}" in text
    assert all(label in text for label, _ in rb.corners)
    assert "a PI (the differentiator" in text and "not simulated" in text
    assert "SPICE simulation skipped" in text


def test_a_model_plants_sheet_reads_the_typed_result_and_computes_nothing(robust, monkeypatch):
    from designer.pid import delayloop, delaymargins, design, model
    from designer.pid.result import PidResult
    expected = P.summary_text(robust)

    def forbidden(*args, **kwargs):
        raise AssertionError("a renderer called back into the design or its JSON")

    monkeypatch.setattr(PidResult, "to_dict", forbidden)
    for mod, names in ((design, ("design_model_pid", "analyse", "loop_figures", "robust_check",
                                       "rule_table", "model_loop_scope")),
                       (delaymargins, ("loop_margins", "loop_response")), (delayloop, ("closed_loop_step",)),
                       (model, ("controller_tf", "waveform_limits", "stage_tfs"))):
        for name in names:
            monkeypatch.setattr(mod, name, forbidden)
    assert P.summary_text(robust) == expected
    assert set(P.plots(robust)) == {"closed-loop.png", "blocks.png", "loop-bode.png", "reaction-curve.png"}


@pytest.mark.spice
def test_a_pi_renders():
    res = design_model_pid(PidSpec(plant_tf="K=2 tau=1m theta=0", tuning="simc", simc_tauc_s=2e-4),
                           simulate=True, simulator="ngspice-cli")
    text = P.summary_text(res)
    assert not res.parts.has_derivative and "a PI" in text
    for rule in ("zn", "cohen-coon", "chr0", "chr20", "amigo"):
        assert re.search(rf"{rule}\s+-\s+-.*does not apply: {rule}: L = 0", text), rule
    assert "differentiator" not in text.split("Expected scope readings")[-1]
    assert "inf" in text.split("Closed loop")[-1]      # the ideal PI's phase never reaches -180 deg
    assert all(png.startswith(b"\x89PNG") for png in P.plots(res).values())


def test_an_integrating_plant_renders_without_simulation():
    res = design_model_pid(PidSpec(plant_tf="K=50 tau=10m integrator", plant_input="-5:5", plant_output="-2:2"),
                           simulate=False)
    text = P.summary_text(res)
    assert "G(s) = 50 / (s (10 ms s + 1)) (integrating)" in text
    assert "The plant accepts u from -5 V to 5 V and delivers y from -2 V to 2 V" in text
    assert re.search(r"imc\s+-.*does not apply: imc: .*integrating plant", text)
    assert "not simulated" in text and "SPICE vs analytic" not in text
    assert set(P.plots(res)) == {n for n, _ in P.MODEL_PLOTS}
    assert P.schematic(res).png().startswith(b"\x89PNG")


# ---- the block schematic is the deck ------------------------------------------------

TEST = SquareTest(amplitude_v=1.0, frequency_hz=100.0, delay_s=1e-4)


def deck_terminals(deck: str) -> dict:
    """(designator, terminal) -> net of the controller's R, C and X lines
    (:func:`helpers.deck_terminals`, the model's own elements left out), and the
    plant block's: its input (the node the model senses), output (the node it
    drives) and ground."""
    out = {k: v for k, v in all_terminals(deck).items() if "plant" not in k[0]}
    for line in deck.splitlines():
        f = line.split()
        if f and f[0] == "Gplant_u":           # G n+ n- nc+ nc- gain: the model senses u
            out[(PLANT_BLOCK, "in")], out[(PLANT_BLOCK, "gnd")] = f[3], f[4]
        elif f and f[0] == "Eplant_o":         # E n+ n- ...: the model drives y
            out[(PLANT_BLOCK, "out")] = f[1]
    return out


def package_options():
    for name in opamps.names():
        amp = opamps.get(name)
        for kind in opamps.PACKAGE_KINDS:
            try:
                amp.package(kind)
            except DesignError:
                continue
            yield name, kind


def _drawn(parts, name, kind):
    amp = opamps.get(name)
    deck = model_loop_deck(parts, IDENTIFIED, amp, TEST, "t", 1.0)
    b = board(controller_netlist(parts), amp, kind)
    terms = deck_terminals(deck)
    for p in b.decoupling:
        terms[(p.ref, "a")], terms[(p.ref, "b")] = p.a, p.b
    return b, deck, terms, draw_model_loop(b, amp, IDENTIFIED.text())


@pytest.mark.parametrize("derivative", [True, False], ids=["PID", "PI"])
@pytest.mark.parametrize("name,kind", list(package_options()))
def test_the_block_loop_drawing_is_its_deck(derivative, name, kind):
    parts = seed_parts() if derivative else replace(seed_parts(), r7=None, r11=None, r12=None, c3=None)
    b, deck, terms, sheet = _drawn(parts, name, kind)
    assert terms[(PLANT_BLOCK, "in")] == "u" and terms[(PLANT_BLOCK, "out")] == "y"
    assert check_connectivity(sheet, terms) == []
    nets, _ = sheet.connectivity()
    assert {k for k in deck_terminals(deck) if k[0][0] in "RC" or k[0] == PLANT_BLOCK} <= set(nets)
    amps = {k[0] for k in deck_terminals(deck) if k[0].startswith("U")}
    assert amps == {a.ref for a in b.netlist.amps} and all((a, "out") in nets for a in amps)
    # the plant's output reaches R17 and its input is the last op-amp's output, through labels
    assert nets[(PLANT_BLOCK, "out")] == nets[("R17", "a")] and nets[(PLANT_BLOCK, "in")] == nets[("U7", "out")]


def test_a_miswired_block_is_caught():
    _, _, terms, sheet = _drawn(seed_parts(), "LM741", None)
    swapped = dict(terms)
    swapped[(PLANT_BLOCK, "in")], swapped[(PLANT_BLOCK, "out")] = (terms[(PLANT_BLOCK, "out")],
                                                                   terms[(PLANT_BLOCK, "in")])
    assert check_connectivity(sheet, swapped)
    floating = dict(terms)
    floating[(PLANT_BLOCK, "gnd")] = "vee"
    assert check_connectivity(sheet, floating)


@pytest.mark.spice
def test_the_spanish_optimised_sheet_leaves_no_english_word(tmp_path):
    """Issue 29: the optimiser's notes (its target, its verdict) in Spanish on the seed plant's sheet."""
    from designer.core.i18n import catalogue
    args = ["--plant-fc", "3500", "--plant-zeta", "0.2", "--tuning", "optimize", "--target-overshoot", "10",
            "--name", "optimize_es"]
    _summary, _rep, page, nodes = spanish_sheet("design-pid", args, tmp_path)
    english, _spanish = vocabulary()
    assert foreign(nodes, english) == []
    assert catalogue("es")["optimize: target overshoot <= {os} %{ts} for a {step} V step with {opamp} limits"].split(
        "{")[0] in " ".join(nodes) and "<title>PID con" in page


def test_the_spanish_sheet_of_a_trimmed_difference_amplifier_leaves_no_english_word():
    """Issue 29: the section on a difference amplifier that is not balanced (the seed's trimmed bench, not
    simulated) reads in Spanish: which input it attenuates, the loop gain and the other way round."""
    from designer.core.i18n import catalogue, language
    from designer.pid.blocks import seed_bench_parts
    from designer.pid.design import SEED_BENCH_PLANT, analyze_pid
    from designer.report.document import to_text
    result = analyze_pid(PidSpec(plant_parts=SEED_BENCH_PLANT, controller_parts=seed_bench_parts(), opamp="LM741",
                                 step_v=2.0, kp=45, ti_s=43.215e-6, td_s=10.8037e-6), simulate=False)
    with language("es"):
        sections = dict(P.sections(result, with_images=False))
        heading = catalogue("es")["Difference amplifier as built"]
        text = to_text("t", [(heading, sections[heading])])
    english, _spanish = vocabulary()
    assert foreign(text.splitlines(), english) == [] and "U2 pondera la salida y" in text
