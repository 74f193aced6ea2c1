"""From a plant and a tuning choice to a sized, checked and SPICE-verified
op-amp PID controller: the orchestration behind ``design-pid``.

:func:`design_pid` returns a :class:`PidResult`; its ``to_dict`` is the JSON of
``design-pid --json`` and ``result.json``.
"""

from __future__ import annotations

import json
import math
import time
from dataclasses import dataclass, field
from pathlib import Path

import numpy as np
from scipy import signal

from ..core import eseries, opamps
from ..core.errors import DesignError
from ..core.jsonio import json_safe
from ..core.lti import dominant_pair, response_span
from ..core.opamps import OpAmp
from ..core.ranges import RANGES
from ..core.units import format_eng
from ..plant.bench import recommend_square_wave
from ..plant.model import plant_tf, plant_tf_opamp
from ..plant.sallenkey import SallenKeyParts, check_parts
from ..spice.deck import SquareTest
from . import blocks, model, tuning
from .netlist import closed_loop_deck
from .verify import loop_metrics

#: phase margin below which the loop is called under-damped on the bench
MIN_PHASE_MARGIN_DEG = 30.0
#: largest acceptable steady-state error of the leaky-integrator loop
MAX_STEADY_STATE_ERROR = 0.02


@dataclass
class PidSpec:
    """What the user asked for (SI units)."""

    plant_fc_hz: float | None = None
    plant_zeta: float | None = None
    plant_parts: SallenKeyParts | None = None
    plant_json: str | None = None
    tuning: str | None = None          #: rule name, "optimize", or None (zn, or explicit if given)
    kp: float | None = None
    ti_s: float | None = None
    td_s: float | None = None
    opamp: str = "LM741"
    step_v: float = 1.0
    edge_s: float = 100e-9
    r_series: str = "E24"
    c_series: str = "E12"
    r_min: float = 1e3
    r_max: float = 1e6
    c_min: float = 1e-9
    c_max: float = 10e-6
    target_overshoot_pct: float | None = None
    target_settling_s: float | None = None
    f_integrator_hz: float | None = None
    f_differentiator_hz: float | None = None
    square_hz: float | None = None
    controller_parts: blocks.PidParts | None = None   #: skip sizing (e.g. the seed's own parts)
    tol: float = 0.01
    _json_plant: SallenKeyParts | None = field(default=None, init=False, repr=False)

    def validate(self) -> None:
        """Refuse, in one line, anything outside :data:`designer.ranges.RANGES` or
        inconsistent, before any work; the plant's parts go through
        :func:`designer.plant.sallenkey.check_parts` (the one plant validation)."""
        sources = sum(x is not None for x in (self.plant_fc_hz, self.plant_parts, self.plant_json))
        if sources != 1:
            raise DesignError("give the plant one way: --plant-fc/--plant-zeta, --plant-r1..--plant-c2, "
                              "or --plant-json")
        if self.plant_fc_hz is not None:
            if self.plant_zeta is None:
                raise DesignError("--plant-fc needs --plant-zeta")
            _check("fc_hz", self.plant_fc_hz, "--plant-fc")
            _check("zeta", self.plant_zeta, "--plant-zeta")
        elif self.plant_zeta is not None:
            raise DesignError("--plant-zeta needs --plant-fc")
        if self.plant_parts is not None:
            self.plant_parts = check_parts(self.plant_parts, name_of=PLANT_FLAGS)
        if self.plant_json is not None:
            self._json_plant = plant_from_json(self.plant_json)   # read and checked now, not after work
        opamps.get(self.opamp)
        for key, flag in (("r_min", "--r-min"), ("r_max", "--r-max")):
            _check("resistor_ohm", getattr(self, key), flag)
        for key, flag in (("c_min", "--c-min"), ("c_max", "--c-max")):
            _check("capacitor_f", getattr(self, key), flag)
        self.r_series, self.c_series = eseries.check_bounds(
            self.r_series, self.c_series, self.r_min, self.r_max, self.c_min, self.c_max)
        _check("step_v", self.step_v, "--step")
        _check("edge_s", self.edge_s, "--edge")
        explicit = [v is not None for v in (self.kp, self.ti_s, self.td_s)]
        if any(explicit) and not all(explicit):
            raise DesignError("--kp, --ti and --td go together (give all three)")
        if all(explicit):
            if self.tuning not in (None, "explicit"):
                raise DesignError(f"--tuning {self.tuning} and explicit --kp/--ti/--td exclude each other")
            tuning.explicit(self.kp, self.ti_s, self.td_s)
        elif self.tuning not in (None, "optimize") and self.tuning not in tuning.RULES:
            raise DesignError(f"unknown --tuning {_short(self.tuning)}; allowed: {', '.join(tuning.RULES)}, "
                              "optimize")
        if self.tuning == "optimize":
            if self.target_overshoot_pct is None:
                raise DesignError("--tuning optimize needs --target-overshoot P (percent)")
            _check("target_overshoot_pct", self.target_overshoot_pct, "--target-overshoot")
            if self.target_settling_s is not None:
                _check("target_settling_s", self.target_settling_s, "--target-settling")
        elif self.target_overshoot_pct is not None or self.target_settling_s is not None:
            raise DesignError("--target-overshoot/--target-settling only apply to --tuning optimize")
        for key, flag in (("f_integrator_hz", "--f-integrator"), ("f_differentiator_hz", "--f-differentiator"),
                          ("square_hz", "--square-freq")):
            if getattr(self, key) is not None:
                _check(key, getattr(self, key), flag)


