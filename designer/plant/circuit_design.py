"""``design-plant --topology NAME``: the plant's target realised by any registered
section (:mod:`designer.filters`), through the one :class:`~designer.filters.topology.Topology`
interface: the E-series search (:func:`designer.plant.circuit.search`; with R and C
given, the seed's procedure: the section's exact design from them rounded jointly,
:func:`designer.plant.circuit.rounded`), the figures
(fn, zeta, Q, gain, -3 dB, the op-amp-aware dominant pair, the step), the
sensitivities over the declared parts, the deck, BOM and wiring from the topology's
netlist (:func:`designer.spice.deck.board`), and the ngspice ``.ac`` of that deck
against the op-amp-aware model (the conformance's rule: 0.05 dB and 0.5 degrees over
fn / 30 .. 30 fn), and the Sallen-Key plant's bench (:func:`with_bench`: the tolerance band,
the sine check, the scope settings, :mod:`designer.plant.bench`). The seed's Sallen-Key low-pass
(:mod:`designer.plant.design`) chooses its parts through the same search entry (the section's fast path,
:meth:`~designer.filters.topology.Topology.fast_search`), listing (:func:`designer.plant.circuit.listed`) and
``--compensate-gbw`` (:func:`designer.plant.circuit.compensate_gbw`): ``--topology sallen-key-lowpass`` builds
the same parts; and computes its analysis here (:func:`section_analysis`: the figures, with the ideal pair
by :meth:`~designer.filters.topology.Topology.ideal_pair`, the steps over :func:`step_span`, the
sensitivities, the bench), its result byte for byte what it was.

The op-amp's reach: a section needs GBW >= :data:`GBW_MARGIN` x fn x Q x noise gain
(the noise gain 1 + |G| of an inverting section, G of a non-inverting one): the rule of
``design-filter`` (:mod:`designer.filters.design`, whose default margin is 100 for a
filter's passband accuracy) with a tenth of its margin, since a plant's figures are
reported with the op-amp's effect (the op-amp-aware model) rather than hidden by it.
"""

from __future__ import annotations

import dataclasses
import math
import time
from dataclasses import dataclass, field

import numpy as np

from ..core import opamps
from ..core.checks import SPICE_AGREEMENT, Check
from ..core.errors import DesignError
from ..core.i18n import N_, Message
from ..core.jsonio import json_safe
from ..core.lti import dense_time, response_span, slowest_settling_s, step_response
from ..core.metrics import step_metrics
from ..core.eseries import series_name
from ..core.ranges import parse_in_range
from ..core.units import format_eng
from ..filters import registry
from ..filters.deck import ac_deck, simulate_ac
from ..filters.topology import SectionTarget
from ..spice.deck import SINE_POINTS_PER_DECADE
from ..spice.simulate import tool_info
from . import circuit
from .sourcing import MAX_ERROR, candidates, part_series
from .result import METRICS, PLANT_SCHEMA_VERSION, Sourcing, Target

__all__ = ["GBW_MARGIN", "SPICE_DB", "SPICE_DEG", "CircuitAnalysisSpec", "CircuitPlantResult", "design_circuit_plant",
           "check_opamp_reach", "analyze_circuit_plant", "analyze_circuit_spec", "check_circuit_parts",
           "tolerance_nominal", "built_name", "SQUARE_NRMS_PASS", "SquareRun", "square_deck", "with_square_test",
           "default_square_hz", "with_bench", "section_analysis", "step_span"]

#: the op-amp's gain-bandwidth a section needs, in units of fn x Q x noise gain
GBW_MARGIN = 10.0
#: SPICE's .ac against the op-amp-aware model: the largest gain (dB) and phase (degrees) difference allowed
SPICE_DB, SPICE_DEG = 0.05, 0.5


