"""No NaN or infinity reaches a user from a plant on a registered section (designer.plant.circuit,
designer.plant.circuit_design): a quantity that does not exist is None (JSON null) and the sheet says so,
one that exists is computed. ``result.json`` goes through :func:`designer.core.jsonio.json_safe`, which
writes a NaN as null, so the sweep checks the object before it (a strict cleaner in its place) as well as
the sheet's text and the sensitivities.

The sweep is over the whole registry (a new section is picked up without editing this file), the slowest
and a fast catalogue op-amp, fc from 10 Hz to 100 kHz, a light and a heavy damping and gains 1 and 3
(each where the section takes it): designed (``design-plant --topology``, specs beyond the op-amp's reach
refused) and the exact synthesis analysed as built (``analyze-plant --topology``, which takes any parts:
there the op-amp's pole meets the section's)."""

import math
import re

import numpy as np
import pytest

from designer.core import opamps
from designer.core.errors import DesignError
from designer.filters import REGISTRY
from designer.plant import circuit, circuit_design
from designer.plant.circuit_design import analyze_circuit_plant, design_circuit_plant
from designer.plant.circuit_report import summary_text
from designer.plant.spec import PlantSpec

TOPOLOGIES = list(REGISTRY.values())
IDS = [t.name for t in TOPOLOGIES]
#: the catalogue's slowest op-amp (its pole nearest a section's) and a fast one
OPAMPS = ("LM358", "NE5532")
FCS = (10.0, 1e3, 100e3)


def strict(obj, path="$"):
    """json_safe's walk, raising on a non-finite number with its path (json_safe would write null)."""
    if isinstance(obj, dict):
        return {k: strict(v, f"{path}.{k}") for k, v in obj.items()}
    if isinstance(obj, (list, tuple)):
        return [strict(v, f"{path}[{i}]") for i, v in enumerate(obj)]
    if isinstance(obj, np.ndarray):
        return strict(obj.tolist(), path)
    if isinstance(obj, np.bool_):
        return bool(obj)
    if isinstance(obj, (np.floating, np.integer)):
        obj = obj.item()
    if isinstance(obj, float) and not math.isfinite(obj):
        raise AssertionError(f"{path} is {obj!r}")
    return obj


def assert_finite(result, where: str) -> None:
    """The result's JSON, its sensitivities and its sheet hold no NaN or infinity."""
    try:
        result.to_dict()
    except AssertionError as e:
        raise AssertionError(f"{where}: {e}") from None
    for table in result.sensitivity.values():
        for label, row in table.items():
            assert all(v is None or math.isfinite(v) for v in row.values()), (where, label, row)
    bad = [line for line in summary_text(result).splitlines() if re.search(r"(?i)\b(nan|inf)\b", line)]
    assert not bad, (where, bad)


def grid(topology):
    zetas = (None,) if topology.order == 1 else (0.1, 2.0)
    for fc in FCS:
        for zeta in zetas:
            for gain in (1.0, 3.0):
                yield fc, zeta, gain


@pytest.mark.parametrize("topology", TOPOLOGIES, ids=IDS)
def test_no_nan_or_inf_reaches_the_json_or_the_sheet(topology, monkeypatch):
    monkeypatch.setattr(circuit_design, "json_safe", strict)
    designed = analysed = 0
    for fc, zeta, gain in grid(topology):
        try:
            exact = topology.synthesize(circuit.plant_target(topology, fc, zeta, gain))
        except DesignError:
            continue     # a gain this section does not take
        for amp in OPAMPS:
            where = f"{topology.name} {amp} fc {fc:g} zeta {zeta} gain {gain:g}"
            try:
                r = design_circuit_plant(PlantSpec(fc_hz=fc, zeta=zeta, gain=gain, opamp=amp,
                                                   topology=topology.name), simulate=False)
            except DesignError:
                pass     # beyond the op-amp's reach, no parts close enough
            else:
                assert_finite(r, "design " + where)
                designed += 1
            assert_finite(analyze_circuit_plant(topology.name, exact, amp, simulate=False), "analyze " + where)
            analysed += 1
    assert designed and analysed


