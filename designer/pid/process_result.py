"""What a controller design for a model plant knows, typed until the JSON edge
(:mod:`designer.pid.process_loop` fills it; :mod:`designer.pid.process_report`
renders it and computes nothing).

:class:`ProcessPidResult` holds the model and where it came from, every rule's
row (:class:`RuleRow`: gains, margins, Ms, IAE and, when simulated, SPICE's
overshoot), the chosen gains, the parts, the checks, the loop as built
(margins, step figures, every op-amp's levels), the worst case over the model's
95 % corners (:class:`RobustCheck`), the bench test, the deck and the SPICE run.
"""

from __future__ import annotations

import math
from dataclasses import dataclass, field

from ..core.checks import Check
from ..core.jsonio import SCHEMA_VERSION, json_safe
from ..spice.simulate import tool_info
from .result import LoopVerdicts

__all__ = ["ProcessPidResult"]


@dataclass(frozen=True)
class LoopFigures:
    """One loop's figures: gains, margins (:class:`~designer.pid.delaymargins.DelayLoopMargins`),
    step figures (:class:`~designer.pid.delayloop.StepFigures`, None when unstable)
    and the controller output's extremes over the step."""

    kp: float
    ti_s: float
    td_s: float
    margins: object
    step: object
    u_min_v: float
    u_max_v: float

    def to_dict(self) -> dict:
        m = self.margins
        return {"kp": self.kp, "ti_s": self.ti_s, "td_s": self.td_s, "stable": m.stable,
                "phase_margin_deg": m.phase_margin_deg, "crossover_hz": m.crossover_hz,
                "gain_margin_db": m.gain_margin_db, "delay_margin_s": m.delay_margin_s, "ms": m.ms,
                "step": None if self.step is None else self.step.to_dict(),
                "u_min_v": self.u_min_v, "u_max_v": self.u_max_v}


@dataclass(frozen=True)
class RuleRow:
    """One rule on the one plant: its tuning (:class:`~designer.pid.rules.RuleTuning`),
    or the reason it does not apply, and its loop as it would be built."""

    rule: str
    tuning: object
    reason: str | None
    figures: LoopFigures | None
    spice_overshoot_pct: float | None = None

    def to_dict(self) -> dict:
        return {"rule": self.rule, "applies": self.tuning is not None, "reason": self.reason,
                "tuning": None if self.tuning is None else self.tuning.to_dict(),
                "loop": None if self.figures is None else self.figures.to_dict(),
                "spice_overshoot_pct": self.spice_overshoot_pct}


@dataclass(frozen=True)
class RobustCheck:
    """The loop as built at each corner of the model's 95 % box (label, LoopFigures)."""

    corners: tuple
    min_phase_margin_deg: float
    min_gain_margin_db: float
    max_ms: float

    def worst(self, key: str, sign: float = 1.0):
        """(label, value) of the corner with the smallest ``sign`` x figure ``key``
        of :meth:`LoopFigures.to_dict` (sign -1: the largest); an unstable corner first."""
        def value(fig):
            d = fig.to_dict()
            v = d[key] if key in d else (d["step"] or {}).get(key)
            return math.inf if v is None or (isinstance(v, float) and math.isnan(v)) else sign * v
        unstable = [(lab, f) for lab, f in self.corners if not f.margins.stable]
        if unstable:
            return unstable[0][0], math.nan
        lab, fig = min(self.corners, key=lambda c: value(c[1]))
        return lab, sign * value(fig)

    @property
    def all_stable(self) -> bool:
        return all(f.margins.stable for _, f in self.corners)

    def checks(self) -> tuple:
        pm_at, pm = self.worst("phase_margin_deg")
        os_at, os_ = self.worst("overshoot_pct", -1.0)
        ms_at, ms = self.worst("ms", -1.0)
        n = len(self.corners)
        if not self.all_stable:
            return (Check("robust_stability", False, f"the loop is unstable at the 95 % corner {pm_at} "
                                                     f"(of {n} corners)"),)
        return (Check("robust_stability", True, f"stable at all {n} corners of the model's 95 % intervals"),
                Check("robust_phase_margin", bool(pm >= self.min_phase_margin_deg),
                      f"worst {pm:.3g} deg at the corner {pm_at} (want >= {self.min_phase_margin_deg:g} deg); "
                      f"worst overshoot {os_:.3g} % at {os_at}"),
                Check("robust_max_sensitivity", bool(ms <= self.max_ms),
                      f"worst Ms {ms:.3g} at the corner {ms_at} (want <= {self.max_ms:g})"))

    def to_dict(self) -> dict:
        pm_at, pm = self.worst("phase_margin_deg")
        os_at, os_ = self.worst("overshoot_pct", -1.0)
        gm_at, gm = self.worst("gain_margin_db")
        ms_at, ms = self.worst("ms", -1.0)
        return {"corners": [{"corner": lab, **f.to_dict()} for lab, f in self.corners],
                "all_stable": self.all_stable,
                "worst_phase_margin_deg": pm, "worst_phase_margin_at": pm_at,
                "worst_gain_margin_db": gm, "worst_gain_margin_at": gm_at,
                "worst_ms": ms, "worst_ms_at": ms_at,
                "worst_overshoot_pct": os_, "worst_overshoot_at": os_at}


