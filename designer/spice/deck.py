"""The parts every ngspice deck is built from, with PySpice's Circuit API:
the part and net table of a circuit (:class:`Netlist`: every resistor,
capacitor and op-amp with its designator and the nets of its terminals, the one
description that the deck, the schematic, the wiring table and the bill of
materials are all written from), the square-wave bench test
(:class:`SquareTest`, its PULSE source and the time step that resolves the
response), op-amp instances and supplies from the project's behavioural model
library, ``.meas`` lines for the step metrics, the closing ``.tran``, and the
``.ac`` deck of the sine check.

Decks are standalone: the models are inlined, so ``ngspice -b deck.cir`` alone
prints overshoot, peak time, rise time and settling time.
"""

from __future__ import annotations

from dataclasses import dataclass

from ..core.errors import ParamError
from ..core.i18n import N_
from ..core.opamps import OpAmp
from ..core.units import format_eng
from .library import library_text

__all__ = ["SINE_POINTS_PER_DECADE", "Amp", "Board", "GROUND", "MAX_SIM_POINTS", "Netlist", "Part", "STEPS_PER_TIME_SCALE", "SquareTest",
           "ac_lines", "add_supplies", "board", "bench_circuit", "finish_deck", "measure_lines", "opamp_library_text",
           "settle_error_source"]

#: the simulation's maximum step is at most this fraction of the response's time scale
STEPS_PER_TIME_SCALE = 50
#: a bench period needing more simulation steps than this is refused (minutes of ngspice, GBs of data)
MAX_SIM_POINTS = 2_000_000


#: the ground net's name in a :class:`Netlist` (SPICE's node 0)
GROUND = "0"


@dataclass(frozen=True)
class Part:
    """One resistor or capacitor: designator (``R1``, ``C3``: its first letter is
    its kind), the nets of its two terminals, its value (ohm or farad) and its role."""

    ref: str
    a: str
    b: str
    value: float
    role: str = ""

    @property
    def kind(self) -> str:
        return self.ref[0]

    @property
    def unit(self) -> str:
        return "Ohm" if self.kind == "R" else "F"


@dataclass(frozen=True)
class Amp:
    """One op-amp of the circuit: its name in the deck (``U1``..: the designator
    with one op-amp per package; :func:`designer.core.opamps.assign` gives the
    package designators), its role and the nets of its inputs and output."""

    ref: str
    role: str
    inp: str
    inn: str
    out: str

    def nets(self) -> dict:
        return {"inp": self.inp, "inn": self.inn, "out": self.out, "vcc": "vcc", "vee": "vee"}


@dataclass(frozen=True)
class Netlist:
    """A circuit as parts and op-amps on named nets (ground is :data:`GROUND`,
    supplies ``vcc`` and ``vee``), in the order the sheet lists them."""

    parts: tuple
    amps: tuple

    def part(self, ref: str) -> Part:
        for p in self.parts:
            if p.ref == ref:
                return p
        raise KeyError(ref)

    def terminals(self) -> dict:
        """(designator, terminal) -> net, for every part (``a``, ``b``) and op-amp
        (``inp``, ``inn``, ``out``, ``vcc``, ``vee``)."""
        out = {}
        for p in self.parts:
            out[(p.ref, "a")], out[(p.ref, "b")] = p.a, p.b
        for a in self.amps:
            out.update({(a.ref, k): v for k, v in a.nets().items()})
        return out

    def add_to(self, circuit, opamp: OpAmp) -> None:
        """Every part and op-amp into a PySpice circuit (element names are the designators)."""
        node = lambda n: circuit.gnd if n == GROUND else n  # noqa: E731
        for p in self.parts:
            getattr(circuit, p.kind)(p.ref[1:], node(p.a), node(p.b), f"{p.value:.6g}")
        for a in self.amps:
            add_opamp(circuit, a.ref, node(a.inp), node(a.inn), a.out, opamp)


#: decoupling on the bench: one ceramic per supply pin of every package, one bulk capacitor per rail
DECOUPLING_F, BULK_F = 100e-9, 10e-6


