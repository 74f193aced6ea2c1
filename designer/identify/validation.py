"""Judging a model on data it was not fitted to: the fit percentage of
MATLAB's ``compare``, the residual tests of its ``resid``, and an ARX model
fitted by linear least squares as the reference a continuous-time model
should at least match.

Sources: L. Ljung, *System Identification: Theory for the User*, 2nd ed.
(Prentice Hall, 1999): the ARX model and its least-squares estimate (sections
4.2 and 7.3), model validation by simulation on fresh data and residual
analysis (section 16.6: the autocorrelation of the residuals and their
cross-correlation with past inputs, each inside its confidence band), and the
dryer example (section 17.3). MathWorks, System Identification Toolbox
documentation: ``compare`` (fit = 100 (1 - ||y - yhat|| / ||y - mean(y)||)),
``resid`` (99 % bands, 25 lags by default), ``arx`` (orders [na nb nk]),
``detrend``.

Conventions, chosen so that every model is judged the same way:

- :func:`split_record`: the estimation part is the first ``fraction`` of the
  record (default half, as Ljung's dryer example), validation the rest.
- :func:`validate` (``how="detrend"``, the default): the validation part's
  output and the model's simulation each have their mean removed
  (``detrend(z, 0)``, as the toolbox's dryer example does: a level is not the
  model's to know), and the model is driven by the record's input from the
  record's start (at rest at its first level), so its state at the
  validation start is the one the recorded past input left it in; the
  validation output is never used (``compare`` estimates that state from it
  instead). A separate validation record is simulated from rest at its
  first input level. A start from
  rest on the validation part alone leaves a transient that fails the
  whiteness test of a true model (tests/identify/test_validation.py).
  ``how="continue"``: the model
  simulated over the whole record from its start (its own offset and initial
  state), scored on the validation samples only; this is the one that suits an
  integrating plant, whose validation output depends on everything before it.
  ``how="rest"``: as ``"detrend"`` on a record scored whole (no split), but
  the input level the plant rested at before the record is fitted to the
  output by linear least squares (one number: the model's response is linear
  in it; ``compare`` estimates the whole initial state from the data
  instead). A sequence starts with a jump from the operating point to its
  first level, so a rest at that level (seed 003's furnace under four periods
  of a 31-bit sequence: a 90 degC transient the model never made) scored every
  good model under 35 % and a poorer one best. The output scored is the one
  fitted, so the rest level costs no fresh data.
- ``block`` = m > 1 (a long record scored on block means): the model is
  simulated at the record's own rate under the recorded input, and the means
  of m consecutive samples of its simulation are scored against the same
  means of the output (the residual tests on those means too): exactly what
  the output-error fits compare (:mod:`.outputerror`, its ``block``). The
  block means of the input simulated as a record of their own are not the
  means of the response (a held input's means are ramps between its levels),
  which moved every candidate's validation fit, by 0.11 to 1.3 points with
  blocks of 2 and by up to 9.0 with blocks of 5 (an SOPDT under a random
  binary signal at 10 dB, tests/identify/test_assess_synthetic.py).
- Residual bands (Ljung section 16.6): a white residual's normalised
  autocorrelation at lag k != 0 is about N(0, 1/N), so the 99 % band is
  +-2.576/sqrt(N); the cross-correlation of input and residual at lag k is
  about N(0, P/N), P = sum_m r_ee(m) r_uu(m) (the two normalised
  autocorrelations), so its band is +-2.576 sqrt(P/N). The bands are per lag,
  as ``resid`` draws them: a perfectly white residual has every one of 25
  lags inside with probability 0.99^25 = 0.78 (51 cross-correlation lags:
  0.60), so :attr:`Correlation.worst` (the largest |r| over its band) says by
  how much a lag is out.
"""

from __future__ import annotations

import math
from dataclasses import dataclass, field

import numpy as np

from ..core.errors import DesignError

