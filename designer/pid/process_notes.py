"""The lines a model plant's design adds to its notes when a part or an op-amp,
not the tuning, limits the loop: :func:`sizing_notes` (a part the sizing pinned
at a bound, and which bound to move) and :func:`opamp_speed_notes` (op-amps too
slow for the loop's crossover, and which op-amp of the library keeps it)."""

from __future__ import annotations

import math

from ..core import opamps
from ..core.i18n import N_, Message
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
            fix = Message(N_("no practical C4 reaches it (it would take {c}): this loop is too slow for an analog leak "
                             "at fc/100; accept a higher corner with --f-integrator (the steady-state error grows) or "
                             "keep the integral action digital"), c=format_eng(c_need, 'F'))
        else:
            fix = Message(N_("give C4 room with --c-max {c} (now {c_max}), or accept a higher leak corner with "
                             "--f-integrator"), c=_cli_value(c_need), c_max=format_eng(spec.c_max, 'F'))
        out.append(Message(N_("the integrator leak R13 would need {r} for a {f} corner with C4 = {c4}, above its {r_top} "
                              "limit, so the corner is {f_built}: {fix}"), r=format_eng(need, 'Ohm'),
                           f=format_eng(f_i, 'Hz'), c4=format_eng(p.c4, 'F'), r_top=format_eng(r_top, 'Ohm'),
                           f_built=format_eng(p.f_integrator_hz, 'Hz'), fix=fix))
    for key, label, part in (("ti", "Ti = R8 R14 C4/R6", "C4"), ("td", "Td = R6 R11 C3/R7", "C3")):
        err = sel.errors_pct.get(key)
        if err is not None and abs(err) > 100 * spec.tol:
            out.append(Message(N_("{label} is {err} % off its target: its RC is beyond the part bounds; {part} and its "
                                  "resistors are limited by --c-max {c_max} and --r-max {r_max}: widen them (e.g. "
                                  "--c-max 100u)"), label=label, err=f"{err:+.3g}", part=part,
                               c_max=format_eng(spec.c_max, 'F'), r_max=format_eng(spec.r_max, 'Ohm')))
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
    slower = (N_("the optimiser found no slower loop that meets the limits with it") if optimized
              else N_("--tuning optimize counts the op-amps' poles"))
    lost = (N_("is unstable") if not built.stable
            else Message(N_("has {pm} deg of phase margin"), pm=f"{built.phase_margin_deg:.3g}"))
    head = Message(N_("the {opamp} (GBW {gbw}) is too slow for this loop: with ideal op-amps these gains give {pm} deg "
                      "of phase margin at {fc}, with its poles the loop {lost}; "), opamp=amp.name,
                   gbw=format_eng(amp.gbw_hz, 'Hz'), pm=f"{ideal.phase_margin_deg:.3g}", fc=format_eng(fc, 'Hz'),
                   lost=lost)
    if fast:
        return [Message("{head}{fix}{or_slower}", head=head, fix=Message(
            N_("an op-amp of about {need} GBW keeps it (--opamp {opamp}, {gbw})"), need=format_eng(need, 'Hz'),
            opamp=fast[0].name, gbw=format_eng(fast[0].gbw_hz, 'Hz')),
            or_slower="" if optimized else Message(N_(", or slow the loop ({slower})"), slower=slower))]
    top = max(real, key=lambda a: a.gbw_hz)
    return [Message("{head}{need}{fix}", head=head, need=Message(
        N_("it needs about {need} of GBW and the library's fastest, the {opamp}, has {gbw}: "),
        need=format_eng(need, 'Hz'), opamp=top.name, gbw=format_eng(top.gbw_hz, 'Hz')),
        fix=(Message(N_("{slower}; lower --min-pm or --max-ms, or slow the plant"), slower=slower) if optimized
             else Message(N_("slow the loop down ({slower}, or a larger --simc-tauc or --imc-lambda)"), slower=slower)))]
