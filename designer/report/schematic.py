"""Schematic drawing helpers over schemdraw, with the connectivity of what is
drawn kept alongside: every part's terminals, every wire, and every ground,
supply and net label are recorded as they are placed, so that the drawing can
be checked against the deck it claims to show (:meth:`Sheet.connectivity`,
the check SOFIA does) and not only looked at.

Parts are labelled with their designator and value code (``R1`` / ``1k6``),
op-amps with their package designator, part number and pin numbers, probe
points with the scope channel. The circuits themselves are laid out by the
wings (:mod:`designer.plant.schematic`, :mod:`designer.pid.schematic`), from
the part and net table the netlist is written from.
"""

from __future__ import annotations

from ..core.units import value_code

__all__ = ["Sheet", "check_connectivity"]

#: coordinates are compared on this grid (schemdraw works in floats)
_GRID = 1e-6


def _key(pt) -> tuple:
    return (round(float(pt[0]) / _GRID), round(float(pt[1]) / _GRID))


class Sheet:
    """A schemdraw drawing plus what is connected to what in it.

    Parameters
    ----------
    fontsize : float
        Label size (points) for the whole drawing.
    """

    def __init__(self, fontsize: float = 11, unit: float = 2.5):
        import schemdraw
        self.d = schemdraw.Drawing(show=False, canvas="svg")
        self.d.config(fontsize=fontsize, unit=unit, lw=1.1)
        self.fontsize = fontsize
        self.segments = []          # wires: (point, point)
        self.pins = {}              # (designator, terminal) -> point
        self.marks = []             # (point, net name): ground, supplies, labels

    # ---- placing ---------------------------------------------------------------------------
    def part(self, p, start, end, label_loc: str = "top", name: str | None = None):
        """A resistor or capacitor ``p`` (``ref``, ``kind``, ``value``) from ``start``
        to ``end``; terminal ``a`` at ``start``, ``b`` at ``end``."""
        import schemdraw.elements as elm
        kind = elm.Resistor if p.kind == "R" else elm.Capacitor
        text = f"{name or p.ref}\n{value_code(p.value)}"
        e = self.d.add(kind().at(start).to(end).label(text, loc=label_loc, fontsize=self.fontsize * 0.9))
        self.pins[(p.ref, "a")], self.pins[(p.ref, "b")] = tuple(start), tuple(end)
        return e

    def opamp(self, amp, unit, part_name: str, at, plus_on_top: bool = True):
        """Op-amp ``amp`` (its deck designator ``ref``) drawn as package unit ``unit``
        (designator and pins), with its + input at ``at`` (on top, or below).
        Returns the anchor points {inp, inn, out}."""
        import schemdraw.elements as elm
        e = self.d.add(elm.Opamp(leads=True, flip=plus_on_top).right().anchor("in2").at(at)
                       .label(f"{unit.designator}\n{part_name}", loc="center", ofst=(0.15, 0),
                              fontsize=self.fontsize * 0.8))
        pts = {"inp": tuple(e.absanchors["in2"]), "inn": tuple(e.absanchors["in1"]),
               "out": tuple(e.absanchors["out"])}
        for term, pt in pts.items():
            self.pins[(amp.ref, term)] = pt
            pin = unit.pins[term]
            dx, dy = (0.25, 0.28) if term == "out" else (-0.3, 0.28 if (term == "inp") == plus_on_top else -0.32)
            self.text((pt[0] + dx, pt[1] + dy), str(pin), size=0.75)
        return pts

    def text(self, at, s: str, size: float = 1.0, halign: str = "center", color: str = "black"):
        import schemdraw.elements as elm
        self.d.add(elm.Label().right().at(at).label(s, fontsize=self.fontsize * size, halign=halign, color=color))

    def wire(self, *points):
        """Straight wires through ``points`` in order (give the corners)."""
        import schemdraw.elements as elm
        for a, b in zip(points, points[1:]):
            if _key(a) != _key(b):
                self.d.add(elm.Line().at(a).to(b))
                self.segments.append((tuple(a), tuple(b)))

    def dot(self, at):
        import schemdraw.elements as elm
        self.d.add(elm.Dot().at(at))

    def ground(self, at):
        import schemdraw.elements as elm
        self.d.add(elm.Ground().right().at(at))
        self.marks.append((tuple(at), "0"))

    def supply(self, at, net: str, text: str, up: bool = True):
        """A supply rail symbol (``vcc`` up, ``vee`` down) labelled ``text``."""
        import schemdraw.elements as elm
        self.d.add(elm.Vdd().right().at(at).label(text, fontsize=self.fontsize * 0.75))
        self.marks.append((tuple(at), net))

    def net_label(self, at, net: str, text: str, loc: str = "right"):
        """A named net: every label of the same net is one net (instead of a long wire)."""
        import schemdraw.elements as elm
        self.d.add(elm.Dot(open=True).right().at(at))
        ofs = {"right": (0.2, 0), "left": (-0.2, 0), "top": (0, 0.3), "bottom": (0, -0.35)}[loc]
        self.text((at[0] + ofs[0], at[1] + ofs[1]), text, size=0.9,
                  halign={"right": "left", "left": "right"}.get(loc, "center"))
        self.marks.append((tuple(at), net))

    def probe(self, at, text: str, dy: float = 0.7):
        """A scope probe point: a filled dot and the channel's tag above it."""
        import schemdraw.elements as elm
        self.d.add(elm.Dot().at(at))
        self.d.add(elm.Line().at(at).to((at[0], at[1] + dy)).color("#b00").linestyle(":"))
        self.text((at[0], at[1] + dy + 0.25), text, size=0.85, color="#b00")

    # ---- what is connected -----------------------------------------------------------------
    def connectivity(self) -> tuple:
        """(nets, named): ``nets`` maps every recorded terminal (designator, terminal)
        to a net id of the drawing (terminals on one id are joined by wires, or by
        labels of the same name); ``named`` maps a net id to the names of the
        ground, supply and net labels on it."""
        points = {}
        for pt in list(self.pins.values()) + [m[0] for m in self.marks] + [p for s in self.segments for p in s]:
            points[_key(pt)] = pt
        parent = {k: k for k in points}

        def find(k):
            while parent[k] != k:
                parent[k] = parent[parent[k]]
                k = parent[k]
            return k

        def union(a, b):
            parent[find(a)] = find(b)

        for a, b in self.segments:
            on = [k for k, p in points.items() if _on_segment(p, a, b)]
            for k in on[1:]:
                union(on[0], k)
        by_name = {}
        for pt, net in self.marks:
            k = _key(pt)
            if net in by_name:
                union(by_name[net], k)
            else:
                by_name[net] = k
        nets = {term: find(_key(pt)) for term, pt in self.pins.items()}
        named = {}
        for pt, net in self.marks:
            named.setdefault(find(_key(pt)), set()).add(net)
        return nets, named

    # ---- output ------------------------------------------------------------------------------
    def svg(self) -> str:
        """The drawing as SVG text (for inline HTML)."""
        self.d.draw(show=False, canvas="svg")
        return self.d.get_imagedata("svg").decode("utf-8")

    def png(self, dpi: int = 100, inches_per_unit: float | None = None) -> bytes:
        """The drawing as PNG bytes (beside the Markdown sheet), through matplotlib;
        ``inches_per_unit``: the picture sized to the drawing (None: matplotlib's default figure)."""
        import io

        import matplotlib
        matplotlib.use("Agg")   # schemdraw draws through pyplot: a file, never a GUI window
        fig = self.d.draw(show=False, canvas="matplotlib")
        if inches_per_unit is not None:
            bb = self.d.get_bbox()
            fig.fig.set_size_inches((bb.xmax - bb.xmin + 1) * inches_per_unit,
                                    (bb.ymax - bb.ymin + 1) * inches_per_unit)
        buf = io.BytesIO()
        fig.fig.savefig(buf, format="png", dpi=dpi)
        import sys
        if "matplotlib.pyplot" in sys.modules:
            sys.modules["matplotlib.pyplot"].close(fig.fig)
        return buf.getvalue()


