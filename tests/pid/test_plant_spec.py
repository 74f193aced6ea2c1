"""Where a PID's plant comes from (designer.pid.plant_spec.PlantSource, issue 26): validated once, when
given; the spec holds one beside the controller's fields, and the old flat keywords make the same spec."""

import dataclasses
import json

import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

from designer.cli.common import flag_message
from designer.core.errors import DesignError
from designer.core.process_build import fopdt
from designer.core.ranges import RANGES
from designer.filters.sallen_key_lowpass_parts import FIELD_OF, refs
from designer.pid import tuning
from designer.pid.plant import resolve_plant
from designer.pid.plant_spec import PLANT_FIELDS, PlantSource
from designer.pid.spec import PidSpec, pid_spec
from designer.plant.sallenkey import JSON_KEYS, SallenKeyParts

SEED = dict(plant_fc_hz=3500, plant_zeta=0.2)
TF = "K=2 tau=1m theta=200u"
#: an MFB low-pass's parts, by its declared designators (designer.filters.registry)
MFB = dict(zip(("R1", "R2", "R3", "C1", "C2"), ("10k", "20k", "6k8", "10n", "100n")))


def refused(make, **kw) -> DesignError:
    with pytest.raises(DesignError) as exc:
        make(**kw)
    return exc.value


def bad_plant_json(tmp_path) -> str:
    """A design-plant result.json whose last network part is not a number."""
    path = tmp_path / "plant.json"
    built = {JSON_KEYS[FIELD_OF[r]]: v for r, v in zip(refs(with_gain=False), (820, 1e3, 10e-9, "x"))}
    path.write_text(json.dumps({"built": built}))
    return str(path)


#: every refusal that moved from PidSpec to PlantSource: (keywords, how the library's message starts)
REFUSALS = {
    "no source": (dict(), "give the plant one way: plant_fc_hz/plant_zeta, plant_r1..plant_c2, plant_topology "
                          "with plant_values, plant_json, plant_tf, plant_model or --plant-capture"),
    "two sources": (dict(SEED, plant_tf=TF), "give the plant one way"),
    "topology without values": (dict(plant_topology="mfb-lowpass"),
                                "plant_topology and plant_values go together"),
    "values without topology": (dict(SEED, plant_values=MFB), "plant_topology and plant_values go together"),
    "fc without zeta": (dict(plant_fc_hz=3500), "plant_fc_hz needs plant_zeta"),
    "zeta without fc": (dict(plant_tf=TF, plant_zeta=0.2), "plant_zeta needs plant_fc_hz"),
    "fc out of range": (dict(plant_fc_hz=0, plant_zeta=0.2), "plant_fc_hz must be"),
    "zeta not a number": (dict(plant_fc_hz=3500, plant_zeta="x"), "plant_zeta: 'x' is not a number"),
    "a part out of range": (dict(plant_parts=SallenKeyParts("1e300", 1e3, 1e-8, 1e-7)), "plant_r1 must be"),
    "parts that oscillate": (dict(plant_parts=SallenKeyParts(1e4, 1e4, 1e-8, 1e-8, 4.0)),
                             "plant_r1..plant_c2: these parts give zeta"),
    "a bad plant json": (dict(plant_json=None), "plant_json "),
    "a bad typed model": (dict(plant_tf="K=2"), "plant_tf "),
    "not a process model": (dict(plant_process="fopdt"),
                            "plant_process must be a designer.core.process.ProcessModel"),
    "a method without a model file": (dict(SEED, plant_method="alfaro"),
                                      "plant_method chooses among the methods of a plant_model file"),
    "an input range for a Sallen-Key plant": (dict(SEED, plant_input="0:10"),
                                              "plant_input is for a plant given as a model"),
    "an output range upside down": (dict(plant_tf=TF, plant_output="5:1"), "plant_output needs LO < HI"),
    "an input range that is no range": (dict(plant_tf=TF, plant_input="0"), "plant_input is a range LO:HI"),
    "an unknown topology": (dict(plant_topology="mfb-lowpas", plant_values=MFB),
                            "plant_topology: unknown topology 'mfb-lowpas'"),
    "a part the topology lacks": (dict(plant_topology="mfb-lowpass", plant_values={**MFB, "R9": "1k"}),
                                  "plant_values: mfb-lowpass has no part R9"),
}


