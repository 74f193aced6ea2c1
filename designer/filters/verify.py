"""The proof of a designed cascade in SPICE: one standalone deck (``ngspice -b``
prints its measurements) with an ``.ac`` sweep (gain and phase at the mask's
frequencies, the -3 dB point, the stopband attenuation) and a ``.tran`` of the
bench test (a step for a low-pass, the bench sheet's tone burst otherwise),
compared with the analytic cascade, ideal and op-amp-aware, by the project's
NRMS rule (:func:`designer.core.compare.nrms`, Xyce's ``xyce_verify``: below 1
passes); the mask checked on SPICE's own ``.ac``; each stage's slew and swing at
the bench amplitude and at its peak, with the catalogue's op-amp that can when
the chosen one cannot.

Sources and rules:

- the analytic transient is each stage's transfer function driven by the one
  before it (the stages do not load each other, :mod:`designer.filters.cascade`),
  ``scipy.signal.lsim`` stage by stage; the op-amp-aware stage's transfer
  function is the rational function of degree (section order + 1) that its
  nodal response (:func:`designer.filters.topology.nodal_response`, one pole per
  op-amp) is, recovered by Sanathanan-Koerner iterations of Levy's linear least
  squares on j w (Levy 1959; Sanathanan & Koerner, IEEE TAC 1963), the fit's own
  worst error reported;
- NRMS of the ``.ac`` magnitude over log f with an absolute tolerance of -60 dB of
  the passband gain (the conformance's floor), of the transient with 1 % of the
  output's step (the plant's rule, :func:`designer.plant.design.run_spice`);
- the burst: ngspice's ``SIN`` source has no cycle count, so the deck gates the
  sine with a behavioural source of time alone in series with the ``.ac`` source
  (``V = time <= T ? A sin(w time) : 0``; its small-signal part is nil, so the
  ``.ac`` is unchanged); the gate closes at a zero crossing (whole cycles), so
  the input stays continuous;
- slew: a sine of amplitude V at f slews at 2 pi f V (its steepest point); the step's
  slope is the analytic transient's derivative; swing: the node's largest excursion.
"""

from __future__ import annotations

import math
import re
from dataclasses import dataclass, field

import numpy as np

from ..core import opamps
from ..core.compare import nrms
from ..core.units import format_eng
from .bench import burst_tone
from .deck import ac_deck
from .prototype import delay_error_pct
from .registry import get as get_topology

__all__ = ["PROOF_POINTS_PER_DECADE", "TRAN_POINTS", "NRMS_PASS", "BenchSignal", "StageDrive", "Proof",
           "mask_edges", "band_edge_db", "bench_signal", "proof_deck", "opamp_aware_polys", "stage_polys", "analytic_tran", "stage_drive",
           "prove", "phase_delay_error_pct"]

#: the proof's ``.ac`` density (points per decade)
PROOF_POINTS_PER_DECADE = 200
#: the analytic transient's uniform grid
TRAN_POINTS = 4000
#: an NRMS below this passes (Xyce's rule)
NRMS_PASS = 1.0
#: the ``.ac`` comparison's absolute floor, relative to the passband gain (-60 dB)
AC_FLOOR = 1e-3
#: the transient comparison's absolute tolerance, relative to the output's step (1 %)
TRAN_ABSTOL = 0.01
#: Sanathanan-Koerner iterations of the op-amp-aware stage fit
SK_ITERATIONS = 4


