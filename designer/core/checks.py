"""Checks: one typed record for every pass/fail verdict a design gets (slew
rate, output swing, phase margin, accuracy of a gain...), with a stable
snake_case id that is the same in every command and in ``result.json``."""

from __future__ import annotations

from dataclasses import dataclass

from .i18n import N_

__all__ = ["Check", "IDS", "SPICE_AGREEMENT"]

#: what each check id means, for the build sheets (ids not listed print as themselves)
TITLES = {
    "slew_rate": N_("slew rate"),
    "output_swing": N_("output swing"),
    "prbs_slew_rate": N_("slew rate under the PRBS"),
    "prbs_output_swing": N_("output swing under the PRBS"),
    "square_wave_period": N_("square-wave period"),
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
    """One verdict: ``id`` (snake_case, stable), whether it passed, and why."""

    id: str
    ok: bool
    detail: str

    @property
    def title(self) -> str:
        """A readable name for the sheets: ``slew rate``, ``bandwidth summer``."""
        return TITLES.get(self.id, self.id.replace("_", " "))

    def to_dict(self) -> dict:
        # "name" is the id too: the key result.json has always had
        return {"id": self.id, "name": self.id, "ok": bool(self.ok), "detail": self.detail}


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
