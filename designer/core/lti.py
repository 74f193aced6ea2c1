"""Linear time-invariant maths on transfer functions: exact step responses
(repeated poles included), frequency responses, the dominant pole pair, and
the time grids the models and plots use.

Transfer functions are (num, den) coefficient arrays in descending powers of
s, as numpy.polyval and scipy.signal take them.
"""

from __future__ import annotations

import math

import numpy as np

from .errors import DesignError

__all__ = ["MAX_CLUSTER", "StepTerms", "coefficients", "dense_time", "dominant_pair", "filter_foh", "freq_response",
           "pole_clusters", "response_span", "slowest_settling_s", "step_response"]


def coefficients(p, name: str, what: str = "") -> np.ndarray:
    """A polynomial's coefficients, highest power of s first, as a finite float
    array with the leading zeros dropped; a :class:`DesignError` naming ``name``
    (its ``param``; ``what`` before it in the message) when they are not numbers,
    not finite, none, or all zero.

    Parameters
    ----------
    p : array_like
        The coefficients.
    name : str
        The parameter's name (the error's ``param``).
    what : str
        What the message says before the name.

    Returns
    -------
    numpy.ndarray
        The coefficients.
    """
    label = f"{what}: {name}" if what else name
    try:
        a = np.atleast_1d(np.asarray(p, float))
    except (TypeError, ValueError):
        raise DesignError(f"{label} must be a sequence of numbers (highest power of s first)", param=name) from None
    if a.ndim != 1 or a.size == 0 or not np.all(np.isfinite(a)):
        raise DesignError(f"{label} must be a non-empty sequence of finite numbers (highest power of s first)",
                          param=name)
    nz = np.flatnonzero(a)
    if nz.size == 0:
        raise DesignError(f"{label} is all zeros", param=name)
    return a[nz[0]:]


def dominant_pair(den):
    """Natural frequency (Hz) and damping of the slowest pole pair of ``den``.

    For a complex pair: fn = |p| / 2 pi and zeta = -Re p / |p|. For real poles
    the two slowest define fn = sqrt(p1 p2) / 2 pi, zeta = (p1 + p2) / (2 sqrt(p1 p2)).

    Parameters
    ----------
    den : array_like
        The denominator, highest power first.

    Returns
    -------
    tuple of float
        (fn in Hz, zeta).
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
    about twice the 2 % settling time of the dominant pair.

    Parameters
    ----------
    fn_hz : float
        The dominant pair's natural frequency.
    zeta : float
        Its damping.

    Returns
    -------
    float
        The span (s).
    """
    wn = 2 * math.pi * fn_hz
    if zeta < 1:
        ts = 4.0 / (zeta * wn)
    else:
        slow = wn * (zeta - math.sqrt(zeta * zeta - 1.0))
        ts = 4.0 / slow
    return 2.0 * max(ts, 6.0 / wn)


def step_response(num, den, t):
    """Response to a unit step applied at t = 0, evaluated at ``t`` (0 before it).

    Closed form from the partial-fraction expansion of Y(s) = num(s) / (s den(s)),
    repeated poles included (a critically damped plant, zeta = 1, has one):
    a pole p of multiplicity m contributes sum_k c_k t^(k-1)/(k-1)! e^(p t),
    with the Laurent coefficients c_k from Taylor series at p. Exact and
    vectorised, on any grid, uniform or not (scipy's lsim steps through a
    uniform grid in a loop, and importing scipy.signal costs half a second).

    Parameters
    ----------
    num, den : array_like
        The transfer function, highest power first.
    t : array_like
        The times (s).

    Returns
    -------
    numpy.ndarray
        The response on ``t``.
    """
    return StepTerms.of(num, den)(t)


