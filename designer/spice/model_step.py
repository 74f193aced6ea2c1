"""A simulated step capture of a plant known only as a model: the response of a
:class:`~designer.core.process.ProcessModel` to an input step, simulated in
ngspice and sampled on a uniform grid as a scope would record it, with its
noise and quantisation if asked.

The deck is the input source, a PWL step of ``step_v`` volts at
``step_time_s`` (rising in :data:`EDGE_FRACTION` of a sample interval: a step
to the grid), and the plant as :func:`designer.spice.behavioural.plant_lines`
writes it (native integrators, the dead time a matched lossless line); it runs
under either backend of :func:`designer.spice.simulate.get_simulator`. The
``.tran`` maximum step is the smaller of the sample interval and
:func:`~designer.spice.behavioural.max_step_hint_s` (about 0.05 % of a step
of integration error), and the PWL has corners where the delayed edge leaves
the line, so that ngspice has time points there (the line sets none at a
mere corner; without them the sample before the delayed edge was 0.07 % of
the step off). The output is interpolated linearly from ngspice's time points
onto the grid, the input is the source's own PWL sampled there: noiseless,
the output is the model's own exact step (:meth:`ProcessModel.step`) within
0.1 % of the step (measured in ``tests/spice/test_model_step.py`` for FOPDT
with dead time, SOPDT, underdamped (zeta = 0.3) and integrating plants:
0.007 % at most with the default 2001 points; a lightly damped pair,
zeta = 0.05, drifts to 0.08 % over its long record of many periods).

Noise and quantisation, as a scope's two channels: Gaussian noise of standard
deviation ``noise_v`` is added to the input and to the output, each its own
draws (the input's first), from ``numpy.random.default_rng(seed)``; then
each channel is rounded to a multiple of ``lsb_v`` (an ADC's step), which
must be at most a quarter of the step's swing on each channel (:data:`MIN_CODES`).
The same seed gives the same samples.

Example: seed 000's DC motor (course notes, UNaM: Km = W(inf)/a and
tau_m = -t0 / ln(1 - w(t0)/W(inf)); a = 2 V, W(inf) = 2.5, w(0.15 s) = 1.75,
so Km = 1.25 and tau_m = 0.1246 s)::

    from designer.core.process_build import fopdt
    from designer.spice.model_step import simulate_step
    t, u, y = simulate_step(fopdt(1.25, 0.1246), step_v=2.0, noise_v=0.01, seed=0)
    # y settles at 2.5 (W(inf)), y(t_step + 0.15 s) = 1.75
"""

from __future__ import annotations

import math
import numbers

import numpy as np

from ..core.errors import DesignError, ParamError
from ..core.process import ProcessModel
from ..core.units import format_eng
from .behavioural import max_step_hint_s, plant_lines
from .deck import MAX_SIM_POINTS

__all__ = ["DURATION_SETTLING_TIMES", "MAX_POINTS", "MIN_CODES", "default_duration_s", "default_step_time_s",
           "simulate_step", "step_deck"]

#: the default record: this many 2 % settling times of the model (:attr:`ProcessModel.settling_time_s`)
DURATION_SETTLING_TIMES = 5.0
#: the default step time: this fraction of the record (a pre-trigger stretch at rest)
STEP_TIME_FRACTION = 0.1
#: the default number of samples, and the allowed range
DEFAULT_POINTS = 2001
MIN_POINTS, MAX_POINTS = 10, 1_000_000
#: the input's rise, as a fraction of the sample interval (a step, to the grid)
EDGE_FRACTION = 1e-3
#: the largest |step|, noise and LSB (volts): beyond, the numbers are a typo
MAX_VOLTS = 1e6
#: the largest seed (numpy takes any non-negative integer; a command line needs a bound)
MAX_SEED = 10**9
#: the fewest quantisation steps (LSBs) the step must span on each channel, input and output: below,
#: the record cannot show it (an LSB above the swing rounds a 1 V step to a record of zeros)
MIN_CODES = 4


def default_duration_s(model: ProcessModel) -> float:
    """The default record length: :data:`DURATION_SETTLING_TIMES` times the
    model's 2 % settling time (its dead time included; an integrating plant's
    is that of its lag, see :attr:`ProcessModel.settling_time_s`); a pure
    integrator K/s, which has none, the same times its time scale 1/|K|
    (:attr:`ProcessModel.time_scale_s`).

    Parameters
    ----------
    model : ProcessModel

    Returns
    -------
    float
        Seconds.
    """
    return DURATION_SETTLING_TIMES * (model.settling_time_s or model.time_scale_s)