@dataclass(eq=False)
class CircuitPlantResult:
    """A plant designed on a registered topology; :meth:`to_dict` is its JSON.

    Parameters
    ----------
    topology : str
        The registry's name.
    mode : str
        ``design`` (searched) or ``analyze`` (parts as built).
    target : Target
        fn, zeta (None: first order) and gain asked for.
    values : dict
        The build: designator -> E-series value.
    ideal : dict or None
        The continuous synthesis at the build's reference capacitor (None: parts as built).
    alternatives : list of designer.plant.circuit.Candidate
        The best combinations, best first (the build first).
    sourcing : Sourcing
        Each part's series and tolerance.
    opamp : designer.core.opamps.OpAmp
        The op-amp.
    figures : dict
        ``ideal`` and ``opamp``: fn_hz, zeta, q, gain, f3db_hz, their errors.
    steps : dict
        ``ideal`` and ``opamp`` unit-step metrics (None for a high- or band-pass: the step settles to 0).
    sensitivity : dict
        ``ideal`` and ``opamp``: designator -> {"wn", "zeta"}.
    netlist : designer.spice.deck.Netlist
        The section as built.
    deck : str
        The standalone ngspice ``.ac`` deck.
    checks : list of Check
        The verdicts (the SPICE agreement when simulated).
    notes : list of str
        What the user should know.
    spice : dict or None
        ``max_db``, ``max_deg`` of SPICE against the op-amp-aware model, the simulator.
    package : str or None
        The op-amp package of the wiring.
    square : SquareRun or None
        The square-wave bench test in ngspice against the op-amp-aware model (``--square-freq``).
    monte_carlo, worst_case : object or None
        The tolerance analyses, when asked for.
    amplitude_v : float
        The bench's high level (V): the square wave's and the PRBS's.
    prbs : designer.plant.prbs.PrbsRun or None
        The PRBS bench test (``--stimulus prbs``, :func:`designer.plant.circuit_prbs.with_section_prbs`).
    test : designer.spice.deck.SquareTest or None
        The bench's square wave (the square-wave test's, else the one recommended: :func:`with_bench`).
    tolerance : designer.plant.bench.ToleranceBand or None
        The readings' band over the parts' tolerance corners (:func:`designer.plant.bench.tolerance_band`).
    sine : designer.plant.bench.SineCheck or None
        The sine check of the op-amp-aware model (and of SPICE's ``.ac`` when simulated).
    scope : designer.plant.bench.ScopeSetup or None
        The scope as set for the square wave.
    step_metrics : dict
        ``ideal`` and ``opamp``: the :class:`~designer.core.metrics.StepMetrics` of :attr:`steps` (a low-pass's).
    models : dict
        ``ideal`` and ``opamp``: the (num, den) the steps and the bench are computed from (leading zeros of num
        trimmed).
    rising : tuple or None
        (t, y): the op-amp-aware unit step over the bench's rising half period (at most 4 spans), the grid the
        slew and swing checks read (:func:`designer.plant.bench.rising_step`; set with the bench).
    """

    topology: str
    mode: str
    target: Target
    values: dict
    ideal: dict
    alternatives: list
    sourcing: Sourcing
    opamp: object
    figures: dict
    steps: dict
    sensitivity: dict
    netlist: object
    deck: str
    checks: list
    notes: list
    spice: dict | None = None
    package: str | None = None
    square: object = None
    monte_carlo: object = None
    worst_case: object = None
    amplitude_v: float = 2.0
    prbs: object = None
    test: object = None
    tolerance: object = None
    sine: object = None
    scope: object = None
    files: dict = field(default_factory=dict)
    timings: dict = field(default_factory=dict)
    step_metrics: dict = field(default_factory=dict)
    models: dict = field(default_factory=dict)
    rising: tuple | None = None

    @property
    def section(self):
        """The registered :class:`~designer.filters.topology.Topology`."""
        return registry.get(self.topology)

    def verdicts(self) -> list:
        """Every pass/fail verdict (``--fail-on-check``).

        Returns
        -------
        list of Check
            The checks.
        """
        return list(self.checks)

    def to_dict(self) -> dict:
        """The JSON form (``result.json``, ``--json``).

        Returns
        -------
        dict
            JSON-safe.
        """
        topo = self.section
        parts = {p.ref: {"kind": p.kind, "role": p.role, "value": self.values[p.ref],
                         **self.sourcing.parts[p.ref].to_dict()} for p in topo.parts}
        return json_safe({
            "schema_version": PLANT_SCHEMA_VERSION,
            "tool": tool_info(None if self.spice is None else self.spice["simulator"]),
            "mode": self.mode,
            "topology": self.topology,
            "topology_title": topo.title,
            "spec": self.target.to_dict(),
            "parts": parts,
            "ideal": self.ideal,
            "built": self.figures,
            "series": self.sourcing.to_dict(),
            "alternatives": [{**c.values, "fn_hz": c.fn_hz, "zeta": c.zeta, "gain": c.gain,
                              "worst_error_pct": 100 * c.worst} for c in self.alternatives],
            "opamp": self.opamp.to_dict(), "package": self.opamp.package(self.package).to_dict(),
            "analytic": self.steps["ideal"],
            "analytic_opamp": self.steps["opamp"],
            "sensitivity": self.sensitivity,
            "checks": [c.to_dict() for c in self.checks],
            "notes": self.notes,
            "spice": self.spice,
            **({} if self.square is None else {"square_test": self.square.to_dict()}),
            "monte_carlo": None if self.monte_carlo is None else self.monte_carlo.to_dict(),
            "worst_case": None if self.worst_case is None else self.worst_case.to_dict(),
            # the bench (the Sallen-Key plant's): the square wave, the tolerance band, the scope, the sine check
            **({} if self.tolerance is None else {
                "test_signal": self.test.to_dict(), "tolerance_band": self.tolerance.to_dict(),
                "scope": None if self.scope is None else self.scope.to_dict(),
                "sine_check": None if self.sine is None else self.sine.to_dict()}),
            # only with --stimulus prbs, before files (the Sallen-Key plant's JSON's place)
            **({} if self.prbs is None else {"prbs": self.prbs.to_dict()}),
            "files": self.files,
        })


def check_opamp_reach(topology, target: SectionTarget, amp) -> None:
    """Refuse a section beyond the op-amp's gain-bandwidth (the module docstring's rule).

    Parameters
    ----------
    topology : Topology
        The section.
    target : SectionTarget
        Its target.
    amp : designer.core.opamps.OpAmp
        The op-amp (the ideal one is never refused).

    Raises
    ------
    DesignError
        One line: the GBW needed, the op-amp's, and a catalogue op-amp fast enough.
    """
    if amp.ideal:
        return
    noise_gain = 1.0 + target.gain if topology.inverting else target.gain
    need = GBW_MARGIN * target.fn_hz * (target.q or 1.0) * noise_gain
    if need <= amp.gbw_hz:
        return
    ok = opamps.fast_enough(need)
    instead = f"use --opamp {ok.name} ({format_eng(ok.gbw_hz, 'Hz')})" if ok else \
        "no catalogue op-amp is fast enough: lower fc, Q or the gain"
    q = f" x Q {target.q:.3g}" if target.q else ""
    raise DesignError(f"opamp: {amp.name} (GBW {format_eng(amp.gbw_hz, 'Hz')}) is too slow for {topology.name} at fn "
                      f"{format_eng(target.fn_hz, 'Hz')}: it needs GBW >= {GBW_MARGIN:g} x fn{q} x noise gain "
                      f"{noise_gain:.3g} = {format_eng(need, 'Hz')}; {instead}", param="opamp")


def _figures(topo, values: dict, amp, target: Target) -> dict:
    """The ideal and op-amp-aware figures of the build, with their errors against the target."""
    arrays = circuit.circuit_figures(topo, values)
    # the ideal pair by the section's closed form where it has one (Topology.ideal_pair: the Sallen-Key
    # low-pass's is its parts record's, bit for bit); the op-amp-aware pair that of the model the steps are
    # computed from, the ideal op-amp's too (its A0 and GBW: the deck's)
    fn_i, z_i = topo.ideal_pair(values)
    fn_o, z_o = (float(x) for x in circuit.dominant_pairs(circuit.opamp_tf(topo, values, amp)[1], topo.order == 1))
    ideal = {"fn_hz": fn_i, "zeta": z_i, "q": 1 / (2 * z_i), "gain": float(arrays["gain"]),
             "f3db_hz": circuit.corner_frequencies(topo, values)}
    opa = {"fn_hz": fn_o, "zeta": z_o, "q": 1 / (2 * z_o) if z_o else math.inf,
           "f3db_hz": circuit.corner_frequencies(topo, values, amp)}
    for f in (ideal, opa):
        f["fn_error_pct"] = None if target.fc_hz is None else 100 * (f["fn_hz"] / target.fc_hz - 1)
        f["zeta_error_pct"] = None if target.zeta is None else 100 * (f["zeta"] / target.zeta - 1)
        if topo.order == 1:
            f["zeta"] = f["q"] = None
    ideal["gain_error_pct"] = None if target.gain is None else 100 * (ideal["gain"] / target.gain - 1)
    return {"ideal": ideal, "opamp": opa}


