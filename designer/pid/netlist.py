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
from ..spice.deck import (
    SquareTest,
    add_opamp,
    add_supplies,
    finish_deck,
    measure_lines,
    opamp_library_text,
    settle_error_source,
)
from .blocks import PidParts

#: signals whose extremes the deck measures (one per op-amp output)
PROBES = ("ve", "vp", "vd", "vi", "vs", "u", "y")


def add_controller(circuit, parts: PidParts, opamp: OpAmp, ref="ref", y="y", u="u"):
    """The six controller op-amps between the reference, the plant output and ``u``."""
    gnd = circuit.gnd
    r = lambda x: f"{x:.6g}"  # noqa: E731
    # U1 difference amplifier: ve = y - r (equal resistors)
    circuit.R(15, ref, "n1", r(parts.r15))
    circuit.R(16, "n1", "ve", r(parts.r16))
    circuit.R(17, y, "p1", r(parts.r17))
    circuit.R(18, "p1", gnd, r(parts.r18))
    add_opamp(circuit, "U1", "p1", "n1", "ve", opamp)
    # U2 unity inverter
    circuit.R(10, "ve", "n2", r(parts.r10))
    circuit.R(9, "n2", "vp", r(parts.r9))
    add_opamp(circuit, "U2", gnd, "n2", "vp", opamp)
    if parts.has_derivative:
        # U3 differentiator with input resistor
        circuit.R(12, "ve", "d3", r(parts.r12))
        circuit.C(3, "d3", "n3", r(parts.c3))
        circuit.R(11, "n3", "vd", r(parts.r11))
        add_opamp(circuit, "U3", gnd, "n3", "vd", opamp)
    # U4 integrator with feedback resistor
    circuit.R(14, "ve", "n4", r(parts.r14))
    circuit.R(13, "n4", "vi", r(parts.r13))
    circuit.C(4, "n4", "vi", r(parts.c4))
    add_opamp(circuit, "U4", gnd, "n4", "vi", opamp)
    # U5 summer
    circuit.R(6, "vp", "n5", r(parts.r6))
    if parts.has_derivative:
        circuit.R(7, "vd", "n5", r(parts.r7))
    circuit.R(8, "vi", "n5", r(parts.r8))
    circuit.R(5, "n5", "vs", r(parts.r5))
    add_opamp(circuit, "U5", gnd, "n5", "vs", opamp)
    # U6 final inverting gain
    circuit.R(4, "vs", "n6", r(parts.r4))
    circuit.R(3, "n6", u, r(parts.r3))
    add_opamp(circuit, "U6", gnd, "n6", u, opamp)


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
        opamp_library_text().rstrip(),
    ])
    add_supplies(circuit, opamp)
    circuit.V("ref", "ref", circuit.gnd, test.source())
    add_controller(circuit, parts, opamp)
    add_sallen_key(circuit, plant, opamp, "u", "y", prefix="P")
    settle_error_source(circuit, "y", expected_final)
    sq = test
    t0 = test.delay_s
    extremes = []
    for node in PROBES:
        if node == "vd" and not parts.has_derivative:
            continue
        extremes += [f".meas tran {node}_max MAX v({node}) FROM={t0:.6g} TO={test.stop_s:.6g}",
                     f".meas tran {node}_min MIN v({node}) FROM={t0:.6g} TO={test.stop_s:.6g}"]
    lines = measure_lines("y", sq, expected_final) + extremes
    return finish_deck(circuit, sq, lines, points=points)
