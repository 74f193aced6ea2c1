"""The SPICE engine of the plant Monte Carlo (issue 17): every sample simulated
in ngspice, many samples per ngspice process.

The engine takes a section (issue 26): a registered low-pass
:class:`~designer.filters.topology.Topology`, its values by designator and its op-amp, and a
deck of it under a square-wave test (the Sallen-Key plant's, :func:`designer.plant.netlist.plant_deck`,
output net ``out``; any low-pass section's, :func:`designer.plant.circuit_design.square_deck`,
output net ``vout``). The deck is loaded once, without its ``.tran`` and ``.meas`` lines; a loop of control
commands then, per sample, ``alter``\\ s each part of the section
(by its designator, as the section's ``.ac`` engine does, :mod:`.spice_ac`; the op-amp's integrating capacitor for
``--tol GBW``; for ``--tol SR`` the op-amp subcircuit's own ``SR`` parameter,
made a global ``.param`` of the loaded copy, is changed by ``alterparam`` and the
circuit ``reset`` before the other alters, :func:`opamp_commands`), runs ``tran`` over the rising half of the bench period only, and
``meas``\\ ures from the control block (in ngspice 39 a deck's own ``.meas`` lines
print the first pass's value on every pass of an ``alter`` loop). Both backends
of :mod:`designer.spice.simulate` run the loop (``run_script``): ``ngspice -b``
with a ``.control`` block, or the shared library fed the commands one by one.

Measured per sample: the peak of v(out) (MAX), the first peak's time (where
d v(out)/dt falls through 0: MAX_AT is quantised to the time grid), the 10 % and
90 % crossings and the last time |v(out) - final|/final crosses 2 %. From them,
with the final value final = amplitude x G(0), the op-amp model's DC gain
(:meth:`~designer.filters.topology.Topology.step_final`; the Sallen-Key low-pass's K A0/(K + A0),
K = 1 + R4/R3; an inverting section's output, negative, is measured negated):

- ``overshoot_pct`` = 100 (peak - final)/final, ``peak_time_s`` (from the step's edge),
  ``rise_time_s`` (10-90 %), ``settling_time_s`` (2 %);
- ``zeta``, ``fn_hz``, ``q``: the second-order equivalents of the step, zeta from the
  overshoot (zeta = -ln(OS)/sqrt(pi^2 + ln^2 OS)) and fn from the peak time
  (tp = pi/(wn sqrt(1 - zeta^2))), seed 001's step relations inverted. The analytic
  engine's fn/zeta are the third-order model's dominant pair: with an LM741
  (GBW 1 MHz) under the seed's 3.5 kHz plant the two definitions differ by about
  0.1 % in fn. Without an overshoot (below :data:`OVERSHOOT_FLOOR_PCT`) the step has
  no peak: peak time, fn, zeta and Q are NaN.

A low-pass steps to its DC gain: the engine takes the low-pass sections only (a high-pass's or a
band-pass's step settles to 0, where these levels mean nothing). On a first-order section (the RC
low-pass) the step has no overshoot: its rise and settling times are measured, its fn and zeta NaN.

The maximum step is :data:`MAX_STEP_FACTOR` times the deck's (at most 1/30 of the
response's time scale): /work/shared/FACTS.md measured 0.007 pp of overshoot and
0.015 % of peak time against the deck's own step, ten times faster.

:func:`evaluate` is a pure function of picklable arguments (a :class:`SpiceContext`
and a chunk of samples), so a scale-out runner can map it over chunks on workers.
"""

from __future__ import annotations

import math
import re
from dataclasses import dataclass

import numpy as np

from ..core.errors import DesignError, SimulatorError
from ..filters import registry

__all__ = ["FIGURES", "batched", "commands", "context", "evaluate", "measures", "parse", "step_sections"]

