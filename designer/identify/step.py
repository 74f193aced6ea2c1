"""Identification from a step response: run every method, score, rank.

:func:`identify_step` normalises the capture (:mod:`.preprocess`), runs the
first-order methods (:mod:`.first_order`) and the second-order ones
(:mod:`.second_order`'s list of :mod:`.underdamped`, :mod:`.overdamped` and
:mod:`.dc_motor`), and the least-squares refinements (:mod:`.refine`)
started from the best classical estimate of each structure. Every model is
then driven by the real input amplitude and step time and scored against the
data with IAE and ISE; methods are ranked by IAE, valid ones first, and the
best valid one is ``best``. The comparison with a design is :mod:`.against`,
the table and the plot :mod:`.report`.
"""

from __future__ import annotations

import math
import time
from dataclasses import dataclass, field

from ..core.errors import DesignError
from ..core.jsonio import json_safe
from ..core.metrics import Overshoot, StepMetrics
from ..core.stepfit import overshoot_mismatch
from .first_order import FIRST_ORDER_METHODS
from .io import CaptureInfo
from .normalise import PreparedStep
from .preprocess import prepare_step
from .refine import refine_all
from .second_order import STEP_METHODS
from .structures import MethodResult, assessment_dict, iae_ise, model_step, rank_key, unphysical

__all__ = ["IdentifyResult", "identify_step", "judge"]

#: Every classical step method, first order then second order.
ALL_STEP_METHODS = list(FIRST_ORDER_METHODS) + list(STEP_METHODS)
#: The measured figures reported (``measured`` in the JSON).
MEASURED_KEYS = ("overshoot_pct", "peak_time_s", "rise_time_s", "rise_time_0_100_s",
                 "settling_time_s", "final_value")


def _method_name(fn) -> str:
    return getattr(fn, "__name__", "method").replace("_", "-")


def run_method(fn, t, y, yf, sigma=None, overshoot: Overshoot | None = None) -> list:
    """Call one method (with the noise ``sigma`` of ``y`` when given, and the
    measured ``overshoot`` for the first-order methods, which check it); never
    let it crash the run."""
    kw = {} if sigma is None else {"sigma": sigma}
    if overshoot is not None and _method_name(fn) in _KNOWN_FIRST:
        kw["overshoot"] = overshoot
    try:
        out = fn(t, y, yf, **kw)
    except Exception as exc:  # noqa: BLE001 - a method bug must not stop the others
        msg = str(exc).splitlines()[0] if str(exc) else type(exc).__name__
        return [MethodResult(name=_method_name(fn), model="fopdt", params={}, valid=False,
                             note=f"method failed: {msg}")]
    if out is None:
        return []
    return list(out) if isinstance(out, (list, tuple)) else [out]


@dataclass
class IdentifyResult:
    """Every method's result, ranked by IAE (valid first), the best one, the
    normalised step, the figures measured on the data (None when the data do
    not allow it) with the overshoot and its uncertainty every validity check
    used (``overshoot``) and, for ``--against``, the comparison with a design
    (an :class:`~.against.Comparison`)."""

    methods: list
    best: MethodResult | None
    step: PreparedStep
    capture: CaptureInfo | None = None
    comparison: object | None = None
    measured: StepMetrics | None = None
    #: seconds per phase, for the benchmarks; not in :meth:`to_dict`, so that the
    #: JSON of a capture is the same on every run (the committed references regenerate byte for byte)
    timings: dict = field(default_factory=dict)
    overshoot: Overshoot | None = None
    #: every route's models scored on validation data (:class:`~.assess.Assessment`), when assessed
    assessment: object | None = None

    def best_of(self, models) -> MethodResult | None:
        """The best valid result whose model is one of ``models``."""
        for m in self.methods:
            if m.valid and m.model in models and math.isfinite(m.iae):
                return m
        return None

    def measured_dict(self) -> dict:
        """The :data:`MEASURED_KEYS` of the measured figures ({} when none)."""
        if self.measured is None:
            return {}
        d = self.measured.to_dict()
        out = {k: d.get(k) for k in MEASURED_KEYS}
        if self.overshoot is not None:
            out["overshoot_sigma_pct"] = self.overshoot.sigma_pct
        return out

    def to_dict(self) -> dict:
        d = {"methods": [m.to_dict() for m in self.methods],
             "best": self.best.to_dict() if self.best else None,
             "preprocessing": self.step.to_dict(),
             "measured": json_safe(self.measured_dict())}
        if self.capture is not None:
            d["capture"] = self.capture.to_dict()
        if self.comparison is not None:
            d["comparison"] = self.comparison.to_dict()
        if self.assessment is not None:
            d.update(assessment_dict(self.assessment))
        return d


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


