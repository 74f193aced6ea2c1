"""A PID's plant as a model plus, optionally, its circuit (issue 26): the one
resolver of plant sources, the model of a circuit from its own sections, the
controller's action reversed for an inverting circuit, and a PID for a plant
that is any registered circuit (an MFB low-pass, a first-order section, a
2-stage cascade) designed, simulated with the plant's own sections in the
ngspice deck, and drawn (the drawing checked against the deck)."""

import math

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st
from helpers import deck_terminals

from designer.cli.common import flag_message
from designer.core.errors import DesignError
from designer.filters.registry import REGISTRY, get
from designer.pid import report as P
from designer.pid.design import design_pid
from designer.pid.netlist import controller_netlist, loop_netlist
from designer.pid.plant import (PLANT_PREFIX, Plant, circuit_from_cascade, circuit_plant, parse_part_values,
                                resolve_plant)
from designer.pid.result import PidResult
from designer.pid.spec import PidSpec
from designer.report.schematic import check_connectivity

RC = {"R1": "10k", "C1": "100n"}
MFB = {"R1": "10k", "R2": "20k", "R3": "6k8", "C1": "10n", "C2": "100n"}
SK = {"R1": "10k", "R2": "10k", "C1": "10n", "C2": "47n"}
#: the done-when's three circuits: an MFB low-pass, a first-order section, a 2-stage cascade
CIRCUITS = {"mfb-lowpass": dict(plant_topology="mfb-lowpass", plant_values=MFB),
            "rc-lowpass": dict(plant_topology="rc-lowpass", plant_values=[f"{k}={v}" for k, v in RC.items()]),
            "cascade": dict(plant_circuit=[("rc-lowpass", RC), ("sallen-key-lowpass", SK)])}


def refusal(**kw):
    with pytest.raises(DesignError) as exc:
        PidSpec(**kw)
    return exc.value


# ---- the model of a circuit -------------------------------------------------------------------

def test_a_first_order_plant_is_its_closed_form():
    plant = circuit_plant("rc-lowpass", RC)
    tau = 10e3 * 100e-9
    assert np.allclose(plant.model.num, [1.0]) and np.allclose(plant.model.den, [tau, 1.0])
    assert not plant.reversed_action and plant.design_model is plant.model


def test_a_cascade_is_the_product_of_its_sections():
    plant = circuit_from_cascade(CIRCUITS["cascade"]["plant_circuit"])
    vals = {k: parse_part_values(get("sallen-key-lowpass"), SK)[k] for k in SK}
    a = vals["R1"] * vals["R2"] * vals["C1"] * vals["C2"]
    b = vals["C1"] * (vals["R1"] + vals["R2"])   # SLOA088's unity-gain s coefficient
    assert np.allclose(plant.model.den, np.polymul([1e-3, 1.0], [a, b, 1.0]), rtol=1e-12)
    assert plant.circuit.topology == "cascade" and len(plant.circuit.stages) == 2


def test_an_inverting_circuit_reverses_the_controllers_action():
    plant = circuit_plant("mfb-lowpass", MFB)
    assert plant.reversed_action and plant.model.gain < 0
    assert math.isclose(plant.design_model.gain, -plant.model.gain)
    assert np.allclose(plant.design_model.den, plant.model.den)
    spec = PidSpec(plant_topology="mfb-lowpass", plant_values=MFB)
    parts = design_pid(spec, simulate=False).parts
    normal, rev = controller_netlist(parts), controller_netlist(parts, reversed_action=True)
    assert (normal.part("R15").a, normal.part("R17").a) == ("ref", "y")
    assert (rev.part("R15").a, rev.part("R17").a) == ("y", "ref")


def test_every_plant_source_resolves_to_one_type():
    sources = [dict(plant_fc_hz=3500, plant_zeta=0.2), dict(plant_tf="K=2 tau=1m"), *CIRCUITS.values()]
    for kw in sources:
        plant = resolve_plant(PidSpec(**kw))
        assert isinstance(plant, Plant) and plant.model.gain != 0
    sk = resolve_plant(PidSpec(plant_fc_hz=3500, plant_zeta=0.2))
    assert sk.circuit.topology == "sallen-key-lowpass"
    # the Sallen-Key circuit's model is its own closed form (fn of the parts)
    from designer.pid.design import resolve_plant as sallen_key
    parts = sallen_key(PidSpec(plant_fc_hz=3500, plant_zeta=0.2))[0]
    assert math.isclose(sk.model.params["fn_hz"], parts.fn_hz, rel_tol=1e-9)


