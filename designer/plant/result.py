"""What a plant design or analysis found, typed until the JSON edge.

A :class:`PlantResult` holds the target, the parts (the exact design and the
build), the two analytic models of the build (ideal op-amp, and the chosen
op-amp's finite gain-bandwidth: seed 001's plant, IV.3-IV.9, with the third
pole the seed leaves out), the bench test with its checks and tolerance band,
and the SPICE run compared with both models. The report renders it as it is;
:meth:`PlantResult.to_dict` is the one JSON form (``design-plant --json`` and
``result.json``).
"""

from __future__ import annotations

from dataclasses import dataclass, field

import numpy as np

from ..core import eseries
from ..core.checks import SPICE_AGREEMENT, Check
from ..core.i18n import N_
from ..core.jsonio import SCHEMA_VERSION, json_safe
from ..core.metrics import StepMetrics
from ..core.opamps import OpAmp
from ..spice.deck import SquareTest
from ..spice.simulate import tool_info
from .bench import BenchPeriod, ScopeSetup, SineCheck, ToleranceBand
from .circuit import DEFAULT_TOPOLOGY
from .sallenkey import KEY_OF, SallenKeyParts

__all__ = ["PlantResult"]

#: the plant JSON's schema: the project's (:data:`designer.core.jsonio.SCHEMA_VERSION`) plus one for the
#: ``topology`` key (the section that realises the plant; every other key as before)
PLANT_SCHEMA_VERSION = SCHEMA_VERSION + 1

#: the step metrics a result gives, in the order of its JSON
METRICS = ("overshoot_pct", "peak_time_s", "rise_time_s", "settling_time_s", "settling_time_5pct_s",
           "rise_time_0_100_s", "peak_value", "final_value")


def _pct(value, target):
    if target is None or value is None:
        return None
    return 100.0 * (value / target - 1.0)


@dataclass(frozen=True)
class Target:
    """What the plant should be: fn (Hz), zeta and the DC gain K. An analysis of
    parts as built may have no fn or zeta to aim at."""

    fc_hz: float | None
    zeta: float | None
    gain: float

    @property
    def q(self) -> float | None:
        return None if self.zeta is None else 1 / (2 * self.zeta)

    def to_dict(self) -> dict:
        return {"fc_hz": self.fc_hz, "zeta": self.zeta, "gain": self.gain}


@dataclass(frozen=True)
class Figures:
    """The fn and zeta a circuit (or a model of it) lands on, and how far from
    the target they are (percent; None without a target)."""

    fn_hz: float
    zeta: float
    fn_error_pct: float | None
    zeta_error_pct: float | None

    @classmethod
    def against(cls, fn_hz: float, zeta: float, target: Target) -> Figures:
        return cls(fn_hz, zeta, _pct(fn_hz, target.fc_hz), _pct(zeta, target.zeta))

    @property
    def q(self) -> float:
        return 1 / (2 * self.zeta)


@dataclass(frozen=True)
class Ratios:
    """The seed's m = R1/R2 and n = C2/C1 of the exact design (None without one)."""

    m: float | None = None
    n: float | None = None

    def to_dict(self) -> dict:
        return {"m": self.m, "n": self.n}


@dataclass(frozen=True)
class Alternative:
    """One of the best E-series combinations (``values``: the network's designator -> value, ohm and farad), and
    where it lands."""

    values: dict
    figures: Figures

    def to_dict(self) -> dict:
        f = self.figures
        return {**{KEY_OF[r]: v for r, v in self.values.items()},
                "fn_hz": f.fn_hz, "zeta": f.zeta, "fn_error_pct": f.fn_error_pct, "zeta_error_pct": f.zeta_error_pct}


@dataclass(frozen=True)
class PartSource:
    """Where one part comes from: its series label and tolerance."""

    series: str
    tolerance_pct: float

    def to_dict(self) -> dict:
        return {"series": self.series, "tolerance_pct": self.tolerance_pct}


