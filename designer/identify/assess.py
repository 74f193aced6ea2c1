"""Every route's models judged on data they were not fitted to, and the best
one chosen by that alone.

Routes: ``step`` (the classical step methods and their least-squares fits,
:mod:`.step`), ``correlation`` and ``spectral`` (a broadband input,
:mod:`.broadband`) and ``output-error`` (:mod:`.outputerror`, any input).
Each model is simulated under the recorded input of the validation data
(:func:`designer.identify.outputerror.simulate`: zero-order hold, the dead
time not a whole number of samples) and scored by MATLAB ``compare``'s fit
percentage and the residual tests of ``resid`` (:mod:`.validation`). The best
model is the valid one with the best validation fit across all routes, a
difference within one standard error of the two models' validation losses
being none: among the models so tied with the best fit, the one with the
fewest parameters (:mod:`.ranking`).

Sources: L. Ljung, *System Identification: Theory for the User*, 2nd ed.
(1999), section 16.6 (validation on fresh data, residual analysis) and the
dryer example of section 17.3; MathWorks System Identification Toolbox
``compare`` and ``resid``.

The split (:func:`choose_split`): the estimation part is the first
:data:`ESTIMATION_FRACTION` of the record, the rest validation; for a periodic
sequence whole periods (the first of the estimation part settles the plant,
so it needs two, and validation one); a separate validation record
(``validation``) leaves the whole capture for estimation. A step capture has
one edge, which every step method needs whole: it is scored on the whole
record, and says so.

A model is valid (:func:`judge_candidate`) when its route's own checks passed
(the route's assumptions included: a wrapped impulse response, a drifting
period mean, an input read as white that was not), every parameter's 95 %
interval is narrower than the parameter, and it is a process model
(:mod:`designer.core.process_build`'s ranges).
"""

from __future__ import annotations

import math
from dataclasses import dataclass, field, replace

import numpy as np

from ..core import process_build as pb
from ..core.errors import DesignError, ParamError
from ..core.process import ProcessModel
from .frequency import wide_interval
from .outputerror import fit_output_error, simulate
from .ranking import rank
from .validation import Split, Validation, block_means, validate

__all__ = ["ROUTES", "ESTIMATION_FRACTION", "MAX_SAMPLES", "OE_KINDS", "OE_INITIAL", "Candidate", "Assessment",
           "method_process", "choose_split", "choose_hold", "judge_candidate", "assess", "regular_interval",
           "match_validation", "assess_result", "identify_record"]

#: the routes, in the order the table shows them
ROUTES = ("step", "correlation", "spectral", "output-error")
#: the estimation part's share of one record
ESTIMATION_FRACTION = 2.0 / 3.0
#: records longer than this are block-averaged to it: the output-error fits and the validation scores compare
#: block means of the output with those of the model simulated at the record's own rate
#: (:func:`~.outputerror.fit_output_error`'s and :func:`~.validation.validate`'s ``block``)
MAX_SAMPLES = 20_000
#: the output-error route's model structures
OE_KINDS = ("fopdt", "sopdt", "underdamped", "lead-lag", "integrating")
#: the initial state of each structure's fit (:func:`~.outputerror.fit_output_error`): estimated, but an
#: integrating model's taken from the record's rest (every model is scored from the record's start at rest,
#: and an integrator's unknown balance input, estimated beside its gain, trades off against it: K 0.24 /s
#: with an interval of +-0.34 for 0.30 /s under a random binary input at 10 dB)
OE_INITIAL = {"integrating": "rest"}
#: the two holds' FOPDT fits tie when their rms residuals are this close (relative)
HOLD_TIE = 0.01
#: evenly sampled: every interval within this fraction of the mean one
SPACING_TOLERANCE = 0.01


# --------------------------------------------------------------------------- models

