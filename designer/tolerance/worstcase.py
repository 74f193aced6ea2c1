"""Worst case: the true extremes of each figure over the tolerance box, every
part anywhere within nominal (1 +- tol).

Every corner of the box is evaluated at once (2^d of them, d the parts that
vary; the engine is vectorised), then a bounded optimiser (L-BFGS-B on the
relative deviations in [-1, 1]^d) starts from the worst corner of each figure
in each direction: a figure that is not monotone in a part (a loop's overshoot)
can peak inside the box. The tests check the result against a brute-force grid.
"""

from __future__ import annotations

import itertools
from dataclasses import dataclass

import numpy as np

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
    """figure -> (min Extreme, max Extreme), and the number of corners evaluated."""

    extremes: dict
    corners: int

    def to_dict(self) -> dict:
        return {"corners": self.corners, "method": "every corner, then L-BFGS-B from the worst corner",
                **{k: {"min": lo.to_dict(), "max": hi.to_dict()} for k, (lo, hi) in self.extremes.items()}}

    def summary_lines(self) -> list:
        out = [f"Worst case over the tolerance box ({self.corners} corners, then a bounded search):"]
        for k, (lo, hi) in self.extremes.items():
            out.append(f"  {k}: {lo.value:.5g} to {hi.value:.5g}"
                       + ("" if lo.at_corner and hi.at_corner else " (an extreme inside the box)"))
        return out


def worst_case(evaluate, nominal: dict, tol: dict, figures=FIGURES) -> WorstCase:
    """The extremes of ``figures`` of ``evaluate(values) -> {figure: array}`` over the box.

    Parameters
    ----------
    evaluate : callable
        Designator -> array of values, to figure -> array (an engine such as
        :func:`designer.tolerance.plant.plant_figures` with its op-amp bound).
    nominal, tol : dict
        Designator -> nominal value and -> tolerance (fraction).
    """
    from scipy.optimize import minimize
    refs = list(tol)
    d = len(refs)
    signs = np.array(list(itertools.product((-1.0, 1.0), repeat=d)))

    def values(dev):
        dev = np.atleast_2d(dev)
        return {r: nominal[r] * (1 + tol[r] * dev[:, k]) for k, r in enumerate(refs)}

    at_corners = evaluate(values(signs))
    out = {}
    for fig in figures:
        v = np.asarray(at_corners[fig], float)
        pair = []
        for sign in (1.0, -1.0):                      # min, then max
            score = np.where(np.isfinite(v), sign * v, np.inf)
            k = int(np.argmin(score))
            best, x_best, corner = float(v[k]), signs[k], True

            def f(x, sign=sign):
                y = float(np.asarray(evaluate(values(x))[fig], float)[0])
                return sign * y if np.isfinite(y) else np.inf

            res = minimize(f, signs[k] * 0.999, method="L-BFGS-B", bounds=[(-1.0, 1.0)] * d,
                           options={"maxiter": 60})
            if np.isfinite(res.fun) and sign * res.fun < sign * best - 1e-12 * max(1.0, abs(best)):
                best, x_best, corner = float(sign * res.fun), np.clip(res.x, -1, 1), False
            pair.append(Extreme(best, {r: float(x_best[i]) for i, r in enumerate(refs)}, corner))
        out[fig] = tuple(pair)
    return WorstCase(out, len(signs))
