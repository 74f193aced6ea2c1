"""Command-line layer: ``design-plant`` and ``analyze-plant``.

Thin: parse, call the library, print. Any :class:`DesignError` becomes one
line on stderr and exit status 2.
"""

from __future__ import annotations

import argparse
import json
import os
import re
import sys

from . import __version__, opamps
from .eseries import SERIES
from .errors import DesignError
from .ranges import help_range, parse_in_range


class OneLineParser(argparse.ArgumentParser):
    """argparse, but a usage mistake is one line (and exit status 2)."""

    def error(self, message):
        raise DesignError(f"{message} (see {self.prog} --help)")


def print_output(text: str, end: str = "\n") -> None:
    """Print; a pipe closed by the reader (``| head``) is their choice, not an error."""
    try:
        print(text, end=end)
        sys.stdout.flush()
    except BrokenPipeError:
        _silence_stdout()


def _silence_stdout() -> None:
    # the interpreter flushes stdout again at exit: point it at /dev/null so that
    # a reader who stopped early (| head) gets no "Exception ignored" message
    try:
        os.dup2(os.open(os.devnull, os.O_WRONLY), sys.stdout.fileno())
    except (OSError, ValueError):
        pass


def run_cli(prog: str, build_parser, action, argv=None) -> int:
    """Run ``action(args)`` with the one-line error convention; returns the exit status:
    0 done, 1 a check failed (when asked), 2 bad input or usage, 3 simulator error,
    130 interrupted. Every failure is one line on stderr, never a traceback."""
    from .errors import EXIT_BAD_INPUT, EXIT_INTERRUPTED, EXIT_SIMULATOR, SimulatorError
    try:
        parser = build_parser()
        args = parser.parse_args(argv)
        return action(args) or 0
    except SimulatorError as exc:
        _fail(prog, f"simulator error: {exc}")
        return EXIT_SIMULATOR
    except DesignError as exc:
        _fail(prog, str(exc))
        return EXIT_BAD_INPUT
    except BrokenPipeError:
        _silence_stdout()
        return 0
    except KeyboardInterrupt:
        _fail(prog, "interrupted")
        return EXIT_INTERRUPTED
    except MemoryError:
        _fail(prog, "out of memory: the input is too large for this machine")
        return EXIT_BAD_INPUT
    except OSError as exc:   # a file system problem no check caught earlier
        where = f" {exc.filename!r}" if getattr(exc, "filename", None) else ""
        _fail(prog, f"cannot read or write{where}: {exc.strerror or exc}")
        return EXIT_BAD_INPUT


def _fail(prog: str, message: str) -> None:
    line = " ".join(str(message).split())   # one line, whatever the message holds
    try:
        print(f"{prog}: error: {line}", file=sys.stderr)
    except OSError:
        pass


def add_part_options(group):
    """E-series and value bounds for the parts (design-plant and design-pid)."""
    group.add_argument("--r-series", default="E24", help=f"resistor series: {', '.join(SERIES)} (default E24)")
    group.add_argument("--c-series", default="E12", help="capacitor series (default E12)")
    group.add_argument("--r-min", default="1k", help=f"smallest resistor (default 1k) {help_range('resistor_ohm')}")
    group.add_argument("--r-max", default="1M", help=f"largest resistor (default 1M) {help_range('resistor_ohm')}")
    group.add_argument("--c-min", default="1n", help=f"smallest capacitor (default 1n) {help_range('capacitor_f')}")
    group.add_argument("--c-max", default="10u", help=f"largest capacitor (default 10u) {help_range('capacitor_f')}")


def part_options(args) -> dict:
    """The parsed :func:`add_part_options`, as spec keyword arguments."""
    keys = {"r_min": "resistor_ohm", "r_max": "resistor_ohm", "c_min": "capacitor_f", "c_max": "capacitor_f"}
    return {"r_series": args.r_series, "c_series": args.c_series,
            **{k: parse_in_range(getattr(args, k), f"--{k.replace('_', '-')}", key) for k, key in keys.items()}}


