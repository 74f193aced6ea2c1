"""The plant under the pseudo-random binary sequence the bench plays
(``design-plant --stimulus prbs``; seed 003, section 2.4, on seed 001's plant).

:func:`plan_for_result` chooses the sequence for a designed (or analysed)
plant with :func:`designer.core.prbs.plan_for_plant`, from the op-amp-aware
model's 2 % settling time and -3 dB bandwidth: levels 0 V and the bench's
``--amplitude`` (the square wave's range), :data:`PERIODS` periods (the first
brings the plant to its periodic steady state; ``identify`` uses the others).

:func:`prbs_run` gives what a scope would capture: the input sampled halfway
between samples of a grid :data:`SAMPLES_PER_INTERVAL` to the clock interval
(as :mod:`designer.identify.broadband` reads it), the output from ngspice
(:func:`designer.plant.netlist.plant_prbs_deck`, the same PWL source
``make-prbs`` writes) when simulated, else the model's, and the op-amp-aware
model's exact response to the held input (zero-order hold at half the sample
interval), with the swing and slew checks of the op-amp under that input.
"""

from __future__ import annotations

from dataclasses import dataclass, fields

import numpy as np

from ..core.checks import Check
from ..core.i18n import N_
from ..core.prbs import PrbsPlan, plan_for_plant

__all__ = ["MAX_INTERVALS", "PERIODS", "SAMPLES_PER_INTERVAL", "attach", "check_size", "model_response",
           "op_amp_checks", "plan_for_result", "plan_of", "prbs_run", "run_deck", "with_prbs"]

#: periods played: the first settles the plant, the other three are identified
PERIODS = 4
#: samples of the capture per clock interval
SAMPLES_PER_INTERVAL = 10
#: at most this many clock intervals are played (all periods): bounds the capture's memory
MAX_INTERVALS = 1 << 16
#: at most this many ngspice time steps (the step is at most 1/100 of 1/wn)
MAX_SPICE_STEPS = 2_000_000


def plan_for_result(result, amplitude_v: float, bits=None, clock_hz=None) -> PrbsPlan:
    """The sequence for a :class:`~designer.plant.result.PlantResult`: levels
    0 V and ``amplitude_v``; ``bits`` and ``clock_hz`` chosen for the plant's
    op-amp-aware model unless given (a given clock is kept as is).

    Parameters
    ----------
    result : PlantResult
        The plant.
    amplitude_v : float
        The sequence's amplitude (V).
    bits : int, optional
        The register's length; None: chosen.
    clock_hz : float, optional
        The clock; None: chosen.

    Returns
    -------
    PrbsPlan
        The sequence.
    """
    settling = result.analytic_opamp.step.settling_time_s
    sine = result.sine
    band = sine.f_3db_hz if sine is not None and sine.f_3db_hz is not None else result.built.fn_hz
    return plan_of(settling, band, result.built.fn_hz, amplitude_v, bits, clock_hz)


def plan_of(settling_s: float, band_hz: float, fn_hz: float, amplitude_v: float, bits=None, clock_hz=None) -> PrbsPlan:
    """The sequence for a plant of 2 % settling time ``settling_s``, band edge ``band_hz`` and natural
    frequency ``fn_hz`` (its time step): levels 0 V and ``amplitude_v``, :data:`PERIODS` periods,
    ``bits`` and ``clock_hz`` chosen unless given (:func:`designer.core.prbs.plan_for_plant`), its
    size checked (:func:`check_size`).

    Parameters
    ----------
    settling_s : float
        The settling time (s).
    band_hz : float
        The band edge the clock covers (Hz).
    fn_hz : float
        The natural frequency (Hz).
    amplitude_v : float
        The sequence's high level (V).
    bits : int, optional
        The register's length; None: chosen.
    clock_hz : float, optional
        The clock; None: chosen.

    Returns
    -------
    PrbsPlan
        The sequence.
    """
    half = 0.5 * float(amplitude_v)
    plan = plan_for_plant(settling_s, band_hz, amplitude=half, offset=half, periods=PERIODS,
                          dt_s=None if clock_hz is None else 1.0 / float(clock_hz), bits=bits)
    check_size(plan, fn_hz)
    return plan


