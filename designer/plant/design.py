"""From a spec (fc, zeta, gain) to a verified Sallen-Key plant: synthesis,
joint E-series selection, analytic models, netlist, simulation and comparison
(seed 001, IV.3-IV.9: the plant it designs by hand, with its rounding done
jointly and its LM741 modelled).

``design_plant`` and ``analyze_plant`` return a
:class:`~designer.plant.result.PlantResult`, typed; its ``to_dict`` is the
JSON of ``design-plant --json`` and ``result.json``, and the report module
renders the same object as text, Markdown and HTML. Its analysis is the section
pipeline's on the Sallen-Key low-pass (:func:`designer.plant.circuit_design.section_analysis`:
figures, steps, sensitivities, square wave, tolerance band with the gain pair held, sine
check); this module adds what only the seed's plant has: the models' responses over the
bench's rising half period, the slew-rate and swing checks, the scope, and its own
``.tran`` deck in SPICE (the ``netlists/`` reference, compared with both models).

Which builds are listed: :func:`designer.plant.circuit.listed`, every section's rule (each
response once, at the level whose resistors lie in 1 kOhm..100 kOhm, those within 0.5 % of the
target in that band first; the module says why). The parts are ranked by the generic entry,
:func:`designer.plant.circuit.search` (:func:`~designer.plant.circuit.rounded` with R and C fixed),
which takes the Sallen-Key low-pass's own exact search (its
:meth:`~designer.filters.topology.Topology.fast_search`), as ``design-plant --topology
sallen-key-lowpass`` does.
"""

from __future__ import annotations

import math
import time
from dataclasses import dataclass

import numpy as np

from ..core import eseries
from ..core.compare import disagreements, metric_deltas, nrms, resample
from ..core.errors import ParamError
from ..core.lti import step_response
from ..core.metrics import step_metrics
from ..core.opamps import OpAmp
from ..core.ranges import RANGES
from ..core.units import format_eng, value_code
from ..spice.simulate import get_simulator
from .bench import PERIOD_CHECK, SIGNAL_CHECKS, bench_period, plant_scope, rising_step
from .circuit_design import section_analysis, step_span
from . import circuit
from .model import Sensitivity
from .netlist import plant_deck
from .result import (
    Alternative,
    Comparison,
    Figures,
    Model,
    PartSource,
    PlantResult,
    Ratios,
    Sourcing,
    SpiceRun,
    Target,
)
from ..filters.sallen_key_lowpass_synthesis import (
    SallenKeyParts,
    exact_on_capacitors,
    ratios_from_rc,
    realizability_notes,
    seed_ratios,
    unity_gain_c2_min,
)
from ..filters.sallen_key_lowpass_parts import gain_of, network, part_values, parts_of, section_of
from ..filters.sallen_key_lowpass_search import scored
from ..filters.topology import SectionTarget
from .sourcing import MAX_ERROR, NOTE_ERROR, candidates, part_series
from .spec import AnalysisSpec, PlantSpec

__all__ = ["PlantSpec", "AnalysisSpec", "PlantResult", "choose_parts", "design_plant", "analyze_plant"]


def gain_resistors(gain: float, spec: PlantSpec):
    """R3 (to ground) and R4 (feedback) for K = 1 + R4/R3 from the resistor series."""
    if gain == 1.0:
        return None, None, 1.0
    r4, r3 = eseries.nearest_ratio_pair(gain - 1.0, spec.r_series, spec.r_min, spec.r_max)
    return r3, r4, 1.0 + r4 / r3


@dataclass(frozen=True)
class Choice:
    """The parts a spec gets: the build, the exact design it rounds and its
    ratios, the ranked alternatives (:class:`~designer.plant.selection.Candidate`),
    notes, and the targets aimed at (moved off by ``compensate_gbw``)."""

    built: SallenKeyParts
    ideal: SallenKeyParts | None
    ratios: Ratios
    ranked: list
    notes: list
    fc_target_hz: float | None = None
    zeta_target: float | None = None


