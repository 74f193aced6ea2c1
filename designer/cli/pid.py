"""Command-line layer of ``design-pid`` and ``analyze-pid``: parse, call
:func:`designer.pid.design.design_pid` / ``analyze_pid``, print. Any
:class:`~designer.core.errors.DesignError` becomes one line on stderr and exit status 2."""

from __future__ import annotations

import sys

from ..core.errors import DesignError
from ..core.ranges import help_range
from . import common
from .common import add_opamp_option, add_output_options, add_part_options, emit
from .pid_tolerance import add_monte_carlo, loop_monte_carlo, monte_carlo_settings, replay, replay_name
from .plant import cluster_ahead

__all__ = ["analyze_pid_main", "analyze_pid_parser", "design_pid_main", "pid_parser", "plant_capture_model"]

EPILOG = """examples:
  design-pid --plant-fc 3500 --plant-zeta 0.2
        the seed's plant, Ziegler-Nichols reaction curve done right (T from L, not from 0), LM741s
  design-pid --plant-fc 3500 --plant-zeta 0.2 --kp 45 --ti 43.215u --td 10.8037u
        the seed's final gains with LM741s: see what really happens (and why) in the checks
  design-pid --plant-fc 3500 --plant-zeta 0.2 --kp 45 --ti 43.215u --td 10.8037u --seed-parts
        ... built with the seed's own part list (V.13) instead of E-series parts
  design-pid --plant-fc 3500 --plant-zeta 0.2 --tuning optimize --target-overshoot 10
        gains that keep every LM741 out of saturation and within its slew rate for a 1 V step
  design-pid --plant-r1 820 --plant-r2 1k --plant-c1 10n --plant-c2 220n --tuning amigo --opamp TL072
  design-pid --plant-json reports/plant_fc3500_z0.2/result.json --tuning chr0 --json --no-sim
  design-pid --plant-topology mfb-lowpass --plant-part R1=10k R2=20k R3=6k8 C1=10n C2=100n
        a plant that is a filter section (any registered low-pass, or a design-filter result.json as --plant-json):
        designed on its model, its own circuit in the SPICE deck and on the sheet (an inverting one: action reversed)
  design-pid --plant-tf "K=2 tau=1m theta=200u" --tuning simc
        a plant known only as a model (FOPDT), SIMC's PI/PID, the model in the SPICE deck
  design-pid --plant-model models.json --tuning optimize --robust
        the best model of an `identify --json` output; gains minimising IAE with PM >= 45 deg, GM >= 6 dB,
        Ms <= 1.7 at every corner of the identified 95 % intervals
  design-pid --plant-capture motor.csv --plant-input 0:10 --tuning amigo
        identify the capture first (as `identify` does, same options), then design for its best model

Model plants (--plant-tf, --plant-model, --plant-capture): {forms}. Type them as key=value words separated by
spaces or commas, values in engineering notation with a decimal point (1.25, 124.6m, 200u, 1.5 ms).
Rules on the model each intends: zn, cohen-coon, chr0, chr20 (on the tangent of the model's own step),
amigo, simc (--simc-tauc, default theta; SOPDT form on an SOPDT, its series PID converted to Kp, Ti, Td),
imc (--imc-lambda); default: the first of amigo, simc, imc that applies. Every rule is listed on the sheet
with its margins, Ms, IAE and overshoot. The deck puts the model in ngspice as native integrators and a
matched transmission line for the dead time; the analytic loop uses the exact delay.

The controller (seed 001, Fig. 66): U1 difference amp (R15-R18), U2 unity inverter (R9, R10),
U3 differentiator (R12 + C3 in, R11 feedback), U4 integrator (R14 in, R13 || C4 feedback),
U5 summer (R6, R7, R8 in, R5 feedback), U6 final gain (R4 in, R3 feedback):
  Kp = R5 R3/(R6 R4),  Ti = R8 R14 C4/R6,  Td = R6 R11 C3/R7.
Rules: zn (on the reaction curve's tangent, as the seed), and on the least-squares FOPDT fit of the plant's
step: cohen-coon, chr0, chr20 (Chien-Hrones-Reswick set-point, 0 and 20 % overshoot), amigo, simc (a PI);
optimize. The build sheet lists every rule with the model it used. Values accept engineering notation
(43.215u, 4k7, 10n); each option's range is in its help line, and a plant from parts or --plant-json
is held to the same ranges (fn and zeta as --plant-fc/--plant-zeta) and must be stable.
Outputs: netlists/<name>.cir (runs alone with `ngspice -b`), reports/<name>/build-sheet.md/.html,
result.json and plots. Exit status: 0 done, 2 bad input (one line on stderr, nothing written),
3 simulator error."""