def check_size(plan: PrbsPlan, fn_hz: float) -> None:
    """One line when the run would be too long: more than :data:`MAX_INTERVALS`
    intervals, or more than :data:`MAX_SPICE_STEPS` time steps of a plant of
    natural frequency ``fn_hz`` (its step is at most 1/100 of 1/wn).

    Parameters
    ----------
    plan : PrbsPlan
        The sequence.
    fn_hz : float
        The plant's natural frequency (Hz).

    Raises
    ------
    DesignError
        The run too long (one line).
    """
    import math

    from ..core.errors import DesignError
    from ..core.units import format_eng
    total = plan.n * plan.periods
    if total > MAX_INTERVALS:
        raise DesignError(f"a PRBS of {plan.bits} bits played {plan.periods} times is {total:,} clock intervals; "
                          f"at most {MAX_INTERVALS:,} are simulated: fewer --prbs-bits or a slower --prbs-clock")
    step = min(plan.dt_s / SAMPLES_PER_INTERVAL, 1.0 / (2 * math.pi * fn_hz) / 100)
    if plan.periods * plan.period_s / step > MAX_SPICE_STEPS:
        raise DesignError(f"the PRBS lasts {format_eng(plan.periods * plan.period_s, 's')}, more than "
                          f"{MAX_SPICE_STEPS:,} time steps of this plant: a faster --prbs-clock or fewer --prbs-bits")


@dataclass(frozen=True, eq=False)
class PrbsCapture:
    """The plant under the sequence, sampled as a scope would: input, output
    (SPICE when simulated, else the op-amp-aware model) and the model."""

    time_s: np.ndarray
    input_v: np.ndarray
    output_v: np.ndarray
    analytic_opamp_v: np.ndarray

    def columns(self) -> dict:
        """Column name -> samples, in the order of waveforms.csv."""
        return {f.name: getattr(self, f.name) for f in fields(self)}


@dataclass(frozen=True, eq=False)
class PrbsRun:
    """The PRBS bench test of a plant: the ``plan`` played, the ``capture``,
    the standalone ``deck``, the ``simulator`` (None: not simulated), the
    ``checks`` of the op-amp under it, and the SPICE output's NRMS difference
    from the model (``nrms``, relative to the output's span)."""

    plan: PrbsPlan
    capture: PrbsCapture
    deck: str
    simulator: str | None
    checks: tuple
    nrms: float | None = None

    def to_dict(self) -> dict:
        y = self.capture.output_v
        return {**self.plan.to_dict(), "low_v": self.plan.offset - self.plan.amplitude,
                "high_v": self.plan.offset + self.plan.amplitude, "simulator": self.simulator,
                "samples": int(y.size), "sample_interval_s": float(self.capture.time_s[1] - self.capture.time_s[0]),
                "output_min_v": float(np.min(y)), "output_max_v": float(np.max(y)),
                "spice_vs_model_nrms": self.nrms, "checks": [c.to_dict() for c in self.checks]}


