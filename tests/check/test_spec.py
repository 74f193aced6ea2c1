"""check.spec: a spec file is validated once, when loaded; every refusal is one
line naming the file, the line, what is wrong and what is allowed."""

import subprocess
import textwrap
import time
from pathlib import Path

import pytest
import yaml
from helpers import ROOT, script
from hypothesis import HealthCheck, given, settings
from hypothesis import strategies as st

from designer.check.spec import load_spec, parse_yaml
from designer.check.yamlread import MAX_NODES
from designer.core.errors import DesignError

SPECS = sorted((ROOT / "specs").glob("*.yaml"))
DECK = "deck\nV1 in 0 PULSE(0 1 1u 1n 1n 1 2)\nR1 in out 1k\nC1 out 0 1n\n.tran 10n 20u\n" \
       ".meas tran vmax MAX v(out)\n.meas tran T_Rise WHEN v(out)=0.5 RISE=1\n.end\n"


def write(tmp_path, text, name="spec.yaml") -> Path:
    path = tmp_path / name
    path.write_text(textwrap.dedent(text))
    return path


def refusal(path, **kw) -> str:
    with pytest.raises(DesignError) as info:
        load_spec(path, **kw)
    msg = str(info.value)
    assert "\n" not in msg
    return msg


@pytest.mark.parametrize("path", SPECS, ids=lambda p: p.stem)
def test_the_dogfood_specs_load(path):
    spec = load_spec(path, root=ROOT)   # one reads a reference result in reports/: the repository is the root
    assert spec.name == path.stem and spec.corners


def test_corners_and_designs_follow_the_opamp_list():
    spec = load_spec(ROOT / "specs" / "plant_fc3500_z0.2.yaml")
    assert spec.corners == ("LM741", "TL072")
    assert [d.opamp for d in spec.designs] == list(spec.corners)
    assert spec.classname("TL072") == "plant_fc3500_z0.2[TL072]"
    assert spec.golden.path("TL072").name == "plant_fc3500_z0.2-TL072.csv"


def test_a_typo_names_file_line_allowed_keys_and_the_closest(tmp_path):
    path = write(tmp_path, """\
        kind: plant
        target: {fc: 3.5k, zeta: 0.2}
        checks:
          fn_hz:
            min: 3k
            tolerence: 1
        """)
    msg = refusal(path)
    assert msg.startswith(f"{path}:6: unknown key 'tolerence'")
    assert "allowed: min, typ, max, fail" in msg and "closest: 'typ'" in msg


@pytest.mark.parametrize("body, line, words", [
    ("kind: plant\ntarget: {fc: 3.5k, zeta: 0.2\n", 3, "not valid YAML"),
    ("kind: plnt\n", 1, "closest: 'plant'"),
    ("kind: plant\ntarget: {fc: 3.5k, zeta: 0.2}\nchecks:\n  fn_hz: {min: abc}\n", 4, "is not a number"),
    ("kind: plant\ntarget: {fc: 3.5k, zeta: 0.2}\nchecks:\n  fn_hz: {min: 4k, max: 3k}\n", 4, "above max"),
    ("kind: plant\ntarget: {fc: 3.5k, zeta: 0.2}\nopamp: [LM741, LM7411]\nchecks:\n  fn_hz: {min: 1}\n", 3,
     "unknown op-amp 'LM7411'"),
    ("kind: plant\ntarget: {fc: 35M, zeta: 0.2}\nchecks:\n  fn_hz: {min: 1}\n", 2, "target.fc must be"),
    ("kind: plant\nparts: {R1: 1k, R2: 1k, C1: 1n, C2: -1n}\nchecks:\n  fn_hz: {min: 1}\n", 2, "parts.C2"),
    ("kind: plant\ntarget: {fc: 3.5k, zeta: 0.2}\nchecks:\n  fnhz: {min: 3k}\n", 4, "closest: 'fn_hz'"),
    ("kind: plant\ntarget: {fc: 3.5k, zeta: 0.2}\n", 1, "nothing to check"),
    ("kind: plant\ntarget: {fc: 3.5k, zeta: 0.2}\ndesign_checks: [slew_rte]\n", 3, "closest: 'slew_rate'"),
    ("kind: plant\ntarget: {fc: 3.5k, zeta: 0.2}\nspice_agreement: {nrms_max: 1, against: model}\n", 3,
     "allowed: opamp_model, ideal"),
    ("kind: pid\nplant: {fc: 3.5k, zeta: 0.2}\ntuning: {kp: 45}\ndesign_checks: all\n", 3, "tuning.kp"),
    ("kind: pid\nplant: {fc: 3.5k, zeta: 0.2}\ncontroller: {R3: 1k}\ndesign_checks: all\n", 3, "controller.R4"),
    ("kind: plant\ntarget: {fc: 3.5k, zeta: 0.2}\nopamp: [LM741, TL072]\n"
     "golden: {file: g.csv}\n", 4, "needs {corner}"),
    ("kind: plant\ntarget: {fc: 3.5k, zeta: 0.2}\ngolden: {file: g.csv}\n", 3, "record it with check-design"),
    ("kind: plant\ntarget: {fc: 3.5k, zeta: 0.2}\nchecks:\n  fn_hz: {max: 4k}\ntolerance: [zeta]\n", 5,
     "needs a check on zeta"),
    ("name: ../x\nkind: plant\ntarget: {fc: 3.5k, zeta: 0.2}\ndesign_checks: all\n", 1, "not a plain file name"),
])
def test_bad_specs_are_refused_in_one_line(tmp_path, body, line, words):
    path = write(tmp_path, body)
    msg = refusal(path)
    assert msg.startswith(f"{path}:{line}: ") and words in msg, msg


