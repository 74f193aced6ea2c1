"""From a spec (fc, zeta, gain) to a verified Sallen-Key plant: synthesis,
joint E-series selection, analytic models, netlist, simulation and comparison.

``design_plant`` and ``analyze_plant`` return a :class:`PlantResult`, whose
``to_dict`` is the JSON of ``design-plant --json`` and ``result.json``; the
report module renders the same data as text, Markdown and HTML.
"""

from __future__ import annotations

import math
import time
from dataclasses import dataclass, field

import numpy as np

from ..core import eseries, opamps
from ..core.compare import disagreements, metric_deltas, nrms, resample
from ..core.errors import DesignError
from ..core.jsonio import json_safe
from ..core.lti import dense_time, dominant_pair, response_span, step_response
from ..core.metrics import step_metrics
from ..core.opamps import OpAmp
from ..core.ranges import RANGES
from ..core.units import format_eng, value_code
from ..spice.deck import SquareTest
from ..spice.simulate import get_simulator
from .bench import recommend_square_wave, signal_checks, tolerance_band
from .model import plant_tf, plant_tf_opamp, sensitivities
from .netlist import plant_deck
from .sallenkey import SallenKeyParts, check_parts, ratios_from_rc, realizability_notes, resistors_for_caps
from .selection import around, brute_force, joint_search


@dataclass
class PlantSpec:
    """What the user asked for. Values in ohms, farads, hertz, volts."""

    fc_hz: float
    zeta: float
    gain: float = 1.0
    r_series: str = "E24"
    c_series: str = "E12"
    r_min: float = 1e3
    r_max: float = 1e6
    c_min: float = 1e-9
    c_max: float = 1e-5
    r: float | None = None        #: the seed's procedure: fix R ...
    c: float | None = None        #: ... and C, solve m and n
    opamp: str = "LM741"
    compensate_gbw: bool = False
    amplitude_v: float = 2.0
    square_hz: float | None = None
    alternatives: int = 5

    def validate(self) -> None:
        """Every value inside its physical range (:mod:`designer.ranges`), the
        options consistent; a :class:`DesignError` naming the option otherwise."""
        R = RANGES
        R["fc_hz"].check(self.fc_hz, "--fc")
        R["zeta"].check(self.zeta, "--zeta")
        R["gain"].check(self.gain, "--gain")
        for name, v in (("--r-min", self.r_min), ("--r-max", self.r_max)):
            R["resistor_ohm"].check(v, name)
        for name, v in (("--c-min", self.c_min), ("--c-max", self.c_max)):
            R["capacitor_f"].check(v, name)
        self.r_series, self.c_series = eseries.check_bounds(
            self.r_series, self.c_series, self.r_min, self.r_max, self.c_min, self.c_max)
        R["amplitude_v"].check(self.amplitude_v, "--amplitude")
        if (self.r is None) != (self.c is None):
            raise DesignError("--r and --c go together (the seed's procedure fixes both R and C)")
        if self.r is not None:
            R["resistor_ohm"].check(self.r, "--r")
            R["capacitor_f"].check(self.c, "--c")
        if self.square_hz is not None:
            R["square_hz"].check(self.square_hz, "--square-freq")
        R["alternatives"].check(self.alternatives, "--alternatives")
        opamps.get(self.opamp)


