"""designer.core.workers: worker processes (check-design --jobs, the build sheets' renderer)."""

import os
import time

from designer.core.workers import run_tasks


def _work(task):
    return task, time.monotonic(), os.getpid()


def _lost(task, reason):
    return task, None, reason


def test_results_keep_task_order_and_longest_tasks_start_first():
    tasks = [1, 5, 2, 9, 3]
    out = run_tasks(tasks, _work, jobs=1, timeout=60, lost=_lost, cost=lambda t: t)
    assert [r[0] for r in out] == tasks
    started = [r[0] for r in sorted(out, key=lambda r: r[1])]
    assert started == sorted(tasks, reverse=True)


def test_without_cost_tasks_start_in_order():
    tasks = [1, 5, 2]
    out = run_tasks(tasks, _work, jobs=1, timeout=60, lost=_lost)
    assert [r[0] for r in sorted(out, key=lambda r: r[1])] == tasks


def test_a_task_past_its_timeout_is_lost_and_the_rest_still_run():
    def work(task):
        if task == "hang":
            time.sleep(60)
        return task
    out = run_tasks(["hang", "a", "b"], work, jobs=2, timeout=1.0, lost=lambda t, why: ("lost", why))
    assert out[0][0] == "lost" and "timed out" in out[0][1]
    assert out[1:] == ["a", "b"]


def test_done_is_called_once_per_task_as_it_finishes_lost_ones_included():
    def work(task):
        if task == "hang":
            time.sleep(60)
        return task * 2
    seen = []
    out = run_tasks(["hang", "a", "b", "c"], work, jobs=2, timeout=1.0, lost=lambda t, why: "lost",
                    done=lambda i, r: seen.append((i, r)))
    assert out == ["lost", "aa", "bb", "cc"]
    assert sorted(seen) == [(0, "lost"), (1, "aa"), (2, "bb"), (3, "cc")]


def _echo_big(task):
    return b"y" * len(task)


def test_a_queued_worker_reads_tasks_while_a_large_answer_waits():
    """Bug: the renderer's parent sends its pictures' tasks without reading the answers in between; a task and
    an answer each larger than the pipe's buffer (~200 kB each way) left both processes blocked in send for
    good (design-pid on a 4th-order cascade plant hung at its sheet). A queued worker writes its answers from
    a thread, so the parent's sends complete and every answer arrives."""
    import multiprocessing

    from designer.core.workers import Worker
    w = Worker(multiprocessing.get_context("fork"), _echo_big, queued=True)
    try:
        tasks = [b"x" * (2_000_000 + k) for k in range(4)]
        start = time.monotonic()
        for task in tasks:      # all sent before any answer is read, as the renderer's caller does
            w.conn.send(task)
        for task in tasks:
            assert w.conn.poll(60), "no answer: the worker and its parent are blocked on each other"
            assert w.conn.recv() == ("ok", b"y" * len(task))
        assert time.monotonic() - start < 60
    finally:
        w.kill()
