"""The Dask side of the runner (designer.tolerance.cluster): a LocalCluster's lost chunk run
once more (then exit 3), the cluster started ahead and taken or closed, thread workers for
ngspice-cli chunks, no worker left behind, the --dask address input, and an address where no
scheduler answers (nothing, a web server, something else: one line within 3 s, exit 3), and
a SIGKILLed --dask local run quiet."""

import contextlib
import http.server
import os
import socket
import subprocess
import threading
import time
import uuid

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

from designer.tolerance.spice_mc import plant_context
from designer.core import opamps
from designer.core.errors import DesignError, SimulatorError
from designer.tolerance import cluster, plant
from designer.tolerance.cluster import parse_dask
from designer.tolerance.runner import Draw, Runner, Scale
from helpers import processes_tagged, script, tagged_env, wait_gone
from mc_engines import always_dies, dies_once

AMP = opamps.get("LM741")
NOMINAL = {"R1": 1.6e3, "R2": 3.9e3, "C1": 3.3e-9, "C2": 100e-9}
TOL = {"R1": 0.05, "R2": 0.05, "C1": 0.10, "C2": 0.10}


def assert_same(a: dict, b: dict):
    assert list(a) == list(b)
    for k in a:
        np.testing.assert_array_equal(a[k], b[k], err_msg=k)


def test_on_a_local_cluster_a_dying_worker_s_chunk_runs_once_more_then_exit_3(tmp_path):
    """One LocalCluster (kept short: 400 builds): a chunk whose worker is killed once gives
    the same figures; a chunk that kills every worker it meets is a simulator error."""
    draw = Draw(NOMINAL, TOL, 400, 1)
    _, ref, _ = Runner().run(plant.evaluate, AMP, draw)
    with Runner(Scale(dask="local", chunk=100)) as run:
        _, f, _ = run.run(dies_once, str(tmp_path / "died"), draw)
        assert (tmp_path / "died").exists()
        assert_same(f, ref)
        with pytest.raises(SimulatorError, match=r"samples 0\.\.99 was lost twice \(its Dask worker died"):
            run.run(always_dies, None, Draw(NOMINAL, TOL, 100, 1))


def _children() -> set:
    """This process's children, but multiprocessing's resource tracker and fork server (they live
    as long as we do; the workers forked from the server, its children, are counted)."""
    import os

    import psutil
    out = set()
    for p in psutil.Process().children(recursive=True):
        try:
            cmd = " ".join(p.cmdline())
            if not ("resource_tracker" in cmd or ("forkserver" in cmd and p.ppid() == os.getpid())):
                out.add(p.pid)
        except psutil.Error:   # gone meanwhile
            pass
    return out


def _gone(pids: set, seconds: float = 10.0) -> set:
    """Those of ``pids`` still running after ``seconds`` (polled)."""
    import time

    import psutil
    deadline = time.monotonic() + seconds
    while True:
        left = {p for p in pids if psutil.pid_exists(p) and psutil.Process(p).status() != psutil.STATUS_ZOMBIE}
        if not left or time.monotonic() >= deadline:
            return left
        time.sleep(0.05)


def test_a_cluster_started_ahead_is_the_one_the_runner_takes():
    """--dask local: the LocalCluster a command starts ahead (while it designs) is the one the
    Monte Carlo runs on, with the same figures; the block's end leaves no worker."""
    draw = Draw(NOMINAL, TOL, 400, 1)
    _, ref, _ = Runner().run(plant.evaluate, AMP, draw)
    scale = Scale(dask="local", chunk=100)
    before = _children()
    with cluster.cluster_ahead(scale):
        start = cluster._ahead
        assert isinstance(start, cluster.ClusterStart) and start.workers == 2
        with Runner(scale) as run:
            assert cluster._ahead is None and start._box == {}     # handed over, not started again
            _, f, _ = run.run(plant.evaluate, AMP, draw)
    assert_same(f, ref)
    assert _gone(_children() - before) == set()


