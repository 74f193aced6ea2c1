"""Pseudo-random binary sequences for identification (seed 003, section 2.4).

A maximum-length sequence (m-sequence, the seed's "s.b.l.m.", eq. 2.4.5) of
``n`` bits has period N = 2^n - 1 intervals of the clock Dt and takes the
levels offset +- a. Its circular autocorrelation is a^2 at lag 0 and
-a^2/N at every other lag (eq. 2.4.6), which is what makes the correlation
method of :mod:`designer.identify.correlation` exact over whole periods. The sequence itself
is :func:`scipy.signal.max_len_seq`'s.

Choosing the sequence for a plant (:func:`plan_for_plant`): the power of a
PRBS falls as sinc^2(f Dt) and is half its low-frequency level at
f = :data:`HALF_POWER` / Dt, so the clock is chosen to put that frequency at
:data:`BAND_FACTOR` times the plant's bandwidth; and the period N Dt must
outlast the plant's settling time (seed 003, 2.4.5: "only a little longer than
the settling time"), by :data:`SETTLE_MARGIN`, or the impulse response wraps
around (:func:`designer.identify.correlation.settling_check` finds it), and put
:data:`LINES_IN_BAND` spectral lines below the bandwidth for the spectral fit.

Writers: the waveform as a bench generator's arbitrary-waveform CSV (one value
per clock interval, the sample rate stated), a ``time_s,value`` CSV, and an
ngspice PWL source (a subcircuit with one output node).
"""

from __future__ import annotations

import math
from dataclasses import dataclass, field

import numpy as np

from ..core.errors import DesignError

__all__ = ["BAND_FACTOR", "HALF_POWER", "LINES_IN_BAND", "MAX_BITS", "MIN_BITS", "PrbsPlan", "SETTLE_MARGIN",
           "awg_csv", "bits_for", "check_bits", "is_mls_length", "linear_complexity", "mls", "mls_bit_errors",
           "nice_interval", "plan_for_plant", "pwl_points", "pwl_subcircuit", "time_value_csv"]

MIN_BITS, MAX_BITS = 3, 20
#: sinc^2(x) = 1/2 at x = 0.4429: the PRBS spectrum's half-power frequency times Dt
HALF_POWER = 0.4429
#: the sequence's half-power band covers the plant to this many times its bandwidth
BAND_FACTOR = 3.0
#: one period outlasts the plant's settling time by this factor
SETTLE_MARGIN = 1.2
#: one period puts at least this many spectral lines (1/period apart) below the bandwidth
LINES_IN_BAND = 10
#: the ngspice PWL source's edge time, as a fraction of the clock interval
EDGE_FRACTION = 1e-3


def check_bits(bits) -> int:
    """``bits`` as an int in MIN_BITS..MAX_BITS, else one line.

    Parameters
    ----------
    bits
        The bits as given.

    Returns
    -------
    int
        The bits.
    """
    try:
        n = int(bits)
        ok = n == float(bits)
    except (TypeError, ValueError, OverflowError):
        ok = False
    if not ok or not MIN_BITS <= n <= MAX_BITS:
        raise DesignError(f"--bits must be a whole number from {MIN_BITS} to {MAX_BITS} "
                          f"(N = 2^n - 1 = 7 .. {2 ** MAX_BITS - 1:,} intervals); got {bits}")
    return n


def mls(bits: int) -> np.ndarray:
    """One period of the maximum-length sequence of ``bits`` bits as +-1 (int8),
    N = 2^bits - 1 values, (N + 1)/2 of them +1 (scipy's taps, state all ones).

    Parameters
    ----------
    bits : int
        The register's length.

    Returns
    -------
    numpy.ndarray
        The period.
    """
    from scipy.signal import max_len_seq
    seq, _ = max_len_seq(check_bits(bits))
    return (2 * seq.astype(np.int8) - 1).astype(np.int8)


