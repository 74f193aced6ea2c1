"""Where the Monte Carlo's builds run, from the outside (designer.tolerance.runner): the same
monte_carlo section and CSV with --jobs 1, --jobs 2 and --dask local; a scheduler that does
not answer is exit 3 within seconds; Ctrl-C and SIGTERM stop a LocalCluster and leave no
process and no file; the progress bar only on a terminal, never with --json."""

import contextlib
import json
import os
import pty
import signal
import socket
import subprocess
import time
import uuid
from pathlib import Path

import pytest
from hypothesis import HealthCheck, given, settings
from hypothesis import strategies as st
from helpers import processes_tagged, script, tagged_env, wait_gone

DESIGN_PLANT = script("design-plant")
DESIGN_PID = script("design-pid")
SEED = ["--fc", "3500", "--zeta", "0.2"]
PID = ["--plant-fc", "3500", "--plant-zeta", "0.2", "--no-sim"]
MC = ["--monte-carlo", "3000", "--seed", "4", "--limit", "fn_hz=3.3k:3.7k", "--limit", "overshoot_pct=0:55",
      "--no-sim"]


def builds(n: str) -> list:
    """:data:`MC` with ``n`` builds (an option is given once)."""
    return ["--monte-carlo", n, *MC[2:]]


def run(exe, *args, timeout=300, **kw):
    env = dict(os.environ, MPLBACKEND="Agg")
    return subprocess.run([exe, *args], capture_output=True, text=True, env=env, timeout=timeout, **kw)


def bundle(out):
    folder = out / "reports" / "plant_fc3500_z0.2"
    return json.loads((folder / "result.json").read_text())["monte_carlo"], (folder / "monte-carlo.csv").read_text()


def test_the_same_section_and_csv_whatever_the_workers(tmp_path):
    runs = {"jobs1": ["--jobs", "1"], "jobs2": ["--jobs", "2"], "dask": ["--dask", "local"]}
    got = {}
    for name, where in runs.items():
        p = run(DESIGN_PLANT, *SEED, *MC, *where, "--out", str(tmp_path / name))
        assert p.returncode == 0 and p.stderr == "", p.stderr   # no bar: stderr is not a terminal
        got[name] = bundle(tmp_path / name)
    ref = got["jobs1"]
    assert ref[0]["settings"]["samples"] == 3000 and ref[1].count("\n") == 3001
    assert got["jobs2"] == ref and got["dask"] == ref


def scheduler_address(path, wait_s: float = 60.0) -> str:
    """The address in a scheduler file, once the scheduler has written it whole (it creates the file
    before it writes it: an empty or cut file is read again)."""
    deadline = time.monotonic() + wait_s
    while True:
        try:
            return json.loads(path.read_text())["address"]
        except (OSError, ValueError, KeyError):
            if time.monotonic() > deadline:
                raise
            time.sleep(0.1)


def test_a_running_scheduler_and_its_worker_give_the_same_section(tmp_path):
    """`dask scheduler` and `dask worker` started as the README says (on this machine), then --dask ADDRESS."""
    dask = os.path.join(os.path.dirname(DESIGN_PLANT), "dask")
    started = []
    try:
        started.append(subprocess.Popen([dask, "scheduler", "--port", "0", "--no-dashboard", "--scheduler-file",
                                         str(tmp_path / "s.json")], stdout=subprocess.DEVNULL,
                                        stderr=subprocess.DEVNULL))
        address = scheduler_address(tmp_path / "s.json")
        started.append(subprocess.Popen([dask, "worker", address, "--nworkers", "1", "--nthreads", "1",
                                         "--no-dashboard"], stdout=subprocess.DEVNULL, stderr=subprocess.DEVNULL))
        args = [*SEED, *MC, "--no-files", "--json"]
        there, here = run(DESIGN_PLANT, *args, "--dask", address), run(DESIGN_PLANT, *args)
        assert there.returncode == 0 and there.stderr == "", there.stderr
        assert json.loads(there.stdout)["monte_carlo"] == json.loads(here.stdout)["monte_carlo"]
    finally:
        for p in reversed(started):
            p.terminate()
            try:
                p.wait(timeout=20)
            except subprocess.TimeoutExpired:
                p.kill()
                p.wait()