@dataclass(frozen=True)
class BenchSignal:
    """The transient test: a ``step`` (a low-pass), a ``burst`` of ``cycles`` cycles or a ``sine`` at ``f_hz``,
    ``amplitude_v`` peak.

    Parameters
    ----------
    kind : str
        ``step``, ``burst`` or ``sine``.
    amplitude_v : float
        Step height or sine peak (V).
    f_hz : float or None
        The tone's frequency (None for a step).
    t_stop_s : float
        The transient's length.
    rise_s : float
        The step's edge (a ramp, the same in the deck and the analytic input).
    cycles : int
        The burst's cycles (0 otherwise).
    """

    kind: str
    amplitude_v: float
    f_hz: float | None
    t_stop_s: float
    rise_s: float
    cycles: int = 0

    @property
    def burst_s(self) -> float:
        """The burst's length, ``cycles / f_hz`` (s)."""
        return self.cycles / self.f_hz

    def source(self) -> str:
        """The input source's transient part in SPICE syntax.

        Returns
        -------
        str
            ``PULSE(...)`` or ``SIN(...)``; a burst: the gating behavioural source's ``V = ...`` expression
            (module docstring).
        """
        if self.kind == "step":
            return f"PULSE(0 {self.amplitude_v:.6g} 0 {self.rise_s:.6g} {self.rise_s:.6g} 1e3 2e3)"
        if self.kind == "burst":
            return (f"V = time <= {self.burst_s:.10g} ? {self.amplitude_v:.6g} * "
                    f"sin({2 * math.pi * self.f_hz:.10g} * time) : 0")
        return f"SIN(0 {self.amplitude_v:.6g} {self.f_hz:.6g} 0)"

    def waveform(self, t) -> np.ndarray:
        """The input at times ``t``.

        Parameters
        ----------
        t : ndarray
            Times, s.

        Returns
        -------
        ndarray
            Volts.
        """
        t = np.asarray(t, float)
        if self.kind == "step":
            return self.amplitude_v * np.clip(t / self.rise_s, 0.0, 1.0)
        if self.kind == "burst":
            return np.where(t <= self.burst_s, self.amplitude_v * np.sin(2 * math.pi * self.f_hz * t), 0.0)
        return self.amplitude_v * np.sin(2 * math.pi * self.f_hz * t)

    def to_dict(self) -> dict:
        """The signal as JSON.

        Returns
        -------
        dict
            Its fields (``cycles`` only for a burst).
        """
        out = {"kind": self.kind, "amplitude_v": self.amplitude_v, "f_hz": self.f_hz, "t_stop_s": self.t_stop_s,
               "rise_s": self.rise_s}
        if self.kind == "burst":
            out["cycles"] = self.cycles
        return out


@dataclass
class StageDrive:
    """One stage's output against its op-amp's slew rate and swing.

    Parameters
    ----------
    stage : int
        1-based.
    bench_swing_v, bench_slew_v_per_s : float
        The stage output's largest excursion and slope in the bench transient.
    peak_hz : float
        Where the cascade up to this stage peaks.
    peak_swing_v, peak_slew_v_per_s : float
        A sine of the bench amplitude at ``peak_hz``: the output's peak and its slew (2 pi f V).
    swing_v, slew_v_per_s : float
        The op-amp's swing (the smaller rail headroom) and slew rate.
    ok : bool
        Both within the op-amp's.
    instead : str or None
        The first catalogue op-amp (by GBW) that meets the stage's GBW need, slew and swing, when
        the chosen one does not.
    """

    stage: int
    bench_swing_v: float
    bench_slew_v_per_s: float
    peak_hz: float
    peak_swing_v: float
    peak_slew_v_per_s: float
    swing_v: float
    slew_v_per_s: float
    ok: bool
    instead: str | None = None

    def to_dict(self) -> dict:
        """The check as JSON.

        Returns
        -------
        dict
            Its fields.
        """
        return dict(self.__dict__)

    def text(self) -> str:
        """One line: the stage's slew and swing against the op-amp's.

        Returns
        -------
        str
            The line (what to use instead when the op-amp cannot).
        """
        line = (f"  stage {self.stage}: swing {format_eng(self.bench_swing_v, 'V')} bench, "
                f"{format_eng(self.peak_swing_v, 'V')} at its peak ({format_eng(self.peak_hz, 'Hz')}) of "
                f"+-{format_eng(self.swing_v, 'V')}; slew {format_eng(self.bench_slew_v_per_s, 'V/s')} bench, "
                f"{format_eng(self.peak_slew_v_per_s, 'V/s')} at its peak of {format_eng(self.slew_v_per_s, 'V/s')}")
        if not self.ok:
            line += f": too much; {self.instead or 'no catalogue op-amp can: lower --amplitude or the gain'}"
        return line