#: how design-pid names the plant's fields in messages (see check_parts)
PLANT_FLAGS = {"r1": "--plant-r1", "r2": "--plant-r2", "c1": "--plant-c1", "c2": "--plant-c2",
               "gain": "--plant-gain", "r3": "R3", "r4": "R4", "plant": "--plant-r1..--plant-c2"}


def _check(key: str, value, flag: str) -> float:
    """``value`` inside ``RANGES[key]`` (a number), else one line naming ``flag``."""
    if isinstance(value, bool) or not isinstance(value, (int, float)):
        raise DesignError(f"{flag} must be a number, got {_short(value)}")
    return RANGES[key].check(float(value), flag)


def _short(value) -> str:
    """A value for a one-line message: short, no newlines, no numpy repr."""
    text = repr(value) if isinstance(value, str) else type(value).__name__
    return text if len(text) <= 40 else text[:37] + "..."


@dataclass
class PidResult:
    """Everything known about one controller design; ``to_dict`` is the JSON."""

    spec: PidSpec
    plant: SallenKeyParts
    plant_source: str
    opamp: OpAmp
    tuning: tuning.Tuning
    rules: list
    parts: blocks.PidParts
    selection: blocks.Selection | None
    checks: list
    analytic: dict
    ideal_pid: dict
    margins: dict
    levels: dict
    test: SquareTest
    expected_final_v: float
    deck: str
    spice: dict | None = None
    spice_levels: dict | None = None
    verdict: dict | None = None
    optimizer: dict | None = None
    notes: list = field(default_factory=list)
    waveforms: dict = field(default_factory=dict, repr=False)
    files: dict = field(default_factory=dict)
    timings: dict = field(default_factory=dict)
    simulator: str | None = None

    def achieved(self) -> dict:
        p = self.parts
        ng = p.noise_gains()
        bw = p.stage_bandwidths(self.opamp.gbw_hz)
        d = {"kp": p.kp, "ti_s": p.ti_s, "td_s": p.td_s,
             "f_integrator_hz": p.f_integrator_hz,
             "f_differentiator_hz": p.f_differentiator_hz if p.has_derivative else None,
             "f_summer_hz": bw["summer"], "integrator_dc_gain": p.integrator_dc_gain,
             "noise_gains": ng, "stage_bandwidths_hz": bw}
        t = self.tuning
        d["errors_pct"] = {"kp": 100 * (p.kp / t.kp - 1), "ti": 100 * (p.ti_s / t.ti_s - 1),
                           "td": 100 * (p.td_s / t.td_s - 1) if t.td_s > 0 else None}
        return d

    def to_dict(self) -> dict:
        pl = self.plant
        amp = self.opamp
        sel = self.selection
        spice = None
        if self.spice is not None:
            spice = {**self.spice, "backend": self.simulator}
        out = {
            "plant": {"source": self.plant_source, **pl.as_dict(), "q": pl.q,
                      "fn_opamp_hz": self.waveforms.get("plant_fn_opamp_hz"),
                      "zeta_opamp": self.waveforms.get("plant_zeta_opamp")},
            "opamp": {"name": amp.name, "gbw_hz": amp.gbw_hz, "slew_v_per_s": amp.slew_v_per_s, "a0": amp.a0,
                      "vcc": amp.vcc, "vee": amp.vee, "vout_max": amp.vout_max, "vout_min": amp.vout_min},
            "tuning": self.tuning.to_dict(),
            "rules": self.rules,
            "optimizer": self.optimizer,
            "components": self.parts.to_dict(),
            "series": None if sel is None else {
                "r": sel.r_series, "c": sel.c_series,
                "r_tolerance_pct": 100 * eseries.TOLERANCE[sel.r_series],
                "c_tolerance_pct": 100 * eseries.TOLERANCE[sel.c_series],
                "best_possible_error_pct": sel.best_possible_pct, "candidates": sel.candidates},
            "achieved": self.achieved(),
            "checks": self.checks,
            "closed_loop": {"analytic": self.analytic, "ideal_pid": self.ideal_pid, "spice": spice,
                            "margins": self.margins, "verdict": self.verdict},
            "levels": {"analytic": self.levels, "spice": self.spice_levels},
            "test_signal": {"kind": "square", "low_v": 0.0, "high_v": self.test.amplitude_v,
                            "frequency_hz": self.test.frequency_hz, "edge_s": self.test.edge_s,
                            "expected_final_v": self.expected_final_v},
            "notes": self.notes,
            "simulator": self.simulator,
            "files": self.files,
        }
        return json_safe(out)


