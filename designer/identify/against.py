"""An identified plant against its design (``identify --against result.json``).

:func:`compare_with_design` puts the best second-order model beside a
design-plant ``result.json`` (fn, zeta, gain, overshoot) and says whether the
built parts' tolerances explain the difference: each identified value is
judged against its :class:`AgreementBand`, the range the design allows over
its part tolerances (the result's own ``built.tolerance_band``, the scope
readings design-plant computed from the parts, where it has one; the corners
of the parts here otherwise), widened for the gain by the measurement's own
error. The Sallen-Key relations are the plant's own: the built record read
into the Sallen-Key low-pass section's values by designator
(:func:`designer.plant.sallenkey.json_values`), each corner's fn and zeta its
ideal pair (:meth:`~designer.filters.topology.Topology.ideal_pair`, seed 001
fig. 43-45), the corners those of the plant's own band
(:func:`designer.plant.bench.tolerance_corners`): this module is
identification's one use of the plant wing.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

from ..core.errors import DesignError
from ..core.fileio import shown
from ..core.jsonio import json_safe, read_result
from ..plant.bench import tolerance_corners
from ..plant.sallenkey import KEY_OF, json_values, ratio_pair, section_of

__all__ = ["agreement_band", "compare_with_design", "load_design", "model_fn_zeta", "overshoot_from_zeta"]

#: Part tolerances assumed when the design's ``built`` has no ``tolerance_band``.
DEFAULT_R_TOL = 0.05
DEFAULT_C_TOL = 0.10
#: Allowance on the static gain for the measurement itself (two scope channels).
GAIN_MEASUREMENT_TOL = 0.02
#: The identified models a design is compared with, best first.
SECOND_ORDER = ("underdamped", "overdamped", "double-pole")


def model_fn_zeta(m) -> tuple:
    """(fn_hz, zeta) of a second-order :class:`~.structures.MethodResult`; (nan, nan) for FOPDT.

    Parameters
    ----------
    m : MethodResult
        A step-identification model.

    Returns
    -------
    tuple of float
        ``(fn_hz, zeta)``.
    """
    p = m.params
    if m.model == "underdamped":
        return p["wn_rad_s"] / (2 * math.pi), p["zeta"]
    if m.model == "overdamped":
        t1, t2 = p["tau1_s"], p["tau2_s"]
        wn = 1.0 / math.sqrt(t1 * t2)
        return wn / (2 * math.pi), (t1 + t2) / (2 * math.sqrt(t1 * t2))
    if m.model == "double-pole":
        return 1.0 / (2 * math.pi * p["tau_s"]), 1.0
    return math.nan, math.nan


def overshoot_from_zeta(zeta: float) -> float:
    """Percent overshoot of a standard second-order step response.

    Parameters
    ----------
    zeta : float
        Damping ratio.

    Returns
    -------
    float
        Overshoot in percent of the final value; 0 for zeta >= 1 or not finite; infinite for
        zeta <= -1 (the formula's limit as zeta falls to -1: two real poles in the right half-plane,
        a step that grows without bound; a tolerance corner of a plant with much gain can be there).
    """
    if not math.isfinite(zeta) or zeta >= 1:
        return 0.0
    if zeta <= -1:
        return math.inf
    try:
        return 100.0 * math.exp(-math.pi * zeta / math.sqrt(1 - zeta * zeta))
    except OverflowError:   # zeta just above -1: past a float, as the limit
        return math.inf


@dataclass(frozen=True)
class AgreementBand:
    """Where an identified plant agrees with its design: ``(lo, hi)`` of fn,
    zeta, overshoot and gain, and what they were computed from."""

    fn_hz: tuple
    zeta: tuple
    overshoot_pct: tuple
    gain: tuple
    r_tol: float
    c_tol: float
    basis: str

    def of(self, key: str) -> tuple:
        """The band of quantity ``key`` (``fn_hz``, ``zeta``, ``overshoot_pct``, ``gain``)."""
        return getattr(self, key)


def agreement_band(built: dict, gain: float = 1.0, r_tol: float = DEFAULT_R_TOL,
                   c_tol: float = DEFAULT_C_TOL) -> AgreementBand:
    """Worst-case band of fn, zeta, overshoot and gain over the part tolerances.

    With the built part values (the Sallen-Key network's, by designator) every
    corner of the tolerance box is evaluated (2^4, or 2^6 with the gain pair's
    corners: its extremes are K's); without them the nominal fn and zeta are scaled by the corner
    factors of fn ~ 1/sqrt(R1 R2 C1 C2) and zeta ~ sqrt(C1/C2) (unity gain).
    The gain, read as the ratio of two measured signals, gets the
    measurement's own error (:data:`GAIN_MEASUREMENT_TOL`) on top.

    Parameters
    ----------
    built : dict
        The design's ``built`` record: the network's part values when known
        (:func:`designer.plant.sallenkey.json_values`), else its ``fn_hz`` and ``zeta``.
    gain : float, optional
        The design's DC gain K (1: unity-gain follower).
    r_tol, c_tol : float, optional
        Relative tolerances of the resistors and capacitors.

    Returns
    -------
    AgreementBand
        The (low, high) bands of fn_hz, zeta, overshoot_pct and gain, the
        tolerances used and how the band was found (``basis``).
    """
    g_lo = g_hi = gain
    if gain != 1.0:
        # K = 1 + R4/R3 with the same resistor tolerance
        ratio = gain - 1.0
        g_lo = 1 + ratio * (1 - r_tol) / (1 + r_tol)
        g_hi = 1 + ratio * (1 + r_tol) / (1 - r_tol)
    values = json_values(built)
    if values is not None:
        # the follower, or with K the gain section whose pair gives K by its ratio (ratio_pair): its
        # corners are the closed form's K extremes, 1 + (K - 1)(1 -+ t)/(1 +- t)
        section = section_of(with_gain=gain != 1.0)
        values = values | (ratio_pair(gain) if gain != 1.0 else {})
        tol = {p.ref: r_tol if p.kind == "R" else c_tol for p in section.parts}
        fns, zetas = zip(*(section.ideal_pair(v) for v in tolerance_corners(values, tol)))
        basis = "corners of the built parts"
    else:
        fn0, z0 = float(built.get("fn_hz", math.nan)), float(built.get("zeta", math.nan))
        fns = [fn0 / ((1 + r_tol) * (1 + c_tol)), fn0 / ((1 - r_tol) * (1 - c_tol))]
        zetas = [z0 * math.sqrt((1 - c_tol) / (1 + c_tol)), z0 * math.sqrt((1 + c_tol) / (1 - c_tol))]
        basis = "scaling of the nominal fn and zeta"
    zl, zh = min(zetas), max(zetas)
    return AgreementBand(fn_hz=(min(fns), max(fns)), zeta=(zl, zh),
                         overshoot_pct=(overshoot_from_zeta(zh), overshoot_from_zeta(zl)),
                         gain=(g_lo * (1 - GAIN_MEASUREMENT_TOL), g_hi * (1 + GAIN_MEASUREMENT_TOL)),
                         r_tol=r_tol, c_tol=c_tol, basis=basis)


def design_band(built: dict, gain: float) -> tuple:
    """``(band, basis)``: the design's own ``built.tolerance_band`` (design-plant's
    ``{key: {"min": lo, "max": hi}}``) where it has one, completed with
    :func:`agreement_band` for what it lacks (the gain); else
    :func:`agreement_band` with the default tolerances."""
    tb = built.get("tolerance_band")
    computed = agreement_band(built, gain)
    if not isinstance(tb, dict):
        basis = (f"assumed {100 * computed.r_tol:g} % R / {100 * computed.c_tol:g} % C "
                 f"({computed.basis})")
        return computed, basis
    given = {k: (float(v["min"]), float(v["max"])) for k, v in tb.items()
             if isinstance(v, dict) and _is_number(v.get("min")) and _is_number(v.get("max"))}
    band = AgreementBand(**{k: given.get(k, computed.of(k))
                            for k in ("fn_hz", "zeta", "overshoot_pct", "gain")},
                         r_tol=computed.r_tol, c_tol=computed.c_tol, basis="built.tolerance_band")
    basis = "built.tolerance_band"
    if _is_number(tb.get("r_tolerance_pct")) and _is_number(tb.get("c_tolerance_pct")):
        basis += f" ({tb['r_tolerance_pct']:g} % R / {tb['c_tolerance_pct']:g} % C)"
    return band, basis


def load_design(path) -> dict:
    """Read a design-plant result.json (:func:`designer.core.jsonio.read_result`);
    a clear one-line error if it is not one, or if a value the comparison uses
    is not a finite number where one is needed.

    Parameters
    ----------
    path : str or path-like
        The design-plant result.json given to ``--against``.

    Returns
    -------
    dict
        The result's JSON object.
    """
    d = read_result(path, "--against", needs={"built": ("fn_hz", "zeta")})
    _check_design(d, shown(path))
    return d


def _is_number(v) -> bool:
    return isinstance(v, (int, float)) and not isinstance(v, bool) and math.isfinite(v)


def _check_design(d: dict, name: str) -> None:
    """The values :func:`compare_with_design` reads: present ones must be usable."""
    def bad(where, what):
        raise DesignError(f"--against: {name}: {where} must be {what}")
    built = d["built"]
    for k in ("fn_hz", "zeta"):
        if not (_is_number(built[k]) and built[k] > 0):
            bad(f"built.{k}", "a positive number")
    for k in (KEY_OF[r] for r in section_of(with_gain=False).designators):
        if k in built and built[k] is not None and not (_is_number(built[k]) and built[k] > 0):
            bad(f"built.{k}", "a positive number (or absent)")
    for key in ("spec", "spice"):
        if d.get(key) is not None and not isinstance(d[key], dict):
            bad(key, "an object (or absent)")
    gain = (d.get("spec") or {}).get("gain")
    if gain is not None and not (_is_number(gain) and gain >= 1):
        bad("spec.gain", "a number >= 1 (or absent)")
    os_pct = (d.get("spice") or {}).get("overshoot_pct")
    if os_pct is not None and not _is_number(os_pct):
        bad("spice.overshoot_pct", "a number (or absent)")
    tb = built.get("tolerance_band")
    if tb is None:
        return
    if not isinstance(tb, dict):
        bad("built.tolerance_band", "an object (or absent)")
    for k, v in tb.items():
        if k in ("r_tolerance_pct", "c_tolerance_pct"):
            if not _is_number(v):
                bad(f"built.tolerance_band.{k}", "a number")
        elif not (isinstance(v, dict) and all(v.get(e) is None or _is_number(v.get(e))
                                              for e in ("min", "max"))):
            bad(f"built.tolerance_band.{k}", 'an object {"min": number, "max": number}')


@dataclass(frozen=True)
class Quantity:
    """One row of the comparison: the design's value, the identified one, and
    whether the identified one lies in the band (None: not identified)."""

    design: float
    identified: float | None
    band: tuple
    unit: str
    note: str = ""

    @property
    def difference_pct(self) -> float | None:
        if self.identified is None or not math.isfinite(self.identified) or not self.design:
            return None
        return 100.0 * (self.identified - self.design) / abs(self.design)

    @property
    def within_tolerance(self) -> bool | None:
        lo, hi = self.band
        if self.identified is None or not math.isfinite(self.identified) or not math.isfinite(lo):
            return None
        return bool(lo <= self.identified <= hi)

    def to_dict(self) -> dict:
        d = {"design": self.design, "identified": json_safe(self.identified),
             "difference_pct": self.difference_pct, "band": list(self.band),
             "within_tolerance": self.within_tolerance, "unit": self.unit}
        if self.note:
            d["note"] = self.note
        return d


@dataclass(frozen=True)
class Comparison:
    """The identified plant against the design: one :class:`Quantity` per
    figure (``fn_hz``, ``zeta``, ``gain``, ``overshoot_pct``) and the verdict."""

    model: str | None
    tolerance_basis: str
    quantities: dict
    spec: dict

    @property
    def verdict(self) -> str:
        judged = {k: q.within_tolerance for k, q in self.quantities.items()
                  if q.within_tolerance is not None}
        if not judged:
            return "no second-order quantity could be identified for the comparison"
        if all(judged.values()):
            return "every difference lies inside the part-tolerance band: tolerances explain it"
        out = [k for k, ok in judged.items() if not ok]
        return (f"{', '.join(out)} outside the part-tolerance band: tolerances alone do not "
                "explain it (check wiring, op-amp limits, loading and the measurement)")

    def to_dict(self) -> dict:
        return {"model": self.model, "tolerance_basis": self.tolerance_basis,
                "quantities": {k: q.to_dict() for k, q in self.quantities.items()},
                "verdict": self.verdict, "spec": dict(self.spec)}


def compare_with_design(result, design: dict) -> Comparison:
    """Identified plant (an :class:`~.step.IdentifyResult`) vs a design-plant result.

    For each of fn, zeta, gain and overshoot: the design (built) value, the
    identified one (the best second-order model's; the overshoot measured on
    the data), the difference and the band (see :func:`design_band`).

    Parameters
    ----------
    result : IdentifyResult
        The step identification of the built plant.
    design : dict
        A design-plant result.json as read by :func:`load_design`.

    Returns
    -------
    Comparison
        The best second-order model's name, the tolerance basis, one
        :class:`Quantity` per compared value and the design's spec.
    """
    built = design["built"]
    spec = design.get("spec", {}) or {}
    gain = float(spec.get("gain", 1.0) or 1.0)
    band, basis = design_band(built, gain)
    m2 = result.best_of(SECOND_ORDER)
    fn_id, z_id = model_fn_zeta(m2) if m2 else (math.nan, math.nan)
    design_os = (design.get("spice") or {}).get("overshoot_pct")
    if design_os is None:
        design_os = overshoot_from_zeta(float(built["zeta"]))
    measured_os = result.measured.overshoot_pct if result.measured is not None else None
    rows = {"fn_hz": Quantity(float(built["fn_hz"]), fn_id, band.fn_hz, "Hz"),
            "zeta": Quantity(float(built["zeta"]), z_id, band.zeta, ""),
            "gain": Quantity(gain, result.step.yf, band.gain, ""),
            "overshoot_pct": Quantity(float(design_os), measured_os, band.overshoot_pct, "%",
                                      "identified overshoot is measured on the data")}
    return Comparison(model=f"{m2.name} ({m2.model})" if m2 else None, tolerance_basis=basis,
                      quantities=rows, spec={k: spec.get(k) for k in ("fc_hz", "zeta", "gain")})
