"""Confidence half-widths of least-squares parameters from the Jacobian at the optimum.

Every nonlinear least-squares fit of the project (the step fit, the frequency-response fit, the output-error
fit) reports its parameters' 95 % intervals the same way, by this one function.

Sources: the linearised (delta-method) covariance of a nonlinear least-squares estimate,
cov = s^2 (J^T J)^-1 with s^2 = SSE / (N - p) (D. M. Bates and D. G. Watts, *Nonlinear Regression Analysis and
Its Applications*, Wiley 1988, section 2.3; L. Ljung, *System Identification*, 2nd ed. 1999, section 9.3), and
the half-width t(1 - alpha/2, N - p) sqrt(cov_ii) of a Student-t interval (Bates and Watts eq. 2.30). They
assume white residuals: with coloured noise or a wrong structure they are optimistic.

**Why the columns are scaled.** The inverse is a pseudo-inverse (a parameter the data do not determine must
not stop the fit's report), and its cut-off is relative to the largest singular value of J^T J (numpy's
``pinv``: 1e-15). A Jacobian's column norms are the parameters' units as much as their information: a dead
time started near 0 and scaled by the sample interval, or an overdamped fit's second time constant shrinking
towards 0 on a first-order record, has a column 1e8 times shorter than the gain's, J^T J a condition of 1e16
from the units alone, and the pseudo-inverse dropped that direction: the parameter came out exact (a dead
time +-3e-18 s, a time constant +-3.4e-8 s) where the data say nothing of it, and a model was wrongly valid.
Scaling every column to unit norm, D = diag(|J_j|), cov = D^-1 ((J D^-1)^T (J D^-1))^+ D^-1 s^2, is the same
covariance where J has full rank (Golub and Van Loan, *Matrix Computations*, 4th ed., section 5.3.7, the
column equilibration of least squares) and leaves the cut-off to collinearity alone. Every product is scaled:
an earlier rule kept the unscaled product for columns within 1e6 of each other, and columns 10^5.75 apart
then gave an infinite half-width where the QR route gives a finite one (10^5 apart, 1.4e-5 off); scaled, both
agree with it to 1e-11 (columns of zeros, parameters the solver holds at a bound, keep a unit scale). A
direction the pseudo-inverse still drops among the other columns (collinear ones) gives every parameter
along it an infinite half-width: the data do not bound it.
"""

from __future__ import annotations

import numpy as np

__all__ = ["PINV_RCOND", "half_widths"]

#: numpy.linalg.pinv's default cut-off, relative to the largest singular value (the directions it drops)
PINV_RCOND = 1e-15
#: a dropped direction's loading on a parameter above this (round-off of a unit vector is ~1e-16) leaves
#: that parameter unbounded
_LOADING = float(np.sqrt(np.finfo(float).eps))


def half_widths(jac, s2: float, dof: int, level: float = 0.95) -> np.ndarray:
    """Student-t half-widths of least-squares parameters, t(1/2 + level/2, dof) sqrt(diag(s2 (J^T J)^+)).

    Parameters
    ----------
    jac : array_like, shape (N, p)
        The residuals' Jacobian at the optimum, d r / d x, in the units the half-widths are wanted in.
    s2 : float
        The residual variance, SSE / dof (scipy's ``least_squares`` reports cost = SSE / 2).
    dof : int
        Degrees of freedom, N - p (at least 1).
    level : float, optional
        The confidence level, 0.95 by default.

    Returns
    -------
    numpy.ndarray, shape (p,)
        One half-width per column, >= 0; ``inf`` for a parameter along a direction the data do not
        determine; 0 for a column of zeros (a parameter the solver held). The columns are scaled to unit
        norm before the pseudo-inverse (see the module docstring).
    """
    from scipy.special import stdtrit    # scipy.stats costs 0.4 s to import

    J = np.asarray(jac, float)
    d = np.linalg.norm(J, axis=0)
    seen = d > 0
    d = np.where(seen, d, 1.0)
    A = (J / d).T @ (J / d)
    cov = np.linalg.pinv(A) / np.outer(d, d) * s2
    half = float(stdtrit(max(int(dof), 1), 0.5 + 0.5 * level)) * np.sqrt(np.clip(np.diag(cov), 0.0, None))
    # the directions pinv dropped (the same cut-off as its own) among the columns the data move: no finite
    # interval along them. A column of zeros is a parameter the solver holds (scipy's least_squares gives a
    # dead time at its bound 0 one): it keeps pinv's 0, the caller knows its bounds
    _, s, vt = np.linalg.svd(A)
    dropped = vt[s <= PINV_RCOND * (s.max() if s.size else 0.0)]
    if dropped.size:
        half = np.where(seen & (np.abs(dropped).max(axis=0) > _LOADING), np.inf, half)
    return half
