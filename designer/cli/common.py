"""What every command shares: the one-line error contract and exit statuses
(:func:`run_cli`), with the library's parameter names shown as the options
the user typed (:data:`FLAGS`); the parser that turns usage mistakes into one
line, printing that survives a closed pipe, the part-selection, output and
op-amp options, design names and the output check before any work
(:func:`check_output`), and writing a result's files then printing it
(:func:`emit`). The commands hand the options to the library's specs as
typed: the specs check them, once.
"""

from __future__ import annotations

import argparse
import json
import re
import sys

from ..core import opamps
from ..core.errors import DesignError
from ..core.eseries import SERIES
from ..core.ranges import help_range

__all__ = ["ExtendList", "FLAGS", "OneLineParser", "StoreOnce", "flag_message", "run_cli"]

#: library parameter -> the option a user types; errors naming a parameter
#: (:attr:`DesignError.param`) are shown with the option instead
FLAGS = {
    # design-plant / analyze-plant
    "fc_hz": "--fc", "zeta": "--zeta", "gain": "--gain", "r_series": "--r-series", "c_series": "--c-series",
    "r_min": "--r-min", "r_max": "--r-max", "c_min": "--c-min", "c_max": "--c-max", "r": "--r", "c": "--c",
    "opamp": "--opamp", "amplitude_v": "--amplitude", "square_hz": "--square-freq",
    "alternatives": "--alternatives", "target_fc_hz": "--fc", "target_zeta": "--zeta", "no_sim": "--no-sim",
    "r1": "--r1", "r2": "--r2", "c1": "--c1", "c2": "--c2", "r3": "--r3", "r4": "--r4",
    # design-pid
    "plant_fc_hz": "--plant-fc", "plant_zeta": "--plant-zeta", "plant_gain": "--plant-gain",
    "plant_r1": "--plant-r1", "plant_r2": "--plant-r2", "plant_c1": "--plant-c1", "plant_c2": "--plant-c2",
    "plant_json": "--plant-json", "plant_topology": "--plant-topology", "plant_values": "--plant-part",
    "tuning": "--tuning", "kp": "--kp", "ti_s": "--ti", "td_s": "--td",
    "step_v": "--step", "edge_s": "--edge", "target_overshoot_pct": "--target-overshoot",
    "target_settling_s": "--target-settling", "f_integrator_hz": "--f-integrator",
    "f_differentiator_hz": "--f-differentiator",
    "plant_tf": "--plant-tf", "plant_model": "--plant-model", "plant_method": "--plant-method",
    "plant_capture": "--plant-capture", "plant_input": "--plant-input", "plant_output": "--plant-output",
    "simc_tauc_s": "--simc-tauc", "imc_lambda_s": "--imc-lambda", "min_phase_margin_deg": "--min-pm",
    # the tuning rules' own names (designer.pid.rules.tune_model) for the same two settings
    "tauc_s": "--simc-tauc", "lambda_s": "--imc-lambda",
    "min_gain_margin_db": "--min-gm", "max_ms": "--max-ms", "robust": "--robust",
    # analyze-pid: the controller as built (r3, r4 as above)
    **{f"r{i}": f"--r{i}" for i in range(5, 19)}, "c3": "--c3", "c4": "--c4", "controller_json": "--parts-json",
    # identify / identify-freq
    "step_time_s": "--step-time", "step_amplitude": "--step-amplitude",
    "input_column": "--input-column", "output_column": "--output-column", "sample_time_s": "--sample-time",
    "column_names": "--columns", "window": "--window", "fmt": "--format", "methods": "--methods",
    "refine": "--no-refine", "method": "--method", "validate": "--validate", "segment_length": "--segment-length",
    "against": "--against", "out_folder": "--out",
    # simulate-capture (its step_v, step_time_s as above)
    # design-filter
    "filter_type": "--type", "family": "--family", "order": "--order", "ripple_db": "--ripple",
    "passband_hz": "--passband", "max_loss_db": "--max-loss", "stopband_hz": "--stopband",
    "min_attenuation_db": "--min-attenuation", "max_delay_error_pct": "--max-delay-error", "delay_to_hz": "--delay-to",
    "topology": "--topology", "stage_order": "--stage-order",
    "stage_gains": "--stage-gain",
    "bessel_norm": "--bessel-norm", "chebyshev_cutoff": "--chebyshev-cutoff", "gbw_margin": "--gbw-margin",
    "impedance_ohm": "--impedance", "series": "--series",
    "f_low_hz": "--f-low", "f_high_hz": "--f-high", "bandpass_method": "--bandpass-method",
    "lang": "--lang",
    "duration_s": "--duration", "points": "--points", "noise_v": "--noise", "lsb_v": "--lsb", "seed": "--seed",
}


