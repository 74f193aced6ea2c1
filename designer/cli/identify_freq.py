"""``identify-freq``: plant models from a measured frequency response (Bode table).

Reads a table of frequency, gain and (optionally) phase, reads asymptotes,
resonant peak and dead time as seeds 000 and 003 do, fits FOPDT,
underdamped and overdamped models to the complex response by least squares,
and prints them ranked by fit error; ``--json`` prints one JSON object.
"""

from __future__ import annotations

import argparse
import json
import math
import sys

from ..core.jsonio import json_safe
from ..core.fileio import MAX_TABLE_BYTES, size_text
from ..core.units import format_eng
from ..identify.frequency import BAND_FACTOR, FREQ_UNITS, GAIN_UNITS, MAX_FIT_ERROR, PHASE_UNITS
from .common import OneLineParser, print_output, run_cli
from .identify import check_output_path, write_png

EPILOG = """\
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

fit error (the iae/ise columns): e = |G_model/G_data - 1| at each tabulated
frequency (gain only without phase); iae = mean of e, ise = mean of e^2.
A model is valid (ok = yes) when its fit error is at most {max_err:g} % and its
corner frequencies (1/tau, wn) lie inside the measured band widened {band:g} times.

limits: a table of at most {size} and {rows:,} rows; frequency {f_rng},
gain {db_rng} (ratio {ratio_rng}), phase {ph_rng} degrees
(after unit conversion).

exit status: 0 success, 2 bad input (one line on stderr saying what and why).
"""


def epilog() -> str:
    """The --help epilog with the validity rule and the input limits filled in."""
    from ..core.ranges import RANGES
    from ..identify.frequency import MAX_POINTS
    return EPILOG.format(max_err=100 * MAX_FIT_ERROR, band=BAND_FACTOR,
                         size=size_text(MAX_TABLE_BYTES), rows=MAX_POINTS,
                         f_rng=RANGES["freq_hz"].text(), db_rng=RANGES["gain_db"].text(),
                         ratio_rng=RANGES["gain_ratio"].text(),
                         ph_rng=RANGES["phase_deg"].text())


def _lower(text: str) -> str:
    return text.strip().lower()


def build_parser() -> argparse.ArgumentParser:
    p = OneLineParser(prog="identify-freq",
                description=__doc__.split("\n\n")[0].strip().replace("``", ""),
                epilog=epilog(), formatter_class=argparse.RawDescriptionHelpFormatter)
    p.add_argument("table", help="CSV table: frequency, gain[, phase]")
    # units in any case: dB, Hz, Rad/s
    p.add_argument("--gain-units", choices=GAIN_UNITS, type=_lower,
                   help="gain in decibels or as the amplitude ratio Vout/Vin (default: from the "
                        "header, else db)")
    p.add_argument("--phase-units", choices=PHASE_UNITS, type=_lower,
                   help="phase in degrees, radians, or the output's time shift in seconds "
                        "(default: from the header, else deg)")
    p.add_argument("--freq-units", choices=FREQ_UNITS, type=_lower,
                   help="frequency in Hz or rad/s (default: from the header, else hz)")
    p.add_argument("--json", action="store_true", help="print one JSON object instead of the table")
    p.add_argument("--plot", metavar="OUT_PNG", help="write a Bode plot of the data and the fits")
    return p


def _fmt_params(p: dict) -> str:
    from ..identify.step import format_params
    return format_params(p, corners=True)


def _pct(v):
    return "n/a" if v is None or not math.isfinite(v) else f"{100.0 * v:.3g} %"