def is_mls_length(n: int) -> int | None:
    """The bits of a period of ``n`` intervals when n = 2^bits - 1 (3..20), else None.

    Parameters
    ----------
    n : int
        A period's length.

    Returns
    -------
    int or None
        The bits.
    """
    b = int(n + 1).bit_length() - 1
    return b if (1 << b) == n + 1 and MIN_BITS <= b <= MAX_BITS else None


@dataclass(frozen=True)
class PrbsPlan:
    """A sequence to play: ``bits``, clock interval ``dt_s``, levels
    ``offset +- amplitude``, ``periods`` played, and why (``reasons``)."""

    bits: int
    dt_s: float
    amplitude: float = 1.0
    offset: float = 0.0
    periods: int = 3
    reasons: tuple = field(default_factory=tuple)

    @property
    def n(self) -> int:
        """Intervals per period, 2^bits - 1."""
        return (1 << self.bits) - 1

    @property
    def clock_hz(self) -> float:
        return 1.0 / self.dt_s

    @property
    def period_s(self) -> float:
        return self.n * self.dt_s

    @property
    def band_hz(self) -> float:
        """The half-power frequency of the sequence's spectrum."""
        return HALF_POWER / self.dt_s

    @property
    def resolution_hz(self) -> float:
        """Spacing of the spectral lines, 1 / period."""
        return 1.0 / self.period_s

    def values(self) -> np.ndarray:
        """The levels played, one per clock interval, every period."""
        one = self.offset + self.amplitude * mls(self.bits).astype(float)
        return np.tile(one, self.periods)

    def to_dict(self) -> dict:
        return {"bits": self.bits, "N": self.n, "clock_hz": self.clock_hz, "dt_s": self.dt_s,
                "amplitude": self.amplitude, "offset": self.offset, "periods": self.periods,
                "period_s": self.period_s, "band_hz": self.band_hz,
                "resolution_hz": self.resolution_hz, "reasons": list(self.reasons)}


def nice_interval(dt: float) -> float:
    """The largest 1-2-5 value (1, 2, 5 x 10^k) at most ``dt``.

    Parameters
    ----------
    dt : float
        An interval (s).

    Returns
    -------
    float
        The 1-2-5 value.
    """
    e = math.floor(math.log10(dt))
    for m in (5.0, 2.0, 1.0):
        if m * 10.0 ** e <= dt * (1 + 1e-9):
            return m * 10.0 ** e
    return 10.0 ** e  # pragma: no cover - m = 1 always fits


def bits_for(period_s: float, dt_s: float) -> int | None:
    """The fewest bits whose period (2^n - 1) dt lasts ``period_s``; None past MAX_BITS.

    Parameters
    ----------
    period_s : float
        The period wanted (s).
    dt_s : float
        The clock interval (s).

    Returns
    -------
    int or None
        The bits.
    """
    need = period_s / dt_s
    for n in range(MIN_BITS, MAX_BITS + 1):
        if (1 << n) - 1 >= need:
            return n
    return None