def default_step_time_s(duration_s: float, points: int = DEFAULT_POINTS) -> float:
    """The default step time: :data:`STEP_TIME_FRACTION` of the record, moved
    to half a sample interval after the sample there (the step falls between
    two samples, where ``identify`` places an edge it sees between them: on a
    sample, every identified dead time would be half a sample short).

    Parameters
    ----------
    duration_s : float
        The record, seconds.
    points : int
        Its samples.

    Returns
    -------
    float
        Seconds.
    """
    dt = float(duration_s) / (int(points) - 1)
    return (math.floor(STEP_TIME_FRACTION * (int(points) - 1)) + 0.5) * dt


def _eng(v: float, unit: str) -> str:
    return f"0 {unit}" if v == 0 else format_eng(v, unit)


def _number(value, name: str) -> float:
    if isinstance(value, (bool, np.bool_)) or not isinstance(value, numbers.Real):
        raise DesignError(f"{name} must be a number, got {type(value).__name__}", param=name)
    value = float(value)
    if not math.isfinite(value):
        raise DesignError(f"{name} must be a finite number, got {value}", param=name)
    return value


def _checked(model, step_v, step_time_s, duration_s, points, noise_v, lsb_v, seed) -> tuple:
    """The inputs checked, defaults filled: (step_v, step_time_s, duration_s, points)."""
    if not isinstance(model, ProcessModel):
        raise DesignError(f"model must be a ProcessModel, got {type(model).__name__}", param="model")
    step_v = _number(step_v, "step_v")
    if step_v == 0 or abs(step_v) > MAX_VOLTS:
        raise DesignError(f"step_v must be non-zero and at most {MAX_VOLTS:g} V in size, got {step_v:g}",
                          param="step_v")
    if isinstance(points, (bool, np.bool_)) or not isinstance(points, numbers.Integral):
        raise DesignError(f"points must be a whole number, got {points!r}", param="points")
    if not MIN_POINTS <= points <= MAX_POINTS:
        raise DesignError(f"points must be {MIN_POINTS} to {MAX_POINTS}, got {points}", param="points")
    duration_s = default_duration_s(model) if duration_s is None else _number(duration_s, "duration_s")
    if not duration_s > 0:
        raise DesignError(f"duration_s must be above 0 s, got {_eng(duration_s, 's')}", param="duration_s")
    step_time_s = (default_step_time_s(duration_s, points) if step_time_s is None
                   else _number(step_time_s, "step_time_s"))
    if not 0 <= step_time_s < duration_s:
        raise DesignError(f"step_time_s must be 0 or later and before the end of the record "
                          f"(duration {_eng(duration_s, 's')}), got {_eng(step_time_s, 's')}", param="step_time_s")
    for name, v in (("noise_v", noise_v), ("lsb_v", lsb_v)):
        v = _number(v, name)
        if not 0 <= v <= MAX_VOLTS:
            raise DesignError(f"{name} must be 0 to {MAX_VOLTS:g} V, got {v:g}", param=name)
    if isinstance(seed, (bool, np.bool_)) or not isinstance(seed, numbers.Integral) or not 0 <= seed <= MAX_SEED:
        raise DesignError(f"seed must be a whole number 0 to {MAX_SEED}, got {seed!r}", param="seed")
    if lsb_v:
        _check_codes(abs(step_v), float(lsb_v), "the input's step")
    steps = duration_s / max_step_s(model, duration_s, points)
    if steps > MAX_SIM_POINTS:
        hint = max_step_hint_s(model.num, model.den, model.theta_s)
        raise DesignError(f"duration_s {_eng(duration_s, 's')} needs {steps:.3g} simulation steps of at most "
                          f"{_eng(hint, 's')} (the model's fastest pole), more than {MAX_SIM_POINTS:g}: give a "
                          f"record of at most {_eng(MAX_SIM_POINTS * hint, 's')}", param="duration_s")
    return step_v, step_time_s, duration_s, int(points)


def _check_codes(swing: float, lsb_v: float, what: str) -> None:
    """A channel's swing spans at least :data:`MIN_CODES` LSBs, else one line saying the largest LSB that does."""
    if swing < MIN_CODES * lsb_v * (1 - 1e-3):   # (within the simulation's 0.1 % of the step)
        raise ParamError(f"{{lsb_v}} {_eng(lsb_v, 'V')} is too coarse for {what} of {_eng(swing, 'V')}: the record "
                         f"would show it in {swing / lsb_v:.3g} quantisation steps, and it needs at least "
                         f"{MIN_CODES}; give {{lsb_v}} at most {_eng(swing / MIN_CODES, 'V')} (0: none), or a larger "
                         "{step_v}", params=("lsb_v", "step_v"))


def max_step_s(model: ProcessModel, duration_s: float, points: int) -> float:
    """The ``.tran`` maximum step: the sample interval, or shorter where the
    plant's dynamics need it (:func:`~designer.spice.behavioural.max_step_hint_s`)."""
    dt = float(duration_s) / (int(points) - 1)
    return min(dt, max_step_hint_s(model.num, model.den, model.theta_s))


