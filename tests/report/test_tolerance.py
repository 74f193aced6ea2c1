"""designer.report.tolerance: a Monte Carlo's histograms (the headline figure's and one
per limited figure) are in the bundle, drawn from the result's own samples, and the
sheet's tolerance section states the yield with its interval and the part to tighten."""

import io
import re

import numpy as np
import pytest
from matplotlib.image import imread

from designer.core import opamps
from designer.pid.design import design_pid
from designer.pid.report import write_outputs as write_pid
from designer.pid.spec import PidSpec
from designer.plant.design import design_plant
from designer.plant.report import write_outputs as write_plant
from designer.plant.spec import PlantSpec
from designer.core.figure_titles import figure_shown
from designer.core.i18n import catalogue, language, localise
from designer.core.units import figure_unit, format_figure
from designer.report.plots import histogram_plot
from designer.report.tolerance import histogram_plots, histogram_words, limit_text, section
from designer.tolerance.loop import loop_monte_carlo
from designer.tolerance.montecarlo import plant_monte_carlo


@pytest.fixture(scope="module")
def plant():
    res = design_plant(PlantSpec(fc_hz=3500, zeta=0.2, alternatives=1), simulate=False)
    res.monte_carlo = plant_monte_carlo(res.built, {"R": "E24", "C": "E12"}, opamps.get("LM741"), 500, 1,
                                        limit_items=["fn_hz=3.3k:3.7k", "overshoot_pct=0:55"])
    return res


def test_the_plant_bundle_holds_a_histogram_per_limited_figure(plant, tmp_path):
    files = write_plant(plant, tmp_path, "mc")
    folder = tmp_path / "reports" / "mc"
    names = {p.rsplit("/", 1)[-1] for p in files["plots"]}
    assert {"mc-fn_hz.png", "mc-overshoot_pct.png"} <= names
    for n in ("mc-fn_hz.png", "mc-overshoot_pct.png"):
        img = imread(io.BytesIO((folder / n).read_bytes()), format="png")
        assert img.shape[0] > 200 and img.shape[1] > 500
    md = (folder / "build-sheet.md").read_text()
    mc = plant.monte_carlo
    lo, hi = mc.yield_interval()
    fn = figure_shown("fn_hz")[0]   # the figure by its title (issue 29); the file keeps the id
    assert "## Tolerance analysis (Monte Carlo)" in md and f"![histogram of {fn}](mc-fn_hz.png)" in md
    assert f"({mc.yield_count} of 500; 95 % Wilson interval" in md
    assert f"Buy {mc.tighten['part']} tighter" in md
    assert f"alt='histogram of {fn}' src='data:image/png;base64," in (folder / "build-sheet.html").read_text()


def test_the_headline_histogram_comes_first_and_without_limits_is_still_drawn(plant):
    assert [n for n, _ in histogram_plots(plant)] == ["mc-fn_hz.png", "mc-overshoot_pct.png"]
    bare = plant_monte_carlo(plant.built, {"R": "E24", "C": "E12"}, opamps.get("LM741"), 50, 1)
    assert bare.headline == "fn_hz" and "no yield" in section(type("R", (), {"monte_carlo": bare})(),
                                                                 with_images=False)[0][1]


def test_the_histogram_draws_what_it_is_given():
    v = np.random.default_rng(0).normal(3500, 50, 400)
    png = histogram_plot(v, "fn_hz", 3500, 3400, 3600)
    assert png[:8] == b"\x89PNG\r\n\x1a\n"
    assert histogram_plot(np.full(10, np.nan), "zeta")[:4] == b"\x89PNG"       # nothing finite: empty axes
    assert [figure_unit(n) for n in ("fn_hz", "peak_time_s", "overshoot_pct", "phase_margin_deg", "gain_margin_db",
                                     "zeta")] == ["Hz", "s", "%", "deg", "dB", ""]


def test_the_pid_sheet_shows_the_loops_tolerance_section(tmp_path):
    res = design_pid(PidSpec(plant_fc_hz=3500, plant_zeta=0.2, tuning="optimize", target_overshoot_pct=10),
                     simulate=False)
    res.monte_carlo = loop_monte_carlo(res, {"R": "E24", "C": "E12"}, 20, seed=1,
                                       limit_items=["phase_margin_deg=27:90"], tighten=False)
    write_pid(res, tmp_path, "loop")
    folder = tmp_path / "reports" / "loop"
    assert (folder / "mc-phase_margin_deg.png").exists() and (folder / "monte-carlo.csv").exists()
    md = (folder / "build-sheet.md").read_text()
    assert "Unstable: " in md and "an op-amp beyond its swing" in md.lower() and "Yield " in md


