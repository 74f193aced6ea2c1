"""The lab bench: the recommended square wave (the seed's 330 Hz, 2 V test of
section IV.9), the slew, swing and period checks for it, the band of the
readings that part tolerances allow (worst case over the tolerance corners),
the whole bench period as a scope would capture it, and the sine check.

Written once against the :class:`~designer.filters.topology.Topology` (issue 26): the
tolerance band takes a section, its values by designator and the tolerances per part kind
or per part (its corners' fn and zeta the section's :meth:`~designer.filters.topology.Topology.ideal_pair`,
their steps from its coefficients), so the Sallen-Key plant and a section plant
(``design-plant --topology``) read the same band; the sine check takes any transfer function
and the section's kind (a high-pass read as a low-pass in 1/f, a band-pass at its centre); the slew and
swing checks take any section's op-amp-aware step (:func:`signal_checks`: the extremes over the whole
period by superposition of the two edges' steps, a high-pass's slope read after the jump at its edge).

The sine check's resonance peak: a second-order low-pass peaks only for
zeta < 1/sqrt(2) = 0.707, by Mr = 1 / (2 zeta sqrt(1 - zeta^2)) at
fn sqrt(1 - 2 zeta^2) (seed 000, eq 79; Ogata, *Modern Control Engineering*,
5th ed., 7-2). Just below 0.707 the rise is a few millionths of the DC gain at a
frequency far below fn (0.00005 dB at 58 Hz for a 1 kHz Butterworth built at zeta
0.7059; 0.1 dB needs zeta 0.652): no scope shows it, so a rise under
:data:`PEAK_MIN_DB` is reported as no peak, with the reason."""

from __future__ import annotations

import itertools
import math
from dataclasses import dataclass, field, fields

import numpy as np

from ..core.checks import Check
from ..core.compare import resample
from ..core.i18n import N_, Message
from ..core.lti import dense_time, dominant_pair, step_response
from ..core.metrics import step_metrics
from ..core.opamps import OpAmp
from ..spice.deck import SquareTest

__all__ = ["PEAK_MIN_DB", "PERIOD_CHECK", "SIGNAL_CHECKS", "ScopeSetup", "channel", "no_peak_reason", "period_extremes",
           "recommend_square_wave", "rising_step", "scope_setup", "signal_checks", "corner_tolerances",
           "tolerance_band", "tolerance_corners"]


def recommend_square_wave(settling_time_s: float, amplitude_v: float, frequency_hz=None,
                          delay_s=None, time_scale_s=None) -> SquareTest:
    """A square wave whose half period leaves the response 1.5 settling times
    (2 %) to settle, rounded down to a round generator setting (the seed used
    330 Hz for its 891 us settling time). ``time_scale_s``: see :class:`SquareTest`.

    Parameters
    ----------
    settling_time_s : float
        The response's 2 % settling time (s).
    amplitude_v : float
        The step (V).
    frequency_hz : float, optional
        The frequency given (``--test-frequency``); None: chosen.
    delay_s : float, optional
        The first edge's delay (s); None: chosen.
    time_scale_s : float, optional
        The response's time scale (s), for the edge; None: from the settling time.

    Returns
    -------
    designer.spice.deck.SquareTest
        The square wave.
    """
    if frequency_hz is None:
        frequency_hz = nice_frequency_below(1.0 / (2 * 1.5 * settling_time_s))
    half = 0.5 / frequency_hz
    if delay_s is None:
        # the rising edge a little after t = 0, within a few time scales for a slow square wave
        delay_s = half * 0.05 if time_scale_s is None else min(half * 0.05, 20 * time_scale_s)
    return SquareTest(amplitude_v=amplitude_v, frequency_hz=frequency_hz, delay_s=delay_s,
                      time_scale_s=time_scale_s)


#: the ids of the op-amp's checks under the bench's square wave (:func:`signal_checks`)
SIGNAL_CHECKS = ("slew_rate", "output_swing")