def _num(x: float) -> str:
    return "%.12g" % x


def step_deck(model: ProcessModel, step_v: float = 1.0, step_time_s: float | None = None,
              duration_s: float | None = None, points: int = DEFAULT_POINTS) -> str:
    """The standalone deck of the step: the input ``u`` (a PWL step), the plant
    from ``u`` to ``y``, and the ``.tran`` line.

    Parameters
    ----------
    model : ProcessModel
        The plant.
    step_v : float
        The input step, volts (non-zero, either sign).
    step_time_s : float, optional
        When the input steps, 0 <= it < ``duration_s`` (default
        :func:`default_step_time_s`).
    duration_s : float, optional
        The record, from t = 0 (default :func:`default_duration_s`).
    points : int
        Samples of the record (:data:`MIN_POINTS` to :data:`MAX_POINTS`); they
        set the sample interval, the input's rise and the largest time step.

    Returns
    -------
    str
        Deck text ending in ``.end`` (no ``.control`` block: the backends add theirs).
    """
    step_v, t0, duration, points = _checked(model, step_v, step_time_s, duration_s, points, 0.0, 0.0, 0)
    return _deck(model, step_v, t0, duration, points)


def _deck(model, step_v, t0, duration, points) -> str:
    dt = duration / (points - 1)
    edge = EDGE_FRACTION * dt
    corners = ([(0.0, 0.0)] if t0 > 0 else []) + [(t0, 0.0), (t0 + edge, step_v)]
    if model.theta_s > 0:   # time points where the delayed edge arrives (the line sets none at a corner)
        corners += [(t0 + model.theta_s, step_v), (t0 + model.theta_s + edge, step_v)]
    src = "PWL(" + " ".join(f"{_num(a)} {_num(b)}" for a, b in corners) + ")"
    h = max_step_s(model, duration, points)
    return "\n".join([f"simulated step capture: {model.text()}",
                      f"Vu u 0 {src}",
                      *plant_lines(model.num, model.den, model.theta_s, "u", "y", name="plant"),
                      f".tran {_num(h)} {_num(duration)} 0 {_num(h)}",
                      ".end"]) + "\n"


def simulate_step(model: ProcessModel, step_v: float = 1.0, step_time_s: float | None = None,
                  duration_s: float | None = None, points: int = DEFAULT_POINTS, *, noise_v: float = 0.0,
                  lsb_v: float = 0.0, seed: int = 0, simulator: str = "pyspice",
                  timeout_s: float | None = None) -> tuple:
    """Simulate the model's response to an input step in ngspice, sampled on a uniform grid.

    Parameters
    ----------
    model : ProcessModel
        The plant (any kind: FOPDT, SOPDT, underdamped, rational, integrating;
        with its dead time).
    step_v : float
        The input step, volts: u goes from 0 to ``step_v`` (non-zero, either
        sign, size at most :data:`MAX_VOLTS`).
    step_time_s : float, optional
        When it steps, 0 <= it < ``duration_s`` (default
        :func:`default_step_time_s`: :data:`STEP_TIME_FRACTION` of the
        record, between two samples).
    duration_s : float, optional
        The record, from t = 0, seconds (default :data:`DURATION_SETTLING_TIMES`
        settling times of the model).
    points : int
        Samples, :data:`MIN_POINTS` to :data:`MAX_POINTS`, t = 0 to ``duration_s``
        inclusive.
    noise_v : float
        Standard deviation of Gaussian noise added to each channel, volts (0: none).
    lsb_v : float
        Quantisation step of each channel, volts (0: none); applied after the
        noise. The step must span at least :data:`MIN_CODES` of them on the
        input (``step_v``) and on the output (its noiseless swing over the
        record), else the record could not show it: refused.
    seed : int
        Seed of the ``numpy.random.default_rng`` the noise is drawn from
        (0 to :data:`MAX_SEED`).
    simulator : {"pyspice", "ngspice-cli"}
        The backend (:func:`designer.spice.simulate.get_simulator`).
    timeout_s : float, optional
        Bound of an ``ngspice -b`` run (the default of ``get_simulator``).

    Returns
    -------
    t, u, y : ndarray
        Time (s, uniform), input and output (V), ``points`` samples each.

    Raises
    ------
    DesignError
        An input outside its range, in one line naming the parameter.
    SimulatorError
        ngspice missing or failed.

    Examples
    --------
    Seed 000's DC motor, Km = 1.25, tau_m = 0.1246 s, driven with a = 2 V:

    >>> from designer.core.process_build import fopdt
    >>> t, u, y = simulate_step(fopdt(1.25, 0.1246), step_v=2.0)   # doctest: +SKIP
    >>> round(float(y[-1]), 3)                                      # doctest: +SKIP
    2.5
    """
    from .simulate import get_simulator
    step_v, t0, duration, points = _checked(model, step_v, step_time_s, duration_s, points, noise_v, lsb_v, seed)
    sim = get_simulator(simulator, timeout=timeout_s)
    res = sim.run(_deck(model, step_v, t0, duration, points))
    t = np.linspace(0.0, duration, points)
    ts = res["time"]
    # the input is the source's own PWL on the grid (ngspice's time points near a breakpoint are
    # placed within its tolerance, and interpolating them puts a sliver of the edge on the sample at t0)
    u = np.interp(t, [t0, t0 + EDGE_FRACTION * duration / (points - 1)], [0.0, step_v])
    y = np.interp(t, ts, res["y"])
    return t, *_recorded(u, y, points, noise_v, lsb_v, seed)


