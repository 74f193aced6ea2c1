"""Analytic models of the Sallen-Key plant (seed 001, IV.3-IV.9): the ideal
second-order transfer function, the third-order one with a single-pole
op-amp, and the sensitivities of wn and zeta to every part and op-amp figure.
Step and frequency responses come from :mod:`designer.core.lti`.
"""

from __future__ import annotations

import math
from dataclasses import dataclass, replace

import numpy as np

from ..core.lti import dominant_pair
from ..core.opamps import OpAmp
from ..filters.sallen_key_lowpass_parts import FIELD_OF, refs
from ..filters.sallen_key_lowpass_synthesis import opamp_denominator
from .sallenkey import SallenKeyParts

__all__ = ["plant_tf", "plant_tf_opamp", "plant_model", "opamp_pair", "sensitivities"]


def plant_tf(parts: SallenKeyParts):
    """Ideal op-amp: K / (a s^2 + b s + 1).

    Parameters
    ----------
    parts : SallenKeyParts
        The parts.

    Returns
    -------
    tuple of numpy.ndarray
        (num, den), highest power first.
    """
    return np.array([parts.gain]), np.array([parts.a, parts.b, 1.0])


def plant_tf_opamp(parts: SallenKeyParts, opamp: OpAmp):
    """Sallen-Key low-pass with a single-pole op-amp (third order).

    Vo/Vin = 1/D(s), D from the section's closed form
    (:func:`designer.filters.sallen_key_lowpass_synthesis.opamp_denominator`), normalised to D(0) = 1.

    Parameters
    ----------
    parts : SallenKeyParts
        The parts.
    opamp : OpAmp
        The op-amp.

    Returns
    -------
    tuple of numpy.ndarray
        (num, den), highest power first.
    """
    d = opamp_denominator(parts.r1, parts.r2, parts.c1, parts.c2, parts.gain, opamp.a0, opamp.gbw_hz)
    return np.array([1.0 / d[-1]]), d / d[-1]


def plant_model(parts: SallenKeyParts, opamp: OpAmp):
    """The model a loop or a check takes of the plant: :func:`plant_tf` with an ideal
    op-amp, else :func:`plant_tf_opamp`.

    Parameters
    ----------
    parts : SallenKeyParts
        The parts.
    opamp : OpAmp
        The op-amp.

    Returns
    -------
    tuple of numpy.ndarray
        (num, den), highest power first.
    """
    return plant_tf(parts) if opamp.ideal else plant_tf_opamp(parts, opamp)


def opamp_pair(parts: SallenKeyParts, opamp: OpAmp) -> tuple:
    """fn (Hz) and zeta of the op-amp-aware model's dominant pair
    (:func:`designer.core.lti.dominant_pair` of :func:`plant_tf_opamp`).

    Parameters
    ----------
    parts : SallenKeyParts
        The parts.
    opamp : OpAmp
        The op-amp.

    Returns
    -------
    tuple of float
        (fn_hz, zeta).
    """
    return dominant_pair(plant_tf_opamp(parts, opamp)[1])


@dataclass(frozen=True)
class Sensitivity:
    """How much wn and zeta move, relatively, for a relative change of one part:
    S = d ln(y) / d ln(x)."""

    wn: float
    zeta: float

    def to_dict(self) -> dict:
        return {"wn": self.wn, "zeta": self.zeta}


def sensitivities(parts: SallenKeyParts, opamp: OpAmp | None = None, rel_step: float = 1e-6) -> dict:
    """Relative sensitivities S_x^y = d ln y / d ln x of wn and zeta.

    x runs over R1, R2, C1, C2, the gain K (when not a follower) and, with an
    op-amp, its GBW and DC gain A0 (through the op-amp-aware model). Central
    differences in log space.

    Parameters
    ----------
    parts : SallenKeyParts
        The parts.
    opamp : OpAmp, optional
        The op-amp (its GBW and A0 join the list).
    rel_step : float
        The central differences' relative step.

    Returns
    -------
    dict
        ``{"R1": Sensitivity, ...}`` in that order.
    """
    def figures(p, amp):
        if amp is None:
            return p.wn, p.zeta
        fn, z = opamp_pair(p, amp)
        return 2 * math.pi * fn, z

    h = rel_step
    dl = math.log((1 + h) / (1 - h))

    def moved(obj, attr):
        """S of wn and zeta for ``attr`` of ``obj`` (the parts or the op-amp)."""
        up, dn = (replace(obj, **{attr: getattr(obj, attr) * f}) for f in (1 + h, 1 - h))
        if obj is parts:
            (wu, zu), (wd, zd) = figures(up, opamp), figures(dn, opamp)
        else:
            (wu, zu), (wd, zd) = figures(parts, up), figures(parts, dn)
        return Sensitivity(math.log(wu / wd) / dl, math.log(zu / zd) / dl)

    names = {r: FIELD_OF[r] for r in refs(with_gain=False)}
    if parts.gain != 1.0:
        names["K"] = "gain"
    table = {label: moved(parts, attr) for label, attr in names.items()}
    if opamp is not None and not opamp.ideal:
        table.update({label: moved(opamp, attr) for label, attr in (("GBW", "gbw_hz"), ("A0", "a0"))})
    return table
