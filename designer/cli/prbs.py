"""``make-prbs``: the pseudo-random binary sequence a bench function generator
plays for identification (seed 003, section 2.4), as files the generator's
software, a spreadsheet and ngspice read.

The maths (the m-sequence, the clock and bits chosen for a plant, the file
texts) is :mod:`designer.core.prbs`; this module reads the command line
and the plant model (``--plant-tf`` as design-pid reads it,
:func:`designer.core.process_text.parse_tf`; ``--plant-model``, an identify
or identify-freq JSON, :func:`designer.pid.plant_source.model_from_json`)
and writes the bundle atomically (all files or none).
"""

from __future__ import annotations

import argparse
import json
import math
import sys

from ..core.errors import DesignError
from ..core.jsonio import json_safe
from ..core.ranges import help_range, parse_in_range
from ..core.units import format_eng, parse_value
from .common import OneLineParser, print_output, run_cli

__all__ = ["build_parser", "make_prbs_main"]

#: the files of the bundle: name -> what it is
FILES = {"prbs_awg.csv": "arbitrary-waveform CSV for the generator's software (sample_rate_hz line, "
                         "then one value per clock interval)",
         "prbs.csv": "time_s,value: the level from each time on",
         "prbs.cir": "ngspice PWL source as a subcircuit: X1 <node> prbs_source"}
#: the most values a bundle holds (periods x N)
MAX_VALUES = 1 << 22

EPILOG = """\
examples:
  make-prbs --bits 8 --clock 1k                  # N = 255 at 1 kHz, 3 periods, +-1 V
  make-prbs --bits 10 --dt 2m --amplitude 0.2 --offset 2.5 --periods 5 --out bench
  make-prbs --for-plant --plant-tf "K=2 tau=1m theta=200u"
        clock and bits chosen for the plant, and why
  make-prbs --for-plant --plant-model models.json   # identify/identify-freq --json output

the sequence: a maximum-length sequence (scipy.signal.max_len_seq) of n bits,
N = 2^n - 1 clock intervals per period, levels offset +- amplitude. Its power
is flat to within 3 dB up to 0.443 x the clock; one period must outlast the
plant's settling time, or the identified impulse response wraps around.

--for-plant: the clock puts that half-power frequency at 3x the plant's -3 dB
bandwidth (rounded down to 1, 2 or 5 x 10^k s), the bits make one period
outlast 1.2x the plant's 2 % settling time. --bits, --clock or --dt given with
it are kept (a period too short is said so). The model must be stable and not
integrating (it must settle).

files (--out DIR, default prbs; written together or not at all):
  prbs_awg.csv  sample_rate_hz,<clock> then one value per line (one per clock
                interval: set the generator's sample rate to the clock)
  prbs.csv      time_s,value
  prbs.cir      .subckt prbs_source out with a PWL source (edges Dt/1000)
A capture of the plant under it (input and output channels) goes to identify.

limits: --bits 3 to 20; clock {clock}; --amplitude {amp}; --offset {off};
--periods {per}; at most {maxv:,} values in all.

exit status: 0 success, 2 bad input (one line on stderr saying what and why).
"""


def build_parser() -> argparse.ArgumentParser:
    """The ``make-prbs`` command line.

    Returns
    -------
    argparse.ArgumentParser
        The parser of ``make-prbs``'s options.
    """
    p = OneLineParser(prog="make-prbs",
                      description="Write a pseudo-random binary sequence (maximum-length sequence) for a "
                                  "function generator and ngspice, to identify a plant by correlation.",
                      epilog=EPILOG.format(clock=help_range("prbs_clock_hz"),
                                           amp=help_range("prbs_amplitude_v"),
                                           off=help_range("prbs_offset_v"),
                                           per=help_range("prbs_periods"), maxv=MAX_VALUES),
                      formatter_class=argparse.RawDescriptionHelpFormatter)
    p.add_argument("--bits", metavar="N", help="bits n of the sequence, 3 to 20 (N = 2^n - 1 intervals "
                                                "a period); required without --for-plant")
    g = p.add_mutually_exclusive_group()
    g.add_argument("--clock", metavar="HZ", help="clock frequency " + help_range("prbs_clock_hz"))
    g.add_argument("--dt", metavar="S", help="clock interval, 1/clock (e.g. 1m)")
    p.add_argument("--amplitude", default="1", metavar="V",
                   help="levels are offset +- amplitude " + help_range("prbs_amplitude_v") + " (default 1)")
    p.add_argument("--offset", default="0", metavar="V", help="mean level " + help_range("prbs_offset_v")
                   + " (default 0)")
    p.add_argument("--periods", default="3", metavar="P",
                   help="whole periods written " + help_range("prbs_periods")
                        + " (default 3: the first settles the plant)")
    p.add_argument("--for-plant", action="store_true",
                   help="choose the clock and bits for the plant of --plant-tf or --plant-model")
    m = p.add_mutually_exclusive_group()
    m.add_argument("--plant-tf", metavar="MODEL", help='a typed model, e.g. "K=2 tau=1m theta=200u" '
                                                       "(design-pid's forms)")
    m.add_argument("--plant-model", metavar="FILE", help="an identify or identify-freq --json output")
    p.add_argument("--out", default="prbs", metavar="DIR", help="folder of the files (default prbs)")
    p.add_argument("--no-files", action="store_true", help="print the plan only")
    p.add_argument("--json", action="store_true", help="print one JSON object instead of the text")
    return p


