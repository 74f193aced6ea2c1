"""``simulate-capture``: a step capture of a plant known only as a model,
simulated in ngspice (:func:`designer.spice.model_step.simulate_step`) and
written as the CSV ``t,u,y`` that ``identify`` and ``design-pid
--plant-capture`` read, with the model, the step, the noise and the seed in
``#`` comment lines above the header. ``--input`` plays another input instead
(a PRBS, a random binary signal, a chirp or a recorded signal:
:mod:`designer.core.excitation`, :func:`designer.spice.model_step.simulate_input`).
"""

from __future__ import annotations

import io
import math
import sys

import numpy as np

from ..core.errors import DesignError
from ..core.ranges import RANGES, help_range, parse_in_range
from ..core.units import format_eng
from .common import command_parser, print_output, run_cli

__all__ = ["build_parser"]

#: the samples of a step capture when --points is not given
DEFAULT_POINTS = 2001

EPILOG = """\
examples:
  simulate-capture --plant-tf "K=1.25 tau=124.6m" --step 2 --out motor.csv
        seed 000's DC motor (Km = 1.25, tau_m = 0.1246 s) driven with 2 V: W(inf) = 2.5
  simulate-capture --plant-tf "K=2 tau=1m theta=200u" --noise 5m --lsb 20m --seed 7 --out fopdt.csv
        a scope's view of it: 5 mV rms of noise on each channel, 20 mV steps (an 8-bit scope at 0.5 V/div)
  simulate-capture --plant-tf "K=1 fn=500 zeta=0.3" --points 5001 --duration 20m --out ring.csv
  simulate-capture --plant-tf "K=2 poles=[(1ms+1)^2] theta=200u" --input random-binary --switch-prob 0.2 \\
        --noise 5m --seed 3 --out rbs.csv     a random binary input, as the DaISy dryer's
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

inputs (--input): step (the default, as above); prbs, a maximum-length
sequence between 0 and --step V, its clock and bits chosen for the plant as
make-prbs --for-plant chooses them (or --clock, --bits), the record 3 periods;
random-binary, between 0 and --step V, switching with probability
--switch-prob (default 0.2) at each tick of --clock (default: the prbs clock
for the plant), the switches drawn from numpy default_rng([--seed, 1]), the
record 25 settling times (whole ticks); chirp, a logarithmic sine sweep
between 0 and --step V from --f-start to --f-stop (default: a hundredth of
the plant's bandwidth to 3 times it), the record 25 settling times; or a
CSV of time,value rows (a
recorded input, any layout identify reads), each value held from its time on,
the record to its last time. Each starts from rest at 0 V; the '#' lines
record it. Default --points for them: a whole number of samples a clock tick,
at least 10 (every tick on a sample: u holds each level from its sample on),
or 20 a period of the sweep's top; at least 2001.

limits: --step {step}; --step-time 0 or later, before the end of the record;
--duration {span}, and at most {sim_steps:g} simulation steps (a fast model in a
long record is refused, saying the longest record); --points {points};
--noise {noise}; --lsb {lsb}; --seed a whole number {seed}; --clock {clock};
--bits 3 to 20; --switch-prob {prob}; --f-start, --f-stop {chirp} (f-start below
f-stop, f-stop at most a tenth of the sample rate).

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
                         noise=RANGES["noise_v"].text(), lsb=RANGES["lsb_v"].text(), seed=RANGES["seed"].text(),
                         clock=RANGES["prbs_clock_hz"].text(), prob=RANGES["switch_probability"].text(),
                         chirp=RANGES["chirp_hz"].text())


def build_parser():
    """The ``simulate-capture`` command line.

    Returns
    -------
    argparse.ArgumentParser
        The parser of ``simulate-capture``'s options.
    """
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
    p.add_argument("--points", metavar="N",
                   help=f"samples, t = 0 to --duration inclusive {help_range('capture_points')} (default 2001; "
                        "another --input: see below)")
    p.add_argument("--noise", default="0", metavar="V",
                   help=f"standard deviation of Gaussian noise on u and y, volts {help_range('noise_v')} "
                        "(default 0)")
    p.add_argument("--lsb", default="0", metavar="V",
                   help=f"quantisation step of u and y, volts {help_range('lsb_v')} (default 0: none)")
    p.add_argument("--seed", default="0", metavar="N",
                   help=f"seed of the noise, a whole number {help_range('seed')} (default 0; recorded in the file)")
    p.add_argument("--input", default="step", metavar="KIND|FILE",
                   help="the input: step (default), prbs, random-binary, chirp, or a CSV of time,value rows "
                        "(each value held from its time on)")
    p.add_argument("--clock", metavar="HZ", help=f"prbs, random-binary: the clock {help_range('prbs_clock_hz')} "
                                                 "(default: chosen for the plant as make-prbs --for-plant does)")
    p.add_argument("--bits", metavar="N", help="prbs: bits of the sequence, 3 to 20 (default: chosen for the plant)")
    p.add_argument("--switch-prob", metavar="P",
                   help=f"random-binary: chance of a switch at each clock tick {help_range('switch_probability')} "
                        "(default 0.2)")
    p.add_argument("--f-start", metavar="HZ", help=f"chirp: first frequency {help_range('chirp_hz')} (default: "
                                                   "a hundredth of the plant's bandwidth)")
    p.add_argument("--f-stop", metavar="HZ", help=f"chirp: last frequency {help_range('chirp_hz')} (default: 3 "
                                                  "times the plant's bandwidth)")
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
            "input": input_kind(args.input),
            "points": None if args.points is None else _whole(args.points, "--points", "capture_points"),
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


def header_lines(model, typed: str, opts: dict, simulator: str, exc=None) -> list:
    """The ``#`` lines above the header: what made the capture, enough to make it again
    (``exc``: the :class:`~designer.core.excitation.Excitation` of an input other than a step)."""
    from .. import __version__
    from ..spice.simulate import ngspice_version
    version = ngspice_version(simulator)
    dt = opts["duration_s"] / (opts["points"] - 1)
    noise = ("none" if opts["noise_v"] == 0 else
             f"Gaussian, sigma {_eng(opts['noise_v'], 'V')} on u and on y (numpy default_rng)")
    what = "a step response" if exc is None else f"the response to a {exc.kind} input"
    return [f"# simulate-capture (designer {__version__}): {what} simulated in ngspice"
            f"{' ' + version if version else ''} ({simulator})",
            f"# model: {model.text()}",
            f"# plant-tf: {' '.join(typed.split())}",
            (f"# step: u 0 V -> {_eng(opts['step_v'], 'V')} at t = {_eng(opts['step_time_s'], 's')} "
             f"({opts['step_time_s']!r} s)") if exc is None else f"# input: {exc.text}",
            f"# record: t = 0 s to {_eng(opts['duration_s'], 's')} ({opts['duration_s']!r} s), {opts['points']} "
            f"samples, interval {_eng(dt, 's')}",
            f"# noise: {noise}; lsb: {'none' if opts['lsb_v'] == 0 else _eng(opts['lsb_v'], 'V')}",
            f"# seed: {opts['seed']}" + ("" if exc is None or exc.kind != "random-binary" else
                                         " (the noise: numpy default_rng(seed); the switches: default_rng([seed, 1]))")]


def csv_text(comments, t, u, y) -> str:
    """The file: the comment lines, the header ``t,u,y``, one row per sample
    (12 significant digits of time, 10 of each signal)."""
    buf = io.StringIO()
    buf.write("\n".join(comments) + "\nt,u,y\n")
    # + 0.0: a sample rounded to -0 is written 0
    np.savetxt(buf, np.column_stack([t, np.asarray(u) + 0.0, np.asarray(y) + 0.0]), fmt=("%.12g", "%.10g", "%.10g"),
               delimiter=",")
    return buf.getvalue()


#: the options of one input kind: option -> (argparse dest, the kinds that take it)
INPUT_OPTIONS = {"--step-time": ("step_time", ("step",)), "--clock": ("clock", ("prbs", "random-binary")),
                 "--bits": ("bits", ("prbs",)), "--switch-prob": ("switch_prob", ("random-binary",)),
                 "--f-start": ("f_start", ("chirp",)), "--f-stop": ("f_stop", ("chirp",))}
#: a random binary or chirp record's default length, in the model's 2 % settling times
EXPERIMENT_SETTLING_TIMES = 25.0
#: default samples: at least this many a clock tick (prbs, random-binary) ...
SAMPLES_PER_TICK = 10
#: ... or a period of the chirp's top frequency
SAMPLES_PER_PERIOD = 20


def input_kind(text: str) -> str:
    """``--input``: one of :data:`~designer.core.excitation.INPUT_KINDS`, or ``file`` for a path
    that exists; anything else refused in one line.

    Parameters
    ----------
    text : str
        The option as typed.

    Returns
    -------
    str
        The kind, or ``"file"``.
    """
    from pathlib import Path

    from ..core.excitation import INPUT_KINDS
    from ..core.fileio import shown
    kind = str(text).strip().lower()
    if kind in INPUT_KINDS:
        return kind
    if str(text) and Path(text).exists():
        return "file"
    raise DesignError(f"--input {shown(text)} is neither {', '.join(INPUT_KINDS[:-1])} nor {INPUT_KINDS[-1]}, "
                      "nor a file (a CSV of time,value rows)")


def _plan(model, args, level_v):
    """make-prbs' plan for the plant (its clock and bits rules), --clock and --bits kept."""
    from ..core.prbs import check_bits, plan_for_plant
    from .prbs import bandwidth_hz
    dt = None if args.clock is None else 1.0 / parse_in_range(args.clock, "--clock", "prbs_clock_hz")
    bits = None if getattr(args, "bits", None) is None else check_bits(args.bits)
    if model.integrating and (dt is None or bits is None and args.input == "prbs"):
        raise DesignError(f"the model {model.text()} is integrating: it never settles, so no clock is chosen "
                          "for it; give --clock" + (" and --bits" if args.input == "prbs" else ""))
    if model.integrating:
        from ..core.prbs import PrbsPlan
        return PrbsPlan(bits or 3, dt, level_v / 2, level_v / 2, 3)
    return plan_for_plant(model.settling_time_s, bandwidth_hz(model), amplitude=level_v / 2, offset=level_v / 2,
                          periods=3, dt_s=dt, bits=bits, plant=f"the plant {model.text()}")


