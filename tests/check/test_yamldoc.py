"""check.yamldoc (with check.yamlread's bounds): a stranger's spec file is read with
budgets, refused in one line naming the file and the line, and otherwise read as PyYAML's
safe loader reads it, with the line of every key."""

import subprocess
import time

import pytest
import yaml
from helpers import script
from hypothesis import HealthCheck, given, settings
from hypothesis import strategies as st
from specfiles import DECK, refusal, write

from designer.check.spec import load_spec
from designer.check.yamldoc import parse_yaml
from designer.check.yamlread import MAX_NODES
from designer.core.errors import DesignError


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
