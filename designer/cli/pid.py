"""Command-line layer of ``design-pid``: parse, call :func:`designer.pid.design.design_pid`,
print. Any :class:`~designer.errors.DesignError` becomes one line on stderr and exit status 2."""

from __future__ import annotations

import argparse
import sys

from .. import __version__
from ..core import opamps
from ..core.errors import DesignError
from ..core.ranges import help_range, parse_in_range
from .common import OneLineParser, add_part_options, check_name, emit, optional, part_options, run_cli

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
    o.add_argument("--opamp", default="LM741", metavar="NAME",
                   help=f"{', '.join(opamps.names())} (default LM741, as the seed's bench)")
    o.add_argument("--step", default="1", metavar="V",
                   help=f"reference square wave 0 -> V volts {_r('step_v')} (default 1)")
    o.add_argument("--edge", default="100n", metavar="S",
                   help=f"rise/fall time of the reference {_r('edge_s')} (default 100n, a function generator)")
    o.add_argument("--square-freq", metavar="HZ",
                   help=f"reference frequency {_r('square_hz')} (default: half period = 1.5x the closed "
                        "loop's settling time, rounded)")
    out = p.add_argument_group("output")
    out.add_argument("--out", default=".", metavar="DIR", help="write netlists/ and reports/ under DIR (default .)")
    out.add_argument("--name", help="design name for the files (default pid_<tuning>_<opamp>_fn<fn>_z<zeta>)")
    out.add_argument("--json", action="store_true", help="print one JSON object on stdout instead of the summary")
    out.add_argument("--no-files", action="store_true", help="write no netlist or report files")
    out.add_argument("--no-sim", action="store_true", help="skip ngspice (analytic figures only)")
    out.add_argument("--simulator", default="pyspice", choices=("pyspice", "ngspice-cli"),
                     help="pyspice: ngspice shared library (default); ngspice-cli: `ngspice -b` subprocess")
    return p


def _build_spec(args):
    from ..pid.blocks import seed_parts
    from ..pid.design import PidSpec
    from ..plant.sallenkey import SallenKeyParts
    plant_parts = None
    names = ("r1", "r2", "c1", "c2")
    given = [getattr(args, f"plant_{n}") for n in names]
    if any(v is not None for v in given):
        if not all(v is not None for v in given):
            raise DesignError("--plant-r1, --plant-r2, --plant-c1 and --plant-c2 go together")
        keys = ("resistor_ohm", "resistor_ohm", "capacitor_f", "capacitor_f")
        vals = [parse_in_range(v, f"--plant-{n}", k) for v, n, k in zip(given, names, keys)]
        gain = 1.0 if args.plant_gain is None else parse_in_range(args.plant_gain, "--plant-gain", "gain")
        # R3/R4 derived from K by the one plant validation (check_parts, in PidSpec.validate)
        plant_parts = SallenKeyParts(*vals, gain)
    elif args.plant_gain is not None:
        raise DesignError("--plant-gain goes with --plant-r1..--plant-c2")
    if args.plant_zeta is not None and args.plant_fc is None:
        raise DesignError("--plant-zeta needs --plant-fc")
    tuning = None if args.tuning is None else args.tuning.strip().lower()
    spec = PidSpec(
        plant_fc_hz=optional(args.plant_fc, "--plant-fc", "fc_hz"),
        plant_zeta=optional(args.plant_zeta, "--plant-zeta", "zeta"),
        plant_parts=plant_parts, plant_json=args.plant_json, tuning=tuning,
        kp=optional(args.kp, "--kp", "kp"), ti_s=optional(args.ti, "--ti", "ti_s"),
        td_s=optional(args.td, "--td", "td_s"),
        opamp=args.opamp, step_v=parse_in_range(args.step, "--step", "step_v"),
        edge_s=parse_in_range(args.edge, "--edge", "edge_s"),
        **part_options(args),
        target_overshoot_pct=optional(args.target_overshoot, "--target-overshoot", "target_overshoot_pct"),
        target_settling_s=optional(args.target_settling, "--target-settling", "target_settling_s"),
        f_integrator_hz=optional(args.f_integrator, "--f-integrator", "f_integrator_hz"),
        f_differentiator_hz=optional(args.f_differentiator, "--f-differentiator", "f_differentiator_hz"),
        square_hz=optional(args.square_freq, "--square-freq", "square_hz"),
        controller_parts=seed_parts() if args.seed_parts else None)
    spec.validate()
    return spec


def _default_name(spec, fn_hz, zeta) -> str:
    method = "explicit" if spec.kp is not None else (spec.tuning or "zn")
    extra = "_seedparts" if spec.controller_parts is not None else ""
    return f"pid_{method}_{spec.opamp.lower()}_fn{fn_hz:.5g}_z{zeta:.3g}{extra}"


def _run(args) -> int:
    from ..pid.design import design_pid
    from ..pid.report import summary_text, write_outputs
    spec = _build_spec(args)
    if args.name is not None:
        check_name(args.name)
    if not args.no_files:
        from ..core.fileio import check_can_create
        check_can_create(args.out, ("netlists", "reports"))  # fail before the work, creating nothing
    result = design_pid(spec, simulate=not args.no_sim, simulator=args.simulator)
    name = args.name or _default_name(spec, result.plant.fn_hz, result.plant.zeta)
    return emit(result, args, name, write_outputs, summary_text)


def design_pid_main(argv=None) -> int:
    return run_cli("design-pid", _parser, _run, argv)


if __name__ == "__main__":  # pragma: no cover
    sys.exit(design_pid_main())
