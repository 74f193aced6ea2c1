"""A plant model for PID design from a result JSON file (``--plant-model FILE``).

Three kinds of file are read, each as the command that wrote it lays it out:

- ``identify ... --json`` (:meth:`designer.identify.step.IdentifyResult.to_dict`):
  ``methods``, a ranked list (valid first, then by IAE) of
  ``{name, model, params, valid, note, points}``, and ``best``, the first
  valid one (or null); the least-squares fits carry their 95 % half-widths
  in ``points`` as ``<param>_ci95``. ``capture.source`` names the capture.
- ``identify-freq ... --json`` (:meth:`designer.identify.frequency.FreqIdentifyResult.to_dict`),
  also what ``identify`` prints for a frequency table (``"format":
  "frequency-table"``): the same ``methods`` and ``best``, with ``data``
  (``data.source`` names the table) and ``error_definition``.
- a ``design-plant``/``analyze-plant`` ``result.json``
  (:meth:`designer.plant.result.PlantResult.to_dict`): the Sallen-Key parts
  as built (``built``), whose ideal-op-amp model K/(a s^2 + b s + 1)
  (:func:`designer.plant.model.plant_tf`) becomes an underdamped model
  (fn, zeta of :class:`~designer.plant.sallenkey.SallenKeyParts`) or, for
  zeta >= 1, the SOPDT with tau1,2 = (b +- sqrt(b^2 - 4 a))/2.

Identification's parameter names (:mod:`designer.core.stepfit`) map to the
constructors of :mod:`designer.core.process_build`: ``fopdt`` (K, tau_s, theta_s)
-> :func:`~designer.core.process_build.fopdt`; ``overdamped`` (K, tau1_s, tau2_s,
theta_s, fast one first) and ``double-pole`` (K, tau_s, theta_s: tau1 = tau2)
-> :func:`~designer.core.process_build.sopdt` (which sorts, slow first);
``underdamped`` (K, wn_rad_s, zeta, theta_s) ->
:func:`~designer.core.process_build.underdamped` with fn = wn / 2 pi (its
half-width too). Every other file (a ``check-design`` or ``design-pid``
result, anything else) is refused in one line saying what it is and what is
accepted. This module reads identification's JSON, never its code (``pid``
does not import ``identify``).
"""

from __future__ import annotations

import difflib
import math
import os
import re

from ..core.errors import DesignError
from ..core.fileio import shown
from ..core.process import ProcessModel
from ..core.process_build import fopdt, sopdt, underdamped
from ..plant.sallenkey import JSON_KEYS, SallenKeyParts, check_parts

__all__ = ["model_from_json", "model_from_result", "result_kind", "sallen_key_model"]

#: what ``--plant-model`` reads, for messages
ACCEPTED = ("an identify or identify-freq --json output, or a design-plant/analyze-plant result.json")
#: the ``format`` of what ``identify`` prints for a broadband capture (a PRBS or noise input): its ranking
#: laid out as identify's or identify-freq's (``--method``), or none at all when nothing fitted
IDENTIFY_FORMATS = ("broadband",)
#: identification's models this module maps (stepfit's and identify-freq's names)
IDENTIFIED_MODELS = ("fopdt", "double-pole", "overdamped", "underdamped")
#: ``built`` keys of a plant result (design-plant, analyze-plant) by :class:`SallenKeyParts` field
BUILT_KEYS = {**JSON_KEYS, "gain": "gain"}


def result_kind(data) -> str | None:
    """What wrote a parsed result JSON: ``"identify"``, ``"identify-freq"``,
    ``"plant"`` (design-plant/analyze-plant), ``"check-design"``,
    ``"design-pid"``, or None (none of these).

    Parameters
    ----------
    data : object
        The parsed JSON.

    Returns
    -------
    str or None
    """
    if not isinstance(data, dict):
        return None
    if data.get("format") in IDENTIFY_FORMATS and "best" in data:
        return "identify"    # identify wrote it, whatever ranking it carries (or none, when nothing fitted)
    if isinstance(data.get("methods"), list) and ({"best", "preprocessing", "error_definition"} & set(data)):
        freq = "error_definition" in data or "data" in data or data.get("format") == "frequency-table"
        return "identify-freq" if freq else "identify"
    if isinstance(data.get("built"), dict) and data.get("mode") in ("design", "analyze", None):
        return "plant"
    if isinstance(data.get("corners"), list) and "counts" in data:
        return "check-design"
    if isinstance(data.get("components"), dict) and "tuning" in data:
        return "design-pid"
    return None


