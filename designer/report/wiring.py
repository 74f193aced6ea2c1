"""What a student needs to buy and to wire, from a circuit's part and net table
as built on the bench (a :class:`designer.spice.deck.Board`, read here by its
fields): the bill of materials (grouped by value, as a parts order wants it; as
a sheet table and as ``bom.csv``) and the pin-level wiring table.

The seed built its controller on breadboards and lost time to bad contacts
(001, end of section V.13): the wiring table lists every connection by pin, so
that each can be checked with a meter.
"""

from __future__ import annotations

import csv
import io

from ..core.i18n import N_
from ..core.i18n import gettext as _
from ..core.units import format_eng, value_code

__all__ = ["BOM_HEADER", "CATALOGUE_WORDS", "bench_rows", "bom_csv", "bom_rows", "net_text", "wiring_rows"]

#: bill of materials columns (bom.csv and the sheet)
BOM_HEADER = ("Ref", "Value", "Code", "Qty", "Series", "Tolerance", "Package", "Description")
#: the words of the op-amp catalogue (designer/core/data/opamps.json) a sheet shows: the packages' names and the
#: notes of the pins left open; translated where they are shown (bom.csv keeps them as the catalogue has them)
CATALOGUE_WORDS = (N_("DIP-8 single"), N_("DIP-8 dual"), N_("DIP-14 quad"), N_("offset null (leave open)"),
                   N_("not connected"))


def _package_of(part) -> str:
    if part.kind == "R":
        return _("axial, 0.25 W metal film")
    if part.value >= 1e-6:
        return _("radial electrolytic, 35 V")
    if part.role.startswith("U") and "pin" in part.role:
        return _("ceramic X7R, 5 mm pitch")
    return _("film or C0G ceramic, 5 mm pitch")


def bom_rows(board, source_of, opamp_name: str) -> list:
    """Bill of materials rows (:data:`BOM_HEADER`), parts of one value, series and
    package grouped on one row; ``source_of(ref)`` gives (series, tolerance in
    percent), or None where the part is not from an E-series (decoupling).

    Parameters
    ----------
    board : designer.spice.deck.Board
        The bench build.
    source_of : callable
        ``source_of(ref)`` -> (series, tolerance in percent) or None.
    opamp_name : str
        The op-amp's name.

    Returns
    -------
    list
        The rows.
    """
    groups, order = {}, []
    for p in board.parts():
        src = source_of(p.ref)
        series, tol = src if src is not None else ("", None)
        if src is None:   # decoupling: any 20 % part of that value
            series, tol = "E6", 20.0
        key = (p.kind, p.value, series, tol, _package_of(p))
        if key not in groups:
            groups[key] = []
            order.append(key)
        groups[key].append(p)
    rows = []
    for key in order:
        ps = groups[key]
        kind, value, series, tol, pkg = key
        roles = [p.role for p in ps]
        desc = _(roles[0]) if len(ps) == 1 else (_("decoupling, at the supply pins") if ps[0].ref[1:2] in "123456789"
                                                and len(ps[0].ref) == 4 else "; ".join(f"{p.ref}: {_(p.role)}"
                                                                                      for p in ps))
        rows.append([", ".join(p.ref for p in ps), format_eng(value, ps[0].unit, 4), value_code(value), len(ps),
                     series, "" if tol is None else f"{tol:g} %", pkg, desc])
    pkg = board.package
    what = ", ".join(f"{u.designator} {_(a.role)}" for a, u in zip(board.netlist.amps, board.units))
    spare = [u.designator for u in board.spares]
    rows.append([", ".join(board.ics), pkg.part, "", len(board.ics), "", "", pkg.pinout,
                 _("{opamp} op-amps: {what}").format(opamp=opamp_name, what=what)
                 + (_("; spare {units} tied off").format(units=", ".join(spare)) if spare else "")])
    return rows


def bom_csv(rows) -> str:
    """``bom.csv``: the bill of materials, one header row, comma separated.

    Parameters
    ----------
    rows : list
        The bill of materials' rows (:func:`bom_rows`).

    Returns
    -------
    str
        The CSV text.
    """
    buf = io.StringIO()
    w = csv.writer(buf, lineterminator="\n")
    w.writerow(BOM_HEADER)
    w.writerows(rows)
    return buf.getvalue()


#: pin roles as the wiring table names them
PIN_NAMES = {"inp": "+in", "inn": "-in", "out": "out"}


def _pins_on(board, net) -> list:
    out = []
    for a, u in zip(board.netlist.amps, board.units):
        for term, name in PIN_NAMES.items():
            if getattr(a, term) == net:
                out.append(_pin(u, term))
    return out


def _pin(u, term) -> str:
    """An op-amp unit's pin: ``U1A pin 1 (out)``."""
    return _("{unit} pin {pin} ({name})").format(unit=u.designator, pin=u.pins[term], name=PIN_NAMES[term])


