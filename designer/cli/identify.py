"""``identify`` and ``identify-freq``: plant models from measurements.

``identify`` reads a CSV step-response capture (generic, Tektronix, Rigol or
this project's waveforms), runs every classical method of seeds 000-003 plus
least squares, and prints them ranked by IAE; a capture under any other
recorded input goes to the correlation, spectral and output-error routes, and
every route's models are scored on held-out data (issue 28); a frequency-response table given
to it (a header naming a frequency and a gain column, as identify-freq reads
it) is analysed as ``identify-freq`` does, never fitted as a step.
``identify-freq`` reads a table of frequency, gain and (optionally) phase,
reads asymptotes, resonant peak and dead time as seeds 000 and 003 do, fits
FOPDT, underdamped and overdamped models to the complex response by least
squares, and prints them ranked by fit error. With ``--json`` either prints
one JSON object instead.
"""

from __future__ import annotations

import argparse
import json
import sys
from pathlib import Path

from ..core.errors import DesignError
from ..core.fileio import (
    MAX_CAPTURE_BYTES,
    MAX_CAPTURE_ROWS,
    MAX_TABLE_BYTES,
    atomic_write,
    shown,
    size_text,
)
from ..core.jsonio import json_safe
from ..core.ranges import RANGES, help_range
from ..identify.io import FORMAT_NAMES, FORMATS, FREQ_UNITS, GAIN_UNITS, MAX_POINTS, PHASE_UNITS
from .common import OneLineParser, print_output, run_cli

__all__ = ["CAPTURE_DESTS", "FORMATS", "build_freq_parser", "build_parser", "capture_params", "capture_spec",
           "identify_freq_main", "identify_main", "identify_run", "identify_spec_of"]

IDENTIFY_EPILOG = """\
examples:
  identify capture.csv                         # t,y or t,u,y (header optional)
  identify scope.csv --step-time 0 --step-amplitude 2
        a scope export of the output only: step at t = 0 s, input step of 2 V
  identify plant.csv --json > models.json      # methods[], best, preprocessing
  identify bench.csv --against reports/plant_fc3500_z0.2/result.json
        compare fn, zeta, gain and overshoot with the design and its part tolerances
  identify sq330.csv --plot fit.png            # a 330 Hz square wave: steps averaged
  identify capture.csv --methods smith,alfaro,least-squares
  identify TEK0001.CSV --window 0 7m           # only the stretch from 0 to 7 ms
  identify scope.csv --format rigol-no-x       # read as that layout, whatever it looks like
  identify dryer.dat --sample-time 0.08 --columns u,y
        plain columns without a time column (DaISy's u y): sample k at k x 0.08 s

input layouts (--format, recognised when not given): {formats}.
A frequency-response table (header f_hz,gain_db,phase_deg or any other header
identify-freq reads: f_khz, w_rad_s, gain_ratio, phase_rad, shift_s, shift_us,
a WaveForms network-analyser export) is analysed as identify-freq does, with
the same --json and --plot output and "format": "frequency-table"; the step
options (--step-time, --window, --format ...) are refused with it.
Generic CSV: comma, semicolon, tab or space separated, decimal commas, CRLF, a
BOM, '#' comments (non-UTF-8 bytes in them are fine). The format read is printed
and is "format" in the JSON. With two signals the first is the input and the
second the output unless their names say otherwise (u/vin/in, y/vout/out);
--input-column/--output-column choose by name or column number.

data: the step time and amplitude come from the input's edges; without an
input, from the output's own (the step at its last sample at rest, or t = 0 if
it is still at rest there; the record cut where its next, opposite edge starts).
A square wave's full edges are averaged coherently, rising and falling apart,
and the noise is taken from the averaged plateaus. The baseline is the settled
stretch just before the edge. A straight ramp or a flat top at a rail marks the
record non-linear (no model valid); a time constant below the sample interval or
a least-squares parameter with a confidence interval wider than itself is not
valid. Quantised (8-bit) data have at least one LSB/sqrt(12) of noise.

methods: first order (ziegler-nichols, hagglund, smith, sundaresan-krishnaswamy,
nishikawa, alfaro, broida, chen-yang, ho, viteckova, alfaro-123c), double pole
(ho-double-pole, viteckova-double-pole), second order (overshoot,
log-decrement, t4-t3, two-pole, chen, stark-mollenkamp, jahanmiri-fallahi,
peeling, dc-motor, alfaro-123c-overdamped, harriott), and least-squares fits
(fopdt, overdamped, underdamped) with 95 % confidence intervals. Parameters: K, tau_s, theta_s; K, wn_rad_s,
zeta, theta_s; K, tau1_s, tau2_s, theta_s.

limits: a capture of at most {size} and {rows:,} samples; every time (and
--step-time, --window) {t_rng} and the record {span_rng} long; every sample {v_rng}
(file units); the output's step {step_rng} in size.

broadband input (seed 003 sections 2.4 and 3.2): an input column that is a
pseudo-random binary sequence (make-prbs writes one) or noise - many
transitions at irregular intervals, no dominant frequency - is recognised and
identified by correlation (the impulse response over whole periods, eq.
2.4.19, and the step methods on its running integral) and by spectral analysis
(H = S_yu/S_uu with coherence, analysed as identify-freq does). A sequence
needs two whole periods at least (the first settles the plant) and a clock
that is a whole number of sample intervals; a period shorter than the plant's
settling is said so, with the bits or clock that would be enough.
--method correlation|spectral keeps one; --step-time, --step-amplitude and
--against are for steps.

validation (issue 28): a capture with an input channel also gets output-error
fits (fopdt, sopdt, underdamped, lead-lag, dead time not a whole number of
samples), and every route's models are simulated under the recorded input of
validation data (a broadband capture's last third, whole periods of a sequence;
--validate OTHER.csv; a step capture on itself, said so) and scored by the
compare fit % and the residual tests; the best by validation fit across routes
is "validation.best" in the JSON and what design-pid --plant-capture tunes for.
A model is valid only if every 95 % interval is narrower than its parameter. An
input that never moves is refused (nothing to identify).

exit status: 0 success, 2 bad input (one line on stderr saying what and why).
"""

