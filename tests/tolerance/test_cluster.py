"""The Dask side of the runner (designer.tolerance.cluster): a LocalCluster's lost chunk run
once more (then exit 3), the cluster started ahead and taken or closed, thread workers for
ngspice-cli chunks, no worker left behind, and the --dask address input."""

import contextlib

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

from designer.core import opamps
from designer.core.errors import DesignError, SimulatorError
from designer.tolerance import cluster, plant
from designer.tolerance.cluster import parse_dask
from designer.tolerance.runner import Draw, Runner, Scale
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
    from designer.tolerance import spice_engine
    from designer.tolerance.montecarlo import _apply, plant_parts
    from designer.tolerance.spice_mc import spice_evaluate
    res = design_plant(PlantSpec(fc_hz=3500, zeta=0.2), simulate=False)
    nominal = plant_parts(res.built)
    ctx = spice_evaluate(spice_engine.context(res.deck, res.built, res.opamp, res.test, "ngspice-cli"), res.opamp)
    draw = Draw(nominal, {k: 0.05 for k in nominal}, 48, 2)
    _, ref, _ = Runner().run(_apply, ctx, draw)
    before = _children()
    with Runner(Scale(dask="local", chunk=8, work="ngspice-cli")) as run:
        workers = run._pool.cluster.workers.values()
        assert len(workers) == 2 and all(isinstance(w, distributed.Worker) for w in workers)
        _, f, _ = run.run(_apply, ctx, draw)
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
    assert parse_dask(" tls://sched.lab:8786 ") == "tls://sched.lab:8786"
    assert parse_dask("LOCAL") == "local"
    for bad in ("sched", "host:0", "host:70000", "http://host:8786", ":8786"):
        with pytest.raises(DesignError):
            parse_dask(bad)
