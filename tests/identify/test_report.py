"""The identification sheet's drawings (issue 28: each model judged by its
residuals, as ``resid`` draws them): the residual tests of the best few valid
models, each drawn from its own validation, nothing recomputed."""

import matplotlib

matplotlib.use("Agg")

import matplotlib.pyplot as plt  # noqa: E402
import numpy as np  # noqa: E402
from matplotlib.collections import LineCollection  # noqa: E402

from designer.identify.assess import identify_record  # noqa: E402
from designer.identify.report import broadband_plot, ranked_candidates, residual_axes  # noqa: E402
from prbs_capture import prbs_capture  # noqa: E402

# seed 003 eq. 2.4.21, minutes
FURNACE = ([44.735, 0.464], list(np.polymul([1.0, 0.054], [1.0, 0.0095])))


def test_the_residual_plots_cover_the_best_few_models():
    """The furnace under 4 periods of the seed's 31-bit sequence: three valid
    models scored. Each axis has one stem collection per model, the best first,
    at its lags (within a third of a lag) and its own correlations, labelled
    with its validation fit; the sheet's PNG draws them without a warning."""
    t, u, y = prbs_capture(*FURNACE, bits=5, per_bit=3, periods=4, ts=1.0, amplitude=0.1, offset=0.0)
    res = identify_record(t, y, u, name="furnace")
    top = [c for c in ranked_candidates(res.assessment) if c.valid and c.validation is not None][:3]
    assert len(top) == 3 and top[0] is res.assessment.best_candidate
    fig, pair = plt.subplots(1, 2)
    try:
        residual_axes(pair, top)
        for ax, what in zip(pair, ("whiteness", "cross")):
            stems = [c for c in ax.collections if isinstance(c, LineCollection) and c.get_label().startswith(
                tuple(f"{m.route} {m.name} {m.kind}" for m in top))]
            assert [s.get_label().split(",")[0] for s in stems] == [f"{m.route} {m.name} {m.kind}" for m in top]
            for s, m in zip(stems, top):
                corr = getattr(m.validation, what)
                segs = s.get_segments()
                x = np.array([g[0][0] for g in segs])
                top_y = np.array([g[1][1] for g in segs])
                assert np.all(np.abs(x - corr.lags) <= 1 / 3 + 1e-12)
                assert np.array_equal(top_y, corr.r)
                assert f"fit {m.validation.fit_percent:.1f} %" in s.get_label()
    finally:
        plt.close(fig)
    png = broadband_plot(res)
    assert png[:8] == b"\x89PNG\r\n\x1a\n"