FREQ_EPILOG = """\
examples:
  identify-freq bode.csv                      # f_hz,gain_db,phase_deg (header optional)
  identify-freq sensor.csv --gain-units ratio --phase-units s
        gain as Vout/Vin and phase as the output's time shift behind the input
  identify-freq opamp.csv --json > models.json  # methods[], best, data, error_definition
  identify-freq bode.csv --plot bode.png      # data against the fitted models

table: one row per frequency: frequency, gain[, phase]; comma, semicolon (decimal
comma allowed), tab or space separated; '#' lines are comments. A header row may
name the units (f_hz, f_khz, w_rad_s, gain_db, gain_ratio, phase_deg, phase_rad,
shift_s, shift_us); options override it. Defaults: Hz, dB, degrees. A phase
given as a time shift dt is the output lagging the input: phase = -360 f dt.

methods: asymptotes (K, high-frequency slope -> order, corner where the gain
has fallen 3.01n dB; 1 pole -> fopdt, 2 -> double-pole), resonant-peak (zeta from
the peak height -10 log(4 zeta^2 (1 - zeta^2)), wn from its frequency),
least-squares (fopdt, underdamped, overdamped, with dead time when there is
phase; 95 % confidence half-widths). Dead time is read from the phase lag the
model does not explain.

tables: a Digilent WaveForms network-analyser export (frequency, each channel's
magnitude, the relative channel's phase) is read as that channel's response.
The low-frequency slope is a regression over the lowest decade. A loop-gain
table (gain above 0 dB at the lowest frequency, falling through it) also gets
its crossover, phase margin and gain margin ("loop" in the JSON).

fit error (the iae/ise columns): e = |G_model/G_data - 1| at each tabulated
frequency (gain only without phase); iae = mean of e, ise = mean of e^2.
A model is valid (ok = yes) when its fit error is at most {max_err:g} % and its
corner frequencies (1/tau, wn) lie inside the measured band widened {band:g} times.

limits: a table of at most {size} and {rows:,} rows; frequency {f_rng},
gain {db_rng} (ratio {ratio_rng}), phase {ph_rng} degrees
(after unit conversion).

exit status: 0 success, 2 bad input (one line on stderr saying what and why).
"""


