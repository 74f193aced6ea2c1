"""A plant realised by any registered section (:mod:`designer.filters`): the
target T(s) of the seed (001, IV.3-IV.9; fn, zeta and the passband gain) as a
:class:`~designer.filters.topology.SectionTarget` (Q = 1 / (2 zeta)), its parts
chosen jointly from E-series values by one search written against the
:class:`~designer.filters.topology.Topology`, and its figures: ideal (the
topology's own coefficients), op-amp-aware (the dominant pair of the topology's
netlist with the single-pole op-amp), step, -3 dB and sensitivities, all
vectorised over arrays of part values (the Monte Carlo's analytic engine).

The search (:func:`search`) is exact over its candidate set:

- capacitors: every combination of series values the topology's free choices
  reach (a reference capacitor C from the series, and for a topology with a
  capacitor ``ratio`` every other series value C' with C'/C realisable: the
  topology's own limit, e.g. C2/C1 >= 4 Q^2 (1 + |A0|) of the MFB low-pass);
- resistors: for each capacitor combination, the continuous synthesis's
  resistors (:meth:`Topology.synthesize`) and their ``width`` nearest series
  values on each side inside the bounds.

Every combination of the set is evaluated at once (numpy) and ranked by the
worse relative error ``max(|fn/fn0 - 1|, |zeta/zeta0 - 1|, |G/G0 - 1|)``, then
the summed error (the Sallen-Key search's ranking: :mod:`designer.plant.selection`).
:func:`brute_force` enumerates the same set one combination at a time (the
tests' reference); with ``width`` as wide as the series the resistors' set is
every series value, so the search is brute force over the whole grid.

A section with an exact search of its own (:meth:`~designer.filters.topology.Topology.fast_search`:
the Sallen-Key low-pass's parallelogram search over the whole grid, seed 001's plant)
gives :func:`search` and :func:`rounded` its ranking instead; ``fast=False`` enumerates the
candidate set on every section (the conformance suite's).

Which builds are listed (:func:`listed`). The search ranks combinations by their error
alone, and the same response comes back at other impedance levels: every resistor times
ten and every capacitor over ten (but a gain pair, :attr:`~designer.filters.topology.Topology.choice_parts`,
whose ratio alone counts) keeps every time constant and ratio, so the same transfer function
(30k/120k/1n5/4n7 and 3k/12k/15n/47n on the Sallen-Key low-pass). Each response is listed
once, at the level whose resistors lie in :data:`R_BAND`, 1 kOhm to 100 kOhm (nearest its
middle, 10 kOhm, otherwise), and among the builds within :data:`BAND_ERROR` of the target
(well inside what the parts' own tolerance moves: a 5 % resistor moves fn 2.5 %) those in
the band come first. The band is an op-amp section's, whatever its network:

- below 1 kOhm the op-amp's output drives the network's resistors (the LM741 is specified
  into 2 kOhm, TI SNOSC25), and the generator's 50 Ohm output adds to the input resistor:
  5 % of 1 kOhm already;
- above 100 kOhm the resistors' thermal noise, sqrt(4 k T R) = 41 nV/sqrt(Hz) at 100 kOhm
  and 300 K (Johnson-Nyquist; Horowitz and Hill, *The Art of Electronics*, 3rd ed., 8.1.1),
  and the op-amp's input bias current through them (LM741: 80 nA typical, 500 nA max, TI
  SNOSC25: 8 mV to 50 mV of output offset at 100 kOhm) grow, and a few pF of board and
  input capacitance and leakage become part of the circuit.

The part bounds still decide what the search may use (a design the band cannot reach is
built outside it, best error first).

The op-amp-aware transfer function (:func:`opamp_tf`) is the section's own
:meth:`~designer.filters.topology.Topology.opamp_model`: Cramer's rule on its nodal
equations by default (:meth:`~designer.filters.topology.Topology.nodal_model`), the
closed forms where a section has them (the Sallen-Key low-pass: seed 001, IV.3-IV.9).
"""

from __future__ import annotations

import dataclasses

import itertools
import math
from dataclasses import dataclass

import numpy as np

from ..core.errors import DesignError
from ..core.units import format_eng
from ..filters import registry
from ..filters.topology import SectionTarget, Topology

__all__ = ["BAND_ERROR", "BELOW_BOUND", "DEFAULT_TOPOLOGY", "FIGURES", "OPAMP_PARAMETERS", "R_BAND", "Candidate",
           "plant_target", "capacitor_combinations", "candidate_set", "search", "rounded", "brute_force", "listed",
           "GBW_ROUNDS", "gbw_shift", "compensate_gbw", "opamp_tf", "dominant_pairs", "circuit_figures", "evaluate",
           "sensitivities", "corner_frequencies", "step_of_pair"]