def to_text(result) -> str:
    d = result.data
    lines = [f"Table: {d.source or 'data'}: {d.w.size} points, "
             f"{format_eng(d.f_hz[0], 'Hz')} to {format_eng(d.f_hz[-1], 'Hz')}, "
             f"gain in {d.units['gain']}, "
             + (f"phase in {d.units['phase']}" if d.phase is not None else "no phase")
             + (" (inverting: K < 0)" if d.sign < 0 else "")]
    lines += [f"  note: {n}" for n in d.notes]
    lines += ["",
             "Methods ranked by fit error (mean |G_model/G_data - 1| over the table; "
             "lower is better)"]
    head = f"{'#':>2}  {'method':<15} {'model':<12} {'parameters':<84} {'error':>9}  ok"
    lines += [head, "-" * len(head)]
    for i, m in enumerate(result.methods, 1):
        lines.append(f"{i:>2}  {m.name:<15} {m.model:<12} {_fmt_params(m.params):<84} "
                     f"{_pct(m.iae):>9}  {'yes' if m.valid else 'NO'}")
        if m.note:
            lines.append(f"{'':>4}{m.note}")
    lines.append("")
    b = result.best
    lines.append(f"Best: {b.name} ({b.model}): {_fmt_params(b.params)}" if b else
                 "Best: none of the methods is valid for these data")
    return "\n".join(lines)


def plot_bode(result, path, n_models: int = 3) -> None:
    """PNG Bode plot of the data and the best valid models (written atomically)."""
    import matplotlib
    matplotlib.use("Agg")
    import matplotlib.pyplot as plt
    import numpy as np

    from ..identify.frequency import model_phase, model_response

    d = result.data
    w = np.geomspace(d.w[0] / 2.0, d.w[-1] * 2.0, 400)
    f = w / (2 * math.pi)
    has_phase = d.phase is not None
    fig, axes = plt.subplots(2 if has_phase else 1, 1, sharex=True,
                             figsize=(8, 6 if has_phase else 4), dpi=110, squeeze=False)
    ax_g = axes[0][0]
    ax_g.semilogx(d.f_hz, d.gain_db, "o", color="k", ms=4, label="data")
    shown = [m for m in result.methods if m.valid][:n_models]
    for m in shown:
        g = model_response(m.model, m.params, w)
        label = f"{m.name} ({m.model}), error {100 * m.iae:.2g} %"
        ax_g.semilogx(f, 20 * np.log10(np.abs(g)), lw=1.2, label=label)
        if has_phase:
            p = dict(m.params)
            axes[1][0].semilogx(f, np.rad2deg(model_phase(m.model, p, w)), lw=1.2)
    ax_g.set_ylabel("gain (dB)")
    ax_g.set_title("Frequency response: data and identified models")
    ax_g.grid(True, which="both", alpha=0.3)
    ax_g.legend(fontsize=8, loc="lower left")
    if has_phase:
        ax_p = axes[1][0]
        ax_p.semilogx(d.f_hz, np.rad2deg(d.phase), "o", color="k", ms=4)
        ax_p.set_ylabel("phase (deg)")
        ax_p.grid(True, which="both", alpha=0.3)
    axes[-1][0].set_xlabel("frequency (Hz)")
    fig.tight_layout()
    write_png(path, fig)


def run(args):
    """Identify from parsed arguments, write the plot; return the result."""
    from ..identify.frequency import identify_freq, read_freq_table
    if args.plot:
        check_output_path(args.plot, "--plot")
    data = read_freq_table(args.table, gain_units=args.gain_units,
                           phase_units=args.phase_units, freq_units=args.freq_units)
    result = identify_freq(data)
    if args.plot:
        plot_bode(result, args.plot)
    return result


def identify_freq_main(argv=None) -> int:
    """Console entry point ``identify-freq``."""
    return run_cli("identify-freq", build_parser, _main, argv)


def _main(args) -> int:
    result = run(args)
    if args.json:
        print_output(json.dumps(json_safe(result.to_dict()), indent=2, allow_nan=False))
    else:
        print_output(to_text(result) + (f"\n\nPlot written to {args.plot}" if args.plot else ""))
    return 0


if __name__ == "__main__":  # pragma: no cover
    sys.exit(identify_freq_main())