def identify_step(t, y, u=None, step_time=None, step_amplitude=None, *, methods=None,
                  refine: bool = True, capture: CaptureInfo | None = None,
                  window=None) -> IdentifyResult:
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
    capture : CaptureInfo, optional
        Where the data came from (reported as ``capture``).
    window : (float, float), optional
        Use only the samples between these times (s).

    Returns
    -------
    IdentifyResult
    """
    want = _check_names(methods)
    clock = time.perf_counter
    t0 = clock()
    step = prepare_step(t, y, u, step_time=step_time, step_amplitude=step_amplitude,
                        window=window)
    timings = {"prepare": clock() - t0}
    # Methods assume a rising response; a negative gain is flipped and restored.
    sgn = 1.0 if step.yf >= 0 else -1.0
    tw, yw, yfw = step.t, sgn * step.y, sgn * step.yf
    post = step.t_raw >= step.t_step
    t_eval, y_eval = step.t_raw[post], step.y_raw[post]
    t1 = clock()
    # measured once: the overshoot every validity check below uses
    measured, overshoot = _measured(step, t_eval, y_eval)
    timings["measure"] = clock() - t1
    results = []
    for fn in ALL_STEP_METHODS:
        if want is not None and _method_name(fn) in _KNOWN_FIRST and _method_name(fn) not in want:
            continue
        results.extend(run_method(fn, tw, yw, yfw, step.work_sigma, overshoot))
    if want is not None:
        results = [r for r in results if r.name in want]
    timings["methods"] = clock() - t1 - timings["measure"]
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
                            and math.isfinite(m.iae)), key=rank_key)
            if cands:
                c = cands[0]
                starts[model] = MethodResult(c.name, c.model, {k: (sgn * v if k == "K" else v)
                                                               for k, v in c.params.items()})
        fits = refine_all(tw, yw, yfw, starts, step.work_sigma, overshoot)
        for m in fits:
            m.note = "; ".join(s for s in (f"started from {starts[m.model].name}"
                                           if m.model in starts else "", m.note) if s)
            _flip(m, sgn)
        _score_all(fits, step, t_eval, y_eval)
        results.extend(fits)
    timings["refine"] = clock() - t1
    for m in results:
        judge(m, step, overshoot)
    results.sort(key=rank_key)
    best = next((m for m in results if m.valid and math.isfinite(m.iae)), None)
    timings["total"] = clock() - t0
    return IdentifyResult(methods=results, best=best, step=step, capture=capture,
                          measured=measured, timings=timings, overshoot=overshoot)


#: A least-squares parameter whose 95 % half-width exceeds this fraction of its
#: value is not determined by the data.
MAX_CI_FRACTION = 1.0
_SCALES = ("K", "tau_s", "tau1_s", "tau2_s", "wn_rad_s", "zeta")


def judge(m: MethodResult, step: PreparedStep, overshoot: Overshoot | None = None) -> None:
    """Mark a result invalid (saying why) when the record cannot support it: a
    non-linear record (no linear model is valid), a model whose own overshoot
    the measured ``overshoot`` rules out (:meth:`~designer.core.metrics.Overshoot.differs`:
    a monotonic model on an overshooting record, an underdamped one that rings
    far more or less than the data), a time constant (or 1/wn) below the
    sample interval, or a least-squares parameter whose 95 % confidence
    interval is wider than the value.

    Parameters
    ----------
    m : MethodResult
        Changed in place (``valid``, ``note``).
    step : PreparedStep
        The record it was fitted to.
    overshoot : Overshoot, optional
        The overshoot measured on the record, with its uncertainty.
    """
    if not m.valid:
        return
    why = ""
    if step.nonlinear:
        why = f"not a linear plant's response ({step.nonlinear.split(':')[0]})"
    if not why and overshoot is not None:
        try:
            why = overshoot_mismatch(m.model, m.params, overshoot)
        except (KeyError, ValueError, TypeError):   # a model without a zeta (a failed method's)
            why = ""
    dt = step.dt
    if not why and math.isfinite(dt):
        for k, v in m.params.items():
            tc = 1.0 / v if k == "wn_rad_s" and v else (v if k.startswith("tau") else None)
            if tc is not None and math.isfinite(tc) and tc < dt:
                what = "1/wn" if k == "wn_rad_s" else k[:-2]
                why = (f"{what} = {tc:.3g} s is below the sample interval ({dt:.3g} s): the "
                       "record cannot resolve it"
                       + ("; the fopdt result has this model's real order"
                          if m.model == "overdamped" else ""))
                break
    if not why and m.name == "least-squares":
        for k in _SCALES:
            ci = m.points.get(f"{k}_ci95")
            v = m.params.get(k)
            # an infinite half-width (a direction the data do not determine) too; nan (no interval) passes
            if ci is not None and v and ci > MAX_CI_FRACTION * abs(v):
                why = (f"the 95 % confidence interval of {k} (±{ci:.3g}) is wider than its "
                       f"value ({v:.3g}): not determined by the data")
                break
    if why:
        m.valid = False
        m.note = "; ".join(x for x in (m.note, why) if x)


def _flip(m: MethodResult, sgn: float) -> None:
    if sgn < 0 and "K" in m.params and m.params["K"] is not None:
        m.params["K"] = -m.params["K"]


_KNOWN_FIRST = {_method_name(f) for f in FIRST_ORDER_METHODS}


def known_method_names() -> set:
    """Names accepted by ``--methods``: every classical method and least-squares."""
    return {_method_name(f) for f in ALL_STEP_METHODS} | {"least-squares"}


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


def _measured(step: PreparedStep, t_eval, y_eval) -> tuple:
    """The figures measured on the data and the :class:`~designer.core.metrics.Overshoot`
    every validity check uses, or ``(None, None)`` when the data allow none
    (:func:`designer.core.metrics.measure_step`, on block means of a long record)."""
    from ..core.metrics import measure_step
    from .settle import block_mean
    if step.sigma > 0 and t_eval.size > 50:
        t_eval, y_eval = block_mean(t_eval, y_eval)
    try:
        return measure_step(t_eval, y_eval, t_step=step.t_step, initial=step.y0,
                            final=step.y_final, lsb=step.lsb, sigma=step.sigma)
    except DesignError:
        return None, None