def test_a_first_order_section_past_its_op_amps_reach_has_a_finite_fn():
    """Root cause of the NaN (bug): the inverting high-pass at fc 100 kHz, gain 3, on an LM358 (GBW 700 kHz,
    noise gain 4): its pole and the op-amp's merge into a complex pair, there was no real pole to take, and
    the op-amp-aware fn was inf (the sheet 'inf Hz', JSON null) and every wn sensitivity NaN. fn is now the
    slowest pole's |p|, as numpy's roots of the op-amp-aware denominator give it; all real, the real pole's
    corner as before."""
    topo, amp = REGISTRY["inverting-highpass"], opamps.get("LM358")
    values = topo.synthesize(circuit.plant_target(topo, 100e3, None, 3.0))
    den = np.asarray(circuit.opamp_tf(topo, values, amp)[1], float)
    poles = np.roots(den)
    assert np.all(np.abs(poles.imag) > 0.1 * np.abs(poles))     # a complex pair, no real pole
    fn = float(circuit.circuit_figures(topo, values, amp)["fn_hz"])
    assert fn == pytest.approx(np.min(np.abs(poles)) / (2 * math.pi), rel=1e-9)
    s = circuit.sensitivities(topo, values, amp)
    assert all(math.isfinite(row["wn"]) and row["zeta"] is None for row in s.values())
    # a real pole (fc 1 kHz): its corner, as before
    values = topo.synthesize(circuit.plant_target(topo, 1e3, None, 3.0))
    poles = np.roots(np.asarray(circuit.opamp_tf(topo, values, amp)[1], float))
    assert np.all(poles.imag == 0)
    fn = float(circuit.circuit_figures(topo, values, amp)["fn_hz"])
    assert fn == pytest.approx(np.min(np.abs(poles)) / (2 * math.pi), rel=1e-9)


def test_unstable_tolerance_corners_are_counted_not_stepped():
    """Root cause (bug): a Sallen-Key gain-100 high-pass at zeta 0.01 (Q 50) on its 5 %/10 % corners: positive
    feedback past its edge on many of them, whose step grows without bound (exp overflowed: a RuntimeWarning,
    then NaN readings). Each such corner is left out of the step readings and the envelope and counted; the
    count is the corners whose ideal pair has zeta <= 0 (a second-order section is unstable exactly there),
    brute force over the corners."""
    from designer.core.eseries import TOLERANCE
    from designer.plant.bench import corner_tolerances, tolerance_corners
    topo = REGISTRY["sallen-key-highpass-gain"]
    r = design_circuit_plant(PlantSpec(fc_hz=1e3, zeta=0.01, gain=100.0, opamp="ideal", topology=topo.name),
                             simulate=False)
    tol = corner_tolerances(topo, {"R": TOLERANCE[r.sourcing.r_series], "C": TOLERANCE[r.sourcing.c_series]})
    expected = sum(float(topo.ideal_pair(v)[1]) <= 0 for v in tolerance_corners(r.values, tol))
    assert 0 < expected == r.tolerance.unstable_corners
    # said in the notes (result.json's and the sheet's); the band's JSON keeps its {min, max} keys, which
    # identify --against reads back
    assert any(f"{expected} tolerance corners are unstable" in str(n) for n in r.to_dict()["notes"])
    assert f"{expected} tolerance corners are unstable" in summary_text(r)
    assert "unstable_corners" not in r.tolerance.to_dict()
    assert r.tolerance.zeta.lo < 0     # the corners' zeta, real numbers, stay in the band
    stable = design_circuit_plant(PlantSpec(fc_hz=1e3, zeta=0.5, gain=3.0, opamp="ideal", topology=topo.name),
                                  simulate=False)
    assert stable.tolerance.unstable_corners == 0
    assert not any("tolerance corners are unstable" in str(n) for n in stable.to_dict()["notes"])


def test_a_compensated_aim_far_off_is_refused():
    """Root cause (bug): --compensate-gbw skipped the 5 % check: fc 10 mHz, zeta 0.05, gain 100 on an LM741
    built zeta -0.33, an unstable plant 1000 % off, and the bench crashed on its NaN settling time. Now
    refused as the uncompensated target is, naming the compensated aim."""
    with pytest.raises(DesignError) as exc:
        design_circuit_plant(PlantSpec(fc_hz=0.01, zeta=0.05, gain=100.0, opamp="LM741", compensate_gbw=True,
                                       topology="sallen-key-lowpass-gain"), simulate=False)
    msg = str(exc.value)
    assert exc.value.param == "fc_hz" and "\n" not in msg and "off the compensated aim" in msg, msg


def test_unstable_parts_as_built_are_refused():
    """Root cause (bug): analyze-plant --topology on parts whose section is unstable (a Sallen-Key low-pass of
    gain 11 on equal parts: zeta = (2 - 10) / 2 = -4, the closed form 3 - K over 2 at R1 = R2, C1 = C2)
    overflowed in the step and filled the sheet with NaN. Refused in one line, as the seed's plant's are."""
    values = {"R1": 10e3, "R2": 10e3, "C1": 10e-9, "C2": 10e-9, "R3": 1e3, "R4": 10e3}
    with pytest.raises(DesignError) as exc:
        analyze_circuit_plant("sallen-key-lowpass-gain", values, "LM741", simulate=False)
    msg = str(exc.value)
    gain = 1 + values["R4"] / values["R3"]
    assert exc.value.param == "part" and "\n" not in msg and "unstable" in msg
    assert f"zeta {(3 - gain) / 2:.3g}" in msg, msg
