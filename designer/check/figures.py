"""The figures a spec's ``checks:`` can limit, by kind, and where each comes
from in a design's typed result (one corner: the op-amp-aware model and the
SPICE run with that corner's op-amp).

Names without a prefix are what the bench sees with the corner's op-amp: the
SPICE run's step figures (``overshoot_pct``), or the circuit's own (``fn_hz``,
``zeta``, ``q`` of the dominant pair with that op-amp, ``kp``), so every corner
of ``opamp: [LM741, TL072]`` checks its own number; ``model_<figure>`` is the
analytic model with the corner's op-amp, and for a plant ``ideal_<figure>``
the ideal-op-amp model (``ideal_fn_hz``, ``ideal_zeta``, ``ideal_q``: the
passive parts alone, the same in every corner). ``fn_opamp_hz`` and
``zeta_opamp``, the earlier names of the corner's fn and zeta, stay accepted
as aliases (:data:`ALIASES`): their meaning never changed, so a spec using
them keeps checking the number it always did. A ``kind: netlist`` spec limits
the deck's own ``.meas`` results, by name.
"""

from __future__ import annotations

from dataclasses import replace

__all__ = ["ALIASES", "BAND", "PID", "PLANT", "SECTION_BAND", "band_of", "circuit_band_of", "corner_band",
           "plant_figures"]

STEP = ("overshoot_pct", "peak_time_s", "rise_time_s", "settling_time_s")

