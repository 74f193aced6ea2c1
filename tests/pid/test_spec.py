"""The design-pid spec: validated once, when built; its errors name the
library's parameters, and the command line shows its options for them from one
table (designer.cli.common.FLAGS)."""

import dataclasses
import json

import pytest

from designer.cli.common import flag_message
from designer.core.errors import DesignError
from designer.filters.sallen_key_lowpass_parts import gain_of, gain_refs, refs, section_of
from designer.pid.spec import PidSpec
from designer.plant.sallenkey import SallenKeyParts

SEED = dict(plant_fc_hz=3500, plant_zeta=0.2)


def refusal(**kw):
    with pytest.raises(DesignError) as exc:
        PidSpec(**kw)
    return exc.value


@pytest.mark.parametrize("kw,library,cli", [
    (dict(SEED, kp=0, ti_s=1e-5, td_s=0), "kp must be 0.0001 to 10000, got 0", "--kp must be"),
    (dict(SEED, kp=1, ti_s="1e300", td_s=0), "ti_s must be 1 ns to 10000 s, got '1e300'", "--ti must be"),
    (dict(SEED, kp=1, ti_s="4x", td_s=0), "ti_s: '4x' is not a number", "--ti: '4x' is not a number"),
    (dict(SEED, kp=1, ti_s=1e-5), "kp, ti_s and td_s go together (give all three)",
     "--kp, --ti and --td go together (give all three)"),
    (dict(SEED, kp=1, ti_s=1e-5, td_s=0, tuning="zn"), "tuning zn and explicit kp/ti_s/td_s exclude each other",
     "--tuning zn and explicit --kp/--ti/--td exclude each other"),
    (dict(plant_fc_hz=3500), "plant_fc_hz needs plant_zeta", "--plant-fc needs --plant-zeta"),
    (dict(plant_zeta=0.2), "give the plant one way", "give the plant one way: --plant-fc/--plant-zeta, "
                                                       "--plant-r1..--plant-c2, --plant-topology with "
                                                       "--plant-part, --plant-json, --plant-tf, "
                                                       "--plant-model or --plant-capture"),
    (dict(SEED, tuning="Magic"), "unknown tuning 'magic'", "unknown --tuning 'magic'"),
    (dict(SEED, tuning="optimize"), "tuning optimize needs target_overshoot_pct",
     "--tuning optimize needs --target-overshoot P (percent)"),
    (dict(SEED, target_settling_s=1e-3), "target_overshoot_pct/target_settling_s only apply to tuning optimize",
     "--target-overshoot/--target-settling only apply to --tuning optimize"),
    (dict(SEED, r_min="1M", r_max="1k"), "r_min (1e+06 Ohm) is above r_max (1000 Ohm)", "--r-min (1e+06 Ohm)"),
    (dict(SEED, step_v=0), "step_v must be 1 mV to 100 V", "--step must be"),
    (dict(plant_parts=SallenKeyParts("1e300", 1e3, 1e-8, 1e-7)), "plant_r1 must be", "--plant-r1 must be"),
    (dict(plant_parts=SallenKeyParts(1e4, 1e4, 1e-8, 1e-8, 4.0)), "plant_r1..plant_c2: these parts give zeta",
     "--plant-r1..--plant-c2: these parts give zeta"),
])
def test_errors_name_the_parameter_and_the_cli_shows_the_option(kw, library, cli):
    exc = refusal(**kw)
    assert str(exc).startswith(library), str(exc)
    assert flag_message(exc).startswith(cli), flag_message(exc)
    assert "\n" not in str(exc)


def test_a_spec_is_normalised_once_and_frozen():
    spec = PidSpec(plant_fc_hz="3.5k", plant_zeta="0.2", kp="4k7", ti_s="43.215u", td_s="0", opamp=" lm741 ",
                   r_series="e96", c_max="4u7", tuning=" Explicit ")
    assert (spec.plant_fc_hz, spec.kp, spec.ti_s, spec.td_s) == (3500.0, 4700.0, pytest.approx(43.215e-6), 0.0)
    assert (spec.opamp, spec.r_series, spec.c_max, spec.tuning, spec.method) == \
        ("LM741", "E96", pytest.approx(4.7e-6), "explicit", "explicit")
    with pytest.raises(dataclasses.FrozenInstanceError):
        spec.kp = 1e9
    # a plant given as built comes out of the plant validation: floats, R3/R4 derived from its gain
    # (held as the generic record: the gain section and its values by designator)
    p = PidSpec(plant_parts=SallenKeyParts("10k", "10k", "10n", "10n", "1.5")).plant_parts
    st = p.stages[0]
    assert st.topology is section_of(with_gain=True) and gain_of(st.values) == 1.5
    assert [st.values[r] for r in (*refs(with_gain=False)[:1], *gain_refs())] == [1e4, 1e4, 5e3]


def test_a_plant_json_is_read_and_checked_when_the_spec_is_built(tmp_path):
    path = tmp_path / "plant.json"
    path.write_text(json.dumps({"built": {"R1_ohm": 820, "R2_ohm": 1e3, "C1_f": 10e-9, "C2_f": 220e-9}}))
    spec = PidSpec(plant_json=str(path))
    st = spec.json_plant.stages[0]   # the generic record: the follower, its values by designator
    assert st.topology is section_of(with_gain=False) and st.values[refs()[0]] == 820.0
    path.write_text(json.dumps({"built": {"R1_ohm": 820, "R2_ohm": 1e3, "C1_f": 10e-9, "C2_f": "x"}}))
    exc = refusal(plant_json=str(path))
    assert str(exc).startswith("plant_json ") and "built.C2_f must be a number" in str(exc)
    assert flag_message(exc).startswith("--plant-json ")
    path.write_text("[1]")
    assert "not a design-plant result.json" in flag_message(refusal(plant_json=str(path)))


def test_pid_spec_is_the_one_mapping_from_plain_parameters():
    """Issue 26: designer.pid.spec.pid_spec turns what a front end has (design-pid's options, the PID page's
    fields) into the spec: the plant's four parts with its gain as SallenKeyParts, the seed's controller parts;
    a value None is not given."""
    from designer.pid.blocks import seed_parts
    from designer.pid.spec import pid_spec
    spec = pid_spec({"plant_r1": "820", "plant_r2": "1k", "plant_c1": "10n", "plant_c2": "220n", "plant_gain": None,
                     "tuning": "amigo", "seed_parts": True, "kp": None})
    assert spec == PidSpec(plant_parts=SallenKeyParts("820", "1k", "10n", "220n"), tuning="amigo",
                           controller_parts=seed_parts())
    assert pid_spec({**SEED, "seed_parts": False}) == PidSpec(**SEED)


@pytest.mark.parametrize("params, library, cli", [
    ({"plant_r1": "820", "plant_r2": "1k"}, "plant_r1, plant_r2, plant_c1 and plant_c2 go together",
     "--plant-r1, --plant-r2, --plant-c1 and --plant-c2 go together"),
    ({**SEED, "plant_gain": 2}, "plant_gain goes with plant_r1..plant_c2",
     "--plant-gain goes with --plant-r1..--plant-c2"),
])
def test_pid_spec_refuses_naming_its_parameters(params, library, cli):
    from designer.pid.spec import pid_spec
    with pytest.raises(DesignError) as exc:
        pid_spec(params)
    assert str(exc.value) == library and flag_message(exc.value) == cli
