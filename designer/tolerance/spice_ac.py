"""The SPICE engine of a Monte Carlo on a registered section's plant (``design-plant
--topology NAME --engine spice|both``): every build simulated in ngspice, many builds
per ngspice process, as the Sallen-Key plant's engine does (:mod:`.spice_engine`).

The section's ``.ac`` deck (:func:`designer.filters.deck.ac_deck`, the one the
plant's SPICE check runs) is loaded once without its analysis; a loop of control
commands then, per build, ``alter``\\ s each part of the section by its designator
(``R3`` -> element ``r3``: the deck's parts are the topology's netlist; a drawn ``GBW``, the
op-amp's gain-bandwidth, alters every op-amp's integrating capacitor to A0/(2 pi GBW RINT), as the
Sallen-Key plant's engine does, :func:`designer.tolerance.spice_engine.opamp_commands`), runs
``ac dec`` :data:`POINTS_PER_DECADE` over fn / :data:`SPAN` .. fn x :data:`SPAN`
(fn the nominal build's), and ``echo``\\ es the sweep's frequencies (ngspice spreads
its points evenly in log f between the two ends) and the real and imaginary parts of v(vout).

The figures are those of the second-order (first-order) section the response is
closest to: the section's own form H(s) = s^m / (a0 + a1 s + a2 s^2), m the power
of s of its numerator (0 for a low-pass, 1 for a band-pass or first-order high-pass,
2 for a high-pass), fitted by linear least squares on s^m / H(j w) over the sweep
(Levy's method, E. C. Levy, "Complex-curve fitting", IRE Trans. Automatic Control,
1959): wn = sqrt(a0 / a2), Q = sqrt(a0 a2) / |a1| (first order: wn = a0 / a1), and
the gain 1 / |a_m| (the passband gain magnitude of each form: at DC, at infinity or
at the centre frequency). With an ideal op-amp they are the section's closed forms;
with the op-amp model the response has one pole more (the op-amp's), and the fit
lands next to the analytic engine's dominant pair (the tests state how near).
``overshoot_pct`` and ``peak_time_s`` follow from the fitted pair as the analytic
engine's follow from its own (:func:`designer.plant.circuit.step_of_pair`).

:func:`evaluate` is a pure function of picklable arguments (an :class:`AcContext`
and a chunk of builds), so a scale-out runner can map it over chunks on workers.
"""

from __future__ import annotations

import math
import re
from dataclasses import dataclass

import numpy as np

from ..core.errors import SimulatorError

__all__ = ["FIGURES", "POINTS_PER_DECADE", "SPAN", "AcContext", "context", "commands", "parse", "fit", "evaluate",
           "section_chunk", "section_evaluate"]

#: the figures the engine measures (and the analytic engine gives too: their disagreement is reported)
FIGURES = ("fn_hz", "zeta", "q", "gain")
#: the sweep: fn / SPAN .. fn x SPAN, POINTS_PER_DECADE a decade (10 points at the default)
SPAN = 3.0
POINTS_PER_DECADE = 10
_ROW = re.compile(r"^\s*MCROW (\d+)\s*$", re.M)
_VALUES = re.compile(r"^\s*(MCF|MCRE|MCIM)\s+(.*)$", re.M)


@dataclass(frozen=True)
class AcContext:
    """What every build of one section's Monte Carlo shares (picklable: strings and numbers).

    Parameters
    ----------
    circuit : str
        The section's ``.ac`` deck without its analysis.
    elements : tuple
        (designator, element name) of every part that may vary.
    f_lo_hz, f_hi_hz : float
        The sweep.
    order : int
        The section's order (1 or 2).
    zeros : int
        The power of s of its numerator (m in the module docstring).
    simulator : str
        The backend's name.
    cints : tuple
        The op-amps' integrating capacitors (``c.xu1.cint``; empty with the ideal op-amp).
    a0, rint, gbw_hz : float
        The op-amp model's DC gain, integrating resistor (ohm) and nominal gain-bandwidth (Hz).
    """

    circuit: str
    elements: tuple
    f_lo_hz: float
    f_hi_hz: float
    order: int
    zeros: int
    simulator: str = "ngspice-cli"
    cints: tuple = ()
    a0: float = 0.0
    rint: float = 0.0
    gbw_hz: float = 0.0


