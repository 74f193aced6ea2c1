"""``simulate-capture``: a step capture of a plant known only as a model,
simulated in ngspice (:func:`designer.spice.model_step.simulate_step`) and
written as the CSV ``t,u,y`` that ``identify`` and ``design-pid
--plant-capture`` read, with the model, the step, the noise and the seed in
``#`` comment lines above the header.
"""

from __future__ import annotations

import io
import sys

import numpy as np

from ..core.errors import DesignError
from ..core.ranges import RANGES, help_range, parse_in_range
from ..core.units import format_eng
from .common import command_parser, print_output, run_cli

__all__ = ["build_parser"]

EPILOG = """\
examples:
  simulate-capture --plant-tf "K=1.25 tau=124.6m" --step 2 --out motor.csv
        seed 000's DC motor (Km = 1.25, tau_m = 0.1246 s) driven with 2 V: W(inf) = 2.5
  simulate-capture --plant-tf "K=2 tau=1m theta=200u" --noise 5m --lsb 20m --seed 7 --out fopdt.csv
        a scope's view of it: 5 mV rms of noise on each channel, 20 mV steps (an 8-bit scope at 0.5 V/div)
  simulate-capture --plant-tf "K=1 fn=500 zeta=0.3" --points 5001 --duration 20m --out ring.csv
  identify motor.csv                    # reads the file as written ('#' lines are comments)
  design-pid --plant-capture motor.csv --tuning amigo

model (--plant-tf, as design-pid's): {forms}
Values in engineering notation (124.6m, 200u, 5m).

the capture: t from 0 to --duration in --points uniform samples; the input u
steps from 0 to --step volts at --step-time (rising within a thousandth of a
sample interval); y is the plant's output, simulated in ngspice (the model as
native integrators, its dead time a matched lossless line), noiseless within
0.1 % of the step of the model's exact response. Gaussian noise of standard
deviation --noise is added to u and to y (each its own draws, from numpy's
default_rng(--seed): the same seed gives the same file), then each is rounded
to a multiple of --lsb. The '#' lines above the header record the model, the
step, the record, the noise, the LSB, the seed and the simulator.

limits: --step {step}; --step-time 0 or later, before the end of the record;
--duration {span}, and at most {sim_steps:g} simulation steps (a fast model in a
long record is refused, saying the longest record); --points {points};
--noise {noise}; --lsb {lsb}; --seed a whole number {seed}.

exit status: 0 success, 2 bad input (one line on stderr saying what and why;
nothing written), 3 simulator error.
"""


def epilog() -> str:
    """The ``--help`` epilog with the model forms and every range filled in."""
    import textwrap

    from ..core.process_text import FORMS_TEXT
    from ..spice.deck import MAX_SIM_POINTS
    forms = textwrap.fill(FORMS_TEXT + ".", 80, initial_indent=" " * 36)[36:]
    return EPILOG.format(forms=forms, step=RANGES["step_v"].text(), span=RANGES["capture_span_s"].text(),
                         sim_steps=MAX_SIM_POINTS, points=RANGES["capture_points"].text(),
                         noise=RANGES["noise_v"].text(), lsb=RANGES["lsb_v"].text(), seed=RANGES["seed"].text())


def build_parser():
    """The ``simulate-capture`` command line."""
    p = command_parser("simulate-capture", "Simulate a plant model's step response in ngspice and write it as a "
                       "capture (CSV t,u,y) that identify reads.", epilog())
    p.add_argument("--plant-tf", metavar="MODEL", required=True,
                   help="the plant, typed as for design-pid, e.g. \"K=2 tau=1m theta=200u\" (forms below)")
    p.add_argument("--step", default="1", metavar="V", help=f"input step, volts {help_range('step_v')} (default 1)")
    p.add_argument("--step-time", metavar="S",
                   help="when the input steps, seconds, 0 or later and before the end of the record "
                        "(default 10 %% of --duration, moved half a sample interval later to fall between two "
                        "samples, where identify puts an edge it sees between them)")
    p.add_argument("--duration", metavar="S",
                   help=f"record length, seconds {help_range('capture_span_s')} (default 5 times the model's "
                        "2 %% settling time, dead time included)")
    p.add_argument("--points", default="2001", metavar="N",
                   help=f"samples, t = 0 to --duration inclusive {help_range('capture_points')} (default 2001)")
    p.add_argument("--noise", default="0", metavar="V",
                   help=f"standard deviation of Gaussian noise on u and y, volts {help_range('noise_v')} "
                        "(default 0)")
    p.add_argument("--lsb", default="0", metavar="V",
                   help=f"quantisation step of u and y, volts {help_range('lsb_v')} (default 0: none)")
    p.add_argument("--seed", default="0", metavar="N",
                   help=f"seed of the noise, a whole number {help_range('seed')} (default 0; recorded in the file)")
    p.add_argument("--simulator", default="pyspice", choices=("pyspice", "ngspice-cli"),
                   help="pyspice: ngspice shared library via PySpice (default); ngspice-cli: `ngspice -b` subprocess")
    p.add_argument("--out", required=True, metavar="FILE", help="the CSV to write (replaced whole)")
    return p