#: the topology of ``design-plant`` without ``--topology``: the seed's plant (its own search, :mod:`.selection`)
DEFAULT_TOPOLOGY = "sallen-key-lowpass"
#: the figures :func:`circuit_figures` gives (the Monte Carlo's, as the Sallen-Key engine's)
#: how far under a topology's capacitor-ratio bound the search still takes a pair (the bound's resistors,
#: rounded): a pair further under it is off by more than the series' rounding (zeta ~5 % high at 1/1.1)
BELOW_BOUND = 1.1
FIGURES = ("fn_hz", "zeta", "q", "ideal_fn_hz", "ideal_zeta", "ideal_q", "overshoot_pct", "peak_time_s", "gain")
#: the resistors' preferred band, ohm (the module docstring: loading below, noise and bias current above)
R_BAND = (1e3, 100e3)
#: within this worse relative error of the target a build in :data:`R_BAND` lists before better ones outside it
BAND_ERROR = 0.005


@dataclass(frozen=True)
class Candidate:
    """One combination of part values and where it lands.

    Parameters
    ----------
    values : dict
        Designator -> value (ohm, farad).
    fn_hz, zeta, gain : float
        Its ideal figures (zeta None for a first-order section).
    worst : float
        The worse relative error against the target.
    """

    values: dict
    fn_hz: float
    zeta: float | None
    gain: float
    worst: float


def plant_target(topology: Topology, fc_hz: float, zeta, gain: float = 1.0) -> SectionTarget:
    """The section target of a plant: fn, Q = 1 / (2 zeta) (second order) and the gain magnitude.

    Parameters
    ----------
    topology : Topology
        The section (its kind and order).
    fc_hz : float
        Natural (corner, centre) frequency, Hz.
    zeta : float or None
        Damping ratio; None for a first-order section.
    gain : float
        Passband gain magnitude.

    Returns
    -------
    SectionTarget
        The target :meth:`Topology.synthesize` takes.

    Raises
    ------
    DesignError
        A damping for a first-order section, or none for a second-order one.
    """
    if topology.order == 1 and zeta is not None:
        raise DesignError(f"zeta: {topology.name} is first-order and has no damping; leave the damping out or use a "
                          "second-order topology", param="zeta")
    if topology.order == 2 and zeta is None:
        raise DesignError(f"zeta: {topology.name} is second-order: give its damping", param="zeta")
    q = None if zeta is None else 1.0 / (2.0 * zeta)
    return SectionTarget(topology.kind, fc_hz, q=q, gain=gain)


def _capacitors(topology: Topology) -> tuple:
    return tuple(p.ref for p in topology.parts if p.kind == "C")


def capacitor_combinations(topology: Topology, target: SectionTarget, c_values) -> dict:
    """The capacitor combinations the topology's choices reach, each with its continuous synthesis.

    A synthesis scales with its reference capacitor (every capacitor times c, every resistor
    over c, but the parts a free choice sets, :attr:`Topology.choice_parts`): the topology
    synthesises once per capacitor ratio (at the smallest capacitor), scaled to every other.

    Parameters
    ----------
    topology : Topology
        The section.
    target : SectionTarget
        The target.
    c_values : array_like
        The capacitor series values inside the bounds, ascending.

    Returns
    -------
    dict
        Designator -> array (one entry per combination): the capacitors exact series
        values, the resistors continuous.

    Raises
    ------
    DesignError
        The target is beyond the topology (its own limit, one line), or no capacitor
        combination inside the bounds realises it (the ratio bound against the range).
    """
    c_values = np.asarray(c_values, dtype=float)
    topology.check_realisable(target)
    caps = _capacitors(topology)
    c0 = float(c_values[0])
    bound = topology.limits(target).get("ratio_min", 0.0)
    if "ratio" in topology.choices:
        i, j = np.meshgrid(np.arange(len(c_values)), np.arange(len(c_values)), indexing="ij")
        m = c_values[j.ravel()] / c_values[i.ravel()]
        # below the topology's ratio bound no exact resistors realise the target, but rounded ones can still
        # come nearer than any pair above it (unity-gain Sallen-Key at fc 212 Hz, zeta 0.998: C1 = C2 gives
        # zeta 1.0, 0.196 % off, the best above the bound 0.314 %): a pair up to BELOW_BOUND under the bound
        # takes the bound's resistors (the nearest realisable synthesis) with its own capacitors
        keep = m >= bound / BELOW_BOUND * (1 - 1e-12)
        ref, m = c_values[i.ravel()][keep], m[keep]
        keys, inverse = np.unique(np.round(np.log(m), 9), return_inverse=True)
        actual = [float(m[np.argmax(inverse == k)]) for k in range(len(keys))]
        choices = [{"ratio": max(r, bound * (1 + 1e-9))} for r in actual]
    else:
        ref, inverse, choices, actual = c_values, np.zeros(len(c_values), int), [{}], [None]
    bases = []
    for ch, r in zip(choices, actual):
        try:
            v = topology.synthesize(SectionTarget(target.kind, target.fn_hz, target.q, target.gain, c_f=c0), **ch)
            if r is not None and r < ch["ratio"]:   # C2 = ratio C1: the pair's own capacitors
                v = {k: x * r / ch["ratio"] if k in caps and k != topology.reference_capacitor else x
                     for k, x in v.items()}
            bases.append(v if all(math.isfinite(x) and x > 0 for x in v.values()) else None)
        except DesignError:
            bases.append(None)
    ok = np.array([bases[k] is not None for k in inverse], bool)
    ref, inverse = ref[ok], inverse[ok]
    scale = ref / c0
    columns = {}
    for r in topology.designators:
        base = np.array([np.nan if b is None else b[r] for b in bases])[inverse]
        if r in caps:
            # the capacitors are series values up to rounding: snap them
            x = base * scale
            idx = np.clip(np.searchsorted(c_values, x), 1, len(c_values) - 1)
            nearer_low = np.abs(np.log(c_values[idx - 1] / x)) <= np.abs(np.log(c_values[idx] / x))
            columns[r] = c_values[np.where(nearer_low, idx - 1, idx)] if len(c_values) > 1 else np.full(len(x),
                                                                                                       c_values[0])
        else:
            columns[r] = base if r in topology.choice_parts else base / scale
    if not len(columns[topology.designators[0]]):
        why = f"its capacitor ratio must be at least {bound:.4g}" if bound else "no capacitor value fits"
        raise DesignError(f"c_max: {topology.name} cannot realise fn {format_eng(target.fn_hz, 'Hz', 4)}"
                          + (f", Q {target.q:.4g}" if target.q else "")
                          + f" with capacitors from {format_eng(c_values[0], 'F')} to {format_eng(c_values[-1], 'F')}"
                          f": {why}; widen the "
                          "capacitor bounds, lower Q, or use another topology", param="c_max")
    return columns


