"""Identification from a step response: run every method, score, rank, compare.

:func:`identify_step` normalises the capture (:mod:`.preprocess`), runs the
first-order methods (:mod:`.first_order`), the second-order methods of
:mod:`.second_order` when that module is present, and the least-squares
refinements (:mod:`.refine`) started from the best classical estimate of each
structure. Every model is then driven by the real input amplitude and step
time and scored against the data with IAE and ISE; methods are ranked by IAE,
valid ones first, and the best valid one is ``best``.

:func:`compare_with_design` puts the identified plant beside a design-plant
``result.json`` (fn, zeta, gain, overshoot) and says whether the built parts'
tolerances explain the difference.
"""

from __future__ import annotations

import itertools
import math
import time
from dataclasses import dataclass, field

from ..core.errors import DesignError
from ..core.jsonio import json_safe
from ..core.units import format_eng
from .first_order import FIRST_ORDER_METHODS
from .preprocess import PreparedStep, prepare_step
from .refine import refine_all
from .structures import MethodResult, iae_ise, model_step, unphysical

#: Part tolerances assumed when the design's ``built`` has no ``tolerance_band``.
DEFAULT_R_TOL = 0.05
DEFAULT_C_TOL = 0.10
#: Allowance on the static gain for the measurement itself (two scope channels).
GAIN_MEASUREMENT_TOL = 0.02
SECOND_ORDER = ("underdamped", "overdamped", "double-pole")


def second_order_methods() -> list:
    """Part B's ``STEP_METHODS`` when :mod:`.second_order` exists, else []."""
    try:
        from . import second_order  # noqa: PLC0415 - optional sibling module
    except ImportError:
        return []
    return list(getattr(second_order, "STEP_METHODS", []))


def all_step_methods() -> list:
    return list(FIRST_ORDER_METHODS) + second_order_methods()


def _method_name(fn) -> str:
    return getattr(fn, "__name__", "method").replace("_", "-")


def run_method(fn, t, y, yf) -> list:
    """Call one method; never let it crash the run."""
    try:
        out = fn(t, y, yf)
    except Exception as exc:  # noqa: BLE001 - a method bug must not stop the others
        msg = str(exc).splitlines()[0] if str(exc) else type(exc).__name__
        return [MethodResult(name=_method_name(fn), model="fopdt", params={}, valid=False,
                             note=f"method failed: {msg}")]
    if out is None:
        return []
    return list(out) if isinstance(out, (list, tuple)) else [out]


