"""The parts every ngspice deck is built from, with PySpice's Circuit API:
the square-wave bench test (:class:`SquareTest`, its PULSE source and the time
step that resolves the response), op-amp instances and supplies from the
project's behavioural model library, ``.meas`` lines for the step metrics, and
the closing ``.tran``.

Decks are standalone: the models are inlined, so ``ngspice -b deck.cir`` alone
prints overshoot, peak time, rise time and settling time.
"""

from __future__ import annotations

from dataclasses import dataclass

from ..core.errors import ParamError
from ..core.opamps import OpAmp
from ..core.units import format_eng
from .library import library_text

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
    """The project's behavioural op-amp subcircuits, for inlining."""
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


def add_supplies(circuit, opamp: OpAmp):
    circuit.V("cc", "vcc", circuit.gnd, f"{opamp.vcc:.6g}")
    circuit.V("ee", "vee", circuit.gnd, f"{opamp.vee:.6g}")


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