def period_extremes(y_unit) -> tuple:
    """The output's lowest and highest values over the square wave's period, per volt of its amplitude, from
    the unit step response ``y_unit`` over the rising half period (from the rising edge to the falling one).

    By superposition the output is s(t) after the rising edge and s(T/2) - s(t) after the falling one (the
    level the rising edge reached, s(inf) once settled, less a step): a low-pass overshoots on the rising
    edge and undershoots below 0 V as deep on the falling one, an inverting section swings to -gain, a
    high-pass's output jumps by the amplitude at each edge, below 0 V on the falling one. 0 V (the output at
    rest) is inside the range; a step's value within 1e-9 of its largest below 0 is the closed form's
    rounding, not an undershoot.

    Parameters
    ----------
    y_unit : array_like
        The unit step response from the rising edge to the falling one (or until it has settled).

    Returns
    -------
    tuple of float
        (lo, hi), per volt.
    """
    y = np.asarray(y_unit, float)
    y_max, y_end = float(np.max(y)), float(y[-1])
    y_min = float(np.min(y))
    y_min = y_min if y_min < -1e-9 * float(np.max(np.abs(y))) else 0.0
    # the falling edge first: it is the low end of a low-pass's swing (its -0.0 kept for a step that never
    # overshoots, the seed plant's sheet's "-0 V")
    return min(-(y_max - y_end), y_min, 0.0), max(y_max, y_end - y_min, 0.0)


def signal_checks(t, y_unit, amplitude_v: float, opamp: OpAmp, edge: bool = False) -> list:
    """Slew and swing checks (:class:`~designer.core.checks.Check`, ids :data:`SIGNAL_CHECKS`) of the op-amp
    output for a 0 <-> amplitude square wave, given the unit step response ``y_unit`` of the output over the
    rising half period (any section: its extremes :func:`period_extremes`; its largest slope the rising
    edge's, the falling edge's mirrored), against half the op-amp's slew rate and its output range on its
    supplies.

    A step that jumps with the edge (``edge``: a high-pass's) asks the op-amp to follow the generator's edge,
    which every op-amp slews through (the jump takes jump / slew rate): its slope is read after the edge, from
    the first turn of the output's magnitude on, the response's own (2 zeta wn x the jump for a second-order
    high-pass). That slope under half the slew rate is a jump slewed in under about 1 / (4 zeta wn), a small
    part of the response; the detail gives the jump's time.

    Parameters
    ----------
    t : array_like
        The times from the rising edge (s; a grid uniform or not, fine where the step is fast:
        :func:`rising_step`).
    y_unit : array_like
        The op-amp-aware unit step response on ``t``.
    amplitude_v : float
        The square wave's high level (V; low 0 V).
    opamp : designer.core.opamps.OpAmp
        The op-amp (an ideal one passes both, saying what the output needs).
    edge : bool
        The step jumps with the edge.

    Returns
    -------
    list of Check
        ``slew_rate``, ``output_swing``.
    """
    y = np.asarray(y_unit, float)
    turns = np.flatnonzero(np.diff(np.abs(y)) < 0) if edge else ()
    start = int(turns[0]) if len(turns) else 0
    slope = float(np.max(np.abs(np.gradient(y, t)[start:]))) * abs(amplitude_v)
    jump = abs(float(y[start]) * amplitude_v)
    lo, hi = period_extremes(y)
    peak, trough = hi * amplitude_v, lo * amplitude_v
    swing = dict(lo=f"{trough:.3g}", hi=f"{peak:.3g}")
    need = f"{slope / 1e6:.3g}"
    if opamp.ideal:
        slew = Check.of("slew_rate", True, N_("ideal op-amp; output jumps {jump} V at each edge, then needs {need} "
                                              "V/us"), jump=f"{jump:.3g}", need=need) if start else \
            Check.of("slew_rate", True, N_("ideal op-amp; output needs {need} V/us"), need=need)
        return [slew, Check.of("output_swing", True, N_("ideal op-amp; output spans {lo} V to {hi} V"), **swing)]
    sr = opamp.slew_v_per_s
    slew_ok = slope <= 0.5 * sr
    have = f"{sr / 1e6:.3g}"
    if start:
        slew = Check.of("slew_rate", slew_ok,
                        N_("output jumps {jump} V at each edge (slewed in {time} us), then needs {need} V/us, "
                           "{opamp} gives {have} V/us") if slew_ok else
                        N_("output jumps {jump} V at each edge (slewed in {time} us), then needs {need} V/us, "
                           "{opamp} gives {have} V/us (keep below half of it: lower the amplitude)"),
                        jump=f"{jump:.3g}", time=f"{jump / sr * 1e6:.3g}", need=need, opamp=opamp.name, have=have)
    else:
        slew = Check.of("slew_rate", slew_ok,
                        N_("output needs {need} V/us, {opamp} gives {have} V/us") if slew_ok else
                        N_("output needs {need} V/us, {opamp} gives {have} V/us (keep below half of it: lower the "
                           "amplitude)"), need=need, opamp=opamp.name, have=have)
    return [slew, Check.of("output_swing", peak <= opamp.vout_max and trough >= opamp.vout_min,
                           N_("output spans {lo} V to {hi} V; {opamp} on {vcc}/{vee} V reaches {min} V to {max} V"),
                           **swing, opamp=opamp.name, vcc=f"{opamp.vcc:g}", vee=f"{opamp.vee:g}",
                           min=f"{opamp.vout_min:.3g}", max=f"{opamp.vout_max:.3g}")]