@dataclass
class PlantResult:
    """Everything known about one plant design; ``to_dict`` is the JSON."""

    spec: dict
    ratios: dict
    ideal: SallenKeyParts | None
    built: SallenKeyParts
    opamp: OpAmp
    series: dict
    alternatives: list
    notes: list
    fn_opamp_hz: float
    zeta_opamp: float
    analytic: dict
    analytic_opamp: dict
    spice: dict | None
    comparison: dict
    sensitivity: dict
    sensitivity_opamp: dict
    tolerance: dict
    test: SquareTest
    checks: list
    waveforms: dict = field(default_factory=dict, repr=False)
    files: dict = field(default_factory=dict)
    timings: dict = field(default_factory=dict)
    simulator: str | None = None
    mode: str = "design"

    def to_dict(self) -> dict:
        b = self.built
        target_fn = self.spec.get("fc_hz")
        target_z = self.spec.get("zeta")
        built = {**b.as_dict(), "q": b.q,
                 "fn_error_pct": _pct(b.fn_hz, target_fn), "zeta_error_pct": _pct(b.zeta, target_z),
                 "fn_opamp_hz": self.fn_opamp_hz, "zeta_opamp": self.zeta_opamp,
                 "fn_opamp_error_pct": _pct(self.fn_opamp_hz, target_fn),
                 "zeta_opamp_error_pct": _pct(self.zeta_opamp, target_z),
                 "tolerance_band": self.tolerance}
        return json_safe({
            "mode": self.mode,
            "spec": self.spec,
            "ratios": self.ratios,
            "ideal": None if self.ideal is None else {**self.ideal.as_dict(), "q": self.ideal.q},
            "built": built,
            "series": self.series,
            "alternatives": self.alternatives,
            "opamp": {"name": self.opamp.name, "gbw_hz": self.opamp.gbw_hz,
                      "slew_v_per_s": self.opamp.slew_v_per_s, "a0": self.opamp.a0,
                      "vcc": self.opamp.vcc, "vee": self.opamp.vee,
                      "vout_max": self.opamp.vout_max, "vout_min": self.opamp.vout_min},
            "test_signal": {"kind": "square", "low_v": 0.0, "high_v": self.test.amplitude_v,
                            "frequency_hz": self.test.frequency_hz,
                            "offset_v": self.test.amplitude_v / 2,
                            "amplitude_vpp": self.test.amplitude_v},
            "checks": self.checks,
            "notes": self.notes,
            "analytic": self.analytic,
            "analytic_opamp": self.analytic_opamp,
            "spice": self.spice,
            "comparison": self.comparison,
            "sensitivity": {"ideal": self.sensitivity, "opamp": self.sensitivity_opamp},
            "simulator": self.simulator,
            "files": self.files,
        })


def _pct(value, target):
    if target is None or value is None:
        return None
    return 100.0 * (value / target - 1.0)


def candidates(series: str, lo: float, hi: float, what: str) -> np.ndarray:
    vals = eseries.values(series, lo, hi)
    if vals.size == 0:
        raise DesignError(f"no {series} {what} value between {lo:g} and {hi:g}; widen the bounds")
    return vals


def gain_resistors(gain: float, spec: PlantSpec):
    """R3 (to ground) and R4 (feedback) for K = 1 + R4/R3 from the resistor series."""
    if gain == 1.0:
        return None, None, 1.0
    r4, r3 = eseries.nearest_ratio_pair(gain - 1.0, spec.r_series, spec.r_min, spec.r_max)
    return r3, r4, 1.0 + r4 / r3


def gbw_shift(parts: SallenKeyParts, opamp: OpAmp):
    """How far the op-amp's finite GBW moves these parts: (fn_ideal / fn_opamp,
    zeta_ideal / zeta_opamp). ``--compensate-gbw`` multiplies the targets by it."""
    fo, zo = dominant_pair(plant_tf_opamp(parts, opamp)[1])
    return parts.fn_hz / fo, parts.zeta / zo


@dataclass
class Choice:
    """The parts a spec gets: the build, the exact design it rounds, the ranked
    alternatives, and the targets aimed at (moved off by ``--compensate-gbw``)."""

    built: SallenKeyParts
    ideal: SallenKeyParts | None
    ratios: dict
    ranked: list
    notes: list
    fc_target_hz: float
    zeta_target: float


