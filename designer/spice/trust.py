"""Decks are data: a stranger's ngspice deck, read and checked by us before
ngspice sees it.

``check-design`` runs the decks of pull requests on CI runners. ngspice reads
more than a circuit from a deck: a ``.control`` block (or a deck titled
``*ng_script``, or a ``*#`` line) is a script with ``shell``, ``write`` and
``source``; ``.include`` and ``.lib`` open any file; XSPICE models read files
named in their parameters; ``.osdi`` loads compiled code. :func:`expand_deck`
reads the deck and every file it reaches (``.include``/``.inc``, ``.lib FILE
SECTION``, nested, relative to the including file or absolute), each with the
bounded reader of :mod:`designer.core.fileio`, and

- refuses a file that resolves (symbolic links followed) outside ``root``,
  the spec's folder tree;
- refuses every line that would make ngspice run a command or open a file:
  ``.control``/``.endc`` in any spelling ngspice accepts (any case, leading
  spaces, tabs or extra dots, a word that merely starts so, as ``.controlx``
  does for ngspice), a ``*#`` command line, a script-mode title
  (``*ng_script``), ``.osdi``, and model parameters that name files
  (:data:`FILE_PARAMETERS`); continuation lines (``+``) are checked alone and
  joined;
- inlines every included file (a ``.lib`` call: only its section), so the
  text handed to ngspice is the whole circuit and ngspice itself opens no file
  of the user's (nothing can change between our check and its read).

Every refusal is one :class:`~designer.core.errors.DesignError` line naming the
file and line. What ngspice accepts was measured on Debian's ngspice 39:
``.controlx``, `` .CONTROL`` and a tab before it open a control block; a
``*#`` line runs as a command; ``..control``, ``. control`` and a control word
split over a continuation line do not (refused here all the same).
"""

from __future__ import annotations

import os
import re
from dataclasses import dataclass
from pathlib import Path

from ..core.errors import DesignError
from ..core.fileio import MIB, read_text, shown

__all__ = ["MAX_TOTAL_BYTES", "check_deck_text", "expand_deck"]

#: the most files one deck may reach, the deepest nesting, and their text in all
MAX_FILES, MAX_DEPTH, MAX_TOTAL_BYTES = 256, 16, 16 * MIB
#: model and instance parameters of ngspice's XSPICE code models that name a file to read
FILE_PARAMETERS = ("file", "input_file", "state_file", "table_file")

_DOT = re.compile(r"^\.+\s*([a-z_]\w*)")
_FILE_PARAM = re.compile(r"(?<![\w.])(" + "|".join(FILE_PARAMETERS) + r")\s*=", re.I)
#: why each refused dot-command word is refused (matched as a prefix, as ngspice does)
_REFUSED = (("control", "a .control block is an ngspice script (it can run shell commands and write files)"),
            ("endc", "a .endc line closes an ngspice script block"),
            ("osdi", ".osdi loads compiled model code"))
_HINT = "check-design runs a deck's own analysis and .meas lines; decks are data (see the README's trust boundary)"


@dataclass(frozen=True)
class _Line:
    file: Path
    number: int       #: 1-based line in its file
    text: str


