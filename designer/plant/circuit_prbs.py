"""A plant on any registered section (:mod:`designer.plant.circuit_design`) under the
pseudo-random binary sequence the bench plays (``design-plant --topology NAME --stimulus
prbs``; seed 003, section 2.4), written once against the
:class:`~designer.filters.topology.Topology`: the section's op-amp-aware model
(:func:`designer.plant.circuit.opamp_tf`), its deck (the topology's netlist) and nothing
named after a part.

The sequence (:func:`designer.plant.prbs.plan_of`, :func:`designer.core.prbs.plan_for_plant`)
is chosen from two figures of the model, read so that they mean the same for every kind of
section:

- its length from the slowest time constant: a period outlasts 1.2x the time the slowest
  pole's envelope takes to fall to 2 %, ln(50) / min |Re p| (a low-pass's step settles to
  its DC gain, a high-pass's and a band-pass's to 0, all at that rate);
- its clock from the band edge where the section's own dynamics end: the upper -3 dB
  frequency of a low-pass and of a band-pass (the op-amp-aware model's), and a high-pass's
  corner (above it a high-pass passes the sequence as it is, up to the op-amp's bandwidth,
  which would make the sequence needlessly fast and long).

The levels are the bench's (0 V and ``--amplitude``, the square wave's range): a section
that blocks DC (a high-pass, a band-pass) swings its output about 0 V, an inverting one below
0 V. ngspice runs the section's netlist driven by the same PWL source ``make-prbs`` writes
(:func:`designer.plant.netlist.prbs_deck`), and its output is compared with the model's exact
response to the held input (:func:`designer.plant.prbs.run_deck`), with the op-amp's swing and
slew checks under it.
"""

from __future__ import annotations


import numpy as np

from ..core.lti import slowest_settling_s
from ..core.prbs import PrbsPlan
from . import circuit
from .prbs import attach, plan_of, run_deck

__all__ = ["band_edge_hz", "section_plan", "with_section_prbs"]


def _model(result) -> tuple:
    """The op-amp-aware model of the build, its leading zero numerator terms dropped."""
    num, den = circuit.opamp_tf(result.section, result.values, result.opamp)
    num = np.trim_zeros(np.asarray(num, float), "f")
    return (num if num.size else np.zeros(1)), np.asarray(den, float)


def band_edge_hz(result) -> float:
    """The band edge the sequence's clock covers (the module docstring): the op-amp-aware model's
    upper -3 dB frequency, a high-pass's corner (its natural frequency without one).

    Parameters
    ----------
    result : designer.plant.circuit_design.CircuitPlantResult
        The plant.

    Returns
    -------
    float
        Hz.
    """
    edges = result.figures["opamp"]["f3db_hz"]
    if not edges:
        return float(result.figures["opamp"]["fn_hz"])
    return float(min(edges) if result.section.kind == "highpass" else max(edges))


def section_plan(result, amplitude_v: float, bits=None, clock_hz=None) -> PrbsPlan:
    """The sequence for a section plant: levels 0 V and ``amplitude_v``; ``bits`` and ``clock_hz``
    chosen from :func:`designer.core.lti.slowest_settling_s` and :func:`band_edge_hz` unless given.

    Parameters
    ----------
    result : designer.plant.circuit_design.CircuitPlantResult
        The plant.
    amplitude_v : float
        The sequence's high level (V).
    bits : int, optional
        The register's length; None: chosen.
    clock_hz : float, optional
        The clock; None: chosen.

    Returns
    -------
    PrbsPlan
        The sequence.
    """
    _, den = _model(result)
    return plan_of(slowest_settling_s(den), band_edge_hz(result), float(result.figures["opamp"]["fn_hz"]),
                   amplitude_v, bits, clock_hz)


def with_section_prbs(result, amplitude_v: float, bits=None, clock_hz=None, simulate: bool = True,
                      simulator: str = "pyspice"):
    """``result`` with its PRBS bench test (``result.prbs``, a :class:`designer.plant.prbs.PrbsRun`),
    the op-amp's checks under it added to its checks; returned.

    Parameters
    ----------
    result : designer.plant.circuit_design.CircuitPlantResult
        The plant.
    amplitude_v : float
        The sequence's high level (V).
    bits : int, optional
        The register's length; None: chosen.
    clock_hz : float, optional
        The clock; None: chosen.
    simulate : bool
        Run it in ngspice too.
    simulator : str
        The backend.

    Returns
    -------
    designer.plant.circuit_design.CircuitPlantResult
        ``result``.
    """
    from .netlist import prbs_deck
    plan = section_plan(result, amplitude_v, bits, clock_hz)
    num, den = _model(result)
    topo, amp = result.section, result.opamp
    fig = result.figures["opamp"]
    fn = float(fig["fn_hz"])
    q = "" if fig["zeta"] is None else f" zeta={fig['zeta']:.4g}"
    deck = prbs_deck(result.netlist, amp, plan, f"{topo.title} plant fn={fn:.5g}Hz{q} under a PRBS of {plan.bits} "
                     f"bits, op-amp={amp.name}", max(fn, float(result.figures["ideal"]["fn_hz"])), "vin")
    return attach(result, run_deck(num, den, plan, deck, amp, simulate, simulator, "vout", "vin"))
