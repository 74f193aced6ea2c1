"""Nothing outlives a command, however it dies (designer.core.lifetime): SIGKILL,
SIGTERM, SIGHUP and SIGINT at a spread of instants, for check-design (two
workers, a deck that never finishes) and each sheet command. Within 2 s no
process of ours is left (read from /proc by an environment mark every child
inherits), the exit status is the signal's (128 + it, one line) or the run's
own when it had finished, and the output folder is entirely the old one or
entirely the new one."""

import hashlib
import json
import signal
import subprocess
import time
import uuid
from pathlib import Path

import pytest

from helpers import script, tagged_env, wait_gone

pytestmark = pytest.mark.spice

SIGNALS = (signal.SIGKILL, signal.SIGTERM, signal.SIGHUP, signal.SIGINT)
#: seconds after the command's code starts (it catches the signals from its first line: :func:`handling`)
INSTANTS = (0.0, 0.12, 0.4, 0.9)
NEVER = ("never\nV1 in 0 SIN(0 1 1k)\nR1 in out 1k\nC1 out 0 100n\n.tran 10n 100\n.meas tran vmax MAX v(out)\n"
         ".end\n")
QUICK = NEVER.replace(".tran 10n 100", ".tran 1u 1m")


def tree(folder: Path) -> dict:
    """Relative path -> digest (or link target) of everything in ``folder``."""
    out = {}
    for p in sorted(folder.rglob("*")):
        rel = str(p.relative_to(folder))
        if p.is_symlink():
            out[rel] = "-> " + str(p.readlink())
        elif p.is_file():
            out[rel] = hashlib.sha256(p.read_bytes()).hexdigest()
    return out


def stop(argv, sig, at: float, tag: str, cwd=None, timeout: float = 120):
    """Run ``argv``, send ``sig`` after ``at`` seconds; (return code, stderr)."""
    p = subprocess.Popen(argv, cwd=cwd, env=tagged_env(tag), stdout=subprocess.DEVNULL, stderr=subprocess.PIPE,
                         text=True, stdin=subprocess.DEVNULL)
    if sig != signal.SIGKILL:
        handling(p.pid)
    time.sleep(at)
    try:
        p.send_signal(sig)
    except ProcessLookupError:
        pass
    _, err = p.communicate(timeout=timeout)
    return p.returncode, err


def handling(pid: int, seconds: float = 10.0) -> None:
    """Wait until process ``pid`` catches SIGTERM (its ``SigCgt`` in /proc): the command's own code
    runs from then on; before, the interpreter is still starting (see the README)."""
    deadline = time.monotonic() + seconds
    while time.monotonic() < deadline:
        try:
            status = Path(f"/proc/{pid}/status").read_text()
        except OSError:
            return
        caught = int(next(ln for ln in status.splitlines() if ln.startswith("SigCgt:")).split()[1], 16)
        if caught & (1 << (signal.SIGTERM - 1)):
            return
        time.sleep(0.002)


def assert_ended_by(code: int, err: str, sig, prog: str, finished=(0, 1)):
    if code in finished:   # it was done before the signal came (a quiet machine designs a plant in 0.9 s)
        assert "Traceback" not in err
        return
    if sig == signal.SIGKILL:
        assert code == -signal.SIGKILL, (code, err)
        return
    words = {signal.SIGINT: "interrupted", signal.SIGTERM: "terminated (SIGTERM)", signal.SIGHUP: "hung up (SIGHUP)"}
    assert code == 128 + sig, (code, err)
    assert err.splitlines() == [f"{prog}: error: {words[sig]}"], err


@pytest.mark.parametrize("backend", ["pyspice", "ngspice-cli"])
@pytest.mark.parametrize("sig", SIGNALS, ids=lambda s: signal.Signals(s).name)
@pytest.mark.parametrize("at", INSTANTS)
def test_check_design_killed_leaves_nothing_running_and_the_old_out(tmp_path, backend, sig, at):
    specs = []
    for name in ("a", "b"):
        (tmp_path / f"{name}.cir").write_text(QUICK)
        spec = tmp_path / f"{name}.yaml"
        spec.write_text(f"name: {name}\nkind: netlist\ndeck: {name}.cir\nchecks:\n  vmax: {{max: 2}}\n")
        specs.append(spec)
    out = tmp_path / "out"
    argv = [script("check-design"), *map(str, specs), "--jobs", "2", "--simulator", backend, "--out", str(out),
            "--junit", str(out / "junit.xml")]
    first = subprocess.run(argv, capture_output=True, text=True, timeout=120)
    assert first.returncode == 0, first.stderr
    old = tree(out)
    for name in ("a", "b"):   # now the same specs never finish
        (tmp_path / f"{name}.cir").write_text(NEVER)
    tag = uuid.uuid4().hex
    code, err = stop(argv, sig, at, tag)
    assert_ended_by(code, err, sig, "check-design", finished=())
    assert wait_gone(tag) == [], "a worker or ngspice outlived check-design"
    now = {k: v for k, v in tree(out).items() if not Path(k).name.startswith(".")}
    assert now == old   # nothing published by the killed run; its staging folder is cleaned by the next


