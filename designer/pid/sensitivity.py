"""The sensitivity peak of a feedback loop: Ms = max over w of |S(jw)|, S = 1/(1 + L(jw)).

1/Ms is the shortest distance from the Nyquist curve of L to the critical point -1
(Astrom and Murray, *Feedback Systems*: the stability margin s_m = 1/Ms; Astrom and
Hagglund, *Advanced PID Control*: Ms of 1.2 to 2 for a robust loop, the bound the
optimiser's ``--max-ms`` holds). One function for every loop this package models:
the model plant's (:func:`designer.pid.delaymargins.loop_margins`, exact dead time)
and the Sallen-Key plant's (:func:`designer.pid.model.margins`, op-amp poles
included); each passes its own L(jw).

The peak is found on the caller's dense log grid, then refined between the grid
point's two neighbours by a bounded scalar search (scipy's ``minimize_scalar``,
Brent's method on the bracket): on a smooth single peak the refined value is at
least the grid's and agrees with a 2,000,001-point brute-force grid to far below
1e-6 relative (``tests/pid/test_sensitivity.py``).
"""

from __future__ import annotations

import math

import numpy as np

__all__ = ["sensitivity_peak"]


def sensitivity_peak(w, samples, loop=None) -> tuple[float, float]:
    """The sensitivity peak Ms = max |1/(1 + L(jw))| and the frequency where it occurs.

    Parameters
    ----------
    w : array_like
        Angular frequencies (rad/s), ascending (a dense log grid over the loop's band).
    samples : array_like
        The loop gain L(jw) on ``w``.
    loop : callable, optional
        ``loop(w)`` -> L(jw) for an array of angular frequencies (rad/s): the loop's
        transfer function, used to refine the grid's peak between its neighbours.
        Without it the grid's peak is returned as it is.

    Returns
    -------
    tuple of float
        (Ms, w at the peak in rad/s). Ms is inf where 1 + L vanishes on the grid;
        a peak at either end of the grid is not refined (it lies outside the band).
    """
    from scipy.optimize import minimize_scalar
    w = np.asarray(w, float)
    with np.errstate(divide="ignore"):
        s = 1 / np.abs(1 + np.asarray(samples))
    i = int(np.argmax(s))
    if loop is None or not math.isfinite(s[i]) or i == 0 or i == w.size - 1:
        return float(s[i]), float(w[i])
    neg = lambda x: -1 / abs(1 + loop(np.array([x]))[0])  # noqa: E731
    res = minimize_scalar(neg, bounds=(w[i - 1], w[i + 1]), method="bounded",
                          options={"xatol": 1e-12 * w[i + 1]})
    # the search keeps to the bracket; should it stop below the grid's own point, that point stands
    return (-float(res.fun), float(res.x)) if -res.fun >= s[i] else (float(s[i]), float(w[i]))
