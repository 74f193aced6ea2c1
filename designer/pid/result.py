"""What a controller design knows, typed until the JSON edge: one result for
every plant (the Sallen-Key circuit of the seed, or a model that a registered
circuit may realise).

:class:`PidResult` nests the tuning (:class:`designer.pid.tuning.Tuning`, the
rules and the optimiser's run; for a model plant the chosen gains and every
rule's :class:`RuleRow`: gains, margins, Ms, IAE and, when simulated, SPICE's
overshoot), the parts and their selection, what the parts achieve, the checks
(:class:`designer.core.checks.Check`), the analytic closed loop and its
margins, the levels at every op-amp output, the worst case over a model's
95 % corners (:class:`RobustCheck`), the bench test, the SPICE run and its
verdict, and the waveforms the plots draw. Its one :meth:`PidResult.to_dict`
is the JSON of ``design-pid --json`` and ``result.json`` (each plant kind's
keys as before the two results were one); the build sheet
(:mod:`designer.pid.report`) reads the typed result and computes nothing.
"""

from __future__ import annotations

import math
from dataclasses import dataclass, field

import numpy as np

from ..core.checks import SPICE_AGREEMENT, Check
from ..core.jsonio import SCHEMA_VERSION, json_safe
from ..core.metrics import StepMetrics
from ..core.opamps import OpAmp
from ..spice.deck import SquareTest
from ..spice.simulate import tool_info
from .blocks import PidParts
from .plant import PlantCircuit
from .selection import Selection
from .spec import PidSpec
from .tuning import Tuning
from .verify import SpiceRun, Verdict

__all__ = ["Achieved", "AnalyticLoop", "LoopFigures", "PidResult", "RobustCheck", "RuleRow", "Waveforms"]


def loop_verdicts(checks, verdict, spice) -> list:
    """The design checks and, when simulated, the SPICE agreement of a loop as one
    more verdict (:data:`~designer.core.checks.SPICE_AGREEMENT`), with why."""
    if verdict is None:
        return list(checks)
    why = [f"nrms {spice.nrms:.3g} (below 1 agrees)"]
    if verdict.overshoot_delta_pp is not None:
        why.append(f"overshoot {verdict.overshoot_delta_pp:+.3g} pp (allowed +/-1 pp)")
    if not spice.stable:
        why.append("the SPICE loop oscillates or latches")
    if spice.saturated:
        why.append("an op-amp saturates in SPICE")
    if verdict.explained_by:
        why.append("explained by the failed checks " + ", ".join(verdict.explained_by))
    return list(checks) + [Check(SPICE_AGREEMENT, verdict.agree, "; ".join(why))]


@dataclass(frozen=True)
class Achieved:
    """What the chosen parts realise, and how far the gains are from the tuning's."""

    kp: float
    ti_s: float
    td_s: float
    f_integrator_hz: float
    f_differentiator_hz: float | None   #: None for a PI
    f_summer_hz: float
    integrator_dc_gain: float
    noise_gains: dict                   #: stage -> high-frequency noise gain
    stage_bandwidths_hz: dict           #: stage -> GBW / noise gain
    errors_pct: dict                    #: kp, ti, td (None for a PI) against the tuning

    @classmethod
    def of(cls, parts: PidParts, amp: OpAmp, tuning: Tuning) -> "Achieved":
        bw = parts.stage_bandwidths(amp.gbw_hz)
        errors = {"kp": 100 * (parts.kp / tuning.kp - 1), "ti": 100 * (parts.ti_s / tuning.ti_s - 1),
                  "td": 100 * (parts.td_s / tuning.td_s - 1) if tuning.td_s > 0 else None}
        return cls(parts.kp, parts.ti_s, parts.td_s, parts.f_integrator_hz,
                   parts.f_differentiator_hz if parts.has_derivative else None, bw["summer"],
                   parts.integrator_dc_gain, parts.noise_gains(), bw, errors)

    def to_dict(self) -> dict:
        return {"kp": self.kp, "ti_s": self.ti_s, "td_s": self.td_s, "f_integrator_hz": self.f_integrator_hz,
                "f_differentiator_hz": self.f_differentiator_hz, "f_summer_hz": self.f_summer_hz,
                "integrator_dc_gain": self.integrator_dc_gain, "noise_gains": self.noise_gains,
                "stage_bandwidths_hz": self.stage_bandwidths_hz, "errors_pct": self.errors_pct}


@dataclass(frozen=True)
class AnalyticLoop:
    """The realised loop with the op-amp poles: step figures over the rising
    half period (against the expected settled output), stability and DC gain."""

    figures: StepMetrics
    stable: bool
    dc_gain: float                      #: y/r at DC (the integrator leaks: slightly below 1)
    levels: dict                        #: role -> designer.pid.model.StageLevels (empty when unstable)

    @property
    def steady_state_error_pct(self) -> float:
        return 100 * (1 - self.dc_gain)

    def to_dict(self) -> dict:
        return {**self.figures.to_dict(), "stable": self.stable, "dc_gain": self.dc_gain,
                "steady_state_error_pct": self.steady_state_error_pct}


