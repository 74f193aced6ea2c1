"""The runner-up part sets of a designed filter: the joint E-series choice's alternatives.

The joint choice (:mod:`designer.filters.joint`) minimises the cascade's worst
deviation from the ideal, the mask's and the delay target's limits weighted in;
the next best sets of the same candidates, found exactly by the same branch and
bound (:func:`designer.filters.joint.joint_alternatives`), are what a builder short
of one value reaches for. Each is listed with its worst deviation in dB, its
objective and how far it breaks the limits (0: it meets the mask and the delay
target), its parts named as built (stage i's R1 is Ri01).
"""

from __future__ import annotations

from dataclasses import dataclass

from ..core.errors import DesignError
from ..core.ranges import RANGES, parse_in_range
from .joint import joint_alternatives, objective
from .registry import get as get_topology

__all__ = ["Alternative", "alternatives_count", "design_alternatives"]


def alternatives_count(value) -> int:
    """How many part sets to list, as asked (a number or text): a whole number in ``RANGES["alternatives"]``.

    Parameters
    ----------
    value : int, float or str
        The count as given.

    Returns
    -------
    int
        The count.

    Raises
    ------
    DesignError
        Not a whole number in the range (naming ``alternatives``).
    """
    n = parse_in_range(value, "alternatives", "alternatives")
    if n != int(n):
        raise DesignError(f"alternatives must be a whole number from {RANGES['alternatives'].text()}, got {value!r}",
                          param="alternatives")
    return int(n)


@dataclass(frozen=True)
class Alternative:
    """One part set of the joint search's candidates.

    Parameters
    ----------
    rank : int
        1 the joint choice, 2 the next best, ...
    choice : tuple of int
        One candidate index per stage (build order).
    error_db : float
        The cascade's worst deviation from the ideal over the objective grid, dB (the op-amp's model in).
    objective_db : float
        The joint search's objective: the deviation, or the limits' violation x 1000 when larger.
    violation : float or None
        How far it breaks the mask (dB) or the delay target (% points), the worst; 0 when it meets them;
        None without a mask or a delay target.
    parts : dict
        Designator as built (``R101``) -> value (Ohm, F), every stage's.
    """

    rank: int
    choice: tuple
    error_db: float
    objective_db: float
    violation: float | None
    parts: dict

    def to_dict(self) -> dict:
        """The alternative as JSON.

        Returns
        -------
        dict
            ``rank``, ``error_db``, ``objective_db``, ``violation`` and ``parts``.
        """
        return {"rank": self.rank, "error_db": self.error_db, "objective_db": self.objective_db,
                "violation": self.violation, "parts": dict(self.parts)}


def design_alternatives(result, alternatives: int) -> list:
    """The ``count`` best part sets of ``result``'s candidates, the joint choice first (exact: equal to the
    enumeration of every combination).

    Parameters
    ----------
    result : designer.filters.FilterDesign
        A design by :func:`designer.filters.design.design` (its ``problem`` set).
    alternatives : int or str
        How many (:func:`alternatives_count`); fewer are listed when the candidates make fewer.

    Returns
    -------
    list of Alternative
        Best first.

    Raises
    ------
    DesignError
        ``alternatives`` not a whole number from 1 to 50.
    """
    count = alternatives_count(alternatives)
    search, limits, n_dev = result.problem
    errors = [st.errors for st in result.stages]
    out = []
    for rank, (choice, j) in enumerate(joint_alternatives(search, [st.chosen for st in result.stages], count, limits,
                                                    n_dev), 1):
        violation = None
        if limits:
            total = sum(e[c] for e, c in zip(search, choice))
            violation = max(0.0, *(float(o + sg * total[col]) for col, sg, o in limits))
        parts = {}
        for st, c in zip(result.stages, choice):
            topo = get_topology(st.topology)
            parts.update({topo.prefixed(ref, f"{st.number}0"): float(v) for ref, v in st.candidates[c].items()})
        out.append(Alternative(rank, tuple(choice), objective(errors, choice), j, violation, parts))
    return out
