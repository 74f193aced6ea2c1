"""Command-line layer: ``design-plant`` and ``analyze-plant``.

Thin: parse, call the library, print. Any :class:`DesignError` becomes one
line on stderr and exit status 2.
"""

from __future__ import annotations

import argparse
import json
import os
import sys

from . import __version__, opamps
from .eseries import SERIES
from .errors import DesignError
from .units import parse_positive, parse_value


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
    group.add_argument("--r-min", default="1k", help="smallest resistor (default 1k)")
    group.add_argument("--r-max", default="1M", help="largest resistor (default 1M)")
    group.add_argument("--c-min", default="1n", help="smallest capacitor (default 1n)")
    group.add_argument("--c-max", default="10u", help="largest capacitor (default 10u)")


def part_options(args) -> dict:
    """The parsed :func:`add_part_options`, as spec keyword arguments."""
    return {"r_series": args.r_series, "c_series": args.c_series,
            **{k: parse_positive(getattr(args, k), f"--{k.replace('_', '-')}")
               for k in ("r_min", "r_max", "c_min", "c_max")}}


def _common_output(p):
    g = p.add_argument_group("output")
    g.add_argument("--out", default=".", metavar="DIR",
                   help="write netlists/<name>.cir and reports/<name>/ under DIR (default: current directory)")
    g.add_argument("--name", help="design name used for the files (default from the figures, "
                                   "e.g. plant_fc3500_z0.2)")
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
                   help="bench square wave goes 0 -> V volts (default 2, as the seed's bench test)")
    s.add_argument("--square-freq", metavar="HZ",
                   help="bench square-wave frequency (default: a round value whose half period is "
                        "1.5x the 2 %% settling time; 330 Hz for the seed's plant)")


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
    t.add_argument("--fc", required=True, metavar="HZ", help="natural frequency fn = wn / 2 pi, Hz (e.g. 3500, 3.5k)")
    t.add_argument("--zeta", required=True, metavar="Z", help="damping ratio, > 0 (>= 1 is overdamped)")
    t.add_argument("--gain", default="1", metavar="K", help="DC gain K = 1 + R4/R3, >= 1 (default 1: follower)")
    t.add_argument("--compensate-gbw", action="store_true",
                   help="pre-distort the targets so the circuit lands on them with the op-amp's finite GBW")
    sel = p.add_argument_group("parts")
    sel.add_argument("--r", metavar="OHM", help="the seed's procedure: fix R (R2 = R, R1 = m R) ...")
    sel.add_argument("--c", metavar="F", help="... and C (C1 = C, C2 = n C), solve m and n")
    add_part_options(sel)
    sel.add_argument("--alternatives", default="5", help="how many best combinations to list (default 5)")
    _common_output(p)
    return p


def _design(args) -> int:
    from .plant import PlantSpec, design_plant
    spec = PlantSpec(
        fc_hz=parse_positive(args.fc, "--fc"), zeta=parse_positive(args.zeta, "--zeta"),
        gain=parse_value(args.gain, "--gain"),
        **part_options(args),
        r=None if args.r is None else parse_positive(args.r, "--r"),
        c=None if args.c is None else parse_positive(args.c, "--c"),
        opamp=args.opamp, compensate_gbw=args.compensate_gbw,
        amplitude_v=parse_positive(args.amplitude, "--amplitude"),
        square_hz=None if args.square_freq is None else parse_positive(args.square_freq, "--square-freq"),
        alternatives=_count(args.alternatives))
    spec.validate()
    name = args.name or f"plant_fc{spec.fc_hz:g}_z{spec.zeta:g}" + ("" if spec.gain == 1 else f"_k{spec.gain:g}")
    _check_name(name)
    if not args.no_files:
        from .fileio import ensure_dir
        ensure_dir(args.out)  # fail before the work, not after
    result = design_plant(spec, simulate=not args.no_sim, simulator=args.simulator)
    return _emit(result, args, name)


def _count(text) -> int:
    try:
        n = int(str(text))
    except ValueError:
        raise DesignError(f"--alternatives must be a whole number from 1 to 50, got {text!r}") from None
    if not 1 <= n <= 50:
        raise DesignError(f"--alternatives must be a whole number from 1 to 50, got {text!r}")
    return n


def _check_name(name):
    if not name or "/" in name or name.startswith("."):
        raise DesignError(f"--name {name!r} must be a plain file name (no '/', not starting with '.')")


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
    for n, what in (("r1", "input resistor, ohms"), ("r2", "resistor to the non-inverting input, ohms"),
                    ("c1", "non-inverting input to ground, farads"), ("c2", "feedback capacitor, farads")):
        g.add_argument(f"--{n}", required=True, help=what)
    g.add_argument("--gain", default=None, metavar="K", help="gain K = 1 + R4/R3 (default 1)")
    g.add_argument("--r3", help="gain resistor to ground (with --r4, instead of --gain)")
    g.add_argument("--r4", help="gain feedback resistor")
    g.add_argument("--fc", help="target fn, Hz, to report errors against (optional)")
    g.add_argument("--zeta", help="target damping, to report errors against (optional)")
    g.add_argument("--r-series", default="E24", help="series the resistors come from, for the tolerance band")
    g.add_argument("--c-series", default="E12", help="series the capacitors come from, for the tolerance band")
    _common_output(p)
    return p


def _analyze(args) -> int:
    from .plant import analyze_plant
    from .sallenkey import SallenKeyParts
    r3 = r4 = None
    if (args.r3 is None) != (args.r4 is None):
        raise DesignError("--r3 and --r4 go together (K = 1 + R4/R3)")
    if args.r3 is not None:
        if args.gain is not None:
            raise DesignError("give either --gain or --r3/--r4, not both")
        r3, r4 = parse_positive(args.r3, "--r3"), parse_positive(args.r4, "--r4")
        gain = 1 + r4 / r3
    else:
        gain = 1.0 if args.gain is None else parse_value(args.gain, "--gain")
        if not gain >= 1:
            raise DesignError(f"--gain must be >= 1 (K = 1 + R4/R3), got {args.gain!r}")
        if gain != 1:
            r3, r4 = 10e3, (gain - 1) * 10e3
    parts = SallenKeyParts(parse_positive(args.r1, "--r1"), parse_positive(args.r2, "--r2"),
                           parse_positive(args.c1, "--c1"), parse_positive(args.c2, "--c2"), gain, r3, r4)
    fc = None if args.fc is None else parse_positive(args.fc, "--fc")
    zeta = None if args.zeta is None else parse_positive(args.zeta, "--zeta")
    from .eseries import series_name
    series_name(args.r_series), series_name(args.c_series)
    opamps.get(args.opamp)
    name = args.name or "built_" + "_".join(
        f"{k}{v}" for k, v in (("r1", args.r1), ("r2", args.r2), ("c1", args.c1), ("c2", args.c2)))
    _check_name(name)
    if not args.no_files:
        from .fileio import ensure_dir
        ensure_dir(args.out)
    result = analyze_plant(parts, args.opamp, fc, zeta, args.r_series, args.c_series,
                           parse_positive(args.amplitude, "--amplitude"),
                           None if args.square_freq is None else parse_positive(args.square_freq, "--square-freq"),
                           simulate=not args.no_sim, simulator=args.simulator)
    return _emit(result, args, name)


def design_plant_main(argv=None) -> int:
    return run_cli("design-plant", _design_parser, _design, argv)


def analyze_plant_main(argv=None) -> int:
    return run_cli("analyze-plant", _analyze_parser, _analyze, argv)


if __name__ == "__main__":  # pragma: no cover
    sys.exit(design_plant_main())
