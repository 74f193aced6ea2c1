"""Command-line layer of ``design-pid``: parse, call :func:`designer.pid.design.design_pid`,
print. Any :class:`~designer.core.errors.DesignError` becomes one line on stderr and exit status 2."""

from __future__ import annotations

import argparse
import sys

from .. import __version__
from ..core.errors import DesignError
from ..core.ranges import help_range
from . import common
from .common import OneLineParser, add_opamp_option, add_output_options, add_part_options, emit

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


def _parser():
    p = OneLineParser(
        prog="design-pid",
        description="Tune an analog PID controller for a Sallen-Key plant, size its six op-amp stages from "
                    "E-series parts, check them against the op-amp's bandwidth, slew rate and swing, and verify "
                    "the whole closed loop (controller + plant circuit) in ngspice.",
        epilog=EPILOG, formatter_class=argparse.RawDescriptionHelpFormatter)
    p.add_argument("--version", action="version", version=f"%(prog)s {__version__}")
    g = p.add_argument_group("plant (one of three ways)")
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
    g.add_argument("--plant-json", metavar="FILE",
                   help="a result.json written by design-plant or analyze-plant (its 'built' parts, checked "
                        "against the same ranges)")
    t = p.add_argument_group("tuning")
    t.add_argument("--tuning", metavar="RULE",
                   help="zn (default), cohen-coon, chr0, chr20, amigo, simc, optimize")
    t.add_argument("--kp", help=f"explicit proportional gain {_r('kp')} (with --ti and --td)")
    t.add_argument("--ti", metavar="S", help=f"explicit integral time {_r('ti_s')} (e.g. 43.215u)")
    t.add_argument("--td", metavar="S", help=f"explicit derivative time {_r('td_s')}; 0 for a PI")
    t.add_argument("--target-overshoot", metavar="PCT",
                   help=f"--tuning optimize: largest overshoot {_r('target_overshoot_pct')}")
    t.add_argument("--target-settling", metavar="S",
                   help=f"--tuning optimize: largest 2 %% settling time {_r('target_settling_s')}")
    t.add_argument("--seed-parts", action="store_true",
                   help="use the seed's own controller parts (V.13, difference amp untrimmed) instead of sizing")
    s = p.add_argument_group("parts")
    add_part_options(s)
    s.add_argument("--f-integrator", metavar="HZ",
                   help=f"integrator leak corner 1/(2 pi R13 C4) {_r('f_integrator_hz')} (default fn/100)")
    s.add_argument("--f-differentiator", metavar="HZ",
                   help=f"derivative filter corner 1/(2 pi R12 C3) {_r('f_differentiator_hz')} (default 10 fn)")
    o = p.add_argument_group("op-amps and test signal")
    add_opamp_option(o)
    o.add_argument("--step", default="1", metavar="V",
                   help=f"reference square wave 0 -> V volts {_r('step_v')} (default 1)")
    o.add_argument("--edge", default="100n", metavar="S",
                   help=f"rise/fall time of the reference {_r('edge_s')} (default 100n, a function generator)")
    o.add_argument("--square-freq", metavar="HZ",
                   help=f"reference frequency {_r('square_hz')} (default: half period = 1.5x the closed "
                        "loop's settling time, rounded)")
    add_output_options(p, "pid_<tuning>_<opamp>_fn<fn>_z<zeta>")
    return p


#: the spec's parameters set from options of the same meaning (their options: FLAGS)
SPEC_PARAMS = ("plant_fc_hz", "plant_zeta", "plant_json", "tuning", "kp", "ti_s", "td_s", "opamp", "step_v", "edge_s",
               "r_series", "c_series", "r_min", "r_max", "c_min", "c_max", "target_overshoot_pct",
               "target_settling_s", "f_integrator_hz", "f_differentiator_hz", "square_hz")


def _build_spec(args):
    """The spec from the options as typed: the spec parses and checks them (the one validation)."""
    from ..pid.blocks import seed_parts
    from ..pid.spec import PidSpec
    from ..plant.sallenkey import SallenKeyParts
    plant_parts = None
    given = [args.plant_r1, args.plant_r2, args.plant_c1, args.plant_c2]
    if any(v is not None for v in given):
        if not all(v is not None for v in given):
            raise DesignError("--plant-r1, --plant-r2, --plant-c1 and --plant-c2 go together")
        plant_parts = SallenKeyParts(*given, args.plant_gain)
    elif args.plant_gain is not None:
        raise DesignError("--plant-gain goes with --plant-r1..--plant-c2")
    typed = {p: getattr(args, common.FLAGS[p][2:].replace("-", "_")) for p in SPEC_PARAMS}
    return PidSpec(plant_parts=plant_parts, controller_parts=seed_parts() if args.seed_parts else None, **typed)


def _default_name(spec, fn_hz, zeta) -> str:
    extra = "_seedparts" if spec.controller_parts is not None else ""
    return f"pid_{spec.method}_{spec.opamp.lower()}_fn{fn_hz:.5g}_z{zeta:.3g}{extra}"


def _run(args) -> int:
    from ..pid.design import design_pid
    from ..pid.report import summary_text, write_outputs
    spec = _build_spec(args)
    # the default name needs the plant as built; its fixed start stands in for it in the check
    common.check_output(args, args.name if args.name is not None else f"pid_{spec.method}")
    result = design_pid(spec, simulate=not args.no_sim, simulator=args.simulator)
    name = args.name or _default_name(spec, result.plant.fn_hz, result.plant.zeta)
    return emit(result, args, name, write_outputs, summary_text)


def design_pid_main(argv=None) -> int:
    return common.run_cli("design-pid", _parser, _run, argv)


if __name__ == "__main__":  # pragma: no cover
    sys.exit(design_pid_main())
