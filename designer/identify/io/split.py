"""A long capture read on two cores: a forked helper parses the second half of
the file while the caller parses the first.

numpy's text parser holds the GIL (threads do not help: measured) and is most
of ``identify``'s time on a long record: about half a second for 1 million
rows of three columns on the 2-core machine, 3 s for 5 million.
:class:`FileBlocks` is the rest of the file as blocks of text (what
:func:`.capture._load` parses, about ``BLOCK_BYTES`` of whole lines each);
:meth:`FileBlocks.ahead` forks a helper that parses, with the caller's own
block parser, every block from the first line break past the middle of what is
left to the end of the file, and keeps its rows. When the caller's blocks reach
that line, the helper's rows come through a pipe, a block at a time, in order,
marked :data:`PARSED`.

The result is the same as reading the file in one process: the helper reads
the same bytes in the same blocks and parses them with the same function.
Anything the helper does not finish cleanly (a bad cell, a line too long,
more bytes than the reader's limit, a crash, a kill) makes the caller read
that half itself, as it would have without a helper, so every message and
its line numbers are the ones a single process gives. No helper on one core,
in a process with other threads running (a fork copies none of them, and
whatever lock they held stays held in the child), or when less than
:data:`SPLIT_BYTES` is left. The helper dies with the caller
(:func:`~designer.core.lifetime.die_with_parent`) and is killed and reaped when
the reading ends, however it ends.
"""

from __future__ import annotations

import os
import signal
import struct
import threading

import numpy as np

from ...core import lifetime
from ...core.errors import DesignError
from ...core.fileio import BLOCK_BYTES, MAX_LINE_BYTES, MIB, decode, size_text

__all__ = ["FileBlocks", "PARSED"]

#: the least left to read for a helper: below it, the fork and the pipe cost more than half the parse saves
SPLIT_BYTES = 8 * MIB
#: marks a block the helper parsed: ``(PARSED, (rows, where, lines))`` (``where``: the line
#: offsets of the rows within the block, None when no line was skipped)
PARSED = object()
_HEAD = struct.Struct("<q")        # the helper's status: bytes it read, or -1 (read it again here)
_BLOCK = struct.Struct("<qqqq")    # a block: rows, columns, lines, rows' line offsets given (1) or not (0)


def text_blocks(read, carry: bytes, name: str):
    """The text read by ``read(n)`` (after ``carry``) as blocks of decoded whole lines,
    about BLOCK_BYTES each, each with ``(may hold comments, has quotes, lines)``; a line
    longer than MAX_LINE_BYTES is refused. Kept as text: numpy's parser splits the
    lines itself, a list of a million strings costs a tenth of a second per 50 MB."""
    while True:
        data = read(BLOCK_BYTES)
        if not data:
            if carry.strip():
                text = decode(carry)
                yield text, _flags(text, carry)
            return
        buf = carry + data
        cut = buf.rfind(b"\n")
        if cut < 0:
            if len(buf) > MAX_LINE_BYTES:
                raise DesignError(f"capture file {name} has a line longer than "
                                  f"{size_text(MAX_LINE_BYTES)}: not a CSV text file")
            carry = buf
            continue
        carry = buf[cut + 1:]
        data = buf[:cut + 1]
        text = decode(data)
        yield text, _flags(text, data)


def _flags(text: str, data: bytes) -> tuple:
    """(may hold comment or blank lines, has quotes, lines) of a block, its text and its
    bytes. Only the one-character searches, and whether the block is blank (numpy's
    parser warns on a block without a number; ``isspace`` stops at the first number): a
    blank line among numbers is found by the parsed rows falling short of the lines
    (:func:`.capture._parse_block`), where searching every block for a two-character
    run (a newline twice) took longer than reading it. The lines as
    :func:`.capture.text_lines` counts them, counted by numpy, 8x faster than
    ``str.count`` (a newline is one byte in UTF-8, never part of another character)."""
    n = int(np.count_nonzero(np.frombuffer(data, dtype=np.uint8) == 10))
    return "#" in text or data.isspace(), '"' in text, n + (0 if not data or data.endswith(b"\n") else 1)


def _cores() -> int:
    try:
        return len(os.sched_getaffinity(0))
    except AttributeError:   # pragma: no cover - not Linux
        return os.cpu_count() or 1


