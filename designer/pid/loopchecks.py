"""The checks and names every PID loop shares, whatever its plant (a
Sallen-Key circuit or a model that any circuit may realise, :mod:`designer.pid.design`): the op-amps' bench designators, the
leaky integrator's steady-state error, the slew rate and output swing of every
op-amp stage (the slew budget: 5 % of the rise time, Jung, *Op Amp
Applications Handbook*, 2005, section 1.5), and what a SPICE run says beyond
its figures.

Kept apart from :mod:`designer.pid.design` so that the optimiser and the model
loop's figures (:mod:`designer.pid.modelloop`) need not import the design.
"""

from __future__ import annotations

import math
from dataclasses import replace

from ..core.checks import Check, listing
from ..core.i18n import N_, Message
from ..core.units import format_eng
from . import model

__all__ = ["MAX_STEADY_STATE_ERROR", "designators", "named", "kick_note", "steady_state_check", "stage_checks",
           "spice_notes"]

#: largest acceptable steady-state error of the leaky-integrator loop
MAX_STEADY_STATE_ERROR = 0.02


def designators(parts, plant, amp, package, netlist=None) -> dict:
    """The deck's op-amp (``U6``) -> its designator on the bench in ``package``
    (``U3B`` in duals), so that checks, notes and JSON name the op-amp the
    sheet wires; a stage the circuit does not have (a PI's differentiator) is
    absent. ``plant`` None: the controller alone (a plant known only as a model);
    ``netlist``: the loop's table as given (a circuit plant's).

    Parameters
    ----------
    parts : designer.pid.blocks.PidParts
        The controller.
    plant : designer.pid.plant.Plant, designer.pid.plant.PlantCircuit or None
        A circuit plant (:func:`designer.pid.netlist.plant_circuit`), or None.
    amp : designer.core.opamps.OpAmp
        The op-amp (its packages).
    package : str or None
        ``single``, ``dual``, ``quad`` or the op-amp's default.
    netlist : designer.spice.deck.Netlist, optional
        The loop's table, when not the controller's or the Sallen-Key loop's.

    Returns
    -------
    dict
        Deck designator -> bench designator.
    """
    from ..spice.deck import board
    from .netlist import controller_netlist, loop_netlist
    if netlist is None:
        netlist = controller_netlist(parts) if plant is None else loop_netlist(parts, plant)
    bd = board(netlist, amp, package)
    return {a.ref: u.designator for a, u in zip(bd.netlist.amps, bd.units)}


def named(levels: dict, names: dict) -> dict:
    """Per-stage figures (analytic or SPICE, keyed by role, each with the deck's
    ``opamp``) with their op-amp named as on the bench; stages not built dropped.

    Parameters
    ----------
    levels : dict
        Role -> figures with an ``opamp`` field.
    names : dict
        Deck designator -> bench designator (:func:`designators`).

    Returns
    -------
    dict
        The same, renamed.
    """
    return {role: replace(v, opamp=names[v.opamp]) for role, v in levels.items() if v.opamp in names}


def kick_note(parts, amp, step_v, name_of=str) -> str:
    """The controller's answer to the step edge alone (ideal op-amps):
    u = Kp (1 + Td/(R12 C3)) x step, the high-frequency gain times the step.

    Parameters
    ----------
    parts : designer.pid.blocks.PidParts
        The controller.
    amp : designer.core.opamps.OpAmp
        Its op-amps (their swing).
    step_v : float
        The reference step, volts.
    name_of : callable
        Deck designator -> the name shown.

    Returns
    -------
    str
        A clause for the swing check's message, or "" when the kick fits.
    """
    hf = parts.kp * (1 + (parts.td_s / (parts.r12 * parts.c3) if parts.has_derivative else 0.0))
    u = hf * step_v
    if amp.ideal or abs(u) <= amp.vout_max:
        return ""
    return Message(N_("; even before the loop reacts, the step edge alone asks {unit} for Kp (1 + Td/(R12 C3)) x {step} V "
                      "= {u} V (the {opamp} reaches {vmax} V)"), unit=name_of('U6'), step=f"{step_v:g}", u=f"{u:.3g}",
                   opamp=amp.name, vmax=f"{amp.vout_max:.3g}")


def steady_state_check(dc_gain: float) -> list:
    """The leaky integrator's steady-state error 1 - y/r at DC (none when unknown).

    Parameters
    ----------
    dc_gain : float
        y/r at DC of the loop as built.

    Returns
    -------
    list of Check
        One check, or none.
    """
    if not math.isfinite(dc_gain):
        return []
    e = 1 - dc_gain
    return [Check.of("steady_state_error", abs(e) <= MAX_STEADY_STATE_ERROR,
                     N_("{error} % of the step (the integrator leaks through R13; want <= {max} %)"),
                     error=f"{100 * e:.3g}", max=f"{100 * MAX_STEADY_STATE_ERROR:g}")]


