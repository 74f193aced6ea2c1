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
"""

from __future__ import annotations

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

    def netlist(self, values: dict, prefix: str = "", amp_ref: str = "U1", inp: str = "vin",
                out: str = "vout") -> Netlist:
        x, p, n = self.internal(amp_ref, "x", "p", "n")
        ends = {"C1": (inp, x), "C2": (x, p), "R2": (p, GROUND), "R1": (x, out)}
        return self.amplified(values, prefix, ends, amp_ref, p, n, out)