def step_span(figures: dict) -> float:
    """The time a build's step is read over: :func:`designer.core.lti.response_span` of the slower of the
    ideal and op-amp-aware pairs, at the lighter damping (a first-order section's taken as 1).

    Parameters
    ----------
    figures : dict
        ``ideal`` and ``opamp`` figures (:attr:`CircuitPlantResult.figures`).

    Returns
    -------
    float
        The span (s).
    """
    fig_i, fig_o = figures["ideal"], figures["opamp"]
    return response_span(min(fig_i["fn_hz"], fig_o["fn_hz"]), min(fig_i["zeta"] or 1.0, fig_o["zeta"] or 1.0))


def _models(topo, values: dict, amp) -> dict:
    """The ideal and op-amp-aware (num, den), num's leading zeros trimmed (scipy warns of them)."""
    out = {}
    for key, (num, den) in (("ideal", topo.coefficients(values)), ("opamp", circuit.opamp_tf(topo, values, amp))):
        num, den = np.asarray(num, float), np.asarray(den, float)
        out[key] = (np.trim_zeros(num, "f") if np.any(num) else num, den)
    return out


def _steps(topo, models: dict, figures: dict) -> dict:
    """Unit-step metrics of both models (a low-pass's; None for a step that settles to 0)."""
    if topo.kind != "lowpass":
        return {"ideal": None, "opamp": None}
    t = dense_time(step_span(figures))
    return {key: step_metrics(t, step_response(num, den, t), final=float(num[-1] / den[-1]))
            for key, (num, den) in models.items()}


def _spice(netlist, amp, fn_hz: float, topo, values: dict, simulator: str) -> tuple:
    """ngspice's .ac of the build against the op-amp-aware model: (summary, Check)."""
    f, h = simulate_ac(netlist, amp, fn_hz / 30, fn_hz * 30, simulator=simulator)
    model = topo.response(values, 2j * np.pi * f, amp)
    ratio = h / model
    db = float(np.max(np.abs(20 * np.log10(np.abs(ratio)))))
    deg = float(np.max(np.abs(np.degrees(np.angle(ratio)))))
    ok = db <= SPICE_DB and deg <= SPICE_DEG
    check = Check.of(SPICE_AGREEMENT, ok, N_("SPICE .ac against the op-amp-aware model, fn/30 .. 30 fn: {db} dB, "
                                            "{deg} deg (allowed {db_max} dB, {deg_max} deg)"),
                     db=f"{db:.3g}", deg=f"{deg:.3g}", db_max=f"{SPICE_DB:g}", deg_max=f"{SPICE_DEG:g}")
    return {"simulator": simulator, "max_db": db, "max_deg": deg, "pass": ok}, check


def design_circuit_plant(spec, simulate: bool = True, simulator: str = "ngspice-cli") -> CircuitPlantResult:
    """Design, analyse and (unless ``simulate`` is False) verify a plant on ``spec.topology``.

    Parameters
    ----------
    spec : designer.plant.spec.PlantSpec
        The request (its ``topology`` any registered one; with ``r`` and ``c`` the seed's procedure:
        the section's :meth:`~designer.filters.topology.Topology.synthesize_rc` design, rounded jointly
        to the series by :func:`designer.plant.circuit.rounded`, as the seed's plant rounds its own).
    simulate : bool
        Run ngspice's .ac of the deck.
    simulator : str
        :func:`designer.spice.simulate.get_simulator`'s name.

    Returns
    -------
    CircuitPlantResult
        The typed result.

    Raises
    ------
    DesignError
        A target the topology cannot realise, the op-amp too slow, no parts close enough (one line each).
    """
    tick = time.perf_counter()
    topo = registry.get(spec.topology)
    amp = spec.amp
    target = Target(spec.fc_hz, spec.zeta, spec.gain)
    section = circuit.plant_target(topo, spec.fc_hz, spec.zeta, spec.gain)
    check_opamp_reach(topo, section, amp)
    rv = candidates(spec.r_series, spec.r_min, spec.r_max, "resistor")
    cv = candidates(spec.c_series, spec.c_min, spec.c_max, "capacitor")

    def rank(aim):
        # a pool four times the list: impedance-scaled copies and swapped builds fold into one (circuit.listed)
        if spec.r is None:
            return circuit.listed(topo, circuit.search(topo, aim, rv, cv, top=4 * spec.alternatives),
                                  spec.alternatives)
        # the seed's procedure on the section: R and C fixed, the rest solved, then rounded jointly; the level
        # is the user's: each response once, best error first
        exact = topo.synthesize_rc(aim, spec.r, spec.c)
        return circuit.listed(topo, circuit.rounded(topo, aim, exact, rv, cv, top=4 * spec.alternatives),
                              spec.alternatives, band=False)
    # the plant's spec is its dominant pair: aim off by the op-amp's shift of it (as the seed's plant does)
    aim, ranked = circuit.compensate_gbw(topo, section, amp, rank) if spec.compensate_gbw else (section, rank(section))
    exact = None if spec.r is None else topo.synthesize_rc(aim, spec.r, spec.c)
    best = ranked[0]
    # against the aim, compensated or not, as the seed's plant checks its own (plant.design): a compensated
    # aim's best parts were let through however far off (bug: fc 10 mHz, zeta 0.05, gain 100 on an LM741 with
    # --compensate-gbw built zeta -0.33, an unstable plant 1000 % off, and the bench crashed on its NaN settling)
    if best.worst > MAX_ERROR:
        what = "the target" if aim is section else f"the compensated aim (fn {format_eng(aim.fn_hz, 'Hz')})"
        raise DesignError(f"fc_hz: the best {spec.r_series}/{spec.c_series} parts for {topo.name} land "
                          f"{100 * best.worst:.3g} % off {what} (more than {100 * MAX_ERROR:g} %); widen the "
                          "part bounds or use a finer series", param="fc_hz")
    t_search = time.perf_counter() - tick
    values = best.values
    ideal = exact if spec.r is not None else topo.synthesize(dataclasses.replace(aim, c_f=values[topo.reference_capacitor]))
    labels, _, _, _ = part_series(values, spec.r_series, spec.c_series)
    notes = [Message(N_("{section}: parts {parts}"), section=Message(topo.title),
                     parts=Message.joined(", ", (Message(N_("{ref} ({role})"), ref=p.ref, role=Message(p.role))
                                                        for p in topo.parts)))]
    if spec.r is not None:
        notes.append(Message(N_("R = {r} and C = {c} fixed (the seed's procedure): the exact design {parts}, "
                                "rounded jointly to the series"), r=format_eng(spec.r, "Ohm"),
                             c=format_eng(spec.c, "F"),
                             parts=", ".join(f"{ref} = {format_eng(v, 'Ohm' if ref[0] == 'R' else 'F')}"
                                             for ref, v in exact.items())))
    if spec.compensate_gbw:
        notes.append(Message(N_("--compensate-gbw: designed for fn {fn} Hz{q} so that with the {opamp}'s {gbw} GBW it "
                                "lands on the spec"), fn=f"{aim.fn_hz:.5g}", q=f", Q {aim.q:.4g}" if aim.q else "",
                             opamp=amp.name, gbw=format_eng(amp.gbw_hz, 'Hz')))
    if math.isfinite(best.worst) and best.worst > 0.005:
        notes.append(Message(N_("the best parts land {pct} % off the target; a finer series or wider bounds may come "
                                "closer"), pct=f"{100 * best.worst:.3g}"))
    result = _analyse(topo, "design", target, values, ideal, ranked, Sourcing(spec.r_series, spec.c_series, labels),
                      amp, notes, spec.package, simulate, simulator)
    result.timings = {"search_s": t_search, **result.timings}
    return _square(result, spec.amplitude_v, spec.square_hz, simulate, simulator)


