"""Sallen-Key low-pass synthesis (seed 001, sections IV.3-IV.9).

Topology and names follow the seed: R1 from the input to node V1, R2 from V1
to the non-inverting input, C1 from the non-inverting input to ground, C2 from
V1 to the output; gain K = 1 + R4/R3 (R3 to ground, R4 feedback), K = 1 is a
voltage follower.

    Vs/Ve = K / (a s^2 + b s + 1),  a = R1 R2 C1 C2,
    b = C1 (R1 + R2) + R1 C2 (1 - K)
    wn = 1/sqrt(a),  zeta = b / (2 sqrt(a)),  Q = 1 / (2 zeta)

These formulas live in :func:`coefficients` and :func:`wn_zeta` only (the
parts' properties, :func:`fn_zeta`, the section's ideal-pair hook and the
vectorised search use them). At unity gain zeta can
only be reached with C2/C1 >= 1/zeta^2 (:func:`unity_gain_c2_min`).
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

from ..core.errors import DesignError
from ..core.ranges import RANGES, parse_in_range

__all__ = ["DEFAULT_R3_OHM", "GAIN_TOLERANCE", "JSON_KEYS", "NETWORK_KEYS", "SallenKeyParts", "check_parts", "coefficients", "exact_on_capacitors", "fn_zeta",
          
           "opamp_denominator", "ratios_from_rc", "realizability_notes", "pair_of", "resistors_for_caps", "seed_ratios", "wn_zeta"]

#: the result.json key of each field of the record (:meth:`SallenKeyParts.as_dict`), the network first
JSON_KEYS = {"r1": "R1_ohm", "r2": "R2_ohm", "c1": "C1_f", "c2": "C2_f", "r3": "R3_ohm", "r4": "R4_ohm"}
#: the keys of the RC network (a follower's every part), in the record's order
NETWORK_KEYS = tuple(JSON_KEYS.values())[:4]


@dataclass(frozen=True)
class SallenKeyParts:
    """Component values of a Sallen-Key low-pass (ohms and farads).

    Parameters
    ----------
    r1, r2 : float
        The input resistor and the resistor to the non-inverting input.
    c1, c2 : float
        The capacitor to ground and the feedback capacitor.
    gain : float
        K = 1 + R4/R3 (1: a follower).
    r3, r4 : float or None
        The gain pair: to ground and feedback (None for a follower).
    """

    r1: float
    r2: float
    c1: float
    c2: float
    gain: float = 1.0
    r3: float | None = None  #: gain-setting resistor to ground (None for a follower)
    r4: float | None = None  #: gain-setting feedback resistor

    @property
    def a(self) -> float:
        return coefficients(self.r1, self.r2, self.c1, self.c2, self.gain)[0]

    @property
    def b(self) -> float:
        return coefficients(self.r1, self.r2, self.c1, self.c2, self.gain)[1]

    @property
    def wn(self) -> float:
        return float(wn_zeta(self.r1, self.r2, self.c1, self.c2, self.gain)[0])

    @property
    def fn_hz(self) -> float:
        return float(fn_zeta(self.r1, self.r2, self.c1, self.c2, self.gain)[0])

    @property
    def zeta(self) -> float:
        return float(fn_zeta(self.r1, self.r2, self.c1, self.c2, self.gain)[1])

    @property
    def q(self) -> float:
        return 1.0 / (2 * self.zeta) if self.zeta > 0 else math.inf

    def as_dict(self) -> dict:
        """The parts and their figures as result.json writes them.

        Returns
        -------
        dict
            :data:`JSON_KEYS` of the parts present, ``gain``, ``fn_hz`` and ``zeta``.
        """
        d = {key: getattr(self, f) for f, key in JSON_KEYS.items() if getattr(self, f) is not None}
        d.update(gain=self.gain, fn_hz=self.fn_hz, zeta=self.zeta)
        return d


def coefficients(r1, r2, c1, c2, gain=1.0):
    """a and b of K / (a s^2 + b s + 1), for numbers or arrays of them.

    Parameters
    ----------
    r1, r2, c1, c2 : float or array_like
        The parts (Ohm, F).
    gain : float or array_like
        The gain K.

    Returns
    -------
    tuple
        (a, b).
    """
    return r1 * r2 * c1 * c2, c1 * (r1 + r2) + r1 * c2 * (1.0 - gain)


def opamp_denominator(r1, r2, c1, c2, gain, a0, gbw_hz):
    """D(s) of the Sallen-Key low-pass with a single-pole op-amp, Vo/Vin = 1/D(s)
    (third order; numbers or arrays of them, the coefficients on the last axis).

    Node equations with Vp = Vo (1/A + 1/K) and V1 = Vp (1 + s R2 C1) give
    D = (N/A0) [(1 + s R2 C1)(1 + R1/R2 + s R1 C2) - R1/R2] - s R1 C2,
    N = 1 + A0/K + s/wp, wp = 2 pi GBW / A0; as A0, wp -> inf, Vo/Vin -> K/(a s^2 + b s + 1).
    The products are written out in the order :func:`numpy.polymul` takes them, so that a
    scalar's coefficients are the ones the plant's model has always had.

    Parameters
    ----------
    r1, r2, c1, c2 : float or array_like
        The parts (Ohm, F).
    gain : float or array_like
        The gain K.
    a0 : float
        The op-amp's DC gain (V/V).
    gbw_hz : float
        Its gain-bandwidth, Hz.

    Returns
    -------
    ndarray
        D's coefficients, highest power first, shape ``batch + (4,)`` (D(0) is not 1).
    """
    wp = 2 * math.pi * gbw_hz / a0
    n1, n0 = (1.0 / wp) / a0, (1.0 + a0 / gain) / a0
    # (R2 C1 s + 1)(R1 C2 s + 1 + R1/R2) - R1/R2
    i2 = (r2 * c1) * (r1 * c2)
    i1 = (r2 * c1) * (1.0 + r1 / r2) + (r1 * c2)
    i0 = (1.0 + r1 / r2) - r1 / r2
    d = (n1 * i2, n1 * i1 + n0 * i2, n1 * i0 + n0 * i1 - r1 * c2, n0 * i0)
    return np.stack(np.broadcast_arrays(*(np.asarray(x, dtype=float) for x in d)), axis=-1)


def wn_zeta(r1, r2, c1, c2, gain=1.0):
    """Angular natural frequency (rad/s) and damping of the Sallen-Key low-pass, for
    numbers or arrays of them: wn = 1/sqrt(a), zeta = b / (2 sqrt(a)) (the section's
    :meth:`~designer.filters.topology.Topology.ideal_wn_zeta`, its parts record's and the
    joint search's arithmetic).

    Parameters
    ----------
    r1, r2, c1, c2 : float or array_like
        The parts (Ohm, F).
    gain : float or array_like
        The gain K.

    Returns
    -------
    tuple
        (wn in rad/s, zeta).
    """
    return pair_of(*coefficients(r1, r2, c1, c2, gain))


def pair_of(a, b):
    """(wn in rad/s, zeta) of K / (a s^2 + b s + 1): wn = 1/sqrt(a), zeta = b / (2 sqrt(a))
    (numbers or arrays), the arithmetic of :func:`wn_zeta` on :func:`coefficients`' a and b.

    Parameters
    ----------
    a, b : float or array_like
        The coefficients of s^2 and s.

    Returns
    -------
    tuple
        (wn in rad/s, zeta).
    """
    sa = np.sqrt(a)
    return 1.0 / sa, b / (2 * sa)


def fn_zeta(r1, r2, c1, c2, gain=1.0):
    """Natural frequency (Hz) and damping of the Sallen-Key low-pass, for numbers
    or arrays of them (the joint search evaluates millions at once): :func:`wn_zeta`'s
    pair with fn = wn / (2 pi).

    Parameters
    ----------
    r1, r2, c1, c2 : float or array_like
        The parts (Ohm, F).
    gain : float or array_like
        The gain K.

    Returns
    -------
    tuple
        (fn in Hz, zeta).
    """
    wn, zeta = wn_zeta(r1, r2, c1, c2, gain)
    # wn = 1/sqrt(a) first, then fn: the rounding the designs' figures have always had
    return wn / (2 * np.pi), zeta


def unity_gain_c2_min(c1, zeta: float):
    """The smallest C2 with which a unity-gain Sallen-Key reaches ``zeta`` with C1:
    C2/C1 >= 1/zeta^2 (seed 001's realizability condition, n >= 1/zeta^2)."""
    return c1 / zeta ** 2


def ratios_from_rc(fc_hz: float, zeta: float, r: float, c: float, gain: float = 1.0):
    """The seed's procedure (simplification 2): fix R and C, solve m and n.

    With R1 = m R, R2 = R, C1 = C, C2 = n C:  m n = 1/(wn R C)^2 and
    m = 2 zeta sqrt(mn) - 1 + mn (K - 1),  n = mn / m.

    Parameters
    ----------
    fc_hz : float
        The natural frequency.
    zeta : float
        The damping.
    r : float
        R (Ohm).
    c : float
        C (F).
    gain : float
        The gain K.

    Returns
    -------
    (m, n) : tuple of float

    Raises
    ------
    DesignError
        When m <= 0, i.e. R C is too large for this fc and zeta; the message
        says how small R C must be.
    """
    wn = 2 * math.pi * fc_hz
    p = 1.0 / (wn * r * c) ** 2
    m = 2 * zeta * math.sqrt(p) - 1.0 + p * (gain - 1.0)
    if m <= 0:
        if gain == 1.0:
            limit = 2 * zeta / wn
            raise DesignError(
                f"no positive m, n for R = {r:g} Ohm, C = {c:g} F: unity gain needs "
                f"R*C < 2*zeta/wn = {limit:.4g} s (R*C is {r * c:.4g} s); choose a smaller R or C")
        raise DesignError(f"no positive m, n for R = {r:g} Ohm, C = {c:g} F at gain {gain:g}: "
                          "choose a smaller R or C, or a larger gain")
    return m, p / m


def resistors_for_caps(fc_hz: float, zeta: float, c1, c2, gain: float = 1.0):
    """Exact R1, R2 (ohms) that give fc and zeta with capacitors C1, C2.

    From R1 R2 = 1/(wn^2 C1 C2) and b = 2 zeta / wn:
    (C1 + C2 (1 - K)) R1^2 - (2 zeta/wn) R1 + C1/(wn^2 C1 C2) = 0.
    Vectorised over c1, c2. Returns two arrays (R1 roots, smaller first); a
    root is nan where it is not a positive real number (for unity gain that is
    C2/C1 < 1/zeta^2).

    Parameters
    ----------
    fc_hz : float
        The natural frequency.
    zeta : float
        The damping.
    c1, c2 : float or array_like
        The capacitors (F).
    gain : float
        The gain K.

    Returns
    -------
    tuple of numpy.ndarray
        The R1 roots, smaller first (nan where not a positive real number).
    """
    c1 = np.asarray(c1, float)
    c2 = np.asarray(c2, float)
    wn = 2 * np.pi * fc_hz
    alpha = c1 + c2 * (1.0 - gain)
    beta = 2 * zeta / wn
    gamma = 1.0 / (wn * wn * c2)
    with np.errstate(invalid="ignore", divide="ignore", over="ignore"):
        disc = beta * beta - 4 * alpha * gamma
        sq = np.sqrt(np.where(disc >= 0, disc, np.nan))
        # The cancellation-free form of the quadratic's roots: q = (beta + sq)/2
        # gives gamma/q and q/alpha, so an alpha near zero (K C2 close to
        # C1 + C2) leaves the finite root exact and sends the other to infinity.
        q = 0.5 * (beta + sq)
        ra = gamma / q
        rb = np.where(alpha != 0, q / alpha, np.nan)
        rb = np.where(np.isfinite(rb), rb, np.nan)
    lo = np.fmin(ra, rb)
    hi = np.fmax(ra, rb)
    lo = np.where(lo > 0, lo, np.nan)
    hi = np.where(hi > 0, hi, np.nan)
    lo2 = np.where(np.isnan(lo), hi, lo)
    hi2 = np.where(np.isnan(lo), np.nan, hi)
    return lo2, hi2


def realizability_notes(fc_hz: float, zeta: float, gain: float, c_lo: float, c_hi: float) -> list:
    """Plain-language warnings about a spec, with a suggested fix.

    Parameters
    ----------
    fc_hz : float
        The natural frequency.
    zeta : float
        The damping.
    gain : float
        The gain K.
    c_lo, c_hi : float
        The capacitors' range (F).

    Returns
    -------
    list of str
        The warnings.
    """
    notes = []
    if gain == 1.0:
        need = unity_gain_c2_min(1.0, zeta)
        if need > c_hi / c_lo:
            k = 1.0 + 1.0 / (2 * zeta) if zeta < 0.5 else 2.0
            notes.append(
                f"unity gain needs C2/C1 >= 1/zeta^2 = {need:.4g}, more than the capacitor bounds allow "
                f"({c_hi / c_lo:.4g}); use --gain K > 1 (e.g. --gain {k:.2g}) or widen --c-min/--c-max")
        elif need > 100:
            notes.append(
                f"unity gain needs C2/C1 >= 1/zeta^2 = {need:.4g}, an impractical capacitor ratio; "
                "a gain K > 1 (--gain) lowers it")
    elif gain >= 3.0:
        notes.append(f"gain K = {gain:g} >= 3 makes the equal-component Sallen-Key unstable; "
                     "it relies on R1 C2 (K-1) staying below C1 (R1 + R2), so damping is very sensitive to parts")
    return notes


#: relative mismatch allowed between a stated gain K and its resistors' 1 + R4/R3
GAIN_TOLERANCE = 1e-3
#: R3 when only K is given (R4 = (K - 1) R3), as the command-line tools derive it
DEFAULT_R3_OHM = 10e3
_PART_NAMES = {"r1": "R1", "r2": "R2", "c1": "C1", "c2": "C2", "r3": "R3", "r4": "R4", "gain": "gain K",
               "plant": "the plant"}


def check_parts(parts: SallenKeyParts, name_of=None, text: bool = False) -> SallenKeyParts:
    """The one validation of a Sallen-Key plant as built, however it arrives
    (designed, typed as parts, or read from a JSON file).

    Checks, in this order: every part value is a real number inside its
    physical range (``designer.core.ranges``: ``resistor_ohm``, ``capacitor_f``,
    ``gain``); R3 and R4 come together; a stated gain agrees with its
    resistors, K = 1 + R4/R3 (seed 001, Fig. 43), within
    :data:`GAIN_TOLERANCE`; and the circuit is a stable plant whose fn and
    zeta (the module's formulas) lie in the ranges ``fc_hz`` and ``zeta``
    that ``--fc``/``--zeta`` accept. A zeta <= 0 (K too large for the parts)
    means the circuit oscillates on its own.

    Parameters
    ----------
    parts : SallenKeyParts
        Values as received, possibly of the wrong type. ``gain`` may be None
        (then it is 1 + R4/R3, or 1 without R3/R4).
    name_of : mapping or callable, optional
        What to call each field in messages: keys ``r1, r2, c1, c2, r3, r4,
        gain`` and ``plant`` (the whole circuit), e.g. ``{"r1": "--plant-r1"}``;
        missing keys default to ``R1``... ``gain K``, ``the plant``. Names
        may be ``{name}`` markers of a
        :class:`~designer.core.errors.ParamError` (the caller raises it).
    text : bool
        Also accept values as text in engineering notation (``"4k7"``), as a
        user typed them; a file's values must be numbers.

    Returns
    -------
    SallenKeyParts
        Floats only; the gain is the resistors' 1 + R4/R3 when they are given,
        and a gain K > 1 without them gets R3 = :data:`DEFAULT_R3_OHM` and
        R4 = (K - 1) R3, so that the netlist builds the gain the model assumes.

    Raises
    ------
    DesignError
        One line naming the offending field and what is allowed.
    """
    def name(key):
        if callable(name_of):
            return name_of(key)
        return (name_of or {}).get(key, _PART_NAMES[key])

    def number(key, value, range_key):
        if text:
            return parse_in_range(value, name(key), range_key)
        return RANGES[range_key].check(value, name(key))

    r1, r2 = (number(k, getattr(parts, k), "resistor_ohm") for k in ("r1", "r2"))
    c1, c2 = (number(k, getattr(parts, k), "capacitor_f") for k in ("c1", "c2"))
    if (parts.r3 is None) != (parts.r4 is None):
        raise DesignError(f"{name('r3')} and {name('r4')} go together (K = 1 + R4/R3)")
    gain = None if parts.gain is None else number("gain", parts.gain, "gain")
    if parts.r3 is not None:
        r3, r4 = number("r3", parts.r3, "resistor_ohm"), number("r4", parts.r4, "resistor_ohm")
        k = RANGES["gain"].check(1.0 + r4 / r3, f"1 + {name('r4')}/{name('r3')}")
        if gain is not None and abs(gain - k) > GAIN_TOLERANCE * k:
            raise DesignError(f"{name('gain')} = {gain:g} does not match its resistors: K = 1 + R4/R3 = "
                              f"{k:.6g} (they must agree within {100 * GAIN_TOLERANCE:g} %)")
        gain = k
    elif gain is None or gain <= 1.0 + GAIN_TOLERANCE:
        gain, r3, r4 = 1.0, None, None   # a voltage follower
    else:
        r3, r4 = DEFAULT_R3_OHM, (gain - 1.0) * DEFAULT_R3_OHM
    out = SallenKeyParts(r1, r2, c1, c2, gain, r3, r4)
    if not out.b > 0:
        raise DesignError(
            f"{name('plant')}: these parts give zeta = {out.zeta:.4g} <= 0 (R1 C2 (K - 1) is not below "
            "C1 (R1 + R2)): the circuit oscillates on its own; lower the gain or change the parts")
    RANGES["fc_hz"].check(out.fn_hz, f"{name('plant')}: the natural frequency fn of these parts")
    RANGES["zeta"].check(out.zeta, f"{name('plant')}: the damping ratio zeta of these parts")
    return out


def exact_on_capacitors(build, fc_hz: float, zeta: float, gain: float, r3=None, r4=None):
    """The exact design a build rounds (seed 001, IV.5: the ratios m = R1/R2 and n = C2/C1 that hit fc and
    zeta): the build's capacitors with the resistors that give the target exactly (nearest to the build's
    R1), or, at unity gain when their ratio is below 1/zeta^2, the nearest capacitor ratio that has such
    resistors.

    Parameters
    ----------
    build : object
        Has ``r1``, ``c1``, ``c2`` (a search candidate or a :class:`SallenKeyParts`).
    fc_hz, zeta : float
        The target.
    gain : float
        K, as the gain pair realises it.
    r3, r4 : float or None
        The gain pair (None for a follower), carried into the record.

    Returns
    -------
    SallenKeyParts or None
        The exact design; None when no positive resistors exist.
    """
    c2 = build.c2 if gain != 1.0 else max(build.c2, unity_gain_c2_min(build.c1, zeta) * (1 + 1e-12))
    lo, hi = resistors_for_caps(fc_hz, zeta, build.c1, c2, gain)
    roots = [float(x) for x in (lo, hi) if not math.isnan(float(x))]
    if not roots:
        return None
    r1 = min(roots, key=lambda r: abs(math.log(r / build.r1)))
    r2 = 1.0 / ((2 * math.pi * fc_hz) ** 2 * build.c1 * c2 * r1)
    return SallenKeyParts(r1, r2, build.c1, c2, gain, r3, r4)


def seed_ratios(parts) -> tuple:
    """The seed's ratios of a parts record (001, IV.5): m = R1/R2 and n = C2/C1.

    Parameters
    ----------
    parts : SallenKeyParts
        The parts.

    Returns
    -------
    tuple of float
        (m, n).
    """
    return parts.r1 / parts.r2, parts.c2 / parts.c1
