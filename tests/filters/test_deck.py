"""The ``.ac`` deck of a filter circuit: standalone (the op-amp models inlined),
the same answer from both simulator backends, a missing output net refused."""

import numpy as np
import pytest

from designer.core.errors import SimulatorError
from designer.core.opamps import get as get_opamp
from designer.filters import ac_deck, get, simulate_ac


def section():
    t = get("mfb-lowpass")
    return t, t.synthesize(t.example)


def test_deck_is_standalone_with_the_op_amp_model_and_the_sweep():
    t, values = section()
    deck = ac_deck(t.netlist(values), get_opamp("TL072"), 10.0, 1e5, title="mfb")
    low = deck.lower()
    assert ".subckt opamp_beh" in low and ".include" not in low and ".lib " not in low
    assert "vin vin 0 dc 0 ac 1" in low
    assert ".ac dec 50 10 100000" in low and low.rstrip().endswith(".end")
    for p in t.netlist(values).parts:
        assert f"{p.ref.lower()} " in low


@pytest.mark.spice
def test_both_backends_give_the_same_response():
    t, values = section()
    amp = get_opamp("LM741")
    f1, h1 = simulate_ac(t.netlist(values), amp, 100.0, 1e4, simulator="ngspice-cli")
    f2, h2 = simulate_ac(t.netlist(values), amp, 100.0, 1e4, simulator="pyspice")
    np.testing.assert_allclose(f1, f2, rtol=1e-12)
    np.testing.assert_allclose(h1, h2, rtol=1e-9)


@pytest.mark.spice
def test_an_output_net_the_circuit_lacks_is_a_simulator_error():
    t, values = section()
    with pytest.raises(SimulatorError, match="no vector 'nowhere'"):
        simulate_ac(t.netlist(values), get_opamp("ideal"), 100.0, 1e4, out="nowhere")
