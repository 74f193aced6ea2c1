"""Worst case against brute force: a grid over the whole tolerance box."""

import itertools

import numpy as np
import pytest

from designer.core import opamps
from designer.tolerance.plant import plant_figures
from designer.tolerance.worstcase import worst_case

NOMINAL = {"R1": 1.6e3, "R2": 3.9e3, "C1": 3.3e-9, "C2": 100e-9}
TOL = {"R1": 0.05, "R2": 0.05, "C1": 0.10, "C2": 0.10}


def test_plant_extremes_equal_a_brute_force_grid():
    amp = opamps.get("LM741")
    wc = worst_case(lambda v: plant_figures(v, amp), NOMINAL, TOL)
    grid = np.array(list(itertools.product(np.linspace(-1, 1, 9), repeat=4)))
    v = {r: NOMINAL[r] * (1 + TOL[r] * grid[:, k]) for k, r in enumerate(NOMINAL)}
    f = plant_figures(v, amp)
    for fig, (lo, hi) in wc.extremes.items():
        x = f[fig][np.isfinite(f[fig])]
        # the grid holds every corner, so it can only be as extreme as the search
        assert lo.value <= x.min() * (1 + 1e-9) and hi.value >= x.max() * (1 - 1e-9), fig
        assert lo.value == pytest.approx(x.min(), rel=1e-6) and hi.value == pytest.approx(x.max(), rel=1e-6), fig


def test_an_extreme_inside_the_box_is_found():
    # y = -(a - 0.3)^2: its maximum is inside the box, at a deviation of 0.3, not at a corner
    def evaluate(v):
        a = v["A"] / 10.0 - 1.0
        return {"y": -(a / 0.1 - 0.3) ** 2}
    wc = worst_case(evaluate, {"A": 10.0}, {"A": 0.1}, figures=("y",))
    lo, hi = wc.extremes["y"]
    assert lo.at_corner and lo.value == pytest.approx(-1.69)
    assert not hi.at_corner and hi.value == pytest.approx(0.0, abs=1e-9)
    assert hi.deviations["A"] == pytest.approx(0.3, abs=1e-4)


def test_the_sensitivity_corners_find_a_monotone_plants_extremes():
    # a box too large to enumerate (max_corners below 2^4) starts from the corners the slopes point
    # to: for fn and zeta, monotone in every part, they are the extremes every corner gives
    amp = opamps.get("LM741")
    full = worst_case(lambda v: plant_figures(v, amp), NOMINAL, TOL, ("fn_hz", "zeta"))
    fast = worst_case(lambda v: plant_figures(v, amp), NOMINAL, TOL, ("fn_hz", "zeta"), max_corners=8)
    assert fast.corners < full.corners == 16 and "slopes" in fast.method
    for fig in ("fn_hz", "zeta"):
        for a, b in zip(full.extremes[fig], fast.extremes[fig]):
            assert b.value == pytest.approx(a.value, rel=1e-9)


def test_the_search_is_english_in_the_json_and_in_the_sheets_language_on_the_sheet():
    """Issue 29: how the box was searched is result.json's English (a str), and the Spanish sheet's worst-case
    paragraph says it in Spanish, the number of corners kept."""
    import json

    from designer.core.i18n import catalogue, language
    from designer.report.tolerance import worst_case_blocks
    amp = opamps.get("LM741")
    es = catalogue("es")
    for max_corners in (8, 2 ** 20):
        wc = worst_case(lambda v: plant_figures(v, amp), NOMINAL, TOL, ("fn_hz",), max_corners=max_corners)
        data = json.loads(json.dumps(wc.to_dict()))
        assert data["method"] == str(wc.method) and ("slopes" in data["method"]) == (max_corners == 8)
        with language("es"):
            head = worst_case_blocks(wc)[0][1]
        spanish = es[wc.method.message].format(**wc.method.values)
        assert spanish in head and data["method"] not in head
        assert ("(16 esquinas son demasiadas" in head) == (max_corners == 8)   # 2^4 corners, over max_corners 8