@dataclass
class Proof:
    """What the proof found.

    Attributes
    ----------
    signal : BenchSignal
        The transient test.
    measurements : dict
        ngspice's ``meas`` values by name (dB, degrees, Hz, V).
    nrms : dict
        ``ac_ideal``, ``ac_opamp``, ``tran_ideal``, ``tran_opamp``: SPICE against each model.
    fit_error : float
        The op-amp-aware stage fits' worst relative error on their grid.
    mask : dict or None
        The mask checked on SPICE's ``.ac``: ``passband_loss_db``, ``stopband_attenuation_db``, margins, ``met``.
    stages : list of StageDrive
        Slew and swing per stage.
    ac : dict
        ``max_deviation_passband_db``, ``max_deviation_60db_db`` and ``points`` (the earlier check's keys).
    """

    signal: BenchSignal
    measurements: dict
    nrms: dict
    fit_error: float
    mask: dict | None
    stages: list = field(default_factory=list)
    ac: dict = field(default_factory=dict)

    @property
    def passed(self) -> bool:  # noqa: D401
        """SPICE agrees with the op-amp-aware model (NRMS below 1 on both analyses) and meets the mask."""
        agree = self.nrms["ac_opamp"] < NRMS_PASS and self.nrms["tran_opamp"] < NRMS_PASS
        return agree and (self.mask is None or self.mask["met"])

    def to_dict(self) -> dict:
        """The proof as JSON.

        Returns
        -------
        dict
            The earlier check's keys (``max_deviation_*``) and every figure of the proof.
        """
        return {**self.ac, "signal": self.signal.to_dict(), "measurements": self.measurements,
                "nrms": self.nrms, "nrms_pass_below": NRMS_PASS, "fit_error": self.fit_error, "mask": self.mask,
                "stages": [s.to_dict() for s in self.stages], "passed": self.passed}

    def lines(self) -> list:
        """The summary's lines.

        Returns
        -------
        list of str
            NRMS, the mask on SPICE's .ac, each stage's slew and swing.
        """
        n = self.nrms
        out = [f"SPICE proof ({self.signal.kind} test, NRMS below {NRMS_PASS:g} agrees): .ac NRMS "
               f"{n['ac_opamp']:.3g} against the op-amp-aware cascade ({n['ac_ideal']:.3g} ideal), .tran "
               f"{n['tran_opamp']:.3g} ({n['tran_ideal']:.3g} ideal)"]
        if self.mask is not None:
            m = self.mask
            out.append(f"  mask on SPICE's .ac: passband loss {m['passband_loss_db']:.3g} dB (at most "
                       f"{m['max_loss_db']:g}), stopband attenuation {m['stopband_attenuation_db']:.3g} dB (at least "
                       f"{m['min_attenuation_db']:g})"
                       + (f", group delay within {m['delay_error_pct']:.3g} % of DC's (at most "
                          f"{m['max_delay_error_pct']:g} %)" if "delay_error_pct" in m else "")
                       + f": {'met' if m['met'] else 'NOT met'}")
        out += [s.text() for s in self.stages]
        return out


def mask_edges(result) -> tuple:
    """The passband and stopband edges a design is judged at: its mask's, else its own passband
    edge and transition end (a band-pass: a pair of each).

    Parameters
    ----------
    result : designer.filters.FilterDesign
        The design.

    Returns
    -------
    tuple
        (passband edge, stopband edge): Hz, or [low, high] pairs for a band-pass.
    """
    s, f = result.spec, result.figures
    if s.has_mask:
        return s.passband_hz, s.stopband_hz
    return f["passband_edge_hz"], f["transition_end_hz"]


def _edges(result) -> tuple:
    """(passband frequencies, stopband frequencies, sweep) the proof measures at (:func:`mask_edges`, as lists)."""
    as_list = lambda v: list(v) if isinstance(v, (list, tuple)) else [v]  # noqa: E731
    fp, ft = mask_edges(result)
    return as_list(fp), as_list(ft), result.figures["sweep_hz"]


