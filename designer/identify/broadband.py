"""Identification from a broadband input: a pseudo-random binary sequence or
noise (seed 003, sections 2.4 and 3.2).

:func:`examine_input` recognises the excitation: many transitions, at
irregular intervals (a square wave's are regular), no spectral line holding
most of the power (a sine's or a square wave's fundamental does). A two-level
input is then read as a sequence: its clock interval from the transitions
(which must be a whole number of sample intervals), its period from the bits
(an m-sequence when it is 2^n - 1 intervals and every period is the nearest
m-sequence bit for bit, :func:`~designer.core.prbs.mls_bit_errors`; else a
periodic binary sequence, for the spectral method). Anything else broadband is
noise; an input of 3 to :data:`MAX_LEVELS` levels held at a clock (a
three-level PRBS) is refused, named (:func:`multilevel_levels`).

:func:`identify_broadband` then estimates, on the periods after the first
(the seed's "establishment sequence": the plant must be in periodic steady
state, 2.4.2),

- ``correlation`` (:mod:`.correlation`): the impulse response from the
  cross-correlation (eq. 2.4.19; for noise eq. 2.4.4), the step response as its
  running integral, and the settling check; the step methods of
  :func:`~.step.identify_step` run on that step response;
- ``spectral`` (:mod:`.spectral`): H = S_yu/S_uu with its coherence, as a
  frequency table (:class:`~.io.FreqData`) on which identify-freq's analysis
  (:func:`~.frequency.identify_freq`) runs;

each ranked as it is today. ``method`` forces one of them. A method whose
assumption failed gives no valid model (:func:`_refuse_unsettled`): a wrapped
impulse response none from the correlation, and an output whose mean drifts
from period to period (no periodic steady state, eq. 2.4.2: an integrating
plant) none at all, ``refused`` saying why.
"""

from __future__ import annotations

import math
import time
from dataclasses import dataclass, field

import numpy as np

from ..core.errors import DesignError
from . import correlation as corr
from . import spectral as spec
from ..core.prbs import MAX_BITS, MIN_BITS, SETTLE_MARGIN, bits_for, is_mls_length, mls_bit_errors

__all__ = ["BroadbandResult", "check_method", "examine_input", "identify_broadband", "looks_broadband",
           "multilevel_levels", "period_drift", "between_levels", "other_input", "other_excitation"]

#: at least this many transitions make an input broadband
MIN_TRANSITIONS = 20
#: a square wave's (a PWM's) intervals between transitions, high and low apart,
#: vary less than this (std / mean)
REGULAR_CV = 0.2
#: no single spectral line of a broadband input holds this share of its AC power
MAX_LINE_SHARE = 0.5
#: a two-level input spends less than this fraction of its samples between its levels
TWO_LEVEL_FRACTION = 0.1
#: ... in every one of this many equal parts of the record (two transitions at least)
SPREAD_PARTS = 8
#: a broadband input spans at least this many quantisation steps
MIN_LSB = 16
#: fewest samples for any broadband identification
MIN_SAMPLES = 256
#: bits that disagree with the sequence one period later, at most (noise on the input)
PERIOD_MISMATCH = 0.01
METHODS = ("correlation", "spectral")
#: bits whose linear complexity tells an m-sequence shorter than two periods
LFSR_BITS = 200
#: periods of the record compared with the nearest m-sequence (the last ones; the fewest errors count)
MLS_ROWS = 4
#: the output's mean may move by at most this fraction of its span a period (and
#: three standard errors) for the record to be in periodic steady state (eq. 2.4.2)
MAX_PERIOD_DRIFT = 0.01


@dataclass
class Excitation:
    """What the input is: ``kind`` ``"mls"`` (a maximum-length sequence),
    ``"periodic"`` (a periodic binary sequence of another length),
    ``"noise"`` or ``"other"`` (neither a step, a square wave nor a sequence:
    a chirp, a knob turned by hand, a PWM of changing duty; the output-error
    route alone, :func:`other_input`, ``why`` saying so); sample interval ``ts``; for a sequence its clock interval
    (``samples_per_bit`` samples), levels ``offset +- amplitude``, period
    (``n`` intervals, ``period`` samples), ``bits`` for an m-sequence; the
    whole periods used (``count`` from sample ``start``)."""

    kind: str
    ts: float
    transitions: int
    offset: float = 0.0
    amplitude: float = 0.0
    samples_per_bit: int = 0
    n: int = 0
    bits: int | None = None
    start: int = 0
    count: int = 0
    #: of a period of an m-sequence's length: its values that differ from the nearest m-sequence
    bit_errors: int = 0
    #: of an ``"other"`` input: what it is, in words
    why: str = ""

    @property
    def dt_s(self) -> float:
        return self.samples_per_bit * self.ts

    @property
    def period(self) -> int:
        return self.n * self.samples_per_bit

    def text(self) -> str:
        from ..core.units import format_eng as fe
        if self.kind == "other":
            return f"{self.why}, sampled every {fe(self.ts, 's')}"
        if self.kind == "noise":
            return (f"noise input ({self.transitions} transitions), sampled every "
                    f"{fe(self.ts, 's')}")
        what = (f"maximum-length sequence, {self.bits} bits (N = {self.n})" if self.kind == "mls"
                else f"periodic binary sequence of {self.n} intervals (not an m-sequence)"
                if not self.bit_errors else
                f"a binary sequence of {self.n} intervals a period, not maximum-length ({self.bit_errors} "
                f"bits of each period differ from the nearest {is_mls_length(self.n)}-bit m-sequence)")
        return (f"{what}, clock {fe(1 / self.dt_s, 'Hz')} (Dt = {fe(self.dt_s, 's')}, "
                f"{self.samples_per_bit} samples), levels {self.offset:.4g} +- "
                f"{self.amplitude:.4g}; {self.count} whole period(s) of "
                f"{fe(self.period * self.ts, 's')} used after the first")

    def to_dict(self) -> dict:
        d = {"kind": self.kind, "sample_interval_s": self.ts, "transitions": self.transitions}
        if self.kind == "other":
            d["input"] = self.why
        elif self.kind != "noise":
            d.update({"clock_hz": 1 / self.dt_s, "dt_s": self.dt_s,
                      "samples_per_interval": self.samples_per_bit, "N": self.n,
                      "bits": self.bits, "offset": self.offset, "amplitude": self.amplitude,
                      "period_s": self.period * self.ts, "periods_used": self.count,
                      "first_sample": self.start})
            if self.bit_errors:
                d["bits_differing_from_mls"] = self.bit_errors
        return d