@pytest.mark.spice
def test_spice_chunks_of_ngspice_processes_run_on_thread_workers():
    """The SPICE engine with ngspice-cli (each chunk an ``ngspice -b`` process): the LocalCluster's
    workers are threads of this process (no worker process starts), with the same figures as here;
    every other work gets worker processes."""
    import distributed

    from designer.plant.design import design_plant
    from designer.plant.spec import PlantSpec
    from designer.tolerance.montecarlo import apply_engine, plant_parts
    from designer.tolerance.spice_mc import spice_evaluate
    res = design_plant(PlantSpec(fc_hz=3500, zeta=0.2), simulate=False)
    nominal = plant_parts(res.built)
    ctx = spice_evaluate(plant_context(res, "ngspice-cli"), res.opamp)
    draw = Draw(nominal, {k: 0.05 for k in nominal}, 48, 2)
    _, ref, _ = Runner().run(apply_engine, ctx, draw)
    before = _children()
    with Runner(Scale(dask="local", chunk=8, work="ngspice-cli")) as run:
        workers = run._pool.cluster.workers.values()
        assert len(workers) == 2 and all(isinstance(w, distributed.Worker) for w in workers)
        _, f, _ = run.run(apply_engine, ctx, draw)
        assert _children() - before == set()     # ngspice ended with each chunk; no worker process
    assert_same(f, ref)
    assert [w for w, (threads, _) in cluster.WORKERS.items() if threads] == ["ngspice-cli"]


def test_the_modules_worker_processes_start_with_exist():
    """The fork server skips a module it cannot import: a misspelt name would only slow the workers."""
    import importlib
    for work, (_, modules) in cluster.WORKERS.items():
        for name in modules:
            assert importlib.import_module(name), (work, name)


@pytest.mark.parametrize("how", ["unused", "interrupted"])
def test_a_cluster_started_ahead_and_not_taken_is_closed(how):
    """A cluster no runner took (the design failed, or Ctrl-C came while it started) is waited
    for and closed when the block ends: no worker is left."""
    before = _children()
    with pytest.raises(KeyboardInterrupt) if how == "interrupted" else contextlib.nullcontext():
        with cluster.cluster_ahead(Scale(dask="local")):
            start = cluster._ahead
            if how == "interrupted":
                raise KeyboardInterrupt
            start._thread.join(60)      # started, then left alone
            assert "cluster" in start._box
    assert cluster._ahead is None and not start._thread.is_alive() and start._box == {}
    assert _gone(_children() - before) == set()


def test_without_dask_local_nothing_starts_ahead():
    for scale in (None, Scale(), Scale(jobs=2), Scale(dask="tcp://127.0.0.1:1")):
        with cluster.cluster_ahead(scale):
            assert cluster._ahead is None


@settings(max_examples=200, deadline=None)
@given(st.text(max_size=30))
def test_dask_address_input_is_an_address_or_one_line(text):
    try:
        a = parse_dask(text)
    except DesignError as exc:
        assert "\n" not in str(exc) and "--dask" in str(exc)
    else:
        assert a == "local" or "://" in a


def test_dask_addresses():
    assert parse_dask("10.0.0.5:8786") == "tcp://10.0.0.5:8786"
    assert parse_dask(" TCP://sched.lab:8786 ") == "tcp://sched.lab:8786"
    assert parse_dask("LOCAL") == "local"
    for bad in ("sched", "host:0", "host:70000", "http://host:8786", ":8786"):
        with pytest.raises(DesignError):
            parse_dask(bad)
    for other in ("tls://sched.lab:8786", "ws://h:1", "ucx://h:2", "gopher://h:3"):   # issue 25: tls was a TypeError
        with pytest.raises(DesignError, match="only a tcp:// scheduler address"):
            parse_dask(other)


