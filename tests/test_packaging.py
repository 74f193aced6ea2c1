"""The package as users install it: `pip wheel .`, the wheel installed into a
fresh virtual environment, and the commands run from an unrelated folder,
SPICE included (the model library ships inside the wheel); the lock of the
tested versions that `make setup` installs from; the committed reference
outputs, which must regenerate byte for byte (no wall-clock values in them)."""

import json
import os
import re
import subprocess
import sys
import sysconfig
import tomllib
import zipfile
from importlib import metadata
from pathlib import Path

import pytest
from helpers import ROOT
from packaging.requirements import Requirement
from packaging.utils import canonicalize_name

LOCK = ROOT / "requirements-lock.txt"


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


@pytest.mark.spice
def test_the_wheel_carries_the_model_library_and_the_opamp_data(installed):
    wheel, _ = installed
    names = zipfile.ZipFile(wheel).namelist()
    assert "designer/spice/circuits/opamp_behavioural.lib" in names
    assert "designer/core/data/opamps.json" in names
    # designer-web's pages and the plotting library they load from the server, with its licence (no CDN)
    for name in ("plant.html", "pid.html", "identify.html", "check.html", "common.js", "style.css",
                 "vendor/uplot/uPlot.iife.min.js", "vendor/uplot/uPlot.min.css", "vendor/uplot/LICENSE"):
        assert f"designer/web/static/{name}" in names, name


@pytest.mark.spice
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
                "simulate-capture", "make-prbs", "designer-web", "design-filter", "analyze-filter"):
        assert subprocess.run([str(venv / "bin" / cmd), "--help"], capture_output=True, cwd=tmp_path,
                              env=env).returncode == 0, cmd


# --------------------------------------------------------------------------- the lock and the metadata

def pyproject() -> dict:
    return tomllib.loads((ROOT / "pyproject.toml").read_text())


def locked() -> dict:
    """{canonical name: Requirement} of the lock's entries (``name==version ; marker``, hashes after)."""
    out = {}
    for line in LOCK.read_text().splitlines():
        if line and not line[0].isspace() and not line.startswith("#"):
            req = Requirement(line.rstrip(" \\"))
            out[canonicalize_name(req.name)] = req
    return out


def test_the_licence_is_an_spdx_expression_for_setuptools_77():
    """A table (``{text = ...}``) is deprecated and refused by setuptools from 2027-02-18."""
    meta = pyproject()
    assert meta["project"]["license"] == "GPL-3.0-or-later"
    assert any(Requirement(r).name == "setuptools" and Requirement(r).specifier.contains("77")
               and not Requirement(r).specifier.contains("76.9") for r in meta["build-system"]["requires"])


def test_the_lock_pins_every_dependency_with_hashes():
    """Every runtime and test dependency of pyproject.toml is in the lock, pinned (==) to a
    version its range allows, and every entry carries hashes (pip installs it with --require-hashes)."""
    meta = pyproject()["project"]
    lock = locked()
    wanted = [Requirement(r) for r in meta["dependencies"] + meta["optional-dependencies"]["test"]]
    for req in wanted:
        name = canonicalize_name(req.name)
        assert name in lock, f"{req.name} is not in {LOCK.name} (make lock)"
        (pin,) = lock[name].specifier
        assert pin.operator == "==" and req.specifier.contains(pin.version, prereleases=True), (req, pin)
    for extra in {e for r in wanted for e in r.extras}:          # dask[distributed] -> distributed
        assert canonicalize_name(extra) in lock, extra
    text = LOCK.read_text()
    for name, req in lock.items():
        block = text.split(f"\n{req.name}==", 1)[1].split("\n", 1)[1]
        assert block.lstrip().startswith("--hash=sha256:"), f"{name} has no hash in the lock"


def test_the_lock_is_what_is_installed():
    """The versions the tests run with are the lock's: every entry whose marker holds on this
    Python is installed at exactly its version (``make setup`` installs from the lock)."""
    wrong = []
    for name, req in locked().items():
        if req.marker is not None and not req.marker.evaluate():
            continue
        (pin,) = req.specifier
        try:
            have = metadata.version(name)
        except metadata.PackageNotFoundError:
            have = None
        if have != pin.version:
            wrong.append(f"{name} {have} (lock {pin.version})")
    assert not wrong, "installed versions differ from the lock (make setup): " + ", ".join(wrong)


def test_make_setup_installs_from_the_lock_and_python_is_supported():
    """The venv comes from the lock (and is made anew when it changes); the Pythons the
    lock is for (3.11 to 3.13: Debian 12 and 13) are the ones pyproject.toml accepts."""
    make = (ROOT / "Makefile").read_text()
    assert re.search(r"^\$\(VENV_STAMP\):.*\$\(LOCK\)", make, re.M)
    assert "pip install -q --require-hashes -r $(LOCK)" in make and "--no-deps -e ." in make
    assert "python3-venv" in make
    assert pyproject()["project"]["requires-python"] == ">=3.11"
    assert "--python-version 3.11" in make and "--universal" in make
    assert sys.version_info >= (3, 11)


# --------------------------------------------------------------------------- the committed reference outputs

#: keys that hold a run's wall-clock time or a date
_CLOCK_KEY = re.compile(r"timing|elapsed|wall_?clock|duration|runtime|(^|_)(date|created|started|finished)(_|$)",
                        re.I)
#: a date and time of day, as a run's stamp would be written
_STAMP = re.compile(r"\b20\d\d-[01]\d-[0-3]\d[T ][0-2]\d:[0-5]\d")


def _clock_keys(node, path="") -> list:
    if isinstance(node, dict):
        return [f"{path}/{k}" for k in node if _CLOCK_KEY.search(k)] + \
            [x for k, v in node.items() for x in _clock_keys(v, f"{path}/{k}")]
    if isinstance(node, list):
        return [x for i, v in enumerate(node) for x in _clock_keys(v, f"{path}[{i}]")]
    return []


def test_committed_reference_outputs_hold_no_wall_clock_values():
    """What ``make demo`` writes and git keeps must regenerate byte for byte on the same
    versions: no timings or dates in its JSON, no time stamps in its text, no creation
    time in its PNGs' metadata."""
    files = subprocess.run(["git", "ls-files", "captures", "reports", "netlists"], cwd=ROOT, capture_output=True,
                           text=True, check=True).stdout.split()
    if not files:
        pytest.skip("not a git checkout")
    found = []
    for name in files:
        data = (ROOT / name).read_bytes()
        if name.endswith(".json"):
            found += [f"{name}: {k}" for k in _clock_keys(json.loads(data))]
        if name.endswith(".png"):
            found += [f"{name}: PNG {m.group(1).decode()}" for m in
                      re.finditer(rb"[it]EXt(Creation Time|date:\w+|Date)\x00", data)]
        else:
            found += [f"{name}: {m.group(0)}" for m in _STAMP.finditer(data.decode("utf-8", "replace"))]
    assert not found, found
