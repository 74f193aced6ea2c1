"""Analytic models of the Sallen-Key plant (seed 001, IV.3-IV.9): the ideal
second-order transfer function, the third-order one with a single-pole
op-amp, and the sensitivities of wn and zeta to every part and op-amp figure.
Step and frequency responses come from :mod:`designer.core.lti`.
"""

from __future__ import annotations

import math

import numpy as np

from ..core.lti import dominant_pair
from ..core.opamps import OpAmp
from .sallenkey import SallenKeyParts


def plant_tf(parts: SallenKeyParts):
    """Ideal op-amp: K / (a s^2 + b s + 1)."""
    return np.array([parts.gain]), np.array([parts.a, parts.b, 1.0])


def plant_tf_opamp(parts: SallenKeyParts, opamp: OpAmp):
    """Sallen-Key low-pass with a single-pole op-amp (third order).

    Node equations with Vp = Vo (1/A + 1/K) and V1 = Vp (1 + s R2 C1) give
    Vo/Vin = 1/D(s),  D = (N/A0) [(1 + s R2 C1)(1 + R1/R2 + s R1 C2) - R1/R2] - s R1 C2,
    N = 1 + A0/K + s/wp. As A0, wp -> inf this is the ideal K/(a s^2 + b s + 1).
    """
    r1, r2, c1, c2, k = parts.r1, parts.r2, parts.c1, parts.c2, parts.gain
    a0 = opamp.a0
    wp = 2 * math.pi * opamp.gbw_hz / a0
    n = np.array([1.0 / wp, 1.0 + a0 / k]) / a0
    inner = np.polysub(np.polymul([r2 * c1, 1.0], [r1 * c2, 1.0 + r1 / r2]), [r1 / r2])
    d = np.polysub(np.polymul(n, inner), [r1 * c2, 0.0])
    return np.array([1.0 / d[-1]]), d / d[-1]


def sensitivities(parts: SallenKeyParts, opamp: OpAmp | None = None, rel_step: float = 1e-6):
    """Relative sensitivities S_x^y = d ln y / d ln x of wn and zeta.

    x runs over R1, R2, C1, C2, the gain K (when not a follower) and, with an
    op-amp, its GBW and DC gain A0 (through the op-amp-aware model). Central
    differences in log space.
    """
    def figures(p, amp):
        if amp is None:
            return p.wn, p.zeta
        fn, z = dominant_pair(plant_tf_opamp(p, amp)[1])
        return 2 * math.pi * fn, z

    names = {"R1": "r1", "R2": "r2", "C1": "c1", "C2": "c2"}
    if parts.gain != 1.0:
        names["K"] = "gain"
    h = rel_step
    table = {}
    for label, attr in names.items():
        up = _scaled(parts, attr, 1 + h)
        dn = _scaled(parts, attr, 1 - h)
        (wu, zu), (wd, zd) = figures(up, opamp), figures(dn, opamp)
        dl = math.log((1 + h) / (1 - h))
        table[label] = {"wn": math.log(wu / wd) / dl, "zeta": math.log(zu / zd) / dl}
    if opamp is not None and not opamp.ideal:
        from dataclasses import replace
        for label, attr in (("GBW", "gbw_hz"), ("A0", "a0")):
            up = replace(opamp, **{attr: getattr(opamp, attr) * (1 + h)})
            dn = replace(opamp, **{attr: getattr(opamp, attr) * (1 - h)})
            (wu, zu), (wd, zd) = figures(parts, up), figures(parts, dn)
            dl = math.log((1 + h) / (1 - h))
            table[label] = {"wn": math.log(wu / wd) / dl, "zeta": math.log(zu / zd) / dl}
    return table


def _scaled(parts, attr, factor):
    from dataclasses import replace
    return replace(parts, **{attr: getattr(parts, attr) * factor})
