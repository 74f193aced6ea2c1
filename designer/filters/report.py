"""A designed filter's build sheet, rendered from the typed design
(:class:`~designer.filters.design.FilterDesign`) and its bench test
(:class:`~designer.filters.bench.FilterBench`) as they are: nothing here
computes a figure of the design.

The sheet follows the plant's (:mod:`designer.plant.report`, the same
:mod:`designer.report` blocks, wiring, bill of materials and bundle): the
cascade's schematic stage by stage (each stage a row of its parts between
labelled nets and its op-amp with pin numbers: labels of one name are one net,
checked against the deck by :func:`designer.report.schematic.check_connectivity`),
the bill of materials of all stages (the op-amps in the op-amp's default
package: a dual or quad package takes two or four stages), the wiring by pin,
each stage's figures and op-amp checks, the sine sweep with its tolerance band
and the generator and scope settings, the step or tone-burst test, the Bode plot
with the mask drawn, the Bessel's group delay, and why the values differ from a
table's (the tables' corner convention, the op-amp pre-distortion, the joint
E-series choice), and with ``--alternatives`` the joint search's next best part sets
(:mod:`designer.filters.alternatives`).
"""

from __future__ import annotations

import math
from dataclasses import dataclass, field

import numpy as np

from ..core.i18n import N_
from ..core.i18n import gettext as _
from ..core.i18n import localise
from ..core.jsonio import json_safe
from ..core.units import format_eng
from ..report import document as R
from ..report.plots import figure, log_frequency_axis, png_bytes, step_plot
from ..report.schematic import Sheet
from ..report.wiring import bom_csv, bom_rows, wiring_rows
from ..spice.deck import GROUND, board
from .bench import FilterBench, bench_of

__all__ = ["FilterSheet", "sheet_of", "alternatives_json", "alternative_words", "build_board", "draw_cascade", "net_label", "sections", "title_of",
           "bom", "plots", "schematic", "write_outputs", "write_folder", "SHEET_FILES"]

#: the decoupling's middle digit (C191, C192, ..): the stages' own capacitors are C101, C201, ..
DECOUPLING_DIGIT = "9"
#: the design's figures that are times measured on the clock
WALL_CLOCK = ("search_s", "candidates_s")
#: the sheet's files besides the deck and result.json, in a --out folder
SHEET_FILES = ("build-sheet.md", "build-sheet.html", "schematic.png", "bode.png", "time-test.png", "bom.csv")


@dataclass
class FilterSheet:
    """A design with its bench test: what the sheet and the bundle are written from.

    Parameters
    ----------
    design : FilterDesign
        The design.
    bench : FilterBench
        Its bench test.
    files : dict
        Paths written (set when written).
    timings : dict
        Seconds spent (``report_s``).
    wall_clock : bool
        Keep the search's wall-clock figures (``search_s``, ``candidates_s``) in the JSON; a bundle
        leaves them out, so that it regenerates byte for byte.
    extra : dict
        More of the JSON (the tolerance analyses'), beside the design's.
    alternatives : list
        The joint search's best part sets asked for (:class:`~designer.filters.alternatives.Alternative`, best
        first): a table on the sheet, ``alternatives`` in the JSON; empty (none asked): neither.
    """

    design: object
    bench: FilterBench
    files: dict = field(default_factory=dict)
    timings: dict = field(default_factory=dict)
    wall_clock: bool = True
    extra: dict = field(default_factory=dict)
    alternatives: list = field(default_factory=list)

    @property
    def deck(self) -> str:
        """The design's ngspice deck (:meth:`FilterDesign.deck`)."""
        return self.design.deck()

    def to_dict(self) -> dict:
        """The design's JSON with the bench's under ``bench`` and the files.

        Returns
        -------
        dict
            JSON-ready.
        """
        data = {**self.design.to_dict(), **self.extra, **alternatives_json(self.alternatives),
                "bench": self.bench.to_dict(), "files": dict(self.files)}
        if not self.wall_clock:
            data["figures"] = {k: v for k, v in data["figures"].items() if k not in WALL_CLOCK}
        return data


def sheet_of(result) -> FilterSheet:
    """The sheet's typed content for ``result``.

    Parameters
    ----------
    result : FilterDesign
        The design.

    Returns
    -------
    FilterSheet
        With :func:`designer.filters.bench.bench_of`'s bench.
    """
    return FilterSheet(result, bench_of(result))


def alternatives_json(alternatives: list) -> dict:
    """The part sets' JSON as design-filter --json prints it: ``{"alternatives": [...]}``, or ``{}`` when none
    were asked for.

    Parameters
    ----------
    alternatives : list of Alternative
        Best first.

    Returns
    -------
    dict
        JSON-ready.
    """
    return {"alternatives": json_safe([a.to_dict() for a in alternatives])} if alternatives else {}


