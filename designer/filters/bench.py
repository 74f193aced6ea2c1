"""The bench test of a designed filter (:class:`~designer.filters.design.FilterDesign`),
computed once and kept typed for the build sheet (:mod:`designer.filters.report`,
which formats and recomputes nothing):

- a sine sweep: 1-2-5 frequencies across the sweep (and the mask's edges and
  the -3 dB points), each with the gain and phase the chosen parts give with the
  op-amp's model, their band over :data:`BUILDS` builds of the parts drawn
  uniformly within their tolerances (seed :data:`SEED`; the 0.5th to 99.5th
  percentile), and the generator and scope settings to read it (1-2-5 steps:
  two periods across ten divisions, the trace over six of eight divisions);
- the step test (a low-pass: a 0 -> A square wave whose half period is five
  settling times) or the tone burst (high- and band-pass: ten cycles at the
  passband's centre or, a high-pass, the 1-2-5 value at or above three times the
  cut-off, :func:`burst_tone`; the SPICE proof's transient is the same burst), its
  output from the chosen parts' ideal transfer function
  (:func:`designer.core.lti.filter_foh`, exact for a piecewise-linear input);
- each stage's op-amp checks at the bench amplitude: its GBW against
  margin x fn x Q x noise gain (SLOA088's rule of thumb, the design's figure), the
  stage's output peak against the op-amp's swing, and the slew a sine of that
  peak needs at the stage's fn, 2 pi fn Vpk (Franco, "Design with Operational
  Amplifiers", full-power bandwidth), against the slew rate;
- the Bessel's group delay, tau = -d phi / d omega (finite differences);
- each stage beside its row of the normalised tables (:mod:`designer.filters.tables`).
"""

from __future__ import annotations

import math
from dataclasses import asdict, dataclass, field

import numpy as np

from ..core.i18n import N_
from ..core.jsonio import json_safe
from ..core.lti import filter_foh
from ..core.metrics import step_metrics
from .registry import get as get_topology
from .tables import coefficient_table

__all__ = ["BUILDS", "SEED", "R_TOL_PCT", "C_TOL_PCT", "SweepPoint", "TimeTest", "StageCheck", "TableCompare",
           "FilterBench", "BURST_CYCLES", "nice_up", "nice_down", "burst_tone", "bench_of", "passband_gain"]

#: Monte Carlo builds behind each sweep point's band, and their recorded seed
BUILDS, SEED = 500, 0
#: the parts' tolerances the band assumes (and the bill of materials lists): 1 % metal film, 5 % film or C0G
R_TOL_PCT, C_TOL_PCT = 1.0, 5.0
#: the tone burst's cycles (the bench sheet's time test of a high- or band-pass, and the SPICE proof's transient)
BURST_CYCLES = 10
#: sweep points more than this far below the passband gain are not on the table (the scope's floor)
FLOOR_DB = 60.0


def _nice(x: float, up: bool) -> float:
    """The least 1-2-5 value at or above ``x`` (``up``), or the largest at or below it."""
    e = math.floor(math.log10(x))
    near = [m * 10.0 ** k for k in (e - 1, e, e + 1) for m in (1, 2, 5)]
    if up:
        return float(min(v for v in near if v >= x * (1 - 1e-12)))
    return float(max(v for v in near if v <= x * (1 + 1e-12)))


def nice_up(x: float) -> float:
    """The least 1-2-5 value (1, 2, 5 x 10^k) at or above ``x``.

    Parameters
    ----------
    x : float
        A positive number.

    Returns
    -------
    float
        The 1-2-5 value.
    """
    return _nice(x, True)


def nice_down(x: float) -> float:
    """The largest 1-2-5 value at or below ``x``.

    Parameters
    ----------
    x : float
        A positive number.

    Returns
    -------
    float
        The 1-2-5 value.
    """
    return _nice(x, False)