# --------------------------------------------------------------------------- recognition

def _schmitt(u, lo, hi) -> np.ndarray:
    """0/1 state of ``u`` with hysteresis between ``lo`` and ``hi`` (the first
    undecided samples take the first decided state)."""
    s = np.where(u >= hi, 1, np.where(u <= lo, 0, -1)).astype(np.int8)
    idx = np.where(s >= 0, np.arange(s.size), 0)
    np.maximum.accumulate(idx, out=idx)
    out = s[idx]
    first = int(np.argmax(s >= 0)) if np.any(s >= 0) else 0
    out[:first] = s[first]
    return out


def _transitions(u) -> tuple:
    """(indices where the Schmitt state changes, low level, high level)."""
    lo, hi = np.percentile(u, [1, 99])
    span = hi - lo
    if not span > 0:
        return np.empty(0, np.int64), lo, hi
    state = _schmitt(u, lo + 0.35 * span, lo + 0.65 * span)
    return np.nonzero(np.diff(state))[0] + 1, lo, hi


def _line_share(u) -> float:
    """The largest share of the AC power of ``u`` in one DFT bin."""
    x = np.asarray(u[: 1 << 20], float)
    x = x - x.mean()
    p = np.abs(np.fft.rfft(x)) ** 2
    total = p[1:].sum()
    return float(p[1:].max() / total) if total > 0 else 1.0


def positional_input(cap):
    """The capture with its input kept only if it is one, when the reader chose it by position
    alone (:attr:`~designer.identify.io.Capture.input_by_position`): a step
    (:func:`~designer.identify.io.looks_like_step_input`), a broadband excitation
    (:func:`looks_broadband`) or a multi-level sequence (refused later, named); anything else (a
    second output, as ``time_s,analytic,spice``) is dropped with a note.

    Parameters
    ----------
    cap : Capture
        As :func:`~designer.identify.io.read_capture` returned it (changed in place).

    Returns
    -------
    Capture
        The same capture.
    """
    from .io import looks_like_step_input
    if not cap.input_by_position or cap.u is None:
        return cap
    cap.input_by_position = False
    if looks_like_step_input(cap.u, cap.y) or looks_broadband(cap.u) or multilevel_levels(cap.u) is not None:
        return cap
    cap.notes.append(f"column {cap.input_name!r} does not look like a step input (its transitions are not "
                     "much faster than the output's) nor a broadband one; no input column used (see "
                     "--input-column)")
    cap.u, cap.input_name = None, None
    return cap


