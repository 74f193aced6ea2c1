"""design-pid for a plant that is any registered circuit (issue 26), from the
outside: --plant-topology with --plant-part, a design-filter result.json as
--plant-json (its cascade), the JSON's ``topology``, and the one-line refusals
(exit status 2, nothing written)."""

import json
import os
import subprocess

import pytest
from helpers import script

DESIGN_PID = script("design-pid")
DESIGN_FILTER = script("design-filter")


def run(exe, *args, cwd=None):
    env = dict(os.environ, MPLBACKEND="Agg")
    return subprocess.run([exe, *args], capture_output=True, text=True, cwd=cwd, env=env, timeout=300)


def one_line_refusal(p, what):
    assert p.returncode == 2, (p.returncode, p.stderr)
    lines = p.stderr.splitlines()
    assert len(lines) == 1 and "Traceback" not in p.stderr, p.stderr
    assert what in lines[0], lines[0]
    return lines[0]


def test_a_section_plant_from_the_command_line():
    p = run(DESIGN_PID, "--plant-topology", "mfb-lowpass", "--plant-part", "R1=10k", "R2=20k", "R3=6k8",
            "--plant-part", "C1=10n", "C2=100n", "--no-sim", "--json", "--no-files")
    assert p.returncode == 0, p.stderr
    plant = json.loads(p.stdout)["plant"]
    assert plant["topology"] == "mfb-lowpass" and plant["reversed_action"] is True
    assert plant["circuit"][0]["parts"]["RP3"] == 6800.0
    assert plant["circuit_model"]["gain"] == -plant["model"]["gain"]


def test_a_design_filter_result_is_a_cascade_plant(tmp_path):
    f = run(DESIGN_FILTER, "--family", "butterworth", "--order", "3", "--fc", "1k", "--no-sim", "--json")
    assert f.returncode == 0, f.stderr
    path = tmp_path / "filter.json"
    path.write_text(f.stdout)
    stages = json.loads(f.stdout)["stages"]
    p = run(DESIGN_PID, "--plant-json", str(path), "--no-sim", "--json", "--no-files")
    assert p.returncode == 0, p.stderr
    plant = json.loads(p.stdout)["plant"]
    assert plant["topology"] == "cascade"
    assert [s["topology"] for s in plant["circuit"]] == [s["topology"] for s in stages]


@pytest.mark.parametrize("args,what", [
    (["--plant-topology", "sallen-key-lowpass", "--plant-part", "R1=10k", "R2=10k", "C1=10n", "C2=47n", "R5=1k"],
     "--plant-part: sallen-key-lowpass has no part R5; its parts are R1, R2, C1, C2"),
    (["--plant-topology", "mfb-lowpas", "--plant-part", "R1=1k"], "--plant-topology: unknown topology 'mfb-lowpas'"),
    (["--plant-topology", "rc-lowpass"], "--plant-topology and --plant-part go together"),
    (["--plant-topology", "rc-highpass", "--plant-part", "R1=10k", "C1=10n"], "passes no DC"),
    (["--plant-topology", "rc-lowpass", "--plant-part", "R1=10k", "C1=1e9"], "--plant-part C1 must be"),
    (["--plant-fc", "3500", "--plant-zeta", "0.2", "--plant-topology", "rc-lowpass", "--plant-part", "R1=10k",
      "C1=10n"], "give the plant one way"),
])
def test_bad_circuit_plants_are_refused_in_one_line(tmp_path, args, what):
    one_line_refusal(run(DESIGN_PID, *args, "--no-sim", "--out", str(tmp_path)), what)
    assert not list(tmp_path.iterdir())
