"""The analytic engine of a Sallen-Key plant's Monte Carlo, by designator: the generic chunk function
(:func:`designer.plant.circuit.evaluate`) on the Sallen-Key low-pass section the parts make (the
follower, or the gain section with R3 and R4), which takes the section's own figures
(:meth:`~designer.filters.topology.Topology.sample_figures`,
:mod:`designer.filters.sallen_key_lowpass_figures`: seed 001's formulas, the third-order model with the
op-amp and its exact step), every sample at once.
"""

from __future__ import annotations

from ..filters.sallen_key_lowpass_parts import gain_refs, section_of
from ..plant import circuit

__all__ = ["FIGURES", "context", "evaluate", "plant_figures"]

FIGURES = circuit.FIGURES


def context(values: dict, opamp) -> tuple:
    """The chunk function's context (:func:`designer.plant.circuit.evaluate`) for sampled parts.

    Parameters
    ----------
    values : dict
        Designator -> array over the samples (the gain pair's when the plant has gain).
    opamp : designer.core.opamps.OpAmp or None
        The op-amp (None: ideal).

    Returns
    -------
    tuple
        (the section's registry name, the op-amp).
    """
    return section_of(with_gain=all(r in values for r in gain_refs())).name, opamp


def plant_figures(v: dict, opamp=None) -> dict:
    """Every figure of :data:`FIGURES` for the sampled parts ``v`` (designator -> array; ``GBW``, Hz,
    when there: the op-amp's gain-bandwidth of each sample).

    Parameters
    ----------
    v : dict
        Designator -> array over the samples.
    opamp : designer.core.opamps.OpAmp, optional
        The op-amp (None: ideal).

    Returns
    -------
    dict
        Figure -> array over the samples.
    """
    return circuit.evaluate(context(v, opamp), v)


def evaluate(opamp, values: dict) -> dict:
    """A chunk function (:mod:`.runner`) of the op-amp alone as context: :func:`plant_figures`.

    Parameters
    ----------
    opamp : designer.core.opamps.OpAmp or None
        The op-amp (None: ideal).
    values : dict
        Designator -> array over the chunk's samples.

    Returns
    -------
    dict
        Figure -> array over the samples.
    """
    return plant_figures(values, opamp)