def test_designators_do_not_collide_with_the_controller_or_the_decoupling():
    spec = PidSpec(**CIRCUITS["cascade"])
    res = design_pid(spec, simulate=False)
    net = loop_netlist(res.parts, spec.circuit)
    refs = [p.ref for p in net.parts] + [a.ref for a in net.amps]
    assert len(refs) == len(set(refs))
    board = P.build_board(res)
    assert not {p.ref for p in net.parts} & {p.ref for p in board.decoupling}
    assert all(r[1] == PLANT_PREFIX for r in refs if r not in {p.ref for p in controller_netlist(res.parts).parts}
               | {a.ref for a in controller_netlist(res.parts).amps})


SK_RECORDS = {"follower": dict(r1=1600.0, r2=3900.0, c1=3.3e-9, c2=100e-9),
              "gain": dict(r1=1600.0, r2=3900.0, c1=100e-9, c2=3.3e-9, gain=1.5, r3=10e3, r4=5e3)}


@pytest.mark.parametrize("kind", sorted(SK_RECORDS))
def test_the_sallen_key_plants_loop_is_the_generic_circuit_loop_named_as_its_own_sheet(kind):
    # issue 26: one loop netlist for every circuit plant; the seed's plant (a parts record) goes through its
    # registered section's netlist and comes out as the plant's own sheet draws it (designer.plant.netlist,
    # an independent writer): the same parts, nets, values and roles, op-amp U1 "plant", the controller after it
    from designer.pid.blocks import seed_parts
    from designer.pid.netlist import plant_ref_prefix
    from designer.pid.plant import sallen_key_circuit
    from designer.plant.netlist import plant_netlist
    from designer.plant.sallenkey import SallenKeyParts, check_parts
    rec = check_parts(SallenKeyParts(**SK_RECORDS[kind]))
    circuit = sallen_key_circuit(rec)   # the one conversion of the record (the loop takes the generic record)
    prefix = plant_ref_prefix(circuit)
    assert prefix == ("" if kind == "follower" else PLANT_PREFIX)
    own = plant_netlist(rec, "u", "y", prefix="p", amp_ref="U1", ref_prefix=prefix)
    net = loop_netlist(seed_parts(), circuit)
    assert net == loop_netlist(seed_parts(), Plant(None, circuit))
    assert net.parts[:len(own.parts)] == own.parts and net.amps[:1] == own.amps
    assert net.parts[len(own.parts):] == controller_netlist(seed_parts()).parts
    # the same section given by topology keeps the generic scheme (RP1 .., UP)
    generic = circuit_plant(circuit.stages[0].topology, circuit.stages[0].values)
    assert {a.ref for a in loop_netlist(seed_parts(), generic).amps} >= {"UP"}


@pytest.mark.parametrize("kind", sorted(SK_RECORDS))
def test_the_sallen_key_closed_forms_equal_the_sections_nodal_model(kind):
    # the fast path of plant_model (seed 001's closed forms) stands in for the generic nodal model of its
    # section (designer.plant.circuit.opamp_tf): equal to rounding, with the op-amp and ideal
    from designer.core import opamps
    from designer.pid.design import ideal_pair, plant_model
    from designer.pid.plant import sallen_key_circuit
    from designer.plant.circuit import opamp_tf
    from designer.plant.sallenkey import SallenKeyParts, check_parts
    rec = check_parts(SallenKeyParts(**SK_RECORDS[kind]))
    circuit = sallen_key_circuit(rec)
    st0 = circuit.stages[0]
    for name in ("LM741", "TL072"):
        amp = opamps.get(name)
        num, den = plant_model(circuit, amp)
        n, d = opamp_tf(st0.topology, st0.values, amp)
        assert np.allclose(den, d / d[-1], rtol=1e-9, atol=0) and math.isclose(num[-1], n[-1] / d[-1], rel_tol=1e-9)
    num, den = plant_model(circuit)
    n, d = st0.topology.coefficients(st0.values)
    assert np.allclose(den, np.asarray(d) / d[-1], rtol=1e-9) and math.isclose(num[-1], n[-1] / d[-1], rel_tol=1e-9)
    assert np.allclose(ideal_pair(circuit), dominant(den), rtol=1e-9)
    # the section's ideal-pair hook gives the parts record's own figures, bit for bit
    assert ideal_pair(circuit) == (rec.fn_hz, rec.zeta) == circuit.ideal_pair()


