"""What the Sallen-Key sections share: the non-inverting amplifier around the
RC network, a follower (K = 1) or gain K = 1 + R4/R3 with R3 from the inverting
input to ground and R4 from the output to it (TI, "Op Amps for Everyone",
ch. 16, SLOA088: the Sallen-Key topology's general form).

With a finite-gain op-amp A(s) the amplifier is Vo = K' Vp with
K' = A / (1 + A/K): every Sallen-Key H(s) with K replaced by K'(s) (the nodal
analysis of :func:`~designer.filters.topology.nodal_response` computes it).
The low-pass and high-pass networks are in their own modules.
"""

from __future__ import annotations

from ..core.errors import DesignError
from ..core.i18n import N_
from ..spice.deck import GROUND, Amp, Netlist
from .topology import DEFAULT_IMPEDANCE_OHM, PartSpec, SectionTarget, Topology

__all__ = ["SallenKeySection", "GAIN_PARTS"]

#: the gain network of a Sallen-Key section with gain
#: the sections' titles by kind and gain (whole phrases, so that the catalogue translates each)
_TITLES = {("lowpass", False): N_("Sallen-Key low-pass, unity gain"), ("lowpass", True): N_("Sallen-Key low-pass, gain K"),
          ("highpass", False): N_("Sallen-Key high-pass, unity gain"),
          ("highpass", True): N_("Sallen-Key high-pass, gain K")}
GAIN_PARTS = (PartSpec("R3", "R", N_("gain: inverting input to ground")),
              PartSpec("R4", "R", N_("gain: output to inverting input")))


class SallenKeySection(Topology):
    """A Sallen-Key section: its RC network (:attr:`network`, set by the subclass)
    and the amplifier, a follower or gain K (``with_gain``).

    Parameters
    ----------
    with_gain : bool
        False: a follower; True: K = 1 + R4/R3 (R3, R4 added to the parts and
        ``r3``, R3's value, to the choices).

    Attributes
    ----------
    network : tuple of PartSpec
        The RC network's parts.
    base_name : str
        The follower's registry name; the gain section's is ``base_name + "-gain"``.
    """

    network: tuple = ()
    base_name: str = ""
    order, inverting = 2, False

    def __init__(self, with_gain: bool = False):
        self.with_gain = with_gain
        self.name = self.base_name + ("-gain" if with_gain else "")
        self.title = _TITLES[self.kind, with_gain]
        self.parts = self.network + (GAIN_PARTS if with_gain else ())
        self.choices = ("ratio", "r3") if with_gain else ("ratio",)
        self.choice_parts = tuple(p.ref for p in GAIN_PARTS) if with_gain else ()
        self.example = SectionTarget(self.kind, 1e3, q=1.3 if with_gain else 0.7071, gain=2.0 if with_gain else 1.0)

    def gain_of(self, v: dict):
        """K = 1 + R4/R3 (1 for the follower).

        Parameters
        ----------
        v : dict
            Designator -> value (arrays allowed).

        Returns
        -------
        float or ndarray
            The gain.
        """
        return 1.0 + v["R4"] / v["R3"] if self.with_gain else 1.0

    def sensitivity_parameters(self) -> tuple:
        return ("K",) if self.with_gain else ()

    def with_parameter(self, values: dict, name: str, factor) -> dict:
        if name not in self.sensitivity_parameters():
            return super().with_parameter(values, name, factor)
        # K = 1 + R4/R3 times factor with R3 kept: R4 = (K factor - 1) R3 (the network untouched)
        return {**values, "R4": (self.gain_of(values) * factor - 1.0) * values["R3"]}

    def check_gain(self, target: SectionTarget) -> None:
        """Refuse a gain the amplifier cannot give: not 1 for the follower, not above 1 with gain.

        Parameters
        ----------
        target : SectionTarget
            The target.

        Raises
        ------
        DesignError
            One line naming the other section.
        """
        if not self.with_gain:
            self.require_unity_gain(target, f"use {self.base_name}-gain")
        elif target.gain <= 1.0:
            raise DesignError(f"gain: {self.name} needs a gain above 1 (R4/R3 = K - 1), got {target.gain:.4g}; "
                              f"use {self.base_name} for unity gain", param="gain")

    def _check_limits(self, target: SectionTarget, choices: dict) -> None:
        self.check_gain(target)

    def gain_values(self, target: SectionTarget, choices: dict) -> dict:
        """R3 (the choice ``r3``, else the target's impedance) and R4 = (K - 1) R3; none for a follower.

        Parameters
        ----------
        target : SectionTarget
            The target (its gain K).
        choices : dict
            The synthesis's choices.

        Returns
        -------
        dict
            {"R3": .., "R4": ..} or {}.
        """
        if not self.with_gain:
            return {}
        r3 = choices.get("r3", target.impedance_ohm or DEFAULT_IMPEDANCE_OHM)
        return {"R3": r3, "R4": (target.gain - 1) * r3}

    def amplified(self, values: dict, prefix: str, ends: dict, amp_ref: str, p: str, n: str, out: str) -> Netlist:
        """The section's netlist: the network's ``ends``, the gain network from ``n``
        (the inverting input) and the op-amp (follower: its inverting input is ``out``).

        Parameters
        ----------
        values : dict
            Designator -> value.
        prefix : str
            The stage's designator prefix.
        ends : dict
            The network's designator -> (net a, net b).
        amp_ref : str
            The op-amp's designator.
        p, n, out : str
            The non-inverting input, inverting input and output nets.

        Returns
        -------
        Netlist
            The section.
        """
        ends = {**ends, "R3": (n, GROUND), "R4": (out, n)}
        return self.assemble(values, prefix, ends, Amp(amp_ref, self.title, p, n if self.with_gain else out, out))