def stage_checks(stable, levels, amp, step_v, rise, parts, name_of=str) -> list:
    """Slew rate and output swing of every op-amp stage of the analytic loop
    (``levels``: :func:`designer.pid.model.waveform_limits`), for any plant.

    Parameters
    ----------
    stable : bool
        Whether the loop is stable.
    levels : dict
        Role -> the stage's figures.
    amp : designer.core.opamps.OpAmp
        The op-amps.
    step_v : float
        The reference step, volts.
    rise : float
        The loop's rise time, seconds (the slew budget is 5 % of it).
    parts : designer.pid.blocks.PidParts
        The controller.
    name_of : callable
        Deck designator -> the name shown.

    Returns
    -------
    list of Check
        ``slew_rate`` and ``output_swing``.
    """
    out = []
    if not stable:
        out.append(Check.of("slew_rate", False, N_("unstable loop: no steady waveforms to check")))
        out.append(Check.of("output_swing", False, N_("unstable loop: the outputs run to the rails{kick}"),
                            kick=kick_note(parts, amp, step_v, name_of)))
        return out
    if amp.ideal:
        worst_sw = max(levels.values(), key=lambda v: max(abs(v.v_max), abs(v.v_min)))
        out.append(Check.of("slew_rate", True, N_("ideal op-amps (no slew limit)")))
        out.append(Check.of("output_swing", True, N_("ideal op-amps; the largest excursion is {unit} ({signal}) {lo} V "
                                                     "to {hi} V"), unit=worst_sw.opamp, signal=worst_sw.signal,
                            lo=f"{worst_sw.v_min:.3g}", hi=f"{worst_sw.v_max:.3g}"))
        return out
    budget = model.SLEW_DELAY_FRACTION * rise
    slow = [(N_("{unit} {role} needs {need} V/us, slews for ~{delay}"),
             {"unit": v.opamp, "role": role, "need": f"{v.slope_v_per_s / 1e6:.3g}",
              "delay": format_eng(v.slew_delay_s, 's')}) for role, v in levels.items() if not v.slew_ok]
    worst_role, worst_v = max(levels.items(), key=lambda kv: kv[1].slew_delay_s)
    # one message for a pass, one for a failure, the values of both given (a message takes the ones it names)
    out.append(Check.of("slew_rate", not slow,
                        N_("{opamp} slews at {rate} V/us; slewing may delay a stage by at most {budget} (5 % of the "
                           "rise time). {slow}") if slow else
                        N_("{opamp} slews at {rate} V/us; slewing may delay a stage by at most {budget} (5 % of the "
                           "rise time). worst: {unit} {role}, {delay}"),
                        opamp=amp.name, rate=f"{amp.slew_v_per_s / 1e6:.3g}", budget=format_eng(budget, 's'),
                        slow=listing("; ", slow), unit=worst_v.opamp, role=worst_role,
                        delay=format_eng(worst_v.slew_delay_s, 's')))
    clip = [(N_("{unit} {role} {lo}..{hi} V"), {"unit": v.opamp, "role": role, "lo": f"{v.v_min:.3g}",
                                                  "hi": f"{v.v_max:.3g}"}) for role, v in levels.items() if not v.swing_ok]
    out.append(Check.of("output_swing", not clip,
                        N_("{opamp} outputs reach {lo} V to {hi} V on {vcc}/{vee} V supplies for a {step} V square "
                           "wave; would need {clip}") if clip else
                        N_("{opamp} outputs reach {lo} V to {hi} V on {vcc}/{vee} V supplies for a {step} V square "
                           "wave; all stages stay inside"),
                        opamp=amp.name, lo=f"{amp.vout_min:.3g}", hi=f"{amp.vout_max:.3g}", vcc=f"{amp.vcc:g}",
                        vee=f"{amp.vee:g}", step=f"{step_v:g}", clip=listing("; ", clip)))
    return out


def spice_notes(sp, verdict, expected_final_v: float) -> list:
    """What a SPICE run of a loop says beyond its figures: saturated stages,
    oscillation, latch-up, a disagreement no check explains.

    Parameters
    ----------
    sp : designer.pid.verify.SpiceRun
        The run.
    verdict : designer.pid.verify.Verdict
        Its comparison with the analytic loop.
    expected_final_v : float
        The settled output expected, volts.

    Returns
    -------
    list of str
        The notes.
    """
    out = []
    # each unit with its stage's name (a word of the catalogue: shown in the sheet's language)
    sat = [Message(N_("{opamp} {stage}"), opamp=v.opamp, stage=role) for role, v in sp.stages.items() if v.saturated]
    if sat:
        out.append(Message(N_("SPICE: op-amp output pinned at a rail: {units}"), units=Message.joined(", ", sat)))
    osc = sp.oscillation
    if osc.oscillating:
        out.append(Message(N_("SPICE: the loop is still oscillating at the end of the half period ({v} V peak to "
                              "peak)"), v=f"{osc.tail_p2p_v:.3g}"))
    if osc.latched:
        out.append(Message(N_("SPICE: the output is stuck at {v} V instead of settling near {final} V (latch-up)"),
                           v=f"{osc.tail_mean_v:.3g}", final=f"{expected_final_v:.3g}"))
    if verdict.unexplained:
        out.append(N_("SPICE and the analytic loop disagree and no check explains it (please report this)"))
    return out