def bench_signal(result) -> BenchSignal:
    """The transient test of ``result``: a step for a low-pass; otherwise the bench sheet's tone burst
    in the sheet's window (:func:`designer.filters.bench.burst_tone`); the bench amplitude.

    Parameters
    ----------
    result : designer.filters.FilterDesign
        The design.

    Returns
    -------
    BenchSignal
        The test.
    """
    s, fc = result.spec, result.fc_hz
    if s.filter_type == "lowpass":
        # the slowest section sets the settling: its time constant Q / (pi fn)
        slow = max((st.plan.q or 0.5) / (math.pi * st.plan.fn_hz) for st in result.stages)
        return BenchSignal("step", s.amplitude_v, None, max(12 * slow, 6 / fc), 1e-3 / fc)
    f, cycles, t_stop = burst_tone(result)
    return BenchSignal("burst", s.amplitude_v, float(f), t_stop, 1e-3 / f, cycles)


def _level_db(result) -> float:
    return 20 * math.log10(result.spec.gain)


def _meas_lines(result) -> list:
    """The control block's ``meas`` lines: gain and phase at the mask's (or design's) edges, the
    passband gain, the -3 dB point(s), the stopband's largest gain, each stage's output extremes."""
    kind = result.spec.filter_type
    fp, ft, (lo, hi) = _edges(result)
    a, b = result.figures["passband_range_hz"]
    at = {"lowpass": a, "highpass": b, "bandpass": result.fc_hz}[kind]
    level = _level_db(result) - 10 * math.log10(2)
    crossings = {"lowpass": [("f3db_hz", "last")], "highpass": [("f3db_hz", "1")],
                 "bandpass": [("f3db_low_hz", "1"), ("f3db_high_hz", "last")]}[kind]
    out = [f"meas ac passband_db find vdb(vout) at={at:.6g}",
           *(f"meas ac {name} when vdb(vout)={level:.6g} cross={cross}" for name, cross in crossings)]
    # the phase from the real and imaginary parts: vp() wraps at +-180 degrees, where `find` would
    # interpolate across the jump
    for name, freqs in (("pass", fp), ("stop", ft)):
        for i, f in enumerate(freqs, 1):
            out += [f"meas ac {name}{i}_db find vdb(vout) at={f:.6g}", f"meas ac {name}{i}_re find vr(vout) at={f:.6g}",
                    f"meas ac {name}{i}_im find vi(vout) at={f:.6g}"]
    # the stopband's largest gain: beyond the stopband edge (a band-pass: below the lower, above the upper)
    if kind == "lowpass":
        spans = [(ft[0], hi)]
    elif kind == "highpass":
        spans = [(lo, ft[0])]
    else:
        spans = [(lo, ft[0]), (ft[-1], hi)]
    out += [f"meas ac stopmax{i}_db max vdb(vout) from={x:.6g} to={y:.6g}" for i, (x, y) in enumerate(spans, 1)]
    return out


def _tran_meas_lines(result) -> list:
    nodes = [f"s{i}" for i in range(1, len(result.stages))] + ["vout"]
    return [f"meas tran {n}_{w}_v {w} v({n})" for n in nodes for w in ("max", "min")]


def _circuit(result, signal: BenchSignal) -> str:
    """The cascade's deck without analyses (:func:`designer.filters.deck.ac_deck`'s), the input
    source driving both the ``.ac`` (1 V) and the ``.tran`` (the bench signal)."""
    lo, hi = result.figures["sweep_hz"]
    text = ac_deck(result.cascade().netlist(), result.opamp, lo, hi,
                   title=f"{result.spec.family} {result.spec.filter_type} order {result.order}",
                   points_per_decade=PROOF_POINTS_PER_DECADE)
    lines = [ln for ln in text.rstrip().splitlines() if not ln.startswith(".ac ") and ln.strip().lower() != ".end"]
    src = re.compile(r"^(Vin\s+(\S+)\s+(\S+)\s+DC 0 AC 1)\s*$", re.I)

    def sub(m):
        if signal.kind != "burst":
            return f"{m.group(1)} {signal.source()}"
        # the .ac source below the gated burst (module docstring): a B-source of time alone adds nothing to .ac
        node, ref = m.group(2), m.group(3)
        return f"Vin {node}_ac {ref} DC 0 AC 1\nBburst {node} {node}_ac {signal.source()}"

    lines = [src.sub(sub, ln) for ln in lines]
    return "\n".join(lines) + "\n"