def method_process(model: str, params: dict, ci95: dict | None = None, source: str = "identify") -> ProcessModel:
    """A route's model (stepfit's and identify-freq's names) as a :class:`ProcessModel`.

    Parameters
    ----------
    model : str
        ``fopdt``, ``double-pole``, ``overdamped``, ``underdamped`` (as the
        step and frequency methods name them), ``sopdt`` or ``integrating``
        (K e^(-theta s)/s, :mod:`.integrating`).
    params : dict
        Its parameters (K, tau_s / tau1_s, tau2_s / wn_rad_s, zeta, theta_s).
    ci95 : dict, optional
        95 % half-widths by parameter.
    source : str
        Where it came from.

    Returns
    -------
    ProcessModel

    Raises
    ------
    DesignError
        A model not mapped, or parameters outside the process model's ranges.
    """
    p = {k: float(v) for k, v in params.items() if isinstance(v, (int, float))}
    ci = {k: float(v) for k, v in (ci95 or {}).items() if isinstance(v, (int, float)) and math.isfinite(v)}
    theta = p.get("theta_s", 0.0)
    if model == "fopdt":
        return pb.fopdt(p["K"], p["tau_s"], theta, source=source, ci95=ci or None)
    if model == "double-pole":
        return pb.sopdt(p["K"], p["tau_s"], p["tau_s"], theta, source=source)
    if model in ("overdamped", "sopdt"):
        return pb.sopdt(p["K"], p["tau1_s"], p["tau2_s"], theta, source=source, ci95=ci or None)
    if model == "underdamped":
        if "wn_rad_s" in ci:
            ci["fn_hz"] = ci.pop("wn_rad_s") / (2 * math.pi)
        return pb.underdamped(p["K"], p["wn_rad_s"] / (2 * math.pi), p["zeta"], theta, source=source,
                              ci95=ci or None)
    if model == "integrating":
        return pb.integrating(p["K"], 0.0, theta, source=source, ci95=ci or None)
    raise DesignError(f"model {model!r} is not a process model this route maps")


class _Simulated:
    """A process model as :func:`~.validation.validate` drives it."""

    def __init__(self, model: ProcessModel, ts: float, hold: str = "zoh"):
        self.model, self.ts, self.hold = model, ts, hold

    def response(self, u):
        return simulate(self.model, u, self.ts, self.hold)


@dataclass
class Candidate:
    """One model of one route, judged on validation data.

    Attributes
    ----------
    route : str
        One of :data:`ROUTES`.
    name : str
        The method (``smith``, ``least-squares``, ``asymptotes``, ``oe``...).
    kind : str
        Its structure (``fopdt``, ``overdamped``, ``sopdt``...).
    params : dict
    ci95 : dict
        95 % half-widths (empty for a method without intervals).
    model : ProcessModel or None
    valid : bool
    note : str
        Why not valid ("" when valid).
    validation : Validation or None
        None when it could not be simulated.
    """

    route: str
    name: str
    kind: str
    params: dict
    ci95: dict
    model: ProcessModel | None
    valid: bool
    note: str
    validation: Validation | None = None

    @property
    def fit_percent(self) -> float:
        """The validation fit (nan without a validation)."""
        return self.validation.fit_percent if self.validation is not None else math.nan

    @property
    def label(self) -> str:
        """``route name kind``."""
        return f"{self.route} {self.name} {self.kind}"

    def to_dict(self) -> dict:
        """JSON-ready.

        Returns
        -------
        dict
            Route, method, model, parameters, intervals, validity and the validation.
        """
        return {"route": self.route, "name": self.name, "model": self.kind, "params": dict(self.params),
                "ci95": dict(self.ci95), "valid": self.valid, "note": self.note,
                "process_model": None if self.model is None else self.model.to_dict(),
                "validation": None if self.validation is None else self.validation.to_dict()}


@dataclass
class Assessment:
    """Every route's models scored on validation data.

    Attributes
    ----------
    scope : str
        ``"split"`` (one record, estimation then validation), ``"whole"`` (no
        room for a split: scored on the data fitted) or ``"separate"`` (a
        second record).
    split : Split or None
        Of a split record (samples of the scored, possibly block-averaged, record).
    note : str
        How the data were split, in words.
    sample_time_s : float
        Of the record scored.
    decimated_by : int
        Block means of this many samples (1: none): the output-error fits
        and every candidate's validation compare them with the block means
        of the model simulated at the record's own rate (``sample_time_s``
        is the block means' interval).
    candidates : list of Candidate
    best : int or None
        Index of the best valid candidate: the best validation fit, or among
        those tied with it the one with the fewest parameters (``ranking``).
    skipped : dict
        Route -> why it gave no model.
    output_error : list
        The output-error fits (:class:`~.outputerror.OEFit`).
    hold : str
        The input between samples every model is simulated with (``zoh`` or
        ``foh``): the one under which the output-error FOPDT fits the
        estimation data better (a sequence switching between the scope's
        samples is a ramp to a first-order hold, centred where it switched).
    ranking : str
        Why the best is not the best validation fit ("" when it is): tied
        with it within the margin, fewer parameters (:func:`~.ranking.rank`).
    """

    scope: str
    split: Split | None
    note: str
    sample_time_s: float
    decimated_by: int = 1
    candidates: list = field(default_factory=list)
    best: int | None = None
    skipped: dict = field(default_factory=dict)
    output_error: list = field(default_factory=list)
    hold: str = "zoh"
    view: object | None = None
    ranking: str = ""

    @property
    def best_candidate(self) -> Candidate | None:
        """The best valid candidate, or None."""
        return None if self.best is None else self.candidates[self.best]

    def route_best(self, route: str) -> Candidate | None:
        """The route's candidate with the best validation fit among its valid ones (else its best fit)."""
        own = [c for c in self.candidates if c.route == route and math.isfinite(c.fit_percent)]
        if not own:
            return None
        return max(own, key=lambda c: (c.valid, c.fit_percent))

    def to_dict(self) -> dict:
        """JSON-ready.

        Returns
        -------
        dict
            The split, every candidate, the best, the skipped routes.
        """
        out = {"scope": self.scope, "split": None if self.split is None else self.split.to_dict(),
               "split_note": self.note, "sample_time_s": self.sample_time_s, "decimated_by": self.decimated_by,
               "hold": self.hold, "best": None if self.best_candidate is None else self.best_candidate.to_dict(),
               "skipped": dict(self.skipped), "models": [c.to_dict() for c in self.candidates]}
        if self.ranking:
            # only when a tie decided: a capture whose best is its best fit keeps its JSON as it was
            out["ranking"] = self.ranking
        return out