def _square(result, amplitude_v: float, square_hz, simulate: bool, simulator: str):
    """``result`` with its square-wave test when ``square_hz`` is given (and ``simulate``), its bench amplitude
    recorded."""
    result.amplitude_v = amplitude_v
    if square_hz is not None and simulate:
        with_square_test(result, amplitude_v, square_hz, simulator)
    elif square_hz is not None:
        result.notes.append("--square-freq: the square-wave test is simulated; skipped with --no-sim")
    return with_bench(result, square_hz, simulate, simulator)


def with_bench(result: CircuitPlantResult, square_hz=None, simulate: bool = False,
               simulator: str = "ngspice-cli", hold=(), refuse_unsimulable: bool = False) -> CircuitPlantResult:
    """``result`` with the Sallen-Key plant's bench (:mod:`designer.plant.bench`): the square wave (the
    square-wave test's, else :func:`~designer.plant.bench.recommend_square_wave` from the op-amp-aware
    model's 2 % settling time: a low-pass's step's, else its slowest pole's, :func:`default_square_hz`),
    the tolerance band over every declared part at +/- its series' tolerance (the readings' span: the
    rising half period, at most 4 response spans, as the Sallen-Key plant's), the scope as set for that
    square wave (CH2 from the op-amp-aware step's extremes: a high- or band-pass's output jumps with the
    edges and swings below 0 V on the falling one), the op-amp's ``slew_rate`` and ``output_swing`` checks under
    it (:func:`~designer.plant.bench.signal_checks` of the op-amp-aware step over the rising half period, at most
    4 response spans: the Sallen-Key plant's, bit for bit; first in ``checks``, replaced when the bench is set
    again) and the sine check of the op-amp-aware model
    (:func:`~designer.plant.bench.sine_check`; a band-pass at its centre, a high-pass against its
    high-frequency gain), with, when ``simulate``, ngspice's ``.ac`` of the section over fn/100 .. 100 fn at
    :data:`~designer.spice.deck.SINE_POINTS_PER_DECADE` (the Sallen-Key plant's sine check, bit for bit);
    returned.

    Parameters
    ----------
    result : CircuitPlantResult
        The design (its ``amplitude_v`` the bench's).
    square_hz : float, optional
        The square wave's frequency (None: the square-wave test's, else recommended).
    simulate : bool
        Run the sine check's ``.ac`` in ngspice.
    simulator : str
        :func:`designer.spice.simulate.get_simulator`'s name.
    hold : sequence of str
        Designators the tolerance band holds at their values (the Sallen-Key plant's gain pair).
    refuse_unsimulable : bool
        With ``simulate``, refuse a square wave too slow to simulate before any SPICE run (the Sallen-Key plant
        simulates it: :meth:`designer.spice.deck.SquareTest.check_simulable`).

    Returns
    -------
    CircuitPlantResult
        ``result``.
    """
    from ..core.metrics import step_metrics as metrics
    from ..filters.deck import simulate_ac as ac
    from .bench import (PERIOD_CHECK, SIGNAL_CHECKS, period_check, period_extremes, plant_scope, recommend_square_wave,
                        rising_step, signal_checks, sine_check, tolerance_band)
    from ..core.eseries import TOLERANCE
    topo, amp, a = result.section, result.opamp, result.amplitude_v
    models = result.models or _models(topo, result.values, amp)
    num_o, den_o = models["opamp"]
    fig_i, fig_o = result.figures["ideal"], result.figures["opamp"]
    span = step_span(result.figures)
    t = dense_time(4 * span)
    y = step_response(num_o, den_o, t)
    final = float(num_o[-1] / den_o[-1])
    if topo.kind == "lowpass":
        # the op-amp-aware step's own 2 % settling time (its metrics, read over the step's span)
        m_o = result.step_metrics.get("opamp")
        if m_o is None:
            ts = dense_time(span)
            m_o = metrics(ts, step_response(num_o, den_o, ts), final=final)
        settling = m_o.settling_time_s
    if topo.kind != "lowpass" or not math.isfinite(settling):
        # a low-pass's step that does not settle inside its span (a lightly damped pair beside a slow op-amp
        # pole): the slowest mode's envelope, which exists, rather than a NaN square wave (nice_frequency_below
        # crashed on it)
        settling = slowest_settling_s(den_o)
    if result.square is not None:
        test = result.square.test
    else:
        # the response's fastest time scale (1/wn, or the fast real pole) bounds the simulation step
        fastest = 1.0 / float(np.max(np.abs(np.roots(models["ideal"][1]))))
        test = recommend_square_wave(settling, a, square_hz, time_scale_s=fastest)
    r_tol, c_tol = (TOLERANCE[s] for s in (result.sourcing.r_series, result.sourcing.c_series))
    result.test = test
    # every declared part at its series' tolerance, but those held (the Sallen-Key plant's gain pair)
    tolerances = {r: r_tol if r[0] == "R" else c_tol for r in topo.designators if r not in hold} if hold else \
        {"R": r_tol, "C": c_tol}
    result.tolerance = tolerance_band(topo, result.values, tolerances, min(test.half_period_s, 4 * span))
    # the op-amp's slew and swing under the square wave, from the op-amp-aware step over the rising half period
    # (at most 4 spans: settled), as the Sallen-Key plant's; replaced when the bench is set again
    tw, yw, edge = rising_step(models["ideal"], models["opamp"], min(test.half_period_s, 4 * span), known=(t, y))
    result.rising = (tw, yw)
    # and a square wave too fast for the step to settle in its half period (a --square-freq), as the seed's
    late = period_check(test, settling)
    result.checks = [*signal_checks(tw, yw, a, amp, edge), *([] if late is None else [late]),
                     *(c for c in result.checks if c.id not in (*SIGNAL_CHECKS, PERIOD_CHECK))]
    if result.tolerance.unstable_corners:
        note = Message(N_("{n} tolerance corners are unstable (zeta <= 0: poles in the right half-plane): a build "
                          "there oscillates; their step readings are left out of the band"),
                       n=result.tolerance.unstable_corners)
        if note not in result.notes:   # the bench set again (check-design's square-wave run) says it once
            result.notes.append(note)
    # the output over the period, per volt (the two edges' steps by superposition), as the swing check reads it
    lo, hi = period_extremes(y)
    result.scope = plant_scope(test, hi, lo, settling, N_("generator (CH1)"))
    fn = fig_i["fn_hz"]
    spice = None
    if simulate:
        if refuse_unsimulable:
            test.check_simulable()
        tick = time.perf_counter()
        # at the sine check's density: its peak and -3 dB point are read off the sweep
        spice = ac(result.netlist, amp, fn / 100, fn * 100, simulator=simulator,
                   points_per_decade=SINE_POINTS_PER_DECADE)
        result.timings["simulation_s"] = result.timings.get("simulation_s", 0.0) + time.perf_counter() - tick
    result.sine = sine_check(num_o, den_o, amp, a, fn, spice, kind=topo.kind, zeta=fig_o["zeta"] or 1.0)
    return result