def optional(text, name: str, key: str):
    """:func:`parse_in_range`, or None for an option not given."""
    return None if text is None else parse_in_range(text, name, key)


def _common_output(p):
    g = p.add_argument_group("output")
    g.add_argument("--out", default=".", metavar="DIR",
                   help="write netlists/<name>.cir and reports/<name>/ under DIR (default: current directory)")
    g.add_argument("--name", help="design name used for the files: letters, digits and . _ - + = , @ "
                                   "(default from the figures, e.g. plant_fc3500_z0.2)")
    g.add_argument("--json", action="store_true", help="print one JSON object on stdout instead of the summary")
    g.add_argument("--no-files", action="store_true", help="do not write the netlist and report files")
    s = p.add_argument_group("simulation")
    s.add_argument("--no-sim", action="store_true", help="skip the ngspice run (analytic figures only)")
    s.add_argument("--simulator", default="pyspice", choices=("pyspice", "ngspice-cli"),
                   help="pyspice: ngspice shared library via PySpice (default); "
                        "ngspice-cli: `ngspice -b` subprocess")
    s.add_argument("--opamp", default="LM741", metavar="NAME",
                   help=f"op-amp model: {', '.join(opamps.names())} (default LM741, as the seed's bench)")
    s.add_argument("--amplitude", default="2", metavar="V",
                   help="bench square wave goes 0 -> V volts (default 2, as the seed's bench test) "
                        + help_range("amplitude_v"))
    s.add_argument("--square-freq", metavar="HZ",
                   help="bench square-wave frequency (default: a round value whose half period is "
                        "1.5x the 2 %% settling time; 330 Hz for the seed's plant) " + help_range("square_hz"))


def _design_parser():
    p = OneLineParser(
        prog="design-plant",
        description="Design a unity-gain (or gain K) Sallen-Key low-pass that realises the second-order plant "
                    "T(s) = K wn^2 / (s^2 + 2 zeta wn s + wn^2), pick all four parts jointly from E-series values, "
                    "and verify it in ngspice. Values accept engineering notation: 4k7, 820, 10n, 2u2, 3.5k.",
        epilog="""examples:
  design-plant --fc 3500 --zeta 0.2                  the seed's plant, E24 resistors, E12 capacitors
  design-plant --fc 3500 --zeta 0.2 --r 1k --c 10n   the seed's procedure: fix R and C, solve m and n
  design-plant --fc 1k --zeta 0.05 --gain 2          low damping needs a gain K > 1 (C2/C1 >= 1/zeta^2 at K = 1)
  design-plant --fc 20k --zeta 0.5 --opamp LM358 --compensate-gbw
  design-plant --fc 3500 --zeta 0.2 --json --no-sim

Outputs: netlists/<name>.cir (run it alone with `ngspice -b`), reports/<name>/build-sheet.md and .html,
result.json, step.png, bode.png. Exit status 2 on bad input.""",
        formatter_class=argparse.RawDescriptionHelpFormatter)
    p.add_argument("--version", action="version", version=f"%(prog)s {__version__}")
    t = p.add_argument_group("target")
    t.add_argument("--fc", required=True, metavar="HZ",
                   help=f"natural frequency fn = wn / 2 pi, Hz (e.g. 3500, 3.5k) {help_range('fc_hz')}")
    t.add_argument("--zeta", required=True, metavar="Z",
                   help=f"damping ratio (>= 1 is overdamped) {help_range('zeta')}")
    t.add_argument("--gain", default="1", metavar="K",
                   help=f"DC gain K = 1 + R4/R3 (default 1: follower) {help_range('gain')}")
    t.add_argument("--compensate-gbw", action="store_true",
                   help="pre-distort the targets so the circuit lands on them with the op-amp's finite GBW")
    sel = p.add_argument_group("parts")
    sel.add_argument("--r", metavar="OHM", help="the seed's procedure: fix R (R2 = R, R1 = m R) ... "
                                                "(resistors: " + help_range("resistor_ohm")[1:])
    sel.add_argument("--c", metavar="F", help="... and C (C1 = C, C2 = n C), solve m and n "
                                              "(capacitors: " + help_range("capacitor_f")[1:])
    add_part_options(sel)
    sel.add_argument("--alternatives", default="5",
                     help=f"how many best combinations to list (default 5) {help_range('alternatives')}")
    _common_output(p)
    return p