def _analyses(result, signal: BenchSignal) -> tuple:
    lo, hi = result.figures["sweep_hz"]
    step = signal.t_stop_s / TRAN_POINTS
    return (f"ac dec {PROOF_POINTS_PER_DECADE} {lo:.6g} {hi:.6g}",
            f"tran {step:.6g} {signal.t_stop_s:.6g} 0 {step:.6g}")


def proof_deck(result) -> str:
    """The standalone proof deck: ``ngspice -b`` runs the ``.ac`` sweep and the bench ``.tran``
    and prints every measurement (:func:`prove` lists them).

    Parameters
    ----------
    result : designer.filters.FilterDesign
        The design.

    Returns
    -------
    str
        The deck's text.
    """
    signal = bench_signal(result)
    ac, tran = _analyses(result, signal)
    # the analyses and their measurements in a .control block: ngspice's batch-mode .meas cannot parse vdb()
    # (no vector is saved for it), and `quit 0` ends a batch run without dot analyses with status 0
    control = [".control", ac, *_meas_lines(result), tran, *_tran_meas_lines(result), "quit 0", ".endc", ".end"]
    return _circuit(result, signal) + "\n".join(control) + "\n"


def opamp_aware_polys(topology, values: dict, opamp) -> tuple:
    """The op-amp-aware section's transfer function as polynomials (num, den) in s, highest power
    first, of degree order + 1 (one op-amp pole): Sanathanan-Koerner iterations of Levy's fit on
    j w from fn/100 to 30 GBW (at least 100 fn) (module docstring).

    Parameters
    ----------
    topology : Topology
        The section.
    values : dict
        Its part values (numbers).
    opamp : designer.core.opamps.OpAmp
        The op-amp (A0, GBW).

    Returns
    -------
    tuple
        (num, den, worst relative error of the fit on its grid).
    """
    wn = 2 * math.pi * float(topology.figures(values).fn_hz)
    m = topology.order + 1
    top = max(1e2, 30 * opamp.gbw_hz * 2 * math.pi / wn)
    x = 1j * np.geomspace(1e-2, top, 400)
    h = topology.response(values, x * wn, opamp)
    powers = x[:, None] ** np.arange(m + 1)[None, :]
    weight = np.ones(x.size)
    for _ in range(SK_ITERATIONS):
        # N(x) - H(x) (1 + d1 x + ... + dm x^m) = 0, each row over the previous denominator's size
        a = np.hstack([powers, -h[:, None] * powers[:, 1:]]) / weight[:, None]
        rhs = h / weight
        a_r = np.vstack([a.real, a.imag])
        r_r = np.concatenate([rhs.real, rhs.imag])
        scale = np.linalg.norm(a_r, axis=0)
        scale[scale == 0] = 1.0
        coef = np.linalg.lstsq(a_r / scale, r_r, rcond=None)[0] / scale
        num, den = coef[:m + 1], np.concatenate([[1.0], coef[m + 1:]])
        weight = np.abs(powers @ den)
    fit = (powers @ num) / (powers @ den)
    # the error against the section's largest gain: far above GBW the response is tiny
    err = float(np.max(np.abs(fit - h)) / np.max(np.abs(h)))
    k = np.arange(m + 1)
    return (num / wn ** k)[::-1], (den / wn ** k)[::-1], err


def stage_polys(result, opamp=None) -> tuple:
    """Each chosen stage's (num, den): ideal (``opamp`` None) or op-amp-aware
    (:func:`opamp_aware_polys`); and the fits' worst error (0 for the ideal).

    Parameters
    ----------
    result : designer.filters.FilterDesign
        The design.
    opamp : designer.core.opamps.OpAmp, optional
        The op-amp; None for the ideal sections.

    Returns
    -------
    tuple
        (list of (num, den), worst fit error).
    """
    polys, worst = [], 0.0
    for st in result.stages:
        topo = get_topology(st.topology)
        if opamp is None or opamp.ideal:
            num, den = topo.coefficients(st.values)
            polys.append((np.asarray(num, float), np.asarray(den, float)))
        else:
            num, den, err = opamp_aware_polys(topo, st.values, opamp)
            polys.append((num, den))
            worst = max(worst, err)
    return polys, worst


