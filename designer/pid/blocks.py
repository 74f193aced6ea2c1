"""The seed's op-amp PID controller (seed 001, Figures 65-66): its parts, the
formulas that tie them to Kp, Ti and Td, and the static checks (corners, stage
bandwidths, bounds, accuracy).

Topology and part names follow the seed; the difference amplifier's four
resistors are not named in the text, so this project fixes them as:

* U1 difference amplifier: R15 from the reference r to the inverting input,
  R16 feedback, R17 from the plant output y to the non-inverting input, R18
  from there to ground. With all four equal, v_e = y - r.
* U2 unity inverter: R10 in, R9 feedback (R9 = R10): v_p = -v_e.
* U3 differentiator: R12 in series with C3 in, R11 feedback:
  v_d = -R11 C3 s / (R12 C3 s + 1) v_e.
* U4 integrator: R14 in, R13 || C4 feedback: v_i = -(R13/R14) / (R13 C4 s + 1) v_e.
* U5 summer: R6 (from v_p), R7 (from v_d), R8 (from v_i) in, R5 feedback.
* U6 final inverting gain: R4 in, R3 feedback; its output u drives the plant.

Three inversions after v_e = y - r make u = Kp (1 + 1/(Ti s) + Td s)(r - y) with

    Kp = R5 R3 / (R6 R4),  Ti = R8 R14 C4 / R6,  Td = R6 R11 C3 / R7

and the realisation's own corners: integrator leak 1/(2 pi R13 C4), derivative
filter 1/(2 pi R12 C3). A PI controller (Td = 0) leaves out U3, R7, R11, R12, C3.

See Also
--------
designer.pid.selection : the joint E-series selection of these parts.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

from ..core import eseries
from ..core.checks import Check
from ..core.i18n import N_
from ..core.errors import DesignError
from ..core.units import format_eng

__all__ = ["PidParts", "THESIS_BENCH", "continuous_parts", "seed_bench_parts", "seed_parts", "static_checks"]

#: "Well below / well above" the plant's fn for the check (factor).
CORNER_MARGIN = 5.0
#: Default corner targets relative to fn (the seed used 130 Hz and 33 kHz for fn = 3.5 kHz).
F_INTEGRATOR_RATIO = 1.0 / 100.0
F_DIFFERENTIATOR_RATIO = 10.0


@dataclass(frozen=True)
class PidParts:
    """Component values of the controller (ohms and farads).

    ``r7``, ``r11``, ``r12`` and ``c3`` are None for a PI controller.
    """

    r3: float
    r4: float
    r5: float
    r6: float
    r7: float | None
    r8: float
    r9: float
    r10: float
    r11: float | None
    r12: float | None
    r13: float
    r14: float
    r15: float
    r16: float
    r17: float
    r18: float
    c3: float | None
    c4: float

    @property
    def has_derivative(self) -> bool:
        return self.c3 is not None

    @property
    def kp(self) -> float:
        return self.r5 * self.r3 / (self.r6 * self.r4) * (self.r9 / self.r10)

    @property
    def ti_s(self) -> float:
        return self.r8 * self.r14 * self.c4 / self.r6

    @property
    def td_s(self) -> float:
        return self.r6 * self.r11 * self.c3 / self.r7 if self.has_derivative else 0.0

    @property
    def f_integrator_hz(self) -> float:
        return 1.0 / (2 * math.pi * self.r13 * self.c4)

    @property
    def f_differentiator_hz(self) -> float:
        return 1.0 / (2 * math.pi * self.r12 * self.c3) if self.has_derivative else math.inf

    @property
    def integrator_dc_gain(self) -> float:
        """DC gain of the integral path relative to the proportional one,
        R13 C4 / Ti: the leak bounds the loop's DC gain to Kp (1 + this)."""
        return self.r13 * self.c4 / self.ti_s

    def noise_gains(self) -> dict:
        """High-frequency noise gain 1 + Zf/Zin of each op-amp stage (the
        integrator's is 1 there; its DC value 1 + R13/R14 is given too)."""
        y_sum = 1 / self.r6 + 1 / self.r8 + (1 / self.r7 if self.has_derivative else 0.0)
        ng = {"difference": 1 + self.r16 / self.r15,
              "inverter": 1 + self.r9 / self.r10,
              "integrator": 1.0,
              "summer": 1 + self.r5 * y_sum,
              "gain": 1 + self.r3 / self.r4}
        if self.has_derivative:
            ng["differentiator"] = 1 + self.r11 / self.r12
        return ng

    def stage_bandwidths(self, gbw_hz: float) -> dict:
        """Closed-loop bandwidth GBW / noise gain of each stage (Hz)."""
        return {k: gbw_hz / v for k, v in self.noise_gains().items()}

    def resistors(self) -> dict:
        out = {}
        for i in range(3, 19):
            v = getattr(self, f"r{i}")
            if v is not None:
                out[f"R{i}"] = v
        return out

    def capacitors(self) -> dict:
        return {k: v for k, v in (("C3", self.c3), ("C4", self.c4)) if v is not None}

    def to_dict(self) -> dict:
        d = {f"{k}_ohm": v for k, v in self.resistors().items()}
        d.update({f"{k}_f": v for k, v in self.capacitors().items()})
        return d

    @classmethod
    def from_dict(cls, d: dict) -> "PidParts":
        kw = {f"r{i}": d.get(f"R{i}_ohm") for i in range(3, 19)}
        kw.update(c3=d.get("C3_f"), c4=d.get("C4_f"))
        return cls(**kw)