__all__ = ["DEFAULT_FRACTION", "RESID_LAGS", "Z99", "Split", "Correlation", "Validation", "ARXModel",
           "split_record", "block_means", "compare_fit", "whiteness", "cross_correlation", "validate", "arx_fit"]

#: the estimation part's share of a record (Ljung's dryer example halves it)
DEFAULT_FRACTION = 0.5
#: lags of the residual tests (``resid``'s default)
RESID_LAGS = 25
#: two-sided 99 % point of the normal distribution (``resid``'s band)
Z99 = 2.5758293035489004


# --------------------------------------------------------------------------- the split

@dataclass(frozen=True)
class Split:
    """Sample ranges of a record: estimation ``[0, n_est)``, validation ``[n_est, n)``.

    Attributes
    ----------
    n : int
        Samples in the record.
    n_est : int
        Samples of the estimation part (the first ones).
    """

    n: int
    n_est: int

    @property
    def estimation(self) -> slice:
        """The estimation samples."""
        return slice(0, self.n_est)

    @property
    def validation(self) -> slice:
        """The validation samples."""
        return slice(self.n_est, self.n)

    def to_dict(self) -> dict:
        """JSON-ready.

        Returns
        -------
        dict
            ``samples``, ``estimation`` and ``validation`` ([start, stop)).
        """
        return {"samples": self.n, "estimation": [0, self.n_est], "validation": [self.n_est, self.n]}


def split_record(n: int, fraction: float = DEFAULT_FRACTION, min_part: int = 20) -> Split:
    """Split a record of ``n`` samples into estimation (first) and validation parts.

    Parameters
    ----------
    n : int
        Samples in the record.
    fraction : float
        Share of the estimation part, strictly between 0 and 1.
    min_part : int
        Fewest samples either part may have.

    Returns
    -------
    Split

    Raises
    ------
    DesignError
        A fraction outside (0, 1) or a record too short for two parts.
    """
    if not 0.0 < fraction < 1.0:
        raise DesignError(f"fraction must be strictly between 0 and 1, got {fraction}")
    n_est = int(round(n * fraction))
    if n_est < min_part or n - n_est < min_part:
        raise DesignError(f"a record of {n} samples is too short to split into estimation and validation "
                          f"parts of {min_part} samples or more")
    return Split(int(n), n_est)


def block_means(x, m: int) -> np.ndarray:
    """Means of ``m`` consecutive samples (rows), a trailing partial block dropped.

    Parameters
    ----------
    x : array_like
        Samples along the first axis.
    m : int
        Block length, 1 or more (1: ``x`` itself).

    Returns
    -------
    numpy.ndarray
        ``len(x) // m`` means.
    """
    x = np.asarray(x, float)
    if m == 1:
        return x
    k = x.shape[0] // m
    return x[:k * m].reshape(k, m, *x.shape[1:]).mean(axis=1)


# --------------------------------------------------------------------------- scores

def compare_fit(y, yhat) -> float:
    """MATLAB ``compare``'s fit, 100 (1 - ||y - yhat|| / ||y - mean(y)||), in percent.

    Parameters
    ----------
    y, yhat : array_like
        Measured and simulated outputs, the same length.

    Returns
    -------
    float
        100 for a perfect simulation, 0 for one no better than the mean,
        negative for a worse one.
    """
    y = np.asarray(y, float)
    yhat = np.asarray(yhat, float)
    if y.shape != yhat.shape:
        raise DesignError(f"measured and simulated outputs differ in length ({y.size} and {yhat.size})")
    spread = float(np.linalg.norm(y - y.mean()))
    if spread == 0.0:
        raise DesignError("the measured output never moves: a fit percentage needs a varying output")
    return 100.0 * (1.0 - float(np.linalg.norm(y - yhat)) / spread)