def _lower(series: np.ndarray, x) -> np.ndarray:
    """The index of the last series value <= x (-1 below the series), rounding forgiven."""
    return np.searchsorted(series, np.asarray(x) * (1 + 1e-12), side="right") - 1


def candidate_set(topology: Topology, target: SectionTarget, r_values, c_values, width: int = 1) -> list:
    """The search's candidate set: per capacitor combination, each part's candidate values
    (a capacitor its one value; a resistor the ``width`` series values at or below its
    continuous value and the ``width`` above, inside the series).

    Parameters
    ----------
    topology : Topology
        The section.
    target : SectionTarget
        The target.
    r_values, c_values : array_like
        The resistor and capacitor series values inside the bounds, ascending.
    width : int
        How many series values on each side of a continuous resistor (>= 1).

    Returns
    -------
    list of dict
        Per capacitor combination, designator -> 1-D array of candidate values.
    """
    rv = np.asarray(r_values, dtype=float)
    caps = _capacitors(topology)
    combos = capacitor_combinations(topology, target, c_values)
    out = []
    for b in range(len(combos[topology.designators[0]])):
        block = {}
        for ref in topology.designators:
            x = combos[ref][b]
            lo = int(_lower(rv, x))
            block[ref] = np.array([x]) if ref in caps else rv[max(0, lo - width + 1):max(0, lo + width + 1)]
        out.append(block)
    return out


def _errors(topology: Topology, target: SectionTarget, values: dict) -> tuple:
    """(worse, summed) relative error and the figures of arrays of part values."""
    with np.errstate(divide="ignore", invalid="ignore"):    # no damping at all: Q infinite, an error like any
        f = topology.figures(values)
    errs = [np.abs(np.asarray(f.fn_hz) / target.fn_hz - 1), np.abs(np.asarray(f.gain) / target.gain - 1)]
    zeta = None
    if f.q is not None:
        zeta = np.asarray(f.zeta)
        errs.append(np.abs(zeta * 2.0 * target.q - 1))
    worst = np.maximum.reduce(errs)
    return worst, sum(errs), f, zeta


def _ranked(topology, target, values: dict, top: int) -> list:
    worst, total, _, _ = _errors(topology, target, values)
    refs = topology.designators
    # the worse error (rounded: ties), then the summed error, then the values: one order for every run
    order = np.lexsort(tuple(values[r] for r in reversed(refs)) + (total, np.round(worst, 12)))[:top]
    return _candidates(topology, target, {r: np.asarray(values[r])[order] for r in refs})


def _candidates(topology, target, values: dict) -> list:
    """The combinations ``values`` (designator -> array) as :class:`Candidate`, in their order."""
    refs = topology.designators
    values = {r: np.atleast_1d(np.asarray(values[r], dtype=float)) for r in refs}
    if not values[refs[0]].size:
        return []
    worst, _, f, zeta = _errors(topology, target, values)
    fn, gain, worst = np.atleast_1d(f.fn_hz), np.atleast_1d(f.gain), np.atleast_1d(worst)
    return [Candidate({r: float(values[r][i]) for r in refs}, float(fn[i]),
                      None if zeta is None else float(np.atleast_1d(zeta)[i]), float(gain[i]), float(worst[i]))
            for i in range(values[refs[0]].size)]