@dataclass(frozen=True)
class SweepPoint:
    """One row of the sine sweep.

    Parameters
    ----------
    f_hz : float
        Generator frequency.
    gain_db, phase_deg : float
        Expected gain (dB, relative to 1 V/V) and phase (output against input, -180..180 deg).
    gain_lo_db, gain_hi_db, phase_lo_deg, phase_hi_deg : float
        The band of the builds.
    out_pk_v : float
        The output's expected peak at the bench amplitude.
    time_per_div_s, ch1_v_per_div, ch2_v_per_div : float
        Scope settings.
    note : str
        What the point is (``passband edge``, ``-3 dB``...), or empty.
    """

    f_hz: float
    gain_db: float
    phase_deg: float
    gain_lo_db: float
    gain_hi_db: float
    phase_lo_deg: float
    phase_hi_deg: float
    out_pk_v: float
    time_per_div_s: float
    ch1_v_per_div: float
    ch2_v_per_div: float
    note: str = ""


@dataclass
class TimeTest:
    """The step (low-pass) or tone-burst test.

    Parameters
    ----------
    kind : str
        ``step`` or ``burst``.
    frequency_hz : float
        Square-wave frequency (step) or the burst's tone.
    amplitude_v : float
        Step height, or the tone's peak.
    cycles : int
        The burst's cycles (0 for a step).
    repeat_hz : float
        How often the burst repeats (0 for a step).
    t_s, input_v, output_v : ndarray
        The simulated test (from the step or the burst's start).
    metrics : dict
        Step: overshoot_pct, rise_time_s, settling_time_s, peak_v, final_v; burst: peak_v,
        steady_pk_v, settle_s (to within 2 % of the steady peak).
    time_per_div_s, ch2_v_per_div : float
        Scope settings.
    """

    kind: str
    frequency_hz: float
    amplitude_v: float
    cycles: int
    repeat_hz: float
    t_s: np.ndarray
    input_v: np.ndarray
    output_v: np.ndarray
    metrics: dict
    time_per_div_s: float
    ch2_v_per_div: float

    def to_dict(self) -> dict:
        """Settings and figures (the waveforms left out).

        Returns
        -------
        dict
            JSON-ready.
        """
        return json_safe({k: v for k, v in asdict(self).items() if k not in ("t_s", "input_v", "output_v")})


@dataclass(frozen=True)
class StageCheck:
    """One stage against its op-amp at the bench amplitude.

    Parameters
    ----------
    stage : int
        Stage number.
    gbw_needed_hz, gbw_hz : float
        What the stage needs, what the op-amp has.
    out_peak_v, swing_v : float
        The stage output's peak, the op-amp's swing (the smaller of its two rails' reach).
    slew_needed_v_per_s, slew_v_per_s : float
        2 pi fn x the output's peak, the op-amp's slew rate.
    """

    stage: int
    gbw_needed_hz: float
    gbw_hz: float
    out_peak_v: float
    swing_v: float
    slew_needed_v_per_s: float
    slew_v_per_s: float

    @property
    def ok(self) -> bool:
        """All three within the op-amp's."""
        return (self.gbw_needed_hz <= self.gbw_hz and self.out_peak_v <= self.swing_v
                and self.slew_needed_v_per_s <= self.slew_v_per_s)


@dataclass(frozen=True)
class TableCompare:
    """A stage beside the normalised table's row with its Q.

    Parameters
    ----------
    stage : int
        Stage number.
    table_fn_ratio, table_q, table_k : float or None
        The table's fn/fC, Q, fC_i/fC (None: no table for this stage, a band-pass section).
    design_fn_ratio : float
        This design's fn/fc (a high-pass: fc/fn, as the tables' low-pass).
    fn_hz, q : float
        The plan's fn and Q.
    fn_design_hz, q_design : float
        What the parts were synthesised for (pre-distorted for the op-amp with ``--compensate-gbw``).
    fn_built_hz, q_built : float
        What the chosen parts give (ideal op-amp).
    """

    stage: int
    table_fn_ratio: float | None
    table_q: float | None
    table_k: float | None
    design_fn_ratio: float | None
    fn_hz: float
    q: float | None
    fn_design_hz: float
    q_design: float | None
    fn_built_hz: float
    q_built: float | None