def analytic_tran(polys: list, t, x) -> list:
    """Every stage's output for the input ``x`` on the uniform grid ``t``: each stage driven by
    the one before it, zero initial state (the bilinear transform by ``scipy.signal.bilinear`` on the
    polynomials, then ``lfilter``).

    Parameters
    ----------
    polys : list of (num, den)
        The stages' transfer functions, input first.
    t, x : ndarray
        Uniform times (s) and the input (V).

    Returns
    -------
    list of ndarray
        Each stage's output, in order.
    """
    from scipy import signal as sig
    out, y = [], np.asarray(x, float)
    dt = float(t[1] - t[0])
    for num, den in polys:
        num = _trim(np.asarray(num, float), np.asarray(den, float))
        # the bilinear (Tustin) discretisation, run by lfilter in C rather than lsim's Python loop over the
        # samples: its error is about (w dt)^2 / 12 of the response, 2e-5 at 400 points per period of fc
        numd, dend = sig.bilinear(num, den, fs=1.0 / dt)
        y = sig.lfilter(numd, dend, y)
        out.append(y)
    return out


def _trim(num: np.ndarray, den: np.ndarray) -> np.ndarray:
    """``num`` without the leading coefficients that are rounding (below 1e-12 of its largest at the
    natural frequency's scale): scipy refuses an improper-looking numerator."""
    wn = abs(den[-1] / den[0]) ** (1 / (den.size - 1)) if den.size > 1 and den[0] and den[-1] else 1.0
    k = np.arange(num.size)[::-1]
    size = np.abs(num) * wn ** k
    keep = np.flatnonzero(size > 1e-12 * np.max(size)) if np.any(size) else np.array([num.size - 1])
    return num[keep[0]:]


def _swing(opamp) -> float:
    return min(opamp.vout_max, -opamp.vout_min)


def _instead(need_gbw: float, swing_v: float, slew: float) -> str | None:
    ok = [o for o in sorted((opamps.get(n) for n in opamps.names() if n != "ideal"), key=lambda o: o.gbw_hz)
          if o.gbw_hz >= need_gbw and o.slew_v_per_s >= slew and _swing(o) >= swing_v]
    return f"use {ok[0].name} (GBW {format_eng(ok[0].gbw_hz, 'Hz')}, slew {format_eng(ok[0].slew_v_per_s, 'V/s')}, " \
           f"swing +-{format_eng(_swing(ok[0]), 'V')})" if ok else None


def stage_drive(result, signal: BenchSignal, t, outputs: list) -> list:
    """Each stage's slew and swing (:class:`StageDrive`): in the bench transient (``outputs``, the
    analytic op-amp-aware stage outputs on ``t``) and for a sine of the bench amplitude at the
    frequency where the cascade up to the stage peaks (op-amp-aware).

    Parameters
    ----------
    result : designer.filters.FilterDesign
        The design.
    signal : BenchSignal
        The bench test.
    t : ndarray
        The transient's times.
    outputs : list of ndarray
        Each stage's output.

    Returns
    -------
    list of StageDrive
        In stage order.
    """
    op = result.opamp
    f = np.geomspace(result.fc_hz / 1000, result.fc_hz * 1000, 3001)
    s = 2j * math.pi * f
    h = np.ones(f.size, complex)
    out = []
    for st, y in zip(result.stages, outputs):
        h = h * get_topology(st.topology).response(st.values, s, None if op.ideal else op)
        k = int(np.argmax(np.abs(h)))
        peak_v = signal.amplitude_v * float(np.abs(h[k]))
        peak_slew = 2 * math.pi * float(f[k]) * peak_v
        bench_v = float(np.max(np.abs(y)))
        bench_slew = float(np.max(np.abs(np.gradient(y, t))))
        swing, slew = (math.inf, math.inf) if op.ideal else (_swing(op), op.slew_v_per_s)
        ok = max(bench_v, peak_v) <= swing and max(bench_slew, peak_slew) <= slew
        instead = None if ok else _instead(st.gbw_needed_hz, max(bench_v, peak_v), max(bench_slew, peak_slew))
        out.append(StageDrive(st.number, bench_v, bench_slew, float(f[k]), peak_v, peak_slew, swing, slew, ok,
                              instead))
    return out