# --------------------------------------------------------------------------- the record

def regular_interval(t, name: str = "capture") -> float:
    """The sample interval of an evenly sampled record.

    Parameters
    ----------
    t : array_like
        Sample times.
    name : str
        The record's name in messages.

    Returns
    -------
    float

    Raises
    ------
    DesignError
        Fewer than two samples, or intervals differing by more than 1 %.
    """
    t = np.asarray(t, float)
    if t.size < 2:
        raise DesignError(f"{name}: {t.size} sample(s); a record needs two or more")
    ts = float((t[-1] - t[0]) / (t.size - 1))
    d = np.diff(t)
    if not ts > 0 or np.max(np.abs(d - ts)) > SPACING_TOLERANCE * ts:
        raise DesignError(f"{name}: the samples are not evenly spaced (intervals from {d.min():.4g} s to "
                          f"{d.max():.4g} s): validation needs a uniformly sampled record")
    return ts


def match_validation(ts: float, tv, uv, yv, name: str = "validation record") -> tuple:
    """A validation record brought to the capture's sample interval ``ts``.

    Parameters
    ----------
    ts : float
        The capture's interval (s).
    tv, uv, yv : array_like
        The validation record.
    name : str
        Its name in messages.

    Returns
    -------
    tuple of (numpy.ndarray, numpy.ndarray, str)
        Input and output at ``ts``, and how they were resampled ("" when not):
        every k-th sample of a record k times faster, each sample held k times
        for one k times slower.

    Raises
    ------
    DesignError
        An interval that is not a whole multiple or divisor of ``ts``.
    """
    from ..core.units import format_eng as fe
    tv_s = regular_interval(tv, name)
    uv, yv = np.asarray(uv, float), np.asarray(yv, float)
    ratio = ts / tv_s
    for k, faster in ((round(ratio), True), (round(1 / ratio), False)):
        if k >= 1 and abs((ratio if faster else 1 / ratio) - k) <= 1e-3 * k:
            if k == 1:
                return uv, yv, ""
            if faster:
                return uv[::k], yv[::k], f"every {k}th sample of {name} (sampled every {fe(tv_s, 's')})"
            return (np.repeat(uv, k), np.repeat(yv, k),
                    f"each sample of {name} (sampled every {fe(tv_s, 's')}) held {k} times")
    raise DesignError(f"{name} is sampled every {fe(tv_s, 's')}, the capture every {fe(ts, 's')}: not a whole "
                      "multiple of one another (ratio {:.4g}); record it at the capture's rate or a whole "
                      "multiple of it".format(ratio))


def choose_split(n: int, excitation=None, fraction: float = ESTIMATION_FRACTION) -> tuple:
    """Where the estimation part of one record ends, and why.

    Parameters
    ----------
    n : int
        Samples in the record.
    excitation : Excitation or None
        A broadband input (:func:`~.broadband.examine_input`): a sequence is
        split at a whole period; None for a step or square wave.
    fraction : float
        The estimation part's share.

    Returns
    -------
    tuple of (int or None, str)
        The estimation part's length (None: no split, scored on the whole
        record) and a sentence saying so.
    """
    if excitation is None:
        return None, ("a step capture: its edge is needed whole by every step method, so every model is scored "
                      "on the whole record it was fitted to (no room for a split: a second capture of the plant gives fresh data)")
    if excitation.kind in ("noise", "other"):
        k = int(round(fraction * n))
        from .broadband import MIN_SAMPLES
        if k < 2 * MIN_SAMPLES or n - k < MIN_SAMPLES // 2:
            return None, (f"{n} samples: too few to split (estimation needs {2 * MIN_SAMPLES}); scored on the whole "
                          "record it was fitted to")
        return k, (f"estimation samples 0-{k - 1} (the first {100 * fraction:.0f} %), validation {k}-{n - 1}")
    p = excitation.period
    periods = (n - excitation.start) // p + 1     # the first, settling one, included
    est = max(2, int(math.floor(fraction * periods)))
    if periods < 3 or est >= periods:
        return None, (f"{periods} whole period(s) of the sequence: no room for a split (estimation needs two, one "
                      "to settle and one to measure, validation one more); scored on the whole record")
    k = excitation.start + (est - 1) * p
    return k, (f"estimation: the first {est} periods (samples 0-{k - 1}), validation: the next "
               f"{(n - k) // p} whole period(s) (samples {k}-{n - 1})")