def model_response(num, den, plan: PrbsPlan, per_interval: int = SAMPLES_PER_INTERVAL) -> tuple:
    """(t, u, y): the held sequence and the exact response of N(s)/D(s) to it,
    at t = (k + 1/2) ts, ts = Dt / ``per_interval``, from the steady state of
    its first level (as ngspice's operating point starts the transient).

    Parameters
    ----------
    num, den : array_like
        The model, highest power first.
    plan : PrbsPlan
        The sequence.
    per_interval : int
        Samples per clock interval.

    Returns
    -------
    tuple of numpy.ndarray
        (t, u, y).
    """
    import scipy.signal as sig
    ts = plan.dt_s / per_interval
    u2 = np.repeat(plan.values(), 2 * per_interval)
    b, a, _ = sig.cont2discrete((num, den), ts / 2, method="zoh")
    u0 = float(u2[0])
    y2 = sig.lfilter(np.squeeze(b), a, u2 - u0) + u0 * float(num[-1] / den[-1])
    t = (np.arange(u2.size // 2) + 0.5) * ts
    return t, u2[1::2].copy(), y2[1::2].copy()


def op_amp_checks(t, y, opamp) -> tuple:
    """The swing and slew the op-amp needs to follow ``y`` (the model's output).

    Parameters
    ----------
    t, y : array_like
        The model's output.
    opamp : designer.core.opamps.OpAmp or None
        The op-amp (None: ideal).

    Returns
    -------
    tuple of designer.core.checks.Check
        The swing and slew checks.
    """
    lo, hi = float(np.min(y)), float(np.max(y))
    slope = float(np.max(np.abs(np.diff(y)))) / float(t[1] - t[0])
    span = {"lo": f"{lo:.3g}", "hi": f"{hi:.3g}"}
    need = f"{slope / 1e6:.3g}"
    if opamp.ideal:
        return (Check.of("prbs_output_swing", True, N_("ideal op-amp; output spans {lo} V to {hi} V"), **span),
                Check.of("prbs_slew_rate", True, N_("ideal op-amp; output needs {need} V/us"), need=need))
    sr = opamp.slew_v_per_s
    return (Check.of("prbs_output_swing", lo >= opamp.vout_min and hi <= opamp.vout_max,
                     N_("under the PRBS the output spans {lo} V to {hi} V; {opamp} reaches {min} V to {max} V"),
                     **span, opamp=opamp.name, min=f"{opamp.vout_min:.3g}", max=f"{opamp.vout_max:.3g}"),
            Check.of("prbs_slew_rate", slope <= 0.5 * sr,
                     N_("under the PRBS the output needs {need} V/us, {opamp} gives {have} V/us")
                     if slope <= 0.5 * sr else
                     N_("under the PRBS the output needs {need} V/us, {opamp} gives {have} V/us (keep below half "
                        "of it: lower the amplitude)"), need=need, opamp=opamp.name, have=f"{sr / 1e6:.3g}"))


def prbs_run(result, plan: PrbsPlan, simulate: bool = True, simulator: str = "pyspice") -> PrbsRun:
    """The plant of ``result`` under ``plan``: the model's response and, when
    ``simulate``, ngspice's (see the module docstring).

    Parameters
    ----------
    result : PlantResult
        The plant.
    plan : PrbsPlan
        The sequence.
    simulate : bool
        Run it in ngspice too.
    simulator : str
        The backend.

    Returns
    -------
    PrbsRun
        The responses, the deck and the checks.
    """
    from .netlist import plant_prbs_deck
    deck = plant_prbs_deck(result.built, result.opamp, plan,
                           f"Sallen-Key plant fn={result.built.fn_hz:.5g}Hz zeta={result.built.zeta:.4g} under a "
                           f"PRBS of {plan.bits} bits, op-amp={result.opamp.name}")
    return run_deck(result.analytic_opamp.num, result.analytic_opamp.den, plan, deck, result.opamp, simulate,
                    simulator, "out", "input")


def run_deck(num, den, plan: PrbsPlan, deck: str, opamp, simulate: bool = True, simulator: str = "pyspice",
             out: str = "out", inp: str = "input") -> PrbsRun:
    """A circuit's PRBS deck (:func:`designer.plant.netlist.prbs_deck`) against its model N(s)/D(s):
    the model's response to the held sequence (:func:`model_response`), the op-amp's checks under
    it and, when ``simulate``, ngspice's output on the same samples.

    Parameters
    ----------
    num, den : array_like
        The op-amp-aware model, highest power first.
    plan : PrbsPlan
        The sequence.
    deck : str
        The circuit under the sequence.
    opamp : designer.core.opamps.OpAmp
        The op-amp.
    simulate : bool
        Run the deck in ngspice too.
    simulator : str
        The backend.
    out, inp : str
        The deck's output and input nets.

    Returns
    -------
    PrbsRun
        The responses, the deck and the checks.
    """
    from ..core.compare import resample
    from ..spice.simulate import get_simulator
    t, u, y_model = model_response(num, den, plan)
    checks = op_amp_checks(t, y_model, opamp)
    if not simulate:
        return PrbsRun(plan, PrbsCapture(t, u, y_model, y_model), deck, None, checks)
    sim = get_simulator(simulator)
    res = sim.run(deck)
    ts = res["time"]
    y = resample(ts, np.real(res[out]), t)
    u_s = resample(ts, np.real(res[inp]), t)
    span = float(np.ptp(y_model)) or 1.0
    fit = float(np.sqrt(np.mean((y - y_model) ** 2)) / span)
    return PrbsRun(plan, PrbsCapture(t, u_s, y, y_model), deck, sim.name, checks, fit)


#: SPICE and the model agree under the PRBS when their RMS difference is below this share of the output's span
NRMS_LIMIT = 0.01


def with_prbs(result, amplitude_v: float, bits=None, clock_hz=None, simulate: bool = True,
              simulator: str = "pyspice"):
    """``result`` with its PRBS bench test (:attr:`PlantResult.prbs`), the
    op-amp's checks under it added to its checks; returned.

    Parameters
    ----------
    result : PlantResult
        The plant.
    amplitude_v : float
        The sequence's amplitude (V).
    bits : int, optional
        The register's length; None: chosen.
    clock_hz : float, optional
        The clock; None: chosen.
    simulate : bool
        Run it in ngspice too.
    simulator : str
        The backend.

    Returns
    -------
    PlantResult
        ``result``.
    """
    plan = plan_for_result(result, amplitude_v, bits, clock_hz)
    return attach(result, prbs_run(result, plan, simulate, simulator))


def attach(result, run: PrbsRun):
    """``result`` (a plant's, any topology) with the PRBS run ``run`` as its ``prbs``, the op-amp's
    checks under it added to its checks, and a note when SPICE departs from the model; returned.

    Parameters
    ----------
    result : PlantResult or designer.plant.circuit_design.CircuitPlantResult
        The plant.
    run : PrbsRun
        Its PRBS bench test.

    Returns
    -------
    object
        ``result``.
    """
    result.prbs = run
    result.checks = list(result.checks) + list(run.checks)
    if run.nrms is not None and run.nrms >= NRMS_LIMIT:
        result.notes.append(f"under the PRBS, SPICE differs from the op-amp-aware model by {100 * run.nrms:.3g} % "
                            "RMS of the output's span")
    return result