@dataclass(frozen=True)
class Sourcing:
    """The series of every part (``parts``: reference -> :class:`PartSource`),
    and the resistor and capacitor series whose tolerances the band uses."""

    r_series: str
    c_series: str
    parts: dict

    @property
    def r_tolerance_pct(self) -> float:
        return 100 * eseries.TOLERANCE[self.r_series]

    def source(self, ref: str):
        """A part's (series label, tolerance %) as the bill of materials lists it
        (:func:`designer.report.wiring.bom_rows`' ``source``), None for a part without one (the op-amp).

        Parameters
        ----------
        ref : str
            The designator.

        Returns
        -------
        tuple or None
            (series, tolerance_pct).
        """
        src = self.parts.get(ref)
        return None if src is None else (src.series, src.tolerance_pct)

    @property
    def c_tolerance_pct(self) -> float:
        return 100 * eseries.TOLERANCE[self.c_series]

    def to_dict(self) -> dict:
        return {"r": self.r_series, "c": self.c_series, "r_tolerance_pct": self.r_tolerance_pct,
                "c_tolerance_pct": self.c_tolerance_pct,
                "parts": {ref: p.to_dict() for ref, p in self.parts.items()}}


@dataclass(frozen=True, eq=False)
class Model:
    """One analytic model of the build: its transfer function (num, den), the
    figures of its dominant pair, its unit-step metrics, the sensitivities of
    wn and zeta (:class:`~designer.plant.model.Sensitivity` by part) and its
    response to the bench's rising edge (volts, on :attr:`PlantResult.time_s`)."""

    num: np.ndarray
    den: np.ndarray
    figures: Figures
    step: StepMetrics
    sensitivity: dict
    response: np.ndarray

    @property
    def dc_gain(self) -> float:
        return float(self.num[-1] / self.den[-1])


@dataclass(frozen=True)
class Comparison:
    """SPICE against the two models: metric deltas (SPICE minus model, as
    :func:`designer.core.compare.metric_deltas` gives them), the NRMS absolute
    tolerance, and what disagrees with the op-amp-aware model (empty: agrees)."""

    vs_ideal: dict
    vs_opamp: dict
    nrms_abstol_v: float
    disagreements: list

    @property
    def passed(self) -> bool:
        return not self.disagreements

    def to_dict(self) -> dict:
        return {"spice_vs_analytic": self.vs_ideal, "spice_vs_analytic_opamp": self.vs_opamp,
                "nrms_abstol_v": self.nrms_abstol_v, "pass": self.passed, "disagreements": self.disagreements}


@dataclass(frozen=True, eq=False)
class SpiceRun:
    """The simulated bench test: its step metrics (normalised by the amplitude),
    the NRMS waveform errors against both models, ngspice's own ``.meas``
    values, the output on :attr:`PlantResult.time_s` (volts) and the comparison."""

    simulator: str
    step: StepMetrics
    nrms: float
    nrms_ideal: float
    measurements: dict
    response: np.ndarray
    comparison: Comparison

    def to_dict(self) -> dict:
        return {**_metrics(self.step), "nrms": self.nrms, "nrms_ideal": self.nrms_ideal,
                "measurements": self.measurements}


def _metrics(m: StepMetrics) -> dict:
    d = m.to_dict()
    return {k: d[k] for k in METRICS}


def parts_dict(p: SallenKeyParts) -> dict:
    """A part set as the JSON gives it: values, gain, fn, zeta and Q."""
    return {**p.as_dict(), "q": p.q}