class _Reader:
    """One deck's expansion: the files read so far, their sizes, the root."""

    def __init__(self, root: Path | None, shown_base: Path | None):
        self.root = None if root is None else Path(root).resolve()
        self.base = shown_base
        self.files = 0
        self.bytes = 0

    def name(self, path: Path) -> str:
        """A file as messages show it: relative to the spec's folder when inside it."""
        if self.base is not None:
            try:
                return shown(path.relative_to(self.base))
            except ValueError:
                pass
        return shown(path)

    def refuse(self, line: _Line, why: str) -> DesignError:
        return DesignError(f"{self.name(line.file)}:{line.number}: {why}; {_HINT}")

    def resolve(self, name: str, line: _Line) -> Path:
        """A file named in ``line``: relative to the including file's folder, inside the root."""
        if not name:
            raise self.refuse(line, "an include without a file name")
        raw = Path(os.path.expanduser(name))
        target = raw if raw.is_absolute() else line.file.parent / raw
        try:
            real = target.resolve(strict=True)
        except FileNotFoundError:
            raise DesignError(f"{self.name(line.file)}:{line.number}: included file {shown(name)} does not "
                              "exist") from None
        except (OSError, RuntimeError) as exc:   # a symlink loop, a file name the system refuses
            raise DesignError(f"{self.name(line.file)}:{line.number}: cannot resolve included file "
                              f"{shown(name)} ({exc})") from None
        if self.root is not None and not real.is_relative_to(self.root):
            raise self.refuse(line, f"included file {shown(name)} resolves to {shown(real)}, outside "
                                    f"{shown(self.root)} (every file a deck reaches must lie inside it)")
        return real

    def read(self, path: Path, depth: int, line: _Line | None) -> list:
        """The lines of ``path``, checked."""
        if depth > MAX_DEPTH:
            raise self.refuse(line, f"includes nested deeper than {MAX_DEPTH} levels (a loop?)")
        self.files += 1
        if self.files > MAX_FILES:
            raise self.refuse(line, f"the deck reaches more than {MAX_FILES} files")
        what = "deck" if line is None else "included file"
        text = read_text(path, what, MAX_TOTAL_BYTES)
        self.bytes += len(text)
        if self.bytes > MAX_TOTAL_BYTES:
            raise DesignError(f"{self.name(path)}: the deck and its includes hold more than "
                              f"{MAX_TOTAL_BYTES // MIB} MiB of text")
        lines = [_Line(path, i, t) for i, t in enumerate(text.splitlines(), 1)]
        check_lines(lines, self, title=line is None)
        return lines


def _word(text: str) -> str | None:
    """The dot-command word of a line (``.INCLUDE`` -> ``include``), or None."""
    m = _DOT.match(text.lstrip().lower())
    return m.group(1) if m else None


def _logical(lines: list) -> list:
    """(physical lines, joined text) of each logical line: a ``+`` line continues the one before."""
    out = []
    for ln in lines:
        s = ln.text.lstrip()
        if s.startswith("+") and out:
            group, text = out[-1]
            out[-1] = (group + [ln], text + " " + s[1:])
        else:
            out.append(([ln], ln.text))
    return out


def check_lines(lines: list, reader: _Reader, title: bool) -> None:
    """Refuse what makes ngspice run a command or open a file, in one file's lines
    (``title``: the first line is the deck's title)."""
    for k, ln in enumerate(lines):
        s = ln.text.lstrip().lower()
        if s.startswith("*ng_script"):
            raise reader.refuse(ln, "a deck titled *ng_script runs as an ngspice script")
        if s.startswith("*#"):
            raise reader.refuse(ln, "a '*#' line is an ngspice command")
        if title and k == 0:
            continue
        for piece in (s, s[1:].lstrip() if s.startswith("+") else ""):
            word = _word(piece)
            for prefix, why in _REFUSED:
                if word is not None and word.startswith(prefix):
                    raise reader.refuse(ln, why)
    for group, text in _logical(lines[1:] if title else lines):
        first = group[0]
        s = text.lstrip().lower()
        if s.startswith("*"):
            continue
        glued = _word(s.replace(" ", "")) or ""   # a word split over a continuation line
        for prefix, why in _REFUSED:
            if glued.startswith(prefix) or (_word(s) or "").startswith(prefix):
                raise reader.refuse(first, why)
        m = _FILE_PARAM.search(_strip_comment(text))
        if m:
            raise reader.refuse(first, f"the parameter {m.group(1).lower()}= makes an XSPICE model read a "
                                       "file; give the data in the deck itself (e.g. a PWL source)")


def _strip_comment(text: str) -> str:
    """A line without its trailing ``;`` or `` $ `` comment (ngspice's inline comments)."""
    return re.split(r";|\s\$\s", text, maxsplit=1)[0]