@dataclass
class FilterBench:
    """Everything the build sheet shows beyond the design itself.

    Parameters
    ----------
    sweep : list of SweepPoint
        The sine sweep.
    time_test : TimeTest
        The step or burst.
    checks : list of StageCheck
        Per stage.
    tables : list of TableCompare
        Per stage.
    table_corner : float
        The tables' fC over this design's fc (1 but for a Chebyshev).
    group_delay : tuple or None
        (f_hz, delay_s) arrays of a Bessel, else None.
    amplitude_v : float
        The generator's peak.
    """

    sweep: list
    time_test: TimeTest
    checks: list
    tables: list
    table_corner: float
    group_delay: tuple | None = None
    amplitude_v: float = 1.0
    builds: int = BUILDS
    seed: int = SEED
    r_tol_pct: float = R_TOL_PCT
    c_tol_pct: float = C_TOL_PCT
    f_hz: np.ndarray = field(default=None, repr=False)
    h: np.ndarray = field(default=None, repr=False)
    h_lo_db: np.ndarray = field(default=None, repr=False)
    h_hi_db: np.ndarray = field(default=None, repr=False)

    def to_dict(self) -> dict:
        """The bench as JSON (curves left out).

        Returns
        -------
        dict
            ``sweep``, ``time_test``, ``checks``, ``tables``, the band's builds, seed and tolerances.
        """
        gd = None
        if self.group_delay is not None:
            gd = {"dc_delay_s": float(self.group_delay[1][0])}
        return json_safe({"amplitude_v": self.amplitude_v, "builds": self.builds, "seed": self.seed,
                          "r_tol_pct": self.r_tol_pct, "c_tol_pct": self.c_tol_pct,
                          "sweep": [asdict(p) for p in self.sweep], "time_test": self.time_test.to_dict(),
                          "checks": [{**asdict(c), "ok": c.ok} for c in self.checks],
                          "table_corner": self.table_corner, "tables": [asdict(t) for t in self.tables],
                          "group_delay": gd})


def passband_gain(result) -> float:
    """The passband gain magnitude asked (V/V).

    Parameters
    ----------
    result : FilterDesign
        The design.

    Returns
    -------
    float
        ``spec.gain``.
    """
    return float(result.spec.gain)


def burst_tone(result) -> tuple:
    """The tone burst of a high- or band-pass: its tone, the 1-2-5 value at or above three times the
    cut-off (a high-pass, well inside the passband) or the passband's geometric centre (a band-pass), and
    its cycles, and the window that shows it: the burst and eight of the chosen cascade's slowest time
    constants after it; the bench sheet's time test and the SPICE proof's transient
    (:func:`designer.filters.verify.bench_signal`) are this one burst.

    Parameters
    ----------
    result : designer.filters.FilterDesign
        A high- or band-pass design.

    Returns
    -------
    tuple
        (tone frequency in Hz, cycles, window in s).
    """
    if result.spec.filter_type == "highpass":
        f0 = nice_up(3 * result.fc_hz)
    else:
        f0 = math.sqrt(result.spec.f_low_hz * result.spec.f_high_hz)
    return f0, BURST_CYCLES, BURST_CYCLES / f0 + 8 * _slowest_time_constant(result)


def _slowest_time_constant(result) -> float:
    """The chosen cascade's slowest mode's time constant, 1 / min |Re p| (s)."""
    _, den = result.cascade().coefficients()
    return 1 / float(np.min(np.abs(np.roots(den).real)))


def _drawn_values(result, rng) -> list:
    """Every stage's parts, :data:`BUILDS` builds each, uniform within the tolerances."""
    out = []
    for st in result.stages:
        vals = {}
        for ref, v in st.values.items():
            tol = (R_TOL_PCT if ref.startswith("R") else C_TOL_PCT) / 100
            vals[ref] = v * (1 + rng.uniform(-tol, tol, BUILDS))
        out.append(vals)
    return out