def alternative_words(alt) -> tuple:
    """One part set as the sheet, the summary and the page show it: whether it meets the mask (and the delay
    target), in the current language (``meets the limits``, ``breaks the limits by X``, or empty without
    limits), and its parts as a line, every stage's in build order (``R101 10 kOhm, C101 10 nF, ..``).

    Parameters
    ----------
    alt : Alternative
        The part set.

    Returns
    -------
    tuple of str
        (limits, parts).
    """
    parts = ", ".join(f"{ref} {format_eng(v, 'Ohm' if ref.startswith('R') else 'F')}" for ref, v in alt.parts.items())
    if alt.violation is None:
        return "", parts
    return (_("meets the limits") if alt.violation <= 0 else
            _("breaks the limits by {amount}").format(amount=f"{alt.violation:.3g}")), parts


def _alternatives(data: FilterSheet) -> list:
    alts, s = data.alternatives, data.design.spec
    limited = alts[0].violation is not None
    head = [_("rank"), _("worst deviation from the ideal")] + ([_("limits")] if limited else []) + [_("parts")]
    rows = [[a.rank, f"{a.error_db:.3g} dB", *alternative_words(a)[0 if limited else 1:]] for a in alts]
    what = (_("the mask and the group-delay target") if s.has_delay_target else _("the mask")) if limited else None
    text = _("The joint search's best part sets over the same E-series candidates, best first (1 is the one "
             "built): its worst deviation from the ideal with the {opamp} model{limits}. A builder short of one "
             "value takes the next set whole, not that part alone.").format(
                 opamp=data.design.opamp.name,
                 limits=_("; the limits are {what} (the search weighs how far a set breaks them, in dB or % "
                          "points, 1000 times its deviation)").format(what=what) if limited else "")
    return [R.text(text), R.table(head, rows, "compact")]


def build_board(result):
    """The cascade as built: its netlist in the op-amp's default package.

    Parameters
    ----------
    result : FilterDesign
        The design.

    Returns
    -------
    designer.spice.deck.Board
        Stages in package units in order (U1A, U1B, U2A ...).
    """
    return board(result.cascade().netlist(), result.opamp, decoupling_digit=DECOUPLING_DIGIT)


def net_label(net: str) -> str:
    """What a cascade net is called on the sheet.

    Parameters
    ----------
    net : str
        The deck's net (``vin``, ``s1``, ``vout``, ``u2_x``, ``0``).

    Returns
    -------
    str
        ``IN (CH1)``, ``S1``, ``OUT (CH2)``, ``U2 x``, ``ground``.
    """
    if net == "vin":
        return "IN (CH1)"
    if net == "vout":
        return "OUT (CH2)"
    if net == GROUND:
        return "ground"
    if net.startswith("s") and net[1:].isdigit():
        return f"S{net[1:]}"
    amp, _, node = net.partition("_")
    return f"{amp.upper()} {node}" if node else net


def _end(s: Sheet, at, net: str, loc: str) -> None:
    """A part's or pin's end: the ground symbol on ground, else its net's label."""
    if net == GROUND:
        s.ground(at)
    else:
        s.net_label(at, net, net_label(net), loc=loc)


def draw_cascade(b, result, sheet: Sheet | None = None) -> Sheet:
    """The cascade of ``b`` (:func:`build_board`) stage by stage, two stages a row:
    each stage titled with its section, fn, Q and gain, its parts one under the
    other between their nets' labels, its op-amp (package unit and pins) with
    its pins on their nets' labels.

    Parameters
    ----------
    b : designer.spice.deck.Board
        The board.
    result : FilterDesign
        The design (the stages' titles); with one stage every part of the board is its own, unprefixed
        (a section plant's sheet, :func:`designer.plant.circuit_report.schematic`).
    sheet : Sheet, optional
        Draw on this sheet (a new one by default).

    Returns
    -------
    Sheet
        The drawing, its connectivity recorded.
    """
    import schemdraw.elements as elm
    # large labels: the drawing spans the printed page's width, two stages side by side
    s = sheet or CascadeSheet(fontsize=18, unit=2.0)
    parts = b.netlist.parts
    width, pitch = 27.0, 3.8
    # a stage's parts carry its prefix (R101 ..); a single section (a plant's) is every part, unprefixed (R1 ..)
    mine_of = (lambda st: list(parts)) if len(result.stages) == 1 else \
        (lambda st: [p for p in parts if p.ref[1:-1] == f"{st.number}0"])
    heights = [max(len(mine_of(st)), 2) * pitch + 4.6 for st in result.stages]
    y, row_h = 0.0, 0.0
    for i, (st, amp) in enumerate(zip(result.stages, b.netlist.amps)):
        col = i % 2
        if col == 0:
            y = y - row_h
            row_h = max(heights[i:i + 2])
        x0 = col * width
        # the labels in the sheet's language (the page draws this schematic too), numbers as it writes them
        q = f"Q {st.plan.q:.3g}" if st.plan.q else _("first order")
        s.text((x0, y + 3.9), _("Stage {number}: {topology}").format(number=st.number, topology=st.topology),
               size=1.05, halign="left")
        s.text((x0, y + 2.9), localise(_("fn {fn}, {q}, gain {gain}").format(
            fn=format_eng(st.plan.fn_hz, 'Hz', 4), q=q, gain=f"{st.gain:.3g}")), size=0.95, halign="left")
        # the drawing's extent: matplotlib crops the picture to its elements, not to the labels' text
        s.d.add(elm.Line().at((x0 - 0.6, y + 4.5)).to((x0 + width - 0.6, y + 4.5)).color("white"))
        mine = mine_of(st)
        for k, p in enumerate(mine):
            yy = y - k * pitch
            a, c = (x0 + 4.2, yy), (x0 + 8.2, yy)
            s.part(p, a, c, label_loc="top")
            _end(s, a, p.a, "left")
            _end(s, c, p.b, "right")
        unit = b.unit_of(amp.ref)
        pts = s.opamp(amp, unit, b.package.part, (x0 + 19.5, y - 0.6), plus_on_top=True)
        for term, loc in (("inp", "left"), ("inn", "left"), ("out", "right")):
            pt = pts[term]
            end = (pt[0] + (1.0 if term == "out" else -3.0), pt[1])
            s.wire(pt, end)
            _end(s, end, getattr(amp, term), loc)
    return s


