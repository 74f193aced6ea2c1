"""The chunk runner: the same figures whatever the chunking and the workers, a lost
chunk run once more (then exit 3), --target-ci's rounds against an independent
Wilson interval, and the CLI inputs it parses."""


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
from designer.tolerance.runner import MAX_JOBS, Draw, Runner, Scale, parse_jobs
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


def inside(figs, n):
    fn, os_ = figs["fn_hz"][:n], figs["overshoot_pct"][:n]
    return int(np.count_nonzero((fn >= 3300) & (fn <= 3700) & (os_ >= 0) & (os_ <= 55)))


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
