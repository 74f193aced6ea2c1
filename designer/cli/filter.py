"""``design-filter``: an active filter from a specification (low- or high-pass;
Butterworth, Bessel or Chebyshev; an order and cut-off, or a mask), as a
cascade of Sallen-Key or MFB stages with E-series parts chosen jointly across
the stages, every stage checked against its op-amp, and the cascade proven
with ngspice's ``.ac`` (:mod:`designer.filters.design`).
"""

from __future__ import annotations

import json
import math
import sys
from pathlib import Path

from ..core.eseries import SERIES
from ..core.opamps import names as opamp_names
from ..core.ranges import help_range
from ..core.units import format_eng
from .common import ExtendList, command_parser, print_output, run_cli
from .filter_tolerance import add_filter_tolerance, run_tolerance, tolerance_json, tolerance_lines, tolerance_settings

__all__ = ["design_filter_main", "analyze_filter_main", "summary_text"]

EPILOG = """examples:
  design-filter --family butterworth --order 4 --fc 1k
  design-filter --type highpass --family chebyshev --ripple 0.5 --order 5 --fc 1k --topology mfb
  design-filter --family chebyshev --passband 3k --max-loss 1 --stopband 12k --min-attenuation 40
  design-filter --family bessel --order 6 --fc 10k --gain 4 --opamp NE5532 --json --out build/aa

conventions: --fc is the -3 dB frequency (Butterworth; Bessel with --bessel-norm mag), the frequency whose
period is 2 pi times the DC group delay (Bessel, --bessel-norm delay), or the ripple edge (Chebyshev, unless
--chebyshev-cutoff 3db). --gain is the passband gain at DC (low-pass) or high frequency (high-pass).
"""