def rising_step(ideal: tuple, opamp: tuple, t_end: float, known: tuple | None = None) -> tuple:
    """The op-amp-aware unit step over the rising half period, on the grid :func:`signal_checks` reads: uniform
    (:func:`~designer.core.lti.dense_time`) up to ``t_end``; where the ideal step jumps (a high-pass's: its
    numerator of the denominator's degree) refined over the op-amp-aware model's fastest time constant from the
    edge, where the output slews (50 time constants at 1/80 of one: the uniform grid's step may be longer than
    the whole edge).

    Parameters
    ----------
    ideal, opamp : tuple
        (num, den) of the ideal and op-amp-aware models (highest power first, num's leading zeros trimmed).
    t_end : float
        The grid's end (s): the half period, or the span over which the step settles.
    known : tuple, optional
        (t, y): the op-amp-aware step already computed on a grid; taken when that grid is this one (the bench's
        own step over 4 spans, when the half period is longer: not simulated twice).

    Returns
    -------
    tuple
        (t, y, edge): the grid, the step on it, whether it jumps (:func:`signal_checks`'s ``edge``).
    """
    (num_i, den_i), (num_o, den_o) = ideal, opamp
    t = dense_time(t_end)
    edge = len(num_i) == len(den_i)
    if edge:
        fastest = 1.0 / float(np.max(np.abs(np.roots(den_o))))
        t = np.union1d(t, np.linspace(0.0, min(t_end, 50 * fastest), 4001))
    if known is not None and known[0].shape == t.shape and np.array_equal(known[0], t):
        return t, known[1], edge
    return t, step_response(num_o, den_o, t), edge


#: the id of :func:`period_check`'s check
PERIOD_CHECK = "square_wave_period"


def period_check(test: SquareTest, settling_time_s: float) -> Check | None:
    """A failed check when the square wave's half period is shorter than the 2 %
    settling time (the scope would never show a settled step); None when it is not."""
    if test.half_period_s >= settling_time_s:
        return None
    return Check.of(PERIOD_CHECK, False,
                    N_("half period {half} us is shorter than the 2 % settling time {settling} us: the scope will "
                       "not show a settled step"), half=f"{test.half_period_s * 1e6:.4g}",
                    settling=f"{settling_time_s * 1e6:.4g}")


@dataclass(frozen=True)
class Band:
    """The range a reading may take; None when no corner has the reading
    (e.g. the peak time of a response that never overshoots)."""

    lo: float | None
    hi: float | None

    def to_dict(self) -> dict:
        return {"min": self.lo, "max": self.hi}


@dataclass(frozen=True)
class ToleranceBand:
    """Where the scope readings of a build may land, given its parts'
    tolerances: each figure's band over the tolerance corners."""

    fn_hz: Band
    zeta: Band
    overshoot_pct: Band
    peak_time_s: Band
    rise_time_s: Band
    settling_time_s: Band
    r_tolerance_pct: float
    c_tolerance_pct: float
    t_s: np.ndarray | None = field(default=None, repr=False, compare=False)    #: the envelope's grid
    lo: np.ndarray | None = field(default=None, repr=False, compare=False)     #: lowest unit step over the corners
    hi: np.ndarray | None = field(default=None, repr=False, compare=False)     #: highest
    #: corners whose poles reach the right half-plane (no step readings there); the result's notes say it, the
    #: band's JSON keeps its keys (identify --against reads every key as a {min, max} band)
    unstable_corners: int = field(default=0, compare=False)

    def to_dict(self) -> dict:
        out = {}
        for f in fields(self):
            if f.name in ("t_s", "lo", "hi", "unstable_corners"):
                continue
            value = getattr(self, f.name)
            out[f.name] = value.to_dict() if isinstance(value, Band) else value
        return out