#: a library parameter's name inside a message's text (``give tauc_s``; a rule's reason quoted in
#: another message): the names with an underscore, which are no English word; not part of a longer
#: name, a dotted key, a ``{marker}``, an option or a ``key=value``
_NAME_IN_TEXT = re.compile(r"(?<![\w.{-])(" + "|".join(sorted((re.escape(k) for k in FLAGS if "_" in k),
                                                               key=len, reverse=True)) + r")(?![\w=])")


def flag_message(exc: DesignError) -> str:
    """The error's message with the options the user typed for the parameters it
    names (:meth:`DesignError.naming`: every ``{name}`` marker of a
    :class:`~designer.core.errors.ParamError`, else the parameter it starts with),
    and for a library name anywhere in its text (``simc: ... give tauc_s``, said
    by the tuning rules, reads ``give --simc-tauc``).

    Parameters
    ----------
    exc : DesignError
        The library's error.

    Returns
    -------
    str
        The message in the command line's words.
    """
    text = exc.naming(FLAGS) if callable(getattr(exc, "naming", None)) else str(exc)
    return _NAME_IN_TEXT.sub(lambda m: FLAGS[m.group(1)], text)


#: where the options given so far are noted during one parse (removed from the namespace after it)
_GIVEN = "_designer_options_given"


def _shown_value(values) -> str:
    """An option's value(s) as typed, cut to a readable length, for a message."""
    text = " ".join(map(str, values)) if isinstance(values, (list, tuple)) else str(values)
    return text if len(text) <= 40 else text[:37] + "..."


class StoreOnce(argparse.Action):
    """argparse's ``store`` for an option that takes one value (or a fixed number):
    given twice, it is refused in one line naming both values, where argparse
    would keep the last and drop the first without a word (``--fc 1k --fc 2k``)."""

    def __call__(self, parser, namespace, values, option_string=None):
        given = namespace.__dict__.setdefault(_GIVEN, {})
        if self.dest in given:
            flag = next((s for s in self.option_strings if s.startswith("--")), option_string or self.dest)
            parser.error(f"{flag} given twice: {given[self.dest]} and {_shown_value(values)}; give it once")
        given[self.dest] = _shown_value(values)
        setattr(namespace, self.dest, values)


class ExtendList(argparse.Action):
    """argparse's ``store`` for an option that takes a list (``nargs="+"``): given
    again, its values are added to the earlier ones (``--tol R=1% --tol C=5%`` is
    ``--tol R=1% C=5%``), never dropped."""

    def __call__(self, parser, namespace, values, option_string=None):
        setattr(namespace, self.dest, list(getattr(namespace, self.dest, None) or []) + list(values))


class _Store(argparse.Action):
    """What ``action="store"`` (argparse's default) makes: :class:`ExtendList` for a list, else :class:`StoreOnce`."""

    def __new__(cls, option_strings, dest, nargs=None, **kwargs):
        kind = ExtendList if nargs in ("+", "*") and option_strings else StoreOnce
        return kind(option_strings, dest, nargs=nargs, **kwargs)


class OneLineParser(argparse.ArgumentParser):
    """argparse, but a usage mistake is one line (and exit status 2), option
    values such as ``-1e-3`` or ``-2m`` are values, not unknown options (argparse
    before Python 3.13 takes only ``-2`` and ``-.5`` for numbers), and no option
    given twice is silently dropped: a single-valued one is refused
    (:class:`StoreOnce`), a list's values accumulate (:class:`ExtendList`);
    ``append`` options (``--limit``) repeat as before."""

    def __init__(self, *args, **kwargs):
        super().__init__(*args, **kwargs)
        self._negative_number_matcher = re.compile(r"^-\.?\d")
        # argparse's own hook for the action classes; argument groups share this registry
        self.register("action", None, _Store)
        self.register("action", "store", _Store)

    def parse_known_args(self, args=None, namespace=None):
        namespace, extras = super().parse_known_args(args, namespace)
        namespace.__dict__.pop(_GIVEN, None)
        return namespace, extras

    def error(self, message):
        raise DesignError(f"{message} (see {self.prog} --help)")