def _parser():
    p = command_parser("design-filter", "Design an active low- or high-pass filter from a specification: "
                       "scipy's prototypes, Sallen-Key or MFB stages in rising Q, E-series parts chosen jointly "
                       "across the stages, each stage's op-amp checked, the cascade checked in ngspice.", EPILOG)
    r = p.add_argument_group("response")
    r.add_argument("--type", dest="filter_type", default="lowpass", metavar="TYPE",
                   help="lowpass, highpass or bandpass (default lowpass)")
    r.add_argument("--family", default="butterworth",
                   help="butterworth (maximally flat), bessel (flat group delay) or chebyshev (equiripple "
                        "passband, steeper) (default butterworth)")
    r.add_argument("--order", help="filter order, 1 to 10 (or give the mask instead)")
    r.add_argument("--fc", dest="fc_hz", help=f"cut-off frequency, e.g. 1k {help_range('fc_hz')}")
    r.add_argument("--f-low", dest="f_low_hz", help=f"band-pass: lower band edge {help_range('fc_hz')}")
    r.add_argument("--f-high", dest="f_high_hz", help=f"band-pass: upper band edge {help_range('fc_hz')}")
    r.add_argument("--bandpass-method", default="auto", help="band-pass: wide (a high-pass at --f-low then a "
                   "low-pass at --f-high, order --order each), narrow (the band-pass transformation into --order "
                   "MFB band-pass sections) or auto (wide from f-high/f-low >= 2; default)")
    r.add_argument("--ripple", dest="ripple_db", help=f"Chebyshev passband ripple in dB {help_range('ripple_db')}, "
                   "default 1 (with a mask: the mask's --max-loss)")
    r.add_argument("--bessel-norm", default="mag", help="Bessel cut-off: mag (-3 dB at --fc, default) or delay")
    r.add_argument("--chebyshev-cutoff", default="ripple", help="Chebyshev cut-off: ripple (the ripple edge at "
                   "--fc, default) or 3db")
    m = p.add_argument_group("mask (instead of --order and --fc: picks the least order that meets it)")
    m.add_argument("--passband", dest="passband_hz", help=f"passband edge frequency {help_range('fc_hz')}; a "
                   "band-pass takes two, F1,F2 (the order, edges and wide or narrow split then come from the mask)")
    m.add_argument("--max-loss", dest="max_loss_db", help=f"largest loss in the passband, dB "
                   f"{help_range('max_loss_db')}")
    m.add_argument("--stopband", dest="stopband_hz", help=f"stopband edge frequency {help_range('fc_hz')}; a "
                   "band-pass takes two, F1,F2, outside the passband's")
    m.add_argument("--min-attenuation", dest="min_attenuation_db", help="least attenuation in the stopband, dB "
                   f"{help_range('min_attenuation_db')}")
    m.add_argument("--max-delay-error", dest="max_delay_error_pct", metavar="PCT", help="a Bessel low-pass's "
                   "group-delay target with the mask: the delay within PCT %% of its DC value up to --delay-to "
                   + help_range("max_delay_error_pct").replace("%", "%%") + "; the least order meeting both")
    m.add_argument("--delay-to", dest="delay_to_hz", metavar="F", help="the frequency the group-delay target holds "
                   f"to {help_range('fc_hz')}")
    s = p.add_argument_group("stages")
    s.add_argument("--topology", default="sallen-key", help="sallen-key, mfb (inverting multiple feedback) or auto "
                   "(Sallen-Key, MFB where it cannot); a comma list gives one per stage (default sallen-key)")
    s.add_argument("--stage-order", help="the stages (numbered 1.. in rising Q) in build order, e.g. 2,1 "
                   "(default: rising Q, so that a high-Q stage does not clip)")
    s.add_argument("--gain", default="1", help=f"passband gain, V/V {help_range('gain')} (default 1), put in the "
                   "lowest-Q second-order stage, or split evenly in dB, then last, where that stage would clip")
    s.add_argument("--stage-gain", dest="stage_gains", metavar="G1,G2,..",
                   help=f"each stage's gain in build order, V/V {help_range('gain')} each, a comma list with one per "
                   "stage whose product is --gain (e.g. --gain 4 --stage-gain 2,2,1); each stage's peak gain and "
                   "output are still checked against the op-amp's swing")
    s.add_argument("--opamp", default="LM741", metavar="NAME",
                   help=f"op-amp of every stage: {', '.join(opamp_names())} (default LM741)")
    s.add_argument("--amplitude", dest="amplitude_v", default="1", help="bench input amplitude, peak volts "
                   f"{help_range('amplitude_v')} (default 1): no stage output may exceed the op-amp's swing")
    s.add_argument("--gbw-margin", default="100", help="a stage needs GBW >= margin x fn x Q x noise gain "
                   f"{help_range('gbw_margin')} (default 100, TI's rule of thumb)")
    s.add_argument("--impedance", dest="impedance_ohm", default="10k",
                   help=f"the resistor scale of the synthesis {help_range('impedance_ohm')} (default 10k)")
    s.add_argument("--compensate-gbw", action="store_true", help="pre-distort each stage's fn and Q so that its "
                   "response with the op-amp's finite gain and GBW matches the ideal one")
    k = p.add_argument_group("parts")
    k.add_argument("--series", dest="r_series", default="E24", help=f"resistor series: {', '.join(SERIES)} "
                   "(default E24)")
    k.add_argument("--c-series", default="E12", help="capacitor series (default E12)")
    k.add_argument("--r-min", default="1k", help=f"smallest resistor (default 1k) {help_range('resistor_ohm')}")
    k.add_argument("--r-max", default="1M", help=f"largest resistor (default 1M) {help_range('resistor_ohm')}")
    k.add_argument("--c-min", default="1n", help=f"smallest capacitor (default 1n) {help_range('capacitor_f')}")
    k.add_argument("--c-max", default="10u", help=f"largest capacitor (default 10u) {help_range('capacitor_f')}")
    k.add_argument("--alternatives", metavar="N", help="also list the N best part sets of the joint choice's "
                   "candidates, the joint choice first, each with its deviation and whether it meets the mask "
                   f"{help_range('alternatives')}")
    add_filter_tolerance(p, optimize=True)
    o = p.add_argument_group("output")
    o.add_argument("--json", action="store_true", help="print one JSON object instead of the summary")
    _add_lang(o)
    o.add_argument("--out", metavar="DIR", help="write DIR/filter.cir (the ngspice .ac deck of the cascade), "
                   "DIR/result.json and the build sheet (build-sheet.html and .md, schematic, plots, bom.csv); with "
                   "--name, the bundle DIR/reports/NAME/ and DIR/netlists/NAME.cir instead")
    o.add_argument("--name", help="design name of the bundle under --out (default .): letters, digits and "
                   ". _ - + = , @")
    o.add_argument("--no-sim", action="store_true", help="skip the ngspice check")
    o.add_argument("--simulator", default="ngspice-cli", choices=("ngspice-cli", "pyspice"),
                   help="ngspice-cli: `ngspice -b` (default); pyspice: the shared library")
    return p