# ---- plant ------------------------------------------------------------------

def plant_from_json(path) -> SallenKeyParts:
    """The built plant of a ``design-plant``/``analyze-plant`` result.json,
    through the one plant validation (:func:`designer.plant.sallenkey.check_parts`):
    values of the wrong type, out of range, a gain that disagrees with R3/R4 or
    an unstable circuit are refused in one line naming the file and the key."""
    p = Path(path)
    shown = _short(str(p))
    try:
        data = json.loads(p.read_text(encoding="utf-8"))
    except OSError as exc:
        raise DesignError(f"--plant-json: cannot read {shown}: {exc.strerror or exc}") from None
    except UnicodeDecodeError:
        raise DesignError(f"--plant-json: {shown} is not UTF-8 text (expected a design-plant result.json)") \
            from None
    except (json.JSONDecodeError, RecursionError):
        raise DesignError(f"--plant-json: {shown} is not JSON (expected a design-plant result.json)") from None
    built = data.get("built") if isinstance(data, dict) else None
    keys = {"r1": "R1_ohm", "r2": "R2_ohm", "c1": "C1_f", "c2": "C2_f", "gain": "gain", "r3": "R3_ohm",
            "r4": "R4_ohm"}
    if not isinstance(built, dict) or not all(keys[k] in built for k in ("r1", "r2", "c1", "c2")):
        raise DesignError(f"--plant-json: {shown} is not a design-plant result "
                          "(no 'built' object with R1_ohm, R2_ohm, C1_f, C2_f)")
    raw = SallenKeyParts(*(built.get(keys[k]) for k in ("r1", "r2", "c1", "c2", "gain", "r3", "r4")))
    names = {k: f"--plant-json {shown}: built.{v}" for k, v in keys.items()}
    names["plant"] = f"--plant-json {shown}"
    return check_parts(raw, name_of=names)


