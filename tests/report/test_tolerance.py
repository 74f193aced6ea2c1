"""designer.report.tolerance: a Monte Carlo's histograms (the headline figure's and one
per limited figure) are in the bundle, drawn from the result's own samples, and the
sheet's tolerance section states the yield with its interval and the part to tighten."""

import io

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
from designer.core.units import figure_unit
from designer.report.plots import histogram_plot
from designer.report.tolerance import histogram_plots, section
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
    assert "## Tolerance analysis (Monte Carlo)" in md and "![histogram of fn_hz](mc-fn_hz.png)" in md
    assert f"({mc.yield_count} of 500; 95 % Wilson interval" in md
    assert f"Buy {mc.tighten['part']} tighter" in md
    assert "alt='histogram of fn_hz' src='data:image/png;base64," in (folder / "build-sheet.html").read_text()


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
    assert f"| phase_margin_deg | lowest | {pm_lo.value:.4g} deg |" in md
    assert f"|  | highest | {pm_hi.value:.4g} deg |" in md
    for e in (pm_lo, pm_hi):
        up = [r for r, d in e.deviations.items() if d >= 0.995]
        if e.at_corner and up:
            assert f"+tol: {' '.join(up)}" in md
    assert f"{res.worst_case.corners} corners evaluated" in md
