"""Analytic models of the Sallen-Key plant (seed 001, IV.3-IV.9): the ideal
second-order transfer function, the third-order one with a single-pole
op-amp, and the sensitivities of wn and zeta to every part and op-amp figure.
Step and frequency responses come from :mod:`designer.core.lti`.
"""

from __future__ import annotations

from dataclasses import dataclass


from ..core.lti import dominant_pair
from ..core.opamps import OpAmp
from ..filters.sallen_key_lowpass_parts import part_values, section_of
from . import circuit
from .sallenkey import SallenKeyParts

__all__ = ["plant_tf", "plant_tf_opamp", "plant_model", "opamp_pair", "sensitivities"]


def plant_tf(parts: SallenKeyParts):
    """Ideal op-amp: K / (a s^2 + b s + 1), the section's own coefficients
    (:meth:`~designer.filters.topology.Topology.coefficients` of the Sallen-Key low-pass the parts realise).

    Parameters
    ----------
    parts : SallenKeyParts
        The parts.

    Returns
    -------
    tuple of numpy.ndarray
        (num, den), highest power first.
    """
    num, den = section_of(parts).coefficients(part_values(parts))
    return num[-1:], den   # a low-pass's numerator is its constant term K


def plant_tf_opamp(parts: SallenKeyParts, opamp: OpAmp):
    """Sallen-Key low-pass with a single-pole op-amp (third order).

    Vo/Vin = 1/D(s), normalised to D(0) = 1: the generic op-amp-aware model
    (:func:`designer.plant.circuit.opamp_tf`) of the Sallen-Key low-pass the parts realise, which is
    the section's closed form (:func:`designer.filters.sallen_key_lowpass_synthesis.opamp_denominator`,
    :meth:`~designer.filters.sallen_key_lowpass.SallenKeyLowPass.opamp_model`), K = 1 + R4/R3.

    Parameters
    ----------
    parts : SallenKeyParts
        The parts.
    opamp : OpAmp
        The op-amp.

    Returns
    -------
    tuple of numpy.ndarray
        (num, den), highest power first.
    """
    num, den = circuit.opamp_tf(section_of(parts), part_values(parts), opamp)
    return num[-1:], den   # the numerator's constant term alone, as the model has always had it


def plant_model(parts: SallenKeyParts, opamp: OpAmp):
    """The model a loop or a check takes of the plant: :func:`plant_tf` with an ideal
    op-amp, else :func:`plant_tf_opamp`.

    Parameters
    ----------
    parts : SallenKeyParts
        The parts.
    opamp : OpAmp
        The op-amp.

    Returns
    -------
    tuple of numpy.ndarray
        (num, den), highest power first.
    """
    return plant_tf(parts) if opamp.ideal else plant_tf_opamp(parts, opamp)


def opamp_pair(parts: SallenKeyParts, opamp: OpAmp) -> tuple:
    """fn (Hz) and zeta of the op-amp-aware model's dominant pair
    (:func:`designer.core.lti.dominant_pair` of :func:`plant_tf_opamp`).

    Parameters
    ----------
    parts : SallenKeyParts
        The parts.
    opamp : OpAmp
        The op-amp.

    Returns
    -------
    tuple of float
        (fn_hz, zeta).
    """
    return dominant_pair(plant_tf_opamp(parts, opamp)[1])


@dataclass(frozen=True)
class Sensitivity:
    """How much wn and zeta move, relatively, for a relative change of one part:
    S = d ln(y) / d ln(x)."""

    wn: float
    zeta: float

    def to_dict(self) -> dict:
        return {"wn": self.wn, "zeta": self.zeta}


def sensitivities(parts: SallenKeyParts, opamp: OpAmp | None = None, rel_step: float = 1e-6) -> dict:
    """Relative sensitivities S_x^y = d ln y / d ln x of wn and zeta: the generic section's
    (:func:`designer.plant.circuit.sensitivities` of the Sallen-Key low-pass the parts realise), its
    RC network's rows, the gain K's (when not a follower) and, with a real op-amp, GBW's and A0's.

    Parameters
    ----------
    parts : SallenKeyParts
        The parts.
    opamp : OpAmp, optional
        The op-amp (its GBW and A0 join the list; the ideal one: the ideal model, as with none).
    rel_step : float
        The central differences' relative step.

    Returns
    -------
    dict
        ``{"R1": Sensitivity, ...}``: the network, then K, GBW, A0.
    """
    section = section_of(parts)
    table = circuit.sensitivities(section, part_values(parts), opamp, rel_step)
    # the plant's table has always shown K rather than the gain pair that sets it (R3, R4)
    return {label: Sensitivity(s["wn"], s["zeta"]) for label, s in table.items()
            if label not in section.choice_parts}
