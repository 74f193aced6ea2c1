"""Statistics of sampled figures: mean, standard deviation, percentiles, Cpk
against limits, the yield with its 95 % Wilson interval, and each part's share of
each figure's variance (standardised regression coefficients squared)."""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

__all__ = ["Limit", "Z95", "figure_stats", "parse_limit", "variance_shares", "wilson"]

#: the percentiles reported: +-3 sigma, +-2 sigma (95 %) and the median of a normal figure
PERCENTILES = (0.135, 2.5, 50.0, 97.5, 99.865)
#: z of a two-sided 95 % interval
Z95 = 1.959963984540054


def wilson(k: int, n: int, z: float = Z95) -> tuple:
    """The Wilson score interval (lo, hi) of a proportion k/n (Wilson 1927).

    Parameters
    ----------
    k : int
        The successes.
    n : int
        The trials.
    z : float
        The normal quantile (95 %: 1.96).

    Returns
    -------
    tuple of float
        (lo, hi).
    """
    if n <= 0:
        return (math.nan, math.nan)
    p = k / n
    den = 1 + z * z / n
    mid = (p + z * z / (2 * n)) / den
    half = z * math.sqrt(p * (1 - p) / n + z * z / (4 * n * n)) / den
    # at k = 0 (k = n) the interval starts at 0 (ends at 1) exactly, not at a rounding error from it
    return (0.0 if k == 0 else max(0.0, mid - half), 1.0 if k == n else min(1.0, mid + half))


@dataclass(frozen=True)
class Limit:
    """A window a figure is counted against: min and/or max (None: open)."""

    figure: str
    min: float | None
    max: float | None

    def inside(self, v) -> np.ndarray:
        v = np.asarray(v, float)
        ok = np.isfinite(v)
        if self.min is not None:
            ok &= v >= self.min
        if self.max is not None:
            ok &= v <= self.max
        return ok

    def window(self) -> str:
        """``3.3 kHz to 3.7 kHz``, ``>= 45 deg``: the window with its units."""
        from ..core.units import format_figure
        f = self.figure
        if self.min is not None and self.max is not None:
            return f"{format_figure(f, self.min)} to {format_figure(f, self.max)}"
        return f">= {format_figure(f, self.min)}" if self.min is not None else f"<= {format_figure(f, self.max)}"

    def text(self) -> str:
        """``fn_hz 3.3 kHz to 3.7 kHz``: the figure and its window."""
        return f"{self.figure} {self.window()}"

    def to_dict(self) -> dict:
        return {"figure": self.figure, "min": self.min, "max": self.max}


def parse_limit(text: str, figures) -> Limit:
    """``FIGURE=MIN:MAX`` in engineering notation, both bounds given (``overshoot_pct=0:55``).

    Parameters
    ----------
    text : str
        The ``--limit`` item.
    figures : iterable of str
        The figures that may be limited.

    Returns
    -------
    Limit
        The limit.
    """
    from ..core.errors import DesignError
    from ..core.units import parse_value
    t = str(text)
    shape = f"--limit {text!r}: give FIGURE=MIN:MAX with both bounds, such as fn_hz=3.3k:3.7k or overshoot_pct=0:55"
    if "=" not in t or ":" not in t.split("=", 1)[1]:
        raise DesignError(shape)
    name, rng = (s.strip() for s in t.split("=", 1))
    if name not in figures:
        raise DesignError(f"--limit {name!r}: unknown figure; the figures are {', '.join(figures)}")
    lo_t, hi_t = (s.strip() for s in rng.split(":", 1))
    if not lo_t or not hi_t:
        raise DesignError(shape)
    lo, hi = parse_value(lo_t, f"--limit {name} min"), parse_value(hi_t, f"--limit {name} max")
    if lo > hi:
        raise DesignError(f"--limit {name}: min {lo:g} is above max {hi:g}")
    return Limit(name, lo, hi)


