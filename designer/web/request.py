"""A request's inputs as the command line its command parses.

``{"fc": 3500, "zeta": "0.2", "r-series": "E24"}`` becomes ``--fc=3500
--zeta=0.2 --r-series=E24``: every key is an option's name (dashes or
underscores), every value what a user types after it (numbers, engineering
notation in strings; ``true`` for a switch, a list for an option that takes
several values). The command's own parser then checks them, so a refusal is its
one line. What a page must not choose is refused here in one line: where files
go and how output is printed (the server sets those), the processes and
addresses a run uses (``jobs``, ``dask``, ``timeout``), the trust settings of
check-design. An option that names a file on the command line (``plant-model``,
``plant-json``...) takes the file's *content* here, written into the request's
private folder under a fixed name: no path a user gives is ever opened.

Values are values: each JSON type is checked against what the option takes (a
number or a text for a valued option, a boolean for a switch, a list only where
the option repeats or takes several values, an object only as a file's content),
a single value is joined to its option (``--zeta=--help`` is the value
``--help``, which the command refuses), and a word of a several-value option
that begins with ``-`` is refused unless it is a number, so nothing a request
sends can become an option, ``--help`` and ``--version`` included (a worker
must never exit). :func:`parse_json` bounds the JSON's nesting and refuses text
that is not Unicode (a lone surrogate), before any of it is used.
"""

from __future__ import annotations

import decimal
import json
import math
import os
import re
from typing import NamedTuple

from ..core.errors import DesignError

__all__ = ["FILE_OPTIONS", "MAX_DEPTH", "MAX_JSON_BYTES", "REFUSED", "SERVERS_OWN", "Traits", "build_argv",
           "check_text", "check_value", "option_name", "parse_json", "parser_traits", "split_language",
           "value_text", "write_content"]

#: options the server sets itself (files, output form) or that would reach past a request's folder
REFUSED = ("out", "json", "no-files", "plot", "help", "version", "junit", "summary", "root", "allow-outside",
           "jobs", "dask", "spice-jobs", "timeout", "fail-on-check", "no-fail")
#: of those, the processes, addresses and deadlines of a run: the server's (designer-web --jobs, --timeout)
SERVERS_OWN = ("jobs", "dask", "spice-jobs", "timeout")
#: options whose value is a file's content -> the name it is written under in the request's folder
FILE_OPTIONS = {"plant-json": "plant-result.json", "plant-model": "plant-model.json",
                "parts-json": "parts-result.json", "plant-capture": "plant-capture.csv",
                "against": "design-result.json", "validate": "validation-capture.csv"}
#: most bytes of a request's JSON body (its options; a model or result.json given inline included)
MAX_JSON_BYTES = 4 * 1024 * 1024
#: deepest nesting of a request's JSON (a model's JSON is 4 deep; Python's own parser fails near 1000)
MAX_DEPTH = 64
_KEY = re.compile(r"^[a-z][a-z0-9-]{0,40}$")
#: a word beginning with "-" that the commands' parsers read as a number (designer.cli.common.OneLineParser)
_NEGATIVE = re.compile(r"^-\.?\d")
_FORM_EXAMPLE = 'e.g. {"fc": 3500, "zeta": 0.2}'


def parse_json(raw: bytes):
    """A request's JSON body, checked before any of it is used.

    Parameters
    ----------
    raw : bytes
        The body; empty is ``{}``.

    Returns
    -------
    object
        The parsed JSON.

    Raises
    ------
    DesignError
        Not UTF-8, not JSON, nested deeper than :data:`MAX_DEPTH`, or holding a
        text that is not Unicode (a lone surrogate such as ``"\\ud800"``): one line.
    """
    try:
        text = (raw or b"{}").decode("utf-8")
    except UnicodeDecodeError as exc:
        raise DesignError(f"the request's body is not UTF-8 (byte {exc.start}): send JSON in UTF-8") from None
    try:
        value = json.loads(text)
    except RecursionError:
        raise DesignError(f"the request's JSON is nested too deeply: at most {MAX_DEPTH} levels") from None
    except ValueError as exc:
        raise DesignError(f"the request's body is not JSON: {exc}") from None
    check_value(value)
    return value


def split_language(options):
    """A request's ``lang`` (the page's language) apart from its other options.

    Parameters
    ----------
    options : dict or object
        The request's options (anything else is returned as it is, for its own refusal).

    Returns
    -------
    tuple
        (the other options, the language checked by :func:`designer.core.i18n.check_language`, or None).
    """
    from ..core.i18n import check_language
    if not isinstance(options, dict) or "lang" not in options:
        return options, None
    rest = dict(options)
    lang = rest.pop("lang")
    return rest, check_language(lang if isinstance(lang, str) else repr(lang))


def check_value(value) -> None:
    """Refuse (one line) JSON nested deeper than :data:`MAX_DEPTH` or holding a text
    that is no Unicode (a lone surrogate): every later step may then write and print it.

    Parameters
    ----------
    value : object
        The request's decoded JSON.
    """
    todo = [(value, 1)]
    while todo:
        v, depth = todo.pop()
        if isinstance(v, (dict, list)):
            if depth > MAX_DEPTH:
                raise DesignError(f"the request's JSON is nested too deeply: at most {MAX_DEPTH} levels")
            items = list(v.items()) if isinstance(v, dict) else [(None, x) for x in v]
            for k, x in items:
                if k is not None:
                    check_text(k)
                todo.append((x, depth + 1))
        elif isinstance(v, str):
            check_text(v)