def section_analysis(topology, mode: str, target: Target, values: dict, sourcing: Sourcing, amp, amplitude_v: float,
                     square_hz=None, package=None, hold=(), simulate: bool = False,
                     simulator: str = "ngspice-cli") -> CircuitPlantResult:
    """A build's analysis by the section pipeline: the figures, steps, sensitivities and deck, and the bench
    (:func:`with_bench`, its sine check's ``.ac`` in ngspice when ``simulate``, a square wave too slow to
    simulate refused first); what the seed's Sallen-Key plant
    (:func:`designer.plant.design.design_plant`, ``analyze_plant``) computes its result from.

    Parameters
    ----------
    topology : Topology
        The section.
    mode : str
        ``design`` or ``analyze``.
    target : Target
        What the errors are reported against.
    values : dict
        Designator -> value (ohm, farad).
    sourcing : Sourcing
        Each part's series and tolerance.
    amp : designer.core.opamps.OpAmp
        The op-amp.
    amplitude_v : float
        The bench's high level (V).
    square_hz : float, optional
        The square wave's frequency (None: recommended).
    package : str, optional
        The op-amp package of the wiring.
    hold : sequence of str
        Designators the tolerance band holds (:func:`with_bench`).
    simulate : bool
        Run the sine check's ``.ac`` in ngspice.
    simulator : str
        :func:`designer.spice.simulate.get_simulator`'s name.

    Returns
    -------
    CircuitPlantResult
        The result (no ``spice`` agreement check: its caller simulates the build its own way).
    """
    result = _analyse(topology, mode, target, values, None, [], sourcing, amp, [], package, False, simulator)
    result.amplitude_v = amplitude_v
    return with_bench(result, square_hz, simulate, simulator, hold=hold, refuse_unsimulable=True)