def _response(result, f, values=None) -> np.ndarray:
    """The cascade with the op-amp's model at ``f``: (n_f,) nominal, (n_f, BUILDS) for drawn values."""
    opamp = result.opamp
    s = 2j * math.pi * np.asarray(f, dtype=float)
    if values is None:
        return result.cascade().response(s, opamp)
    s = s[:, None]
    h = np.ones((s.shape[0], BUILDS), dtype=complex)
    for st, vals in zip(result.stages, values):
        h = h * get_topology(st.topology).response(vals, s, opamp)
    return h


def _sweep_frequencies(result, h_db_of) -> list:
    """1-2-5 frequencies within the sweep whose gain is within :data:`FLOOR_DB`, plus the key ones."""
    lo, hi = result.figures["sweep_hz"]
    s = result.spec
    keys = {}
    f3 = result.figures.get("f3_hz")
    for v in (f3 if isinstance(f3, (list, tuple)) else [f3]):
        if v:
            keys[float(v)] = "-3 dB"   # the same in every language
    if s.has_mask:
        keys.update({float(e): N_("passband edge") for e in s.passband_edges})
        keys.update({float(e): N_("stopband edge") for e in s.stopband_edges})
    e_lo, e_hi = math.floor(math.log10(lo)), math.ceil(math.log10(hi))
    grid = [m * 10.0 ** e for e in range(e_lo, e_hi + 1) for m in (1, 2, 5) if lo <= m * 10.0 ** e <= hi]
    ref = 20 * math.log10(passband_gain(result))
    fs = [f for f in grid if h_db_of(f) >= ref - FLOOR_DB and all(abs(math.log(f / k)) > 0.05 for k in keys)]
    return sorted([(f, "") for f in fs] + [(k, note) for k, note in keys.items()])


def _scope(f, amp, out_pk):
    return nice_up(2 / (10 * f)), nice_up(2 * amp / 6), nice_up(max(2 * out_pk / 6, 1e-3))


def _sweep(result, rng):
    amp = float(result.spec.amplitude_v)
    nominal = lambda f: 20 * math.log10(abs(_response(result, [f])[0]))  # noqa: E731
    rows = _sweep_frequencies(result, nominal)
    f = np.array([r[0] for r in rows])
    h = _response(result, f)
    hb = _response(result, f, _drawn_values(result, rng))
    g, gb = 20 * np.log10(np.abs(h)), 20 * np.log10(np.abs(hb))
    ph = np.degrees(np.angle(h))
    # the builds' phase relative to the nominal, wrapped (a build never moves it by half a turn)
    dph = np.degrees(np.angle(hb / h[:, None]))
    out = []
    for i, (fi, note) in enumerate(rows):
        out_pk = amp * abs(h[i])
        t, c1, c2 = _scope(fi, amp, out_pk)
        out.append(SweepPoint(float(fi), float(g[i]), float(ph[i]), float(np.percentile(gb[i], 0.5)),
                              float(np.percentile(gb[i], 99.5)), float(ph[i] + np.percentile(dph[i], 0.5)),
                              float(ph[i] + np.percentile(dph[i], 99.5)), float(out_pk), t, c1, c2, note))
    return out


