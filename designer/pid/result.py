"""What a controller design knows, typed until the JSON edge.

:class:`PidResult` nests the tuning (:class:`designer.pid.tuning.Tuning`, the
rules and the optimiser's run), the parts and their selection, what the parts
achieve, the checks (:class:`designer.core.checks.Check`), the analytic closed
loop and its margins, the levels at every op-amp output, the bench test, the
SPICE run and its verdict, and the waveforms the plots draw. Its one
:meth:`PidResult.to_dict` is the JSON of ``design-pid --json`` and
``result.json``; the build sheet (:mod:`designer.pid.report`) reads the typed
result and computes nothing.
"""

from __future__ import annotations

from dataclasses import dataclass, field

import numpy as np

from ..core.checks import SPICE_AGREEMENT, Check
from ..core.jsonio import SCHEMA_VERSION, json_safe
from ..core.metrics import StepMetrics
from ..core.opamps import OpAmp
from ..plant.sallenkey import SallenKeyParts
from ..spice.deck import SquareTest
from ..spice.simulate import tool_info
from .blocks import PidParts
from .model import Margins
from .optimize import OptimizeResult
from .plant import sallen_key_circuit
from .selection import Selection
from .spec import PidSpec
from .tuning import Tuning
from .verify import SpiceRun, Verdict

__all__ = ["PidResult"]


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


@dataclass
class PidResult(LoopVerdicts):
    """Everything known about one controller design; :meth:`to_dict` is the JSON.

    ``files`` and ``timings`` are filled in as the bundle is written.
    """

    spec: PidSpec
    plant: SallenKeyParts
    plant_source: str
    plant_series: tuple | None          #: (R, C) series of a plant designed here, else None
    plant_fn_opamp_hz: float            #: the plant's dominant pair with its op-amp
    plant_zeta_opamp: float
    opamp: OpAmp
    tuning: Tuning
    rules: tuple                        #: every rule on the same reaction curve
    optimizer: OptimizeResult | None
    parts: PidParts
    selection: Selection | None         #: None for given parts
    achieved: Achieved
    checks: tuple                       #: Check, static then dynamic
    analytic: AnalyticLoop
    ideal_pid: StepMetrics
    margins: Margins
    test: SquareTest
    expected_final_v: float
    deck: str
    waveforms: Waveforms = field(repr=False)
    notes: list = field(default_factory=list)
    spice: SpiceRun | None = None
    verdict: Verdict | None = None
    scope: object = None                #: designer.plant.bench.ScopeSetup of the bench test (CH2 per node)
    diff_amp: object = None             #: designer.pid.model.DiffAmpBalance when R15..R18 are unbalanced
    seed_bench: object = None           #: designer.pid.design.SeedBenchFinding for the seed's as-built parts
    package: str | None = None          #: op-amp package kind the sheet wires (None: the op-amp's default)
    #: a tolerance analysis of the loop (designer.tolerance.loop.LoopMonteCarlo), when asked for
    monte_carlo: object = None
    #: the loop's worst case over the tolerance box (designer.tolerance.worstcase.WorstCase), when asked for
    worst_case: object = None
    files: dict = field(default_factory=dict)
    timings: dict = field(default_factory=dict)


    def to_dict(self) -> dict:
        pl = self.plant
        out = {
            "schema_version": SCHEMA_VERSION,
            "tool": tool_info(self.simulator),
            "plant": {"source": self.plant_source, **pl.as_dict(), "q": pl.q, "fn_opamp_hz": self.plant_fn_opamp_hz,
                      "zeta_opamp": self.plant_zeta_opamp, "topology": sallen_key_circuit(pl).topology},
            "opamp": self.opamp.to_dict(), "package": self.opamp.package(self.package).to_dict(),
            "tuning": self.tuning.to_dict(),
            "rules": [r.to_dict(brief=True) for r in self.rules],
            "optimizer": None if self.optimizer is None else self.optimizer.to_dict(),
            "components": self.parts.to_dict(),
            "series": None if self.selection is None else self.selection.to_dict(),
            "achieved": self.achieved.to_dict(),
            "checks": [c.to_dict() for c in self.checks],
            "closed_loop": {"analytic": self.analytic.to_dict(), "ideal_pid": self.ideal_pid.to_dict(),
                            "spice": None if self.spice is None else self.spice.to_dict(),
                            "margins": self.margins.to_dict(),
                            "verdict": None if self.verdict is None else self.verdict.to_dict()},
            "levels": {"analytic": {k: v.to_dict() for k, v in self.analytic.levels.items()},
                       "spice": None if self.spice is None else {k: v.to_dict() for k, v in self.spice.stages.items()}},
            "test_signal": {**self.test.to_dict(), "edge_s": self.test.edge_s,
                            "expected_final_v": self.expected_final_v},
            "notes": self.notes,
            "simulator": self.simulator,
            "scope": None if self.scope is None else self.scope.to_dict(),
            "difference_amplifier": None if self.diff_amp is None else self.diff_amp.to_dict(),
            "seed_bench": None if self.seed_bench is None else self.seed_bench.to_dict(),
            "monte_carlo": None if self.monte_carlo is None else self.monte_carlo.to_dict(),
            "worst_case": None if self.worst_case is None else self.worst_case.to_dict(),
            "files": self.files,
        }
        return json_safe(out)