@dataclass(frozen=True)
class Board:
    """A :class:`Netlist` as built on the bench: its op-amps placed in packages
    (``units``, one :class:`~designer.core.opamps.Unit` per op-amp, in order),
    the spare units of the last package (tied off as followers), and the
    decoupling the deck leaves out (ideal supplies): a ``100n`` from each
    package's V+ and V- pin to ground (C101/C102 for U1, C201/C202 for U2 ...)
    and a ``10u`` per rail where the supply enters (C901, C902)."""

    netlist: Netlist
    units: tuple
    spares: tuple
    decoupling: tuple
    package: object

    def unit_of(self, amp_ref: str):
        """The package unit of the deck's op-amp ``amp_ref``."""
        for a, u in zip(self.netlist.amps, self.units):
            if a.ref == amp_ref:
                return u
        raise KeyError(amp_ref)

    @property
    def ics(self) -> list:
        """Package designators (U1, U2, ...) in order."""
        return sorted({u.ic_ref for u in self.units}, key=lambda r: int(r[1:]))

    def parts(self) -> tuple:
        """Every two-terminal part on the board: the circuit's, then the decoupling."""
        return self.netlist.parts + self.decoupling


def board(netlist: Netlist, opamp: OpAmp, package: str | None = None, decoupling_digit: str = "0") -> Board:
    """The bench build of ``netlist`` with ``opamp`` in ``package`` (``single``,
    ``dual``, ``quad``; None: the op-amp's default). A kind the op-amp does not
    come in is a :class:`~designer.core.errors.DesignError` (one line).
    ``decoupling_digit`` is the decoupling designators' middle digit (``"0"``:
    C101, C102 .. C901, C902): a filter cascade names its stages' parts C101,
    C201 .. and takes ``"9"`` (C191, C192 .., the bulk pair C9991, C9992).

    Parameters
    ----------
    netlist : Netlist
        The circuit's parts and op-amps.
    opamp : designer.core.opamps.OpAmp
        The op-amp built with.
    package : str or None
        ``single``, ``dual`` or ``quad``; None: the op-amp's default.
    decoupling_digit : str
        The decoupling designators' middle digit.

    Returns
    -------
    Board
        The op-amps assigned to packages, with their decoupling and bulk capacitors.
    """
    from ..core.opamps import assign, spare_units
    pkg = opamp.package(package)
    d = decoupling_digit
    units = assign(len(netlist.amps), pkg)
    ics = sorted({u.ic for u in units})
    dec = []
    for ic in ics:
        dec += [Part(f"C{ic}{d}1", "vcc", GROUND, DECOUPLING_F, f"U{ic} V+ (pin {pkg.vcc}) to ground, at the pin"),
                Part(f"C{ic}{d}2", "vee", GROUND, DECOUPLING_F, f"U{ic} V- (pin {pkg.vee}) to ground, at the pin")]
    # the bulk pair: C901, C902; with another digit C99d1, C99d2, clear of package 9's pair (C9d1)
    bulk = "C90" if d == "0" else f"C99{d}"
    dec += [Part(f"{bulk}1", "vcc", GROUND, BULK_F, N_("+supply entry to ground (bulk, + to the rail)")),
            Part(f"{bulk}2", GROUND, "vee", BULK_F, N_("-supply entry to ground (bulk, + to ground)"))]
    return Board(netlist, tuple(units), tuple(spare_units(len(units), pkg)), tuple(dec), pkg)