#: the figures the SPICE engine gives
FIGURES = ("fn_hz", "zeta", "q", "overshoot_pct", "peak_time_s", "rise_time_s", "settling_time_s")
#: the figures both engines give (their disagreement is reported by ``--engine both``)
SHARED = ("fn_hz", "zeta", "q", "overshoot_pct", "peak_time_s")
#: the loop's maximum time step against the plant deck's (FACTS.md: x10, 0.007 pp of overshoot)
MAX_STEP_FACTOR = 10
#: ... and at most this fraction of the response's time scale (1/wn)
MIN_STEPS_PER_TIME_SCALE = 30
#: an overshoot below this (percent) is no peak: the step is taken as monotone
OVERSHOOT_FLOOR_PCT = 0.01
#: samples per ngspice run (bounds one run's output and time; a chunk larger than this takes several)
BATCH = 1000
#: seconds allowed per sample of a batch, on top of the simulator's fixed timeout
SECONDS_PER_SAMPLE = 1.0
#: the measurements of one sample, by the name ngspice prints
_MEASURES = ("mcpeak", "mctpk", "mct10", "mct90", "mcts")
_LINE = re.compile(r"^\s*(mcpeak|mctpk|mct10|mct90|mcts)\s*=\s*([-+]?[\d.]+(?:[eE][-+]?\d+)?)", re.M)
_ROW = re.compile(r"^\s*MCROW (\d+)\s*$", re.M)
#: the op-amp figures an engine may vary (designer.tolerance.parts.OPAMP_FIGURES)
OPAMP = ("GBW", "SR")
#: the global parameter the loaded circuit gives every op-amp's slew rate (:func:`slew_parametrised`)
SLEW_PARAM = "mcsr"


@dataclass(frozen=True)
class SpiceContext:
    """What every sample of one design shares (picklable: strings, numbers and the op-amp record).

    ``circuit`` is the deck without its analyses; ``elements`` maps each
    designator that may vary to its element in the deck (``R3`` -> ``r3``);
    ``cint`` names the op-amp's integrating capacitor and ``rint`` its resistor
    (``GBW`` varies through C = A0/(2 pi GBW RINT); the model's slew current is fixed
    at the nominal one, so the slew rate follows the gain-bandwidth, as a real
    op-amp's compensation capacitor moves both, unless ``SR`` varies too:
    :func:`opamp_commands`, :func:`designer.tolerance.parts.opamp_arrays`); ``section`` the
    registered section, ``node`` its output net in the deck, ``sign`` -1 for an inverting
    section (its output measured negated), ``opamp`` the op-amp (the settled output's A0)."""

    circuit: str
    elements: tuple
    t0: float
    t1: float
    max_step_s: float
    amplitude_v: float
    a0: float
    nominal: tuple                    #: (designator, nominal value) of every part that may vary
    cint: str | None = None
    rint: float | None = None
    simulator: str = "ngspice-cli"
    section: str = "sallen-key-lowpass"
    node: str = "out"
    sign: float = 1.0
    opamp: object = None

    def final_v(self, values: dict, n: int) -> np.ndarray:
        """Each sample's settled output: amplitude x G(0) of its parts (the drawn ones, the others
        at their nominal), :meth:`~designer.filters.topology.Topology.step_final`."""
        topo = registry.get(self.section)
        nom = dict(self.nominal)
        parts = {r: np.broadcast_to(np.asarray(values.get(r, nom[r]), float), (n,)) for r in topo.designators}
        return np.asarray(topo.step_final(parts, self.opamp, self.amplitude_v), float) * np.ones(n)


def step_sections() -> tuple:
    """The registered sections the step engine takes: the low-passes (a step settles to their DC gain).

    Returns
    -------
    tuple of str
        Their registry names.
    """
    return tuple(n for n in registry.names() if registry.get(n).kind == "lowpass")


