"""The record with its models: the recorded output of the data an
:class:`~.assess.Assessment` scored, and its best valid models simulated under
the recorded input, as MATLAB's ``compare`` draws them.

Each model is simulated as the assessment scored it
(:func:`~.outputerror.simulate` at the record's own sample interval under the
assessment's hold, driven from the record's start at rest at its first input
level, or at the rest level the score fitted (``Validation.rest_shift``); a
separate validation record from its own start; a long record's block means
of the simulation, as :func:`~.validation.validate`'s ``block``), then raised by the difference of the
validation part's means: the fit percentage compares the two with their means
removed (:func:`~.validation.validate`, ``how="detrend"``), so this is the
level at which the score sees the model. Nothing is fitted here.

Sources: L. Ljung, *System Identification: Theory for the User*, 2nd ed.
(1999), section 16.6; MathWorks System Identification Toolbox ``compare``.
"""

from __future__ import annotations

import math
from dataclasses import dataclass, field

import numpy as np

from .outputerror import simulate
from .validation import block_means

__all__ = ["ModelTrace", "RecordView", "record_view"]


@dataclass(frozen=True)
class ModelTrace:
    """One model's simulation over the record.

    Attributes
    ----------
    route, name, kind : str
        Its route, method and structure (as :class:`~.assess.Candidate`).
    fit_percent : float
        Its validation fit (%).
    y : numpy.ndarray
        The simulated output at each sample of the record.
    """

    route: str
    name: str
    kind: str
    fit_percent: float
    y: np.ndarray

    @property
    def label(self) -> str:
        """``route method (model), validation fit F %``: what the plots' legends say."""
        return f"{self.route} {self.name} ({self.kind}), validation fit {self.fit_percent:.1f} %"


@dataclass(frozen=True)
class RecordView:
    """The scored record and its best valid models.

    Attributes
    ----------
    t : numpy.ndarray
        Sample times (s) of the scored record (block means centred).
    u, y : numpy.ndarray
        The recorded input and output there.
    validation_start_s : float or None
        Where the validation part starts (None: the whole record was scored
        on the data fitted; a separate validation record starts at ``t[0]``).
    scope : str
        The assessment's (``split``, ``whole``, ``separate``).
    note : str
        The split in words.
    models : tuple of ModelTrace
        Up to ``n_models`` valid models: the assessment's best, then by validation fit.
    """

    t: np.ndarray
    u: np.ndarray
    y: np.ndarray
    validation_start_s: float | None
    scope: str
    note: str
    models: tuple = field(default_factory=tuple)


def record_view(assessment, t, u, y, n_models: int = 3) -> RecordView:
    """The record an assessment scored, with its best valid models simulated on it.

    Parameters
    ----------
    assessment : Assessment
        :func:`~.assess.assess_result`'s answer for this record.
    t, u, y : array_like
        The record it scored (evenly sampled): the capture, or the separate
        validation record (at the capture's interval,
        :func:`~.assess.match_validation`) when it had one.
    n_models : int
        How many valid models to simulate.

    Returns
    -------
    RecordView
    """
    a = assessment
    t, u, y = (np.asarray(x, float) for x in (t, u, y))
    k = a.decimated_by
    # block means of k samples, as the assessment scored them
    tb, ub, yb = (block_means(x, k) for x in (t, u, y))
    if a.scope == "separate":
        start, val = float(tb[0]), slice(0, ub.size)
    elif a.split is None:
        start, val = None, slice(0, ub.size)
    else:
        start, val = float(tb[a.split.n_est]), a.split.validation
    best = a.best_candidate     # first, even where a tie within the margin put it after a better fit
    order = sorted((c for c in a.candidates if c.valid and c.model is not None and math.isfinite(c.fit_percent)),
                   key=lambda c: (c is not best, -c.fit_percent))[:n_models]
    traces = []
    for c in order:
        ym = block_means(simulate(c.model, u[:ub.size * k] - u[0] + c.validation.rest_shift,
                                  a.sample_time_s / k, a.hold), k)
        traces.append(ModelTrace(c.route, c.name, c.kind, c.fit_percent,
                                 ym + (yb[val].mean() - ym[val].mean())))
    return RecordView(tb, ub, yb, start, a.scope, a.note, tuple(traces))