@dataclass(frozen=True)
class SquareTest:
    """The bench test: a 0 -> ``amplitude_v`` square wave (a function generator
    with offset amplitude/2), as the seed's 330 Hz test. One period is
    simulated: the rising step at ``delay_s``, the falling one half a period later.

    ``time_scale_s`` is the fastest time the response must be resolved at (1/wn
    of the plant): the simulation's maximum step and the edges stay well below it
    whatever the square-wave frequency, so that a slow square wave cannot hide
    the response between two time steps."""

    amplitude_v: float
    frequency_hz: float
    delay_s: float
    edge_time_s: float | None = None  #: rise/fall time of the edges (default: fast against everything)
    time_scale_s: float | None = None

    @property
    def half_period_s(self) -> float:
        return 0.5 / self.frequency_hz

    @property
    def edge_s(self) -> float:
        if self.edge_time_s is not None:
            return self.edge_time_s
        # fast against the response, but not a zero-time discontinuity for the solver
        edge = self.half_period_s * 1e-5
        return edge if self.time_scale_s is None else min(edge, self.time_scale_s / 100)

    @property
    def stop_s(self) -> float:
        return self.delay_s + 2 * self.half_period_s

    def max_step_s(self, points: int = 20000) -> float:
        """The simulation's maximum time step: a period / ``points``, and at most
        1/:data:`STEPS_PER_TIME_SCALE` of the response's time scale."""
        tmax = 2 * self.half_period_s / points
        return tmax if self.time_scale_s is None else min(tmax, self.time_scale_s / STEPS_PER_TIME_SCALE)

    def simulation_points(self, points: int = 20000) -> float:
        return self.stop_s / self.max_step_s(points)

    def check_simulable(self, points: int = 20000) -> None:
        """Refuse a period too long to simulate at the response's resolution
        (naming the parameters ``square_hz`` and ``simulate=False``)."""
        n = self.simulation_points(points)
        if n > MAX_SIM_POINTS:
            f_min = self.frequency_hz * n / MAX_SIM_POINTS
            raise ParamError(
                f"square wave {format_eng(self.frequency_hz, 'Hz')} is too slow to simulate: its period is "
                f"{n:.3g} time steps of the response ({format_eng(self.max_step_s(points), 's')}), more than "
                f"{MAX_SIM_POINTS:.0e}; use {{square_hz}} of at least {format_eng(f_min, 'Hz', 3)}, or {{no_sim}}",
                params=("square_hz", "no_sim"))

    def to_dict(self) -> dict:
        """The function generator's settings, as every result's JSON gives them."""
        return {"kind": "square", "low_v": 0.0, "high_v": self.amplitude_v, "frequency_hz": self.frequency_hz,
                "offset_v": self.amplitude_v / 2, "amplitude_vpp": self.amplitude_v}

    def source(self) -> str:
        """SPICE PULSE source text."""
        return (f"PULSE(0 {self.amplitude_v:.6g} {self.delay_s:.6g} {self.edge_s:.6g} {self.edge_s:.6g} "
                f"{self.half_period_s - self.edge_s:.6g} {2 * self.half_period_s:.6g})")


def opamp_library_text() -> str:
    """The project's behavioural op-amp subcircuits, for inlining.

    Returns
    -------
    str
        The text of ``opamp_behavioural.lib``.
    """
    return library_text("opamp_behavioural.lib")


def opamp_params(opamp: OpAmp) -> dict:
    """Instance parameters of the subcircuit that models ``opamp``."""
    if opamp.ideal:
        return {"A0": f"{opamp.a0:.6g}"}
    return {"A0": f"{opamp.a0:.6g}", "GBW": f"{opamp.gbw_hz:.6g}", "SR": f"{opamp.slew_v_per_s:.6g}",
            "VOH": f"{opamp.swing_high_v:.6g}", "VOL": f"{opamp.swing_low_v:.6g}"}


def subckt_name(opamp: OpAmp) -> str:
    return "OPAMP_IDEAL" if opamp.ideal else "OPAMP_BEH"


def add_opamp(circuit, name: str, inp, inn, out, opamp: OpAmp, vcc="vcc", vee="vee"):
    """One op-amp instance (pins inp inn vcc vee out)."""
    circuit.X(name, subckt_name(opamp), inp, inn, vcc, vee, out, **opamp_params(opamp))


def bench_circuit(title: str, opamp: OpAmp, comments: list):
    """A standalone deck's start: a PySpice circuit titled ``title`` whose raw text is the
    ``comments`` lines and the op-amp library, with the op-amps' supplies (:func:`add_supplies`).
    The Sallen-Key plant's decks, a section's ``.ac`` and square-wave decks start here.

    Parameters
    ----------
    title : str
        The deck's ``.title``.
    comments : list of str
        The comment lines above the library, each with its ``*``.
    opamp : designer.core.opamps.OpAmp
        Whose supplies and model the deck uses.

    Returns
    -------
    PySpice.Spice.Netlist.Circuit
        The circuit, for the caller's sources, netlist and analyses.
    """
    import logging

    from PySpice.Spice.Netlist import Circuit
    logging.getLogger("PySpice").setLevel(logging.ERROR)
    circuit = Circuit(title)
    circuit.raw_spice = "\n".join([*comments, opamp_library_text().rstrip()])
    add_supplies(circuit, opamp)
    return circuit


def add_supplies(circuit, opamp: OpAmp):
    """The op-amps' supplies: sources ``Vcc`` and ``Vee`` from ground to the ``vcc`` and ``vee`` rails.

    Parameters
    ----------
    circuit : PySpice.Spice.Netlist.Circuit
        The circuit the sources are added to.
    opamp : designer.core.opamps.OpAmp
        Whose rail voltages they are.
    """
    circuit.V("cc", "vcc", circuit.gnd, f"{opamp.vcc:.6g}")
    circuit.V("ee", "vee", circuit.gnd, f"{opamp.vee:.6g}")


