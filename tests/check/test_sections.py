"""check.sections: a spec's ``yield:`` and ``tolerances:`` load with their defaults, and each
bad value is one line at its key (read through load_spec, as a spec file is)."""

import textwrap

import pytest
import yaml
from hypothesis import HealthCheck, given, settings
from hypothesis import strategies as st
from specfiles import refusal, write

from designer.check.spec import load_spec
from designer.core.errors import DesignError


# ---- tolerances: and yield: (issue 17) ---------------------------------------------

YIELD_BASE = textwrap.dedent("""\
    kind: plant
    target: {fc: 3.5k, zeta: 0.2}
    checks:
      fn_hz: {min: 3.4k, max: 3.6k}
    """)


def test_yield_and_tolerances_load_with_their_defaults(tmp_path):
    spec = load_spec(write(tmp_path, YIELD_BASE + "tolerances: {R: 1%, C2: 0.02}\nyield: {min: 95%}\n"))
    y = spec.yield_spec
    assert (y.min, y.samples, y.seed, y.engine, y.sampler, y.dist) == (0.95, 2000, 0, "analytic", "random", "uniform")
    assert y.tolerances == ("R=1.0%", "C2=2.0%")
    assert load_spec(write(tmp_path, YIELD_BASE)).yield_spec is None


def test_a_pid_spec_names_the_loops_parts(tmp_path):
    spec = load_spec(write(tmp_path, """\
        kind: pid
        plant: {fc: 3.5k, zeta: 0.2}
        checks:
          phase_margin_deg: {min: 30}
        tolerances: {R18: 0.1%, C4: 2%}
        yield: {min: 0.9, samples: 500, seed: 7, dist: normal, sampler: sobol}
        """))
    y = spec.yield_spec
    assert (y.min, y.samples, y.seed, y.dist, y.sampler) == (0.9, 500, 7, "normal", "sobol")
    assert y.tolerances == ("R18=0.1%", "C4=2.0%")


@pytest.mark.parametrize("extra, line, words", [
    ("yield: {min: 95%}\ntolerances: {SR: 20%}", 6, "give yield.engine: spice"),
    ("yield: {min: 95%, engine: magic}", 5, "allowed: analytic, spice"),
    ("yield: {min: 95}", 5, "write 95%"),
    ("yield: {min: 0%}", 5, "above 0 and at most 100 %"),
    ("yield: {samples: 100}", 5, "yield needs min"),
    ("yield: {min: 95%, samples: 5}", 5, "from 10 to"),
    ("yield: {min: 95%, samples: 1.5}", 5, "whole number"),
    ("yield: {min: 95%, seed: -1}", 5, "whole number >= 0"),
    ("yield: {min: 95%, sampler: grid}", 5, "allowed: random, lhs, sobol"),
    ("yield: {min: 95%, dist: cauchy}", 5, "allowed: uniform, normal"),
    ("yield: {min: 95%, mni: 1}", 5, "closest: 'min'"),
    ("yield: [95%]", 5, "must be a mapping"),
    ("yield: {min: 95%}\ntolerances: {X9: 1%}", 6, "unknown key 'X9' in tolerances"),
    ("yield: {min: 95%}\ntolerances: {R: 0%}", 6, "above 0 and at most 50 %"),
    ("yield: {min: 95%}\ntolerances: {R: 60%}", 6, "at most 50 %"),
    ("yield: {min: 95%}\ntolerances: {C: lots}", 6, "is not a tolerance"),
    ("yield: {min: 95%}\ntolerances: {C: [1]}", 6, "got a list"),
    ("tolerances: {R: 1%}", 5, "give yield:"),
    # a key twice is refused, not the last one kept (as --tol R=1% --tol R=2% is on the command line)
    ("yield: {min: 95%}\ntolerances: {R: 1%, C: 5%, R: 2%}", 6, "duplicate key 'R' in tolerances (first at line 6)"),
    ("yield: {min: 95%}\ntolerances:\n  C2: 1%\n  C2: 2%", 8, "duplicate key 'C2' in tolerances (first at line 7)"),
    ("yield: {min: 95%}\ntolerances: {r: 1%}", 6, "unknown key 'r' in tolerances"),
])
def test_a_bad_yield_or_tolerances_is_one_line_at_its_key(tmp_path, extra, line, words):
    msg = refusal(write(tmp_path, YIELD_BASE + extra + "\n"))
    assert msg.startswith(f"{tmp_path / 'spec.yaml'}:{line}:") and words in msg, msg


def test_a_yield_needs_a_check_the_engine_computes(tmp_path):
    msg = refusal(write(tmp_path, """\
        kind: plant
        target: {fc: 3.5k, zeta: 0.2}
        checks:
          nrms: {max: 1}
          rise_time_s: {max: 1m}
        yield: {min: 95%}
        """))
    assert "none of them limits a figure the analytic engine computes" in msg and "not: nrms, rise_time_s" in msg


@settings(max_examples=60, deadline=None, suppress_health_check=[HealthCheck.function_scoped_fixture])
@given(pct=st.floats(min_value=-50, max_value=250, allow_nan=False), percent=st.booleans())
def test_yield_min_is_a_fraction_or_one_line(tmp_path, pct, percent):
    text = f"{pct!r}%" if percent else repr(pct / 100)
    path = write(tmp_path, YIELD_BASE + f"yield: {{min: '{text}'}}\n")
    value = pct / 100
    if 0 < value <= 1:
        assert load_spec(path).yield_spec.min == pytest.approx(value, rel=1e-12, abs=1e-15)
    else:
        msg = refusal(path)
        assert "yield.min must be a percentage above 0 and at most 100 %" in msg


@settings(max_examples=60, deadline=None, suppress_health_check=[HealthCheck.function_scoped_fixture])
@given(key=st.sampled_from(["R", "C", "R1", "C2", "R3", "Q1", "r", "GBW"]),
       value=st.one_of(st.floats(allow_nan=True, allow_infinity=True), st.text(max_size=8), st.integers(-5, 80)))
def test_tolerances_are_valid_or_one_line(tmp_path, key, value):
    path = write(tmp_path, YIELD_BASE + "yield: {min: 95%}\n")
    path.write_text(path.read_text() + yaml.safe_dump({"tolerances": {key: value}}))
    try:
        spec = load_spec(path)
    except DesignError as exc:
        assert "\n" not in str(exc) and str(exc).startswith(str(path))
        return
    (item,) = spec.yield_spec.tolerances
    name, pct = item.split("=")
    assert name == key and 0 < float(pct.rstrip("%")) <= 50