@dataclass(frozen=True)
class FigureStats:
    """One figure over the samples."""

    figure: str
    nominal: float
    mean: float
    std: float
    percentiles: dict
    cpk: float | None                  #: against the figure's limit (None without one)

    def to_dict(self) -> dict:
        return {"figure": self.figure, "nominal": self.nominal, "mean": self.mean, "std": self.std,
                "percentiles": {f"{k:g}": v for k, v in self.percentiles.items()}, "cpk": self.cpk}


def figure_stats(name: str, v, nominal: float, limit: Limit | None = None) -> FigureStats:
    """A figure's statistics over the samples (NaN left out): mean, standard deviation, percentiles,
    and the process capability Cpk against ``limit`` (None without one or without spread).

    Parameters
    ----------
    name : str
        The figure.
    v : array_like
        Its value in each sample.
    nominal : float
        The nominal design's value.
    limit : Limit, optional
        The figure's limit.

    Returns
    -------
    FigureStats
        The statistics.
    """
    v = np.asarray(v, float)
    v = v[np.isfinite(v)]
    mean = float(v.mean()) if v.size else math.nan
    std = float(v.std(ddof=1)) if v.size > 1 else math.nan
    pct = {p: float(x) for p, x in zip(PERCENTILES, np.percentile(v, PERCENTILES))} if v.size else {}
    cpk = None
    if limit is not None and std > 0:
        sides = [(limit.max - mean) / (3 * std)] if limit.max is not None else []
        sides += [(mean - limit.min) / (3 * std)] if limit.min is not None else []
        cpk = float(min(sides))
    return FigureStats(name, float(nominal), mean, std, pct, cpk)


def variance_shares(x: dict, y) -> dict:
    """Each part's share of the variance of ``y``: the squared standardised
    regression coefficients of y on the parts' relative deviations (their sum is the
    linear model's R^2; a part absent from the figure gets ~0).

    Parameters
    ----------
    x : dict
        Part -> relative deviations over the samples.
    y : array_like
        The figure over the samples.

    Returns
    -------
    dict
        Part -> share.
    """
    y = np.asarray(y, float)
    keep = np.isfinite(y)
    refs = list(x)
    a = np.column_stack([np.asarray(x[r], float)[keep] for r in refs])
    yy = y[keep]
    if yy.size < len(refs) + 2 or np.std(yy) == 0:
        return {r: 0.0 for r in refs}
    az = (a - a.mean(0)) / np.where(a.std(0) > 0, a.std(0), 1.0)
    yz = (yy - yy.mean()) / yy.std()
    beta, *_ = np.linalg.lstsq(az, yz, rcond=None)
    return {r: float(b * b) for r, b in zip(refs, beta)}


def failing_samples(figs: dict, limits, worst: int = 5) -> dict:
    """figure -> {count, worst}: how many samples fall outside each limit and the indices of the
    ``worst`` farthest from the window's centre (a sample without the figure, NaN, first)."""
    out = {}
    for lim in limits:
        bad = np.nonzero(~lim.inside(figs[lim.figure]))[0]
        v = np.asarray(figs[lim.figure], float)[bad]
        centre = 0.5 * ((lim.min if lim.min is not None else lim.max) + (lim.max if lim.max is not None else lim.min))
        order = np.argsort(-np.abs(np.nan_to_num(v, nan=np.inf) - centre))[:worst]
        out[lim.figure] = {"count": int(bad.size), "worst": [int(i) for i in bad[order]]}
    return out


def samples_csv(values: dict, figures: dict) -> str:
    """One row per sample: its index, every varied part's value, every figure (a reader can recompute
    any figure from a row)."""
    import io
    refs, figs = list(values), list(figures)
    n = len(next(iter(values.values())))
    out = io.StringIO()
    out.write(",".join(["sample", *refs, *figs]) + "\n")
    cols = [np.arange(n)] + [values[r] for r in refs] + [figures[f] for f in figs]
    np.savetxt(out, np.column_stack(cols), delimiter=",", fmt=["%d"] + ["%.10g"] * (len(cols) - 1))
    return out.getvalue()
