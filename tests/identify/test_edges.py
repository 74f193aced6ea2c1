"""Edges: the transitions of a step or a square wave, and none in a flat or noisy signal."""

import numpy as np
import pytest

from designer.identify.edges import find_edges


def _square(t, f, amp, t0=0.0):
    """Square wave 0 / amp starting high at t0 (and low before it)."""
    ph = np.floor((t - t0) * 2 * f)
    return np.where((t >= t0) & (ph % 2 == 0), amp, 0.0)


def test_edges_of_a_square_wave():
    t = np.linspace(-1e-3, 7e-3, 16001)
    u = 0.5 + _square(t, 330.0, 2.0)
    edges = find_edges(t, u)
    half = 1 / 660
    expect = [k * half for k in range(int(7e-3 / half) + 1)]
    assert len(edges) == len(expect)
    dt = t[1] - t[0]
    for e, te in zip(edges, expect):
        assert abs(e.time - te) <= dt
    assert [round(e.amplitude, 9) for e in edges[:2]] == [2.0, -2.0]
    assert edges[0].before == pytest.approx(0.5) and edges[0].after == pytest.approx(2.5)


def test_no_edges_in_a_flat_or_noisy_input():
    rng = np.random.default_rng(1)
    t = np.linspace(0, 1, 1000)
    assert find_edges(t, np.ones_like(t)) == []
    assert find_edges(t, 1 + 0.01 * rng.standard_normal(t.size)) == []
