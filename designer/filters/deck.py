"""A filter circuit (a section's or a cascade's
:class:`~designer.spice.deck.Netlist`) as a standalone ngspice ``.ac`` deck,
and its frequency response simulated: the SPICE side of the conformance of
every topology's analytic response.

The deck drives the input net with a 1 V AC source, models the op-amps with the
project's behavioural subcircuits (``OPAMP_IDEAL``: a gain of A0 and nothing
else; ``OPAMP_BEH``: A0 and one pole at GBW/A0, the model of
:func:`~designer.filters.topology.open_loop_gain`), and sweeps ``.ac dec``.
"""

from __future__ import annotations

import numpy as np

from ..core.errors import SimulatorError
from ..core.opamps import OpAmp
from ..spice.deck import Netlist, ac_lines, bench_circuit
from ..spice.simulate import get_simulator

__all__ = ["AC_POINTS_PER_DECADE", "ac_deck", "simulate_ac"]

#: points per decade of an ``.ac`` sweep unless a caller asks for more
AC_POINTS_PER_DECADE = 50


def ac_deck(netlist: Netlist, opamp: OpAmp, f_lo: float, f_hi: float, inp: str = "vin",
            title: str = "filter", points_per_decade: int = AC_POINTS_PER_DECADE) -> str:
    """The ``.ac`` deck of ``netlist`` driven at net ``inp``.

    Parameters
    ----------
    netlist : Netlist
        The circuit.
    opamp : OpAmp
        The op-amp model of every op-amp (its A0, GBW, supplies).
    f_lo, f_hi : float
        The sweep, Hz.
    inp : str
        The input net (1 V AC).
    title : str
        The deck's title line.
    points_per_decade : int
        The sweep's density.

    Returns
    -------
    str
        Standalone deck text (``ngspice -b`` runs it).
    """
    circuit = bench_circuit(title, opamp, [f"* {title}: 1 V AC at {inp}; op-amp {opamp.name}"])
    circuit.V("in", inp, circuit.gnd, "DC 0 AC 1")
    netlist.add_to(circuit, opamp)
    return "\n".join([str(circuit).rstrip(), *ac_lines(f_lo, f_hi, points_per_decade), ".end"]) + "\n"


def simulate_ac(netlist: Netlist, opamp: OpAmp, f_lo: float, f_hi: float, inp: str = "vin", out: str = "vout",
                simulator: str = "ngspice-cli", points_per_decade: int = AC_POINTS_PER_DECADE) -> tuple:
    """Simulate :func:`ac_deck` and read V(out).

    Parameters
    ----------
    netlist : Netlist
        The circuit.
    opamp : OpAmp
        The op-amp model.
    f_lo, f_hi : float
        The sweep, Hz.
    inp, out : str
        Input and output nets.
    simulator : str
        ``ngspice-cli`` or ``pyspice`` (:func:`designer.spice.simulate.get_simulator`).
    points_per_decade : int
        The sweep's density.

    Returns
    -------
    tuple of ndarray
        (frequency in Hz, complex V(out) / V(in)).

    Raises
    ------
    SimulatorError
        ngspice failed, or the output net is not in its result.
    """
    res = get_simulator(simulator).run(ac_deck(netlist, opamp, f_lo, f_hi, inp, points_per_decade=points_per_decade))
    try:
        h = np.asarray(res[out], dtype=complex)
    except KeyError as exc:
        raise SimulatorError(str(exc)) from None
    return np.asarray(res["frequency"], dtype=float), h
