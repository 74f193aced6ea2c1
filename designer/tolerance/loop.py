"""The analytic engine for a PID loop around a Sallen-Key plant (issue 17): the
plant's parts and the controller's eighteen vary together, and each sample's
loop as built (op-amp poles, leak, filter: :func:`designer.pid.model.assemble`)
gives whether it is stable, its phase and gain margins, its step figures for
the design's test step, and whether any op-amp leaves its output swing.

One sample at a time (a state-space model per sample, a few milliseconds
each): the loop's figures have no closed form. Sample i is a function of
(seed, i) alone, as for the plant (:mod:`.sampling`).
"""

from __future__ import annotations

import math
from dataclasses import dataclass, fields

import numpy as np

FIGURES = ("stable", "phase_margin_deg", "gain_margin_db", "overshoot_pct", "settling_time_s", "saturated")
#: frequency points of each sample's loop gain (log, from the leak corner / 20 to the op-amp's GBW)
BODE_POINTS = 1500
#: time points of each sample's step
STEP_POINTS = 2001


def loop_parts(result) -> dict:
    """Designator -> nominal value of the loop's parts: the plant's (R1, R2, C1, C2) and the controller's."""
    p, c = result.plant, result.parts
    out = {"R1": p.r1, "R2": p.r2, "C1": p.c1, "C2": p.c2}
    for f in fields(c):
        v = getattr(c, f.name)
        if v is not None:
            out[f.name.upper()] = v
    return out


@dataclass(frozen=True)
class LoopContext:
    """What the loop engine needs of a design-pid result besides the parts (small and
    picklable: it travels with every chunk, :mod:`.runner`)."""

    opamp: object        #: the op-amp of every stage
    step_v: float        #: the design's test step
    edge_s: float        #: its rise time
    t_end: float         #: the step's duration

    @classmethod
    def of(cls, result) -> "LoopContext":
        return cls(result.opamp, float(result.test.amplitude_v), float(result.test.edge_s),
                   float(result.waveforms.t[-1]))


def loop_figures(values: dict, result) -> dict:
    """Every figure of :data:`FIGURES` for each sample (arrays over the samples)."""
    return evaluate(LoopContext.of(result), values)


def evaluate(context: LoopContext, values: dict) -> dict:
    """The engine's chunk function (:mod:`.runner`): every figure of :data:`FIGURES` of each sample."""
    from ..pid import model
    from ..pid.blocks import PidParts
    from ..pid.verify import loop_metrics
    from ..plant.model import plant_tf, plant_tf_opamp
    from ..plant.sallenkey import SallenKeyParts
    amp = context.opamp
    n = next(iter(values.values())).size
    out = {k: np.full(n, np.nan) for k in FIGURES}
    step = context.step_v
    names = [f.name for f in fields(PidParts)]
    t = np.linspace(0.0, context.t_end, STEP_POINTS)
    r = model.reference(t, step, 0.0, context.edge_s)
    for i in range(n):
        plant = SallenKeyParts(values["R1"][i], values["R2"][i], values["C1"][i], values["C2"][i])
        parts = PidParts(**{k: (values[k.upper()][i] if k.upper() in values else None) for k in names})
        pn, pd = plant_tf(plant) if amp.ideal else plant_tf_opamp(plant, amp)
        lm = model.assemble(parts, amp, pn, pd)
        stable = lm.stable()
        out["stable"][i] = float(stable)
        f_lo = min(parts.f_integrator_hz, plant.fn_hz) / 20
        f_hi = max(amp.gbw_hz if not amp.ideal else 0.0, 100 * plant.fn_hz)
        w = 2 * np.pi * np.logspace(math.log10(f_lo), math.log10(f_hi), BODE_POINTS)
        mg = model.margins(w, model.loop_gain(parts, amp, pn, pd, w))
        out["phase_margin_deg"][i], out["gain_margin_db"][i] = mg.phase_margin_deg, mg.gain_margin_db
        if not stable:
            out["saturated"][i] = 1.0
            continue
        waves = lm.simulate(t, r)
        dc = model.dc_gain(lm)
        fig = loop_metrics(t, waves["y"], step * dc)
        out["overshoot_pct"][i], out["settling_time_s"][i] = fig.overshoot_pct, fig.settling_time_s
        if amp.ideal:
            out["saturated"][i] = 0.0
        else:
            peak = max(max(float(np.max(v)), float(v[-1] - np.min(v))) for k, v in waves.items() if k != "y")
            low = min(min(float(np.min(v)), float(v[-1] - np.max(v))) for k, v in waves.items() if k != "y")
            out["saturated"][i] = float(peak > amp.vout_max or low < amp.vout_min)
    return out


