"""The Sallen-Key plant as a part and net table, and as ngspice decks (seed
001, Figures 43-45): the circuit with the seed's part names, a standalone deck
of it under the square-wave bench test whose ``.meas`` lines print the step
metrics (section IV.9), and the ``.ac`` deck of the sine check.

The table (:class:`~designer.spice.deck.Netlist`) is the one description of the
circuit: the decks, the schematic (:mod:`designer.plant.schematic`), the wiring
table and the bill of materials are all written from it.

Designators are the Sallen-Key low-pass section's own
(:mod:`designer.filters.sallen_key_lowpass_parts`, the seed's names): R1, R2,
C1, C2, and with gain K = (R3 + R4)/R3 the gain pair R3 (to ground) and R4
(feedback), as on the command line and in check-design; its op-amp is U1. Where
the plant shares a sheet with a controller that owns R3 and R4 (the PID's
closed loop), the caller gives a designator prefix (``ref_prefix``, the
section's chaining mechanism: R3 -> RP3).
"""

from __future__ import annotations

from ..core.i18n import N_
from ..core.opamps import OpAmp
from ..filters.deck import ac_deck
from ..filters.sallen_key_lowpass_parts import part_values, section_of
from ..spice.deck import (
    SINE_POINTS_PER_DECADE,
    Amp,
    Netlist,
    SquareTest,
    bench_circuit,
    finish_deck,
    measure_lines,
    settle_error_source,
)
from .sallenkey import SallenKeyParts

__all__ = ["plant_ac_deck", "plant_deck", "plant_netlist", "plant_prbs_deck", "prbs_deck"]


def plant_netlist(parts: SallenKeyParts, inp: str = "input", out: str = "out", prefix: str = "",
                  amp_ref: str = "U1", ref_prefix: str = "") -> Netlist:
    """The Sallen-Key low-pass between nets ``inp`` and ``out`` (internal nets
    ``v1``, ``vp``, ``vn`` with ``prefix``): R1 from the input to v1, R2 from v1
    to the non-inverting input, C1 from there to ground, C2 from v1 to the output
    (the positive feedback); a follower at K = 1, else the gain pair (inverting
    input to ground, output to inverting input). Designators and roles are the
    section's (:func:`designer.filters.sallen_key_lowpass_parts.section_of`).

    Parameters
    ----------
    parts : SallenKeyParts
        The parts.
    inp, out : str
        The input and output nets.
    prefix : str
        Prepended to the internal nets.
    amp_ref : str
        The op-amp's reference.
    ref_prefix : str
        Put after each designator's letter (R1 -> RP1 with ``"P"``), for a sheet
        the plant shares.

    Returns
    -------
    Netlist
        The circuit.
    """
    section = section_of(parts)
    vp, vn = f"{prefix}vp", f"{prefix}vn"
    net = section.wired(part_values(parts), ref_prefix, amp_ref, inp, out, (f"{prefix}v1", vp, vn))
    follower = parts.r3 is None
    return Netlist(net.parts, (Amp(amp_ref, N_("plant"), vp, out if follower else vn, out),))


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
    circuit = bench_circuit(title, opamp, [
        f"* {title}",
        f"* op-amp: {opamp.name} ({opamp.description}); supplies {opamp.vcc:g} V / {opamp.vee:g} V",
        f"* test: 0 -> {test.amplitude_v:g} V square wave at {test.frequency_hz:g} Hz, step at {test.delay_s:.4g} s",
        "* Run: ngspice -b <this file>   (prints overshoot_pct, peak_time_s, rise_time_s, settling_time_s)"])
    circuit.V("in", "input", circuit.gnd, test.source())
    plant_netlist(parts).add_to(circuit, opamp)
    final = parts.gain * test.amplitude_v
    settle_error_source(circuit, "out", final)
    return finish_deck(circuit, test, measure_lines("out", test, final))


def plant_ac_deck(parts: SallenKeyParts, opamp: OpAmp, f_lo: float, f_hi: float, title: str) -> str:
    """The sine check as an ngspice deck: the generic section's ``.ac`` deck
    (:func:`designer.filters.deck.ac_deck`) of :func:`plant_netlist`, driven at
    the plant's ``input`` net by 1 V AC, at the sine check's density (v(out) is the gain).

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
    return ac_deck(plant_netlist(parts), opamp, f_lo, f_hi, inp="input", title=title,
                   points_per_decade=SINE_POINTS_PER_DECADE)


def plant_prbs_deck(parts: SallenKeyParts, opamp: OpAmp, plan, title: str, samples_per_interval: int = 10) -> str:
    """The Sallen-Key plant driven by the pseudo-random binary sequence of
    ``plan`` (a :class:`~designer.core.prbs.PrbsPlan`, as ``make-prbs``
    writes it: its ngspice PWL subcircuit on the input), every period of it
    (:func:`prbs_deck` of :func:`plant_netlist`): the prediction a bench capture
    of the plant under that sequence is compared with, and what ``identify`` reads.

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
    return prbs_deck(plant_netlist(parts), opamp, plan, title, parts.fn_hz, "input", samples_per_interval)


def prbs_deck(netlist, opamp: OpAmp, plan, title: str, fn_hz: float, inp: str = "input",
              samples_per_interval: int = 10) -> str:
    """Any circuit (its :class:`~designer.spice.deck.Netlist`, input net ``inp``) driven by the
    pseudo-random binary sequence of ``plan`` (its ngspice PWL subcircuit, as ``make-prbs``
    writes it), every period of it, the maximum time step a ``samples_per_interval``-th of the
    clock interval and at most 1/100 of 1/wn (``fn_hz`` its natural frequency).

    Parameters
    ----------
    netlist : designer.spice.deck.Netlist
        The circuit.
    opamp : OpAmp
        The op-amp.
    plan : designer.core.prbs.PrbsPlan
        The sequence.
    title : str
        The deck's title line.
    fn_hz : float
        The circuit's natural frequency (its time step).
    inp : str
        The net the sequence drives.
    samples_per_interval : int
        Output samples per clock interval.

    Returns
    -------
    str
        The deck.
    """
    import math

    from ..core.prbs import pwl_subcircuit
    step = min(plan.dt_s / samples_per_interval, 1.0 / (2 * math.pi * fn_hz) / 100)
    circuit = bench_circuit(title, opamp, [
        f"* {title}",
        f"* op-amp: {opamp.name} ({opamp.description}); supplies {opamp.vcc:g} V / {opamp.vee:g} V",
        f"* stimulus: PRBS of {plan.bits} bits (N = {plan.n}), clock {plan.clock_hz:.6g} Hz, "
        f"{plan.periods} period(s), levels {plan.offset - plan.amplitude:.6g} V and {plan.offset + plan.amplitude:.6g} V",
        pwl_subcircuit(plan).rstrip(), f"Xgen {inp} prbs_source"])
    netlist.add_to(circuit, opamp)
    stop = plan.periods * plan.period_s
    return "\n".join([str(circuit).rstrip(), f".tran {step:.6g} {stop:.6g} 0 {step:.6g}", ".end"]) + "\n"
