"""Analytic models of the Sallen-Key plant: the ideal second-order transfer
function, the one with a single-pole op-amp, their step responses on a dense
grid, and sensitivities.

Transfer functions are (num, den) coefficient arrays in descending powers of
s, as numpy.polyval and scipy.signal take them.
"""

from __future__ import annotations

import math

import numpy as np

from .opamps import OpAmp
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


def dominant_pair(den):
    """Natural frequency (Hz) and damping of the slowest pole pair of ``den``.

    For a complex pair: fn = |p| / 2 pi and zeta = -Re p / |p|. For real poles
    the two slowest define fn = sqrt(p1 p2) / 2 pi, zeta = (p1 + p2) / (2 sqrt(p1 p2)).
    """
    poles = np.roots(den)
    cplx = poles[np.abs(poles.imag) > 1e-9 * np.abs(poles)]
    if cplx.size:
        p = cplx[np.argmin(np.abs(cplx))]
        w = abs(p)
        return w / (2 * math.pi), -p.real / w
    real = np.sort(np.abs(poles.real))[:2]
    w = math.sqrt(real[0] * real[1])
    return w / (2 * math.pi), (real[0] + real[1]) / (2 * w)


def response_span(fn_hz: float, zeta: float) -> float:
    """A simulation/plot length that shows the whole step response settling:
    about twice the 2 % settling time of the dominant pair."""
    wn = 2 * math.pi * fn_hz
    if zeta < 1:
        ts = 4.0 / (zeta * wn)
    else:
        slow = wn * (zeta - math.sqrt(zeta * zeta - 1.0))
        ts = 4.0 / slow
    return 2.0 * max(ts, 6.0 / wn)


def step_response(num, den, t):
    """Response to a unit step applied at t = 0, evaluated at ``t``.

    Closed form from the partial-fraction expansion, y(t) = H(0) + sum r_i/p_i e^(p_i t)
    with residues r_i = num(p_i) / den'(p_i): exact and vectorised (scipy's lsim
    steps through the grid in a loop, and importing scipy.signal costs half a
    second per command). Repeated or zero poles fall back to scipy.signal.step.
    """
    t = np.asarray(t, float)
    num = np.trim_zeros(np.atleast_1d(np.asarray(num, float)), "f")
    den = np.trim_zeros(np.atleast_1d(np.asarray(den, float)), "f")
    if len(num) < len(den):
        p = np.roots(den)
        close = np.abs(p[:, None] - p[None, :]) <= 1e-6 * np.abs(p)[:, None]
        np.fill_diagonal(close, False)
        if np.all(np.abs(p) > 0) and not np.any(close):
            r = np.polyval(num, p) / np.polyval(np.polyder(den), p)
            h0 = num[-1] / den[-1]
            return np.real(h0 + np.exp(np.outer(t, p)) @ (r / p))
    from scipy import signal
    _, y = signal.step((num, den), T=t)
    return y


def freq_response(num, den, f_hz):
    """Complex H(j 2 pi f) at the frequencies ``f_hz``."""
    s = 2j * np.pi * np.asarray(f_hz, float)
    return np.polyval(num, s) / np.polyval(den, s)


def dense_time(t_end: float, n: int = 20001):
    """Uniform grid from 0 to ``t_end`` (dense: crossing times then interpolate well)."""
    return np.linspace(0.0, t_end, n)


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