def choose_parts(spec: PlantSpec) -> Choice:
    """The E-series parts for a (validated) spec, without any analysis: what
    ``design-plant`` builds, and what ``design-pid`` needs of a designed plant."""
    amp = opamps.get(spec.opamp)
    rv = candidates(spec.r_series, spec.r_min, spec.r_max, "resistor")
    cv = candidates(spec.c_series, spec.c_min, spec.c_max, "capacitor")
    r3, r4, k = gain_resistors(spec.gain, spec)
    notes = realizability_notes(spec.fc_hz, spec.zeta, spec.gain, spec.c_min, spec.c_max)
    if k != spec.gain:
        notes.append(f"gain K = {spec.gain:g} realised as 1 + {r4:g}/{r3:g} = {k:.5g}")
    top = max(1, spec.alternatives)

    def select(fc_t, z_t):
        """Ranked E-series candidates, the exact design they round, and its ratios."""
        if spec.r is not None:
            # the seed's procedure: R and C fixed, m and n solved, each part rounded jointly
            m, n = ratios_from_rc(fc_t, z_t, spec.r, spec.c, k)
            ideal = SallenKeyParts(m * spec.r, spec.r, spec.c, n * spec.c, k, r3, r4)
            pool_r = np.unique(np.concatenate([around(ideal.r1, rv), around(ideal.r2, rv)]))
            pool_c = np.unique(np.concatenate([around(ideal.c1, cv), around(ideal.c2, cv)]))
            return brute_force(fc_t, z_t, pool_r, pool_c, k, top=4 * top), ideal, {"m": m, "n": n}
        ranked = joint_search(fc_t, z_t, rv, cv, k, top=4 * top)
        best = ranked[0]
        # the exact design the parts round: same capacitors, or, when their ratio is
        # below the unity-gain limit 1/zeta^2, the nearest ratio that has one
        c2 = best.c2 if k != 1.0 else max(best.c2, best.c1 / z_t ** 2 * (1 + 1e-12))
        lo, hi = resistors_for_caps(fc_t, z_t, best.c1, c2, k)
        roots = [float(x) for x in (lo, hi) if not math.isnan(float(x))]
        if not roots:
            return ranked, None, {"m": None, "n": None}
        r1 = min(roots, key=lambda r: abs(math.log(r / best.r1)))
        r2 = 1.0 / ((2 * math.pi * fc_t) ** 2 * best.c1 * c2 * r1)
        return ranked, SallenKeyParts(r1, r2, best.c1, c2, k, r3, r4), {"m": r1 / r2, "n": c2 / best.c1}

    fc_t, z_t = spec.fc_hz, spec.zeta
    ranked, ideal, ratios = select(fc_t, z_t)
    if spec.compensate_gbw:
        # aim off by the shift the op-amp causes on the parts chosen, and choose again;
        # the shift hardly depends on the parts, so two or three rounds settle it
        for _ in range(4):
            b = ranked[0]
            sf, sz = gbw_shift(SallenKeyParts(b.r1, b.r2, b.c1, b.c2, k, r3, r4), amp)
            new = (spec.fc_hz * sf, spec.zeta * sz)
            if abs(new[0] / fc_t - 1) < 1e-9 and abs(new[1] / z_t - 1) < 1e-9:
                break
            fc_t, z_t = new
            ranked, ideal, ratios = select(fc_t, z_t)
    ranked = _distinct(ranked, k)[:top]
    best = ranked[0]
    built = SallenKeyParts(best.r1, best.r2, best.c1, best.c2, k, r3, r4)
    if best.worst > MAX_ERROR:
        raise DesignError(_unreachable(spec, fc_t, best.worst))
    if spec.r is None and best.worst > NOTE_ERROR:
        notes += _bound_notes(spec, fc_t, z_t, k, best.worst)
    return Choice(built, ideal, ratios, ranked, notes, fc_t, z_t)