# --------------------------------------------------------------------------- addresses where no scheduler is
# (issue 25, item 7: an HTTP server hung the command for minutes, other peers gave "MemoryError"); every peer
# is a socket of this test on 127.0.0.1: nothing leaves the machine

@contextlib.contextmanager
def peer(kind: str):
    """``tcp://127.0.0.1:PORT`` where ``kind`` answers: "http" (a web server), "silent" (accepts, says
    nothing), "talker" (a banner of text), "closer" (hangs up at once), "closed" (nothing listens),
    "full" (a listener whose queue is full: connecting times out, as at an unroutable address)."""
    if kind == "http":
        srv = http.server.ThreadingHTTPServer(("127.0.0.1", 0), http.server.SimpleHTTPRequestHandler)
        thread = threading.Thread(target=srv.serve_forever, daemon=True)
        thread.start()
        try:
            yield f"tcp://127.0.0.1:{srv.server_address[1]}"
        finally:
            srv.shutdown()
            srv.server_close()
        return
    lsock = socket.socket()
    lsock.bind(("127.0.0.1", 0))
    port = lsock.getsockname()[1]
    held = []
    if kind == "closed":
        lsock.close()
        yield f"tcp://127.0.0.1:{port}"
        return
    lsock.listen(0 if kind == "full" else 8)
    stop = threading.Event()

    def serve():
        lsock.settimeout(0.1)
        while not stop.is_set():
            try:
                conn, _ = lsock.accept()
            except OSError:
                continue
            if kind == "talker":
                conn.sendall(b"SSH-2.0-OpenSSH_9.2p1 Debian-2\r\n")
            if kind == "closer":
                conn.close()
            else:
                held.append(conn)
    if kind == "full":
        for _ in range(3):   # the queue of a listener that never accepts: the next SYN goes unanswered
            c = socket.socket()
            c.setblocking(False)
            with contextlib.suppress(BlockingIOError):
                c.connect(("127.0.0.1", port))
            held.append(c)
        time.sleep(0.2)
        thread = None
    else:
        thread = threading.Thread(target=serve, daemon=True)
        thread.start()
    try:
        yield f"tcp://127.0.0.1:{port}"
    finally:
        stop.set()
        if thread is not None:
            thread.join()
        for c in held:
            c.close()
        lsock.close()


#: what each peer is told as
SAID = {
    "http": "something else answered: it accepted the connection but sent no handshake within 3 s",
    "silent": "something else answered: it accepted the connection but sent no handshake within 3 s",
    "talker": "something else answered: what it sent is not a scheduler's handshake",
    "closer": "something else answered: it closed the connection without a scheduler's handshake",
    "closed": "nothing listens there (connection refused)",
}


@pytest.mark.parametrize("kind", list(SAID))
def test_no_scheduler_is_told_within_the_connect_timeout(kind):
    with peer(kind) as address:
        tick = time.monotonic()
        why = cluster.probe(address)
        took = time.monotonic() - tick
    assert why == SAID[kind] and took < cluster.CONNECT_TIMEOUT + 0.5


def test_an_address_that_does_not_answer_a_connection_is_told_at_the_timeout():
    """As at an unroutable address (10.255.255.1 gave "MemoryError"), without sending anything off this
    machine: a loopback listener whose queue is full leaves the SYN unanswered."""
    with peer("full") as address:
        tick = time.monotonic()
        why = cluster.probe(address, timeout=0.5)
        took = time.monotonic() - tick
    assert why == "nothing answered within 0.5 s" and 0.4 < took < 1.5
    assert cluster.probe("tcp://no-such-host.invalid:8786") == "the host 'no-such-host.invalid' is unknown"


def test_a_real_scheduler_passes_the_probe():
    distributed = pytest.importorskip("distributed")

    async def main():
        async with distributed.Scheduler(host="127.0.0.1", port=0, dashboard_address=None) as s:
            return await asyncio.get_running_loop().run_in_executor(None, cluster.probe, s.address)
    import asyncio
    import logging
    logging.getLogger("distributed").setLevel(logging.CRITICAL)
    assert asyncio.run(main()) is None


