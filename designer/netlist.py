"""ngspice decks written with PySpice's Circuit API.

Decks are standalone: the behavioural op-amp models from ``circuits/`` are
inlined, supplies and the square-wave test source are included, and ``.tran``
plus ``.meas`` lines are appended so that ``ngspice -b deck.cir`` alone prints
overshoot, peak time, rise time and settling time.
"""

from __future__ import annotations

import math
from dataclasses import dataclass
from pathlib import Path

from .opamps import OpAmp
from .sallenkey import SallenKeyParts

CIRCUITS_DIR = Path(__file__).resolve().parents[1] / "circuits"
OPAMP_LIBRARY = CIRCUITS_DIR / "opamp_behavioural.lib"


#: the simulation's maximum step is at most this fraction of the response's time scale
STEPS_PER_TIME_SCALE = 50
#: a bench period needing more simulation steps than this is refused (minutes of ngspice, GBs of data)
MAX_SIM_POINTS = 2_000_000


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
        """Refuse a period too long to simulate at the response's resolution."""
        n = self.simulation_points(points)
        if n > MAX_SIM_POINTS:
            from .errors import DesignError
            from .units import format_eng
            f_min = self.frequency_hz * n / MAX_SIM_POINTS
            raise DesignError(
                f"square wave {format_eng(self.frequency_hz, 'Hz')} is too slow to simulate: its period is "
                f"{n:.3g} time steps of the response ({format_eng(self.max_step_s(points), 's')}), more than "
                f"{MAX_SIM_POINTS:.0e}; use --square-freq of at least {format_eng(f_min, 'Hz', 3)}, or --no-sim")

    def source(self) -> str:
        """SPICE PULSE source text."""
        return (f"PULSE(0 {self.amplitude_v:.6g} {self.delay_s:.6g} {self.edge_s:.6g} {self.edge_s:.6g} "
                f"{self.half_period_s - self.edge_s:.6g} {2 * self.half_period_s:.6g})")


def opamp_library_text() -> str:
    """The project's behavioural op-amp subcircuits, for inlining."""
    return OPAMP_LIBRARY.read_text()


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


def add_supplies(circuit, opamp: OpAmp):
    circuit.V("cc", "vcc", circuit.gnd, f"{opamp.vcc:.6g}")
    circuit.V("ee", "vee", circuit.gnd, f"{opamp.vee:.6g}")


def add_sallen_key(circuit, parts: SallenKeyParts, opamp: OpAmp, inp: str, out: str, prefix: str = ""):
    """The Sallen-Key low-pass between nodes ``inp`` and ``out``, with the seed's
    part names (R1, R2, C1, C2; R3, R4 for gain), optionally prefixed."""
    v1, vp, vn = f"{prefix}v1", f"{prefix}vp", f"{prefix}vn"
    circuit.R(f"{prefix}1", inp, v1, f"{parts.r1:.6g}")
    circuit.R(f"{prefix}2", v1, vp, f"{parts.r2:.6g}")
    circuit.C(f"{prefix}1", vp, circuit.gnd, f"{parts.c1:.6g}")
    circuit.C(f"{prefix}2", v1, out, f"{parts.c2:.6g}")
    if parts.r3 is None:
        add_opamp(circuit, f"{prefix}1", vp, out, out, opamp)
    else:
        circuit.R(f"{prefix}3", vn, circuit.gnd, f"{parts.r3:.6g}")
        circuit.R(f"{prefix}4", out, vn, f"{parts.r4:.6g}")
        add_opamp(circuit, f"{prefix}1", vp, vn, out, opamp)


def measure_lines(node: str, test: SquareTest, final: float, initial: float = 0.0) -> list:
    """``.meas`` statements for the rising step of ``test`` seen at ``node``.

    Levels are literal numbers (ngspice cannot use one measurement as another's
    level): ``final`` and ``initial`` are the expected settled values.
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
    """A probe node ``settle_err`` = |v(node) - final| / |span|, for the settling-time measure."""
    span = abs(final - initial)
    circuit.B("settle", "settle_err", circuit.gnd,
              voltage_expression=f"abs(V({node})-{final:.6g})/{span:.6g}")


def finish_deck(circuit, test: SquareTest, extra_lines=(), points: int = 20000) -> str:
    """Circuit text plus ``.tran`` (max step: see :meth:`SquareTest.max_step_s`), extra lines and ``.end``."""
    tmax = test.max_step_s(points)
    lines = [str(circuit).rstrip(),
             f".tran {tmax:.6g} {test.stop_s:.6g} 0 {tmax:.6g}",
             *extra_lines, ".end"]
    return "\n".join(lines) + "\n"


def plant_deck(parts: SallenKeyParts, opamp: OpAmp, test: SquareTest, title: str) -> str:
    """Standalone deck of the Sallen-Key plant under the square-wave test."""
    from PySpice.Spice.Netlist import Circuit
    import logging
    logging.getLogger("PySpice").setLevel(logging.ERROR)

    circuit = Circuit(title)
    circuit.raw_spice = "\n".join([
        f"* {title}",
        f"* op-amp: {opamp.name} ({opamp.description}); supplies {opamp.vcc:g} V / {opamp.vee:g} V",
        f"* test: 0 -> {test.amplitude_v:g} V square wave at {test.frequency_hz:g} Hz, step at {test.delay_s:.4g} s",
        "* Run: ngspice -b <this file>   (prints overshoot_pct, peak_time_s, rise_time_s, settling_time_s)",
        opamp_library_text().rstrip(),
    ])
    add_supplies(circuit, opamp)
    circuit.V("in", "input", circuit.gnd, test.source())
    add_sallen_key(circuit, parts, opamp, "input", "out")
    final = parts.gain * test.amplitude_v
    settle_error_source(circuit, "out", final)
    return finish_deck(circuit, test, measure_lines("out", test, final))


def nice_frequency_below(f: float) -> float:
    """The largest 1-1.5-2.2-3.3-4.7-6.8 (E6) x 10^k value not above ``f``
    (function generators are set to round numbers)."""
    k = math.floor(math.log10(f))
    best = None
    for dec in (k - 1, k):
        for m in (1.0, 1.5, 2.2, 3.3, 4.7, 6.8):
            v = float(f"{m * 10 ** dec:.3g}")
            if v <= f * (1 + 1e-12):
                best = v
    return best