@dataclass(frozen=True)
class Correlation:
    """A normalised correlation at lags, against its 99 % band.

    Attributes
    ----------
    lags : numpy.ndarray
        The lags (samples).
    r : numpy.ndarray
        The correlation at each lag, normalised (1 at lag 0 for an autocorrelation).
    band : float
        Half-width of the 99 % band.
    """

    lags: np.ndarray
    r: np.ndarray
    band: float

    @property
    def inside(self) -> bool:
        """True when every lag is inside the band."""
        return bool(np.all(np.abs(self.r) <= self.band))

    @property
    def worst(self) -> float:
        """The largest |r| over the lags, as a multiple of the band."""
        return float(np.max(np.abs(self.r)) / self.band)

    def to_dict(self) -> dict:
        """JSON-ready.

        Returns
        -------
        dict
            ``lags``, ``r``, ``band``, ``inside``, ``worst_over_band``.
        """
        return {"lags": [int(k) for k in self.lags], "r": [float(v) for v in self.r],
                "band": self.band, "inside": self.inside, "worst_over_band": self.worst}


def _xcorr(a, b, lags) -> np.ndarray:
    """sum_t a[t] b[t + k] / N for each k of ``lags`` (k >= 0 or < 0), zero-mean inputs."""
    n = a.size
    out = np.empty(len(lags))
    for i, k in enumerate(lags):
        out[i] = a[:n - k] @ b[k:] / n if k >= 0 else a[-k:] @ b[:n + k] / n
    return out


def whiteness(e, lags: int = RESID_LAGS) -> Correlation:
    """The residuals' normalised autocorrelation at lags 1..``lags`` and its 99 % band.

    Parameters
    ----------
    e : array_like
        Residuals (their mean is removed).
    lags : int
        Highest lag.

    Returns
    -------
    Correlation
        Band +-2.576/sqrt(N) (Ljung section 16.6, at 99 %).
    """
    e = np.asarray(e, float) - np.mean(e)
    ks = np.arange(1, lags + 1)
    r = _xcorr(e, e, ks) / (e @ e / e.size)
    return Correlation(ks, r, Z99 / math.sqrt(e.size))


def cross_correlation(u, e, lags: int = RESID_LAGS) -> Correlation:
    """The normalised cross-correlation of input and residual, r_ue(k) for k =
    -``lags``..``lags`` (k > 0: the residual k samples after the input), and
    its 99 % band.

    Parameters
    ----------
    u, e : array_like
        Input and residuals, the same length (means removed here).
    lags : int
        Highest |lag|.

    Returns
    -------
    Correlation
        Band +-2.576 sqrt(P/N), P = sum_m r_ee(m) r_uu(m) over |m| <= ``lags``
        (Ljung section 16.6): a coloured input widens it.
    """
    u = np.asarray(u, float) - np.mean(u)
    e = np.asarray(e, float) - np.mean(e)
    n = e.size
    ks = np.arange(-lags, lags + 1)
    if not u @ u > 0:
        # an input that does not move here (the validation part of a step capture, after its edge): its
        # deviations are all 0, so is every product with the residuals; nothing to normalise
        return Correlation(ks, np.zeros(ks.size), Z99 / math.sqrt(n))
    norm = math.sqrt((u @ u / n) * (e @ e / n))
    r = _xcorr(u, e, ks) / norm
    ruu = _xcorr(u, u, ks) / (u @ u / n)
    ree = _xcorr(e, e, ks) / (e @ e / n)
    p = max(float(ruu @ ree), 1.0 / n)
    return Correlation(ks, r, Z99 * math.sqrt(p / n))


# --------------------------------------------------------------------------- validation

