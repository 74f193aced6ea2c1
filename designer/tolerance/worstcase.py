"""Worst case: the true extremes of each figure over the tolerance box, every
part anywhere within nominal (1 +- tol).

Every corner of the box is evaluated at once (2^d of them, d the parts that
vary; the engine is vectorised), then a bounded optimiser (L-BFGS-B on the
relative deviations in [-1, 1]^d) starts from the worst corner of each figure
in each direction: a figure that is not monotone in a part (a loop's overshoot)
can peak inside the box. The tests check the result against a brute-force grid.
"""

from __future__ import annotations

import dataclasses
import itertools
from dataclasses import dataclass

import numpy as np

from ..core.i18n import N_, Message
from ..core.figure_titles import figure_range

__all__ = ["WorstCase", "worst_case"]

#: figures whose extremes are reported
FIGURES = ("fn_hz", "zeta", "q", "overshoot_pct", "peak_time_s")


@dataclass(frozen=True)
class Extreme:
    """One extreme: the value, the parts' relative deviations (times their tolerance)
    where it is reached, and whether it is a corner."""

    value: float
    deviations: dict
    at_corner: bool

    def to_dict(self) -> dict:
        return {"value": self.value, "deviations": self.deviations, "at_corner": self.at_corner}


@dataclass(frozen=True)
class WorstCase:
    """figure -> (min Extreme, max Extreme), and the number of corners evaluated; a figure no corner has is
    in ``missing`` only."""

    extremes: dict
    corners: int
    #: how the box was searched, in English (result.json's); a Message (a sheet shows it in its language)
    method: str = Message(N_("every corner, then L-BFGS-B from the worst corner"))
    #: figure -> how many of the corners evaluated have no value (NaN: no peak where a build is overdamped);
    #: only figures missing somewhere. Its extremes are then over the builds that have it, and may be
    #: exceeded near the others (a peak time grows without bound as zeta nears 1)
    missing: dict = dataclasses.field(default_factory=dict)

    def to_dict(self) -> dict:
        return {"corners": self.corners, "method": self.method,
                **{k: {"min": lo.to_dict(), "max": hi.to_dict(),
                       **({"missing_corners": self.missing[k]} if k in self.missing else {})}
                   for k, (lo, hi) in self.extremes.items()},
                **{k: {"min": None, "max": None, "missing_corners": n} for k, n in self.missing.items()
                   if k not in self.extremes}}

    def summary_lines(self) -> list:
        what = "corners" if self.method.startswith("every") else "corners the sensitivities point to"
        out = [f"Worst case over the tolerance box ({self.corners} {what}, then a bounded search):"]
        for k, (lo, hi) in self.extremes.items():
            out.append("  " + figure_range(k, lo.value, hi.value)
                       + ("" if lo.at_corner and hi.at_corner else " (an extreme inside the box)")
                       + ("" if k not in self.missing else
                          f" (no value at {self.missing[k]} of {self.corners} corners: over the builds that have"
                          " it, and may be exceeded near the others)"))
        out += [f"  {figure_range(k, None, None)} at any of the {self.corners} corners"
                for k in self.missing if k not in self.extremes]
        return out


def sensitivity_corners(evaluate, values, d: int, figures) -> np.ndarray:
    """The corners a box too large to enumerate is searched from: each part alone at -tol
    and +tol (2d runs), and for each figure the corner every part's slope points up and
    the one it points down (a linear model's extremes, exact for a monotone figure)."""
    probes = np.vstack([-np.eye(d), np.eye(d)])
    at = evaluate(values(probes))
    out = [np.ones(d), -np.ones(d)]
    for fig in figures:
        v = np.nan_to_num(np.asarray(at[fig], float), nan=0.0, posinf=0.0, neginf=0.0)
        slope = np.sign(v[d:] - v[:d])
        slope[slope == 0] = 1.0
        out += [slope, -slope]
    return np.unique(np.array(out), axis=0)


def worst_case(evaluate, nominal: dict, tol: dict, figures=FIGURES, max_corners: int = 4096,
               maxiter: int = 60) -> WorstCase:
    """The extremes of ``figures`` of ``evaluate(values) -> {figure: array}`` over the box.

    Parameters
    ----------
    evaluate : callable
        Designator -> array of values, to figure -> array (an engine such as
        :func:`designer.tolerance.plant.plant_figures` with its op-amp bound).
    nominal, tol : dict
        Designator -> nominal value and -> tolerance (fraction).
    figures : sequence of str
        The figures whose extremes are sought.
    max_corners : int
        Every corner is evaluated up to this many (2^d); a larger box (a loop's 22 parts: 4 million
        corners) starts from the corners the parts' slopes point to (:func:`sensitivity_corners`).
    maxiter : int
        The bounded search's iterations per figure and direction.

    Returns
    -------
    WorstCase
        Each figure's extremes and the corners evaluated.
    """
    from scipy.optimize import minimize
    refs = list(tol)
    d = len(refs)

    def values(dev):
        dev = np.atleast_2d(dev)
        return {r: nominal[r] * (1 + tol[r] * dev[:, k]) for k, r in enumerate(refs)}

    if 2 ** d <= max_corners:
        signs = np.array(list(itertools.product((-1.0, 1.0), repeat=d)))
        method = WorstCase.method
    else:
        signs = sensitivity_corners(evaluate, values, d, figures)
        method = Message(N_("each part alone at -tol and +tol, the corners their slopes point to, then L-BFGS-B "
                            "from the worst ({corners} corners are too many to enumerate)"), corners=str(2 ** d))
    at_corners = evaluate(values(signs))
    out, missing = {}, {}
    for fig in figures:
        v = np.asarray(at_corners[fig], float)
        if not np.isfinite(v).all():
            missing[fig] = int(np.count_nonzero(~np.isfinite(v)))
        if missing.get(fig) == len(v):
            # no corner has it (a first-order section's peak time): nothing to start a search from, and
            # L-BFGS-B on an objective inf everywhere stepped to NaN deviations (LinAlgError in the engine)
            continue
        pair = []
        for sign in (1.0, -1.0):                      # min, then max
            score = np.where(np.isfinite(v), sign * v, np.inf)
            k = int(np.argmin(score))
            best, x_best, corner = float(v[k]), signs[k], True

            def f(x, sign=sign):
                if not np.isfinite(x).all():    # a step from a NaN gradient: no build to evaluate there
                    return np.inf
                y = float(np.asarray(evaluate(values(x))[fig], float)[0])
                return sign * y if np.isfinite(y) else np.inf

            # a figure can be missing in part of the box (no peak where a build is overdamped): f is inf
            # there, and a step the search tries there makes its finite-difference gradient inf - inf; the
            # search then ends, its answer kept only when finite (below), so the NaN is no news to print
            with np.errstate(invalid="ignore"):
                res = minimize(f, signs[k] * 0.999, method="L-BFGS-B", bounds=[(-1.0, 1.0)] * d,
                               options={"maxiter": maxiter})
            if np.isfinite(res.fun) and sign * res.fun < sign * best - 1e-12 * max(1.0, abs(best)):
                best, x_best, corner = float(sign * res.fun), np.clip(res.x, -1, 1), False
            pair.append(Extreme(best, {r: float(x_best[i]) for i, r in enumerate(refs)}, corner))
        out[fig] = tuple(pair)
    return WorstCase(out, len(signs), method, missing)
