"""Continuous-time process models fitted by output error to any recorded
input: FOPDT, SOPDT (overdamped), underdamped, integrating (with or
without a lag) and a lead-lag (two lags and a zero), each with a dead time, simulated under the recorded input
exactly and fitted by bounded nonlinear least squares.

Sources: L. Ljung, *System Identification: Theory for the User*, 2nd ed.
(1999): the output-error model structure (section 4.2), sampling a
continuous-time model under a hold (section 2.1 and appendix to chapter 4),
the asymptotic covariance of the prediction-error estimate (section 9.3);
K. J. Astrom and B. Wittenmark, *Computer-Controlled Systems*, 3rd ed.,
section 2.3 (sampling a system with a time delay: the delayed
zero-order-hold input splits each sample interval in two); G. F. Franklin,
J. D. Powell and M. Workman, *Digital Control of Dynamic Systems*, 3rd ed.,
section 6.3 (the triangle, or first-order, hold). MathWorks System
Identification Toolbox: ``procest`` (the process models P1D, P2D, P2DU,
P1DI, their ``InputDelay`` not a whole number of samples, ``InterSample``
'zoh' or 'foh', ``InitialCondition`` 'zero' or 'estimate'), ``tfest`` and
``oe``.

**Simulation.** The model G(s) = N(s)/D(s) e^(-theta s) (strictly proper
N/D, realised as x' = A x + B v, y = C x) is driven by v(t) = u(t - theta),
u the recorded input held between samples. Write theta = (d + f) T with d
whole samples and 0 <= f < 1. Over one sample interval [kT, (k+1)T] the
delayed zero-order-hold input is u[k-d-1] for the first f T and u[k-d] for
the remaining (1-f) T, so, with sigma the time left to (k+1)T,

    x[k+1] = Phi x[k] + Gamma_a u[k-d] + Gamma_b u[k-d-1]
    Phi     = e^(A T)
    Gamma_a = int_0^((1-f)T) e^(A s) ds B
    Gamma_b = e^(A (1-f) T) int_0^(f T) e^(A s) ds B

(Gamma_a + Gamma_b is the ordinary hold's Gamma; f = 0 gives it back, and
f -> 1 gives d + 1 whole samples: the model is continuous in theta). With
the first-order hold u is linear between samples, the delayed input is
linear on each of the two parts, and with I0(L) = int_0^L e^(A s) ds B,
I1(L) = int_0^L e^(A s) s ds B, L2 = (1-f)T, L1 = f T, E2 = e^(A L2):

    x[k+1] = Phi x[k] + G0 u[k-d+1] + G1 u[k-d] + G2 u[k-d-1]
    G0 = (1-f) I0(L2) - I1(L2)/T
    G1 = f I0(L2) + I1(L2)/T + E2 (I0(L1) - I1(L1)/T)
    G2 = E2 I1(L1)/T

All the integrals come from one matrix exponential of
[[A, B, 0], [0, 0, 1], [0, 0, 0]] L per part (Van Loan's block trick). The
sampled model is then one transfer function in z^-1 (denominator the
characteristic polynomial of Phi, numerator from its Markov parameters),
run over the record by ``scipy.signal.lfilter``, a fraction of the time of
``scipy.signal.lsim`` (benchmarks/bench_outputerror.py).

**Initial state.** The record starts at rest at its first input level
(the input before the record, the delay line's content, is u[0]): the model
is simulated on u - u[0] from zero state, plus an output level estimated by
linear least squares (``initial="rest"``). With ``initial="estimate"`` the
free response of the model's states (and, for an integrating model, a drift
from an unknown balance input) are estimated too, linearly, at every
evaluation (variable projection: the nonlinear parameters' intervals then
equal those of the joint problem, Golub and Pereyra 1973).

**Fit.** ``scipy.optimize.least_squares`` (trust-region reflective, physical
bounds, parameters scaled by their start so each moves on the order of 1),
started from an ARX estimate (:func:`~designer.identify.validation.arx_fit`,
with the dead time from a grid over the ARX input delay, then converted to
continuous time), from a second start at half its dead time, and from the
caller's ``start`` when given (a classical method's estimate); the lower cost
wins. The start is fitted on at most :data:`START_SAMPLES` block means of a
long record; the output-error fit itself simulates every sample, and with
``block`` = m > 1 compares means of m consecutive samples of the simulation
with the same means of the output: exact under the record's own hold (the
means' half-block delay and low-pass act on both sides alike; fitting the
block means as a record of their own does not, it turns a held input into
ramps and moved an SOPDT's dead time by half a sample), with m times fewer
residuals. 95 % half-widths from the Jacobian at the optimum,
t(0.975, N - p) sqrt(diag((J^T J)^-1) s^2), s^2 = SSE/(N - p), by
:func:`designer.core.lsq_intervals.half_widths` (columns of very different
lengths scaled first; they assume white output noise: with coloured noise or a
wrong structure they are optimistic). A parameter held at its bound has no interval (a dead time at
0 is a plant without one); any other at a bound makes the model invalid. A
model is valid when the solver converged, no parameter but the dead time
sits at a bound, every interval is narrower than its parameter (the dead
time's exempt but an integrator's, as in the other routes: one reaching 0
says the data show no dead time), and the
process model's own ranges (:mod:`designer.core.process_build`) accept it.
"""

from __future__ import annotations

import math
from dataclasses import dataclass, field

import numpy as np

from ..core import process_build as pb
from ..core.errors import DesignError
from ..core.lsq_intervals import half_widths
from ..core.process import ProcessModel
from .validation import DEFAULT_FRACTION, Split, arx_fit, block_means, split_record, validate

__all__ = ["FIT_KINDS", "HOLDS", "INITIALS", "Sampled", "sample_model", "simulate", "OEFit", "OEResult", "power_of_two",
           "fit_output_error", "identify_output_error", "all_pass_pair"]