def _add_lang(group) -> None:
    """``--lang``: the build sheet's language (the summary and the JSON stay English)."""
    from ..core.i18n import DEFAULT, LANGUAGES
    group.add_argument("--lang", default=DEFAULT, choices=LANGUAGES,
                       help=f"language of the build sheet written with --out: {', '.join(LANGUAGES)} (default "
                            f"{DEFAULT}, whatever LANG says; es writes decimal commas); the summary and JSON stay English")


def _spec(args):
    from ..filters.spec import FilterSpec
    keys = ("filter_type", "family", "order", "fc_hz", "ripple_db", "bessel_norm", "chebyshev_cutoff", "passband_hz",
            "max_loss_db", "stopband_hz", "min_attenuation_db", "max_delay_error_pct", "delay_to_hz", "f_low_hz", "f_high_hz", "bandpass_method", "topology", "stage_order", "gain",
            "stage_gains", "opamp",
            "amplitude_v", "gbw_margin", "impedance_ohm", "r_series", "c_series", "r_min", "r_max", "c_min",
            "c_max")
    kw = {k: getattr(args, k) for k in keys if getattr(args, k) is not None}
    kw["compensate_gbw"] = args.compensate_gbw
    if "order" in kw:
        from ..core.ranges import parse_in_range
        kw["order"] = parse_in_range(kw["order"], "order", "filter_order")
    return FilterSpec(**kw)


def _ordinal(n: int) -> str:
    return f"{n}{'th' if 10 <= n % 100 <= 20 else {1: 'st', 2: 'nd', 3: 'rd'}.get(n % 10, 'th')}"


