"""Golden waveforms: recorded once (``check-design --update-golden``), compared
on every run by the one waveform rule, :func:`designer.core.compare.nrms`
(xyce_verify's: the gold interpolated onto the test's time points,
trapezoidal weights, per-signal ``reltol`` and ``abstol``, a pass below 1).

The file is the ``waveforms.csv`` layout (``time_s`` then one column per
signal, CSV, ``identify`` reads it) under a header of ``# key: value``
comment lines recording what produced it: the tool's version, ngspice's, the
simulator backend, the spec and the corner. A file recorded by other versions
still compares; the difference is a warning (a JUnit property), not a failure.

A refusal that a recording would cure advises it as a :class:`~designer.core.i18n.Message` whose
``{update_golden}`` value (:func:`record_advice`) names :func:`designer.check.batch.check_specs`'s parameter: its
text is the command line's (``check-design --update-golden``), and a front end with its own words for the switch
reads the value by that key (the Check page: its field's label, :func:`designer.web.forms.page_text`).
"""

from __future__ import annotations

import io
import warnings

import numpy as np

from ..core.compare import nrms
from ..core.errors import DesignError
from ..core.fileio import MAX_TABLE_BYTES, atomic_write, read_text, shown
from ..core.i18n import N_, Message
from ..core.units import format_eng

__all__ = ["RECORD_GOLDEN", "compare", "read_golden", "record_advice", "write_golden"]

TITLE = "designer golden waveform"
#: the header's keys whose change since recording is worth a warning
VERSIONED = ("tool", "ngspice", "simulator")
#: check_specs' ``update_golden`` as the command line gives it (the ``{update_golden}`` value of the advice)
RECORD_GOLDEN = "check-design --update-golden"


def record_advice(problem: str, aside: bool = False, switch: str = RECORD_GOLDEN) -> Message:
    """``problem`` and the advice to record the golden file, the switch carried as the ``update_golden`` value
    (each front end names it its own way; the text is the command line's).

    Parameters
    ----------
    problem : str
        What is wrong with the golden file (one clause, naming it).
    aside : bool
        The advice in parentheses after ``problem`` (else after a semicolon).
    switch : str
        How the text names the switch (:data:`RECORD_GOLDEN`; ``--update-golden`` where the command is
        understood).

    Returns
    -------
    Message
        ``<problem>; record it with check-design --update-golden`` (or ``<problem> (record it with ...)``).
    """
    form = N_("{problem} (record it with {update_golden})") if aside else \
        N_("{problem}; record it with {update_golden}")
    return Message(form, problem=problem, update_golden=switch)


def header_of(tool: dict, spec: str, corner: str) -> dict:
    """The header a golden file records: ``tool`` is a :func:`~designer.spice.simulate.tool_info`."""
    return {"tool": f"{tool.get('name')} {tool.get('version')}", "ngspice": str(tool.get("ngspice")),
            "simulator": str(tool.get("simulator")), "spec": spec, "corner": corner or "-"}


def write_golden(path, t, signals: dict, header: dict) -> None:
    """Record ``signals`` (name -> samples on ``t``) at ``path``, atomically; a
    sample that is not a finite number is refused (the file could never compare).

    Parameters
    ----------
    path : path-like
        The golden file written.
    t : array_like
        The time points (s).
    signals : dict
        Signal name -> samples on ``t``.
    header : dict
        What the file's header records (the spec, the corner, the tool).
    """
    t = np.asarray(t, float)
    _finite(t, "the run's time", t, f" {shown(path)}")
    for sig, values in signals.items():
        _finite(np.asarray(values, float), f"the run's {sig}", t, f" {shown(path)}")
    buf = io.StringIO()
    buf.write(f"# {TITLE}\n" + "".join(f"# {k}: {v}\n" for k, v in header.items()))
    cols = np.column_stack([np.asarray(t, float)] + [np.asarray(v, float) for v in signals.values()])
    np.savetxt(buf, cols, delimiter=",", header=",".join(["time_s", *signals]), comments="", fmt="%.12g")
    atomic_write(path, buf.getvalue())


def read_golden(path) -> tuple:
    """(header dict, time, {signal: samples}) of a golden file; a file that is
    not one (no ``time_s,...`` line, fewer than 2 samples, a sample that is
    not a finite number, time not increasing) is refused in one line naming it
    (and the column and row of a bad sample).

    Parameters
    ----------
    path : path-like
        The golden file.

    Returns
    -------
    tuple
        (header dict, time array, {signal: samples}).
    """
    name = shown(path)
    text = read_text(path, "golden file", MAX_TABLE_BYTES * 4)
    header, body, lines = {}, [], []
    for n, ln in enumerate(text.splitlines(), 1):
        if ln.startswith("#"):
            key, sep, value = ln[1:].partition(":")
            if sep:
                header[key.strip()] = value.strip()
        elif ln.strip():
            body.append(ln)
            lines.append(n)
    if not body or not body[0].startswith("time_s,"):
        raise DesignError(record_advice(f"golden file {name} is not a golden waveform (a time_s,... header line, "
                                        "then samples)"))
    names = [c.strip() for c in body[0].split(",")]
    if len(body) < 3:   # loadtxt warns on no rows; one row is no waveform
        rows = f"{len(body) - 1} row{'' if len(body) == 2 else 's'}"
        raise DesignError(record_advice(f"golden file {name}: {rows} of samples; a golden waveform has at least 2",
                                        aside=True))
    try:
        with warnings.catch_warnings():
            warnings.simplefilter("error")   # whatever numpy would print is a refusal here
            data = np.loadtxt(body[1:], delimiter=",", ndmin=2)
    except (ValueError, Warning) as exc:
        raise DesignError(f"golden file {name}: unreadable samples ({' '.join(str(exc).split())})") from None
    if data.shape[1] != len(names):
        raise DesignError(f"golden file {name}: {data.shape[1]} columns of samples under the {len(names)} names of "
                          f"its header line; they must match")
    bad = ~np.isfinite(data)
    if bad.any():
        row, col = (int(i) for i in np.argwhere(bad)[0])
        raise DesignError(record_advice(f"golden file {name}:{lines[row + 1]}: {names[col]} is "
                                        f"{float(data[row, col])} in sample row {row + 1}; a golden waveform holds "
                                        "finite numbers only", aside=True))
    t = data[:, 0]
    if not np.all(np.diff(t) > 0):
        raise DesignError(f"golden file {name}: time_s must increase")
    return header, t, {n: data[:, i] for i, n in enumerate(names) if i}


