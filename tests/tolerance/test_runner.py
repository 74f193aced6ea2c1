"""The chunk runner: the same figures whatever the chunking and the workers, a lost
chunk run once more (then exit 3), --target-ci's rounds against an independent
Wilson interval, and the CLI inputs it parses."""

import contextlib

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

from designer.core import opamps
from designer.core.errors import DesignError, SimulatorError
from designer.plant.sallenkey import SallenKeyParts
from designer.tolerance import plant, runner, sampling
from designer.tolerance.montecarlo import (
    MAX_TARGET_CI,
    TARGET_ROUND,
    parse_target_ci,
    plant_monte_carlo,
)
from designer.tolerance.runner import MAX_JOBS, Draw, Runner, Scale, parse_dask, parse_jobs
from helpers import wilson_half_width
from mc_engines import always_dies, dies_once

AMP = opamps.get("LM741")
NOMINAL = {"R1": 1.6e3, "R2": 3.9e3, "C1": 3.3e-9, "C2": 100e-9}
TOL = {"R1": 0.05, "R2": 0.05, "C1": 0.10, "C2": 0.10}
PARTS = SallenKeyParts(1.6e3, 3.9e3, 3.3e-9, 100e-9)
SERIES = {"R": "E24", "C": "E12"}
LIMITS = ["fn_hz=3.3k:3.7k", "overshoot_pct=0:55"]


def assert_same(a: dict, b: dict):
    assert list(a) == list(b)
    for k in a:
        np.testing.assert_array_equal(a[k], b[k], err_msg=k)


@pytest.mark.parametrize("sampler", ["random", "sobol", "lhs"])
def test_any_chunking_gives_the_same_samples_and_figures(sampler):
    draw = Draw(NOMINAL, TOL, 5000, 7, sampler)
    whole_v, whole_f, _ = Runner(Scale(chunk=5000)).run(plant.evaluate, AMP, draw)
    # the samples are those the sampler draws for the whole run at once
    assert_same(whole_v, draw.values())
    for chunk in (16, 999, 4096, None):
        v, f, _ = Runner(Scale(chunk=chunk)).run(plant.evaluate, AMP, draw)
        assert_same(v, whole_v)
        assert_same(f, whole_f)


def test_two_worker_processes_give_the_same_result():
    draw = Draw(NOMINAL, TOL, 3000, 3)
    v1, f1, _ = Runner(Scale(jobs=1)).run(plant.evaluate, AMP, draw)
    v2, f2, _ = Runner(Scale(jobs=2, chunk=300)).run(plant.evaluate, AMP, draw)
    assert_same(v1, v2)
    assert_same(f1, f2)


def test_the_monte_carlo_section_is_the_same_with_two_workers():
    a = plant_monte_carlo(PARTS, SERIES, AMP, 2000, seed=5, limit_items=LIMITS)
    b = plant_monte_carlo(PARTS, SERIES, AMP, 2000, seed=5, limit_items=LIMITS, scale=Scale(jobs=2, chunk=128))
    assert a.to_dict() == b.to_dict() and a.csv_text() == b.csv_text()


def test_a_chunk_whose_worker_dies_runs_once_more(tmp_path):
    draw = Draw(NOMINAL, TOL, 400, 1)
    v, f, _ = Runner(Scale(jobs=2, chunk=100)).run(dies_once, str(tmp_path / "died"), draw)
    assert (tmp_path / "died").exists()
    _, ref, _ = Runner().run(plant.evaluate, AMP, draw)
    assert_same(f, ref)


def test_a_chunk_lost_twice_is_a_simulator_error_naming_it():
    draw = Draw(NOMINAL, TOL, 100, 1)
    with pytest.raises(SimulatorError, match=r"samples 0\.\.99 was lost twice") as e:
        Runner(Scale(jobs=2, chunk=100)).run(always_dies, None, draw)
    assert "\n" not in str(e.value)


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


