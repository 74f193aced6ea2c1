"""The plant's schematic (seed 001, Figures 43-45: the unity-gain Sallen-Key
low-pass, with the gain resistors of its general form when K > 1), drawn from
the part and net table the deck is written from
(:func:`designer.plant.netlist.plant_netlist` as built on the bench,
:func:`designer.spice.deck.board`): every value, designator, pin number and net
comes from that table, the layout alone is written here.
"""

from __future__ import annotations

from ..filters.sallen_key_lowpass_parts import section_of
from ..report.schematic import Sheet

__all__ = ["draw_plant", "draw_supplies"]

#: the scope probes of the plant's bench test (seed IV.9: input on CH1, output on CH2)
PROBES = {"input": "CH1", "out": "CH2"}


def draw_plant(board, opamp, sheet: Sheet | None = None, origin=(0.0, 0.0), inp_label: str = "generator",
               probes: dict = PROBES, supplies: bool = True, ref_prefix: str = "") -> Sheet:
    """The Sallen-Key plant of ``board`` (a :class:`~designer.spice.deck.Board`
    whose netlist is :func:`~designer.plant.netlist.plant_netlist`'s) on
    ``sheet`` (a new one by default) at ``origin``; its input net is labelled
    ``inp_label`` and the ``probes`` nets get scope tags. With ``supplies``, the
    decoupling of every package is drawn too.

    Parameters
    ----------
    board : designer.spice.deck.Board
        The bench build.
    opamp : designer.core.opamps.OpAmp
        The op-amp.
    sheet : Sheet, optional
        The sheet drawn on; None: a new one.
    origin : tuple of float
        Where the plant starts.
    inp_label : str
        What drives the input.
    probes : dict
        Net -> the scope channel on it.
    supplies : bool
        Draw the supplies.
    ref_prefix : str
        The plant's designator prefix on a shared sheet (:func:`~designer.plant.netlist.plant_netlist`).

    Returns
    -------
    Sheet
        The sheet.
    """
    s = sheet or Sheet()
    n = board.netlist
    amp = n.amps[0]
    unit = board.unit_of(amp.ref)
    x0, y0 = origin
    section = section_of(with_gain=amp.inn != amp.out)
    # the section's parts in its declared order: the network (input R, R to +in, C to ground, feedback C),
    # then the gain pair (to ground, feedback)
    r_in, r_pos, c_gnd, c_fb, *gain = (n.part(section.prefixed(r, ref_prefix)) for r in section.designators)
    pin = (x0, y0)
    a = (x0 + 3.0, y0)
    b = (x0 + 6.0, y0)
    s.net_label(pin, r_in.a, inp_label, loc="left")
    if r_in.a in probes:
        s.probe(pin, probes[r_in.a])
    s.part(r_in, pin, a)
    s.part(r_pos, a, b)
    s.dot(a)
    pts = s.opamp(amp, unit, board.package.part, (b[0] + 1.8, b[1]), plus_on_top=True)
    s.wire(b, pts["inp"])
    s.dot(b)
    gnd1 = (b[0], b[1] - 2.5)
    s.part(c_gnd, b, gnd1, label_loc="top")
    s.ground(gnd1)
    out = pts["out"]
    o = (out[0] + 1.0, out[1])
    s.wire(out, o)
    top = a[1] + 2.2
    s.wire(a, (a[0], top))
    s.part(c_fb, (a[0], top), (o[0], top))
    s.wire((o[0], top), o)
    s.dot(o)
    if amp.out in probes:
        s.probe((o[0] + 0.8, o[1]), probes[amp.out])
    s.wire(o, (o[0] + 0.8, o[1]))
    s.net_label((o[0] + 0.8, o[1]), amp.out, "out" if amp.out == "out" else amp.out)
    inn = pts["inn"]
    low = inn[1] - 1.2
    if amp.inn == amp.out:      # follower: output back to the inverting input
        s.wire(inn, (inn[0] - 0.5, inn[1]), (inn[0] - 0.5, low), (o[0], low), o)
    else:
        to_ground, feedback = gain
        k = (inn[0] - 0.5, low)
        s.wire(inn, (inn[0] - 0.5, inn[1]), k)
        s.part(feedback, (o[0], low), k, label_loc="bottom")
        s.wire(o, (o[0], low))
        s.dot(k)
        g = (k[0], k[1] - 2.5)
        s.part(to_ground, k, g, label_loc="bottom")
        s.ground(g)
    if supplies:
        draw_supplies(s, board, opamp, (x0 + 1.0, y0 - 8.2 if amp.inn != amp.out else y0 - 5.6))
    return s


def draw_supplies(s: Sheet, board, opamp, at, per_row: int = 16) -> None:
    """Every package's supply pins with their 100n ceramics, and the bulk capacitors
    at the supply entry, in rows of ``per_row`` capacitors starting at ``at``.

    Parameters
    ----------
    s : Sheet
        The sheet.
    board : designer.spice.deck.Board
        The bench build.
    opamp : designer.core.opamps.OpAmp
        The op-amp.
    at : tuple of float
        Where they are drawn.
    per_row : int
        Parts per row.
    """
    x0, y = at
    vcc, vee = f"{opamp.vcc:+g}V", f"{opamp.vee:+g}V"
    dec = {p.ref: p for p in board.decoupling}
    pkg = board.package
    cols = []
    for ic in board.ics:
        n = ic[1:]
        cols += [(dec[f"C{n}01"], "vcc", f"{vcc} {ic}.{pkg.vcc}"), (dec[f"C{n}02"], "vee", f"{vee} {ic}.{pkg.vee}")]
    cols += [(dec["C901"], "vcc", f"{vcc} in"), (dec["C902"], "vee", f"{vee} in")]
    x = x0
    for i, (c, net, text) in enumerate(cols):
        if i and i % per_row == 0:
            x, y = x0, y - 3.6
        top, bottom = (x, y + 1.6), (x, y)
        s.supply(top, net, text)
        s.part(c, top, bottom, label_loc="bottom") if c.a == net else s.part(c, bottom, top, label_loc="bottom")
        s.ground(bottom)
        x += 2.6