@pytest.mark.parametrize("seed", range(3))
def test_the_sallen_key_plants_model_is_named_by_its_ideal_pair_to_the_bit(seed):
    """pair_model (the Sallen-Key plant's ProcessModel) takes the circuit's ideal pair, the section's one hook
    (issue 26), not a copy of it (its 1/(2 pi sqrt(a)) differed from the record's (1/sqrt(a))/(2 pi) in the
    last bit on a third of networks): the model's fn and zeta are the plant's named pair, bit for bit; an
    overdamped plant's model is the SOPDT of the same denominator."""
    from designer.pid.plant import pair_model, sallen_key_circuit
    from designer.plant.sallenkey import SallenKeyParts, check_parts
    rng = np.random.default_rng(seed)
    for _ in range(40):
        r1, r2 = 10 ** rng.uniform(3, 5, 2)
        c1 = 10 ** rng.uniform(-9, -7)
        c2 = c1 * 10 ** rng.uniform(-0.5, 2)
        circuit = sallen_key_circuit(check_parts(SallenKeyParts(r1, r2, c1, c2)))
        fn, zeta = circuit.ideal_pair()
        model = pair_model(circuit)
        if zeta < 1:
            assert (model.kind, model.params["fn_hz"], model.params["zeta"]) == ("underdamped", fn, zeta)
        else:
            assert model.kind == "sopdt"
            assert np.allclose(model.den, plant_model_den(circuit), rtol=1e-12)


def plant_model_den(circuit):
    """The circuit's ideal denominator, constant term 1."""
    den = np.asarray(circuit.coefficients()[1], float)
    return den / den[-1]


def dominant(den):
    from designer.core.lti import dominant_pair
    return dominant_pair(den)


def test_a_non_sallen_key_circuit_plants_model_is_its_sections_nodal_model():
    # the generic path of plant_model: a cascade's op-amp-aware model is the product of its sections'
    from designer.core import opamps
    from designer.pid.design import plant_model, plant_step
    from designer.plant.circuit import opamp_tf
    amp = opamps.get("LM741")
    plant = resolve_plant(PidSpec(**CIRCUITS["cascade"]))
    num, den = plant_model(plant, amp)
    n1, d1 = opamp_tf(plant.circuit.stages[0].topology, plant.circuit.stages[0].values, amp)
    n2, d2 = opamp_tf(plant.circuit.stages[1].topology, plant.circuit.stages[1].values, amp)
    assert np.allclose(den, np.polymul(d1, d2)) and math.isclose(num[-1], n1[-1] * n2[-1])
    ps = plant_step(plant, amp)
    assert np.array_equal(ps.num, num) and np.array_equal(ps.den, den)


# ---- bad input ---------------------------------------------------------------------------------

def test_an_unknown_topology_lists_the_registered_ones():
    exc = refusal(plant_topology="mfb-lowpas", plant_values=MFB)
    text = flag_message(exc)
    assert text.startswith("--plant-topology: unknown topology") and "mfb-lowpass" in text and "\n" not in text


def test_a_part_the_topology_lacks_lists_its_parts():
    exc = refusal(plant_topology="sallen-key-lowpass", plant_values=dict(SK, R5="1k"))
    text = flag_message(exc)
    assert text.startswith("--plant-part: sallen-key-lowpass has no part R5; its parts are R1, R2, C1, C2"), text


@pytest.mark.parametrize("values,what", [
    (["R1=10k"], "needs C1 too"),
    (["R1=10k", "C1"], "is not REF=VALUE"),
    (["R1=10k", "R1=1k", "C1=1n"], "R1 given twice"),
    (["R1=1e300", "C1=1n"], "--plant-part R1 must be"),
])
def test_bad_part_values_are_one_line_each(values, what):
    text = flag_message(refusal(plant_topology="rc-lowpass", plant_values=values))
    assert what in text and "\n" not in text, text