def resolve_plant(spec: PidSpec):
    """(parts, description) of the plant, designed or given, validated by
    :func:`designer.plant.sallenkey.check_parts` however it arrives."""
    if spec.plant_parts is not None:
        return check_parts(spec.plant_parts, name_of=PLANT_FLAGS), "parts"
    if spec.plant_json is not None:
        parts = spec._json_plant if spec._json_plant is not None else plant_from_json(spec.plant_json)
        return parts, f"json:{spec.plant_json}"
    from ..plant.design import PlantSpec, choose_parts
    ps = PlantSpec(fc_hz=spec.plant_fc_hz, zeta=spec.plant_zeta, opamp=spec.opamp,
                   r_series=spec.r_series, c_series=spec.c_series, r_min=spec.r_min, r_max=spec.r_max,
                   c_min=spec.c_min, c_max=spec.c_max, alternatives=1)
    ps.validate()
    res = choose_parts(ps)   # the parts only: no analysis, no deck
    what = f"the plant designed for --plant-fc {spec.plant_fc_hz:g} --plant-zeta {spec.plant_zeta:g}"
    built = check_parts(res.built, name_of={k: f"{what}: {v}" for k, v in
                                            (("r1", "R1"), ("r2", "R2"), ("c1", "C1"), ("c2", "C2"),
                                             ("r3", "R3"), ("r4", "R4"), ("gain", "gain K"))} | {"plant": what})
    return built, f"design-plant fc={spec.plant_fc_hz:g} Hz zeta={spec.plant_zeta:g}"


def plant_model(parts: SallenKeyParts, amp: OpAmp):
    return plant_tf(parts) if amp.ideal else plant_tf_opamp(parts, amp)


# ---- the flow ----------------------------------------------------------------

def design_pid(spec: PidSpec, simulate: bool = True, simulator: str = "pyspice") -> PidResult:
    """Tune, size, check, and (unless ``simulate`` is False) verify in SPICE."""
    tick = time.perf_counter()
    timings = {}
    spec.validate()
    amp = opamps.get(spec.opamp)
    plant, source = resolve_plant(spec)
    pn, pd = plant_model(plant, amp)
    fn_o, z_o = dominant_pair(pd)
    dc = float(pn[-1] / pd[-1])
    span = response_span(min(plant.fn_hz, fn_o), min(plant.zeta, z_o))
    # reaction curve of the plant as built (with its op-amp), on a dense grid
    tp = np.linspace(0.0, span, 20001)
    _, yp = signal.step((pn, pd), T=tp)
    curve = tuning.reaction_curve(tp, yp, final=dc)
    rules = [r.to_dict(brief=True) for r in tuning.all_rules(curve)]
    notes = []
    opt = presized = None
    timings["plant_s"] = time.perf_counter() - tick
    tick = time.perf_counter()
    if spec.kp is not None:
        tun = tuning.explicit(spec.kp, spec.ti_s, spec.td_s)
        tun = tuning.Tuning("explicit", tun.kp, tun.ti_s, tun.td_s, curve, ())
    elif spec.tuning == "optimize":
        tun, opt, presized = _optimize(spec, plant, amp, pn, pd, curve, span)
        notes.append(f"optimize: {opt['message']} after {opt['evaluations']} closed-loop evaluations")
    else:
        tun = tuning.tune(spec.tuning or "zn", curve)
    notes += list(tun.notes)
    if tun.method == "zn":
        notes.append(f"ZN reaction curve: inflection at {format_eng(curve.t_inflection_s, 's')}, "
                     f"L = {format_eng(curve.L_s, 's')}, T = {format_eng(curve.T_s, 's')} (from L to where the "
                     f"tangent reaches the final value, {format_eng(curve.t_tangent_final_s, 's')}; the seed "
                     "used that absolute time as T)")
    timings["tuning_s"] = time.perf_counter() - tick
    tick = time.perf_counter()
    if spec.controller_parts is not None:
        parts, sel = spec.controller_parts, None
        targets = {"kp": tun.kp, "ti_s": tun.ti_s, "td_s": tun.td_s}
    else:
        sel = presized or _select(spec, tun, plant)
        parts, targets = sel.parts, sel.targets
        notes += sel.notes
    checks = blocks.static_checks(parts, plant.fn_hz, amp.gbw_hz, targets, r_min=spec.r_min,
                                  r_max=spec.r_max, c_min=spec.c_min, c_max=spec.c_max, tol=spec.tol)
    timings["sizing_s"] = time.perf_counter() - tick
    tick = time.perf_counter()
    res = _analyse(spec, plant, source, amp, tun, rules, parts, sel, checks, pn, pd, span, notes, simulate)
    res.optimizer = opt
    res.waveforms.update(plant_fn_opamp_hz=fn_o, plant_zeta_opamp=z_o, reaction_curve=(tp, yp))
    timings["analytic_s"] = time.perf_counter() - tick
    res.timings = timings
    if simulate:
        run_spice(res, simulator)
    else:
        res.notes.append("SPICE simulation skipped (--no-sim): the closed-loop figures are analytic only")
    return res