def command_parser(prog: str, description: str, epilog: str) -> OneLineParser:
    """A command's parser: one-line usage errors, ``--help`` with the epilog's
    examples as written, and ``--version``."""
    from .. import __version__
    p = OneLineParser(prog=prog, description=description, epilog=epilog,
                      formatter_class=argparse.RawDescriptionHelpFormatter)
    p.add_argument("--version", action="version", version=f"%(prog)s {__version__}")
    return p


def print_output(text: str, end: str = "\n") -> None:
    """Print; a pipe closed by the reader (``| head``) is their choice, not an error."""
    try:
        print(text, end=end)
        sys.stdout.flush()
    except BrokenPipeError:
        _silence_stdout()


def _silence_stdout() -> None:
    from ..core.lifetime import to_devnull
    to_devnull(sys.stdout)


def run_cli(prog: str, build_parser, action, argv=None) -> int:
    """Run ``action(args)`` with the one-line error convention; returns the exit status:
    0 done, 1 a check failed (when asked), 2 bad input or usage, 3 simulator error,
    130, 143, 129 interrupted by SIGINT, SIGTERM, SIGHUP. Every failure is one line on stderr, never a traceback.

    Parameters
    ----------
    prog : str
        The command's name, for its messages.
    build_parser : callable
        Returns the command's :class:`argparse.ArgumentParser`.
    action : callable
        Runs the parsed arguments; returns an exit status or None (0).
    argv : list of str, optional
        The arguments; None reads ``sys.argv[1:]``.

    Returns
    -------
    int
        The exit status.
    """
    from ..core.errors import EXIT_BAD_INPUT, EXIT_SIMULATOR, SimulatorError
    from ..core import lifetime
    try:
        try:
            parser = build_parser()
            args = parser.parse_args(argv)
            args.prog = prog   # for messages written after the action's own work (see failed_checks_status)
            return action(args) or 0
        except BaseException as exc:
            stop = lifetime.interruption(exc)
            if stop is not None and stop is not exc:   # a stop signal in another error's clothes
                raise stop from None
            raise
    except SimulatorError as exc:
        _fail(prog, f"simulator error: {exc}")
        return EXIT_SIMULATOR
    except DesignError as exc:
        _fail(prog, flag_message(exc))
        return EXIT_BAD_INPUT
    except BrokenPipeError:
        _silence_stdout()
        return 0
    except KeyboardInterrupt as exc:   # Ctrl-C, or SIGTERM/SIGHUP (designer.core.lifetime): 128 + the signal
        _fail(prog, lifetime.words_of(exc))
        return lifetime.status_of(exc)
    except MemoryError:
        _fail(prog, "out of memory: the input is too large for this machine")
        return EXIT_BAD_INPUT
    except OSError as exc:   # a file system problem no check caught earlier
        where = f" {exc.filename!r}" if getattr(exc, "filename", None) else ""
        _fail(prog, f"cannot read or write{where}: {exc.strerror or exc}")
        return EXIT_BAD_INPUT


def _fail(prog: str, message: str, kind: str = "error: ") -> None:
    line = " ".join(str(message).split())   # one line, whatever the message holds
    try:
        print(f"{prog}: {kind}{line}", file=sys.stderr)
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
    """:func:`add_part_options` as typed, as keyword arguments of a spec
    (a :class:`~designer.core.eseries.PartBounds`, which checks them)."""
    return {k: getattr(args, k) for k in ("r_series", "c_series", "r_min", "r_max", "c_min", "c_max")}