def search(topology: Topology, target: SectionTarget, r_values, c_values, top: int = 5, width: int = 1,
           fast: bool = True) -> list:
    """The ``top`` best combinations of the candidate set (:func:`candidate_set`), best first; the
    section's own exact search instead when it has one (:meth:`Topology.fast_search`) and ``fast``.

    Parameters
    ----------
    topology : Topology
        The section.
    target : SectionTarget
        The target.
    r_values, c_values : array_like
        The resistor and capacitor series values inside the bounds, ascending.
    top : int
        How many to return.
    width : int
        The resistors' neighbours on each side.
    fast : bool
        Take the section's fast path when it has one (False: the candidate set, on every section).

    Returns
    -------
    list of Candidate
        Best first (worse error, then summed error, then values; a fast path's own order).
    """
    found = topology.fast_search(target, r_values, c_values, top) if fast else None
    if found is not None:
        return _candidates(topology, target, found)
    rv = np.asarray(r_values, dtype=float)
    combos = capacitor_combinations(topology, target, c_values)
    n_b = len(combos[topology.designators[0]])
    res = [p.ref for p in topology.parts if p.kind == "R"]
    offsets = np.arange(-width + 1, width + 1)
    # every resistor's 2 width candidates, as an axis each: (combination, o_1, ..., o_k)
    shape = (n_b,) + (len(offsets),) * len(res)
    valid = np.ones(shape, bool)
    values = {}
    for axis, ref in enumerate(res):
        idx = _lower(rv, combos[ref])[:, None] + offsets[None, :]
        ok = (idx >= 0) & (idx < len(rv))
        view = [n_b] + [1] * len(res)
        view[axis + 1] = len(offsets)
        values[ref] = np.broadcast_to(rv[np.clip(idx, 0, len(rv) - 1)].reshape(view), shape)
        valid &= ok.reshape(view)
    for ref in topology.designators:
        if ref not in values:
            values[ref] = np.broadcast_to(combos[ref].reshape((n_b,) + (1,) * len(res)), shape)
    values = {r: v[valid] for r, v in values.items()}
    return _ranked(topology, target, values, top)


def rounded(topology: Topology, target: SectionTarget, ideal: dict, r_values, c_values, top: int = 5,
            width: int = 2, fast: bool = True) -> list:
    """The ``top`` best combinations of each part's ``width`` series values on each side of its
    value in ``ideal`` (an exact design: :meth:`Topology.synthesize_rc`'s, the seed's "fix R
    and C"): that design rounded jointly, as the seed's plant rounds its own
    (:func:`designer.plant.design.choose_parts`), every combination evaluated at once.

    Parameters
    ----------
    topology : Topology
        The section.
    target : SectionTarget
        The target the combinations are ranked against.
    ideal : dict
        Designator -> continuous value.
    r_values, c_values : array_like
        The resistor and capacitor series values inside the bounds, ascending.
    top : int
        How many to return.
    width : int
        Series values on each side of each part's value (a part beyond the bounds takes the nearest).
    fast : bool
        Take the section's fast path when it has one (:meth:`Topology.fast_search` with ``around``:
        the Sallen-Key low-pass pools each kind's neighbours, as the seed's plant always has).

    Returns
    -------
    list of Candidate
        Best first, ranked as :func:`search` ranks.
    """
    found = topology.fast_search(target, r_values, c_values, top, around=ideal, width=width) if fast else None
    if found is not None:
        return _candidates(topology, target, found)
    axes = []
    for p in topology.parts:
        series = np.unique(np.asarray(r_values if p.kind == "R" else c_values, dtype=float))
        i = int(np.searchsorted(series, ideal[p.ref]))
        axes.append(series[max(0, i - width):i + width])
    grid = np.meshgrid(*axes, indexing="ij")
    return _ranked(topology, target, {p.ref: g.ravel() for p, g in zip(topology.parts, grid)}, top)


def brute_force(topology: Topology, target: SectionTarget, blocks: list, top: int = 5) -> list:
    """Every combination of ``blocks`` (:func:`candidate_set`'s form) evaluated one at a
    time with scalar values: the reference the tests hold :func:`search` to.

    Parameters
    ----------
    topology : Topology
        The section.
    target : SectionTarget
        The target.
    blocks : list of dict
        Designator -> candidate values, per block; the set is the union of each block's product.
    top : int
        How many to return.

    Returns
    -------
    list of Candidate
        Best first, ranked as :func:`search` ranks.
    """
    rows = []
    for block in blocks:
        for combo in itertools.product(*(block[r] for r in topology.designators)):
            v = dict(zip(topology.designators, (float(x) for x in combo)))
            worst, total, _, _ = _errors(topology, target, v)
            rows.append((round(float(worst), 12), float(total), tuple(v[r] for r in topology.designators), v))
    rows.sort(key=lambda row: row[:3])
    values = {r: np.array([row[3][r] for row in rows[:top]]) for r in topology.designators}
    return _ranked(topology, target, values, top)


def _scaled(topology: Topology, kind: str) -> list:
    """The parts of ``kind`` that scale with the impedance level (not a gain pair's)."""
    return [p.ref for p in topology.parts if p.kind == kind and p.ref not in topology.choice_parts]


def _outside_band(topology: Topology, c: Candidate) -> float:
    """How far (decades) a build's impedance-scaled resistors stray outside :data:`R_BAND` (0: inside)."""
    r = [c.values[ref] for ref in _scaled(topology, "R")]
    if not r:
        return 0.0
    lo, hi = R_BAND
    return max(0.0, math.log10(lo / min(r)), math.log10(max(r) / hi))


def _level(topology: Topology, c: Candidate) -> float:
    """How far (decades) the geometric mean of a build's impedance-scaled resistors is from 10 kOhm."""
    r = [c.values[ref] for ref in _scaled(topology, "R")]
    return abs(math.log10(math.prod(r) ** (1 / len(r)) / 1e4)) if r else 0.0