def design_plant(spec: PlantSpec, simulate: bool = True, simulator: str = "pyspice") -> PlantResult:
    """Design, analyse and (unless ``simulate`` is False) verify a plant."""
    tick = time.perf_counter()
    spec.validate()
    amp = opamps.get(spec.opamp)
    choice = choose_parts(spec)
    built, ideal, ratios, ranked, notes = choice.built, choice.ideal, choice.ratios, choice.ranked, choice.notes
    fc_t, z_t = choice.fc_target_hz, choice.zeta_target
    t_search = time.perf_counter() - tick
    result = _analyse(built, ideal, amp, spec.r_series, spec.c_series,
                      {"fc_hz": spec.fc_hz, "zeta": spec.zeta, "gain": spec.gain},
                      ratios, notes, spec.amplitude_v, spec.square_hz, simulate, simulator)
    result.alternatives = [_alt(c, spec.fc_hz, spec.zeta) for c in ranked]
    result.series["parts"] = {ref: {"series": spec.r_series if ref[0] == "R" else spec.c_series,
                                    "tolerance_pct": 100 * eseries.TOLERANCE[spec.r_series if ref[0] == "R"
                                                                             else spec.c_series]}
                              for ref in ("R1", "R2", "C1", "C2") + (("R3", "R4") if built.r3 is not None else ())}
    if spec.compensate_gbw:
        result.notes.append(f"--compensate-gbw: designed for fn {fc_t:.5g} Hz, zeta {z_t:.4g} so that with "
                            f"the {amp.name}'s {amp.gbw_hz / 1e6:g} MHz GBW it lands on the spec")
    elif not amp.ideal:
        e_fn, e_z = result.fn_opamp_hz / spec.fc_hz - 1, result.zeta_opamp / spec.zeta - 1
        if max(abs(e_fn), abs(e_z)) > NOTE_ERROR * 2:
            result.notes.append(
                f"with the {amp.name}'s {format_eng(amp.gbw_hz, 'Hz')} gain-bandwidth the circuit lands "
                f"{100 * e_fn:+.3g} % off in fn and {100 * e_z:+.3g} % in zeta; --compensate-gbw aims the "
                "design off so that it lands on the spec (or choose a faster --opamp)")
    result.timings = {"search_s": t_search, **result.timings}
    return result


def analyze_plant(parts: SallenKeyParts, opamp: str = "LM741", target_fc=None, target_zeta=None,
                  r_series: str | None = None, c_series: str | None = None, amplitude_v: float = 2.0,
                  square_hz=None, simulate: bool = True, simulator: str = "pyspice") -> PlantResult:
    """Analyse parts as built (e.g. the seed's rounded 820/1k/10n/220n).

    ``r_series``/``c_series``: where the parts come from, for their tolerance;
    None labels each part with the smallest series that holds its value.
    """
    parts = check_parts(parts)
    for name, v, key in (("target fc", target_fc, "fc_hz"), ("target zeta", target_zeta, "zeta")):
        if v is not None:
            RANGES[key].check(v, name)
    RANGES["amplitude_v"].check(amplitude_v, "amplitude")
    if square_hz is not None:
        RANGES["square_hz"].check(square_hz, "square-wave frequency")
    amp = opamps.get(opamp)
    spec = {"fc_hz": target_fc, "zeta": target_zeta, "gain": parts.gain}
    notes = [f"these parts give fn = {parts.fn_hz:.5g} Hz and zeta = {parts.zeta:.4g} (Q = {parts.q:.4g})"]
    values = {"R1": parts.r1, "R2": parts.r2, "C1": parts.c1, "C2": parts.c2}
    if parts.r3 is not None:
        values.update(R3=parts.r3, R4=parts.r4)
    labels, r_s, c_s, why = part_series(values, r_series, c_series)
    notes += why
    res = _analyse(parts, None, amp, r_s, c_s, spec, {"m": parts.r1 / parts.r2, "n": parts.c2 / parts.c1},
                   notes, amplitude_v, square_hz, simulate, simulator)
    res.series["parts"] = labels
    res.mode = "analyze"
    return res


#: what an unlabelled part is assumed to be: a 5 % resistor, a 10 % capacitor
DEFAULT_SERIES = {"R": "E24", "C": "E12"}