@dataclass(frozen=True)
class Waveforms:
    """What the plots draw, on the analytic grid ``t`` (from the rising edge)."""

    t: np.ndarray
    r: np.ndarray
    analytic: dict                      #: signal -> realised loop, every op-amp output
    ideal_pid: np.ndarray               #: plant output with the ideal PID and ideal plant
    open_loop: np.ndarray               #: the plant alone
    bode_w: np.ndarray                  #: rad/s
    loop_gain: np.ndarray               #: L(j bode_w) with the op-amp poles
    reaction_t: np.ndarray              #: the plant's step (reaction curve)
    reaction_y: np.ndarray
    fopdt_y: np.ndarray | None          #: the least-squares FOPDT's step on reaction_t


class LoopVerdicts:
    """What a loop's result (a Sallen-Key plant's or a model's) says of its checks and its SPICE run;
    the result has ``checks``, ``spice`` and ``verdict``."""

    @property
    def simulator(self) -> str | None:
        return None if self.spice is None else self.spice.backend

    def failed_checks(self) -> list:
        return [c for c in self.checks if not c.ok]

    def verdicts(self) -> list:
        """Every pass/fail verdict: the design checks and, when simulated, the
        SPICE agreement with the analytic loop (``--fail-on-check``)."""
        return loop_verdicts(self.checks, self.verdict, self.spice)


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


