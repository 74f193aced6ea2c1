"""Multiple-feedback (MFB) band-pass section: inverting, centre frequency f0,
quality factor Q, gain at f0 -R3 C1 / (R1 (C1 + C2)).

Parts (TI's names): R1 from the input to node x, R2 from x to ground, C1 from x
to the inverting input n, C2 from x to the output, R3 from n to the output; the
non-inverting input is grounded.

Nodal analysis, written out (ideal op-amp: Vn = 0; Rp = R1 R2 / (R1 + R2))::

    n:  Vx s C1 = -Vo / R3                        ->  Vx = -Vo / (s C1 R3)
    x:  (Vi - Vx)/R1 = Vx/R2 + Vx s C1 + (Vx - Vo) s C2

and so (TI, "Op Amps for Everyone", ch. 16, SLOA088: the band-pass, MFB
topology, in the general form)::

    H(s) = -(C1 R3 Rp / R1) s / (C1 C2 R3 Rp s^2 + Rp (C1 + C2) s + 1)

    w0 = 1 / sqrt(C1 C2 R3 Rp),   Q = sqrt(C1 C2 R3 Rp) / (Rp (C1 + C2)),   gain Am = R3 C1 / (R1 (C1 + C2))

With a finite-gain op-amp, Vo = -A(s) Vn and the n row is (Vx - Vn) s C1 = (Vn - Vo)/R3
(:func:`~designer.filters.topology.nodal_response`).

Design (TI's, equal capacitors C1 = C2 = C): R3 = 2 Q/(w0 C), R1 = R3/(2 Am),
Rp = 1/(2 Q w0 C), R2 = 1/(1/Rp - 1/R1).

Realisability: R2 > 0 needs R1 > Rp, i.e. Am < 2 Q^2.

R and C given (:meth:`~designer.filters.topology.Topology.synthesize_rc`): the input resistor R1 = R and
C1 = C, C2 free: the gain gives R3 = Am R (C1 + C2)/C1, the s coefficient
Rp (C1 + C2) = 1/(w0 Q) and the s^2 one C1 C2 R3 Rp = 1/w0^2 then give

    C2 = Q/(w0 Am R),   Rp = 1/(w0 Q (C + C2)),   R2 = 1/(1/Rp - 1/R),

R2 positive only when Rp < R, i.e. w0 Q R C + Q^2/Am > 1 (the section's limit
Am < 2 Q^2, its equal-capacitor design's, still applies).
"""

from __future__ import annotations

from ..core.errors import DesignError, ParamError
from ..core.i18n import N_
from ..spice.deck import GROUND, Amp, Netlist
from .topology import PartSpec, SectionTarget, Topology, polynomial

__all__ = ["MfbBandPass"]


class MfbBandPass(Topology):
    """The inverting MFB band-pass section (parts R1 R2 R3 C1 C2)."""

    name, title = "mfb-bandpass", N_("MFB band-pass (inverting)")
    kind, order, inverting = "bandpass", 2, True
    parts = (PartSpec("R1", "R", N_("input resistor")),
             PartSpec("R2", "R", N_("node x to ground")),
             PartSpec("R3", "R", N_("inverting input to the output (feedback)")),
             PartSpec("C1", "C", N_("node x to the inverting input")),
             PartSpec("C2", "C", N_("node x to the output (feedback)")))
    example = SectionTarget("bandpass", 1e3, q=5.0, gain=4.0)

    def coefficients(self, values: dict) -> tuple:
        v = self.values_of(values)
        r1, r2, r3, c1, c2 = (v[r] for r in ("R1", "R2", "R3", "C1", "C2"))
        rp = r1 * r2 / (r1 + r2)
        den = polynomial(c1 * c2 * r3 * rp, rp * (c1 + c2), 1.0)
        return polynomial(0.0, -c1 * r3 * rp / r1, 0.0), den

    def limits(self, target: SectionTarget) -> dict:
        return {"gain_max": 2 * target.q ** 2}

    def _check_limits(self, target: SectionTarget, choices: dict) -> None:
        bound = self.limits(target)["gain_max"]
        if target.gain >= bound:
            raise DesignError(f"gain: {target.gain:.4g} at f0 is not below the bound 2 Q^2 = {bound:.4g} of "
                              f"{self.name} at Q = {target.q:.4g}; ask for a lower gain or a higher Q, or add "
                              "gain in another stage", param="gain")

    def synthesize(self, target: SectionTarget, **choices) -> dict:
        self.check_realisable(target, **choices)
        q, g, w = target.q, target.gain, target.wn
        c = self.scale(target)
        r3 = 2 * q / (w * c)
        r1 = r3 / (2 * g)
        rp = 1.0 / (2 * q * w * c)
        return {"R1": r1, "R2": 1.0 / (1.0 / rp - 1.0 / r1), "R3": r3, "C1": c, "C2": c}

    def _rc_design(self, target: SectionTarget, r: float, c: float) -> dict:
        """R1 = R, C1 = C; C2, R2 and R3 solved (the module's equations)."""
        q, g, w = target.q, target.gain, target.wn
        c2 = q / (w * g * r)
        rp = 1.0 / (w * q * (c + c2))
        if rp >= r:
            raise ParamError(f"{{r}} and {{c}}: no positive R2 for R = {r:g} Ohm, C = {c:g} F: {self.name} needs "
                             f"R*C > (1 - Q^2/gain)/(w0 Q) = {(1 - q * q / g) / (w * q):.4g} s (R*C is "
                             f"{r * c:.4g} s); choose a larger R or C", params=("r", "c"))
        return {"R1": r, "R2": 1.0 / (1.0 / rp - 1.0 / r), "R3": g * r * (c + c2) / c, "C1": c, "C2": c2}

    def netlist(self, values: dict, prefix: str = "", amp_ref: str = "U1", inp: str = "vin",
                out: str = "vout") -> Netlist:
        x, n = self.internal(amp_ref, "x", "n")
        ends = {"R1": (inp, x), "R2": (x, GROUND), "C1": (x, n), "C2": (x, out), "R3": (n, out)}
        return self.assemble(values, prefix, ends, Amp(amp_ref, self.title, GROUND, n, out))