def analyze_circuit_plant(topology: str, values: dict, opamp: str = "LM741", target_fc_hz=None, target_zeta=None,
                          r_series=None, c_series=None, package=None, simulate: bool = True,
                          simulator: str = "ngspice-cli", amplitude_v=2.0, square_hz=None) -> CircuitPlantResult:
    """Analyse a section's parts as built (``analyze-plant --topology NAME --part R1=1k6 ..``).

    Parameters
    ----------
    topology : str
        A registered section's name.
    values : dict
        Designator -> value (a number or engineering notation), every declared part.
    opamp : str or designer.core.opamps.OpAmp
        The op-amp's catalogue name, or the op-amp itself (a Monte Carlo build's, its GBW and slew rate drawn).
    target_fc_hz, target_zeta : float or str, optional
        What the errors are reported against.
    r_series, c_series : str, optional
        Where the parts come from, for their tolerance (None: the smallest series holding each value).
    package : str, optional
        The op-amp package of the wiring.
    simulate : bool
        Run ngspice's .ac of the deck.
    simulator : str
        :func:`designer.spice.simulate.get_simulator`'s name.
    amplitude_v : float or str
        The square wave's high level (V).
    square_hz : float or str, optional
        The square-wave bench test's frequency (None: no square-wave test).

    Returns
    -------
    CircuitPlantResult
        The typed result (``mode`` "analyze").

    Raises
    ------
    DesignError
        A part missing, not the section's, or out of range; a bad target, series or square wave (one line each).
    """
    topo = registry.get(topology)
    parsed = check_circuit_parts(topo, values)
    fc, zeta = _analysis_target(topo, target_fc_hz, target_zeta)
    amplitude_v = parse_in_range(amplitude_v, "amplitude_v", "amplitude_v")
    square_hz = None if square_hz is None else parse_in_range(square_hz, "square_hz", "square_hz")
    amp = opamp if isinstance(opamp, opamps.OpAmp) else opamps.get(opamp)   # an OpAmp: a replayed build's own
    amp.package(package)
    series = [None if s is None else series_name(s) for s in (r_series, c_series)]
    labels, r_s, c_s, why = part_series(parsed, *series)
    _check_stable(topo, parsed, amp)
    gain = float(topo.figures(parsed).gain)
    fig = topo.figures(parsed)
    notes = [Message(N_("these parts give fn = {fn} Hz{q}, gain {gain}"), fn=f"{fig.fn_hz:.5g}",
                     q="" if fig.q is None else f", Q = {fig.q:.4g}", gain=f"{gain:.4g}"), *why]
    return _square(_analyse(topo, "analyze", Target(fc, zeta, gain), parsed, None, [], Sourcing(r_s, c_s, labels),
                            amp, notes, package, simulate, simulator), amplitude_v, square_hz, simulate, simulator)


def _check_stable(topo, values: dict, amp) -> None:
    """Refuse parts as built whose section is unstable, ideal or with ``amp`` (a pole with Re p >= 0: a gain
    section's positive feedback past its edge, zeta <= 0), as the seed's plant refuses its own: such a build
    oscillates and has no step, no settling and no bench (bug: the step's exp overflowed and the sheet filled
    with NaN)."""
    for who, (_, den) in (("", topo.coefficients(values)), (f" with the {amp.name}", circuit.opamp_tf(topo, values, amp))):
        poles = np.roots(np.asarray(den, float))
        if np.any(poles.real >= 0):
            fn, zeta = topo.ideal_pair(values)
            z = "" if zeta is None else f", zeta {float(zeta):.3g}"
            raise DesignError(f"part: these parts make {topo.name} unstable{who} (fn {format_eng(float(fn), 'Hz')}{z}: "
                              "a pole in the right half-plane, the build oscillates); change the parts",
                              param="part")


def _analysis_target(topo, target_fc_hz, target_zeta) -> tuple:
    """(fc, zeta) an analysis reports its errors against, checked (None: not given)."""
    fc = None if target_fc_hz is None else parse_in_range(target_fc_hz, "target_fc_hz", "fc_hz")
    zeta = None if target_zeta is None else parse_in_range(target_zeta, "target_zeta", "zeta")
    if zeta is not None and topo.order == 1:
        raise DesignError(f"target_zeta: {topo.name} is first-order and has no damping", param="target_zeta")
    return fc, zeta


def check_circuit_parts(topology, values: dict) -> dict:
    """A section's parts as built, checked: every declared part once, each a value in range.

    Parameters
    ----------
    topology : Topology
        The section.
    values : dict
        Designator -> value (a number or engineering notation).

    Returns
    -------
    dict
        Designator -> value (ohm, farad), in the section's order.

    Raises
    ------
    DesignError
        A part missing, not the section's, or out of range (one line, ``param`` "part").
    """
    unknown = [r for r in values if r not in topology.designators]
    missing = [r for r in topology.designators if r not in values]
    if unknown or missing:
        what = f"has no part {unknown[0]}" if unknown else f"needs {', '.join(missing)} too"
        raise DesignError(f"part: {topology.name} {what}; its parts are {', '.join(topology.designators)}",
                          param="part")
    return {r: parse_in_range(values[r], f"part {r}", "resistor_ohm" if r[0] == "R" else "capacitor_f")
            for r in topology.designators}


def built_name(topology: str, values: dict) -> str:
    """The default name of an analysis of parts as built (its files): ``built_`` with each part's designator
    and value code (``built_r1820_r21k_c110n_c2220n``), the section's name after ``built_`` but for the
    default one's.

    Parameters
    ----------
    topology : str
        The section's registered name.
    values : dict
        Designator -> value (ohm, farad), in the order the name lists them.

    Returns
    -------
    str
        The name.
    """
    from ..core.units import value_code
    where = "" if topology == circuit.DEFAULT_TOPOLOGY else f"{topology}_"
    return f"built_{where}" + "_".join(f"{r.lower()}{value_code(v)}" for r, v in values.items())


@dataclass(frozen=True)
class CircuitAnalysisSpec:
    """A section's parts as built, to analyse (check-design's ``topology:`` with ``parts:``); the
    parts are checked when the spec is made (:func:`check_circuit_parts`).

    Parameters
    ----------
    topology : str
        A registered section's name.
    values : dict
        Designator -> value, every declared part.
    opamp : str
        The op-amp's catalogue name.
    target_fc_hz, target_zeta : float or str, optional
        What the errors are reported against.
    r_series, c_series : str, optional
        Where the parts come from (None: the smallest series holding each value).
    package : str, optional
        The op-amp package of the wiring.
    amplitude_v : float or str
        The square wave's high level (V).
    square_hz : float or str, optional
        The square-wave bench test's frequency (None: no square-wave test).
    """

    topology: str
    values: dict
    opamp: str = "LM741"
    target_fc_hz: object = None
    target_zeta: object = None
    r_series: str | None = None
    c_series: str | None = None
    package: str | None = None
    amplitude_v: object = 2.0
    square_hz: object = None

    def __post_init__(self):
        topo = registry.get(self.topology)
        check_circuit_parts(topo, self.values)
        _analysis_target(topo, self.target_fc_hz, self.target_zeta)
        opamps.get(self.opamp)
        parse_in_range(self.amplitude_v, "amplitude_v", "amplitude_v")
        if self.square_hz is not None:
            parse_in_range(self.square_hz, "square_hz", "square_hz")


