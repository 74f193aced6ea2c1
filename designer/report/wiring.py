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

from ..core.units import format_eng, value_code

__all__ = ["BOM_HEADER", "bench_rows", "bom_csv", "bom_rows", "net_text", "wiring_rows"]

#: bill of materials columns (bom.csv and the sheet)
BOM_HEADER = ("Ref", "Value", "Code", "Qty", "Series", "Tolerance", "Package", "Description")


def _package_of(part) -> str:
    if part.kind == "R":
        return "axial, 0.25 W metal film"
    if part.value >= 1e-6:
        return "radial electrolytic, 35 V"
    if part.role.startswith("U") and "pin" in part.role:
        return "ceramic X7R, 5 mm pitch"
    return "film or C0G ceramic, 5 mm pitch"


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
        desc = roles[0] if len(ps) == 1 else ("decoupling, at the supply pins" if ps[0].ref[1:2] in "123456789"
                                             and len(ps[0].ref) == 4 else "; ".join(f"{p.ref}: {p.role}"
                                                                                   for p in ps))
        rows.append([", ".join(p.ref for p in ps), format_eng(value, ps[0].unit, 4), value_code(value), len(ps),
                     series, "" if tol is None else f"{tol:g} %", pkg, desc])
    pkg = board.package
    what = ", ".join(f"{u.designator} {a.role}" for a, u in zip(board.netlist.amps, board.units))
    spare = [u.designator for u in board.spares]
    rows.append([", ".join(board.ics), pkg.part, "", len(board.ics), "", "", pkg.pinout,
                 f"{opamp_name} op-amps: {what}" + (f"; spare {', '.join(spare)} tied off" if spare else "")])
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
                out.append(f"{u.designator} pin {u.pins[term]} ({name})")
    return out


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
    if pins:
        return (f"{label}: " if label else "") + ", ".join(pins)
    return label or f"node {net}"


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
            rows.append(["wire", "", f"{u.designator} pin {u.pins['out']} (out)",
                         f"{u.designator} pin {u.pins['inn']} (-in): follower"])
        if a.inp == "0":
            rows.append(["wire", "", f"{u.designator} pin {u.pins['inp']} (+in)", "ground"])
    pkg = board.package
    vcc, vee = supplies
    # the decoupling as the board names it: two per package in package order, then the two bulk ones
    dec = board.decoupling
    for i, ic in enumerate(board.ics):
        opened = (f"; pins {', '.join(str(k) for k in pkg.unused)} open ({', '.join(sorted(set(pkg.unused.values())))})"
                  if pkg.unused else "")
        rows.append([ic, pkg.part, f"pin {pkg.vcc} (V+): {vcc:+g} V, {dec[2 * i].ref} 100n to ground at the pin",
                     f"pin {pkg.vee} (V-): {vee:+g} V, {dec[2 * i + 1].ref} 100n to ground at the pin" + opened])
    for u in board.spares:
        rows.append(["wire", "", f"{u.designator} pin {u.pins['inp']} (+in)", "ground (spare unit)"])
        rows.append(["wire", "", f"{u.designator} pin {u.pins['out']} (out)",
                     f"{u.designator} pin {u.pins['inn']} (-in): spare as a follower, so it cannot oscillate"])
    rows.append(["wire", "", "supply 0 V, generator ground, scope grounds", "ground (one star point)"])
    rows.append([f"{dec[-2].ref}, {dec[-1].ref}", "10u", f"{vcc:+g} V and {vee:+g} V where the supply enters",
                 "ground (mind the polarity)"])
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
    rows = [["generator", f"square {format_eng(test.frequency_hz, 'Hz')}, {format_eng(a, 'V')} pk-pk, offset "
                          f"{format_eng(a / 2, 'V')} (0 to {format_eng(a, 'V')}), into {into}"]]
    if scope is None:
        return rows
    rows += [["time base", f"{format_eng(scope.time_per_div_s, 's')}/div, edge {scope.edge_div:g} div from the left"],
             ["trigger", f"CH1 rising, {format_eng(scope.trigger_v, 'V')}"]]
    for c in scope.channels[:channels]:
        rows.append([c.name, f"{format_eng(c.volts_per_div, 'V')}/div DC, 0 V {c.zero_div_below_centre:g} div "
                             f"below centre: {c.node}"])
    return rows

