"""design-pid driven with generated arguments (issue 7, "make the classes impossible").

Whatever the values (numbers across 600 orders of magnitude, odd strings, plant
JSON files with odd values and types), the command ends with exit status 0, 1
or 2; on 2 with exactly one line on stderr; never a traceback, a printed
warning or a numpy repr; and a refused run writes nothing. In-process (the
console script's own entry point) with ``--no-sim``, so that the file runs in
seconds; ``PID_FUZZ_EXAMPLES`` raises the number of examples for a deeper run.
"""

import contextlib
import io
import json
import os
import warnings

from fuzzing import ODD, sci
from hypothesis import HealthCheck, example, given, settings
from hypothesis import strategies as st

from designer.cli.pid import design_pid_main
from designer.core.ranges import RANGES

SCALE = float(os.environ.get("PID_FUZZ_EXAMPLES", "1"))


def examples(n):
    return settings(max_examples=max(1, int(n * SCALE)), deadline=None,
                    suppress_health_check=[HealthCheck.function_scoped_fixture, HealthCheck.too_slow])


# ---- the contract -------------------------------------------------------------

def run(argv):
    """Run design-pid in-process; returns (status, stdout, stderr) after checking the contract."""
    out, err = io.StringIO(), io.StringIO()
    with warnings.catch_warnings(record=True) as caught:
        warnings.simplefilter("always")   # a warning swallowed by an except clause still counts
        with contextlib.redirect_stdout(out), contextlib.redirect_stderr(err):
            status = design_pid_main(argv)   # an exception here is a traceback for the user
    out, err = out.getvalue(), err.getvalue()
    assert not caught, [f"{w.category.__name__}: {w.message}" for w in caught]
    assert status in (0, 1, 2), status
    for stream in (out, err):
        assert "Traceback" not in stream and "np.float64(" not in stream and "np.complex" not in stream
        assert "Warning:" not in stream
    if status == 2:
        lines = err.splitlines()
        assert len(lines) == 1 and lines[0].startswith("design-pid: error: "), err
        assert lines[0].strip() != "design-pid: error:"
    return status, out, err


def files_under(path):
    return [p for p in path.rglob("*")] if path.exists() else []


# ---- generated values ----------------------------------------------------------

def in_range(key):
    """Log-uniform values inside RANGES[key] (these reach the design itself)."""
    r = RANGES[key]
    lo = max(r.lo, 1e-300)
    return st.floats(0.0, 1.0).map(lambda u: f"{lo * (r.hi / lo) ** u:.6g}")


def values(key=None):
    options = [sci(), st.sampled_from(ODD), st.floats(allow_nan=True, allow_infinity=True).map(repr),
               st.builds(lambda m, p: f"{m:g}{p}", st.floats(0.1, 999.0),
                         st.sampled_from(list("fpnumkMG") + ["MEG", "F", "Ohm", "kOhm", "Hz", "s", "V", "%"])),
               st.text(max_size=6)]
    if key is not None:
        options.append(in_range(key))
    return st.one_of(*options)


def flag(option, value):
    """``--opt=value`` (so that "-1e5" is a value, not an option), sometimes ``--opt value``."""
    return [f"{option}={value}"] if value.startswith("-") or not value else [option, value]


SEED_PLANT = ["--plant-fc", "3500", "--plant-zeta", "0.2"]
PARTS_PLANT = {"--plant-r1": "820", "--plant-r2": "1k", "--plant-c1": "10n", "--plant-c2": "220n"}
GAINS = {"--kp": "3.3", "--ti": "43u", "--td": "10u"}
#: option -> (its range key, the other arguments it needs)
NUMERIC = {
    "--plant-fc": ("fc_hz", ["--plant-zeta", "0.2"]),
    "--plant-zeta": ("zeta", ["--plant-fc", "3500"]),
    **{o: ("resistor_ohm" if "-r" in o else "capacitor_f",
           [x for k, v in PARTS_PLANT.items() if k != o for x in (k, v)]) for o in PARTS_PLANT},
    "--plant-gain": ("gain", [x for kv in PARTS_PLANT.items() for x in kv]),
    **{o: (k, SEED_PLANT + [x for g, v in GAINS.items() if g != o for x in (g, v)])
       for o, k in (("--kp", "kp"), ("--ti", "ti_s"), ("--td", "td_s"))},
    "--f-integrator": ("f_integrator_hz", SEED_PLANT),
    "--f-differentiator": ("f_differentiator_hz", SEED_PLANT),
    "--step": ("step_v", SEED_PLANT),
    "--edge": ("edge_s", SEED_PLANT),
    "--square-freq": ("square_hz", SEED_PLANT),
    "--r-min": ("resistor_ohm", SEED_PLANT),
    "--r-max": ("resistor_ohm", SEED_PLANT),
    "--c-min": ("capacitor_f", SEED_PLANT),
    "--c-max": ("capacitor_f", SEED_PLANT),
}


