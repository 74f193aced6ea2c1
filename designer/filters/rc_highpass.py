"""First-order high-pass section: a CR divider buffered by a follower.

Parts: C1 from the input to the non-inverting input p, R1 from p to ground;
the op-amp is a voltage follower.

Transfer function (node p: (Vi - Vp) s C1 = Vp / R1; Vo = Vp; TI, "Op Amps for
Everyone", ch. 16, SLOA088: the first-order high-pass, at unity gain)::

    H(s) = R1 C1 s / (R1 C1 s + 1),   fc = 1 / (2 pi R1 C1)

With a finite-gain op-amp the follower gives Vo = Vp A/(1 + A).

Design: as :mod:`designer.filters.rc_lowpass` (R1 C1 = 1/wc). Every fc is
reachable; the gain is 1.
"""

from __future__ import annotations

from ..core.i18n import N_
from ..spice.deck import GROUND, Amp, Netlist
from .rc_lowpass import RcLowPass
from .topology import PartSpec, SectionTarget, polynomial

__all__ = ["RcHighPass"]


class RcHighPass(RcLowPass):
    """The first-order CR high-pass with a follower (parts R1 C1); its design is the
    low-pass's (:class:`~designer.filters.rc_lowpass.RcLowPass`)."""

    name, title = "rc-highpass", N_("First-order high-pass (CR and follower)")
    kind = "highpass"
    parts = (PartSpec("R1", "R", N_("non-inverting input to ground")),
             PartSpec("C1", "C", N_("input capacitor")))
    example = SectionTarget("highpass", 1e3)

    def coefficients(self, values: dict) -> tuple:
        v = self.values_of(values)
        tau = v["R1"] * v["C1"]
        return polynomial(tau, 0.0), polynomial(tau, 1.0)

    def netlist(self, values: dict, prefix: str = "", amp_ref: str = "U1", inp: str = "vin",
                out: str = "vout") -> Netlist:
        (p,) = self.internal(amp_ref, "p")
        return self.assemble(values, prefix, {"C1": (inp, p), "R1": (p, GROUND)}, Amp(amp_ref, self.title, p, out, out))