class CascadeSheet(Sheet):
    """A :class:`Sheet` whose PNG is sized to the drawing (a cascade is larger than matplotlib's default figure)."""

    def png(self, dpi: int = 100, inches_per_unit: float | None = 0.3) -> bytes:
        """The drawing as PNG bytes, 0.3 inch a unit (readable when printed at the sheet's width).

        Parameters
        ----------
        dpi : int
            Resolution.
        inches_per_unit : float
            Scale.

        Returns
        -------
        bytes
            PNG.
        """
        return super().png(dpi, inches_per_unit)


def schematic(sheet_data: FilterSheet) -> Sheet:
    """The cascade's drawing (:func:`draw_cascade`) of a :class:`FilterSheet`.

    Parameters
    ----------
    sheet_data : FilterSheet
        The sheet.

    Returns
    -------
    Sheet
        The drawing.
    """
    return draw_cascade(build_board(sheet_data.design), sheet_data.design)


def title_of(result) -> str:
    """The sheet's title.

    Parameters
    ----------
    result : FilterDesign
        The design.

    Returns
    -------
    str
        ``4th-order Butterworth low-pass, fc 1 kHz ...``.
    """
    s = result.spec
    kind = _(_KIND_WORDS[s.filter_type])
    where = (_("band {low} to {high}").format(low=format_eng(s.f_low_hz, "Hz"), high=format_eng(s.f_high_hz, "Hz"))
             if s.filter_type == "bandpass" else f"fc {format_eng(result.fc_hz, 'Hz')}")
    fam = s.family.capitalize() + (f" {s.ripple_db:g} dB" if s.family == "chebyshev" else "")
    return _("Order-{order} {family} {kind}, {where}, gain {gain}, {opamp}").format(
        order=result.order, family=fam, kind=kind, where=where, gain=f"{s.gain:g}", opamp=result.opamp.name)


#: the response types in the sheet's words (translated where shown)
_KIND_WORDS = {"lowpass": N_("low-pass"), "highpass": N_("high-pass"), "bandpass": N_("band-pass")}


def bom(result, b=None) -> list:
    """The bill of materials rows (:data:`designer.report.wiring.BOM_HEADER`).

    Parameters
    ----------
    result : FilterDesign
        The design.
    b : Board, optional
        :func:`build_board`'s board.

    Returns
    -------
    list
        Rows; resistors of the design's series at the bench's 1 %, capacitors at 5 %.
    """
    from .bench import C_TOL_PCT, R_TOL_PCT
    b = b or build_board(result)
    stage_refs = {p.ref for p in b.netlist.parts}
    s = result.spec

    def source(ref):
        if ref not in stage_refs:
            return None
        return (s.r_series, R_TOL_PCT) if ref.startswith("R") else (s.c_series, C_TOL_PCT)
    return bom_rows(b, source, result.opamp.name)


def _deg(v) -> str:
    return f"{v:+.1f}"