# ---- the properties --------------------------------------------------------------

@examples(120)
@given(data=st.data(), option=st.sampled_from(sorted(NUMERIC)))
def test_any_value_of_any_numeric_option(data, option):
    key, rest = NUMERIC[option]
    value = data.draw(values(key), label="value")
    run([*rest, *flag(option, value), "--no-sim", "--no-files"])


@examples(30)
@given(kp=values("kp"), ti=values("ti_s"), td=values("td_s"), fc=values("fc_hz"), zeta=values("zeta"),
       opamp=st.sampled_from(["LM741", "ideal", "TL072"]))
def test_gains_and_plant_together(kp, ti, td, fc, zeta, opamp):
    run([*flag("--plant-fc", fc), *flag("--plant-zeta", zeta), *flag("--kp", kp), *flag("--ti", ti),
         *flag("--td", td), "--opamp", opamp, "--no-sim", "--no-files"])


@examples(12)
@given(rule=st.sampled_from(["zn", "cohen-coon", "chr0", "chr20", "amigo", "simc"]),
       fc=in_range("fc_hz"), zeta=in_range("zeta"))
def test_every_rule_on_any_plant_in_range(rule, fc, zeta):
    run(["--plant-fc", fc, "--plant-zeta", zeta, "--tuning", rule, "--no-sim", "--no-files"])


@examples(6)
@given(overshoot=values("target_overshoot_pct"), settling=st.none() | values("target_settling_s"))
def test_optimiser_targets(overshoot, settling):
    extra = [] if settling is None else flag("--target-settling", settling)
    run([*SEED_PLANT, "--opamp", "ideal", "--tuning", "optimize", *flag("--target-overshoot", overshoot), *extra,
         "--no-sim", "--no-files"])


@examples(30)
@given(tuning=st.text(max_size=12) | st.sampled_from(["ZN", " simc ", "optimize", "explicit", "zn\n"]),
       opamp=st.text(max_size=12) | st.sampled_from(["lm741", "LM741 ", "ideal"]),
       series=st.text(max_size=5) | st.sampled_from(["E3", "e96", "E192", "E0", "E7"]))
def test_odd_strings(tuning, opamp, series):
    run([*SEED_PLANT, *flag("--tuning", tuning), *flag("--opamp", opamp), *flag("--r-series", series),
         "--no-sim", "--no-files"])


def part_value(key):
    """A JSON value for a part: a number in or out of range, or something that is not a number."""
    r = RANGES[key]
    good = st.floats(0.0, 1.0).map(lambda u: r.lo * (r.hi / r.lo) ** u)
    return st.one_of(good, good, st.floats(allow_nan=True, allow_infinity=True), st.integers(-10 ** 30, 10 ** 30),
                     st.text(max_size=6), st.booleans(), st.none(), st.lists(st.integers(), max_size=2),
                     st.dictionaries(st.text(max_size=2), st.integers(), max_size=1))


JSON_KEYS = {"R1_ohm": "resistor_ohm", "R2_ohm": "resistor_ohm", "C1_f": "capacitor_f", "C2_f": "capacitor_f",
             "R3_ohm": "resistor_ohm", "R4_ohm": "resistor_ohm", "gain": "gain"}


@st.composite
def plant_documents(draw):
    built = {}
    for k, key in JSON_KEYS.items():
        # R3/R4 and gain may be missing; R1..C2 almost always present
        if draw(st.integers(0, 9)) < (9 if k[0] in "RC" and k[1] in "12" else 5):
            built[k] = draw(part_value(key))
    doc = draw(st.sampled_from(["result", "result", "result", "other"]))
    if doc == "result":
        return {"built": built, "target": {"fc_hz": 3500}}
    return draw(st.one_of(st.just([built]), st.just("built"), st.just({"built": [built]}), st.none(),
                          st.just({"built": {"built": built}})))


@examples(60)
@given(doc=plant_documents(), rule=st.sampled_from(["zn", "simc"]))
def test_any_plant_json(tmp_path_factory, doc, rule):
    path = tmp_path_factory.mktemp("plant") / "result.json"
    path.write_text(json.dumps(doc))   # NaN and Infinity are written as JSON reads them back
    run(["--plant-json", str(path), "--tuning", rule, "--no-sim", "--no-files"])


@examples(8)
@given(raw=st.binary(max_size=40) | st.sampled_from([b"\xff\xfe{\x00}\x00", b"[" * 5000, b"{\"built\": 1e999}"]))
def test_plant_json_that_is_not_json(tmp_path_factory, raw):
    path = tmp_path_factory.mktemp("plant") / "result.json"
    path.write_bytes(raw)
    run(["--plant-json", str(path), "--no-sim", "--no-files"])