def choose_parts(spec: PlantSpec) -> Choice:
    """The E-series parts for a spec, without any analysis: what
    ``design-plant`` builds, and what ``design-pid`` needs of a designed plant.

    Parameters
    ----------
    spec : PlantSpec
        The request.

    Returns
    -------
    Choice
        The build and its alternatives.
    """
    rv = candidates(spec.r_series, spec.r_min, spec.r_max, "resistor")
    cv = candidates(spec.c_series, spec.c_min, spec.c_max, "capacitor")
    r3, r4, k = gain_resistors(spec.gain, spec)
    notes = realizability_notes(spec.fc_hz, spec.zeta, spec.gain, spec.c_min, spec.c_max)
    if k != spec.gain:
        notes.append(f"gain K = {spec.gain:g} realised as 1 + {r4:g}/{r3:g} = {k:.5g}")
    top = spec.alternatives
    topo = section_of(with_gain=r3 is not None)

    # with R and C fixed (the seed's procedure) the level is the user's: each response once, best error first
    band = spec.r is None
    target = SectionTarget("lowpass", spec.fc_hz, q=1.0 / (2.0 * spec.zeta), gain=spec.gain)
    exact = {"ideal": None, "ratios": None}

    def zeta_of(aim):
        return spec.zeta if aim is target else 1.0 / (2.0 * aim.q)

    def rank(aim):
        """The builds listed for a target (circuit.listed) from the generic entry, circuit.search (the section's
        fast path); with R and C fixed (the seed's procedure) circuit.rounded of the exact design they give."""
        if spec.r is None:
            return circuit.listed(topo, circuit.search(topo, aim, rv, cv, top=4 * top), top, band)
        m, n = ratios_from_rc(aim.fn_hz, zeta_of(aim), spec.r, spec.c, k)
        ideal = SallenKeyParts(m * spec.r, spec.r, spec.c, n * spec.c, k, r3, r4)
        # each part rounded jointly around the exact design
        found = circuit.rounded(topo, aim, part_values(ideal), rv, cv, top=4 * top)
        exact.update(ideal=ideal, ratios=Ratios(m, n))
        return circuit.listed(topo, found, top, band)

    # --compensate-gbw: aim off by the shift the op-amp causes on the parts chosen, and choose again (every
    # section's rule, circuit.compensate_gbw)
    aim, chosen = circuit.compensate_gbw(topo, target, spec.amp, rank) if spec.compensate_gbw else (target,
                                                                                                     rank(target))
    fc_t, z_t = aim.fn_hz, zeta_of(aim)
    ideal, ratios = exact["ideal"], exact["ratios"]
    ranked = scored(*network({r: np.array([c.values[r] for c in chosen]) for r in topo.designators}), fc_t, z_t, k)
    best = ranked[0]
    if spec.r is None:
        # solved once, for the target finally aimed at
        ideal = exact_on_capacitors(best, fc_t, z_t, k, r3, r4)
        ratios = Ratios() if ideal is None else Ratios(*seed_ratios(ideal))
    built = parts_of(part_values(best), gain=k, r3=r3, r4=r4)
    if best.worst > MAX_ERROR:
        raise _unreachable(spec, fc_t, best.worst)
    if spec.r is None and best.worst > NOTE_ERROR:
        notes += _bound_notes(spec, fc_t, z_t, best.worst)
    return Choice(built, ideal, ratios, ranked, notes, fc_t, z_t)


def design_plant(spec: PlantSpec, simulate: bool = True, simulator: str = "pyspice") -> PlantResult:
    """Design, analyse and (unless ``simulate`` is False) verify a plant.

    Parameters
    ----------
    spec : PlantSpec
        The request.
    simulate : bool
        Verify in ngspice.
    simulator : str
        The backend.

    Returns
    -------
    PlantResult
        The design, its analysis and its verification.
    """
    tick = time.perf_counter()
    amp = spec.amp
    choice = choose_parts(spec)
    t_search = time.perf_counter() - tick
    target = Target(spec.fc_hz, spec.zeta, spec.gain)
    built = choice.built
    refs = section_of(built).designators

    def source(ref):
        series = spec.r_series if ref[0] == "R" else spec.c_series
        return PartSource(series, 100 * eseries.TOLERANCE[series])

    sourcing = Sourcing(spec.r_series, spec.c_series, {ref: source(ref) for ref in refs})
    alternatives = [Alternative(part_values(c), Figures.against(c.fn_hz, c.zeta, target)) for c in choice.ranked]
    result = _analyse("design", target, choice, sourcing, alternatives, amp, spec.amplitude_v, spec.square_hz,
                      simulate, simulator, spec.package)
    if spec.compensate_gbw:
        result.notes.append(f"--compensate-gbw: designed for fn {choice.fc_target_hz:.5g} Hz, zeta "
                            f"{choice.zeta_target:.4g} so that with the {amp.name}'s {amp.gbw_hz / 1e6:g} MHz GBW "
                            "it lands on the spec")
    elif not amp.ideal:
        fig = result.analytic_opamp.figures
        if max(abs(fig.fn_error_pct), abs(fig.zeta_error_pct)) > 100 * NOTE_ERROR * 2:
            result.notes.append(
                f"with the {amp.name}'s {format_eng(amp.gbw_hz, 'Hz')} gain-bandwidth the circuit lands "
                f"{fig.fn_error_pct:+.3g} % off in fn and {fig.zeta_error_pct:+.3g} % in zeta; --compensate-gbw "
                "aims the design off so that it lands on the spec (or choose a faster --opamp)")
    result.timings = {"search_s": t_search, **result.timings}
    return result