def corner_tolerances(topology, tolerances: dict) -> dict:
    """Each part's tolerance (fraction) from ``tolerances`` given per part kind (``{"R": 0.05, "C": 0.1}``)
    or per designator (parts not named are held at their value).

    Parameters
    ----------
    topology : designer.filters.topology.Topology
        The section.
    tolerances : dict
        ``"R"``/``"C"`` -> fraction, or designator -> fraction.

    Returns
    -------
    dict
        Designator -> fraction, in the section's declared order, for the parts that vary.
    """
    by_kind = set(tolerances) <= {"R", "C"}
    return {p.ref: float(tolerances[p.kind] if by_kind else tolerances[p.ref]) for p in topology.parts
            if (p.kind if by_kind else p.ref) in tolerances}


def tolerance_corners(values: dict, tolerances: dict) -> list:
    """The 2^n corners of the n parts of ``tolerances`` at -/+ their tolerance, the other parts of
    ``values`` held: in ``tolerances``' order, its last part's sign the fastest (every band over a
    section's corners takes them from here: :func:`tolerance_band`, check-design's, identify's).

    Parameters
    ----------
    values : dict
        Designator -> nominal value.
    tolerances : dict
        Designator -> tolerance (a fraction) of each part that varies.

    Returns
    -------
    list of dict
        Designator -> value, one per corner.
    """
    out = []
    for signs in itertools.product((-1, 1), repeat=len(tolerances)):
        v = dict(values)
        for (ref, x), sign in zip(tolerances.items(), signs):
            v[ref] = values[ref] * (1 + sign * x)
        out.append(v)
    return out


def tolerance_band(topology, values: dict, tolerances: dict, t_end: float) -> ToleranceBand:
    """Min and max of fn, zeta and the step metrics over the tolerance corners of a section
    (every varying part at -/+ its tolerance: 2^n corners, the parts in the section's declared
    order, the last part's sign the fastest; ideal op-amp), for the scope readings.

    fn and zeta are the section's ideal pair (:meth:`~designer.filters.topology.Topology.ideal_pair`;
    a band-pass's centre and 1/(2 Q)); the step metrics are a low-pass's (a high- or band-pass's
    step settles to 0: their bands are empty, the envelope of the steps is still drawn).

    Parameters
    ----------
    topology : designer.filters.topology.Topology
        The section.
    values : dict
        Designator -> value (ohm, farad), every declared part.
    tolerances : dict
        Per part kind (``{"R": r_tol, "C": c_tol}``) or per designator (fractions); a designator
        not named is held (the Sallen-Key plant's band varies its RC network, not its gain pair).
    t_end : float
        The step response's span (s).

    Returns
    -------
    ToleranceBand
        The extremes and the band of step responses.
    """
    tol = corner_tolerances(topology, tolerances)
    t = dense_time(t_end, 8001)
    rows = []
    lo = hi = None
    unstable = 0
    for v in tolerance_corners(values, tol):
        num, den = (np.asarray(c, float) for c in topology.coefficients(v))
        num = np.trim_zeros(num, "f") if np.any(num) else num
        fn, zeta = topology.ideal_pair(v)
        if np.any(np.real(np.roots(den)) >= 0):
            # an unstable corner (a high-Q gain section's positive feedback past its edge: zeta <= 0) has no
            # step readings and no envelope to draw (its step grows without bound: exp overflowed); its fn and
            # zeta are real and stay in their bands, the count is reported
            unstable += 1
            rows.append((fn, zeta, None, None, None, None))
            continue
        y = step_response(num, den, t)
        lo = y if lo is None else np.minimum(lo, y)
        hi = y if hi is None else np.maximum(hi, y)
        if topology.kind == "lowpass":
            m = step_metrics(t, y, final=float(num[-1] / den[-1]))
            rows.append((fn, zeta, m.overshoot_pct, m.peak_time_s, m.rise_time_s, m.settling_time_s))
        else:
            rows.append((fn, zeta, None, None, None, None))
    bands = []
    for column in zip(*rows):
        vals = [v for v in column if v is not None and not math.isnan(v)]
        bands.append(Band(min(vals), max(vals)) if vals else Band(None, None))
    r_tol = max((x for ref, x in tol.items() if ref[0] == "R"), default=0.0)
    c_tol = max((x for ref, x in tol.items() if ref[0] == "C"), default=0.0)
    return ToleranceBand(*bands, r_tolerance_pct=100 * r_tol, c_tolerance_pct=100 * c_tol,
                         t_s=None if lo is None else t, lo=lo, hi=hi, unstable_corners=unstable)


