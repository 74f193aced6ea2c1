"""A design's files as one bundle: ``reports/<name>/`` (build sheets, result.json,
plots, the deck) and ``netlists/<name>.cir``, written so that they are never
half-written nor mixed with an older bundle (see :mod:`designer.core.fileio`)."""

from __future__ import annotations

import json

from .document import to_html, to_markdown

__all__ = ["draw_early", "schematic_pictures", "write_design"]


def bundle_paths(out_dir, name: str, images, extra: dict = None) -> dict:
    """Name every file of a design's bundle under ``out_dir``: ``reports/<name>/``
    (build sheets, result.json, plots, the deck as ``<name>.cir``, and ``extra``:
    key -> file name in the report folder) and ``netlists/<name>.cir``, a link to
    that deck. Creates ``netlists/`` and ``reports/`` only."""
    from pathlib import Path

    from ..core.fileio import check_can_create, ensure_dir
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

    from ..core import fileio
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


def schematic_pictures(schematic, result) -> tuple:
    """``schematic(result)`` (a wing's drawing of the design) as (SVG text, PNG bytes).

    Parameters
    ----------
    schematic : callable
        ``schematic(result)``: the wing's drawing of the design.
    result
        The design's typed result.

    Returns
    -------
    tuple
        (SVG text, PNG bytes).
    """
    sheet = schematic(result)
    return sheet.svg(), sheet.png()


class Early:
    """A design's pictures that do not depend on its SPICE run (the schematic and
    ``names``), sent to the renderer before that run (:func:`draw_early`), so that
    they are drawn on the other core while ngspice runs on this one."""

    def __init__(self, plots, schematic, result, names):
        from . import render
        self.names = tuple(n for n, _ in plots if n in names)
        draws = dict(plots)
        # the result is pickled now, before the SPICE run fills it: these pictures read none of that
        self.drawing = render.submit_many([(schematic_pictures, (schematic, result)),
                                           *((draws[n], (result,)) for n in self.names)])


def draw_early(result, plots, schematic, names) -> Early:
    """Start drawing the schematic and the ``names`` among ``plots`` (those that read
    nothing of the SPICE run); :func:`write_design` takes the :class:`Early` and
    draws the rest. The pictures are the same as when drawn after the run.

    Parameters
    ----------
    result
        The design's typed result.
    plots : list of tuple
        ``(file name, draw(result) -> PNG)`` pairs.
    schematic : callable
        ``schematic(result)``: the wing's drawing of the design.
    names : iterable of str
        The file names among ``plots`` drawn now.

    Returns
    -------
    Early
        The pictures started.
    """
    return Early(plots, schematic, result, names)


def write_design(result, out_dir, name: str, plots, schematic, sections, title: str, texts: dict = None,
                 early: Early = None) -> dict:
    """A design's whole bundle under ``out_dir`` (:func:`bundle_paths`, :func:`write_bundle`).

    The pictures (``plots``: ``(file name, draw(result) -> PNG)`` pairs, and the
    schematic, ``schematic(result)`` a drawing, as :func:`schematic_pictures`) are
    drawn in the renderer when one is started (:mod:`.render`), side by side, while
    the data files are made here; those started by :func:`draw_early` (``early``)
    are not drawn again. ``sections(svg)`` gives the sheet with the
    schematic inlined; ``texts``: key -> (file name, text(result)). ``result.files``
    is set before result.json is written, so it lists itself; it is returned, and
    ``result.timings["report_s"]`` set.

    Parameters
    ----------
    result
        The design's typed result (its ``files`` and ``timings`` are set).
    out_dir : path-like
        The folder the bundle goes under.
    name : str
        The design's name (the bundle's file names).
    plots : list of tuple
        ``(file name, draw(result) -> PNG)`` pairs.
    schematic : callable
        ``schematic(result)``: the wing's drawing of the design.
    sections : callable
        ``sections(svg)``: the sheet's sections with the schematic inlined.
    title : str
        The sheet's title.
    texts : dict, optional
        Key -> (file name, text(result)): more files of the bundle.
    early : Early, optional
        The pictures :func:`draw_early` started.

    Returns
    -------
    dict
        The bundle's files (``result.files``).
    """
    import time

    from . import render
    tick = time.perf_counter()
    done = early.names if early is not None else ()
    late = [(n, draw) for n, draw in plots if n not in done]
    calls = [(draw, (result,)) for _, draw in late]
    if early is None:
        calls.insert(0, (schematic_pictures, (schematic, result)))
    drawing = render.submit_many(calls)
    names = [n for n, _ in plots]
    texts = texts or {}
    result.files = bundle_paths(out_dir, name, [*names, "schematic.png"], {k: f for k, (f, _) in texts.items()})
    extras = {k: text(result) for k, (_, text) in texts.items()}
    data = result.to_dict()
    drawn = drawing.result()
    if early is None:
        (svg, png), *drawn = drawn
    else:
        (svg, png), *first = early.drawing.result()
        drawn = first + drawn
    pngs = dict(zip([*done, *(n for n, _ in late)], drawn))
    images = {**{n: pngs[n] for n in names}, "schematic.png": png}
    write_bundle(result.files, result.deck, images, title, sections(svg), data, extras)
    result.timings["report_s"] = time.perf_counter() - tick
    return result.files
