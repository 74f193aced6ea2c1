"""One 95 % interval rule for every least-squares fit: exact on a linear model whatever its columns' scales
(every product scaled to unit-norm columns), an unbounded half-width along a direction the data do not
determine."""

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st
from scipy.special import stdtrit

from designer.core.lsq_intervals import half_widths


def qr_half_widths(X, s2, dof):
    """The same half-widths by the QR route (no normal equations, no cut-off): cov = s2 R^-1 R^-T, whose
    diagonal is the squared row norms of R^-1 (Golub and Van Loan section 5.3)."""
    R = np.linalg.qr(X, mode="r")
    Ri = np.linalg.solve(R, np.eye(R.shape[0]))
    return stdtrit(dof, 0.975) * np.sqrt(s2 * np.sum(Ri * Ri, axis=1))


def planted(scales, n=400, seed=0):
    """A linear model's Jacobian (for y = X b, d r / d b = -X): smooth columns of given norms."""
    t = np.linspace(0.0, 1.0, n)
    base = np.column_stack([np.ones(n), t, np.exp(-3 * t), np.sin(5 * t), t * t][:len(scales)])
    base /= np.linalg.norm(base, axis=0)
    return -base * np.asarray(scales, float)


def test_a_column_1e8_shorter_keeps_its_interval():
    """The case the fits hit (a dead time started near 0, a time constant fading to 0): one column 1e8
    times shorter than the gain's. The unscaled pseudo-inverse drops it (a near-zero half-width, the
    parameter looks exact); the rule gives the QR route's half-width, 1e8 times the others'."""
    J = planted([1.0, 1e-8, 0.3])
    s2, dof = 1e-4, J.shape[0] - 3
    got = half_widths(J, s2, dof)
    want = qr_half_widths(J, s2, dof)
    np.testing.assert_allclose(got, want, rtol=1e-6)
    old = stdtrit(dof, 0.975) * np.sqrt(np.clip(np.diag(np.linalg.pinv(J.T @ J) * s2), 0.0, None))
    assert old[1] < 1e-6 * want[1]          # what the fits reported before: the column dropped


def test_central_differences_of_a_nonlinear_model_agree():
    """A nonlinear model, a e^(-t/b) + c t with c's effect made 1e9 times weaker than a's (c scaled by 1e-9
    in the model): the half-widths from a central-difference Jacobian equal the QR route's on it."""
    t = np.linspace(0.0, 5.0, 300)
    rng = np.random.default_rng(3)

    def model(p):
        return p[0] * np.exp(-t / p[1]) + 1e-9 * p[2] * t

    p = np.array([2.0, 0.7, 0.5])
    y = model(p) + 0.01 * rng.standard_normal(t.size)
    cols = []
    for i in range(3):
        h = 1e-5 * abs(p[i])
        up, dn = p.copy(), p.copy()
        up[i] += h
        dn[i] -= h
        cols.append(-(model(up) - model(dn)) / (2 * h))
    J = np.column_stack(cols)
    d = np.linalg.norm(J, axis=0)
    assert d.max() / d.min() > 1e6         # J^T J's condition from the scales alone > 1e12
    r = y - model(p)
    dof = t.size - 3
    np.testing.assert_allclose(half_widths(J, r @ r / dof, dof), qr_half_widths(J, r @ r / dof, dof), rtol=1e-6)


@pytest.mark.parametrize("exponents", [[0, 0, -5.75, 0, 0], [0, -5, 0, 0]])
def test_columns_under_1e6_apart_match_the_qr_route(exponents):
    """Bug (found by the property below): columns within 1e6 of each other kept the unscaled product, and
    one column 10^5.75 shorter than the others gave an infinite half-width (the QR route: 3.1e8), one
    10^5 shorter a half-width 1.4e-5 off. Both are scaled now."""
    J = planted([10.0 ** e for e in exponents])
    got, want = half_widths(J, 1.0, 1), qr_half_widths(J, 1.0, 1)
    assert np.all(np.isfinite(got))
    np.testing.assert_allclose(got, want, rtol=1e-9)


def test_collinear_columns_are_unbounded():
    """Two parameters the data cannot tell apart (equal columns): no finite interval for either; the
    third keeps the interval it has with one of the two removed."""
    J = planted([1.0, 0.5])
    J = np.column_stack([J[:, 0], J[:, 1], J[:, 1]])
    h = half_widths(J, 1e-3, J.shape[0] - 3)
    assert np.isinf(h[1]) and np.isinf(h[2]) and np.isfinite(h[0])
    assert h[0] == pytest.approx(qr_half_widths(J[:, :2], 1e-3, J.shape[0] - 3)[0], rel=1e-9)


def test_a_column_of_zeros_is_a_held_parameter():
    """A column of zeros (scipy's Jacobian of a dead time held at its bound 0): 0, as the fits always
    reported it, and the others as without it."""
    J = planted([1.0, 0.2])
    Jz = np.column_stack([J, np.zeros(J.shape[0])])
    dof = J.shape[0] - 3
    h = half_widths(Jz, 1e-3, dof)
    assert h[2] == 0.0
    np.testing.assert_allclose(h[:2], qr_half_widths(J, 1e-3, dof), rtol=1e-9)


@settings(max_examples=60, deadline=None)
@given(scales=st.lists(st.floats(-10.0, 2.0), min_size=1, max_size=5), s2=st.floats(1e-12, 1e3),
       dof=st.integers(1, 10_000))
def test_any_column_scales_match_the_qr_route(scales, s2, dof):
    """Whatever the columns' norms (1e-10 to 100), full rank: the QR route's half-widths."""
    J = planted([10.0 ** e for e in scales])
    np.testing.assert_allclose(half_widths(J, s2, dof), qr_half_widths(J, s2, dof), rtol=1e-6)