#: the model structures fitted, with their parameters (in the solver's order)
FIT_KINDS = {
    "fopdt": ("K", "tau_s", "theta_s"),
    "sopdt": ("K", "tau1_s", "tau2_s", "theta_s"),
    "underdamped": ("K", "wn_rad_s", "zeta", "theta_s"),
    "integrating": ("K", "theta_s"),
    "integrating-lag": ("K", "tau_s", "theta_s"),
    # two lags and a zero, K (tz s + 1)/((tau1 s + 1)(tau2 s + 1)) e^(-theta s): a rational model of low
    # order (tfest's np = 2, nz = 1), as seed 003's furnace (a lead-lag, eq. 2.4.21)
    "lead-lag": ("K", "tau1_s", "tau2_s", "tz_s", "theta_s"),
}
HOLDS = ("zoh", "foh")
INITIALS = ("rest", "estimate")
#: the ARX start is fitted on at most this many samples (block means of longer records)
START_SAMPLES = 5000
#: input delays (samples of the start's record) tried by the ARX start, at most
MAX_START_DELAY = 150
#: the damping ratio's bounds (zeta >= 1 is the SOPDT)
ZETA_BOUNDS = (0.005, 0.999)
#: a time constant below this fraction of the sample interval cannot be seen in the record
MIN_TAU_OF_T = 1e-3


# --------------------------------------------------------------------------- the sampled model

def _rational(kind: str, p: dict) -> tuple:
    """(num, den) in s, highest power first, of the fit kind's rational part."""
    K = p["K"]
    if kind == "fopdt":
        return [K], [p["tau_s"], 1.0]
    if kind == "sopdt":
        t1, t2 = p["tau1_s"], p["tau2_s"]
        return [K], [t1 * t2, t1 + t2, 1.0]
    if kind == "underdamped":
        wn, z = p["wn_rad_s"], p["zeta"]
        return [K * wn * wn], [1.0, 2.0 * z * wn, wn * wn]
    if kind == "integrating":
        return [K], [1.0, 0.0]
    if kind == "integrating-lag":
        return [K], [p["tau_s"], 1.0, 0.0]
    if kind == "lead-lag":
        t1, t2 = p["tau1_s"], p["tau2_s"]
        return [K * p["tz_s"], K], [t1 * t2, t1 + t2, 1.0]

    raise DesignError(f"kind {kind!r} unknown; allowed: {', '.join(FIT_KINDS)}")


def _integrals(A, B, L: float) -> tuple:
    """e^(A L), I0(L) = int_0^L e^(A s) ds B and I1(L) = int_0^L e^(A s) s ds B,
    from one exponential of [[A, B, 0], [0, 0, 1], [0, 0, 0]] L: its last
    column holds int_0^L e^(A s) B (L - s) ds = L I0 - I1."""
    n = A.shape[0]
    M = np.zeros((n + 2, n + 2))
    M[:n, :n] = A
    M[:n, n] = B
    M[n, n + 1] = 1.0
    E = _expm_small(M * L)
    i0 = E[:n, n]
    return E[:n, :n], i0, L * i0 - E[:n, n + 1]


def _expm_small(M) -> np.ndarray:
    """e^M of a small matrix by scaling and squaring a Taylor series: at these
    sizes (at most 5 x 5) a few dozen numpy products, many times faster than
    ``scipy.linalg.expm``'s Pade machinery, which dominated the fit's time.
    After scaling ||M|| <= 1/2, 20 terms leave a remainder below 1e-21."""
    norm = float(np.max(np.sum(np.abs(M), axis=1)))
    k = max(0, int(math.ceil(math.log2(norm))) + 1) if norm > 0 else 0
    X = M / (2.0 ** k)
    E = np.eye(M.shape[0])
    term = np.eye(M.shape[0])
    for i in range(1, 21):
        term = term @ X / i
        E = E + term
    for _ in range(k):
        E = E @ E
    return E


@dataclass(frozen=True)
class Sampled:
    """A process model sampled under a hold: y = (b(z^-1)/a(z^-1)) u, with
    ``b``'s first taps zero for the dead time's whole samples (run it with
    :meth:`run`, or ``scipy.signal.lfilter``).

    Attributes
    ----------
    b, a : numpy.ndarray
        Numerator and denominator in powers of z^-1 (a[0] = 1).
    sample_time_s : float
    hold : str
    """

    b: np.ndarray
    a: np.ndarray
    sample_time_s: float
    hold: str

    def run(self, u) -> np.ndarray:
        """The response from rest to ``u`` (one value per sample).

        Parameters
        ----------
        u : array_like
            Input deviations.

        Returns
        -------
        numpy.ndarray
            ``lfilter(b, a, u)``, computed without the dead time's leading
            zero taps (the output shifted instead): a filter of d + 3 taps
            costs d + 3 multiplications per sample, and the solver may try a
            dead time of half the record.
        """
        from scipy.signal import lfilter
        u = np.asarray(u, float)
        k = int(np.argmax(self.b != 0)) if np.any(self.b != 0) else 0
        y = lfilter(self.b[k:], self.a, u)
        if k == 0:
            return y
        out = np.zeros_like(y)
        if k < y.size:
            out[k:] = y[:y.size - k]
        return out


def power_of_two(x: float) -> float:
    """The power of two nearest ``x`` (1 for 0 or a non-finite ``x``): a scale that divides exactly.

    Parameters
    ----------
    x : float
        A positive size.

    Returns
    -------
    float
        2 ** round(log2 x).
    """
    return 2.0 ** round(math.log2(x)) if x > 0 and math.isfinite(x) else 1.0