def _sweep(data: FilterSheet) -> list:
    bench, amp = data.bench, data.bench.amplitude_v
    rows = [[format_eng(p.f_hz, "Hz", 4), f"{p.gain_db:+.2f}", f"{p.gain_lo_db:+.2f} .. {p.gain_hi_db:+.2f}",
             _deg(p.phase_deg), f"{_deg(p.phase_lo_deg)} .. {_deg(p.phase_hi_deg)}",
             format_eng(p.out_pk_v, "V", 3), format_eng(p.time_per_div_s, "s") + "/div",
             format_eng(p.ch1_v_per_div, "V") + "/div", format_eng(p.ch2_v_per_div, "V") + "/div",
             _(p.note) if p.note else ""]
            for p in bench.sweep]
    return [R.text(_("Generator: sine, {peak} peak ({pp} pk-pk), no offset, output High-Z, into IN; scope CH1 on IN, "
                     "CH2 on OUT, DC coupled, trigger CH1 rising at 0 V. At each frequency read the gain 20 log10(CH2 "
                     "pk-pk / CH1 pk-pk) and the phase -360 x f x (the delay from CH1's rising zero crossing to "
                     "CH2's); the phase is shown within -180..+180 deg, as the scope shows it.").format(
                         peak=format_eng(amp, "V"), pp=format_eng(2 * amp, "V"))),
            R.text(_("Band: {builds} builds of the parts drawn within R {r} %, C {c} % (seed {seed}), 0.5th to 99.5th "
                     "percentile, with the {opamp} model.").format(
                         builds=bench.builds, r=f"{bench.r_tol_pct:g}", c=f"{bench.c_tol_pct:g}", seed=bench.seed,
                         opamp=data.design.opamp.name)),
            R.table(["f", _("gain (dB)"), _("band (dB)"), _("phase (deg)"), _("band (deg)"), _("CH2 peak"),
                     _("time base"), "CH1", "CH2", ""], rows, "compact")]


def _time_test(data: FilterSheet) -> list:
    tt = data.bench.time_test
    m = tt.metrics
    if tt.kind == "step":
        gen = _("square {f}, 0 to {a} (offset {offset}), into IN").format(
            f=format_eng(tt.frequency_hz, "Hz"), a=format_eng(tt.amplitude_v, "V"),
            offset=format_eng(tt.amplitude_v / 2, "V"))
        rows = [[_("overshoot"), f"{m['overshoot_pct']:.3g} %"],
                [_("rise time (10-90 %)"), format_eng(m["rise_time_s"], "s")],
                [_("settling time (2 %)"), format_eng(m["settling_time_s"], "s")],
                [_("output peak"), format_eng(m["peak_v"], "V")], [_("final value"), format_eng(m["final_v"], "V")]]
        what = _("the step: the rising edge of a square wave whose half period is five settling times")
    else:
        gen = _("burst of {cycles} cycles of a {f} sine, {a} peak, repeated at {repeat}, into IN").format(
            cycles=tt.cycles, f=format_eng(tt.frequency_hz, "Hz"), a=format_eng(tt.amplitude_v, "V"),
            repeat=format_eng(tt.repeat_hz, "Hz"))
        rows = [[_("steady output peak"), format_eng(m["steady_pk_v"], "V")],
                [_("largest output peak"), format_eng(m["peak_v"], "V")],
                [_("within 2 % of the steady peak after"), format_eng(m["settle_s"], "s")]]
        what = _("the tone burst at the passband's centre: the output builds up and rings out")
    settings = [[_("generator"), gen],
                [_("time base"), _("{t}/div, trigger CH1 rising").format(t=format_eng(tt.time_per_div_s, "s"))],
                ["CH2", _("{v}/div DC on OUT").format(v=format_eng(tt.ch2_v_per_div, "V"))]]
    return [R.text(_("Test: {what} (the chosen parts, ideal op-amps).").format(what=what)),
            R.table([_("set"), _("to")], settings, "compact"),
            R.table([_("reading"), _("expected")], rows, "compact")]


def _stages(data: FilterSheet) -> list:
    r = data.design
    op = r.opamp
    rows = []
    of = _("{needed} of {available}")
    for st, c in zip(r.stages, data.bench.checks):
        rows.append([st.number, st.topology, format_eng(st.plan.fn_hz, "Hz", 4),
                     "" if st.plan.q is None else f"{st.plan.q:.4g}", f"{st.gain:.4g}",
                     f"{20 * math.log10(st.peak_gain):+.2f} dB", format_eng(c.out_peak_v, "V", 3),
                     of.format(needed=format_eng(c.gbw_needed_hz, "Hz", 3), available=format_eng(c.gbw_hz, "Hz", 3)),
                     of.format(needed=format_eng(c.slew_needed_v_per_s, "V/s", 3),
                               available=format_eng(c.slew_v_per_s, "V/s", 3)),
                     _("ok") if c.ok else _("FAILED")])
    return [R.text(_("Each stage against the {opamp} at {amp} peak in: GBW needed = {margin} x fn x Q x noise gain; "
                     "the output's peak (the cascade up to it, at its worst frequency) within the swing {swing}; the "
                     "slew a sine of that peak needs at fn, 2 pi fn Vpk.").format(
                         opamp=op.name, amp=format_eng(data.bench.amplitude_v, "V"), margin=f"{r.spec.gbw_margin:g}",
                         swing=format_eng(data.bench.checks[0].swing_v, "V"))),
            R.table([_("stage"), _("section"), "fn", "Q", _("gain"), _("peak gain"), _("output peak"),
                     _("GBW needed"), _("slew needed"), _("check")], rows)]