@examples(10)
@given(data=st.data(), option=st.sampled_from(sorted(NUMERIC)))
def test_a_refusal_writes_nothing(tmp_path_factory, data, option):
    key, rest = NUMERIC[option]
    value = data.draw(values(), label="value")
    out = tmp_path_factory.mktemp("out") / "deep" / "er"
    status, _, _ = run([*rest, *flag(option, value), "--no-sim", "--out", str(out)])
    if status != 0:
        assert files_under(out.parent.parent) == []
    else:
        assert any(p.name == "result.json" for p in files_under(out))


def test_refused_before_any_file_and_before_the_design(tmp_path, monkeypatch):
    # a refused spec: nothing under --out, not even the folder, and the design never starts
    import designer.pid.design

    def no_design(*args, **kwargs):
        raise AssertionError("the design started before the spec was refused")

    monkeypatch.setattr(designer.pid.design, "design_pid", no_design)
    out = tmp_path / "new"
    status, _, err = run([*SEED_PLANT, "--ti", "1e300", "--td", "1e300", "--kp", "1", "--out", str(out)])
    assert status == 2 and f"--ti must be {RANGES['ti_s'].text()}, got '1e300'" in err and not out.exists()
    status, _, err = run([*SEED_PLANT, "--kp", "1", "--ti", "1e-300", "--td", "0", "--out", str(out)])
    assert status == 2 and f"--ti must be {RANGES['ti_s'].text()}" in err and "improper" not in err
    assert not out.exists()
    bad = tmp_path / "plant.json"
    bad.write_text(json.dumps({"built": {"R1_ohm": 1e3, "R2_ohm": 1e3, "C1_f": 1e-9, "C2_f": "x"}}))
    status, _, err = run(["--plant-json", str(bad), "--out", str(out)])
    assert status == 2 and "built.C2_f" in err and not out.exists()


def help_entries(text):
    """option -> its help text (continuation lines joined), from argparse's --help."""
    entries, current = {}, None
    for line in text.splitlines():
        if line.startswith("  -"):
            current = line.split()[0]
            entries[current] = line
        elif current and line.startswith("    "):
            entries[current] += line
        else:
            current = None
    return {k: " ".join(v.split()) for k, v in entries.items()}


def test_every_numeric_option_states_its_range_in_help(capsys):
    import pytest
    with pytest.raises(SystemExit):
        design_pid_main(["--help"])
    entries = help_entries(capsys.readouterr().out)
    # --r-max/--c-max share the range stated on --r-min/--c-min (designer.cli.add_part_options)
    options = {o: k for o, (k, _) in NUMERIC.items() if o not in ("--r-max", "--c-max")}
    options.update({"--target-overshoot": "target_overshoot_pct", "--target-settling": "target_settling_s"})
    for option, key in options.items():
        assert f"({RANGES[key].text()})" in entries[option], (option, entries[option])


# ---- a plant known only as a model (issue 16) -------------------------------------

MODEL_PLANT = ["--plant-tf", "K=2 tau=1m theta=200u"]
#: the model plant's numeric options and the other arguments they need
MODEL_NUMERIC = {
    "--simc-tauc": ("simc_tauc_s", MODEL_PLANT + ["--tuning", "simc"]),
    "--imc-lambda": ("imc_lambda_s", MODEL_PLANT + ["--tuning", "imc"]),
    "--min-pm": ("min_phase_margin_deg", MODEL_PLANT),
    "--min-gm": ("min_gain_margin_db", MODEL_PLANT),
    "--max-ms": ("max_ms", MODEL_PLANT),
}


@examples(40)
@given(data=st.data(), option=st.sampled_from(sorted(MODEL_NUMERIC)))
def test_any_value_of_any_model_plant_option(data, option):
    key, rest = MODEL_NUMERIC[option]
    run(rest + flag(option, data.draw(values(key))) + ["--no-sim", "--no-files"])


def model_texts():
    """Typed models: well-formed ones with values from anywhere, and garbage."""
    value = values()
    forms = [st.builds(lambda k, t, th: f"K={k} tau={t} theta={th}", value, value, value),
             st.builds(lambda k, a, b: f"K={k} tau1={a} tau2={b}", value, value, value),
             st.builds(lambda k, f, z: f"K={k} fn={f} zeta={z}", value, value, value),
             st.builds(lambda n, d: f"num=[{n}] den=[{d} 1]", value, value),
             st.builds(lambda k, t: f"K={k} tau={t} integrator", value, value),
             st.text(max_size=30)]
    return st.one_of(*forms)


@examples(60)
@given(text=model_texts())
@example(text="K=0.3 fn=251.82MEG zeta=1.3e-262")   # overflowed the tangent rules' search: now refused
def test_any_typed_model(text):
    run(flag("--plant-tf", text) + ["--no-sim", "--no-files"])


@examples(20)
@given(rng=st.builds(lambda a, b: f"{a}:{b}", values(), values()) | st.text(max_size=10))
def test_any_plant_input_range(rng):
    run(MODEL_PLANT + flag("--plant-input", rng) + ["--no-sim", "--no-files"])