# --------------------------------------------------------------------------- judging

def judge_candidate(route: str, m, ts: float, source: str) -> Candidate:
    """A route's :class:`~.structures.MethodResult` as a candidate, its validity
    checked again (intervals narrower than the parameters, a process model).

    Parameters
    ----------
    route : str
    m : MethodResult
    ts : float
        Sample interval it will be simulated at.
    source : str
        The data's name (kept out of the model's ``source``: the JSON of a
        capture is the same whatever its file is called).

    Returns
    -------
    Candidate
        Not yet validated.
    """
    ci = {k[:-5]: float(v) for k, v in m.points.items()
          if k.endswith("_ci95") and isinstance(v, (int, float)) and math.isfinite(v)}
    notes = [m.note] if (not m.valid and m.note) else []
    valid = bool(m.valid)
    wide = wide_interval(m)
    if wide:
        valid = False
        if wide not in m.note:
            notes.append(wide)
    model = None
    try:
        model = method_process(m.model, m.params, ci, f"identify {route} {m.name} {m.model}")
    except (DesignError, KeyError, TypeError, ValueError) as exc:
        valid = False
        notes.append(f"not a process model: {exc}")
    return Candidate(route, m.name, m.model, dict(m.params), ci, model, valid and model is not None,
                     "; ".join(n for n in notes if n))


def _check_settles(c: Candidate, span: float) -> None:
    """A model of the broadband and output-error routes whose dead time plus 2 %
    settling outlasts the estimation record is not valid: the record cannot have
    shown its slow part (a step capture's own methods check their edge)."""
    if c.route == "step" or c.model is None or not c.valid:
        return
    need = c.model.settling_time_s
    if math.isfinite(need) and need > span:
        from ..core.units import format_eng as fe
        c.valid = False
        c.note = "; ".join(n for n in (c.note, f"its dead time plus 2 % settling ({fe(need, 's')}) outlasts the "
                                       f"estimation record ({fe(span, 's')})") if n)


def _score(c: Candidate, ts: float, hold: str, u, y, split: Split | None, how: str = "detrend",
           block: int = 1) -> None:
    """Validate ``c`` on the record ``u``, ``y`` sampled every ``ts`` (block means of ``block`` scored)."""
    if c.model is None:
        return
    try:
        v = validate(_Simulated(c.model, ts, hold), u, y, split, how=how, block=block)
    except (DesignError, ValueError, np.linalg.LinAlgError) as exc:
        c.valid = False
        c.note = "; ".join(n for n in (c.note, f"not simulated: {exc}") if n)
        return
    if not math.isfinite(v.fit_percent):
        c.valid = False
        c.note = "; ".join(n for n in (c.note, "its simulation diverges") if n)
    c.validation = v


