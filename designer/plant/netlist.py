"""The Sallen-Key plant as an ngspice deck (seed 001, Figures 43-45): the
circuit with the seed's part names, and a standalone deck of it under the
square-wave bench test whose ``.meas`` lines print the step metrics."""

from __future__ import annotations

from ..core.opamps import OpAmp
from ..spice.deck import (
    SquareTest,
    add_opamp,
    add_supplies,
    finish_deck,
    measure_lines,
    opamp_library_text,
    settle_error_source,
)
from .sallenkey import SallenKeyParts


def add_sallen_key(circuit, parts: SallenKeyParts, opamp: OpAmp, inp: str, out: str, prefix: str = ""):
    """The Sallen-Key low-pass between nodes ``inp`` and ``out``, with the seed's
    part names (R1, R2, C1, C2; R3, R4 for gain), optionally prefixed."""
    v1, vp, vn = f"{prefix}v1", f"{prefix}vp", f"{prefix}vn"
    circuit.R(f"{prefix}1", inp, v1, f"{parts.r1:.6g}")
    circuit.R(f"{prefix}2", v1, vp, f"{parts.r2:.6g}")
    circuit.C(f"{prefix}1", vp, circuit.gnd, f"{parts.c1:.6g}")
    circuit.C(f"{prefix}2", v1, out, f"{parts.c2:.6g}")
    if parts.r3 is None:
        add_opamp(circuit, f"{prefix}1", vp, out, out, opamp)
    else:
        circuit.R(f"{prefix}3", vn, circuit.gnd, f"{parts.r3:.6g}")
        circuit.R(f"{prefix}4", out, vn, f"{parts.r4:.6g}")
        add_opamp(circuit, f"{prefix}1", vp, vn, out, opamp)


def plant_deck(parts: SallenKeyParts, opamp: OpAmp, test: SquareTest, title: str) -> str:
    """Standalone deck of the Sallen-Key plant under the square-wave test."""
    import logging

    from PySpice.Spice.Netlist import Circuit
    logging.getLogger("PySpice").setLevel(logging.ERROR)

    circuit = Circuit(title)
    circuit.raw_spice = "\n".join([
        f"* {title}",
        f"* op-amp: {opamp.name} ({opamp.description}); supplies {opamp.vcc:g} V / {opamp.vee:g} V",
        f"* test: 0 -> {test.amplitude_v:g} V square wave at {test.frequency_hz:g} Hz, step at {test.delay_s:.4g} s",
        "* Run: ngspice -b <this file>   (prints overshoot_pct, peak_time_s, rise_time_s, settling_time_s)",
        opamp_library_text().rstrip(),
    ])
    add_supplies(circuit, opamp)
    circuit.V("in", "input", circuit.gnd, test.source())
    add_sallen_key(circuit, parts, opamp, "input", "out")
    final = parts.gain * test.amplitude_v
    settle_error_source(circuit, "out", final)
    return finish_deck(circuit, test, measure_lines("out", test, final))
