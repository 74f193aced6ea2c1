"""The typed result and its one JSON form: the committed reference's keys all
there (additions allowed), checks with stable snake_case ids, and renderers that
read the typed result as it is."""

import json

import numpy as np
import pytest
from helpers import REPORTS

from designer.plant import report
from designer.plant.design import design_plant
from designer.plant.result import PlantResult
from designer.plant.spec import PlantSpec

REFERENCE = REPORTS / "plant_fc3500_z0.2" / "result.json"


def missing_keys(ref, new, path=""):
    """Keys of ``ref`` (recursively, lists element by element) that ``new`` lacks."""
    if isinstance(ref, dict):
        if not isinstance(new, dict):
            return [path or "/"]
        return [m for k, v in ref.items()
                for m in ([f"{path}/{k}"] if k not in new else missing_keys(v, new[k], f"{path}/{k}"))]
    if isinstance(ref, list) and isinstance(new, list):
        return [m for i, (a, b) in enumerate(zip(ref, new)) for m in missing_keys(a, b, f"{path}[{i}]")]
    return []


@pytest.mark.spice
def test_the_json_keeps_every_key_of_the_reference(tmp_path):
    r = design_plant(PlantSpec(3500, 0.2))
    report.write_outputs(r, tmp_path, "p")
    new = r.to_dict()
    ref = json.loads(REFERENCE.read_text())
    # the reference also holds the optional tolerance analyses make demo asks for (--monte-carlo, --worst-case)
    assert new["monte_carlo"] is None and new["worst_case"] is None
    for key in ("monte_carlo", "worst_case"):
        ref[key] = None
    ref["files"].pop("monte_carlo_csv", None)
    assert missing_keys(ref, new) == []
    assert json.loads(json.dumps(new, allow_nan=False)) == new   # plain JSON values only


def test_checks_have_snake_case_ids_and_readable_titles():
    r = design_plant(PlantSpec(3500, 0.2, square_hz=10e3), simulate=False)
    assert [c.id for c in r.checks] == ["slew_rate", "output_swing", "square_wave_period"]
    assert [c["id"] for c in r.to_dict()["checks"]] == ["slew_rate", "output_swing", "square_wave_period"]
    assert not r.checks[-1].ok
    assert "square-wave period" in report.summary_text(r)


def test_renderers_read_the_typed_result_and_never_its_json(monkeypatch):
    r = design_plant(PlantSpec(1e3, 0.5, gain=2.0, r_series="E96"), simulate=False)

    def no_json(self):
        raise AssertionError("a renderer read to_dict()")

    monkeypatch.setattr(PlantResult, "to_dict", no_json)
    text = report.summary_text(r)
    assert "Bill of materials" in text and "R3" in text and "R4" in text and "not simulated" in text
    lines = report.waveforms_csv(r).splitlines()
    assert lines[0] == "time_s,input_v,output_v,analytic_v,analytic_opamp_v" and len(lines) == 4002
    data = np.loadtxt(lines[1:], delimiter=",")
    # not simulated: the output column is the op-amp-aware model
    assert np.array_equal(data[:, 2], data[:, 4])


def test_the_result_is_typed_to_the_leaves():
    r = design_plant(PlantSpec(3500, 0.2), simulate=False)
    assert r.analytic.figures.fn_hz == r.built.fn_hz == r.alternatives[0].figures.fn_hz
    assert r.analytic_opamp.figures.fn_error_pct == pytest.approx(100 * (r.analytic_opamp.figures.fn_hz / 3500 - 1))
    assert r.tolerance.fn_hz.lo < r.built.fn_hz < r.tolerance.fn_hz.hi
    assert r.sourcing.parts["R1"].tolerance_pct == 5.0 and r.sourcing.c_tolerance_pct == 10.0
    assert r.ratios.m == pytest.approx(r.ideal.r1 / r.ideal.r2)
    d = r.to_dict()
    assert d["spice"] is None and d["comparison"] == {} and d["simulator"] is None
    assert d["opamp"] == r.opamp.to_dict() and d["test_signal"] == r.test.to_dict()


def test_both_plants_bills_of_materials_read_a_parts_source_from_the_sourcing():
    # one lookup (Sourcing.source) for the Sallen-Key sheet's and a section plant's bill of materials
    from designer.plant import circuit_report
    from designer.plant.circuit_design import design_circuit_plant

    res = design_plant(PlantSpec(fc_hz=3500, zeta=0.2), simulate=False)
    for ref, src in res.sourcing.parts.items():
        assert res.sourcing.source(ref) == (src.series, src.tolerance_pct)
    assert res.sourcing.source("U1") is None
    section = design_circuit_plant(PlantSpec(fc_hz=1000, zeta=0.5, topology="mfb-lowpass"), simulate=False)
    for result, rows in ((res, report.bom(res)), (section, circuit_report.bom(section))):
        # a row lists equal parts together ("R1, R2")
        row_of = {ref: r for r in rows for ref in r[0].split(", ")}
        for ref in result.sourcing.parts:
            series, tol = result.sourcing.source(ref)
            assert series in row_of[ref] and f"{tol:g} %" in row_of[ref]