def _r(key: str) -> str:
    """The range of ``key`` for a --help line (argparse needs %% for %)."""
    return help_range(key).replace("%", "%%")


def pid_parser():
    """The ``design-pid`` command line.

    Returns
    -------
    argparse.ArgumentParser
        The parser of ``design-pid``'s options.
    """
    from ..core.process_text import FORMS_TEXT
    p = common.command_parser(
        "design-pid",
        "Tune an analog PID controller for a Sallen-Key plant, size its six op-amp stages from E-series parts, "
        "check them against the op-amp's bandwidth, slew rate and swing, and verify the whole closed loop "
        "(controller + plant circuit) in ngspice; or for a plant known only as a model (typed, identified "
        "from a capture, or an identify result).", EPILOG.replace("{forms}", FORMS_TEXT))
    _add_plant_options(p)
    t = p.add_argument_group("tuning")
    t.add_argument("--tuning", metavar="RULE",
                   help="zn (default for a Sallen-Key plant), cohen-coon, chr0, chr20, amigo, simc, optimize; "
                        "for a model plant also imc (default: the first of amigo, simc, imc that applies)")
    t.add_argument("--kp", help=f"explicit proportional gain {_r('kp')} (with --ti and --td)")
    t.add_argument("--ti", metavar="S", help=f"explicit integral time {_r('ti_s')} (e.g. 43.215u)")
    t.add_argument("--td", metavar="S", help=f"explicit derivative time {_r('td_s')}; 0 for a PI")
    t.add_argument("--target-overshoot", metavar="PCT",
                   help=f"--tuning optimize: largest overshoot {_r('target_overshoot_pct')}")
    t.add_argument("--target-settling", metavar="S",
                   help=f"--tuning optimize: largest 2 %% settling time {_r('target_settling_s')}")
    _add_model_tuning_options(t)
    t.add_argument("--rules-spice", action="store_true",
                   help="model plant: simulate every applicable rule's loop too, for the rule table's SPICE "
                        "overshoot (one more ngspice run per rule)")
    t.add_argument("--seed-parts", action="store_true",
                   help="use the seed's own controller parts (V.13, difference amp untrimmed) instead of sizing")
    s = p.add_argument_group("parts")
    add_part_options(s)
    s.add_argument("--f-integrator", metavar="HZ",
                   help=f"integrator leak corner 1/(2 pi R13 C4) {_r('f_integrator_hz')} (default fn/100)")
    s.add_argument("--f-differentiator", metavar="HZ",
                   help=f"derivative filter corner 1/(2 pi R12 C3) {_r('f_differentiator_hz')} (default 10 fn)")
    _add_signal_options(p)
    _add_capture_options(p)
    add_output_options(p, "pid_<tuning>_<opamp>_fn<fn>_z<zeta>")
    add_monte_carlo(p)
    return p


def _add_model_tuning_options(t):
    """Tuning options of a model plant (design-pid and analyze-pid)."""
    t.add_argument("--simc-tauc", metavar="S", help=f"SIMC's closed-loop time constant tau_c {_r('simc_tauc_s')} "
                                                     "(default theta, the dead time)")
    t.add_argument("--imc-lambda", metavar="S", help=f"IMC's closed-loop time constant lambda {_r('imc_lambda_s')} "
                                                      "(default max(0.25 theta, 0.2 tau))")
    t.add_argument("--min-pm", metavar="DEG", help=f"model plant: smallest phase margin {_r('min_phase_margin_deg')} "
                                                    "(default 45; the check, and optimize's constraint)")
    t.add_argument("--min-gm", metavar="DB", help=f"model plant: smallest gain margin {_r('min_gain_margin_db')} "
                                                   "(default 6)")
    t.add_argument("--max-ms", metavar="MS", help=f"model plant: largest maximum sensitivity Ms {_r('max_ms')} "
                                                   "(default 1.7)")
    t.add_argument("--robust", action="store_true",
                   help="model plant with 95 %% intervals (identify's least-squares fits): optimize keeps its "
                        "constraints at every corner of the interval box")


