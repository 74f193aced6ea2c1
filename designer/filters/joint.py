"""E-series parts chosen jointly across all the stages of a cascade.

Every stage offers a candidate set (the neighbouring series values of each
continuous part, for each of its capacitor choices: :func:`candidates`); the
stage's error is e_i(c, f) = |H_i(c, f)| in dB minus its target's, on one
frequency grid, so that the cascade's error is the sum over stages and the
objective is the worst deviation in dB of the whole response,

    J(c_1 .. c_n) = max_f | sum_i e_i(c_i, f) |.

:func:`joint_search` minimises J exactly over the product of the candidate
sets by branch and bound, vectorised with numpy: stages are added one at a
time to every surviving partial choice; a partial sum P(f) can still end
anywhere in [P + L(f), P + U(f)], L and U the sums of the remaining stages'
least and greatest errors at each f, so max_f dist(0, [P + L, P + U]) is a
lower bound on every completion's J, and a partial whose bound exceeds the
best complete J known (initially the per-stage choice's) is dropped. Nothing
better than the best can be dropped, so the result is the exhaustive
enumeration's (:func:`brute_force`, the test's reference) at a fraction of its
cost. A mask adds one-sided limits at single frequencies (the loss at the
passband edge, the attenuation at the stopband edge): ``limits`` of
(column k, sign, offset) whose violation offset + sign * S(f_k) > 0 costs
:data:`PENALTY` dB per dB in J, so a choice that meets the mask wins over any
that does not; its bound is the violation at the best end of the reachable
interval. A Bessel's group-delay target (the delay within T % of its DC value
from DC to a frequency) is more one-sided limits of the same kind, on columns
that only limits read (``n_dev``: J's deviation is max_f |S| over the first
``n_dev`` columns, the dB ones): the cascade's delay is the sum of its stages',
tau = sum_i tau_i, so |tau(f) - tau(0)| <= T/100 tau(0) is, at each f, the two
sums sum_i (+-100 (tau_i(f) - tau_i(0)) - T tau_i(0)) / tau_ref <= 0 (tau_ref
the ideal's DC delay), linear in the stages like the dB errors; their
violation is the delay error's excess over T in % points (times tau(0) /
tau_ref, about 1), weighted by the same :data:`PENALTY`: a choice that meets
the mask and the delay target wins over any that does not, and the search stays
exact (the same interval bound holds for every limit column). Per-stage rounding (:func:`per_stage`, each stage minimising its own
error alone: what the filter design tools do) is a point of the same product,
so the joint choice is never worse.
"""

from __future__ import annotations

import itertools

import numpy as np

__all__ = ["objective", "per_stage", "descend", "joint_search", "brute_force", "delay_columns", "joint_alternatives"]

#: dB of objective per dB of mask violation: a mask met is worth more than any deviation
PENALTY = 1000.0
#: the partial sums processed at once (elements of the (partials x candidates x f) block)
_BLOCK = 4_000_000


def _score(total: np.ndarray, limits, n_dev=None) -> np.ndarray:
    """J of sums ``total`` (rows): max_f |S| over the first ``n_dev`` columns, and PENALTY x the worst
    limit's violation."""
    j = np.max(np.abs(total[..., :n_dev]), axis=-1)
    for col, sign, offset in limits or ():
        j = np.maximum(j, PENALTY * (offset + sign * total[..., col]))
    return j


def delay_columns(taus: list, max_error_pct: float, tau_ref: float, first: int) -> tuple:
    """A group-delay target as limit columns (the module's rule): per stage, the columns
    +-100 (tau_i(f) - tau_i(0)) / tau_ref - T tau_i(0) / tau_ref at every f but DC, and their limits.

    Parameters
    ----------
    taus : list of ndarray
        Per stage, shape (n_candidates_i, n_f): each candidate's group delay (s), DC first.
    max_error_pct : float
        T: the delay error allowed, % of the DC delay.
    tau_ref : float
        The scale of the columns (s): the ideal's DC delay, so that a violation reads in % points.
    first : int
        The index the first column will have (the number of columns before them).

    Returns
    -------
    tuple
        (list of ndarray per stage, shape (n_candidates_i, 2 (n_f - 1)); list of limits (column, 1, 0)).
    """
    cols = []
    for tau in taus:
        dev = 100 * (tau[:, 1:] - tau[:, :1]) / tau_ref
        allowed = max_error_pct * tau[:, :1] / tau_ref
        cols.append(np.hstack([dev - allowed, -dev - allowed]))
    n = cols[0].shape[1] if cols else 0
    return cols, [(first + k, 1.0, 0.0) for k in range(n)]


