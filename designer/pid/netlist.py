"""Standalone closed-loop ngspice deck: the six-op-amp PID controller of
seed 001 (Figure 66), the Sallen-Key plant circuit, the project's behavioural
op-amp models (inlined from ``circuits/``), supplies, a square-wave reference
like the seed's bench test, ``.tran`` and ``.meas`` lines.

Node names: ``ref`` reference, ``ve`` error (y - r), ``vp``/``vd``/``vi``
proportional, derivative and integral stage outputs, ``vs`` summer, ``u``
controller output (plant input), ``y`` plant output. Op-amps are XU1..XU6
(controller) and XP1 (plant).
"""

from __future__ import annotations

import logging

from ..core.opamps import OpAmp
from ..plant.netlist import add_sallen_key
from ..plant.sallenkey import SallenKeyParts
from ..spice import deck
from ..spice.deck import SquareTest
from .blocks import PidParts

#: signals whose extremes the deck measures (one per op-amp output)
PROBES = ("ve", "vp", "vd", "vi", "vs", "u", "y")


def add_controller(circuit, parts: PidParts, opamp: OpAmp, ref="ref", y="y", u="u"):
    """The six controller op-amps between the reference, the plant output and ``u``
    (U3 and R7 only with a derivative path)."""
    gnd = circuit.gnd
    p = parts
    # per op-amp: its name, non-inverting input, inverting input and output, after its
    # passives (kind, number, node, node, value)
    stages = (
        # U1 difference amplifier: ve = y - r (equal resistors)
        ("U1", "p1", "n1", "ve", (("R", 15, ref, "n1", p.r15), ("R", 16, "n1", "ve", p.r16),
                                  ("R", 17, y, "p1", p.r17), ("R", 18, "p1", gnd, p.r18))),
        # U2 unity inverter
        ("U2", gnd, "n2", "vp", (("R", 10, "ve", "n2", p.r10), ("R", 9, "n2", "vp", p.r9))),
        # U3 differentiator with input resistor
        ("U3", gnd, "n3", "vd", (("R", 12, "ve", "d3", p.r12), ("C", 3, "d3", "n3", p.c3),
                                 ("R", 11, "n3", "vd", p.r11))),
        # U4 integrator with feedback resistor
        ("U4", gnd, "n4", "vi", (("R", 14, "ve", "n4", p.r14), ("R", 13, "n4", "vi", p.r13),
                                 ("C", 4, "n4", "vi", p.c4))),
        # U5 summer
        ("U5", gnd, "n5", "vs", (("R", 6, "vp", "n5", p.r6), ("R", 7, "vd", "n5", p.r7),
                                 ("R", 8, "vi", "n5", p.r8), ("R", 5, "n5", "vs", p.r5))),
        # U6 final inverting gain
        ("U6", gnd, "n6", u, (("R", 4, "vs", "n6", p.r4), ("R", 3, "n6", u, p.r3))),
    )
    for name, inp, inn, out, passives in stages:
        if name == "U3" and not p.has_derivative:
            continue
        for kind, number, a, b, value in passives:
            if value is not None:   # R7 of a PI
                getattr(circuit, kind)(number, a, b, f"{value:.6g}")
        deck.add_opamp(circuit, name, inp, inn, out, opamp)


def closed_loop_deck(parts: PidParts, plant: SallenKeyParts, opamp: OpAmp, test: SquareTest,
                     title: str, expected_final: float, points: int = 20000) -> str:
    """The whole loop as a standalone deck; ``expected_final`` (V) is the settled
    plant output the ``.meas`` levels refer to (the analytic closed loop's)."""
    from PySpice.Spice.Netlist import Circuit
    logging.getLogger("PySpice").setLevel(logging.ERROR)
    circuit = Circuit(title)
    circuit.raw_spice = "\n".join([
        f"* {title}",
        f"* op-amps: {opamp.name} ({opamp.description}); supplies {opamp.vcc:g} V / {opamp.vee:g} V",
        f"* reference: 0 -> {test.amplitude_v:g} V square wave at {test.frequency_hz:g} Hz, edges "
        f"{test.edge_s:.3g} s, rising step at {test.delay_s:.4g} s",
        "* controller (seed 001, Fig. 66): U1 difference (ve = y - r), U2 inverter, U3 differentiator,",
        "*   U4 integrator, U5 summer, U6 gain -> u = Kp (1 + 1/(Ti s) + Td s) (r - y); plant XP1",
        "* Run: ngspice -b <this file>   (prints overshoot_pct, peak_time_s, rise_time_s, settling_time_s,",
        "*   and the extremes of every op-amp output)",
        deck.opamp_library_text().rstrip(),
    ])
    deck.add_supplies(circuit, opamp)
    circuit.V("ref", "ref", circuit.gnd, test.source())
    add_controller(circuit, parts, opamp)
    add_sallen_key(circuit, plant, opamp, "u", "y", prefix="P")
    deck.settle_error_source(circuit, "y", expected_final)
    t0 = test.delay_s
    extremes = []
    for node in PROBES:
        if node == "vd" and not parts.has_derivative:
            continue
        extremes += [f".meas tran {node}_max MAX v({node}) FROM={t0:.6g} TO={test.stop_s:.6g}",
                     f".meas tran {node}_min MIN v({node}) FROM={t0:.6g} TO={test.stop_s:.6g}"]
    lines = deck.measure_lines("y", test, expected_final) + extremes
    return deck.finish_deck(circuit, test, lines, points=points)