class StepTerms:
    """The partial-fraction terms of a step response, computed once and then
    evaluated at any times: :func:`step_response` is ``StepTerms.of(num, den)(t)``.

    A caller that evaluates one step at many separate points (a root finder, a
    bounded maximiser) pays the poles and residues once; the arithmetic of each
    evaluation is :func:`step_response`'s, so the numbers are the same bit for bit.

    Parameters
    ----------
    terms : tuple of tuple
        (pole, multiplicity, Laurent coefficients) per pole cluster, the step's
        pole at 0 included; empty for a zero numerator.
    """

    __slots__ = ("terms",)

    def __init__(self, terms: tuple):
        self.terms = terms

    @classmethod
    def of(cls, num, den) -> StepTerms:
        """The terms of the unit step of ``num/den``.

        Parameters
        ----------
        num, den : array_like
            The transfer function, highest power first, proper.

        Returns
        -------
        StepTerms

        Raises
        ------
        ValueError
            An improper transfer function.
        """
        num = np.trim_zeros(np.atleast_1d(np.asarray(num, float)), "f")
        den = np.trim_zeros(np.atleast_1d(np.asarray(den, float)), "f")
        if num.size == 0:
            return cls(())
        if den.size == 0 or len(num) > len(den):
            raise ValueError("step_response needs a proper transfer function (deg num <= deg den)")
        clusters = pole_clusters(np.concatenate([np.roots(den), [0.0]]))
        terms = []
        for i, (p, m) in enumerate(clusters):
            others = [q for j, (q, mq) in enumerate(clusters) if j != i for _ in range(mq)]
            # (s - p)^m Y(s) = num(s) / g(s), analytic at p, with g(p + x) = den[0] prod (x - (q - p)):
            # expanded in x from the differences q - p, never evaluated from expanded
            # coefficients (that cancels catastrophically for close poles)
            gx = den[0] * np.poly(np.array(others, complex) - p) if others else np.array([den[0]], complex)
            terms.append((p, m, _series_ratio(_taylor(num, p, m), list(gx[::-1][:m]) + [0j] * max(0, m - gx.size))))
        return cls(tuple(terms))

    def exponentials(self, t) -> list:
        """The terms' exponentials e^(p t) on ``t`` (clipped at 0), one array per pole.

        Parameters
        ----------
        t : array_like
            The times (s).

        Returns
        -------
        list of numpy.ndarray
            For :meth:`__call__`'s ``exps``: two steps over one denominator (a
            step and its slope) share their poles, so they can share these.
        """
        tp = np.clip(np.asarray(t, float), 0.0, None)
        return [np.exp(p * tp) for p, _, _ in self.terms]

    def __call__(self, t, exps=None) -> np.ndarray:
        """The step at ``t`` (0 before the step).

        Parameters
        ----------
        t : array_like
            The times (s).
        exps : list of numpy.ndarray, optional
            :meth:`exponentials` on ``t`` of terms with these same poles, in order
            (computed here when not given).

        Returns
        -------
        numpy.ndarray
            The response on ``t``.
        """
        t = np.asarray(t, float)
        if not self.terms:
            return np.zeros_like(t)
        y = np.zeros(t.shape, complex)
        tp = np.clip(t, 0.0, None)
        for k, (p, m, c) in enumerate(self.terms):
            # c[j] multiplies 1/(s - p)^(m - j): t^(m-j-1)/(m-j-1)! e^(p t). A simple pole's polynomial is
            # its constant c[0] (t^0/0! is 1 exactly) and the step's pole at 0 has e^(0 t) = 1 exactly: both
            # taken as scalars, the same numbers without four array passes a term (a plant's analysis
            # evaluates some 25 steps)
            poly_t = c[0] if m == 1 else sum(c[j] * tp ** (m - j - 1) / math.factorial(m - j - 1)
                                             for j in range(m))
            if exps is not None:
                y = y + poly_t * exps[k]
            elif p == 0:
                y = y + poly_t
            else:
                y = y + poly_t * np.exp(p * tp)
        return np.where(t >= 0, y.real, 0.0)


#: widest relative diameter of a group of poles taken as one repeated pole
MAX_CLUSTER = 1e-3