def _recorded(u, y, points, noise_v, lsb_v, seed) -> tuple:
    """(u, y) as the scope records them: the output's swing checked against the LSB, noise from
    ``default_rng(seed)`` (the input's draws first), then quantisation."""
    if lsb_v > 0:   # the output's swing over the record, noiseless (the input's was checked before the run)
        _check_codes(float(np.ptp(y)), lsb_v, "the output's swing")
    if noise_v > 0:
        rng = np.random.default_rng(seed)
        u = u + noise_v * rng.standard_normal(points)
        y = y + noise_v * rng.standard_normal(points)
    if lsb_v > 0:
        u = lsb_v * np.round(u / lsb_v)
        y = lsb_v * np.round(y / lsb_v)
    return u, y


def input_deck(model: ProcessModel, corners_t, corners_v, duration_s: float, points: int) -> str:
    """The standalone deck of the model under a piecewise-linear input: the source ``u`` (its
    corners on continuation lines), the plant from ``u`` to ``y`` and the ``.tran`` line.

    Parameters
    ----------
    model : ProcessModel
        The plant.
    corners_t, corners_v : array_like
        The source's corners (s, increasing; V).
    duration_s : float
        The record, seconds.
    points : int
        Its samples (they set the largest time step).

    Returns
    -------
    str
        Deck text ending in ``.end``.
    """
    pairs = [f"{_num(a)} {_num(b)}" for a, b in zip(corners_t, corners_v)]
    src = ["Vu u 0 PWL("] + ["+ " + " ".join(pairs[i:i + 8]) for i in range(0, len(pairs), 8)] + ["+ )"]
    h = max_step_s(model, duration_s, points)
    return "\n".join([f"simulated capture: {model.text()}", *src,
                      *plant_lines(model.num, model.den, model.theta_s, "u", "y", name="plant"),
                      f".tran {_num(h)} {_num(duration_s)} 0 {_num(h)}", ".end"]) + "\n"


def simulate_input(model: ProcessModel, excitation, duration_s: float, points: int = DEFAULT_POINTS, *,
                   noise_v: float = 0.0, lsb_v: float = 0.0, seed: int = 0, simulator: str = "pyspice",
                   timeout_s: float | None = None) -> tuple:
    """Simulate the model's response to any input (a PRBS, a random binary signal, a chirp, a
    recorded signal: :mod:`designer.core.excitation`) in ngspice, sampled on a uniform grid and
    recorded as :func:`simulate_step` records a step (the same noise, quantisation and checks,
    the input's swing in place of the step).

    Parameters
    ----------
    model : ProcessModel
        The plant.
    excitation : Excitation
        The input's corners (:class:`designer.core.excitation.Excitation`).
    duration_s : float
        The record, from t = 0, seconds.
    points : int
        Samples, :data:`MIN_POINTS` to :data:`MAX_POINTS`.
    noise_v, lsb_v, seed, simulator, timeout_s
        As :func:`simulate_step`'s.

    Returns
    -------
    tuple of ndarray
        ``(t, u, y)`` on the uniform grid, as :func:`simulate_step` returns them.

    Raises
    ------
    DesignError, SimulatorError
        As :func:`simulate_step` (the input's swing checked against ``lsb_v`` as its step is).
    """
    from .simulate import get_simulator
    swing = float(np.ptp(excitation.v))
    _, _, duration, points = _checked(model, swing or 1.0, 0.0, duration_s, points, noise_v, lsb_v, seed)
    sim = get_simulator(simulator, timeout=timeout_s)
    res = sim.run(input_deck(model, excitation.t, excitation.v, duration, points))
    t = np.linspace(0.0, duration, points)
    u = excitation.at(t)
    y = np.interp(t, res["time"], res["y"])
    return t, *_recorded(u, y, points, noise_v, lsb_v, seed)