def check_text(text: str) -> str:
    """``text`` when it encodes as UTF-8, else a one-line refusal naming where it breaks.

    Parameters
    ----------
    text : str
        A text of the request.

    Returns
    -------
    str
        ``text`` unchanged.
    """
    try:
        text.encode("utf-8")
    except UnicodeEncodeError as exc:
        raise DesignError(f"a text of the request is not Unicode: a lone surrogate at character {exc.start} of "
                          f"{text[:exc.start][-20:]!r}...; send UTF-8 text") from None
    return text


def option_name(key) -> str:
    """``"r_series"`` -> ``"--r-series"``, after checking it is an option's name at all.

    Parameters
    ----------
    key : str
        A field or option name of the request.

    Returns
    -------
    str
        The option, ``--`` and the name.
    """
    name = str(key).strip().lstrip("-").replace("_", "-").lower()
    if not _KEY.match(name):
        raise DesignError(f"{str(key)[:60]!r} is not an option name (letters, digits and dashes, as --help lists "
                          "them)")
    if name in SERVERS_OWN:
        raise DesignError(f"--{name} is the server's own setting: a request does not choose processes, addresses "
                          "or deadlines")
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

    Returns
    -------
    list of str
        The command's arguments.
    """
    if not isinstance(options, dict):
        raise DesignError("the request's body must be a JSON object of option names and values, " + _FORM_EXAMPLE)
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
                raise DesignError(f"{opt} is a switch: true or false, got {_shown(value)}")
            if word in (True, "true", "on"):
                argv.append(opt)
            continue
        if opt[2:] in FILE_OPTIONS:
            argv.append(f"{opt}={write_content(tmp, FILE_OPTIONS[opt[2:]], value, opt)}")
            continue
        several = opt in t.appended or opt in t.multi
        if isinstance(value, list) and not several and t.known is not None:
            raise DesignError(f"{opt} takes one value, got {len(value)}" if len(value) != 1 else
                              f"{opt} takes one value, not a list: {_shown(value)}")
        values = value if isinstance(value, list) else [value]
        words = [value_text(v, opt) for v in values]
        count = t.nargs.get(opt)
        if isinstance(count, int) and len(words) != count:
            raise DesignError(f"{opt} takes {count} values, got {len(words)}")
        if not words:
            raise DesignError(f"{opt} takes at least one value, got an empty list")
        if opt in t.appended or len(words) == 1:
            # joined to its option: a value that begins with "-" (--help, -x) is a value, never an option
            argv += [f"{opt}={w}" for w in words]
        else:
            for w in words:
                if w.startswith("-") and not _NEGATIVE.match(w):
                    raise DesignError(f"{opt} {w[:40]!r}: a value of an option that takes several must not begin "
                                      "with '-' unless it is a number")
            argv += [opt, *words]
    return argv


def _shown(value) -> str:
    return json.dumps(value)[:40]


def value_text(value, opt: str) -> str:
    """One value as typed: a string as it is, a number as Python writes it (a negative one without an
    exponent, as the parsers read a number).

    Parameters
    ----------
    value : str, int or float
        A JSON value of a request.
    opt : str
        What it is given for: an option (``--fc``) or a library parameter (``fc_hz``, then the error's
        ``param``).

    Returns
    -------
    str
        The value as a user would type it.
    """
    param = None if opt.startswith("-") else opt
    if isinstance(value, bool) or isinstance(value, (dict, list)):
        raise DesignError(f"{opt} takes a number or a text such as 4k7, got {_shown(value)}", param=param)
    if isinstance(value, float):
        if not math.isfinite(value):
            raise DesignError(f"{opt} takes a finite number, got {value!r}", param=param)
        text = repr(value)
        return format(decimal.Decimal(text), "f") if "e" in text else text
    if isinstance(value, int):
        return str(value)
    if not isinstance(value, str):
        raise DesignError(f"{opt} takes a number or a text such as 4k7, got {type(value).__name__}", param=param)
    return check_text(value)


def write_content(tmp: str | None, name: str, value, opt: str) -> str:
    """A file option's content (text, or a JSON object or list written as JSON) in the
    request's folder; returns its path.

    Parameters
    ----------
    tmp : str or None
        The request's folder (None: the request takes no files).
    name : str
        The file's name.
    value : str, dict or list
        The content.
    opt : str
        The option, for messages.

    Returns
    -------
    str
        The file's path.
    """
    if tmp is None:
        raise DesignError(f"{opt} is not taken by this request")
    if isinstance(value, (dict, list)):
        value = json.dumps(value)
    if not isinstance(value, str):
        raise DesignError(f"{opt} takes the file's content: a JSON object or a text, got {_shown(value)}")
    check_text(value)
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
    nargs: dict = {}   #: option -> how many values it takes, where that is a fixed number above 1


def parser_traits(parser) -> Traits:
    """The :class:`Traits` of an argparse parser.

    Parameters
    ----------
    parser : argparse.ArgumentParser
        A command's parser.

    Returns
    -------
    Traits
        Its switches, appended, multi-valued and known options, and the number of
        values of each option that takes a fixed number above 1.
    """
    import argparse
    switches, appended, multi, known, nargs = set(), set(), set(), set(), {}
    for action in parser._actions:   # argparse has no public list of its actions
        for opt in action.option_strings:
            known.add(opt)
            if action.nargs == 0:
                switches.add(opt)
            elif isinstance(action, argparse._AppendAction):
                appended.add(opt)
            elif action.nargs not in (None, "?"):
                multi.add(opt)
                if isinstance(action.nargs, int):
                    nargs[opt] = action.nargs
    return Traits(switches, appended, multi, known, nargs)