def analyze_circuit_spec(spec: CircuitAnalysisSpec, simulate: bool = True,
                         simulator: str = "ngspice-cli") -> CircuitPlantResult:
    """:func:`analyze_circuit_plant` of a :class:`CircuitAnalysisSpec`.

    Parameters
    ----------
    spec : CircuitAnalysisSpec
        The parts as built.
    simulate : bool
        Run ngspice's .ac of the deck.
    simulator : str
        :func:`designer.spice.simulate.get_simulator`'s name.

    Returns
    -------
    CircuitPlantResult
        The typed result (``mode`` "analyze").
    """
    return analyze_circuit_plant(spec.topology, spec.values, spec.opamp, spec.target_fc_hz, spec.target_zeta,
                                 spec.r_series, spec.c_series, spec.package, simulate=simulate, simulator=simulator,
                                 amplitude_v=spec.amplitude_v, square_hz=spec.square_hz)


def _analyse(topo, mode: str, target: Target, values: dict, ideal, ranked: list, sourcing: Sourcing, amp, notes: list,
             package, simulate: bool, simulator: str) -> CircuitPlantResult:
    """The figures, sensitivities, deck and (when ``simulate``) SPICE check of a build, as one result."""
    tick = time.perf_counter()
    figures = _figures(topo, values, amp, target)
    models = _models(topo, values, amp)
    metrics = _steps(topo, models, figures)
    steps = {k: None if m is None else {f: m.to_dict()[f] for f in METRICS} for k, m in metrics.items()}
    sensitivity = {"ideal": circuit.sensitivities(topo, values), "opamp": circuit.sensitivities(topo, values, amp)}
    netlist = topo.netlist(values)
    fn = figures["ideal"]["fn_hz"]
    deck = ac_deck(netlist, amp, fn / 30, fn * 30, title=f"{topo.title} plant fn={fn:.5g}Hz op-amp={amp.name}")
    timings = {"analytic_s": time.perf_counter() - tick}
    checks, run = [], None
    if simulate:
        tick = time.perf_counter()
        run, check = _spice(netlist, amp, fn, topo, values, simulator)
        checks.append(check)
        timings["simulation_s"] = time.perf_counter() - tick
    else:
        notes.append(N_("SPICE simulation skipped (--no-sim): the figures are analytic only"))
    return CircuitPlantResult(topo.name, mode, target, values, ideal, ranked, sourcing, amp, figures, steps,
                              sensitivity, netlist, deck, checks, notes, run, package, timings=timings,
                              step_metrics=metrics, models=models)


#: SPICE's square-wave output against the op-amp-aware model's: NRMS (Xyce's rule, :func:`designer.core.compare.nrms`,
#: reltol 1 %, abstol 1 % of the passband gain x amplitude, as the Sallen-Key plant's bench test) below this passes
SQUARE_NRMS_PASS = 1.0
#: the model's response is computed on this many points of the period
SQUARE_POINTS = 20001


@dataclass
class SquareRun:
    """The square-wave bench test of a section plant: one period in ngspice against the op-amp-aware model.

    Parameters
    ----------
    test : designer.spice.deck.SquareTest
        The square wave.
    deck : str
        The ``.tran`` deck (``square-test.cir``).
    t : numpy.ndarray
        The comparison's times (s, from 0).
    u, y_spice, y_model : numpy.ndarray
        The input, SPICE's output and the model's, on ``t``.
    nrms : float
        The NRMS of SPICE against the model.
    abstol_v : float
        Its absolute tolerance.
    simulator : str
        The backend.
    y_ideal : numpy.ndarray, optional
        The ideal-op-amp model's output on ``t`` (check-design's ``analytic_v``).
    nrms_ideal : float, optional
        The NRMS of SPICE against the ideal model (check-design's ``nrms_ideal``).
    """

    test: object
    deck: str
    t: np.ndarray
    u: np.ndarray
    y_spice: np.ndarray
    y_model: np.ndarray
    nrms: float
    abstol_v: float
    simulator: str
    y_ideal: np.ndarray | None = None
    nrms_ideal: float | None = None

    def waves(self) -> tuple:
        """(t, {signal: samples}): the run under the Sallen-Key plant's signal names (check-design's
        golden waveforms): ``input_v``, ``output_v`` (SPICE), ``analytic_opamp_v``, ``analytic_v``.

        Returns
        -------
        tuple
            (times in s, signal name -> samples on them).
        """
        return self.t, {"input_v": self.u, "output_v": self.y_spice, "analytic_v": self.y_ideal,
                        "analytic_opamp_v": self.y_model}

    @property
    def check(self) -> Check:
        """The verdict (NRMS below :data:`SQUARE_NRMS_PASS`)."""
        ok = self.nrms < SQUARE_NRMS_PASS
        return Check("square_wave_agreement", ok, f"SPICE's output under the {format_eng(self.test.frequency_hz, 'Hz')} "
                     f"square wave against the op-amp-aware model: NRMS {self.nrms:.3g} (reltol 1 %, abstol "
                     f"{format_eng(self.abstol_v, 'V')}; below {SQUARE_NRMS_PASS:g} agrees)")

    def to_dict(self) -> dict:
        """The JSON form (``square_test``).

        Returns
        -------
        dict
            The generator's settings, the NRMS and the verdict.
        """
        return {"generator": self.test.to_dict(), "delay_s": self.test.delay_s, "simulator": self.simulator,
                "nrms": self.nrms, "nrms_pass_below": SQUARE_NRMS_PASS, "abstol_v": self.abstol_v,
                "reltol": 0.01, "pass": self.check.ok}

    def csv_text(self) -> str:
        """``waveforms.csv``: time, input, SPICE's output, the model's.

        Returns
        -------
        str
            CSV text.
        """
        rows = "".join(f"{a:.12g},{b:.9g},{c:.9g},{d:.9g}\n" for a, b, c, d in
                       zip(self.t, self.u, self.y_spice, self.y_model))
        return "time_s,input_v,spice_v,model_v\n" + rows