def test_a_plant_that_passes_no_dc_is_refused():
    values = {r: ("10k" if r[0] == "R" else "10n") for r in get("mfb-highpass").designators}
    text = flag_message(refusal(plant_topology="mfb-highpass", plant_values=values))
    assert "passes no DC" in text and "\n" not in text


def test_the_plant_is_given_one_way():
    assert "give the plant one way" in str(refusal(plant_fc_hz=3500, plant_zeta=0.2, plant_topology="rc-lowpass",
                                                   plant_values=RC))
    assert "go together" in str(refusal(plant_fc_hz=3500, plant_zeta=0.2, plant_values=RC))


@settings(max_examples=60, deadline=None)
@given(st.text(max_size=12))
def test_any_typed_value_is_a_part_or_a_one_line_refusal(text):
    try:
        got = parse_part_values(get("rc-lowpass"), {"R1": text, "C1": "1n"})
    except DesignError as exc:
        assert "\n" not in str(exc)
    else:
        assert 0.1 <= got["R1"] <= 1e9


# ---- designed, simulated with the plant's circuit in the deck, drawn ----------------------------


@pytest.fixture(scope="module", params=list(CIRCUITS))
def designed(request):
    spec = PidSpec(**CIRCUITS[request.param])
    return spec, design_pid(spec, simulate=True, simulator="ngspice-cli")


@pytest.mark.spice
def test_a_circuit_plant_is_designed_and_simulated_with_its_own_sections(designed):
    spec, res = designed
    assert isinstance(res, PidResult) and res.stable and res.spice is not None
    plant_net = spec.circuit.circuit.netlist("u", "y")
    terms = deck_terminals(res.deck)
    for p in plant_net.parts:
        assert (terms[(p.ref, "a")], terms[(p.ref, "b")]) == (p.a, p.b)
    for a in plant_net.amps:
        assert (terms[(a.ref, "inp")], terms[(a.ref, "inn")], terms[(a.ref, "out")]) == (a.inp, a.inn, a.out)
    # the analytic loop (the circuit's model) and ngspice (the circuit) agree by the project's rule
    assert res.verdict.agree, (res.verdict, res.analytic, res.spice.figures)
    assert math.isclose(res.spice.figures.final_value, res.expected_final_v, rel_tol=0.02)
    data = res.to_dict()
    assert data["plant"]["topology"] == spec.circuit.circuit.topology and data["plant"]["kind"] == "circuit"
    assert data["plant"]["reversed_action"] == spec.circuit.reversed_action


@pytest.mark.spice
def test_a_circuit_plant_is_drawn_as_its_deck(designed):
    spec, res = designed
    board = P.build_board(res)
    sheet = P.schematic(res)
    terms = deck_terminals(res.deck)
    for p in board.decoupling:
        terms[(p.ref, "a")], terms[(p.ref, "b")] = p.a, p.b
    assert check_connectivity(sheet, terms) == []
    nets, _ = sheet.connectivity()
    plant_net = spec.circuit.circuit.netlist("u", "y")
    assert {(p.ref, "a") for p in plant_net.parts} <= set(nets)
    assert {(a.ref, "out") for a in plant_net.amps} <= set(nets)
    # the plant's output reaches the difference amplifier's y input; a miswired drawing is caught
    y_in = "R17" if not spec.circuit.reversed_action else "R15"
    last = plant_net.amps[-1].ref
    assert nets[(last, "out")] == nets[(y_in, "a")]
    wrong = dict(terms)
    wrong[(last, "out")] = "u"
    assert check_connectivity(sheet, wrong)


def test_every_registered_lowpass_is_a_plant():
    for name, topo in REGISTRY.items():
        if topo.kind != "lowpass":
            continue
        values = topo.synthesize(topo.example)
        plant = circuit_plant(topo, values)
        assert plant.reversed_action == topo.inverting
        assert math.isclose(abs(plant.model.gain), topo.figures(values).gain, rel_tol=1e-9)


def test_a_sallen_key_result_names_its_topology():
    res = design_pid(PidSpec(plant_fc_hz=3500, plant_zeta=0.2), simulate=False)
    assert res.to_dict()["plant"]["topology"] == "sallen-key-lowpass"