# --------------------------------------------------------------------------- shared

def check_output_path(path, option: str) -> None:
    """Refuse, before any work, an output file that cannot be written
    (:func:`designer.core.fileio.check_output_file`: a directory, a link, FIFO or
    device there, a parent that is a file). Nothing is created here: a run
    refused later must leave no trace."""
    if str(path) == "":
        raise DesignError(f"{option} needs a file name, such as fit.png")
    from ..core.fileio import check_output_file
    try:
        check_output_file(path, option)
    except OSError as exc:   # a name too long
        raise DesignError(f"{option} {shown(path)} is not a usable file name: {exc.strerror or exc}") from None


def write_png(path, png: bytes, option: str = "--plot") -> None:
    """Write a PNG atomically; an OS error (disk full, permission) is one line."""
    try:
        atomic_write(path, png)
    except OSError as exc:
        raise DesignError(f"{option}: cannot write {shown(path)}: "
                          f"{exc.strerror or exc}") from None


def _run(args, identify, text, plot) -> int:
    """Either command: its result printed as JSON or as its table (and the plot written)."""
    out = getattr(args, "out", None)
    if out is not None:
        check_sheet_folder(out)
    result = identify(args)
    if args.plot:
        write_png(args.plot, plot(result))
    if out is not None:
        write_sheet(out, result, text, plot)
    if args.json:
        print_output(json.dumps(json_safe(result.to_dict()), indent=2, allow_nan=False))
    else:
        print_output(text(result) + (f"\n\nPlot written to {args.plot}" if args.plot else "")
                     + (f"\n\nBuild sheet written to {out}" if out is not None else ""))
    return 0


def check_sheet_folder(out) -> None:
    """Refuse, before any work, an ``--out`` that is a file or a symbolic link (the folder is
    replaced whole: :func:`designer.core.fileio.check_output_folder`)."""
    if str(out) == "":
        raise DesignError("--out needs a folder name, such as ident")
    from ..core.fileio import check_output_folder
    check_output_folder(out, "--out")


def write_sheet(out, result, text, plot) -> None:
    """The identification's build sheet in folder ``out``, all files or none:
    ``build-sheet.md`` (the table and the figure), ``identify.png`` (for a
    broadband capture: the impulse response, the step it integrates to, the
    spectral estimate with its coherence, the models' fits), ``result.json``,
    and for a broadband capture ``spectrum.csv`` (the spectral estimate as a
    table identify-freq reads)."""
    from ..core import fileio
    out = Path(out)
    files = {"identify.png": plot(result),
             "result.json": json.dumps(json_safe(result.to_dict()), indent=2, allow_nan=False) + "\n"}
    spectrum = getattr(result, "spectrum", None)
    if spectrum is not None and spectrum.f.size:
        from ..identify.spectral import table_text
        files["spectrum.csv"] = table_text(spectrum)
    files["build-sheet.md"] = ("# Identification\n\n![data and models](identify.png)\n\n```\n" + text(result)
                               + "\n```\n\nFiles: " + ", ".join(f"[{n}]({n})" for n in files) + "\n")
    stage = fileio.new_folder_beside(out)
    try:
        for name, data in files.items():
            (stage / name).write_bytes(data if isinstance(data, bytes) else data.encode("utf-8"))
    except OSError as exc:
        fileio.remove_tree(stage)
        raise fileio.os_error("write", out, exc) from None
    fileio.publish_folder(stage, out)


def _parser(prog: str, description: str, epilog: str, data_help: str, data_name: str):
    p = OneLineParser(prog=prog, description=description, epilog=epilog,
                      formatter_class=argparse.RawDescriptionHelpFormatter)
    p.add_argument(data_name, help=data_help)
    return p