def _add_capture_options(p):
    """identify's options, for --plant-capture."""
    g = p.add_argument_group("capture (with --plant-capture; as identify's options, see identify --help)")
    g.add_argument("--step-time", metavar="T", help="when the input stepped, in seconds")
    g.add_argument("--step-amplitude", metavar="A", help="input step size in input units (either sign)")
    g.add_argument("--window", nargs=2, metavar=("T0", "T1"), help="use only the samples from T0 to T1 seconds")
    g.add_argument("--format", metavar="LAYOUT", default="auto", help="the capture's layout (default auto)")
    g.add_argument("--input-column", metavar="NAME|N", help="input column by name or number; 'none' ignores it")
    g.add_argument("--output-column", metavar="NAME|N", help="output column by name or number")
    from .identify import add_plain_columns_options
    add_plain_columns_options(g)
    g.add_argument("--methods", nargs="+", metavar="NAME", help="only these identification methods")
    g.add_argument("--no-refine", action="store_true", help="skip the least-squares fits (then no 95 %% intervals)")


def _add_plant_options(p):
    """The plant, one of the ways (design-pid and analyze-pid)."""
    g = p.add_argument_group("plant (one way: a Sallen-Key circuit, or a model)")
    g.add_argument("--plant-fc", metavar="HZ",
                   help=f"design the plant as design-plant does: natural frequency {_r('fc_hz')}")
    g.add_argument("--plant-zeta", metavar="Z", help=f"... and damping ratio {_r('zeta')}")
    for n, what, key in (("r1", "input resistor", "resistor_ohm"),
                         ("r2", "resistor to the non-inverting input", "resistor_ohm"),
                         ("c1", "non-inverting input to ground", "capacitor_f"),
                         ("c2", "feedback capacitor", "capacitor_f")):
        g.add_argument(f"--plant-{n}", metavar="VALUE", help=f"plant as built: {what} {_r(key)}")
    g.add_argument("--plant-gain", metavar="K",
                   help=f"plant gain K = 1 + R4/R3 with --plant-r1.. {_r('gain')} (default 1; R3 = 10k, "
                        "R4 = (K - 1) R3)")
    from ..filters.registry import REGISTRY
    lows = [n for n, t in REGISTRY.items() if t.kind == "lowpass"]
    g.add_argument("--plant-topology", metavar="NAME",
                   help="plant as built from one filter section, its circuit in the deck and on the sheet: "
                        f"{', '.join(lows)} (with --plant-part)")
    g.add_argument("--plant-part", nargs="+", action=common.ExtendList, metavar="REF=VALUE",
                   help=f"with --plant-topology: every part of the section, e.g. R1=10k C1=100n "
                        f"(resistors {_r('resistor_ohm')}, capacitors {_r('capacitor_f')})")
    g.add_argument("--plant-json", metavar="FILE",
                   help="a result.json written by design-plant or analyze-plant (the seed's plant: its 'built' "
                        "parts, checked against the same ranges; a --topology section: its section and parts), or "
                        "by design-filter (its stages as a cascade plant)")
    g.add_argument("--plant-tf", metavar="MODEL",
                   help="a model typed by hand, e.g. \"K=2 tau=1m theta=200u\" (forms below)")
    g.add_argument("--plant-model", metavar="FILE",
                   help="an identify or identify-freq --json output (its best valid model), or a design-plant "
                        "result.json read as its model")
    g.add_argument("--plant-method", metavar="NAME",
                   help="with --plant-model/--plant-capture: this method's model instead of the best "
                        "(e.g. alfaro, least-squares:overdamped)")
    g.add_argument("--plant-capture", metavar="CSV",
                   help="a step capture (any layout identify reads) or frequency table: identified first")
    g.add_argument("--plant-input", metavar="LO:HI",
                   help=f"model plant: the input range the plant accepts, volts, each {_r('plant_voltage_v')} "
                        "(e.g. 0:10, an actuator's); the controller's output is checked against it")
    g.add_argument("--plant-output", metavar="LO:HI", help="model plant: the output range it can deliver, volts")


