"""The build sheet and bundle of a plant on a registered topology
(:class:`~designer.plant.circuit_design.CircuitPlantResult`): the bill of materials
and the wiring from the topology's netlist on the bench board
(:func:`designer.spice.deck.board`, :mod:`designer.report.wiring`: topology-free), the
target and what the build achieves, the bench (the generator and scope settings, the sine
check, the readings' tolerance band and its plot, ``band.png``), the SPICE agreement, the sensitivities over the
declared parts and the alternatives; rendered as the result is (nothing recomputed).
The schematic is the filter cascade's drawing of one stage
(:func:`designer.filters.report.draw_cascade`: any registered section), titled with
the build's ideal fn, Q and gain.
"""

from __future__ import annotations

from dataclasses import dataclass

from ..core.i18n import N_, language, translated
from ..core.i18n import gettext as _
from ..core.units import format_eng
from ..filters.prototype import SectionPlan
from ..report import document as R
from ..report.bundle import write_design
from ..report.tolerance import csv_texts
from ..report.tolerance import histogram_plots
from ..report.tolerance import section as tolerance_section
from ..report.wiring import bench_rows, bom_csv, bom_rows, wiring_rows
from ..spice.deck import board
from . import circuit
from .report import METRIC_ROWS, prbs_blocks, prbs_png, prbs_texts, sine_text

__all__ = ["bench_settings", "title_of", "sections", "bom", "schematic", "summary_text", "write_outputs", "bench_blocks",
           "band_png"]

#: the schematic's width (drawing units) that holds the op-amp's output label
OUTPUT_LABEL_ROOM = 31.0
#: what the section's end nets are called on the sheet
#: the bill of materials' columns as the sheet heads them
BOM_SHOWN = (N_("Ref"), N_("Value"), N_("Code"), N_("Qty"), N_("Series"), N_("Tol."), N_("Package"), N_("Role"))
NET_LABELS = {"vin": N_("generator (CH1)"), "vout": N_("output (CH2)"), "0": N_("ground")}


def title_of(result) -> str:
    """The sheet's title.

    Parameters
    ----------
    result : CircuitPlantResult
        The design.

    Returns
    -------
    str
        One line.
    """
    t = result.target
    if result.mode == "analyze":
        f = result.figures["ideal"]
        zeta = "" if f["zeta"] is None else f", zeta {f['zeta']:.4g}"
        return _("{section} plant as built: fn {fn} Hz{zeta}, gain {gain}").format(
            section=_(result.section.title), fn=f"{f['fn_hz']:.5g}", zeta=zeta, gain=f"{f['gain']:.4g}")
    zeta = "" if t.zeta is None else f", zeta {t.zeta:g}"
    return _("{section} plant: fc {fc} Hz{zeta}, gain {gain}").format(
        section=_(result.section.title), fc=f"{t.fc_hz:g}", zeta=zeta, gain=f"{t.gain:g}")


def bom(result) -> list:
    """The bill of materials rows (:data:`designer.report.wiring.BOM_HEADER`).

    Parameters
    ----------
    result : CircuitPlantResult
        The design.

    Returns
    -------
    list of list
        Rows.
    """
    return bom_rows(board(result.netlist, result.opamp, result.package), result.sourcing.source, result.opamp.name)


def _f(v, unit: str) -> str:
    return "-" if v is None else format_eng(v, unit, 4)


def _n(v) -> str:
    return "-" if v is None else f"{v:.4g}"


def _sensitivity_rows(sensitivity: dict) -> list:
    """The parts' (and the section's parameters') rows, ideal and op-amp-aware side by side, then the
    op-amp's own (GBW, A0: the op-amp-aware model's only)."""
    ideal, opamp = sensitivity["ideal"], sensitivity["opamp"]
    none = {"wn": None, "zeta": None}
    # the op-amp's rows to four decimals, as the plant's sheet: their finite differences resolve ~1e-7
    # (A0's row of wn is that small), so more digits would show rounding
    fmt = {label: (lambda v: "-" if v is None else f"{v:+.4f}") for label in circuit.OPAMP_PARAMETERS}
    return [[label, *(fmt.get(label, _n)(table.get(label, none)[k]) for table in (ideal, opamp) for k in ("wn", "zeta"))]
            for label in {**ideal, **opamp}]