def context(deck: str, netlist, topology, values: dict, fn_hz: float, simulator: str = "ngspice-cli",
            opamp=None) -> AcContext:
    """The :class:`AcContext` of a section plant's deck.

    Parameters
    ----------
    deck : str
        The section's ``.ac`` deck (a :class:`~designer.plant.circuit_design.CircuitPlantResult`'s ``deck``).
    netlist : designer.spice.deck.Netlist
        Its parts (their designators are the deck's elements).
    topology : designer.filters.topology.Topology
        The section.
    values : dict
        The nominal build: designator -> value.
    fn_hz : float
        The sweep's centre.
    simulator : str
        The backend.
    opamp : designer.core.opamps.OpAmp, optional
        The deck's op-amp, whose gain-bandwidth a build may vary (None or the ideal one: not).

    Returns
    -------
    AcContext
        The context.
    """
    from ..spice.simulate import get_simulator
    from .spice_engine import deck_rint
    keep = [ln for ln in deck.splitlines() if not re.match(r"\s*\.(ac|end)\b", ln, re.I)]
    num = np.atleast_1d(np.asarray(topology.coefficients(values)[0], float))
    scale = np.max(np.abs(num))
    zeros = 0
    while zeros < num.size - 1 and abs(num[num.size - 1 - zeros]) <= 1e-12 * scale:
        zeros += 1
    amp = () if opamp is None or opamp.ideal else (tuple(f"c.x{a.ref.lower()}.cint" for a in netlist.amps),
                                                   opamp.a0, deck_rint(deck), opamp.gbw_hz)
    return AcContext("\n".join(keep) + "\n.end\n", tuple((p.ref, p.ref.lower()) for p in netlist.parts),
                     fn_hz / SPAN, fn_hz * SPAN, topology.order, zeros, get_simulator(simulator).name, *amp)


def commands(ctx: AcContext, values: dict, start: int = 0) -> list:
    """The control commands of builds ``start``.. (their values ``values``): per build its
    ``alter`` lines, the ``ac`` sweep, a row marker, v(vout)'s real and imaginary parts, ``destroy all``.

    Parameters
    ----------
    ctx : AcContext
        The deck and its sweep.
    values : dict
        Designator -> array over the builds.
    start : int
        The first build's index.

    Returns
    -------
    list of str
        The commands.
    """
    from .spice_engine import opamp_commands
    n = len(next(iter(values.values())))
    elem = dict(ctx.elements)
    unknown = [d for d in values if d not in elem and not (d == "GBW" and ctx.cints)]
    if unknown:
        raise ValueError(f"the section's deck has no part {unknown[0]}")
    sweep = f"ac dec {POINTS_PER_DECADE} {ctx.f_lo_hz:.12g} {ctx.f_hi_hz:.12g}"
    out = []
    for i in range(n):
        if "GBW" in values:   # the slew rate is no .ac's business: only the integrating capacitors move
            out += opamp_commands({"GBW": values["GBW"]}, i, ctx.cints, ctx.a0, ctx.rint, ctx.gbw_hz, 0.0)
        out += [f"alter {elem[d]} = {float(v[i]):.12g}" for d, v in values.items() if d != "GBW"]
        out += [sweep, f"echo MCROW {start + i}", "let mcf = real(frequency)", "let mcre = real(v(vout))",
                "let mcim = imag(v(vout))", "echo MCF $&mcf", "echo MCRE $&mcre", "echo MCIM $&mcim", "destroy all"]
    return out


def parse(output: str, start: int, n: int) -> tuple:
    """The sweep's frequencies and v(vout) of builds ``start`` .. ``start + n - 1`` (complex,
    shape (n, points)); a :class:`SimulatorError` when a build's row is missing or short.

    Parameters
    ----------
    output : str
        ngspice's output.
    start : int
        The first build's index.
    n : int
        The builds.

    Returns
    -------
    tuple
        (frequencies in Hz, complex responses (n, points)).
    """
    marks = list(_ROW.finditer(output))
    f, rows = None, {}
    for j, m in enumerate(marks):
        i = int(m.group(1)) - start
        if not 0 <= i < n:
            continue
        seg = output[m.end():marks[j + 1].start() if j + 1 < len(marks) else len(output)]
        got = {name: np.array(text.split(), float) for name, text in _VALUES.findall(seg)}
        if f is None and "MCF" in got:
            f = got["MCF"]
        if f is not None and all(k in got and got[k].size == f.size for k in ("MCRE", "MCIM")):
            rows[i] = got["MCRE"] + 1j * got["MCIM"]
    if len(rows) < n:
        missing = min(set(range(n)) - set(rows)) + start
        raise SimulatorError(f"ngspice stopped before Monte Carlo sample {missing} (of {start}..{start + n - 1})")
    return f, np.stack([rows[i] for i in range(n)])