def clock_interval(args) -> float | None:
    """The clock interval from --clock or --dt (None when neither is given)."""
    if args.clock is not None:
        return 1.0 / parse_in_range(args.clock, "--clock", "prbs_clock_hz")
    if args.dt is not None:
        dt = parse_value(args.dt, "--dt")
        if not (math.isfinite(dt) and dt > 0):
            raise DesignError(f"--dt must be a positive time, got {args.dt!r}")
        parse_in_range(1.0 / dt, "--dt's clock (1/dt)", "prbs_clock_hz")
        return dt
    return None


def plant_model(args):
    """The --for-plant model (a :class:`~designer.core.process.ProcessModel`), checked to settle."""
    if args.plant_tf is not None:
        from ..core.process_text import parse_tf
        model = parse_tf(args.plant_tf)
    elif args.plant_model is not None:
        from ..pid.plant_source import model_from_json
        model = model_from_json(args.plant_model)
    else:
        raise DesignError("--for-plant needs the plant: --plant-tf \"K=.. tau=..\" or --plant-model FILE")
    if model.integrating:
        raise DesignError(f"the --for-plant model {model.text()} is integrating: it never settles, so no "
                          "period outlasts its settling; identify it in a closed loop")
    if any(p.real >= 0 for p in model.poles):
        raise DesignError(f"the --for-plant model {model.text()} is unstable: a PRBS experiment needs a "
                          "plant that settles")
    return model


def _time_constants(model) -> str:
    """``, time constant 1 ps``, ``, time constants 1 ms to 5 ms``, or nothing, for a message."""
    tc = sorted(model.time_constants_s)
    if not tc:
        return ""
    if len(tc) == 1 or tc[0] == tc[-1]:
        return f", time constant {format_eng(tc[0], 's')}"
    return f", time constants {format_eng(tc[0], 's')} to {format_eng(tc[-1], 's')}"


def bandwidth_hz(model) -> float:
    """The -3 dB bandwidth of a settling model: the highest frequency where its
    gain is still within 3 dB of its static gain (after any resonant peak)."""
    import numpy as np
    tc = model.time_constants_s
    fast, slow = (min(tc), max(tc)) if tc else (model.theta_s or 1.0, model.theta_s or 1.0)
    w = np.geomspace(0.001 / slow, 1000.0 / fast, 4000)
    g = np.abs(model.freq(w)) / abs(model.gain)
    above = np.nonzero(g >= 1.0 / math.sqrt(2.0))[0]
    return float(w[above[-1]] / (2.0 * math.pi)) if above.size else float(w[0] / (2 * math.pi))