@dataclass
class IdentifyResult:
    """Every method's result, ranked by IAE (valid first), and the best one."""

    methods: list
    best: MethodResult | None
    step: PreparedStep
    capture: dict | None = None
    comparison: dict | None = None
    measured: dict = field(default_factory=dict)
    timings: dict = field(default_factory=dict)

    def best_of(self, models) -> MethodResult | None:
        for m in self.methods:
            if m.valid and m.model in models and math.isfinite(m.iae):
                return m
        return None

    def to_dict(self) -> dict:
        d = {"methods": [m.to_dict() for m in self.methods],
             "best": self.best.to_dict() if self.best else None,
             "preprocessing": self.step.to_dict(),
             "measured": {k: json_safe(v) for k, v in self.measured.items()},
             "timings_s": dict(self.timings)}
        if self.capture is not None:
            d["capture"] = self.capture
        if self.comparison is not None:
            d["comparison"] = self.comparison
        return d

    def to_text(self) -> str:
        s = self.step
        lines = []
        if self.capture:
            lines.append(f"Capture: {self.capture.get('source', '')} ({self.capture.get('format')}, "
                         f"{self.capture.get('samples')} samples, output {self.capture.get('output')!r}"
                         + (f", input {self.capture['input']!r}" if self.capture.get("input") else "")
                         + ")")
        lines.append(f"Step at {format_eng(s.t_step, 's')}, amplitude {s.amplitude:.4g}; "
                     f"baseline y0 = {s.y0:.4g}, final value {s.y_final:.4g}, "
                     f"static gain K = {s.yf:.4g}; noise {_pct(s.sigma, s.y_final - s.y0)} of the step")
        for n in (self.capture or {}).get("notes", []) + s.notes:
            lines.append(f"  note: {n}")
        if self.measured:
            m = self.measured
            lines.append("Measured: overshoot "
                         + (f"{m['overshoot_pct']:.2f} %" if m.get("overshoot_pct") is not None
                            else "n/a")
                         + f", peak time {format_eng(m.get('peak_time_s'), 's')}"
                         + f", rise time (10-90 %) {format_eng(m.get('rise_time_s'), 's')}"
                         + f", settling (2 %) {format_eng(m.get('settling_time_s'), 's')}")
        lines.append("")
        lines.append("Methods ranked by IAE (integral of |data - model| over the response; "
                     "lower is better)")
        head = f"{'#':>2}  {'method':<24} {'model':<12} {'parameters':<52} {'IAE':>10} {'ISE':>10}  ok"
        lines.append(head)
        lines.append("-" * len(head))
        for i, m in enumerate(self.methods, 1):
            lines.append(f"{i:>2}  {m.name:<24} {m.model:<12} {format_params(m.params):<52} "
                         f"{_g(m.iae):>10} {_g(m.ise):>10}  {'yes' if m.valid else 'NO'}")
            if m.note:
                lines.append(f"{'':>4}{m.note}")
        lines.append("")
        lines.append("IAE in output units x s, ISE in output units^2 x s.")
        if self.best:
            lines.append(f"Best: {self.best.name} ({self.best.model}): {format_params(self.best.params)}")
        else:
            lines.append("Best: none of the methods is valid for these data")
        if self.comparison:
            lines.append("")
            lines.extend(comparison_text(self.comparison))
        return "\n".join(lines)


def _g(v):
    return "n/a" if v is None or not math.isfinite(v) else f"{v:.4g}"


def _pct(a, span):
    return f"{100 * a / abs(span):.2g} %" if span else "n/a"


def format_params(p: dict, corners: bool = False) -> str:
    """Parameters with units: K 2, tau 1.5 ms, theta 200 us, wn 2.2e4 rad/s (3.5 kHz), zeta 0.21;
    with ``corners``, each time constant also as the corner frequency a Bode plot shows."""
    out = []
    for k, v in p.items():
        if v is None or (isinstance(v, float) and not math.isfinite(v)):
            out.append(f"{k} n/a")
        elif k.endswith("_rad_s"):
            out.append(f"{k[:-6]} {v:.4g} rad/s ({format_eng(v / (2 * math.pi), 'Hz')})")
        elif corners and k.startswith("tau") and v > 0:
            out.append(f"{k[:-2]} {format_eng(v, 's')} (corner {format_eng(1 / (2 * math.pi * v), 'Hz')})")
        elif k.endswith("_s"):
            out.append(f"{k[:-2]} {format_eng(v, 's')}")
        else:
            out.append(f"{k} {v:.4g}")
    return ", ".join(out)


#: Samples per block when scoring a model: keeps the temporaries of a long
#: record (several per sample) a few MB instead of several times the record.
SCORE_BLOCK = 1 << 17


def _score(m: MethodResult, step: PreparedStep, t_eval, y_eval) -> None:
    """IAE/ISE of a method's model against the data (real amplitude and step time).

    Block by block, each block sharing its last sample with the next one, so
    the sums of the blocks' trapezoid rules are the whole record's."""
    try:
        if not m.params or any(not (isinstance(v, (int, float)) and math.isfinite(v))
                               for v in m.params.values()):
            raise ValueError("no parameters")
        why = unphysical(m.model, m.params)
        if why:
            raise ValueError(f"unstable or non-physical ({why})")
        iae = ise = 0.0
        for a in range(0, max(t_eval.size - 1, 1), SCORE_BLOCK):
            tb = t_eval[a:a + SCORE_BLOCK + 1]
            ym = step.y0 + step.amplitude * model_step(m.model, m.params, tb - step.t_step)
            i1, i2 = iae_ise(tb, y_eval[a:a + SCORE_BLOCK + 1], ym)
            iae, ise = iae + i1, ise + i2
        m.iae, m.ise = iae, ise
    except (ValueError, KeyError, TypeError, ZeroDivisionError, OverflowError) as exc:
        m.iae = m.ise = math.nan
        if m.valid:
            m.valid = False
            m.note = "; ".join(s for s in (m.note, f"model cannot be evaluated: {exc}") if s)


