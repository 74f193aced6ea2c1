"""First-order low-pass section: an RC divider buffered by a follower.

Parts: R1 from the input to the non-inverting input p, C1 from p to ground;
the op-amp is a voltage follower.

Transfer function (node p: (Vi - Vp)/R1 = Vp s C1; Vo = Vp; TI, "Op Amps for
Everyone", ch. 16, SLOA088: the first-order low-pass, non-inverting, at unity gain)::

    H(s) = 1 / (R1 C1 s + 1),   fc = 1 / (2 pi R1 C1)

With a finite-gain op-amp the follower gives Vo = Vp A/(1 + A).

Design: R1 the target's impedance (or C1 the target's capacitor), the other from
R1 C1 = 1/wc. Every fc is reachable; the gain is 1.
"""

from __future__ import annotations

from ..core.i18n import N_
from ..spice.deck import GROUND, Amp, Netlist
from .topology import PartSpec, SectionTarget, Topology, polynomial

__all__ = ["RcLowPass"]


class RcLowPass(Topology):
    """The first-order RC low-pass with a follower (parts R1 C1)."""

    name, title = "rc-lowpass", N_("First-order low-pass (RC and follower)")
    kind, order, inverting = "lowpass", 1, False
    parts = (PartSpec("R1", "R", N_("input resistor")),
             PartSpec("C1", "C", N_("non-inverting input to ground")))
    example = SectionTarget("lowpass", 1e3)

    def coefficients(self, values: dict) -> tuple:
        v = self.values_of(values)
        return polynomial(0.0, 1.0 + 0 * v["R1"]), polynomial(v["R1"] * v["C1"], 1.0)

    def _check_limits(self, target: SectionTarget, choices: dict) -> None:
        self.require_unity_gain(target, "add the gain in another stage")

    def synthesize(self, target: SectionTarget, **choices) -> dict:
        self.check_realisable(target, **choices)
        c = self.scale(target)
        return {"R1": 1.0 / (target.wn * c), "C1": c}

    def netlist(self, values: dict, prefix: str = "", amp_ref: str = "U1", inp: str = "vin",
                out: str = "vout") -> Netlist:
        (p,) = self.internal(amp_ref, "p")
        return self.assemble(values, prefix, {"R1": (inp, p), "C1": (p, GROUND)}, Amp(amp_ref, self.title, p, out, out))

