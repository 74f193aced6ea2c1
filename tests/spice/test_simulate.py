import numpy as np
import pytest

from designer.core import opamps
from designer.core.errors import DesignError
from designer.plant.netlist import plant_deck
from designer.plant.sallenkey import SallenKeyParts
from designer.spice.deck import SquareTest
from designer.spice.simulate import (NgspiceCli, error_lines, get_simulator, read_raw, recorded_command, tool_info,
                                     with_raw_output)

pytestmark = pytest.mark.spice

SEED = SallenKeyParts(820, 1e3, 10e-9, 220e-9)


@pytest.fixture(scope="module")
def deck():
    return plant_deck(SEED, opamps.get("LM741"), SquareTest(2.0, 330.0, 1e-4), "seed plant")


@pytest.fixture(scope="module")
def both(deck):
    return {name: get_simulator(name).run(deck) for name in ("pyspice", "ngspice-cli")}


def test_both_backends_give_the_same_waveforms(both):
    a, b = both["pyspice"], both["ngspice-cli"]
    assert a.backend == "pyspice" and b.backend == "ngspice-cli"
    assert np.array_equal(a["time"], b["time"])
    assert np.max(np.abs(a["out"] - b["out"])) < 1e-9
    assert a["v(out)"] is a["out"]


def test_both_backends_report_the_same_measurements(both):
    a, b = both["pyspice"].measurements, both["ngspice-cli"].measurements
    for key in ("overshoot_pct", "peak_time_s", "rise_time_s", "settling_time_s"):
        assert key in a
        assert a[key] == pytest.approx(b[key], rel=1e-6)


def test_deck_runs_alone_and_prints_its_measurements(deck, tmp_path):
    import subprocess
    path = tmp_path / "alone.cir"
    path.write_text(deck)
    out = subprocess.run(["ngspice", "-b", str(path)], capture_output=True, text=True, cwd=tmp_path, timeout=60)
    assert out.returncode == 0
    for key in ("overshoot_pct", "peak_time_s", "rise_time_s", "settling_time_s"):
        assert key in out.stdout


def test_cli_backend_ignores_stderr_notes(deck):
    # ngspice writes "Note: No compatibility mode selected!" on stderr in normal runs
    res = NgspiceCli().run(deck)
    assert "Note:" in res.log or "note" in res.log.lower()
    assert res.measurements["overshoot_pct"] > 0


def test_ngspice_error_is_reported(tmp_path):
    bad = "bad deck\nR1 a 0 1k\nX1 a b NO_SUCH_SUBCKT\n.tran 1u 10u\n.end\n"
    for name in ("ngspice-cli", "pyspice"):
        with pytest.raises(DesignError, match="ngspice"):
            get_simulator(name).run(bad)


def test_missing_ngspice_names_the_fix():
    with pytest.raises(DesignError, match="apt-get install ngspice"):
        NgspiceCli(executable="ngspice-not-here").run("x\n.end\n")


def test_unknown_backend():
    with pytest.raises(DesignError, match="allowed: pyspice, ngspice-cli"):
        get_simulator("spectre")


def test_raw_reader_reads_ascii_and_binary(deck, tmp_path):
    import subprocess
    for ftype in ("binary", "ascii"):
        raw = tmp_path / f"{ftype}.raw"
        text = with_raw_output(deck, raw).replace("set filetype=binary", f"set filetype={ftype}")
        (tmp_path / "d.cir").write_text(text)
        subprocess.run(["ngspice", "-b", str(tmp_path / "d.cir")], capture_output=True, timeout=60, check=True)
        vecs = read_raw(raw)
        assert "time" in vecs and "v(out)" in vecs
        assert vecs["v(out)"].max() == pytest.approx(3.0, abs=0.2)


def test_error_lines_skip_notes():
    assert error_lines("Note: No compatibility mode selected!\nWarning: x failed\n") == []
    assert error_lines("Error: unknown subckt: x1 a b\n") == ["Error: unknown subckt: x1 a b"]


def test_a_failed_measurement_is_not_a_failed_run(deck):
    # regression: ngspice prints "name failed!" for a .meas whose level is never crossed
    never = deck.replace(".end\n", ".meas tran never WHEN v(out)=1e6 CROSS=1\n.end\n")
    for name in ("pyspice", "ngspice-cli"):
        res = get_simulator(name).run(never)
        assert "never" not in res.measurements
        assert "overshoot_pct" in res.measurements


NO_ANALYSIS = "* no analysis\nR1 a 0 1k\nV1 a 0 1\n.end\n"


@pytest.mark.parametrize("backend", ["pyspice", "ngspice-cli"])
def test_a_deck_with_no_analysis_says_so(backend):
    """Regression (issue 7.9): the CLI backend returned ngspice's constants as if they were results."""
    from designer.core.errors import SimulatorError
    with pytest.raises(SimulatorError, match="no analysis"):
        get_simulator(backend).run(NO_ANALYSIS)


@pytest.mark.parametrize("damage", ["empty", "truncated", "no-header", "garbage"])
def test_unreadable_raw_file_is_one_clear_error(deck, tmp_path, damage):
    """Regression (issue 7.9): a corrupt or truncated raw file was a traceback."""
    import subprocess

    from designer.core.errors import SimulatorError
    good = tmp_path / "good.raw"
    path = tmp_path / "deck.cir"
    path.write_text(with_raw_output(deck, good))
    subprocess.run(["ngspice", "-b", str(path)], capture_output=True, cwd=tmp_path, timeout=60, check=True)
    data = good.read_bytes()
    bad = tmp_path / "bad.raw"
    bad.write_bytes({"empty": b"", "truncated": data[: len(data) // 2],
                     "no-header": data[data.find(b"Binary:"):], "garbage": bytes(range(256)) * 4}[damage])
    with pytest.raises(SimulatorError) as e:
        read_raw(bad)
    assert "raw file" in str(e.value) and "\n" not in str(e.value)
    assert read_raw(good)["time"].size > 100


def test_a_recorded_command_is_the_results_record_and_leaves_sys_argv():
    """The web page's check job records the command line its request stands for by recorded_command, where it
    once swapped sys.argv (a global of the whole worker); nested, each block its own; an explicit argv wins."""
    import sys
    before = list(sys.argv)
    assert tool_info(None)["argv"] == before
    with recorded_command(["check-design", "a.yaml"]):
        assert tool_info(None)["argv"] == ["check-design", "a.yaml"] and sys.argv == before
        with recorded_command(["check-design", "b.yaml"]):
            assert tool_info(None)["argv"] == ["check-design", "b.yaml"]
        assert tool_info(None)["argv"] == ["check-design", "a.yaml"]
        assert tool_info(None, ["x"])["argv"] == ["x"]
    assert tool_info(None)["argv"] == before