def objective(errors: list, choice, limits=None, n_dev=None) -> float:
    """J of one choice: the cascade's worst deviation in dB (and its mask violation, weighted).

    Parameters
    ----------
    errors : list of ndarray
        Per stage, shape (n_candidates_i, n_f): candidate's dB error at each f.
    choice : sequence of int
        One candidate index per stage.
    limits : list of tuple, optional
        (column, sign, offset): the violation offset + sign * S[column] must stay <= 0.
    n_dev : int, optional
        The columns of the deviation (the first ``n_dev``; default all); the others serve ``limits`` only.

    Returns
    -------
    float
        max(max_f |sum_i errors[i][choice[i]]|, PENALTY x the worst violation).
    """
    total = sum(e[c] for e, c in zip(errors, choice))
    return float(_score(total, limits, n_dev))


def per_stage(errors: list, n_dev=None) -> list:
    """Each stage's own best candidate (least max_f |e_i|), independently of the others.

    Parameters
    ----------
    errors : list of ndarray
        As :func:`objective`.
    n_dev : int, optional
        As :func:`objective`: each stage's own deviation is over these columns.

    Returns
    -------
    list of int
        One index per stage.
    """
    return [int(np.argmin(np.max(np.abs(e[:, :n_dev]), axis=1))) for e in errors]


def brute_force(errors: list, limits=None, n_dev=None) -> tuple:
    """Exhaustive enumeration of every combination (for tests and small cases).

    Parameters
    ----------
    errors : list of ndarray
        As :func:`objective`.
    limits : list of tuple, optional
        As :func:`objective`.
    n_dev : int, optional
        As :func:`objective`.

    Returns
    -------
    tuple
        (choice as a list of int, J).
    """
    best, best_j = None, np.inf
    for choice in itertools.product(*(range(len(e)) for e in errors)):
        j = objective(errors, choice, limits, n_dev)
        if j < best_j:
            best, best_j = list(choice), j
    return best, best_j


def descend(errors: list, choice, limits=None, n_dev=None) -> list:
    """Coordinate descent from ``choice``: each stage in turn moved to its best
    candidate with the others held, until no move helps. A local optimum whose J
    bounds :func:`joint_search` tightly from the start.

    Parameters
    ----------
    errors : list of ndarray
        As :func:`objective`.
    choice : sequence of int
        The starting choice.
    limits : list of tuple, optional
        As :func:`objective`.
    n_dev : int, optional
        As :func:`objective`.

    Returns
    -------
    list of int
        The improved choice.
    """
    choice = list(choice)
    total = sum(e[c] for e, c in zip(errors, choice))
    best = float(_score(total, limits, n_dev))
    improved = True
    while improved:
        improved = False
        for i, e in enumerate(errors):
            others = total - e[choice[i]]
            j = _score(others[None, :] + e, limits, n_dev)
            c = int(np.argmin(j))
            if j[c] < best - 1e-15:
                best, choice[i], total, improved = float(j[c]), c, others + e[c], True
    return choice


def joint_search(errors: list, start=None, limits=None, n_dev=None) -> tuple:
    """The exact minimiser of :func:`objective` over the product of the candidate sets.

    Parameters
    ----------
    errors : list of ndarray
        As :func:`objective`.
    start : sequence of int, optional
        A known choice whose J bounds the search (default: :func:`per_stage`).
    limits : list of tuple, optional
        As :func:`objective`.
    n_dev : int, optional
        As :func:`objective`.

    Returns
    -------
    tuple
        (choice as a list of int, J, number of partial choices examined).
    """
    start = descend(errors, per_stage(errors, n_dev) if start is None else start, limits, n_dev)
    best_j = objective(errors, start, limits, n_dev)
    sums, picks, examined = _survivors(errors, best_j, limits, n_dev)
    j = _score(sums, limits, n_dev)
    w = int(np.argmin(j))
    return [int(c) for c in picks[w]], float(j[w]), examined