CHECK_SPEC = "name: p\nkind: plant\ntarget: {fc: 3.5k, zeta: 0.2}\nopamp: [LM741, TL072]\nchecks:\n  overshoot_pct: {max: 80}\n"


@pytest.mark.parametrize("kind", ["http", "talker", "closer", "closed"])
@pytest.mark.parametrize("command", ["design-plant", "check-design"])
def test_a_command_given_no_scheduler_says_so_in_one_line_exit_3(tmp_path, command, kind):
    if command == "design-plant":
        argv = [script(command), "--fc", "3500", "--zeta", "0.2", "--no-sim", "--monte-carlo", "2000",
                "--out", str(tmp_path / "out")]
    else:
        (tmp_path / "p.yaml").write_text(CHECK_SPEC)
        argv = [script(command), str(tmp_path / "p.yaml"), "--out", str(tmp_path / "out")]
    with peer(kind) as address:
        tick = time.monotonic()
        p = subprocess.run([*argv, "--dask", address], capture_output=True, text=True, timeout=120,
                           env=dict(os.environ, MPLBACKEND="Agg"))
        took = time.monotonic() - tick
    assert p.returncode == 3 and p.stderr.splitlines() == [
        f"{command}: error: simulator error: --dask {address}: no Dask scheduler there ({SAID[kind]})"], p.stderr
    assert "MemoryError" not in p.stderr and "Error:" not in p.stderr
    print(f"{command} --dask at {kind}: {took:.2f} s")   # bench: the whole command, its design included
    assert took < 15
    assert not (tmp_path / "out").exists() or not any((tmp_path / "out").rglob("*.json"))


@pytest.mark.parametrize("command", ["design-plant", "check-design"])
def test_a_tls_or_other_scheme_is_bad_input(tmp_path, command):
    (tmp_path / "p.yaml").write_text(CHECK_SPEC)
    first = ["--fc", "3500", "--zeta", "0.2", "--no-sim", "--monte-carlo", "100"] if command == "design-plant" \
        else [str(tmp_path / "p.yaml")]
    p = subprocess.run([script(command), *first, "--dask", "tls://127.0.0.1:8786", "--out", str(tmp_path / "o")],
                       capture_output=True, text=True, timeout=120)
    assert p.returncode == 2 and p.stderr.splitlines() == [
        f"{command}: error: --dask 'tls://127.0.0.1:8786': only a tcp:// scheduler address is taken (a tls:// one "
        "needs certificates or a transport this command has no options for)"]


def test_a_sigkilled_local_cluster_run_prints_nothing_and_leaves_nothing(tmp_path):
    """Issue 25 (item 10): after a SIGKILL of `--dask local`, multiprocessing's resource tracker cleaned the
    workers' semaphores up and said so in two warning lines on the command's stderr."""
    tag = uuid.uuid4().hex
    err = tmp_path / "stderr"
    with open(err, "w") as fh:
        p = subprocess.Popen([script("design-pid"), "--plant-fc", "3500", "--plant-zeta", "0.2", "--no-sim",
                              "--monte-carlo", "40000", "--dask", "local", "--no-files"],
                             env=tagged_env(tag, MPLBACKEND="Agg"), stdout=subprocess.DEVNULL, stderr=fh,
                             stdin=subprocess.DEVNULL)
    deadline = time.monotonic() + 60
    # the command, the tracker, the fork server and two workers: the workers' semaphores exist
    while len(processes_tagged(tag)) < 5 and time.monotonic() < deadline:
        time.sleep(0.05)
    time.sleep(1.5)
    assert p.poll() is None, "the run ended before it was killed: make it longer"
    p.kill()
    p.wait(timeout=30)
    assert wait_gone(tag, 10.0) == [], "a process outlived design-pid"
    assert err.read_text() == ""
