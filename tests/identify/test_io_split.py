"""A long capture read on two cores (designer.identify.io.split): the helper's half
gives the same samples, line numbers and messages as one process reading it all,
and no helper is left behind however the reading ends."""

import os

import numpy as np
import pytest

from designer.core.errors import DesignError
from designer.identify.io import format_generic, read_capture, split
from designer.identify.structures import model_step


@pytest.fixture
def small_blocks(monkeypatch):
    """Blocks of 16 KiB and a helper from 64 KiB left: the reading of a 1 MB file splits."""
    monkeypatch.setattr(split, "BLOCK_BYTES", 16 * 1024)
    monkeypatch.setattr(split, "SPLIT_BYTES", 64 * 1024)


@pytest.fixture
def helpers(monkeypatch):
    """The helpers started (their pids), with the real ``ahead``."""
    started = []
    ahead = split.FileBlocks.ahead

    def spy(self, parse):
        ahead(self, parse)
        if self._pid is not None:
            started.append(self._pid)

    monkeypatch.setattr(split.FileBlocks, "ahead", spy)
    return started


def _one_process(monkeypatch, path):
    """read_capture with no helper: the reference."""
    with monkeypatch.context() as m:
        m.setattr(split, "SPLIT_BYTES", 1 << 62)
        try:
            return read_capture(path)
        except DesignError as exc:
            return str(exc)


def _lines(n=20000):
    t = np.linspace(-1e-3, 9e-3, n)
    return format_generic(t, model_step("fopdt", {"K": 2.0, "tau_s": 1e-3, "theta_s": 0.0}, t),
                          np.where(t >= 0, 1.0, 0.0)).splitlines()


def _no_children():
    with pytest.raises(ChildProcessError):
        os.waitpid(-1, os.WNOHANG)


@pytest.mark.skipif(len(os.sched_getaffinity(0)) < 2, reason="a helper needs a second core")
def test_the_helper_reads_the_same_samples(tmp_path, monkeypatch, small_blocks, helpers):
    lines = _lines()
    # blank and comment lines in the helper's half, one without a final newline
    lines[15000] += "\n\n# a note\n   "
    path = tmp_path / "c.csv"
    path.write_text("\n".join(lines))
    parsed = []
    blocks = split.FileBlocks._blocks

    def counted(self):
        for item in blocks(self):
            parsed.append(item[0] is split.PARSED)
            yield item

    monkeypatch.setattr(split.FileBlocks, "_blocks", counted)
    cap = read_capture(path)
    assert len(helpers) == 1 and sum(parsed) > 10   # most of the second half came from the helper
    ref = _one_process(monkeypatch, path)
    assert cap.t.size == ref.t.size == len(_lines()) - 1
    for a, b in ((cap.t, ref.t), (cap.y, ref.y), (cap.u, ref.u)):
        assert np.array_equal(a, b)
    _no_children()


@pytest.mark.skipif(len(os.sched_getaffinity(0)) < 2, reason="a helper needs a second core")
@pytest.mark.parametrize("where, bad", [(15000, "bad cell"), (15000, "time back"), (5000, "bad cell"),
                                        (19990, "time back")])
def test_a_problem_anywhere_is_named_at_its_line(tmp_path, monkeypatch, small_blocks, helpers, where, bad):
    """A bad cell or a time going back, in either half, after skipped lines in the helper's
    half: the message a single process gives, line number included."""
    lines = _lines()
    lines[12000] += "\n# a comment in the helper's half"
    if bad == "bad cell":
        lines[where] = lines[where].rsplit(",", 1)[0] + ",oops"
    else:
        lines[where] = lines[3].split(",", 1)[0] + "," + lines[where].split(",", 1)[1]
    path = tmp_path / "c.csv"
    path.write_text("\n".join(lines) + "\n")
    with pytest.raises(DesignError) as err:
        read_capture(path)
    assert len(helpers) == 1
    ref = _one_process(monkeypatch, path)
    assert str(err.value) == ref
    line_no = where + 2 if where > 12000 else where + 1
    assert f"line {line_no}" in ref
    _no_children()


@pytest.mark.skipif(len(os.sched_getaffinity(0)) < 2, reason="a helper needs a second core")
def test_a_helper_that_dies_leaves_its_half_to_the_caller(tmp_path, monkeypatch, small_blocks, helpers):
    monkeypatch.setattr(split, "_helper", lambda *args: os._exit(9))
    path = tmp_path / "c.csv"
    path.write_text("\n".join(_lines()) + "\n")
    cap = read_capture(path)
    assert len(helpers) == 1
    assert np.array_equal(cap.y, _one_process(monkeypatch, path).y)
    _no_children()


def test_no_helper_for_a_short_file_or_beside_other_threads(tmp_path, monkeypatch, helpers):
    import threading
    path = tmp_path / "c.csv"
    path.write_text("\n".join(_lines()) + "\n")   # about 1 MB: below SPLIT_BYTES
    read_capture(path)
    monkeypatch.setattr(split, "SPLIT_BYTES", 64 * 1024)
    stop = threading.Event()
    other = threading.Thread(target=stop.wait)
    other.start()
    try:
        read_capture(path)   # a fork beside a running thread could copy a held lock
    finally:
        stop.set()
        other.join()
    assert helpers == []


@pytest.mark.parametrize("helper", [False, True])
def test_a_block_of_blank_lines_is_no_warning(tmp_path, monkeypatch, helper):
    """A run of blank lines long enough to be a block of its own (at the end of a file, or in
    the helper's half): read without a warning line (numpy warns on a text with no number,
    and the tests turn warnings into errors)."""
    monkeypatch.setattr(split, "BLOCK_BYTES", 16 * 1024)
    monkeypatch.setattr(split, "SPLIT_BYTES", 64 * 1024 if helper else 1 << 62)
    lines = _lines()
    lines[15000] += "\n" * 40000
    path = tmp_path / "c.csv"
    path.write_text("\n".join(lines) + "\n" * 300000)
    cap = read_capture(path)
    assert cap.t.size == len(lines) - 1
    assert np.array_equal(cap.y, _one_process(monkeypatch, path).y)
