"""The Sallen-Key low-pass's part names, in one place: the designators the
section declares (:class:`~designer.filters.sallen_key_lowpass.SallenKeyLowPass`:
R1, R2, C1, C2 and, with gain K = 1 + R4/R3, R3 and R4; the seed's names, seed
001 sections IV.3-IV.9, which are TI's in "Op Amps for Everyone", ch. 16,
SLOA088) and the lower-case field of each on the plant's parts record
(:class:`designer.plant.sallenkey.SallenKeyParts`: ``r1`` .. ``r4``), the
names the JSON keys, the command line's ``--r1`` .. and check-design's YAML
spell.

Every module outside the Sallen-Key family reads the plant's parts from here
(the section's declaration, :attr:`~designer.filters.topology.Topology.parts`)
instead of spelling them: the designator of a field, the field of a
designator, the section of a parts record and its values by designator.
"""

from __future__ import annotations

import numpy as np

from .registry import get
from .sallen_key_lowpass_synthesis import JSON_KEYS, SallenKeyParts
from .topology import Topology

__all__ = ["FIELD_OF", "KEY_OF", "REF_OF", "section_of", "part_values", "refs", "gain_refs",
           "parts_of", "gain_of", "network", "record_of", "json_values", "ratio_pair"]

#: the plant record's field of each designator of the section (with gain)
FIELD_OF = {"R1": "r1", "R2": "r2", "C1": "c1", "C2": "c2", "R3": "r3", "R4": "r4"}
#: the designator of each field
REF_OF = {f: r for r, f in FIELD_OF.items()}
#: the result.json key of each designator (:data:`~designer.filters.sallen_key_lowpass_synthesis.JSON_KEYS`
#: by field: design-plant's ``built`` record)
KEY_OF = {r: JSON_KEYS[f] for r, f in FIELD_OF.items()}
#: the registry names of the follower and of the section with gain
_NAMES = ("sallen-key-lowpass", "sallen-key-lowpass-gain")


def section_of(parts=None, with_gain: bool | None = None) -> Topology:
    """The registered Sallen-Key low-pass a parts record realises: the follower
    when it has no gain pair (``r3`` None), else the section with gain.

    Parameters
    ----------
    parts : object, optional
        Has ``r3`` (a :class:`~designer.plant.sallenkey.SallenKeyParts`).
    with_gain : bool, optional
        Instead of ``parts``: which section.

    Returns
    -------
    Topology
        The registry's instance.
    """
    if with_gain is None:
        with_gain = parts is not None and getattr(parts, "r3", None) is not None
    return get(_NAMES[bool(with_gain)])


def refs(with_gain: bool = True) -> tuple:
    """The section's designators, in its declared order.

    Parameters
    ----------
    with_gain : bool
        Include the gain pair.

    Returns
    -------
    tuple of str
        ``R1 R2 C1 C2`` (then ``R3 R4``).
    """
    return section_of(with_gain=with_gain).designators


def gain_refs() -> tuple:
    """The designators the gain section adds to the follower's (to ground, feedback).

    Returns
    -------
    tuple of str
        The gain pair.
    """
    return section_of(with_gain=True).choice_parts


def part_values(parts) -> dict:
    """A parts record's values by designator, the parts of :func:`section_of` it.

    Parameters
    ----------
    parts : object
        Has the fields of :data:`FIELD_OF` (a :class:`~designer.plant.sallenkey.SallenKeyParts`).

    Returns
    -------
    dict
        Designator -> value (ohm, farad).
    """
    return {r: getattr(parts, FIELD_OF[r]) for r in section_of(parts).designators}


def network(values: dict) -> tuple:
    """The RC network's values of ``values`` in the section's declared order
    (the input resistor, the resistor to the non-inverting input, the capacitor
    to ground, the feedback capacitor: the seed's r1, r2, c1, c2 of the closed forms).

    Parameters
    ----------
    values : dict
        Designator -> value (numbers or arrays).

    Returns
    -------
    tuple
        Four values.
    """
    return tuple(values[r] for r in refs(with_gain=False))


def gain_of(values: dict):
    """K = 1 + (feedback)/(to ground) of the gain pair in ``values``, 1 (shaped as
    the network's values) without it.

    Parameters
    ----------
    values : dict
        Designator -> value (numbers or arrays).

    Returns
    -------
    float or ndarray
        The gain.
    """
    to_ground, feedback = gain_refs()
    if to_ground in values and feedback in values:
        return 1.0 + np.asarray(values[feedback]) / np.asarray(values[to_ground])
    return np.ones_like(np.asarray(network(values)[0], dtype=float))


def parts_of(values: dict, base=None, **other) -> SallenKeyParts:
    """A parts record from values by designator.

    Parameters
    ----------
    values : dict
        Designator -> value: the network's, and optionally the gain pair's.
    base : SallenKeyParts, optional
        Where a gain pair missing from ``values`` comes from.
    **other
        The record's other fields (``gain``; None leaves it to
        :func:`~designer.filters.sallen_key_lowpass_synthesis.check_parts`).

    Returns
    -------
    SallenKeyParts
        The record.
    """
    kw = {FIELD_OF[r]: values[r] for r in refs() if r in values}
    if base is not None:
        kw = {FIELD_OF[r]: getattr(base, FIELD_OF[r]) for r in gain_refs()} | kw
    return SallenKeyParts(**kw, **other)


def record_of(topology, values: dict):
    """The parts record of a Sallen-Key low-pass section with its values (its
    gain K = 1 + R4/R3 from the gain pair, 1 for the follower), or None for any
    other section: where the record's closed forms (seed 001, IV.3-IV.9) can
    stand in for a section's nodal model.

    Parameters
    ----------
    topology : Topology
        A registered section.
    values : dict
        Its values by designator.

    Returns
    -------
    SallenKeyParts or None
        The record, or None when ``topology`` is not the Sallen-Key low-pass.
    """
    if topology.name not in _NAMES:
        return None
    with_gain = "R3" in topology.designators
    gain = 1.0 + values["R4"] / values["R3"] if with_gain else 1.0
    return parts_of(values, gain=gain)


def json_values(record: dict, with_gain: bool = False) -> dict | None:
    """The values by designator of a result.json's parts record (design-plant's ``built``,
    its keys :data:`KEY_OF`), or None when one of them is missing or not a number.

    Parameters
    ----------
    record : dict
        The parsed record.
    with_gain : bool
        Read the gain pair too (else the RC network only).

    Returns
    -------
    dict or None
        Designator -> value (float), the section's declared order.
    """
    keys = [KEY_OF[r] for r in refs(with_gain)]
    if not all(isinstance(record.get(k), (int, float)) for k in keys):
        return None
    return {r: float(record[k]) for r, k in zip(refs(with_gain), keys)}


def ratio_pair(gain: float) -> dict:
    """A gain pair that gives K = ``gain`` by its ratio alone: to ground 1, feedback K - 1
    (K = 1 + R4/R3 only knows their ratio; a band over its tolerance corners, R4 (1 +- t) /
    (R3 (1 -+ t)), is then the closed form's 1 + (K - 1)(1 +- t)/(1 -+ t), to the bit).

    Parameters
    ----------
    gain : float
        K > 1.

    Returns
    -------
    dict
        The gain pair's designators -> values.
    """
    to_ground, feedback = gain_refs()
    return {to_ground: 1.0, feedback: gain - 1.0}