def analyze_plant(spec: AnalysisSpec, simulate: bool = True, simulator: str = "pyspice") -> PlantResult:
    """Analyse parts as built (e.g. the seed's rounded 820/1k/10n/220n): what
    they really give, and (unless ``simulate`` is False) SPICE's verdict.

    Parameters
    ----------
    spec : AnalysisSpec
        The parts as built.
    simulate : bool
        Verify in ngspice.
    simulator : str
        The backend.

    Returns
    -------
    PlantResult
        The analysis and its verification.
    """
    parts = spec.parts
    target = Target(spec.target_fc_hz, spec.target_zeta, parts.gain)
    notes = [f"these parts give fn = {parts.fn_hz:.5g} Hz and zeta = {parts.zeta:.4g} (Q = {parts.q:.4g})"]
    values = part_values(parts)
    labels, r_s, c_s, why = part_series(values, spec.r_series, spec.c_series)
    choice = Choice(parts, None, Ratios(*seed_ratios(parts)), [], notes + why)
    return _analyse("analyze", target, choice, Sourcing(r_s, c_s, labels), [], spec.amp, spec.amplitude_v,
                    spec.square_hz, simulate, simulator, spec.package)


def _bound_notes(spec: PlantSpec, fc: float, zeta: float, worst: float) -> list:
    """Which part bound keeps the design ``worst`` off. Each bound is relaxed by a
    decade (within the physical ranges) and the search run again; where that at
    least halves the error, the bound is named with the mildest series value
    that gets nearly all of the gain (bisection over the values in between: the
    error only falls as a bound is relaxed)."""
    out = []
    tries = (("--r-min", "r_min", 0.1, "resistor_ohm", "Ohm", "r_series"),
             ("--r-max", "r_max", 10.0, "resistor_ohm", "Ohm", "r_series"),
             ("--c-min", "c_min", 0.1, "capacitor_f", "F", "c_series"),
             ("--c-max", "c_max", 10.0, "capacitor_f", "F", "c_series"))

    def best_with(attr, value):
        b = {k: getattr(spec, k) for k in ("r_min", "r_max", "c_min", "c_max")} | {attr: value}
        rv = eseries.values(spec.r_series, b["r_min"], b["r_max"])
        cv = eseries.values(spec.c_series, b["c_min"], b["c_max"])
        if not (rv.size and cv.size):
            return math.inf
        # the generic entry (the section's fast path), the gain pair chosen again within the bounds tried
        found = {r: np.array([v]) for r, v in circuit.search(section_of(with_gain=spec.gain != 1.0), aim, rv, cv,
                                                                 top=1)[0].values.items()}
        return scored(*network(found), fc, zeta, float(gain_of(found)[0]))[0].worst

    aim = SectionTarget("lowpass", fc, q=1.0 / (2.0 * zeta), gain=spec.gain)

    for flag, attr, factor, key, unit, series in tries:
        rng, bound = RANGES[key], getattr(spec, attr)
        relaxed = min(max(bound * factor, rng.lo), rng.hi)
        if relaxed == bound:
            continue
        floor = best_with(attr, relaxed)
        if not floor <= worst / 2:
            continue
        # mildest relaxation first: values from just past the bound out to the decade
        steps = eseries.values(getattr(spec, series), min(bound, relaxed), max(bound, relaxed))
        steps = steps[steps != bound][::-1] if factor < 1 else steps[steps != bound]
        lo, hi = 0, len(steps) - 1           # steps[hi] (the decade) reaches the floor
        while lo < hi:
            mid = (lo + hi) // 2
            if best_with(attr, steps[mid]) <= floor * 1.1 + 1e-9:
                hi = mid
            else:
                lo = mid + 1
        value = steps[lo] if len(steps) else relaxed
        out.append(f"the design is {100 * worst:.3g} % off because of {flag} ({format_eng(bound, unit)}): "
                   f"{flag} {value_code(value)} gets it within {100 * best_with(attr, value):.2g} %")
    return out


