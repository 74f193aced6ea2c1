"""Checks: one typed record for every pass/fail verdict a design gets (slew
rate, output swing, phase margin, accuracy of a gain...), with a stable
snake_case id that is the same in every command and in ``result.json``."""

from __future__ import annotations

from dataclasses import dataclass, field

from .i18n import N_
from .i18n import translated

__all__ = ["Check", "IDS", "SPICE_AGREEMENT", "listing"]

#: what each check id means, for the build sheets (ids not listed print as themselves)
TITLES = {
    "slew_rate": N_("slew rate"),
    "output_swing": N_("output swing"),
    "prbs_slew_rate": N_("slew rate under the PRBS"),
    "prbs_output_swing": N_("output swing under the PRBS"),
    "square_wave_period": N_("square-wave period"),
    "square_wave_agreement": N_("SPICE agreement under the square wave"),
    "spice_agreement": N_("SPICE agreement"),
    "closed_loop_stable": N_("closed loop stable"),
    "phase_margin": N_("phase margin"),
    "steady_state_error": N_("steady-state error"),
    "kp_accuracy": N_("Kp accuracy"),
    "ti_accuracy": N_("Ti accuracy"),
    "td_accuracy": N_("Td accuracy"),
    "integrator_corner": N_("integrator corner"),
    "differentiator_corner": N_("differentiator corner"),
    "resistor_bounds": N_("resistor bounds"),
    "capacitor_bounds": N_("capacitor bounds"),
}


@dataclass(frozen=True)
class Check:
    """One verdict: ``id`` (snake_case, stable), whether it passed, and why.

    ``detail`` is the why in English (``result.json``'s); a check made with :meth:`of` also keeps its message and
    values, so that each sheet shows it in its own language (:meth:`shown`).
    """

    id: str
    ok: bool
    detail: str
    message: str | None = field(default=None, compare=False, repr=False)   #: the detail's message (English)
    values: tuple = field(default=(), compare=False, repr=False)           #: its {name} values, (name, text) pairs

    @classmethod
    def of(cls, id: str, ok, message: str, **values) -> "Check":
        """A check whose detail is ``message`` (marked with ``N_`` where it is written) filled with ``values``.

        Parameters
        ----------
        id : str
            The check's id.
        ok : bool
            Whether it passed.
        message : str
            The detail's English text with ``{name}`` fields.
        **values
            The fields' values (already written as text: ``f"{x:.3g}"``), or a list written by :func:`listing`.

        Returns
        -------
        Check
            The check, its ``detail`` the English text.
        """
        values = tuple(sorted(values.items()))
        return cls(id, bool(ok), _fill(message, values, False), message, values)

    def shown(self) -> str:
        """The detail in the current language (:func:`designer.core.i18n.gettext`, the message and each value that is
        a message of the catalogue; as written without a message).

        Returns
        -------
        str
            The text.
        """
        if self.message is None:
            return self.detail
        return _fill(self.message, self.values, True)

    @property
    def title(self) -> str:
        """A readable name for the sheets: ``slew rate``, ``bandwidth summer``."""
        return TITLES.get(self.id, self.id.replace("_", " "))

    def to_dict(self) -> dict:
        # "name" is the id too: the key result.json has always had (the detail in English: the file's language)
        return {"id": self.id, "name": self.id, "ok": bool(self.ok), "detail": self.detail}


def listing(sep: str, items) -> tuple:
    """A list inside a check's detail (the stages that slew too long, the poles near the crossover), each item a
    message of its own, joined by ``sep``: a value of :meth:`Check.of`.

    Parameters
    ----------
    sep : str
        What goes between two items (``"; "``).
    items : iterable of (str, dict)
        Each item's message (marked ``N_``) and its values.

    Returns
    -------
    tuple
        The list as :meth:`Check.of` keeps it.
    """
    return ("parts", sep, tuple((m, tuple(sorted(v.items()))) for m, v in items))


def _fill(message: str, values: tuple, translate: bool) -> str:
    """``message`` with its ``values`` (a list of :func:`listing` written out), in the current language when
    ``translate``; a value that is itself a word of the catalogue (a stage's role, "gain") translated too."""
    word = translated if translate else str   # a value that is a Message reads in the sheet's language too

    def text(v):
        if isinstance(v, tuple) and v[:1] == ("parts",):
            return v[1].join(_fill(m, vals, translate) for m, vals in v[2])
        return word(v)
    return word(message).format(**{k: text(v) for k, v in values})


def failed(checks) -> list:
    """The checks that did not pass."""
    return [c for c in checks if not c.ok]


#: the id of the verdict on SPICE against the analytic model (every command that simulates)
SPICE_AGREEMENT = "spice_agreement"

#: every id a design command can give, by command family; ``bandwidth_<stage>`` ids are the PID's
#: per-stage checks (``difference``, ``inverter``, ``differentiator``, ``integrator``, ``summer``, ``gain``)
IDS = {
    "plant": ("slew_rate", "output_swing", "square_wave_period", SPICE_AGREEMENT),
    "pid": ("kp_accuracy", "ti_accuracy", "td_accuracy", "integrator_corner", "differentiator_corner",
            *(f"bandwidth_{s}" for s in ("difference", "inverter", "differentiator", "integrator", "summer",
                                          "gain")),
            "resistor_bounds", "capacitor_bounds", "closed_loop_stable", "phase_margin", "steady_state_error",
            "slew_rate", "output_swing", SPICE_AGREEMENT),
}