@dataclass(frozen=True)
class Validation:
    """A model judged on validation data.

    Attributes
    ----------
    fit_percent : float
        :func:`compare_fit` of the simulation.
    whiteness : Correlation
        The residuals' autocorrelation (lags 1..25).
    cross : Correlation
        Input-residual cross-correlation (lags -25..25).
    how : str
        ``"detrend"``, ``"continue"`` or ``"rest"`` (see the module's notes).
    samples : int
        Validation samples scored.
    rest_shift : float
        ``how="rest"``: the fitted rest level's distance below the first
        input level (the model was driven by ``u - u[0] + rest_shift``); 0
        otherwise.
    residuals : numpy.ndarray or None
        The residuals scored (measured minus simulated, each detrended as
        scored), for comparing two models sample by sample; not in the JSON.
    spread : float
        ||y - mean(y)|| of the output scored (the fit's denominator).
    """

    fit_percent: float
    whiteness: Correlation
    cross: Correlation
    how: str
    samples: int
    rest_shift: float = 0.0
    residuals: np.ndarray | None = field(default=None, repr=False, compare=False)
    spread: float = math.nan

    def to_dict(self) -> dict:
        """JSON-ready.

        Returns
        -------
        dict
            The fit, how it was simulated, the samples and both correlations.
        """
        return {"fit_percent": self.fit_percent, "how": self.how, "samples": self.samples,
                "whiteness": self.whiteness.to_dict(), "cross_correlation": self.cross.to_dict()}


