"""check.spec: a spec file is validated once, when loaded; every refusal is one
line naming the file, the line, what is wrong and what is allowed."""

import pytest
from helpers import ROOT
from specfiles import DECK, refusal, write

from designer.check.spec import load_spec

SPECS = sorted((ROOT / "specs").glob("*.yaml"))


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