@pytest.mark.spice
@pytest.mark.parametrize("simulator", ["ngspice-cli", "pyspice"])
def test_the_spice_engine_gives_the_same_section_whatever_the_workers(simulator):
    args = [*SEED, *builds("120"), "--engine", "spice", "--simulator", simulator, "--no-files", "--json"]
    got = [run(DESIGN_PLANT, *args, *where) for where in ([], ["--jobs", "2"], ["--dask", "local"])]
    assert all(p.returncode == 0 and p.stderr == "" for p in got), [p.stderr for p in got]
    sections = [json.loads(p.stdout)["monte_carlo"] for p in got]
    assert sections[0]["settings"]["engine"] == "spice" and sections[0]["settings"]["samples"] == 120
    assert sections[1] == sections[0] and sections[2] == sections[0]


def test_a_local_cluster_beside_another_prints_nothing():
    """Dask's scheduler serves HTTP on 8787 by default and warns on stderr when another cluster holds it."""
    with socket.socket() as other:
        try:
            other.bind(("0.0.0.0", 8787))
            other.listen()
        except OSError:   # held already: the same case
            pass
        p = run(DESIGN_PLANT, *SEED, "--monte-carlo", "300", "--no-sim", "--no-files", "--dask", "local")
    assert p.returncode == 0 and p.stderr == "", p.stderr


def test_the_loop_on_two_workers_is_the_same():
    a = run(DESIGN_PID, *PID, "--monte-carlo", "40", "--seed", "2", "--no-files", "--json")
    b = run(DESIGN_PID, *PID, "--monte-carlo", "40", "--seed", "2", "--no-files", "--json", "--jobs", "2")
    assert a.returncode == b.returncode == 0, a.stderr + b.stderr
    assert json.loads(a.stdout)["monte_carlo"] == json.loads(b.stdout)["monte_carlo"]


def free_port() -> int:
    with socket.socket() as s:
        s.bind(("127.0.0.1", 0))
        return s.getsockname()[1]


def test_a_scheduler_that_does_not_answer_is_exit_3_within_seconds(tmp_path):
    address = f"tcp://127.0.0.1:{free_port()}"
    tick = time.monotonic()
    p = run(DESIGN_PLANT, *SEED, *MC, "--dask", address, "--out", str(tmp_path), timeout=60)
    took = time.monotonic() - tick
    assert p.returncode == 3 and len(p.stderr.splitlines()) == 1 and address in p.stderr, p.stderr
    assert took < 15 and not any(tmp_path.iterdir())


@pytest.mark.parametrize("args, what", [
    (["--monte-carlo", "100", "--jobs", "0"], "--jobs '0'"),
    (["--monte-carlo", "100", "--jobs", "65"], "1 to 64"),
    (["--monte-carlo", "100", "--jobs", "two"], "whole number"),
    (["--dask", "local"], "--dask goes with --monte-carlo"),
    (["--jobs", "2"], "--jobs goes with --monte-carlo"),
    (["--monte-carlo", "100", "--dask", "sched"], "scheduler's address"),
    (["--monte-carlo", "100", "--target-ci", "1%"], "needs --limit"),
    (["--monte-carlo", "100", "--limit", "fn_hz=3k:4k", "--target-ci", "0"], "above 0"),
    (["--monte-carlo", "100", "--limit", "fn_hz=3k:4k", "--target-ci", "0%"], "above 0"),
    (["--monte-carlo", "100", "--limit", "fn_hz=3k:4k", "--target-ci", "51%"], "at most 50 %"),
    (["--monte-carlo", "100", "--limit", "fn_hz=3k:4k", "--target-ci", "lots"], "--target-ci 'lots'"),
    (["--monte-carlo", "100", "--limit", "fn_hz=3k:4k", "--target-ci", "1%", "--sampler", "lhs"], "random or sobol"),
])
def test_bad_scale_settings_one_line_nothing_written(tmp_path, args, what):
    p = run(DESIGN_PLANT, *SEED, *args, "--no-sim", "--out", str(tmp_path))
    assert p.returncode == 2 and len(p.stderr.splitlines()) == 1 and what in p.stderr, p.stderr
    assert not any(tmp_path.iterdir())


def test_target_ci_from_the_command_line():
    p = run(DESIGN_PLANT, *SEED, *builds("100000"), "--target-ci", "2%", "--no-files", "--json")
    assert p.returncode == 0, p.stderr
    d = json.loads(p.stdout)["monte_carlo"]
    t = d["settings"]["target_ci"]
    assert t["reached"] and t["half_width_pct"] == 2 and t["max_samples"] == 100000
    assert d["settings"]["samples"] == t["rounds"][-1] < 100000
    lo, hi = d["yield"]["ci95"]
    assert (hi - lo) / 2 < 0.02