def _survivors(errors: list, best_j: float, limits, n_dev) -> tuple:
    """The branch and bound of :func:`joint_search`: every complete choice whose bound is within ``best_j``
    (so every one with J <= best_j), as (their sums, their picks in stage order, partials examined)."""
    n = len(errors)
    # the stages whose candidates differ most first: their choice decides most, and the
    # narrow remainder [L, U] then bounds tightly
    order = sorted(range(n), key=lambda i: -float(np.max(np.ptp(errors[i], axis=0))))
    lo = [e.min(axis=0) for e in errors]
    hi = [e.max(axis=0) for e in errors]
    nf = errors[0].shape[1]
    rest_lo = [np.zeros(nf)] * (n + 1)
    rest_hi = [np.zeros(nf)] * (n + 1)
    for k in range(n - 1, -1, -1):
        rest_lo[k] = rest_lo[k + 1] + lo[order[k]]
        rest_hi[k] = rest_hi[k + 1] + hi[order[k]]
    partial = np.zeros((1, nf))
    picks = np.zeros((1, 0), dtype=np.int64)
    examined = 0
    slack = 1e-12 * max(best_j, 1e-30)
    for k, i in enumerate(order):
        e = errors[i]
        kept_sums, kept_picks = [], []
        step = max(1, _BLOCK // (len(e) * nf))
        for a in range(0, len(partial), step):
            block = partial[a:a + step, None, :] + e[None, :, :]
            block = block.reshape(-1, nf)
            examined += len(block)
            # distance from 0 of the interval every completion can still reach, at each f
            low, high = block + rest_lo[k + 1], block + rest_hi[k + 1]
            bound = np.max(np.maximum(np.maximum(low[:, :n_dev], -high[:, :n_dev]), 0.0), axis=1)
            for col, sign, offset in limits or ():
                best_end = low[:, col] if sign > 0 else high[:, col]
                bound = np.maximum(bound, PENALTY * (offset + sign * best_end))
            keep = bound <= best_j + slack
            if np.any(keep):
                base = np.repeat(picks[a:a + step], len(e), axis=0)
                cand = np.tile(np.arange(len(e)), min(step, len(partial) - a))[:, None]
                kept_sums.append(block[keep])
                kept_picks.append(np.hstack([base, cand])[keep])
        partial = np.vstack(kept_sums)
        picks = np.vstack(kept_picks)
    in_stage_order = np.empty_like(picks)
    in_stage_order[:, order] = picks
    return partial, in_stage_order, examined


def joint_alternatives(errors: list, best, count: int, limits=None, n_dev=None) -> list:
    """The ``count`` least-J choices, best first (the joint choice first): exact, as :func:`joint_search`.
    The choices one stage away from ``best`` are ``count`` distinct choices or more (else every choice is
    enumerated), so the ``count``-th least J among them bounds the ``count``-th least J of all; the
    branch and bound keeps every choice within that bound, and the ``count`` least are taken from those.

    Parameters
    ----------
    errors : list of ndarray
        As :func:`objective`.
    best : sequence of int
        The joint choice (:func:`joint_search`'s).
    count : int
        How many choices, 1 or more.
    limits : list of tuple, optional
        As :func:`objective`.
    n_dev : int, optional
        As :func:`objective`.

    Returns
    -------
    list of tuple
        (choice as a list of int, J), J rising (ties in the enumeration's order); fewer when the product
        has fewer choices.
    """
    best = [int(c) for c in best]
    near = {tuple(best)}
    for i, e in enumerate(errors):
        near.update(tuple(best[:i] + [c] + best[i + 1:]) for c in range(len(e)))
    js = sorted(objective(errors, ch, limits, n_dev) for ch in near)
    bound = js[count - 1] if len(js) >= count else np.inf
    sums, picks, _ = _survivors(errors, bound, limits, n_dev)
    j = _score(sums, limits, n_dev)
    top = np.argsort(j, kind="stable")[:count]
    return [([int(c) for c in picks[w]], float(j[w])) for w in top]