def plan_for_plant(settling_s: float, bandwidth_hz: float, *, amplitude=1.0, offset=0.0,
                   periods=3, dt_s=None, bits=None, plant: str = "the plant") -> PrbsPlan:
    """Choose the clock and bits for a plant of 2 % settling time ``settling_s``
    and -3 dB bandwidth ``bandwidth_hz``.

    The clock interval is the 1-2-5 value at most HALF_POWER / (BAND_FACTOR
    bandwidth) (the sequence's half-power band covers the plant to three times
    its bandwidth); the bits the fewest whose period lasts SETTLE_MARGIN times
    the settling time. ``dt_s`` or ``bits`` given are kept (a given ``bits``
    too short for the plant is said so in ``reasons``). A clock chosen here
    lies in the range a given one must (``RANGES["prbs_clock_hz"]``, 1 uHz to
    1 GHz), else the plant (``plant``, its words in the message) is refused.

    Parameters
    ----------
    settling_s : float
        The plant's 2 % settling time (s).
    bandwidth_hz : float
        Its bandwidth.
    amplitude, offset : float
        The levels: offset +- amplitude.
    periods : int
        The periods played.
    dt_s : float, optional
        The clock interval; None: chosen.
    bits : int, optional
        The register's length; None: chosen.
    plant : str
        What the messages call the plant.

    Returns
    -------
    PrbsPlan
        The sequence to play.
    """
    if not (math.isfinite(settling_s) and settling_s > 0 and math.isfinite(bandwidth_hz)
            and bandwidth_hz > 0):
        raise DesignError("the plant model has no finite settling time and bandwidth: "
                          "--for-plant needs a stable plant")
    reasons = []
    if dt_s is None:
        dt_s = nice_interval(HALF_POWER / (BAND_FACTOR * bandwidth_hz))
        _check_chosen_clock(1.0 / dt_s, bandwidth_hz, plant)
        reasons.append(f"clock {_hz(1 / dt_s)} (Dt = {_sec(dt_s)}): the sequence's half-power "
                       f"band, {_hz(HALF_POWER / dt_s)}, covers {BAND_FACTOR:g}x the plant's "
                       f"bandwidth of {_hz(bandwidth_hz)}")
    need = SETTLE_MARGIN * settling_s
    lines = LINES_IN_BAND / bandwidth_hz
    if bits is None:
        n = bits_for(max(need, lines), dt_s)
        if n is None:
            n = MAX_BITS
            reasons.append(f"{MAX_BITS} bits, the most: a period of {_sec(((1 << n) - 1) * dt_s)} "
                           f"is shorter than {SETTLE_MARGIN:g}x the settling time "
                           f"({_sec(need)}) or {LINES_IN_BAND} spectral lines in the bandwidth "
                           f"({_sec(lines)}); a slower clock would be needed")
        else:
            why = (f"outlasts {SETTLE_MARGIN:g}x the plant's 2 % settling time of {_sec(settling_s)}"
                   if need >= lines else
                   f"puts {LINES_IN_BAND} spectral lines (1/period apart) in the plant's bandwidth "
                   f"(and outlasts {SETTLE_MARGIN:g}x its settling time of {_sec(settling_s)})")
            reasons.append(f"{n} bits (N = {(1 << n) - 1}): one period, "
                           f"{_sec(((1 << n) - 1) * dt_s)}, {why}")
    else:
        n = check_bits(bits)
        if ((1 << n) - 1) * dt_s < need:
            enough = bits_for(need, dt_s)
            reasons.append(f"{n} bits as asked: a period of {_sec(((1 << n) - 1) * dt_s)} is "
                           f"shorter than {SETTLE_MARGIN:g}x the settling time ({_sec(need)}): "
                           "the impulse response will wrap around"
                           + (f"; {enough} bits would be enough" if enough else ""))
    return PrbsPlan(n, float(dt_s), float(amplitude), float(offset), int(periods), tuple(reasons))


def _check_chosen_clock(clock_hz: float, bandwidth_hz: float, plant: str) -> None:
    """The clock chosen for a plant, refused outside the range of a clock given by hand."""
    from .ranges import RANGES
    allowed = RANGES["prbs_clock_hz"]
    if not allowed.contains(clock_hz):
        raise DesignError(f"{plant}, -3 dB bandwidth {_hz(bandwidth_hz)}, would need a PRBS clock of "
                          f"{_hz(clock_hz)} for a half-power band of {BAND_FACTOR:g}x its bandwidth; a clock is "
                          f"{allowed.text()}: this plant is outside what a PRBS bench identifies")


# --------------------------------------------------------------------------- writers

def _hz(f: float) -> str:
    from ..core.units import format_eng
    return format_eng(f, "Hz")


def _sec(t: float) -> str:
    from ..core.units import format_eng
    return format_eng(t, "s")


def _head(plan: PrbsPlan) -> list:
    return [f"PRBS: maximum-length sequence of {plan.bits} bits (N = {plan.n}), "
            f"{plan.periods} period(s) of {_sec(plan.period_s)}",
            f"clock {_hz(plan.clock_hz)} (Dt = {_sec(plan.dt_s)}), levels "
            f"{plan.offset - plan.amplitude:.6g} V and {plan.offset + plan.amplitude:.6g} V"]