def _time_test(result) -> TimeTest:
    amp = float(result.spec.amplitude_v)
    num, den = result.cascade().coefficients()
    slow = _slowest_time_constant(result)
    kind = result.spec.filter_type
    if kind == "lowpass":
        t_end = 12 * slow
        t = np.linspace(0, t_end, 6001)
        x = np.full_like(t, amp)
        x[0] = 0.0
        y = filter_foh(num, den, t, x)
        m = step_metrics(t, y, initial=0.0, final=amp * float(num[-1] / den[-1]))
        half = nice_up(max(m.settling_time_s, slow) * 5)
        metrics = {"overshoot_pct": m.overshoot_pct, "rise_time_s": m.rise_time_s,
                   "settling_time_s": m.settling_time_s, "peak_v": float(np.max(np.abs(y))),
                   "final_v": float(y[-1])}
        return TimeTest("step", nice_down(0.5 / half), amp, 0, 0.0, t, x, y, metrics,
                        nice_up(max(m.settling_time_s, m.rise_time_s) * 1.5 / 10),
                        nice_up(max(np.max(np.abs(y)), 1e-3) * 2 / 6))
    f0, cycles, t_end = burst_tone(result)
    t_tone = cycles / f0
    t = np.linspace(0, t_end, 8001)
    x = np.where(t <= t_tone, amp * np.sin(2 * math.pi * f0 * t), 0.0)
    y = filter_foh(num, den, t, x)
    steady = amp * abs(result.cascade().response(2j * math.pi * f0))
    env = np.abs(y)
    within = np.flatnonzero((t <= t_tone) & (env >= 0.98 * steady))
    metrics = {"peak_v": float(np.max(env)), "steady_pk_v": float(steady),
               "settle_s": float(t[within[0]]) if within.size else float("nan")}
    return TimeTest("burst", float(f0), amp, cycles, nice_down(1 / (2 * t_end)), t, x, y, metrics,
                    nice_up(t_end / 10), nice_up(max(float(np.max(env)), 1e-3) * 2 / 6))


def _checks(result) -> list:
    op = result.opamp
    swing = min(op.vout_max, -op.vout_min)
    return [StageCheck(st.number, st.gbw_needed_hz, op.gbw_hz, st.node_peak_v, swing,
                       2 * math.pi * st.plan.fn_hz * st.node_peak_v, op.slew_v_per_s) for st in result.stages]


def _tables(result) -> tuple:
    s = result.spec
    rows = coefficient_table(s.family, result.order, s.ripple_db) if s.filter_type != "bandpass" else []
    corner = 1.0
    if rows:
        from .tables import table_corner
        corner = table_corner(s.family, result.order, s.ripple_db)
    out = []
    for st in result.stages:
        topo = get_topology(st.topology)
        built = topo.figures(st.values)
        match = None
        if rows:
            same = [r for r in rows if r.order == st.plan.order]
            match = min(same, key=lambda r: abs((r.q or 0) - (st.plan.q or 0))) if same else None
        ratio = None
        if s.filter_type in ("lowpass", "highpass"):
            ratio = st.plan.fn_hz / result.fc_hz if s.filter_type == "lowpass" else result.fc_hz / st.plan.fn_hz
        out.append(TableCompare(st.number, match and match.fn_ratio, match and match.q, match and match.k, ratio,
                                st.plan.fn_hz, st.plan.q, st.fn_design_hz or st.plan.fn_hz,
                                st.q_design if st.q_design is not None else st.plan.q, built.fn_hz, built.q))
    return out, corner


def bench_of(result) -> FilterBench:
    """The bench test of ``result`` (see the module docstring).

    Parameters
    ----------
    result : FilterDesign
        The design.

    Returns
    -------
    FilterBench
        Its sweep, time test, stage checks, table comparison and (Bessel) group delay.
    """
    rng = np.random.default_rng(SEED)
    sweep = _sweep(result, rng)
    lo, hi = result.figures["sweep_hz"]
    f = np.logspace(math.log10(lo), math.log10(hi), 160)
    h = _response(result, f)
    hb = _response(result, f, _drawn_values(result, np.random.default_rng(SEED)))
    gb = 20 * np.log10(np.abs(hb))
    gd = None
    if result.spec.family == "bessel":
        ph = np.unwrap(np.angle(h))
        w = 2 * math.pi * f
        gd = (f[:-1], -np.diff(ph) / np.diff(w))
    tables, corner = _tables(result)
    return FilterBench(sweep, _time_test(result), _checks(result), tables, corner, gd,
                       float(result.spec.amplitude_v), f_hz=f, h=h, h_lo_db=np.percentile(gb, 0.5, axis=1),
                       h_hi_db=np.percentile(gb, 99.5, axis=1))
