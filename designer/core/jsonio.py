"""JSON at the edges: results become plain JSON values here (numpy scalars to
Python numbers, nan and inf to null), and a ``result.json`` a command wrote is
read back here (:func:`read_result`, for ``identify --against`` and
``design-pid --plant-json``)."""

from __future__ import annotations

import json
import math

import numpy as np

from .errors import DesignError
from .fileio import MAX_TABLE_BYTES, read_text, shown

__all__ = ["SCHEMA_VERSION", "json_safe", "read_result"]


#: the layout version of every result.json (``schema_version``; 2 added it and ``tool``, the
#: program that wrote the file); raised when a key changes meaning or goes
SCHEMA_VERSION = 2


def json_safe(obj):
    """JSON-ready copy: numpy scalars and arrays to Python numbers and lists,
    tuples to lists, nan/inf to None (the one cleaner of every result).

    Parameters
    ----------
    obj
        Any result (dicts, lists, numbers, numpy values).

    Returns
    -------
    object
        The JSON-ready copy.
    """
    if isinstance(obj, dict):
        return {k: json_safe(v) for k, v in obj.items()}
    if isinstance(obj, (list, tuple)):
        return [json_safe(v) for v in obj]
    if isinstance(obj, np.ndarray):
        return json_safe(obj.tolist())
    if isinstance(obj, np.bool_):
        return bool(obj)
    if isinstance(obj, (np.floating, np.integer)):
        obj = obj.item()
    if isinstance(obj, float) and not math.isfinite(obj):
        return None
    return obj


def read_result(path, option: str, needs: dict | None = None,
                what: str = "a design-plant result.json") -> dict:
    """Read a ``result.json`` a command wrote, refusing anything else in one line.

    Parameters
    ----------
    path : str or Path
        The file (read through :func:`designer.core.fileio.read_text`: at most
        :data:`~designer.core.fileio.MAX_TABLE_BYTES`, UTF-8 text; a
        directory, ``/dev/zero`` or a FIFO is refused).
    option : str
        The option that named the file (``--against``), for messages.
    needs : dict, optional
        ``{section: (key, ...)}``: the object must have each section as an
        object holding those keys, e.g. ``{"built": ("fn_hz", "zeta")}``.
    what : str
        What the file should be, for messages.

    Returns
    -------
    dict
        The parsed object. Values are not checked: the caller checks the ones
        it uses.

    Raises
    ------
    DesignError
        Unreadable file, not JSON, a key twice in one object, nested too
        deeply, not an object, or a needed section or key missing.
    """
    name = shown(path)
    text = read_text(path, f"{option} file", MAX_TABLE_BYTES)
    try:
        data = json.loads(text, object_pairs_hook=_once_each)
    except _KeyTwice as exc:
        raise DesignError(f"{option}: {name} has the key {exc.key!r} twice in one object, so which one counts is "
                          f"a guess; expected {what} as the command wrote it (each key once)") from None
    except json.JSONDecodeError as exc:
        raise DesignError(f"{option}: {name} is not JSON ({exc.msg} at line {exc.lineno}); "
                          f"expected {what}") from None
    except RecursionError:
        raise DesignError(f"{option}: {name} is nested too deeply to be {what}") from None
    missing = [sec for sec, keys in (needs or {}).items()
               if not (isinstance(data, dict) and isinstance(data.get(sec), dict)
                       and set(keys) <= set(data[sec]))]
    if not isinstance(data, dict) or missing:
        need = "; ".join(f"'{sec}' with {_and(needs[sec])}" for sec in missing)
        raise DesignError(f"{option}: {name} is not {what}"
                          + (f" (needs {need})" if need else " (expected a JSON object)"))
    return data


class _KeyTwice(Exception):
    """A key given twice in one JSON object (:func:`_once_each`)."""

    def __init__(self, key: str):
        super().__init__(key)
        self.key = key


def _once_each(pairs) -> dict:
    """``json.loads``'s ``object_pairs_hook``: the object, unless a key repeats (where
    ``json`` keeps the last without a word, RFC 8259 section 4 leaves it to the reader)."""
    out = {}
    for key, value in pairs:
        if key in out:
            raise _KeyTwice(key)
        out[key] = value
    return out


def _and(keys) -> str:
    """``a, b and c``."""
    keys = list(keys)
    return keys[0] if len(keys) == 1 else ", ".join(keys[:-1]) + " and " + keys[-1]