def _same_response(topology: Topology, a: Candidate, b: Candidate) -> bool:
    """One build scaled in impedance (R times s, C over s; a gain pair, whose ratio alone counts, at
    any level): every ratio of the scaled resistors, of the capacitors and of the gain pair, and one
    time constant equal."""
    res, caps, pair = _scaled(topology, "R"), _scaled(topology, "C"), list(topology.choice_parts)
    pairs = []
    for group in (res, caps, pair):
        pairs += [(a.values[r] / a.values[group[0]], b.values[r] / b.values[group[0]]) for r in group[1:]]
    if res and caps:
        pairs.append((a.values[res[0]] * a.values[caps[0]], b.values[res[0]] * b.values[caps[0]]))
    return all(math.isclose(x, y, rel_tol=1e-9) for x, y in pairs)


def _parts_key(topology: Topology, c: Candidate) -> tuple:
    """A build's values as a sorted set per kind (which part holds which value left out)."""
    return tuple(tuple(sorted(c.values[p.ref] for p in topology.parts if p.kind == kind)) for kind in "RC")


def _same_build(topology: Topology, a: Candidate, b: Candidate) -> bool:
    """Of two builds with the same parts as a set per kind (:func:`_parts_key`), the same figures: equal
    parts swapped where the section is symmetric (R1 and R2 of the unity-gain Sallen-Key low-pass), one build."""
    close = [(a.fn_hz, b.fn_hz), (a.gain, b.gain)] + ([] if a.zeta is None else [(a.zeta, b.zeta)])
    return all(math.isclose(x, y, rel_tol=1e-9) for x, y in close)


def listed(topology: Topology, ranked: list, top: int, band: bool = True) -> list:
    """The builds a design lists, best first, from candidates ranked by error (the module docstring).

    Each build once (equal parts swapped in a symmetric section), each response once (an
    impedance-scaled copy is the same design): at the level whose resistors stray least outside
    :data:`R_BAND`, nearest 10 kOhm when several lie inside. With ``band``, the builds in the
    band within :data:`BAND_ERROR` of the target come first.

    Parameters
    ----------
    topology : Topology
        The section.
    ranked : list of Candidate
        Combinations, best error first (:func:`search`, :func:`rounded`).
    top : int
        How many to list at most.
    band : bool
        Put the builds in the resistor band first (False: the user fixed R, keep the error order).

    Returns
    -------
    list of Candidate
        Members of ``ranked``.
    """
    builds, seen = [], {}
    for c in ranked:
        same_parts = seen.setdefault(_parts_key(topology, c), [])
        if not any(_same_build(topology, b, c) for b in same_parts):
            same_parts.append(c)
            builds.append(c)
    groups = []
    for c in builds:
        home = next((g for g in groups if _same_response(topology, g[0], c)), None)
        if home is None:
            groups.append([c])
        else:
            home.append(c)
    # a group's members have the same errors: its place in the ranking is its first member's
    reps = [min(g, key=lambda c: (_outside_band(topology, c), _level(topology, c))) for g in groups]
    if band:
        reps.sort(key=lambda c: not (_outside_band(topology, c) == 0 and c.worst <= BAND_ERROR))  # stable
    return reps[:top]


#: rounds of :func:`compensate_gbw` at most (the shift hardly depends on the parts: two or three settle it)
GBW_ROUNDS = 4


def gbw_shift(topology: Topology, values: dict, opamp) -> tuple:
    """How far the op-amp's finite gain and GBW move a build: (fn_ideal / fn_opamp, zeta_ideal / zeta_opamp),
    the op-amp-aware figures the dominant pair of :meth:`~designer.filters.topology.Topology.opamp_model`
    (zeta's 1 for a first-order section).

    Parameters
    ----------
    topology : Topology
        The section.
    values : dict
        Designator -> value.
    opamp : designer.core.opamps.OpAmp
        The op-amp.

    Returns
    -------
    tuple of float
        The two ratios.
    """
    f = circuit_figures(topology, values, opamp)
    fn = float(f["ideal_fn_hz"]) / float(f["fn_hz"])
    return fn, 1.0 if topology.order == 1 else float(f["ideal_zeta"]) / float(f["zeta"])