def stop_when(argv, sig, ready, out, within: float = 60) -> None:
    """Start ``argv`` (tagged), send it ``sig`` once ``ready(tagged pids)``; it ends (within
    ``within`` seconds) with its one line and 128 + sig, leaves no process and no result.json
    under ``out``."""
    tag = uuid.uuid4().hex
    p = subprocess.Popen(argv, env=tagged_env(tag, MPLBACKEND="Agg"), stdout=subprocess.DEVNULL,
                         stderr=subprocess.PIPE, text=True, stdin=subprocess.DEVNULL)
    deadline = time.monotonic() + 60
    while not ready(processes_tagged(tag)) and time.monotonic() < deadline:
        time.sleep(0.02)
    p.send_signal(sig)
    _, err = p.communicate(timeout=within)
    assert p.returncode == 128 + sig, err
    words = "terminated (SIGTERM)" if sig == signal.SIGTERM else "interrupted"
    prog = os.path.basename(argv[0])
    assert err.splitlines() == [f"{prog}: error: {words}"], err
    assert wait_gone(tag, 5.0) == [], f"a process outlived {prog}"
    assert not out.exists() or not any(out.rglob("*.json"))


def _after(seconds: float, ready):
    """``ready``, then ``seconds`` more."""
    since = []

    def check(pids):
        if not since and ready(pids):
            since.append(time.monotonic())
        return bool(since) and time.monotonic() - since[0] >= seconds
    return check


@pytest.mark.parametrize("where, when", [("--dask local", "starting"), ("--dask local", "working"),
                                         ("--jobs 2", "working")])
@pytest.mark.parametrize("sig", [signal.SIGTERM, signal.SIGINT], ids=lambda s: signal.Signals(s).name)
def test_a_stopped_run_leaves_no_process_and_no_file(tmp_path, sig, where, when):
    argv = [DESIGN_PID, *PID, "--monte-carlo", "3000", *where.split(), "--out", str(tmp_path / "out")]
    # starting: as the first worker process appears; working: the command and two workers, a second later
    stop_when(argv, sig, _after(0.0 if when == "starting" else 1.0,
                                lambda pids: len(pids) >= (2 if when == "starting" else 3)), tmp_path / "out")


def _ngspice_among(pids) -> bool:
    """An ``ngspice`` program among ``pids`` (the command's own arguments name ngspice-cli)."""
    for pid in pids:
        try:
            with open(f"/proc/{pid}/cmdline", "rb") as f:
                if os.path.basename(f.read().split(b"\0")[0]) == b"ngspice":
                    return True
        except OSError:   # gone meanwhile
            pass
    return False


@pytest.mark.spice
@pytest.mark.parametrize("sig", [signal.SIGTERM, signal.SIGINT], ids=lambda s: signal.Signals(s).name)
def test_a_stopped_spice_run_on_thread_workers_leaves_no_process_and_no_file(tmp_path, sig):
    """--engine spice --simulator ngspice-cli --dask local: the LocalCluster's workers are threads
    (each chunk is an ngspice -b process); stopped while ngspice runs, the command still ends at
    once with one line and its status, not when the running chunks would (1250 builds each here,
    half a minute), and no ngspice outlives it."""
    argv = [DESIGN_PLANT, *SEED, "--monte-carlo", "20000", "--engine", "spice", "--simulator", "ngspice-cli",
            "--no-sim", "--dask", "local", "--out", str(tmp_path / "out")]
    stop_when(argv, sig, _after(0.5, _ngspice_among), tmp_path / "out", within=15)