def _score_all(results, step, t_eval, y_eval) -> None:
    """Score every result; long records in two threads (numpy releases the GIL)."""
    if t_eval.size < 200_000 or len(results) < 2:
        for m in results:
            _score(m, step, t_eval, y_eval)
        return
    from concurrent.futures import ThreadPoolExecutor
    with ThreadPoolExecutor(max_workers=2) as ex:
        list(ex.map(lambda m: _score(m, step, t_eval, y_eval), results))


def _rank_key(m):
    iae = m.iae if m.iae is not None and math.isfinite(m.iae) else math.inf
    return (not m.valid, iae)


def identify_step(t, y, u=None, step_time=None, step_amplitude=None, *, methods=None,
                  refine: bool = True, capture: dict | None = None) -> IdentifyResult:
    """Identify plant models from a step response.

    Parameters
    ----------
    t, y : array_like
        Time (s, increasing) and output, as captured.
    u : array_like, optional
        Input; its edges give step time and amplitude (a square wave is split
        into steps and averaged).
    step_time, step_amplitude : float, optional
        When there is no input (see :func:`.preprocess.prepare_step`).
    methods : iterable of str, optional
        Keep only these method names (``least-squares`` for the fits).
    refine : bool
        Run the least-squares refinements (default True).

    Returns
    -------
    IdentifyResult
    """
    want = _check_names(methods)
    clock = time.perf_counter
    t0 = clock()
    step = prepare_step(t, y, u, step_time=step_time, step_amplitude=step_amplitude)
    timings = {"prepare": clock() - t0}
    # Methods assume a rising response; a negative gain is flipped and restored.
    sgn = 1.0 if step.yf >= 0 else -1.0
    tw, yw, yfw = step.t, sgn * step.y, sgn * step.yf
    results = []
    for fn in all_step_methods():
        if want is not None and _method_name(fn) in _KNOWN_FIRST and _method_name(fn) not in want:
            continue
        results.extend(run_method(fn, tw, yw, yfw))
    if want is not None:
        results = [r for r in results if r.name in want]
    timings["methods"] = clock() - t0 - timings["prepare"]
    post = step.t_raw >= step.t_step
    t_eval, y_eval = step.t_raw[post], step.y_raw[post]
    t1 = clock()
    for m in results:
        _flip(m, sgn)
    _score_all(results, step, t_eval, y_eval)
    timings["score"] = clock() - t1
    t1 = clock()
    if refine and (want is None or "least-squares" in want):
        starts = {}
        for model, compatible in (("fopdt", ("fopdt",)), ("overdamped", ("overdamped", "double-pole")),
                                  ("underdamped", ("underdamped",))):
            cands = sorted((m for m in results if m.valid and m.model in compatible
                            and math.isfinite(m.iae)), key=_rank_key)
            if cands:
                c = cands[0]
                starts[model] = MethodResult(c.name, c.model, {k: (sgn * v if k == "K" else v)
                                                               for k, v in c.params.items()})
        fits = refine_all(tw, yw, yfw, starts)
        for m in fits:
            m.note = "; ".join(s for s in (f"started from {starts[m.model].name}"
                                           if m.model in starts else "", m.note) if s)
            _flip(m, sgn)
        _score_all(fits, step, t_eval, y_eval)
        results.extend(fits)
    timings["refine"] = clock() - t1
    results.sort(key=_rank_key)
    best = next((m for m in results if m.valid and math.isfinite(m.iae)), None)
    t1 = clock()
    measured = _measured(step, t_eval, y_eval)
    timings["measure"] = clock() - t1
    timings["total"] = clock() - t0
    return IdentifyResult(methods=results, best=best, step=step, capture=capture,
                          measured=measured, timings=timings)