def test_a_missing_file_is_refused(tmp_path):
    assert "does not exist" in refusal(tmp_path / "nope.yaml")


def test_netlist_checks_name_the_decks_measurements(tmp_path):
    (tmp_path / "decks").mkdir()
    (tmp_path / "decks" / "rc.cir").write_text(DECK)
    ok = write(tmp_path, "kind: netlist\ndeck: decks/rc.cir\nchecks:\n  vmax: {max: 1}\n  t_rise: {max: 1}\n")
    spec = load_spec(ok)
    assert spec.designs == (DECK,) and [c.figure for c in spec.checks] == ["vmax", "t_rise"]
    bad = write(tmp_path, "kind: netlist\ndeck: decks/rc.cir\nchecks:\n  vmin: {max: 1}\n", "bad.yaml")
    msg = refusal(bad)
    assert msg.startswith(f"{bad}:4: unknown measurement 'vmin'") and "allowed: t_rise, vmax" in msg


@pytest.mark.parametrize("deck, words", [
    ("just one line\n", "not an ngspice deck"),
    ("t\nR1 a 0 1k\n.control\nrun\n.endc\n.tran 1u 1m\n.end\n", ".control block"),
    ("t\nR1 a 0 1k\n.op\n.end\n", "no .tran or .ac line"),
])
def test_a_deck_that_is_no_ngspice_deck_is_refused(tmp_path, deck, words):
    (tmp_path / "d.cir").write_text(deck)
    path = write(tmp_path, "kind: netlist\ndeck: d.cir\nchecks:\n  vmax: {max: 1}\n")
    msg = refusal(path)
    assert msg.startswith(f"{path}:2: ") and words in msg


def test_golden_files_may_be_missing_when_they_are_being_recorded(tmp_path):
    path = write(tmp_path, "kind: plant\ntarget: {fc: 3.5k, zeta: 0.2}\ngolden: {file: \"g/{corner}.csv\"}\n")
    spec = load_spec(path, update_golden=True)
    assert spec.golden.path("LM741") == tmp_path / "g" / "LM741.csv"
    assert spec.golden.signals == {"output_v": (0.01, 1e-3)}


# ---- bounded YAML: a stranger's spec cannot exhaust memory, recurse or hide a key ----------

def laughs(levels=9, width=9) -> str:
    """A "billion laughs": ``levels`` lists each holding ``width`` aliases of the one before (9 x 9: 431 bytes,
    387 million strings once expanded), under a key the spec does not have."""
    rows = ["kind: plant", "lol:", f"  a: &a [{', '.join(['lol'] * width)}]"]
    for i in range(1, levels):
        prev, name = chr(96 + i), chr(97 + i)
        rows.append(f"  {name}: &{name} [{', '.join([f'*{prev}'] * width)}]")
    return "\n".join(rows) + "\n"


