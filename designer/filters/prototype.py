"""Normalised low-pass prototypes from scipy.signal, their poles paired into
sections, and the order a mask needs.

The poles come from scipy.signal's analog prototypes, never from hand-typed
tables (scipy.signal docs: ``buttap``, ``besselap``, ``cheb1ap``, ``buttord``,
``cheb1ord``; the section tables of TI's "Op Amps for Everyone", ch. 16,
SLOA088, and Zverev's "Handbook of Filter Synthesis" are what they reproduce):

- Butterworth: ``buttap(n)``, -3 dB at 1 rad/s;
- Bessel: ``besselap(n, norm)``, ``norm="mag"`` (-3 dB at 1 rad/s, the
  convention of scipy's ``bessel`` default and of most tables) or
  ``norm="delay"`` (group delay 1 s at DC; the cut-off then names the delay
  1 / (2 pi fc)) -- the literature mixes them, so the caller chooses;
- Chebyshev type I: ``cheb1ap(n, rp)``, the ripple edge at 1 rad/s (scipy's
  ``cheby1`` convention), or rescaled so that 1 rad/s is the -3 dB point:
  |H|^2 = 1 / (1 + eps^2 T_n(w)^2) is -3 dB where T_n(w) = 1/eps, i.e. at
  w3 = cosh(acosh(1/eps) / n), eps = sqrt(10^(rp/10) - 1) (valid for rp < 3.01 dB).

Pairing: a complex pair p, p* is the section s^2 + (wn/Q) s + wn^2 with
wn = |p| and Q = wn / (-2 Re p); a real pole -wn is a first-order section.
A high-pass is the low-pass transformation s -> wc/s: each section keeps its Q
and its wn becomes 1/wn (SLOA088: the high-pass uses the low-pass coefficients).
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np
from scipy import signal

from ..core.errors import DesignError

__all__ = ["FAMILIES", "RESPONSE_TYPES", "BESSEL_NORMS", "CHEBYSHEV_CUTOFFS", "BANDPASS_METHODS", "MAX_ORDER",
           "BESSEL_SEARCH_ORDER", "WIDE_RATIO", "SectionPlan", "prototype_zpk", "plan_sections", "reference_ba", "reference_response",
           "order_from_mask", "bandpass_from_mask", "group_delay", "delay_error_pct", "DELAY_POINTS", "chebyshev_3db_factor", "bandpass_method", "plan_bandpass", "reference_bandpass"]

FAMILIES = ("butterworth", "bessel", "chebyshev")
RESPONSE_TYPES = ("lowpass", "highpass", "bandpass")
#: how a band-pass is built: ``wide`` a high-pass at the lower edge then a low-pass at the upper one,
#: ``narrow`` the band-pass transformation of the prototype into band-pass sections; ``auto`` by :data:`WIDE_RATIO`
BANDPASS_METHODS = ("auto", "wide", "narrow")
#: the edge ratio f_high / f_low from which ``auto`` builds a band-pass as a low-pass and high-pass cascade
WIDE_RATIO = 2.0
BESSEL_NORMS = ("mag", "delay")
CHEBYSHEV_CUTOFFS = ("ripple", "3db")
MAX_ORDER = 10
#: how far a Bessel mask beyond :data:`MAX_ORDER` is searched to name the order it needs (a Bessel's skirt
#: tends to a Gaussian's as its order grows, so its attenuation at a given edge peaks at some order and then
#: falls: a mask may need no order at all)
BESSEL_SEARCH_ORDER = 25


@dataclass(frozen=True)
class SectionPlan:
    """One section of the normalised design.

    Parameters
    ----------
    kind : str
        ``lowpass`` or ``highpass``.
    order : int
        1 or 2.
    fn_hz : float
        Natural (corner) frequency, Hz, after scaling to the cut-off.
    q : float or None
        Quality factor (None for first order).
    """

    kind: str
    order: int
    fn_hz: float
    q: float | None


def chebyshev_3db_factor(order: int, ripple_db: float) -> float:
    """w3: the -3 dB frequency of the Chebyshev prototype whose ripple edge is 1 rad/s.

    Parameters
    ----------
    order : int
        Filter order.
    ripple_db : float
        Passband ripple, dB (below 3.01 dB).

    Returns
    -------
    float
        cosh(acosh(1/eps) / n), eps = sqrt(10^(rp/10) - 1).
    """
    eps = math.sqrt(10 ** (ripple_db / 10) - 1)
    return math.cosh(math.acosh(1 / eps) / order)


def prototype_zpk(family: str, order: int, ripple_db: float = 1.0, bessel_norm: str = "mag",
                  chebyshev_cutoff: str = "ripple") -> tuple:
    """The normalised analog low-pass prototype (cut-off 1 rad/s in the chosen convention).

    Parameters
    ----------
    family : str
        One of :data:`FAMILIES`.
    order : int
        1..:data:`MAX_ORDER`.
    ripple_db : float
        Chebyshev passband ripple, dB.
    bessel_norm : str
        ``mag`` or ``delay`` (scipy's ``besselap`` normalisations).
    chebyshev_cutoff : str
        ``ripple`` (the ripple edge at 1 rad/s) or ``3db``.

    Returns
    -------
    tuple
        (zeros, poles, k) as scipy returns them (poles rescaled for ``3db``).
    """
    if family == "butterworth":
        return signal.buttap(order)
    if family == "bessel":
        return signal.besselap(order, norm=bessel_norm)
    z, p, k = signal.cheb1ap(order, ripple_db)
    if chebyshev_cutoff == "3db":
        # s -> s w3 moves the -3 dB point from w3 to 1: poles / w3, and k / w3^n keeps the gain
        w3 = chebyshev_3db_factor(order, ripple_db)
        p, k = p / w3, k / w3 ** order
    return z, p, k


def plan_sections(kind: str, family: str, order: int, fc_hz: float, ripple_db: float = 1.0,
                  bessel_norm: str = "mag", chebyshev_cutoff: str = "ripple") -> list:
    """The prototype's poles as sections scaled to ``fc_hz``, in rising Q
    (the first-order section first; it has no peak).

    Parameters
    ----------
    kind : str
        ``lowpass`` or ``highpass``.
    family, order, ripple_db, bessel_norm, chebyshev_cutoff
        As :func:`prototype_zpk`.
    fc_hz : float
        The cut-off, Hz.

    Returns
    -------
    list of SectionPlan
        Sections sorted by Q (first order first).
    """
    _, poles, _ = prototype_zpk(family, order, ripple_db, bessel_norm, chebyshev_cutoff)
    plans = []
    for p in poles:
        if abs(p.imag) <= 1e-9 * abs(p):
            wn, q, n = -p.real, None, 1
        elif p.imag > 0:
            wn = abs(p)
            q, n = wn / (-2 * p.real), 2
        else:
            continue   # the conjugate of one already taken
        fn = fc_hz * wn if kind == "lowpass" else fc_hz / wn
        plans.append(SectionPlan(kind, n, float(fn), None if q is None else float(q)))
    return sorted(plans, key=lambda s: (s.order == 2, s.q or 0.0))


def reference_ba(kind: str, family: str, order: int, fc_hz: float, ripple_db: float = 1.0,
                 bessel_norm: str = "mag", chebyshev_cutoff: str = "ripple") -> tuple:
    """The target transfer function by scipy's own analog designers (``butter``,
    ``bessel``, ``cheby1``; ``analog=True``), its passband gain (DC for a
    low-pass, infinite frequency for a high-pass) normalised to 1.

    Parameters
    ----------
    kind, family, order, fc_hz, ripple_db, bessel_norm, chebyshev_cutoff
        As :func:`plan_sections`.

    Returns
    -------
    tuple of ndarray
        (b, a), polynomials in s (rad/s).
    """
    wc = 2 * math.pi * fc_hz
    btype = "low" if kind == "lowpass" else "high"
    if family == "butterworth":
        b, a = signal.butter(order, wc, btype, analog=True)
    elif family == "bessel":
        b, a = signal.bessel(order, wc, btype, analog=True, norm=bessel_norm)
    else:
        if chebyshev_cutoff == "3db":
            w3 = chebyshev_3db_factor(order, ripple_db)
            wc = wc / w3 if kind == "lowpass" else wc * w3
        b, a = signal.cheby1(order, ripple_db, wc, btype, analog=True)
    # the passband gain: b/a at s = 0 (low-pass) or the leading coefficients' ratio (high-pass)
    g = b[-1] / a[-1] if kind == "lowpass" else b[np.flatnonzero(b)[0]] / a[0] if len(b) == len(a) else \
        b[0] / a[0]
    return np.asarray(b) / g, np.asarray(a)


def reference_response(f_hz, *args, **kwargs) -> np.ndarray:
    """:func:`reference_ba` evaluated at ``f_hz`` (``scipy.signal.freqs``).

    Parameters
    ----------
    f_hz : ndarray
        Frequencies, Hz.
    *args, **kwargs
        As :func:`reference_ba`.

    Returns
    -------
    ndarray
        Complex H(j 2 pi f), passband gain 1.
    """
    b, a = reference_ba(*args, **kwargs)
    return signal.freqs(b, a, 2 * math.pi * np.asarray(f_hz, dtype=float))[1]


def _loss_db(kind, family, order, fc_hz, f_hz, ripple_db, bessel_norm):
    h = reference_response(np.atleast_1d(f_hz), kind, family, order, fc_hz, ripple_db, bessel_norm)
    return -20 * np.log10(np.abs(h))


def group_delay(zpk: tuple, f_hz, fc_hz: float = 1 / (2 * math.pi)) -> np.ndarray:
    """The group delay of a prototype scaled to ``fc_hz``, exact from its poles: for H = k / prod(s - p),
    tau(w) = -d arg H(jw) / dw = sum over the poles of -Re p / ((Re p)^2 + (w - Im p)^2) (zeros at the
    origin, a high-pass's, add none; a low-pass prototype has none).

    Parameters
    ----------
    zpk : tuple
        (zeros, poles, gain) of the normalised prototype (:func:`prototype_zpk`; cut-off 1 rad/s).
    f_hz : array_like
        Frequencies, Hz.
    fc_hz : float
        The cut-off the prototype is scaled to (its poles times 2 pi fc).

    Returns
    -------
    ndarray
        Group delay, s.
    """
    p = np.asarray(zpk[1], complex) * 2 * math.pi * fc_hz
    w = 2 * math.pi * np.asarray(f_hz, float)[..., None]
    return np.sum(-p.real / (p.real ** 2 + (w - p.imag) ** 2), axis=-1)


def delay_error_pct(tau: np.ndarray, tau_dc: float) -> float:
    """The largest departure of a group delay from its DC value, % of it.

    Parameters
    ----------
    tau : ndarray
        Group delay over the band the target covers, s.
    tau_dc : float
        The delay at DC, s.

    Returns
    -------
    float
        max |tau / tau_dc - 1| x 100.
    """
    return float(100 * np.max(np.abs(np.asarray(tau) / tau_dc - 1)))


#: points of the grid a group-delay target is judged on, from DC to its frequency
DELAY_POINTS = 201


def _bessel_order_beyond(kind, passband_hz, max_loss_db, stopband_hz, min_attenuation_db, bessel_norm,
                         max_delay_error_pct, delay_to_hz):
    """The least Bessel order from MAX_ORDER + 1 to BESSEL_SEARCH_ORDER meeting the mask (and the delay
    target), or None: :func:`order_from_mask`'s search on the normalised prototype alone. A low-pass's loss
    at f is L(f / fc) and a high-pass's L(fc / f), L the prototype's (monotonic: a Bessel does not peak), so
    the passband edge sits at the w_p where L(w_p) is the loss allowed, fc = f_p / w_p (high-pass f_p w_p),
    and the stopband edge at w_p times the edges' ratio."""
    ratio = stopband_hz / passband_hz if kind == "lowpass" else passband_hz / stopband_hz
    for order in range(MAX_ORDER + 1, BESSEL_SEARCH_ORDER + 1):
        _, p, _ = prototype_zpk("bessel", order, 1.0, bessel_norm)

        def loss(w, p=p):
            return float(20 * np.sum(np.log10(np.abs(1j * w - p) / np.abs(p))))
        lo, hi = -12.0, 12.0
        for _ in range(100):
            mid = 0.5 * (lo + hi)
            lo, hi = (lo, mid) if loss(math.exp(mid)) > max_loss_db else (mid, hi)
        w_p = math.exp(lo)
        if loss(w_p * ratio) < min_attenuation_db:
            continue
        if max_delay_error_pct is not None:
            tau = group_delay((None, p, None), np.linspace(0.0, delay_to_hz, DELAY_POINTS), passband_hz / w_p)
            if delay_error_pct(tau, tau[0]) > max_delay_error_pct:
                continue
        return order
    return None


def order_from_mask(kind: str, family: str, passband_hz: float, max_loss_db: float, stopband_hz: float,
                    min_attenuation_db: float, bessel_norm: str = "mag", max_delay_error_pct: float | None = None,
                    delay_to_hz: float | None = None) -> tuple:
    """The least order meeting the mask, and the cut-off it gives.

    Butterworth and Chebyshev by scipy's ``buttord`` and ``cheb1ord`` (``analog=True``;
    the Chebyshev's ripple is the mask's loss and its cut-off the passband edge);
    Bessel (no closed form) by search: for n = 1, 2, ... the cut-off that puts the
    loss at the passband edge at exactly ``max_loss_db`` (bisection on log fc,
    the loss falling monotonically as fc rises for a low-pass), then the
    attenuation at the stopband edge checked.

    Parameters
    ----------
    kind : str
        ``lowpass`` (passband below stopband) or ``highpass``.
    family : str
        One of :data:`FAMILIES`.
    passband_hz, max_loss_db, stopband_hz, min_attenuation_db : float
        The mask.
    bessel_norm : str
        The Bessel normalisation the cut-off is given in.
    max_delay_error_pct, delay_to_hz : float or None
        A Bessel low-pass's group-delay target: the delay within this % of its DC value from DC to
        ``delay_to_hz`` (:func:`group_delay`, on :data:`DELAY_POINTS` points); the least order meeting the
        mask and the target.

    Returns
    -------
    tuple
        (order, fc_hz): the cut-off in the family's convention (Butterworth -3 dB,
        Bessel per ``bessel_norm``, Chebyshev the ripple edge).

    Raises
    ------
    DesignError
        The mask needs more than :data:`MAX_ORDER` (naming the order it needs).
    """
    wp, ws = 2 * math.pi * passband_hz, 2 * math.pi * stopband_hz
    if family in ("butterworth", "chebyshev"):
        fn = signal.buttord if family == "butterworth" else signal.cheb1ord
        n, wn = fn(wp, ws, max_loss_db, min_attenuation_db, analog=True)
        n, fc = int(n), float(wn) / (2 * math.pi)
    else:
        n, fc, att = None, None, 0.0
        for order in range(1, MAX_ORDER + 1):
            lo, hi = math.log(passband_hz) - 12, math.log(passband_hz) + 12
            for _ in range(100):
                mid = 0.5 * (lo + hi)
                loss = _loss_db(kind, family, order, math.exp(mid), passband_hz, 1.0, bessel_norm)[0]
                # low-pass: a higher fc, less loss at the passband edge; high-pass the other way
                if (loss > max_loss_db) == (kind == "lowpass"):
                    lo = mid
                else:
                    hi = mid
            fc_try = math.exp(hi if kind == "lowpass" else lo)
            att = _loss_db(kind, family, order, fc_try, stopband_hz, 1.0, bessel_norm)[0]
            err = None
            if max_delay_error_pct is not None:
                zpk = prototype_zpk(family, order, 1.0, bessel_norm)
                tau = group_delay(zpk, np.linspace(0.0, delay_to_hz, DELAY_POINTS), fc_try)
                err = delay_error_pct(tau, tau[0])
            if att >= min_attenuation_db and (err is None or err <= max_delay_error_pct):
                n, fc = order, fc_try
                break
        if n is None:
            # no closed form names a Bessel's order: the search goes on (on the prototype alone) to say it
            need = _bessel_order_beyond(kind, passband_hz, max_loss_db, stopband_hz, min_attenuation_db,
                                        bessel_norm, max_delay_error_pct, delay_to_hz)
            which = (f"of order {need}, above the limit {MAX_ORDER}" if need is not None else
                     f"above order {MAX_ORDER}, and no order up to {BESSEL_SEARCH_ORDER} meets "
                     f"{'them' if max_delay_error_pct is not None else 'it'}: a Bessel's skirt tends to a "
                     "Gaussian's as its order grows")
        if n is None and max_delay_error_pct is not None:
            raise DesignError(f"order: the mask and the group-delay target need a Bessel filter {which} (order "
                              f"{MAX_ORDER}: {att:.3g} dB at the stopband edge, "
                              f"{min_attenuation_db:.3g} dB asked; the delay within {err:.3g} % up to "
                              f"{delay_to_hz:g} Hz, {max_delay_error_pct:g} % asked); lower --delay-to, allow more "
                              "delay error or widen the transition band", param="order")
        if n is None:
            raise DesignError(f"order: the mask needs a Bessel filter {which} (order {MAX_ORDER} "
                              f"gives {att:.3g} dB at the stopband edge, {min_attenuation_db:.3g} dB asked); widen "
                              "the transition band, or use butterworth or chebyshev", param="order")
    if n > MAX_ORDER:
        raise DesignError(f"order: the mask needs a {family} filter of order {n}, above the limit {MAX_ORDER}; "
                          "widen the transition band, allow more passband loss or less stopband attenuation",
                          param="order")
    return n, fc


def bandpass_method(f_low_hz: float, f_high_hz: float, method: str = "auto") -> str:
    """``wide`` or ``narrow``: ``method`` itself, or for ``auto`` wide from an edge ratio of :data:`WIDE_RATIO`.

    Parameters
    ----------
    f_low_hz, f_high_hz : float
        The band edges.
    method : str
        One of :data:`BANDPASS_METHODS`.

    Returns
    -------
    str
        ``wide`` or ``narrow``.
    """
    if method != "auto":
        return method
    return "wide" if f_high_hz / f_low_hz >= WIDE_RATIO else "narrow"


def plan_bandpass(family: str, order: int, f_low_hz: float, f_high_hz: float, ripple_db: float = 1.0,
                  bessel_norm: str = "mag", chebyshev_cutoff: str = "ripple", method: str = "auto") -> list:
    """The sections of a band-pass from the order-``order`` prototype, in rising Q.

    Wide: the high-pass at ``f_low_hz`` and the low-pass at ``f_high_hz`` (order ``order`` each).
    Narrow: the band-pass transformation s -> (s^2 + w0^2) / (B s), w0 = 2 pi sqrt(f_low f_high),
    B = 2 pi (f_high - f_low) (scipy's ``lp2bp``): each prototype pole p gives the roots of
    s^2 - p B s + w0^2 = 0, and each root in the upper half plane is a band-pass section
    (wn = |r|, Q = wn / (-2 Re r)); a real pole gives the one section s^2 - p B s + w0^2:
    ``order`` sections, filter order 2 x ``order``.

    Parameters
    ----------
    family, order, ripple_db, bessel_norm, chebyshev_cutoff
        As :func:`prototype_zpk`.
    f_low_hz, f_high_hz : float
        The band edges (in the family's cut-off convention).
    method : str
        One of :data:`BANDPASS_METHODS`.

    Returns
    -------
    list of SectionPlan
        Sorted by Q (first-order sections first).
    """
    conv = (ripple_db, bessel_norm, chebyshev_cutoff)
    if bandpass_method(f_low_hz, f_high_hz, method) == "wide":
        plans = plan_sections("highpass", family, order, f_low_hz, *conv) + \
            plan_sections("lowpass", family, order, f_high_hz, *conv)
        return sorted(plans, key=lambda s: (s.order == 2, s.q or 0.0))
    _, poles, _ = prototype_zpk(family, order, *conv)
    w0 = 2 * math.pi * math.sqrt(f_low_hz * f_high_hz)
    bw = 2 * math.pi * (f_high_hz - f_low_hz)
    plans = []
    for p in poles:
        if abs(p.imag) <= 1e-9 * abs(p):
            # a real pole: s^2 - p B s + w0^2 is one section (wn = w0, Q = w0 / (-p B)), even when its roots
            # are real (Q < 1/2, a wide band)
            plans.append(SectionPlan("bandpass", 2, float(w0 / (2 * math.pi)), float(w0 / (-p.real * bw))))
            continue
        d = np.sqrt(complex(p * bw) ** 2 - 4 * w0 * w0)
        for r in ((p * bw + d) / 2, (p * bw - d) / 2):
            if r.imag > 1e-12 * abs(r):
                wn = abs(r)
                plans.append(SectionPlan("bandpass", 2, float(wn / (2 * math.pi)), float(wn / (-2 * r.real))))
    return sorted(plans, key=lambda s: s.q)


def reference_bandpass(f_hz, family: str, order: int, f_low_hz: float, f_high_hz: float, ripple_db: float = 1.0,
                       bessel_norm: str = "mag", chebyshev_cutoff: str = "ripple", method: str = "auto") -> np.ndarray:
    """The band-pass target at ``f_hz``: wide, the product of :func:`reference_response`'s high-pass and
    low-pass (each passband gain 1); narrow, scipy's ``lp2bp_zpk`` of the prototype, gain 1 at the centre.

    Parameters
    ----------
    f_hz : ndarray
        Frequencies, Hz.
    family, order, f_low_hz, f_high_hz, ripple_db, bessel_norm, chebyshev_cutoff, method
        As :func:`plan_bandpass`.

    Returns
    -------
    ndarray
        Complex H(j 2 pi f).
    """
    f = np.asarray(f_hz, dtype=float)
    conv = (ripple_db, bessel_norm, chebyshev_cutoff)
    if bandpass_method(f_low_hz, f_high_hz, method) == "wide":
        return reference_response(f, "highpass", family, order, f_low_hz, *conv) * \
            reference_response(f, "lowpass", family, order, f_high_hz, *conv)
    z, p, k = prototype_zpk(family, order, *conv)
    w0 = 2 * math.pi * math.sqrt(f_low_hz * f_high_hz)
    z, p, k = signal.lp2bp_zpk(z, p, k, w0, 2 * math.pi * (f_high_hz - f_low_hz))
    h = signal.freqs_zpk(z, p, k, 2 * math.pi * np.append(f, math.sqrt(f_low_hz * f_high_hz)))[1]
    return h[:-1] / abs(h[-1])


def _band_loss_db(f_hz, family, order, f_low_hz, f_high_hz, conv, method) -> np.ndarray:
    return -20 * np.log10(np.abs(reference_bandpass(np.atleast_1d(f_hz), family, order, f_low_hz, f_high_hz,
                                                    *conv, method)))


def _first_feasible(lo: float, hi: float, ok) -> float:
    """The first x from ``lo`` towards ``hi`` (either way round; log scale) where ``ok(x)``: a scan of 40 points a
    decade, then 50 halvings between the last refused point and the first accepted one. A scan, not a bisection
    over the whole span, because a Chebyshev's loss at an edge is not monotonic in its cut-off (the ripple):
    the set of accepted cut-offs has gaps, and the nearest one is the one that attenuates most."""
    grid = np.geomspace(lo, hi, max(2, int(abs(math.log10(hi / lo)) * 40) + 1))
    prev = None
    for x in grid:
        if ok(x):
            break
        prev = x
    else:
        return float(hi)
    if prev is None:
        return float(x)
    a, b = math.log(prev), math.log(x)
    for _ in range(50):
        mid = 0.5 * (a + b)
        if ok(math.exp(mid)):
            b = mid
        else:
            a = mid
    return math.exp(b)


def _band_edges_search(family, order, passband, max_loss_db, conv, method) -> tuple:
    """(f_low, f_high) of an order-``order`` band-pass whose loss over the passband is at most ``max_loss_db``,
    its edges as close to the passband as that allows (the most stopband attenuation).

    Wide: the low-pass edge upwards from p2 / 2, the loss over the passband's upper half held to the limit,
    and the high-pass edge downwards from 2 p1, over its lower half, each with the other held, alternated until
    they settle (each side's loss at the far edge is small but not nil: a first-order high-pass still takes
    0.97 dB an octave above its corner). Narrow: the centre the passband's geometric centre, the bandwidth
    the least that holds the loss over the passband (the transformation is geometrically symmetric).
    """
    p1, p2 = passband
    grid = np.geomspace(p1, p2, 41)
    limit = max_loss_db * (1 + 1e-9)
    if method == "wide":
        upper, lower = grid[grid >= math.sqrt(p1 * p2)], grid[grid <= math.sqrt(p1 * p2)]
        # each side's normalised design once (cut-off 1 rad/s): at cut-off fc its loss at f is the normalised one at f / fc
        norm = {k: reference_ba(k, family, order, 1 / (2 * math.pi), *conv) for k in ("lowpass", "highpass")}
        side = lambda kind, f, fc: -20 * np.log10(np.abs(signal.freqs(*norm[kind], f / fc)[1]))  # noqa: E731
        fl, fh = p1 / 2, p2 * 2
        for _ in range(8):
            before = (fl, fh)
            held = side("highpass", upper, fl)   # the product's loss in dB: the sides' losses add
            fh = _first_feasible(p2 / 2, p2 * 100, lambda x: np.max(held + side("lowpass", upper, x)) <= limit)
            held = side("lowpass", lower, fh)
            fl = _first_feasible(p1 * 2, p1 / 100, lambda x: np.max(held + side("highpass", lower, x)) <= limit)
            if math.isclose(fl, before[0], rel_tol=1e-12) and math.isclose(fh, before[1], rel_tol=1e-12):
                break
        return fl, fh
    f0 = math.sqrt(p1 * p2)
    z, p, k = prototype_zpk(family, order, *conv)   # once: reference_bandpass's transformation, per bandwidth

    def loss(bw):
        zb, pb, kb = signal.lp2bp_zpk(z, p, k, 2 * math.pi * f0, 2 * math.pi * bw)
        h = np.abs(signal.freqs_zpk(zb, pb, kb, 2 * math.pi * np.append(grid, f0))[1])
        return -20 * np.log10(h[:-1] / h[-1])

    bw = _first_feasible((p2 - p1) / 4, (p2 - p1) * 100, lambda b: np.max(loss(b)) <= limit)
    return _centred(f0, bw)


def _centred(f0: float, bw: float) -> tuple:
    """The edges (f_low, f_high) of geometric centre ``f0`` and width ``bw``: f_low f_high = f0^2, f_high - f_low = bw."""
    fl = (-bw + math.sqrt(bw * bw + 4 * f0 * f0)) / 2
    return fl, fl + bw


def bandpass_from_mask(family: str, passband_hz: tuple, max_loss_db: float, stopband_hz: tuple,
                       min_attenuation_db: float, bessel_norm: str = "mag", chebyshev_cutoff: str = "ripple",
                       method: str = "auto") -> tuple:
    """The least prototype order, band edges and method of a band-pass meeting a mask.

    The method (``wide`` or ``narrow``) is :func:`bandpass_method` of the passband edges.
    Narrow Butterworth and Chebyshev: scipy's ``buttord`` / ``cheb1ord`` with the band-pass edges
    (``analog=True``; their ``wn`` are the edges of ``lp2bp``'s transformation, the one
    :func:`plan_bandpass` uses; a Chebyshev at ``3db`` takes the edges where the prototype's
    w3 (:func:`chebyshev_3db_factor`) lands: f = (w3 B + sqrt(w3^2 B^2 + 4 f0^2)) / 2).
    Bessel, and every wide band-pass (a high-pass and a low-pass of the same order, whose response
    is not ``lp2bp``'s): for n = 1, 2, ... the edges that put the loss at the passband edges at
    ``max_loss_db`` (bisection), then the attenuation at both stopband edges checked. Every answer
    is checked on :func:`reference_bandpass` at the four edges.

    Parameters
    ----------
    family : str
        One of :data:`FAMILIES` (a Chebyshev's ripple is ``max_loss_db``).
    passband_hz, stopband_hz : tuple of float
        (low, high) edges, Hz; the stopband's outside the passband's.
    max_loss_db, min_attenuation_db : float
        The mask's largest passband loss and least stopband attenuation, dB.
    bessel_norm, chebyshev_cutoff : str
        The cut-off conventions the edges are given in (:func:`prototype_zpk`).
    method : str
        One of :data:`BANDPASS_METHODS`.

    Returns
    -------
    tuple
        (order of the prototype, f_low_hz, f_high_hz, method): the band-pass's order is 2 x order.

    Raises
    ------
    DesignError
        The mask needs a prototype above :data:`MAX_ORDER`: naming the order it needs (searched up to
        :data:`BESSEL_SEARCH_ORDER` where no closed form gives it) and what order 10 gives.
    """
    method = bandpass_method(passband_hz[0], passband_hz[1], method)
    conv = (max_loss_db, bessel_norm, chebyshev_cutoff)

    inside = np.geomspace(*passband_hz, 41)

    def meets(n, fl, fh) -> tuple:
        # the loss over the passband (its edges among the points; a Chebyshev's troughs inside), the
        # attenuation at the stopband edges (the skirts fall monotonically beyond them)
        loss = _band_loss_db(np.array([*inside, *stopband_hz]), family, n, fl, fh, conv, method)
        att = float(min(loss[-2:]))
        return max(loss[:-2]) <= max_loss_db * (1 + 1e-6) + 1e-9 and att >= min_attenuation_db * (1 - 1e-6), att

    start = 1
    if family != "bessel" and method == "narrow":
        fn = signal.buttord if family == "butterworth" else signal.cheb1ord
        n, wn = fn(2 * math.pi * np.asarray(passband_hz, float), 2 * math.pi * np.asarray(stopband_hz, float),
                   max_loss_db, min_attenuation_db, analog=True)
        n = int(n)
        if n > MAX_ORDER:
            raise DesignError(f"order: the band-pass mask needs a {family} prototype of order {n} (a band-pass of "
                              f"order {2 * n}), above the limit {MAX_ORDER}; widen the transition bands, allow more "
                              "passband loss or less stopband attenuation", param="order")
        fl, fh = (float(w) / (2 * math.pi) for w in wn)
        if family == "chebyshev" and chebyshev_cutoff == "3db":
            w3 = chebyshev_3db_factor(n, max_loss_db)
            fl, fh = _centred(math.sqrt(fl * fh), w3 * (fh - fl))
        if meets(n, fl, fh)[0]:
            return n, fl, fh, method
        start = n + 1
    elif family != "bessel":
        # a wide band-pass needs at least what each side needs alone (scipy's buttord / cheb1ord per side)
        fn = signal.buttord if family == "butterworth" else signal.cheb1ord
        start = max(int(fn(2 * math.pi * p, 2 * math.pi * st, max_loss_db, min_attenuation_db, analog=True)[0])
                    for p, st in zip(passband_hz, stopband_hz))
    for n in range(start, MAX_ORDER + 1):
        fl, fh = _band_edges_search(family, n, passband_hz, max_loss_db, conv, method)
        ok, att = meets(n, fl, fh)
        if ok:
            return n, fl, fh, method
    # no closed form names the order of a Bessel (or of a wide band-pass): the search goes on to say it, as
    # order_from_mask's does, and order 10's attenuation is what the refusal shows beside it
    att = meets(MAX_ORDER, *_band_edges_search(family, MAX_ORDER, passband_hz, max_loss_db, conv, method))[1] \
        if start > MAX_ORDER else att
    need = next((n for n in range(max(start, MAX_ORDER + 1), BESSEL_SEARCH_ORDER + 1)
                 if meets(n, *_band_edges_search(family, n, passband_hz, max_loss_db, conv, method))[0]), None)
    which = (f"of order {need} (a band-pass of order {2 * need}), above the limit {MAX_ORDER}" if need is not None
             else f"above order {MAX_ORDER}, and no order up to {BESSEL_SEARCH_ORDER} meets it"
             + (": a Bessel's skirt tends to a Gaussian's as its order grows" if family == "bessel" else ""))
    raise DesignError(f"order: the band-pass mask needs a {family} prototype {which} ({method} band-pass: order "
                      f"{MAX_ORDER} gives {att:.3g} dB at the stopband edges, {min_attenuation_db:.3g} dB asked); "
                      "widen the transition bands, or allow more passband loss", param="order")