def _whole(text, option: str, key: str) -> int:
    """A whole number inside ``RANGES[key]`` (engineering notation allowed: 10k)."""
    value = parse_in_range(text, option, key)
    if value != int(value):
        raise DesignError(f"{option} must be a whole number {RANGES[key].text()}, got {text!r}")
    return int(value)


def _model(text):
    from ..core.process_text import parse_tf
    try:
        return parse_tf(text)
    except DesignError as exc:
        raise DesignError(f"--plant-tf {exc}") from None


def _options(args) -> dict:
    """The options as the library's arguments, each checked (one line naming the option)."""
    model = _model(args.plant_tf)
    opts = {"step_v": parse_in_range(args.step, "--step", "step_v"),
            "points": _whole(args.points, "--points", "capture_points"),
            "noise_v": parse_in_range(args.noise, "--noise", "noise_v"),
            "lsb_v": parse_in_range(args.lsb, "--lsb", "lsb_v"),
            "seed": _whole(args.seed, "--seed", "seed")}
    opts["duration_s"] = (None if args.duration is None
                          else parse_in_range(args.duration, "--duration", "capture_span_s"))
    opts["step_time_s"] = (None if args.step_time is None
                           else parse_in_range(args.step_time, "--step-time", "capture_time_s"))
    return model, opts


def _eng(v: float, unit: str) -> str:
    return "0 " + unit if v == 0 else format_eng(v, unit)


def header_lines(model, typed: str, opts: dict, simulator: str) -> list:
    """The ``#`` lines above the header: what made the capture, enough to make it again."""
    from .. import __version__
    from ..spice.simulate import ngspice_version
    version = ngspice_version(simulator)
    dt = opts["duration_s"] / (opts["points"] - 1)
    noise = ("none" if opts["noise_v"] == 0 else
             f"Gaussian, sigma {_eng(opts['noise_v'], 'V')} on u and on y (numpy default_rng)")
    return [f"# simulate-capture (designer {__version__}): a step response simulated in ngspice"
            f"{' ' + version if version else ''} ({simulator})",
            f"# model: {model.text()}",
            f"# plant-tf: {' '.join(typed.split())}",
            f"# step: u 0 V -> {_eng(opts['step_v'], 'V')} at t = {_eng(opts['step_time_s'], 's')} "
            f"({opts['step_time_s']!r} s)",
            f"# record: t = 0 s to {_eng(opts['duration_s'], 's')} ({opts['duration_s']!r} s), {opts['points']} "
            f"samples, interval {_eng(dt, 's')}",
            f"# noise: {noise}; lsb: {'none' if opts['lsb_v'] == 0 else _eng(opts['lsb_v'], 'V')}",
            f"# seed: {opts['seed']}"]


def csv_text(comments, t, u, y) -> str:
    """The file: the comment lines, the header ``t,u,y``, one row per sample
    (12 significant digits of time, 10 of each signal)."""
    buf = io.StringIO()
    buf.write("\n".join(comments) + "\nt,u,y\n")
    # + 0.0: a sample rounded to -0 is written 0
    np.savetxt(buf, np.column_stack([t, np.asarray(u) + 0.0, np.asarray(y) + 0.0]), fmt=("%.12g", "%.10g", "%.10g"),
               delimiter=",")
    return buf.getvalue()


def capture_run(args) -> int:
    from ..core.fileio import atomic_write, shown
    from .identify import check_output_path
    from ..spice.model_step import default_duration_s, default_step_time_s, simulate_step
    model, opts = _options(args)
    if args.out == "":
        raise DesignError("--out needs a file name, such as capture.csv")
    check_output_path(args.out, "--out")
    if opts["duration_s"] is None:
        opts["duration_s"] = default_duration_s(model)
    if opts["step_time_s"] is None:
        opts["step_time_s"] = default_step_time_s(opts["duration_s"], opts["points"])
    t, u, y = simulate_step(model, simulator=args.simulator, **opts)
    atomic_write(args.out, csv_text(header_lines(model, args.plant_tf, opts, args.simulator), t, u, y))
    print_output(f"Wrote {shown(args.out)}: {opts['points']} samples of t,u,y, t = 0 s to "
                 f"{_eng(opts['duration_s'], 's')}; u steps 0 V -> {_eng(opts['step_v'], 'V')} at "
                 f"{_eng(opts['step_time_s'], 's')}\nModel: {model.text()}\n"
                 f"Noise: {_eng(opts['noise_v'], 'V')} rms, LSB {_eng(opts['lsb_v'], 'V')}, seed {opts['seed']}")
    return 0


def simulate_capture_main(argv=None) -> int:
    """Console entry point ``simulate-capture``."""
    return run_cli("simulate-capture", build_parser, capture_run, argv)


if __name__ == "__main__":  # pragma: no cover
    sys.exit(simulate_capture_main())