def _tables(data: FilterSheet) -> list:
    r, bench = data.design, data.bench
    s, f = r.spec, r.figures
    rows = []
    for t in bench.tables:
        rows.append([t.stage, "" if t.table_fn_ratio is None else f"{t.table_fn_ratio:.4f}",
                     "" if t.table_q is None else f"{t.table_q:.4f}", "" if t.table_k is None else f"{t.table_k:.3f}",
                     "" if t.design_fn_ratio is None else f"{t.design_fn_ratio:.4f}",
                     format_eng(t.fn_hz, "Hz", 5), "" if t.q is None else f"{t.q:.4f}",
                     format_eng(t.fn_design_hz, "Hz", 5), "" if t.q_design is None else f"{t.q_design:.4f}",
                     format_eng(t.fn_built_hz, "Hz", 5), "" if t.q_built is None else f"{t.q_built:.4f}"])
    text = []
    if s.filter_type == "bandpass":
        text.append(_("A band-pass has no row in the low-pass tables: its sections come from the prototype "
                      "transformed (or a high-pass and a low-pass cascade)."))
    elif abs(bench.table_corner - 1) > 1e-9:
        edge = _("ripple edge") if s.chebyshev_cutoff == "ripple" else _("-3 dB point below the ripple top")
        text.append(_("The tables (TI SLOA088, section 16.9) put the corner fC 3 dB below the DC gain; this design's "
                      "fc is the {edge}: fC = {ratio} x the ripple edge, so the table's fn/fC differ from this "
                      "design's fn/fc by that factor; Q is the same.").format(edge=edge,
                                                                              ratio=f"{bench.table_corner:.4f}"))
    else:
        text.append(_("The tables (TI SLOA088, section 16.9) and this design share the corner: fn/fc and Q agree "
                      "with the table's; k = fCi/fC is each section's own -3 dB point, not its fn."))
    if s.filter_type == "highpass":
        text.append(_("A high-pass uses the low-pass table with each fn mirrored about fc: fn = fc / (table fn/fC)."))
    if s.compensate_gbw:
        text.append(_("--compensate-gbw: each stage's parts are synthesised for a pre-distorted fn and Q (the "
                      "'synthesised for' columns) so that with the op-amp's finite GBW it gives the table's."))
    text.append(_("The parts are E-series values chosen jointly across the stages against the whole response: the "
                  "worst deviation from the ideal is {joint} dB, against {per_stage} dB when each stage is rounded on "
                  "its own and {nearest} dB with every part at its nearest value; so a stage's built fn and Q may sit "
                  "further from its target than rounding would put them, when that makes the whole response "
                  "closer.").format(joint=f"{f['error_joint_db']:.3g}", per_stage=f"{f['error_per_stage_db']:.3g}",
                                    nearest=f"{f['error_nearest_db']:.3g}"))
    if "delay_error_per_stage_pct" in f:
        text.append(_("The group-delay target is part of the joint choice: the delay departs {joint} % from its DC "
                      "value (at most {target} % asked), against {per_stage} % when each stage is rounded on its own "
                      "and {nearest} % with every part at its nearest value (a set that meets the target wins over one that "
                      "does not, whatever their deviations).").format(
            joint=f"{f['delay_error_pct']:.3g}", target=f"{s.max_delay_error_pct:g}",
            per_stage=f"{f['delay_error_per_stage_pct']:.3g}", nearest=f"{f['delay_error_nearest_pct']:.3g}"))
    return [R.table([_("stage"), _("table fn/fC"), _("table Q"), _("table k"), _("design fn/fc"), "fn", "Q",
                     _("synthesised for fn"), _("and Q"), _("built fn"), _("built Q")], rows, "compact"),
            *[R.text(t) for t in text]]


