"""The yield a ``check-design`` spec requires (issue 17): the spec's own
``checks:`` limits, named as :mod:`designer.check.figures` names them, counted
on an engine's figures over the builds its ``tolerances:`` allow.

The analytic engine computes the models' figures: where a check limits a SPICE
figure (``overshoot_pct``), the op-amp-aware model's figure stands in for it
(:data:`PLANT`, :data:`LOOP`); a check on a figure no engine computes (``nrms``,
``rise_time_s`` of a plant) is not counted, and the verdict says so. A report-only
check (``fail: false``) is never counted.
"""

from __future__ import annotations

from dataclasses import dataclass

from ..core.units import format_eng
from .loop import LIMITABLE, STANDS_IN
from .stats import Limit

#: check-design's plant figure -> the analytic plant engine's (designer.tolerance.plant.FIGURES)
PLANT = {**{f: f for f in ("fn_hz", "zeta", "q", "ideal_fn_hz", "ideal_zeta", "ideal_q", "gain", "overshoot_pct",
                            "peak_time_s")},
         "fn_opamp_hz": "fn_hz", "zeta_opamp": "zeta", "model_overshoot_pct": "overshoot_pct",
         "model_peak_time_s": "peak_time_s"}
#: check-design's loop figure -> the analytic loop engine's (designer.tolerance.loop.FIGURES)
LOOP = {**{f: f for f in LIMITABLE}, **STANDS_IN}
BY_KIND = {"plant": PLANT, "pid": LOOP}
#: the engines a spec's yield may use (``spice`` comes with the SPICE engine)
ENGINES = ("analytic",)


def counted(kind: str, checks) -> tuple:
    """(the checks the yield counts, the names of those it cannot): failing checks whose figure the
    analytic engine computes, and the others'."""
    table = BY_KIND[kind]
    live = [c for c in checks if c.fail]
    return tuple(c for c in live if c.figure in table), tuple(c.figure for c in live if c.figure not in table)


@dataclass(frozen=True)
class YieldVerdict:
    """A spec's yield on one corner: the Monte Carlo, the limits counted (spec names), its verdict."""

    mc: object                  #: designer.tolerance.montecarlo.MonteCarlo (or the loop's)
    required: float             #: the fraction the spec requires
    names: dict                 #: engine figure -> the spec's name of it
    skipped: tuple              #: the spec's figures not counted

    @property
    def fraction(self) -> float:
        return self.mc.yield_count / self.mc.n

    @property
    def ok(self) -> bool:
        return self.fraction >= self.required

    def losses(self) -> list:
        """(spec figure, builds lost) largest first; a loop's unstable builds as ``stable``."""
        out = [(self.names[k], v["count"]) for k, v in self.mc.failing.items()]
        p = getattr(self.mc, "p_unstable", None)
        if p is not None:
            out.append(("stable", p["count"]))
        return sorted(out, key=lambda kv: -kv[1])

    def corner(self) -> tuple:
        """(build index, {designator: (value, relative deviation)}) of the worst build of the figure that
        loses most (None when every build passes)."""
        lost = self.losses()
        if not lost or not lost[0][1]:
            return None, {}
        fig = lost[0][0]
        mc = self.mc
        if fig == "stable":
            i = mc.unstable_samples[0]
        else:
            engine = next(k for k, v in self.names.items() if v == fig)
            i = mc.failing[engine]["worst"][0]
        return i, {r: (float(mc.values[r][i]), float(mc.values[r][i] / mc.nominal[r] - 1)) for r in mc.values}

    def message(self) -> str:
        """``yield: 91.2 % (...) below min 95 %; fn_hz loses most ...; the corner: build 12, R1 ...``."""
        mc = self.mc
        lo, hi = mc.yield_interval()
        over = ", ".join(dict.fromkeys(self.names.values()))
        text = (f"yield: {100 * self.fraction:.4g} % ({mc.yield_count}/{mc.n} builds; 95 % Wilson interval "
                f"{100 * lo:.4g} % to {100 * hi:.4g} %) {'at or above' if self.ok else 'below'} min "
                f"{100 * self.required:g} % over {over} ({mc.engine} engine, {mc.sampler} sampler, seed {mc.seed}")
        text += ")" if not self.skipped else f"; not counted, no engine figure: {', '.join(self.skipped)})"
        if self.ok:
            return text
        fig, count = self.losses()[0]
        lim = next((lim for lim in mc.limits if self.names[lim.figure] == fig), None)
        where = "unstable" if lim is None else f"outside {lim.window()}"
        i, parts = self.corner()
        corner = ", ".join(f"{r} {format_eng(v, _unit(r), 4)} ({100 * d:+.2f} %)" for r, (v, d) in parts.items())
        return f"{text}; {fig} loses most: {count} builds {where}; the corner (build {i}, its worst): {corner}"


def _unit(ref: str) -> str:
    return "Ohm" if ref.startswith("R") else "F" if ref.startswith("C") else "Hz"


def spec_yield(kind: str, res, checks, required: float, samples: int, seed: int, tol_items=(),
               sampler: str = "random", dist: str = "uniform") -> YieldVerdict:
    """The yield of one corner's design ``res`` (a PlantResult or a PidResult) over ``checks``
    (:class:`designer.check.limits.Limit`, the spec's), required to reach ``required``.

    The spec's tolerance items (``R=1%``) win over the series' defaults, as ``--tol`` does."""
    from .loop import loop_monte_carlo, loop_series
    from .montecarlo import plant_monte_carlo
    use, skipped = counted(kind, checks)
    table = BY_KIND[kind]
    limits = tuple(Limit(table[c.figure], c.min, c.max) for c in use)
    names = {table[c.figure]: c.figure for c in use}
    if kind == "plant":
        s = res.sourcing
        mc = plant_monte_carlo(res.built, {"R": s.r_series, "C": s.c_series}, res.opamp, samples, seed, sampler,
                               dist, tol_items, limits, tighten=False)
    else:
        mc = loop_monte_carlo(res, loop_series(res), samples, seed, sampler, dist, tol_items, limits, tighten=False)
    return YieldVerdict(mc, required, names, skipped)