def test_the_pid_package_has_no_import_cycle():
    """design <-> process_loop <-> process_optimize and spec <-> plant went (function-level imports counted)."""
    import ast
    from pathlib import Path

    import designer.pid as pkg
    root = Path(pkg.__file__).parent
    graph = {}
    for f in root.glob("*.py"):
        graph[f.stem] = {(n.module or "").split(".")[0] or a.name for n in ast.walk(ast.parse(f.read_text()))
                         if isinstance(n, ast.ImportFrom) and n.level == 1 for a in n.names}
    done = set()

    def visit(m, path):
        assert m not in path, " -> ".join(path + [m])
        if m in done or m not in graph:
            return
        for x in graph[m]:
            visit(x, path + [m])
        done.add(m)

    for m in graph:
        visit(m, [])


@pytest.mark.parametrize("bad", [[1], 5, "rc-lowpass", [("rc-lowpass",)], [], [("nope", RC)]])
def test_a_malformed_plant_circuit_is_one_line(bad):
    text = str(refusal(plant_circuit=bad))
    assert "\n" not in text and ("plant_circuit" in text or "topology" in text), text


def test_a_pid_for_an_mfb_plant_and_for_the_seed_plant_is_one_type_carrying_its_circuits_record():
    """Issue 26: design_pid returns one type for every plant, and its ``plant`` is the generic record
    (designer.pid.plant.PlantCircuit: the plant's topology and its values by designator), the MFB low-pass's
    and the seed's Sallen-Key plant's alike; the seed plant's JSON keeps its own keys, its figures the record's."""
    import pickle

    from designer.pid.plant import PlantCircuit
    mfb = design_pid(PidSpec(**CIRCUITS["mfb-lowpass"]), simulate=False)
    seed = design_pid(PidSpec(plant_fc_hz=3500, plant_zeta=0.2), simulate=False)
    assert type(mfb) is type(seed) is PidResult
    assert type(mfb.plant) is type(seed.plant) is PlantCircuit
    assert mfb.plant.topology == "mfb-lowpass" and mfb.plant.stages[0].topology is get("mfb-lowpass")
    assert mfb.plant.stages[0].values == parse_part_values(get("mfb-lowpass"), MFB)
    assert mfb.plant == mfb.spec.plant.circuit.circuit and mfb.model is not None
    assert seed.plant.topology == "sallen-key-lowpass" and seed.model is None
    plant = seed.to_dict()["plant"]
    assert plant["topology"] == seed.plant.topology
    assert (plant["fn_hz"], plant["zeta"]) == seed.plant.ideal_pair() == (seed.plant.fn_hz, seed.plant.zeta)
    assert all(plant[f"{ref}_{'ohm' if ref[0] == 'R' else 'f'}"] == v for ref, v in seed.plant.stages[0].values.items())
    # the record travels to --jobs and dask workers as its registered section, equal
    for circuit in (mfb.plant, seed.plant):
        back = pickle.loads(pickle.dumps(circuit))
        assert back == circuit and back.stages[0].topology is circuit.stages[0].topology


def test_the_seed_plants_parts_are_given_as_its_record_or_as_the_generic_record_and_nothing_else():
    # the flags' parts record is converted once; the generic record (a replaced spec's, a Monte Carlo
    # build's) is checked as the record it stands for; another section is refused naming where it goes
    from designer.pid.plant import sallen_key_circuit
    from designer.plant.sallenkey import SallenKeyParts, check_parts
    rec = SallenKeyParts(10e3, 10e3, 10e-9, 10e-9, 1.5)
    spec = PidSpec(plant_parts=rec)
    assert spec.plant_parts == sallen_key_circuit(check_parts(rec)) == PidSpec(plant_parts=spec.plant_parts).plant_parts
    exc = refusal(plant_parts=circuit_plant("mfb-lowpass", MFB).circuit)
    assert "plant_topology" in str(exc) and "\n" not in str(exc)
    assert "--plant-topology with --plant-part" in flag_message(exc)
    exc = refusal(plant_parts=(10e3, 10e3, 10e-9, 10e-9))
    assert "SallenKeyParts" in str(exc) and "\n" not in str(exc)
