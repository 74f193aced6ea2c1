"""Reading the user's text input files with bounded memory and time.

Captures, frequency tables and design results are files a user names on the
command line; any path can arrive: a directory, ``/dev/zero``, a FIFO, a
UTF-16 export, a 5 GB log. Everything here reads through
:class:`LimitedReader`, which never lets more than a stated number of bytes
through (``limit + 1`` at most are read, so a non-regular file that never ends
costs one limit's worth of time, and a regular file above the limit is refused
from its size before any byte is read), and every problem becomes one
:class:`~designer.errors.DesignError` line naming the file and what is allowed.

Encoding: UTF-8 (with or without a byte-order mark) and ASCII are read. Bytes
that are not UTF-8 are replaced (Windows instruments write a Latin-1 degree or
micro sign in header cells; the numbers are ASCII either way), but a file that
is UTF-16 or UTF-32, or binary (NUL bytes), is refused by name: decoded as
UTF-8 it would show up as ``\\x00-\\x000...`` cells.
"""

from __future__ import annotations

import io
import os
import stat
from pathlib import Path

from .errors import DesignError

MIB = 1 << 20
#: Largest step-response capture ``identify`` reads (bytes): 256 MiB, about
#: 5 million rows of three columns at 9 significant digits.
MAX_CAPTURE_BYTES = 256 * MIB
#: Most samples (data rows) of a capture: bounds memory however short the rows are.
MAX_CAPTURE_ROWS = 10_000_000
#: Largest frequency-response table or design ``result.json`` read (bytes).
MAX_TABLE_BYTES = 16 * MIB
#: Longest line accepted; a CSV line is never near this.
MAX_LINE_BYTES = 1 * MIB
#: Bytes examined for the encoding, and read per block when streaming.
SNIFF_BYTES = 64 * 1024
BLOCK_BYTES = 4 * MIB


def shown(path) -> str:
    """The path as messages print it: as typed, or quoted with escapes when it
    holds characters (a newline, a tab) that would break the one-line message."""
    s = str(path)
    return s if s.isprintable() else repr(s)


def show_cell(cell: str) -> str:
    """A cell of the user's file for a message: quoted, escaped, cut to a readable length."""
    return repr(cell if len(cell) <= 40 else cell[:37] + "...")


def size_text(n: int) -> str:
    """``256 MiB``, ``1.5 GiB``, ``300 bytes``."""
    for unit, scale in (("GiB", 1 << 30), ("MiB", MIB), ("KiB", 1024)):
        if n >= scale:
            return f"{n / scale:.4g} {unit}"
    return f"{n} bytes"


class LimitedReader(io.RawIOBase):
    """A binary file that raises :class:`DesignError` once more than ``limit``
    bytes have been read from it (it reads at most ``limit + 1``)."""

    def __init__(self, fh, limit: int, name: str, what: str, size: int | None = None):
        super().__init__()
        self._fh, self.limit, self.name, self.what = fh, limit, name, what
        self.size = size    #: bytes in the file when it is a regular file, else None
        self.count = 0

    def readable(self) -> bool:
        return True

    def readinto(self, buf) -> int:
        room = self.limit + 1 - self.count
        if room <= 0:
            self._too_big()
        view = memoryview(buf)[:room]
        try:
            n = self._fh.readinto(view) or 0
        except OSError as exc:
            raise DesignError(f"cannot read {self.what} {self.name}: "
                              f"{exc.strerror or exc}") from None
        self.count += n
        if self.count > self.limit:
            self._too_big()
        return n

    def _too_big(self):
        raise DesignError(f"{self.what} {self.name} is larger than {size_text(self.limit)}, "
                          f"the most this command reads; cut or decimate it")

    def close(self) -> None:
        try:
            self._fh.close()
        finally:
            super().close()


def open_limited(path, what: str, limit: int) -> LimitedReader:
    """Open ``path`` for reading at most ``limit`` bytes (see the module docstring).

    Raises
    ------
    DesignError
        Missing file, a directory, no permission, a regular file above ``limit``.
    """
    name = shown(path)
    if str(path) == "":
        raise DesignError(f"no {what} given: the name is empty")
    p = Path(path)
    try:
        fh = open(p, "rb", buffering=0)  # noqa: SIM115 - returned to the caller
    except FileNotFoundError:
        raise DesignError(f"{what} {name} does not exist") from None
    except IsADirectoryError:
        raise DesignError(f"{what} {name} is a directory; give a file") from None
    except OSError as exc:
        raise DesignError(f"cannot open {what} {name}: {exc.strerror or exc}") from None
    except ValueError:   # a NUL byte or an unencodable character in the name
        raise DesignError(f"cannot open {what} {name}: not a valid file name") from None
    try:
        st = os.fstat(fh.fileno())
    except OSError as exc:  # pragma: no cover - fstat on an open file does not fail
        fh.close()
        raise DesignError(f"cannot open {what} {name}: {exc.strerror or exc}") from None
    if stat.S_ISDIR(st.st_mode):
        fh.close()
        raise DesignError(f"{what} {name} is a directory; give a file")
    if stat.S_ISREG(st.st_mode) and st.st_size > limit:
        fh.close()
        raise DesignError(f"{what} {name} is {size_text(st.st_size)}; at most "
                          f"{size_text(limit)} is read: cut or decimate it")
    return LimitedReader(fh, limit, name, what,
                         size=st.st_size if stat.S_ISREG(st.st_mode) else None)


def check_encoding(head: bytes, name: str, what: str) -> int:
    """Refuse UTF-16/UTF-32 and binary data; return the length of a UTF-8 BOM (0 or 3)."""
    boms = ((b"\x00\x00\xfe\xff", "UTF-32"), (b"\xff\xfe\x00\x00", "UTF-32"),
            (b"\xff\xfe", "UTF-16"), (b"\xfe\xff", "UTF-16"))
    for bom, enc in boms:
        if head.startswith(bom):
            raise _not_utf8(name, what, enc)
    if b"\x00" in head:
        # ASCII text in UTF-16 has a NUL in every other byte
        even, odd = head[0::2], head[1::2]
        ne, no = even.count(0) / max(len(even), 1), odd.count(0) / max(len(odd), 1)
        if max(ne, no) >= 0.4 and min(ne, no) < 0.1:
            raise _not_utf8(name, what, "UTF-16")
        raise DesignError(f"{what} {name} is not a text file (it holds NUL bytes): "
                          "expected UTF-8 or ASCII text")
    return 3 if head.startswith(b"\xef\xbb\xbf") else 0


def _not_utf8(name, what, enc):
    return DesignError(f"{what} {name} is {enc} text, not UTF-8: save or convert it as "
                       "UTF-8 (or ASCII) CSV, e.g. iconv -f " + enc + " -t UTF-8")


def decode(data: bytes) -> str:
    """UTF-8 text; undecodable bytes (a Latin-1 degree sign in a header) replaced."""
    return data.decode("utf-8", errors="replace")


def read_text(path, what: str, limit: int = MAX_TABLE_BYTES) -> str:
    """The whole text of a small input file (a table, a JSON result), with every
    check of this module."""
    with open_limited(path, what, limit) as fh:
        head = fh.read(SNIFF_BYTES) or b""
        skip = check_encoding(head, fh.name, what)   # /dev/zero stops here
        data = head + (fh.read() or b"")
    return decode(data[skip:])