@pytest.mark.parametrize("case", REFUSALS)
def test_a_plant_source_refuses_as_the_spec_did_naming_the_spec_s_parameters(case, tmp_path):
    """Each refusal moved out of PidSpec: one line naming the plant's parameter, the same from PlantSource
    and from the spec given the old flat keywords (and the command line shows its options for it)."""
    kw, library = REFUSALS[case]
    if "plant_json" in kw:
        kw = dict(plant_json=bad_plant_json(tmp_path))
    exc = refused(PlantSource, **kw)
    assert str(exc).startswith(library) and "\n" not in str(exc), str(exc)
    flat = refused(PidSpec, **kw)
    assert (type(flat), str(flat), flat.param) == (type(exc), str(exc), exc.param)
    assert flag_message(flat) == flag_message(exc)
    assert "--plant-" in flag_message(exc) or exc.param == "plant_process"   # a library-only parameter


#: one of each kind of plant source, as keywords
SOURCES = {"fc and zeta": dict(SEED, plant_input=None),
           "parts": dict(plant_parts=SallenKeyParts("820", "1k", "10n", "220n")),
           "typed model": dict(plant_tf=TF, plant_input="0:10", plant_output=(-5, 5)),
           "process": dict(plant_process=fopdt(2.0, 1e-3, 2e-4)),
           "section": dict(plant_topology="mfb-lowpass", plant_values=MFB)}


@pytest.mark.parametrize("case", SOURCES)
def test_the_flat_keywords_make_the_spec_the_nested_form_makes(case):
    kw = SOURCES[case]
    flat = PidSpec(**kw, tuning="amigo", opamp="TL072")
    nested = PidSpec(plant=PlantSource(**kw), tuning="amigo", opamp="TL072")
    assert flat == nested and flat.plant == PlantSource(**kw)
    for name in PLANT_FIELDS + ("json_plant", "process", "circuit"):   # the old attributes read the plant's
        assert getattr(flat, name) is getattr(flat.plant, name)
    assert resolve_plant(flat) == resolve_plant(flat.plant, opamp="TL072", bounds=flat)


def test_flat_keywords_beside_a_plant_replace_its_fields_and_a_plant_must_be_a_plant_source():
    spec = PidSpec(**SEED, kp=2, ti_s=1e-4, td_s=1e-5)
    changed = dataclasses.replace(spec, plant_fc_hz=None, plant_zeta=None, plant_tf=TF)
    assert changed == PidSpec(plant=PlantSource(plant_tf=TF), kp=2, ti_s=1e-4, td_s=1e-5)
    assert dataclasses.replace(spec, kp=3) == PidSpec(**SEED, kp=3, ti_s=1e-4, td_s=1e-5)
    assert str(refused(PidSpec, plant=SEED)) == "plant must be a designer.pid.plant_spec.PlantSource"
    with pytest.raises(TypeError, match="'plant_fc'"):
        PidSpec(plant_fc=3500)


def test_the_controller_s_model_only_options_are_still_refused_for_a_sallen_key_plant():
    exc = refused(PidSpec, **SEED, max_ms=1.5)
    assert str(exc).startswith("max_ms is for a plant given as a model")
    assert PidSpec(plant_tf=TF, max_ms=1.5).max_ms == 1.5


positive = st.floats(0.0, 1.0)


def in_range(key: str):
    """A number inside RANGES[key], log-uniform."""
    r = RANGES[key]
    return positive.map(lambda u: r.lo * (r.hi / r.lo) ** u)


@settings(max_examples=60, deadline=None)
@given(fc=in_range("fc_hz"), zeta=in_range("zeta"), step=in_range("step_v"),
       rule=st.sampled_from((None, *tuning.RULES)), opamp=st.sampled_from(("LM741", "TL072", "ideal")),
       parts=st.none() | st.tuples(in_range("resistor_ohm"), in_range("resistor_ohm"),
                                   in_range("capacitor_f"), in_range("capacitor_f")))