@dataclass(eq=False)
class PlantResult:
    """Everything known about one plant design (``mode`` "design") or one
    analysis of parts as built ("analyze"); :meth:`to_dict` is the JSON."""

    mode: str
    target: Target
    ratios: Ratios
    ideal: SallenKeyParts | None     #: the exact design the build rounds (None: parts as built)
    built: SallenKeyParts
    sourcing: Sourcing
    alternatives: list               #: :class:`Alternative`, best first (empty for an analysis)
    opamp: OpAmp
    analytic: Model                  #: with an ideal op-amp
    analytic_opamp: Model            #: with the chosen op-amp
    time_s: np.ndarray               #: the rising half period (from the edge), where the models are compared
    test: SquareTest
    tolerance: ToleranceBand
    checks: list                     #: :class:`~designer.core.checks.Check`
    notes: list
    deck: str                        #: the standalone ngspice deck
    bench: BenchPeriod
    spice: SpiceRun | None = None
    scope: ScopeSetup | None = None      #: the scope as set for the square-wave test
    sine: SineCheck | None = None        #: the sine check (resonance peak, -3 dB), SPICE .ac when simulated
    package: str | None = None           #: the op-amp package kind the sheet wires (None: the op-amp's default)
    #: a tolerance analysis of the parts as built (designer.tolerance.montecarlo.MonteCarlo), when asked for
    monte_carlo: object = None
    #: the extremes over the tolerance box (designer.tolerance.worstcase.WorstCase), when asked for
    worst_case: object = None
    #: the bench test under a PRBS (designer.plant.prbs.PrbsRun), with --stimulus prbs
    prbs: object = None
    files: dict = field(default_factory=dict)
    timings: dict = field(default_factory=dict)

    def verdicts(self) -> list:
        """Every pass/fail verdict: the design checks and, when simulated, the
        SPICE agreement with the op-amp-aware model (``--fail-on-check``)."""
        if self.spice is None:
            return list(self.checks)
        cmp_ = self.spice.comparison
        if cmp_.disagreements:
            return list(self.checks) + [Check(SPICE_AGREEMENT, cmp_.passed, "; ".join(cmp_.disagreements))]
        return list(self.checks) + [Check.of(SPICE_AGREEMENT, cmp_.passed, N_("waveform NRMS {nrms} (below 1) and "
                                                                              "every step figure within its allowance"),
                                             nrms=f"{self.spice.nrms:.3g}")]

    def to_dict(self) -> dict:
        d = self._to_dict()
        if self.prbs is not None:   # only then: a step design's JSON stays as it was
            files = d.pop("files")
            d = {**d, "prbs": json_safe(self.prbs.to_dict()), "files": files}
        return d

    def _to_dict(self) -> dict:
        target, fig, opa = self.target, self.analytic.figures, self.analytic_opamp.figures
        built = {**parts_dict(self.built), "fn_error_pct": fig.fn_error_pct, "zeta_error_pct": fig.zeta_error_pct,
                 "fn_opamp_hz": opa.fn_hz, "zeta_opamp": opa.zeta, "fn_opamp_error_pct": opa.fn_error_pct,
                 "zeta_opamp_error_pct": opa.zeta_error_pct, "tolerance_band": self.tolerance.to_dict()}
        return json_safe({
            "schema_version": PLANT_SCHEMA_VERSION,
            "tool": tool_info(self.spice.simulator if self.spice is not None else None),
            "mode": self.mode,
            "topology": DEFAULT_TOPOLOGY,
            "spec": target.to_dict(),
            "ratios": self.ratios.to_dict(),
            "ideal": None if self.ideal is None else parts_dict(self.ideal),
            "built": built,
            "series": self.sourcing.to_dict(),
            "alternatives": [a.to_dict() for a in self.alternatives],
            "opamp": self.opamp.to_dict(), "package": self.opamp.package(self.package).to_dict(),
            "test_signal": self.test.to_dict(),
            "checks": [c.to_dict() for c in self.checks],
            "notes": self.notes,
            "monte_carlo": None if self.monte_carlo is None else self.monte_carlo.to_dict(),
            "worst_case": None if self.worst_case is None else self.worst_case.to_dict(),
            "analytic": _metrics(self.analytic.step),
            "analytic_opamp": _metrics(self.analytic_opamp.step),
            "spice": None if self.spice is None else self.spice.to_dict(),
            "comparison": {} if self.spice is None else self.spice.comparison.to_dict(),
            "sensitivity": {"ideal": {k: s.to_dict() for k, s in self.analytic.sensitivity.items()},
                            "opamp": {k: s.to_dict() for k, s in self.analytic_opamp.sensitivity.items()}},
            "simulator": None if self.spice is None else self.spice.simulator,
            "scope": None if self.scope is None else self.scope.to_dict(),
            "sine_check": None if self.sine is None else self.sine.to_dict(),
            "files": self.files,
        })