def awg_csv(plan: PrbsPlan) -> str:
    """An arbitrary-waveform CSV: ``sample_rate_hz,<clock>`` then one value per
    line, one per clock interval (the generator holds each for Dt).

    Parameters
    ----------
    plan : PrbsPlan
        The sequence.

    Returns
    -------
    str
        The CSV text.
    """
    vals = plan.values()
    return (f"sample_rate_hz,{plan.clock_hz:.12g}\n"
            + "\n".join(f"{v:.6g}" for v in vals) + "\n")


def time_value_csv(plan: PrbsPlan) -> str:
    """``time_s,value`` rows: each level at the start of its clock interval, and
    the last level again at the end of the record.

    Parameters
    ----------
    plan : PrbsPlan
        The sequence.

    Returns
    -------
    str
        The CSV text.
    """
    vals = plan.values()
    t = np.arange(vals.size + 1) * plan.dt_s
    v = np.append(vals, vals[-1])
    return "time_s,value\n" + "\n".join(f"{a:.12g},{b:.6g}" for a, b in zip(t, v)) + "\n"


def pwl_points(plan: PrbsPlan, edge_s: float | None = None) -> tuple:
    """(t, v) corners of the sequence as a piecewise-linear source: a level
    change takes ``edge_s`` (default EDGE_FRACTION Dt) from the clock edge.

    Parameters
    ----------
    plan : PrbsPlan
        The sequence.
    edge_s : float, optional
        A level change's duration (s).

    Returns
    -------
    tuple of numpy.ndarray
        (t, v).
    """
    vals = plan.values()
    edge = plan.dt_s * EDGE_FRACTION if edge_s is None else float(edge_s)
    change = np.nonzero(np.diff(vals))[0] + 1
    t = [0.0]
    v = [vals[0]]
    for k in change:
        t += [k * plan.dt_s, k * plan.dt_s + edge]
        v += [vals[k - 1], vals[k]]
    t.append(vals.size * plan.dt_s)
    v.append(vals[-1])
    return np.asarray(t), np.asarray(v)


def pwl_subcircuit(plan: PrbsPlan, name: str = "prbs_source") -> str:
    """An ngspice ``.subckt <name> out`` whose voltage source plays the sequence
    (``X1 in <name>`` puts it on node ``in``).

    Parameters
    ----------
    plan : PrbsPlan
        The sequence.
    name : str
        The subcircuit's name.

    Returns
    -------
    str
        The subcircuit's text.
    """
    t, v = pwl_points(plan)
    pairs = [f"{a:.12g} {b:.6g}" for a, b in zip(t, v)]
    lines = ["* " + h for h in _head(plan)]
    lines += [f"* use: X1 <node> {name}", f".subckt {name} out", "Vprbs out 0 PWL("]
    for i in range(0, len(pairs), 6):
        lines.append("+ " + " ".join(pairs[i:i + 6]))
    lines += ["+ )", f".ends {name}"]
    return "\n".join(lines) + "\n"


def _berlekamp_massey(bits) -> tuple:
    """(L, c): the shortest linear feedback shift register that generates the 0/1
    sequence ``bits`` over GF(2), s_i = c_1 s_(i-1) + ... + c_L s_(i-L) (Massey 1969)."""
    s = [int(b) & 1 for b in bits]
    n = len(s)
    c, b = [1] + [0] * n, [1] + [0] * n
    L, m = 0, -1
    for i in range(n):
        d = s[i]
        for j in range(1, L + 1):
            d ^= c[j] & s[i - j]
        if d:
            t = c[:]
            shift = i - m
            for j in range(n + 1 - shift):
                c[j + shift] ^= b[j]
            if 2 * L <= i:
                L, m, b = i + 1 - L, i, t
    return L, c[:L + 1]