def test_a_rerun_with_fewer_corners_leaves_no_stale_corner(tmp_path):
    spec = tmp_path / "p.yaml"
    body = "name: p\nkind: plant\ntarget: {{fc: 3.5k, zeta: 0.2}}\nopamp: {amps}\nchecks:\n  overshoot_pct: {{max: 80}}\n"
    spec.write_text(body.format(amps="[LM741, TL072]"))
    out = tmp_path / "out"
    assert subprocess.run([script("check-design"), str(spec), "--out", str(out)], capture_output=True,
                          timeout=300).returncode == 0
    assert {p.name for p in (out / "p" / "reports").iterdir()} == {"LM741", "TL072"}
    spec.write_text(body.format(amps="[TL072]"))
    assert subprocess.run([script("check-design"), str(spec), "--out", str(out)], capture_output=True,
                          timeout=300).returncode == 0
    assert {p.name for p in (out / "p" / "reports").iterdir()} == {"TL072"}
    result = json.loads((out / "p" / "result.json").read_text())
    design = json.loads((out / "p" / "reports" / "TL072" / "result.json").read_text())
    # the paths recorded are where the files are, not the staging folder they were written in
    for path in [result["files"]["result_json"], design["files"]["build_sheet_md"], *design["files"]["plots"]]:
        assert Path(path).is_file() and str(out / "p") in path, path
    assert not [p for p in out.iterdir() if p.name.startswith(".")]


SHEETS = {
    "design-plant": (["--fc", "3500", "--zeta", "0.2"], ["--fc", "2000", "--zeta", "0.3"]),
    "analyze-plant": (["--r1", "1k6", "--r2", "3k9", "--c1", "3n3", "--c2", "100n"],
                      ["--r1", "2k2", "--r2", "3k9", "--c1", "3n3", "--c2", "100n"]),
    "design-pid": (["--plant-fc", "3500", "--plant-zeta", "0.2", "--tuning", "optimize", "--target-overshoot", "10"],
                   ["--plant-fc", "3500", "--plant-zeta", "0.2", "--tuning", "zn"]),
    "analyze-pid": (["--plant-fc", "3500", "--plant-zeta", "0.2", "--kp", "3.3", "--ti", "43u", "--td", "11u",
                     "--r3", "12k", "--r4", "1.777k", "--r5", "22k", "--r6", "3.3k", "--r7", "14.356k", "--r8",
                     "1.2k", "--r9", "10k", "--r10", "10k", "--r11", "10k", "--r12", "1.026k", "--r13", "26.048k",
                     "--r14", "2.528k", "--r15", "10k", "--r16", "3.279k", "--r17", "1.716k", "--r18", "9.98k",
                     "--c3", "4.7n", "--c4", "47n"], None),
}


@pytest.fixture(scope="module")
def old_bundles(tmp_path_factory) -> dict:
    """command -> a folder holding the bundle ``b`` of its older run (once per module: copied per test)."""
    out = {}
    for command, (_, old_args) in SHEETS.items():
        folder = tmp_path_factory.mktemp(f"old-{command}")
        if old_args is not None:
            done = subprocess.run([script(command), "--name", "b", "--out", str(folder), *old_args],
                                  capture_output=True, text=True, timeout=300)
            assert done.returncode == 0, done.stderr
        out[command] = folder
    return out


