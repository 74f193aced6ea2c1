"""Writing files without ever leaving a half-written one or a mixed bundle.

- :func:`atomic_write`: one file, through a temporary file beside it and a rename.
- :func:`publish_folder`: a whole folder (a design's report bundle) written
  elsewhere first, then swapped in with one atomic exchange of directories
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
import os
import re
import shutil
import tempfile
from pathlib import Path

from .errors import DesignError

# our temporaries carry the writing process id, so a later run knows when they are stale
_TMP_FILE = re.compile(r"^\..+\.(?P<pid>\d+)\.[^.]+\.tmp$")
_TMP_DIR = re.compile(r"^\.(?P<name>.+)\.(?P<kind>new|old)-(?P<pid>\d+)-[^.]+$")


def os_error(action: str, path, exc: OSError) -> DesignError:
    if isinstance(exc, IsADirectoryError) or exc.errno == errno.EISDIR:
        why = "it is a directory"
    elif isinstance(exc, NotADirectoryError) or exc.errno == errno.ENOTDIR:
        why = "a part of the path is a file, not a directory"
    else:
        why = exc.strerror or str(exc)
    return DesignError(f"cannot {action} {str(path)!r}: {why}")


def ensure_dir(path) -> Path:
    """Create a directory (and parents); a clear :class:`DesignError` if not possible."""
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
    directory, and whatever exists on the way must be a directory."""
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


def atomic_write(path, data, mode: str = "w") -> Path:
    """Write ``data`` (str or bytes) to ``path`` through a temporary file and rename."""
    path = Path(path)
    ensure_dir(path.parent)
    if path.is_dir():
        raise DesignError(f"cannot write {str(path)!r}: it is a directory")
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
    can be renamed into place), named so that :func:`clean_stale` recognises it."""
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
    in one atomic step where the system allows it; the old content is deleted."""
    staged, target = Path(staged), Path(target)
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
    where the file system has no symbolic links (the caller then copies)."""
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
    interrupted two-rename swap (old moved aside, new not in place) is rolled back."""
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
    shutil.rmtree(path, ignore_errors=True)