def part_series(values: dict, r_series=None, c_series=None):
    """Each part's series label and tolerance, and the series whose tolerance the band
    uses (the loosest part's, worst case).

    With a series given, every part of that kind is from it. Without, a part is
    labelled with the smallest series that holds its value ("not a standard value"
    when none does) and assumed at least as tight as the default E24 resistor /
    E12 capacitor: a 1k from a 5 % kit is not a 40 % E3 part, but a 1k26 exists
    only as an E192 (0.5 %) part.

    Returns (labels {ref: {"series", "tolerance_pct"}}, r band series, c band series, notes).
    """
    order = list(eseries.SERIES)
    given = {"R": None if r_series is None else eseries.series_name(r_series),
             "C": None if c_series is None else eseries.series_name(c_series)}
    labels, band, notes = {}, {"R": None, "C": None}, []
    for ref, v in values.items():
        kind = ref[0]
        found = eseries.smallest_series(v)
        if given[kind] is not None:
            series = given[kind]
            label = series if found is not None and order.index(found) <= order.index(series) \
                else f"{series} (not an {series} value)"
        elif found is None:
            series, label = DEFAULT_SERIES[kind], "not a standard value"
            unit = "Ohm" if kind == "R" else "F"
            notes.append(f"{ref} = {format_eng(v, unit)} is not a standard E-series value; its tolerance is "
                         f"taken as {100 * eseries.TOLERANCE[series]:g} %")
        else:
            series = order[max(order.index(found), order.index(DEFAULT_SERIES[kind]))]
            label = found
        labels[ref] = {"series": label, "tolerance_pct": 100 * eseries.TOLERANCE[series]}
        if band[kind] is None or eseries.TOLERANCE[series] > eseries.TOLERANCE[band[kind]]:
            band[kind] = series
    return labels, band["R"] or DEFAULT_SERIES["R"], band["C"] or DEFAULT_SERIES["C"], notes


#: a design further off than this is refused, with the reason
MAX_ERROR = 0.05
#: a design further off than this says which bound holds it back (and, at twice it,
#: that the op-amp's gain-bandwidth moves it)
NOTE_ERROR = 0.005


def _bound_notes(spec: PlantSpec, fc: float, zeta: float, gain: float, worst: float) -> list:
    """Which part bound keeps the design ``worst`` off. Each bound is relaxed by a
    decade (within the physical ranges) and the search run again; where that at
    least halves the error, the bound is named with the mildest series value
    that gets nearly all of the gain (bisection over the values in between: the
    error only falls as a bound is relaxed)."""
    from dataclasses import replace as _replace
    out = []
    tries = (("--r-min", "r_min", 0.1, "resistor_ohm", "Ohm", "r_series"),
             ("--r-max", "r_max", 10.0, "resistor_ohm", "Ohm", "r_series"),
             ("--c-min", "c_min", 0.1, "capacitor_f", "F", "c_series"),
             ("--c-max", "c_max", 10.0, "capacitor_f", "F", "c_series"))

    def best_with(attr, value):
        s2 = _replace(spec, **{attr: value})
        rv = eseries.values(s2.r_series, s2.r_min, s2.r_max)
        cv = eseries.values(s2.c_series, s2.c_min, s2.c_max)
        return joint_search(fc, zeta, rv, cv, gain, top=1)[0].worst if rv.size and cv.size else math.inf

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


def _unreachable(spec: PlantSpec, fc: float, worst: float) -> str:
    """Why no combination within the bounds comes close, and what to change."""
    head = (f"no {spec.r_series}/{spec.c_series} combination within the bounds comes within "
            f"{100 * MAX_ERROR:g} % of the target (best: {100 * worst:.3g} % off)")
    rc = 1.0 / (2 * math.pi * fc)
    if rc < spec.r_min * spec.c_min:
        return (f"{head}: fc {fc:.4g} Hz needs R*C near {rc:.3g} s but the bounds allow no less than "
                f"{spec.r_min * spec.c_min:.3g} s; lower --r-min or --c-min")
    if rc > spec.r_max * spec.c_max:
        return (f"{head}: fc {fc:.4g} Hz needs R*C near {rc:.3g} s but the bounds allow no more than "
                f"{spec.r_max * spec.c_max:.3g} s; raise --r-max or --c-max")
    if spec.gain == 1.0 and 1 / spec.zeta ** 2 > spec.c_max / spec.c_min:
        return (f"{head}: unity gain needs C2/C1 >= 1/zeta^2 = {1 / spec.zeta ** 2:.4g}; "
                f"use --gain K > 1 or widen --c-min/--c-max")
    return f"{head}; widen the bounds or use a finer series (--r-series/--c-series)"


