"""A request's inputs checked before any of them is used: its JSON body, its
field names, its values.

``{"fc": 3500, "zeta": "0.2", "r-series": "E24"}``: every key is a field's name,
the command's option name (dashes or underscores), every value what a user types
after it (numbers, engineering notation in strings; ``true`` for a switch, a
list for a field that takes several values). The page's name tables
(:mod:`.forms`) map the fields to the library's parameters; nothing builds a
command line. What a page must not choose is refused here in one line
(:func:`option_name`): where files go and how output is printed (the server
sets those), the processes and addresses a run uses (``jobs``, ``dask``,
``timeout``), the trust settings of check-design. A field that names a file on
the command line (``plant-model``, ``plant-json``...) takes the file's
*content*, written into the request's private folder under a fixed name
(:func:`write_content`): no path a user gives is ever opened. :func:`parse_json`
bounds the JSON's nesting and refuses text that is not Unicode (a lone
surrogate), before any of it is used; :func:`value_text` checks each value's
JSON type.
"""

from __future__ import annotations

import decimal
import json
import math
import os
import re

from ..core.errors import DesignError

__all__ = ["MAX_DEPTH", "MAX_JSON_BYTES", "REFUSED", "SERVERS_OWN", "check_text", "check_value", "option_name",
           "parse_json", "split_language", "value_text", "write_content"]

#: options the server sets itself (files, output form) or that would reach past a request's folder
REFUSED = ("out", "json", "no-files", "plot", "help", "version", "junit", "summary", "root", "allow-outside",
           "jobs", "dask", "spice-jobs", "timeout", "fail-on-check", "no-fail")
#: of those, the processes, addresses and deadlines of a run: the server's (designer-web --jobs, --timeout)
SERVERS_OWN = ("jobs", "dask", "spice-jobs", "timeout")
#: most bytes of a request's JSON body (its options; a model or result.json given inline included)
MAX_JSON_BYTES = 4 * 1024 * 1024
#: deepest nesting of a request's JSON (a model's JSON is 4 deep; Python's own parser fails near 1000)
MAX_DEPTH = 64
_KEY = re.compile(r"^[a-z][a-z0-9-]{0,40}$")


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
