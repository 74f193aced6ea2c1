"""The whole loop's schematic: the seed's six-op-amp PID controller (001,
Figure 66: the difference amplifier, the proportional, derivative and integral
branches, the summer and the final gain) driving the Sallen-Key plant
(Figures 43-45), drawn from the part and net table the deck is written from
(:func:`designer.pid.netlist.loop_netlist` as built on the bench,
:func:`designer.spice.deck.board`); or, for a plant known only as a model, the
same controller (:func:`designer.pid.netlist.controller_netlist`) driving a
block labelled with the model's G(s) (:func:`draw_model_loop`). The scope
probes are the seed's: the reference on CH1, the plant output on CH2, and every
op-amp output it photographs (Figures 79-90).
"""

from __future__ import annotations

from ..plant.schematic import draw_plant, draw_supplies
from ..report.schematic import Sheet

__all__ = ["PLANT_BLOCK", "draw_loop", "draw_model_loop"]

#: probe tags: the reference and the output on the scope's two channels, the controller's nodes as test points
PROBES = {"ref": "CH1", "y": "CH2", "ve": "TP ve", "vp": "TP vp", "vd": "TP vd", "vi": "TP vi", "vs": "TP vs",
          "u": "TP u"}


def _inverting(s, board, amp, inputs, feedback, x_in, row, x_out_min=None):
    """One inverting stage: ``inputs`` are chains of parts drawn from (x_in, y)
    rightwards to the inverting input at ``row`` (each chain a list of parts
    ending on the inverting input's net, with the y of its start), ``feedback``
    the parts in parallel from the inverting input to the output, stacked above.
    Returns the output point (after a short lead)."""
    unit = board.unit_of(amp.ref)
    xa = x_in + 5.5
    pts = s.opamp(amp, unit, board.package.part, (xa, row - 1.25), plus_on_top=False)
    s.wire(pts["inp"], (pts["inp"][0], pts["inp"][1] - 0.6))
    s.ground((pts["inp"][0], pts["inp"][1] - 0.6))
    node = (xa - 0.5, row)
    for chain, y0 in inputs:
        x = x_in
        for i, p in enumerate(chain):
            width = 5.0 / len(chain) if len(chain) > 1 else 3.0
            end = (x + width, y0)
            s.part(p, (x, y0), end)
            if i < len(chain) - 1:
                s.dot(end)
            x += width
        if y0 == row:
            s.wire((x, y0), pts["inn"])
        else:
            s.wire((x, y0), (node[0], y0), node)
    s.dot(node)
    out = pts["out"]
    xo = max(out[0] + 0.6, x_out_min or 0)
    s.wire(out, (xo, out[1]))
    level = row
    for p in feedback:
        top = level + 1.3
        s.wire((node[0], level), (node[0], top))
        s.part(p, (node[0], top), (xo, top))
        s.wire((xo, top), (xo, level if level != row else out[1]))
        level = top
    s.dot((xo, out[1]))
    return (xo, out[1])


def draw_loop(board, opamp, probes: dict = PROBES, plant_prefix: str = "") -> Sheet:
    """The closed loop of ``board`` (a :class:`~designer.spice.deck.Board` of
    :func:`~designer.pid.netlist.loop_netlist`, its plant's designators prefixed
    with ``plant_prefix``) on a new sheet.

    Parameters
    ----------
    board : designer.spice.deck.Board
        The loop as built.
    opamp : designer.core.opamps.OpAmp
        Its op-amp.
    probes : dict
        Node -> probe tag (:data:`PROBES`).
    plant_prefix : str
        The designator prefix the plant's parts carry in the loop (:func:`~designer.pid.netlist.plant_ref_prefix`).

    Returns
    -------
    Sheet
    """
    s = Sheet(fontsize=10)
    bottom = _draw_controller(s, board, probes)
    # the plant, below, fed from u by its net label
    draw_plant(board, opamp, s, origin=(0.0, bottom), inp_label="u", probes={"y": probes.get("y", "CH2")},
               supplies=False, ref_prefix=plant_prefix)
    draw_supplies(s, board, opamp, (17.5, bottom - 1.0), per_row=12)
    return s