@pytest.mark.parametrize("command", sorted(SHEETS))
@pytest.mark.parametrize("sig", SIGNALS, ids=lambda s: signal.Signals(s).name)
@pytest.mark.parametrize("at", INSTANTS[:1] + INSTANTS[2:])
def test_a_sheet_command_killed_leaves_nothing_running_and_a_whole_bundle(tmp_path, old_bundles, command, sig, at):
    import shutil
    new_args, _ = SHEETS[command]
    out = tmp_path / "out"
    shutil.copytree(old_bundles[command], out, symlinks=True)
    base = [script(command), "--name", "b", "--out", str(out)]
    old = tree(out)
    tag = uuid.uuid4().hex
    code, err = stop(base + new_args, sig, at, tag)
    assert_ended_by(code, err, sig, command)
    assert wait_gone(tag) == [], f"a renderer, helper or ngspice outlived {command}"
    now = {k: v for k, v in tree(out).items() if not any(part.startswith(".") for part in Path(k).parts)}
    if now != old:   # then it is the whole new bundle, and the netlist is its deck
        result = json.loads((out / "reports" / "b" / "result.json").read_text())
        assert result["tool"]["argv"][-len(new_args):] == new_args
        files = result["files"]
        for path in [files["netlist"], files["build_sheet_html"], *files["plots"]]:
            assert Path(path).is_file(), path


#: this session's long runs (issues 16, 17): a model plant's loop, a Monte Carlo, a simulated capture
LONG_RUNS = {
    "design-pid": ["--plant-tf", "K=2 tau=1m theta=200u", "--tuning", "optimize", "--rules-spice"],
    "design-plant": ["--fc", "3500", "--zeta", "0.2", "--monte-carlo", "200000", "--limit", "fn_hz=3.3k:3.7k"],
    "simulate-capture": ["--plant-tf", "K=1.25 tau=124.6m", "--points", "200000", "--noise", "10m"],
}


@pytest.mark.parametrize("command", sorted(LONG_RUNS))
@pytest.mark.parametrize("sig", (signal.SIGKILL, signal.SIGTERM), ids=lambda s: signal.Signals(s).name)
def test_the_long_runs_killed_leave_nothing_running_and_nothing_half_written(tmp_path, command, sig):
    out = tmp_path / "out"
    out.mkdir()
    where = ["--out", str(out / "capture.csv")] if command == "simulate-capture" else ["--out", str(out)]
    tag = uuid.uuid4().hex
    code, err = stop([script(command), *LONG_RUNS[command], *where], sig, 0.9, tag)
    assert_ended_by(code, err, sig, command)
    assert wait_gone(tag) == [], f"a renderer, helper or ngspice outlived {command}"
    left = [p for p in out.rglob("*") if p.is_file() and not any(q.startswith(".") for q in p.relative_to(out).parts)]
    if command == "simulate-capture":
        assert left in ([], [out / "capture.csv"]) and (not left or left[0].read_text().count("\n") > 200000)
    elif left:   # a whole bundle or none
        result = json.loads(next(p for p in left if p.name == "result.json").read_text())
        assert all(Path(f).is_file() for f in [result["files"]["netlist"], *result["files"]["plots"]])


#: the filter commands' long runs (issue 27): the SPICE proof, a Monte Carlo over worker processes and SPICE
#: builds of an 8th-order cascade
FILTER_RUNS = {
    "design-filter": ["--family", "butterworth", "--order", "8", "--fc", "1k", "--monte-carlo", "100000",
                      "--spice-samples", "60", "--jobs", "2"],
    "analyze-filter": ["--target", "--order 2 --fc 1k", "--stage", "sallen-key-lowpass", "--part", "R101=10k",
                       "--part", "R102=10k", "--part", "C101=10n", "--part", "C102=22n", "--monte-carlo", "100000",
                       "--spice-samples", "60", "--jobs", "2"],
}


@pytest.mark.parametrize("command", sorted(FILTER_RUNS))
@pytest.mark.parametrize("sig", (signal.SIGKILL, signal.SIGTERM), ids=lambda s: signal.Signals(s).name)
def test_the_filter_runs_killed_leave_nothing_running_and_nothing_half_written(tmp_path, command, sig):
    out = tmp_path / "out"
    tag = uuid.uuid4().hex
    # 3 s: past the imports, into the proof, the workers and ngspice
    code, err = stop([script(command), *FILTER_RUNS[command], "--out", str(out)], sig, 3.0, tag)
    assert_ended_by(code, err, sig, command)
    assert wait_gone(tag) == [], f"a worker or ngspice outlived {command}"
    left = [p for p in out.rglob("*") if p.is_file()] if out.exists() else []
    if left:   # a whole folder or none
        result = json.loads((out / "result.json").read_text())
        assert all(Path(f).is_file() for f in result["files"].values() if isinstance(f, str))