@dataclass(frozen=True)
class BenchPeriod:
    """One whole bench period (rising and falling edge) on a uniform grid, as
    a scope captures it: the input, the output (SPICE when simulated, else the
    op-amp-aware model) and both analytic models. ``identify`` reads it back."""

    time_s: np.ndarray
    input_v: np.ndarray
    output_v: np.ndarray
    analytic_v: np.ndarray
    analytic_opamp_v: np.ndarray

    def columns(self) -> dict:
        """Column name -> samples, in the order of the CSV."""
        return {f.name: getattr(self, f.name) for f in fields(self)}


def bench_period(test: SquareTest, ideal_tf, opamp_tf, spice=None, n: int = 4001) -> BenchPeriod:
    """The :class:`BenchPeriod` of ``test``: the models' responses to the square
    wave by superposition of two steps; ``spice``, when simulated, is its
    (time, output, input) over the period."""
    t = np.linspace(0.0, test.stop_s, n)
    u = np.where((t >= test.delay_s) & (t < test.delay_s + test.half_period_s), test.amplitude_v, 0.0)

    def square(num, den):
        up = np.clip(t - test.delay_s, 0.0, None)
        down = np.clip(t - test.delay_s - test.half_period_s, 0.0, None)
        y = step_response(num, den, up) * (t >= test.delay_s)
        return test.amplitude_v * (y - step_response(num, den, down) * (t >= test.delay_s + test.half_period_s))

    ideal, with_opamp = square(*ideal_tf), square(*opamp_tf)
    if spice is None:
        return BenchPeriod(t, u, with_opamp, ideal, with_opamp)
    ts, ys, us = spice
    return BenchPeriod(t, resample(ts, us, t), resample(ts, ys, t), ideal, with_opamp)


def nice_frequency_below(f: float) -> float:
    """The largest 1-1.5-2.2-3.3-4.7-6.8 (E6) x 10^k value not above ``f``
    (function generators are set to round numbers)."""
    k = math.floor(math.log10(f))
    best = None
    for dec in (k - 1, k):
        for m in (1.0, 1.5, 2.2, 3.3, 4.7, 6.8):
            v = float(f"{m * 10 ** dec:.3g}")
            if v <= f * (1 + 1e-12):
                best = v
    return best


# ---- the scope and the generator, as set on the bench ---------------------------------------

#: a scope screen: 10 horizontal and 8 vertical divisions
H_DIVS, V_DIVS = 10, 8
#: where the trigger (the rising edge) sits, in divisions from the left of the screen
EDGE_DIV = 1.0


def one_two_five(x: float) -> float:
    """The smallest 1-2-5 setting (1, 2, 5 x 10^k: what scope knobs step through) at or above ``x``."""
    k = math.floor(math.log10(x))
    for dec in (k, k + 1):
        for m in (1.0, 2.0, 5.0):
            v = float(f"{m * 10.0 ** dec:.3g}")
            if v >= x * (1 - 1e-9):
                return v
    return float(f"{10.0 ** (k + 1):.3g}")  # pragma: no cover - the loop always returns


@dataclass(frozen=True)
class Channel:
    """One scope channel: what it probes, its volts/div (1-2-5) and where its
    0 V sits (divisions below the screen's centre), so that the signal's whole
    swing ``lo``..``hi`` stays on the 8 divisions."""

    name: str
    node: str
    volts_per_div: float
    zero_div_below_centre: float
    lo_v: float
    hi_v: float

    def to_dict(self) -> dict:
        return {"name": self.name, "node": self.node, "volts_per_div": self.volts_per_div,
                "zero_div_below_centre": self.zero_div_below_centre, "lo_v": self.lo_v, "hi_v": self.hi_v}


@dataclass(frozen=True)
class ScopeSetup:
    """The scope as set for the square-wave test: time/div (1-2-5) so that the
    response settles on screen after the edge, the edge ``edge_div`` divisions
    from the left, trigger on CH1's rising edge at ``trigger_v``, and the channels."""

    time_per_div_s: float
    edge_div: float
    trigger_v: float
    channels: tuple

    def to_dict(self) -> dict:
        return {"time_per_div_s": self.time_per_div_s, "edge_div": self.edge_div, "trigger_v": self.trigger_v,
                "channels": [c.to_dict() for c in self.channels]}