def _targets(result) -> list:
    t, fi, fo = result.target, result.figures["ideal"], result.figures["opamp"]
    rows = [["fn", _f(t.fc_hz, "Hz"), _f(fi["fn_hz"], "Hz"), _f(fo["fn_hz"], "Hz")],
            ["zeta", _n(t.zeta), _n(fi["zeta"]), _n(fo["zeta"])],
            [_("gain"), _n(t.gain), _n(fi["gain"]), ""],
            ["-3 dB", "", ", ".join(_f(f, "Hz") for f in fi["f3db_hz"]),
             ", ".join(_f(f, "Hz") for f in fo["f3db_hz"])]]
    out = [R.table([_("figure"), _("target"), _("ideal op-amp"), result.opamp.name], rows)]
    step = result.steps["opamp"]
    if step is not None:
        out.append(R.text(_("step ({opamp}): overshoot {os} %, peak time {tp}, 2 % settling {ts}").format(
            # a step without a peak (no overshoot) has no peak time: worded as the seed plant's sheet words it
            opamp=result.opamp.name, os=f"{step['overshoot_pct']:.3g}", tp=R.fmt_time(step['peak_time_s']),
            ts=R.fmt_time(step['settling_time_s']))))
    return out


def _section_sine_text(sine) -> str:
    """The sine check in one line: a low- or high-pass's as the Sallen-Key plant's sheet gives it (its gain read
    against DC, or against the high-frequency end), a band-pass's at its centre."""
    if sine.kind != "bandpass":
        return sine_text(sine)
    spice = sine.spice_f_peak_hz is not None
    f, g = (sine.spice_f_peak_hz, sine.spice_peak_gain) if spice else (sine.f_peak_hz, sine.peak_gain)
    lo, hi = (sine.spice_f_3db_low_hz, sine.spice_f_3db_hz) if spice else (sine.f_3db_low_hz, sine.f_3db_hz)
    return _("sine {amplitude} pk at the centre {f}: gain x{gain}, -3 dB (x0.707) at {lo} and {hi}").format(
        amplitude=format_eng(sine.amplitude_v, 'V'), f=format_eng(f, 'Hz', 3), gain=f"{g:.3g}",
        lo=_f(lo, "Hz"), hi=_f(hi, "Hz"))


def bench_settings(result) -> list:
    """The generator and the scope as set for the square wave (into the section's input part, as its
    declaration names it), and the sine check: the sheet's settings table, which the page shows too.

    Parameters
    ----------
    result : CircuitPlantResult
        The design with its bench (:func:`designer.plant.circuit_design.with_bench`).

    Returns
    -------
    list
        (set, to) rows; empty when the result has no bench.
    """
    if result.test is None:
        return []
    into = next(p.ref for p in result.section.netlist(result.values).parts if "vin" in (p.a, p.b))
    rows = bench_rows(result.test, result.scope, into)
    if result.sine is not None:
        rows.append([_("sine check"), _section_sine_text(result.sine)])
    return rows


def bench_blocks(result, with_images: bool = False) -> list:
    """The bench: the generator and the scope as set, the sine check, and the readings' band over the parts'
    tolerance corners (a low-pass's step readings; fn and zeta for every kind), the band's plot with images.

    Parameters
    ----------
    result : CircuitPlantResult
        The design (its ``tolerance``, ``scope``, ``sine`` and ``test``).
    with_images : bool
        Include the band's plot (``band.png``).

    Returns
    -------
    list
        Blocks (:mod:`designer.report.document`); empty when the result has no bench.
    """
    tol = result.tolerance
    if tol is None:
        return []
    rows = bench_settings(result)
    fo = result.figures["opamp"]
    readings = [["fn", _f(fo["fn_hz"], "Hz"), f"{_f(tol.fn_hz.lo, 'Hz')} .. {_f(tol.fn_hz.hi, 'Hz')}"]]
    if result.section.order == 2:
        readings.append(["zeta", _n(fo["zeta"]), f"{_n(tol.zeta.lo)} .. {_n(tol.zeta.hi)}"])
    step = result.steps["opamp"]
    if step is not None:
        for key, label, f in METRIC_ROWS:
            band = getattr(tol, key)
            readings.append([_(label), f(step.get(key)), f"{f(band.lo)} .. {f(band.hi)}"])
    head = _("band (R {r} %, C {c} %)").format(r=f"{tol.r_tolerance_pct:g}", c=f"{tol.c_tolerance_pct:g}")
    image = [R.image("band.png", head)] if with_images else []
    return [R.subhead(_("Generator and scope")), R.table([_("set"), _("to")], rows, "compact"),
            R.table([_("reading (rising edge)"), _("expected ({opamp} model)").format(opamp=result.opamp.name), head],
                    readings), *image]