#: figure -> (unit, what it is), for a plant
PLANT = {
    "fn_hz": ("Hz", "natural frequency with the corner's op-amp (dominant pair)"),
    "zeta": ("", "damping ratio with the corner's op-amp (dominant pair)"),
    "q": ("", "quality factor 1/(2 zeta) with the corner's op-amp"),
    "ideal_fn_hz": ("Hz", "natural frequency of the parts alone (ideal op-amp)"),
    "ideal_zeta": ("", "damping ratio of the parts alone (ideal op-amp)"),
    "ideal_q": ("", "quality factor 1/(2 zeta) of the parts alone (ideal op-amp)"),
    "gain": ("", "DC gain K"),
    "fn_opamp_hz": ("Hz", "alias of fn_hz (its earlier name)"),
    "zeta_opamp": ("", "alias of zeta (its earlier name)"),
    "fn_error_pct": ("", "fn_hz (the corner's, with its op-amp) against the target fc, percent (with a target)"),
    "zeta_error_pct": ("", "zeta (the corner's, with its op-amp) against the target, percent (with a target)"),
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

#: figure -> (unit, what it is), for an active filter (designer.check.filter_kind): the corner's op-amp model,
#: and ngspice's .ac run (``spice_``); the mask's figures need ``mask:``, the design's a designed filter
FILTER = {
    "f3_hz": ("Hz", "-3 dB frequency below the passband gain (low- or high-pass), with the corner's op-amp"),
    "f3_low_hz": ("Hz", "a band-pass's lower -3 dB frequency, with the corner's op-amp"),
    "f3_high_hz": ("Hz", "a band-pass's upper -3 dB frequency, with the corner's op-amp"),
    "passband_gain_db": ("", "the passband gain, dB (the design's, or as built the cascade's own)"),
    "passband_loss_db": ("", "the largest loss below the passband gain over the mask's passband, dB"),
    "stopband_attenuation_db": ("", "the least attenuation over the mask's stopband, dB"),
    "delay_error_pct": ("", "the group delay's largest departure from its DC value up to delay.to, percent"),
    **{f"spice_{k}": (u, f"SPICE .ac: {w}") for k, (u, w) in (
        ("f3_hz", ("Hz", "-3 dB frequency")), ("f3_low_hz", ("Hz", "lower -3 dB frequency")),
        ("f3_high_hz", ("Hz", "upper -3 dB frequency")), ("passband_loss_db", ("", "passband loss, dB")),
        ("stopband_attenuation_db", ("", "stopband attenuation, dB")),
        ("delay_error_pct", ("", "group delay error up to delay.to, percent")))},
    "spice_max_deviation_db": ("", "SPICE .ac against the op-amp-aware model, largest |difference| down to -60 dB"),
    "stages": ("", "number of stages"),
    "order": ("", "filter order (designed)"),
    "passband_deviation_db": ("", "largest passband deviation from the ideal response, dB (designed)"),
    "error_joint_db": ("", "the joint E-series choice's worst deviation from the ideal, dB (designed)"),
    "error_per_stage_db": ("", "per-stage rounding's worst deviation from the ideal, dB (designed)"),
    "gbw_ratio_min": ("", "the op-amp's GBW over the most a stage needs, the smallest over the stages (designed)"),
}

FIGURES = {"plant": PLANT, "pid": PID, "filter": FILTER}

#: accepted alias -> the figure it names (a plant's earlier names, kept so old specs still load)
ALIASES = {"fn_opamp_hz": "fn_hz", "zeta_opamp": "zeta"}

#: the tolerance band's figures (worst case over the part tolerances): fn and zeta with the corner's
#: op-amp and of the parts alone, and the step figures (see :func:`band_of`)
BAND = ("fn_hz", "zeta", "ideal_fn_hz", "ideal_zeta", *ALIASES, "overshoot_pct", "peak_time_s", "rise_time_s",
        "settling_time_s")
#: the band's figures on a plant of another topology (:func:`circuit_band_of`): fn and zeta, with the
#: corner's op-amp and of the parts alone (its step figures are the models', SPICE's .ac has no step)
SECTION_BAND = ("fn_hz", "zeta", "ideal_fn_hz", "ideal_zeta", *ALIASES)


def unit_of(kind: str, figure: str) -> str:
    """The unit a figure is printed in (none for a deck's measurement)."""
    return FIGURES.get(kind, {}).get(figure, ("",))[0]


def plant_figures(res) -> dict:
    """Every :data:`PLANT` figure of a :class:`~designer.plant.result.PlantResult`.

    Parameters
    ----------
    res : designer.plant.result.PlantResult
        The designed or analysed plant.

    Returns
    -------
    dict
        Figure name -> value.
    """
    a, o = res.analytic, res.analytic_opamp
    out = {"fn_hz": float(o.figures.fn_hz), "zeta": float(o.figures.zeta), "q": float(o.figures.q),
           "ideal_fn_hz": a.figures.fn_hz, "ideal_zeta": a.figures.zeta, "ideal_q": a.figures.q,
           "gain": res.built.gain,
           # the error against the target is the corner's, as fn_hz is
           "fn_error_pct": _float(o.figures.fn_error_pct), "zeta_error_pct": _float(o.figures.zeta_error_pct)}
    out.update({alias: out[name] for alias, name in ALIASES.items()})
    for f in STEP:
        out[f"model_{f}"] = getattr(o.step, f)
        out[f"ideal_{f}"] = getattr(a.step, f)
        out[f] = None if res.spice is None else getattr(res.spice.step, f)
    out["nrms"] = None if res.spice is None else res.spice.nrms
    out["nrms_ideal"] = None if res.spice is None else res.spice.nrms_ideal
    return out


def circuit_plant_figures(res) -> dict:
    """The :data:`PLANT` figures of a plant on another topology
    (:class:`~designer.plant.circuit_design.CircuitPlantResult`): fn, zeta, Q with the corner's
    op-amp and of the parts alone, the gain, the errors and the models' step figures; ``nrms`` and
    ``nrms_ideal`` are its square-wave test's (SPICE's ``.tran`` against the op-amp-aware and the ideal
    model, when it ran); None for what it has not (SPICE's step figures: its .ac sweep has no step).

    Parameters
    ----------
    res : CircuitPlantResult
        The corner's design.

    Returns
    -------
    dict
        Figure -> value or None.
    """
    i, o = res.figures["ideal"], res.figures["opamp"]
    out = {"fn_hz": o["fn_hz"], "zeta": o["zeta"], "q": o["q"], "ideal_fn_hz": i["fn_hz"], "ideal_zeta": i["zeta"],
           "ideal_q": i["q"], "gain": i["gain"], "fn_error_pct": o["fn_error_pct"],
           "zeta_error_pct": o["zeta_error_pct"], "nrms": None if res.square is None else res.square.nrms,
           "nrms_ideal": None if res.square is None else res.square.nrms_ideal}
    out.update({alias: out[name] for alias, name in ALIASES.items()})
    for f in STEP:
        out[f"model_{f}"] = None if res.steps["opamp"] is None else res.steps["opamp"][f]
        out[f"ideal_{f}"] = None if res.steps["ideal"] is None else res.steps["ideal"][f]
        out[f] = None
    return out


def _float(value):
    """A plain float (the model's figures are numpy scalars), None kept."""
    return None if value is None else float(value)


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
    """figure -> (lo, hi) of a plant's tolerance band (:data:`BAND`).

    The band is the worst case over the 16 corners of the Sallen-Key section's
    RC network at +/- its tolerance, the gain pair held
    (:func:`~designer.plant.bench.tolerance_band`). ``fn_hz`` and ``zeta`` (and
    their aliases) follow the corner, as their figures do: the dominant pair of
    the op-amp-aware model at each tolerance corner, with the corner's op-amp,
    computed exactly rather than by scaling the passive band (the op-amp's shift
    itself moves a little with the parts): :func:`corner_band` on the section,
    as a plant on any other section has it (:func:`circuit_band_of`).
    ``ideal_fn_hz`` and ``ideal_zeta`` are the passive band (ideal op-amp).
    The step figures' band is the ideal-op-amp model's, as the build sheet
    prints it.

    Parameters
    ----------
    res : PlantResult
        One corner's plant result (its ``built`` parts, ``opamp`` and ``tolerance``).

    Returns
    -------
    dict
        figure -> (lo, hi); (None, None) where no tolerance corner has the figure.
    """
    if hasattr(res, "section"):
        return circuit_band_of(res)
    # imported here: loading a spec (which reads this module) needs no plant model
    from ..filters.sallen_key_lowpass_parts import part_values, section_of
    t = res.tolerance
    out = {f: (getattr(t, f).lo, getattr(t, f).hi) for f in BAND if hasattr(t, f)}
    out["ideal_fn_hz"], out["ideal_zeta"] = out["fn_hz"], out["zeta"]
    # the corners of the passive band: the RC network at the series' tolerances, the gain pair held
    section = section_of(res.built)
    tol = {p.ref: (t.r_tolerance_pct if p.kind == "R" else t.c_tolerance_pct) / 100 for p in section.parts
           if p.ref not in section.choice_parts}
    # the plant's corner figures take its op-amp model even for the ideal op-amp (its finite A0 and GBW:
    # PlantResult.analytic_opamp), where circuit_figures takes the ideal one's pair: its band does the same
    amp = replace(res.opamp, ideal=False)
    corners = corner_band(section, part_values(res.built), tol, amp)
    out["fn_hz"], out["zeta"] = corners["fn_hz"], corners["zeta"]
    out.update({alias: out[name] for alias, name in ALIASES.items()})
    return out


def circuit_band_of(res) -> dict:
    """figure -> (lo, hi) of :data:`SECTION_BAND` for a plant on a registered section
    (:class:`~designer.plant.circuit_design.CircuitPlantResult`): the worst case over the 2^n corners of
    its n declared parts at +/- their tolerance (the series' own, :func:`designer.tolerance.parts.resolve`,
    as ``--worst-case`` and the Monte Carlo take them), as the Sallen-Key plant's band is over its 16;
    ``fn_hz``, ``zeta`` the op-amp-aware model's dominant pair with the corner's op-amp, ``ideal_*`` the
    parts alone (:func:`designer.plant.circuit.circuit_figures`, vectorised over the corners).

    Parameters
    ----------
    res : CircuitPlantResult
        One corner's plant result.

    Returns
    -------
    dict
        figure -> (lo, hi); (None, None) where no corner has the figure (a first-order section's zeta).
    """
    from ..tolerance.parts import resolve
    s = res.sourcing
    return corner_band(res.section, res.values, resolve((), res.values, {"R": s.r_series, "C": s.c_series}).of,
                       res.opamp)


def corner_band(topology, values: dict, tolerances: dict, opamp) -> dict:
    """figure -> (lo, hi) of :data:`SECTION_BAND` over the 2^n corners of the n parts of ``tolerances``
    at +/- their tolerance, the other parts held: ``fn_hz``, ``zeta`` the op-amp-aware model's dominant
    pair, ``ideal_*`` the parts alone (:func:`designer.plant.circuit.circuit_figures`, every corner at once).

    Parameters
    ----------
    topology : designer.filters.topology.Topology
        The section.
    values : dict
        Designator -> nominal value, every declared part.
    tolerances : dict
        Designator -> tolerance (a fraction) of each part that varies.
    opamp : designer.core.opamps.OpAmp
        The corner's op-amp (the ideal one: the parts' own pair).

    Returns
    -------
    dict
        figure -> (lo, hi); (None, None) where no corner has the figure (a first-order section's zeta).
    """
    import numpy as np

    from ..plant import circuit
    from ..plant.bench import tolerance_corners
    every = tolerance_corners({r: values[r] for r in topology.designators}, tolerances)
    corners = {r: np.array([v[r] for v in every], float) for r in topology.designators}
    figs = circuit.circuit_figures(topology, corners, opamp)
    out = {}
    for f in SECTION_BAND:
        v = np.asarray(figs[ALIASES.get(f, f)], float)
        v = v[np.isfinite(v)]
        out[f] = (float(v.min()), float(v.max())) if v.size else (None, None)
    return out
