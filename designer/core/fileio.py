"""File I/O in one place: reading the user's input files with bounded memory
and time, and writing files without ever leaving a half-written one or a
mixed bundle.

Reading
-------
Captures, frequency tables and design results are files a user names on the
command line; any path can arrive: a directory, ``/dev/zero``, a FIFO, a
UTF-16 export, a 5 GB log. Only regular files are read: a FIFO (whose
opening would block), a device or a socket is refused by its kind before it is
opened. Everything here reads through :class:`LimitedReader`, which never lets
more than a stated number of bytes through (``limit + 1`` at most are read; a
regular file above the limit is refused from its size before any byte is read),
and every problem becomes one :class:`~designer.core.errors.DesignError` line
naming the file and what is allowed.

Encoding: UTF-8 (with or without a byte-order mark) and ASCII are read. Bytes
that are not UTF-8 are replaced (Windows instruments write a Latin-1 degree or
micro sign in header cells; the numbers are ASCII either way), but a file that
is UTF-16 or UTF-32, or binary (NUL bytes), is refused by name: decoded as
UTF-8 it would show up as ``\\x00-\\x000...`` cells.

Writing
-------
- :func:`atomic_write`: one file, through a temporary file beside it and a
  rename, over a regular file only (:func:`check_output_file`: a symbolic link,
  FIFO, device or directory named as an output is refused, before any work).
- :func:`publish_folder`: a whole folder (a design's report bundle) written
  elsewhere first (:func:`check_output_folder` before any work: never over a
  symbolic link or a file), then swapped in with one atomic exchange of directories
  (Linux ``renameat2(RENAME_EXCHANGE)``; elsewhere two renames, rolled back on
  the next run if interrupted), so readers see the old bundle or the new one.
- :func:`link_into`: a relative symbolic link put in place atomically; the
  netlist beside the reports is such a link into the bundle, so the one
  exchange switches netlist and report together.
- :func:`clean_stale`: temporaries of our own naming left by a killed run
  (its process gone) are removed, or an interrupted swap rolled back.

Every operating-system error becomes a :class:`DesignError` of one line.
"""

from __future__ import annotations

import errno
import io
import os
import re
import shutil
import stat
import tempfile
from pathlib import Path

from .errors import DesignError

__all__ = ["BLOCK_BYTES", "LimitedReader", "MAX_CAPTURE_BYTES", "MAX_CAPTURE_ROWS", "MAX_LINE_BYTES",
           "MAX_TABLE_BYTES", "MIB", "SNIFF_BYTES", "atomic_write", "check_can_create", "check_encoding",
           "check_output_file", "check_output_folder", "check_plain_name", "clean_stale", "decode", "ensure_dir",
           "link_into", "new_folder_beside", "open_limited", "os_error", "publish_folder", "read_text", "remove_tree",
           "show_cell", "shown", "size_text"]