def _output_options(p, plot_help: str, json_first: bool = False) -> None:
    options = [(("--plot",), {"metavar": "OUT_PNG", "help": plot_help}),
               (("--json",), {"action": "store_true",
                              "help": "print one JSON object instead of the table"})]
    for flags, kwargs in (options[::-1] if json_first else options):
        p.add_argument(*flags, **kwargs)


# --------------------------------------------------------------------------- identify

def identify_epilog() -> str:
    """The ``identify --help`` epilog with the input limits filled in."""
    import textwrap
    formats = textwrap.fill(", ".join(f"{k} ({v})" for k, v in FORMAT_NAMES.items()), 80,
                            initial_indent=" " * 48)[48:]
    return IDENTIFY_EPILOG.format(formats=formats, size=size_text(MAX_CAPTURE_BYTES),
                                  rows=MAX_CAPTURE_ROWS,
                                  t_rng=RANGES["capture_time_s"].text(),
                                  span_rng=RANGES["capture_span_s"].text(),
                                  v_rng=RANGES["capture_value"].text(),
                                  step_rng=RANGES["output_step"].text())


def build_parser() -> argparse.ArgumentParser:
    """The ``identify`` command line.

    Returns
    -------
    argparse.ArgumentParser
        The parser of ``identify``'s options.
    """
    p = _parser("identify", "Identify plant models (FOPDT, two lags, second order, integrating, with dead\n"
                "time) from a capture under any recorded input: a step (its methods ranked by IAE),\n"
                "a square wave, a sequence, noise, a chirp or anything else (output-error fits);\n"
                "every route's models scored on data they were not fitted to, the best by validation fit.",
                identify_epilog(), "CSV file with the step response, or the record under any input", "capture")
    p.add_argument("--step-time", metavar="T",
                   help="when the input stepped, in seconds " + help_range("capture_time_s")
                        + " (default: from the input column, else from the output's own edge: "
                          "t = 0 if it is still at rest there, else its last sample at rest)")
    p.add_argument("--step-amplitude", metavar="A",
                   help="input step size in input units, either sign, size "
                        + help_range("step_amplitude")
                        + " (default: from the input column, else 1)")
    p.add_argument("--window", nargs=2, metavar=("T0", "T1"),
                   help="use only the samples from T0 to T1 seconds, each "
                        + help_range("capture_time_s") + ", T0 < T1 (default: the whole record)")
    p.add_argument("--format", choices=("auto",) + FORMATS, default="auto", type=_lower,
                   help="read the file as this layout (default: auto, recognised from its "
                        "header)")
    p.add_argument("--input-column", metavar="NAME|N",
                   help="input column by header name or number (time is 1); 'none' ignores it")
    p.add_argument("--output-column", metavar="NAME|N", help="output column by name or number")
    add_plain_columns_options(p)
    p.add_argument("--methods", nargs="+", metavar="NAME",
                   help="only these methods (space or comma separated), e.g. smith alfaro "
                        "least-squares")
    p.add_argument("--no-refine", action="store_true", help="skip the least-squares fits")
    p.add_argument("--method", choices=("correlation", "spectral"), type=_lower,
                   help="broadband input (PRBS or noise) only: the models of this estimate alone "
                        "(default: both; the best from the spectral fit when it has a valid one)")
    p.add_argument("--validate", metavar="CSV",
                   help="a second capture of the same plant, same layout and columns, to score every model on "
                        "(default: the capture's last third, whole periods of a sequence; a step capture is "
                        "scored on itself); resampled when its sample interval is a whole multiple or divisor")
    p.add_argument("--segment-length", metavar="N",
                   help="noise or random input: the Welch segment in samples, " + help_range("segment_length")
                        + " and at most half the record (default: reaching a decade below the slowest corner "
                          "the first estimate shows, at most a quarter of the record)")
    p.add_argument("--against", metavar="RESULT_JSON",
                   help="a design-plant result.json to compare fn, zeta, gain and overshoot with")
    _output_options(p, "write a PNG of the data against the best models")
    p.add_argument("--out", metavar="DIR",
                   help="write a build sheet folder: build-sheet.md, identify.png, result.json (and for a "
                        "broadband capture spectrum.csv, identify-freq's table), all or none")
    return p