def model_from_json(path, method: str | None = None) -> ProcessModel:
    """The plant model in a result JSON file.

    Parameters
    ----------
    path : str or Path
        An ``identify``/``identify-freq`` ``--json`` output or a
        ``design-plant``/``analyze-plant`` ``result.json`` (read through
        :func:`designer.core.jsonio.read_result`, the one reader of result
        files: bounded, a regular file, one-line refusals).
    method : str, optional
        For an identification result: the method to take instead of the best,
        by name (``alfaro``; ``least-squares`` is the best-ranked valid fit)
        or ``name:model`` (``least-squares:overdamped``; a space works too).

    Returns
    -------
    ProcessModel
        With the method's 95 % half-widths as ``ci95`` (least-squares fits)
        and ``source`` such as ``"identify least-squares fopdt (capture.csv)"``.

    Raises
    ------
    DesignError
        One line: the file unreadable or not JSON; a check-design, design-pid
        or other result; no valid best model, or ``method`` unknown or not
        valid (listing the valid methods); parameters outside the ranges of
        :mod:`designer.core.process_build`; a plant's parts out of range.
    """
    from ..core.jsonio import read_result
    data = read_result(path, "--plant-model", what=ACCEPTED)   # the one reader of result files: bounded, one line
    return model_from_result(data, method, name=shown(path))


def model_from_result(data, method: str | None = None, *, name: str = "result") -> ProcessModel:
    """:func:`model_from_json` of JSON already parsed (``name`` names it in messages).

    Parameters
    ----------
    data : dict
        The parsed result.
    method : str, optional
        As :func:`model_from_json`'s.
    name : str
        How messages name the result.

    Returns
    -------
    ProcessModel
    """
    kind = result_kind(data)
    where = f"plant model {name}"
    if kind in ("identify", "identify-freq"):
        return model_from_identify(data, method, name=name, tool=kind)
    if kind == "plant":
        if method is not None:
            raise DesignError(f"{where} is a design-plant result: it has one model, the circuit's; a method "
                              f"({method!r}) chooses among an identify result's models")
        return model_from_plant(data, name=name)
    if kind == "check-design":
        raise DesignError(f"{where} is a check-design result (the verdicts of a spec), not a plant model; "
                          f"give {ACCEPTED}")
    if kind == "design-pid":
        raise DesignError(f"{where} is a design-pid result (a controller), not a plant model; give {ACCEPTED}")
    raise DesignError(f"{where} is not a plant model: expected {ACCEPTED}")


# --------------------------------------------------------------------------- identification

def _entries(data: dict, where: str) -> list:
    """The methods, each checked to have the fields read here."""
    out = []
    for i, m in enumerate(data.get("methods") or ()):   # none in a broadband result that found nothing
        if not (isinstance(m, dict) and isinstance(m.get("name"), str) and isinstance(m.get("model"), str)
                and isinstance(m.get("params"), dict) and isinstance(m.get("valid"), bool)):
            raise DesignError(f"{where}: methods[{i}] is not a method result (it needs name, model, params "
                              "and valid)")
        out.append(m)
    return out


def _labels(methods: list) -> dict:
    """id(entry) -> its label: the name, or ``name:model`` where names repeat."""
    names = [m["name"] for m in methods]
    return {id(m): m["name"] if names.count(m["name"]) == 1 else f"{m['name']}:{m['model']}" for m in methods}


def _valid_text(methods: list, labels: dict) -> str:
    valid = [labels[id(m)] for m in methods if m["valid"]]
    return "valid methods: " + (", ".join(valid) if valid else "none (no model fits these data)")


def _chosen(methods: list, best, method, where: str, tool: str) -> dict:
    """The method entry to use: ``best``, or the one ``method`` names."""
    labels = _labels(methods)
    if method is None:
        if not isinstance(best, dict):
            raise DesignError(f"{where}: this {tool} result has no valid model (best: none): nothing to design "
                              f"for; {_valid_text(methods, labels)}")
        label = best.get("name", "?") if not isinstance(best.get("model"), str) else \
            f"{best.get('name', '?')}:{best['model']}"
        if best.get("valid") is not True:
            note = f" ({best['note']})" if isinstance(best.get("note"), str) and best["note"] else ""
            raise DesignError(f"{where}: the best model, {label}, is not valid{note}; "
                              f"{_valid_text(methods, labels)}")
        return best
    parts = re.split(r"[:\s]+", str(method).strip().lower(), maxsplit=1)
    mname, mmodel = parts[0], (parts[1] if len(parts) > 1 and parts[1] else None)
    matches = [m for m in methods if m["name"].lower() == mname
               and (mmodel is None or m["model"].lower() == mmodel)]
    if not matches:
        every = list(dict.fromkeys(labels[id(m)] for m in methods))
        close = difflib.get_close_matches(str(method).strip().lower(), every, n=1, cutoff=0.6)
        hint = f" (did you mean {close[0]}?)" if close else ""
        raise DesignError(f"{where}: no method {str(method)!r} in this {tool} result{hint}; methods: "
                          + (", ".join(every) if every else "none"))
    valid = [m for m in matches if m["valid"]]
    if not valid:
        m = matches[0]
        note = f" ({m['note']})" if isinstance(m.get("note"), str) and m["note"] else ""
        raise DesignError(f"{where}: method {labels[id(m)]} is not valid for these data{note}; "
                          f"{_valid_text(methods, labels)}")
    return valid[0]


def _data_name(data: dict, name: str) -> str:
    """The capture or table the result was identified from (its file name), else ``name``."""
    section = data.get("capture", data.get("data"))
    src = section.get("source") if isinstance(section, dict) else None
    return os.path.basename(src) if isinstance(src, str) and src else os.path.basename(name) or name