def _design(args) -> int:
    from .plant import PlantSpec, design_plant
    spec = PlantSpec(
        fc_hz=parse_in_range(args.fc, "--fc", "fc_hz"), zeta=parse_in_range(args.zeta, "--zeta", "zeta"),
        gain=parse_in_range(args.gain, "--gain", "gain"),
        **part_options(args),
        r=optional(args.r, "--r", "resistor_ohm"), c=optional(args.c, "--c", "capacitor_f"),
        opamp=args.opamp, compensate_gbw=args.compensate_gbw,
        amplitude_v=parse_in_range(args.amplitude, "--amplitude", "amplitude_v"),
        square_hz=optional(args.square_freq, "--square-freq", "square_hz"),
        alternatives=_count(args.alternatives))
    spec.validate()
    name = args.name if args.name is not None else (
        f"plant_fc{spec.fc_hz:g}_z{spec.zeta:g}" + ("" if spec.gain == 1 else f"_k{spec.gain:g}"))
    check_name(name)
    if not args.no_files:
        from .fileio import check_can_create
        check_can_create(args.out, ("netlists", "reports"))  # fail before the work, not after
    result = design_plant(spec, simulate=not args.no_sim, simulator=args.simulator)
    return _emit(result, args, name)


def _count(text) -> int:
    try:
        n = int(str(text).strip())
    except ValueError:
        raise DesignError(f"--alternatives must be a whole number from 1 to 50, got {text!r}") from None
    if not 1 <= n <= 50:
        raise DesignError(f"--alternatives must be a whole number from 1 to 50, got {text!r}")
    return n


_NAME = re.compile(r"^[A-Za-z0-9_+=,@-][A-Za-z0-9._+=,@-]{0,119}$")


def check_name(name) -> str:
    """A design name is a plain file name: letters, digits and ``. _ - + = , @``, not
    starting with '.', at most 120 characters (it names a folder and a netlist)."""
    if not _NAME.match(name or ""):
        what = "must not be empty" if not name else f"{name[:40]!r} is not a plain file name"
        raise DesignError(f"--name {what}: use letters, digits and . _ - + = , @ (not starting with '.', "
                          "at most 120 characters)")
    return name


def _emit(result, args, name) -> int:
    from .plant_report import summary_text, write_outputs
    return emit(result, args, name, write_outputs, summary_text)


def emit(result, args, name, write_outputs, summary_text) -> int:
    """Write the files (unless --no-files), then print JSON or the summary and the file list."""
    if not args.no_files:
        write_outputs(result, args.out, name)
    if args.json:
        print_output(json.dumps(result.to_dict(), indent=2))
    else:
        text = summary_text(result)
        if result.files:
            text += "\nFiles:\n" + "".join(
                f"  {key}: {', '.join(path) if isinstance(path, list) else path}\n"
                for key, path in result.files.items())
        print_output(text, end="")
    return 0