def summary_text(result) -> str:
    """The design as text, in engineering notation with units.

    Parameters
    ----------
    result : designer.filters.FilterDesign
        The design.

    Returns
    -------
    str
        Lines ending in newline.
    """
    from ..filters.design import MAX_COMBINATIONS
    from ..filters.registry import get as get_topology
    s, f, op = result.spec, result.figures, result.opamp
    if s.family == "chebyshev":
        conv = f"{s.ripple_db:g} dB ripple, " + ("ripple edge" if s.chebyshev_cutoff == "ripple" else "-3 dB")
    else:
        conv = "-3 dB" if s.family == "butterworth" or s.bessel_norm == "mag" else "delay-normalised"
    kind = {"lowpass": "low-pass", "highpass": "high-pass", "bandpass": "band-pass"}[s.filter_type]
    where = f"fc {format_eng(result.fc_hz, 'Hz')}"
    if s.filter_type == "bandpass":
        method = result.to_dict()["spec"]["bandpass_method"]
        where = f"band {format_eng(s.f_low_hz, 'Hz')} to {format_eng(s.f_high_hz, 'Hz')} ({method}: " + \
            ("high-pass then low-pass, each" if method == "wide" else "band-pass sections from an") + \
            f" order-{result.order} prototype)"
    lines = [f"{_ordinal(result.order)}-order {s.family.capitalize()} {kind}, {where} "
             f"({conv}), gain {s.gain:g}" + (" (inverting)" if f["inverting"] else "")
             + f"; op-amp {op.name} (GBW {format_eng(op.gbw_hz, 'Hz')})"]
    if s.has_mask:
        where_pass, where_stop = s.mask_phrases()
        lines.append(f"  from the mask: at most {s.max_loss_db:g} dB loss {where_pass}, at least "
                     f"{s.min_attenuation_db:g} dB {where_stop}"
                     + (f", the group delay within {s.max_delay_error_pct:g} % of its DC value up to "
                        f"{format_eng(s.delay_to_hz, 'Hz')}" if s.has_delay_target else ""))
    lines.append(f"Stages, in build order ({s.r_series} resistors, {s.c_series} capacitors; in brackets the "
                 "continuous design at the nearest capacitor):")
    for st in result.stages:
        topo = get_topology(st.topology)
        q = f"Q {st.plan.q:.4g}" if st.plan.q else "first order"
        lines.append(f"  {st.number}  {st.topology:<24} fn {format_eng(st.plan.fn_hz, 'Hz'):<10} {q:<12} gain "
                     f"{st.gain:.4g}  peak gain {20 * math.log10(st.peak_gain):.3g} dB  output peak "
                     f"{format_eng(st.node_peak_v, 'V')}  GBW needed {format_eng(st.gbw_needed_hz, 'Hz')}")
        parts = []
        for ref in topo.designators:
            unit = "Ohm" if ref.startswith("R") else "F"
            parts.append(f"{topo.prefixed(ref, str(st.number) + '0')} {format_eng(st.values[ref], unit)} "
                         f"({format_eng(st.continuous[ref], unit)})")
        lines.append("     " + ", ".join(parts))
    lo, hi = f["objective_range_hz"]
    f3 = lambda v: " and ".join(format_eng(x, "Hz") for x in v) if isinstance(v, (list, tuple)) \
        else format_eng(v, "Hz")  # noqa: E731
    lines += [f"Achieved with the chosen parts and the {op.name} model:",
              f"  max passband deviation from the ideal  {f['passband_deviation_db']:.3g} dB",
              f"  -3 dB frequency                        {f3(f['f3_hz'])} (target {f3(f['f3_target_hz'])})"]
    if s.has_mask:
        lines += [f"  mask margins: passband {f['mask_passband_margin_db']:.3g} dB, stopband "
                  f"{f['mask_stopband_margin_db']:.3g} dB"]
    if s.has_delay_target:
        lines += [f"  group delay                            within {f['delay_error_pct']:.3g} % of its DC value "
                  f"{format_eng(f['delay_dc_s'], 's')} up to {format_eng(s.delay_to_hz, 'Hz')} (at most "
                  f"{s.max_delay_error_pct:g} %; the ideal Bessel {f['delay_error_ideal_pct']:.3g} %): "
                  + ("met" if f["delay_target_met"] else "NOT met")]
    lines += [f"E-series choice: worst deviation from the ideal over {format_eng(lo, 'Hz')} to "
              f"{format_eng(hi, 'Hz')} (passband and transition band):",
              f"  joint across the stages   {f['error_joint_db']:.3g} dB  (exact over {f['combinations']} "
              f"combinations; {f['examined']} partial choices examined in {f['search_s']:.3g} s"
              + (f"; {f['candidates_dropped']} stage candidates worst on their own dropped to stay within "
                 f"{MAX_COMBINATIONS}" if f.get("candidates_dropped") else "") + ")",
              f"  per-stage rounding        {f['error_per_stage_db']:.3g} dB",
              f"  nearest values            {f['error_nearest_db']:.3g} dB",
              f"  continuous parts          {f['error_continuous_db']:.3g} dB  (the op-amp's share)"]
    if s.has_mask:
        broken = [f[f"mask_violation_{k}_db"] for k in ("joint", "per_stage", "nearest")]
        lines.append("  mask broken by (0: met): joint {:.3g} dB, per-stage {:.3g} dB, nearest {:.3g} dB".format(*broken))
    if "delay_error_per_stage_pct" in f:
        lines.append(f"  group delay error (at most {s.max_delay_error_pct:g} %, weighed by the joint choice): joint "
                     f"{f['delay_error_pct']:.3g} %, per-stage {f['delay_error_per_stage_pct']:.3g} %, nearest "
                     f"{f['delay_error_nearest_pct']:.3g} %")
    if result.spice:
        sp = result.spice
        lines.append(f"SPICE (.ac, {sp['simulator']}) against the analytic response of these parts: max deviation "
                     f"{sp['max_deviation_passband_db']:.2g} dB in the passband, {sp['max_deviation_60db_db']:.2g} "
                     "dB down to -60 dB")
    lines += _proof_lines(result)
    return "\n".join(lines) + "\n"


def _check_sheet_args(args) -> None:
    """Before the work: --name a plain name, its report folder no link or file."""
    if getattr(args, "name", None) is not None:
        from .common import check_name
        check_name(args.name)


def _proof_lines(result) -> list:
    """The SPICE proof's lines (NRMS against both models, the mask on SPICE's .ac, slew and swing per stage)."""
    return result.proof.lines() if getattr(result, "proof", None) is not None else []


def _write_sheet(result, folder, name, extra=None, lang=None, alts=None):
    """The build sheet: into ``folder`` (filter.cir, result.json and the sheet's files), or with ``name``
    the bundle under ``folder`` (default .): reports/NAME/ and netlists/NAME.cir; ``extra`` (the tolerance
    analyses' JSON) joins result.json, and ``alts`` (--alternatives' part sets) the sheet and result.json.
    Returns the :class:`~designer.filters.report.FilterSheet` written (its ``files`` set)."""
    from ..filters.report import sheet_of, write_folder, write_outputs
    data = sheet_of(result)
    data.extra = dict(extra or {})
    data.alternatives = list(alts or [])
    if name is None:
        write_folder(data, folder, lang)
    else:
        from .common import check_name
        write_outputs(data, folder or ".", check_name(name), lang)
    return data


