"""``identify``: plant models from a measured or simulated step response.

Reads a CSV capture (generic, Tektronix, Rigol or this project's waveforms),
runs every classical method of seeds 000-003 plus least squares, and prints
them ranked by IAE; ``--json`` prints one JSON object instead.
"""

from __future__ import annotations

import argparse
import json
import sys
from pathlib import Path

from ..core.errors import DesignError
from ..core.jsonio import json_safe
from ..core.ranges import RANGES, help_range, parse_in_range
from ..core.units import parse_value
from ..report.plots import png_bytes
from .common import OneLineParser, print_output, run_cli

EPILOG = """\
examples:
  identify capture.csv                         # t,y or t,u,y (header optional)
  identify scope.csv --step-time 0 --step-amplitude 2
        a scope export of the output only: step at t = 0 s, input step of 2 V
  identify plant.csv --json > models.json      # methods[], best, preprocessing
  identify bench.csv --against reports/plant_fc3500_z0.2/result.json
        compare fn, zeta, gain and overshoot with the design and its part tolerances
  identify sq330.csv --plot fit.png            # a 330 Hz square wave: steps averaged
  identify capture.csv --methods smith,alfaro,least-squares

input layouts: generic CSV (comma, semicolon with decimal comma, tab), Tektronix
TDS/TBS and MSO/DPO exports, Rigol X,CH1,Start,Increment exports, design-plant /
design-pid waveforms (time_s,...). With two signals the first is the input and
the second the output unless their names say otherwise (u/vin/in, y/vout/out);
--input-column/--output-column choose by name or column number.

methods: first order (ziegler-nichols, hagglund, smith, sundaresan-krishnaswamy,
nishikawa, alfaro, broida, chen-yang, ho, viteckova), double pole
(ho-double-pole, viteckova-double-pole), the second-order methods when
available, and least-squares fits (fopdt, overdamped, underdamped) with 95 %
confidence intervals. Parameters: K, tau_s, theta_s; K, wn_rad_s, zeta,
theta_s; K, tau1_s, tau2_s, theta_s.

limits: a capture of at most {size} and {rows:,} samples; every time
{t_rng} and the record {span_rng} long; every sample {v_rng}
(file units); the output's step {step_rng} in size.

exit status: 0 success, 2 bad input (one line on stderr saying what and why).
"""


def epilog() -> str:
    """The --help epilog with the input limits filled in."""
    from ..core.fileio import MAX_CAPTURE_BYTES, MAX_CAPTURE_ROWS, size_text
    return EPILOG.format(size=size_text(MAX_CAPTURE_BYTES), rows=MAX_CAPTURE_ROWS,
                         t_rng=RANGES["capture_time_s"].text(),
                         span_rng=RANGES["capture_span_s"].text(),
                         v_rng=RANGES["capture_value"].text(),
                         step_rng=RANGES["output_step"].text())


def step_time(text) -> float:
    """``--step-time``: engineering notation, inside ``RANGES["capture_time_s"]``."""
    return parse_in_range(text, "--step-time", "capture_time_s")


def step_amplitude(text) -> float:
    """``--step-amplitude``: non-zero, its size inside ``RANGES["step_amplitude"]``
    (a negative value is a falling step)."""
    value = parse_value(text, "--step-amplitude")
    if value == 0:
        raise DesignError("--step-amplitude must be non-zero (its size "
                          f"{RANGES['step_amplitude'].text()}, either sign)")
    RANGES["step_amplitude"].check(abs(value), "the size of --step-amplitude (either sign)",
                                   shown=repr(text))
    return value


def build_parser() -> argparse.ArgumentParser:
    p = OneLineParser(prog="identify",
                description="Identify plant models (FOPDT, double pole, second order with dead\n"
                            "time) from a measured or simulated step response, ranked by IAE.",
                epilog=epilog(), formatter_class=argparse.RawDescriptionHelpFormatter)
    p.add_argument("capture", help="CSV file with the step response")
    p.add_argument("--step-time", metavar="T",
                   help="when the input stepped, in seconds " + help_range("capture_time_s")
                        + " (default: from the input column, else t = 0 if the record spans "
                          "it, else the first sample)")
    p.add_argument("--step-amplitude", metavar="A",
                   help="input step size in input units, either sign, size "
                        + help_range("step_amplitude")
                        + " (default: from the input column, else 1)")
    p.add_argument("--input-column", metavar="NAME|N",
                   help="input column by header name or number (time is 1); 'none' ignores it")
    p.add_argument("--output-column", metavar="NAME|N", help="output column by name or number")
    p.add_argument("--methods", nargs="+", metavar="NAME",
                   help="only these methods (space or comma separated), e.g. smith alfaro "
                        "least-squares")
    p.add_argument("--no-refine", action="store_true", help="skip the least-squares fits")
    p.add_argument("--against", metavar="RESULT_JSON",
                   help="a design-plant result.json to compare fn, zeta, gain and overshoot with")
    p.add_argument("--plot", metavar="OUT_PNG", help="write a PNG of the data against the best models")
    p.add_argument("--json", action="store_true", help="print one JSON object instead of the table")
    return p