def add_output_options(p, default_name: str):
    """The options every designing command shares: where and how to write
    (``--out``, ``--name``, ``--json``, ``--no-files``) and whether and how to
    simulate (``--no-sim``, ``--simulator``). Returns the "simulation" group,
    for the command's own test-signal options."""
    g = p.add_argument_group("output")
    g.add_argument("--out", default=".", metavar="DIR",
                   help="write netlists/<name>.cir and reports/<name>/ under DIR (default: current directory)")
    g.add_argument("--name", help="design name used for the files: letters, digits and . _ - + = , @ "
                                   f"(default from the figures, e.g. {default_name})")
    g.add_argument("--json", action="store_true", help="print one JSON object on stdout instead of the summary")
    g.add_argument("--no-files", action="store_true", help="do not write the netlist and report files")
    add_lang_option(g)
    g.add_argument("--fail-on-check", action="store_true",
                   help="exit status 1 when a design check or the SPICE agreement fails (for CI; the files and "
                        "the summary are written first, the failed checks listed on stderr)")
    s = p.add_argument_group("simulation")
    s.add_argument("--no-sim", action="store_true", help="skip the ngspice run (analytic figures only)")
    s.add_argument("--simulator", default="pyspice", choices=("pyspice", "ngspice-cli"),
                   help="pyspice: ngspice shared library via PySpice (default); "
                        "ngspice-cli: `ngspice -b` subprocess")
    return s


def add_lang_option(group):
    """``--lang``: the language of the build sheet and the summary (:mod:`designer.core.i18n`).

    Parameters
    ----------
    group : argparse group or parser
        Where the option goes.
    """
    from ..core.i18n import DEFAULT, LANGUAGES
    group.add_argument("--lang", default=DEFAULT, choices=LANGUAGES,
                       help=f"language of the build sheet and the summary: {', '.join(LANGUAGES)} (default {DEFAULT}, "
                            "whatever LANG or LC_ALL say, so a sheet is the same on every machine; es writes decimal "
                            "commas; values are typed with a dot in every language: a comma separates list items)")


def add_opamp_option(group):
    """``--opamp``: the catalogue's names (the seed's bench used LM741s)."""
    group.add_argument("--opamp", default="LM741", metavar="NAME",
                       help=f"op-amp model: {', '.join(opamps.names())} (default LM741, as the seed's bench)")


def check_name(name) -> str:
    """``--name``: a plain file name (:func:`designer.core.fileio.check_plain_name`)."""
    from ..core.fileio import check_plain_name
    return check_plain_name(name, "--name")


def check_output(args, name: str) -> None:
    """Before any work: the design name is a plain file name and, unless
    ``--no-files``, ``netlists/`` and ``reports/`` can be created under ``--out``
    and ``reports/<name>`` is no link or file (a refusal after the work would
    waste it, and must write nothing)."""
    check_name(name)
    if not args.no_files:
        import os

        from ..core.fileio import check_can_create, check_output_folder
        check_can_create(args.out, ("netlists", "reports"))
        # the report folder is replaced whole: a link or a file of its name refused now, not after the work
        check_output_folder(os.path.join(args.out, "reports", name), "report folder")


def emit(result, args, name, write_outputs, summary_text) -> int:
    """Write the files (unless --no-files), then print JSON or the summary and the file list.
    Returns the exit status: 1 with ``--fail-on-check`` when a verdict failed
    (:meth:`verdicts` of the result: the checks and the SPICE agreement), else 0."""
    from ..core.i18n import language
    with language(getattr(args, "lang", None)):
        if not args.no_files:
            write_outputs(result, args.out, name)
        text = None if args.json else summary_text(result)
    if args.json:
        print_output(json.dumps(result.to_dict(), indent=2))
    else:
        if result.files:
            text += "\nFiles:\n" + "".join(
                f"  {key}: {', '.join(path) if isinstance(path, list) else path}\n"
                for key, path in result.files.items())
        print_output(text, end="")
    return failed_checks_status(result, args)


def failed_checks_status(result, args) -> int:
    """With ``--fail-on-check``: each failed verdict as a line on stderr
    (``<prog>: check failed: slew_rate: ...``) and exit status 1; else 0."""
    from ..core.errors import EXIT_CHECK_FAILED
    if not getattr(args, "fail_on_check", False):
        return 0
    bad = [c for c in result.verdicts() if not c.ok]
    for c in bad:
        _fail(args.prog, f"check failed: {c.id}: {c.detail}", "")
    return EXIT_CHECK_FAILED if bad else 0