def compensate_gbw(topology: Topology, target: SectionTarget, opamp, rank, rounds: int = GBW_ROUNDS) -> tuple:
    """``--compensate-gbw``: aim off by the shift the op-amp causes on the build chosen (:func:`gbw_shift`),
    fn times its fn ratio and zeta times its zeta ratio, and choose again, until the aim settles (1e-9) or
    ``rounds`` are done; the round whose build's op-amp-aware fn and zeta land nearest the spec is taken (the
    spec's own build among them: never worse than no compensation).

    One rule for the plant on every section, the seed plant's (its spec is the dominant pair), rather than
    :func:`designer.filters.design.predistort` (a least-squares fit of the whole response over fn/10 .. 10 fn,
    a filter's rule, which ``design-plant --topology`` took before). Measured (LM741, LM358, TL072; fc 300 Hz
    to 30 kHz), the worse of the op-amp-aware fn and zeta errors: on the Sallen-Key low-pass (32 specs,
    gain 1 to 2.5) 0.007 % to 1.3 % here against 0.12 % to 8.4 % by the fit, better on 28, equal on 3, 0.09 pp
    worse on one (the series' rounding); the fit lands further off than no compensation on 14 of 16 (fc
    20 kHz, zeta 0.3: 5.1 % against 1.1 %), this on none. On the other sections (94 specs) better on 29, equal
    on 59, worse on 6, four of them the Sallen-Key high-pass's, whose shift depends on its capacitor ratio (the
    rounds swing between builds; up to 1.9 pp worse).

    Parameters
    ----------
    topology : Topology
        The section.
    target : SectionTarget
        The spec.
    opamp : designer.core.opamps.OpAmp
        The op-amp.
    rank : callable
        Target -> the builds for it, best first (:func:`search` then :func:`listed`).
    rounds : int
        At most this many aims after the spec's.

    Returns
    -------
    tuple
        (the target finally aimed at, its builds).
    """
    def landing(ranked):
        # how far the build's op-amp-aware dominant pair lands from the spec: the worse of fn's and zeta's errors
        f = circuit_figures(topology, ranked[0].values, opamp)
        errs = [abs(float(f["fn_hz"]) / target.fn_hz - 1)]
        if target.q is not None:
            errs.append(abs(float(f["zeta"]) * 2 * target.q - 1))
        return max(errs)

    aim, ranked = target, rank(target)
    best = (landing(ranked), aim, ranked)
    for _ in range(rounds):
        sf, sz = gbw_shift(topology, ranked[0].values, opamp)
        q = None if target.q is None else target.q / sz
        new = dataclasses.replace(target, fn_hz=target.fn_hz * sf, q=q)
        if abs(new.fn_hz / aim.fn_hz - 1) < 1e-9 and (q is None or abs(aim.q / q - 1) < 1e-9):
            break
        try:
            ranked, aim = rank(new), new
        except DesignError:     # the aim beyond the section's reach (a ratio bound): keep the last one
            break
        # where the shift depends on the build (a Sallen-Key high-pass's on its capacitor ratio) the rounds can
        # swing between builds: the round that lands nearest counts (the later one of equals: a settled aim)
        here = landing(ranked)
        if here <= best[0]:
            best = (here, aim, ranked)
    return best[1], best[2]


def opamp_tf(topology: Topology, values: dict, opamp) -> tuple:
    """The op-amp-aware transfer function of the section as polynomials (vectorised):
    the section's own model, :meth:`~designer.filters.topology.Topology.opamp_model`
    (the nodal solution by default, a section's closed form where it has one).

    Parameters
    ----------
    topology : Topology
        The section.
    values : dict
        Designator -> value, numbers or arrays (one batch shape).
    opamp : designer.core.opamps.OpAmp
        Its A0 and GBW (the single-pole model).

    Returns
    -------
    tuple of ndarray
        (num, den), each of shape ``batch + (n + 1,)``, highest power first, den's
        constant term 1.
    """
    return topology.opamp_model(values, opamp)


def dominant_pairs(den: np.ndarray, first_order: bool = False) -> tuple:
    """fn (Hz) and zeta of the slowest pole pair of each polynomial (vectorised
    :func:`designer.core.lti.dominant_pair`: the slowest complex pair, else the two
    slowest real poles; one real pole: its corner and zeta NaN).

    Parameters
    ----------
    den : ndarray
        Shape ``batch + (m + 1,)``, highest power first.
    first_order : bool
        A first-order section's: the slowest pole alone, a real one's corner or a complex pair's |p| (the
        section's pole merged with the op-amp's), zeta NaN.

    Returns
    -------
    tuple of ndarray
        (fn_hz, zeta), shape ``batch``.
    """
    den = np.asarray(den, float)
    m = den.shape[-1] - 1
    if m == 1:
        return np.abs(den[..., 1] / den[..., 0]) / (2 * math.pi), np.full(den.shape[:-1], np.nan)
    comp = np.zeros(den.shape[:-1] + (m, m))
    comp[..., 0, :] = -den[..., 1:] / den[..., :1]
    comp[..., np.arange(1, m), np.arange(m - 1)] = 1.0
    poles = np.linalg.eigvals(comp)
    mag = np.abs(poles)
    cplx = np.abs(poles.imag) > 1e-9 * mag
    slow_c = np.argmin(np.where(cplx, mag, np.inf), axis=-1)
    pc = np.take_along_axis(poles, slow_c[..., None], -1)[..., 0]
    real = np.sort(np.where(cplx, np.inf, np.abs(poles.real)), axis=-1)
    if first_order:
        # the slowest pole, real or one of a complex pair (|p|): a first-order section near its op-amp's
        # gain-bandwidth (an inverting high-pass at fc 100 kHz on an LM358) has its pole and the op-amp's
        # merged into a complex pair, and no real pole at all (its fn was inf); all real, the same bits
        slow = np.minimum(real[..., 0], np.min(np.where(cplx, mag, np.inf), axis=-1))
        return slow / (2 * math.pi), np.full(den.shape[:-1], np.nan)
    with np.errstate(invalid="ignore", over="ignore"):
        w_r = np.sqrt(real[..., 0] * real[..., 1])
        z_r = (real[..., 0] + real[..., 1]) / (2 * w_r)
    has = np.any(cplx, axis=-1)
    # |p| as hypot(Re, Im), which is dominant_pair's abs() of one pole to the bit (numpy's vectorised complex
    # abs rounds differently in a third of cases: the plant's sensitivities, finite differences, would move)
    mag_c = np.hypot(pc.real, pc.imag)
    w = np.where(has, mag_c, w_r)
    z = np.where(has, -pc.real / np.where(has, mag_c, 1.0), z_r)
    return w / (2 * math.pi), z