# --------------------------------------------------------------------------- reading

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
    holds characters (a newline, a tab) that would break the one-line message.

    Parameters
    ----------
    path : path-like
        The path.

    Returns
    -------
    str
        The path as the message shows it.
    """
    s = str(path)
    return s if s.isprintable() else repr(s)


def show_cell(cell: str) -> str:
    """A cell of the user's file for a message: quoted, escaped, cut to a readable length.

    Parameters
    ----------
    cell : str
        The cell.

    Returns
    -------
    str
        The cell as the message shows it.
    """
    return repr(cell if len(cell) <= 40 else cell[:37] + "...")


_PLAIN_NAME = re.compile(r"^[A-Za-z0-9_+=,@-][A-Za-z0-9._+=,@-]{0,119}$")


def check_plain_name(name, what: str) -> str:
    """A name that becomes a file or folder name (a design's ``--name``, a check
    spec's ``name:``): letters, digits and ``. _ - + = , @``, not starting with
    '.', at most 120 characters; else a :class:`DesignError` naming ``what``.

    Parameters
    ----------
    name : str
        The name.
    what : str
        Where it was given (``--name``), for the message.

    Returns
    -------
    str
        The name.
    """
    if not isinstance(name, str) or not _PLAIN_NAME.match(name):
        what_is = ("must not be empty" if not name else
                   f"{show_cell(str(name))} is not a plain file name")
        raise DesignError(f"{what} {what_is}: use letters, digits and . _ - + = , @ (not starting with '.', "
                          "at most 120 characters)")
    return name


def size_text(n: int) -> str:
    """``256 MiB``, ``1.5 GiB``, ``300 bytes``.

    Parameters
    ----------
    n : int
        A size in bytes.

    Returns
    -------
    str
        The text.
    """
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

    def fileno(self) -> int:
        return self._fh.fileno()

    def seekable(self) -> bool:
        return self._fh.seekable()

    def seek(self, offset: int, whence: int = io.SEEK_SET) -> int:
        """Go to byte ``offset`` from the start (a file read in parts: see
        :mod:`designer.identify.io.split`); the bytes before it count as read."""
        if whence != io.SEEK_SET:
            raise io.UnsupportedOperation("only seeks from the start")
        self.count = self._fh.seek(offset)
        if self.count > self.limit:
            self._too_big()
        return self.count

    def _too_big(self):
        raise DesignError(f"{self.what} {self.name} is larger than {size_text(self.limit)}, "
                          f"the most this command reads; cut or decimate it")

    def close(self) -> None:
        try:
            self._fh.close()
        finally:
            super().close()


def open_limited(path, what: str, limit: int) -> LimitedReader:
    """Open the regular file ``path`` for reading at most ``limit`` bytes (see
    the module docstring).

    The path is ``os.stat``-ed first (following symbolic links: a link to a
    regular file is read), and anything but a regular file is refused before it
    is opened: ``open()`` of a FIFO with no writer blocks forever, and a device
    or a socket is no saved measurement. The file is then opened without
    blocking and checked again, so a FIFO put in its place meanwhile is refused
    too.

    Parameters
    ----------
    path : str or Path
        The input file the user named.
    what : str
        What it is, for messages (``"capture file"``, ``"table"``).
    limit : int
        The most bytes read from it.

    Returns
    -------
    LimitedReader
        The open file.

    Raises
    ------
    DesignError
        Missing file, a directory, a FIFO, a device, a socket or any other
        file that is not a regular one, no permission, a file above ``limit``.
    """
    name = shown(path)
    if str(path) == "":
        raise DesignError(f"no {what} given: the name is empty")
    p = Path(path)

    def failed(exc):
        if isinstance(exc, FileNotFoundError):   # a dangling symbolic link too
            return DesignError(f"{what} {name} does not exist")
        if isinstance(exc, ValueError):   # a NUL byte or an unencodable character in the name
            return DesignError(f"cannot open {what} {name}: not a valid file name")
        return DesignError(f"cannot open {what} {name}: {exc.strerror or exc}")

    def refuse_irregular(mode):
        if stat.S_ISREG(mode):
            return
        if stat.S_ISDIR(mode):
            raise DesignError(f"{what} {name} is a directory; give a file")
        kinds = ((stat.S_ISFIFO, "a FIFO (named pipe)"), (stat.S_ISCHR, "a character device"),
                 (stat.S_ISBLK, "a block device"), (stat.S_ISSOCK, "a socket"))
        kind = next((k for test, k in kinds if test(mode)), "not a regular file")
        raise DesignError(f"{what} {name} is {kind}; a regular file is needed (save the data to a file "
                          "and give that)")

    try:
        st = os.stat(p)   # never blocks, unlike open() of a FIFO
    except (OSError, ValueError) as exc:
        raise failed(exc) from None
    refuse_irregular(st.st_mode)
    try:
        # O_NONBLOCK: should the path have become a FIFO since the stat, open() still returns
        fd = os.open(p, os.O_RDONLY | getattr(os, "O_NONBLOCK", 0) | getattr(os, "O_CLOEXEC", 0))
    except (OSError, ValueError) as exc:
        raise failed(exc) from None
    try:
        st = os.fstat(fd)
        refuse_irregular(st.st_mode)
        os.set_blocking(fd, True)
        fh = io.FileIO(fd, "rb", closefd=True)
    except BaseException:
        os.close(fd)   # a refusal (or an interrupt) leaves no descriptor open
        raise
    if st.st_size > limit:
        fh.close()
        raise DesignError(f"{what} {name} is {size_text(st.st_size)}; at most "
                          f"{size_text(limit)} is read: cut or decimate it")
    return LimitedReader(fh, limit, name, what, size=st.st_size)


def check_encoding(head: bytes, name: str, what: str) -> int:
    """Refuse UTF-16/UTF-32 and binary data; return the length of a UTF-8 BOM (0 or 3).

    Parameters
    ----------
    head : bytes
        The file's first bytes.
    name : str
        The file, as messages show it.
    what : str
        What the file is (``capture``).

    Returns
    -------
    int
        The length of the BOM.
    """
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
    """UTF-8 text; undecodable bytes (a Latin-1 degree sign in a header) replaced.

    Parameters
    ----------
    data : bytes
        The bytes.

    Returns
    -------
    str
        The text.
    """
    return data.decode("utf-8", errors="replace")


def read_text(path, what: str, limit: int = MAX_TABLE_BYTES) -> str:
    """The whole text of a small input file (a table, a JSON result), with every
    check of this module.

    Parameters
    ----------
    path : path-like
        The file.
    what : str
        What it is, for the messages.
    limit : int
        The most bytes it may have.

    Returns
    -------
    str
        Its text.
    """
    with open_limited(path, what, limit) as fh:
        head = fh.read(SNIFF_BYTES) or b""
        skip = check_encoding(head, fh.name, what)   # /dev/zero stops here
        data = head + (fh.read() or b"")
    return decode(data[skip:])


# --------------------------------------------------------------------------- writing

# our temporaries carry the writing process id, so a later run knows when they are stale
_TMP_FILE = re.compile(r"^\..+\.(?P<pid>\d+)\.[^.]+\.tmp$")
_TMP_DIR = re.compile(r"^\.(?P<name>.+)\.(?P<kind>new|old)-(?P<pid>\d+)-[^.]+$")


def os_error(action: str, path, exc: OSError) -> DesignError:
    """The one-line error for an ``OSError`` met while doing ``action`` on ``path``: a directory where
    a file was expected, a file where a folder was, else the system's own words.

    Parameters
    ----------
    action : str
        What was being done (``write``, ``read``).
    path : path-like
        Where.
    exc : OSError
        What the system raised.

    Returns
    -------
    DesignError
        The error to raise.
    """
    if isinstance(exc, IsADirectoryError) or exc.errno == errno.EISDIR:
        why = "it is a directory"
    elif isinstance(exc, NotADirectoryError) or exc.errno == errno.ENOTDIR:
        why = "a part of the path is a file, not a directory"
    else:
        why = exc.strerror or str(exc)
    return DesignError(f"cannot {action} {str(path)!r}: {why}")


def ensure_dir(path) -> Path:
    """Create a directory (and parents); a clear :class:`DesignError` if not possible.

    Parameters
    ----------
    path : path-like
        The directory.

    Returns
    -------
    pathlib.Path
        ``path``.
    """
    path = Path(path)
    try:
        path.mkdir(parents=True, exist_ok=True)
    except FileExistsError:
        raise DesignError(f"cannot create directory {str(path)!r}: a file of that name exists") from None
    except OSError as exc:
        raise DesignError(f"cannot create directory {str(path)!r}: {exc.strerror or exc}") from None
    if not os.access(path, os.W_OK):
        raise DesignError(f"cannot write to directory {str(path)!r}: permission denied")
    return path


def check_can_create(path, subdirs=()) -> Path:
    """Fail early, creating nothing, when ``path`` (and ``path/<subdir>``) could
    not be made directories: the nearest existing ancestor must be a writable
    directory, and whatever exists on the way must be a directory.

    Parameters
    ----------
    path : path-like
        The folder to be made.
    subdirs : iterable of str
        Folders to be made inside it.

    Returns
    -------
    pathlib.Path
        ``path``.
    """
    path = Path(path)
    for p in [path / d for d in subdirs] + [path] + list(path.parents):
        if os.path.lexists(p):
            if not p.is_dir():
                raise DesignError(f"cannot create directory {str(p)!r}: a file of that name exists")
            if p == path or p in path.parents:
                if not os.access(p, os.W_OK | os.X_OK):
                    raise DesignError(f"cannot write to directory {str(p)!r}: permission denied")
                break
    return path


_KINDS = ((stat.S_ISLNK, "a symbolic link"), (stat.S_ISDIR, "a directory"), (stat.S_ISFIFO, "a FIFO (named pipe)"),
          (stat.S_ISCHR, "a character device"), (stat.S_ISBLK, "a block device"), (stat.S_ISSOCK, "a socket"))


def _kind(mode: int) -> str:
    """What a file system entry is, for a message: ``a file``, ``a directory``, ``a FIFO (named pipe)``..."""
    return "a file" if stat.S_ISREG(mode) else next((k for test, k in _KINDS if test(mode)), "not a regular file")


def _output_stat(path, what: str) -> tuple:
    """(``path`` as a Path, its ``os.lstat`` or None where nothing is), or one line: no name, not a
    valid name (a NUL byte), or a system error; a parent that is a file is the caller's (None here)."""
    path = Path(path)
    if str(path) == "":
        raise DesignError(f"no {what} given: the name is empty")
    try:
        return path, os.lstat(path)
    except (FileNotFoundError, NotADirectoryError):   # nothing there; a parent that is a file: the caller's
        return path, None
    except OSError as exc:
        raise os_error("write", path, exc) from None
    except ValueError:   # a NUL byte in the name
        raise DesignError(f"cannot write {what} {shown(path)}: not a valid file name") from None


def check_output_file(path, what: str = "output file") -> Path:
    """Before any work: ``path`` may be written, through a temporary file and a
    rename, only over a regular file (or where nothing is); a symbolic link, a
    FIFO, a device, a socket or a directory there is refused in one line, as is
    a folder that cannot be created.

    Parameters
    ----------
    path : path-like
        The file to be written.
    what : str
        What it is, for the message.

    Returns
    -------
    pathlib.Path
        ``path``.
    """
    path, st = _output_stat(path, what)
    if st is not None and not stat.S_ISREG(st.st_mode):
        raise DesignError(f"cannot write {what} {shown(path)}: it is {_kind(st.st_mode)}; give the name of a "
                          "regular file (or of none yet), which is replaced whole")
    check_can_create(path.parent)
    return path


def check_output_folder(path, what: str = "output folder", whole: bool = True) -> Path:
    """Before any work: a folder may be written at ``path``: nothing there yet, or
    a directory. A symbolic link is refused when the folder is replaced ``whole``
    (:func:`publish_folder` would swap the link, not what it points to), and when
    it points to nothing (dangling) or to no directory; with ``whole`` False a
    link to a directory is written through. A file, a FIFO or a device there is
    refused; so is a parent that cannot be created (:func:`check_can_create`).
    Each refusal is one line naming ``what``.

    Parameters
    ----------
    path : path-like
        The folder to be written.
    what : str
        What it is, for the message.
    whole : bool
        The folder is replaced whole (:func:`publish_folder`), not written into.

    Returns
    -------
    pathlib.Path
        ``path``.
    """
    path, st = _output_stat(path, what)
    if st is not None and stat.S_ISLNK(st.st_mode):
        dest = shown(os.readlink(path))
        if not path.exists():
            raise DesignError(f"cannot write {what} {shown(path)}: it is a symbolic link to nothing ({dest}); "
                              "remove it, or give a folder's name")
        if whole or not path.is_dir():
            raise DesignError(f"cannot write {what} {shown(path)}: it is a symbolic link (to {dest}); "
                              + ("the folder is replaced whole: give a folder's name" if whole else
                                 "give a folder's name, or a link to a folder"))
    elif st is not None and not stat.S_ISDIR(st.st_mode):
        raise DesignError(f"cannot write {what} {shown(path)}: it is {_kind(st.st_mode)}, not a folder")
    check_can_create(path.parent)
    return path


def atomic_write(path, data, mode: str = "w") -> Path:
    """Write ``data`` (str or bytes) to ``path`` through a temporary file and rename,
    over a regular file only (:func:`check_output_file`, before any folder is made).

    Parameters
    ----------
    path : path-like
        The file.
    data : str or bytes
        Its content.
    mode : str
        ``"w"`` (text) or ``"wb"`` (bytes).

    Returns
    -------
    pathlib.Path
        The file written.
    """
    path = Path(path)
    check_output_file(path, "file")
    ensure_dir(path.parent)
    binary = isinstance(data, (bytes, bytearray))
    try:
        fd, tmp = tempfile.mkstemp(prefix=f".{path.name}.{os.getpid()}.", suffix=".tmp", dir=path.parent)
    except OSError as exc:
        raise os_error("write", path, exc) from None
    try:
        with os.fdopen(fd, "wb" if binary else "w", encoding=None if binary else "utf-8") as fh:
            fh.write(data)
        os.chmod(tmp, 0o644)
        os.replace(tmp, path)
    except BaseException as exc:
        _remove(tmp)
        if isinstance(exc, OSError):
            raise os_error("write", path, exc) from None
        raise
    return path


def new_folder_beside(target) -> Path:
    """A private, empty staging folder next to ``target`` (same file system, so it
    can be renamed into place), named so that :func:`clean_stale` recognises it.

    Parameters
    ----------
    target : path-like
        The folder the staged one will replace.

    Returns
    -------
    pathlib.Path
        The staging folder.
    """
    target = Path(target)
    ensure_dir(target.parent)
    try:
        stage = Path(tempfile.mkdtemp(prefix=f".{target.name}.new-{os.getpid()}-", dir=target.parent))
        umask = os.umask(0o022)
        os.umask(umask)
        os.chmod(stage, 0o777 & ~umask)   # mkdtemp makes it private; the bundle is not
        return stage
    except OSError as exc:
        raise os_error("write in", target.parent, exc) from None


def publish_folder(staged, target) -> None:
    """Put the finished folder ``staged`` at ``target``, replacing what is there
    in one atomic step where the system allows it; the old content is deleted.

    Parameters
    ----------
    staged : path-like
        The finished folder.
    target : path-like
        Where it goes.
    """
    staged, target = Path(staged), Path(target)
    if os.path.islink(target) or (os.path.lexists(target) and not os.path.isdir(target)):
        # the exchange below would swap a link or a file with the folder, and leave it under the stage's name
        remove_tree(staged)
        check_output_folder(target, "folder")   # says what is there, in one line
        raise DesignError(f"cannot write folder {shown(target)}: it is not a folder")
    try:
        if not os.path.lexists(target):
            os.rename(staged, target)
            return
        if _exchange(staged, target):
            remove_tree(staged)          # now holds the old bundle
            return
        # no atomic exchange here: move the old one aside, the new one in;
        # clean_stale rolls back if we are killed in between
        aside = target.parent / f".{target.name}.old-{os.getpid()}-{staged.name.rsplit('-', 1)[-1]}"
        os.rename(target, aside)
        os.rename(staged, target)
        remove_tree(aside)
    except OSError as exc:
        remove_tree(staged)
        raise os_error("write", target, exc) from None


def link_into(link, target) -> bool:
    """Make ``link`` a relative symbolic link to ``target`` (atomically); False
    where the file system has no symbolic links (the caller then copies).

    Parameters
    ----------
    link : path-like
        The link made.
    target : path-like
        What it points to.

    Returns
    -------
    bool
        The link was made.
    """
    link, target = Path(link), Path(target)
    rel = os.path.relpath(target, link.parent)
    if link.is_symlink() and os.readlink(link) == rel:
        return True
    if link.is_dir() and not link.is_symlink():
        raise DesignError(f"cannot write {str(link)!r}: it is a directory")
    tmp = link.parent / f".{link.name}.{os.getpid()}.link.tmp"
    try:
        _remove(tmp)
        os.symlink(rel, tmp)
    except OSError as exc:
        if exc.errno in (errno.EPERM, errno.EOPNOTSUPP, errno.ENOSYS):
            return False
        raise os_error("write", link, exc) from None
    try:
        os.replace(tmp, link)
    except OSError as exc:
        _remove(tmp)
        raise os_error("write", link, exc) from None
    return True


def clean_stale(folder) -> None:
    """Remove our temporaries in ``folder`` whose writing process is gone; an
    interrupted two-rename swap (old moved aside, new not in place) is rolled back.

    Parameters
    ----------
    folder : path-like
        The folder our temporaries may be in.
    """
    folder = Path(folder)
    try:
        entries = list(os.scandir(folder))
    except OSError:
        return
    for e in entries:
        m = _TMP_DIR.match(e.name) or _TMP_FILE.match(e.name)
        if not m or _alive(int(m.group("pid"))):
            continue
        path = Path(e.path)
        if m.re is _TMP_DIR and m.group("kind") == "old" and not os.path.lexists(folder / m.group("name")):
            try:
                os.rename(path, folder / m.group("name"))
                continue
            except OSError:
                pass
        if e.is_dir(follow_symlinks=False):
            remove_tree(path)
        else:
            _remove(path)


def _alive(pid: int) -> bool:
    if pid == os.getpid():
        return True
    try:
        os.kill(pid, 0)
    except ProcessLookupError:
        return False
    except OSError:
        return True   # exists, owned by someone else
    return True


def _exchange(a: Path, b: Path) -> bool:
    """Atomically swap two paths (Linux renameat2 RENAME_EXCHANGE); False if unsupported."""
    try:
        import ctypes
        libc = ctypes.CDLL(None, use_errno=True)
        fn = libc.renameat2
    except (OSError, AttributeError):
        return False
    at_fdcwd, rename_exchange = -100, 2
    fn.argtypes = [ctypes.c_int, ctypes.c_char_p, ctypes.c_int, ctypes.c_char_p, ctypes.c_uint]
    if fn(at_fdcwd, os.fsencode(a), at_fdcwd, os.fsencode(b), rename_exchange) == 0:
        return True
    err = ctypes.get_errno()
    if err in (errno.ENOSYS, errno.EINVAL, errno.EOPNOTSUPP):
        return False
    raise OSError(err, os.strerror(err), str(b))


def _remove(path) -> None:
    try:
        os.unlink(path)
    except OSError:
        pass


def remove_tree(path) -> None:
    """Remove a folder of ours and everything in it; a symbolic link or a file there is
    unlinked (``rmtree`` refuses a link, and would leave it).

    Parameters
    ----------
    path : path-like
        The folder.
    """
    if os.path.islink(path) or (os.path.lexists(path) and not os.path.isdir(path)):
        _remove(path)
        return
    shutil.rmtree(path, ignore_errors=True)