@dataclass(kw_only=True)
class PidResult(LoopVerdicts):
    """Everything known about one controller design, for either kind of plant; :meth:`to_dict` is the JSON.

    The plant is either the Sallen-Key circuit of the seed (the reaction-curve
    ``tuning`` and its ``rules``) or a model (``model`` set: a
    :class:`~designer.core.process.ProcessModel`, typed or identified, that a
    registered circuit may realise; the chosen ``method`` and gains, every rule's
    :class:`RuleRow`, the ``robust`` corners). The fields of the other kind stay
    None. ``plant`` is the circuit of either, as the one generic record
    (:class:`~designer.pid.plant.PlantCircuit`: the seed's Sallen-Key section, an MFB
    low-pass, a cascade), None for a plant known only as a model. ``files`` and
    ``timings`` are filled in as the bundle is written.
    """

    spec: PidSpec
    opamp: OpAmp
    rules: tuple                        #: Tuning per reaction-curve rule (Sallen-Key plant), else RuleRow per rule
    optimizer: object                   #: designer.pid.optimize's OptimizeResult or ModelOptimizeResult, else None
    parts: PidParts
    selection: Selection | None         #: None for given parts
    achieved: Achieved
    checks: tuple                       #: Check, static then dynamic
    analytic: AnalyticLoop
    ideal_pid: StepMetrics | None       #: the ideal PID around the plant (None: a model's ideal loop is unstable)
    margins: object                     #: Margins (Sallen-Key plant) or DelayLoopMargins (model) of the loop as built
    test: SquareTest
    expected_final_v: float
    deck: str
    waveforms: Waveforms = field(repr=False)
    notes: list = field(default_factory=list)
    #: the plant's circuit as the generic record (designer.pid.plant.PlantCircuit: its sections and values),
    #: the seed's Sallen-Key plant or a registered circuit that realises a model; None for a model alone
    plant: PlantCircuit | None = None
    # the Sallen-Key plant's (None for a model plant)
    plant_source: str | None = None
    plant_series: tuple | None = None   #: (R, C) series of a plant designed here, else None
    plant_fn_opamp_hz: float | None = None  #: the plant's dominant pair with its op-amp
    plant_zeta_opamp: float | None = None
    tuning: Tuning | None = None
    diff_amp: object = None             #: designer.pid.model.DiffAmpBalance when R15..R18 are unbalanced
    seed_bench: object = None           #: designer.pid.design.SeedBenchFinding for the seed's as-built parts
    # the model plant's (None for the Sallen-Key plant)
    model: object = None                #: designer.core.process.ProcessModel
    reduced: object = None              #: the model the rules see (designer.pid.reduction)
    method: str | None = None           #: a rule, optimize, explicit or as-built
    kp: float | None = None
    ti_s: float | None = None
    td_s: float | None = None
    rule: object = None                 #: RuleTuning of the chosen rule, else None
    fc_ref_hz: float | None = None      #: the ideal loop's crossover the corners are set from
    ideal_margins: object = None        #: DelayLoopMargins of the ideal PID around the model
    robust: RobustCheck | None = None
    limits: tuple = (45.0, 6.0, 1.7)    #: (min PM deg, min GM dB, max Ms) of a model's loop
    # both
    package: str | None = None          #: op-amp package kind the sheet wires (None: the op-amp's default)
    spice: SpiceRun | None = None
    verdict: Verdict | None = None
    scope: object = None                #: designer.plant.bench.ScopeSetup of the bench test (CH2 per node)
    #: a tolerance analysis of the loop (designer.tolerance.loop.LoopMonteCarlo), when asked for
    monte_carlo: object = None
    #: the loop's worst case over the tolerance box (designer.tolerance.worstcase.WorstCase), when asked for
    worst_case: object = None
    files: dict = field(default_factory=dict)
    timings: dict = field(default_factory=dict)

    @property
    def stable(self) -> bool:
        """Whether the loop as built is stable (the analytic loop's verdict)."""
        return self.analytic.stable

    @property
    def dc_gain(self) -> float:
        """The loop as built's y/r at DC."""
        return self.analytic.dc_gain

    @property
    def levels(self) -> dict:
        """Role -> analytic levels at every op-amp output."""
        return self.analytic.levels

    def circuit_dict(self) -> dict:
        """A circuit plant's keys of a model's ``plant`` (none for a model alone): ``kind``
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
        """The JSON of ``design-pid --json`` and ``result.json`` (a model plant's keys when ``model`` is set)."""
        tail = {
            "levels": {"analytic": {k: v.to_dict() for k, v in self.levels.items()},
                       "spice": None if self.spice is None else {k: v.to_dict() for k, v in self.spice.stages.items()}},
            "test_signal": {**self.test.to_dict(), "edge_s": self.test.edge_s,
                            "expected_final_v": self.expected_final_v},
            "notes": self.notes,
            "simulator": self.simulator,
            "scope": None if self.scope is None else self.scope.to_dict(),
        }
        if self.model is None:
            tail.update({"difference_amplifier": None if self.diff_amp is None else self.diff_amp.to_dict(),
                         "seed_bench": None if self.seed_bench is None else self.seed_bench.to_dict()})
        tail.update({"monte_carlo": None if self.monte_carlo is None else self.monte_carlo.to_dict(),
                     "worst_case": None if self.worst_case is None else self.worst_case.to_dict(),
                     "files": self.files})
        head = {"schema_version": SCHEMA_VERSION, "tool": tool_info(self.simulator)}
        return json_safe({**head, **(self._circuit_keys() if self.model is None else self._model_keys()), **tail})

    def _circuit_keys(self) -> dict:
        """The Sallen-Key plant's keys from ``plant`` to ``closed_loop``."""
        from ..filters.sallen_key_lowpass_parts import record_of
        st = self.plant.stages[0]
        pl = record_of(st.topology, st.values)   # the seed plant's own keys (R1_ohm .., gain, fn_hz, zeta), as ever
        return {
            "plant": {"source": self.plant_source, **pl.as_dict(), "q": pl.q, "fn_opamp_hz": self.plant_fn_opamp_hz,
                      "zeta_opamp": self.plant_zeta_opamp, "topology": self.plant.topology},
            **self._amp_keys(),
            "tuning": self.tuning.to_dict(),
            "rules": [r.to_dict(brief=True) for r in self.rules],
            "optimizer": None if self.optimizer is None else self.optimizer.to_dict(),
            **self._parts_keys(),
            "checks": [c.to_dict() for c in self.checks],
            "closed_loop": {"analytic": self.analytic.to_dict(), "ideal_pid": self.ideal_pid.to_dict(),
                            "spice": None if self.spice is None else self.spice.to_dict(),
                            "margins": self.margins.to_dict(),
                            "verdict": None if self.verdict is None else self.verdict.to_dict()},
        }

    def _model_keys(self) -> dict:
        """A model plant's keys from ``plant`` to ``robust``."""
        pm_min, gm_min, ms_max = self.limits
        return {
            "plant": {"kind": "model", "source": self.model.source, "model": self.model.to_dict(),
                      "rules_model": self.reduced.to_dict(), "input_range_v": self.spec.plant.plant_input,
                      "output_range_v": self.spec.plant.plant_output, **self.circuit_dict()},
            **self._amp_keys(),
            "tuning": {"method": self.method, "kp": self.kp, "ti_s": self.ti_s, "td_s": self.td_s,
                       "rule": None if self.rule is None else self.rule.to_dict()},
            "rules": [r.to_dict() for r in self.rules],
            "optimizer": None if self.optimizer is None else self.optimizer.to_dict(),
            "limits": {"min_phase_margin_deg": pm_min, "min_gain_margin_db": gm_min, "max_ms": ms_max},
            **self._parts_keys(),
            "fc_ref_hz": self.fc_ref_hz,
            "checks": [c.to_dict() for c in self.checks],
            "closed_loop": {"analytic": self.analytic.to_dict(),
                            "ideal_pid": None if self.ideal_pid is None else self.ideal_pid.to_dict(),
                            "margins": self.margins.to_dict(), "ideal_pid_margins": self.ideal_margins.to_dict(),
                            "spice": None if self.spice is None else self.spice.to_dict(),
                            "verdict": None if self.verdict is None else self.verdict.to_dict()},
            "robust": None if self.robust is None else self.robust.to_dict(),
        }

    def _amp_keys(self) -> dict:
        return {"opamp": self.opamp.to_dict(), "package": self.opamp.package(self.package).to_dict()}

    def _parts_keys(self) -> dict:
        return {"components": self.parts.to_dict(),
                "series": None if self.selection is None else self.selection.to_dict(),
                "achieved": self.achieved.to_dict()}