def unity_resistor(series: str, lo: float, hi: float) -> float:
    """The value used where only equality matters (R9 = R10, R15..R18): 10 kOhm
    when the bounds allow it, else the series value nearest their geometric mean."""
    vals = eseries.values(series, lo, hi)
    if vals.size == 0:
        raise DesignError(f"no {series} resistor between {lo:g} and {hi:g} Ohm")
    target = 10e3 if lo <= 10e3 <= hi else math.sqrt(lo * hi)
    return float(vals[np.argmin(np.abs(np.log(vals / target)))])


def check_targets(kp, ti, td):
    """The sizing's precondition on gains from any source (a rule, the optimiser, a
    caller of this module); a user's gains were checked against their ranges by the spec."""
    for name, v, above, what in (("kp", kp, kp > 0, "a finite gain above 0"),
                                 ("ti_s", ti, ti > 0, "a finite time above 0 s"),
                                 ("td_s", td, td >= 0, "a finite time of 0 s or more")):
        if not (math.isfinite(v) and above):
            raise DesignError(f"{name} must be {what}, got {float(v):g}", param=name)


def static_checks(parts: PidParts, fn_hz: float, gbw_hz: float, targets: dict, *,
                  r_min: float, r_max: float, c_min: float, c_max: float, tol: float = 0.01,
                  fn_name: str = "fn") -> list:
    """Checks that need only the part values: accuracy of Kp/Ti/Td, the
    integrator and differentiator corners against fn, each stage's bandwidth
    against the highest frequency the controller handles, and the bounds.
    ``fn_name`` is what the messages call ``fn_hz`` (``fc``, the crossover, for
    a plant known only as a model).

    Parameters
    ----------
    parts : PidParts
        The controller.
    fn_hz : float
        The plant's natural frequency (a model plant: the loop's crossover).
    gbw_hz : float
        The op-amp's gain-bandwidth.
    targets : dict
        ``kp``, ``ti_s``, ``td_s`` the parts should give.
    r_min, r_max : float
        The resistors' bounds (Ohm).
    c_min, c_max : float
        The capacitors' bounds (F).
    tol : float
        The accuracy the gains are held to (fraction).
    fn_name : str
        How the messages name ``fn_hz``.

    Returns
    -------
    list of designer.core.checks.Check
    """
    checks = []
    for key, label, unit in (("kp", "Kp", ""), ("ti_s", "Ti", "s"), ("td_s", "Td", "s")):
        want = targets[key]
        if key == "td_s" and not want:
            continue
        got = getattr(parts, key)
        e = got / want - 1
        checks.append(Check.of(f"{label.lower()}_accuracy", abs(e) <= tol * (1 + 1e-9),
                               N_("{name} = {got} for {want} ({error} %, allowed +/-{tol} %)"), name=label,
                               got=format_eng(got, unit), want=format_eng(want, unit), error=f"{e * 100:+.2f}",
                               tol=f"{tol * 100:g}"))
    fi = parts.f_integrator_hz
    checks.append(Check.of("integrator_corner", fi <= fn_hz / CORNER_MARGIN,
                           N_("1/(2 pi R13 C4) = {corner}, must be below {fn}/{margin} = {limit} ({fn} = {f})"),
                           corner=format_eng(fi, 'Hz'), fn=fn_name, margin=f"{CORNER_MARGIN:g}",
                           limit=format_eng(fn_hz / CORNER_MARGIN, 'Hz'), f=format_eng(fn_hz, 'Hz')))
    if parts.has_derivative:
        fd = parts.f_differentiator_hz
        checks.append(Check.of("differentiator_corner", fd >= fn_hz * CORNER_MARGIN,
                               N_("1/(2 pi R12 C3) = {corner}, must be above {margin} {fn} = {limit}"),
                               corner=format_eng(fd, 'Hz'), margin=f"{CORNER_MARGIN:g}", fn=fn_name,
                               limit=format_eng(fn_hz * CORNER_MARGIN, 'Hz')))
        f_need = fd
    else:
        f_need = CORNER_MARGIN * fn_hz
    ng = parts.noise_gains()
    for stage, bw in parts.stage_bandwidths(gbw_hz).items():
        values = dict(gbw=format_eng(gbw_hz, 'Hz'), gain=f"{ng[stage]:.3g}", bw=format_eng(bw, 'Hz'),
                      need=format_eng(f_need, 'Hz'))
        if parts.has_derivative:
            checks.append(Check.of(f"bandwidth_{stage}", bw >= f_need,
                                   N_("GBW/noise gain = {gbw}/{gain} = {bw}, must be above the differentiator "
                                      "corner ({need})"), **values))
        else:
            checks.append(Check.of(f"bandwidth_{stage}", bw >= f_need,
                                   N_("GBW/noise gain = {gbw}/{gain} = {bw}, must be above {margin} {fn} ({need})"),
                                   margin=f"{CORNER_MARGIN:g}", fn=fn_name, **values))
    rs, cs = parts.resistors(), parts.capacitors()
    bad_r = [f"{k} = {format_eng(v, 'Ohm')}" for k, v in rs.items()
             if not r_min * (1 - 1e-9) <= v <= r_max * (1 + 1e-9)]
    bad_c = [f"{k} = {format_eng(v, 'F')}" for k, v in cs.items()
             if not c_min * (1 - 1e-9) <= v <= c_max * (1 + 1e-9)]
    checks.append(Check.of("resistor_bounds", True, N_("all resistors within {lo}..{hi} (smallest {small}, largest "
                                                       "{large})"), lo=format_eng(r_min, 'Ohm'),
                           hi=format_eng(r_max, 'Ohm'), small=format_eng(min(rs.values()), 'Ohm'),
                           large=format_eng(max(rs.values()), 'Ohm')) if not bad_r else
                  Check.of("resistor_bounds", False, N_("outside the bounds: {parts}"), parts=", ".join(bad_r)))
    checks.append(Check.of("capacitor_bounds", True, N_("all capacitors within {lo}..{hi}"),
                           lo=format_eng(c_min, 'F'), hi=format_eng(c_max, 'F')) if not bad_c else
                  Check.of("capacitor_bounds", False, N_("outside the bounds: {parts}"), parts=", ".join(bad_c)))
    return checks