def _achieved(r) -> list:
    f, s = r.figures, r.spec
    f3 = f["f3_hz"]
    f3t = f["f3_target_hz"]
    show = lambda v: _("{a} and {b}").format(a=format_eng(v[0], "Hz", 5), b=format_eng(v[1], "Hz", 5)) \
        if isinstance(v, (list, tuple)) else format_eng(v, "Hz", 5)  # noqa: E731
    rows = [[_("-3 dB frequency"), show(f3t), show(f3)],
            [_("max passband deviation from the ideal"), "0 dB", f"{f['passband_deviation_db']:.3g} dB"]]
    if s.has_mask:
        where_pass, where_stop = s.mask_phrases()
        rows += [[_("mask: passband margin"), _(">= 0 (loss <= {loss} dB {where})").format(
                     loss=f"{s.max_loss_db:g}", where=where_pass), f"{f['mask_passband_margin_db']:.3g} dB"],
                 [_("mask: stopband margin"), _(">= 0 (>= {att} dB {where})").format(
                     att=f"{s.min_attenuation_db:g}", where=where_stop), f"{f['mask_stopband_margin_db']:.3g} dB"]]
    rows += _delay_rows(r)
    out = [R.table([_("figure"), _("target"), _("chosen parts, {opamp} model").format(opamp=r.opamp.name)], rows)]
    if r.spice:
        sp = r.spice
        out.append(R.text(_("SPICE (.ac, {simulator}) against the analytic response of these parts: max deviation "
                            "{passband} dB in the passband, {down60} dB down to -60 dB.").format(
                                simulator=sp["simulator"], passband=f"{sp['max_deviation_passband_db']:.2g}",
                                down60=f"{sp['max_deviation_60db_db']:.2g}")))
    return out


def sections(data: FilterSheet, with_images: bool = True, schematic_svg: str = "") -> list:
    """The build sheet as (heading, blocks) sections (:mod:`designer.report.document`), in the current
    language (:mod:`designer.core.i18n`).

    Parameters
    ----------
    data : FilterSheet
        The design and its bench.
    with_images : bool
        Include the schematic and plots (False: the terminal text).
    schematic_svg : str
        The schematic inlined in the HTML.

    Returns
    -------
    list
        (heading, blocks) pairs.
    """
    r = data.design
    b = build_board(r)
    op = r.opamp
    labels = {net: net_label(net) for net in {p.a for p in b.netlist.parts} | {p.b for p in b.netlist.parts}
              | {a.out for a in b.netlist.amps}}
    first = [R.subhead(_("Bill of materials")),
             R.table([_("Ref"), _("Value"), _("Code"), _("Qty"), _("Series"), _("Tol."), _("Package")],
                     # the package by its name in the sheet's language (designer.report.wiring.CATALOGUE_WORDS)
                     [[*x[:6], _(x[6])] for x in bom(r, b)], "compact"),
             R.text(_("Supplies {vcc} V and {vee} V. Set the generator's output to High-Z.").format(
                 vcc=f"{op.vcc:+g}", vee=f"{op.vee:+g}"))]
    # the cascade is wider than the plant: its schematic takes the page's width, the parts list follows
    fig = [(_("Schematic"), [R.figure("schematic.png", schematic_svg, _("the cascade's schematic, stage by stage"))])] \
        if with_images else []
    out = [*fig, (_("Build"), first),
           (_("Stages and their op-amp checks"), _stages(data)),
           (_("Wiring"), [R.text(_("Nets by name: a label on the schematic is that net; S1, S2 .. are the stages' "
                                   "outputs, each the next stage's input.")),
                          R.table([_("part"), _("code"), _("from"), _("to")],
                                  wiring_rows(b, labels, (op.vcc, op.vee)))]),
           (_("Bench test: sine sweep"), _sweep(data)),
           (_("Bench test: step") if data.bench.time_test.kind == "step" else _("Bench test: tone burst"),
            _time_test(data)),
           (_("Target and achieved"), _achieved(r)),
           (_("Why the values differ from a table's"), _tables(data))]
    if data.alternatives:
        out.append((_("Alternatives (best first)"), _alternatives(data)))
    if with_images:
        imgs = [R.image("bode.png", _("Bode plot with the mask and the sweep's points")),
                R.image("time-test.png", _("the step or burst test"))]
        if data.bench.group_delay is not None:
            imgs.append(R.image("group-delay.png", _("group delay")))
            imgs += [R.text(_("Group-delay target: {what}, {target}; achieved {got}.").format(
                what=row[0], target=row[1], got=row[2])) for row in _delay_rows(r)]
        out.append((_("Plots"), [R.columns(imgs[:2]), *imgs[2:]]))
    return out