def channel(name: str, node: str, lo: float, hi: float) -> Channel:
    """The 1-2-5 volts/div and 0 V position that fit ``lo``..``hi`` on 6 of the 8
    divisions (a division of headroom at each edge of the screen).

    Parameters
    ----------
    name : str
        The channel (``CH1``).
    node : str
        The node it probes.
    lo, hi : float
        The range of the signal (V).

    Returns
    -------
    Channel
        The channel's settings.
    """
    lo, hi = min(lo, 0.0), max(hi, 0.0)
    vdiv = one_two_five(max(hi - lo, 1e-6) / (V_DIVS - 2))
    # centre the swing on the screen: 0 V this many divisions below the centre
    zero = round(((hi + lo) / 2) / vdiv * 2) / 2
    return Channel(name, node, vdiv, zero, lo, hi)


def scope_setup(window_s: float, trigger_v: float, channels) -> ScopeSetup:
    """Time/div showing ``window_s`` after the edge (the edge :data:`EDGE_DIV` in).

    Parameters
    ----------
    window_s : float
        The time shown after the edge (s).
    trigger_v : float
        The trigger level (V).
    channels : sequence of Channel
        The channels.

    Returns
    -------
    ScopeSetup
        The scope's settings.
    """
    return ScopeSetup(one_two_five(window_s / (H_DIVS - EDGE_DIV)), EDGE_DIV, trigger_v, tuple(channels))


def plant_scope(test: SquareTest, peak_value: float, trough_value: float,
                settling_time_s: float, generator: str = N_("generator (R1)")) -> ScopeSetup:
    """A plant's bench scope: CH1 the generator (0 -> amplitude), CH2 the output
    (its peak and, on the falling edge, its undershoot), 1.2 settling times on screen
    (at most the half period) after the trigger at half the amplitude.

    Parameters
    ----------
    test : SquareTest
        The square wave.
    peak_value, trough_value : float
        The output's extremes over the period per volt of square wave.
    settling_time_s : float
        The step's settling time (s; not finite: the whole half period on screen).
    generator : str
        CH1's label (the seed's plant names the part the generator drives).

    Returns
    -------
    ScopeSetup
        The settings.
    """
    a = test.amplitude_v
    window = min(1.2 * settling_time_s, test.half_period_s) if math.isfinite(settling_time_s) \
        else test.half_period_s
    return scope_setup(window, a / 2, (channel("CH1", generator, 0.0, a),
                                       channel("CH2", N_("U1 output"), a * trough_value, a * peak_value)))


@dataclass(frozen=True, eq=False)
class SineCheck:
    """The sine check (a student will try one): the resonance peak and the -3 dB
    point of the gain, from the model and, when simulated, measured in the SPICE
    ``.ac`` run; the sine's amplitude to set, and the curves for the Bode plot."""

    amplitude_v: float                  #: generator amplitude (peak) that keeps the output in the op-amp's limits
    dc_gain: float
    f_peak_hz: float | None             #: None: no resonance peak (``no_peak`` says why)
    peak_gain: float | None             #: |H| at the peak, V/V
    f_3db_hz: float
    spice_f_peak_hz: float | None = None
    spice_peak_gain: float | None = None
    spice_f_3db_hz: float | None = None
    f_hz: np.ndarray | None = None      #: the model's sweep
    h_model: np.ndarray | None = None
    spice_f_hz: np.ndarray | None = None
    h_spice: np.ndarray | None = None
    no_peak: str | None = None          #: why the model shows no peak (None: it does)
    spice_no_peak: str | None = None    #: why SPICE's .ac shows none (None: it does, or not simulated)
    #: the response read: a low-pass's gain against DC (the Sallen-Key plant's), a high-pass's against its
    #: high-frequency gain (``dc_gain`` is then that passband gain), a band-pass's at its centre (``f_peak_hz``,
    #: ``peak_gain`` and ``dc_gain`` the centre's; ``f_3db_hz`` the upper -3 dB point, ``f_3db_low_hz`` the lower)
    kind: str = "lowpass"
    f_3db_low_hz: float | None = None
    spice_f_3db_low_hz: float | None = None

    def to_dict(self) -> dict:
        out = {"amplitude_v": self.amplitude_v, "dc_gain": self.dc_gain, "f_peak_hz": self.f_peak_hz,
               "peak_gain": self.peak_gain, "no_peak_reason": self.no_peak, "f_3db_hz": self.f_3db_hz,
               "spice_f_peak_hz": self.spice_f_peak_hz, "spice_peak_gain": self.spice_peak_gain,
               "spice_no_peak_reason": self.spice_no_peak, "spice_f_3db_hz": self.spice_f_3db_hz}
        if self.kind != "lowpass":   # a section's high- or band-pass: the keys a low-pass's JSON never had
            out.update(kind=self.kind, f_3db_low_hz=self.f_3db_low_hz, spice_f_3db_low_hz=self.spice_f_3db_low_hz)
        return out