def make_plan(args):
    from ..core.prbs import PrbsPlan, check_bits, plan_for_plant
    amplitude = parse_in_range(args.amplitude, "--amplitude", "prbs_amplitude_v")
    offset = parse_in_range(args.offset, "--offset", "prbs_offset_v")
    periods = parse_in_range(args.periods, "--periods", "prbs_periods")
    if periods != int(periods):
        raise DesignError(f"--periods must be a whole number {help_range('prbs_periods')}, got {args.periods!r}")
    bits = None if args.bits is None else check_bits(args.bits)
    dt = clock_interval(args)
    model = None
    if args.for_plant:
        model = plant_model(args)
        plan = plan_for_plant(model.settling_time_s, bandwidth_hz(model), amplitude=amplitude,
                              offset=offset, periods=int(periods), dt_s=dt, bits=bits,
                              plant=f"--for-plant: the plant {model.text()}{_time_constants(model)}")
    else:
        if args.plant_tf is not None or args.plant_model is not None:
            raise DesignError("--plant-tf and --plant-model go with --for-plant")
        if bits is None or dt is None:
            raise DesignError("give --bits and --clock (or --dt), or --for-plant with the plant's model")
        plan = PrbsPlan(bits, dt, amplitude, offset, int(periods))
    if plan.n * plan.periods > MAX_VALUES:
        raise DesignError(f"{plan.periods} periods of {plan.n:,} intervals are {plan.n * plan.periods:,} values; "
                          f"at most {MAX_VALUES:,} are written (fewer periods or bits)")
    return plan, model


def write_bundle(plan, out) -> list:
    """The three files in folder ``out``, all or none (a staging folder renamed into place); an
    existing folder (or a link to one) keeps its other files, each of these replaced atomically."""
    from ..core import fileio
    from ..core.prbs import awg_csv, pwl_subcircuit, time_value_csv
    out = fileio.check_output_folder(out, "--out", whole=False)
    texts = {"prbs_awg.csv": awg_csv(plan), "prbs.csv": time_value_csv(plan), "prbs.cir": pwl_subcircuit(plan)}
    if out.is_dir():
        for name, text in texts.items():   # an existing folder: each file replaced atomically
            fileio.atomic_write(out / name, text)
        return [out / n for n in texts]
    stage = fileio.new_folder_beside(out)
    try:
        for name, text in texts.items():
            (stage / name).write_text(text, encoding="utf-8")
    except OSError as exc:
        fileio.remove_tree(stage)
        raise fileio.os_error("write", out, exc) from None
    fileio.publish_folder(stage, out)
    return [out / n for n in texts]


def plan_text(plan, model, files) -> str:
    lines = [f"PRBS: maximum-length sequence of {plan.bits} bits (N = {plan.n} intervals a period)",
             f"  clock {format_eng(plan.clock_hz, 'Hz')} (Dt = {format_eng(plan.dt_s, 's')}), period "
             f"{format_eng(plan.period_s, 's')}, {plan.periods} period(s) = {format_eng(plan.periods * plan.period_s, 's')}",
             f"  levels {plan.offset - plan.amplitude:.6g} V and {plan.offset + plan.amplitude:.6g} V "
             f"(offset {plan.offset:.6g} V +- {plan.amplitude:.6g} V)",
             f"  spectrum flat within 3 dB to {format_eng(plan.band_hz, 'Hz')}, lines every "
             f"{format_eng(plan.resolution_hz, 'Hz')}"]
    if model is not None:
        lines.append(f"Plant: {model.text()}: settling (2 %) {format_eng(model.settling_time_s, 's')}")
    lines += [f"  why: {r}" for r in plan.reasons]
    for f in files:
        lines.append(f"Wrote {f} ({FILES[f.name]})")
    if files:
        lines.append("Capture the generator's output and the plant's output together for two periods or more "
                     "after the first, then: identify <capture.csv>")
    return "\n".join(lines)


def run(args) -> int:
    if not args.no_files:   # before any work: a folder there, or a link to one, or nothing yet
        from ..core.fileio import check_output_folder
        check_output_folder(args.out, "--out", whole=False)
    plan, model = make_plan(args)
    files = [] if args.no_files else write_bundle(plan, args.out)
    if args.json:
        d = {"prbs": plan.to_dict(), "files": [str(f) for f in files]}
        if model is not None:
            d["plant"] = {"model": model.text(), "settling_time_s": model.settling_time_s,
                          "bandwidth_hz": bandwidth_hz(model)}
        print_output(json.dumps(json_safe(d), indent=2, allow_nan=False))
    else:
        print_output(plan_text(plan, model, files))
    return 0


def make_prbs_main(argv=None) -> int:
    """Console entry point ``make-prbs``.

    Parameters
    ----------
    argv : list of str, optional
        The arguments; None reads ``sys.argv[1:]``.

    Returns
    -------
    int
        The exit status (see :func:`~designer.cli.common.run_cli`).
    """
    return run_cli("make-prbs", build_parser, run, argv)


if __name__ == "__main__":  # pragma: no cover
    sys.exit(make_prbs_main())