def sample_model(num, den, theta_s: float, sample_time_s: float, hold: str = "zoh") -> Sampled:
    """Sample N(s)/D(s) e^(-theta s) exactly under a zero- or first-order hold
    (the equations of the module's notes, dead time not a whole number of samples).

    Parameters
    ----------
    num, den : sequence of float
        The rational part, highest power of s first, strictly proper.
    theta_s : float
        Dead time (s), >= 0.
    sample_time_s : float
        Sample interval T (s).
    hold : {"zoh", "foh"}
        The input between samples: held, or linear between them.

    Returns
    -------
    Sampled
    """
    from scipy.signal import tf2ss
    if hold not in HOLDS:
        raise DesignError(f"hold must be one of {', '.join(HOLDS)}, got {hold!r}")
    T = float(sample_time_s)
    den = np.trim_zeros(np.asarray(den, float), "f")
    num = np.trim_zeros(np.asarray(num, float), "f")
    if num.size >= den.size:
        raise DesignError("an output-error model needs a strictly proper rational part")
    # the numerator's scale out of tf2ss: scipy's normalize reads a numerator of all-tiny coefficients
    # (against a monic denominator: a gain of 1e-9, or 0.015 over time constants of 5e5 s, in the scale
    # fuzz) as badly conditioned and strips them. A power of two: the scaling is exact.
    g = power_of_two(float(np.max(np.abs(num))) / abs(den[0])) if num.size else 1.0
    scaled = num / g
    # and its leading coefficients within 1e-14 of 0 against the monic denominator stripped here, as normalize
    # would strip them, silently: it warned BadCoefficients on an overdamped fit of a record sampled every
    # 1e-10 s (its zero's coefficient 1e-16 of the constant one), the same numbers either way
    keep = np.flatnonzero(np.abs(scaled / den[0]) > 1e-14)
    A, B, C, _ = tf2ss(scaled[min(int(keep[0]) if keep.size else scaled.size - 1, scaled.size - 1):], den)
    B, C = B[:, 0], C[0] * g
    n = A.shape[0]
    d = int(math.floor(theta_s / T + 1e-12))
    f = max(theta_s / T - d, 0.0)
    if f > 1.0 - 1e-12:   # rounding: a whole number of samples
        d, f = d + 1, 0.0
    phi, i0_2, i1_2 = _integrals(A, B, (1.0 - f) * T)
    _, i0_1, i1_1 = _integrals(A, B, f * T)
    if hold == "zoh":
        gammas = (np.zeros(n), i0_2, phi @ i0_1)
    else:
        gammas = ((1.0 - f) * i0_2 - i1_2 / T,
                  f * i0_2 + i1_2 / T + phi @ (i0_1 - i1_1 / T),
                  phi @ i1_1 / T)
    Phi, *_ = _integrals(A, B, T)
    # denominator: the characteristic polynomial of Phi from its eigenvalues
    # e^(p T), accurate even when the poles crowd near z = 1 (slow plant, fast samples)
    poles = np.roots(den)
    a = np.real(np.poly(np.exp(poles * T))) if poles.size else np.ones(1)
    b = np.zeros(n + 2 + d)
    # numerator of C (zI - Phi)^-1 G (in z^-1: taps 1..n) from the Markov parameters
    # h_i = C Phi^(i-1) G: c_i = sum_{m<i} a_m h_(i-m); each G_j then shifted by j + d - 1
    for j, g in enumerate(gammas):
        h = np.empty(n)
        v = g.copy()
        for i in range(n):
            h[i] = C @ v
            v = Phi @ v
        c = np.array([sum(a[m] * h[i - m] for m in range(i + 1)) for i in range(n)])
        b[j + d: j + d + n] += c
    return Sampled(b, a, T, hold)


def simulate(model: ProcessModel, u, sample_time_s: float, hold: str = "zoh") -> np.ndarray:
    """The response of a process model, from rest, to the recorded input ``u``
    (deviations from the rest level), under a hold.

    Parameters
    ----------
    model : ProcessModel
        Any kind but ``rational`` with a non-strictly-proper part.
    u : array_like
        Input deviations, one per sample.
    sample_time_s : float
        Sample interval (s).
    hold : {"zoh", "foh"}

    Returns
    -------
    numpy.ndarray
        The output deviation at each sample.
    """
    return sample_model(model.num, model.den, model.theta_s, sample_time_s, hold).run(u)


# --------------------------------------------------------------------------- one evaluation

#: samples of a free response filtered at a time: the rest is exactly zero once the state underflows
FREE_CHUNK = 1 << 14


#: the smallest normal float
TINY = float(np.finfo(float).tiny)


def _free_response(a: np.ndarray, n: int) -> np.ndarray:
    """The free response of 1/a(z^-1) from the unit state 0 over ``n``
    samples: ``lfilter([1], a, zeros(n), zi=e_0)[0]`` (one filter, its state
    carried from chunk to chunk: the same numbers), but a stable model's
    response stops being filtered once every state is below the smallest
    normal float (the rest is then zeros where the one filter gives
    subnormals, which round to nothing beside any normal value and never
    reach zero: x 0.9975 rounds the smallest subnormal to itself; a pole at
    0.9975, 10^6 samples: stopped after about 300,000)."""
    from scipy.signal import lfilter
    out = np.zeros(n)
    zi = np.zeros(a.size - 1)
    zi[0] = 1.0
    zero = np.zeros(min(FREE_CHUNK, n))
    for j in range(0, n, FREE_CHUNK):
        m = min(FREE_CHUNK, n - j)
        out[j:j + m], zi = lfilter([1.0], a, zero[:m], zi=zi)
        if np.all(np.abs(zi) < TINY):
            break
    return out


