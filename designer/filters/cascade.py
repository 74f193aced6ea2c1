"""A cascade of filter sections, itself a circuit: stage i is a
(:class:`~designer.filters.topology.Topology`, part values) pair whose
designators get the prefix ``i0`` (stage 1's R1 is R101, stage 2's C2 is C202:
the numbering of :func:`designer.spice.deck.board`'s decoupling), whose op-amp
is ``Ui`` and whose output net feeds stage i + 1.

The transfer function is the product of the stages' (each stage drives the
next from an op-amp output, an ideal source in both models, so the stages do not
load each other):

    H(s) = H1(s) H2(s) ... Hn(s)

and its polynomials are the products of the stages' (``numpy.polymul``).
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from ..core.errors import DesignError
from ..spice.deck import Netlist
from .topology import Topology

__all__ = ["Cascade", "Stage"]


@dataclass(frozen=True)
class Stage:
    """One stage of a cascade.

    Parameters
    ----------
    topology : Topology
        The section.
    values : dict
        Its designator -> value (ohm, farad), numbers.
    """

    topology: Topology
    values: dict


class Cascade:
    """Sections in series, input first.

    Parameters
    ----------
    stages : iterable of Stage or (Topology, dict)
        The sections and their part values.

    Raises
    ------
    DesignError
        No stage, or a stage's values not matching its topology's parts.
    """

    def __init__(self, stages):
        self.stages = tuple(s if isinstance(s, Stage) else Stage(*s) for s in stages)
        if not self.stages:
            raise DesignError("stages: a cascade needs at least one section", param="stages")
        for st in self.stages:
            st.topology.values_of(st.values)

    @staticmethod
    def prefix(i: int) -> str:
        """The designator prefix of stage ``i`` (1-based): ``"10"`` for stage 1.

        Parameters
        ----------
        i : int
            Stage number.

        Returns
        -------
        str
            The prefix.
        """
        return f"{i}0"

    @property
    def order(self) -> int:
        """The sum of the stages' orders."""
        return sum(st.topology.order for st in self.stages)

    @property
    def values(self) -> dict:
        """Every part's value by its cascade designator (R101, C202, ...)."""
        return {st.topology.prefixed(ref, self.prefix(i)): v
                for i, st in enumerate(self.stages, 1) for ref, v in st.values.items()}

    def coefficients(self) -> tuple:
        """The ideal (num, den) polynomials in s, highest power first: the stages' products.

        Returns
        -------
        tuple of ndarray
            (num, den).
        """
        num, den = np.array([1.0]), np.array([1.0])
        for st in self.stages:
            n, d = st.topology.coefficients(st.values)
            num, den = np.polymul(num, n), np.polymul(den, d)
        return num, den

    def response(self, s, opamp=None) -> np.ndarray:
        """H(s): the product of the stages' responses.

        Parameters
        ----------
        s : complex or ndarray
            Laplace variable, rad/s.
        opamp : designer.core.opamps.OpAmp, optional
            None: ideal op-amps; else every stage's with its A0 and GBW.

        Returns
        -------
        ndarray
            The complex transfer function.
        """
        h = np.ones(np.shape(s), dtype=complex)
        for st in self.stages:
            h = h * st.topology.response(st.values, s, opamp)
        return h

    def netlist(self, inp: str = "vin", out: str = "vout", prefix=None, amp_ref=None, link: str = "s") -> Netlist:
        """The whole cascade: stage i's parts prefixed ``i0``, its op-amp ``Ui``,
        its output net ``s{i}`` (the last one's ``out``) the next stage's input.

        Parameters
        ----------
        inp, out : str
            The cascade's input and output nets.
        prefix : callable, optional
            Stage number -> designator prefix (default :meth:`prefix`).
        amp_ref : callable, optional
            Stage number -> op-amp designator (default ``Ui``).
        link : str
            The stem of the nets between stages (``s1``, ``s2``, ...).

        Returns
        -------
        Netlist
            Every stage's parts then op-amps, in stage order.
        """
        prefix = prefix or self.prefix
        amp_ref = amp_ref or (lambda i: f"U{i}")
        parts, amps, node = [], [], inp
        for i, st in enumerate(self.stages, 1):
            nxt = out if i == len(self.stages) else f"{link}{i}"
            net = st.topology.netlist(st.values, prefix=prefix(i), amp_ref=amp_ref(i), inp=node, out=nxt)
            parts += net.parts
            amps += net.amps
            node = nxt
        return Netlist(tuple(parts), tuple(amps))