def seed_parts() -> PidParts:
    """The seed's own controller (lines ~3263-3330), with the difference
    amplifier as designed (all 10 kOhm) rather than the bench-trimmed values.

    Returns
    -------
    PidParts
    """
    return PidParts(r3=12e3, r4=1.777e3, r5=22e3, r6=3.3e3, r7=14.356e3, r8=1.2e3, r9=10e3,
                    r10=10e3, r11=10e3, r12=1.026e3, r13=26.048e3, r14=2.528e3, r15=10e3,
                    r16=10e3, r17=10e3, r18=10e3, c3=4.7e-9, c4=47e-9)


def continuous_parts(kp: float, ti_s: float, td_s: float, fn_hz: float, *,
                     f_integrator_hz: float | None = None, f_differentiator_hz: float | None = None,
                     r: float = 10e3) -> PidParts:
    """Exact (unrounded) parts with a fixed, balanced structure, for searching
    gains before any part is chosen: R6 = R7 = R8 = R9 = R10 = R14 = R15..R18 = r,
    R11 C3 = Td, R14 C4 = Ti, corners as in :func:`designer.pid.selection.select_parts`, and Kp split
    between the summer and the final gain so that their noise gains match
    (1 + 3 g = 1 + Kp/g, g = sqrt(Kp/3); 1 + 2 g and g = sqrt(Kp/2) for a PI).

    Parameters
    ----------
    kp : float
        Proportional gain.
    ti_s : float
        Integral time (s).
    td_s : float
        Derivative time (s; 0 for a PI).
    fn_hz : float
        The plant's natural frequency (a model plant: the loop's crossover) the corners are set from.
    f_integrator_hz : float, optional
        The integrator leak's corner (default fn/100).
    f_differentiator_hz : float, optional
        The derivative filter's corner (default 10 fn).
    r : float
        The balanced resistors' value (Ohm).

    Returns
    -------
    PidParts
    """
    check_targets(kp, ti_s, td_s)
    f_i = fn_hz * F_INTEGRATOR_RATIO if f_integrator_hz is None else f_integrator_hz
    f_d = fn_hz * F_DIFFERENTIATOR_RATIO if f_differentiator_hz is None else f_differentiator_hz
    has_d = td_s > 0
    g = math.sqrt(kp / (3.0 if has_d else 2.0))
    c4 = ti_s / r
    c3 = td_s / r if has_d else None
    return PidParts(r3=r * kp / g, r4=r, r5=g * r, r6=r, r7=r if has_d else None, r8=r, r9=r, r10=r,
                    r11=r if has_d else None,
                    r12=1.0 / (2 * math.pi * f_d * c3) if has_d else None,
                    r13=1.0 / (2 * math.pi * f_i * c4), r14=r, r15=r, r16=r, r17=r, r18=r,
                    c3=c3, c4=c4)