def assess(u, y, ts: float, route_results: dict, *, split_at: int | None, note: str,
           validation: tuple | None = None, skipped: dict | None = None, source: str = "capture",
           kinds=OE_KINDS, rest: str = "first") -> Assessment:
    """Fit the output-error models, score every route's models on validation
    data, choose the best.

    Parameters
    ----------
    u, y : array_like
        The whole record (input and output), evenly sampled.
    ts : float
        Its sample interval (s).
    route_results : dict
        Route -> list of :class:`~.structures.MethodResult` estimated on the
        estimation part (the whole record without a split).
    split_at : int or None
        The estimation part's length (:func:`choose_split`); None: no split.
    note : str
        The split in words.
    validation : tuple of (u, y), optional
        A separate validation record at ``ts`` (:func:`match_validation`).
    skipped : dict, optional
        Route -> why it gave no model.
    source : str
        The data's name.
    kinds : sequence of str
        The output-error structures.
    rest : {"first", "fitted"}
        A record scored whole (no split, no separate record): the models start
        at rest at the first input level (a step capture, at rest before its
        edge) or at a rest level fitted to the output (``"fitted"``: a
        sequence or any input that jumped from the operating point to its
        first sample; :func:`~.validation.validate`, ``how="rest"``).

    Returns
    -------
    Assessment

    Raises
    ------
    DesignError
        An input that never moves (nothing to identify), a record too short.
    """
    u = np.asarray(u, float)
    y = np.asarray(y, float)
    if u.shape != y.shape:
        raise DesignError(f"{source}: the input ({u.size} samples) and the output ({y.size}) must have the same "
                          "length")
    if np.ptp(u) == 0:
        raise DesignError(f"{source}: the input never moves: there is nothing to identify (a capture of the "
                          "plant under a step, a sequence or any moving input)")
    k = max(1, int(math.ceil(u.size / MAX_SAMPLES)))
    uu, T = block_means(u, k), ts * k
    vu = vy = None
    if validation is not None:
        vu, vy = (np.asarray(a, float) for a in validation)
    split = None
    full = slice(None)      # the estimation part at the record's own rate, for the output-error fits
    if validation is not None:
        scope = "separate"
        est = slice(None)
    elif split_at is None:
        scope = "whole"
        est = slice(None)
    else:
        scope = "split"
        split = Split(uu.size, max(1, split_at // k))
        est = split.estimation
        full = slice(0, split.n_est * k)
    res = Assessment(scope, split, note + (f"; block means of {k} samples scored" if k > 1 else ""), T, k,
                     skipped=dict(skipped or {}))
    for route, methods in route_results.items():
        for m in methods:
            res.candidates.append(judge_candidate(route, m, T, source))
    # the output-error fits simulate at the record's own rate under its hold and compare block means of the
    # simulation with the output's (fit_output_error's block): fitted on the block means as a record of its
    # own, an SOPDT's dead time under a random binary signal p 0.5 at 10 dB came out 0.950 s and 0.944 s
    # for 0.900 s (blocks of 2 and 3; 0.899 s without): the block means of a held input are a ramp between
    # levels (foh won the hold's tie) and the output's means a moving average the model did not reproduce
    fu, fy = u[full], y[full]
    fits = {}
    for hold in ("zoh", "foh"):
        try:
            fits[hold] = fit_output_error(fu, fy, ts, "fopdt", hold=hold, initial="estimate", block=k)
        except DesignError as exc:
            res.skipped.setdefault("output-error", str(exc))
    if len(fits) == 2:
        # the holds differ by half a sample at most, so the better fit is a start for the other: its own
        # starts can stop in a local minimum of the dead time (an SOPDT under a random binary signal
        # switching with probability 0.5, zoh: theta 5.1 s, rms 0.0742, against foh's 1.59 s, 0.0436),
        # and the hold would then be chosen on the optimiser's luck, not on the data. Taken only when it
        # moves the rms by more than a tie (HOLD_TIE): a smaller gain cannot change the hold
        worse, better = sorted(fits, key=lambda h: -fits[h].rms_residual)
        if fits[worse].rms_residual > (1.0 + HOLD_TIE) * fits[better].rms_residual:
            again = fit_output_error(fu, fy, ts, "fopdt", hold=worse, initial="estimate",
                                     start=fits[better].params, block=k)
            if again.rms_residual < (1.0 - HOLD_TIE) * fits[worse].rms_residual:
                fits[worse] = again
    if fits:
        res.hold = choose_hold(fits, fu)     # the input's own levels, not its block means
    for kind in kinds if fits else ():
        try:
            f = fits[res.hold] if kind == "fopdt" else fit_output_error(
                fu, fy, ts, kind, hold=res.hold, initial=OE_INITIAL.get(kind, "estimate"), block=k)
        except DesignError as exc:
            res.skipped.setdefault("output-error", str(exc))
            continue
        res.output_error.append(f)
        model = None if f.model is None else replace(f.model, source=f"identify output-error oe {kind}")
        c = Candidate("output-error", "oe", kind, dict(f.params), {k2: v for k2, v in f.ci95.items() if v is not None},
                      model, f.valid and model is not None, f.note)
        res.candidates.append(c)
    span = T * (uu[est].size - 1)
    for c in res.candidates:
        _check_settles(c, span)
    # every candidate simulated at the record's own rate, its block means scored (validate's block): the
    # response to the block means of the input is not the block means of the response
    drive = (vu, vy, None) if validation is not None else (u, y, split)
    how = "rest" if scope == "whole" and rest == "fitted" else "detrend"
    if how == "rest":
        res.note += "; each model from rest at the input level that fits the output best"
    for c in res.candidates:
        _score(c, ts, res.hold, *drive, how=how, block=k)
        if c.kind == "integrating" and c.valid and c.fit_percent < 0:
            # its dead time at 0 has no interval to fail: a settling plant's integrator, worse than the mean
            c.valid = False
            c.note = "; ".join(n for n in (c.note, f"its validation fit ({c.fit_percent:.1f} %) is below 0: the "
                                           "output does not follow the input's integral") if n)
    r = rank(res.candidates)
    if r is not None:
        res.best, res.ranking = r.best, r.note
        if r.note:
            c = res.candidates[r.best]
            c.note = "; ".join(n for n in (c.note, r.note) if n)
    return res


def choose_hold(fits: dict, u) -> str:
    """The hold between samples: the one whose FOPDT fits the estimation data
    better, and on a tie (rms residuals within :data:`HOLD_TIE` of each other)
    the one the input's levels say: a two-level input
    (:func:`~.broadband.between_levels`: a step, a square wave, a binary
    sequence) is held between samples (zoh), any other moves between them
    (foh). A clear difference decides alone: a sequence switching between the
    scope's samples is a first-order hold's ramp (seed 003's furnace: foh's
    FOPDT 4.8 times closer). On a tie foh read a held input as a ramp and put
    the dead time half a sample late (an underdamped plant under a random
    binary signal: 0.54 s for 0.49 s, the FOPDT fits 0.2 % apart).

    Parameters
    ----------
    fits : dict
        Hold -> its FOPDT :class:`~.outputerror.OEFit`.
    u : array_like
        The input they were fitted on.

    Returns
    -------
    str
        ``"zoh"`` or ``"foh"``.
    """
    from .broadband import TWO_LEVEL_FRACTION, between_levels
    if len(fits) < 2:
        return next(iter(fits))
    z, f = fits["zoh"].rms_residual, fits["foh"].rms_residual
    if abs(z - f) <= HOLD_TIE * min(z, f):
        return "zoh" if between_levels(u) <= TWO_LEVEL_FRACTION else "foh"
    return "zoh" if z < f else "foh"


# --------------------------------------------------------------------------- a capture's result

def _route_methods(result) -> tuple:
    """(route -> its methods, route -> why it gave none) of an identification result."""
    if not hasattr(result, "excitation"):
        return {"step": list(result.methods)}, {}
    if getattr(result, "ramp", None) is not None:
        # a step capture whose response ramps: the integrating asymptote is the step route's model
        return {"step": [result.ramp]}, {"correlation": "the input is a step", "spectral": "the input is a step"}
    if result.excitation.kind == "other":
        why = next((n for n in result.notes if n.startswith("the correlation and spectral routes: ")),
                   "the input is not a binary sequence or noise")
        return {}, {"step": result.notes[0] if result.notes else "not a step or square wave",
                    "correlation": why, "spectral": why}
    routes, skipped = {}, {}
    for route, r in (("correlation", result.step_result), ("spectral", result.freq_result)):
        if r is not None:
            routes[route] = list(r.methods)
        else:
            why = [n for n in result.notes if route in n or ("step methods" in n and route == "correlation")]
            skipped[route] = why[-1] if why else (f"--method {result.method}" if result.method else "no estimate")
    if result.refused:
        for route in routes:
            skipped.setdefault(route, result.refused)
    return routes, skipped


def assess_result(result, t, u, y, *, validation: tuple | None = None, segment_length: int | None = None,
                  refine: bool = True, methods=None, method=None, name: str = "capture") -> Assessment:
    """Every route of an identification result, plus the output-error fits,
    scored on validation data (module docstring); the routes of a broadband
    capture that can be split are estimated again on its estimation part.

    Parameters
    ----------
    result : IdentifyResult or BroadbandResult
        The identification of the whole record (:func:`~.step.identify_step`,
        :func:`~.broadband.identify_broadband`).
    t, u, y : array_like
        The record it came from (``u`` None: a step of the result's amplitude at its step time).
    validation : tuple of (t, u, y), optional
        A second record of the same plant.
    segment_length, refine, methods, method :
        As :func:`~.broadband.identify_broadband` took them.
    name : str
        The capture's name in messages.

    Returns
    -------
    Assessment

    Raises
    ------
    DesignError
        An unevenly sampled record; a validation record at an interval that
        is not a whole multiple; an input that never moves.
    """
    t = np.asarray(t, float)
    y = np.asarray(y, float)
    if u is None:
        st = result.step
        u = np.where(t >= st.t_step, st.amplitude, 0.0)
    u = np.asarray(u, float)
    ts = regular_interval(t, name)
    vrec, vnote = None, ""
    if validation is not None:
        vu, vy, how = match_validation(ts, *validation)
        vrec = (vu, vy)
        vnote = "validation: the separate record" + (f" ({how})" if how else "") + "; the whole capture estimated"
    routes, skipped = _route_methods(result)
    ex = getattr(result, "excitation", None)
    split_at, note = (None, vnote) if vrec is not None else choose_split(u.size, ex)
    if split_at is not None and ex.kind != "other":
        from .broadband import identify_broadband
        try:
            est = identify_broadband(t[:split_at], y[:split_at], u[:split_at], method=method, refine=refine,
                                     methods=methods, name="the estimation part", segment_length=segment_length)
        except DesignError as exc:
            split_at, note = None, f"no split ({exc}); scored on the whole record"
        else:
            routes, skipped = _route_methods(est)
    if split_at is not None and getattr(result, "ramp", None) is not None:
        # the asymptote again on the estimation part alone: the validation part is fresh data to it too
        from .integrating import step_capture_ramp
        m = step_capture_ramp(t[:split_at], u[:split_at], y[:split_at])
        routes = {"step": [m]} if m is not None else {}
    # a step capture (a ramping one too) rests at its first level before the edge; any other input may have
    # jumped there from the operating point
    step = ex is None or getattr(result, "ramp", None) is not None
    return assess(u, y, ts, routes, split_at=split_at, note=note, validation=vrec, skipped=skipped, source=name,
                  rest="first" if step else "fitted")


def identify_record(t, y, u=None, *, step_time=None, step_amplitude=None, window=None, methods=None,
                    refine: bool = True, method=None, capture=None, name: str = "capture",
                    validation: tuple | None = None, segment_length: int | None = None,
                    step_only_given=(), assess_routes: bool = True):
    """A capture's identification, every route, scored on validation data:
    what ``identify`` prints and ``design-pid --plant-capture`` tunes for.

    Parameters
    ----------
    t, y, u : array_like
        The capture (``u`` None: no input channel).
    step_time, step_amplitude, window, methods, refine :
        As :func:`~.step.identify_step` takes them.
    method : str, optional
        A broadband capture's route (``correlation`` or ``spectral``).
    capture : CaptureInfo, optional
        What was read, kept with the result.
    name : str
        The capture's name in messages.
    validation : tuple of (t, u, y), optional
        A second record of the same plant to score on.
    segment_length : int, optional
        A noise input's Welch segment (samples).
    step_only_given : sequence of str
        The parameters of a step's edge it was given (:data:`designer.identify.spec.STEP_EDGE_ONLY`:
        refused for a broadband capture, named as ``{name}`` markers of a
        :class:`~designer.core.errors.ParamError`).
    assess_routes : bool
        Score the routes (False: the routes alone, as before validation existed).

    Returns
    -------
    IdentifyResult or BroadbandResult
        With ``assessment`` (:class:`Assessment`) when the capture has an input
        channel or a validation record.
    """
    from .broadband import examine_input, identify_broadband, other_input
    from .step import identify_step
    t_all, y_all = np.asarray(t, float), np.asarray(y, float)
    u_all = None if u is None else np.asarray(u, float)
    t, y = t_all, y_all
    if window is not None:
        keep = (t_all >= window[0]) & (t_all <= window[1])
        t, y = t_all[keep], y_all[keep]
        u = None if u is None else u_all[keep]
    result = None
    if u is not None:
        u = np.asarray(u, float)
        if assess_routes and u.size and np.ptp(u) == 0 and step_time is None:
            raise DesignError(f"{name}: the input never moves (it stays at {u[0]:.6g}): there is nothing to "
                              "identify (a capture of the plant under a step, a sequence or any moving input)")
        ex = examine_input(t, u, name=name)
        if ex is not None:
            if step_only_given:
                g = list(step_only_given)
                raise ParamError(f"{', '.join('{%s}' % n for n in g)} {'is' if len(g) == 1 else 'are'} for a "
                                 f"step capture; the input of {name} is broadband ({ex.kind}): drop "
                                 f"{'it' if len(g) == 1 else 'them'}", g)
            try:
                result = identify_broadband(t, y, u, excitation=ex, method=method, refine=refine,
                                            methods=methods, capture=capture, name=name,
                                            segment_length=segment_length)
            except DesignError as exc:
                # a noise input too short for the correlation and spectral estimates (512 samples) still
                # has the output-error route (50); a route asked for by name, or a segment, keeps the refusal
                if ex.kind != "noise" or method is not None or segment_length is not None or not assess_routes:
                    raise
                result = _output_error_only(t, u, f"a noise input ({ex.transitions} transitions) too short for "
                                            "the correlation and spectral routes", capture, routes=str(exc))
        elif segment_length is not None:
            raise DesignError(f"{name}: a segment length is for a broadband (noise or random) input's Welch "
                              "estimate; this capture's input is a step or square wave")
    elif segment_length is not None:
        raise DesignError(f"{name}: a segment length is for a broadband input's Welch estimate; this capture "
                          "has no input channel")
    if result is None and u is not None and step_time is None and assess_routes:
        other = other_input(u)
        if other:
            result = _output_error_only(t, u, other, capture)
    if result is None:
        if step_time is not None and step_amplitude is not None:
            u = u_all = None
        ramps = u is not None and step_time is None and assess_routes
        try:
            result = identify_step(t_all, y_all, u_all, step_time=step_time, step_amplitude=step_amplitude,
                                   methods=methods, refine=refine, capture=capture, window=window)
        except DesignError as exc:
            result = _ramp_result(t, u, y, capture, str(exc)) if ramps else None
            if result is None:
                raise
        else:
            if ramps and result.best is None:
                result = _ramp_result(t, u, y, capture, "no valid model") or result
    if method and not hasattr(result, "excitation"):
        result.step.notes.append(f"--method {method} ignored: the input is not broadband "
                                 "(a step or square wave), identified by the step methods")
    if assess_routes and (u is not None or validation is not None):
        try:
            result.assessment = assess_result(result, t, u, y, validation=validation, segment_length=segment_length,
                                              refine=refine, methods=methods, method=method, name=name)
        except DesignError as exc:
            if validation is not None or hasattr(result, "excitation"):
                raise
            # a step capture the step methods could read (unevenly sampled, say): identified as before
            result.step.notes.append(f"not validated: {exc}")
            return result
        _attach_view(result.assessment, t, u, y, validation)
        explained = (getattr(result, "refused", "") or getattr(getattr(result, "step", None), "nonlinear", "")
                     or getattr(result, "ramp", None) is not None)   # a ramp never settles: no settling to wait for
        # a step capture whose own methods found a valid model from its edge is not "too short" (the step
        # methods check their edge; a gain outside the process model's range, 1.5e-10 V/V in the scale fuzz,
        # leaves no candidate valid for other reasons than the record)
        step_answer = not hasattr(result, "excitation") and getattr(result, "best", None) is not None
        if not explained and not step_answer:
            _check_room(result.assessment, t, name)
    return result


def _attach_view(a: Assessment, t, u, y, validation: tuple | None) -> None:
    """The record ``a`` scored, with its best models on it (a step capture without an input channel: none)."""
    from .recordview import record_view
    if validation is not None:
        ts = regular_interval(t)
        vu, vy, _ = match_validation(ts, *validation)
        a.view = record_view(a, np.arange(vu.size) * ts, vu, vy)
    elif u is not None:
        a.view = record_view(a, t, u, y)


def _output_error_only(t, u, why: str, capture, routes: str = ""):
    """A capture whose input only the output-error route reads (a chirp, a
    knob, a PWM of changing duty, or a noise input too short for the
    correlation and spectral estimates: ``routes``, their refusal): a
    broadband result of kind ``"other"`` without estimates, the routes'
    reasons in its notes."""
    from .broadband import BroadbandResult, other_excitation
    notes = ["the step methods need a step or a square wave, the correlation and spectral routes a binary "
             "sequence or noise: the output-error fit alone"]
    if routes:
        notes = ["the step methods need a step or a square wave: the output-error fit alone",
                 f"the correlation and spectral routes: {routes}"]
    return BroadbandResult(other_excitation(t, u, why), method="output-error", capture=capture, notes=notes)


def _ramp_result(t, u, y, capture, why: str):
    """A step capture whose response ramps (:func:`~.integrating.step_capture_ramp`
    valid: an integrating plant), which the step methods refused or found no
    valid model in (``why``): a broadband result of kind ``"other"`` whose step
    route is the asymptote method, scored with the output-error fits on the
    record's last third; None when the response does not ramp."""
    from .broadband import BroadbandResult, other_excitation
    from .edges import check_samples
    from .integrating import step_capture_ramp
    try:
        check_samples(t, y, u)      # a record no method can use keeps the step methods' refusal
    except DesignError:
        return None
    m = step_capture_ramp(t, u, y)
    if m is None or not m.valid:
        return None
    return BroadbandResult(other_excitation(t, u, "a step whose response ramps without settling (an integrating "
                                                  "plant)"),
                           method="output-error", capture=capture, ramp=m,
                           notes=[f"the step methods: {why}", "the response ramps: the integrating process's "
                                  "asymptote (step route) and the output-error fits, scored on fresh data"])


def _check_room(a: Assessment, t, name: str) -> None:
    """One line when no model is valid and the best-fitting one's dead time
    plus settling outlasts the record: the record is too short to tell."""
    if a.best is not None:
        return
    # an integrating model has no settling to compare: the slowest lag the record shows decides
    scored = [c for c in a.candidates if c.model is not None and math.isfinite(c.fit_percent)
              and not c.kind.startswith("integrating")]
    if not scored:
        return
    c = max(scored, key=lambda c: c.fit_percent)
    need = c.model.settling_time_s      # the dead time included
    span = float(t[-1] - t[0]) if np.size(t) > 1 else 0.0
    if math.isfinite(need) and need > span:
        from ..core.units import format_eng as fe
        raise DesignError(f"{name}: the record ({fe(span, 's')}) is too short for the plant's dead time plus "
                          f"settling ({fe(need, 's')} by the best-fitting model, {c.label}): record at least "
                          f"{fe(2 * need, 's')}")
