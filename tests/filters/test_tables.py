"""The normalised section tables (designer.filters.tables): TI SLOA088's
coefficient tables ("Op Amps for Everyone", ch. 16, section 16.9: Bessel,
Butterworth, Tschebyscheff 0.5/1/2/3 dB, orders 2-10) reproduced from scipy's
prototypes, checked for every order against closed forms computed here
independently of scipy (Butterworth's pole angles, Chebyshev's sinh/cosh poles,
the reverse Bessel polynomial), and against a few published rows."""

import math

import numpy as np
import pytest

from designer.filters.tables import coefficient_table, section_3db_ratio, table_corner

FAMILIES = [("butterworth", None), ("bessel", None), ("chebyshev", 0.5), ("chebyshev", 1.0), ("chebyshev", 2.0),
            ("chebyshev", 3.0)]
ORDERS = range(2, 11)


def rows_from_poles(poles, corner):
    """(order, a, b) of each section from left-half-plane poles, frequency divided by ``corner``,
    first order first then rising Q."""
    out = []
    for p in poles:
        p = complex(p) / corner
        if abs(p.imag) < 1e-9:
            out.append((1, -1 / p.real, 0.0, None))
        elif p.imag > 0:
            wn = abs(p)
            out.append((2, -2 * p.real / wn ** 2, 1 / wn ** 2, wn / (-2 * p.real)))
    return sorted(out, key=lambda r: (r[0] == 2, r[3] or 0.0))


def butterworth_poles(n):
    # s_m = exp(j pi (2m + n + 1) / (2n)), m = 0..n-1: the left half of the unit circle
    return [complex(math.cos(t), math.sin(t)) for t in (math.pi * (2 * m + n + 1) / (2 * n) for m in range(n))]


def chebyshev_poles(n, ripple):
    # the ripple edge at 1 rad/s: -sinh(mu) sin(theta_k) + j cosh(mu) cos(theta_k), theta_k = (2k-1) pi / (2n)
    eps = math.sqrt(10 ** (ripple / 10) - 1)
    mu = math.asinh(1 / eps) / n
    th = [(2 * k - 1) * math.pi / (2 * n) for k in range(1, n + 1)]
    return [complex(-math.sinh(mu) * math.sin(t), math.cosh(mu) * math.cos(t)) for t in th]


def bessel_poles(n):
    # the reverse Bessel polynomial theta_n(s) = sum (2n-k)! / (2^(n-k) k! (n-k)!) s^k, its -3 dB point found
    # by bisection and moved to 1 rad/s
    coef = [math.factorial(2 * n - k) / (2 ** (n - k) * math.factorial(k) * math.factorial(n - k))
            for k in range(n + 1)]
    poly = np.array(coef[::-1])

    def gain(w):
        return abs(coef[0] / np.polyval(poly, 1j * w))

    lo, hi = 1e-3, 1e3
    for _ in range(200):
        mid = math.sqrt(lo * hi)
        lo, hi = (mid, hi) if gain(mid) > 1 / math.sqrt(2) else (lo, mid)
    return list(np.roots(poly) / lo)


def closed_form(family, order, ripple):
    if family == "butterworth":
        return rows_from_poles(butterworth_poles(order), 1.0)
    if family == "bessel":
        return rows_from_poles(bessel_poles(order), 1.0)
    poles = chebyshev_poles(order, ripple)
    # the table's corner: 3 dB below the DC gain, found by bisection beyond the ripple edge (1 rad/s)

    def rel(w):
        return abs(np.prod([-p for p in poles]) / np.prod([1j * w - p for p in poles]))

    lo, hi = 1.0, 10.0
    for _ in range(200):
        mid = 0.5 * (lo + hi)
        lo, hi = (mid, hi) if rel(mid) > 1 / math.sqrt(2) else (lo, mid)
    return rows_from_poles(poles, lo)


@pytest.mark.parametrize("family,ripple", FAMILIES)
@pytest.mark.parametrize("order", ORDERS)
def test_table_equals_closed_form_poles(family, ripple, order):
    got = coefficient_table(family, order, ripple or 1.0)
    want = closed_form(family, order, ripple)
    assert [r.order for r in got] == [w[0] for w in want]
    assert sum(r.order for r in got) == order
    for r, (n, a, b, q) in zip(got, want):
        assert r.a == pytest.approx(a, rel=1e-7)
        assert r.b == pytest.approx(b, rel=1e-7, abs=1e-12)
        if n == 2:
            assert r.q == pytest.approx(q, rel=1e-7)
            assert r.fn_ratio == pytest.approx(1 / math.sqrt(b), rel=1e-7)
            assert r.q == pytest.approx(math.sqrt(r.b) / r.a, rel=1e-12)
        else:
            assert r.fn_ratio == pytest.approx(1 / a, rel=1e-7)