def run(args):
    """Identify from parsed arguments, write the plot; return the result."""
    from ..identify.io import read_capture

    t_step = None if args.step_time is None else step_time(args.step_time)
    amp = None if args.step_amplitude is None else step_amplitude(args.step_amplitude)
    if args.plot:
        check_output_path(args.plot, "--plot")
    # The file is read before scipy is imported, so bad input fails fast.
    cap = read_capture(args.capture, input_column=args.input_column,
                       output_column=args.output_column)
    from ..identify.step import compare_with_design, identify_step, load_design
    design = load_design(args.against) if args.against else None
    u = cap.u
    if t_step is not None:
        u = None if amp is not None else u
    result = identify_step(cap.t, cap.y, u, step_time=t_step, step_amplitude=amp,
                           methods=args.methods, refine=not args.no_refine,
                           capture=cap.to_dict())
    if design is not None:
        result.comparison = compare_with_design(result, design)
    if args.plot:
        plot_fit(result, args.plot)
    return result


def check_output_path(path, option: str) -> None:
    """Refuse, before any work, an output file that cannot be written: the path
    is a directory, or one of its parents is a file. (Nothing is created here:
    a run refused later must leave no trace.)"""
    from ..core.fileio import shown
    if str(path) == "":
        raise DesignError(f"{option} needs a file name, such as fit.png")
    p = Path(path)
    try:
        is_dir = str(path) in (".", "..") or p.is_dir()
        blocker = next((q for q in p.parents if q.exists()), None)
        blocked = blocker is not None and not blocker.is_dir()
    except (OSError, ValueError) as exc:   # a name too long, a NUL byte
        raise DesignError(f"{option} {shown(path)} is not a usable file name: "
                          f"{getattr(exc, 'strerror', None) or exc}") from None
    if is_dir:
        raise DesignError(f"{option} {shown(path)} is a directory; give a file name such as "
                          "fit.png")
    if blocked:
        raise DesignError(f"{option} {shown(path)}: cannot create directory {shown(blocker)}: "
                          "a file of that name exists")


def write_png(path, fig, option: str = "--plot") -> None:
    """Write a figure atomically; an OS error (disk full, permission) is one line."""
    from ..core.fileio import atomic_write
    from ..core.fileio import shown
    try:
        atomic_write(path, png_bytes(fig))
    except OSError as exc:
        raise DesignError(f"{option}: cannot write {shown(path)}: "
                          f"{exc.strerror or exc}") from None


def identify_main(argv=None) -> int:
    """Console entry point ``identify``."""
    return run_cli("identify", build_parser, _main, argv)


def _main(args) -> int:
    result = run(args)
    if args.json:
        print_output(json.dumps(json_safe(result.to_dict()), indent=2, allow_nan=False))
    else:
        print_output(result.to_text() + (f"\n\nPlot written to {args.plot}" if args.plot else ""))
    return 0


def plot_fit(result, path, n_models: int = 3) -> None:
    """PNG of the data against the best ``n_models`` valid models (written atomically)."""
    import matplotlib
    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    from ..identify.preprocess import block_mean
    from ..identify.structures import model_step

    s = result.step
    t, y = block_mean(s.t_raw, s.y_raw, 20000)
    fig, (ax, axr) = plt.subplots(2, 1, figsize=(8, 6), dpi=110, sharex=True,
                                  gridspec_kw={"height_ratios": [3, 1]})
    tt = t - s.t_step
    ax.plot(tt, y, color="k", lw=2.2, alpha=0.35, label="data")
    shown = [m for m in result.methods if m.valid][:n_models]
    for m, style in zip(shown, ("-", "--", ":")):
        ym = s.y0 + s.amplitude * model_step(m.model, m.params, tt)
        line, = ax.plot(tt, ym, lw=1.2, ls=style, label=f"{m.name} ({m.model}), IAE {m.iae:.3g}")
        axr.plot(tt, y - ym, lw=0.8, ls=style, color=line.get_color())
    for a in (ax, axr):
        a.axvline(0.0, color="k", lw=0.6, ls=":")
        a.grid(True, alpha=0.3)
    axr.set_xlabel("time since the step (s)")
    axr.set_ylabel("data - model")
    ax.set_ylabel(result.capture.get("output", "output") if result.capture else "output")
    ax.set_title("Step response: data and best identified models")
    ax.legend(fontsize=8, loc="best")
    fig.tight_layout()
    write_png(path, fig)


if __name__ == "__main__":  # pragma: no cover
    sys.exit(identify_main())
