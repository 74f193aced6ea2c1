"""Synthetic captures of known plants under any recorded input (issue 28,
Done when): FOPDT, SOPDT with dead time, underdamped (zeta 0.2) and
integrating plants, driven by the library's own excitations
(:mod:`designer.core.excitation`: a random binary signal switching with
probability 0.1 and 0.5, a chirp, a step), simulated by
``scipy.signal.lsim`` of the true transfer function on a grid ten times
finer than the scope's (the dead time a shift of the input, the PWL source
read as simulate-capture's deck reads it), white noise at a stated SNR
(noise power against the clean output's variance) from a recorded seed and
8-bit quantisation over the output's span. :func:`identify_record` (what
``identify`` runs) must give a best model of the true structure with the
gain within 2 %, time constants and dead time within 5 %, zeta within 0.02,
and a validation fit within 1 point of the true model's own fit, computed
with the library's validation function on the same split and hold.

The record is sized as an engineer sizes a capture: the scope's time base
to the plant's dynamics, its sample count to the noise. A first capture of
3001 samples (:data:`POINTS`) spans the case's window: 300 s every 0.1 s
(TS) under a random binary signal or a chirp, 60 s under a single step
(:data:`STEP_WINDOW`: the step at a tenth, then 2.6 times the slowest
plant's dead time plus 2 % settling; the library refuses a record too short
for the model's settling), 30 s for the integrator under any input
(:data:`INTEGRATOR_WINDOW`: 27 dead times, about 30 switches of the random
binary signal p 0.1 at its 0.1 s clock, which stays the same whatever the
sample interval). When the best model's 95 % interval on some parameter is
wider than the issue's tolerance there, by the ratio r (:data:`WIDE`, the
widest ratio measured at the first capture), the case gets
N = 3001 r^2 x 1.2 samples, at most :data:`LONGEST` (100,000, the library's
cap; over a set window rounded to a whole number of samples per 0.1 s, the
random binary clock a multiple of the sample interval as the correlation
route requires): a parameter's interval shrinks like 1/sqrt(N), with the number of
independent input edges or sweep cycles (random inputs and chirps: the
record lengthened at TS, a chirp sweeping the same band more slowly), or
with the samples around each edge at a fixed SNR (a single step, whose one
edge holds all the dead time's information, and the integrator: the window
kept, the sample interval window / (N - 1)). The integrator's window
is short on purpose: the SNR is against the clean output's variance, a
ramp's or a random walk's drift, which grows as the window squared, so a
longer window raises the noise faster than it adds edges (at 300 s its dead
time was 46 % off at 20 dB and no model was valid at 10 dB). Beyond
:data:`~designer.identify.assess.MAX_SAMPLES` (20,000) the assessment fits
and scores block means; the output-error fits simulate the model at the
record's own rate and compare its block means with the output's, so the
means leave the fit unbiased (:func:`test_block_means_leave_the_fit_unbiased`;
fitted on the block means as a record of their own they moved an SOPDT's dead
time under a random binary signal p 0.5 at 10 dB to 0.950 s and 0.944 s for
0.900 s with blocks of 2 and 3 samples). Every candidate's validation, and
the true model's fit here, simulate the model at the record's own rate too and
score the block means of the simulation against the output's
(:func:`test_validation_of_block_means_is_exact`). The SOPDT under a step
at 10 dB would need 409,000 samples over its 60 s, over the cap: at 99,601
it passes, its short lag's interval (+-0.14 s) still wider than its
tolerance. Under a step at 10 dB an FOPDT's best rival is a lead-lag whose
zero mirrors its fast lag, an approximation of dead time that is not valid
(:func:`test_an_all_pass_lead_lag_is_not_a_structure_of_its_own`)."""

import functools
import math

import numpy as np
import pytest
from scipy import signal as sig

from designer.core import process_build as pb
from designer.core.excitation import chirp_input, random_binary_input
from designer.identify.assess import MAX_SAMPLES, identify_record
from designer.identify.outputerror import simulate
from designer.identify.validation import validate

SEED = 28
TS = 0.1            # s, the scope's sample interval
POINTS = 3001       # 300 s
FINE = 10           # simulation points per sample interval
LEVEL = 1.0         # V, the input's high level