def context(deck: str, topology, values: dict, opamp, test, simulator: str = "ngspice-cli",
            node: str = "out") -> SpiceContext:
    """The :class:`SpiceContext` of a section's step deck for the backend ``simulator``: the
    Sallen-Key plant's (a :class:`~designer.plant.result.PlantResult`'s ``deck``, its parts' section
    and values, ``opamp`` and ``test``), or any low-pass section's under a square wave.

    Parameters
    ----------
    deck : str
        The deck: the section (its parts named by designator, its op-amp ``U1``) under ``test``.
    topology : designer.filters.topology.Topology or str
        The section (or its registry name): a low-pass (:func:`step_sections`).
    values : dict
        Its nominal values by designator.
    opamp : designer.core.opamps.OpAmp
        Its op-amp.
    test : designer.spice.deck.SquareTest
        The deck's square-wave test.
    simulator : str
        The backend.
    node : str
        The section's output net in the deck (the plant deck's ``out``; a section's own netlist's ``vout``).

    Returns
    -------
    SpiceContext
        The context.

    Raises
    ------
    DesignError
        The section is not a low-pass.
    """
    topo = registry.get(topology) if isinstance(topology, str) else topology
    if topo.kind != "lowpass":
        raise DesignError(f"topology: the SPICE step engine measures a low-pass's step (it settles to the DC gain); "
                          f"{topo.name} is a {topo.kind}; allowed: {', '.join(step_sections())}", param="topology")
    keep = [ln for ln in deck.splitlines()
            if not re.match(r"\s*\.(meas\w*|tran|end)\b", ln, re.I)]
    values = topo.values_of(values)
    net = topo.netlist({r: float(v) for r, v in values.items()})
    elements = tuple((p.ref, p.ref.lower()) for p in net.parts)
    nominal = tuple((p.ref, float(values[p.ref])) for p in net.parts)
    step = MAX_STEP_FACTOR * test.max_step_s()
    if test.time_scale_s is not None:
        step = min(step, test.time_scale_s / MIN_STEPS_PER_TIME_SCALE)
    cint = rint = None
    circuit = "\n".join(keep) + "\n.end\n"
    if not opamp.ideal:
        rint = deck_rint(deck)
        cint = f"c.x{net.amps[0].ref.lower()}.cint"
        nominal += (("GBW", opamp.gbw_hz), ("SR", opamp.slew_v_per_s))
        circuit = slew_parametrised(circuit)
    from ..spice.simulate import get_simulator
    return SpiceContext(circuit, elements, test.delay_s, test.delay_s + test.half_period_s,
                        step, test.amplitude_v, opamp.a0, nominal, cint, rint, get_simulator(simulator).name,
                        topo.name, node, -1.0 if topo.inverting else 1.0, opamp)


def commands(ctx: SpiceContext, values: dict, start: int = 0) -> list:
    """The control commands of samples ``start``.. (their values ``values``): per sample its
    ``alter`` lines, ``tran`` over the rising half, a row marker, the ``meas`` lines, ``destroy all``.

    Parameters
    ----------
    ctx : SpiceContext
        The deck and its test.
    values : dict
        Designator -> array over the samples.
    start : int
        The first sample's index.

    Returns
    -------
    list of str
        The commands.
    """
    n = len(next(iter(values.values())))
    final = ctx.final_v(values, n)
    elem = dict(ctx.elements)
    unknown = [d for d in values if d not in elem and d not in OPAMP]
    if unknown:
        raise ValueError(f"the deck has no part {unknown[0]}")
    if any(d in values for d in OPAMP) and ctx.cint is None:
        raise ValueError("the ideal op-amp has no gain-bandwidth or slew rate to vary")
    win = f"FROM={ctx.t0:.10g} TO={ctx.t1:.10g}"
    tran = f"tran {ctx.max_step_s:.6g} {ctx.t1:.10g} 0 {ctx.max_step_s:.6g}"
    nom = dict(ctx.nominal)
    out = []
    for i in range(n):
        if ctx.cint is not None:
            out += opamp_commands(values, i, (ctx.cint,), ctx.a0, ctx.rint, nom["GBW"], nom["SR"])
        for d, v in values.items():
            if d not in OPAMP:
                out.append(f"alter {elem[d]} = {float(v[i]):.12g}")
        # an inverting section's output measured negated: its step rises to |final| as a plant's does
        f = ctx.sign * float(final[i])
        out += [tran, f"echo MCROW {start + i}", *measures(win, f, ctx.node, sign=ctx.sign), "destroy all"]
    return out


def deck_rint(deck: str) -> float:
    """The behavioural op-amp's integrating resistor RINT (ohm), as the deck's library sets it."""
    from ..core.units import parse_value
    m = re.search(r"^\.param\s+RINT\s*=\s*(\S+)", deck, re.M | re.I)
    if m is None:
        raise ValueError("the deck's op-amp library sets no RINT")
    return parse_value(m.group(1), "RINT")