def validate(model, u, y, split: Split | None = None, *, how: str = "detrend",
             lags: int = RESID_LAGS, block: int = 1) -> Validation:
    """Simulate ``model`` on validation data and score it.

    Parameters
    ----------
    model : object
        Anything with ``response(u)`` (the output deviation from rest under
        input deviations ``u``) and, for ``how="continue"``, ``simulate(u)``
        (the output over a whole record from its start): :class:`ARXModel`,
        :class:`designer.identify.outputerror.OEFit`.
    u, y : array_like
        The record (with ``split``) or a separate validation record (without),
        at the model's own sample interval.
    split : Split, optional
        Where validation starts (in block means when ``block`` > 1); None: all
        of ``u``, ``y`` is validation data.
    how : {"detrend", "continue", "rest"}
        See the module's notes (``"rest"`` without ``split`` only).
    lags : int
        Lags of the residual tests.
    block : int
        Score the means of this many consecutive samples (module notes; a
        trailing partial block dropped): the model is simulated on every
        sample of ``u``, and its block means compared with ``y``'s.

    Returns
    -------
    Validation
    """
    u = np.asarray(u, float)
    y = np.asarray(y, float)
    if u.shape != y.shape:
        raise DesignError(f"input and output differ in length ({u.size} and {y.size})")
    if isinstance(block, bool) or not isinstance(block, (int, np.integer)) or block < 1:
        raise DesignError(f"block must be a whole number of samples, 1 or more, got {block!r}")
    block = int(block)
    if block > 1:
        u, y = u[:u.size // block * block], y[:y.size // block * block]

    def means(x):
        return block_means(np.asarray(x, float), block)

    # the scored record: block means of the input and output (themselves when block is 1)
    ub, yb = means(u), means(y)
    val = split.validation if split is not None else slice(0, ub.size)
    shift = 0.0
    if how == "rest" and split is not None:
        raise DesignError("how='rest' fits the rest level to the output scored: only for a record scored whole "
                          "(split None)")
    if how in ("detrend", "rest"):
        uv = ub[val] - ub[val].mean()
        yv = yb[val] - yb[val].mean()
        # the model starts at rest at the first input level of what drives it: a separate record, or the
        # whole record when it is split, so that its state at the validation start is the one the
        # recorded past input left it in, not a made-up rest (every sample of it: block means of the
        # response, not the response to block means)
        yhat = means(model.response(u - u[0]))[val]
        yhat = yhat - yhat.mean()
        if how == "rest":
            # the response to a constant input, detrended: its least-squares share is the rest level's offset
            s = means(model.response(np.ones(u.size)))
            s = s - s.mean()
            ss = float(s @ s)
            if ss > 0.0 and math.isfinite(ss):
                shift = float((yv - yhat) @ s) / ss
                yhat = yhat + shift * s
    elif how == "continue":
        uv, yv = ub[val], yb[val]
        yhat = means(model.simulate(u))[val]
    else:
        raise DesignError(f"how must be 'detrend', 'continue' or 'rest', got {how!r}")
    e = yv - yhat
    return Validation(compare_fit(yv, yhat), whiteness(e, lags), cross_correlation(uv, e, lags), how,
                      int(yv.size), shift, e, float(np.linalg.norm(yv - yv.mean())))


# --------------------------------------------------------------------------- ARX

@dataclass(frozen=True)
class ARXModel:
    """A(q) y(t) = B(q) u(t) + e(t), fitted on deviations from the estimation means.

    Attributes
    ----------
    a : numpy.ndarray
        1, a1 .. a_na (coefficients of q^0 .. q^-na).
    b : numpy.ndarray
        Coefficients of q^0 .. q^-(nk + nb - 1) (the first nk zero).
    orders : tuple
        (na, nb, nk).
    u_mean, y_mean : float
        The estimation data's means (the operating point).
    loss : float
        Mean squared one-step prediction error on the estimation data.
    """

    a: np.ndarray
    b: np.ndarray
    orders: tuple
    u_mean: float
    y_mean: float
    loss: float

    @property
    def static_gain(self) -> float:
        """B(1)/A(1) (infinite for an integrating model)."""
        den = float(np.sum(self.a))
        return math.inf if den == 0 else float(np.sum(self.b)) / den

    def response(self, u) -> np.ndarray:
        """Simulated (not predicted) output deviation from rest.

        Parameters
        ----------
        u : array_like
            Input deviations, one per sample.

        Returns
        -------
        numpy.ndarray
            B(q)/A(q) u from zero initial conditions.
        """
        from scipy.signal import lfilter
        return lfilter(self.b, self.a, np.asarray(u, float))

    def simulate(self, u) -> np.ndarray:
        """Simulated output of a whole record around the estimation means.

        Parameters
        ----------
        u : array_like
            The record's input (absolute).

        Returns
        -------
        numpy.ndarray
            y_mean + B(q)/A(q) (u - u_mean).
        """
        return self.y_mean + self.response(np.asarray(u, float) - self.u_mean)

    def to_dict(self) -> dict:
        """JSON-ready.

        Returns
        -------
        dict
            Orders, coefficients, static gain, loss.
        """
        return {"orders": list(self.orders), "a": [float(v) for v in self.a], "b": [float(v) for v in self.b],
                "static_gain": self.static_gain, "loss": self.loss}


def arx_fit(u, y, na: int, nb: int, nk: int) -> ARXModel:
    """ARX[na nb nk] by linear least squares (numpy), on deviations from the means.

    y(t) + a1 y(t-1) + .. + a_na y(t-na) = b1 u(t-nk) + .. + b_nb u(t-nk-nb+1) + e(t)
    (Ljung eq. 4.7; the estimate of section 7.3).

    Parameters
    ----------
    u, y : array_like
        Estimation input and output.
    na, nb, nk : int
        Orders: poles, numerator taps, input delay in samples (na, nb, nk >= 0, nb >= 1).

    Returns
    -------
    ARXModel
    """
    if na < 0 or nb < 1 or nk < 0:
        raise DesignError(f"ARX orders need na >= 0, nb >= 1, nk >= 0; got [{na} {nb} {nk}]")
    u = np.asarray(u, float)
    y = np.asarray(y, float)
    um, ym = float(u.mean()), float(y.mean())
    ud, yd = u - um, y - ym
    m = max(na, nk + nb - 1)
    n = y.size
    if n - m <= na + nb:
        raise DesignError(f"{n} samples are too few for ARX[{na} {nb} {nk}]")
    cols = [-yd[m - i:n - i] for i in range(1, na + 1)] + [ud[m - nk - j:n - nk - j] for j in range(nb)]
    X = np.column_stack(cols)
    theta, *_ = np.linalg.lstsq(X, yd[m:], rcond=None)
    e = yd[m:] - X @ theta
    a = np.concatenate(([1.0], theta[:na]))
    b = np.concatenate((np.zeros(nk), theta[na:]))
    return ARXModel(a, b, (na, nb, nk), um, ym, float(e @ e / e.size))
