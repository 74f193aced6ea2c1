"""Build sheets: one description of the content (sections of tables, text
and images) rendered to Markdown, self-contained printable HTML and terminal
text, so the three never disagree."""

from __future__ import annotations

import base64
import html
import math

from ..core.units import format_eng, value_code

# ---- content blocks ---------------------------------------------------------

def table(header, rows):
    return ("table", list(header), [list(r) for r in rows])


def text(s):
    return ("text", s)


def image(name, alt):
    return ("image", name, alt)


def fmt_pct(v, digits=3):
    return "n/a" if v is None or (isinstance(v, float) and math.isnan(v)) else f"{v:+.{digits}g} %"


def fmt_time(v):
    return "n/a" if v is None else format_eng(v, "s")


# ---- renderers --------------------------------------------------------------

def to_markdown(title, sections) -> str:
    out = [f"# {title}", ""]
    for heading, blocks in sections:
        out += [f"## {heading}", ""]
        for b in blocks:
            if b[0] == "text":
                out += [b[1], ""]
            elif b[0] == "table":
                out.append("| " + " | ".join(b[1]) + " |")
                out.append("|" + "---|" * len(b[1]))
                out += ["| " + " | ".join(str(c) for c in r) + " |" for r in b[2]]
                out.append("")
            elif b[0] == "image":
                out += [f"![{b[2]}]({b[1]})", ""]
    return "\n".join(out).rstrip() + "\n"


_CSS = """body{font-family:system-ui,Segoe UI,Helvetica,Arial,sans-serif;max-width:60rem;margin:2rem auto;
padding:0 1rem;color:#111}h1{font-size:1.5rem}h2{font-size:1.15rem;border-bottom:1px solid #ccc;margin-top:1.6rem}
table{border-collapse:collapse;margin:.5rem 0}td,th{border:1px solid #bbb;padding:.25rem .6rem;text-align:left}
th{background:#f0f0f0}img{max-width:100%}@media print{body{margin:0}h2{page-break-after:avoid}
img,table{page-break-inside:avoid}}"""


def to_html(title, sections, images: dict) -> str:
    """Self-contained HTML: images are embedded as data URIs."""
    e = html.escape
    out = [f"<!DOCTYPE html><html lang='en'><head><meta charset='utf-8'><title>{e(title)}</title>",
           f"<style>{_CSS}</style></head><body>", f"<h1>{e(title)}</h1>"]
    for heading, blocks in sections:
        out.append(f"<h2>{e(heading)}</h2>")
        for b in blocks:
            if b[0] == "text":
                out.append(f"<p>{e(b[1])}</p>")
            elif b[0] == "table":
                out.append("<table><tr>" + "".join(f"<th>{e(h)}</th>" for h in b[1]) + "</tr>")
                out += ["<tr>" + "".join(f"<td>{e(str(c))}</td>" for c in r) + "</tr>" for r in b[2]]
                out.append("</table>")
            elif b[0] == "image" and b[1] in images:
                data = base64.b64encode(images[b[1]]).decode()
                out.append(f"<img alt='{e(b[2])}' src='data:image/png;base64,{data}'>")
    out.append("</body></html>")
    return "\n".join(out) + "\n"


def to_text(title, sections) -> str:
    """Plain terminal rendering (tables aligned, images listed by name)."""
    out = [title, "=" * len(title)]
    for heading, blocks in sections:
        out += ["", heading, "-" * len(heading)]
        for b in blocks:
            if b[0] == "text":
                out.append(b[1])
            elif b[0] == "table":
                rows = [b[1]] + [[str(c) for c in r] for r in b[2]]
                widths = [max(len(r[i]) for r in rows) for i in range(len(b[1]))]
                for j, r in enumerate(rows):
                    out.append("  ".join(c.ljust(w) for c, w in zip(r, widths)).rstrip())
                    if j == 0:
                        out.append("  ".join("-" * w for w in widths))
            elif b[0] == "image":
                out.append(f"[plot: {b[1]}]")
    return "\n".join(out) + "\n"


def part_row(ref, value, unit, role, series=None, tol_pct=None):
    return [ref, format_eng(value, unit, 4), value_code(value), series or "", 
            "" if tol_pct is None else f"{tol_pct:g} %", role]