def net_text(board, net, labels: dict) -> str:
    """A net as the wiring table names it: its label, and the op-amp pins on it by number.

    Parameters
    ----------
    board : designer.spice.deck.Board
        The bench build.
    net : str
        The deck's net.
    labels : dict
        Net -> what to call it.

    Returns
    -------
    str
        The text.
    """
    pins = _pins_on(board, net)
    label = labels.get(net)
    label = _(label) if label else label
    if pins:
        return (f"{label}: " if label else "") + ", ".join(pins)
    return label or _("node {net}").format(net=net)


def wiring_rows(board, labels: dict, supplies: tuple) -> list:
    """The pin-level wiring table: one row per part (from its first terminal's
    net to its second's, each with the op-amp pins it meets), then the wires
    between op-amp pins that no part joins (a follower's output to its -in),
    the supply pins of every package with their decoupling, the spare units'
    tie-off, and the pins left open. ``labels``: net -> what to call it;
    ``supplies``: (V+, V-) volts.

    Parameters
    ----------
    board : designer.spice.deck.Board
        The bench build.
    labels : dict
        Net -> what to call it.
    supplies : tuple
        (V+, V-) volts.

    Returns
    -------
    list
        The rows.
    """
    rows = [[p.ref, value_code(p.value), net_text(board, p.a, labels), net_text(board, p.b, labels)]
            for p in board.netlist.parts]
    for a, u in zip(board.netlist.amps, board.units):
        if a.inn == a.out:
            rows.append([_("wire"), "", _pin(u, "out"), _pin(u, "inn") + _(": follower")])
        if a.inp == "0":
            rows.append([_("wire"), "", _pin(u, "inp"), _("ground")])
    pkg = board.package
    vcc, vee = supplies
    # the decoupling as the board names it: two per package in package order, then the two bulk ones
    dec = board.decoupling
    for i, ic in enumerate(board.ics):
        opened = (_("; pins {pins} open ({what})").format(pins=", ".join(str(k) for k in pkg.unused),
                                                          what=", ".join(sorted({_(v) for v in pkg.unused.values()})))
                  if pkg.unused else "")
        supply = _("pin {pin} ({rail}): {v} V, {cap} 100n to ground at the pin")
        rows.append([ic, pkg.part, supply.format(pin=pkg.vcc, rail="V+", v=f"{vcc:+g}", cap=dec[2 * i].ref),
                     supply.format(pin=pkg.vee, rail="V-", v=f"{vee:+g}", cap=dec[2 * i + 1].ref) + opened])
    for u in board.spares:
        rows.append([_("wire"), "", _pin(u, "inp"), _("ground (spare unit)")])
        rows.append([_("wire"), "", _pin(u, "out"),
                     _pin(u, "inn") + _(": spare as a follower, so it cannot oscillate")])
    rows.append([_("wire"), "", _("supply 0 V, generator ground, scope grounds"), _("ground (one star point)")])
    rows.append([f"{dec[-2].ref}, {dec[-1].ref}", "10u",
                 _("{vcc} V and {vee} V where the supply enters").format(vcc=f"{vcc:+g}", vee=f"{vee:+g}"),
                 _("ground (mind the polarity)")])
    return rows


def bench_rows(test, scope, into: str, channels=None) -> list:
    """The generator and scope settings as (set, to) rows: the square wave (``test``:
    frequency, amplitude, offset) into ``into``, the time base, the trigger and the
    scope's channels (``scope``: a :class:`designer.plant.bench.ScopeSetup`, read by
    its fields; ``channels``: how many of its channels, default all).

    Parameters
    ----------
    test : designer.spice.deck.SquareTest
        The square wave.
    scope : designer.plant.bench.ScopeSetup
        The scope's settings.
    into : str
        Where the generator connects.
    channels : int, optional
        How many of the scope's channels.

    Returns
    -------
    list
        (set, to) rows.
    """
    a = test.amplitude_v
    rows = [[_("generator"), _("square {f}, {a} pk-pk, offset {offset} (0 to {a}), into {into}").format(
        f=format_eng(test.frequency_hz, 'Hz'), a=format_eng(a, 'V'), offset=format_eng(a / 2, 'V'), into=_(into))]]
    if scope is None:
        return rows
    rows += [[_("time base"), _("{t}/div, edge {div} div from the left").format(
                 t=format_eng(scope.time_per_div_s, 's'), div=f"{scope.edge_div:g}")],
             [_("trigger"), _("CH1 rising, {v}").format(v=format_eng(scope.trigger_v, 'V'))]]
    for c in scope.channels[:channels]:
        rows.append([c.name, _("{v}/div DC, 0 V {div} div below centre: {node}").format(
            v=format_eng(c.volts_per_div, 'V'), div=f"{c.zero_div_below_centre:g}", node=_(c.node))])
    return rows