# the true plants: (structure the best model must have, its parameters, the process model)
PLANTS = {
    "fopdt": ("fopdt", {"K": 2.0, "tau_s": 5.0, "theta_s": 1.3}),
    "sopdt": ("sopdt", {"K": 1.5, "tau1_s": 4.0, "tau2_s": 1.5, "theta_s": 0.9}),
    "underdamped": ("underdamped", {"K": 1.0, "wn_rad_s": 1.0, "zeta": 0.2, "theta_s": 0.5}),
    "integrating": ("integrating", {"K": 0.3, "theta_s": 1.1}),
}
INPUTS = ("rb0.1", "rb0.5", "chirp", "step")

#: the widest 95 % interval over the issue's tolerance among the best model's parameters at the first capture
#: (POINTS samples over the case's window, seed 28). 300 s: an SOPDT at 10 dB, its short lag (tolerance 0.075 s)
#: the widest under each input. A step's 60 s and an integrator's 30 s: the dead time (tolerance 0.065 s, 0.045 s,
#: 0.025 s and 0.055 s) the widest, but for the SOPDT under a step at 10 dB its short lag (the step route's
#: overdamped least squares, 1.637 s +-0.799 s)
WIDE = {("sopdt", "rb0.1", 10): 0.2028 / 0.075, ("sopdt", "rb0.5", 10): 0.2163 / 0.075,
        ("sopdt", "chirp", 10): 0.3590 / 0.075,
        ("fopdt", "step", 10): 0.1417 / 0.065, ("sopdt", "step", 20): 0.1478 / 0.045,
        ("sopdt", "step", 10): 0.7993 / 0.075, ("underdamped", "step", 10): 0.0432 / 0.025,
        ("integrating", "rb0.1", 10): 0.1666 / 0.055, ("integrating", "rb0.5", 10): 0.1197 / 0.055,
        ("integrating", "chirp", 20): 0.0945 / 0.055, ("integrating", "chirp", 10): 0.3008 / 0.055,
        ("integrating", "step", 20): 0.1142 / 0.055, ("integrating", "step", 10): 0.4126 / 0.055}
#: the margin over the predicted record
MARGIN = 1.2
#: the longest record made (samples): the library's sample cap
LONGEST = 100_000
#: a step's window (s): the step at a tenth, then 54 s, 2.6 times the slowest settling plant's dead time plus 2 %
#: settling (the FOPDT's 20.9 s)
STEP_WINDOW = 60.0
#: an integrator's window (s): 27 dead times, about 30 edges of the random binary signal p 0.1 (a switch a
#: second on average at its 0.1 s clock) and 27 s of ramp under a step
INTEGRATOR_WINDOW = 30.0


def record_points(plant: str, inp: str, snr_db: float) -> int:
    """The record's samples (the module docstring's rule): POINTS, or POINTS
    (interval / tolerance)^2 MARGIN, at most LONGEST."""
    r = WIDE.get((plant, inp, snr_db))
    return POINTS if r is None else min(LONGEST, int(math.ceil(POINTS * r * r * MARGIN)))


def window(plant: str, inp: str) -> float | None:
    """The case's window (s) set by the plant's dynamics, or None: an input
    of many edges, its record lengthened at TS."""
    if PLANTS[plant][0] == "integrating":
        return INTEGRATOR_WINDOW
    return STEP_WINDOW if inp == "step" else None