def _unreachable(spec: PlantSpec, fc: float, worst: float) -> ParamError:
    """Why no combination within the bounds comes close, and what to change."""
    head = (f"no {spec.r_series}/{spec.c_series} combination within the bounds comes within "
            f"{100 * MAX_ERROR:g} % of the target (best: {100 * worst:.3g} % off)")
    rc = 1.0 / (2 * math.pi * fc)
    need = unity_gain_c2_min(1.0, spec.zeta)
    # at unity gain C2 >= C1/zeta^2, so the time constants sqrt(R1 R2 C1 C2) the bounds allow run from
    # r_min c_min / zeta to r_max c_max zeta, not from r_min c_min to r_max c_max (fc 50 kHz, zeta 0.2: 5 us
    # at least, 3.2 us needed; it said "widen the bounds or use a finer series", and no series can help)
    spread = math.sqrt(need) if spec.gain == 1.0 else 1.0
    floor, ceiling = spec.r_min * spec.c_min * spread, spec.r_max * spec.c_max / spread
    ratio = f" (unity gain: C2/C1 >= 1/zeta^2 = {need:.4g})" if spec.gain == 1.0 else ""
    if rc < floor:
        why = (f": fc {format_eng(fc, 'Hz')} needs R*C near {format_eng(rc, 's')} but the bounds allow no less "
               f"than {format_eng(floor, 's')}{ratio}; lower {{r_min}} or {{c_min}}")
    elif rc > ceiling:
        why = (f": fc {format_eng(fc, 'Hz')} needs R*C near {format_eng(rc, 's')} but the bounds allow no more "
               f"than {format_eng(ceiling, 's')}{ratio}; raise {{r_max}} or {{c_max}}")
    elif spec.gain == 1.0 and need > spec.c_max / spec.c_min:
        why = f": unity gain needs C2/C1 >= 1/zeta^2 = {need:.4g}; use {{gain}} K > 1 or widen {{c_min}}/{{c_max}}"
    else:
        why = "; widen the bounds or use a finer series ({r_series}/{c_series})"
    return ParamError(head + why, params=("r_min", "r_max", "c_min", "c_max", "gain", "r_series", "c_series"))