def inside(figs, n):
    fn, os_ = figs["fn_hz"][:n], figs["overshoot_pct"][:n]
    return int(np.count_nonzero((fn >= 3300) & (fn <= 3700) & (os_ >= 0) & (os_ <= 55)))


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
    with runner.cluster_ahead(scale):
        start = runner._ahead
        assert isinstance(start, runner.ClusterStart) and start.workers == 2
        with Runner(scale) as run:
            assert runner._ahead is None and start._box == {}     # handed over, not started again
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
    assert [w for w, (threads, _) in runner.WORKERS.items() if threads] == ["ngspice-cli"]


def test_the_modules_worker_processes_start_with_exist():
    """The fork server skips a module it cannot import: a misspelt name would only slow the workers."""
    import importlib
    for work, (_, modules) in runner.WORKERS.items():
        for name in modules:
            assert importlib.import_module(name), (work, name)


@pytest.mark.parametrize("how", ["unused", "interrupted"])
def test_a_cluster_started_ahead_and_not_taken_is_closed(how):
    """A cluster no runner took (the design failed, or Ctrl-C came while it started) is waited
    for and closed when the block ends: no worker is left."""
    before = _children()
    with pytest.raises(KeyboardInterrupt) if how == "interrupted" else contextlib.nullcontext():
        with runner.cluster_ahead(Scale(dask="local")):
            start = runner._ahead
            if how == "interrupted":
                raise KeyboardInterrupt
            start._thread.join(60)      # started, then left alone
            assert "cluster" in start._box
    assert runner._ahead is None and not start._thread.is_alive() and start._box == {}
    assert _gone(_children() - before) == set()


def test_without_dask_local_nothing_starts_ahead():
    for scale in (None, Scale(), Scale(jobs=2), Scale(dask="tcp://127.0.0.1:1")):
        with runner.cluster_ahead(scale):
            assert runner._ahead is None


@pytest.mark.parametrize("target", [0.01, 0.02])
def test_target_ci_stops_at_the_first_round_below_it(target):
    mc = plant_monte_carlo(PARTS, SERIES, AMP, 200000, seed=3, limit_items=LIMITS, target_ci=target, tighten=False)
    t = mc.to_dict()["settings"]["target_ci"]
    rounds = t["rounds"]
    assert t["reached"] and rounds[-1] == mc.n == mc.to_dict()["settings"]["samples"] < 200000
    assert rounds[0] == TARGET_ROUND and rounds == sorted(rounds)
    assert wilson_half_width(inside(mc.figures, mc.n), mc.n) < target
    for end in rounds[:-1]:   # every earlier round was still too wide
        assert wilson_half_width(inside(mc.figures, end), end) >= target
    # the samples drawn are the first of the same run at its full size: sample i is f(seed, i)
    full = plant_monte_carlo(PARTS, SERIES, AMP, mc.n, seed=3, limit_items=LIMITS, tighten=False)
    assert_same(full.figures, mc.figures)
    # and the same with two workers
    again = plant_monte_carlo(PARTS, SERIES, AMP, 200000, seed=3, limit_items=LIMITS, target_ci=target,
                              tighten=False, scale=Scale(jobs=2))
    assert again.to_dict() == mc.to_dict()