def _add_signal_options(p):
    """The op-amps and the reference square wave (design-pid and analyze-pid)."""
    o = p.add_argument_group("op-amps and test signal")
    add_opamp_option(o)
    o.add_argument("--step", default="1", metavar="V",
                   help=f"reference square wave 0 -> V volts {_r('step_v')} (default 1)")
    o.add_argument("--edge", default="100n", metavar="S",
                   help=f"rise/fall time of the reference {_r('edge_s')} (default 100n, a function generator)")
    o.add_argument("--square-freq", metavar="HZ",
                   help=f"reference frequency {_r('square_hz')} (default: half period = 1.5x the closed "
                        "loop's settling time, rounded)")
    o.add_argument("--package", choices=("single", "dual", "quad"), metavar="KIND",
                   help="how the build sheet puts the seven op-amps in packages: single (one per DIP-8), dual "
                        "(DIP-8: TL072, LM358, NE5532) or quad (DIP-14: TL074, LM324); default: the op-amp's "
                        "first (LM741 single, the others dual)")


#: the spec's parameters set from options of the same meaning (their options: FLAGS)
MODEL_PARAMS = ("plant_tf", "plant_model", "plant_method", "plant_input", "plant_output", "simc_tauc_s",
                "imc_lambda_s", "min_phase_margin_deg", "min_gain_margin_db", "max_ms", "robust")
#: a plant circuit of any registered topology
CIRCUIT_PARAMS = ("plant_topology", "plant_values")
SPEC_PARAMS = CIRCUIT_PARAMS + ("plant_fc_hz", "plant_zeta", "plant_json", "tuning", "kp", "ti_s", "td_s", "opamp", "step_v", "edge_s",
               "r_series", "c_series", "r_min", "r_max", "c_min", "c_max", "target_overshoot_pct",
               "target_settling_s", "f_integrator_hz", "f_differentiator_hz", "square_hz") + MODEL_PARAMS
#: the Sallen-Key plant as built, part by part (designer.pid.spec.pid_spec makes its parts)
PLANT_PARTS = ("plant_r1", "plant_r2", "plant_c1", "plant_c2", "plant_gain")


def _typed(args, params) -> dict:
    return {p: getattr(args, common.FLAGS[p][2:].replace("-", "_")) for p in params}


def _build_spec(args):
    """The spec from the options as typed: :func:`designer.pid.spec.pid_spec` parses and checks them (the one
    mapping and validation, the web page's too)."""
    from ..pid.spec import pid_spec
    typed = _typed(args, SPEC_PARAMS + PLANT_PARTS)
    process = _captured_model(args, typed)
    return pid_spec({**typed, "seed_parts": args.seed_parts, "package": args.package, "plant_process": process})


def _captured_model(args, typed):
    """--plant-capture: :func:`plant_capture_model` of the capture and identify's options (refused without
    it); None without either."""
    from .identify import capture_params
    params = {"capture": args.plant_capture, **capture_params(args)}
    return plant_capture_model(params, typed.pop("plant_method") if args.plant_capture is not None else None)


def plant_capture_model(params: dict, method: str | None = None):
    """A PID plant from a capture: the capture identified as ``identify`` does (a frequency table as
    ``identify-freq``: :func:`designer.identify.spec.identify_file` of
    :func:`~designer.identify.spec.identify_spec`), its best valid model across every route (or
    ``method``'s); what design-pid ``--plant-capture`` and the PID page's capture tune for.

    Parameters
    ----------
    params : dict
        :func:`~designer.identify.spec.identify_spec`'s plain parameters; ``capture`` None: no capture
        (then any other given is refused).
    method : str, optional
        The identification method whose model to take instead of the best (``plant_method``).

    Returns
    -------
    ProcessModel or None
        The model (its source names the capture's file), or None without a capture.

    Raises
    ------
    DesignError
        One line naming the parameter at fault (``{name}`` markers of a ParamError).
    """
    import os

    from ..core.errors import ParamError
    from ..core.fileio import shown
    from ..identify.spec import identify_file, identify_spec
    from ..pid.plant_source import model_from_result
    unset = {"fmt": "auto", "refine": True}
    if params.get("capture") is None:
        given = [k for k, v in params.items() if k != "capture" and v is not None and v != unset.get(k)]
        if given:
            raise ParamError("{%s} is an option of {plant_capture} (identify's), and no capture is given" % given[0],
                             (given[0], "plant_capture"))
        return None
    result = identify_file(identify_spec(params))
    best = getattr(getattr(result, "assessment", None), "best_candidate", None)
    if method is None and best is not None and not getattr(result, "refused", ""):
        # the best validation fit across every route (identify's "validation"), named with its capture
        import dataclasses
        return dataclasses.replace(best.model, source=f"{best.model.source} ({os.path.basename(params['capture'])})")
    where = f"plant_capture {shown(params['capture'])}"
    try:
        return model_from_result(result.to_dict(), method, name=where)
    except DesignError as exc:
        raise DesignError(str(exc).replace(f"plant model {where}", where), param="plant_capture") from None