def _alt(c, fc, zeta):
    return {"R1_ohm": c.r1, "R2_ohm": c.r2, "C1_f": c.c1, "C2_f": c.c2, "fn_hz": c.fn_hz,
            "zeta": c.zeta, "fn_error_pct": _pct(c.fn_hz, fc), "zeta_error_pct": _pct(c.zeta, zeta)}


def _distinct(ranked, gain):
    """For unity gain R1 and R2 can swap without changing anything: list each build once."""
    seen, out = set(), []
    for c in ranked:
        key = (tuple(sorted((c.r1, c.r2))) if gain == 1.0 else (c.r1, c.r2), c.c1, c.c2)
        if key not in seen:
            seen.add(key)
            out.append(c)
    return out


def _analyse(built, ideal, amp, r_series, c_series, spec, ratios, notes, amplitude_v, square_hz,
             simulate, simulator) -> PlantResult:
    tick = time.perf_counter()
    num_i, den_i = plant_tf(built)
    num_o, den_o = plant_tf_opamp(built, amp)
    fn_o, z_o = dominant_pair(den_o)
    span = response_span(min(built.fn_hz, fn_o), min(built.zeta, z_o))
    t = dense_time(span)
    y_i = step_response(num_i, den_i, t)
    y_o = step_response(num_o, den_o, t)
    k_i = float(num_i[-1] / den_i[-1])
    k_o = float(num_o[-1] / den_o[-1])
    m_i = step_metrics(t, y_i, final=k_i)
    m_o = step_metrics(t, y_o, final=k_o)
    # the response's fastest time scale (1/wn, or the fast real pole) bounds the simulation step
    time_scale = 1.0 / float(np.max(np.abs(np.roots(den_i))))
    test = recommend_square_wave(m_o.settling_time_s, amplitude_v, square_hz, time_scale_s=time_scale)
    if simulate:
        test.check_simulable()
    # the comparisons and plots use the rising half period of the bench test (its start, if
    # the square wave is much slower than the response: a dense grid where the metrics are taken)
    tw = dense_time(min(test.half_period_s, 4 * span))
    y_iw, y_ow = step_response(num_i, den_i, tw), step_response(num_o, den_o, tw)
    checks = signal_checks(tw, y_ow, amplitude_v, amp)
    if test.half_period_s < m_o.settling_time_s:
        checks.append({"name": "square-wave period", "ok": False,
                       "detail": f"half period {test.half_period_s * 1e6:.4g} us is shorter than the 2 % settling "
                                 f"time {m_o.settling_time_s * 1e6:.4g} us: the scope will not show a settled step"})
    sens = sensitivities(built)
    sens_o = sensitivities(built, amp)
    tol = tolerance_band(built, eseries.TOLERANCE[r_series], eseries.TOLERANCE[c_series], tw[-1])
    timings = {"analytic_s": time.perf_counter() - tick}
    result = PlantResult(
        spec=spec, ratios=ratios, ideal=ideal, built=built, opamp=amp,
        series={"r": r_series, "c": c_series, "r_tolerance_pct": 100 * eseries.TOLERANCE[r_series],
                "c_tolerance_pct": 100 * eseries.TOLERANCE[c_series]},
        alternatives=[], notes=list(notes), fn_opamp_hz=fn_o, zeta_opamp=z_o,
        analytic=_metrics_dict(m_i), analytic_opamp=_metrics_dict(m_o), spice=None, comparison={},
        sensitivity=sens, sensitivity_opamp=sens_o, tolerance=tol, test=test, checks=checks,
        waveforms={"t": tw, "analytic": y_iw * amplitude_v, "analytic_opamp": y_ow * amplitude_v,
                   "bode": (num_i, den_i, num_o, den_o)},
        timings=timings)
    tick = time.perf_counter()
    result.deck = plant_deck(built, amp, test, _title(built, amp))
    result.timings["netlist_s"] = time.perf_counter() - tick
    if simulate:
        run_spice(result, simulator, k_o)
    else:
        result.notes.append("SPICE simulation skipped (--no-sim): the figures are analytic only")
    return result