def add_plain_columns_options(group) -> None:
    """``--sample-time`` and ``--columns``, a capture without a time column, on a parser or group:
    the one registration of every command that reads captures (identify, design-pid and
    analyze-pid ``--plant-capture``).

    Parameters
    ----------
    group : argparse.ArgumentParser or argument group
        Where the two options go.

    Returns
    -------
    None
    """
    group.add_argument("--sample-time", metavar="S",
                       help="the file has no time column (plain signal columns, as DaISy's u y): the sample "
                            "interval, seconds " + help_range("sample_time_s") + ", e.g. 0.08 or 80m")
    group.add_argument("--columns", metavar="NAMES",
                       help="with --sample-time: every column's name in order, e.g. u,y or y,u,x (u the input, "
                            "y the output; default: the header's names, else the first column the input and "
                            "the second the output)")


def capture_params(args) -> dict:
    """A command's capture options (``--step-time``, ``--step-amplitude``, ``--window``, ``--format``,
    ``--input-column``, ``--output-column``, ``--sample-time``, ``--columns``, ``--methods``,
    ``--no-refine``; any not registered reads as not given) as the plain parameters of
    :func:`~designer.identify.spec.identify_spec`: the one mapping of every command that identifies a
    capture (identify, design-pid and analyze-pid ``--plant-capture``).

    Parameters
    ----------
    args : argparse.Namespace
        The parsed options.

    Returns
    -------
    dict
        Parameter -> value as typed (None: not given), in the options' order; ``refine`` last.
    """
    return {**{param: getattr(args, dest, None) for param, dest in CAPTURE_DESTS},
            "refine": not getattr(args, "no_refine", False)}


def capture_spec(args, capture, **more):
    """The :class:`~designer.identify.spec.IdentifySpec` of ``capture`` from a command's capture options
    (:func:`capture_params`) and ``more`` (the spec's other fields).

    Parameters
    ----------
    args : argparse.Namespace
        The parsed options.
    capture : str
        The file.
    **more
        Further fields of the spec.

    Returns
    -------
    IdentifySpec
        Checked on construction (its errors name the spec's parameters: :data:`.common.FLAGS`).
    """
    from ..identify.spec import identify_spec
    return identify_spec({"capture": capture, **capture_params(args), **more})


#: the spec's parameters -> the capture options' argparse dests (their flags: :data:`.common.FLAGS`)
CAPTURE_DESTS = (("step_time_s", "step_time"), ("step_amplitude", "step_amplitude"), ("window", "window"),
                 ("fmt", "format"), ("input_column", "input_column"), ("output_column", "output_column"),
                 ("sample_time_s", "sample_time"), ("column_names", "columns"), ("methods", "methods"))


def identify_spec_of(args):
    """``identify``'s options as the library's request (its capture, ``--method``, ``--validate``,
    ``--segment-length`` and ``--against`` with the capture options of :func:`capture_spec`).

    Parameters
    ----------
    args : argparse.Namespace
        The parsed ``identify`` options.

    Returns
    -------
    IdentifySpec
        The request.
    """
    return capture_spec(args, args.capture, method=args.method, validate=args.validate,
                        segment_length=args.segment_length, against=args.against)


def identify_run(args) -> int:
    """``identify``'s action: the options as the library's request
    (:class:`~designer.identify.spec.IdentifySpec`), identified by
    :func:`~designer.identify.spec.identify_file`; a frequency-response table analysed and printed as
    ``identify-freq`` does, saying so (a first line, and ``"format": "frequency-table"`` in the JSON).

    Parameters
    ----------
    args : argparse.Namespace
        The parsed ``identify`` options.

    Returns
    -------
    int
        The exit status: 0 when done.
    """
    from ..identify.report import bode_fit_plot, broadband_plot, broadband_text, fit_plot, freq_text, step_text
    from ..identify.spec import frequency_table_header, header_text, identify_dict, identify_file
    spec = identify_spec_of(args)
    header = frequency_table_header(args.capture)
    if header is None:
        def text(r):
            return broadband_text(r) if hasattr(r, "excitation") else step_text(r)

        def plot(r):
            return broadband_plot(r) if hasattr(r, "excitation") else fit_plot(r)

        def identify(args):
            if args.plot:
                check_output_path(args.plot, "--plot")
            return identify_file(spec)
        return _run(args, identify, text, plot)
    if args.plot and not spec.given() and args.out is None:
        check_output_path(args.plot, "--plot")
    result = identify_file(spec, ("out_folder",) if args.out is not None else ())
    if args.plot:
        write_png(args.plot, bode_fit_plot(result))
    if args.json:
        print_output(json.dumps(json_safe(identify_dict(result)), indent=2, allow_nan=False))
    else:
        print_output(f"Format: frequency table (header {header_text(header)}), analysed as identify-freq does\n"
                     + freq_text(result) + (f"\n\nPlot written to {args.plot}" if args.plot else ""))
    return 0