def pole_clusters(poles, spread: float = 100.0):
    """Group numerically repeated poles: [(mean pole, multiplicity), ...].

    ``np.roots`` splits an m-fold root into m roots about eps^(1/m) |p| apart
    (1e-8 for a double root, 1e-4 for a quadruple one); their mean is accurate
    to about eps. Each group is the largest set of a pole's nearest neighbours
    whose diameter is within ``spread`` eps^(1/m) |p| (and never over
    ``MAX_CLUSTER`` |p|: eps^(1/m) nears 1 for large m). The spread is wide
    because the split grows with the polynomial's other roots (a triple root
    beside a double one 30 times faster splits ten times wider than alone).
    Merging genuinely distinct poles that close changes the response by
    O((dp t)^2) only, while keeping them apart cancels catastrophically: their
    residues grow as 1/dp^(m-1).

    Parameters
    ----------
    poles : array_like
        The poles.
    spread : float
        How many times the expected split of a repeated root still counts as one.

    Returns
    -------
    list of tuple
        (mean pole, multiplicity).
    """
    eps = np.finfo(float).eps
    rest = [complex(p) for p in np.asarray(poles, complex)]
    groups = []
    while rest:
        p = rest[0]
        near = sorted(rest, key=lambda q: abs(q - p))
        # the largest group of p's nearest poles that is tight enough to be one root
        for m in range(len(near), 0, -1):
            g = near[:m]
            scale = max(abs(x) for x in g)
            tol = min(spread * eps ** (1.0 / m), MAX_CLUSTER) * scale
            if m == 1 or max(abs(a - b) for a in g for b in g) <= tol:
                break
        groups.append(g)
        for q in g:
            rest.remove(q)
    out = []
    for g in groups:
        mean = complex(np.mean(g))
        if abs(mean.imag) <= min(spread * eps ** (1.0 / len(g)), MAX_CLUSTER) * abs(mean):
            mean = complex(mean.real, 0.0)
        out.append((mean, len(g)))
    return out


def _taylor(poly, p, n):
    """First ``n`` Taylor coefficients of the polynomial ``poly`` (descending) at ``p``."""
    out, d = [], np.asarray(poly, complex)
    for j in range(n):
        out.append(np.polyval(d, p) / math.factorial(j) if d.size else 0j)
        d = np.polyder(d) if d.size > 1 else np.array([0j])
    return out


def _series_ratio(a, b):
    """Taylor coefficients of a(x)/b(x) from those of a and b (b[0] != 0)."""
    q = []
    for j in range(len(a)):
        q.append((a[j] - sum(b[i] * q[j - i] for i in range(1, j + 1))) / b[0])
    return q


def freq_response(num, den, f_hz):
    """Complex H(j 2 pi f) at the frequencies ``f_hz``.

    Parameters
    ----------
    num, den : array_like
        The transfer function, highest power first.
    f_hz : array_like
        The frequencies (Hz).

    Returns
    -------
    numpy.ndarray
        The complex response.
    """
    s = 2j * np.pi * np.asarray(f_hz, float)
    return np.polyval(num, s) / np.polyval(den, s)


def dense_time(t_end: float, n: int = 20001):
    """Uniform grid from 0 to ``t_end`` (dense: crossing times then interpolate well).

    Parameters
    ----------
    t_end : float
        The grid's end (s).
    n : int
        Its points.

    Returns
    -------
    numpy.ndarray
        The grid.
    """
    return np.linspace(0.0, t_end, n)


#: samples per block of :func:`_first_order_scan` (a block's powers a^m stay well inside the floats)
SCAN_BLOCK = 64


def _first_order_scan(a: complex, f: np.ndarray) -> np.ndarray:
    """z_0 = 0, z_(k+1) = a z_k + f_k: the whole sequence, a block of
    :data:`SCAN_BLOCK` samples at a time (each block from rest as one matrix
    product, then the carries block by block)."""
    n = f.size + 1
    pad = (-f.size) % SCAN_BLOCK
    blocks = np.concatenate([f, np.zeros(pad, dtype=f.dtype)]).reshape(-1, SCAN_BLOCK)
    m = np.arange(SCAN_BLOCK)
    lag = m[:, None] - m[None, :]
    with np.errstate(all="ignore"):
        toeplitz = np.where(lag >= 0, np.power(a, np.maximum(lag, 0)), 0.0)
    within = blocks @ toeplitz.T               # state after each sample of a block, from rest
    powers = np.power(a, m + 1)
    step = a ** SCAN_BLOCK
    out = np.empty_like(within)
    carry = 0.0
    for b in range(within.shape[0]):
        out[b] = powers * carry + within[b]
        carry = step * carry + within[b, -1]
    return np.concatenate([[0.0], out.ravel()[: n - 1]])