def band_edge_db(f, db, edges) -> np.ndarray:
    """A band-pass's gain at its mask's edges from a sweep: a cubic in log f through the sweep's points
    (scipy's ``CubicSpline``), not the chord, which overstates the loss where a narrow band's edges
    curve fastest (0.04 dB at a 900 Hz to 1.1 kHz band's edge at 200 points a decade).

    Parameters
    ----------
    f : ndarray
        The sweep's frequencies, Hz, rising.
    db : ndarray
        Its gain, dB.
    edges : sequence of float
        The edges, Hz.

    Returns
    -------
    ndarray
        The gain at each edge, dB.
    """
    from scipy.interpolate import CubicSpline
    return CubicSpline(np.log(f), db)(np.log(np.asarray(edges, float)))


def _spice_mask(result, f, db, h=None) -> dict | None:
    """The mask on SPICE's ``.ac`` (dB, relative to the passband gain): the largest loss over the
    passband and the least attenuation over the stopband (a decade beyond each edge, as the design's grid);
    with a group-delay target, the delay's largest departure from its value at the sweep's start (two
    decades or more below the cut-off: DC's within 1e-4 relative for a Bessel), from the phase of ``h``
    between neighbouring points (tau = -d phi / d w at their midpoints), up to the target's frequency."""
    s = result.spec
    if not s.has_mask:
        return None
    rel = db - _level_db(result)
    up, down = 1 + 1e-9, 1 - 1e-9
    if s.filter_type == "bandpass":
        (p1, p2), (s1, s2) = s.passband_edges, s.stopband_edges
        in_pass = (f >= p1 * down) & (f <= p2 * up)
        in_stop = (f <= s1 * up) | (f >= s2 * down)
    elif s.filter_type == "lowpass":
        in_pass = (f >= s.passband_hz / 10) & (f <= s.passband_hz * up)
        in_stop = f >= s.stopband_hz * down
    else:
        in_pass = (f >= s.passband_hz * down) & (f <= s.passband_hz * 10)
        in_stop = f <= s.stopband_hz * up
    at = lambda edges: np.interp(np.log(edges), np.log(f), rel) if s.filter_type != "bandpass" else \
        band_edge_db(f, rel, edges)  # noqa: E731  (the edges themselves)
    loss = float(np.max(np.concatenate([-rel[in_pass], -at(s.passband_edges)])))
    att = float(np.min(np.concatenate([-rel[in_stop], -at(s.stopband_edges)])))
    out = {"passband_loss_db": loss, "max_loss_db": s.max_loss_db, "passband_margin_db": s.max_loss_db - loss,
           "stopband_attenuation_db": att, "min_attenuation_db": s.min_attenuation_db,
           "stopband_margin_db": att - s.min_attenuation_db,
           "met": loss <= s.max_loss_db and att >= s.min_attenuation_db}
    if s.has_delay_target and h is not None:
        err = phase_delay_error_pct(f, h, s.delay_to_hz)
        out.update({"delay_error_pct": err, "max_delay_error_pct": s.max_delay_error_pct,
                    "met": out["met"] and err <= s.max_delay_error_pct})
    return out


def phase_delay_error_pct(f, h, to_hz: float) -> float:
    """The group delay's largest departure from its value at a sweep's start, % of it, up to ``to_hz``: tau =
    -d phi / d w between neighbouring points (at their midpoints), the start two decades or more below the
    cut-off standing for DC (a Bessel's delay there is DC's within 1e-4 relative).

    Parameters
    ----------
    f : ndarray
        The sweep's frequencies (Hz, rising), such as SPICE's ``.ac``.
    h : ndarray
        The complex response at ``f``.
    to_hz : float
        The target's frequency.

    Returns
    -------
    float
        The delay error, %.
    """
    w, ph = 2 * math.pi * np.asarray(f, float), np.unwrap(np.angle(h))
    tau, mid = -np.diff(ph) / np.diff(w), np.sqrt(f[1:] * f[:-1])
    return delay_error_pct(tau[mid <= to_hz], tau[0])


