"""Inverting first-order high-pass section: an inverting amplifier with a
capacitor in series with its input resistor.

Parts: R1 and C1 in series from the input to the inverting input n (C1 on the
input side), R2 from n to the output; the non-inverting input is grounded.

Transfer function (node n, ideal op-amp Vn = 0: the input current
Vi / (R1 + 1/(s C1)) flows on through R2; TI, "Op Amps for Everyone", ch. 16,
SLOA088: the first-order high-pass, inverting)::

    H(s) = -(R2/R1) R1 C1 s / (R1 C1 s + 1),   fc = 1 / (2 pi R1 C1),   gain G = R2/R1

(the gain G is the passband's, reached well above fc). With a finite-gain
op-amp, Vo = -A(s) Vn and the n row is the nodal one of the three parts
(:func:`~designer.filters.topology.nodal_response`).

Design: C1 the target's capacitor (or the one that puts R1 near the target's
impedance at wc), R1 = 1/(wc C1), R2 = G R1. Every fc and G > 0 is reachable.
"""

from __future__ import annotations

from ..core.i18n import N_
from ..spice.deck import GROUND, Amp, Netlist
from .topology import PartSpec, SectionTarget, Topology, polynomial

__all__ = ["InvertingHighPass"]


class InvertingHighPass(Topology):
    """The inverting first-order high-pass (parts R1 R2 C1)."""

    name, title = "inverting-highpass", N_("First-order high-pass (inverting)")
    kind, order, inverting = "highpass", 1, True
    parts = (PartSpec("R1", "R", N_("input resistor (sets fc with C1)")),
             PartSpec("R2", "R", N_("gain: inverting input to the output")),
             PartSpec("C1", "C", N_("input capacitor (the zero at DC)")))
    example = SectionTarget("highpass", 1e3, gain=2.0)

    def coefficients(self, values: dict) -> tuple:
        v = self.values_of(values)
        return polynomial(-v["R2"] * v["C1"], 0.0), polynomial(v["R1"] * v["C1"], 1.0)

    def synthesize(self, target: SectionTarget, **choices) -> dict:
        self.check_realisable(target, **choices)
        c = self.scale(target)
        r1 = 1.0 / (target.wn * c)
        return {"R1": r1, "R2": target.gain * r1, "C1": c}

    def netlist(self, values: dict, prefix: str = "", amp_ref: str = "U1", inp: str = "vin",
                out: str = "vout") -> Netlist:
        m, n = self.internal(amp_ref, "m", "n")
        ends = {"C1": (inp, m), "R1": (m, n), "R2": (n, out)}
        return self.assemble(values, prefix, ends, Amp(amp_ref, self.title, GROUND, n, out))