def _columns(s: Sampled, n: int, integrating: bool, initial: str, block: int = 1) -> np.ndarray:
    """The linear part's regressors: the output level; with ``initial="estimate"``
    also the free response of each state of 1/a(z^-1) and, for an integrating
    model, the response to a constant input (an unknown balance input); as
    block means of ``block`` samples when ``block`` > 1, each column's means
    taken on its own (a long record's (n, columns) array never built: 10^6
    samples, a quarter of an identification's time went to stacking and
    averaging it). The free response from state i is the one from state 0
    delayed i samples (lfilter's state z^-i / a(z^-1) with no input: the
    first i outputs are exact zeros and the state shifts down unchanged), so
    it is filtered once."""
    rows = n // block
    cols = [np.ones(rows if block > 1 else n)]
    if initial == "estimate":
        free = _free_response(s.a, n)
        for i in range(s.a.size - 1):
            cols.append(block_means(np.concatenate((np.zeros(i), free[:n - i])) if i else free, block))
        if integrating:
            cols.append(block_means(s.run(np.ones(n)), block))
    return np.column_stack(cols)


def _regressors(s: Sampled, ud, integrating: bool, initial: str, block: int) -> tuple:
    """(response, linear part's regressors) of the sampled model over the whole
    record at its own rate, as block means of ``block`` samples when ``block`` > 1:
    the model sees the input the plant saw (its hold, its levels), and the
    output's block means are compared with the same means of the simulation,
    the block's half-sample delay and low-pass on both sides alike."""
    return block_means(s.run(ud), block), _columns(s, ud.size, integrating, initial, block)


def _evaluate(kind: str, p: dict, ud, y, T: float, hold: str, initial: str, block: int = 1) -> tuple:
    """(residual, simulated deviation, linear coefficients) of one parameter set;
    ``y`` holds the output's block means of ``block`` samples of ``ud``'s."""
    num, den = _rational(kind, p)
    s = sample_model(num, den, p["theta_s"], T, hold)
    if initial == "rest":
        sim = s.run(ud)
        if block > 1:
            sim = block_means(sim, block)
        rest = y - sim
        beta = np.array([rest.mean()])
        return rest - beta[0], sim, beta
    sim, X = _regressors(s, ud, kind.startswith("integrating"), initial, block)
    rest = y - sim
    beta, *_ = np.linalg.lstsq(X, rest, rcond=None)
    return rest - X @ beta, sim, beta


# --------------------------------------------------------------------------- the fit result

@dataclass(frozen=True)
class OEFit:
    """One model fitted by output error.

    Attributes
    ----------
    kind : str
        One of :data:`FIT_KINDS`.
    params : dict
        The fitted parameters (s, rad/s, zeta, K), named as :data:`FIT_KINDS`.
    ci95 : dict
        95 % half-widths by parameter; None for one held at a bound.
    model : ProcessModel or None
        The same model as the project's process model (None when its ranges refuse it).
    valid : bool
        Converged, no parameter but theta at a bound, every interval narrower
        than its parameter, accepted by the process model's ranges.
    note : str
        Why not valid ("" when valid).
    sample_time_s, hold, initial : float, str, str
        How it was simulated.
    u_ref : float
        The input's rest level (the record's first sample).
    linear : tuple
        The linearly estimated coefficients: output level first, then (``initial="estimate"``)
        the free responses' and the balance drift's.
    rms_residual : float
        RMS of the output error over the fitted samples (block means when ``block`` > 1).
    samples : int
        Samples fitted (block means when ``block`` > 1).
    evaluations : int
        Simulations of the record the solver used (the Jacobian's included).
    converged : bool
        The solver's own verdict (status > 0).
    block : int
        The output's block means compared (1: every sample), the model
        simulated at ``sample_time_s`` under ``hold`` all the same.
    """

    kind: str
    params: dict
    ci95: dict
    model: ProcessModel | None
    valid: bool
    note: str
    sample_time_s: float
    hold: str
    initial: str
    u_ref: float
    linear: tuple
    rms_residual: float
    samples: int
    evaluations: int
    converged: bool
    block: int = 1

    @property
    def gain(self) -> float:
        """Static gain (velocity gain for an integrating model)."""
        return float(self.params["K"])

    def sampled(self) -> Sampled:
        """The model sampled at the record's interval and hold.

        Returns
        -------
        Sampled
        """
        num, den = _rational(self.kind, self.params)
        return sample_model(num, den, self.params["theta_s"], self.sample_time_s, self.hold)

    def response(self, u) -> np.ndarray:
        """Output deviation from rest under input deviations ``u``.

        Parameters
        ----------
        u : array_like
            Input deviations from the rest level, one per sample.

        Returns
        -------
        numpy.ndarray
            The output deviation at each sample.
        """
        return self.sampled().run(u)

    def simulate(self, u) -> np.ndarray:
        """The output over a record from its start, as fitted.

        Parameters
        ----------
        u : array_like
            The record's input (absolute), at rest at u[0] before it.

        Returns
        -------
        numpy.ndarray
            The estimated output level plus the response to u - u[0] (and,
            with ``initial="estimate"``, the estimated free response).
        """
        u = np.asarray(u, float)
        s = self.sampled()
        X = _columns(s, u.size, self.kind.startswith("integrating"), self.initial)
        return self.response(u - u[0]) + X @ np.asarray(self.linear)

    def to_dict(self) -> dict:
        """JSON-ready.

        Returns
        -------
        dict
            Every attribute, the process model as its own ``to_dict``; ``block``
            only when the fit compared block means (a record's JSON keys stay
            as they were for every other fit).
        """
        out = {"kind": self.kind, "params": dict(self.params), "ci95": dict(self.ci95),
               "model": None if self.model is None else self.model.to_dict(), "valid": self.valid,
               "note": self.note, "sample_time_s": self.sample_time_s, "hold": self.hold,
               "initial": self.initial, "u_ref": self.u_ref, "linear": [float(v) for v in self.linear],
               "rms_residual": self.rms_residual, "samples": self.samples, "evaluations": self.evaluations,
               "converged": self.converged}
        if self.block > 1:
            out["block"] = self.block
        return out