def _analyze_parser():
    p = OneLineParser(
        prog="analyze-plant",
        description="Analyse a Sallen-Key low-pass as built from its parts: fn, zeta and Q it really gives, step "
                    "metrics with the op-amp model, tolerance band, sensitivity, and an ngspice check.",
        epilog="""examples:
  analyze-plant --r1 820 --r2 1k --c1 10n --c2 220n                 the seed's rounded parts
  analyze-plant --r1 820 --r2 1k --c1 10n --c2 220n --fc 3500 --zeta 0.2   errors against the seed's target
  analyze-plant --r1 10k --r2 10k --c1 10n --c2 10n --gain 2.5      equal-component design with gain
  analyze-plant --r1 10k --r2 10k --c1 10n --c2 10n --r3 10k --r4 15k  gain from its resistors""",
        formatter_class=argparse.RawDescriptionHelpFormatter)
    p.add_argument("--version", action="version", version=f"%(prog)s {__version__}")
    g = p.add_argument_group("parts")
    for n, what, key in (("r1", "input resistor, ohms", "resistor_ohm"),
                         ("r2", "resistor to the non-inverting input, ohms", "resistor_ohm"),
                         ("c1", "non-inverting input to ground, farads", "capacitor_f"),
                         ("c2", "feedback capacitor, farads", "capacitor_f")):
        g.add_argument(f"--{n}", required=True, help=f"{what} {help_range(key)}")
    g.add_argument("--gain", default=None, metavar="K", help=f"gain K = 1 + R4/R3 (default 1) {help_range('gain')}")
    g.add_argument("--r3", help="gain resistor to ground (with --r4, instead of --gain)")
    g.add_argument("--r4", help="gain feedback resistor")
    g.add_argument("--fc", help=f"target fn, Hz, to report errors against (optional) {help_range('fc_hz')}")
    g.add_argument("--zeta", help=f"target damping, to report errors against (optional) {help_range('zeta')}")
    g.add_argument("--r-series", default=None, help="series the resistors come from, for the tolerance band "
                                                    "(default: the smallest series that holds each value)")
    g.add_argument("--c-series", default=None, help="series the capacitors come from, for the tolerance band "
                                                    "(default: the smallest series that holds each value)")
    _common_output(p)
    return p


def _analyze(args) -> int:
    from .plant import analyze_plant
    from .sallenkey import SallenKeyParts, check_parts
    from .units import value_code
    r3 = r4 = None
    if (args.r3 is None) != (args.r4 is None):
        raise DesignError("--r3 and --r4 go together (K = 1 + R4/R3)")
    if args.r3 is not None:
        if args.gain is not None:
            raise DesignError("give either --gain or --r3/--r4, not both")
        r3, r4 = parse_in_range(args.r3, "--r3", "resistor_ohm"), parse_in_range(args.r4, "--r4", "resistor_ohm")
    gain = None if args.gain is None else parse_in_range(args.gain, "--gain", "gain")
    vals = {n: parse_in_range(getattr(args, n), f"--{n}", "resistor_ohm" if n[0] == "r" else "capacitor_f")
            for n in ("r1", "r2", "c1", "c2")}
    # the shared plant check derives R3/R4 for a bare --gain and refuses unstable parts
    parts = check_parts(SallenKeyParts(vals["r1"], vals["r2"], vals["c1"], vals["c2"], gain, r3, r4),
                        name_of={k: f"--{k}" for k in ("r1", "r2", "c1", "c2", "r3", "r4", "gain")})
    fc = optional(args.fc, "--fc", "fc_hz")
    zeta = optional(args.zeta, "--zeta", "zeta")
    from .eseries import series_name
    for s in (args.r_series, args.c_series):
        if s is not None:
            series_name(s)
    opamps.get(args.opamp)
    name = args.name if args.name is not None else "built_" + "_".join(f"{k}{value_code(v)}" for k, v in vals.items())
    check_name(name)
    amplitude = parse_in_range(args.amplitude, "--amplitude", "amplitude_v")
    square = optional(args.square_freq, "--square-freq", "square_hz")
    if not args.no_files:
        from .fileio import check_can_create
        check_can_create(args.out, ("netlists", "reports"))
    result = analyze_plant(parts, args.opamp, fc, zeta, args.r_series, args.c_series, amplitude, square,
                           simulate=not args.no_sim, simulator=args.simulator)
    return _emit(result, args, name)


def design_plant_main(argv=None) -> int:
    return run_cli("design-plant", _design_parser, _design, argv)


def analyze_plant_main(argv=None) -> int:
    return run_cli("analyze-plant", _analyze_parser, _analyze, argv)


if __name__ == "__main__":  # pragma: no cover
    sys.exit(design_plant_main())