def _select(spec, tun, plant):
    return blocks.select_parts(tun.kp, tun.ti_s, tun.td_s, plant.fn_hz, r_series=spec.r_series,
                               c_series=spec.c_series, r_min=spec.r_min, r_max=spec.r_max,
                               c_min=spec.c_min, c_max=spec.c_max, f_integrator_hz=spec.f_integrator_hz,
                               f_differentiator_hz=spec.f_differentiator_hz, tol=spec.tol)


def _optimize(spec, plant, amp, pn, pd, curve, span):
    """Optimise on unrounded parts, size with E-series parts, and check the
    sized circuit in the same model; if rounding pushed it over the slew or
    swing budget, optimise again with a wider margin (at most three rounds)."""
    from . import optimize as O
    t = np.linspace(0.0, 0.6 * span, 2001)
    ctx = O.Context(pn, pd, amp, plant.fn_hz, spec.step_v, spec.edge_s, t, spec.target_overshoot_pct,
                    spec.target_settling_s, spec.f_integrator_hz, spec.f_differentiator_hz)
    # starting points only: ZN's gains and the gentler CHR 0 % formulas on the same
    # tangent (half ZN's Kp, Ti = T); they bracket a working loop even for an underdamped
    # plant, where the rules on the fitted FOPDT can start from an unstable one
    starts = []
    for rule in ("zn", "chr0"):
        r = tuning.tune(rule, curve.tangent)
        starts.append((r.kp, r.ti_s, r.td_s if r.td_s > 0 else 0.3 * curve.L_s))
    fine = O.Context(pn, pd, amp, plant.fn_hz, spec.step_v, spec.edge_s, np.linspace(0.0, 0.6 * span, 20001),
                     spec.target_overshoot_pct, spec.target_settling_s, spec.f_integrator_hz,
                     spec.f_differentiator_hz)
    evaluations = 0
    for attempt in range(3):
        res = O.optimize(ctx, starts)
        evaluations += res.evaluations
        b = res.best
        sel = _select(spec, tuning.Tuning("optimize", b.kp, b.ti_s, b.td_s), plant)
        # the optimiser's coarse grid under-reads short slewing: check the sized
        # circuit on the fine grid the final checks use
        sized = O.evaluate_parts(sel.parts, fine)
        if not res.met or O.meets(sized, fine):
            break
        ctx.slew_limit *= 0.85
        ctx.swing_limit *= 0.9
        starts = [(b.kp, b.ti_s, b.td_s)]
    res.evaluations = evaluations
    note = (f"optimize: target overshoot <= {spec.target_overshoot_pct:g} %"
            + ("" if spec.target_settling_s is None else f", settling <= {format_eng(spec.target_settling_s, 's')}")
            + f" for a {spec.step_v:g} V step with {amp.name} limits")
    out = res.to_dict()
    out["sized"] = sized.to_dict()
    out["rounds"] = attempt + 1
    return tuning.Tuning("optimize", b.kp, b.ti_s, b.td_s, curve, (note,)), out, sel