def fit(f_hz, h, order: int, zeros: int) -> dict:
    """The figures of the section form nearest each response (module docstring).

    Parameters
    ----------
    f_hz : array_like
        The frequencies (Hz).
    h : array_like
        Complex responses, (builds, frequencies) or one response.
    order : int
        1 or 2.
    zeros : int
        The numerator's power of s.

    Returns
    -------
    dict
        ``fn_hz``, ``zeta``, ``q``, ``gain``: arrays over the builds (NaN zeta, Q at first order).
    """
    s = 2j * np.pi * np.asarray(f_hz, float)
    h = np.atleast_2d(np.asarray(h, complex))
    basis = np.stack([s ** k for k in range(order + 1)], axis=1)            # (points, order + 1)
    a_mat = np.concatenate([basis.real, basis.imag])
    rhs = s ** zeros / h                                                   # (builds, points)
    coef = np.linalg.lstsq(a_mat, np.concatenate([rhs.real, rhs.imag], axis=1).T, rcond=None)[0]
    a = np.abs(coef)                                                       # (order + 1, builds)
    with np.errstate(divide="ignore", invalid="ignore"):
        if order == 2:
            wn, q = np.sqrt(a[0] / a[2]), np.sqrt(a[0] * a[2]) / a[1]
        else:
            wn, q = a[0] / a[1], np.full(a.shape[1], np.nan)
        return {"fn_hz": wn / (2 * math.pi), "zeta": 1 / (2 * q), "q": q, "gain": 1 / a[zeros]}


def evaluate(ctx: AcContext, values: dict, start: int = 0) -> dict:
    """Every figure of :data:`FIGURES` for a chunk of builds (designator -> array), each
    simulated in ngspice: one loaded circuit per :data:`designer.tolerance.spice_engine.BATCH` builds.

    Parameters
    ----------
    ctx : AcContext
        The deck and its sweep.
    values : dict
        Designator -> array over the chunk's builds (the section's parts only).
    start : int
        The first build's index (labels the builds in ngspice's output and its messages).

    Returns
    -------
    dict
        Figure -> array over the builds.
    """
    from .spice_engine import batched

    def run(sim, chunk, lo):
        n = len(next(iter(chunk.values())))
        f, h = parse(sim.run_script(ctx.circuit, commands(ctx, chunk, start + lo)), start + lo, n)
        return fit(f, h, ctx.order, ctx.zeros)
    return batched(values, FIGURES, ctx.simulator, run)


def section_chunk(ctx: AcContext, model: tuple, values: dict, start: int = 0) -> dict:
    """A chunk's figures with the SPICE engine: the analytic engine's
    (:func:`designer.plant.circuit.evaluate` of ``model``, (topology name, op-amp)), with
    SPICE's fitted ones in their place and the step figures of the fitted pair. Pure, of
    picklable arguments.

    Parameters
    ----------
    ctx : AcContext
        The deck and its sweep.
    model : tuple
        (topology name, op-amp): the analytic engine's context.
    values : dict
        Designator -> array over the chunk's builds.
    start : int
        The first build's index.

    Returns
    -------
    dict
        Figure -> array over the builds.
    """
    from ..plant.circuit import evaluate as analytic, step_of_pair
    parts = {r: v for r, v in values.items() if r in dict(ctx.elements) or (r == "GBW" and ctx.cints)}
    sp = evaluate(ctx, parts, start)
    return {**analytic(model, values), **sp, **step_of_pair(sp["fn_hz"], sp["zeta"])}


def section_evaluate(ctx: AcContext, model: tuple):
    """``evaluate(values) -> figures`` (:func:`section_chunk` bound to a design; picklable).

    Parameters
    ----------
    ctx : AcContext
        The deck and its sweep.
    model : tuple
        (topology name, op-amp).

    Returns
    -------
    functools.partial
        ``evaluate(values) -> figures``.
    """
    import functools
    return functools.partial(section_chunk, ctx, model)
