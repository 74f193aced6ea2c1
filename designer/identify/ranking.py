"""The best of the models scored on the same validation data: the best
validation fit among the valid ones, where a difference the validation data
cannot resolve is no difference, and among models that tie the one with fewer
parameters.

**The margin.** Two models scored on the same validation samples differ in
mean squared residual by dbar = mean(d), d_t = e_a,t^2 - e_b,t^2 (the paired
loss difference of Diebold and Mariano's test of equal predictive accuracy).
Its standard error is sqrt(S/N), S the long-run variance of d, estimated with
Newey and West's Bartlett-weighted autocovariances (d is autocorrelated when
the models' errors are) up to L = floor(4 (N/100)^(2/9)) lags (Newey and
West's rule of thumb, 1994). A model is tied with the best-fitting one when
its loss exceeds that model's by at most one standard error: the
"one-standard-error rule" (Breiman, Friedman, Olshen and Stone, 1984; Hastie,
Tibshirani and Friedman), which picks the most parsimonious model whose error
is within one standard error of the best's. Among the tied models (the
best-fitting one included) the one with the fewest parameters wins, and
among those the best fit. The margin in fit points is the fit the
best-fitting model would have with its squared-error sum larger by N standard
errors.

Why not an information criterion on the validation residuals (FPE = V (1 +
p/N)/(1 - p/N), AIC): those penalties estimate how much the estimation loss
flatters a model with p parameters, a bias the validation loss, on fresh data,
does not have; they are not a measure of what the validation data resolve.
The standard error is, and it comes from the data.

Measured (tests/identify/test_assess_synthetic.py, seed 28): the SOPDT at 10
dB under a random binary signal p 0.1 (4,388 block means of validation): the
best fit is the correlation route's overdamped model, the output-error SOPDT
0.003 point lower and the lead-lag (a parameter more) 0.005, one standard
error 0.010 and 0.011 point: tied, and the next model, 0.044 point lower
(0.013), is not. Under a single step at 10 dB the output-error SOPDT leads its
FOPDT by 0.017 point with a standard error of 0.019: the FOPDT is the best.
Between an SOPDT and an FOPDT under p 0.5 the difference is 9.4 points, the
error 0.44. Seed 003's furnace: the output-error lead-lag leads the next model
by 1.9 points (8-bit sequence) and 0.26 point (5-bit), errors 0.51 and 0.09:
no tie. The DaISy dryer: the output-error SOPDT ties with a spectral
underdamped model 0.73 point lower (error 0.61), as many parameters: the SOPDT
stays.

Parameters (:data:`PARAMETERS`): those of the model's structure, however the
route estimated them (a double pole is K, tau, theta; an integrator K and
theta).

Sources: F. X. Diebold and R. S. Mariano, "Comparing predictive accuracy",
*Journal of Business and Economic Statistics* 13(3), 253-263 (1995); W. K.
Newey and K. D. West, "A simple, positive semi-definite, heteroskedasticity
and autocorrelation consistent covariance matrix", *Econometrica* 55(3),
703-708 (1987), and "Automatic lag selection in covariance matrix
estimation", *Review of Economic Studies* 61(4), 631-653 (1994); L. Breiman,
J. Friedman, R. Olshen and C. Stone, *Classification and Regression Trees*
(1984), section 3.4.3; T. Hastie, R. Tibshirani and J. Friedman, *The
Elements of Statistical Learning*, 2nd ed. (2009), section 7.10.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

__all__ = ["PARAMETERS", "parameter_count", "nw_lags", "loss_difference", "Ranking", "rank"]

#: the parameters of each structure a route gives (its name as the candidates' ``kind``)
PARAMETERS = {"fopdt": 3, "double-pole": 3, "overdamped": 4, "sopdt": 4, "underdamped": 4, "integrating": 2,
              "integrating-lag": 3, "lead-lag": 5}


def parameter_count(kind: str, params: dict) -> int:
    """The parameters of a model's structure.

    Parameters
    ----------
    kind : str
        Its structure (:data:`PARAMETERS`).
    params : dict
        Its parameters (counted, the numeric ones, for a structure not listed).

    Returns
    -------
    int
    """
    if kind in PARAMETERS:
        return PARAMETERS[kind]
    return sum(1 for v in params.values() if isinstance(v, (int, float)) and not isinstance(v, bool))


def nw_lags(n: int) -> int:
    """Newey and West's (1994) rule-of-thumb bandwidth, floor(4 (n/100)^(2/9)).

    Parameters
    ----------
    n : int
        Samples.

    Returns
    -------
    int
        Autocovariance lags weighted (0 for fewer than 2 samples).
    """
    return int(math.floor(4.0 * (n / 100.0) ** (2.0 / 9.0))) if n > 1 else 0


def loss_difference(e_a, e_b) -> tuple:
    """The mean of e_a^2 - e_b^2 and its Newey-West standard error (module notes).

    Parameters
    ----------
    e_a, e_b : array_like
        Two models' residuals on the same samples.

    Returns
    -------
    tuple of (float, float)
        The mean loss difference (positive: ``e_a`` the larger) and its
        standard error.
    """
    d = np.asarray(e_a, float) ** 2 - np.asarray(e_b, float) ** 2
    n = d.size
    x = d - d.mean()
    s = float(x @ x) / n
    lags = min(nw_lags(n), n - 1)
    for k in range(1, lags + 1):
        s += 2.0 * (1.0 - k / (lags + 1.0)) * float(x[:-k] @ x[k:]) / n
    return float(d.mean()), math.sqrt(max(s, 0.0) / n)


@dataclass(frozen=True)
class Ranking:
    """The choice among scored candidates.

    Attributes
    ----------
    best : int
        Index of the chosen candidate.
    top : int
        Index of the best validation fit (``best`` unless a tie decided).
    tied : tuple of int
        Indices of the candidates tied with ``top`` (itself included).
    margin : float
        One standard error of the chosen candidate's loss difference with
        ``top``'s, in fit points (0 when ``best`` is ``top``).
    note : str
        Why the chosen one won over a better fit ("" when it is the best fit).
    """

    best: int
    top: int
    tied: tuple
    margin: float
    note: str


def _points(e_top, se: float, spread: float) -> float:
    """Fit points of a squared-error sum larger by ``se`` per sample (from ``e_top``'s)."""
    ss = float(np.asarray(e_top, float) @ np.asarray(e_top, float))
    return 100.0 * (math.sqrt(ss + np.size(e_top) * se) - math.sqrt(ss)) / spread


def rank(candidates) -> Ranking | None:
    """The best of candidates scored on the same validation data (module notes).

    Parameters
    ----------
    candidates : sequence
        Objects with ``valid``, ``fit_percent``, ``kind``, ``params``,
        ``label`` and ``validation`` (its ``residuals`` and ``spread``:
        :class:`~.validation.Validation`).

    Returns
    -------
    Ranking or None
        None when no candidate is valid with a finite fit.
    """
    ok = [i for i, c in enumerate(candidates) if c.valid and math.isfinite(c.fit_percent)]
    if not ok:
        return None
    top = max(ok, key=lambda i: candidates[i].fit_percent)
    et = getattr(candidates[top].validation, "residuals", None)
    tied, se = [top], {top: 0.0}
    for i in ok:
        e = getattr(candidates[i].validation, "residuals", None)
        if i == top or et is None or e is None or np.size(e) != np.size(et):
            continue
        dbar, s = loss_difference(e, et)
        if dbar <= s:
            tied.append(i)
            se[i] = s
    best = min(tied, key=lambda i: (parameter_count(candidates[i].kind, candidates[i].params),
                                    -candidates[i].fit_percent))
    if best == top:
        return Ranking(best, top, tuple(sorted(tied)), 0.0, "")
    c, t = candidates[best], candidates[top]
    margin = _points(et, se[best], t.validation.spread)
    note = (f"tied with {t.label} within the margin (fit {c.fit_percent:.3f} % against {t.fit_percent:.3f} %, "
            f"one standard error of their validation losses' difference {margin:.3g} point); fewer parameters "
            f"({parameter_count(c.kind, c.params)} against {parameter_count(t.kind, t.params)})")
    return Ranking(best, top, tuple(sorted(tied)), margin, note)