def test_pid_spec_of_plain_parameters_equals_the_nested_form(fc, zeta, step, rule, opamp, parts):
    """Valid plain parameters build; pid_spec, the flat keywords and PidSpec(plant=PlantSource(...)) give equal
    specs, and parts the plant validation refuses are refused alike by all three."""
    controller = {"tuning": rule, "opamp": opamp, "step_v": step}
    if parts is None:
        plain, plant = {"plant_fc_hz": fc, "plant_zeta": zeta}, {"plant_fc_hz": fc, "plant_zeta": zeta}
    else:
        plain = {f"plant_{FIELD_OF[r]}": v for r, v in zip(refs(with_gain=False), parts)}
        plant = {"plant_parts": SallenKeyParts(*parts)}
    made = []
    for make in (lambda: pid_spec({**plain, **controller}), lambda: PidSpec(**plant, **controller),
                 lambda: PidSpec(plant=PlantSource(**plant), **controller)):
        try:
            made.append(make())
        except DesignError as exc:
            made.append(str(exc))
    assert made[0] == made[1] == made[2]
    if parts is None:
        assert isinstance(made[0], PidSpec) and made[0].plant.plant_fc_hz == pytest.approx(fc)


def test_the_readme_s_pid_library_use():
    from designer import design_pid
    from designer.pid import resolve_plant as exported
    spec = PidSpec(plant=PlantSource(plant_fc_hz=3500, plant_zeta=0.2), tuning="amigo", opamp="TL072")
    res = design_pid(spec, simulate=False)
    flat = PidSpec(plant_fc_hz=3500, plant_zeta=0.2, tuning="amigo", opamp="TL072")
    assert res.to_dict() == design_pid(flat, simulate=False).to_dict()
    assert abs(res.plant.fn_hz / 3500 - 1) < 0.005 and res.tuning.kp > 0
    plant = exported(spec.plant, opamp="TL072")
    assert plant == resolve_plant(spec) and plant.circuit is not None


@pytest.mark.parametrize("case", SOURCES)
def test_a_spec_reaches_a_worker_process_unchanged(case):
    """--jobs and dask send the spec to other processes: it pickles with its plant and what the plant resolved."""
    import pickle
    spec = PidSpec(**SOURCES[case])
    back = pickle.loads(pickle.dumps(spec))
    assert back == spec and back.plant == spec.plant
    assert (back.process, back.json_plant) == (spec.process, spec.json_plant)
    if spec.circuit is not None:   # a registered topology compares by identity: the circuit by what it holds
        assert back.circuit.circuit.to_dict() == spec.circuit.circuit.to_dict()
        assert back.circuit.model == spec.circuit.model


@pytest.mark.parametrize("topology, target", [("mfb-lowpass", ["--fc", "3.5k", "--zeta", "0.7", "--gain", "2"]),
                                              ("sallen-key-lowpass-gain", ["--fc", "100", "--zeta", "0.7", "--gain", "2"]),
                                              ("rc-lowpass", ["--fc", "100"])])
def test_a_section_plants_result_is_a_plant_json_as_its_parts_are(topology, target, tmp_path):
    # design-pid --plant-json of a design-plant --topology result.json was refused as 'not a design-plant
    # result.json (needs built with R1_ohm ..)': only the seed's Sallen-Key record and design-filter's
    # stages were read. Its section and parts are the plant, as --plant-topology with --plant-part gives it.
    import subprocess

    from helpers import script
    p = subprocess.run([script("design-plant"), "--topology", topology, *target, "--no-sim", "--out", str(tmp_path),
                        "--name", "p"], capture_output=True, text=True, timeout=300)
    assert p.returncode == 0, p.stderr
    path = tmp_path / "reports" / "p" / "result.json"
    parts = {k: v["value"] for k, v in json.loads(path.read_text())["parts"].items()}
    read = PlantSource(plant_json=str(path)).circuit
    typed = PlantSource(plant_topology=topology, plant_values=parts).circuit
    assert read.circuit == typed.circuit
    assert (list(read.model.num), list(read.model.den)) == (list(typed.model.num), list(typed.model.den))
    assert "design-plant result" in read.source


def test_a_section_plant_json_that_passes_no_dc_is_one_line(tmp_path):
    import subprocess

    from helpers import script
    p = subprocess.run([script("design-plant"), "--topology", "mfb-highpass", "--fc", "1k", "--zeta", "0.7",
                        "--no-sim", "--out", str(tmp_path), "--name", "p"], capture_output=True, text=True, timeout=300)
    assert p.returncode == 0, p.stderr
    with pytest.raises(DesignError, match="mfb-highpass passes no DC"):
        PlantSource(plant_json=str(tmp_path / "reports" / "p" / "result.json"))
