"""Build sheets: one description of the content (sections of tables, text,
images, schematics and side-by-side columns) rendered to Markdown,
self-contained printable HTML and terminal text, so the three never disagree.

The HTML prints: an ``@page`` rule whose margins suit A4 and Letter alike,
table headers repeated on every page, no row split across pages, numbers that
never wrap, and two-column figure rows; on screen the first section lays the
schematic beside the bill of materials and the bench settings, so that a
1280x800 window shows all three without scrolling.
"""

from __future__ import annotations

import base64
import html
import math

from ..core.i18n import current, localise
from ..core.i18n import gettext as _
from ..core.units import format_eng, value_code

__all__ = ["columns", "figure", "fmt_pct", "fmt_time", "image", "subhead", "table", "text", "to_html", "to_text"]

# ---- content blocks ---------------------------------------------------------

def table(header, rows, cls: str = ""):
    """A table; ``cls`` is an HTML class (``compact`` for the narrow first-page tables).

    Parameters
    ----------
    header : list of str
        The column headings.
    rows : list of list
        The rows' cells.
    cls : str
        The HTML class.

    Returns
    -------
    tuple
        The block.
    """
    return ("table", list(header), [list(r) for r in rows], cls)


def text(s):
    """A paragraph block.

    Parameters
    ----------
    s : str
        The paragraph.

    Returns
    -------
    tuple
        The block.
    """
    return ("text", s)


def image(name, alt):
    """A picture block: the PNG ``name`` (embedded in the HTML, beside the Markdown).

    Parameters
    ----------
    name : str
        The PNG's file name in the bundle.
    alt : str
        Its alternative text.

    Returns
    -------
    tuple
        The block.
    """
    return ("image", name, alt)


def figure(name, svg, alt):
    """A schematic: inline SVG in the HTML, the PNG ``name`` beside the Markdown.

    Parameters
    ----------
    name : str
        The PNG's file name in the bundle.
    svg : str
        The schematic's SVG text.
    alt : str
        Its alternative text.

    Returns
    -------
    tuple
        The block.
    """
    return ("figure", name, svg, alt)


def columns(*cols):
    """Blocks side by side (each argument a list of blocks); one after the other in Markdown and text.

    Parameters
    ----------
    *cols : list
        Each a list of blocks.

    Returns
    -------
    tuple
        The block.
    """
    return ("columns", [list(c) for c in cols])


def subhead(s):
    """A subheading block.

    Parameters
    ----------
    s : str
        The subheading.

    Returns
    -------
    tuple
        The block.
    """
    return ("subhead", s)


def fmt_pct(v, digits=3):
    """A signed percentage to ``digits`` significant digits (``+1.5 %``), ``n/a`` for None or NaN.

    Parameters
    ----------
    v : float or None
        The percentage.
    digits : int
        Significant digits.

    Returns
    -------
    str
        The text.
    """
    return _("n/a") if v is None or (isinstance(v, float) and math.isnan(v)) else f"{v:+.{digits}g} %"


def fmt_time(v):
    """A time in engineering notation (``43.2 us``), ``n/a`` for None.

    Parameters
    ----------
    v : float or None
        The time (s).

    Returns
    -------
    str
        The text.
    """
    return _("n/a") if v is None else format_eng(v, "s")


def _localised(title, sections):
    """The title and sections with their numbers and units as the current language writes them
    (:func:`designer.core.i18n.localise`); as given in English, so an English sheet is unchanged."""
    if current() == "en":
        return title, sections
    return localise(title), [(localise(h), _localised_blocks(blocks)) for h, blocks in sections]


def _localised_blocks(blocks):
    out = []
    for b in blocks:
        if b[0] in ("text", "subhead"):
            out.append((b[0], localise(b[1])))
        elif b[0] == "table":
            out.append(("table", [localise(h) for h in b[1]], [[localise(c) for c in r] for r in b[2]], *b[3:]))
        elif b[0] == "image":
            out.append(("image", b[1], localise(b[2])))
        elif b[0] == "figure":
            out.append(("figure", b[1], b[2], localise(b[3])))
        elif b[0] == "columns":
            out.append(("columns", [_localised_blocks(c) for c in b[1]]))
        else:
            out.append(b)
    return out


def _flat(blocks):
    for b in blocks:
        if b[0] == "columns":
            for col in b[1]:
                yield from _flat(col)
        else:
            yield b


# ---- renderers --------------------------------------------------------------

def to_markdown(title, sections) -> str:
    title, sections = _localised(title, sections)
    out = [f"# {title}", ""]
    for heading, blocks in sections:
        out += [f"## {heading}", ""]
        for b in _flat(blocks):
            if b[0] == "text":
                out += [b[1], ""]
            elif b[0] == "subhead":
                out += [f"### {b[1]}", ""]
            elif b[0] == "table":
                out.append("| " + " | ".join(b[1]) + " |")
                out.append("|" + "---|" * len(b[1]))
                out += ["| " + " | ".join(str(c) for c in r) + " |" for r in b[2]]
                out.append("")
            elif b[0] in ("image", "figure"):
                alt = b[2] if b[0] == "image" else b[3]
                out += [f"![{alt}]({b[1]})", ""]
    return "\n".join(out).rstrip() + "\n"