def _analyse(spec, plant, source, amp, tun, rules, parts, sel, checks, pn, pd, span, notes,
             simulate=True) -> PidResult:
    lm = model.assemble(parts, amp, pn, pd)
    stable = lm.stable()
    # closed-loop DC gain y/r from the state-space model (the integrator leaks)
    iy = model.SIGNALS.index("y")
    try:
        dc_cl = float(-(lm.c[iy] @ np.linalg.solve(lm.a, lm.b)).item() + lm.d[iy, 0])
    except np.linalg.LinAlgError:
        dc_cl = math.nan
    # the settled output every figure and the deck's .meas levels refer to (verify.loop_metrics)
    expected = spec.step_v * dc_cl if math.isfinite(dc_cl) and dc_cl > 0 else spec.step_v
    # a first look on a long grid for the settling time, to size the square wave
    t_long = np.linspace(0.0, span, 8001)
    ts = None
    if stable:
        w_long = lm.simulate(t_long, model.reference(t_long, 1.0, 0.0, spec.edge_s))
        ts = loop_metrics(t_long, w_long["y"], expected / spec.step_v).get("settling_time_s")
    if ts is None:
        ts = span / 2
    f_lo = min(parts.f_integrator_hz, plant.fn_hz) / 20
    f_hi = max(amp.gbw_hz if not amp.ideal else 0.0, 100 * plant.fn_hz)
    w = 2 * np.pi * np.logspace(np.log10(f_lo), np.log10(f_hi), 4000)
    mg = model.margins(w, model.loop_gain(parts, amp, pn, pd, w))
    # the loop's fastest time scale (plant or crossover) bounds the simulation step, so that a
    # slow --square-freq cannot hide the response between time steps (as for the plant)
    f_fast = max(plant.fn_hz, mg["crossover_hz"] if math.isfinite(mg.get("crossover_hz") or math.nan) else 0.0)
    time_scale = 1.0 / (2 * math.pi * f_fast)
    sq = recommend_square_wave(ts, spec.step_v, spec.square_hz, time_scale_s=time_scale)
    hp = sq.half_period_s
    test = SquareTest(spec.step_v, sq.frequency_hz, sq.delay_s, spec.edge_s, time_scale_s=time_scale)
    if simulate:
        test.check_simulable()
    # the rising half period, or its start when the square wave is much slower than the loop
    t = np.linspace(0.0, min(hp, 10 * max(span, ts)), 20001)
    r = model.reference(t, spec.step_v, 0.0, spec.edge_s)
    rails = 2 * max(abs(amp.vcc), abs(amp.vee))
    waves = lm.simulate(t, r) if stable else _diverging(lm, t, r, rails)
    il = model.ideal_loop(tun.kp, tun.ti_s, tun.td_s, *plant_tf(plant))
    y_ideal = (il.simulate(t, r) if il.stable() else _diverging(il, t, r, rails))["y"]
    _, y_open, _ = signal.lsim((pn, pd), r, t)
    analytic = loop_metrics(t, waves["y"], expected)
    analytic.update(stable=stable, dc_gain=dc_cl, steady_state_error_pct=100 * (1 - dc_cl))
    ideal = loop_metrics(t, y_ideal, spec.step_v)   # a true integrator: no steady-state error
    rise = analytic.get("rise_time_s") or (hp / 20)
    levels = model.waveform_limits(waves, t, amp, model.SLEW_DELAY_FRACTION * rise) if stable else {}
    checks = list(checks) + _dynamic_checks(stable, lm, levels, mg, dc_cl, amp, spec.step_v, rise, parts)
    limits = {"closed_loop_stable", "phase_margin", "slew_rate", "output_swing"}
    if not amp.ideal and any(not c["ok"] for c in checks if c["name"] in limits):
        notes.append(f"to have gains chosen for the loop as built with {amp.name}s (stable with the op-amp poles, "
                     "every op-amp inside its swing and slew rate for this step): --tuning optimize "
                     "--target-overshoot P")
    title = (f"PID closed loop Kp={parts.kp:.4g} Ti={parts.ti_s:.4g}s Td={parts.td_s:.4g}s "
             f"plant fn={plant.fn_hz:.5g}Hz zeta={plant.zeta:.4g} op-amp={amp.name}")
    deck = closed_loop_deck(parts, plant, amp, test, title, expected)
    res = PidResult(spec=spec, plant=plant, plant_source=source, opamp=amp, tuning=tun, rules=rules,
                    parts=parts, selection=sel, checks=checks, analytic=analytic, ideal_pid=ideal,
                    margins=mg, levels=levels, test=test, expected_final_v=expected, deck=deck,
                    notes=list(notes))
    res.waveforms = {"t": t, "r": r, "analytic": waves, "ideal_pid": y_ideal, "open_loop": y_open,
                     "bode_w": w}
    return res