def test_a_loops_worst_case_is_on_its_sheet(tmp_path):
    """--worst-case on a loop: the PID sheet's tolerance section lists each figure's lowest and highest
    value and the corner that gives it, as the WorstCase found them (a real search, on a box of four
    parts to keep it short)."""
    from designer.tolerance.loop import loop_figures, loop_parts
    from designer.tolerance.worstcase import worst_case
    res = design_pid(PidSpec(plant_fc_hz=3500, plant_zeta=0.2, tuning="optimize", target_overshoot_pct=10),
                     simulate=False)
    parts = loop_parts(res)
    varied = {"R3": 0.05, "C4": 0.10, "R1": 0.05, "C3": 0.10}

    def evaluate(v):
        n = next(iter(v.values())).size
        return loop_figures({**{k: np.full(n, x) for k, x in parts.items()}, **v}, res)
    res.worst_case = worst_case(evaluate, parts, varied, ("phase_margin_deg", "model_overshoot_pct"), maxiter=3)
    write_pid(res, tmp_path, "wc")
    md = (tmp_path / "reports" / "wc" / "build-sheet.md").read_text()
    assert "## Tolerance analysis (worst case)" in md and "| figure | extreme | value | where (parts) |" in md
    pm_lo, pm_hi = res.worst_case.extremes["phase_margin_deg"]
    assert f"| {figure_shown('phase_margin_deg')[0]} | lowest | {pm_lo.value:.4g} deg |" in md
    assert f"|  | highest | {pm_hi.value:.4g} deg |" in md
    for e in (pm_lo, pm_hi):
        up = [r for r, d in e.deviations.items() if d >= 0.995]
        if e.at_corner and up:
            assert f"+tol: {' '.join(up)}" in md
    assert f"{res.worst_case.corners} corners evaluated" in md



def _tolerance_section(md: str) -> str:
    """The sheet's tolerance section (its heading to the next), in either language."""
    lines = md.splitlines()
    start = next(i for i, line in enumerate(lines) if line.startswith("## ") and "Monte Carlo" in line)
    end = next((i for i in range(start + 1, len(lines)) if lines[i].startswith("## ")), len(lines))
    return "\n".join(lines[start:end])


@pytest.mark.parametrize("lang", ["en", "es"])
def test_the_sheets_tolerance_section_names_figures_by_title_with_units_on_values(plant, tmp_path, lang):
    """Issue 29: a sheet written with --lang and a Monte Carlo names no figure by its id (no word with an
    underscore but the histograms' file names) in its tolerance section; each limited figure shows as its title
    in the sheet's language with its window, units on the values; the HTML holds no id but in a file name."""
    write_plant(plant, tmp_path, "mc", lang=lang)
    folder = tmp_path / "reports" / "mc"
    md = _tolerance_section((folder / "build-sheet.md").read_text())
    words = [w.strip("()[]!.,;:") for w in md.split() if "_" in w]
    assert words and all(re.fullmatch(r"(\w+\]\()?mc-\w+\.png", w) for w in words), words
    es = catalogue("es")
    mc = plant.monte_carlo
    with language(lang):
        for lim in mc.limits:
            with language("en"):
                english = figure_shown(lim.figure)[0]
            title, text = figure_shown(lim.figure)[0], limit_text(lim)
            assert title == (es[english] if lang == "es" else english) and text.startswith(title + " ")
            assert format_figure(lim.figure, lim.min) in text and format_figure(lim.figure, lim.max) in text
            assert localise(text) in md
    html = (folder / "build-sheet.html").read_text()
    ids = [f for f in mc.figures if "_" in f]   # zeta, q, gain are words too
    assert ids and not [f for f in ids if re.search(rf"(?<!mc-){f}(?!\.png)", html)]


@pytest.mark.parametrize("lang", ["en", "es"])
def test_a_histograms_title_and_axis_name_the_figure_by_title_and_unit(plant, lang):
    """The bundle's histogram (mc-<id>.png): its title the figure's title, the builds and those outside the
    limits; its axis the title with the unit; in the sheet's language; the PNG drawn from them."""
    mc = plant.monte_carlo
    with language(lang):
        title, unit = figure_shown("overshoot_pct")
        head, label = histogram_words(mc, "overshoot_pct")
        png = dict(histogram_plots(plant))["mc-overshoot_pct.png"](plant)
    assert head.startswith(title) and str(mc.n) in head and str(mc.failing["overshoot_pct"]["count"]) in head
    assert label == f"{title} ({unit})" and "_" not in head + label and png[:4] == b"\x89PNG"
    assert (title == "step overshoot") == (lang == "en")