def bode_png(data: FilterSheet) -> bytes:
    """Gain (the builds' band shaded, the mask drawn, the sweep's points) and phase.

    Parameters
    ----------
    data : FilterSheet
        The sheet.

    Returns
    -------
    bytes
        PNG.
    """
    r, bench = data.design, data.bench
    s = r.spec
    f, h = bench.f_hz, bench.h
    fig, (a1, a2) = figure(7.5, 4.8, 2, 1, sharex=True)
    a1.fill_between(f, bench.h_lo_db, bench.h_hi_db, color="#f4c27a", alpha=0.5, lw=0,
                    label=_("{n} builds (R {r} %, C {c} %)").format(n=bench.builds, r=f"{bench.r_tol_pct:g}",
                                                                     c=f"{bench.c_tol_pct:g}"))
    a1.plot(f, 20 * np.log10(np.abs(h)), "-", lw=1.6, label=_("chosen parts, {opamp} model").format(opamp=r.opamp.name))
    a1.plot([p.f_hz for p in bench.sweep], [p.gain_db for p in bench.sweep], "o", ms=3.5, mfc="none",
            color="C3", label=_("sweep points"))
    ref = 20 * math.log10(s.gain)
    # down to 30 dB below the mask's stopband (80 dB without a mask), or the response's floor if higher
    lo_db = max(float(np.min(20 * np.log10(np.abs(h)))), ref - (s.min_attenuation_db + 30 if s.has_mask else 80))
    if s.has_mask:
        # the forbidden regions: more loss than allowed in the passband, less attenuation in the stopband
        if s.filter_type == "bandpass":
            pbs, sbs = [s.passband_edges], [(f[0], s.stopband_edges[0]), (s.stopband_edges[1], f[-1])]
        elif s.filter_type == "lowpass":
            pbs, sbs = [(f[0], s.passband_hz)], [(s.stopband_hz, f[-1])]
        else:
            pbs, sbs = [(s.passband_hz, f[-1])], [(f[0], s.stopband_hz)]
        for i, pb in enumerate(pbs):
            a1.fill_between(pb, [lo_db] * 2, [ref - s.max_loss_db] * 2, color="#d33", alpha=0.15, lw=0,
                            label=None if i else _("mask"))
        for sb in sbs:
            a1.fill_between(sb, [ref - s.min_attenuation_db] * 2, [ref + 10] * 2, color="#d33", alpha=0.15, lw=0)
    a1.axhline(ref - 10 * math.log10(2), color="0.5", lw=0.6, ls=":")
    a1.set_ylim(lo_db, ref + 6)
    a2.plot(f, np.degrees(np.unwrap(np.angle(h))), "-", lw=1.4)
    log_frequency_axis(a2)
    a1.set_ylabel(_("gain (dB)"))
    a2.set_ylabel(_("phase (deg)"))
    a2.set_xlabel(_("frequency (Hz)"))
    a1.set_title(title_of(r), fontsize=10)
    for a in (a1, a2):
        a.grid(True, which="both", alpha=0.3)
    a1.legend(fontsize=7.5, loc="lower right" if s.filter_type == "highpass" else "lower left")
    return png_bytes(fig, dpi=100, tight=False)


def time_png(data: FilterSheet) -> bytes:
    """The step or burst: generator and output.

    Parameters
    ----------
    data : FilterSheet
        The sheet.

    Returns
    -------
    bytes
        PNG.
    """
    tt = data.bench.time_test
    title = (N_("Step response") if tt.kind == "step"
             else _("Tone burst at {f}").format(f=format_eng(tt.frequency_hz, 'Hz')))
    return step_plot(tt.t_s, {N_("output (chosen parts)"): tt.output_v, N_("generator (CH1)"): tt.input_v}, title,
                     ylabel=N_("voltage (V)"),
                     xlabel=N_("time from the step") if tt.kind == "step" else N_("time from the burst's start"))


def _delay_rows(r) -> list:
    """The group-delay target's row (none without one): the parts' largest departure from the DC delay."""
    s, f = r.spec, r.figures
    if not s.has_delay_target:
        return []
    return [[_("group delay from DC to {f}").format(f=format_eng(s.delay_to_hz, "Hz")),
             _("within {pct} % of DC's (ideal Bessel {ideal} %)").format(
                 pct=f"{s.max_delay_error_pct:g}", ideal=f"{f['delay_error_ideal_pct']:.3g}"),
             _("{pct} % of {delay}").format(pct=f"{f['delay_error_pct']:.3g}", delay=format_eng(f["delay_dc_s"], "s"))
             + ("" if f["delay_target_met"] else _(" (NOT met)"))]]


