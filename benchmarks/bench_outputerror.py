"""Output-error fits (designer.identify.outputerror) of long records: how long
they take, against a floor measured in the same run.

A first-order plant with dead time (K 2, tau 2 s, theta 0.5 s) and a
second-order one (K 1.5, tau 2 s and 0.5 s, theta 0.3 s), sampled every 10 ms
under a random binary input switching with probability 0.02, with 15 dB of
white noise; 10^5 and 10^6 samples. The records are made by
``scipy.signal.cont2discrete`` (zero-order hold, dead times whole samples),
not by the code under test. No decimation: every sample is fitted.

Floor: one ``scipy.signal.lsim`` of the fitted model over the record, times
the number of record simulations the fit used (the solver's evaluations,
its finite-difference Jacobians included): what the same search would cost
with a general-purpose simulator instead of the sampled model run by
``lfilter``. Goals (issue 28): 10^5 samples in under 2 s, 10^6 in under 10 s.

The whole identification (``identify_record``, what ``identify`` runs: the
correlation and spectral routes on the record and on its estimation part,
every output-error fit, the scores) of the SOPDT's 10^6-sample record, against
one ``scipy.signal.lsim`` of the true model over the record, measured in the
same run. Goal: within :data:`WHOLE_RATIO` of that floor, a student's wait of
seconds, not a minute: 1.35 lsims is 10 s at the bench's 7.4 s lsim of
2026-12-03 (722.2 s / 98 evaluations); before the initial-state regressors
were filtered once per evaluation the whole took about 51 s on that machine.
"""

from __future__ import annotations

import statistics
import time

import numpy as np
import scipy.signal as sig

from designer.identify import outputerror as oe

TS = 0.01
PLANTS = {"fopdt": ({"K": 2.0, "tau_s": 2.0, "theta_s": 0.5}, [2.0], [2.0, 1.0]),
          "sopdt": ({"K": 1.5, "tau1_s": 2.0, "tau2_s": 0.5, "theta_s": 0.3}, [1.5], [1.0, 2.5, 1.0])}
GOALS = {100_000: 2.0, 1_000_000: 10.0}
#: the whole identification of 10^6 samples, at most this many lsims of the true model over the record
WHOLE_RATIO = 1.35


def record(kind, n, seed=0):
    """(u, y, true parameters) of one plant under a random binary input."""
    p, num, den = PLANTS[kind]
    rng = np.random.default_rng(seed)
    flips = rng.random(n) < 0.02
    flips[0] = False
    u = 3.0 + 2.0 * (np.cumsum(flips) % 2)
    b, a, _ = sig.cont2discrete((num, den), TS, method="zoh")
    d = int(round(p["theta_s"] / TS))
    y = sig.lfilter(np.squeeze(b), a, u - u[0])
    y = np.concatenate((np.zeros(d), y[:-d])) + 1.0
    y = y + rng.standard_normal(n) * np.std(y) / 10 ** (15 / 20)
    return u, y, p


def lsim_floor(fit, u):
    """Seconds of one lsim of the fitted model's rational part over the record."""
    m = fit.model
    t = np.arange(u.size) * TS
    times = []
    for _ in range(3):
        t0 = time.perf_counter()
        sig.lsim((m.num, m.den), u - u[0], t)
        times.append(time.perf_counter() - t0)
    return statistics.median(times)


def main():
    print("### output-error fit of long records (zero-order hold, initial state: rest)\n")
    print("| plant | samples | fit (s) | goal (s) | evaluations | lsim floor (s) | fit / floor | "
          "largest parameter error | valid |")
    print("|---|---:|---:|---:|---:|---:|---:|---|---|")
    oe.fit_output_error(*record("fopdt", 2000)[:2], TS, "fopdt")   # warm imports
    for n in GOALS:
        for kind in PLANTS:
            u, y, p = record(kind, n)
            t0 = time.perf_counter()
            fit = oe.fit_output_error(u, y, TS, kind)
            dt = time.perf_counter() - t0
            floor = lsim_floor(fit, u) * fit.evaluations
            worst = max(p, key=lambda k: abs(fit.params[k] / p[k] - 1))
            err = f"{worst} {100 * (fit.params[worst] / p[worst] - 1):+.2f} %"
            print(f"| {kind} | {n:,} | {dt:.2f} | {GOALS[n]:.0f} | {fit.evaluations} | {floor:.1f} | "
                  f"{dt / floor:.3f} | {err} | {'yes' if fit.valid else 'no'} |")
    whole()


def whole(n: int = 1_000_000):
    """The whole identify_record of the SOPDT's record against one lsim of the true model."""
    from designer.identify.assess import identify_record
    u, y, p = record("sopdt", n)
    t = np.arange(n) * TS
    _, num, den = PLANTS["sopdt"]
    t0 = time.perf_counter()
    sig.lsim((num, den), u - u[0], t)
    floor = time.perf_counter() - t0
    t0 = time.perf_counter()
    res = identify_record(t, y, u)
    dt = time.perf_counter() - t0
    a = res.assessment
    best = a.candidates[a.best] if a.best is not None else None
    what = (f"best {best.route} {best.kind}, validation fit {best.fit_percent:.2f} %" if best is not None
            else "no valid model")
    ok = dt / floor <= WHOLE_RATIO
    print(f"\n### identify_record of the sopdt's {n:,} samples (every route, every fit, the scores)\n")
    print("| samples | identify (s) | one lsim of the true model (s) | identify / lsim | goal | verdict | best |")
    print("|---:|---:|---:|---:|---:|---|---|")
    print(f"| {n:,} | {dt:.1f} | {floor:.1f} | {dt / floor:.2f} | <= {WHOLE_RATIO} | {'ok' if ok else 'MISSED'} | "
          f"{what} |")


if __name__ == "__main__":
    main()