_CSS = """body{font-family:system-ui,Segoe UI,Helvetica,Arial,sans-serif;max-width:84rem;margin:.6rem auto;
padding:0 .8rem;color:#111;font-size:14px;line-height:1.3}h1{font-size:1.25rem;margin:.2rem 0 .3rem}
h2{font-size:1.05rem;border-bottom:1px solid #ccc;margin:.9rem 0 .3rem;break-after:avoid}
h3{font-size:.95rem;margin:.4rem 0 .2rem;break-after:avoid}p{margin:.25rem 0}
table{border-collapse:collapse;margin:.3rem 0}td,th{border:1px solid #bbb;padding:.12rem .4rem;text-align:left;
vertical-align:top;white-space:nowrap}td.w{white-space:normal;min-width:12rem}th{background:#f0f0f0}
thead{display:table-header-group}tr{break-inside:avoid}table.compact{font-size:12.5px}
.cols{display:grid;grid-template-columns:repeat(var(--n),minmax(0,1fr));gap:.4rem 1rem;align-items:start}
.cols>div{min-width:0}.fig svg{width:100%;height:auto;max-height:30rem}img{max-width:100%}
.plots{display:grid;grid-template-columns:1fr 1fr;gap:.5rem}.plots img{width:100%}
@page{margin:11mm 10mm}
@media print{body{margin:0;max-width:none;padding:0;font-size:9pt}table{font-size:8pt}table.compact{font-size:7.6pt}
h1{font-size:12.5pt}h2{font-size:10.5pt;margin-top:.5rem}img,.fig{break-inside:avoid}.fig svg{max-height:125mm}
.plots img{break-inside:avoid}}"""


def _cell(c) -> str:
    s = html.escape(str(c))
    # a number never wraps; prose longer than a few words may
    return f"<td class='w'>{s}</td>" if len(str(c)) > 34 and " " in str(c) else f"<td>{s}</td>"


def _html_blocks(blocks, images, out):
    e = html.escape
    for b in blocks:
        if b[0] == "text":
            out.append(f"<p>{e(b[1])}</p>")
        elif b[0] == "subhead":
            out.append(f"<h3>{e(b[1])}</h3>")
        elif b[0] == "table":
            cls = f" class='{b[3]}'" if len(b) > 3 and b[3] else ""
            out.append(f"<table{cls}><thead><tr>" + "".join(f"<th>{e(h)}</th>" for h in b[1]) + "</tr></thead><tbody>")
            out += ["<tr>" + "".join(_cell(c) for c in r) + "</tr>" for r in b[2]]
            out.append("</tbody></table>")
        elif b[0] == "image" and b[1] in images:
            data = base64.b64encode(images[b[1]]).decode()
            out.append(f"<img alt='{e(b[2])}' src='data:image/png;base64,{data}'>")
        elif b[0] == "figure":
            svg = b[2]
            svg = svg[svg.find("<svg"):] if "<svg" in svg else svg
            out.append(f"<div class='fig' role='img' aria-label='{e(b[3])}'>{svg}</div>")
        elif b[0] == "columns":
            plots = all(x[0] == "image" for col in b[1] for x in col)
            if plots:
                out.append("<div class='plots'>")
                for col in b[1]:
                    _html_blocks(col, images, out)
                out.append("</div>")
                continue
            out.append(f"<div class='cols' style='--n:{len(b[1])}'>")
            for col in b[1]:
                out.append("<div>")
                _html_blocks(col, images, out)
                out.append("</div>")
            out.append("</div>")


def to_html(title, sections, images: dict) -> str:
    """Self-contained HTML: images embedded as data URIs, schematics as inline SVG.

    Parameters
    ----------
    title : str
        The document's title.
    sections : list
        (heading, blocks) pairs.
    images : dict
        PNG file name -> bytes.

    Returns
    -------
    str
        The HTML document.
    """
    e = html.escape
    title, sections = _localised(title, sections)
    out = [f"<!DOCTYPE html><html lang='{current()}'><head><meta charset='utf-8'><title>{e(title)}</title>",
           f"<style>{_CSS}</style></head><body>", f"<h1>{e(title)}</h1>"]
    for heading, blocks in sections:
        if heading:
            out.append(f"<h2>{e(heading)}</h2>")
        _html_blocks(blocks, images, out)
    out.append("</body></html>")
    return "\n".join(out) + "\n"


def to_text(title, sections) -> str:
    """Plain terminal rendering (tables aligned, images and schematics listed by name).

    Parameters
    ----------
    title : str
        The document's title.
    sections : list
        (heading, blocks) pairs.

    Returns
    -------
    str
        The text.
    """
    title, sections = _localised(title, sections)
    out = [title, "=" * len(title)]
    for heading, blocks in sections:
        if heading:
            out += ["", heading, "-" * len(heading)]
        for b in _flat(blocks):
            if b[0] == "text":
                out.append(b[1])
            elif b[0] == "subhead":
                out += [b[1] + ":"]
            elif b[0] == "table":
                rows = [b[1]] + [[str(c) for c in r] for r in b[2]]
                widths = [max(len(r[i]) for r in rows) for i in range(len(b[1]))]
                for j, r in enumerate(rows):
                    out.append("  ".join(c.ljust(w) for c, w in zip(r, widths)).rstrip())
                    if j == 0:
                        out.append("  ".join("-" * w for w in widths))
            elif b[0] == "image":
                out.append(_("[plot: {name}]").format(name=b[1]))
            elif b[0] == "figure":
                out.append(_("[schematic: {name}]").format(name=b[1]))
    return "\n".join(out) + "\n"


def part_row(ref, value, unit, role, series=None, tol_pct=None):
    return [ref, format_eng(value, unit, 4), value_code(value), series or "",
            "" if tol_pct is None else f"{tol_pct:g} %", role]
