"""The lines a model plant's design adds to its notes when a part or an op-amp,
not the tuning, limits the loop: :func:`sizing_notes` (a part the sizing pinned
at a bound, and which bound to move) and :func:`opamp_speed_notes` (op-amps too
slow for the loop's crossover, and which op-amp of the library keeps it)."""

from __future__ import annotations

import math

from ..core import opamps
from ..core.units import format_eng
from . import selection

__all__ = []

#: the largest capacitor a sizing message suggests (a 1 mF film capacitor is already a brick)
PRACTICAL_C_MAX_F = 1e-3


def sizing_notes(sel, spec) -> list:
    """One line per part the sizing pinned at a bound, saying which bound to move."""
    out = []
    p, t = sel.parts, sel.targets
    f_i = t.get("f_integrator_hz")
    if f_i and p.f_integrator_hz > 1.5 * f_i:
        need = 1 / (2 * math.pi * f_i * p.c4)
        r_top = min(spec.r_max, selection.R_CORNER_MAX)
        c_need = 1 / (2 * math.pi * f_i * r_top)
        if c_need > PRACTICAL_C_MAX_F:
            fix = (f"no practical C4 reaches it (it would take {format_eng(c_need, 'F')}): this loop is too slow for "
                   f"an analog leak at fc/100; accept a higher corner with --f-integrator (the steady-state error "
                   "grows) or keep the integral action digital")
        else:
            fix = (f"give C4 room with --c-max {_cli_value(c_need)} (now "
                   f"{format_eng(spec.c_max, 'F')}), or accept a higher leak corner with --f-integrator")
        out.append(f"the integrator leak R13 would need {format_eng(need, 'Ohm')} for a {format_eng(f_i, 'Hz')} "
                   f"corner with C4 = {format_eng(p.c4, 'F')}, above its {format_eng(r_top, 'Ohm')} limit, so the "
                   f"corner is {format_eng(p.f_integrator_hz, 'Hz')}: {fix}")
    for key, label, part in (("ti", "Ti = R8 R14 C4/R6", "C4"), ("td", "Td = R6 R11 C3/R7", "C3")):
        err = sel.errors_pct.get(key)
        if err is not None and abs(err) > 100 * spec.tol:
            out.append(f"{label} is {err:+.3g} % off its target: its RC is beyond the part bounds; "
                       f"{part} and its resistors are limited by --c-max {format_eng(spec.c_max, 'F')} and "
                       f"--r-max {format_eng(spec.r_max, 'Ohm')}: widen them (e.g. --c-max 100u)")
    return out


def _cli_value(x: float) -> str:
    """``x`` rounded up to an E6 value, as an option takes it (``470u``)."""
    from ..core.eseries import values
    up = values("E6", x, 10 * x)
    return format_eng(float(up[0]) if up.size else x, "", 3).replace(" ", "")


#: an op-amp keeps a loop's phase when its GBW is about this many times the crossover (four stages in
#: the path, each at GBW over a noise gain of 2 to 4: a few degrees each)
GBW_PER_CROSSOVER = 30.0


def opamp_speed_notes(amp, built, ideal, pm_min: float, optimized: bool = False) -> list:
    """One line when the op-amps, not the gains, lose the loop: its phase margin
    (``built``, the op-amps' poles included) below ``pm_min`` where the same gains
    with ideal op-amps (``ideal``) meet it; it names the library's slowest op-amp
    fast enough (GBW :data:`GBW_PER_CROSSOVER` times the crossover), else says none is."""
    def ok(m):
        return m.stable and math.isfinite(m.phase_margin_deg) and m.phase_margin_deg >= pm_min
    if amp.ideal or ok(built) or not ok(ideal):
        return []
    fc = ideal.crossover_hz
    need = GBW_PER_CROSSOVER * fc
    real = [opamps.get(n) for n in opamps.names() if not opamps.get(n).ideal]
    fast = sorted((a for a in real if a.gbw_hz >= need), key=lambda a: a.gbw_hz)
    slower = ("the optimiser found no slower loop that meets the limits with it" if optimized
              else "--tuning optimize counts the op-amps' poles")
    lost = ("is unstable" if not built.stable else f"has {built.phase_margin_deg:.3g} deg of phase margin")
    head = (f"the {amp.name} (GBW {format_eng(amp.gbw_hz, 'Hz')}) is too slow for this loop: with ideal op-amps "
            f"these gains give {ideal.phase_margin_deg:.3g} deg of phase margin at {format_eng(fc, 'Hz')}, with "
            f"its poles the loop {lost}; ")
    if fast:
        return [head + f"an op-amp of about {format_eng(need, 'Hz')} GBW keeps it (--opamp {fast[0].name}, "
                       f"{format_eng(fast[0].gbw_hz, 'Hz')})" + ("" if optimized else f", or slow the loop ({slower})")]
    top = max(real, key=lambda a: a.gbw_hz)
    return [head + f"it needs about {format_eng(need, 'Hz')} of GBW and the library's fastest, the {top.name}, "
                   f"has {format_eng(top.gbw_hz, 'Hz')}: "
                   + (f"{slower}; lower --min-pm or --max-ms, or slow the plant" if optimized
                      else f"slow the loop down ({slower}, or a larger --simc-tauc or --imc-lambda)")]