def measure_lines(node: str, test: SquareTest, final: float, initial: float = 0.0) -> list:
    """``.meas`` statements for the rising step of ``test`` seen at ``node``.

    Levels are literal numbers (ngspice cannot use one measurement as another's
    level): ``final`` and ``initial`` are the expected settled values.

    Parameters
    ----------
    node : str
        The node measured.
    test : SquareTest
        The square-wave test (its delay, half period and edge).
    final, initial : float
        The expected settled values after and before the step (V).

    Returns
    -------
    list of str
        The ``.meas tran`` lines.
    """
    t0 = test.delay_s
    t1 = test.delay_s + test.half_period_s
    span = final - initial
    win = f"FROM={t0:.6g} TO={t1:.6g}"
    v = f"v({node})"
    lvl = lambda p: f"{initial + p * span:.6g}"  # noqa: E731
    return [
        f".meas tran vfinal FIND {v} AT={t1 - test.edge_s:.6g}",
        f".meas tran vpeak MAX {v} {win}",
        f".meas tran tpeak_abs MAX_AT {v} {win}",
        f".meas tran overshoot_pct param='max(0, (vpeak-{final:.6g})/({span:.6g})*100)'",
        f".meas tran peak_time_s param='tpeak_abs-{t0:.6g}'",
        f".meas tran t10 WHEN {v}={lvl(0.1)} CROSS=1 {win}",
        f".meas tran t90 WHEN {v}={lvl(0.9)} CROSS=1 {win}",
        ".meas tran rise_time_s param='t90-t10'",
        f".meas tran tsettle WHEN v(settle_err)=0.02 CROSS=LAST {win}",
        f".meas tran settling_time_s param='tsettle-{t0:.6g}'",
    ]


def settle_error_source(circuit, node: str, final: float, initial: float = 0.0):
    """A probe node ``settle_err`` = |v(node) - final| / |span|, for the settling-time measure.

    Parameters
    ----------
    circuit : PySpice.Spice.Netlist.Circuit
        The circuit the behavioural source is added to.
    node : str
        The node whose settling is measured.
    final, initial : float
        The expected settled values after and before the step (V).
    """
    span = abs(final - initial)
    circuit.B("settle", "settle_err", circuit.gnd,
              voltage_expression=f"abs(V({node})-{final:.6g})/{span:.6g}")


#: the sine check's ``.ac`` density (points a decade): the resonance peak and the -3 dB point read off it
SINE_POINTS_PER_DECADE = 200


def ac_lines(f_lo: float, f_hi: float, points_per_decade: int = SINE_POINTS_PER_DECADE) -> list:
    """The ``.ac`` analysis of the sine check: a decade sweep from ``f_lo`` to ``f_hi``.

    Parameters
    ----------
    f_lo, f_hi : float
        The sweep's ends (Hz).
    points_per_decade : int
        The frequencies per decade.

    Returns
    -------
    list of str
        The deck's ``.ac`` line.
    """
    return [f".ac dec {points_per_decade} {f_lo:.6g} {f_hi:.6g}"]


def finish_deck(circuit, test: SquareTest, extra_lines=(), points: int = 20000, max_step_s: float | None = None) -> str:
    """Circuit text plus ``.tran`` (max step: :meth:`SquareTest.max_step_s`, or ``max_step_s`` when
    that is shorter: a behavioural plant's own accuracy), extra lines and ``.end``.

    Parameters
    ----------
    circuit : PySpice.Spice.Netlist.Circuit
        The circuit.
    test : SquareTest
        The square-wave test whose rising step is simulated.
    extra_lines : iterable of str
        Lines after ``.tran`` (the ``.meas`` statements).
    points : int
        The time points the test's max step aims at.
    max_step_s : float or None
        A shorter max step (s), or None.

    Returns
    -------
    str
        The deck, ending in ``.end`` and a newline.
    """
    tmax = test.max_step_s(points)
    if max_step_s is not None and max_step_s < tmax:
        tmax = max_step_s
    lines = [str(circuit).rstrip(),
             f".tran {tmax:.6g} {test.stop_s:.6g} 0 {tmax:.6g}",
             *extra_lines, ".end"]
    return "\n".join(lines) + "\n"