def bench_waveforms(result, n: int = 4001) -> dict:
    """The whole simulated bench period (rising and falling edge) on a uniform
    grid: input, the analytic responses (by superposition of two steps) and,
    when simulated, SPICE. Keys are the CSV column names."""
    test = result.test
    t = np.linspace(0.0, test.stop_s, n)
    u = np.where((t >= test.delay_s) & (t < test.delay_s + test.half_period_s), test.amplitude_v, 0.0)
    num_i, den_i, num_o, den_o = result.waveforms["bode"]

    def square(num, den):
        up = np.clip(t - test.delay_s, 0.0, None)
        down = np.clip(t - test.delay_s - test.half_period_s, 0.0, None)
        y = step_response(num, den, up) * (t >= test.delay_s)
        return test.amplitude_v * (y - step_response(num, den, down) * (t >= test.delay_s + test.half_period_s))

    cols = {"time_s": t, "input_v": u, "analytic_v": square(num_i, den_i),
            "analytic_opamp_v": square(num_o, den_o)}
    if "spice_period" in result.waveforms:
        ts, ys, us = result.waveforms["spice_period"]
        cols["input_v"] = resample(ts, us, t)
        cols["output_v"] = resample(ts, ys, t)
    else:
        cols["output_v"] = cols["analytic_opamp_v"]
    return cols


def _title(parts, amp):
    return (f"Sallen-Key low-pass plant fn={parts.fn_hz:.5g}Hz zeta={parts.zeta:.4g} "
            f"K={parts.gain:.4g} op-amp={amp.name}")


def _metrics_dict(m) -> dict:
    d = m.to_dict()
    return {"overshoot_pct": d["overshoot_pct"], "peak_time_s": d["peak_time_s"],
            "rise_time_s": d["rise_time_s"], "settling_time_s": d["settling_time_s"],
            "settling_time_5pct_s": d["settling_time_5pct_s"], "rise_time_0_100_s": d["rise_time_0_100_s"],
            "peak_value": d["peak_value"], "final_value": d["final_value"]}


def run_spice(result: PlantResult, simulator: str, dc_gain_opamp: float) -> None:
    """Simulate the deck and compare SPICE with both analytic models."""
    tick = time.perf_counter()
    sim = get_simulator(simulator)
    res = sim.run(result.deck)
    test = result.test
    t, y = res["time"], res["v(out)"]
    tw = result.waveforms["t"]
    y_s = resample(t, y, tw + test.delay_s)
    amp_v = test.amplitude_v
    m_s = step_metrics(tw, y_s / amp_v, final=dc_gain_opamp)
    spice = _metrics_dict(m_s)
    abstol = 0.01 * abs(result.built.gain * amp_v)
    spice["nrms"] = nrms(result.waveforms["analytic_opamp"], y_s, abstol)
    spice["nrms_ideal"] = nrms(result.waveforms["analytic"], y_s, abstol)
    spice["measurements"] = res.measurements
    result.spice = spice
    result.simulator = sim.name
    from ..core.metrics import StepMetrics
    def sm(d):
        return StepMetrics(**{k: (math.nan if d.get(k) is None else d[k]) for k in StepMetrics.__dataclass_fields__})
    ref = sm(result.analytic_opamp)
    deltas = metric_deltas(ref, m_s)
    z = min(result.zeta_opamp, 0.999)
    half_ring = 0.5 / (result.fn_opamp_hz * math.sqrt(1 - z * z)) if result.zeta_opamp < 1 else 0.0
    off = disagreements(deltas, ref, half_ring)
    if spice["nrms"] >= 1.0:
        off.insert(0, f"waveform NRMS {spice['nrms']:.3g} (allowed below 1)")
    result.comparison = {
        "spice_vs_analytic": metric_deltas(sm(result.analytic), m_s),
        "spice_vs_analytic_opamp": deltas,
        "nrms_abstol_v": abstol,
        "pass": not off,
        "disagreements": off,
    }
    if off:
        result.notes.append("SPICE disagrees with the op-amp-aware model: " + "; ".join(off))
    result.waveforms["spice"] = y_s
    result.waveforms["spice_period"] = (t, y, res["input"])
    result.timings["simulation_s"] = time.perf_counter() - tick