def _argument(text: str, word: str) -> list:
    """The arguments after a dot-command: quoted or plain words (``.lib "my lib.l" tt``)."""
    rest = re.sub(r"^\s*\.+\s*" + re.escape(word), "", _strip_comment(text), count=1, flags=re.I).strip()
    return [a or b for a, b in re.findall(r"[\"']([^\"']*)[\"']|(\S+)", rest)]


def _expand(lines: list, reader: _Reader, depth: int, included: bool) -> list:
    """The lines with every include and library call replaced by the text it names."""
    out = []
    for group, text in _logical(lines):
        first = group[0]
        word = _word(text)
        if word is None or not (word.startswith("inc") or word.startswith("lib")):
            if not (included and word == "end"):   # an included file's .end would end the whole deck
                out.extend(group)
            continue
        args = _argument(text, word)
        if word.startswith("inc"):
            if len(args) != 1:
                raise reader.refuse(first, f".{word} takes one file name, got {len(args)}")
            path = reader.resolve(args[0], first)
            out.extend(_expand(reader.read(path, depth + 1, first), reader, depth + 1, True))
        else:
            if len(args) != 2:
                raise reader.refuse(first, f".{word} in a deck takes a file and a section name "
                                           f"(.lib models.lib tt), got {len(args)} words")
            path = reader.resolve(args[0], first)
            section = _section(reader.read(path, depth + 1, first), args[1], path, reader, first)
            out.extend(_expand(section, reader, depth + 1, True))
    return out


def _section(lines: list, name: str, path: Path, reader: _Reader, call: _Line) -> list:
    """The lines of library section ``name`` (between ``.lib name`` and ``.endl``)."""
    inside, out = False, []
    for ln in lines:
        word = _word(ln.text)
        if not inside:
            if word is not None and word.startswith("lib") and [a.lower() for a in _argument(ln.text, word)] \
                    == [name.lower()]:
                inside = True
            continue
        if word is not None and word.startswith("endl"):
            return out
        out.append(ln)
    if inside:
        raise reader.refuse(call, f"section {shown(name)} of {reader.name(path)} has no .endl")
    raise reader.refuse(call, f"library {reader.name(path)} has no section {shown(name)}")


def expand_deck(path, root=None) -> str:
    """The deck at ``path`` as ngspice will be given it: every ``.include`` and
    ``.lib`` inlined, every line checked (see the module docstring).

    Parameters
    ----------
    path : path-like
        The deck file.
    root : path-like, optional
        The folder every file the deck reaches must resolve inside (the spec's
        folder); None: anywhere (``check-design --allow-outside``, trusted use).

    Returns
    -------
    str
        The expanded deck, ending in a newline ("" for an empty file).

    Raises
    ------
    DesignError
        One line: the file and line at fault and why.
    """
    path = Path(path)
    base = None if root is None else Path(root)
    reader = _Reader(root, base)
    real = path.resolve()
    if reader.root is not None and not real.is_relative_to(reader.root):
        raise DesignError(f"deck {shown(path)} resolves to {shown(real)}, outside {shown(reader.root)}")
    lines = reader.read(real, 0, None)
    if not lines:
        return ""
    body = _expand(lines[1:], reader, 0, False)
    return "\n".join([lines[0].text] + [ln.text for ln in body]) + "\n"


def check_deck_text(text: str, name: str = "deck") -> None:
    """Refuse a deck's text that would run a command or open a file (the same
    rules, for a deck already in memory: no file may be included).

    Parameters
    ----------
    text : str
        The deck's text.
    name : str
        What the deck is called in an error message.

    Raises
    ------
    DesignError
        One line: the line at fault and why.
    """
    lines = [_Line(Path(name), i, t) for i, t in enumerate(text.splitlines(), 1)]
    reader = _Reader(None, None)
    check_lines(lines, reader, title=True)
    for group, joined in _logical(lines[1:]):
        first, word = group[0], _word(joined)
        if word is not None and (word.startswith("inc") or word.startswith("lib")):
            raise reader.refuse(first, f".{word} in a deck given as text: nothing may be included")
