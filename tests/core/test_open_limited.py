"""core.fileio.open_limited: only a regular file is opened (a symbolic link to
one included); a FIFO, a device, a socket or a directory is refused in one
line from its stat, before any open() could block."""

import os
import socket
import threading

import pytest

from designer.core.errors import DesignError
from designer.core.fileio import open_limited


def refusal(path) -> str:
    with pytest.raises(DesignError) as info:
        open_limited(path, "capture file", 1 << 20)
    msg = str(info.value)
    assert "\n" not in msg
    return msg


def test_a_fifo_without_a_writer_is_refused_at_once(tmp_path):
    fifo = tmp_path / "pipe.csv"
    os.mkfifo(fifo)
    done = []
    # in a thread, so that a regression (open() blocking) fails the test instead of hanging it
    th = threading.Thread(target=lambda: done.append(refusal(fifo)), daemon=True)
    th.start()
    th.join(timeout=10)
    if not done:
        os.close(os.open(fifo, os.O_WRONLY | os.O_NONBLOCK))   # pragma: no cover - unblock the reader
    assert done == [f"capture file {fifo} is a FIFO (named pipe); a regular file is needed (save the data to "
                    "a file and give that)"]


@pytest.mark.parametrize("path, kind", [("/dev/null", "a character device"), ("/dev/zero", "a character device")])
def test_devices_are_refused_by_kind(path, kind):
    assert refusal(path) == (f"capture file {path} is {kind}; a regular file is needed (save the data to a "
                             "file and give that)")


def test_sockets_directories_links_and_missing_files(tmp_path):
    sock_path = tmp_path / "s.csv"
    with socket.socket(socket.AF_UNIX) as sock:
        sock.bind(str(sock_path))
        assert "is a socket; a regular file is needed" in refusal(sock_path)
    assert refusal(tmp_path) == f"capture file {tmp_path} is a directory; give a file"
    assert refusal(tmp_path / "none.csv") == f"capture file {tmp_path / 'none.csv'} does not exist"
    dangling = tmp_path / "dangling.csv"
    dangling.symlink_to(tmp_path / "gone.csv")
    assert refusal(dangling).endswith("does not exist")
    fifo = tmp_path / "pipe"
    os.mkfifo(fifo)
    via = tmp_path / "via.csv"
    via.symlink_to(fifo)
    assert "via.csv is a FIFO (named pipe)" in refusal(via)
    assert "not a valid file name" in refusal("a\0b.csv")
    # a regular file, directly or through a symbolic link, is read (blocking reads, its size known)
    real = tmp_path / "real.csv"
    real.write_bytes(b"0,1\n1,2\n")
    link = tmp_path / "link.csv"
    link.symlink_to(real)
    for p in (real, link):
        with open_limited(p, "capture file", 1 << 20) as fh:
            assert fh.size == 8 and fh.read() == b"0,1\n1,2\n"
    assert "is 8 bytes; at most 4 bytes is read" in str(pytest.raises(DesignError, open_limited, real, "x", 4).value)


def test_a_seek_counts_the_bytes_before_it_as_read(tmp_path):
    """LimitedReader.seek (a capture read in two parts, designer.identify.io.split): the
    bytes before the offset count toward the limit, as if read."""
    path = tmp_path / "c.csv"
    path.write_bytes(b"0123456789" * 10)
    with open_limited(path, "capture file", 100) as fh:
        assert fh.seek(95) == 95 and fh.count == 95
        assert fh.read() == b"56789" and os.pread(fh.fileno(), 2, 0) == b"01"
        fh.seek(10)
        assert fh.read(3) == b"012" and fh.count == 13
        with pytest.raises(DesignError, match="larger than 100 bytes"):
            fh.seek(101)