def slew_parametrised(circuit: str) -> str:
    """``circuit`` with every behavioural op-amp instance's ``SR=`` value replaced by the global
    parameter :data:`SLEW_PARAM` (its nominal, the first instance's), which ``alterparam`` can
    change per build (a subcircuit's parameters are fixed once it is expanded; a B source's
    expression is out of ``alter``'s reach). The same circuit at the nominal."""
    inst = re.compile(r"^(X\S*\s.*\bOPAMP_BEH\b.*\bSR=)(\S+)", re.M | re.I)
    m = inst.search(circuit)
    if m is None:
        return circuit
    body = inst.sub(lambda k: k.group(1) + "{" + SLEW_PARAM + "}", circuit)
    first, rest = body.split("\n", 1)         # the title line stays first
    return f"{first}\n.param {SLEW_PARAM}={m.group(2)}\n{rest}"


def opamp_commands(values: dict, i: int, cints, a0: float, rint: float, gbw_nominal: float,
                   sr_nominal: float) -> list:
    """Build ``i``'s op-amp commands: with a drawn ``SR``, ``alterparam`` of :data:`SLEW_PARAM` and
    ``reset`` (first: a reset re-expands the circuit, undoing earlier alters); with a drawn ``GBW``,
    every integrating capacitor ``cints`` altered to A0/(2 pi GBW RINT).

    The subcircuit's slew current is IMAX = SR x CINT of the parsed values; with CINT then altered
    for the build's GBW its slew rate is IMAX/CINT, so the parameter is set to
    SR_build x GBW_nominal/GBW_build, which gives SR_build exactly. Without a drawn SR the slew rate
    follows the GBW (:func:`designer.tolerance.parts.opamp_arrays`)."""
    out = []
    gbw = float(values["GBW"][i]) if "GBW" in values else gbw_nominal
    if "SR" in values:
        out += [f"alterparam {SLEW_PARAM} = {float(values['SR'][i]) * gbw_nominal / gbw:.12g}", "reset"]
    if "GBW" in values:
        c = a0 / (2 * math.pi * gbw * rint)
        out += [f"alter {ref} = {c:.12g}" for ref in cints]
    return out


def measures(win: str, final: float, node: str = "out", first_peak: bool = True, sign: float = 1.0) -> list:
    """The control block's measurements of one run (peak, peak time, 10-90 % and 2 % settling
    crossings) of ``v(node)`` within ``win`` (``FROM=.. TO=..``), ``final`` the settled output.
    The peak's time: ``first_peak``, where the slope first falls through 0 (a plant's second-order
    step, whose first peak is its highest; not quantised to the time grid), else where the
    highest value is (``MAX_AT``, as a loop deck's own ``.meas`` reads it: a loop's first ripple
    need not be its peak).

    Parameters
    ----------
    win : str
        The window, ``FROM=.. TO=..``.
    final : float
        The settled output (V).
    node : str
        The node measured.
    first_peak : bool
        The peak's time where the slope first falls through 0.
    sign : float
        -1: ``-v(node)`` measured (an inverting section's output; ``final`` then its magnitude).

    Returns
    -------
    list of str
        The ``meas`` commands.
    """
    f, v = final, f"v({node})"
    neg = []
    if sign < 0:
        neg, v = [f"let mcneg = -{v}"], "mcneg"
    peak = ([f"let mcdv = deriv({v})", f"meas tran mctpk WHEN mcdv=0 FALL=1 {win}"] if first_peak else
            [f"meas tran mctpk MAX_AT {v} {win}"])
    return [*neg, f"meas tran mcpeak MAX {v} {win}",
            *peak,
            f"meas tran mct10 WHEN {v}={0.1 * f:.10g} CROSS=1 {win}",
            f"meas tran mct90 WHEN {v}={0.9 * f:.10g} CROSS=1 {win}",
            f"let mcerr = abs({v}-{f:.10g})/{f:.10g}",
            f"meas tran mcts WHEN mcerr=0.02 CROSS=LAST {win}"]