def model_from_identify(data: dict, method: str | None = None, *, name: str = "result",
                        tool: str = "identify") -> ProcessModel:
    """The best valid model of a parsed ``identify``/``identify-freq`` result,
    or the one ``method`` names (see :func:`model_from_json`)."""
    where = f"plant model {name}"
    methods = _entries(data, where)
    if method is None and data.get("best") is None and isinstance(data.get("refused"), str):
        # a broadband estimate whose own assumption failed: say which, not just "none valid"
        raise DesignError(f"{where}: {tool} found no valid model: {data['refused']}")
    m = _chosen(methods, data.get("best"), method, where, tool)
    source = f"{tool} {m.get('name', '?')} {m.get('model', '?')} ({_data_name(data, name)})"
    try:
        return method_model(m, source)
    except DesignError as exc:
        raise DesignError(f"{where}: {m.get('name', '?')} {m.get('model', '?')}: {exc}") from None


def _number(params: dict, key: str):
    v = params.get(key)
    if isinstance(v, bool) or not isinstance(v, (int, float)) or not math.isfinite(v):
        raise DesignError(f"parameter {key} is {v!r}, not a number (the method found no model)")
    return float(v)


def method_model(m: dict, source: str) -> ProcessModel:
    """The :class:`ProcessModel` of one identification method entry
    (``{name, model, params, points}``), its ``<param>_ci95`` points as ``ci95``."""
    model, p = m.get("model"), m.get("params") or {}
    points = m.get("points") if isinstance(m.get("points"), dict) else {}
    ci = {k[:-5]: float(v) for k, v in points.items()
          if k.endswith("_ci95") and isinstance(v, (int, float)) and not isinstance(v, bool) and math.isfinite(v)}
    theta = float(p["theta_s"]) if isinstance(p.get("theta_s"), (int, float)) else 0.0   # None: not identified
    if model == "fopdt":
        return fopdt(_number(p, "K"), _number(p, "tau_s"), theta, source=source,
                     ci95=_keep(ci, ("K", "tau_s", "theta_s")))
    if model == "double-pole":
        tau = _number(p, "tau_s")
        if "tau_s" in ci:
            ci["tau1_s"] = ci["tau2_s"] = ci.pop("tau_s")
        return sopdt(_number(p, "K"), tau, tau, theta, source=source,
                     ci95=_keep(ci, ("K", "tau1_s", "tau2_s", "theta_s")))
    if model == "overdamped":
        return sopdt(_number(p, "K"), _number(p, "tau1_s"), _number(p, "tau2_s"), theta, source=source,
                     ci95=_keep(ci, ("K", "tau1_s", "tau2_s", "theta_s")))
    if model == "underdamped":
        if "wn_rad_s" in ci:
            ci["fn_hz"] = ci.pop("wn_rad_s") / (2 * math.pi)
        return underdamped(_number(p, "K"), _number(p, "wn_rad_s") / (2 * math.pi), _number(p, "zeta"), theta,
                           source=source, ci95=_keep(ci, ("K", "fn_hz", "zeta", "theta_s")))
    raise DesignError(f"model {model!r} is not one this tool maps; known: {', '.join(IDENTIFIED_MODELS)}")


def _keep(ci: dict, keys) -> dict | None:
    out = {k: ci[k] for k in keys if k in ci}
    return out or None


# --------------------------------------------------------------------------- a designed plant

def model_from_plant(data: dict, *, name: str = "result") -> ProcessModel:
    """The ideal-op-amp model of the Sallen-Key plant in a parsed
    ``design-plant``/``analyze-plant`` result (its ``built`` parts, checked by
    :func:`designer.plant.sallenkey.check_parts`)."""
    where = f"plant model {name}"
    built = data["built"]
    raw = SallenKeyParts(**{k: built.get(v) for k, v in BUILT_KEYS.items()})

    def name_of(key):
        return where if key == "plant" else f"{where}: built.{BUILT_KEYS[key]}"

    parts = check_parts(raw, name_of=name_of)
    mode = data.get("mode") if data.get("mode") in ("design", "analyze") else "design"
    source = f"{mode}-plant Sallen-Key as built ({os.path.basename(name) or name})"
    return sallen_key_model(parts, source)


def sallen_key_model(parts: SallenKeyParts, source: str = "Sallen-Key") -> ProcessModel:
    """K/(a s^2 + b s + 1) of a Sallen-Key parts record (read from a result.json's
    ``built`` keys) as a :class:`ProcessModel`: the record as the generic plant record
    (:func:`designer.pid.plant.sallen_key_circuit`) and its model,
    :func:`designer.pid.plant.pair_model` (underdamped with the parts' fn and zeta,
    or for zeta >= 1 the SOPDT whose (tau1 s + 1)(tau2 s + 1) = a s^2 + b s + 1).

    Parameters
    ----------
    parts : SallenKeyParts
        The plant's parts.
    source : str
        Where the model came from (its ``source``).

    Returns
    -------
    ProcessModel
    """
    from .plant import pair_model, sallen_key_circuit
    return pair_model(sallen_key_circuit(parts), source)