def band_png(result) -> bytes:
    """The bench's square-wave step (the op-amp-aware model's, and the ideal one's) with the tolerance band shaded.

    Parameters
    ----------
    result : CircuitPlantResult
        The design (its ``tolerance`` and ``test``).

    Returns
    -------
    bytes
        The PNG.
    """
    import numpy as np

    from ..core.lti import step_response
    from ..report.plots import step_plot
    tol, a = result.tolerance, result.test.amplitude_v
    # every corner unstable: no envelope (tolerance_band's), the models' steps over the half period alone
    t = np.linspace(0.0, result.test.half_period_s, 4001) if tol.t_s is None else tol.t_s
    curves = {}
    for label, (num, den) in ((_("analytic ({opamp} model)").format(opamp=result.opamp.name),
                               circuit.opamp_tf(result.section, result.values, result.opamp)),
                              (N_("analytic (ideal op-amp)"), result.section.coefficients(result.values))):
        num = np.asarray(num, float)
        curves[label] = a * step_response(np.trim_zeros(num, "f") if np.any(num) else num, np.asarray(den, float),
                                          t)
    band = None if tol.t_s is None else (tol.t_s, tol.lo * a, tol.hi * a, _("tolerance band (R {r} %, C {c} %)").format(
        r=f"{tol.r_tolerance_pct:g}", c=f"{tol.c_tolerance_pct:g}"))
    return step_plot(t, curves, _("Step response, 0 -> {v} V").format(v=f"{a:g}"), band=band)


def sections(result, with_images: bool = False, schematic_svg: str = "") -> list:
    """The build sheet as (heading, blocks) sections (:mod:`designer.report.document`).

    Parameters
    ----------
    result : CircuitPlantResult
        The design.
    with_images : bool
        Include the schematic (the bundle's sheet; False: the terminal text and the web page's sheet).
    schematic_svg : str
        The schematic inlined in the HTML.

    Returns
    -------
    list of tuple
        The sections.
    """
    b = board(result.netlist, result.opamp, result.package)
    fig = [R.figure("schematic.png", schematic_svg, _("schematic"))] if with_images else []
    prbs = [] if result.prbs is None else [(_("Bench test under a PRBS (--stimulus prbs)"), [
        *prbs_blocks(result), *([R.image("prbs.png", _("the last period of the PRBS: generator, SPICE and the model"))]
                                if with_images else [])])]
    out = [(_("Build"), [*fig, R.table([_(h) for h in BOM_SHOWN], [[*r[:6], _(r[6]), r[7]] for r in bom(result)])]),
           (_("Wiring"), [R.table([_("part"), _("code"), _("from"), _("to")],
                                  wiring_rows(b, NET_LABELS, (result.opamp.vcc, result.opamp.vee)))]),
           *prbs,
           (_("Target and achieved"), _targets(result)),
           *([(_("Bench test: what the scope shows"), bench_blocks(result, with_images))]
             if result.tolerance is not None else []),
           (_("Checks"), [R.table([_("check"), _("result"), _("detail")],
                                  [[_(c.title), _("ok") if c.ok else _("FAILED"), c.shown()] for c in result.checks])]),
           (_("Sensitivity"), [R.table([_("part"), _("S wn (ideal)"), _("S zeta (ideal)"), _("S wn (op-amp)"),
                                        _("S zeta (op-amp)")],
                                    _sensitivity_rows(result.sensitivity))])]
    if len(result.alternatives) > 1:
        refs = result.section.designators
        out.append((_("Alternatives (best first)"),
                    [R.table([*refs, "fn", "zeta", _("gain"), _("worst error")],
                             [[*(format_eng(c.values[r], "Ohm" if r[0] == "R" else "F", 3) for r in refs),
                               _f(c.fn_hz, "Hz"), _n(c.zeta), _n(c.gain), f"{100 * c.worst:.3g} %"]
                              for c in result.alternatives])]))
    if result.monte_carlo is not None:   # the spread and its histograms; --replay I: the build replayed
        out.append((_("Tolerance analysis (Monte Carlo)"), tolerance_section(result, with_images)))
    if result.notes:
        out.append((_("Notes"), [R.text(translated(n)) for n in result.notes]))
    return out