def draw_model_loop(board, opamp, model_text: str, probes: dict = PROBES) -> Sheet:
    """The closed loop around a plant known only as a model, on a new sheet: the
    controller of ``board`` (a :class:`~designer.spice.deck.Board` of
    :func:`~designer.pid.netlist.controller_netlist`) as for a Sallen-Key plant,
    and the plant a block labelled ``model_text`` (``G(s) = ...``) from net ``u``
    to net ``y``, its ground on the common ground. The block's terminals are
    ``PLANT`` ``in``, ``out`` and ``gnd`` in :meth:`Sheet.connectivity`.

    Parameters
    ----------
    board : designer.spice.deck.Board
        The controller as built.
    opamp : designer.core.opamps.OpAmp
        Its op-amp.
    model_text : str
        The block's label.
    probes : dict
        Node -> probe tag (:data:`PROBES`).

    Returns
    -------
    Sheet
    """
    s = Sheet(fontsize=10)
    bottom = _draw_controller(s, board, probes)
    low = draw_plant_block(s, model_text, (0.0, bottom), probes.get("y", "CH2"))
    draw_supplies(s, board, opamp, (1.0, low - 4.2), per_row=16)
    return s


def draw_circuit_loop(board, opamp, plant, probes: dict = PROBES) -> Sheet:
    """The closed loop around a circuit plant of any topology, on a new sheet:
    the controller of ``board`` (a :class:`~designer.spice.deck.Board` of
    :func:`~designer.pid.netlist.loop_netlist`) as for a Sallen-Key
    plant, and below it the plant's own sections (``plant``: the
    :class:`~designer.spice.deck.Netlist` of
    :meth:`~designer.pid.plant.PlantCircuit.netlist`, whose parts and op-amps
    are on ``board``) drawn by :func:`draw_circuit` from net ``u`` to net ``y``.

    Parameters
    ----------
    board : designer.spice.deck.Board
        The loop as built.
    opamp : designer.core.opamps.OpAmp
        Its part (for the supplies).
    plant : designer.spice.deck.Netlist
        The plant's sections.
    probes : dict
        Net -> scope tag.

    Returns
    -------
    Sheet
        The drawing with its connectivity.
    """
    s = Sheet(fontsize=10)
    bottom = _draw_controller(s, board, probes)
    low = draw_circuit(s, board, plant, (0.0, bottom), "u", "y", probes.get("y", "CH2"))
    draw_supplies(s, board, opamp, (1.0, low - 2.5), per_row=16)
    return s


#: a circuit's nets are vertical buses this far apart; a part spans PART_LENGTH of the gap (never a bus)
BUS_PITCH, PART_LENGTH, ROW_PITCH = 4.0, 2.5, 1.6


def draw_circuit(s: Sheet, board, netlist, origin, inp: str, out: str, probe: str = "CH2") -> float:
    """Any circuit of parts and op-amps (``netlist``, placed on ``board``) on ``s``
    as a bus diagram: every net but ground a vertical bus (``inp`` first,
    ``out`` last, labelled with their names at the top, ``out`` with the
    ``probe`` tag), each part on a row of its own from its first net's bus toward
    its second's (to a ground symbol for ground), each op-amp to the right with
    its inputs wired left to their buses and its output over it to its bus.
    Crossings carry no dot and join nothing (:meth:`Sheet.connectivity` joins
    only end points).

    Parameters
    ----------
    s : Sheet
        Where to draw.
    board : designer.spice.deck.Board
        Places the op-amps in packages (designators, pins).
    netlist : designer.spice.deck.Netlist
        The circuit.
    origin : tuple of float
        The top left corner.
    inp, out : str
        The input and output nets (labelled ``u`` and ``y``).
    probe : str
        The output's scope tag.

    Returns
    -------
    float
        The lowest y drawn.
    """
    from ..spice.deck import GROUND
    x0, y0 = origin
    order = [inp]
    for p in netlist.parts:
        order += [p.a, p.b]
    for a in netlist.amps:
        order += [a.inp, a.inn, a.out]
    nets = [n for n in dict.fromkeys(order) if n not in (GROUND, out)] + [out]
    col = {n: x0 + 2.0 + BUS_PITCH * i for i, n in enumerate(nets)}
    at = {n: [] for n in nets}
    for n, text in ((inp, "u"), (out, "y")):
        s.net_label((col[n], y0), n, text, loc="top")
        at[n].append(y0)
    s.probe((col[out], y0), probe, 1.0)
    y = y0 - ROW_PITCH
    for p in netlist.parts:
        ends = [n for n in (p.a, p.b) if n != GROUND]
        first = ends[0]
        x = col[first]
        towards = 1.0 if len(ends) == 1 or col[ends[1]] > x else -1.0
        end = (x + towards * PART_LENGTH, y)
        if p.a == first:
            s.part(p, (x, y), end)
        else:
            s.part(p, end, (x, y))
        at[first].append(y)
        if len(ends) == 1:
            s.ground(end)
        else:
            s.wire(end, (col[ends[1]], y))
            at[ends[1]].append(y)
        y -= ROW_PITCH
    x_amp = col[out] + 3.0
    for a in netlist.amps:
        pts = s.opamp(a, board.unit_of(a.ref), board.package.part, (x_amp, y - 1.0), plus_on_top=True)
        for term, net in (("inp", a.inp), ("inn", a.inn)):
            pt = pts[term]
            if net == GROUND:
                s.wire(pt, (pt[0] - 0.5, pt[1]), (pt[0] - 0.5, pt[1] - 0.6))
                s.ground((pt[0] - 0.5, pt[1] - 0.6))
            else:
                s.wire(pt, (col[net], pt[1]))
                at[net].append(pt[1])
        o = pts["out"]
        top = max(pts["inp"][1], pts["inn"][1]) + 0.9
        s.wire(o, (o[0] + 0.6, o[1]), (o[0] + 0.6, top), (col[a.out], top))
        at[a.out].append(top)
        y = min(pts["inp"][1], pts["inn"][1]) - 1.4 - ROW_PITCH
    for n, ys in at.items():
        if len(set(ys)) > 1:
            s.wire((col[n], max(ys)), (col[n], min(ys)))
        for v in ys:
            if min(ys) < v < max(ys):   # a tee: the bus goes on past it
                s.dot((col[n], v))
    return y


