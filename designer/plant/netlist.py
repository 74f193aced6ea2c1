"""The Sallen-Key plant as a part and net table, and as ngspice decks (seed
001, Figures 43-45): the circuit with the seed's part names, a standalone deck
of it under the square-wave bench test whose ``.meas`` lines print the step
metrics (section IV.9), and the ``.ac`` deck of the sine check.

The table (:class:`~designer.spice.deck.Netlist`) is the one description of the
circuit: the decks, the schematic (:mod:`designer.plant.schematic`), the wiring
table and the bill of materials are all written from it.

Designators follow one scheme on every sheet, the seed's: the plant is R1, R2,
C1, C2 and its op-amp U1; the controller (seed Figure 66) numbers its parts from
R3 and C3 on. The seed's gain resistors of the general Sallen-Key (its R3 to
ground and R4 in the feedback, K = (R3 + R4)/R3) would clash with the
controller's R3 and R4, so they are R19 and R20 here.
"""

from __future__ import annotations

from ..core.i18n import N_
from ..core.opamps import OpAmp
from ..spice.deck import (
    GROUND,
    Amp,
    Netlist,
    Part,
    SquareTest,
    ac_lines,
    add_supplies,
    finish_deck,
    measure_lines,
    opamp_library_text,
    settle_error_source,
)
from .sallenkey import SallenKeyParts

__all__ = ["plant_ac_deck", "plant_deck", "plant_netlist", "plant_prbs_deck"]

#: the seed's name of each plant part (its R3, R4 of the gain are R19, R20 here), by designator
SEED_NAMES = {"R1": "R1", "R2": "R2", "C1": "C1", "C2": "C2", "R19": "R3", "R20": "R4"}
#: designators of the gain resistors (to ground, feedback): the seed's R3 and R4
GAIN_REFS = ("R19", "R20")
#: the designator of each SallenKeyParts field
FIELD_OF = {"R1": "r1", "R2": "r2", "C1": "c1", "C2": "c2", "R19": "r3", "R20": "r4"}


def plant_netlist(parts: SallenKeyParts, inp: str = "input", out: str = "out", prefix: str = "",
                  amp_ref: str = "U1") -> Netlist:
    """The Sallen-Key low-pass between nets ``inp`` and ``out`` (internal nets
    ``v1``, ``vp``, ``vn`` with ``prefix``): R1 from the input to v1, R2 from v1
    to the non-inverting input, C1 from there to ground, C2 from v1 to the output
    (the positive feedback); a follower at K = 1, else R19 (inverting input to
    ground) and R20 (output to inverting input).

    Parameters
    ----------
    parts : SallenKeyParts
        The parts.
    inp, out : str
        The input and output nets.
    prefix : str
        Prepended to the internal nets and designators (for chaining).
    amp_ref : str
        The op-amp's reference.

    Returns
    -------
    Netlist
        The circuit.
    """
    v1, vp, vn = f"{prefix}v1", f"{prefix}vp", f"{prefix}vn"
    rows = [Part("R1", inp, v1, parts.r1, N_("input resistor")),
            Part("R2", v1, vp, parts.r2, N_("to the non-inverting input")),
            Part("C1", vp, GROUND, parts.c1, N_("non-inverting input to ground")),
            Part("C2", v1, out, parts.c2, N_("R1-R2 node to the output (feedback)"))]
    if parts.r3 is None:
        return Netlist(tuple(rows), (Amp(amp_ref, N_("plant"), vp, out, out),))
    rows += [Part("R19", vn, GROUND, parts.r3, N_("gain: inverting input to ground (seed's R3)")),
             Part("R20", out, vn, parts.r4, N_("gain: output to inverting input (seed's R4)"))]
    return Netlist(tuple(rows), (Amp(amp_ref, N_("plant"), vp, vn, out),))


def _circuit(title: str, opamp: OpAmp, header: list):
    import logging

    from PySpice.Spice.Netlist import Circuit
    logging.getLogger("PySpice").setLevel(logging.ERROR)
    circuit = Circuit(title)
    circuit.raw_spice = "\n".join([f"* {title}", *header, opamp_library_text().rstrip()])
    add_supplies(circuit, opamp)
    return circuit