def _design(args) -> int:
    from ..filters.design import design
    spec = _spec(args)
    _check_sheet_args(args)
    count = None
    if args.alternatives is not None:
        from ..filters.alternatives import alternatives_count
        count = alternatives_count(args.alternatives)
    settings = tolerance_settings(args)
    apply = None
    if args.apply_optimum:
        from ..core.errors import DesignError
        from ..filters.design import with_choice
        if args.optimize != "yield":
            raise DesignError("--apply-optimum goes with --optimize yield (the set it builds)")
        apply = lambda res, choice: with_choice(res, choice, not args.no_sim, args.simulator)  # noqa: E731
    result = design(spec, simulate=not args.no_sim and apply is None, simulator=args.simulator)
    extras = run_tolerance(result, args, settings, apply)
    alts = None
    if count is not None:
        from ..filters.alternatives import design_alternatives
        alts = design_alternatives(result, count)
    return _emit(extras.pop("built", result), args, extras, alts)


def _alternatives_lines(spec, alts: list) -> list:
    """--alternatives' lines: each set's deviation, the mask (and delay target) met or broken, its parts."""
    from ..filters.report import alternative_words
    limited = alts[0].violation is not None
    out = ["Alternatives (best first; the joint choice is 1; worst deviation from the ideal"
           + ("; limits: the mask" + (" and the delay target" if spec.has_delay_target else "") if limited else "")
           + "):"]
    for a in alts:
        met, parts = alternative_words(a)
        out.append(f"  {a.rank:>2}  {a.error_db:.3g} dB{'  ' + met if limited else ''}")
        out.append("      " + parts)
    return out


def _emit(result, args, extras: dict, alts=None) -> int:
    """The result (and its tolerance analyses, and --alternatives' sets) printed, and written with --out (or
    --name)."""
    from ..filters.report import alternatives_json
    extra = tolerance_json(extras)
    name = getattr(args, "name", None)
    sheet = _write_sheet(result, args.out, name, extra, getattr(args, "lang", None), alts) \
        if args.out or name else None
    files = sheet.files if sheet is not None else {}
    if args.json:
        # what result.json holds when written (the bench test too)
        print_output(json.dumps(sheet.to_dict() if sheet is not None else
                                {**result.to_dict(), **extra, **alternatives_json(alts or []), "files": {}}, indent=2))
    else:
        text = summary_text(result) + "".join(line + "\n" for line in tolerance_lines(extras)
                                             + (_alternatives_lines(result.spec, alts) if alts is not None else []))
        if files:
            text += "Files:\n" + "".join(f"  {k}: {', '.join(v) if isinstance(v, list) else v}\n"
                                          for k, v in files.items())
        print_output(text, end="")
    return 0


def design_filter_main(argv=None) -> int:
    """``design-filter``'s entry point.

    Parameters
    ----------
    argv : list of str, optional
        The arguments (default ``sys.argv[1:]``).

    Returns
    -------
    int
        The exit status (0 done, 2 bad input, 3 simulator error).
    """
    return run_cli("design-filter", _parser, _design, argv)


ANALYZE_EPILOG = """examples:
  design-filter --order 4 --fc 1k --json --out build/lp      then, the parts as built:
  analyze-filter --from build/lp/result.json --part R101=10.2k --part C202=4.6n
  analyze-filter --from build/lp/result.json --monte-carlo 10000 --limit f3_hz=950:1050 --spice-samples 50
  analyze-filter --target "--order 4 --fc 1k" --stage sallen-key-lowpass --stage sallen-key-lowpass \
      --part R101=10k --part R102=20k --part C101=10n --part C102=12n \
      --part R201=5.1k --part R202=36k --part C201=10n --part C202=47n

--part DESIGNATOR=VALUE names a part as the cascade does: stage i's R1 is Ri01 (R101, R201...). Without
--from, --target takes design-filter's response options (the order and cut-off or the mask, --type, --family,
--gain, --opamp, the series) and --stage each section's registry name, input first; every part is given.
"""


