"""A whole check-design run as a library call (designer.check.batch): what the command line and the web page's
Check both run. Its result.json files are the outcomes it hands back, its refusals come before any run, and
its lines are what check-design prints."""

import json
import shutil

import pytest
from helpers import ROOT

from designer.check.batch import CheckRun, check_specs, load_specs
from designer.core.errors import DesignError

pytestmark = pytest.mark.spice


def _ladder(tmp_path):
    """The repository's rc_ladder spec with its deck and golden file, copied as they are."""
    for rel in ("rc_ladder.yaml", "decks/rc_ladder.cir", "golden/rc_ladder.csv"):
        (tmp_path / "specs" / rel).parent.mkdir(parents=True, exist_ok=True)
        shutil.copy(ROOT / "specs" / rel, tmp_path / "specs" / rel)
    return tmp_path / "specs" / "rc_ladder.yaml"


def test_a_run_hands_back_what_its_output_folder_holds(tmp_path):
    spec = _ladder(tmp_path)
    run = check_specs([spec], "ngspice-cli", out=tmp_path / "out")
    assert isinstance(run, CheckRun) and run.status == 0 and run.seconds > 0
    written = json.loads((tmp_path / "out" / "rc_ladder" / "result.json").read_text())
    assert run.results() == [written] and written["status"] == "pass"
    assert written["files"]["result_json"] == str(tmp_path / "out" / "rc_ladder" / "result.json")
    n = written["counts"]
    assert run.lines() == [f"rc_ladder: pass ({n['pass']} passed, 0 failed, 0 errors, 0 report-only)"]
    assert '<testsuite name="rc_ladder"' in run.junit() and "rc_ladder" in run.summary()
    assert [ln for ln in run.messages() if "warning" not in ln] == []
    # without an output folder: the same judgement, no files
    again = check_specs([spec], "ngspice-cli")
    assert [c["cases"] for c in again.results()[0]["corners"]] == [c["cases"] for c in written["corners"]]
    assert "result_json" not in again.results()[0]["files"]


def test_a_run_records_the_golden_files_it_is_asked_to(tmp_path):
    spec = _ladder(tmp_path)
    golden = tmp_path / "specs" / "golden" / "rc_ladder.csv"
    golden.unlink()
    with pytest.raises(DesignError, match="--update-golden"):
        check_specs([spec])
    run = check_specs([spec], update_golden=True)
    assert run.status == 0 and golden.is_file()
    assert all(c["status"] == "pass" for c in run.results()[0]["corners"][0]["cases"])
    assert check_specs([spec]).status == 0   # the recording is the reference now


def test_two_specs_of_one_name_are_refused_before_any_run(tmp_path):
    spec = _ladder(tmp_path)
    twin = tmp_path / "specs" / "twin.yaml"
    twin.write_text(spec.read_text())
    with pytest.raises(DesignError, match="name 'rc_ladder' is also the name of"):
        load_specs([spec, twin])
    with pytest.raises(DesignError, match="names must differ"):
        check_specs([spec, twin], out=tmp_path / "out")
    assert not (tmp_path / "out").exists()


def test_a_path_outside_the_root_is_refused_naming_the_key(tmp_path):
    spec = _ladder(tmp_path)
    with pytest.raises(DesignError, match=r"rc_ladder.yaml:\d+: golden.file .* outside"):
        check_specs([spec], root=tmp_path / "specs" / "decks")
    assert check_specs([spec], root=tmp_path).status == 0