def _flip(m: MethodResult, sgn: float) -> None:
    if sgn < 0 and "K" in m.params and m.params["K"] is not None:
        m.params["K"] = -m.params["K"]


_KNOWN_FIRST = {_method_name(f) for f in FIRST_ORDER_METHODS}


def known_method_names() -> set:
    """Names accepted by ``--methods``: first-order ones, part B's (by function
    name and by the names their results carry, as far as known) and least-squares."""
    names = set(_KNOWN_FIRST) | {"least-squares"}
    for fn in second_order_methods():
        names.add(_method_name(fn))
        names.update(getattr(fn, "method_names", ()) or ())
    return names


def _check_names(methods):
    if methods is None:
        return None
    want = set()
    for m in methods:
        want.update(x.strip().lower() for x in str(m).split(",") if x.strip())
    if not want:
        raise DesignError("--methods needs at least one method name")
    known = known_method_names()
    unknown = sorted(want - known)
    if unknown:
        raise DesignError(f"unknown method(s) {', '.join(unknown)}; allowed: "
                          f"{', '.join(sorted(known))}")
    return want


def _measured(step: PreparedStep, t_eval, y_eval) -> dict:
    from ..core.metrics import step_metrics
    from .preprocess import block_mean, noise_sigma, smooth_derivative
    if step.sigma > 0 and t_eval.size > 50:
        # Noise spikes would read as overshoot: measure on the smoothed record
        # (block means first, so the filter stays short on long records).
        t_eval, y_eval = block_mean(t_eval, y_eval)
        t_eval, y_eval, _ = smooth_derivative(t_eval, y_eval, sigma=noise_sigma(y_eval),
                                              span=step.y_final - step.y0)
    try:
        sm = step_metrics(t_eval, y_eval, t_step=step.t_step, initial=step.y0,
                          final=step.y_final)
    except DesignError:
        return {}
    d = sm.to_dict()
    return {k: d.get(k) for k in ("overshoot_pct", "peak_time_s", "rise_time_s",
                                  "settling_time_s", "final_value")}


# --------------------------------------------------------------------------- --against

def model_fn_zeta(m: MethodResult) -> tuple:
    """(fn_hz, zeta) of a second-order model; (nan, nan) for FOPDT."""
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
    """Percent overshoot of a standard second-order step response."""
    if not math.isfinite(zeta) or zeta >= 1:
        return 0.0
    return 100.0 * math.exp(-math.pi * zeta / math.sqrt(1 - zeta * zeta))


def sallen_key(r1, r2, c1, c2, k=1.0) -> tuple:
    """(fn_hz, zeta) of the seed's Sallen-Key low-pass (seed 001, fig. 43-45)."""
    a = r1 * r2 * c1 * c2
    b = c1 * (r1 + r2) + r1 * c2 * (1 - k)
    return 1.0 / (2 * math.pi * math.sqrt(a)), b / (2 * math.sqrt(a))