@pytest.mark.parametrize("order", ORDERS)
def test_butterworth_q_closed_form(order):
    # Q_k = 1 / (2 cos(phi_k)), phi_k the pole's angle from the negative real axis: (2k - 1) pi / (2n) for an
    # even order, k pi / n for an odd one; fn = fc for every section
    phis = [(2 * k - 1) * math.pi / (2 * order) for k in range(1, order // 2 + 1)] if order % 2 == 0 else \
        [k * math.pi / order for k in range(1, (order - 1) // 2 + 1)]
    qs = sorted(1 / (2 * math.cos(p)) for p in phis)
    rows = coefficient_table("butterworth", order)
    assert [r.q for r in rows if r.order == 2] == pytest.approx(qs, rel=1e-9)
    assert all(r.fn_ratio == pytest.approx(1.0, rel=1e-9) for r in rows)


@pytest.mark.parametrize("family,ripple", FAMILIES)
@pytest.mark.parametrize("order", ORDERS)
def test_k_is_the_section_minus_3db_point(family, ripple, order):
    # k_i by brute force: the section's own |H| / |H(0)| crossing 1/sqrt(2) on a fine grid
    for r in coefficient_table(family, order, ripple or 1.0):
        w = np.linspace(0.01, 10, 200_001)
        h = 1 / np.abs(1 + r.a * 1j * w + r.b * (1j * w) ** 2)
        k = w[np.flatnonzero(h >= 1 / math.sqrt(2))[-1]]
        assert r.k == pytest.approx(k, abs=1e-4)


@pytest.mark.parametrize("family,ripple", FAMILIES)
@pytest.mark.parametrize("order", ORDERS)
def test_whole_filter_is_3db_down_at_the_corner(family, ripple, order):
    # the product of the sections, each DC gain 1, is 3 dB below DC at fC = 1 (the tables' normalisation)
    h = np.prod([1 / (1 + r.a * 1j + r.b * (1j) ** 2) for r in coefficient_table(family, order, ripple or 1.0)])
    assert 20 * math.log10(abs(h)) == pytest.approx(-10 * math.log10(2), abs=1e-9)


# A few published rows (a, b, k = fCi/fC, Q), "Op Amps for Everyone" (5th ed.), section 16.9, Tables 16.6
# (Bessel) and 16.7 (Butterworth); SLOA088 Example 16-2 (3 dB Tschebyscheff, order 2: a1 = 1.0650,
# b1 = 1.9305). The tables give 4 decimals for a and b, 3 for k, 2 for Q.
PUBLISHED = {
    ("bessel", None, 4): [(1.3397, 0.4889, 0.978, 0.52), (0.7743, 0.3890, 1.797, 0.81)],
    ("bessel", None, 10): [(1.0215, 0.2650, 1.264, 0.50), (0.9393, 0.2549, 1.412, 0.54),
                           (0.7815, 0.2351, 1.780, 0.62), (0.5604, 0.2059, 2.479, 0.81),
                           (0.2883, 0.1665, 3.466, 1.42)],
    ("butterworth", None, 5): [(1.0000, 0.0, 1.000, None), (1.6180, 1.0, 0.859, 0.62), (0.6180, 1.0, 1.448, 1.62)],
    ("butterworth", None, 8): [(1.9616, 1.0, 0.661, 0.51), (1.6629, 1.0, 0.829, 0.60), (1.1111, 1.0, 1.206, 0.90),
                               (0.3902, 1.0, 1.512, 2.56)],
    ("chebyshev", 3.0, 2): [(1.0650, 1.9305, None, None)],
}


@pytest.mark.parametrize("key", list(PUBLISHED))
def test_published_rows(key):
    family, ripple, order = key
    rows = coefficient_table(family, order, ripple or 1.0)
    assert len(rows) == len(PUBLISHED[key])
    for r, (a, b, k, q) in zip(rows, PUBLISHED[key]):
        assert r.a == pytest.approx(a, abs=6e-5) and r.b == pytest.approx(b, abs=6e-5)
        if k is not None:
            assert r.k == pytest.approx(k, abs=6e-4)
        if q is not None:
            assert r.q == pytest.approx(q, abs=6e-3)


def test_corner_conventions():
    # odd-order Chebyshev: the table's corner is the package's own --chebyshev-cutoff 3db factor
    from designer.filters.prototype import chebyshev_3db_factor
    assert table_corner("chebyshev", 5, 0.5) == pytest.approx(chebyshev_3db_factor(5, 0.5), rel=1e-12)
    assert table_corner("butterworth", 4) == 1.0 and table_corner("bessel", 4) == 1.0
    # a second-order section at Q = 1/sqrt(2) is -3 dB at its fn
    assert section_3db_ratio(1 / math.sqrt(2)) == pytest.approx(1.0, rel=1e-12)