def _early(result, args):
    """The pictures that need no SPICE, started in the sheet's language (``--lang``: the run enters it only to
    write the files)."""
    from ..core.i18n import language
    from ..pid.report import draw_early
    with language(getattr(args, "lang", None)):
        return draw_early(result)


def _run(args) -> int:
    from ..pid.design import design_pid
    from ..pid.report import summary_text, write_outputs
    from ..pid.spec import default_name
    spec = _build_spec(args)
    mc, i = monte_carlo_settings(args, spec)
    if spec.process is not None:
        common.check_output(args, replay_name(args.name if args.name is not None else "pid_model", i))
        if i is not None:    # the design is the draw's nominal; the build's own run is the simulation
            result = design_pid(spec, simulate=False, simulator=args.simulator)
            name = args.name or default_name(spec, result)
            return emit(replay(spec, result, args, mc, i), args, replay_name(name, i), write_outputs,
                        summary_text)
        early = []   # the pictures that need no SPICE, drawn in the renderer while ngspice runs
        with cluster_ahead(args):
            result = design_pid(spec, simulate=not args.no_sim, simulator=args.simulator,
                                rules_spice=args.rules_spice,
                                before_spice=None if args.no_files else lambda r: early.append(_early(r, args)))
            result = loop_monte_carlo(result, args, mc)
        return emit(result, args, args.name or default_name(spec, result),
                    lambda *a: write_outputs(*a, early=early[0] if early else None), summary_text)
    # the default name needs the plant as built; its fixed start stands in for it in the check
    common.check_output(args, replay_name(args.name if args.name is not None else f"pid_{spec.method}", i))
    if i is not None:
        result = design_pid(spec, simulate=False, simulator=args.simulator)
        name = args.name or default_name(spec, result)
        return emit(replay(spec, result, args, mc, i), args, replay_name(name, i), write_outputs,
                    summary_text)
    with cluster_ahead(args):
        result = loop_monte_carlo(design_pid(spec, simulate=not args.no_sim, simulator=args.simulator), args, mc)
    name = args.name or default_name(spec, result)
    return emit(result, args, name, write_outputs, summary_text)


def design_pid_main(argv=None) -> int:
    """Console entry point ``design-pid``.

    Parameters
    ----------
    argv : list of str, optional
        The arguments; None reads ``sys.argv[1:]``.

    Returns
    -------
    int
        The exit status (see :func:`~designer.cli.common.run_cli`).
    """
    return common.run_cli("design-pid", pid_parser, _run, argv)


ANALYZE_EPILOG = """examples:
  analyze-pid --plant-fc 3500 --plant-zeta 0.2 --parts-json reports/pid_zn_lm741_fc3500_z0.2/result.json
        a controller as design-pid built it, re-checked (e.g. with --opamp TL072)
  analyze-pid --plant-r1 1k6 --plant-r2 3k9 --plant-c1 3n3 --plant-c2 100n \\
      --r3 12k --r4 1k8 --r5 22k --r6 3k3 --r7 15k --r8 1k2 --r9 10k --r10 10k --r11 10k --r12 1k \\
      --r13 27k --r14 2k7 --r15 10k --r16 10k --r17 10k --r18 10k --c3 4n7 --c4 47n
        the controller on the bench, part by part (leave out --r7 --r11 --r12 --c3 for a PI)
  analyze-pid ... --kp 45 --ti 43.215u --td 10.8037u
        ... and how far its parts are from the gains they were meant to give

The same topology, checks, closed-loop analysis, SPICE verification and build sheet as design-pid
(see design-pid --help), for parts already chosen: Kp = R5 R3/(R6 R4), Ti = R8 R14 C4/R6,
Td = R6 R11 C3/R7. Without --kp/--ti/--td the parts' own gains are the tuning (method as-built) and
the accuracy and part-bound checks are left out. Exit status: 0 done, 1 a check or the SPICE agreement
failed (with --fail-on-check), 2 bad input (one line on stderr, nothing written), 3 simulator error."""