def _analyze_parser():
    from ..core.opamps import names as opamp_names
    p = command_parser("analyze-filter", "Analyze an active filter's parts as built (a design-filter result.json, "
                       "parts changed with --part): the achieved response against its target and mask, the SPICE "
                       "proof, the tolerance yield against the mask.", ANALYZE_EPILOG)
    g = p.add_argument_group("the filter")
    g.add_argument("--from", dest="from_json", metavar="RESULT_JSON",
                   help="a design-filter result.json (its --out folder's): the target, the stages and their parts")
    g.add_argument("--target", metavar="OPTIONS",
                   help="without --from: the response as design-filter's options, quoted, e.g. \"--order 4 --fc 1k\" "
                        "or \"--family chebyshev --passband 3k --max-loss 1 --stopband 12k --min-attenuation 40\"")
    g.add_argument("--stage", action="append", metavar="SECTION",
                   help="without --from: each stage's section, input first (repeatable): " + _section_names())
    # a list or repeated, as analyze-plant's --part and design-pid's --plant-part (the two accumulate)
    g.add_argument("--part", nargs="+", action=ExtendList, metavar="DESIGNATOR=VALUE",
                   help="parts as built, e.g. --part R101=10.2k C202=4.7n, or repeated: --part R101=10.2k --part "
                        "C202=4.7n")
    g.add_argument("--opamp", metavar="NAME", help=f"another op-amp for every stage: {', '.join(opamp_names())}")
    add_filter_tolerance(p)
    o = p.add_argument_group("output")
    o.add_argument("--json", action="store_true", help="print one JSON object instead of the summary")
    _add_lang(o)
    o.add_argument("--out", metavar="DIR", help="write DIR/filter.cir (the proof deck) and DIR/result.json")
    o.add_argument("--no-sim", action="store_true", help="skip the ngspice proof")
    o.add_argument("--simulator", default="ngspice-cli", choices=("ngspice-cli", "pyspice"),
                   help="ngspice-cli: `ngspice -b` (default); pyspice: the shared library")
    return p


def _read_design(path: str) -> dict:
    from ..core.errors import DesignError
    try:
        data = json.loads(Path(path).read_text())
    except OSError as exc:
        raise DesignError(f"--from {path!r}: cannot read it ({exc.strerror or exc})") from None
    except ValueError:
        raise DesignError(f"--from {path!r}: not JSON; give a design-filter result.json") from None
    if not isinstance(data, dict) or data.get("tool") != "design-filter" or "stages" not in data:
        raise DesignError(f"--from {path!r}: not a design-filter result.json (no tool design-filter and stages)")
    return data


def _as_built_inputs(data: dict, parts, opamp) -> tuple:
    """(FilterSpec, order, fc, stages) of a design-filter result.json with --part changes."""
    from ..core.errors import DesignError
    from ..filters.prototype import SectionPlan
    from ..filters.registry import get as get_topology
    from ..filters.spec import FilterSpec
    sp, mask = data["spec"], data["spec"].get("mask")
    kw = {k: sp[k] for k in ("filter_type", "family", "bessel_norm", "chebyshev_cutoff", "gain", "r_series",
                              "c_series", "amplitude_v", "gbw_margin") if sp.get(k) is not None}
    if sp.get("ripple_db") is not None and sp["family"] == "chebyshev" and not mask:
        kw["ripple_db"] = sp["ripple_db"]
    if sp["filter_type"] == "bandpass" and mask:
        kw.update(mask, bandpass_method=sp["bandpass_method"])   # the mask picks the same order and edges
    elif sp["filter_type"] == "bandpass":
        kw.update(order=sp["order"], f_low_hz=sp["f_low_hz"], f_high_hz=sp["f_high_hz"],
                  bandpass_method=sp["bandpass_method"])
    elif mask:
        kw.update(mask, **sp.get("delay_target", {}))
    else:
        kw.update(order=sp["order"], fc_hz=sp["fc_hz"])
    kw["opamp"] = opamp or data["opamp"]["name"]
    spec = FilterSpec(**kw)
    stages, refs = [], {}
    for i, st in enumerate(data["stages"], 1):
        topo = get_topology(st["topology"])
        values = dict(st["parts"])
        for r in values:
            refs[topo.prefixed(r, f"{i}0")] = (len(stages), r)
        stages.append([SectionPlan(st["kind"], st["order"], st["fn_hz"], st["q"]), st["topology"], st["gain"], values])
    for item in parts or ():
        ref, _, text = str(item).partition("=")
        ref = ref.strip().upper()
        if not text or ref not in refs:
            raise DesignError(f"--part {item!r}: give DESIGNATOR=VALUE with one of this filter's parts: "
                              f"{', '.join(refs)}")
        k, r = refs[ref]
        stages[k][3][r] = _part_value(ref, text)
    return spec, int(sp["order"]), float(sp["fc_hz"]), [tuple(s) for s in stages]


