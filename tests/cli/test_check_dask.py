"""check-design --dask (designer.cli.check, designer.tolerance.cluster.DaskPool): every corner as a
task of a LocalCluster gives the same cases and the same files as the forked workers; a scheduler
that does not answer is exit 3 in one line; a bad address is exit 2."""

import json
import socket
import subprocess
import time

import pytest
from helpers import script

CHECK = script("check-design")
DECK = "quick\nV1 in 0 SIN(0 1 1k)\nR1 in out 1k\nC1 out 0 100n\n.tran 1u 1m\n.meas tran vmax MAX v(out)\n.end\n"
PLANT = "name: p\nkind: plant\ntarget: {fc: 3.5k, zeta: 0.2}\nopamp: [LM741, TL072]\nchecks:\n  overshoot_pct: {max: 80}\n"


def specs(folder):
    (folder / "a.cir").write_text(DECK)
    (folder / "a.yaml").write_text("name: a\nkind: netlist\ndeck: a.cir\nchecks:\n  vmax: {max: 0.5}\n")
    (folder / "p.yaml").write_text(PLANT)
    return [str(folder / "a.yaml"), str(folder / "p.yaml")]


def cases(out, name):
    d = json.loads((out / name / "result.json").read_text())
    return d["status"], [(c["corner"], [(k["id"], k["status"], k["value"]) for k in c["cases"]]) for c in d["corners"]]


@pytest.mark.spice
def test_corners_on_a_local_cluster_give_the_same_cases_and_files(tmp_path):
    files = specs(tmp_path)
    here = subprocess.run([CHECK, *files, "--simulator", "ngspice-cli", "--out", str(tmp_path / "here")],
                          capture_output=True, text=True, timeout=300)
    there = subprocess.run([CHECK, *files, "--simulator", "ngspice-cli", "--out", str(tmp_path / "there"), "--dask",
                            "local"], capture_output=True, text=True, timeout=300)
    assert here.returncode == there.returncode == 1, here.stderr + there.stderr   # a's vmax fails on purpose
    assert here.stdout == there.stdout
    for name in ("a", "p"):
        assert cases(tmp_path / "here", name) == cases(tmp_path / "there", name)
    built = sorted(p.relative_to(tmp_path / "there") for p in (tmp_path / "there").rglob("*") if p.is_file())
    assert built == sorted(p.relative_to(tmp_path / "here") for p in (tmp_path / "here").rglob("*") if p.is_file())


def test_a_scheduler_that_does_not_answer_is_exit_3(tmp_path):
    with socket.socket() as s:
        s.bind(("127.0.0.1", 0))
        port = s.getsockname()[1]
    tick = time.monotonic()
    p = subprocess.run([CHECK, *specs(tmp_path), "--dask", f"127.0.0.1:{port}", "--out", str(tmp_path / "out")],
                       capture_output=True, text=True, timeout=60)
    assert p.returncode == 3 and len(p.stderr.splitlines()) == 1 and f"tcp://127.0.0.1:{port}" in p.stderr, p.stderr
    assert time.monotonic() - tick < 15
    assert not (tmp_path / "out").exists() or not any((tmp_path / "out").rglob("*.json"))


def test_a_bad_address_is_one_line(tmp_path):
    p = subprocess.run([CHECK, *specs(tmp_path), "--dask", "nowhere"], capture_output=True, text=True, timeout=60)
    assert p.returncode == 2 and len(p.stderr.splitlines()) == 1 and "--dask 'nowhere'" in p.stderr, p.stderr
