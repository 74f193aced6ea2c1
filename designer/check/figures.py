"""The figures a spec's ``checks:`` can limit, by kind, and where each comes
from in a design's typed result (one corner: the op-amp-aware model and the
SPICE run with that corner's op-amp).

Names without a prefix are what the bench sees: the SPICE run's step figures
(``overshoot_pct``), or the circuit's own (``fn_hz``, ``kp``);
``model_<figure>`` is the analytic model with the corner's op-amp, and for a
plant ``ideal_<figure>`` the ideal-op-amp model. A ``kind: netlist`` spec limits
the deck's own ``.meas`` results, by name.
"""

from __future__ import annotations

STEP = ("overshoot_pct", "peak_time_s", "rise_time_s", "settling_time_s")

#: figure -> (unit, what it is), for a plant
PLANT = {
    "fn_hz": ("Hz", "natural frequency of the parts (ideal op-amp)"),
    "zeta": ("", "damping ratio of the parts (ideal op-amp)"),
    "q": ("", "quality factor 1/(2 zeta) of the parts"),
    "gain": ("", "DC gain K"),
    "fn_opamp_hz": ("Hz", "natural frequency with the corner's op-amp"),
    "zeta_opamp": ("", "damping ratio with the corner's op-amp"),
    "fn_error_pct": ("", "fn against the target, percent (with a target)"),
    "zeta_error_pct": ("", "zeta against the target, percent (with a target)"),
    **{f: ("s" if f.endswith("_s") else "", f"SPICE step figure {f}") for f in STEP},
    **{f"model_{f}": ("s" if f.endswith("_s") else "", f"op-amp-aware model's {f}") for f in STEP},
    **{f"ideal_{f}": ("s" if f.endswith("_s") else "", f"ideal-op-amp model's {f}") for f in STEP},
    "nrms": ("", "SPICE against the op-amp-aware model (xyce_verify rule, 1 % + 1 % of the step)"),
    "nrms_ideal": ("", "SPICE against the ideal-op-amp model"),
}

#: figure -> (unit, what it is), for a controller in its loop
PID = {
    "kp": ("", "proportional gain the parts give"),
    "ti_s": ("s", "integral time the parts give"),
    "td_s": ("s", "derivative time the parts give"),
    "phase_margin_deg": ("", "phase margin with the op-amp poles, degrees"),
    "crossover_hz": ("Hz", "gain crossover of the loop"),
    "gain_margin_db": ("", "gain margin, dB"),
    "steady_state_error_pct": ("", "steady-state error of the loop, percent of the step"),
    **{f: ("s" if f.endswith("_s") else "", f"SPICE closed-loop step figure {f}") for f in STEP},
    **{f"model_{f}": ("s" if f.endswith("_s") else "", f"analytic loop's {f} (op-amp poles)") for f in STEP},
    "nrms": ("", "SPICE against the analytic loop (xyce_verify rule, 1 % + 1 % of the step)"),
}

FIGURES = {"plant": PLANT, "pid": PID}

#: the tolerance band's figures (a plant's build sheet: worst case over its part tolerances)
BAND = ("fn_hz", "zeta", "overshoot_pct", "peak_time_s", "rise_time_s", "settling_time_s")


def unit_of(kind: str, figure: str) -> str:
    """The unit a figure is printed in (none for a deck's measurement)."""
    return FIGURES.get(kind, {}).get(figure, ("",))[0]


def plant_figures(res) -> dict:
    """Every :data:`PLANT` figure of a :class:`~designer.plant.result.PlantResult`."""
    a, o = res.analytic, res.analytic_opamp
    out = {"fn_hz": a.figures.fn_hz, "zeta": a.figures.zeta, "q": a.figures.q, "gain": res.built.gain,
           "fn_opamp_hz": o.figures.fn_hz, "zeta_opamp": o.figures.zeta,
           "fn_error_pct": a.figures.fn_error_pct, "zeta_error_pct": a.figures.zeta_error_pct}
    for f in STEP:
        out[f"model_{f}"] = getattr(o.step, f)
        out[f"ideal_{f}"] = getattr(a.step, f)
        out[f] = None if res.spice is None else getattr(res.spice.step, f)
    out["nrms"] = None if res.spice is None else res.spice.nrms
    out["nrms_ideal"] = None if res.spice is None else res.spice.nrms_ideal
    return out


def pid_figures(res) -> dict:
    """Every :data:`PID` figure of a :class:`~designer.pid.result.PidResult`."""
    m = res.margins
    out = {"kp": res.achieved.kp, "ti_s": res.achieved.ti_s, "td_s": res.achieved.td_s,
           "phase_margin_deg": m.phase_margin_deg, "crossover_hz": m.crossover_hz,
           "gain_margin_db": m.gain_margin_db, "steady_state_error_pct": res.analytic.steady_state_error_pct}
    for f in STEP:
        out[f"model_{f}"] = getattr(res.analytic.figures, f)
        out[f] = None if res.spice is None else getattr(res.spice.figures, f)
    out["nrms"] = None if res.spice is None else res.spice.nrms
    return out


def band_of(res) -> dict:
    """figure -> (lo, hi) of a plant's tolerance band (:data:`BAND`)."""
    t = res.tolerance
    return {f: (getattr(t, f).lo, getattr(t, f).hi) for f in BAND}