def linear_complexity(bits) -> int:
    """The length of the shortest linear feedback shift register that generates
    the 0/1 sequence ``bits`` (Berlekamp-Massey over GF(2)): the bits n of an
    m-sequence once 2n of its bits are seen; about half the length for random bits.

    Parameters
    ----------
    bits : array_like
        The 0/1 sequence.

    Returns
    -------
    int
        The linear complexity.
    """
    return _berlekamp_massey(bits)[0]


#: windows of 2n bits tried for the register of a period with bit errors
#: up to this many bits every register is tried (2^(bits-1) of them, a few ms at 10 bits)
MLS_EXHAUSTIVE_BITS = 10
MLS_WINDOWS = 16


def mls_bit_errors(period, bits: int) -> int:
    """How many of the values of one period (+-1 or 0/1, 2^bits - 1 of them) differ
    from the nearest m-sequence of ``bits`` bits (any register, any phase): 0 for a
    maximum-length sequence.

    Up to :data:`MLS_EXHAUSTIVE_BITS` bits every register is tried (a short period
    with a few flips may hold no error-free window). Above, the register comes
    from Berlekamp-Massey on 2n consecutive bits (n bits
    determine it: an error-free window of the period gives the right one, so
    windows spread over the period are tried, :data:`MLS_WINDOWS` of them); its
    m-sequence (:func:`scipy.signal.max_len_seq` with the register's taps, read in
    either direction) is aligned by the circular cross-correlation, whose peak
    C gives the agreements: (N + C)/2 of N. The count matters because an
    m-sequence's autocorrelation is N at lag 0 and -1 at every other lag (eq.
    2.4.6), and each flipped value moves every other lag's by 0 or +-4: k flips
    leave a floor that is no longer constant, up to 4k/N of the peak at each lag,
    which the correlation's DC term does not remove (seed 003, 2.4).

    Parameters
    ----------
    period : array_like
        The values of one period.
    bits : int
        The register's length.

    Returns
    -------
    int
        The values that differ.
    """
    from scipy.signal import max_len_seq
    x = np.asarray(period)
    n = (1 << bits) - 1
    if x.size != n:
        raise DesignError(f"a period of {x.size} values is not 2^{bits} - 1 = {n}")
    b01 = (x > 0).astype(np.int8)
    pm = 2.0 * b01 - 1.0
    spec = np.conj(np.fft.rfft(pm))
    best = n
    if bits <= MLS_EXHAUSTIVE_BITS:
        # a short period may hold no error-free window of 2n bits (2 flips in 15 values can leave none), so
        # every register is tried: 2^(bits-1) tap sets, those whose sequence is maximum-length counted
        candidates = [[j for j in range(1, bits) if mask >> (j - 1) & 1] for mask in range(1, 1 << (bits - 1))]
    else:
        candidates, seen = [], set()
        for o in np.linspace(0, n, MLS_WINDOWS, endpoint=False).astype(int):
            window = np.roll(b01, -int(o))[:2 * bits]
            L, c = _berlekamp_massey(window)
            key = tuple(c)
            if L != bits or key in seen:
                continue
            seen.add(key)
            taps = [j for j in range(1, bits) if c[j]]
            candidates += [t for t in (taps, [bits - j for j in taps]) if t]
    for t in candidates:
        seq = max_len_seq(bits, taps=t)[0].astype(float) * 2.0 - 1.0
        fs = np.fft.rfft(seq)
        if bits <= MLS_EXHAUSTIVE_BITS and not _is_mls(fs, n):
            continue
        corr = np.fft.irfft(spec * fs, n)
        best = min(best, int(round((n - float(corr.max())) / 2)))
        if best == 0:
            break
    return best


def _is_mls(spectrum, n: int) -> bool:
    """Whether the +-1 sequence of ``spectrum`` (its rfft) is maximum-length: its circular
    autocorrelation is n at lag 0 and -1 at every other lag (eq. 2.4.6)."""
    acf = np.fft.irfft(spectrum * np.conj(spectrum), n)
    return bool(np.all(np.abs(acf[1:] + 1.0) < 0.5))
