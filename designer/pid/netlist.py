"""The closed loop as a part and net table and as a standalone ngspice deck:
the six-op-amp PID controller of seed 001 (Figure 66), the Sallen-Key plant
circuit, the project's behavioural op-amp models (inlined from
``circuits/``), supplies, a square-wave reference like the seed's bench test,
``.tran`` and ``.meas`` lines.

The table (:func:`loop_netlist`) is the one description of the circuit: the
deck, the schematic (:mod:`designer.pid.schematic`), the wiring table and the
bill of materials are all written from it, by the same code for every circuit
plant (:class:`designer.pid.plant.PlantCircuit`: its registered sections'
netlists). A plant's designators are its sections' with the prefix ``P``
(:data:`designer.pid.plant.PLANT_PREFIX`: RP1, UP; RPi1, UPi in a cascade);
the seed's Sallen-Key plant keeps the names of its own sheet
(:data:`designer.pid.plant.SEED_LOOP_NAMES`): its section's designators and
the op-amp U1, unless it has the gain pair, whose R3 and R4 the controller
owns: then its designators carry the prefix ``P`` (:func:`plant_ref_prefix`);
the controller has the seed's R3..R18, C3, C4 and the
op-amps U2 (difference), U3 (inverter), U4 (differentiator), U5 (integrator),
U6 (summer) and U7 (final gain), one per package as the seed built it;
:func:`designer.spice.deck.board` puts them in dual or quad packages.

Node names: ``ref`` reference, ``ve`` error (y - r), ``vp``/``vd``/``vi``
proportional, derivative and integral stage outputs, ``vs`` summer, ``u``
controller output (plant input), ``y`` plant output; ``n2``..``n7`` the
inverting inputs, ``p2`` the difference amplifier's non-inverting input,
``d4`` the differentiator's R12-C3 node, ``pv1``/``pvp``/``pvn`` inside the plant.
"""

from __future__ import annotations

from ..core.i18n import N_
from ..core.opamps import OpAmp
from ..spice import deck
from ..spice.deck import GROUND, Amp, Netlist, Part, SquareTest
from .blocks import PidParts

__all__ = ["closed_loop_deck", "controller_netlist", "loop_netlist", "model_loop_deck", "plant_circuit",
           "plant_ref_prefix"]

#: signals whose extremes the deck measures (one per op-amp output)
PROBES = ("ve", "vp", "vd", "vi", "vs", "u", "y")
#: what the nets are called on the sheet (wiring table, schematic labels)
NET_LABELS = {"ref": N_("reference r (generator, CH1)"), "y": N_("plant output y (CH2)"), "ve": N_("error ve"),
              "vp": N_("proportional vp"), "vd": N_("derivative vd"), "vi": N_("integral vi"), "vs": N_("summer vs"),
              "u": N_("controller output u"), "pv1": N_("plant node A (R1-R2-C2)"), "d4": N_("R12-C3 node"),
              "0": N_("ground")}


def controller_stages(parts: PidParts, ref="ref", y="y", u="u") -> list:
    """The controller's op-amps as (Amp, passives) in signal order; passives are
    :class:`~designer.spice.deck.Part` rows (U4, R7, R11, R12, C3 only with a
    derivative path)."""
    p = parts
    stages = [
        (Amp("U2", "difference", "p2", "n2", "ve"),
         [Part("R15", ref, "n2", p.r15, N_("U2 input from the reference r")),
          Part("R16", "n2", "ve", p.r16, N_("U2 feedback")),
          Part("R17", y, "p2", p.r17, N_("U2 +in from the plant output y")),
          Part("R18", "p2", GROUND, p.r18, N_("U2 +in to ground"))]),
        (Amp("U3", "inverter", GROUND, "n3", "vp"),
         [Part("R10", "ve", "n3", p.r10, N_("U3 input (unity inverter)")),
          Part("R9", "n3", "vp", p.r9, N_("U3 feedback"))]),
    ]
    if p.has_derivative:
        stages.append((Amp("U4", "differentiator", GROUND, "n4", "vd"),
                       [Part("R12", "ve", "d4", p.r12, N_("U4 input, in series with C3")),
                        Part("C3", "d4", "n4", p.c3, N_("U4 input, in series with R12 (derivative)")),
                        Part("R11", "n4", "vd", p.r11, N_("U4 feedback (differentiator)"))]))
    stages += [
        (Amp("U5", "integrator", GROUND, "n5", "vi"),
         [Part("R14", "ve", "n5", p.r14, N_("U5 input (integrator)")),
          Part("R13", "n5", "vi", p.r13, N_("U5 feedback, parallel to C4 (integrator leak)")),
          Part("C4", "n5", "vi", p.c4, N_("U5 feedback (integrator)"))]),
        (Amp("U6", "summer", GROUND, "n6", "vs"),
         [Part("R6", "vp", "n6", p.r6, N_("U6 input from U3 (proportional)"))]
         + ([Part("R7", "vd", "n6", p.r7, N_("U6 input from U4 (derivative)"))] if p.has_derivative else [])
         + [Part("R8", "vi", "n6", p.r8, N_("U6 input from U5 (integral)")),
            Part("R5", "n6", "vs", p.r5, N_("U6 feedback"))]),
        (Amp("U7", "gain", GROUND, "n7", u),
         [Part("R4", "vs", "n7", p.r4, N_("U7 input (final gain)")), Part("R3", "n7", u, p.r3, N_("U7 feedback"))]),
    ]
    return stages


