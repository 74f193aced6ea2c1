"""Multiple-feedback (MFB) high-pass section: inverting, passband gain -C1/C2.

Parts (TI's names): C1 from the input to node x, R1 from x to ground, C2 from
x to the output, C3 from x to the inverting input n, R2 from n to the output;
the non-inverting input is grounded.

Nodal analysis, written out (ideal op-amp: Vn = 0)::

    n:  Vx s C3 = -Vo / R2                        ->  Vx = -Vo / (s C3 R2)
    x:  (Vi - Vx) s C1 = Vx / R1 + (Vx - Vo) s C2 + Vx s C3

and so (the form of TI, "Op Amps for Everyone", ch. 16, SLOA088: the
second-order high-pass, MFB topology)::

    H(s) = -C1 C3 R1 R2 s^2 / (C2 C3 R1 R2 s^2 + R1 (C1 + C2 + C3) s + 1)

    wn = 1 / sqrt(R1 R2 C2 C3),   Q = sqrt(R1 R2 C2 C3) / (R1 (C1 + C2 + C3)),   gain G = C1/C2

With a finite-gain op-amp, Vo = -A(s) Vn and the n row is (Vx - Vn) s C3 = (Vn - Vo)/R2
(:func:`~designer.filters.topology.nodal_response`).

Design (TI's): C1 = C3 = C (the target's), C2 = C/G; then R1 = 1/(wn Q C (2 + 1/G))
and R2 = G/(wn^2 C^2 R1). Every Q > 0 and G > 0 is reachable.

R and C given (:meth:`~designer.filters.topology.Topology.synthesize_rc`): R1 = R, the input capacitor
C1 = C, C2 = C/G (the gain); the s coefficient R (C1 + C2 + C3) = 1/(wn Q) and
R2 C3 = 1/(wn^2 C2 R) give

    C3 = 1/(wn Q R) - C (1 + 1/G),   R2 = 1/(wn^2 C2 C3 R),

positive only when R C (1 + 1/G) < 1/(wn Q).
"""

from __future__ import annotations

from ..core.errors import ParamError
from ..core.i18n import N_
from ..spice.deck import GROUND, Amp, Netlist
from .topology import PartSpec, SectionTarget, Topology, polynomial

__all__ = ["MfbHighPass"]


class MfbHighPass(Topology):
    """The inverting MFB high-pass section (parts R1 R2 C1 C2 C3)."""

    name, title = "mfb-highpass", N_("MFB high-pass (inverting)")
    kind, order, inverting = "highpass", 2, True
    parts = (PartSpec("R1", "R", N_("node x to ground")),
             PartSpec("R2", "R", N_("inverting input to the output (feedback)")),
             PartSpec("C1", "C", N_("input capacitor")),
             PartSpec("C2", "C", N_("gain: node x to the output")),
             PartSpec("C3", "C", N_("node x to the inverting input")))
    example = SectionTarget("highpass", 1e3, q=0.8, gain=2.0)

    def coefficients(self, values: dict) -> tuple:
        v = self.values_of(values)
        r1, r2, c1, c2, c3 = (v[r] for r in ("R1", "R2", "C1", "C2", "C3"))
        den = polynomial(c2 * c3 * r1 * r2, r1 * (c1 + c2 + c3), 1.0)
        return polynomial(-c1 * c3 * r1 * r2, 0.0, 0.0), den

    def synthesize(self, target: SectionTarget, **choices) -> dict:
        self.check_realisable(target, **choices)
        q, g, w = target.q, target.gain, target.wn
        c = self.scale(target)
        r1 = 1.0 / (w * q * c * (2 + 1 / g))
        return {"R1": r1, "R2": g / (w * w * c * c * r1), "C1": c, "C2": c / g, "C3": c}

    def _rc_design(self, target: SectionTarget, r: float, c: float) -> dict:
        """R1 = R, C1 = C, C2 = C/G; C3 and R2 solved (the module's equations)."""
        q, g, w = target.q, target.gain, target.wn
        c3 = 1.0 / (w * q * r) - c * (1 + 1 / g)
        if c3 <= 0:
            raise ParamError(f"{{r}} and {{c}}: no positive C3 for R = {r:g} Ohm, C = {c:g} F: {self.name} needs "
                             f"R*C < 1/(wn Q (1 + 1/|gain|)) = {1.0 / (w * q * (1 + 1 / g)):.4g} s (R*C is "
                             f"{r * c:.4g} s); choose a smaller R or C", params=("r", "c"))
        c2 = c / g
        return {"R1": r, "R2": 1.0 / (w * w * c2 * c3 * r), "C1": c, "C2": c2, "C3": c3}

    def netlist(self, values: dict, prefix: str = "", amp_ref: str = "U1", inp: str = "vin",
                out: str = "vout") -> Netlist:
        x, n = self.internal(amp_ref, "x", "n")
        ends = {"C1": (inp, x), "R1": (x, GROUND), "C2": (x, out), "C3": (x, n), "R2": (n, out)}
        return self.assemble(values, prefix, ends, Amp(amp_ref, self.title, GROUND, n, out))