def test_a_figure_missing_in_part_of_the_box_is_searched_without_warnings():
    # a Sallen-Key low-pass with gain 2 at zeta 0.7 (design-plant --topology sallen-key-lowpass-gain --fc 100
    # --zeta 0.7 --gain 2 --worst-case) has overdamped corners, where the step has no peak: peak_time_s is NaN
    # there, the search's objective inf, and L-BFGS-B's finite differences took inf - inf (a RuntimeWarning
    # printed to the user). Every other figure's extremes bound a brute-force grid of the box; the peak time
    # grows without bound as zeta nears 1 (the grid finds 55 ms, the search 24 ms at a corner), so the worst
    # case says how many corners lack it instead of passing its range off as the box's.
    from designer.plant import circuit
    nominal = {"R1": 12e3, "R2": 2e3, "C1": 390e-9, "C2": 270e-9, "R3": 1e3, "R4": 1e3}
    tol = {"R1": 0.05, "R2": 0.05, "C1": 0.10, "C2": 0.10, "R3": 0.05, "R4": 0.05}
    context = ("sallen-key-lowpass-gain", opamps.get("LM741"))
    wc = worst_case(lambda v: circuit.evaluate(context, v), nominal, tol)
    grid = np.array(list(itertools.product(np.linspace(-1, 1, 5), repeat=6)))
    f = circuit.evaluate(context, {r: nominal[r] * (1 + tol[r] * grid[:, k]) for k, r in enumerate(nominal)})
    assert np.isnan(f["peak_time_s"]).any() and np.isfinite(f["peak_time_s"]).any()
    signs = np.array(list(itertools.product((-1.0, 1.0), repeat=6)))
    at = circuit.evaluate(context, {r: nominal[r] * (1 + tol[r] * signs[:, k]) for k, r in enumerate(nominal)})
    assert wc.missing == {"peak_time_s": int(np.isnan(at["peak_time_s"]).sum())} and wc.missing["peak_time_s"] > 0
    for fig, (lo, hi) in wc.extremes.items():
        x = f[fig][np.isfinite(f[fig])]
        assert lo.value <= x.min() * (1 + 1e-9), fig
        assert hi.value >= x.max() * (1 - 1e-9) or fig in wc.missing, fig
    d = wc.to_dict()
    assert d["peak_time_s"]["missing_corners"] == wc.missing["peak_time_s"] and "missing_corners" not in d["zeta"]
    line = next(t for t in wc.summary_lines() if "peak_time_s" in t)
    assert line.endswith(f"(no value at {wc.missing['peak_time_s']} of 64 corners: over the builds that have it, "
                         "and may be exceeded near the others)")


def test_a_figure_no_corner_has_is_said_and_not_searched():
    # a first-order section has no peak anywhere: the search on an objective inf everywhere stepped to NaN
    # deviations and the engine raised LinAlgError (design-plant --topology rc-lowpass --fc 100 --worst-case)
    from designer.plant import circuit
    nominal, tol = {"R1": 16e3, "C1": 100e-9}, {"R1": 0.05, "C1": 0.10}
    context = ("rc-lowpass", opamps.get("LM741"))
    wc = worst_case(lambda v: circuit.evaluate(context, v), nominal, tol)
    assert wc.missing == {"zeta": 4, "q": 4, "peak_time_s": 4} and set(wc.extremes) == {"fn_hz", "overshoot_pct"}
    signs = np.array(list(itertools.product((-1.0, 1.0), repeat=2)))
    fn = circuit.evaluate(context, {r: nominal[r] * (1 + tol[r] * signs[:, k]) for k, r in enumerate(nominal)})["fn_hz"]
    assert (wc.extremes["fn_hz"][0].value, wc.extremes["fn_hz"][1].value) == (fn.min(), fn.max())
    assert wc.to_dict()["peak_time_s"] == {"min": None, "max": None, "missing_corners": 4}
    assert "  time to the first peak (peak_time_s): no value at any of the 4 corners" in wc.summary_lines()