@dataclass
class ProcessPidResult(LoopVerdicts):
    """Everything known about one controller design for a model plant; :meth:`to_dict` is the JSON."""

    spec: object
    model: object                       #: designer.core.process.ProcessModel
    reduced: object                     #: the model the rules see (designer.pid.reduction)
    opamp: object
    method: str                         #: a rule, optimize, explicit or as-built
    kp: float
    ti_s: float
    td_s: float
    rule: object                        #: RuleTuning of the chosen rule, else None
    rules: tuple                        #: RuleRow per rule of designer.pid.rules.RULES
    optimizer: object
    parts: object
    selection: object
    achieved: object
    fc_ref_hz: float                    #: the ideal loop's crossover the corners are set from
    checks: tuple
    margins: object                     #: DelayLoopMargins of the loop as built
    ideal_margins: object               #: of the ideal PID around the model
    ideal_pid: object                   #: StepMetrics of the ideal PID (filter N = 10) around the model, or None
    analytic: object                    #: StepMetrics of the loop as built (against expected_final_v)
    stable: bool
    dc_gain: float
    levels: dict
    robust: RobustCheck | None
    test: object
    expected_final_v: float
    deck: str
    waveforms: object = field(repr=False)
    notes: list = field(default_factory=list)
    package: str | None = None
    limits: tuple = (45.0, 6.0, 1.7)    #: (min PM deg, min GM dB, max Ms)
    spice: object = None
    verdict: object = None
    scope: object = None                #: designer.plant.bench.ScopeSetup of the bench test (CH2 per node)
    #: the controller's tolerance analysis around the model (designer.tolerance.loop.LoopMonteCarlo), when asked for
    monte_carlo: object = None
    #: the loop's worst case over the controller's tolerance box (designer.tolerance.worstcase.WorstCase)
    worst_case: object = None
    files: dict = field(default_factory=dict)
    timings: dict = field(default_factory=dict)

    def circuit_dict(self) -> dict:
        """A circuit plant's keys of ``plant`` (none for a model plant): ``kind``
        ``circuit``, its ``topology`` (a registry name or ``cascade``), its
        ``circuit`` (stages and parts as on the board), ``circuit_model`` (its own
        transfer function) and ``reversed_action`` (an inverting circuit, the
        model the gains were chosen for being -G)."""
        plant = getattr(self.spec, "circuit", None)
        if plant is None:
            return {}
        c = plant.circuit
        return {"kind": "circuit", "topology": c.topology, "circuit": c.to_dict()["stages"],
                "circuit_model": plant.model.to_dict(), "reversed_action": plant.reversed_action}

    def to_dict(self) -> dict:
        pm_min, gm_min, ms_max = self.limits
        out = {
            "schema_version": SCHEMA_VERSION,
            "tool": tool_info(self.simulator),
            "plant": {"kind": "model", "source": self.model.source, "model": self.model.to_dict(),
                      "rules_model": self.reduced.to_dict(), "input_range_v": self.spec.plant_input,
                      "output_range_v": self.spec.plant_output, **self.circuit_dict()},
            "opamp": self.opamp.to_dict(), "package": self.opamp.package(self.package).to_dict(),
            "tuning": {"method": self.method, "kp": self.kp, "ti_s": self.ti_s, "td_s": self.td_s,
                       "rule": None if self.rule is None else self.rule.to_dict()},
            "rules": [r.to_dict() for r in self.rules],
            "optimizer": None if self.optimizer is None else self.optimizer.to_dict(),
            "limits": {"min_phase_margin_deg": pm_min, "min_gain_margin_db": gm_min, "max_ms": ms_max},
            "components": self.parts.to_dict(),
            "series": None if self.selection is None else self.selection.to_dict(),
            "achieved": self.achieved.to_dict(),
            "fc_ref_hz": self.fc_ref_hz,
            "checks": [c.to_dict() for c in self.checks],
            "closed_loop": {"analytic": {**self.analytic.to_dict(), "stable": self.stable, "dc_gain": self.dc_gain,
                                         "steady_state_error_pct": 100 * (1 - self.dc_gain)},
                            "ideal_pid": None if self.ideal_pid is None else self.ideal_pid.to_dict(),
                            "margins": self.margins.to_dict(), "ideal_pid_margins": self.ideal_margins.to_dict(),
                            "spice": None if self.spice is None else self.spice.to_dict(),
                            "verdict": None if self.verdict is None else self.verdict.to_dict()},
            "robust": None if self.robust is None else self.robust.to_dict(),
            "levels": {"analytic": {k: v.to_dict() for k, v in self.levels.items()},
                       "spice": None if self.spice is None else {k: v.to_dict() for k, v in self.spice.stages.items()}},
            "test_signal": {**self.test.to_dict(), "edge_s": self.test.edge_s,
                            "expected_final_v": self.expected_final_v},
            "notes": self.notes,
            "simulator": self.simulator,
            "scope": None if self.scope is None else self.scope.to_dict(),
            "monte_carlo": None if self.monte_carlo is None else self.monte_carlo.to_dict(),
            "worst_case": None if self.worst_case is None else self.worst_case.to_dict(),
            "files": self.files,
        }
        return json_safe(out)