def plant_deck(parts: SallenKeyParts, opamp: OpAmp, test: SquareTest, title: str) -> str:
    """Standalone deck of the Sallen-Key plant under the square-wave test.

    Parameters
    ----------
    parts : SallenKeyParts
        The parts.
    opamp : OpAmp
        The op-amp.
    test : SquareTest
        The square-wave test.
    title : str
        The deck's title line.

    Returns
    -------
    str
        The deck.
    """
    circuit = _circuit(title, opamp, [
        f"* op-amp: {opamp.name} ({opamp.description}); supplies {opamp.vcc:g} V / {opamp.vee:g} V",
        f"* test: 0 -> {test.amplitude_v:g} V square wave at {test.frequency_hz:g} Hz, step at {test.delay_s:.4g} s",
        "* Run: ngspice -b <this file>   (prints overshoot_pct, peak_time_s, rise_time_s, settling_time_s)"])
    circuit.V("in", "input", circuit.gnd, test.source())
    plant_netlist(parts).add_to(circuit, opamp)
    final = parts.gain * test.amplitude_v
    settle_error_source(circuit, "out", final)
    return finish_deck(circuit, test, measure_lines("out", test, final))


def plant_ac_deck(parts: SallenKeyParts, opamp: OpAmp, f_lo: float, f_hi: float, title: str) -> str:
    """The sine check as an ngspice deck: the same circuit driven by a 1 V AC
    source, an ``.ac`` sweep from ``f_lo`` to ``f_hi`` (v(out) is the gain).

    Parameters
    ----------
    parts : SallenKeyParts
        The parts.
    opamp : OpAmp
        The op-amp.
    f_lo, f_hi : float
        The sweep's ends (Hz).
    title : str
        The deck's title line.

    Returns
    -------
    str
        The deck.
    """
    circuit = _circuit(title, opamp, ["* sine check: 1 V AC at the input, v(out) = gain and phase"])
    circuit.V("in", "input", circuit.gnd, "DC 0 AC 1")
    plant_netlist(parts).add_to(circuit, opamp)
    return "\n".join([str(circuit).rstrip(), *ac_lines(f_lo, f_hi), ".end"]) + "\n"


def plant_prbs_deck(parts: SallenKeyParts, opamp: OpAmp, plan, title: str, samples_per_interval: int = 10) -> str:
    """The Sallen-Key plant driven by the pseudo-random binary sequence of
    ``plan`` (a :class:`~designer.core.prbs.PrbsPlan`, as ``make-prbs``
    writes it: its ngspice PWL subcircuit on the input), every period of it,
    the maximum time step a ``samples_per_interval``-th of the clock interval
    (and at most 1/100 of 1/wn): the prediction a bench capture of the plant
    under that sequence is compared with, and what ``identify`` reads.

    Parameters
    ----------
    parts : SallenKeyParts
        The parts.
    opamp : OpAmp
        The op-amp.
    plan : designer.core.prbs.PrbsPlan
        The sequence.
    title : str
        The deck's title line.
    samples_per_interval : int
        Output samples per clock interval.

    Returns
    -------
    str
        The deck.
    """
    import math

    from ..core.prbs import pwl_subcircuit
    from .sallenkey import fn_zeta
    fn, _ = fn_zeta(parts.r1, parts.r2, parts.c1, parts.c2, parts.gain)
    step = min(plan.dt_s / samples_per_interval, 1.0 / (2 * math.pi * fn) / 100)
    circuit = _circuit(title, opamp, [
        f"* op-amp: {opamp.name} ({opamp.description}); supplies {opamp.vcc:g} V / {opamp.vee:g} V",
        f"* stimulus: PRBS of {plan.bits} bits (N = {plan.n}), clock {plan.clock_hz:.6g} Hz, "
        f"{plan.periods} period(s), levels {plan.offset - plan.amplitude:.6g} V and {plan.offset + plan.amplitude:.6g} V",
        pwl_subcircuit(plan).rstrip(), "Xgen input prbs_source"])
    plant_netlist(parts).add_to(circuit, opamp)
    stop = plan.periods * plan.period_s
    return "\n".join([str(circuit).rstrip(), f".tran {step:.6g} {stop:.6g} 0 {step:.6g}", ".end"]) + "\n"