def circuit_figures(topology: Topology, values: dict, opamp=None) -> dict:
    """Every figure of :data:`FIGURES` for arrays of part values (the Monte Carlo's analytic engine).

    ``fn_hz``, ``zeta``, ``q``: the dominant pair of the op-amp-aware model (of the ideal
    one without an op-amp); ``ideal_*``: the topology's coefficients; ``overshoot_pct``
    and ``peak_time_s``: the dominant pair's, 100 exp(-pi zeta / sqrt(1 - zeta^2)) and
    pi / (wn sqrt(1 - zeta^2)) (0 and NaN at zeta >= 1, :func:`step_of_pair`); ``gain``: the passband
    gain magnitude.

    Parameters
    ----------
    topology : Topology
        The section.
    values : dict
        Designator -> value, numbers or arrays.
    opamp : designer.core.opamps.OpAmp, optional
        The op-amp (None or the ideal one: the ideal figures).

    Returns
    -------
    dict
        Figure -> array (numbers for numbers).
    """
    f = topology.figures(values)
    fn_i = np.asarray(f.fn_hz, float)
    z_i = np.full(fn_i.shape, np.nan) if f.zeta is None else np.asarray(f.zeta, float)
    if opamp is None or opamp.ideal:
        fn, z = fn_i, z_i
    else:
        fn, z = dominant_pairs(opamp_tf(topology, values, opamp)[1], topology.order == 1)
    with np.errstate(divide="ignore", invalid="ignore"):
        return {"fn_hz": fn, "zeta": z, "q": 1 / (2 * z), "ideal_fn_hz": fn_i, "ideal_zeta": z_i,
                "ideal_q": 1 / (2 * z_i), **step_of_pair(fn, z), "gain": np.asarray(f.gain, float)}


def step_of_pair(fn_hz, zeta) -> dict:
    """The step figures of a second-order pair: 100 exp(-pi zeta / sqrt(1 - zeta^2)) and
    pi / (wn sqrt(1 - zeta^2)) (0 and NaN at zeta >= 1 or NaN, a first-order section's).

    Parameters
    ----------
    fn_hz, zeta : array_like
        The pair.

    Returns
    -------
    dict
        ``overshoot_pct``, ``peak_time_s``.
    """
    fn, z = np.asarray(fn_hz, float), np.asarray(zeta, float)
    with np.errstate(divide="ignore", invalid="ignore"):
        under = np.where(z < 1, np.sqrt(np.clip(1 - z * z, 0.0, None)), np.nan)
        over = np.where(z < 1, 100 * np.exp(-math.pi * z / under), 0.0)
        tpk = np.where(z < 1, 1.0 / (2 * fn * under), np.nan)
    return {"overshoot_pct": over, "peak_time_s": tpk}


def evaluate(context: tuple, values: dict) -> dict:
    """The Monte Carlo's chunk function (:mod:`designer.tolerance.runner`): the section's own figures
    (:meth:`~designer.filters.topology.Topology.sample_figures`: the Sallen-Key low-pass's exact
    third-order step) where it has them, else :func:`circuit_figures`.

    Parameters
    ----------
    context : tuple
        (topology name, op-amp).
    values : dict
        Designator -> array of sampled values; ``GBW`` (Hz), when there, the op-amp's gain-bandwidth of
        each build.

    Returns
    -------
    dict
        Figure -> array.
    """
    name, opamp = context
    topo = registry.get(name)
    if "GBW" in values and opamp is not None and not opamp.ideal:
        # the op-amp's spread (--tol GBW): one gain-bandwidth per build, shaped as the parts' batch
        opamp = dataclasses.replace(opamp, gbw_hz=np.asarray(values["GBW"], float))
    values = {r: values[r] for r in topo.designators}
    own = topo.sample_figures(values, opamp)
    return circuit_figures(topo, values, opamp) if own is None else own


#: the op-amp's figures a sensitivity table lists (label -> the :class:`~designer.core.opamps.OpAmp` field)
OPAMP_PARAMETERS = {"GBW": "gbw_hz", "A0": "a0"}


def _pair(topology: Topology, values: dict, opamp) -> tuple:
    """wn (rad/s) and zeta of arrays of part values: the section's ideal pair (its hook,
    :meth:`~designer.filters.topology.Topology.ideal_wn_zeta`: the Sallen-Key plant's record arithmetic), else
    the dominant pair of the op-amp-aware model (:func:`circuit_figures`'s) with wn = 2 pi fn, as the plant's
    model has it."""
    if opamp is None or opamp.ideal:
        return topology.ideal_wn_zeta(values)
    fn, z = dominant_pairs(opamp_tf(topology, values, opamp)[1], topology.order == 1)
    return 2 * math.pi * fn, z


