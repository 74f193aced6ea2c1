"""Sallen-Key high-pass section, unity gain (a follower) or gain K (a
non-inverting amplifier, K = 1 + R4/R3).

Parts (TI's names): C1 from the input to node x, C2 from x to the
non-inverting input p, R2 from p to ground, R1 from x to the output (the
positive feedback); with gain, R3 from the inverting input to ground and R4
from the output to it.

Transfer function (TI, "Op Amps for Everyone", ch. 16, SLOA088: the
second-order high-pass, Sallen-Key topology; here with separate C1, C2)::

    H(s) = K R1 R2 C1 C2 s^2 / (R1 R2 C1 C2 s^2 + (R1 (C1 + C2) + R2 C2 (1 - K)) s + 1)

    wn = 1 / sqrt(R1 R2 C1 C2),   Q = sqrt(R1 R2 C1 C2) / (R1 (C1 + C2) + R2 C2 (1 - K))

Node equations (Vo = K Vp): x: (Vi - Vx) s C1 = (Vx - Vp) s C2 + (Vx - Vo)/R1;
p: (Vx - Vp) s C2 = Vp / R2. Eliminating Vx and multiplying by s C2 R1 R2 gives
H(s) above. With a finite-gain op-amp, K becomes K' = A/(1 + A/K) (computed by
:func:`~designer.filters.topology.nodal_response` from the netlist).

Design (continuous): C1 from the target, C2 = ratio C1 (default 1, TI's equal
capacitors), R1 R2 = 1/(wn^2 C1 C2) = P and R1 the positive root of

    (C1 + C2) R1^2 - R1 / (wn Q) + P C2 (1 - K) = 0,

R2 = P / R1 (at unity gain R1 = 1/(wn Q (C1 + C2))); with gain R3 = the target's
impedance and R4 = (K - 1) R3.

Realisability: every Q > 0 and K >= 1 is reachable (the constant term is never
positive); the cost is the resistor spread, R2/R1 >= 4 Q^2 at unity gain.

R and C given (:meth:`~designer.filters.topology.Topology.synthesize_rc`): the seed's procedure
with the roles of R and C swapped: R1 = R, C1 = C, C2 = n C, R2 = m R. With
u = wn R C, R2 C2 = 1/(wn^2 R C) and the s coefficient R (C + C2) + R2 C2 (1 - K)
= 1/(wn Q) give

    n = 1/(Q u) - 1 + (K - 1)/u^2,   m = 1/(u^2 n)

(the low-pass's m, with zeta = 1/(2 Q)), positive only when R C < 1/(wn Q) at
unity gain; with gain R3 = R, R4 = (K - 1) R.
"""

from __future__ import annotations

from ..core.errors import ParamError
from ..core.i18n import N_
from ..spice.deck import GROUND, Netlist
from .sallen_key import SallenKeySection
from .topology import PartSpec, SectionTarget, polynomial, quadratic_root

__all__ = ["SallenKeyHighPass"]

class SallenKeyHighPass(SallenKeySection):
    """The Sallen-Key high-pass section (unity gain, or gain K with ``with_gain``).

    Parameters
    ----------
    with_gain : bool
        False: a follower (parts R1 R2 C1 C2); True: K = 1 + R4/R3 (R3, R4 added).
    """

    kind, base_name = "highpass", "sallen-key-highpass"
    network = (PartSpec("R1", "R", N_("C1-C2 node to the output (feedback)")),
               PartSpec("R2", "R", N_("non-inverting input to ground")),
               PartSpec("C1", "C", N_("input capacitor")),
               PartSpec("C2", "C", N_("to the non-inverting input")))

    def coefficients(self, values: dict) -> tuple:
        v = self.values_of(values)
        k = self.gain_of(v)
        den = polynomial(v["R1"] * v["R2"] * v["C1"] * v["C2"],
                         v["R1"] * (v["C1"] + v["C2"]) + v["R2"] * v["C2"] * (1 - k), 1.0)
        return polynomial(k * den[0], 0.0, 0.0), den

    def synthesize(self, target: SectionTarget, **choices) -> dict:
        self.check_realisable(target, **choices)
        q, k, w = target.q, target.gain, target.wn
        m = choices.get("ratio", 1.0)
        c1 = self.scale(target)
        c2 = m * c1
        p = 1.0 / (w * w * c1 * c2)
        r1 = quadratic_root(c1 + c2, 1.0 / (w * q), p * c2 * (1 - k))
        return {"R1": r1, "R2": p / r1, "C1": c1, "C2": c2, **self.gain_values(target, choices)}

    def _rc_design(self, target: SectionTarget, r: float, c: float) -> dict:
        """R1 = R, C1 = C, C2 = n C, R2 = m R (the module's equations)."""
        q, k, u = target.q, target.gain, target.wn * r * c
        n = 1.0 / (q * u) - 1.0 + (k - 1.0) / (u * u)
        if n <= 0:
            raise ParamError(f"{{r}} and {{c}}: no positive C2 for R = {r:g} Ohm, C = {c:g} F: {self.name} needs "
                             f"R*C < (1/Q + (K - 1)/(wn R C))/wn; at unity gain R*C < 1/(wn Q) = "
                             f"{1.0 / (target.wn * q):.4g} s (R*C is {r * c:.4g} s); choose a smaller R or C"
                             + (", or a larger gain" if self.with_gain else ""), params=("r", "c"))
        gain = {"R3": r, "R4": (k - 1) * r} if self.with_gain else {}
        return {"R1": r, "R2": r / (u * u * n), "C1": c, "C2": n * c, **gain}

    def netlist(self, values: dict, prefix: str = "", amp_ref: str = "U1", inp: str = "vin",
                out: str = "vout") -> Netlist:
        x, p, n = self.internal(amp_ref, "x", "p", "n")
        ends = {"C1": (inp, x), "C2": (x, p), "R2": (p, GROUND), "R1": (x, out)}
        return self.amplified(values, prefix, ends, amp_ref, p, n, out)