def _part_value(ref: str, text: str) -> float:
    """--part REF=TEXT's value: engineering notation, above 0 (one line otherwise)."""
    from ..core.errors import DesignError
    from ..core.units import parse_value
    value = parse_value(text.strip(), f"--part {ref}")
    if not value > 0:
        raise DesignError(f"--part {ref} must be above 0, got {text.strip()!r}")
    return value


def _section_names() -> str:
    from ..filters.registry import names
    return ", ".join(names())


def _target_inputs(args) -> tuple:
    """(FilterSpec, order, fc, stages) of --target, --stage and --part: each stage matched to the
    target's section of its kind and order nearest its parts' fn and Q."""
    import shlex

    from ..core.errors import DesignError
    from ..filters.design import section_plans
    from ..filters.registry import get as get_topology
    if not args.target or not args.stage:
        raise DesignError("give --from RESULT_JSON, or --target \"OPTIONS\" with one --stage per section and every "
                          "--part")
    try:
        targs = _parser().parse_args(shlex.split(args.target))
    except ValueError as exc:
        raise DesignError(f"--target {args.target!r}: {exc}") from None
    if args.opamp:
        targs.opamp = args.opamp
    spec = _spec(targs)
    order, fc, plans = section_plans(spec)
    topos = [get_topology(name.strip()) for name in args.stage]
    if len(topos) != len(plans):
        raise DesignError(f"--stage: the target is {len(plans)} sections (" + ", ".join(
            f"{p.kind} order {p.order}" for p in plans) + f"), --stage gave {len(topos)}")
    given = {}
    for item in args.part or ():
        ref, _, text = str(item).partition("=")
        given[ref.strip().upper()] = (item, text.strip())
    stages, left = [], list(plans)
    for i, topo in enumerate(topos, 1):
        same = [p for p in left if p.kind == topo.kind and p.order == topo.order]
        if not same:
            raise DesignError(f"--stage {i}: {topo.name} is a {topo.kind} section of order {topo.order}; the target "
                              "has none left (" + ", ".join(f"{p.kind} order {p.order}" for p in left) + ")")
        values = {}
        for r in topo.designators:
            ref = topo.prefixed(r, f"{i}0")
            if ref not in given:
                raise DesignError(f"--part: stage {i} ({topo.name}) needs {ref} (its parts: "
                                  + ", ".join(topo.prefixed(x, f"{i}0") for x in topo.designators) + ")")
            values[r] = _part_value(ref, given.pop(ref)[1])
        fig = topo.figures(values)
        plan = min(same, key=lambda p: abs(math.log(fig.fn_hz / p.fn_hz))
                   + (abs(math.log(fig.q / p.q)) if p.q else 0.0))
        left.remove(plan)
        stages.append((plan, topo.name, float(fig.gain), values))
    if given:
        raise DesignError(f"--part {next(iter(given.values()))[0]!r}: no such part in these stages")
    return spec, order, fc, stages


def _analyze(args) -> int:
    from ..core.errors import DesignError
    from ..filters.design import as_built
    if args.from_json:
        if args.target or args.stage:
            raise DesignError("--target and --stage describe a filter without --from; give one or the other")
        spec, order, fc, stages = _as_built_inputs(_read_design(args.from_json), args.part, args.opamp)
    else:
        spec, order, fc, stages = _target_inputs(args)
    settings = tolerance_settings(args)
    result = as_built(spec, order, fc, stages, simulate=not args.no_sim, simulator=args.simulator)
    return _emit(result, args, run_tolerance(result, args, settings))


def analyze_filter_main(argv=None) -> int:
    """``analyze-filter``'s entry point.

    Parameters
    ----------
    argv : list of str, optional
        The arguments (default ``sys.argv[1:]``).

    Returns
    -------
    int
        The exit status (0 done, 2 bad input, 3 simulator error).
    """
    return run_cli("analyze-filter", _analyze_parser, _analyze, argv)


if __name__ == "__main__":  # pragma: no cover
    sys.exit(design_filter_main())