def sensitivities(topology: Topology, values: dict, opamp=None, rel_step: float = 1e-6) -> dict:
    """Relative sensitivities S = d ln y / d ln x of wn and zeta to every declared part, the section's
    other parameters (:meth:`~designer.filters.topology.Topology.sensitivity_parameters`: a gain section's K)
    and, with a real op-amp, its gain-bandwidth ``GBW`` and DC gain ``A0`` (through the section's
    :meth:`~designer.filters.topology.Topology.opamp_model`).

    Central differences in log space, x (1 + h) against x (1 - h), every row in one batch:
    S = ln(y+ / y-) / ln((1 + h) / (1 - h)). The Sallen-Key plant's table
    (:func:`designer.plant.model.sensitivities`) is this one's rows, bit for bit its old closed forms'.

    Parameters
    ----------
    topology : Topology
        The section.
    values : dict
        Designator -> value.
    opamp : designer.core.opamps.OpAmp, optional
        The op-amp-aware model's (None or the ideal one: the ideal model, no op-amp rows).
    rel_step : float
        The relative step h.

    Returns
    -------
    dict
        Label -> {"wn": S, "zeta": S} (zeta None for a first-order section): the designators in their
        declared order, then the section's parameters, then ``GBW`` and ``A0``.
    """
    h = rel_step
    base = {r: float(values[r]) for r in topology.designators}
    real_amp = opamp is not None and not opamp.ideal
    labels, rows = [], []
    for ref in topology.designators:
        labels.append(ref)
        rows += [{**base, ref: base[ref] * f} for f in (1 + h, 1 - h)]
    for name in topology.sensitivity_parameters():
        labels.append(name)
        rows += [topology.with_parameter(base, name, f) for f in (1 + h, 1 - h)]
    if real_amp:
        # one op-amp per row, shaped as the batch: the parts' rows at its own figures, then each figure moved
        figures = {f: [getattr(opamp, f)] * len(rows) for f in OPAMP_PARAMETERS.values()}
        for label, field in OPAMP_PARAMETERS.items():
            labels.append(label)
            rows += [base, base]
            for f, column in figures.items():
                column += [getattr(opamp, f) * m if f == field else getattr(opamp, f) for m in (1 + h, 1 - h)]
        opamp = dataclasses.replace(opamp, **{f: np.array(c, float) for f, c in figures.items()})
    batch = {r: np.array([row[r] for row in rows], float) for r in topology.designators}
    wn, zeta = (np.asarray(x, float) for x in _pair(topology, batch, opamp))
    dl = math.log((1 + h) / (1 - h))
    out = {}
    for i, label in enumerate(labels):
        up, down = 2 * i, 2 * i + 1
        s_z = None if topology.order == 1 else math.log(float(zeta[up]) / float(zeta[down])) / dl
        out[label] = {"wn": math.log(float(wn[up]) / float(wn[down])) / dl, "zeta": s_z}
    return out


#: :func:`corner_frequencies`' refinement: rounds, and points a round in each crossing's bracket
REFINE, SUBGRID = 4, 513


def corner_frequencies(topology: Topology, values: dict, opamp=None) -> list:
    """The -3 dB frequencies of the response (Hz): where |H| crosses the passband
    gain / sqrt 2 between fn / 1000 and 1000 fn (one for a low- or high-pass, two
    for a band-pass), found on a dense grid and refined on finer grids in log f.

    Parameters
    ----------
    topology : Topology
        The section.
    values : dict
        Designator -> value.
    opamp : designer.core.opamps.OpAmp, optional
        None: the ideal response; else the op-amp-aware one.

    Returns
    -------
    list of float
        Ascending.
    """
    fig = topology.figures(values)
    fn, level = float(fig.fn_hz), float(fig.gain) / math.sqrt(2)
    mag = lambda f: np.abs(topology.response(values, 2j * np.pi * np.asarray(f), opamp))  # noqa: E731
    f = np.logspace(math.log10(fn) - 3, math.log10(fn) + 3, 1201)
    above = mag(f) >= level
    cross = np.flatnonzero(above[1:] != above[:-1])
    if not cross.size:
        return []
    # every crossing's bracket refined together: REFINE rounds of SUBGRID points in log f each (one response
    # evaluation of all the brackets a round, not 60 bisection steps of one point each); the bracket's width
    # in log f shrinks by SUBGRID - 1 a round, to ~1e-13 of f
    lo, hi, a_lo = np.log(f[cross]), np.log(f[cross + 1]), above[cross]
    for _ in range(REFINE):
        grid = lo[:, None] + (hi - lo)[:, None] * np.linspace(0.0, 1.0, SUBGRID)[None, :]
        side = (mag(np.exp(grid)) >= level) == a_lo[:, None]
        k = np.clip(np.sum(np.cumprod(side, axis=1), axis=1) - 1, 0, SUBGRID - 2)   # last point on lo's side
        rows = np.arange(len(lo))
        lo, hi = grid[rows, k], grid[rows, k + 1]
    return [float(x) for x in np.exp(0.5 * (lo + hi))]
