"""Tektronix exports: TDS/TBS (the six-column ``Record Length,...`` layout) and
MSO/DPO (``Model,...`` key/value lines, then ``TIME,CH1,...``).
"""

from __future__ import annotations

from .layout import split_cells, headed_table, is_number, Layout, not_this

__all__ = []


#: Tektronix MSO/DPO: ``Model,...`` key/value lines, then ``TIME,CH1,...``.
read_tektronix_mso = headed_table("tektronix-mso", lambda c: c == "time", "TIME,CH1,...")


def is_tds(lines) -> bool:
    c = split_cells(lines[0], ",")
    return (len(c) >= 5 and c[0].lower() == "record length" and is_number(c[3])
            and is_number(c[4]))


def read_tektronix_tds(lines, name, forced=False) -> Layout:
    """TDS/TBS: rows ``label,value,,time,value,``; the header block occupies
    cells 1-3 of the first rows, and a file of several channels repeats the
    six columns for each (the time of the first is used)."""
    if forced and not is_tds(lines):
        raise not_this(name, "tektronix-tds", 0, lines, "is not 'Record Length,<n>,,<time>,"
                        "<value>,' (the six-column TDS/TBS layout)")
    first = split_cells(lines[0], ",")
    blocks = [b for b in range(0, len(first), 6) if first[b].lower() == "record length"]
    names, cols = ["TIME"], [3]
    for b in blocks:
        meta = {}
        for line in lines[:40]:
            c = [x.strip() for x in line.split(",")]
            if len(c) > b + 1 and c[b]:
                meta[c[b].lower()] = c[b + 1]
        names.append(meta.get("source", f"CH{len(names)}") or f"CH{len(names)}")
        cols.append(b + 4)
    return Layout(names, "tektronix-tds", 0, ",", cols)