def loop_monte_carlo(result, series: dict, n: int, seed: int = 0, sampler: str = "random", dist: str = "uniform",
                     tol_items=(), scale=None):
    """A Monte Carlo of a design-pid result's loop: the probabilities of instability and of
    saturation with their Wilson intervals, and the statistics of the margins and step figures.
    ``scale``: where the samples run (:class:`designer.tolerance.runner.Scale`; default here).

    Returns a :class:`LoopMonteCarlo`."""
    from .parts import resolve
    from .runner import Draw, Runner, Scale
    from .stats import PERCENTILES, wilson
    nominal = loop_parts(result)
    tol = resolve(tol_items, nominal, series)
    values, figs, _ = Runner(scale or Scale()).run(evaluate, LoopContext.of(result),
                                                   Draw(nominal, tol.of, n, seed, sampler, dist))
    unstable = int(np.count_nonzero(figs["stable"] == 0))
    saturated = int(np.count_nonzero(figs["saturated"] == 1))
    stats = {}
    for k in ("phase_margin_deg", "gain_margin_db", "overshoot_pct", "settling_time_s"):
        v = figs[k][np.isfinite(figs[k])]
        stats[k] = None if not v.size else {"mean": float(v.mean()), "std": float(v.std(ddof=1)) if v.size > 1 else 0.0,
                                            "percentiles": {f"{p:g}": float(x) for p, x in
                                                            zip(PERCENTILES, np.percentile(v, PERCENTILES))}}
    summary = {"settings": {"samples": n, "seed": seed, "sampler": sampler, "dist": dist, "engine": "analytic",
                            "tolerances_pct": tol.to_dict()},
               "p_unstable": {"count": unstable, "fraction": unstable / n, "ci95": list(wilson(unstable, n))},
               "p_saturated": {"count": saturated, "fraction": saturated / n, "ci95": list(wilson(saturated, n))},
               "statistics": stats,
               "unstable_samples": [int(i) for i in np.nonzero(figs["stable"] == 0)[0][:5]]}
    return LoopMonteCarlo(summary, values, figs)


class LoopMonteCarlo:
    """A loop's Monte Carlo: its JSON section, the sampled values and figures (for the CSV)."""

    def __init__(self, summary: dict, values: dict, figures: dict):
        self.summary, self.values, self.figures = summary, values, figures

    def to_dict(self) -> dict:
        return self.summary

    def csv_text(self) -> str:
        """One row per sample: its index, every varied part's value, every figure."""
        from .stats import samples_csv
        return samples_csv(self.values, self.figures)

    def summary_lines(self) -> list:
        s = self.summary
        st = s["settings"]
        pu, ps = s["p_unstable"], s["p_saturated"]
        out = [f"Monte Carlo of the loop: {st['samples']} builds ({st['sampler']}, {st['dist']}, seed {st['seed']}), "
               "the plant's and the controller's parts varying together",
               f"  unstable: {100 * pu['fraction']:.2f} % (95 % Wilson {100 * pu['ci95'][0]:.2f}..{100 * pu['ci95'][1]:.2f} %)",
               f"  an op-amp beyond its swing: {100 * ps['fraction']:.2f} % (95 % Wilson "
               f"{100 * ps['ci95'][0]:.2f}..{100 * ps['ci95'][1]:.2f} %)"]
        for k, unit in (("phase_margin_deg", "deg"), ("overshoot_pct", "%")):
            v = s["statistics"].get(k)
            if v:
                p = v["percentiles"]
                out.append(f"  {k}: mean {v['mean']:.4g} {unit}, 2.5..97.5 % {p['2.5']:.4g}..{p['97.5']:.4g} {unit}")
        return out
