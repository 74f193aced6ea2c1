"""Where a plant's parts come from: the series' values within the bounds the search takes
(:func:`candidates`), each part's series label and tolerance (:func:`part_series`), and how far off a
design may land (:data:`MAX_ERROR`, :data:`NOTE_ERROR`): shared by the seed's Sallen-Key plant
(:mod:`designer.plant.design`) and a plant on any section (:mod:`designer.plant.circuit_design`)."""

from __future__ import annotations

import numpy as np

from ..core import eseries
from ..core.errors import DesignError
from ..core.units import format_eng
from .result import PartSource

__all__ = ["DEFAULT_SERIES", "MAX_ERROR", "NOTE_ERROR", "candidates", "part_series"]


def candidates(series: str, lo: float, hi: float, what: str) -> np.ndarray:
    """The series' values between ``lo`` and ``hi``, refused in one line when there are none.

    Parameters
    ----------
    series : str
        The E-series.
    lo, hi : float
        The bounds.
    what : str
        "resistor" or "capacitor", for the message.

    Returns
    -------
    numpy.ndarray
        The values, ascending.
    """
    vals = eseries.values(series, lo, hi)
    if vals.size == 0:
        raise DesignError(f"no {series} {what} value between {lo:g} and {hi:g}; widen the bounds")
    return vals


#: what an unlabelled part is assumed to be: a 5 % resistor, a 10 % capacitor
DEFAULT_SERIES = {"R": "E24", "C": "E12"}


def part_series(values: dict, r_series=None, c_series=None):
    """Each part's series label and tolerance, and the series whose tolerance the band
    uses (the loosest part's, worst case).

    With a series given, every part of that kind is from it. Without, a part is
    labelled with the smallest series that holds its value ("not a standard value"
    when none does) and assumed at least as tight as the default E24 resistor /
    E12 capacitor: a 1k from a 5 % kit is not a 40 % E3 part, but a 1k26 exists
    only as an E192 (0.5 %) part.

    Parameters
    ----------
    values : dict
        Designator -> value (ohm, farad).
    r_series, c_series : str, optional
        Normalised series names (an :class:`~designer.plant.spec.AnalysisSpec`'s); None: labelled by value.

    Returns
    -------
    tuple
        (labels {ref: :class:`~designer.plant.result.PartSource`}, r band series, c band series, notes).
    """
    order = list(eseries.SERIES)
    given = {"R": r_series, "C": c_series}
    labels, band, notes = {}, {"R": None, "C": None}, []
    for ref, v in values.items():
        kind = ref[0]
        found = eseries.smallest_series(v)
        if given[kind] is not None:
            series = given[kind]
            label = series if found is not None and order.index(found) <= order.index(series) \
                else f"{series} (not an {series} value)"
        elif found is None:
            series, label = DEFAULT_SERIES[kind], "not a standard value"
            unit = "Ohm" if kind == "R" else "F"
            notes.append(f"{ref} = {format_eng(v, unit)} is not a standard E-series value; its tolerance is "
                         f"taken as {100 * eseries.TOLERANCE[series]:g} %")
        else:
            series = order[max(order.index(found), order.index(DEFAULT_SERIES[kind]))]
            label = found
        labels[ref] = PartSource(label, 100 * eseries.TOLERANCE[series])
        if band[kind] is None or eseries.TOLERANCE[series] > eseries.TOLERANCE[band[kind]]:
            band[kind] = series
    return labels, band["R"] or DEFAULT_SERIES["R"], band["C"] or DEFAULT_SERIES["C"], notes


#: a design further off than this is refused, with the reason
MAX_ERROR = 0.05
#: a design further off than this says which bound holds it back (and, at twice it,
#: that the op-amp's gain-bandwidth moves it)
NOTE_ERROR = 0.005