def prove(result, simulator: str = "ngspice-cli") -> Proof:
    """Run the proof deck's analyses in ngspice and compare them with the analytic cascade.

    Parameters
    ----------
    result : designer.filters.FilterDesign
        The design.
    simulator : str
        ``ngspice-cli`` or ``pyspice`` (:func:`designer.spice.simulate.get_simulator`).

    Returns
    -------
    Proof
        Measurements, NRMS against the ideal and op-amp-aware models, the mask on SPICE's ``.ac``,
        slew and swing per stage.

    Raises
    ------
    SimulatorError
        ngspice failed.
    """
    import tempfile
    from pathlib import Path

    from ..core import lifetime
    from ..spice.simulate import get_simulator, parse_measurements, read_raw

    signal = bench_signal(result)
    ac, tran = _analyses(result, signal)
    meas = _meas_lines(result) + _tran_meas_lines(result)
    nodes = [f"s{i}" for i in range(1, len(result.stages))] + ["vout"]
    with tempfile.TemporaryDirectory(prefix=lifetime.owned_prefix("proof")) as tmp:
        ac_raw, tran_raw = Path(tmp) / "ac.raw", Path(tmp) / "tran.raw"
        commands = ["set filetype=binary", ac, *_meas_lines(result), f"write {ac_raw} v(vout)", tran,
                    *_tran_meas_lines(result), f"write {tran_raw} " + " ".join(f"v({n})" for n in nodes)]
        text = get_simulator(simulator).run_script(_circuit(result, signal), commands)
        ac_v, tran_v = read_raw(ac_raw), read_raw(tran_raw)
    names = "\n".join(f".meas x {ln.split()[2]}" for ln in meas)
    measured = parse_measurements(text, names)
    for k in [k for k in measured if k.endswith("_re")]:
        im = measured.pop(k[:-3] + "_im", math.nan)
        measured[k[:-3] + "_deg"] = math.degrees(math.atan2(im, measured.pop(k)))
    f = np.real(ac_v["frequency"])
    h = np.asarray(_vector(ac_v, "vout"), complex)
    chosen, op = result.cascade(), result.opamp
    s = 2j * math.pi * f
    gain = result.spec.gain
    logf = np.log10(f)
    an_ideal, an_op = chosen.response(s), chosen.response(s, op)
    n_ac = {"ac_ideal": nrms(np.abs(an_ideal), np.abs(h), AC_FLOOR * gain, t=logf),
            "ac_opamp": nrms(np.abs(an_op), np.abs(h), AC_FLOOR * gain, t=logf)}
    # the earlier check's figures, on the same sweep
    dev = np.abs(20 * np.log10(np.abs(h)) - 20 * np.log10(np.abs(an_op)))
    a, b = result.figures["passband_range_hz"]
    in_pb = (f >= a * (1 - 1e-9)) & (f <= b * (1 + 1e-9))
    within = 20 * np.log10(np.abs(an_op)) >= 20 * math.log10(gain) - 60
    ac_figs = {"simulator": simulator, "points": int(f.size), "max_deviation_passband_db": float(np.max(dev[in_pb])),
               "max_deviation_60db_db": float(np.max(dev[within]))}
    # the transient, analytic on a uniform grid, compared on SPICE's own time points
    t = np.linspace(0.0, signal.t_stop_s, TRAN_POINTS + 1)
    x = signal.waveform(t)
    ideal_polys, _ = stage_polys(result)
    aware_polys, fit_err = stage_polys(result, op)
    y_ideal = analytic_tran(ideal_polys, t, x)
    y_aware = analytic_tran(aware_polys, t, x)
    ts = np.real(tran_v["time"])
    keep = np.concatenate([[True], np.diff(ts) > 0])
    ts, ys = ts[keep], np.real(_vector(tran_v, "vout"))[keep]
    abstol = TRAN_ABSTOL * gain * signal.amplitude_v
    n_tr = {"tran_ideal": nrms(y_ideal[-1], ys, abstol, t=ts, t_gold=t),
            "tran_opamp": nrms(y_aware[-1], ys, abstol, t=ts, t_gold=t)}
    proof = Proof(signal, measured, {**n_ac, **n_tr}, fit_err, _spice_mask(result, f, 20 * np.log10(np.abs(h)), h),
                  stage_drive(result, signal, t, y_aware), ac_figs)
    return proof


def _vector(vectors: dict, node: str):
    for key in (f"v({node})", node):
        if key in vectors:
            return vectors[key]
    raise KeyError(node)