def version_warnings(recorded: dict, now: dict, path) -> list:
    """What differs between the versions a golden file recorded and this run's."""
    diff = [f"{k} {recorded.get(k, '?')} -> {now[k]}" for k in VERSIONED if recorded.get(k) != now[k]]
    return [f"golden file {shown(path)} was recorded with other versions: " + ", ".join(diff)] if diff else []


def compare(t, test: dict, t_gold, gold: dict, tolerances: dict, path=None) -> dict:
    """signal -> its nrms against the gold (xyce_verify rule), for each signal of ``tolerances``
    (name -> (reltol, abstol)); the test's time points outside the gold's span are left out.

    Parameters
    ----------
    t : array_like
        The test run's time points (s).
    test : dict
        Signal -> the run's samples on ``t``.
    t_gold : array_like
        The gold's time points (s).
    gold : dict
        Signal -> the gold's samples on ``t_gold``.
    tolerances : dict
        Signal -> (reltol, abstol): the signals compared.
    path : path-like, optional
        The golden file, named in an error.

    Returns
    -------
    dict
        Signal -> its nrms against the gold.

    Raises
    ------
    DesignError
        One line naming the golden file (``path``): fewer than 2 of the test's
        time points inside the gold's span (the two spans given), or a sample
        of the run or the gold that is not a finite number.
    """
    name = "" if path is None else f" {shown(path)}"
    t, t_gold = np.asarray(t, float), np.asarray(t_gold, float)
    _finite(t, "the run's time", t, name)
    _finite(t_gold, "its time_s", t_gold, name)
    inside = (t >= t_gold[0]) & (t <= t_gold[-1]) if t_gold.size else np.zeros(t.shape, bool)
    if np.count_nonzero(inside) < 2:
        span = f"{format_eng(t_gold[0], 's')} to {format_eng(t_gold[-1], 's')}" if t_gold.size else "no time"
        run = f"{format_eng(t[0], 's')} to {format_eng(t[-1], 's')}" if t.size else "no time"
        raise DesignError(record_advice(f"golden file{name} covers {span}; the run covers {run}: fewer than 2 of "
                                        "the run's time points lie in the golden span, nothing to compare",
                                        aside=True))
    out = {}
    for sig, (reltol, abstol) in tolerances.items():
        y = np.asarray(test[sig], float)
        _finite(y[inside], f"the run's {sig}", t[inside], name)
        _finite(np.asarray(gold[sig], float), f"its {sig}", t_gold, name)
        out[sig] = nrms(gold[sig], y[inside], abstol, reltol=reltol, t=t[inside], t_gold=t_gold)
    return out


def _finite(values, what: str, t, name: str) -> None:
    """Refuse the first sample of ``values`` (on times ``t``) that is not a finite number."""
    bad = np.flatnonzero(~np.isfinite(values))
    if bad.size:
        i = int(bad[0])
        when = f" at {format_eng(t[i], 's')}" if i < np.size(t) and np.isfinite(t[i]) else f" at sample {i + 1}"
        raise DesignError(f"golden file{name}: {what} is {float(values[i])}{when}; only finite samples can be "
                          "compared")


def error_plot(t, test, t_gold, gold, reltol: float, abstol: float, title: str) -> bytes:
    """PNG: gold and test (top) and their normalised error (gold - test) /
    (reltol |gold| + abstol) on the test's points (bottom, +/-1 marked)."""
    import matplotlib
    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    from ..core.compare import resample
    from ..report.plots import png_bytes
    t = np.asarray(t, float)
    g = resample(t_gold, gold, t)
    err = (g - np.asarray(test, float)) / (reltol * np.abs(g) + abstol)
    fig, (a1, a2) = plt.subplots(2, 1, figsize=(7.5, 5.5), sharex=True)
    a1.plot(t_gold, gold, "-", lw=1.6, label="gold")
    a1.plot(t, test, "--", lw=1.3, label="test")
    a1.set_ylabel("signal")
    a1.set_title(title)
    a1.legend()
    a2.plot(t, err, "-", lw=1.0, color="C3")
    for y in (-1, 1):
        a2.axhline(y, color="0.5", lw=0.8, ls=":")
    a2.set_ylabel("normalised error")
    a2.set_xlabel("time (s)")
    for a in (a1, a2):
        a.grid(True, alpha=0.3)
    return png_bytes(fig)