#: the damping at and above which a second-order low-pass has no resonance peak (Mr = 1 there)
ZETA_NO_PEAK = 1 / math.sqrt(2)
#: a rise of the gain above its DC value smaller than this is not shown as a peak: 0.1 dB is 1.2 %,
#: below what a scope's amplitude reading tells apart (a TBS1000's vertical accuracy is +-3 %)
PEAK_MIN_DB = 0.1


def no_peak_reason(zeta: float, peak_gain, dc_gain: float) -> str | None:
    """Why a response shows no resonance peak, or None when it shows one.

    Parameters
    ----------
    zeta : float
        Damping of the response's dominant pole pair.
    peak_gain : float or None
        The highest gain found in the sweep (None: it never rises above its DC value).
    dc_gain : float
        The gain the rise is measured from.

    Returns
    -------
    str or None
        "no resonance peak (zeta >= 0.707)", or, for a rise under :data:`PEAK_MIN_DB`,
        the same with the damping; None for a peak of at least :data:`PEAK_MIN_DB`.
    """
    # a Message: the English text (result.json's), shown on a sheet in its language
    if zeta >= ZETA_NO_PEAK:
        return Message(N_("no resonance peak (zeta >= 0.707)"))
    if peak_gain is None or 20 * math.log10(peak_gain / dc_gain) < PEAK_MIN_DB:
        return Message(N_("no resonance peak (zeta {zeta}, near 0.707: under {db} dB)"), zeta=f"{zeta:.4g}",
                       db=f"{PEAK_MIN_DB:g}")
    return None


def peak_and_corner(f, h) -> tuple:
    """(f_peak, |H| peak, f_-3dB) of a low-pass's sampled response ``h`` on ``f``:
    the peak refined by a parabola in log f (None when the gain never rises above its
    DC value), the -3 dB point interpolated in log f where |H| falls below
    |H(0)|/sqrt(2) after the peak (None when it never does)."""
    f = np.asarray(f, float)
    mag = np.abs(np.asarray(h))
    dc = mag[0]
    i = int(np.argmax(mag))
    fp = gp = None
    if 0 < i < mag.size - 1 and mag[i] > dc * (1 + 1e-6):
        x = np.log(f[i - 1:i + 2])
        y = mag[i - 1:i + 2]
        c = np.polyfit(x - x[1], y, 2)
        dx = -c[1] / (2 * c[0]) if c[0] < 0 else 0.0
        dx = float(np.clip(dx, x[0] - x[1], x[2] - x[1]))
        fp, gp = float(f[i] * math.exp(dx)), float(np.polyval(c, dx))
    level = dc / math.sqrt(2)
    below = np.nonzero(mag[i:] < level)[0]
    f3 = None
    if below.size:
        j = i + int(below[0])
        a, b = mag[j - 1], mag[j]
        t = (a - level) / (a - b)
        f3 = float(math.exp(math.log(f[j - 1]) + t * (math.log(f[j]) - math.log(f[j - 1]))))
    return fp, gp, f3


def centre_and_corners(f, h) -> tuple:
    """(f_centre, |H| there, f_-3dB low, f_-3dB high) of a band-pass's sampled response ``h`` on ``f``
    (ascending): the centre refined by a parabola in log f, as :func:`peak_and_corner` refines a peak,
    and the -3 dB points where |H| falls below the centre's gain over sqrt(2) on either side (None
    where the sweep does not reach it).

    Parameters
    ----------
    f : array_like
        The frequencies (Hz), ascending.
    h : array_like
        The complex response on them.

    Returns
    -------
    tuple
        (f_centre, gain at the centre, f_low, f_high).
    """
    f = np.asarray(f, float)
    mag = np.abs(np.asarray(h))
    i = int(np.argmax(mag))
    fc, gc = float(f[i]), float(mag[i])
    if 0 < i < mag.size - 1:
        x = np.log(f[i - 1:i + 2])
        c = np.polyfit(x - x[1], mag[i - 1:i + 2], 2)
        dx = float(np.clip(-c[1] / (2 * c[0]), x[0] - x[1], x[2] - x[1])) if c[0] < 0 else 0.0
        fc, gc = float(f[i] * math.exp(dx)), float(np.polyval(c, dx))
    # each side as a low-pass read from the centre outwards: peak_and_corner's -3 dB interpolation
    # (the lower side in 1/f, ascending, its corner mapped back)
    low = peak_and_corner(1 / f[:i + 1][::-1], np.concatenate(([gc], mag[:i][::-1])))[2] if i else None
    low = None if low is None else 1 / low
    high = peak_and_corner(f[i:], np.concatenate(([gc], mag[i + 1:])))[2]
    return fc, gc, low, high