#: the plant block's designator on the sheet (its terminals: in, out, gnd)
PLANT_BLOCK = "PLANT"


def draw_plant_block(s: Sheet, model_text: str, origin, probe: str = "CH2") -> float:
    """The plant as a block labelled ``model_text`` on ``s``: net ``u`` at
    ``origin`` into its input, its output to net ``y`` (with the ``probe`` tag),
    its ground terminal below to ground. Returns the lowest y drawn (the ground's)."""
    import schemdraw.elements as elm
    x0, y0 = origin
    # a long G(s) on two lines, split at its fraction bar
    lines = model_text.split(" / ", 1) if len(model_text) > 44 and " / " in model_text else [model_text]
    if len(lines) == 2:
        lines[0] += " /"
    width = max(12.0, 0.4 * max(len(t) for t in lines) + 2.5)
    half = 1.2 + 0.45 * len(lines)
    inp = (x0 + 1.5, y0)
    out = (inp[0] + width, y0)
    gnd = (inp[0] + width / 2, y0 - half)
    s.net_label((x0, y0), "u", "u", loc="left")
    s.wire((x0, y0), inp)
    s.d.add(elm.Rect(corner1=(inp[0], y0 - half), corner2=(out[0], y0 + half), lw=1.3).at((0.0, 0.0)))
    s.text((gnd[0], y0 + half - 0.55), "plant (a model, not on the board)", size=0.8)
    for i, t in enumerate(lines):
        s.text((gnd[0], y0 - 0.2 - 0.9 * i + 0.45 * (len(lines) - 1)), t, size=0.85)
    for term, pt in (("in", inp), ("out", out), ("gnd", gnd)):
        s.pins[(PLANT_BLOCK, term)] = pt
    s.wire(gnd, (gnd[0], gnd[1] - 0.8))
    s.ground((gnd[0], gnd[1] - 0.8))
    y = (out[0] + 2.0, y0)
    s.wire(out, y)
    s.probe(y, probe)
    s.net_label(y, "y", "y")
    return gnd[1] - 0.8


