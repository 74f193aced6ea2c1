"""A ``check-design`` spec file as a YAML document: read with budgets, every key at its
line, its paths kept inside a folder.

A spec may come from a stranger (a pull request): it is data, and may reach
nothing outside its folder (the README's trust boundary). :func:`parse_yaml`
reads the file (at most :data:`MAX_SPEC_BYTES`, UTF-8) with PyYAML's safe
loader, with budgets (:func:`designer.check.yamlread.compose`), into a
:class:`_Doc`: the data and the line of every key. Its accessors refuse in
one line, ``file:line: what is wrong, and what is allowed``; an unknown key
names the allowed keys and the closest one (:func:`closest`). Paths (``deck``,
``golden.file``, the ``json`` files) are relative to the spec file and must
resolve (links followed) inside its folder, or the ``root`` given
(``--root``), unless ``allow_outside`` (:meth:`_Doc.resolve`,
:meth:`_Doc.inside`). What the keys mean is :mod:`designer.check.spec`'s and
:mod:`designer.check.sections`'.
"""

from __future__ import annotations

import difflib
from pathlib import Path

from ..core.errors import DesignError
from ..core.fileio import MIB, read_text, shown
from ..core.i18n import N_, Message
from .yamlread import compose

__all__ = ["MAX_SPEC_BYTES", "WIDER", "parse_yaml"]

#: a spec file is small: at most this many bytes are read
MAX_SPEC_BYTES = 1 * MIB


def closest(key, allowed) -> str:
    """The allowed key nearest to ``key`` (for a typo)."""
    best = difflib.get_close_matches(str(key), list(allowed), n=1, cutoff=0.0)
    return best[0] if best else allowed[0]


#: the command line's advice when a spec's path leaves its folder (a front end without these options says its own)
WIDER = "check-design --root DIR widens the folder, --allow-outside lifts it for trusted specs"


class _Doc:
    """The parsed YAML with the line of every key, for one-line refusals."""

    def __init__(self, path: Path, data, lines: dict):
        self.path, self.data, self.lines = path, data, lines

    def where(self, keys) -> str:
        keys = tuple(k if isinstance(k, int) and not isinstance(k, bool) else str(k) for k in keys)
        while keys and keys not in self.lines:
            keys = keys[:-1]
        return f"{shown(self.path)}:{self.lines.get(keys, 1)}"

    def error(self, keys, message: str) -> DesignError:
        # a typed message (one carrying a parameter, designer.core.i18n.Message) stays typed behind its place
        if isinstance(message, Message):
            return DesignError(Message(N_("{where}: {message}"), where=self.where(keys), message=message))
        return DesignError(f"{self.where(keys)}: {message}")

    def mapping(self, keys, allowed, value=None) -> dict:
        """The mapping at ``keys`` (None: empty), every key text and allowed."""
        value = self.get(keys) if value is None else value
        if value is None:
            return {}
        label = ".".join(map(str, keys)) or "the spec"
        if not isinstance(value, dict):
            raise self.error(keys, f"{label} must be a mapping of {', '.join(allowed)}; got {kind_of(value)}")
        for k in value:
            if k not in allowed:
                raise self.error(tuple(keys) + (k,), f"unknown key {str(k)!r} in {label}; allowed: "
                                 f"{', '.join(allowed)}; closest: {closest(k, allowed)!r}")
        return value

    def get(self, keys):
        v = self.data
        for k in keys:
            if not isinstance(v, dict):
                return None
            v = v.get(k)
        return v

    #: the folder every path of the spec must resolve inside (the spec's own); None: anywhere
    root: Path | None = None

    def resolve(self, keys) -> Path:
        """A path in the spec, relative to the spec file's folder, which it must not
        leave (symbolic links followed) unless ``--allow-outside`` (:attr:`root` None)."""
        value = self.get(keys)
        label = ".".join(map(str, keys))
        if not isinstance(value, str) or not value.strip():
            raise self.error(keys, f"{label} must be a file name, got {kind_of(value)}")
        if self.root is not None and (Path(value).is_absolute() or value.startswith("~")):
            raise self.error(keys, f"{label} {shown(value)} is an absolute path: paths in a spec are relative "
                             f"to its folder and stay inside {shown(self.root)} ({WIDER})")
        return self.inside(keys, self.path.parent / value)

    def inside(self, keys, path: Path) -> Path:
        """``path`` (named at ``keys``), refused when it resolves outside :attr:`root`."""
        if self.root is None:
            return path
        label = ".".join(map(str, keys))
        try:
            real = path.resolve(strict=False)
        except (OSError, RuntimeError) as exc:   # a symbolic link loop
            raise self.error(keys, f"{label} {shown(path)} cannot be resolved ({exc})") from None
        if not real.is_relative_to(self.root):
            raise self.error(keys, f"{label} {shown(path)} resolves to {shown(real)}, outside "
                             f"{shown(self.root)}: paths in a spec stay inside it ({WIDER})")
        return path


def kind_of(value) -> str:
    if value is None:
        return "nothing"
    if isinstance(value, (dict, list)):
        return f"a {'mapping' if isinstance(value, dict) else 'list'}"
    return repr(value) if len(repr(value)) <= 40 else type(value).__name__


def parse_yaml(path) -> _Doc:
    """Read a spec file: text (at most :data:`MAX_SPEC_BYTES`, UTF-8), YAML
    (PyYAML's SafeLoader, bounded by :func:`designer.check.yamlread.compose`:
    no recursive alias, at most 10,000 nodes with the aliases
    expanded, 64 levels, no key twice in a mapping, scalars of
    at most 4096 characters, 65536 for
    ``description``; merge keys ``<<`` work), a mapping; every problem one
    line naming the file and line.

    Parameters
    ----------
    path : path-like
        The spec file.

    Returns
    -------
    _Doc
        The document: its mapping, with the line of every key.
    """
    import yaml
    path = Path(path)
    text = read_text(path, "spec file", MAX_SPEC_BYTES)
    try:
        data, lines = compose(text, path)
    except yaml.YAMLError as exc:
        mark = getattr(exc, "problem_mark", None) or getattr(exc, "context_mark", None)
        line = mark.line + 1 if mark is not None else 1
        what = getattr(exc, "problem", None) or str(exc).splitlines()[0]
        raise DesignError(f"{shown(path)}:{line}: not valid YAML ({what})") from None
    if not isinstance(data, dict):
        raise DesignError(f"{shown(path)}:1: a spec is a mapping of keys (kind:, checks:, ...); got "
                          f"{kind_of(data)}")
    return _Doc(path, data, lines)
