"""Writing files without ever leaving a half-written one: write a temporary
file next to the target, then rename it into place (atomic on POSIX)."""

from __future__ import annotations

import os
import tempfile
from pathlib import Path

from .errors import DesignError


def ensure_dir(path) -> Path:
    """Create a directory (and parents); a clear :class:`DesignError` if not possible."""
    path = Path(path)
    try:
        path.mkdir(parents=True, exist_ok=True)
    except OSError as exc:
        raise DesignError(f"cannot create directory {str(path)!r}: {exc.strerror or exc}") from None
    if not os.access(path, os.W_OK):
        raise DesignError(f"cannot write to directory {str(path)!r}: permission denied")
    return path


def atomic_write(path, data, mode: str = "w") -> Path:
    """Write ``data`` (str or bytes) to ``path`` through a temporary file and rename."""
    path = Path(path)
    ensure_dir(path.parent)
    binary = isinstance(data, (bytes, bytearray))
    try:
        fd, tmp = tempfile.mkstemp(prefix=f".{path.name}.", suffix=".tmp", dir=path.parent)
    except OSError as exc:
        raise DesignError(f"cannot write {str(path)!r}: {exc.strerror or exc}") from None
    try:
        with os.fdopen(fd, "wb" if binary else "w", encoding=None if binary else "utf-8") as fh:
            fh.write(data)
        os.chmod(tmp, 0o644)
        os.replace(tmp, path)
    except BaseException:
        try:
            os.unlink(tmp)
        except OSError:
            pass
        raise
    return path