def _analyse(mode, target: Target, choice: Choice, sourcing: Sourcing, alternatives, amp: OpAmp, amplitude_v,
             square_hz, simulate, simulator, package=None) -> PlantResult:
    """The analysis of a chosen build by the section pipeline
    (:func:`designer.plant.circuit_design.section_analysis`: the figures, steps, sensitivities, the bench's
    square wave, tolerance band and sine check), seen as the seed's :class:`PlantResult`, with what only the
    seed's plant has: the models' responses over the bench's rising half period, the slew-rate and swing
    checks, the scope, and its own ``.tran`` deck in SPICE (the ``netlists/`` reference) against both models."""
    tick = time.perf_counter()
    built = choice.built
    section, values = section_of(built), part_values(built)
    # the gain pair held in the band, as the seed's band (the RC network's corners)
    sec = section_analysis(section, mode, target, values, sourcing, amp, amplitude_v, square_hz, package,
                           hold=section.choice_parts, simulate=simulate, simulator=simulator)
    simulated = sec.timings.get("simulation_s", 0.0)   # the sine check's .ac
    test, m_i, m_o = sec.test, sec.step_metrics["ideal"], sec.step_metrics["opamp"]
    (num_i, den_i), (num_o, den_o) = sec.models["ideal"], sec.models["opamp"]
    # the comparisons and plots use the rising half period of the bench test (its start, if
    # the square wave is much slower than the response: a dense grid where the metrics are taken)
    # (the op-amp-aware step the section's bench computed on this grid, its slew and swing checks', else its own)
    tw, y_ow, _ = rising_step((num_i, den_i), (num_o, den_o), min(test.half_period_s, 4 * step_span(sec.figures)),
                              known=sec.rising)
    y_iw = step_response(num_i, den_i, tw)
    # the slew and swing checks the section pipeline's bench computed on this same grid (bench.signal_checks)
    # and its square-wave period check (the half period against the op-amp-aware step's settling time)
    checks = [c for c in sec.checks if c.id in (*SIGNAL_CHECKS, PERIOD_CHECK)]

    def model(which, num, den, step, response):
        fig = sec.figures[which]
        # the plant's table has always shown K rather than the gain pair that sets it
        table = {label: Sensitivity(s["wn"], s["zeta"]) for label, s in sec.sensitivity[which].items()
                 if label not in section.choice_parts}
        return Model(num, den, Figures(fig["fn_hz"], fig["zeta"], fig["fn_error_pct"], fig["zeta_error_pct"]), step,
                     table, response * amplitude_v)

    analytic, analytic_opamp = model("ideal", num_i, den_i, m_i, y_iw), model("opamp", num_o, den_o, m_o, y_ow)
    timings = {"analytic_s": time.perf_counter() - tick - simulated}
    tick = time.perf_counter()
    deck = plant_deck(built, amp, test, _title(built, amp))
    timings["netlist_s"] = time.perf_counter() - tick
    notes = list(choice.notes)
    spice = period = None
    if simulate:
        tick = time.perf_counter()
        spice, period = run_spice(deck, test, tw, analytic, analytic_opamp, built.gain, simulator)
        if not spice.comparison.passed:
            notes.append("SPICE disagrees with the op-amp-aware model: " + "; ".join(spice.comparison.disagreements))
        timings["simulation_s"] = simulated + time.perf_counter() - tick
    else:
        notes.append("SPICE simulation skipped (--no-sim): the figures are analytic only")
    tick = time.perf_counter()
    bench = bench_period(test, (num_i, den_i), (num_o, den_o), period)
    # the output's extremes over the period (per volt of square wave): the rising edge's peak, and the
    # falling edge's undershoot below 0 V, as deep as the overshoot (superposition)
    peak = m_o.peak_value if math.isfinite(m_o.peak_value) else built.gain
    scope = plant_scope(test, peak, min(0.0, built.gain - peak), m_o.settling_time_s)
    timings["analytic_s"] += time.perf_counter() - tick
    return PlantResult(mode=mode, target=target, ratios=choice.ratios, ideal=choice.ideal, built=built,
                       sourcing=sourcing, alternatives=alternatives, opamp=amp, analytic=analytic,
                       analytic_opamp=analytic_opamp, time_s=tw, test=test, tolerance=sec.tolerance, checks=checks,
                       notes=notes, deck=deck, bench=bench, spice=spice, scope=scope, sine=sec.sine,
                       timings=timings, package=package)


def _title(parts, amp):
    return (f"Sallen-Key low-pass plant fn={parts.fn_hz:.5g}Hz zeta={parts.zeta:.4g} "
            f"K={parts.gain:.4g} op-amp={amp.name}")


def run_spice(deck: str, test, t, analytic: Model, analytic_opamp: Model, gain: float, simulator: str):
    """Simulate the deck and compare SPICE with both analytic models on the
    grid ``t`` (from the rising edge).

    Returns
    -------
    (SpiceRun, (time, output, input))
        The run, and the simulated period as ngspice gave it (for the bench capture).
    """
    sim = get_simulator(simulator)
    res = sim.run(deck)
    ts, y = res["time"], res["v(out)"]
    y_s = resample(ts, y, t + test.delay_s)
    amp_v = test.amplitude_v
    m_s = step_metrics(t, y_s / amp_v, final=analytic_opamp.dc_gain)
    abstol = 0.01 * abs(gain * amp_v)
    fit, fit_ideal = nrms(analytic_opamp.response, y_s, abstol), nrms(analytic.response, y_s, abstol)
    ref, fig = analytic_opamp.step, analytic_opamp.figures
    deltas = metric_deltas(ref, m_s)
    z = min(fig.zeta, 0.999)
    half_ring = 0.5 / (fig.fn_hz * math.sqrt(1 - z * z)) if fig.zeta < 1 else 0.0
    off = disagreements(deltas, ref, half_ring)
    if fit >= 1.0:
        off.insert(0, f"waveform NRMS {fit:.3g} (allowed below 1)")
    comparison = Comparison(metric_deltas(analytic.step, m_s), deltas, abstol, off)
    return (SpiceRun(sim.name, m_s, fit, fit_ideal, res.measurements, y_s, comparison),
            (ts, y, res["input"]))
