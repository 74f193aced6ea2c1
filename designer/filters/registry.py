"""The registry of filter sections, in the style of scipy.signal's
``filter_dict``: name -> :class:`~designer.filters.topology.Topology`
instance. Adding a section is its module plus one line here; the conformance
suite (``tests/filters/test_conformance.py``) picks it up from :data:`REGISTRY`.
"""

from __future__ import annotations

import difflib

from ..core.errors import DesignError
from .inverting_highpass import InvertingHighPass
from .inverting_lowpass import InvertingLowPass
from .mfb_bandpass import MfbBandPass
from .mfb_highpass import MfbHighPass
from .mfb_lowpass import MfbLowPass
from .rc_highpass import RcHighPass
from .rc_lowpass import RcLowPass
from .sallen_key_highpass import SallenKeyHighPass
from .sallen_key_lowpass import SallenKeyLowPass
from .topology import Topology

__all__ = ["REGISTRY", "get", "names", "register"]

#: every registered section by name
REGISTRY: dict = {}


def register(topology: Topology) -> Topology:
    """Add ``topology`` under its name.

    Parameters
    ----------
    topology : Topology
        An instance with a unique :attr:`~designer.filters.topology.Topology.name`.

    Returns
    -------
    Topology
        The same instance.

    Raises
    ------
    ValueError
        The name is taken (a programming error, not bad input).
    """
    if topology.name in REGISTRY:
        raise ValueError(f"a topology named {topology.name!r} is already registered")
    REGISTRY[topology.name] = topology
    return topology


for _t in (SallenKeyLowPass(), SallenKeyLowPass(with_gain=True),
           SallenKeyHighPass(), SallenKeyHighPass(with_gain=True),
           MfbLowPass(),
           MfbHighPass(),
           MfbBandPass(),
           RcLowPass(),
           RcHighPass(),
           InvertingLowPass(),
           InvertingHighPass()):
    register(_t)


def names() -> list:
    """The registered names, in registration order.

    Returns
    -------
    list of str
        The names :func:`get` accepts.
    """
    return list(REGISTRY)


def get(name: str) -> Topology:
    """The registered topology ``name`` (case and surrounding spaces ignored).

    Parameters
    ----------
    name : str
        A registered name.

    Returns
    -------
    Topology
        The instance.

    Raises
    ------
    DesignError
        An unknown name: one line listing the registered ones and the closest.
    """
    key = str(name).strip().lower()
    if key in REGISTRY:
        return REGISTRY[key]
    close = difflib.get_close_matches(key, names(), n=1, cutoff=0.0)
    hint = f"; did you mean {close[0]}?" if close else ""
    raise DesignError(f"topology: unknown topology {name!r}; registered: {', '.join(names())}{hint}",
                      param="topology")