def extreme_lines(parts: PidParts, test: SquareTest) -> list:
    """``.meas`` lines of the extremes of every op-amp output (and y) over the period."""
    t0, out = test.delay_s, []
    for node in PROBES:
        if node == "vd" and not parts.has_derivative:
            continue
        out += [f".meas tran {node}_max MAX v({node}) FROM={t0:.6g} TO={test.stop_s:.6g}",
                f".meas tran {node}_min MIN v({node}) FROM={t0:.6g} TO={test.stop_s:.6g}"]
    return out


def plant_circuit(plant):
    """The circuit a loop's plant is built as, and whether the controller's
    action is reversed: a :class:`~designer.pid.plant.Plant` with its circuit,
    or a :class:`~designer.pid.plant.PlantCircuit` (the seed's Sallen-Key plant
    too: its registered section, named as the seed's sheets,
    :func:`~designer.pid.plant.sallen_key_circuit`).

    Parameters
    ----------
    plant : Plant or PlantCircuit
        The plant.

    Returns
    -------
    tuple
        (:class:`~designer.pid.plant.PlantCircuit`, bool: the action reversed).
    """
    from .plant import Plant, PlantCircuit
    if isinstance(plant, Plant):
        return plant.circuit, plant.reversed_action
    if isinstance(plant, PlantCircuit):
        return plant, plant.inverting
    raise TypeError(f"a loop's plant is a designer.pid.plant.Plant or PlantCircuit, not {type(plant).__name__} "
                    "(a Sallen-Key parts record: designer.pid.plant.sallen_key_circuit)")


def plant_ref_prefix(plant) -> str:
    """The designator prefix of a one-section plant in the loop: none for the
    seed's Sallen-Key follower, :data:`~designer.pid.plant.PLANT_PREFIX` otherwise
    (a Sallen-Key plant's gain pair would take the controller's R3 and R4).

    Parameters
    ----------
    plant : Plant or PlantCircuit
        The plant (:func:`plant_circuit`).

    Returns
    -------
    str
        The prefix its designators carry in the loop ("" for the follower).
    """
    return plant_circuit(plant)[0].prefix(1)


def loop_netlist(parts: PidParts, plant) -> Netlist:
    """The whole loop around a circuit plant as one table: the plant's sections
    between ``u`` and ``y`` first (:meth:`~designer.pid.plant.PlantCircuit.netlist`:
    its designators prefixed, or named as the seed's plant), then the
    controller's stages in signal order, its action reversed for an inverting plant.

    Parameters
    ----------
    parts : PidParts
        The controller.
    plant : Plant or PlantCircuit
        The plant (:func:`plant_circuit`).

    Returns
    -------
    Netlist
        The loop's parts and op-amps, the plant's first.
    """
    circuit, reversed_action = plant_circuit(plant)
    pl = circuit.netlist("u", "y")
    ctl = controller_netlist(parts, reversed_action)
    return Netlist(pl.parts + ctl.parts, pl.amps + ctl.amps)


def closed_loop_deck(parts: PidParts, plant, opamp: OpAmp, test: SquareTest,
                     title: str, expected_final: float, points: int = 20000) -> str:
    """The whole loop around a circuit plant as a standalone deck
    (:func:`loop_netlist`: the plant's own sections and op-amps), with the
    reference, ``.tran`` and ``.meas`` lines of every loop deck; ``expected_final``
    (V) is the settled plant output the ``.meas`` levels refer to (the analytic
    closed loop's).

    Parameters
    ----------
    parts : PidParts
        The controller.
    plant : Plant or PlantCircuit
        The plant (:func:`plant_circuit`).
    opamp : OpAmp
        The op-amp of every stage (the plant's too).
    test : SquareTest
        The reference square wave.
    title : str
        The deck's title line.
    expected_final : float
        The settled plant output (V) the ``.meas`` levels refer to.
    points : int
        ``.tran`` points.

    Returns
    -------
    str
        The deck (runs alone with ``ngspice -b``).
    """
    c, reversed_action = plant_circuit(plant)
    if c.names is not None:   # the seed's plant: the header its reference decks have always had
        about = [f"* plant (seed 001, Fig. 43-45): X{c.names.amp_ref} Sallen-Key; controller (Fig. 66): "
                 "U2 difference (ve = y - r),",
                 "*   U3 inverter, U4 differentiator, U5 integrator, U6 summer, U7 gain -> "
                 "u = Kp (1 + 1/(Ti s) + Td s) (r - y)"]
    else:
        stages = ", ".join(f"{st.topology.title} (U{c.prefix(i)})" for i, st in enumerate(c.stages, 1))
        about = [f"* plant (a circuit, {c.topology}): {stages}; input u, output y",
                 "* controller (seed 001, Fig. 66): U2 difference (ve = y - r"
                 + (", r and y exchanged: the plant inverts" if reversed_action else "") + "), U3 inverter,",
                 "*   U4 differentiator, U5 integrator, U6 summer, U7 gain -> u = Kp (1 + 1/(Ti s) + Td s) (r - y)"]
    return _loop_deck(parts, opamp, test, title, expected_final, about, [], loop_netlist(parts, plant), points)


