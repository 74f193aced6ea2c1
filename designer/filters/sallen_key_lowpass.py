"""Sallen-Key low-pass section, unity gain (a follower) or gain K (a
non-inverting amplifier, K = 1 + R4/R3).

Parts (the seed's names, as :mod:`designer.plant.sallenkey`, which are TI's:
C1 the capacitor to ground): R1 from the input to node x, R2 from x to the
non-inverting input p, C1 from p to ground, C2 from x to the output (the
positive feedback); with gain, R3 from the inverting input to ground and R4
from the output to it.

Transfer function (TI, "Op Amps for Everyone", ch. 16, SLOA088: the second-order
low-pass, Sallen-Key topology, in the general and the unity-gain form)::

    H(s) = K / (R1 R2 C1 C2 s^2 + (C1 (R1 + R2) + R1 C2 (1 - K)) s + 1)

    wn = 1 / sqrt(R1 R2 C1 C2),   Q = sqrt(R1 R2 C1 C2) / (C1 (R1 + R2) + R1 C2 (1 - K))

Node equations (p: the non-inverting input, Vo = K Vp):
x: (Vi - Vx)/R1 = (Vx - Vp)/R2 + (Vx - Vo) s C2;  p: (Vx - Vp)/R2 = Vp s C1.
With a finite-gain op-amp the amplifier is Vo = K' Vp, K' = A/(1 + A/K): the same
H(s) with K replaced by K'(s) (what :func:`~designer.filters.topology.nodal_response`
computes from the netlist). :meth:`SallenKeyLowPass.opamp_model` is that model's closed
form (seed 001, IV.3-IV.9: :func:`~designer.filters.sallen_key_lowpass_synthesis.opamp_denominator`),
equal to the nodal solution to rounding and about three times faster.

Design (continuous): C1 from the target (its capacitor, or the one that puts
R1 = R2 near its impedance), C2 = ratio C1, then R1 R2 = 1/(wn^2 C1 C2) and
R1 from the s coefficient, the root of

    C1 (1 + m (1 - K)) R1^2 - R1 / (wn Q) + 1 / (wn^2 m C1) = 0,   m = C2/C1

(the smaller one; R2 = 1/(wn^2 C1 C2 R1)); with gain, R3 = the target's impedance
and R4 = (K - 1) R3.

Realisability: the quadratic has a real root only when
m (1/(4 Q^2) + K - 1) >= 1, i.e. at unity gain C2/C1 >= 4 Q^2 (SLOA088's
"C2 >= C1 4 b1 / a1^2"), with gain C2/C1 >= 1 / (1/(4 Q^2) + K - 1). The default
ratio is the bound at unity gain (then R1 = R2) and 1 (equal capacitors) with
gain when the bound allows it.

R and C given (:meth:`~designer.filters.topology.Topology.synthesize_rc`): the seed's procedure
(001, simplification 2; :func:`~designer.filters.sallen_key_lowpass_synthesis.ratios_from_rc`):
R2 = R, R1 = m R, C1 = C, C2 = n C with

    m n = 1/(wn R C)^2,   m = 2 zeta sqrt(m n) - 1 + m n (K - 1),   zeta = 1/(2 Q),

positive only when R C < 2 zeta / wn at unity gain; with gain R3 = R, R4 = (K - 1) R.

E-series search (:meth:`SallenKeyLowPass.fast_search`, the plant's search entry's fast path): the
parallelogram search of :mod:`~designer.filters.sallen_key_lowpass_search` over the whole grid, exact
(brute force's ranking) in bounded memory; with gain, K is set first by the pair of series values
nearest the ratio K - 1 (R4/R3), and the network is searched at the K it gives.
"""

from __future__ import annotations

import numpy as np

from ..core.errors import DesignError, ParamError
from ..core.eseries import nearest_ratio_of
from ..core.i18n import N_
from ..spice.deck import GROUND, Netlist
from .sallen_key import SallenKeySection
from .sallen_key_lowpass_figures import sample_figures
from .sallen_key_lowpass_search import around as near, joint_search
from .sallen_key_lowpass_synthesis import coefficients, opamp_denominator, pair_of, ratios_from_rc, wn_zeta
from .topology import PartSpec, SectionTarget, polynomial, quadratic_root