def capture_design(plant: str, inp: str, snr_db: float) -> tuple:
    """(sample interval, samples) of the case's capture (the module
    docstring's rule): more edges at TS, or a finer interval over the
    window the plant's dynamics set."""
    n = record_points(plant, inp, snr_db)
    w = window(plant, inp)
    if w is None:
        return TS, n
    # a whole number of samples per TS: the random binary signal's clock a multiple of the sample interval
    # (the correlation route refuses any other), the same rounding for every input
    per = round(w / TS)
    n = per * min((LONGEST - 1) // per, math.ceil((n - 1) / per)) + 1
    return w / (n - 1), n


def true_model(plant: str):
    """The plant as a :class:`ProcessModel` (its num, den and dead time)."""
    kind, p = PLANTS[plant]
    if kind == "fopdt":
        return pb.fopdt(p["K"], p["tau_s"], p["theta_s"])
    if kind == "sopdt":
        return pb.sopdt(p["K"], p["tau1_s"], p["tau2_s"], p["theta_s"])
    if kind == "underdamped":
        return pb.underdamped(p["K"], p["wn_rad_s"] / (2 * math.pi), p["zeta"], p["theta_s"])
    return pb.integrating(p["K"], 0.0, p["theta_s"])


def excitation(kind: str, points: int = POINTS, seed: int = SEED, ts: float = TS):
    """The library's input (simulate-capture's ``--input``), as a PWL source:
    a random binary signal clocked at TS whatever the sample interval."""
    duration = ts * (points - 1)
    if kind.startswith("rb"):
        return random_binary_input(float(kind[2:]), TS, LEVEL, duration, points, seed=seed)
    if kind == "chirp":
        return chirp_input(0.005, 1.0, LEVEL, duration, points)
    return None


def capture(plant: str, inp: str, snr_db: float, seed: int = SEED, points: int | None = None) -> tuple:
    """(t, u, y_clean, y): the plant's response sampled as the case's design
    says (``points`` given: that many every TS), noise at ``snr_db`` (seeded)
    and 8-bit quantisation over the output's span."""
    m = true_model(plant)
    ts, points = capture_design(plant, inp, snr_db) if points is None else (TS, points)
    t = np.arange(points) * ts
    tf = np.arange((points - 1) * FINE + 1) * (ts / FINE)
    ex = excitation(inp, points, seed, ts)
    if ex is None:          # a step at a tenth of the record, from 0 V
        def at(x):
            return np.where(x >= t[points // 10], LEVEL, 0.0)
    else:
        at = ex.at
    u = at(t)
    ud = np.where(tf >= m.theta_s, at(tf - m.theta_s), at(0.0 * tf))
    _, yc, _ = sig.lsim((m.num, m.den), ud - ud[0], tf)
    yc = yc[::FINE]
    rng = np.random.default_rng([seed, int(snr_db)])
    y = yc + rng.normal(0.0, math.sqrt(np.var(yc) / 10 ** (snr_db / 10)), yc.size)
    lo, q = y.min(), np.ptp(y) / 255
    y = lo + np.round((y - lo) / q) * q
    return t, u, yc, y


class _True:
    def __init__(self, model, ts, hold):
        self.model, self.ts, self.hold = model, ts, hold

    def response(self, u):
        return simulate(self.model, u, self.ts, self.hold)


#: the cases whose best model another structure's fit came close to (an all-pass lead-lag: its test below)
TIES = [("fopdt", "step", 10)]
#: their captures and identifications, shared by the two tests that read them (one identification each)
_SHARED = {}


def identified(plant: str, inp: str, snr_db: float, seed: int = SEED) -> tuple:
    """(t, u, y, identify_record's result) of the case's capture."""
    key = (plant, inp, snr_db, seed)
    if key in _SHARED:
        return _SHARED[key]
    t, u, _, y = capture(plant, inp, snr_db, seed)
    out = (t, u, y, identify_record(t, y, u, name=f"{plant}/{inp}/{snr_db:g} dB"))
    if (plant, inp, snr_db) in TIES and seed == SEED:
        _SHARED[key] = out
    return out


def run(plant: str, inp: str, snr_db: float, seed: int = SEED) -> dict:
    """identify_record on the capture; the best model and the true model's fit."""
    t, u, y, res = identified(plant, inp, snr_db, seed)
    a = res.assessment
    k = a.decimated_by
    assert k == math.ceil(u.size / MAX_SAMPLES)
    # simulated at the record's own rate, its block means scored (as the assessment scores every candidate)
    # (the capture's own sample interval: a step's and the integrator's are finer than TS)
    truth = validate(_True(true_model(plant), float(t[1] - t[0]), a.hold), u, y, a.split, block=k).fit_percent
    return {"a": a, "best": a.best_candidate, "truth": truth}


def misses(plant: str, best) -> list:
    """What of the issue's tolerances the best model misses ([] when none)."""
    kind, p = PLANTS[plant]
    if best is None:
        return ["no valid model"]
    if best.kind != kind and not (kind == "sopdt" and best.kind == "overdamped"):
        return [f"best is {best.label}, not {kind}"]
    q = dict(best.params)
    out = []
    if kind == "sopdt":     # the two lags in either order
        got, want = sorted((q["tau1_s"], q["tau2_s"])), sorted((p["tau1_s"], p["tau2_s"]))
        q["tau1_s"], q["tau2_s"] = got
        p = dict(p, tau1_s=want[0], tau2_s=want[1])
    for name, want in p.items():
        got = q[name]
        if name == "zeta":
            if abs(got - want) > 0.02:
                out.append(f"zeta {got:.4g} (true {want:g}, allowed +-0.02)")
        elif abs(got - want) > (0.02 if name == "K" else 0.05) * abs(want):
            out.append(f"{name} {got:.4g} (true {want:g}, {100 * (got / want - 1):+.1f} %)")
    return out


# what the data cannot give to the tolerance (measured, seed 28)
# (the best model's validation fit is the true model's to 0.05 point in each: the data cannot tell them apart)
_SAME = "; its fit {} equals the true model's {}"
DATA = {
    # ("sopdt", "rb0.1", 10) passes at its predicted 26,331 samples (blocks of 2): the best is the correlation
    # route's stark-mollenkamp overdamped (K 1.494, lags 3.946 s and 1.532 s, theta 0.897 s), 79.483 % against
    # the true model's 79.493 %, the output-error SOPDT (within the tolerances too) and lead-lag tied with it
    # within one standard error (0.010 and 0.011 point). Its models simulated on the input's block means,
    # the lead-lag came first, 0.0001 point above the SOPDT
    # ("sopdt", "chirp", 10) passes at its predicted 82,512 samples (blocks of 5, foh: the output-error SOPDT, K
    # 1.497, lags 4.011 s and 1.471 s, theta 0.913 s +-0.032 s); at 2000 s, the longest record before the block
    # means were unbiased, its short lag was 1.412 s (-5.9 %, +-0.137 s), theta 0.961 s (+6.8 %)
    # the FOPDT under a step at 10 dB, 17,401 samples over 60 s: the output-error FOPDT, within the tolerances
    # (K 2.012, tau 5.033 s, theta 1.246 s +-0.070 s, -4.2 %); an output-error lead-lag whose zero and second lag
    # are an all-pass pair (tz -0.280 s +-0.204 s, tau2 0.291 s +-0.200 s: Pade's approximation of half a second
    # of delay, its theta 0.703 s) fitted 0.002 point better and ranked first until such a pair made a lead-lag
    # invalid (identify.outputerror.all_pass_pair; test_an_all_pass_lead_lag_is_not_a_structure_of_its_own)
}
# sized by the rule (module docstring) every other single step and every integrating case meets the tolerances:
# the FOPDT, SOPDT and underdamped plants under a step over 60 s at 3001 samples (20 dB) or at 39,001 (the SOPDT
# at 20 dB), 10,801 (the underdamped at 10 dB) and 99,601 (the SOPDT at 10 dB: the cap, 409,000 predicted; its
# short lag 1.470 s, -2.0 %, within the tolerance though its interval +-0.14 s is not), the integrator over 30 s
# at 3001 to 99,901 samples (at 300 s its dead time was 46 % off under a random binary signal p 0.1 at 20 dB, and
# no model was valid at 10 dB: the noise, set against a ramp's spread over 300 s, was 10 times the 30 s record's)


def _case(plant, inp, snr):
    why = DATA.get((plant, inp, snr))
    if why is None:
        return pytest.param(plant, inp, snr, id=f"{plant}-{inp}-{snr}dB")
    return pytest.param(plant, inp, snr, id=f"{plant}-{inp}-{snr}dB", marks=pytest.mark.xfail(reason=why))


CASES = [(plant, inp, snr) for plant in PLANTS for inp in INPUTS for snr in (20, 10)]


@pytest.mark.parametrize("plant, inp, snr_db", [_case(*c) for c in CASES])
def test_best_model_recovers_the_plant(plant, inp, snr_db):
    r = run(plant, inp, snr_db)
    best = r["best"]
    assert not misses(plant, best), (misses(plant, best), r["a"].hold, None if best is None else best.params)
    assert best.fit_percent >= r["truth"] - 1.0, (best.label, best.fit_percent, r["truth"])


@pytest.mark.parametrize("plant, inp, snr_db", TIES)
def test_an_all_pass_lead_lag_is_not_a_structure_of_its_own(plant, inp, snr_db):
    """The FOPDT under a step at 10 dB: an output-error lead-lag fits the
    validation data a little better than the FOPDT, its zero in the right half
    plane mirroring its fast lag within their intervals, (1 - a s)/(1 + a s),
    Pade's approximation of a delay: it is not valid (the note says why), and
    the best is the true structure, within the tolerances. The fit of the true
    structure started at the true parameters ends where the fit from its own
    starts ends (the estimator is not the limit)."""
    from designer.identify.assess import OE_INITIAL
    from designer.identify.outputerror import fit_output_error
    t, u, y, res = identified(plant, inp, snr_db)
    a = res.assessment
    kind, p = PLANTS[plant]
    oe = next(c for c in a.candidates if c.route == "output-error" and c.kind == kind)
    assert oe.valid and not misses(plant, oe), (oe.params, oe.note)
    ll = next(c for c in a.candidates if c.route == "output-error" and c.kind == "lead-lag")
    assert not ll.valid and "all-pass pair" in ll.note and ll.params["tz_s"] < 0
    assert abs(ll.params["tz_s"] + ll.params["tau2_s"]) < math.hypot(ll.ci95["tz_s"], ll.ci95["tau2_s"])
    assert ll.fit_percent > oe.fit_percent and a.best_candidate is oe
    k = a.decimated_by
    est = slice(0, a.split.n_est * k) if a.split is not None else slice(None)
    ue, ye, ts, init = u[est], y[est], a.sample_time_s / k, OE_INITIAL.get(kind, "estimate")
    own = fit_output_error(ue, ye, ts, kind, hold=a.hold, initial=init, block=k)
    from_truth = fit_output_error(ue, ye, ts, kind, hold=a.hold, initial=init, start=p, block=k)
    assert from_truth.rms_residual == pytest.approx(own.rms_residual, rel=1e-6)


@functools.lru_cache(maxsize=2)
def _long_capture(points: int) -> tuple:
    """(t, u, y, assessment) of the SOPDT at 10 dB under a random binary signal
    p 0.5, ``points`` samples (scored on block means)."""
    t, u, _, y = capture("sopdt", "rb0.5", 10, points=points)
    a = identify_record(t, y, u, name=f"sopdt/rb0.5/10 dB, {points} samples").assessment
    return t, u, y, a


def _fit(y, yhat) -> float:
    """MATLAB compare's fit of ``yhat`` to ``y``, each with its mean removed (percent)."""
    y, yhat = y - y.mean(), yhat - yhat.mean()
    return 100.0 * (1.0 - np.linalg.norm(y - yhat) / np.linalg.norm(y))


@pytest.mark.parametrize("points", [40_000, 100_000])
def test_block_means_leave_the_fit_unbiased(points):
    """A record longer than MAX_SAMPLES is fitted on block means (issue 28's
    speed goals), the model simulated at the record's own rate under its hold
    and averaged as the output is: the SOPDT at 10 dB under a random binary
    signal p 0.5 gives, with blocks of 2 and 5 samples, what the fit of every
    sample of the same estimation data gives (each parameter within a third of
    that fit's 95 % interval) and the truth within its own interval, the hold
    chosen on the undecimated input (held: zoh). The block means fitted as a
    record of their own (the former way) put the dead time off by more than
    the full fit's interval (0.952 s and 0.939 s under foh for 0.902 s and
    0.892 s)."""
    from designer.identify.assess import OE_INITIAL
    from designer.identify.outputerror import fit_output_error
    _, u, y, a = _long_capture(points)
    k = math.ceil(points / MAX_SAMPLES)
    assert k > 1 and a.decimated_by == k and a.hold == "zoh"
    fit = next(f for f in a.output_error if f.kind == "sopdt")
    assert fit.block == k and fit.sample_time_s == pytest.approx(TS)
    n = a.split.n_est * k if a.split is not None else points
    initial = OE_INITIAL.get("sopdt", "estimate")
    full = fit_output_error(u[:n], y[:n], TS, "sopdt", hold=a.hold, initial=initial)
    for name, want in PLANTS["sopdt"][1].items():
        assert abs(fit.params[name] - full.params[name]) < full.ci95[name] / 3, (name, fit.params, full.params)
        assert abs(fit.params[name] - want) < fit.ci95[name], (name, fit.params, fit.ci95)
    ub, yb = (x[:n].reshape(-1, k).mean(axis=1) for x in (u, y))
    former = fit_output_error(ub, yb, TS * k, "sopdt", hold="foh", initial=initial)
    assert abs(former.params["theta_s"] - full.params["theta_s"]) > full.ci95["theta_s"]


@pytest.mark.parametrize("points", [40_000, 100_000])
def test_validation_of_block_means_is_exact(points):
    """A record scored on block means: every candidate's validation fit is the
    fit of the block means of its simulation at the record's own rate, under
    the assessment's hold, from the record's start at rest, against the
    output's block means on the validation part (to 1e-9 point). The former
    way, the model simulated on the input's block means at their own interval,
    gave other numbers for every candidate (a held input's block means are
    ramps between its levels, not the input the plant saw): 0.11 to 1.3 points
    off with blocks of 2, 0.009 to 9.0 with blocks of 5."""
    _, u, y, a = _long_capture(points)
    k = a.decimated_by
    assert k == math.ceil(points / MAX_SAMPLES) and k > 1 and a.split is not None
    n = u.size // k * k
    ub, yb = (x[:n].reshape(-1, k).mean(axis=1) for x in (u, y))
    val = a.split.validation
    scored = [c for c in a.candidates if c.validation is not None]
    assert len(scored) >= 5
    former = []
    for c in scored:
        sim = simulate(c.model, u[:n] - u[0], TS, a.hold).reshape(-1, k).mean(axis=1)
        assert c.fit_percent == pytest.approx(_fit(yb[val], sim[val]), abs=1e-9), c.label
        assert c.validation.samples == ub[val].size
        old = simulate(c.model, ub - ub[0], TS * k, a.hold)
        former.append(abs(_fit(yb[val], old[val]) - c.fit_percent))
    # measured: 0.11 to 1.3 points with blocks of 2 (40,000 samples), 0.009 to 9.0 with blocks of 5
    assert min(former) > 1e-3, sorted(former)


def test_a_tie_within_the_margin_goes_to_fewer_parameters():
    """The SOPDT under a step at 10 dB, 300 s (its xfail above): the output-error
    SOPDT has the best validation fit, its FOPDT 0.017 point lower, within one
    standard error of their validation losses' difference: the FOPDT, with a
    parameter fewer, is the best, and the assessment's JSON ("ranking" and the
    best's note) and its validation text say why. A capture whose best is its
    best fit has no "ranking" in its JSON."""
    from designer.identify.ranking import rank
    from designer.identify.report import validation_text
    t, u, _, y = capture("sopdt", "step", 10, points=POINTS)
    a = identify_record(t, y, u, name="sopdt/step/10 dB").assessment
    r = rank(a.candidates)
    best, top = a.best_candidate, a.candidates[r.top]
    assert (best.label, top.label) == ("output-error oe fopdt", "output-error oe sopdt")
    assert 0.0 < top.fit_percent - best.fit_percent <= r.margin
    want = f"tied with output-error oe sopdt within the margin (fit {best.fit_percent:.3f} % against " \
           f"{top.fit_percent:.3f} %"
    assert a.ranking.startswith(want) and a.ranking.endswith("; fewer parameters (3 against 4)")
    d = a.to_dict()
    assert d["ranking"] == a.ranking and a.ranking in d["best"]["note"]
    line = next(x for x in validation_text(a) if x.startswith("Best by validation fit: "))
    assert line.startswith(f"Best by validation fit: output-error oe fopdt, fit {best.fit_percent:.2f} % ({want}")
    t, u, _, y = capture("fopdt", "rb0.5", 20)
    plain = identify_record(t, y, u, name="fopdt/rb0.5/20 dB").assessment
    assert plain.ranking == "" and "ranking" not in plain.to_dict()