def excitation(model, args, opts: dict):
    """The input of ``--input`` other than a step (:mod:`designer.core.excitation`), ``opts``'s
    duration and points filled when not given; an option of another kind refused in one line.

    Parameters
    ----------
    model : ProcessModel
        The plant (its settling time and bandwidth set the defaults).
    args : argparse.Namespace
        The parsed options.
    opts : dict
        The checked options (:func:`_options`); ``duration_s`` and ``points`` filled in place.

    Returns
    -------
    Excitation or None
        None for a step.
    """
    from ..core import excitation as ex
    from ..spice.model_step import default_duration_s
    kind = opts["input"]
    wrong = [o for o, (dest, kinds) in INPUT_OPTIONS.items() if getattr(args, dest, None) is not None
             and kind not in kinds]
    if wrong:
        takes = INPUT_OPTIONS[wrong[0]][1]
        raise DesignError(f"{wrong[0]} is for --input {' or '.join(takes)}, not {kind}: drop it")
    if kind == "step":
        return None
    level = opts["step_v"]

    def fill(duration, per_s):
        if opts["duration_s"] is None:
            opts["duration_s"] = duration
        if opts["points"] is None:
            opts["points"] = int(min(1_000_000, max(DEFAULT_POINTS, math.ceil(per_s * opts["duration_s"]) + 1)))

    def fill_clocked(duration, clock):
        """A record of whole clock ticks, each a whole number of samples (at least SAMPLES_PER_TICK):
        every tick on a sample."""
        if opts["duration_s"] is None:
            opts["duration_s"] = math.ceil(duration / clock * (1 - 1e-12)) * clock
        if opts["points"] is None:
            ticks = max(1, round(opts["duration_s"] / clock))
            each = max(SAMPLES_PER_TICK, math.ceil((DEFAULT_POINTS - 1) / ticks))
            opts["points"] = int(min(ticks * each, (1_000_000 - 1) // ticks * ticks) + 1)

    if kind == "prbs":
        plan = _plan(model, args, level)
        fill_clocked(plan.periods * plan.period_s, plan.dt_s)
        return ex.prbs_input(plan, level, opts["duration_s"], opts["points"])
    if kind == "random-binary":
        p = 0.2 if args.switch_prob is None else parse_in_range(args.switch_prob, "--switch-prob",
                                                                 "switch_probability")
        clock = _plan(model, args, level).dt_s
        fill_clocked(EXPERIMENT_SETTLING_TIMES / 5.0 * default_duration_s(model), clock)
        return ex.random_binary_input(p, clock, level, opts["duration_s"], opts["points"], opts["seed"])
    if kind == "chirp":
        from .prbs import bandwidth_hz
        bw = None if model.integrating else bandwidth_hz(model)
        if bw is None and (args.f_start is None or args.f_stop is None):
            raise DesignError(f"the model {model.text()} is integrating: give --f-start and --f-stop")
        f0 = bw / 100 if args.f_start is None else parse_in_range(args.f_start, "--f-start", "chirp_hz")
        f1 = 3 * bw if args.f_stop is None else parse_in_range(args.f_stop, "--f-stop", "chirp_hz")
        if not f0 < f1:
            raise DesignError(f"--f-start ({format_eng(f0, 'Hz')}) must be below --f-stop ({format_eng(f1, 'Hz')})")
        fill(EXPERIMENT_SETTLING_TIMES / 5.0 * default_duration_s(model), SAMPLES_PER_PERIOD * f1)
        rate = (opts["points"] - 1) / opts["duration_s"]
        if f1 > rate / 10:
            raise DesignError(f"--f-stop {format_eng(f1, 'Hz')} is above a tenth of the sample rate "
                              f"({format_eng(rate, 'Hz')}): give more --points or a lower --f-stop")
        return ex.chirp_input(f0, f1, level, opts["duration_s"], opts["points"])
    from ..core.fileio import shown
    from ..identify.io import read_capture
    cap = read_capture(args.input, input_column="none")
    from ..spice.model_step import MAX_VOLTS
    got = ex.file_input(cap.t, cap.y, shown(args.input), min(MAX_VOLTS, RANGES["step_v"].hi))
    fill(float(cap.t[-1]), 0.0)
    return got


def capture_run(args) -> int:
    from ..core.fileio import atomic_write, shown
    from .identify import check_output_path
    from ..spice.model_step import default_duration_s, default_step_time_s, simulate_step
    model, opts = _options(args)
    if args.out == "":
        raise DesignError("--out needs a file name, such as capture.csv")
    check_output_path(args.out, "--out")
    exc = excitation(model, args, opts)
    opts.pop("input")
    if exc is not None:
        from ..spice.model_step import simulate_input
        t, u, y = simulate_input(model, exc, opts["duration_s"], opts["points"], noise_v=opts["noise_v"],
                                 lsb_v=opts["lsb_v"], seed=opts["seed"], simulator=args.simulator)
        atomic_write(args.out, csv_text(header_lines(model, args.plant_tf, opts, args.simulator, exc), t, u, y))
        print_output(f"Wrote {shown(args.out)}: {opts['points']} samples of t,u,y, t = 0 s to "
                     f"{_eng(opts['duration_s'], 's')}; input {exc.text}\nModel: {model.text()}\n"
                     f"Noise: {_eng(opts['noise_v'], 'V')} rms, LSB {_eng(opts['lsb_v'], 'V')}, seed {opts['seed']}")
        return 0
    if opts["points"] is None:
        opts["points"] = DEFAULT_POINTS
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