def looks_broadband(u) -> bool:
    """True for a PRBS or noise: at least MIN_TRANSITIONS transitions at
    irregular intervals and no spectral line holding MAX_LINE_SHARE of the power.

    Parameters
    ----------
    u : array_like
        The input's samples.

    Returns
    -------
    bool
        False also for a square wave, a PWM (of steady or changing duty) and a
        quiet channel's noise.
    """
    u = np.asarray(u, float)
    if u.size < MIN_SAMPLES:
        return False
    edges, lo, hi = _transitions(u)
    if edges.size < MIN_TRANSITIONS:
        return False
    from ..core.waveform import quantum
    lsb = quantum(u[: 1 << 16])
    if lsb > 0 and hi - lo < MIN_LSB * lsb:
        return False            # a quiet channel's noise, a few quantisation steps wide
    # an excitation toggles all through the record, not in a burst (ringing, a glitch)
    if np.min(np.bincount(edges * SPREAD_PARTS // u.size, minlength=SPREAD_PARTS)) < 2:
        return False
    runs = np.diff(edges)
    # a square wave or a PWM: its high runs alike and its low runs alike
    if all(r.std() < REGULAR_CV * r.mean() for r in (runs[0::2], runs[1::2])):
        return False
    if _pwm_period(runs):
        return False            # a PWM of changing duty (output error reads it, other_input)
    return _line_share(u) < MAX_LINE_SHARE


#: a multi-level sequence has at most this many levels (more: a staircase of noise, a sine's samples)
MAX_LEVELS = 9
#: each of its levels holds at least this share of the samples
LEVEL_SHARE = 0.05
#: histogram bins over the input's span when the levels are sought
LEVEL_BINS = 100


def multilevel_levels(u) -> list | None:
    """The levels of a sequence of 3 to :data:`MAX_LEVELS` levels (a three-level
    PRBS, a multi-level random sequence), else None: the samples fall in separate
    clusters (histogram bins holding at least 0.5 % of them, runs of such bins), each
    holding :data:`LEVEL_SHARE`, and the level changes at least
    :data:`MIN_TRANSITIONS` times, spread through the record, held for at least two
    samples at a time in most runs (a clocked sequence, not a quiet channel's
    noise a few quantisation steps wide, which moves nearly every sample).

    Parameters
    ----------
    u : array_like
        The recorded sequence.

    Returns
    -------
    list of float or None
        The levels, lowest first.
    """
    u = np.asarray(u, float)
    if u.size < MIN_SAMPLES or not np.all(np.isfinite(u)):
        return None
    lo, hi = np.percentile(u, [0.5, 99.5])
    span = hi - lo
    if not span > 0:
        return None
    counts, edges = np.histogram(u, LEVEL_BINS, range=(lo - 0.02 * span, hi + 0.02 * span))
    full = counts >= 0.005 * u.size
    # runs of populated bins are the clusters
    starts = np.flatnonzero(full & ~np.r_[False, full[:-1]])
    ends = np.flatnonzero(full & ~np.r_[full[1:], False]) + 1
    levels = []
    for a, b in zip(starts, ends):
        sel = (u >= edges[a]) & (u < edges[b])
        if np.count_nonzero(sel) >= LEVEL_SHARE * u.size:
            levels.append(float(np.median(u[sel])))
    if not 3 <= len(levels) <= MAX_LEVELS:
        return None
    lv = np.asarray(levels)
    idx = np.argmin(np.abs(u[:, None] - lv[None, :]), axis=1)
    change = np.flatnonzero(np.diff(idx)) + 1
    if change.size < MIN_TRANSITIONS:
        return None
    if np.min(np.bincount(change * SPREAD_PARTS // u.size, minlength=SPREAD_PARTS)) < 2:
        return None
    runs = np.diff(change)
    if np.mean(runs >= 2) < 0.8:
        return None
    return levels


def _refuse_multilevel(u, name) -> None:
    """One line for an input of 3 or more levels (:func:`multilevel_levels`)."""
    levels = multilevel_levels(u)
    if levels is None:
        return
    words = {3: "three", 4: "four", 5: "five"}
    k = len(levels)
    raise DesignError(f"{name}: the input is a {words.get(k, str(k))}-level sequence (levels "
                      f"{', '.join(f'{v:.4g}' for v in levels)}): neither a step or square wave (the "
                      "step methods) nor a two-level sequence (a PRBS, see make-prbs) or noise (the "
                      "correlation and spectral methods); capture the plant under one of those")


def _pwm_period(runs) -> bool:
    """True when each high run and the low run after it add up to the same
    period (a PWM whose duty changes: its carrier's period stays)."""
    m = (runs.size // 2) * 2
    if m < 2:
        return False
    pairs = runs[0:m:2] + runs[1:m:2]
    return bool(pairs.std() < REGULAR_CV * pairs.mean() / 4)


def between_levels(u) -> float:
    """The share of an input's samples between its two levels (more than 10 %
    of the span from both the 1st and the 99th percentile): below
    :data:`TWO_LEVEL_FRACTION` a two-level input, held between samples.

    Parameters
    ----------
    u : array_like
        The input channel.

    Returns
    -------
    float
        0 to 1 (0 for an input that never moves).
    """
    u = np.asarray(u, float)
    lo, hi = np.percentile(u, [1, 99])
    span = hi - lo
    if not span > 0:
        return 0.0
    return float(np.count_nonzero((u > lo + 0.1 * span) & (u < lo + 0.9 * span)) / u.size)


def other_input(u) -> str:
    """Whether an input that is not broadband is something else than a step or
    a square wave (the step methods' input): one that spends more than
    :data:`TWO_LEVEL_FRACTION` of its samples between its levels (a chirp, a
    sine, a knob turned by hand), or a two-level one switching at irregular
    intervals (a PWM of changing duty), which only an output-error fit reads.

    Parameters
    ----------
    u : array_like
        The recorded input, one value per sample.

    Returns
    -------
    str
        The input in words ("" for a step, a square wave, or a two-level
        input of fewer than ``MIN_TRANSITIONS // 2`` transitions: steps, for
        the step methods).
    """
    u = np.asarray(u, float)
    edges, lo, hi = _transitions(u)
    if not hi - lo > 0:
        return ""
    between = between_levels(u)
    if between > TWO_LEVEL_FRACTION:
        return (f"an input that is neither a step, a square wave nor a binary sequence or noise "
                f"({100 * between:.0f} % of its samples between its levels, a chirp or a hand-turned knob)")
    runs = np.diff(edges)
    if edges.size >= MIN_TRANSITIONS // 2 and not all(r.std() < REGULAR_CV * r.mean()
                                                       for r in (runs[0::2], runs[1::2])):
        return (f"a two-level input switching at irregular intervals ({edges.size} transitions"
                + (", its period steady: a PWM of changing duty)" if _pwm_period(runs) else ")"))
    return ""


def other_excitation(t, u, why: str) -> Excitation:
    """The :class:`Excitation` of an input :func:`other_input` described.

    Parameters
    ----------
    t, u : array_like
        The record's time and input.
    why : str
        :func:`other_input`'s words.

    Returns
    -------
    Excitation
        Of kind ``"other"``.
    """
    t = np.asarray(t, float)
    ts = float((t[-1] - t[0]) / (t.size - 1)) if t.size > 1 else 0.0
    return Excitation("other", ts, int(_transitions(np.asarray(u, float))[0].size), why=why)


def _clock(edges, ts, name) -> int:
    """Samples per interval of a binary sequence from its transition indices."""
    runs = np.diff(edges).astype(float)
    # the single intervals: 2 and 3 samples mean 2.5. The 1st percentile, not the 10th: a random
    # binary signal switching with probability p has geometric runs, only a fraction p of them single
    # (p = 0.1: the 10th percentile is often two intervals, and the clock read as 1.975 of them)
    short = runs[runs <= 1.5 * np.percentile(runs, 1)]
    b0 = float(np.mean(short))
    k = np.round((edges - edges[0]) / b0)
    kk = k - k.mean()
    dt = float(np.sum(kk * (edges - edges.mean())) / np.sum(kk * kk))   # samples per interval
    m = int(round(dt))
    drift = abs(dt - m) * (edges[-1] - edges[0]) / dt
    if m < 1 or drift > 0.25 * max(m, 1):
        from ..core.units import format_eng as fe
        raise DesignError(f"{name}: the sequence's clock interval ({fe(dt * ts, 's')}) is not a "
                          f"whole number of sample intervals ({fe(ts, 's')}: ratio {dt:.4g}); "
                          "play a clock that is a multiple of the scope's sample interval, or "
                          "sample at a multiple of the clock")
    return m


def _period(bits: np.ndarray) -> int | None:
    """The period of a +-1 bit sequence (m-sequence lengths tried first), or None."""
    n = bits.size
    for nb in range(MIN_BITS, MAX_BITS + 1):
        L = (1 << nb) - 1
        if 2 * L > n:
            break
        if np.mean(bits[L:] != bits[:-L]) <= PERIOD_MISMATCH:
            return L
    x = bits.astype(float)
    nfft = 1 << int(math.ceil(math.log2(2 * n)))
    r = np.fft.irfft(np.abs(np.fft.rfft(x, nfft)) ** 2, nfft)[:n // 2 + 1]
    overlap = n - np.arange(r.size)
    r = r / overlap
    cand = np.nonzero(r[2:] >= 1 - 2 * PERIOD_MISMATCH)[0]
    return int(cand[0] + 2) if cand.size else None


def examine_input(t, u, *, name: str = "capture") -> Excitation | None:
    """The excitation of a capture, or None when ``u`` is not broadband (a step,
    a square wave, a sine: the step methods' input).

    Parameters
    ----------
    t, u : array_like
        The record's time (s) and input.
    name : str
        The capture's name in messages.

    Returns
    -------
    Excitation or None

    Raises
    ------
    DesignError
        A multi-level input, unevenly spaced samples, a clock that is not a
        whole number of samples, fewer than two periods of an m-sequence.
    """
    u = np.asarray(u, float)
    _refuse_multilevel(u, name)       # before the noise test, which its middle levels would pass
    if not looks_broadband(u):
        return None
    t = np.asarray(t, float)
    ts = float((t[-1] - t[0]) / (t.size - 1))
    d = np.diff(t)
    if np.max(np.abs(d - ts)) > 0.01 * ts:
        raise DesignError(f"{name}: the samples are not evenly spaced (intervals from "
                          f"{d.min():.4g} s to {d.max():.4g} s): broadband identification needs a "
                          "uniformly sampled record")
    edges, lo, hi = _transitions(u)
    span = hi - lo
    if between_levels(u) > TWO_LEVEL_FRACTION:
        return Excitation("noise", ts, int(edges.size))
    m = _clock(edges, ts, name)
    state = _schmitt(u, lo + 0.35 * span, lo + 0.65 * span)
    phase = int(edges[0] % m)
    centres = np.arange(phase + m // 2, u.size, m)
    bits = 2 * state[centres].astype(np.int8) - 1
    L = _period(bits)
    if L is None:
        # fewer than two periods of an m-sequence? its first 2n bits give n away
        from ..core.prbs import linear_complexity
        head = bits[:LFSR_BITS]
        nb = linear_complexity((head > 0).astype(np.int8))
        if head.size >= 4 * nb and MIN_BITS <= nb <= MAX_BITS:
            period = ((1 << nb) - 1) * m
            raise DesignError(f"{name}: the input is a maximum-length sequence of {nb} bits "
                              f"(N = {(1 << nb) - 1}), but the record holds "
                              f"{u.size / period:.2f} of its periods ({period} samples each); at "
                              "least 2 whole ones are needed (the first settles the plant, the "
                              "second is measured)")
    hi_level = float(np.median(u[state == 1]))
    lo_level = float(np.median(u[state == 0]))
    ex = Excitation("noise", ts, int(edges.size), 0.5 * (hi_level + lo_level),
                    0.5 * (hi_level - lo_level), m)
    if L is None:
        return ex                      # a random binary signal: read as noise
    nb = is_mls_length(L)
    if nb:
        # the length is an m-sequence's: is the sequence one? The fewest errors of the last
        # MLS_ROWS stretches of a period (a generator's idle lead-in, a misread bit, spoil one)
        whole = bits[:bits.size // L * L].reshape(-1, L)
        ex.bit_errors = L
        for row in whole[::-1][:MLS_ROWS]:
            ex.bit_errors = min(ex.bit_errors, mls_bit_errors(row, nb))
            if not ex.bit_errors:
                break
    ex.kind = "mls" if nb and not ex.bit_errors else "periodic"
    ex.n, ex.bits = L, (nb if ex.kind == "mls" else None)
    p = L * m
    # the sequence starts at most `bits` intervals before its first transition
    first = max(0, int(edges[0]) - (nb or MAX_BITS) * m)
    ex.start = first + p
    ex.count = max(0, (u.size - ex.start) // p)
    return ex


# --------------------------------------------------------------------------- identification

@dataclass
class BroadbandResult:
    """The excitation, the impulse estimate (None for spectral only), the
    step methods' :class:`~.step.IdentifyResult` on its step response, the
    spectral estimate and identify-freq's :class:`~.frequency.FreqIdentifyResult`
    on it, which of the two ``best`` comes from, notes."""

    excitation: Excitation
    impulse: corr.ImpulseEstimate | None = None
    step_result: object | None = None
    spectrum: spec.Spectrum | None = None
    freq_result: object | None = None
    method: str = ""
    notes: list = field(default_factory=list)
    capture: object | None = None
    #: seconds per phase, for the benchmarks; not in :meth:`to_dict` (the JSON is the same on every run)
    timings: dict = field(default_factory=dict)
    #: for a wrapped impulse response: the period, bits or clock interval that would do
    advice: dict | None = None
    #: why no model is valid when the estimates' own assumption failed ("" when it held)
    refused: str = ""
    #: the input's autocorrelation against a white sequence's band (the correlation route's assumption)
    whiteness: corr.InputWhiteness | None = None
    #: the impulse response was solved from the Wiener-Hopf equations (a coloured input)
    prewhitened: bool = False
    #: Welch segment length of a noise input's spectral estimate (samples; 0 for a sequence), and why
    segment_length: int = 0
    segment_note: str = ""
    #: every route's models scored on validation data (:class:`~.assess.Assessment`), when assessed
    assessment: object | None = None
    #: of a step capture whose response ramps (an integrating plant, :mod:`.integrating`): the asymptote
    #: method's :class:`~.structures.MethodResult` on the whole record, the step route's model
    ramp: object | None = None

    @property
    def best(self):
        r = self.step_result if self.method == "correlation" else self.freq_result
        return None if r is None else r.best

    def to_dict(self) -> dict:
        d = {"format": "broadband", "excitation": self.excitation.to_dict(), "method": self.method,
             "best": self.best.to_dict() if self.best else None, "notes": list(self.notes)}
        if self.refused:
            d["refused"] = self.refused
        if self.whiteness is not None:
            d["input_whiteness"] = {**self.whiteness.to_dict(), "prewhitened": self.prewhitened}
        if self.segment_length:
            d["segment_length"] = {"samples": self.segment_length, "note": self.segment_note}
        if self.impulse is not None:
            d["impulse"] = self.impulse.to_dict()
            if self.advice:
                d["impulse"]["advice"] = dict(self.advice)
        if self.step_result is not None:
            d["correlation"] = self.step_result.to_dict()
        if self.spectrum is not None:
            d["spectrum"] = self.spectrum.to_dict()
            d["spectrum"]["coherence"] = [float(c) for c in self.spectrum.coh]
        if self.freq_result is not None:
            d["spectral"] = self.freq_result.to_dict()
        if self.capture is not None:
            d["capture"] = self.capture.to_dict()
        if self.assessment is not None:
            from .structures import assessment_dict
            d.update(assessment_dict(self.assessment))
        # the ranking ``best`` comes from, laid out as identify's (correlation) or
        # identify-freq's (spectral) JSON, so design-pid --plant-model reads it
        chosen = d.get(self.method)
        if isinstance(chosen, dict):
            d["methods"] = chosen["methods"]
            for key in ("preprocessing", "error_definition", "data"):
                if key in chosen:
                    d[key] = chosen[key]
        return d


def _wrap_advice(est: corr.ImpulseEstimate, ex: Excitation) -> tuple:
    """(the note, the advice: the period needed, the bits at this clock, the clock
    interval at these bits) of a wrapped impulse estimate."""
    from ..core.units import format_eng as fe
    need, lower = corr.needed_period(est)
    least = "at least " if lower else ""
    why = (f"its slowest mode (time constant {fe(est.tail_tau_s, 's')}) decays to 2 % in {fe(need, 's')}"
           if not lower else f"settling {least}{fe(need, 's')}")
    text = (f"the impulse response has not settled within one period ({fe(est.period_s, 's')}; {why}): "
            "it wraps around, and the DC term removes part of it")
    advice = {"period_s": SETTLE_MARGIN * need, "lower_bound": lower}
    if ex.kind == "mls" and ex.n:
        nb = bits_for(SETTLE_MARGIN * need, ex.dt_s)
        dt = SETTLE_MARGIN * need / ex.n
        advice.update({"bits": nb, "dt_s": dt})
        text += (f"; {least}{nb} bits at this clock" if nb else "; more than 20 bits at this clock") + \
            f" (or a clock interval of {least}{fe(dt, 's')} with {ex.bits} bits)" + \
            (" would be enough" if not lower else ": run again with them, the check measures again")
    return text, advice


def check_method(method) -> str | None:
    """A broadband capture's route as the user named it, checked.

    Parameters
    ----------
    method : str or None
        ``correlation`` or ``spectral`` (any case), or None.

    Returns
    -------
    str or None
        The lower-case name, or None.
    """
    if method is None:
        return None
    m = str(method).strip().lower()
    if m not in METHODS:
        raise DesignError(f"--method {method!r} unknown; allowed: {', '.join(METHODS)}")
    return m


def identify_broadband(t, y, u, *, excitation: Excitation | None = None, method=None,
                       refine: bool = True, methods=None, capture=None,
                       name: str = "capture", segment_length: int | None = None) -> BroadbandResult:
    """Identify from a broadband capture (see the module docstring).

    A noise input's whiteness is checked first
    (:func:`~.correlation.input_whiteness`): a coloured one (a random binary
    signal held for several samples, filtered noise) has its impulse response
    solved from the Wiener-Hopf equations with its own autocorrelation
    (:func:`~.correlation.wiener_impulse`), never read as white. Its Welch
    segments are sized from the data (:func:`welch_segment`) unless
    ``segment_length`` (samples) is given.

    Parameters
    ----------
    t, y, u : array_like
        The record: time (s), output and input.
    excitation : Excitation, optional
        :func:`examine_input`'s reading (read here when None).
    method : str, optional
        ``correlation`` or ``spectral``: the route ``best`` comes from.
    refine : bool
        Refine the step methods' estimates by least squares.
    methods : sequence of str, optional
        The step methods run on the correlation's step response.
    capture : CaptureInfo, optional
        What was read, kept with the result.
    name : str
        The capture's name in messages.
    segment_length : int, optional
        A noise input's Welch segment (samples).

    Returns
    -------
    BroadbandResult

    Raises
    ------
    DesignError
        The input is not broadband; input and output of different lengths; too
        few periods (an m-sequence needs two whole ones: one to settle, one to
        measure) or samples; correlation forced on a sequence that is no
        m-sequence.
    """
    method = check_method(method)
    t = np.asarray(t, float)
    y = np.asarray(y, float)
    u = np.asarray(u, float)
    if u.shape != y.shape or t.shape != y.shape:
        raise DesignError(f"{name}: the input ({u.size} samples) and the output ({y.size}) "
                          "must have the same length")
    if y.size < MIN_SAMPLES:
        raise DesignError(f"{name}: {y.size} samples; broadband identification needs at least "
                          f"{MIN_SAMPLES}")
    clock = time.perf_counter
    t0 = clock()
    ex = excitation or examine_input(t, u, name=name)
    if ex is None:
        raise DesignError(f"{name}: the input is not broadband (few or regular transitions, or "
                          "one dominant frequency): a step or square wave, for the step methods")
    res = BroadbandResult(ex, capture=capture)
    if ex.kind != "noise" and ex.count < 1:
        raise DesignError(f"{name}: {(y.size - ex.start + ex.period) / ex.period:.2f} periods "
                          f"of the sequence ({ex.period} samples each) in the record; at least "
                          "2 whole ones are needed (the first settles the plant, the second is "
                          "measured)")
    if method == "correlation" and ex.kind == "periodic":
        why = (f"{ex.bit_errors} bits of each period differ from the nearest m-sequence" if ex.bit_errors
               else "which is not 2^n - 1")
        raise DesignError(f"{name}: the input repeats every {ex.n} intervals, {why}: the correlation "
                          "method needs a maximum-length sequence; use --method spectral")
    res.method = method or "spectral"
    ts = ex.ts
    f_nyq = 0.5 / ts
    if segment_length is not None and ex.kind != "noise":
        raise DesignError(f"{name}: a segment length is for a noise or random input's Welch estimate; this "
                          "input is a periodic sequence, whose spectrum is taken over its whole periods")
    if ex.kind == "noise":
        nseg = min(1 << int(math.floor(math.log2(max(y.size // 8, 64)))), 1 << 16)
        if y.size < 8 * 64:
            raise DesignError(f"{name}: {y.size} samples of a noise input; the spectral method "
                              "needs at least 512 (8 segments of 64)")
        max_lag = nseg
        res.whiteness = corr.input_whiteness(u)
        if res.whiteness.kind == "white":
            res.impulse = corr.white_impulse(u, y, ts=ts, max_lag=max_lag)
            res.notes.append("noise input, checked white (" + res.whiteness.text() + "): the correlation "
                             "reads the impulse response from the cross-correlation (eq. 2.4.4)")
        else:
            res.impulse = corr.wiener_impulse(u, y, ts=ts, max_lag=max_lag)
            res.prewhitened = True
            res.notes.append(res.whiteness.text() + ": the correlation's impulse response is prewhitened "
                             "(solved from the Wiener-Hopf equations with the input's own autocorrelation)")
        nseg, res.segment_note = welch_segment(y.size, ts, res.impulse, segment_length)
        res.segment_length = nseg
        res.spectrum = spec.welch_response(u, y, ts=ts, nperseg=nseg, f_max=f_nyq)
    else:
        p = ex.period
        if ex.kind == "mls":
            x = corr.period_mean(u, ex.start, p, ex.count) - ex.offset
            yy = corr.period_mean(y, ex.start, p, ex.count)
            res.impulse = corr.mls_impulse(x, yy, n=ex.n, dt_s=ex.dt_s, ts=ts,
                                           amplitude=ex.amplitude)
        f_max = min(f_nyq, 0.9 / ex.dt_s)
        res.spectrum = spec.periodic_response(u, y, start=ex.start, period=p, count=ex.count,
                                              ts=ts, f_max=f_max)
        res.whiteness = corr.input_whiteness(u[ex.start:ex.start + p * ex.count], mls=ex.kind == "mls")
    timings = {"estimate": clock() - t0}
    if res.impulse is not None and res.impulse.wrapped:
        note, res.advice = _wrap_advice(res.impulse, ex)
        res.notes.append(note)
    if res.impulse is not None and method != "spectral":
        t1 = clock()
        try:
            res.step_result = _step_methods(res.impulse, refine, methods)
        except DesignError as exc:
            if method == "correlation":
                raise DesignError(f"{name}: the step response from the correlation: {exc}") from None
            res.notes.append(f"no step methods on the correlation's step response: {exc}")
        timings["correlation_models"] = clock() - t1
    if method != "correlation":
        t1 = clock()
        banded = spec.log_bands(res.spectrum)
        if banded.f.size < 5:
            if method == "spectral" or res.impulse is None:
                raise DesignError(f"{name}: the spectral estimate has {banded.f.size} usable "
                                  "frequencies (input power and coherence too low): at least 5 "
                                  "are needed; a longer record or more periods")
            res.notes.append("spectral estimate skipped: fewer than 5 usable frequencies")
        else:
            from .frequency import identify_freq
            res.spectrum = banded
            res.freq_result = identify_freq(spec.to_freq_data(banded, name))
        timings["spectral_models"] = clock() - t1
    _refuse_unsettled(res, y)
    if method is None:
        # the spectral fit first: it divides by the input's own spectrum, where the
        # correlation's step is smoothed by the sequence's autocorrelation triangle
        spectral_ok = res.freq_result is not None and res.freq_result.best is not None
        res.method = "spectral" if spectral_ok or res.step_result is None else "correlation"
    timings["total"] = clock() - t0
    res.timings = timings
    return res


#: a Welch segment reaches this factor below the slowest corner the first estimate shows
DECADE = 10.0
#: Welch segments: at least this many samples, and at most the record over this
#: (7 half-overlapped segments or more, so the coherence means something)
MIN_SEGMENT, RECORD_PER_SEGMENT = 64, 4
#: the segment lengths ``--segment-length`` takes (samples)
SEGMENT_RANGE = (16, 1 << 20)


def welch_segment(n: int, ts: float, impulse: corr.ImpulseEstimate | None,
                  given: int | None = None) -> tuple:
    """The Welch segment length of a noise input's spectral estimate, and why.

    The lowest frequency a segment of L samples shows is 1/(L ts); it should
    reach a decade below the slowest corner, 1/(2 pi tau), tau the slowest time
    constant of the first estimate (the correlation's step response settles to
    2 % in ln(50) tau): L >= 10 2 pi tau / ts, a power of two, at most the
    record over :data:`RECORD_PER_SEGMENT`.

    Parameters
    ----------
    n : int
        Samples in the record.
    ts : float
        Sample interval (s).
    impulse : ImpulseEstimate or None
        The correlation's first estimate.
    given : int, optional
        The caller's length (``--segment-length``), used as is when the record holds two segments.

    Returns
    -------
    tuple of (int, str)
        The length and a sentence saying how it was chosen.
    """
    from ..core.units import format_eng as fe
    top = max(MIN_SEGMENT, 1 << int(math.floor(math.log2(max(n // RECORD_PER_SEGMENT, 1)))))
    if given is not None:
        lo, hi = SEGMENT_RANGE
        if not lo <= given <= min(hi, n // 2):
            raise DesignError(f"segment length {given} is outside {lo} to {min(hi, n // 2)} samples (at most "
                              f"half the record of {n}, so that two segments or more are averaged)")
        return int(given), f"given: {given} samples, lowest frequency {fe(1 / (given * ts), 'Hz')}"
    settle = impulse.settling_s if impulse is not None else math.nan
    if not (math.isfinite(settle) and settle > 0):
        nseg = min(1 << int(math.floor(math.log2(max(n // 8, MIN_SEGMENT)))), 1 << 16)
        return nseg, f"{nseg} samples (the record over 8: the first estimate shows no settling time)"
    tau = settle / corr.DECAY
    need = DECADE * 2 * math.pi * tau / ts
    nseg = max(MIN_SEGMENT, 1 << int(math.ceil(math.log2(max(need, 1.0)))))
    why = (f"{nseg} samples: lowest frequency {fe(1 / (nseg * ts), 'Hz')}, a decade below the slowest corner "
           f"({fe(1 / (2 * math.pi * tau), 'Hz')}, tau {fe(tau, 's')} from the correlation's settling)")
    if nseg > top:
        nseg = top
        why = (f"{nseg} samples (a quarter of the record at most): lowest frequency "
               f"{fe(1 / (nseg * ts), 'Hz')}, less than a decade below the slowest corner "
               f"({fe(1 / (2 * math.pi * tau), 'Hz')}): a longer record would show the flat gain better")
    return nseg, why


def period_drift(y, ex: Excitation) -> tuple:
    """(the change of the output's mean from one period to the next, its
    standard error) over the periods used: the least-squares slope of the
    period means (0, inf for fewer than two periods or a noise input). The
    standard error is from the output's sample-to-sample noise (the second
    difference's spread / sqrt 6, as :func:`.correlation.tail_drift` takes it).

    Parameters
    ----------
    y : array_like
        The output.
    ex : Excitation
        The input's excitation (its periods).

    Returns
    -------
    tuple of (float, float)
        The slope per period and its standard error.
    """
    if ex.kind == "noise" or ex.count < 2:
        return 0.0, math.inf
    seg = np.asarray(y, float)[ex.start:ex.start + ex.period * ex.count]
    means = seg.reshape(ex.count, ex.period).mean(axis=1)
    k = np.arange(ex.count) - 0.5 * (ex.count - 1)
    slope = float(np.sum(k * means) / np.sum(k * k))
    sigma = float(np.std(np.diff(seg, 2)) / math.sqrt(6.0))
    se = sigma * math.sqrt(ex.samples_per_bit / ex.period) / math.sqrt(float(np.sum(k * k)))
    return slope, se


def _invalidate(result, why: str) -> None:
    """Mark every valid model of a step or frequency ranking invalid, saying why."""
    if result is None:
        return
    from .structures import rank_key
    for m in result.methods:
        if m.valid:
            m.valid = False
            m.note = why + (f"; {m.note}" if m.note else "")
    result.methods.sort(key=rank_key)
    result.best = None


def _refuse_unsettled(res: BroadbandResult, y) -> None:
    """No valid model when the method's assumption failed: a wrapped impulse
    response (the response outlasts a period) gives no valid step model, and an
    output whose mean drifts from period to period (an integrating plant, a pole
    at the origin, never settles) is in no periodic steady state (seed 003
    eq. 2.4.2, which both the correlation and the spectral estimate assume)."""
    ex = res.excitation
    drift, se = period_drift(y, ex)
    span = float(np.ptp(y)) if y.size else 0.0
    if math.isfinite(se) and abs(drift) > max(MAX_PERIOD_DRIFT * span, 3.0 * se):
        res.refused = (f"the output's mean moves {drift:+.4g} a period ({100 * abs(drift) / span:.1f} % of "
                       "its span) over the periods used: no periodic steady state, which the correlation "
                       "and spectral estimates assume (seed 003 eq. 2.4.2), as an integrating plant (a "
                       "pole at the origin) or one slower than the record gives; no model from them is "
                       "valid (a self-regulating plant: more periods, or a longer one; an integrating "
                       "one: a step test)")
        why = "no periodic steady state (the output's mean drifts period to period)"
        _invalidate(res.step_result, why)
        _invalidate(res.freq_result, why)
    elif res.impulse is not None and res.impulse.wrapped and res.step_result is not None:
        why = ("the impulse response wrapped around (it has not settled within one period; an integrating "
               "plant never does): its step response is cut short, so no model from it is the plant's")
        _invalidate(res.step_result, why)
        if res.freq_result is None or res.freq_result.best is None:
            res.refused = why + " (identify's notes say what period would do)"
    if res.refused:
        res.notes.append(res.refused)


#: samples at rest put before the step response given to the step methods, as a fraction of it
REST_FRACTION = 0.1
#: the step methods get the step response up to this many times its settling time
STEP_SETTLINGS = 3.0
#: the step methods get at most this many samples of the step response (block means
#: beyond: the estimate is smooth over a clock interval, and 2e4 samples cost 0.7 s of ripple search)
MAX_STEP_SAMPLES = 4_000


def _step_methods(est: corr.ImpulseEstimate, refine: bool, methods):
    """The step methods (:func:`~.step.identify_step`) on the estimate's step
    response, preceded by a stretch at rest, as a unit step at t = 0."""
    from .step import identify_step
    t, s = est.t, est.step
    if not est.wrapped:
        # a few settling times: a long settled tail only blurs what the methods measure
        keep = t <= t[0] + max(STEP_SETTLINGS * (est.settling_s - t[0]), 0.2 * (t[-1] - t[0]))
        t, s = t[keep], s[keep]
    k = max(1, int(math.ceil(t.size / MAX_STEP_SAMPLES)))
    if k > 1:
        n = (t.size // k) * k
        t = t[:n].reshape(-1, k).mean(axis=1)
        s = s[:n].reshape(-1, k).mean(axis=1)
    dt = t[1] - t[0]
    pad = max(16, int(REST_FRACTION * t.size))
    tt = np.concatenate((t[0] - dt * np.arange(pad, 0, -1), t))
    ss = np.concatenate((np.zeros(pad), s))
    uu = (tt >= 0).astype(float)
    return identify_step(tt, ss, uu, step_time=0.0, step_amplitude=1.0, methods=methods,
                         refine=refine)