def identify_main(argv=None) -> int:
    """Console entry point ``identify``.

    Parameters
    ----------
    argv : list of str, optional
        The arguments; None reads ``sys.argv[1:]``.

    Returns
    -------
    int
        The exit status (see :func:`~designer.cli.common.run_cli`).
    """
    return run_cli("identify", build_parser, identify_run, argv)


# --------------------------------------------------------------------------- identify-freq

def freq_epilog() -> str:
    """The ``identify-freq --help`` epilog with the validity rule and the input limits."""
    from ..identify.frequency import BAND_FACTOR, MAX_FIT_ERROR
    return FREQ_EPILOG.format(max_err=100 * MAX_FIT_ERROR, band=BAND_FACTOR,
                              size=size_text(MAX_TABLE_BYTES), rows=MAX_POINTS,
                              f_rng=RANGES["freq_hz"].text(), db_rng=RANGES["gain_db"].text(),
                              ratio_rng=RANGES["gain_ratio"].text(),
                              ph_rng=RANGES["phase_deg"].text())


def _lower(text: str) -> str:
    return text.strip().lower()


def build_freq_parser() -> argparse.ArgumentParser:
    """The ``identify-freq`` command line.

    Returns
    -------
    argparse.ArgumentParser
        The parser of ``identify-freq``'s options.
    """
    p = _parser("identify-freq", "identify-freq: plant models from a measured frequency response "
                "(Bode table).",
                freq_epilog(), "CSV table: frequency, gain[, phase]", "table")
    # units in any case: dB, Hz, Rad/s
    p.add_argument("--gain-units", choices=GAIN_UNITS, type=_lower,
                   help="gain in decibels or as the amplitude ratio Vout/Vin (default: from the "
                        "header, else db)")
    p.add_argument("--phase-units", choices=PHASE_UNITS, type=_lower,
                   help="phase in degrees, radians, or the output's time shift in seconds "
                        "(default: from the header, else deg)")
    p.add_argument("--freq-units", choices=FREQ_UNITS, type=_lower,
                   help="frequency in Hz or rad/s (default: from the header, else hz)")
    _output_options(p, "write a Bode plot of the data and the fits", json_first=True)
    return p


def identify_table(args):
    """Identify from parsed ``identify-freq`` arguments; returns the
    :class:`~designer.identify.frequency.FreqIdentifyResult`."""
    from ..identify.frequency import identify_freq
    from ..identify.io import read_freq_table
    if args.plot:
        check_output_path(args.plot, "--plot")
    data = read_freq_table(args.table, gain_units=args.gain_units,
                           phase_units=args.phase_units, freq_units=args.freq_units)
    return identify_freq(data)


def identify_freq_main(argv=None) -> int:
    """Console entry point ``identify-freq``.

    Parameters
    ----------
    argv : list of str, optional
        The arguments; None reads ``sys.argv[1:]``.

    Returns
    -------
    int
        The exit status (see :func:`~designer.cli.common.run_cli`).
    """
    from ..identify.report import bode_fit_plot, freq_text
    return run_cli("identify-freq", build_freq_parser,
                   lambda args: _run(args, identify_table, freq_text, bode_fit_plot), argv)


if __name__ == "__main__":  # pragma: no cover
    sys.exit(identify_main())