def tolerance_band(built: dict, gain: float = 1.0, r_tol: float = DEFAULT_R_TOL,
                   c_tol: float = DEFAULT_C_TOL) -> dict:
    """Worst-case [lo, hi] of fn, zeta, overshoot and gain over the part tolerances.

    With the built part values (R1_ohm, R2_ohm, C1_f, C2_f) every corner of the
    tolerance box is evaluated (brute force, 2^4 or 2^6 with gain resistors);
    without them the nominal fn and zeta are scaled by the corner factors of
    fn ~ 1/sqrt(R1 R2 C1 C2) and zeta ~ sqrt(C1/C2) (unity gain).
    """
    keys = ("R1_ohm", "R2_ohm", "C1_f", "C2_f")
    fns, zetas, gains = [], [], []
    g_lo, g_hi = gain, gain
    if gain != 1.0:
        # K = 1 + R4/R3 with the same resistor tolerance.
        ratio = gain - 1.0
        g_lo = 1 + ratio * (1 - r_tol) / (1 + r_tol)
        g_hi = 1 + ratio * (1 + r_tol) / (1 - r_tol)
    if all(isinstance(built.get(k), (int, float)) for k in keys):
        r1, r2, c1, c2 = (float(built[k]) for k in keys)
        for s in itertools.product((-1, 1), repeat=4):
            for kk in ((g_lo, g_hi) if gain != 1.0 else (gain,)):
                fn, z = sallen_key(r1 * (1 + s[0] * r_tol), r2 * (1 + s[1] * r_tol),
                                   c1 * (1 + s[2] * c_tol), c2 * (1 + s[3] * c_tol), kk)
                fns.append(fn)
                zetas.append(z)
        basis = "corners of the built parts"
    else:
        fn0, z0 = float(built.get("fn_hz", math.nan)), float(built.get("zeta", math.nan))
        fns = [fn0 / ((1 + r_tol) * (1 + c_tol)), fn0 / ((1 - r_tol) * (1 - c_tol))]
        zetas = [z0 * math.sqrt((1 - c_tol) / (1 + c_tol)), z0 * math.sqrt((1 + c_tol) / (1 - c_tol))]
        basis = "scaling of the nominal fn and zeta"
    # The gain is read as the ratio of two measured signals: allow the
    # measurement's own error (scope channel gain, follower offset) on top.
    gains = [g_lo * (1 - GAIN_MEASUREMENT_TOL), g_hi * (1 + GAIN_MEASUREMENT_TOL)]
    zl, zh = min(zetas), max(zetas)
    return {"fn_hz": [min(fns), max(fns)], "zeta": [zl, zh],
            "overshoot_pct": [overshoot_from_zeta(zh), overshoot_from_zeta(zl)],
            "gain": [min(gains), max(gains)],
            "assumed": {"r_tol": r_tol, "c_tol": c_tol, "basis": basis}}


def _band_from_built(built: dict):
    """``built.tolerance_band`` in any of {key: [lo, hi]} or {key: {lo|min, hi|max}}."""
    tb = built.get("tolerance_band")
    if not isinstance(tb, dict):
        return None
    out = {}
    for k, v in tb.items():
        if isinstance(v, (list, tuple)) and len(v) == 2:
            out[k] = [float(v[0]), float(v[1])]
        elif isinstance(v, dict):
            lo = v.get("lo", v.get("min", v.get("low")))
            hi = v.get("hi", v.get("max", v.get("high")))
            if isinstance(lo, (int, float)) and isinstance(hi, (int, float)):
                out[k] = [float(lo), float(hi)]
    return out or None


def load_design(path) -> dict:
    """Read a design-plant result.json (:func:`designer.core.jsonio.read_result`);
    a clear one-line error if it is not one, or if a value the comparison uses
    is not a finite number where one is needed."""
    from ..core.fileio import shown
    from ..core.jsonio import read_result
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
    for k in ("R1_ohm", "R2_ohm", "C1_f", "C2_f"):
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
    if tb is not None:
        if not isinstance(tb, dict):
            bad("built.tolerance_band", "an object (or absent)")
        for k, v in tb.items():
            if isinstance(v, (list, tuple)) and len(v) == 2 and not all(map(_is_number, v)):
                bad(f"built.tolerance_band.{k}", "two numbers [lo, hi]")
        for k in ("r_tolerance_pct", "c_tolerance_pct"):
            if k in tb and not _is_number(tb[k]):
                bad(f"built.tolerance_band.{k}", "a number")