def summary_text(result) -> str:
    """The terminal summary: the sheet as text.

    Parameters
    ----------
    result : CircuitPlantResult
        The design.

    Returns
    -------
    str
        Text.
    """
    text = R.to_text(title_of(result), sections(result)) + "\n"
    # the Monte Carlo's and the worst case's lines, as the Sallen-Key plant's summary prints them
    for extra in (result.monte_carlo, result.worst_case):
        if extra is not None:
            text += "\n" + "\n".join(extra.summary_lines()) + "\n"
    return text


@dataclass(frozen=True)
class _Stage:
    """The build as the cascade drawing's one stage (what its title reads)."""

    number: int
    topology: str
    plan: SectionPlan
    gain: float


@dataclass(frozen=True)
class _OneStage:
    """The build as a one-stage cascade (:func:`designer.filters.report.draw_cascade`'s ``result``)."""

    stages: tuple


def schematic(result):
    """The section's schematic: the filter cascade's drawing of one stage, its parts
    and op-amp on the deck's nets (checked by :func:`designer.report.schematic.check_connectivity`).

    Parameters
    ----------
    result : CircuitPlantResult
        The design.

    Returns
    -------
    designer.report.schematic.Sheet
        The drawing.
    """
    import schemdraw.elements as elm

    from ..filters.report import draw_cascade
    topo, f = result.section, result.figures["ideal"]
    stage = _Stage(1, topo.name, SectionPlan(topo.kind, topo.order, f["fn_hz"], f["q"]), abs(f["gain"]))
    sheet = draw_cascade(board(result.netlist, result.opamp, result.package), _OneStage((stage,)))
    # the picture is cropped to its elements, not to the labels' text: an unseen line past the output's label
    # (a cascade's second column gives it that room)
    sheet.d.add(elm.Line().at((0, 4.5)).to((OUTPUT_LABEL_ROOM, 4.5)).color("white"))
    return sheet


def write_outputs(result, out_dir, name: str, lang: str | None = None) -> dict:
    """Write ``netlists/<name>.cir`` and ``reports/<name>/`` (sheets, schematic.png, result.json,
    bom.csv, monte-carlo.csv with a Monte Carlo) atomically (:func:`designer.report.bundle.write_design`).

    Parameters
    ----------
    result : CircuitPlantResult
        The design (its ``files`` set here, before result.json is written).
    out_dir : str or Path
        Where ``netlists/`` and ``reports/`` go.
    name : str
        The design's name.
    lang : str or None
        The build sheet's language (None: the current one).

    Returns
    -------
    dict
        The files written.
    """
    texts = {"bom_csv": ("bom.csv", lambda r: bom_csv(bom(r))), **csv_texts(result)}
    if result.square is not None:     # --square-freq: the bench test's deck and its waveforms
        texts.update({"square_deck": ("square-test.cir", lambda r: r.square.deck),
                      "waveforms_csv": ("waveforms.csv", lambda r: r.square.csv_text())})
    # --stimulus prbs: the generator's files, its deck, and waveforms.csv becomes its run (as the Sallen-Key plant's)
    texts.update(prbs_texts(result))
    plots = ([("prbs.png", prbs_png)] if result.prbs is not None else []) + list(histogram_plots(result)) + \
        ([("band.png", band_png)] if result.tolerance is not None else [])
    with language(lang):
        return write_design(result, out_dir, name, plots, schematic, lambda svg: sections(result, True, svg),
                            title_of(result), texts)