# --------------------------------------------------------------------------- start

def _arx_start(kind: str, ud, y, T: float) -> dict:
    """A start from ARX models (numpy least squares): the input delay from a grid
    (the lowest one-step loss), poles and gain converted to continuous time, the
    fraction of a sample from the two taps' balance."""
    m = max(1, int(math.ceil(ud.size / START_SAMPLES)))
    us, ys, Ts = (block_means(ud, m), block_means(y, m), T * m) if m > 1 else (ud, y, T)
    integ = kind.startswith("integrating")
    if integ:
        # the output follows the input's running integral like a non-integrating
        # plant (integrating the input, not differencing the noisy output);
        # the mean input stands for the unknown balance input (a bounded output
        # needs the input to average to it)
        us = np.cumsum(us - us.mean()) * Ts
    na = {"fopdt": 1, "sopdt": 2, "underdamped": 2, "integrating": 0, "integrating-lag": 1, "lead-lag": 2}[kind]
    top = max(2, min(MAX_START_DELAY, us.size // 10))
    best = None
    for nk in range(1, top):
        arx = arx_fit(us, ys, na, 2, nk)
        if best is None or arx.loss < best.loss:
            best = arx
    nk = best.orders[2]
    taps = best.b[nk:nk + 2]
    frac = float(np.clip(taps[1] / taps.sum(), 0.0, 1.0)) if taps.sum() != 0 else 0.0
    duration = ud.size * T
    p = {"theta_s": max((nk - 1 + frac) * Ts, 0.0)}
    poles = np.roots(best.a) if na else np.array([])
    s = np.log(poles.astype(complex)) / Ts if poles.size else poles
    gain = float(np.sum(best.b) / np.sum(best.a))
    slow = duration / 10

    def tau_of(sp):
        return float(1.0 / -sp.real) if sp.real < 0 and np.isfinite(sp.real) else slow

    p["K"] = gain
    if kind in ("fopdt", "integrating-lag"):
        p["tau_s"] = tau_of(s[0])
    elif kind in ("sopdt", "lead-lag"):
        taus = sorted((tau_of(x) for x in s), reverse=True)
        if abs(s[0].imag) > 0:   # complex ARX poles: a double pole of the same size
            taus = [1.0 / abs(s[0])] * 2
        p["tau1_s"], p["tau2_s"] = taus[0], 0.5 * taus[1] if taus[0] == taus[1] else taus[1]
        if kind == "lead-lag":
            p["K"], p["tz_s"] = _zero_start(p, ud, y, T)
    elif kind == "underdamped":
        if abs(s[0].imag) > 0 and s[0].real < 0:
            wn = float(abs(s[0]))
            p["wn_rad_s"], p["zeta"] = wn, float(np.clip(-s[0].real / wn, 0.05, 0.9))
        else:
            taus = [tau_of(x) for x in s]
            p["wn_rad_s"], p["zeta"] = 1.0 / math.sqrt(taus[0] * taus[1]), 0.7
    return p


#: dead times tried by :func:`_theta_grid_start`'s coarse pass, at most
GRID_THETAS = 200
#: the coarse pass's lowest points refined by a fine one
GRID_REFINED = 3


def _theta_grid_start(kind: str, p0: dict, ud, y, T: float, hold: str, initial: str, top: float,
                      block: int = 1) -> dict:
    """A start with the dead time from a grid and the gain, given it, by linear
    least squares (the response is linear in K, as are the output level and
    the initial state's columns): an integrator's cost in the dead time is
    flat and holds local minima the ARX start falls into (a random binary
    input switching with probability 0.5: theta 5.5 s for 1.1 s). A coarse
    pass over the whole range, then a fine one (half a sample, or a tenth of
    the coarse step when that is longer) around its
    :data:`GRID_REFINED` lowest points: the local minima lie a few tenths of a
    second apart there (0.25, 0.34, 0.5, 0.9, 1.3 s), finer than the coarse
    step (0.5 s), which kept the one at 0.5 s (rms 1.34077) for the lowest at
    0.9 s (1.34041)."""
    num, den = _rational(kind, {**p0, "K": 1.0})

    def cost(th):
        s = sample_model(num, den, th, T, hold)
        X = np.column_stack(_regressors(s, ud, True, initial, block))
        coef, *_ = np.linalg.lstsq(X, y, rcond=None)
        return float(np.sum((y - X @ coef) ** 2)), float(th), float(coef[0])

    step = max(T, top / GRID_THETAS)
    coarse = sorted(cost(th) for th in np.arange(0.0, top, step))
    fine = max(0.5 * T, step / 10)      # half a sample, but at most 20 points around each
    best = coarse[0]
    for _, th0, _ in coarse[:GRID_REFINED]:
        for th in np.arange(max(th0 - step, 0.0), min(th0 + step, top), fine):
            best = min(best, cost(th))
    _, th, k = best
    return {**p0, "theta_s": th, "K": k if k != 0 else p0["K"]}


def _zero_start(p: dict, ud, y, T: float) -> tuple:
    """(K, tz) of K (tz s + 1)/D(s) for the start's poles and dead time: the
    output is linear in K and K tz (the responses of 1/D and s/D), so one
    linear least squares, with an output level, gives both."""
    den = [p["tau1_s"] * p["tau2_s"], p["tau1_s"] + p["tau2_s"], 1.0]
    a = sample_model([1.0], den, p["theta_s"], T).run(ud)
    b = sample_model([1.0, 0.0], den, p["theta_s"], T).run(ud)
    X = np.column_stack((a, b, np.ones(ud.size)))
    (k, ktz, _), *_ = np.linalg.lstsq(X, y, rcond=None)
    if not (np.isfinite(k) and k != 0 and np.isfinite(ktz)):
        return float(p["K"]), 0.5 * p["tau1_s"]
    return float(k), float(ktz / k)


def _bounds(kind: str, T: float, duration: float) -> dict:
    lo_tau, hi_tau = MIN_TAU_OF_T * T, 10.0 * duration
    return {"K": (-np.inf, np.inf), "tau_s": (lo_tau, hi_tau), "tau1_s": (lo_tau, hi_tau),
            "tau2_s": (lo_tau, hi_tau), "tz_s": (-hi_tau, hi_tau), "wn_rad_s": (1.0 / hi_tau, math.pi / T), "zeta": ZETA_BOUNDS,
            "theta_s": (0.0, 0.5 * duration)}


# --------------------------------------------------------------------------- the fit

def fit_output_error(u, y, sample_time_s: float, kind: str = "fopdt", *, hold: str = "zoh",
                     initial: str = "rest", start: dict | None = None, block: int = 1) -> OEFit:
    """Fit one continuous-time model to a record by output error.

    Parameters
    ----------
    u, y : array_like
        Recorded input and output, one pair per sample, equally spaced.
    sample_time_s : float
        Sample interval (s).
    kind : str
        One of :data:`FIT_KINDS`.
    hold : {"zoh", "foh"}
        The input between samples.
    initial : {"rest", "estimate"}
        The record starts at rest at u[0] (its output level estimated), or
        its initial state is estimated too (see the module's notes).
    start : dict, optional
        A start (parameters named as :data:`FIT_KINDS`), e.g. a classical
        method's estimate, tried beside the ARX start.
    block : int
        Compare means of this many consecutive samples (1: every sample; a
        trailing partial block is dropped). The model is still simulated at
        the record's own rate under ``hold``, and its block means compared
        with the output's: exact (no bias from the averaging), and a long
        record's residual and Jacobian hold ``block`` times fewer rows.

    Returns
    -------
    OEFit

    Raises
    ------
    DesignError
        Input and output of different lengths, a non-finite sample, an input
        that never moves, a record too short, an unknown kind, hold or initial,
        a block that is not a whole number of samples from 1 up.
    """
    from scipy.optimize import least_squares
    if kind not in FIT_KINDS:
        raise DesignError(f"kind {kind!r} unknown; allowed: {', '.join(FIT_KINDS)}")
    if initial not in INITIALS:
        raise DesignError(f"initial must be one of {', '.join(INITIALS)}, got {initial!r}")
    if hold not in HOLDS:
        raise DesignError(f"hold must be one of {', '.join(HOLDS)}, got {hold!r}")
    u = np.asarray(u, float)
    y = np.asarray(y, float)
    T = float(sample_time_s)
    if u.shape != y.shape or u.ndim != 1:
        raise DesignError(f"input and output must be one-dimensional and the same length, got {u.shape} "
                          f"and {y.shape}")
    if not (T > 0 and math.isfinite(T)):
        raise DesignError(f"sample_time_s must be a positive number, got {sample_time_s}")
    if not (np.all(np.isfinite(u)) and np.all(np.isfinite(y))):
        raise DesignError("the record holds a sample that is not a finite number")
    if isinstance(block, bool) or not isinstance(block, (int, np.integer)) or block < 1:
        raise DesignError(f"block must be a whole number of samples, 1 or more, got {block!r}")
    block = int(block)
    u, y = u[:u.size // block * block], y[:y.size // block * block]
    if u.size // block < 50:
        raise DesignError(f"{u.size // block} samples (block means) are too few for an output-error fit "
                          "(50 or more)")
    if np.ptp(u) == 0:
        raise DesignError("the input never moves: there is nothing to identify")
    # amplitudes and the sample interval of order one, by powers of two (exact): a record of 1e-12 V in and
    # 100 V out, or sampled every 1e-13 s (the scale fuzz), leaves the regressions singular and scipy's
    # conversions badly conditioned otherwise; the parameters are scaled back below (_scale_back)
    su, sy, st = power_of_two(float(np.ptp(u))), power_of_two(float(np.ptp(y))), power_of_two(T)
    u0, T_record = float(u[0]), T
    u, y, T = u / su, y / sy, T / st
    names = FIT_KINDS[kind]
    if start is not None:
        start = {k: float(v) / _scale_of(kind, k, su, sy, st) for k, v in start.items() if k in names}
    ud = u - u[0]
    yb = block_means(y, block) if block > 1 else y
    n = yb.size
    bounds = _bounds(kind, T, u.size * T)
    lo = np.array([bounds[k][0] for k in names])
    hi = np.array([bounds[k][1] for k in names])
    yscale = max(float(np.std(y)), 1e-300)

    def scale_of(p0):
        # each parameter moves on the order of 1 in the solver's variables
        sc = np.array([abs(p0[k]) for k in names])
        sc[names.index("theta_s")] = max(p0["theta_s"], T)
        return np.where(sc > 0, sc, 1.0)

    evals = 0

    def solve(p0):
        nonlocal evals
        x0 = np.clip(np.array([p0[k] for k in names], float), lo, hi)
        x0 = np.where((x0 == lo) & np.isfinite(lo) & (np.array(names) != "theta_s"),
                      np.where(lo > 0, lo * 1.5, x0), x0)   # off a bound that has no business there
        sc = scale_of(dict(zip(names, x0)))

        def fun(z):
            nonlocal evals
            evals += 1
            r, *_ = _evaluate(kind, dict(zip(names, z * sc)), ud, yb, T, hold, initial, block)
            return r / yscale

        sol = least_squares(fun, x0 / sc, bounds=(lo / sc, hi / sc), method="trf", x_scale="jac",
                            max_nfev=100 * len(names))
        return sol, sc

    starts = [_arx_start(kind, ud, y, T)]
    if kind.startswith("integrating"):
        starts.append(_theta_grid_start(kind, starts[0], ud, yb, T, hold, initial, bounds["theta_s"][1],
                                        block))
    if start is not None:
        starts.append({k: float(start[k]) for k in names})
    # the cost is kinked and can hold a local minimum in the dead time: a second start at half of it
    starts.append({**starts[0], "theta_s": 0.5 * starts[0]["theta_s"]})
    best = None
    for p0 in starts:
        sol, sc = solve(p0)
        if best is None or sol.cost < best[0].cost:
            best = (sol, sc)
    if kind == "underdamped":
        # an oscillation matches itself inverted half a damped period later: -K with the dead time
        # +- pi/wd is a local minimum the starts can fall into (a random binary input, zeta 0.2:
        # K -0.21, theta 3.69 s for K 1, theta 0.5 s); start again from its mirror images
        q = dict(zip(names, best[0].x * best[1]))
        half = math.pi / (q["wn_rad_s"] * math.sqrt(1.0 - min(q["zeta"], 0.99) ** 2))
        for th in (q["theta_s"] - half, q["theta_s"] + half):
            if bounds["theta_s"][0] <= th <= bounds["theta_s"][1]:
                sol, sc = solve({**q, "K": -q["K"], "theta_s": th})
                if sol.cost < best[0].cost:
                    best = (sol, sc)
    sol, sc = best
    x = sol.x * sc
    params = dict(zip(names, (float(v) for v in x)))
    if params["theta_s"] < 1e-9 * T:    # the solver's round-off at the bound: no dead time
        params["theta_s"] = 0.0
    r, sim, beta = _evaluate(kind, params, ud, yb, T, hold, initial, block)
    n_lin = beta.size
    # intervals from the Jacobian over the parameters not held at a bound
    free = sol.active_mask == 0
    J = sol.jac[:, free] * yscale / sc[free]   # d r / d p in output units (p = z sc)
    dof = max(n - int(free.sum()) - n_lin, 1)
    s2 = float(r @ r) / dof
    ci = {k: None for k in names}
    if free.any():
        # one rule for every fit's intervals (core.lsq_intervals): columns of very different lengths scaled to
        # unit norm before the pseudo-inverse (a dead time started near 0 is scaled by the sample interval, so
        # its column can be 1e8 times shorter than the gain's; unscaled, pinv dropped it and gave the dead
        # time an interval of 3e-18 s: an integrator under a step, 15,561 samples over 30 s at 20 dB, +-0.05 s
        # scaled)
        half = half_widths(J, s2, dof)
        for k, h in zip(np.array(names)[free], half):
            ci[str(k)] = float(h)
    # back to the record's units
    for k in names:
        f = _scale_of(kind, k, su, sy, st)
        params[k] *= f
        if ci[k] is not None:
            ci[k] *= f
    notes = []
    converged = sol.status > 0
    if not converged:
        notes.append(f"the solver stopped without converging ({sol.message})")
    for k, act in zip(names, sol.active_mask):
        if act != 0 and k != "theta_s":
            notes.append(f"{k} at its bound ({params[k]:.4g})")
    for k, h in ci.items():
        # the dead time is exempt, as in the other routes (frequency.wide_interval): an interval reaching 0
        # says the data show no dead time (a delay-free plant fits theta 66 us +-0.62 ms), not that the
        # other parameters are undetermined. Not an integrator's: its dead time is its only time, and one
        # that the data cannot place is a record an integrator cannot be told from a slow lag by (10 s of
        # a 100 s lag: K 0.0093 /s, theta 0.05 s +-0.17 s), which is refused as too short
        exempt = k == "theta_s" and not kind.startswith("integrating")
        if h is not None and not exempt and not h < abs(params[k]):
            notes.append(f"{k}'s 95 % interval +-{h:.3g} is not narrower than {k} = {params[k]:.4g}")
    if kind in ("sopdt", "lead-lag") and params["tau1_s"] < params["tau2_s"]:   # the slow time constant first
        params["tau1_s"], params["tau2_s"] = params["tau2_s"], params["tau1_s"]
        ci["tau1_s"], ci["tau2_s"] = ci["tau2_s"], ci["tau1_s"]
    if kind == "lead-lag":
        notes += all_pass_pair(params, ci)
    model, why = _process_model(kind, params, ci)
    if why:
        notes.append(why)
    return OEFit(kind, params, ci, model, not notes, "; ".join(notes), T_record, hold, initial, u0,
                 _linear_back(beta, sy, su, kind, initial), float(math.sqrt(r @ r / n)) * sy, n, evals, converged,
                 block)


def all_pass_pair(params: dict, ci: dict) -> list:
    """Why a lead-lag is not a structure of its own: its zero in the right half plane mirrors one of its lags.

    (1 - a s)/(1 + a s) is Pade's first-order approximation of a delay of 2a (its phase -2 atan(a w), the
    delay's -2 a w at low frequency): a lead-lag whose zero -|tz| mirrors a lag tau within their 95 %
    intervals (|tau + tz| below the intervals' root sum of squares) trades dead time for the pair, and the
    data cannot tell them apart: the structure without the pair (an FOPDT or SOPDT with a longer dead time)
    says the same with fewer parameters. Measured: an FOPDT (K 2, tau 5 s, theta 1.3 s) under a step at
    10 dB fitted a lead-lag with tz -0.280 s +-0.204 s, tau2 0.291 s +-0.200 s and theta 0.703 s, 0.002
    point of validation fit above the FOPDT (within its tolerances) and ranked first.

    Parameters
    ----------
    params : dict
        The lead-lag's parameters (``K``, ``tau1_s``, ``tau2_s``, ``tz_s``, ``theta_s``).
    ci : dict
        Their 95 % half-widths (None where not computed).

    Returns
    -------
    list of str
        The note ([] when the zero is in the left half plane or mirrors no lag).
    """
    tz, hz = params["tz_s"], ci.get("tz_s")
    if not tz < 0 or hz is None:
        return []
    for lag in ("tau2_s", "tau1_s"):
        h = ci.get(lag)
        if h is not None and abs(params[lag] + tz) < math.hypot(hz, h):
            return [f"its zero (tz_s = {tz:.4g} s) mirrors {lag} = {params[lag]:.4g} s within their intervals: an "
                    "all-pass pair, Pade's approximation of dead time, not a structure of its own"]
    return []


def _scale_of(kind: str, name: str, su: float, sy: float, st: float) -> float:
    """What a parameter fitted on amplitudes divided by ``su`` (input) and ``sy`` (output) and on times
    divided by ``st`` is multiplied by in the record's units: a gain sy/su (an integrating model's, per
    second, sy/(su st)), a time st, a natural frequency 1/st, a damping ratio 1."""
    if name == "K":
        return sy / su / (st if kind.startswith("integrating") else 1.0)
    if name == "wn_rad_s":
        return 1.0 / st
    return st if name.endswith("_s") else 1.0


def _linear_back(beta, sy: float, su: float, kind: str, initial: str) -> tuple:
    """The linear coefficients of a fit on scaled amplitudes in the record's units: the output level and
    the free responses are output quantities (times ``sy``); an integrating model's balance input, the
    last column of :func:`_columns`, is an input quantity (times ``su``)."""
    out = [float(v) * sy for v in beta]
    if initial == "estimate" and kind.startswith("integrating"):
        out[-1] = float(beta[-1]) * su
    return tuple(out)


def _process_model(kind: str, p: dict, ci: dict) -> tuple:
    """The fit as a :class:`ProcessModel` (its constructor checks the ranges), and why not."""
    # an unbounded half-width (a direction the data do not determine) is noted by the caller, not carried
    c = {k: v for k, v in ci.items() if v is not None and math.isfinite(v)}
    src = f"output error ({kind})"
    try:
        if kind == "fopdt":
            return pb.fopdt(p["K"], p["tau_s"], p["theta_s"], source=src, ci95=c), ""
        if kind == "sopdt":
            return pb.sopdt(p["K"], p["tau1_s"], p["tau2_s"], p["theta_s"], source=src, ci95=c), ""
        if kind == "underdamped":
            tp = 2 * math.pi
            cf = {("fn_hz" if k == "wn_rad_s" else k): (v / tp if k == "wn_rad_s" else v) for k, v in c.items()}
            return pb.underdamped(p["K"], p["wn_rad_s"] / tp, p["zeta"], p["theta_s"], source=src, ci95=cf), ""
        if kind == "lead-lag":
            num, den = _rational(kind, p)
            return pb.rational(num, den, p["theta_s"], source=src), ""
        return pb.integrating(p["K"], p.get("tau_s", 0.0), p["theta_s"], source=src, ci95=c), ""
    except DesignError as exc:
        return None, f"not a process model: {exc}"


# --------------------------------------------------------------------------- every kind, validated

@dataclass(frozen=True)
class OEResult:
    """Every kind fitted on the estimation part and judged on validation data.

    Attributes
    ----------
    fits : list of OEFit
    validations : list of Validation
        One per fit, in the same order.
    split : Split or None
        The split of one record (None with a separate validation record).
    best : int or None
        Index of the best valid fit by validation fit (None: none valid).
    notes : list of str
        What the reader should know (no valid model).
    """

    fits: list
    validations: list
    split: Split | None
    best: int | None = None
    notes: list = field(default_factory=list)

    @property
    def best_fit(self) -> OEFit | None:
        """The best valid fit, or None."""
        return None if self.best is None else self.fits[self.best]

    def to_dict(self) -> dict:
        """JSON-ready.

        Returns
        -------
        dict
            The split, the best index, each model with its validation.
        """
        return {"split": None if self.split is None else self.split.to_dict(), "best": self.best,
                "models": [{**f.to_dict(), "validation": v.to_dict()}
                           for f, v in zip(self.fits, self.validations)], "notes": list(self.notes)}


def identify_output_error(u, y, sample_time_s: float, *, kinds=("fopdt", "sopdt", "underdamped"),
                          fraction: float = DEFAULT_FRACTION, validation: tuple | None = None,
                          hold: str = "zoh", initial: str = "estimate") -> OEResult:
    """Fit each kind on the estimation part, validate each on the rest (or on a
    second record), and pick the valid one with the best validation fit.

    Parameters
    ----------
    u, y : array_like
        The record.
    sample_time_s : float
        Sample interval (s).
    kinds : sequence of str
        Kinds of :data:`FIT_KINDS` to fit.
    fraction : float
        The estimation part's share when the record is split.
    validation : tuple of (u, y), optional
        A separate validation record at the same sample interval: then all
        of ``u``, ``y`` is fitted.
    hold, initial : str
        As :func:`fit_output_error`.

    Returns
    -------
    OEResult
        Integrating kinds are validated by continuing the simulation over the
        record (``how="continue"``), the others on detrended validation data.
    """
    u = np.asarray(u, float)
    y = np.asarray(y, float)
    if validation is None:
        split = split_record(u.size, fraction)
        ue, ye = u[split.estimation], y[split.estimation]
        uv, yv = u, y
    else:
        split = None
        ue, ye = u, y
        uv, yv = (np.asarray(v, float) for v in validation)
    fits, vals = [], []
    for kind in kinds:
        fit = fit_output_error(ue, ye, sample_time_s, kind, hold=hold, initial=initial)
        how = "continue" if kind.startswith("integrating") and split is not None else "detrend"
        fits.append(fit)
        vals.append(validate(fit, uv, yv, split, how=how))
    ok = [i for i, f in enumerate(fits) if f.valid]
    best = max(ok, key=lambda i: vals[i].fit_percent) if ok else None
    notes = [] if ok else ["no fitted model is valid"]
    return OEResult(fits, vals, split, best, notes)