def analyze_pid_parser():
    """The ``analyze-pid`` command line.

    Returns
    -------
    argparse.ArgumentParser
        The parser of ``analyze-pid``'s options.
    """
    p = common.command_parser(
        "analyze-pid",
        "Analyse the seed's six-op-amp PID controller as built from its parts, on its plant: the gains the parts "
        "give, the stage checks, the closed loop with the op-amp poles, and ngspice.", ANALYZE_EPILOG)
    _add_plant_options(p)
    c = p.add_argument_group("controller as built (every part, or --parts-json)")
    for i in range(3, 19):
        c.add_argument(f"--r{i}", metavar="OHM", help=f"R{i} {_r('resistor_ohm')}" if i == 3 else None)
    c.add_argument("--c3", metavar="F", help=f"differentiator capacitor {_r('capacitor_f')}")
    c.add_argument("--c4", metavar="F", help=f"integrator capacitor {_r('capacitor_f')}")
    c.add_argument("--parts-json", metavar="FILE",
                   help="a result.json of design-pid or analyze-pid: its 'components' (R3_ohm .. C4_f)")
    t = p.add_argument_group("gains the parts should give (optional, all three)")
    t.add_argument("--kp", help=f"proportional gain {_r('kp')}")
    t.add_argument("--ti", metavar="S", help=f"integral time {_r('ti_s')}")
    t.add_argument("--td", metavar="S", help=f"derivative time {_r('td_s')}; 0 for a PI")
    _add_model_tuning_options(t)
    _add_signal_options(p)
    _add_capture_options(p)
    add_output_options(p, "pid_as-built_<opamp>_fn<fn>_z<zeta>")
    add_monte_carlo(p)
    return p


def _analyze(args) -> int:
    from ..pid.design import analyze_pid
    from ..pid.report import summary_text, write_outputs
    from ..pid.spec import CONTROLLER_FIELDS, analyzed_name, controller_as_built, pid_spec
    parts = controller_as_built({**{k: getattr(args, k) for k in CONTROLLER_FIELDS},
                                 "controller_json": args.parts_json})
    typed = _typed(args, ANALYZE_PARAMS + PLANT_PARTS)
    process = _captured_model(args, typed)
    spec = pid_spec({**typed, "controller_parts": parts, "package": args.package, "plant_process": process})
    mc, i = monte_carlo_settings(args, spec)
    common.check_output(args, replay_name(args.name if args.name is not None else "pid_as-built", i))
    if i is not None:    # the parts as given are the draw's nominal; the build's own run is the simulation
        result = analyze_pid(spec, simulate=False, simulator=args.simulator)
        return emit(replay(spec, result, args, mc, i), args,
                    replay_name(args.name or analyzed_name(spec, result), i), write_outputs, summary_text)
    with cluster_ahead(args):
        result = loop_monte_carlo(analyze_pid(spec, simulate=not args.no_sim, simulator=args.simulator), args, mc)
    return emit(result, args, args.name or analyzed_name(spec, result), write_outputs, summary_text)


#: the spec's parameters analyze-pid sets from options of the same meaning
ANALYZE_PARAMS = CIRCUIT_PARAMS + ("plant_fc_hz", "plant_zeta", "plant_json", "kp", "ti_s", "td_s", "opamp", "step_v", "edge_s",
                  "square_hz") + MODEL_PARAMS


def analyze_pid_main(argv=None) -> int:
    """Console entry point ``analyze-pid``.

    Parameters
    ----------
    argv : list of str, optional
        The arguments; None reads ``sys.argv[1:]``.

    Returns
    -------
    int
        The exit status (see :func:`~designer.cli.common.run_cli`).
    """
    return common.run_cli("analyze-pid", analyze_pid_parser, _analyze, argv)


if __name__ == "__main__":  # pragma: no cover
    sys.exit(design_pid_main())