def test_nothing_of_a_local_cluster_outlives_the_command():
    """The fork server the workers came from is gone when the command has exited, not a moment
    later: it held the command's stdout, so a pipe's reader (`| jq`) waited for it too."""
    import threading
    tag = uuid.uuid4().hex
    p = subprocess.Popen([DESIGN_PID, *PID, "--monte-carlo", "100", "--dask", "local", "--no-files", "--json"],
                         env=tagged_env(tag, MPLBACKEND="Agg"), stdout=subprocess.PIPE,
                         stderr=subprocess.DEVNULL, stdin=subprocess.DEVNULL)
    pipe = f"pipe:[{os.fstat(p.stdout.fileno()).st_ino}]"
    reader = threading.Thread(target=p.stdout.read)   # drained, so that the command never waits on it
    reader.start()
    assert p.wait(timeout=300) == 0
    # the moment it has exited nothing of the cluster holds its stdout; multiprocessing's resource tracker
    # (Python's, started by the first semaphore) sees the command gone through its own pipe and ends a few
    # milliseconds later: it is waited for below, not let live
    holders = []
    for pid in processes_tagged(tag):
        with contextlib.suppress(OSError):
            if b"resource_tracker" in Path(f"/proc/{pid}/cmdline").read_bytes():
                continue
            holders += [pid for fd in Path(f"/proc/{pid}/fd").iterdir() if os.readlink(fd) == pipe]
    assert holders == []
    reader.join(10)
    p.stdout.close()
    assert not reader.is_alive() and wait_gone(tag, 5.0) == []


def test_a_killed_cluster_run_leaves_no_process(tmp_path):
    tag = uuid.uuid4().hex
    argv = [DESIGN_PID, *PID, "--monte-carlo", "3000", "--dask", "local", "--no-files"]
    p = subprocess.Popen(argv, env=tagged_env(tag, MPLBACKEND="Agg"), stdout=subprocess.DEVNULL,
                         stderr=subprocess.DEVNULL, stdin=subprocess.DEVNULL)
    deadline = time.monotonic() + 60
    while len(processes_tagged(tag)) < 3 and time.monotonic() < deadline:
        time.sleep(0.05)
    time.sleep(1.0)
    p.kill()
    p.wait(timeout=30)
    assert wait_gone(tag, 5.0) == [], "a Dask worker outlived design-pid"


def on_a_terminal(*args):
    """Run with stderr on a pseudo-terminal; (return code, what the terminal showed)."""
    master, slave = pty.openpty()
    p = subprocess.Popen(args, stdout=subprocess.DEVNULL, stderr=slave, stdin=subprocess.DEVNULL,
                         env=dict(os.environ, MPLBACKEND="Agg"))
    os.close(slave)
    shown = b""
    while True:
        try:
            chunk = os.read(master, 4096)
        except OSError:   # the other end closed
            break
        if not chunk:
            break
        shown += chunk
    os.close(master)
    return p.wait(timeout=120), shown.decode(errors="replace")


def test_a_progress_bar_on_a_terminal_for_a_long_run_only():
    # sizes far from the one-second threshold on any machine, loaded or not
    code, shown = on_a_terminal(DESIGN_PID, *PID, "--monte-carlo", "2000", "--no-files")
    assert code == 0 and "Monte Carlo" in shown and "2000/2000" in shown and "build" in shown, shown
    code, shown = on_a_terminal(DESIGN_PID, *PID, "--monte-carlo", "2000", "--no-files", "--json")
    assert code == 0 and shown == ""
    code, shown = on_a_terminal(DESIGN_PLANT, *SEED, "--monte-carlo", "100", "--no-sim", "--no-files")
    assert code == 0 and shown == ""     # done in milliseconds: no bar


@settings(max_examples=60, deadline=None, suppress_health_check=[HealthCheck.function_scoped_fixture])
@given(jobs=st.one_of(st.none(), st.text(max_size=6), st.integers(-3, 70).map(str)),
       target=st.one_of(st.none(), st.text(max_size=8), st.floats(allow_nan=True).map(lambda x: f"{x}%")),
       limit=st.booleans())
def test_whatever_is_typed_for_jobs_and_target_ci_ends_in_0_or_one_line_2(tmp_path, capsys, jobs, target, limit):
    """In-process: every --jobs and --target-ci text gives a run or one line and status 2, no file."""
    from designer.cli.plant import design_plant_main
    out = tmp_path / uuid.uuid4().hex    # tmp_path is shared by the examples
    argv = [*SEED, "--monte-carlo", "40", "--no-sim", "--out", str(out)]
    argv += ["--limit", "fn_hz=3k:4k"] if limit else []
    argv += [] if jobs is None else [f"--jobs={jobs}"]
    argv += [] if target is None else [f"--target-ci={target}"]
    status = design_plant_main(argv)
    err = capsys.readouterr().err
    assert status in (0, 2), (argv, err)
    if status == 2:
        assert len(err.splitlines()) == 1 and "Traceback" not in err, (argv, err)
        assert not out.exists() or not any(out.rglob("*.json"))
