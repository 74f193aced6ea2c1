"""A request's inputs as the command line its command parses.

``{"fc": 3500, "zeta": "0.2", "r-series": "E24"}`` becomes ``--fc 3500 --zeta
0.2 --r-series E24``: every key is an option's name (dashes or underscores),
every value what a user types after it (numbers, engineering notation in
strings; ``true`` for a switch, a list for an option that takes several
values). The command's own parser then checks them, so a refusal is its one
line. What a page must not choose is refused here in one line: where files go
and how output is printed (the server sets those), the trust settings of
check-design. An option that names a file on the command line (``plant-model``,
``plant-json``...) takes the file's *content* here, written into the request's
private folder under a fixed name: no path a user gives is ever opened.
"""

from __future__ import annotations

import json
import os
import re
from typing import NamedTuple

from ..core.errors import DesignError

#: options the server sets itself (files, output form) or that would reach past a request's folder
REFUSED = ("out", "json", "no-files", "plot", "help", "version", "junit", "summary", "root", "allow-outside",
           "jobs", "update-golden", "timeout", "fail-on-check", "no-fail")
#: options whose value is a file's content -> the name it is written under in the request's folder
FILE_OPTIONS = {"plant-json": "plant-result.json", "plant-model": "plant-model.json",
                "parts-json": "parts-result.json", "plant-capture": "plant-capture.csv",
                "against": "design-result.json"}
#: most bytes of a request's JSON body (its options; a model or result.json given inline included)
MAX_JSON_BYTES = 4 * 1024 * 1024
_KEY = re.compile(r"^[a-z][a-z0-9-]{0,40}$")


def option_name(key) -> str:
    """``"r_series"`` -> ``"--r-series"``, after checking it is an option's name at all."""
    name = str(key).strip().lstrip("-").replace("_", "-").lower()
    if not _KEY.match(name):
        raise DesignError(f"{str(key)[:60]!r} is not an option name (letters, digits and dashes, as --help lists "
                          "them)")
    if name in REFUSED:
        raise DesignError(f"--{name} is set by the web page itself, not by a request")
    return "--" + name


def build_argv(options: dict, tmp: str | None, traits: "Traits | None" = None) -> list:
    """The argument list of ``options`` (see the module docstring).

    Parameters
    ----------
    options : dict
        Option name -> value, as the request gave them.
    tmp : str or None
        The request's private folder, for the options of :data:`FILE_OPTIONS`.
    traits : Traits, optional
        The command's options (:func:`parser_traits`): only those, spelt out in full (argparse
        would take ``--o`` for ``--out``), each with the values it takes. None: any name.
    """
    if not isinstance(options, dict):
        raise DesignError("the request's body must be a JSON object of option names and values, "
                          'e.g. {"fc": 3500, "zeta": 0.2}')
    t = traits or Traits(set(), set(), set(), None)
    argv = []
    for key, value in options.items():
        opt = option_name(key)
        if t.known is not None and opt not in t.known:
            raise DesignError(f"unrecognized arguments: {opt} (options by their full names, as --help lists them)")
        if value is None:
            continue
        if opt in t.switches:
            # a form's field or a query string says it in words
            word = value if isinstance(value, bool) else str(value).strip().lower() if isinstance(value, str) else None
            if word not in (True, False, "true", "false", "on", "off", ""):
                raise DesignError(f"{opt} is a switch: true or false, got {json.dumps(value)[:40]}")
            if word in (True, "true", "on"):
                argv.append(opt)
            continue
        if opt[2:] in FILE_OPTIONS:
            argv += [opt, write_content(tmp, FILE_OPTIONS[opt[2:]], value, opt)]
            continue
        values = value if isinstance(value, list) else [value]
        if len(values) != 1 and t.known is not None and opt not in t.appended and opt not in t.multi:
            raise DesignError(f"{opt} takes one value, got {len(values)}")
        words = [_word(v, opt) for v in values]
        if opt in t.appended:
            for w in words:
                argv += [opt, w]
        else:
            argv += [opt, *words]
    return argv


def _word(value, opt: str) -> str:
    """One value as typed: a string as it is, a number as Python writes it."""
    if isinstance(value, bool) or isinstance(value, (dict, list)):
        raise DesignError(f"{opt} takes a number or a text such as 4k7, got {json.dumps(value)[:40]}")
    if isinstance(value, float):
        return repr(value)
    return str(value)


def write_content(tmp: str | None, name: str, value, opt: str) -> str:
    """A file option's content (text, or a JSON object or list written as JSON) in the
    request's folder; returns its path."""
    if tmp is None:
        raise DesignError(f"{opt} is not taken by this request")
    if isinstance(value, (dict, list)):
        value = json.dumps(value)
    if not isinstance(value, str):
        raise DesignError(f"{opt} takes the file's content: a JSON object or a text")
    path = os.path.join(tmp, name)
    with open(path, "w", encoding="utf-8") as fh:
        fh.write(value)
    return path


class Traits(NamedTuple):
    """A command's options as its parser defines them."""

    switches: set    #: taking no value (``--no-sim``)
    appended: set    #: given once per value (``--limit``)
    multi: set       #: taking several values after one flag (``--window T0 T1``, ``--methods``)
    known: set | None  #: every option string (None: not checked)


def parser_traits(parser) -> Traits:
    """The :class:`Traits` of an argparse parser."""
    import argparse
    switches, appended, multi, known = set(), set(), set(), set()
    for action in parser._actions:   # argparse has no public list of its actions
        for opt in action.option_strings:
            known.add(opt)
            if action.nargs == 0:
                switches.add(opt)
            elif isinstance(action, argparse._AppendAction):
                appended.add(opt)
            elif action.nargs not in (None, "?"):
                multi.add(opt)
    return Traits(switches, appended, multi, known)