def seed_bench_parts() -> PidParts:
    """The seed's controller as it was built and measured (001, section V.13):
    :func:`seed_parts` with the difference amplifier trimmed by hand on the bench
    to R15 = 10k, R16 = 3.279k, R17 = 1.716k, R18 = 9.98k, in the order the
    thesis lists them and with this project's names for the four positions (R15
    from r, R16 feedback, R17 from y, R18 to ground).

    Returns
    -------
    PidParts
    """
    from dataclasses import replace
    return replace(seed_parts(), r15=10e3, r16=3.279e3, r17=1.716e3, r18=9.98e3)


#: what the thesis reports of its bench (001, V.13, Figures 88-90), for the comparison on the sheet
THESIS_BENCH = {
    "stable": True,
    "output_vs_reference": N_("larger (Fig. 89: 'la magnitud de la salida es mas grande que la senal de entrada')"),
    "overshoot": N_("suppressed ('se redujo significativamente el valor del sobrepaso maximo', Fig. 89-90)"),
    "scope": N_("Fig. 88: CH1 1.00 V/div, CH2 5.00 V/div, 500 us/div, trigger CH1, 434 Hz"),
    "amplitude": N_("not stated for the loop (the plant's own test, IV.9: a 2 V, 330 Hz square wave)"),
    "opamp": N_("LM741 (V.10 uses 1.5 MHz and 0.7 V/us; TI's typicals are 1 MHz and 0.5 V/us)"),
    "plant": N_("R1 = 805 Ohm, R2 = 1k, C1 = 10n, C2 = 220n (its list swaps the C1/C2 names)"),
}