def compare_with_design(result: IdentifyResult, design: dict) -> dict:
    """Identified plant vs a design-plant result: fn, zeta, gain and overshoot.

    For each quantity: the design (built) value, the identified one, the
    difference in percent, the part-tolerance band and whether the identified
    value lies inside it (tolerances explain the difference) or not.
    """
    built = design["built"]
    spec = design.get("spec", {}) or {}
    gain = float(spec.get("gain", 1.0) or 1.0)
    band = _band_from_built(built)
    if band is not None:
        tb = built["tolerance_band"]
        basis = "built.tolerance_band"
        if "r_tolerance_pct" in tb and "c_tolerance_pct" in tb:
            basis += f" ({tb['r_tolerance_pct']:g} % R / {tb['c_tolerance_pct']:g} % C)"
        computed = tolerance_band(built, gain)
        for k, v in computed.items():
            band.setdefault(k, v)
    else:
        band = tolerance_band(built, gain)
        a = band["assumed"]
        basis = f"assumed {100 * a['r_tol']:g} % R / {100 * a['c_tol']:g} % C ({a['basis']})"
    m2 = result.best_of(("underdamped", "overdamped", "double-pole"))
    fn_id, z_id = model_fn_zeta(m2) if m2 else (math.nan, math.nan)
    meas_os = result.measured.get("overshoot_pct")
    spice = design.get("spice") or {}
    design_os = spice.get("overshoot_pct")
    if design_os is None:
        design_os = overshoot_from_zeta(float(built["zeta"]))
    rows = {}

    def row(key, design_v, ident_v, unit):
        ok = None
        lo, hi = band.get(key, [math.nan, math.nan])
        if ident_v is not None and math.isfinite(ident_v) and math.isfinite(lo):
            ok = bool(lo <= ident_v <= hi)
        diff = None
        if ident_v is not None and design_v and math.isfinite(ident_v):
            diff = 100.0 * (ident_v - design_v) / abs(design_v)
        rows[key] = {"design": design_v, "identified": json_safe(ident_v) if ident_v is not None else None,
                     "difference_pct": diff, "band": [lo, hi], "within_tolerance": ok,
                     "unit": unit}

    row("fn_hz", float(built["fn_hz"]), fn_id, "Hz")
    row("zeta", float(built["zeta"]), z_id, "")
    row("gain", gain, result.step.yf, "")
    row("overshoot_pct", float(design_os), meas_os, "%")
    rows["overshoot_pct"]["note"] = "identified overshoot is measured on the data"
    explained = [v["within_tolerance"] for v in rows.values() if v["within_tolerance"] is not None]
    if not explained:
        verdict = "no second-order quantity could be identified for the comparison"
    elif all(explained):
        verdict = "every difference lies inside the part-tolerance band: tolerances explain it"
    else:
        out = [k for k, v in rows.items() if v["within_tolerance"] is False]
        verdict = (f"{', '.join(out)} outside the part-tolerance band: tolerances alone do not "
                   "explain it (check wiring, op-amp limits, loading and the measurement)")
    return {"model": m2.name + " (" + m2.model + ")" if m2 else None, "tolerance_basis": basis,
            "quantities": rows, "verdict": verdict,
            "spec": {k: spec.get(k) for k in ("fc_hz", "zeta", "gain")}}


def comparison_text(c: dict) -> list:
    lines = [f"Against the design (identified with {c['model'] or 'n/a'}; "
             f"tolerances: {c['tolerance_basis']}):"]
    fmt = {"fn_hz": lambda v: format_eng(v, "Hz"), "zeta": lambda v: f"{v:.4g}",
           "gain": lambda v: f"{v:.4g}", "overshoot_pct": lambda v: f"{v:.2f} %"}
    for k, r in c["quantities"].items():
        f = fmt[k]
        ident = "n/a" if r["identified"] is None else f(r["identified"])
        diff = "" if r["difference_pct"] is None else f" ({r['difference_pct']:+.1f} %)"
        lo, hi = r["band"]
        band = "n/a" if not math.isfinite(lo) else f"{f(lo)} .. {f(hi)}"
        inside = {True: "inside", False: "OUTSIDE", None: "-"}[r["within_tolerance"]]
        lines.append(f"  {k:<14} design {f(r['design']):>12}  identified {ident:>12}{diff}  "
                     f"band {band}  {inside}")
    lines.append(f"  verdict: {c['verdict']}")
    return lines