def test_every_target_ci_round_is_split_among_the_workers(monkeypatch):
    """--target-ci's first round (TARGET_ROUND builds of up to 10^5) was one chunk, so --jobs
    ran it on one worker: every round is now split by its own size, and the output (the rounds'
    ends, the samples, the section and the CSV) is the same with --jobs 1 and --jobs 2."""
    rounds = []
    real = runner._ProcessPool.map

    def spy(self, evaluate, context, draw, tasks, bar):
        rounds.append(list(tasks))
        return real(self, evaluate, context, draw, tasks, bar)

    monkeypatch.setattr(runner._ProcessPool, "map", spy)
    kw = dict(seed=3, limit_items=LIMITS, target_ci=0.01, tighten=False)
    one = plant_monte_carlo(PARTS, SERIES, AMP, 100000, **kw)
    two = plant_monte_carlo(PARTS, SERIES, AMP, 100000, scale=Scale(jobs=2), **kw)
    ends = two.to_dict()["settings"]["target_ci"]["rounds"]
    assert len(ends) >= 2 and ends[0] == TARGET_ROUND
    assert len(rounds) == len(ends)
    done = 0
    for tasks, end in zip(rounds, ends):
        # each round's samples, in order, in chunks of about end - done over 8 chunks per worker
        assert tasks[0][0] == done and tasks[-1][1] == end
        assert all(b == c for (_, b), (c, _) in zip(tasks, tasks[1:]))
        assert len(tasks) >= 2 * runner.CHUNKS_PER_WORKER - 1
        done = end
    assert one.to_dict() == two.to_dict() and one.csv_text() == two.csv_text()
    assert_same(one.values, two.values)


def test_target_ci_bounded_by_the_samples_asked():
    mc = plant_monte_carlo(PARTS, SERIES, AMP, 1200, seed=3, limit_items=LIMITS, target_ci=0.001, tighten=False)
    t = mc.to_dict()["settings"]["target_ci"]
    assert mc.n == 1200 and not t["reached"] and t["max_samples"] == 1200
    assert wilson_half_width(inside(mc.figures, 1200), 1200) >= 0.001


@pytest.mark.parametrize("kw, what", [({"target_ci": 0.01}, "needs --limit"),
                                      ({"target_ci": 0.6, "limit_items": LIMITS}, "at most 50 %"),
                                      ({"target_ci": 0.0, "limit_items": LIMITS}, "above 0"),
                                      ({"target_ci": 0.01, "limit_items": LIMITS, "sampler": "lhs"}, "random or sobol")])
def test_target_ci_refusals(kw, what):
    with pytest.raises(DesignError, match=what):
        plant_monte_carlo(PARTS, SERIES, AMP, 1000, **kw)


@settings(max_examples=200, deadline=None)
@given(st.one_of(st.text(max_size=12), st.integers(-5, 100).map(str)))
def test_jobs_input_is_a_whole_number_in_range_or_one_line(text):
    try:
        jobs = parse_jobs(text)
    except DesignError as exc:
        assert "\n" not in str(exc) and "--jobs" in str(exc)
    else:
        assert 1 <= jobs <= MAX_JOBS and jobs == int(text.strip())


@settings(max_examples=200, deadline=None)
@given(st.one_of(st.text(max_size=12), st.floats(allow_nan=True).map(lambda x: f"{x}%"),
                 st.floats(0, 1).map(str)))
def test_target_ci_input_is_a_half_width_in_range_or_one_line(text):
    try:
        v = parse_target_ci(text)
    except DesignError as exc:
        assert "\n" not in str(exc) and "--target-ci" in str(exc)
    else:
        assert 0 < v <= MAX_TARGET_CI


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


@settings(max_examples=200, deadline=None)
@given(n=st.integers(1, 10 ** 6), workers=st.integers(1, 16), work=st.sampled_from(runner.SPICE_WORK))
def test_spice_chunks_are_long_but_every_worker_gets_one(n, workers, work):
    size = Scale(jobs=workers, work=work).chunk_size(n)
    chunks = -(-n // size)
    # a simulator's start is paid per chunk: at least SPICE_MIN_CHUNK builds each, unless that
    # would leave a worker idle (then at least MIN_CHUNK); never more than a sampler's block
    assert runner.MIN_CHUNK <= size <= sampling.CHUNK
    if n >= workers * runner.SPICE_MIN_CHUNK:
        assert size >= runner.SPICE_MIN_CHUNK
    if n >= workers * runner.MIN_CHUNK:
        assert chunks >= workers
    # the other engines keep their finer split
    assert Scale(jobs=workers, work="loop").chunk_size(n) <= size
