"""Multiple-feedback (MFB) low-pass section: inverting, passband gain -R2/R1.

Parts (TI's names): R1 from the input to node x, C2 from x to ground, R2 from
x to the output, R3 from x to the inverting input n, C1 from n to the output;
the non-inverting input is grounded.

Nodal analysis, written out (ideal op-amp: Vn = 0)::

    n:  Vx / R3 = -Vo s C1                        ->  Vx = -s C1 R3 Vo
    x:  (Vi - Vx)/R1 = Vx s C2 + (Vx - Vo)/R2 + Vx/R3

and so (TI, "Op Amps for Everyone", ch. 16, SLOA088: the second-order low-pass,
MFB topology)::

    H(s) = -(R2/R1) / (R2 R3 C1 C2 s^2 + C1 (R2 + R3 + R2 R3 / R1) s + 1)

    wn = 1 / sqrt(R2 R3 C1 C2),   Q = sqrt(R2 R3 C1 C2) / (C1 (R2 + R3 + R2 R3 / R1)),   gain G = R2/R1

With a finite-gain op-amp Vn is no longer 0: the n row becomes
(Vx - Vn)/R3 = (Vn - Vo) s C1 with Vo = -A(s) Vn
(:func:`~designer.filters.topology.nodal_response` solves it from the netlist).

Design (continuous): C1 from the target, C2 = ratio C1; R2 R3 = 1/(wn^2 C1 C2) = P,
R1 = R2/G, so the s coefficient gives C1 R2^2 - R2/(wn Q) + C1 (1 + G) P = 0, R2 its
smaller root (TI's choice), R3 = P/R2.

Realisability: a real root needs C2/C1 >= 4 Q^2 (1 + G) (TI's
"C2 >= 4 b1 (1 - A0) C1 / a1^2", A0 = -G). The default ratio is that bound (then
R2 = 1/(2 wn Q C1)).

R and C given (:meth:`~designer.filters.topology.Topology.synthesize_rc`): the gain resistor R2 = R,
R1 = R/G, the capacitor to ground C2 = C; then R3 C1 = T = 1/(wn^2 R C) and the
s coefficient C1 R + T (1 + G) = 1/(wn Q) give

    C1 = (1/(wn Q) - T (1 + G)) / R,   R3 = T / C1,

positive only when R C > Q (1 + G)/wn (the MFB's own bound, C2/C1 >= 4 Q^2 (1 + G),
then holds: this is the root the default ratio takes, met from the other side).
"""

from __future__ import annotations

from ..core.errors import DesignError, ParamError
from ..core.i18n import N_
from ..spice.deck import GROUND, Amp, Netlist
from .topology import PartSpec, SectionTarget, Topology, polynomial, quadratic_root

__all__ = ["MfbLowPass"]


class MfbLowPass(Topology):
    """The inverting MFB low-pass section (parts R1 R2 R3 C1 C2)."""

    name, title = "mfb-lowpass", N_("MFB low-pass (inverting)")
    kind, order, inverting = "lowpass", 2, True
    parts = (PartSpec("R1", "R", N_("input resistor")),
             PartSpec("R2", "R", N_("gain: node x to the output")),
             PartSpec("R3", "R", N_("node x to the inverting input")),
             PartSpec("C1", "C", N_("inverting input to the output (feedback)")),
             PartSpec("C2", "C", N_("node x to ground")))
    choices = ("ratio",)
    example = SectionTarget("lowpass", 1e3, q=0.7071, gain=2.0)

    def coefficients(self, values: dict) -> tuple:
        v = self.values_of(values)
        r1, r2, r3, c1, c2 = (v[r] for r in ("R1", "R2", "R3", "C1", "C2"))
        den = polynomial(r2 * r3 * c1 * c2, c1 * (r2 + r3 + r2 * r3 / r1), 1.0)
        return polynomial(0.0, 0.0, -r2 / r1), den

    def limits(self, target: SectionTarget) -> dict:
        return {"ratio_min": 4 * target.q ** 2 * (1 + target.gain)}

    def _check_limits(self, target: SectionTarget, choices: dict) -> None:
        bound = self.limits(target)["ratio_min"]
        m = choices.get("ratio")
        if m is not None and m < bound * (1 - 1e-12):
            raise DesignError(f"ratio: C2/C1 = {m:.4g} is below the bound 4 Q^2 (1 + |gain|) = {bound:.4g} of "
                              f"{self.name} at Q = {target.q:.4g}, gain {target.gain:.4g}; use a ratio of at least "
                              f"{bound:.4g}, a lower Q or gain, or a Sallen-Key section", param="ratio")

    def synthesize(self, target: SectionTarget, **choices) -> dict:
        self.check_realisable(target, **choices)
        q, g, w = target.q, target.gain, target.wn
        m = choices.get("ratio", self.limits(target)["ratio_min"])
        c1 = self.scale(target, 1.0 / m ** 0.5)
        c2 = m * c1
        p = 1.0 / (w * w * c1 * c2)
        r2 = quadratic_root(c1, 1.0 / (w * q), c1 * (1 + g) * p)
        return {"R1": r2 / g, "R2": r2, "R3": p / r2, "C1": c1, "C2": c2}

    def _rc_design(self, target: SectionTarget, r: float, c: float) -> dict:
        """R2 = R, R1 = R/G, C2 = C; C1 and R3 solved (the module's equations)."""
        q, g, w = target.q, target.gain, target.wn
        t = 1.0 / (w * w * r * c)
        c1 = (1.0 / (w * q) - t * (1 + g)) / r
        if c1 <= 0:
            raise ParamError(f"{{r}} and {{c}}: no positive C1 for R = {r:g} Ohm, C = {c:g} F: {self.name} needs "
                             f"R*C > Q (1 + |gain|)/wn = {q * (1 + g) / w:.4g} s (R*C is {r * c:.4g} s); choose a "
                             "larger R or C", params=("r", "c"))
        return {"R1": r / g, "R2": r, "R3": t / c1, "C1": c1, "C2": c}

    def netlist(self, values: dict, prefix: str = "", amp_ref: str = "U1", inp: str = "vin",
                out: str = "vout") -> Netlist:
        x, n = self.internal(amp_ref, "x", "n")
        ends = {"R1": (inp, x), "C2": (x, GROUND), "R2": (x, out), "R3": (x, n), "C1": (n, out)}
        return self.assemble(values, prefix, ends, Amp(amp_ref, self.title, GROUND, n, out))