def square_deck(netlist, amp, test, title: str) -> str:
    """The section under the square wave ``test``: one period of ``.tran``.

    Parameters
    ----------
    netlist : designer.spice.deck.Netlist
        The section.
    amp : designer.core.opamps.OpAmp
        The op-amp.
    test : designer.spice.deck.SquareTest
        The square wave on net ``vin``.
    title : str
        The deck's title line.

    Returns
    -------
    str
        The deck.
    """
    from ..spice.deck import bench_circuit, finish_deck
    circuit = bench_circuit(title, amp, [f"* {title}: 0 -> {test.amplitude_v:g} V square wave at "
                                         f"{test.frequency_hz:g} Hz on vin; op-amp {amp.name}"])
    circuit.V("in", "vin", circuit.gnd, test.source())
    netlist.add_to(circuit, amp)
    return finish_deck(circuit, test)


def with_square_test(result: CircuitPlantResult, amplitude_v: float, frequency_hz: float,
                     simulator: str = "ngspice-cli") -> CircuitPlantResult:
    """``result`` with its square-wave bench test (:class:`SquareRun`) and its check added; returned.

    Parameters
    ----------
    result : CircuitPlantResult
        The design.
    amplitude_v : float
        The square wave's high level (V; low 0 V).
    frequency_hz : float
        Its frequency.
    simulator : str
        The backend.

    Returns
    -------
    CircuitPlantResult
        ``result``.
    """
    from ..core.compare import nrms, resample
    from ..spice.deck import SquareTest
    from ..spice.simulate import get_simulator
    topo, amp = result.section, result.opamp
    fn = result.figures["opamp"]["fn_hz"]
    half = 0.5 / frequency_hz
    test = SquareTest(amplitude_v, frequency_hz, min(0.05 * half, 20 / (2 * math.pi * fn)),
                      time_scale_s=1 / (2 * math.pi * fn))
    test.check_simulable()
    deck = square_deck(result.netlist, amp, test, f"{topo.title} plant square-wave test op-amp={amp.name}")
    res = get_simulator(simulator).run(deck)
    e, d = test.edge_s, test.delay_s
    corners = [0.0, d, d + e, d + half, d + half + e, test.stop_s]
    # the edges' corners on the grid, where SPICE's PULSE turns
    t = np.union1d(np.linspace(0.0, test.stop_s, SQUARE_POINTS), corners)
    u = np.interp(t, corners, [0.0, 0.0, amplitude_v, amplitude_v, 0.0, 0.0])
    tau = np.linspace(0.0, test.stop_s, SQUARE_POINTS)
    y_model, y_ideal = (_square_response(num, den, fn, amplitude_v, test, t, tau) for num, den in
                        (circuit.opamp_tf(topo, result.values, amp), topo.coefficients(result.values)))
    y_spice = resample(res["time"], np.real(res["v(vout)"]), t)
    abstol = 0.01 * abs(result.figures["ideal"]["gain"] * amplitude_v)
    fit = nrms(y_model, y_spice, abstol, t=t)
    result.square = SquareRun(test, deck, t, u, y_spice, y_model, fit, abstol, get_simulator(simulator).name,
                              y_ideal, nrms(y_ideal, y_spice, abstol, t=t))
    result.checks = [*result.checks, result.square.check]
    if not result.square.check.ok:
        result.notes.append(f"under the square wave SPICE differs from the linear model (NRMS {fit:.3g}): an "
                            f"output that jumps at the edges (a high-pass's) is slew-limited by the {amp.name}'s "
                            f"{amp.slew_v_per_s / 1e6:.3g} V/us; a lower --amplitude or a faster op-amp follows it")
    return result


def _square_response(num, den, fn: float, amplitude_v: float, test, t, tau):
    """A model's output under the square wave ``test`` on ``t`` (its step response computed on ``tau``)."""
    import scipy.signal as sig
    num, den = np.asarray(num, float), np.asarray(den, float)
    # leading numerator terms that are rounding (|c_k wn^k| at 1e-12 of the largest term) go: a high-pass's
    # numerator is of lower degree than its denominator, and scipy would warn of them
    w = 2 * math.pi * fn
    size = np.abs(num) * w ** np.arange(num.size - 1, -1, -1.0)
    num = num[int(np.argmax(size > 1e-12 * size.max())):]
    # the two edges as steps at their middles (an edge is 1/100 of the time scale or less), by superposition
    # of the step response s: y = A (s(t - d - e/2) - s(t - d - e/2 - half))
    e, d, half = test.edge_s, test.delay_s, test.half_period_s
    step = sig.step((num, den), T=tau)[1]
    s_at = lambda x: np.where(x > 0, np.interp(x, tau, step), 0.0)  # noqa: E731
    return amplitude_v * (s_at(t - d - e / 2) - s_at(t - d - e / 2 - half))


def default_square_hz(result: CircuitPlantResult) -> float:
    """The square-wave test's frequency when none is given (check-design's ``spice_agreement`` and
    ``golden`` on a section): the Sallen-Key plant's rule (:func:`designer.plant.bench.recommend_square_wave`:
    a half period of 1.5 settling times) with the 2 % settling time of the op-amp-aware model's slowest
    pole, ln(50) / sigma (sigma its decay rate: the envelope exp(-sigma t) falls to 2 %; 4 / (zeta wn) for a
    dominant pair, Ogata, *Modern Control Engineering*, 5th ed., section 5-3).

    Parameters
    ----------
    result : CircuitPlantResult
        The design.

    Returns
    -------
    float
        The frequency (Hz).
    """
    from .bench import recommend_square_wave
    den = circuit.opamp_tf(result.section, result.values, result.opamp)[1]
    return recommend_square_wave(slowest_settling_s(den), 1.0).frequency_hz


def tolerance_nominal(result: CircuitPlantResult) -> dict:
    """The parts that vary in a tolerance analysis: designator -> value.

    Parameters
    ----------
    result : CircuitPlantResult
        The design.

    Returns
    -------
    dict
        Every declared part.
    """
    return dict(result.values)