def expanded_nodes(levels, width) -> int:
    """The nodes of :func:`laughs` with every alias expanded (the root, kind, lol, and each level's key and list)."""
    size, total = 1 + width, 0
    for _ in range(levels):
        total += 1 + size
        size = 1 + width * size
    return 1 + 2 + 2 + total


@pytest.mark.untrusted
def test_a_billion_laughs_is_refused_at_once_in_one_line(tmp_path):
    path = write(tmp_path, laughs())
    tick = time.perf_counter()
    msg = refusal(path)
    assert time.perf_counter() - tick < 1.0
    assert msg.startswith(f"{path}:7: alias *d makes the spec more than {MAX_NODES} YAML nodes"), msg
    out = subprocess.run([script("check-design"), str(path)], capture_output=True, text=True, timeout=60)
    assert out.returncode == 2 and out.stdout == ""
    assert out.stderr.count("\n") == 1 and "aliases expanded" in out.stderr and "Traceback" not in out.stderr


@pytest.mark.untrusted
@given(levels=st.integers(1, 12), width=st.integers(1, 12))
@settings(max_examples=40, suppress_health_check=[HealthCheck.function_scoped_fixture])
def test_aliases_are_refused_exactly_beyond_the_node_budget(tmp_path, levels, width):
    path = tmp_path / "bomb.yaml"
    path.write_text(laughs(levels, width))
    tick = time.perf_counter()
    try:
        doc = parse_yaml(path)
    except DesignError as exc:
        assert expanded_nodes(levels, width) > MAX_NODES
        assert "\n" not in str(exc) and f"more than {MAX_NODES} YAML nodes" in str(exc)
    else:
        assert expanded_nodes(levels, width) <= MAX_NODES and doc.data["lol"]["a"] == ["lol"] * width
    assert time.perf_counter() - tick < 1.0


@pytest.mark.untrusted
@pytest.mark.parametrize("body, line", [
    ("kind: plant\na: &x [*x]\n", 2),
    ("kind: plant\nchecks: &x\n  fn_hz: {min: 1}\n  q: [1, *x]\n", 4),
    ("kind: plant\ntarget: &t {fc: 3.5k, <<: *t}\n", 2),
])
def test_an_alias_inside_the_node_it_names_is_refused(tmp_path, body, line):
    path = write(tmp_path, body)
    msg = refusal(path)
    assert msg.startswith(f"{path}:{line}: alias *") and "recursive" in msg, msg


@pytest.mark.untrusted
@pytest.mark.parametrize("body, line, words", [
    ("kind: plant\nchecks:\n  fn_hz: {min: 1}\ntarget: {fc: 3.5k, zeta: 0.2}\nchecks:\n  q: {min: 1}\n", 5,
     "duplicate key 'checks' (first at line 2)"),
    ("kind: plant\ntarget: {fc: 3.5k, zeta: 0.2}\nchecks:\n  fn_hz: {min: 1}\n  q: {max: 9}\n  fn_hz: {max: 2}\n", 6,
     "duplicate key 'fn_hz' in checks (first at line 4)"),
    ("kind: plant\ntarget: {fc: 3.5k, zeta: 0.2, fc: 4k}\n", 2, "duplicate key 'fc' in target (first at line 2)"),
    ("kind: plant\nopamp:\n  - {a: 1,\n     a: 2}\n", 4, "duplicate key 'a' in opamp.0 (first at line 3)"),
])
def test_a_key_given_twice_is_refused_naming_both_lines(tmp_path, body, line, words):
    path = write(tmp_path, body)
    msg = refusal(path)
    assert msg.startswith(f"{path}:{line}: {words}"), msg