def filter_foh(num, den, t, x) -> np.ndarray:
    """The output of num/den (proper, from rest) for the input samples ``x`` on
    the uniform grid ``t``, the input taken linear between samples (first-order
    hold: exact for a piecewise-linear input), as ``scipy.signal``'s
    ``cont2discrete(method="foh")`` and ``lfilter`` give it, without importing
    scipy.signal (a second of start-up on a loaded machine).

    H = D + sum r_i/(s - p_i) (distinct poles): each pole a mode z' = p z + u,
    sampled exactly, z_(k+1) = e^(p h) z_k + (I0 - I1) u_k + I1 u_(k+1), with
    I0 = (e^(p h) - 1)/p and I1 = (e^(p h) - 1 - p h)/(p^2 h), and
    y = D u + sum r_i z_i. Repeated (or nearly repeated) poles have no such
    basis: scipy.signal does those.

    Parameters
    ----------
    num, den : array_like
        The transfer function, highest power first.
    t : array_like
        The uniform grid (s).
    x : array_like
        The input on ``t``.

    Returns
    -------
    numpy.ndarray
        The output on ``t``.
    """
    num = np.atleast_1d(np.asarray(num, float))
    den = np.atleast_1d(np.asarray(den, float))
    den = den[np.flatnonzero(den)[0]:]
    num = num[np.flatnonzero(num)[0]:] if np.any(num) else np.array([0.0])
    t = np.asarray(t, float)
    x = np.asarray(x, float)
    if num.size > den.size:
        raise DesignError("improper transfer function (numerator of higher degree than the denominator)")
    num, den = num / den[0], den / den[0]
    if den.size == 1:
        return num[-1] * x
    d = num[0] if num.size == den.size else 0.0
    rest = np.polysub(num, d * den) if d else num
    poles = np.roots(den)
    close = np.abs(poles[:, None] - poles[None, :]) <= 1e-6 * np.maximum(np.abs(poles[:, None]), 1e-300)
    if np.count_nonzero(close) > poles.size:   # a repeated pole: no modal basis
        from scipy.signal import cont2discrete, lfilter
        bd, ad, _ = cont2discrete((num, den), t[1] - t[0], method="foh")
        return lfilter(np.ravel(bd), np.ravel(ad), x)
    h = float(t[1] - t[0])
    dden = np.polyder(den)
    y = d * x.astype(complex)
    for p in poles:
        r = np.polyval(rest, p) / np.polyval(dden, p)
        ph = p * h
        a = np.exp(ph)
        if abs(ph) < 1e-4:   # the series: the closed forms cancel catastrophically
            i0, i1 = h * (1 + ph / 2 + ph * ph / 6), h * (0.5 + ph / 6 + ph * ph / 24)
        else:
            i0, i1 = (a - 1) / p, (a - 1 - ph) / (p * p * h)
        f = (i0 - i1) * x[:-1] + i1 * x[1:]
        y = y + r * _first_order_scan(a, f.astype(complex))
    return y.real


def slowest_settling_s(den) -> float:
    """ln(50) / min |Re p| over the poles p of ``den``: when the slowest mode's envelope exp(-sigma t) is at
    2 % (4 / (zeta wn) for a dominant pair; Ogata, *Modern Control Engineering*, 5th ed., section 5-3).

    Parameters
    ----------
    den : array_like
        The denominator, highest power first.

    Returns
    -------
    float
        Seconds.
    """
    sigma = np.abs(np.real(np.roots(np.asarray(den, float))))
    return math.log(50.0) / float(np.min(sigma))