__all__ = ["SallenKeyLowPass", "sallen_key_ratio_min"]


def sallen_key_ratio_min(q: float, gain: float) -> float:
    """The least C2/C1 of a Sallen-Key low-pass of quality factor ``q`` and gain ``gain``.

    Parameters
    ----------
    q : float
        Quality factor.
    gain : float
        K >= 1.

    Returns
    -------
    float
        1 / (1/(4 Q^2) + K - 1); 4 Q^2 at unity gain.
    """
    return 1.0 / (1.0 / (4 * q * q) + gain - 1.0)


class SallenKeyLowPass(SallenKeySection):
    """The Sallen-Key low-pass section (unity gain, or gain K with ``with_gain``).

    Parameters
    ----------
    with_gain : bool
        False: a follower (parts R1 R2 C1 C2); True: K = 1 + R4/R3 (R3, R4 added).
    """

    kind, base_name = "lowpass", "sallen-key-lowpass"
    network = (PartSpec("R1", "R", N_("input resistor")),
               PartSpec("R2", "R", N_("to the non-inverting input")),
               PartSpec("C1", "C", N_("non-inverting input to ground")),
               PartSpec("C2", "C", N_("R1-R2 node to the output (feedback)")))

    def coefficients(self, values: dict) -> tuple:
        v = self.values_of(values)
        k = self.gain_of(v)
        # the seed's a and b, written once (the plant's parts record and the joint search use the same function)
        den = polynomial(*coefficients(v["R1"], v["R2"], v["C1"], v["C2"], k), 1.0)
        num = polynomial(0.0, 0.0, k * den[2])
        return num, den

    def opamp_model(self, values: dict, opamp) -> tuple:
        # the closed form Vo/Vin = 1/D(s) (the module's equations) in nodal_model's shape:
        # num padded to den's length, den's constant term 1
        v = self.values_of(values)
        d = opamp_denominator(v["R1"], v["R2"], v["C1"], v["C2"], self.gain_of(v), opamp.a0, opamp.gbw_hz)
        d0 = d[..., -1:]
        num = np.zeros_like(d)
        num[..., -1:] = 1.0 / d0
        return num, d / d0

    def ideal_wn_zeta(self, values: dict, den=None) -> tuple:
        # the parts record's arithmetic (wn_zeta: wn = 1/sqrt(a), zeta = b / (2 sqrt(a))), bit for bit, where the
        # default's sqrt(1/a) may differ in the last bit: the references' fn, zeta and sensitivities are this pair
        if den is not None:
            # den = a s^2 + b s + 1 holds the record's products a and b themselves (coefficients above)
            return pair_of(den[0], den[1])
        v = self.values_of(values)
        return wn_zeta(v["R1"], v["R2"], v["C1"], v["C2"], self.gain_of(v))

    def sample_figures(self, values: dict, opamp=None):
        # the plant's Monte Carlo engine: the third-order model's exact step (its module says how it differs)
        return sample_figures(self.values_of(values), opamp)

    def step_final(self, values: dict, opamp, amplitude_v: float = 1.0):
        # the closed-loop DC gain of the op-amp model, K A0/(K + A0) (the ideal one's A0 too: the deck's),
        # in the seed plant's SPICE engine's order of operations, so its levels and overshoots keep their bits
        v = self.values_of(values)
        k = self.gain_of(v) * np.ones(np.broadcast_shapes(*(x.shape for x in v.values())))
        return amplitude_v * k * opamp.a0 / (k + opamp.a0)

    def limits(self, target: SectionTarget) -> dict:
        return {"ratio_min": sallen_key_ratio_min(target.q, target.gain)}

    def fast_search(self, target: SectionTarget, r_values, c_values, top: int, around: dict | None = None,
                    width: int = 2) -> dict:
        # the seed plant's exact search over the whole grid (sallen_key_lowpass_search.joint_search, the
        # module docstring's separation of fn and zeta), ranked by the fn and zeta errors: with gain, K is
        # set first by R3, R4, the pair of series values nearest the ratio K - 1 (the same for every
        # combination, so its error ranks nothing), and R1 R2 C1 C2 are searched at the K they give
        self.check_realisable(target)
        rv = np.unique(np.asarray(r_values, float))
        cv = np.unique(np.asarray(c_values, float))
        gain = {}
        if self.with_gain:
            r4, r3 = nearest_ratio_of(target.gain - 1.0, rv)
            gain = {"R3": r3, "R4": r4}
        k = self.gain_of(gain)
        if around is not None:
            # the exact design's neighbours, pooled per kind (the seed's joint rounding)
            rv = np.unique(np.concatenate([near(around[r], rv, width) for r in ("R1", "R2")]))
            cv = np.unique(np.concatenate([near(around[c], cv, width) for c in ("C1", "C2")]))
        found = joint_search(target.fn_hz, 1.0 / (2.0 * target.q), rv, cv, k, top=top)
        values = {ref: np.array([getattr(c, ref.lower()) for c in found], float) for ref in ("R1", "R2", "C1", "C2")}
        return {**values, **{ref: np.full(len(found), v) for ref, v in gain.items()}}

    def _check_limits(self, target: SectionTarget, choices: dict) -> None:
        self.check_gain(target)
        bound = sallen_key_ratio_min(target.q, target.gain)
        m = choices.get("ratio")
        if m is not None and m < bound * (1 - 1e-12):
            rule = "4 Q^2" if not self.with_gain else "1/(1/(4 Q^2) + K - 1)"
            raise DesignError(f"ratio: C2/C1 = {m:.4g} is below the bound {rule} = {bound:.4g} of {self.name} "
                              f"at Q = {target.q:.4g}, K = {target.gain:.4g}; use a ratio of at least {bound:.4g}, "
                              "a lower Q" + (", or a higher gain" if self.with_gain else ", or the gain-K section"),
                              param="ratio")

    def synthesize(self, target: SectionTarget, **choices) -> dict:
        self.check_realisable(target, **choices)
        q, k, w = target.q, target.gain, target.wn
        bound = sallen_key_ratio_min(q, k)
        m = choices.get("ratio", bound if not self.with_gain else max(1.0, bound))
        c1 = self.scale(target, 1.0 / m ** 0.5)
        c2 = m * c1
        p = 1.0 / (w * w * c1 * c2)
        r1 = quadratic_root(c1 * (1 + m * (1 - k)), 1.0 / (w * q), c1 * p)
        return {"R1": r1, "R2": p / r1, "C1": c1, "C2": c2, **self.gain_values(target, choices)}

    def _rc_design(self, target: SectionTarget, r: float, c: float) -> dict:
        """The seed's procedure: R2 = R, R1 = m R, C1 = C, C2 = n C (the module's equations)."""
        try:
            m, n = ratios_from_rc(target.fn_hz, 1.0 / (2 * target.q), r, c, target.gain)
        except DesignError as exc:
            raise ParamError("{r} and {c}: " + str(exc), params=("r", "c")) from None
        gain = {"R3": r, "R4": (target.gain - 1) * r} if self.with_gain else {}
        return {"R1": m * r, "R2": r, "C1": c, "C2": n * c, **gain}

    def netlist(self, values: dict, prefix: str = "", amp_ref: str = "U1", inp: str = "vin",
                out: str = "vout") -> Netlist:
        return self.wired(values, prefix, amp_ref, inp, out, self.internal(amp_ref, "x", "p", "n"))

    def wired(self, values: dict, prefix: str, amp_ref: str, inp: str, out: str, nets: tuple) -> Netlist:
        """The section with its internal nets named by the caller (the plant's sheet
        keeps the seed's ``v1``, ``vp``, ``vn``); :meth:`netlist` names them after the op-amp.

        Parameters
        ----------
        values : dict
            Designator -> value (ohm, farad).
        prefix : str
            Put after each designator's letter, for chaining (:meth:`prefixed`).
        amp_ref : str
            The op-amp's designator.
        inp, out : str
            The nets the section sits between.
        nets : tuple of str
            The internal nets: the R1-R2 node, the non-inverting and the inverting input.

        Returns
        -------
        Netlist
            Its parts (roles from :attr:`parts`) and op-amp.
        """
        x, p, n = nets
        ends = {"R1": (inp, x), "R2": (x, p), "C1": (p, GROUND), "C2": (x, out)}
        return self.amplified(values, prefix, ends, amp_ref, p, n, out)