def _draw_controller(s: Sheet, board, probes) -> float:
    """The six controller op-amps of ``board`` on ``s``, from net ``r`` and ``y``
    labels to the ``u`` label; returns the y where the plant goes, below."""
    n = board.netlist
    amps = {a.role: a for a in n.amps}
    P = n.part
    has_d = "differentiator" in amps

    def tag(pt, net, dy=0.7):
        if net in probes:
            s.probe(pt, probes[net], dy)

    # U2 difference amplifier: r through R15 to -in, y through R17 to +in, R18 to ground, R16 feedback
    d = amps["difference"]
    unit = board.unit_of(d.ref)
    pts = s.opamp(d, unit, board.package.part, (3.6, 0.0), plus_on_top=False)
    text = {"ref": "r", "y": "y"}
    s.net_label((0, 1.25), P("R15").a, text[P("R15").a], loc="left")
    tag((0, 1.25), P("R15").a)
    s.part(P("R15"), (0, 1.25), (3.0, 1.25))
    s.wire((3.0, 1.25), pts["inn"])
    s.dot((3.0, 1.25))
    s.net_label((0, 0), P("R17").a, text[P("R17").a], loc="left")
    s.part(P("R17"), (0, 0), (2.4, 0), label_loc="bottom")
    s.wire((2.4, 0), pts["inp"])
    s.dot((2.4, 0))
    s.part(P("R18"), (2.4, 0), (2.4, -2.2), label_loc="bottom")
    s.ground((2.4, -2.2))
    ve = (pts["out"][0] + 0.8, pts["out"][1])
    s.wire((3.0, 1.25), (3.0, 2.8))
    s.part(P("R16"), (3.0, 2.8), (ve[0], 2.8))
    s.wire((ve[0], 2.8), ve, pts["out"])
    s.dot(ve)
    tag(ve, "ve", 0.5)
    # the three branches fed from the ve bus
    x_in = ve[0] + 1.2
    rows = {"inverter": 7.0, "differentiator": 1.25, "integrator": -4.5}
    if not has_d:
        rows = {"inverter": 5.0, "integrator": -2.5}
    s.wire((ve[0], ve[1]), (x_in, ve[1]))
    s.wire((x_in, rows["integrator"]), (x_in, rows["inverter"]))
    s.dot((x_in, ve[1]))
    outs = {}
    common_x = x_in + 5.5 + 3.4 + 0.6
    outs["vp"] = _inverting(s, board, amps["inverter"], [([P("R10")], rows["inverter"])], [P("R9")], x_in,
                            rows["inverter"], common_x)
    s.dot((x_in, rows["inverter"]))
    if has_d:
        outs["vd"] = _inverting(s, board, amps["differentiator"], [([P("R12"), P("C3")], rows["differentiator"])],
                                [P("R11")], x_in, rows["differentiator"], common_x)
    outs["vi"] = _inverting(s, board, amps["integrator"], [([P("R14")], rows["integrator"])],
                            [P("R13"), P("C4")], x_in, rows["integrator"], common_x)
    for net, pt in outs.items():
        tag(pt, net, 0.5)
    # U6 summer: R6, R7, R8 from the branch outputs into one node
    xs = common_x
    summer_in = xs + 3.5
    refs = {"vp": "R6", "vd": "R7", "vi": "R8"}
    for net, pt in outs.items():
        s.part(P(refs[net]), pt, (xs + 3.0, pt[1]))
        s.wire((xs + 3.0, pt[1]), (summer_in, pt[1]))
    ys = [pt[1] for pt in outs.values()]
    s.wire((summer_in, min(ys)), (summer_in, max(ys)))
    row6 = rows.get("differentiator", 1.25) - 0.625 + 0.625
    su = amps["summer"]
    pts = s.opamp(su, board.unit_of(su.ref), board.package.part, (summer_in + 1.4, row6 - 1.25), plus_on_top=False)
    s.wire((summer_in, row6), pts["inn"])
    for pt in outs.values():
        s.dot((summer_in, pt[1])) if pt[1] not in (min(ys), max(ys)) else None
    s.dot((summer_in, row6))
    s.wire(pts["inp"], (pts["inp"][0], pts["inp"][1] - 0.6))
    s.ground((pts["inp"][0], pts["inp"][1] - 0.6))
    node = (summer_in + 0.7, row6)
    vs = (pts["out"][0] + 0.6, pts["out"][1])
    s.wire(node, (node[0], row6 + 2.2))
    s.part(P("R5"), (node[0], row6 + 2.2), (vs[0], row6 + 2.2))
    s.wire((vs[0], row6 + 2.2), vs, pts["out"])
    s.dot(node)
    s.dot(vs)
    tag(vs, "vs", 0.5)
    # U7 final gain
    g = amps["gain"]
    x7 = vs[0]
    pts = s.opamp(g, board.unit_of(g.ref), board.package.part, (x7 + 3.6, vs[1] - 1.25 + 1.25 - 1.25),
                  plus_on_top=False)
    s.part(P("R4"), vs, (x7 + 3.0, vs[1]))
    s.wire((x7 + 3.0, vs[1]), pts["inn"])
    s.dot((x7 + 3.0, vs[1]))
    s.wire(pts["inp"], (pts["inp"][0], pts["inp"][1] - 0.6))
    s.ground((pts["inp"][0], pts["inp"][1] - 0.6))
    u = (pts["out"][0] + 0.6, pts["out"][1])
    s.wire((x7 + 3.0, vs[1]), (x7 + 3.0, vs[1] + 2.2))
    s.part(P("R3"), (x7 + 3.0, vs[1] + 2.2), (u[0], vs[1] + 2.2))
    s.wire((u[0], vs[1] + 2.2), u, pts["out"])
    s.dot(u)
    tag(u, "u", 0.5)
    s.net_label(u, "u", "u")
    return min(rows.values()) - 6.5