def sine_check(num, den, opamp: OpAmp, amplitude_v: float, fn_hz: float, spice=None, kind: str = "lowpass",
               zeta: float | None = None) -> SineCheck:
    """The sine check of a plant model (num, den) with natural frequency ``fn_hz``:
    the sweep fn/100 .. 100 fn (the ``.ac`` deck's), its peak and -3 dB point, and
    the generator amplitude: half the square wave's, lowered (1-2-5 steps) until
    the peak output stays inside the op-amp's swing and needs at most half its slew
    rate. ``spice``: (f, complex H) of the ``.ac`` run.

    A high-pass is read as a low-pass in 1/f (its gain against the high-frequency end, its peak
    and -3 dB point found going down from there: the same rule, mirrored); a band-pass at its
    centre, where a sine comes through largest (its gain there and the -3 dB points either side:
    a band-pass has no DC gain to read a resonance against, its centre is its passband).
    ``zeta``: the damping the no-peak rule reads (None: the dominant pair of ``den``; a
    first-order section passes 1, the critically damped pair of its pole).
    """
    from ..core.lti import freq_response
    f = np.logspace(math.log10(fn_hz / 100), math.log10(fn_hz * 100), 1201)
    h = freq_response(num, den, f)
    top = float(np.max(np.abs(h)))
    zeta = dominant_pair(den)[1] if zeta is None else zeta

    def read(fs, hs):
        """(f_peak, peak gain, f_-3dB, f_-3dB low, why no peak, reference gain) of one sweep."""
        fs, mag = np.asarray(fs, float), np.abs(np.asarray(hs))
        if kind == "bandpass":
            fc, gc, lo3, hi3 = centre_and_corners(fs, hs)
            return fc, gc, hi3, lo3, None, gc
        if kind == "highpass":
            # a low-pass in 1/f (ascending), its frequencies mapped back: the parabola and the interpolation
            # in log(1/f) = -log f are the low-pass's, mirrored
            fp, gp, f3 = peak_and_corner(1 / fs[::-1], np.asarray(hs)[::-1])
            fp, f3 = (None if x is None else 1 / x for x in (fp, f3))
            ref = float(mag[-1])
        else:
            fp, gp, f3 = peak_and_corner(fs, hs)
            ref = float(mag[0])
        why = no_peak_reason(zeta, gp, ref)
        if why is not None:
            fp = gp = None
        return fp, gp, f3, None, why, ref

    fp, gp, f3, f3_low, why, dc = read(f, h)
    amp = amplitude_v / 2
    if not opamp.ideal:
        fmax = fp or fn_hz
        amp = min(amp, 0.9 * opamp.vout_max / top, 0.5 * opamp.slew_v_per_s / (2 * math.pi * fmax * top))
    amp = _one_two_five_below(amp)
    if spice is None:
        return SineCheck(amp, dc, fp, gp, f3, f_hz=f, h_model=h, no_peak=why, kind=kind, f_3db_low_hz=f3_low)
    fs, hs = spice
    # SPICE's own reference gain (its sweep's first point, fn/100, for a low-pass): the rise is judged against
    # what it starts from
    sfp, sgp, sf3, sf3_low, spice_why, _ = read(fs, hs)
    return SineCheck(amp, dc, fp, gp, f3, sfp, sgp, sf3, f, h, np.asarray(fs, float), np.asarray(hs),
                     no_peak=why, spice_no_peak=spice_why, kind=kind, f_3db_low_hz=f3_low,
                     spice_f_3db_low_hz=sf3_low)


def _one_two_five_below(x: float) -> float:
    k = math.floor(math.log10(x))
    best = None
    for dec in (k - 1, k):
        for m in (1.0, 2.0, 5.0):
            v = float(f"{m * 10.0 ** dec:.3g}")
            if v <= x * (1 + 1e-9):
                best = v
    return best