def parse(output: str, start: int, n: int) -> dict:
    """Measurement -> array over samples ``start`` .. ``start + n - 1`` (NaN where a ``meas``
    failed); a :class:`SimulatorError` when a sample's row is missing (ngspice stopped).

    Parameters
    ----------
    output : str
        ngspice's output.
    start : int
        The first sample's index.
    n : int
        The samples.

    Returns
    -------
    dict
        Measurement -> array over the samples.
    """
    raw = {k: np.full(n, np.nan) for k in _MEASURES}
    marks = list(_ROW.finditer(output))
    seen = set()
    for j, m in enumerate(marks):
        i = int(m.group(1)) - start
        if not 0 <= i < n:
            continue
        seen.add(i)
        seg = output[m.end():marks[j + 1].start() if j + 1 < len(marks) else len(output)]
        for name, value in _LINE.findall(seg):
            raw[name][i] = float(value)
    if len(seen) < n:
        missing = min(set(range(n)) - seen) + start
        raise SimulatorError(f"ngspice stopped before Monte Carlo sample {missing} (of {start}..{start + n - 1})")
    return raw


def figures(ctx: SpiceContext, values: dict, raw: dict) -> dict:
    """The figures of :data:`FIGURES` from each sample's measurements (module docstring)."""
    return step_figures(raw, ctx.sign * ctx.final_v(values, len(raw["mcpeak"])), ctx.t0)


def step_figures(raw: dict, final, t0: float) -> dict:
    """The figures of :data:`FIGURES` from each sample's measurements ``raw`` (:data:`_MEASURES`,
    arrays), its settled output ``final`` and the step's time ``t0`` (module docstring)."""
    over = np.maximum(0.0, 100.0 * (raw["mcpeak"] - final) / final)
    peaked = over > OVERSHOOT_FLOOR_PCT
    tp = np.where(peaked, raw["mctpk"] - t0, np.nan)
    with np.errstate(divide="ignore", invalid="ignore"):
        ln = np.log(np.where(peaked, over / 100.0, np.nan))
        zeta = -ln / np.sqrt(math.pi ** 2 + ln * ln)
        wn = math.pi / (tp * np.sqrt(1.0 - zeta * zeta))
        return {"fn_hz": wn / (2 * math.pi), "zeta": zeta, "q": 1.0 / (2.0 * zeta), "overshoot_pct": over,
                "peak_time_s": tp, "rise_time_s": raw["mct90"] - raw["mct10"],
                "settling_time_s": raw["mcts"] - t0}


def evaluate(ctx: SpiceContext, values: dict, start: int = 0) -> dict:
    """Every figure of :data:`FIGURES` for a chunk of samples (designator -> array), each
    simulated in ngspice: one loaded circuit per :data:`BATCH` samples.

    Pure: the same context and values give the same figures in any process
    (``start`` only labels the samples in ngspice's output and its messages).

    Parameters
    ----------
    ctx : SpiceContext
        The deck and its test.
    values : dict
        Designator -> array over the chunk's samples.
    start : int
        The first sample's index.

    Returns
    -------
    dict
        Figure -> array over the samples.
    """
    def run(sim, chunk, lo):
        n = len(next(iter(chunk.values())))
        return figures(ctx, chunk, parse(sim.run_script(ctx.circuit, commands(ctx, chunk, start + lo)), start + lo, n))
    return batched(values, FIGURES, ctx.simulator, run)


def batched(values: dict, names, simulator: str, run) -> dict:
    """A SPICE engine's figures over a chunk of builds, :data:`BATCH` builds per ngspice run:
    ``run(sim, batch, lo)`` gives the figures of the builds ``batch`` (their values, the first at
    index ``lo`` of the chunk) on the backend ``sim``, allowed :data:`SECONDS_PER_SAMPLE` a build.

    Parameters
    ----------
    values : dict
        Designator -> array over the chunk's builds.
    names : tuple of str
        The figures.
    simulator : str
        The backend's name.
    run : callable
        ``run(sim, batch, lo) -> {figure: array}``.

    Returns
    -------
    dict
        Figure -> array over the chunk's builds (NaN where none).
    """
    from ..spice.simulate import DEFAULT_TIMEOUT_S, get_simulator
    values = {k: np.atleast_1d(np.asarray(v, float)) for k, v in values.items()}
    n = len(next(iter(values.values())))
    out = {k: np.full(n, np.nan) for k in names}
    for lo in range(0, n, BATCH):
        hi = min(n, lo + BATCH)
        chunk = {k: v[lo:hi] for k, v in values.items()}
        figs = run(get_simulator(simulator, timeout=DEFAULT_TIMEOUT_S + SECONDS_PER_SAMPLE * (hi - lo)), chunk, lo)
        for k in names:
            out[k][lo:hi] = figs[k]
    return out