def group_delay_png(data: FilterSheet) -> bytes:
    """The group delay of the chosen parts with the op-amp's model.

    Parameters
    ----------
    data : FilterSheet
        The sheet.

    Returns
    -------
    bytes
        PNG.
    """
    f, tau = data.bench.group_delay
    fig, ax = figure(7.5, 3.2)
    ax.plot(f, np.asarray(tau) * 1e6, "-", lw=1.6, label=_("chosen parts"))
    s, figs = data.design.spec, data.design.figures
    if s.has_delay_target:
        # the target: the DC delay +- the allowed error, up to its frequency
        d0, e = figs["delay_dc_s"] * 1e6, s.max_delay_error_pct / 100
        ax.fill_between([f[0], s.delay_to_hz], [d0 * (1 - e)] * 2, [d0 * (1 + e)] * 2, color="tab:green", alpha=0.2, lw=0,
                        label=_("target: within {pct} % to {f} (parts: {got} %)").format(
                            pct=f"{s.max_delay_error_pct:g}", f=format_eng(s.delay_to_hz, 'Hz'),
                            got=f"{figs['delay_error_pct']:.3g}"))
        ax.axvline(s.delay_to_hz, color="tab:green", lw=0.8, ls=":")
        ax.legend(fontsize=8, loc="lower left")
    log_frequency_axis(ax)
    ax.set_xlabel(_("frequency (Hz)"))
    ax.set_ylabel(_("group delay (us)"))
    ax.set_title(_("Group delay (flat in the passband: a Bessel's purpose)"), fontsize=10)
    ax.grid(True, which="both", alpha=0.3)
    return png_bytes(fig, dpi=100, tight=False)


def plots(data: FilterSheet) -> tuple:
    """The sheet's plots: (file name, drawing function) pairs.

    Parameters
    ----------
    data : FilterSheet
        The sheet.

    Returns
    -------
    tuple
        ``bode.png``, ``time-test.png`` and, for a Bessel, ``group-delay.png``.
    """
    out = (("bode.png", bode_png), ("time-test.png", time_png))
    return out + ((("group-delay.png", group_delay_png),) if data.bench.group_delay is not None else ())


def _texts() -> dict:
    return {"bom_csv": ("bom.csv", lambda d: bom_csv(bom(d.design)))}


def write_outputs(data: FilterSheet, out_dir, name: str, lang: str | None = None) -> dict:
    """The bundle: ``reports/<name>/`` (build sheets, result.json, plots, bom.csv, the deck) and
    ``netlists/<name>.cir`` under ``out_dir`` (:func:`designer.report.bundle.write_design`).

    Parameters
    ----------
    data : FilterSheet
        The sheet.
    out_dir : str or Path
        Where ``reports/`` and ``netlists/`` go.
    name : str
        The design's name.
    lang : str or None
        The sheet's language (:mod:`designer.core.i18n`; None: the current one).

    Returns
    -------
    dict
        The files written.
    """
    from ..core.i18n import language
    from ..report.bundle import write_design
    data.wall_clock = False
    with language(lang):
        return write_design(data, out_dir, name, plots(data), schematic,
                            lambda svg: sections(data, schematic_svg=svg), title_of(data.design), _texts())


def write_folder(data: FilterSheet, folder, lang: str | None = None) -> dict:
    """A ``--out`` folder: ``filter.cir`` (the deck), ``result.json`` and the sheet's files
    (:data:`SHEET_FILES`, ``group-delay.png`` for a Bessel), all made in a staging folder beside it and then
    moved in (each by an atomic rename), so that a failure leaves the folder as it was.

    Parameters
    ----------
    data : FilterSheet
        The sheet.
    folder : str or Path
        The folder (created if missing; other files in it are left alone).
    lang : str or None
        The sheet's language (:mod:`designer.core.i18n`; None: the current one).

    Returns
    -------
    dict
        Key -> path of every file written.
    """
    import json
    import os
    from pathlib import Path

    from ..core import fileio
    from ..report.bundle import schematic_pictures
    from ..report.document import to_html, to_markdown
    folder = fileio.ensure_dir(Path(folder))
    names = {"deck": "filter.cir", "result_json": "result.json", "build_sheet_md": "build-sheet.md",
             "build_sheet_html": "build-sheet.html", "bom_csv": "bom.csv", "schematic": "schematic.png"}
    pics = dict((n, draw(data)) for n, draw in plots(data))
    names.update({n.replace(".png", "").replace("-", "_"): n for n in pics})
    data.files = {k: str(folder / v) for k, v in names.items()}
    from ..core.i18n import language
    svg, png = schematic_pictures(schematic, data)
    with language(lang):
        secs = sections(data, schematic_svg=svg)
        title = title_of(data.design)
        images = {**pics, "schematic.png": png}
        contents = {"filter.cir": data.deck, "result.json": json.dumps(data.to_dict(), indent=2) + "\n",
                    "build-sheet.md": to_markdown(title, secs), "build-sheet.html": to_html(title, secs, images),
                    "bom.csv": bom_csv(bom(data.design)), **images}
    fileio.clean_stale(folder.parent)
    stage = fileio.new_folder_beside(folder)
    try:
        try:
            for fname, d in contents.items():
                (stage / fname).write_bytes(d if isinstance(d, bytes) else d.encode("utf-8"))
            for fname in contents:
                os.replace(stage / fname, folder / fname)
        except OSError as exc:
            raise fileio.os_error("write", folder, exc) from None
    finally:
        fileio.remove_tree(stage)
    return dict(data.files)
