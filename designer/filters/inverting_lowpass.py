"""Inverting first-order low-pass section: an inverting amplifier with a
capacitor across its feedback resistor.

Parts: R1 from the input to the inverting input n, R2 from n to the output,
C1 across R2; the non-inverting input is grounded.

Transfer function (node n, ideal op-amp Vn = 0: Vi/R1 = -Vo (1/R2 + s C1); TI,
"Op Amps for Everyone", ch. 16, SLOA088: the first-order low-pass, inverting)::

    H(s) = -(R2/R1) / (R2 C1 s + 1),   fc = 1 / (2 pi R2 C1),   gain G = R2/R1

With a finite-gain op-amp, Vo = -A(s) Vn and the n row is
(Vi - Vn)/R1 = (Vn - Vo)(1/R2 + s C1) (:func:`~designer.filters.topology.nodal_response`).

Design: R1 the target's impedance (or, with the target's capacitor C1,
R2 = 1/(wc C1) and R1 = R2/G), R2 = G R1, C1 = 1/(wc R2). Every fc and G > 0 is
reachable.
"""

from __future__ import annotations

from ..core.i18n import N_
from ..spice.deck import GROUND, Amp, Netlist
from .topology import PartSpec, SectionTarget, Topology, polynomial

__all__ = ["InvertingLowPass"]


class InvertingLowPass(Topology):
    """The inverting first-order low-pass (parts R1 R2 C1)."""

    name, title = "inverting-lowpass", N_("First-order low-pass (inverting)")
    kind, order, inverting = "lowpass", 1, True
    parts = (PartSpec("R1", "R", N_("input resistor")),
             PartSpec("R2", "R", N_("gain: inverting input to the output")),
             PartSpec("C1", "C", N_("across R2 (the pole)")))
    example = SectionTarget("lowpass", 1e3, gain=3.0)

    def coefficients(self, values: dict) -> tuple:
        v = self.values_of(values)
        return polynomial(0.0, -v["R2"] / v["R1"]), polynomial(v["R2"] * v["C1"], 1.0)

    def synthesize(self, target: SectionTarget, **choices) -> dict:
        self.check_realisable(target, **choices)
        c = self.scale(target, 1.0 / target.gain)
        r2 = 1.0 / (target.wn * c)
        return {"R1": r2 / target.gain, "R2": r2, "C1": c}

    def netlist(self, values: dict, prefix: str = "", amp_ref: str = "U1", inp: str = "vin",
                out: str = "vout") -> Netlist:
        (n,) = self.internal(amp_ref, "n")
        ends = {"R1": (inp, n), "R2": (n, out), "C1": (n, out)}
        return self.assemble(values, prefix, ends, Amp(amp_ref, self.title, GROUND, n, out))