@pytest.mark.untrusted
def test_a_big_file_a_long_value_and_deep_nesting_are_refused(tmp_path):
    big = tmp_path / "big.yaml"
    big.write_text("kind: plant\ndescription: " + "x" * (2 * 2 ** 20) + "\n")
    assert refusal(big) == f"spec file {big} is 2 MiB; at most 1 MiB is read: cut or decimate it"
    long = write(tmp_path, "kind: plant\ntarget: {fc: 3.5k, zeta: 0.2}\n\nname: " + "a" * 5000 + "\n", "long.yaml")
    assert refusal(long).startswith(f"{long}:4: name is 5000 characters long; a value may have at most 4096")
    key = write(tmp_path, "kind: plant\n? " + "k" * 5000 + "\n: 1\n", "key.yaml")   # (a plain key: 1024 at most)
    assert refusal(key).startswith(f"{key}:2: a key in the spec is 5000 characters long")
    # a description may be longer (64 KiB)
    desc = write(tmp_path, "kind: plant\ntarget: {fc: 3.5k, zeta: 0.2}\ndesign_checks: all\ndescription: "
                 + "d" * 20000 + "\n", "desc.yaml")
    assert len(parse_yaml(desc).data["description"]) == 20000
    deep = write(tmp_path, "kind: plant\nx: " + "[" * 5000 + "]" * 5000 + "\n", "deep.yaml")
    assert "nests more than 64 levels" in refusal(deep)
    date = write(tmp_path, "kind: plant\nx: 2024-02-30\n", "date.yaml")
    assert refusal(date) == f"{date}:2: not valid YAML (day is out of range for month)"


def test_a_shared_mapping_and_a_merge_key_are_read_as_pyyaml_reads_them(tmp_path):
    (tmp_path / "rc.cir").write_text(DECK)
    path = write(tmp_path, """\
        kind: netlist
        deck: rc.cir
        checks:
          vmax: &lim {min: 0.5, max: 2}
          t_rise: *lim
        golden:
          file: g.csv
          signals:
            out: &tol {reltol: 0.02, abstol: 1m}
            in: {<<: *tol,
                 abstol: 2m}
        """)
    spec = load_spec(path, update_golden=True)
    assert [(c.figure, c.min, c.max) for c in spec.checks] == [("vmax", 0.5, 2), ("t_rise", 0.5, 2)]
    assert spec.golden.signals == {"out": (0.02, 1e-3), "in": (0.02, 2e-3)}
    doc = parse_yaml(path)
    # a merged key's line is its definition's, unless the mapping gives it itself
    assert doc.lines[("golden", "signals", "in", "abstol")] == 11
    assert doc.lines[("golden", "signals", "in", "reltol")] == 9
    assert doc.lines[("checks", "t_rise", "max")] == 4


def _recursive_marks(node, keys=(), out=None) -> dict:
    """The line table as parse_yaml built it before it was bounded (recursive: small documents only)."""
    out = {} if out is None else out
    out.setdefault(keys, node.start_mark.line + 1)
    if isinstance(node, yaml.MappingNode):
        for k, v in node.value:
            key = k.value if isinstance(k.value, str) else None
            out[keys + (key,)] = k.start_mark.line + 1
            _recursive_marks(v, keys + (key,), out)
    elif isinstance(node, yaml.SequenceNode):
        for i, v in enumerate(node.value):
            _recursive_marks(v, keys + (i,), out)
    return out


_SCALARS = st.one_of(st.integers(-10 ** 6, 10 ** 6), st.floats(allow_nan=False), st.booleans(), st.none(),
                     st.text(st.characters(codec="utf-8", exclude_categories=("Cs", "Cc")), max_size=8))
_TREES = st.recursive(_SCALARS, lambda kids: st.one_of(
    st.lists(kids, max_size=4), st.dictionaries(st.text("abcxyz_-", min_size=1, max_size=5), kids, max_size=4)),
    max_leaves=16)


@given(shared=_TREES, other=_TREES, uses=st.integers(1, 4))
@settings(max_examples=60, suppress_health_check=[HealthCheck.function_scoped_fixture])
def test_a_spec_reads_as_safe_load_reads_it_with_the_same_lines(tmp_path, shared, other, uses):
    # the same object several times: the dumper writes an anchor and aliases
    text = yaml.safe_dump({"kind": "plant", "a": shared, "b": [shared] * uses + [other], "c": {"d": shared}})
    path = tmp_path / "s.yaml"
    path.write_text(text)
    doc = parse_yaml(path)
    assert doc.data == yaml.safe_load(text)
    assert doc.lines == _recursive_marks(yaml.compose(text, Loader=yaml.SafeLoader))


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