class FileBlocks:
    """The rest of an open capture (a :class:`~designer.core.fileio.LimitedReader`
    after its first ``carry`` bytes) as :func:`text_blocks`, the second half from a
    helper once :meth:`ahead` has started one. :meth:`close` ends the helper."""

    def __init__(self, fh, carry: bytes):
        self.fh, self.carry = fh, carry
        self._pid = self._r = self._start = None
        self._it = self._blocks()

    def __iter__(self):
        return self

    def __next__(self):
        return next(self._it)

    def _read(self, n: int) -> bytes:
        if self._start is not None:   # the caller's half ends where the helper's begins
            n = min(n, self._start - self.fh.count)
        return self.fh.read(n) if n > 0 else b""

    def _blocks(self):
        yield from text_blocks(self._read, self.carry, self.fh.name)
        if self._start is None:
            return
        start, self._start = self._start, None
        done, given = None, False
        try:
            f = os.fdopen(self._r, "rb")
            self._r = None
            with f:
                head = _exactly(f, _HEAD.size)
                done = None if head is None else _HEAD.unpack(head)[0]
                while done is not None and done >= 0:   # its blocks, until the end mark
                    head = _exactly(f, _BLOCK.size)
                    m, k, lines, has_where = _BLOCK.unpack(head) if head else (-2, 0, 0, 0)
                    if m == -1:
                        break
                    rows = np.empty((max(m, 0), k))
                    where = np.empty(max(m, 0), dtype=np.int64) if has_where else None
                    if m < 0 or not (_fill(f, rows) and (where is None or _fill(f, where))):
                        done = None   # cut short: the helper was killed
                        break
                    given = True
                    yield PARSED, (rows, where, lines)
                    del rows, where
        finally:
            self.close()
        if done is None or done < 0:
            if given:   # pragma: no cover - a helper killed while it sent its rows
                raise DesignError(f"capture file {self.fh.name}: the process reading its second half "
                                  "was killed; run again")
            self.fh.seek(start)   # the helper did not finish: its half is read here, as without one
            done = None
        else:
            self.fh.seek(start + done)   # what was appended since, if anything, is read here
        yield from text_blocks(self.fh.read, b"", self.fh.name)

    def ahead(self, parse) -> None:
        """Fork a helper that parses the second half of what is left with ``parse(text,
        flags) -> (rows, where)`` (rows the block's samples; where 0, or the line offset of
        every row when lines were skipped), when the file is long enough, a second core
        is there and this process runs no other thread."""
        fh = self.fh
        if self._pid is not None or fh.size is None or fh.size - fh.count < SPLIT_BYTES:
            return
        if _cores() < 2 or threading.active_count() > 1:
            return
        mid = fh.count + (fh.size - fh.count) // 2
        try:
            probe = os.pread(fh.fileno(), MAX_LINE_BYTES, mid)
        except OSError:
            return
        cut = probe.find(b"\n")
        if cut < 0 or mid + cut + 1 >= fh.size:
            return   # no line break near the middle: read in one process (and refused there)
        start = mid + cut + 1
        r, w = os.pipe()
        parent = os.getpid()
        try:
            pid = os.fork()
        except OSError:
            os.close(r)
            os.close(w)
            return
        if pid == 0:   # the helper: its rows through the pipe, then gone
            try:
                os.close(r)
                lifetime.die_with_parent(parent)
                lifetime.reset_in_child()
                _helper(fh.fileno(), start, fh.limit, fh.name, parse, w)
            finally:
                os._exit(0)
        os.close(w)
        self._pid, self._r, self._start = pid, r, start

    def close(self) -> None:
        """End the helper (killed if it still runs) and reap it."""
        if self._r is not None:
            os.close(self._r)
            self._r = None
        pid, self._pid = self._pid, None
        if pid is not None:
            try:
                os.kill(pid, signal.SIGKILL)
            except ProcessLookupError:   # pragma: no cover - already reaped
                pass
            try:
                os.waitpid(pid, 0)
            except ChildProcessError:   # pragma: no cover
                pass


class _Redo(Exception):
    """The helper's half is to be read by the caller."""


def _helper(fd: int, start: int, limit: int, name: str, parse, w: int) -> None:
    """In the helper: parse the file from ``start`` to its end, keep the rows, then send
    the status and the blocks (the caller reads the pipe once its own half is done)."""
    got = 0
    out = []
    try:
        def read(n):
            nonlocal got
            data = os.pread(fd, min(n, limit + 1 - start - got), start + got)
            got += len(data)
            if start + got > limit:
                raise _Redo   # too large: the caller's reader says so
            return data

        for text, flags in text_blocks(read, b"", name):
            rows, where = parse(text, flags)
            out.append((np.ascontiguousarray(rows, dtype=float),
                        None if isinstance(where, int) else np.asarray(where, dtype=np.int64), flags[2]))
            del text, rows
    except BaseException:   # noqa: BLE001 - a bad cell, a crash: the caller reads it again, with its message
        got = -1
    with os.fdopen(w, "wb") as f:
        f.write(_HEAD.pack(got))
        if got < 0:
            return
        for rows, where, lines in out:
            f.write(_BLOCK.pack(rows.shape[0], rows.shape[1], lines, where is not None))
            for arr in (rows, where):
                if arr is not None and arr.size:   # (a block of comments has no rows)
                    f.write(memoryview(arr).cast("B"))
        f.write(_BLOCK.pack(-1, 0, 0, 0))


def _exactly(f, n: int) -> bytes | None:
    data = f.read(n)
    return data if data is not None and len(data) == n else None


def _fill(f, arr) -> bool:
    if arr.size == 0:
        return True
    view = memoryview(arr).cast("B")
    return f.readinto(view) == len(view)