def _on_segment(p, a, b, tol: float = 1e-6) -> bool:
    """Whether point ``p`` lies on the segment from ``a`` to ``b``."""
    (px, py), (ax, ay), (bx, by) = p, a, b
    cross = (bx - ax) * (py - ay) - (by - ay) * (px - ax)
    if abs(cross) > tol * max(1.0, abs(bx - ax) + abs(by - ay)):
        return False
    return (min(ax, bx) - tol <= px <= max(ax, bx) + tol) and (min(ay, by) - tol <= py <= max(ay, by) + tol)


def check_connectivity(sheet: Sheet, terminals: dict) -> list:
    """Where the drawing disagrees with the deck: ``terminals`` maps (designator,
    terminal) -> the deck's net. Every drawn terminal must land on a drawing net
    that holds exactly the terminals of one deck net, and every label on it must
    name that net. Returns the disagreements (empty: the drawing is the deck).

    Parameters
    ----------
    sheet : Sheet
        The drawing.
    terminals : dict
        (designator, terminal) -> the deck's net.

    Returns
    -------
    list of str
        The disagreements.
    """
    nets, named = sheet.connectivity()
    problems = []
    deck_to_drawn, drawn_to_deck = {}, {}
    for term, drawn in nets.items():
        if term not in terminals:
            problems.append(f"{term[0]} {term[1]} is drawn but not in the deck")
            continue
        net = terminals[term]
        deck_to_drawn.setdefault(net, set()).add(drawn)
        drawn_to_deck.setdefault(drawn, set()).add(net)
    for net, drawn in deck_to_drawn.items():
        if len(drawn) > 1:
            problems.append(f"deck net {net} is drawn as {len(drawn)} separate nets")
    for drawn, decks in drawn_to_deck.items():
        if len(decks) > 1:
            problems.append(f"the drawing joins deck nets {', '.join(sorted(decks))}")
        for name in named.get(drawn, ()):
            if name not in decks:
                problems.append(f"a label {name!r} sits on deck net {', '.join(sorted(decks))}")
    return problems