def _diverging(lm, t, r, limit):
    """Waveforms of an unstable loop, cut where they leave +/-``limit`` volts (plots only)."""
    with np.errstate(all="ignore"):
        w = lm.simulate(t, r)
    for k, v in w.items():
        bad = ~np.isfinite(v) | (np.abs(v) > limit)
        if np.any(bad):
            v = v.copy()
            v[np.argmax(bad):] = np.nan
            w[k] = v
    return w


def _kick(parts, amp, step_v) -> str:
    """The controller's answer to the step edge alone (ideal op-amps):
    u = Kp (1 + Td/(R12 C3)) x step, the high-frequency gain times the step."""
    hf = parts.kp * (1 + (parts.td_s / (parts.r12 * parts.c3) if parts.has_derivative else 0.0))
    u = hf * step_v
    if amp.ideal or abs(u) <= amp.vout_max:
        return ""
    return (f"; even before the loop reacts, the step edge alone asks U6 for Kp (1 + Td/(R12 C3)) x "
            f"{step_v:g} V = {u:.3g} V (the {amp.name} reaches {amp.vout_max:.3g} V)")


def _dynamic_checks(stable, lm, levels, mg, dc_cl, amp, step_v, rise, parts) -> list:
    out = []
    poles = lm.poles()
    worst = float(np.max(poles.real)) if poles.size else -math.inf
    out.append({"name": "closed_loop_stable", "ok": bool(stable),
                "detail": ("all closed-loop poles in the left half plane" if stable else
                           f"a closed-loop pole has real part {worst:+.4g} 1/s: the loop oscillates or "
                           "latches at a rail")})
    pm = mg["phase_margin_deg"]
    near = ""
    if math.isfinite(pm) and not amp.ideal:
        fc = mg["crossover_hz"]
        close = [f"{k} {format_eng(v, 'Hz')}" for k, v in sorted(parts.stage_bandwidths(amp.gbw_hz).items(),
                                                                  key=lambda kv: kv[1]) if v < 10 * fc]
        if parts.has_derivative and parts.f_differentiator_hz < 10 * fc:
            close.append(f"derivative filter {format_eng(parts.f_differentiator_hz, 'Hz')}")
        if close:
            near = "; poles within 10x of the crossover, each costing phase there: " + ", ".join(close)
    out.append({"name": "phase_margin", "ok": bool(math.isfinite(pm) and pm >= MIN_PHASE_MARGIN_DEG),
                "detail": (f"{pm:.3g} deg at {format_eng(mg['crossover_hz'], 'Hz')} with the op-amp poles "
                           f"(want >= {MIN_PHASE_MARGIN_DEG:g} deg){near}") if math.isfinite(pm)
                else "the loop gain never crosses 1"})
    if math.isfinite(dc_cl):
        e = 1 - dc_cl
        out.append({"name": "steady_state_error", "ok": bool(abs(e) <= MAX_STEADY_STATE_ERROR),
                    "detail": f"{100 * e:.3g} % of the step (the integrator leaks through R13; "
                              f"want <= {100 * MAX_STEADY_STATE_ERROR:g} %)"})
    if not stable:
        out.append({"name": "slew_rate", "ok": False, "detail": "unstable loop: no steady waveforms to check"})
        out.append({"name": "output_swing", "ok": False,
                    "detail": "unstable loop: the outputs run to the rails" + _kick(parts, amp, step_v)})
        return out
    if amp.ideal:
        worst_sw = max(levels.values(), key=lambda v: max(abs(v["v_max"]), abs(v["v_min"])))
        out.append({"name": "slew_rate", "ok": True, "detail": "ideal op-amps (no slew limit)"})
        out.append({"name": "output_swing", "ok": True,
                    "detail": f"ideal op-amps; the largest excursion is {worst_sw['opamp']} "
                              f"({worst_sw['signal']}) {worst_sw['v_min']:.3g} V to {worst_sw['v_max']:.3g} V"})
        return out
    budget = model.SLEW_DELAY_FRACTION * rise
    slow = [f"{v['opamp']} {role} needs {v['slope_v_per_s'] / 1e6:.3g} V/us, slews for ~"
            f"{format_eng(v['slew_delay_s'], 's')}" for role, v in levels.items() if not v["slew_ok"]]
    worst = max(levels.items(), key=lambda kv: kv[1]["slew_delay_s"])
    out.append({"name": "slew_rate", "ok": not slow,
                "detail": (f"{amp.name} slews at {amp.slew_v_per_s / 1e6:.3g} V/us; slewing may delay a stage by "
                           f"at most {format_eng(budget, 's')} (5 % of the rise time). "
                           + ("; ".join(slow) if slow else
                              f"worst: {worst[1]['opamp']} {worst[0]}, {format_eng(worst[1]['slew_delay_s'], 's')}"))})
    clip = [f"{v['opamp']} {role} {v['v_min']:.3g}..{v['v_max']:.3g} V" for role, v in levels.items()
            if not v["swing_ok"]]
    out.append({"name": "output_swing", "ok": not clip,
                "detail": (f"{amp.name} outputs reach {amp.vout_min:.3g} V to {amp.vout_max:.3g} V on "
                           f"{amp.vcc:g}/{amp.vee:g} V supplies for a {step_v:g} V square wave; "
                           + ("would need " + "; ".join(clip) if clip else "all stages stay inside"))})
    return out


