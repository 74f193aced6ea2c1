"""The package as users install it: `pip wheel .`, the wheel installed into a
fresh virtual environment, and the commands run from an unrelated folder,
SPICE included (the model library ships inside the wheel)."""

import json
import os
import subprocess
import sys
import sysconfig
import zipfile
from pathlib import Path

import pytest
from helpers import ROOT

pytestmark = pytest.mark.spice


@pytest.fixture(scope="module")
def installed(tmp_path_factory):
    """A fresh venv holding only the wheel; the dependencies come from this
    environment through a plain path entry (its .pth files, among them the
    editable install of the source tree, are not processed)."""
    tmp = tmp_path_factory.mktemp("wheel")
    subprocess.run([sys.executable, "-m", "pip", "wheel", "-q", "--no-deps",
                    "-w", str(tmp / "dist"), str(ROOT)], check=True, capture_output=True, timeout=600)
    wheel = next((tmp / "dist").glob("designer-*.whl"))
    venv = tmp / "venv"
    subprocess.run([sys.executable, "-m", "venv", "--without-pip", str(venv)], check=True, timeout=120)
    py = venv / "bin" / "python"
    site = subprocess.run([str(py), "-c", "import sysconfig; print(sysconfig.get_paths()['purelib'])"],
                          check=True, capture_output=True, text=True).stdout.strip()
    Path(site, "deps.pth").write_text(sysconfig.get_paths()["purelib"] + "\n")
    subprocess.run([sys.executable, "-m", "pip", "--python", str(py), "install", "-q", "--no-deps", str(wheel)],
                   check=True, capture_output=True, timeout=600)
    return wheel, venv


def test_the_wheel_carries_the_model_library_and_the_opamp_data(installed):
    wheel, _ = installed
    names = zipfile.ZipFile(wheel).namelist()
    assert "designer/spice/circuits/opamp_behavioural.lib" in names
    assert "designer/core/data/opamps.json" in names
    # designer-web's pages and the plotting library they load from the server, with its licence (no CDN)
    for name in ("plant.html", "pid.html", "identify.html", "check.html", "common.js", "style.css",
                 "vendor/uplot/uPlot.iife.min.js", "vendor/uplot/uPlot.min.css", "vendor/uplot/LICENSE"):
        assert f"designer/web/static/{name}" in names, name


def test_installed_commands_work_from_any_folder(installed, tmp_path):
    _, venv = installed
    env = {k: v for k, v in os.environ.items() if k not in ("PYTHONPATH",)}
    where = subprocess.run([str(venv / "bin" / "python"), "-c", "import designer; print(designer.__file__)"],
                           capture_output=True, text=True, cwd=tmp_path, env=env, check=True).stdout
    assert str(venv) in where, where   # the wheel's copy, not the source tree
    out = subprocess.run([str(venv / "bin" / "design-plant"), "--fc", "3500", "--zeta", "0.2", "--json",
                          "--out", str(tmp_path)], capture_output=True, text=True, cwd=tmp_path, env=env,
                         timeout=300)
    assert out.returncode == 0, out.stderr
    d = json.loads(out.stdout)
    assert d["comparison"]["pass"] is True and d["spice"]["overshoot_pct"] > 50
    assert "OPAMP_BEH" in (tmp_path / "netlists" / "plant_fc3500_z0.2.cir").read_text()   # the model inlined
    for cmd in ("analyze-plant", "design-pid", "analyze-pid", "check-design", "identify", "identify-freq",
                "simulate-capture", "make-prbs", "designer-web"):
        assert subprocess.run([str(venv / "bin" / cmd), "--help"], capture_output=True, cwd=tmp_path,
                              env=env).returncode == 0, cmd