def _loop_deck(parts, opamp, test, title, expected_final, about, plant_lines, netlist, points, max_step_s=None):
    """The loop deck either plant gives: header comments (``about``: the plant and controller), the op-amp
    library, raw ``plant_lines``, supplies, the reference, ``netlist``, the .meas lines, .tran, .end."""
    circuit = deck.bench_circuit(title, opamp, [
        f"* {title}",
        f"* op-amps: {opamp.name} ({opamp.description}); supplies {opamp.vcc:g} V / {opamp.vee:g} V",
        f"* reference: 0 -> {test.amplitude_v:g} V square wave at {test.frequency_hz:g} Hz, edges "
        f"{test.edge_s:.3g} s, rising step at {test.delay_s:.4g} s",
        *about,
        "* Run: ngspice -b <this file>   (prints overshoot_pct, peak_time_s, rise_time_s, settling_time_s,",
        "*   and the extremes of every op-amp output)"])
    if plant_lines:     # a model plant's behavioural lines, after the library as before
        circuit.raw_spice = "\n".join([circuit.raw_spice, *plant_lines])
    circuit.V("ref", "ref", circuit.gnd, test.source())
    netlist.add_to(circuit, opamp)
    deck.settle_error_source(circuit, "y", expected_final)
    lines = deck.measure_lines("y", test, expected_final) + extreme_lines(parts, test)
    return deck.finish_deck(circuit, test, lines, points=points, max_step_s=max_step_s)


def controller_netlist(parts: PidParts, reversed_action: bool = False) -> Netlist:
    """The controller alone (U2..U7 and their parts), for a plant that is only a
    model: the deck puts the model between ``u`` and ``y``
    (:func:`designer.spice.behavioural.plant_lines`). ``reversed_action``: the
    reference and the plant output exchanged at the difference amplifier (r into
    R17, y into R15: u = -C(s) (r - y), for an inverting plant).

    Parameters
    ----------
    parts : PidParts
        The controller.
    reversed_action : bool
        Exchange r and y at the difference amplifier.

    Returns
    -------
    Netlist
    """
    rows, amps = [], []
    nets = {"ref": "y", "y": "ref"} if reversed_action else {}
    for amp, passives in controller_stages(parts, **nets):
        rows += passives
        amps.append(amp)
    return Netlist(tuple(rows), tuple(amps))


def model_loop_deck(parts: PidParts, model, opamp: OpAmp, test: SquareTest, title: str,
                    expected_final: float, points: int = 20000) -> str:
    """The controller around a plant known only as a model
    (:class:`~designer.core.process.ProcessModel`), as a standalone deck: the
    model as native linear elements and a matched transmission line for its dead
    time (:mod:`designer.spice.behavioural`), the six op-amp stages as for a
    Sallen-Key plant, the same reference, ``.tran`` and ``.meas`` lines. The
    step is at most the plant's own accuracy hint
    (:func:`~designer.spice.behavioural.max_step_hint_s`).

    Parameters
    ----------
    parts : PidParts
        The controller.
    model : designer.core.process.ProcessModel
        The plant.
    opamp : OpAmp
        The op-amp of every stage.
    test : SquareTest
        The reference square wave.
    title : str
        The deck's title line.
    expected_final : float
        The settled plant output (V) the ``.meas`` levels refer to.
    points : int
        ``.tran`` points.

    Returns
    -------
    str
    """
    from ..spice.behavioural import max_step_hint_s, plant_lines
    about = [f"* plant (a model, not a circuit): {model.text()}",
             f"*   from {model.source}; input u (the controller's output), output y",
             "* controller (seed 001, Fig. 66): U2 difference (ve = y - r), U3 inverter, U4 differentiator,",
             "*   U5 integrator, U6 summer, U7 gain -> u = Kp (1 + 1/(Ti s) + Td s) (r - y)"]
    return _loop_deck(parts, opamp, test, title, expected_final, about,
                      plant_lines(model.num, model.den, model.theta_s, "u", "y", name="plant"),
                      controller_netlist(parts), points, max_step_hint_s(model.num, model.den, model.theta_s))