def run_spice(res: PidResult, simulator: str) -> None:
    """Simulate the deck, compare, detect saturation and oscillation."""
    from .verify import explain, run_and_compare
    tick = time.perf_counter()
    t = res.waveforms["t"]
    out = run_and_compare(res.deck, simulator, t, res.test.delay_s, res.test.half_period_s,
                          res.waveforms["analytic"], res.test.amplitude_v, res.expected_final_v, res.opamp)
    res.simulator = out["backend"]
    sp = dict(out["metrics"])
    sp["deltas_vs_analytic"] = out["deltas"]
    sp["nrms_abstol_v"] = out["nrms_abstol_v"]
    sp["measurements"] = out["measurements"]
    sp["oscillation"] = out["oscillation"]
    res.spice = sp
    res.spice_levels = {role: {**out["saturation"].get(role, {}), **out["slewing"].get(role, {}),
                               "v_min": out["extremes"][sig][0], "v_max": out["extremes"][sig][1]}
                        for _, role, sig in model.OPAMP_OUTPUTS if sig in out["extremes"]}
    res.waveforms["spice"] = out["waves"]
    res.verdict = explain(sp, res.analytic, res.checks)
    sat = [f"{v['opamp']} {role}" for role, v in out["saturation"].items() if v["saturated"]]
    if sat:
        res.notes.append("SPICE: op-amp output pinned at a rail: " + ", ".join(sat))
    osc = out["oscillation"]
    if osc["oscillating"]:
        res.notes.append(f"SPICE: the loop is still oscillating at the end of the half period "
                         f"({osc['tail_p2p_v']:.3g} V peak to peak)")
    if osc["latched"]:
        res.notes.append(f"SPICE: the output is stuck at {osc['tail_mean_v']:.3g} V instead of settling near "
                         f"{res.expected_final_v:.3g} V (latch-up)")
    if res.verdict["unexplained"]:
        res.notes.append("SPICE and the analytic loop disagree and no check explains it (please report this)")
    res.timings["simulation_s"] = time.perf_counter() - tick
