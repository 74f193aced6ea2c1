"""Build sheets: one description of the content (sections of tables, text
and images) rendered to Markdown, self-contained printable HTML and terminal
text, so the three never disagree. Plots are matplotlib PNGs."""

from __future__ import annotations

import base64
import html
import io
import json
import math

import numpy as np

from .fileio import atomic_write
from .units import format_eng, value_code  # noqa: F401  (value_code is part of this module's API)


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


# ---- plots ------------------------------------------------------------------

def png_bytes(fig) -> bytes:
    """A matplotlib figure as PNG bytes (the figure is closed)."""
    buf = io.BytesIO()
    fig.savefig(buf, format="png", dpi=110, bbox_inches="tight")
    import matplotlib.pyplot as plt
    plt.close(fig)
    return buf.getvalue()


def step_plot(t, curves: dict, title: str, ylabel: str = "output (V)") -> bytes:
    """Overlaid step responses; ``curves`` maps a label to an array on ``t``."""
    import matplotlib
    matplotlib.use("Agg")
    import matplotlib.pyplot as plt
    fig, ax = plt.subplots(figsize=(7.5, 4))
    styles = ["-", "--", ":", "-."]
    for i, (label, y) in enumerate(curves.items()):
        if y is not None:
            ax.plot(np.asarray(t) * 1e6, y, styles[i % 4], label=label, lw=1.6 if i == 0 else 1.3)
    ax.set_xlabel("time after the step (us)")
    ax.set_ylabel(ylabel)
    ax.set_title(title)
    ax.grid(True, alpha=0.3)
    ax.legend()
    return png_bytes(fig)


def bode_plot(systems: dict, f_lo: float, f_hi: float, title: str) -> bytes:
    """Magnitude (dB) and phase (deg) of transfer functions ``{label: (num, den)}``."""
    import matplotlib
    matplotlib.use("Agg")
    import matplotlib.pyplot as plt
    from .models import freq_response
    f = np.logspace(np.log10(f_lo), np.log10(f_hi), 600)
    fig, (a1, a2) = plt.subplots(2, 1, figsize=(7.5, 5.5), sharex=True)
    for i, (label, (num, den)) in enumerate(systems.items()):
        h = freq_response(num, den, f)
        a1.semilogx(f, 20 * np.log10(np.abs(h)), ["-", "--", ":"][i % 3], label=label)
        a2.semilogx(f, np.degrees(np.unwrap(np.angle(h))), ["-", "--", ":"][i % 3], label=label)
    a1.set_ylabel("gain (dB)")
    a2.set_ylabel("phase (deg)")
    a2.set_xlabel("frequency (Hz)")
    a1.set_title(title)
    for a in (a1, a2):
        a.grid(True, which="both", alpha=0.3)
    a1.legend()
    return png_bytes(fig)


def json_safe(obj):
    """JSON-ready copy: numpy scalars to Python numbers, nan/inf to None."""
    if isinstance(obj, dict):
        return {k: json_safe(v) for k, v in obj.items()}
    if isinstance(obj, (list, tuple)):
        return [json_safe(v) for v in obj]
    if isinstance(obj, np.ndarray):
        return json_safe(obj.tolist())
    if isinstance(obj, np.bool_):
        return bool(obj)
    if isinstance(obj, (np.floating, np.integer)):
        obj = obj.item()
    if isinstance(obj, float) and not math.isfinite(obj):
        return None
    return obj


def bundle_paths(out_dir, name: str, images, extra: dict = None) -> dict:
    """Name every file of a design's bundle under ``out_dir``: ``reports/<name>/``
    (build sheets, result.json, plots, the deck as ``<name>.cir``, and ``extra``:
    key -> file name in the report folder) and ``netlists/<name>.cir``, a link to
    that deck. Creates ``netlists/`` and ``reports/`` only."""
    from pathlib import Path
    from .fileio import check_can_create, ensure_dir
    out_dir = Path(out_dir)
    check_can_create(out_dir, ("netlists", "reports"))   # both, before creating either
    net_dir = ensure_dir(out_dir / "netlists")
    rep_dir = ensure_dir(out_dir / "reports") / name
    files = {"netlist": str(net_dir / f"{name}.cir"),
             "build_sheet_md": str(rep_dir / "build-sheet.md"),
             "build_sheet_html": str(rep_dir / "build-sheet.html"),
             "result_json": str(rep_dir / "result.json")}
    files.update({k: str(rep_dir / v) for k, v in (extra or {}).items()})
    files["plots"] = [str(rep_dir / n) for n in images]
    return files


def write_bundle(files: dict, deck: str, images: dict, title: str, sections, result: dict,
                 texts: dict = None) -> None:
    """Write a bundle named by :func:`bundle_paths` so that it is never half-written
    nor mixed with an older one: everything goes into a staging folder beside the
    report folder, which is then swapped in atomically; the netlist path is a link
    to the deck inside it, so it switches in the same step (see :mod:`designer.fileio`).
    Stale temporaries of killed runs are cleaned first."""
    from pathlib import Path
    from . import fileio
    rep_dir = Path(files["result_json"]).parent
    net = Path(files["netlist"])
    for folder in (rep_dir.parent, net.parent):
        fileio.clean_stale(folder)
    stage = fileio.new_folder_beside(rep_dir)
    contents = {net.name: deck, **{Path(files[k]).name: v for k, v in (texts or {}).items()},
                **{Path(p).name: images[Path(p).name] for p in files["plots"]},
                "build-sheet.md": to_markdown(title, sections),
                "build-sheet.html": to_html(title, sections, images),
                "result.json": json.dumps(result, indent=2) + "\n"}
    try:
        try:
            for fname, data in contents.items():
                (stage / fname).write_bytes(data if isinstance(data, bytes) else data.encode("utf-8"))
        except OSError as exc:
            raise fileio.os_error("write the report bundle in", rep_dir.parent, exc) from None
        linked = fileio.link_into(net, rep_dir / net.name)
        fileio.publish_folder(stage, rep_dir)
    finally:
        fileio.remove_tree(stage)   # gone already when published; else a failed or interrupted write
    if not linked:  # no symbolic links on this file system: a copy, written atomically
        fileio.atomic_write(net, deck)


def part_row(ref, value, unit, role, series=None, tol_pct=None):
    return [ref, format_eng(value, unit, 4), value_code(value), series or "", 
            "" if tol_pct is None else f"{tol_pct:g} %", role]
