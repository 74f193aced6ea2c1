"""The :class:`Topology` abstraction: one active-filter section (a circuit of
resistors, capacitors and one op-amp) described once, in the style of
scikit-rf's ``Media`` (a small abstract base; everything else inherited).

A topology declares its parts (:class:`PartSpec`: designator, kind R or C, the
role shown on a sheet) and implements four things:

- :meth:`Topology.coefficients`: the ideal transfer function as polynomials in
  s (closed forms, vectorised over arrays of part values);
- :meth:`Topology.synthesize`: continuous part values from a
  :class:`SectionTarget` and the free choices the topology offers;
- :meth:`Topology.synthesize_rc`: the seed's hand procedure (001: "fix R and C,
  solve the rest") on the section: a resistor R and a capacitor C given, the other
  parts solved so that both appear among the parts, or a one-line refusal naming
  which of R or C the section cannot take (the default, from :meth:`synthesize`,
  fits a section with one time constant; the second-order sections write their
  closed forms in their own modules);
- :meth:`Topology.check_realisable`: its realisability limits, refused in one
  line naming the limit and what to change;
- :meth:`Topology.netlist`: its :class:`~designer.spice.deck.Netlist` with a
  designator prefix, an op-amp reference and the nets it sits between.

Inherited from the base: the figures (fn, Q, gain) from the coefficients, the
ideal response H(s) from them, and the op-amp-aware response by nodal analysis
of the topology's own netlist with a finite-gain op-amp (:func:`nodal_response`):
the op-amp is a voltage source at its output,

    V_out = A(s) (V+ - V-),   A(s) = A0 / (1 + s A0 / (2 pi GBW))

(the single-pole model of :mod:`designer.core.opamps` and of the project's
``OPAMP_BEH`` subcircuit), and every other node obeys Kirchhoff's current law,
sum over parts of Y_part (V_node - V_other) = 0 with Y = 1/R or s C, the input
node driven at 1 V (the op-amp's row is solved as V_out / A(s) - (V+ - V-) = 0,
well conditioned at any gain). The section modules write their node equations out.

The op-amp-aware model as polynomials, :meth:`Topology.opamp_model`, is a hook: by
default :meth:`Topology.nodal_model` (Cramer's rule on those equations), overridden by a
section with closed forms (the Sallen-Key low-pass: seed 001, IV.3-IV.9), which must
equal the nodal solution to rounding (the conformance suite checks every section).
So is the ideal pair (wn, zeta) of the denominator, :meth:`Topology.ideal_wn_zeta` (by default from
the coefficients, wn = sqrt(d0/d2), zeta = d1 / (2 sqrt(d0 d2)); the Sallen-Key low-pass gives its parts
record's exact arithmetic), vectorised: the figures' fn and Q, the (fn, zeta) a PID's plant is sized by
(:meth:`Topology.ideal_pair`) and the plant's sensitivities are all this one pair.

So is what a step settles to, :meth:`Topology.step_final` (amplitude x G(0) by nodal analysis at DC; the
Sallen-Key low-pass gives its closed form K A0/(K + A0)), the levels of the SPICE step engine
(:mod:`designer.tolerance.spice_engine`).

The plant's E-series search has a hook too, :meth:`Topology.fast_search`: None by default (the
generic search, :func:`designer.plant.circuit.search`, enumerates its candidate set), overridden by a
section with an exact search of its own (the Sallen-Key low-pass: seed 001's parallelogram search over
the whole grid, :mod:`designer.filters.sallen_key_lowpass_search`), which must equal brute force over
the grid it is given (the tests check it).
"""

from __future__ import annotations

import dataclasses
import math
from abc import ABC, abstractmethod
from dataclasses import dataclass

import numpy as np

from ..core.errors import DesignError
from ..core.units import format_eng
from ..spice.deck import GROUND, Netlist, Part

__all__ = ["KINDS", "DEFAULT_IMPEDANCE_OHM", "PartSpec", "SectionTarget", "Figures", "Topology",
           "RC_MATCH", "open_loop_gain", "nodal_system", "nodal_response", "polynomial", "polyval", "quadratic_root"]

#: the section responses a target may ask for
KINDS = ("lowpass", "highpass", "bandpass")
#: the resistor scale of a synthesis given neither an impedance nor a capacitor (ohm)
DEFAULT_IMPEDANCE_OHM = 10e3
#: how close (relative) a given R must be to the resistor a given C sets, for a section with one free scale
#: (:meth:`Topology.synthesize_rc`'s default): seven significant digits typed agree
RC_MATCH = 1e-6


@dataclass(frozen=True)
class PartSpec:
    """One part of a topology, declared once.

    Parameters
    ----------
    ref : str
        Designator within the section (``R1``, ``C2``).
    kind : str
        ``"R"`` or ``"C"``.
    role : str
        What it does, as a sheet shows it ("input resistor", "feedback capacitor").
    """

    ref: str
    kind: str
    role: str


@dataclass(frozen=True)
class SectionTarget:
    """What one section must realise.

    Parameters
    ----------
    kind : str
        ``lowpass``, ``highpass`` or ``bandpass``.
    fn_hz : float
        Natural (centre, for a band-pass; corner, for a first-order section) frequency, Hz.
    q : float or None
        Quality factor of a second-order section; None for a first-order one.
    gain : float
        Passband gain magnitude (V/V): at DC for a low-pass, at high frequency for a
        high-pass, at fn for a band-pass. An inverting topology realises -gain.
    impedance_ohm : float or None
        The resistor scale the synthesis aims at (default :data:`DEFAULT_IMPEDANCE_OHM`).
    c_f : float or None
        The reference capacitor (farad), instead of ``impedance_ohm``.
    """

    kind: str
    fn_hz: float
    q: float | None = None
    gain: float = 1.0
    impedance_ohm: float | None = None
    c_f: float | None = None

    @property
    def wn(self) -> float:
        """Angular natural frequency, rad/s."""
        return 2 * math.pi * self.fn_hz


@dataclass(frozen=True)
class Figures:
    """A section's figures from its part values (numbers, or arrays for arrays of values).

    Parameters
    ----------
    fn_hz : float or ndarray
        Natural (centre, corner) frequency, Hz.
    q : float or ndarray or None
        Quality factor; None for a first-order section.
    gain : float or ndarray
        Passband gain magnitude (V/V).
    zeta : float or ndarray or None
        Damping, 1/(2 Q) (the section's ideal pair, :meth:`Topology.ideal_wn_zeta`); None for a
        first-order section.
    """

    fn_hz: object
    q: object
    gain: object
    zeta: object = None


def polynomial(*coeffs) -> np.ndarray:
    """Coefficients (highest power of s first; numbers or arrays) stacked into one
    array of shape ``(len(coeffs), *batch)``, broadcast against each other.

    Parameters
    ----------
    *coeffs : float or ndarray
        The coefficients.

    Returns
    -------
    ndarray
        ``poly[k]`` is the coefficient of s**(len(coeffs) - 1 - k).
    """
    return np.stack(np.broadcast_arrays(*(np.asarray(c, dtype=float) for c in coeffs)))


def polyval(poly: np.ndarray, s) -> np.ndarray:
    """A :func:`polynomial` at ``s`` by Horner's rule, its batch broadcast against ``s``.

    Parameters
    ----------
    poly : ndarray
        Shape ``(n + 1, *batch)``.
    s : complex or ndarray
        Where to evaluate it.

    Returns
    -------
    ndarray
        The polynomial's values, shape ``broadcast(batch, s)``.
    """
    out = np.zeros((), dtype=complex)
    for c in poly:
        out = out * s + c
    return out


def quadratic_root(a: float, b: float, c: float) -> float:
    """The positive root of a x^2 - b x + c = 0 (b > 0) that a synthesis takes:
    for c > 0 the smaller one, 2 c / (b + sqrt(D)) (also the positive one when
    a < 0, and exact as a -> 0), for c <= 0 the only positive one,
    (b + sqrt(D)) / (2 a); D = b^2 - 4 a c. A discriminant negative by rounding
    only (a double root at a realisability bound) counts as zero.

    Parameters
    ----------
    a, b, c : float
        The coefficients.

    Returns
    -------
    float
        The root.
    """
    d = b * b - 4 * a * c
    if d < 0:
        d = 0.0 if d > -1e-9 * b * b else math.nan
    return 2 * c / (b + math.sqrt(d)) if c > 0 else (b + math.sqrt(d)) / (2 * a)


def _plain(x):
    """A 0-d result as a float (a number's figures are numbers); arrays and None as they are."""
    return float(x) if x is not None and np.ndim(x) == 0 else x


def open_loop_gain(opamp, s) -> np.ndarray:
    """The single-pole open-loop gain A(s) = A0 / (1 + s A0 / (2 pi GBW)).

    Parameters
    ----------
    opamp : designer.core.opamps.OpAmp
        Supplies ``a0`` (V/V) and ``gbw_hz``.
    s : complex or ndarray
        Laplace variable, rad/s.

    Returns
    -------
    ndarray
        A(s).
    """
    s = np.asarray(s, dtype=complex)
    return opamp.a0 / (1 + s * opamp.a0 / (2 * math.pi * opamp.gbw_hz))


def nodal_system(netlist: Netlist, values: dict, s, opamp, inp: str = "vin") -> tuple:
    """The nodal equations Y(s) V = b of a circuit driven at ``inp`` (1 V), each op-amp a
    finite-gain voltage source; vectorised (:func:`nodal_response` solves them).

    Unknowns: every net but ground and the input. Rows: Kirchhoff's current law
    at each net that no op-amp drives, sum Y (V_net - V_other) = 0 (Y = 1/R,
    s C; a part to the input puts Y * 1 V on the right-hand side), and
    V_out / A - (V+ - V-) = 0 for each op-amp's output (divided by A so that
    the system stays well conditioned however large A is). With the single-pole
    A(s), 1/A(s) = (1 + s A0 / (2 pi GBW)) / A0: every entry is a polynomial of
    degree <= 1 in s, so det Y(s) is a polynomial (Cramer's rule then gives the
    transfer function as a ratio of polynomials).

    Parameters
    ----------
    netlist : Netlist
        The circuit (designators are the keys of ``values``).
    values : dict
        Designator -> value (ohm, farad), numbers or arrays.
    s : complex or ndarray
        Laplace variable, rad/s; broadcast against the value arrays.
    opamp : designer.core.opamps.OpAmp
        Its A0 and GBW give A(s) of every op-amp.
    inp : str
        The input net (driven at 1 V).

    Returns
    -------
    tuple
        (Y of shape ``batch + (n, n)``, b of shape ``batch + (n,)``, {net: row index}).
    """
    s = np.asarray(s, dtype=complex)
    vals = {p.ref: np.asarray(values[p.ref], dtype=float) for p in netlist.parts}
    nets = []
    for p in netlist.parts:
        nets += [p.a, p.b]
    for a in netlist.amps:
        nets += [a.inp, a.inn, a.out]
    nets = [n for n in dict.fromkeys(nets) if n not in (GROUND, inp)]
    idx = {n: i for i, n in enumerate(nets)}
    shape = np.broadcast_shapes(s.shape, *(v.shape for v in vals.values()))
    y_mat = np.zeros(shape + (len(nets), len(nets)), dtype=complex)
    rhs = np.zeros(shape + (len(nets),), dtype=complex)
    driven = {idx[a.out] for a in netlist.amps}
    for p in netlist.parts:
        y = 1 / vals[p.ref] if p.kind == "R" else s * vals[p.ref]
        y = np.broadcast_to(y, shape)
        for here, there in ((p.a, p.b), (p.b, p.a)):
            if here not in idx or idx[here] in driven:
                continue
            i = idx[here]
            y_mat[..., i, i] += y
            if there in idx:
                y_mat[..., i, idx[there]] -= y
            elif there == inp:
                rhs[..., i] += y
    # the op-amp's row divided by A(s): V_out / A - V+ + V- = 0 stays well conditioned at any gain
    inverse_gain = np.broadcast_to(1 / open_loop_gain(opamp, s), shape)
    for a in netlist.amps:
        i = idx[a.out]
        y_mat[..., i, i] += inverse_gain
        for net, sign in ((a.inp, -1.0), (a.inn, 1.0)):
            if net in idx:
                y_mat[..., i, idx[net]] += sign
            elif net == inp:
                rhs[..., i] -= sign
    return y_mat, rhs, idx


def nodal_response(netlist: Netlist, values: dict, s, opamp, inp: str = "vin", out: str = "vout") -> np.ndarray:
    """V(out)/V(inp) of a circuit by nodal analysis (:func:`nodal_system`), each op-amp a
    finite-gain voltage source V_out = A(s) (V+ - V-); vectorised.

    Parameters
    ----------
    netlist : Netlist
        The circuit (designators are the keys of ``values``).
    values : dict
        Designator -> value (ohm, farad), numbers or arrays.
    s : complex or ndarray
        Laplace variable, rad/s; broadcast against the value arrays.
    opamp : designer.core.opamps.OpAmp
        Its A0 and GBW give A(s) of every op-amp.
    inp, out : str
        The input net (driven at 1 V) and the output net.

    Returns
    -------
    ndarray
        The transfer function, shape ``broadcast(values..., s)``.
    """
    y_mat, rhs, idx = nodal_system(netlist, values, s, opamp, inp)
    return np.linalg.solve(y_mat, rhs[..., None])[..., idx[out], 0]


class Topology(ABC):
    """One filter section: a subclass sets the class attributes and implements
    :meth:`coefficients`, :meth:`synthesize`, :meth:`netlist` and (when it has
    limits) :meth:`limits` and the realisability check; the rest is inherited.

    Attributes
    ----------
    name : str
        The registry's name (``sallen-key-lowpass``).
    title : str
        A human name ("Sallen-Key low-pass, unity gain").
    kind : str
        ``lowpass``, ``highpass`` or ``bandpass``.
    order : int
        1 or 2.
    inverting : bool
        Whether the passband gain is negative.
    parts : tuple of PartSpec
        The parts, in the order a sheet lists them.
    choices : tuple of str
        The free choices :meth:`synthesize` takes (besides the target).
    example : SectionTarget
        A typical target (the documentation's and the conformance suite's).
    reference_capacitor : str
        The part :attr:`SectionTarget.c_f` sets (the one the others scale from).
    choice_parts : tuple of str
        Parts set by a free choice (a gain pair), not by the impedance scale.
    """

    name: str = ""
    title: str = ""
    kind: str = "lowpass"
    order: int = 2
    inverting: bool = False
    parts: tuple = ()
    choices: tuple = ()
    example: SectionTarget | None = None
    choice_parts: tuple = ()

    # ---- what every section implements ------------------------------------------------------
    @abstractmethod
    def coefficients(self, values: dict) -> tuple:
        """The ideal transfer function as (num, den) polynomials in s.

        Parameters
        ----------
        values : dict
            Designator -> value (ohm, farad), numbers or arrays.

        Returns
        -------
        tuple of ndarray
            (num, den), each of shape ``(order + 1, *batch)``, highest power first
            (num padded with zeros to the length of den).
        """

    @abstractmethod
    def synthesize(self, target: SectionTarget, **choices) -> dict:
        """Continuous part values realising ``target`` exactly.

        Parameters
        ----------
        target : SectionTarget
            The section's kind, fn, Q, gain and reference impedance or capacitor.
        **choices
            The topology's free choices (:attr:`choices`).

        Returns
        -------
        dict
            Designator -> value (ohm, farad).
        """

    @abstractmethod
    def netlist(self, values: dict, prefix: str = "", amp_ref: str = "U1", inp: str = "vin",
                out: str = "vout") -> Netlist:
        """The section as parts and one op-amp between nets ``inp`` and ``out``.

        Parameters
        ----------
        values : dict
            Designator -> value (ohm, farad), numbers.
        prefix : str
            Put after each designator's letter (``"10"``: R1 -> R101), for chaining.
        amp_ref : str
            The op-amp's designator; internal nets are named after it (``u1_x``).
        inp, out : str
            The nets the section sits between.

        Returns
        -------
        Netlist
            Its parts (roles from :attr:`parts`) and op-amp.
        """

    def synthesize_rc(self, target: SectionTarget, r: float, c: float) -> dict:
        """Continuous part values realising ``target`` exactly with a resistor R and a
        capacitor C given (the seed's "fix R and C, solve the rest").

        The default fits a section with a single free scale (the first-order ones: one
        time constant R C = 1/wc): :meth:`synthesize` with C as the reference capacitor,
        accepted when one of its resistors is R (to :data:`RC_MATCH`, relative: the
        values returned are C's, exact), refused otherwise, since R and C then
        over-determine the section. A section with a second free scale overrides
        ``_rc_design`` (R, C and the target checked) with its closed form (the equations
        in its module).

        Parameters
        ----------
        target : SectionTarget
            The section's kind, fn, Q and gain (its ``impedance_ohm`` and ``c_f`` are
            replaced by ``r`` and ``c``).
        r : float
            The resistor R, ohm.
        c : float
            The capacitor C, farad.

        Returns
        -------
        dict
            Designator -> value (ohm, farad).

        Raises
        ------
        DesignError
            R or C not positive, the target out of the section's limits, or R and C
            that the section cannot take together (one line naming ``r`` or ``c``).
        """
        self.check_rc(r, c)
        self.check_realisable(target)
        return self._rc_design(target, r, c)

    def _rc_design(self, target: SectionTarget, r: float, c: float) -> dict:
        """:meth:`synthesize_rc` on checked inputs: the one-free-scale default; sections override it."""
        values = self.synthesize(dataclasses.replace(target, impedance_ohm=r, c_f=c))
        resistors = [p.ref for p in self.parts if p.kind == "R"]
        if any(abs(values[ref] / r - 1) <= RC_MATCH for ref in resistors):
            return values
        first = resistors[0]
        ohm = lambda v: format_eng(v, "Ohm")  # noqa: E731
        set_by_c = ", ".join(f"{ref} = {ohm(values[ref])}" for ref in resistors)
        raise DesignError(f"r: {self.name} has one free scale, so C = {format_eng(c, 'F')} sets its resistors "
                          f"({set_by_c}) and R = {ohm(r)} is none of them; give R = {ohm(values[first])}, or "
                          f"C = {format_eng(c * values[first] / r, 'F')} (then {first} = R)", param="r")

    def check_rc(self, r: float, c: float) -> None:
        """Refuse an R or C of :meth:`synthesize_rc` that is not a positive number.

        Parameters
        ----------
        r, c : float
            The resistor (ohm) and capacitor (farad).

        Raises
        ------
        DesignError
            One line naming ``r`` or ``c``.
        """
        for name, v in (("r", r), ("c", c)):
            if not (isinstance(v, (int, float)) and math.isfinite(v) and v > 0):
                raise DesignError(f"{name} must be a positive number, got {v!r}", param=name)

    def limits(self, target: SectionTarget) -> dict:
        """The bounds ``target`` puts on the free choices (none by default).

        Parameters
        ----------
        target : SectionTarget
            The section target.

        Returns
        -------
        dict
            Name -> bound (``{"ratio_min": 2.0}``).
        """
        return {}

    # ---- the E-series search's fast path (a hook) ----------------------------------------------
    def fast_search(self, target: SectionTarget, r_values, c_values, top: int, around: dict | None = None,
                    width: int = 2) -> dict | None:
        """The section's own exact E-series search, or None (the default): then the plant's generic
        search (:func:`designer.plant.circuit.search`, :func:`designer.plant.circuit.rounded`)
        enumerates its candidate set. A section with a faster exact search overrides this (the
        Sallen-Key low-pass: its parallelogram search over the whole grid, seed 001's plant).

        Parameters
        ----------
        target : SectionTarget
            The target (fn, Q, gain).
        r_values, c_values : array_like
            The resistor and capacitor series values inside the bounds, ascending.
        top : int
            How many combinations to return at most.
        around : dict, optional
            An exact design (designator -> continuous value) to round jointly (the seed's "fix R
            and C"): the parts then come from the ``width`` series values on each side of its values.
        width : int
            Series values on each side of each value of ``around``.

        Returns
        -------
        dict or None
            Designator -> 1-D array of values, the ranked combinations best first (every array
            the same length, at most ``top``); None: the section has no fast path.
        """
        return None

    # ---- inherited ---------------------------------------------------------------------------
    @property
    def reference_capacitor(self) -> str:
        """The part :attr:`SectionTarget.c_f` sets: the first capacitor :attr:`parts` declares
        (a section whose synthesis scales from another overrides this)."""
        return next(p.ref for p in self.parts if p.kind == "C")

    @property
    def designators(self) -> tuple:
        """The designators of :attr:`parts`, in order."""
        return tuple(p.ref for p in self.parts)

    def values_of(self, values: dict) -> dict:
        """``values`` checked against the declared parts, as float arrays.

        Parameters
        ----------
        values : dict
            Designator -> value.

        Returns
        -------
        dict
            The same keys, values as numpy arrays.

        Raises
        ------
        DesignError
            A designator missing or unknown (one line, naming the parts).
        """
        missing = [r for r in self.designators if r not in values]
        extra = [r for r in values if r not in self.designators]
        if missing or extra:
            what = f"no part {', '.join(extra)}" if extra else f"missing {', '.join(missing)}"
            raise DesignError(f"values: {self.name} has {what}; its parts are {', '.join(self.designators)}",
                              param="values")
        return {r: np.asarray(values[r], dtype=float) for r in self.designators}

    def part_role(self, ref: str) -> str:
        """The declared role of designator ``ref``.

        Parameters
        ----------
        ref : str
            A designator of :attr:`parts`.

        Returns
        -------
        str
            Its role.
        """
        return next(p.role for p in self.parts if p.ref == ref)

    def prefixed(self, ref: str, prefix: str) -> str:
        """``ref`` with ``prefix`` after its letter (R1, "10" -> R101).

        Parameters
        ----------
        ref : str
            A designator.
        prefix : str
            The stage's prefix.

        Returns
        -------
        str
            The prefixed designator.
        """
        return ref[0] + prefix + ref[1:]

    def assemble(self, values: dict, prefix: str, ends: dict, amp) -> Netlist:
        """The section's :class:`Netlist`: each declared part between the nets
        ``ends[ref]``, designator prefixed, value from ``values``, and the op-amp.

        Parameters
        ----------
        values : dict
            Designator -> value.
        prefix : str
            The stage's prefix (:meth:`prefixed`).
        ends : dict
            Designator -> (net a, net b).
        amp : designer.spice.deck.Amp
            The section's op-amp.

        Returns
        -------
        Netlist
            The section.
        """
        parts = tuple(Part(self.prefixed(s.ref, prefix), *ends[s.ref], float(values[s.ref]), s.role)
                      for s in self.parts)
        return Netlist(parts, (amp,))

    @staticmethod
    def internal(amp_ref: str, *names: str) -> tuple:
        """Internal net names of a section, unique per op-amp (``u1_x``).

        Parameters
        ----------
        amp_ref : str
            The section's op-amp designator.
        *names : str
            Short names.

        Returns
        -------
        tuple of str
            The nets.
        """
        return tuple(f"{amp_ref.lower()}_{n}" for n in names)

    def response(self, values: dict, s, opamp=None) -> np.ndarray:
        """H(s), vectorised: the part arrays broadcast against ``s``.

        Parameters
        ----------
        values : dict
            Designator -> value (ohm, farad), numbers or arrays.
        s : complex or ndarray
            Laplace variable (``2j * pi * f``), rad/s.
        opamp : designer.core.opamps.OpAmp, optional
            None: the ideal op-amp (:meth:`coefficients`); else its finite gain and
            gain-bandwidth by nodal analysis of :meth:`netlist` (:func:`nodal_response`).

        Returns
        -------
        ndarray
            The complex transfer function.
        """
        if opamp is None:
            num, den = self.coefficients(values)
            return polyval(num, s) / polyval(den, s)
        vals = self.values_of(values)
        net = self.netlist({r: 1.0 for r in self.designators})
        return nodal_response(net, vals, s, opamp)

    def opamp_model(self, values: dict, opamp) -> tuple:
        """The op-amp-aware transfer function as polynomials (vectorised): by default
        :meth:`nodal_model`; a section with closed forms overrides this (they must equal
        the nodal solution to rounding: the conformance suite checks it on every section).

        Parameters
        ----------
        values : dict
            Designator -> value, numbers or arrays (one batch shape).
        opamp : designer.core.opamps.OpAmp
            Its A0 and GBW (the single-pole model; numbers, or arrays shaped as the batch).

        Returns
        -------
        tuple of ndarray
            (num, den), each of shape ``batch + (n + 1,)``, highest power first, den's
            constant term 1.
        """
        return self.nodal_model(values, opamp)

    def nodal_model(self, values: dict, opamp) -> tuple:
        """The op-amp-aware transfer function by Cramer's rule on the section's nodal
        equations (:func:`nodal_system` of :meth:`netlist`), H = det Y_out(s) / det Y(s):
        every entry of Y is a polynomial of degree <= 1 in s, so both determinants are
        polynomials of degree <= n (n nets), recovered exactly from n + 1 values on a
        circle |s| = wn by the inverse DFT (polynomial interpolation at roots of unity).

        Parameters
        ----------
        values : dict
            Designator -> value, numbers or arrays (one batch shape).
        opamp : designer.core.opamps.OpAmp
            Its A0 and GBW (the single-pole model; numbers, or arrays shaped as the batch).

        Returns
        -------
        tuple of ndarray
            (num, den), each of shape ``batch + (n + 1,)``, highest power first, den's
            constant term 1; numerically zero leading terms (below 1e-10 of the
            polynomial's size at |s| = wn, judged on the whole batch) dropped.
        """
        vals = self.values_of(values)
        shape = np.broadcast_shapes(*(v.shape for v in vals.values()))
        vals = {r: np.broadcast_to(v, shape)[..., None] for r, v in vals.items()}
        net = self.netlist({r: 1.0 for r in self.designators})
        n_nets = len({n for p in net.parts for n in (p.a, p.b)} | {n for a in net.amps for n in (a.inp, a.inn, a.out)})
        size = n_nets + 1
        rho = 2 * math.pi * np.asarray(self.figures({r: v[..., 0] for r, v in vals.items()}).fn_hz, float)[..., None]
        s = rho * np.exp(2j * math.pi * np.arange(size) / size)
        if np.ndim(opamp.a0) or np.ndim(opamp.gbw_hz):
            # per-build op-amp figures (the Monte Carlo's GBW spread) beside the batch, against s's last axis
            opamp = dataclasses.replace(opamp, a0=np.asarray(opamp.a0, float)[..., None],
                                        gbw_hz=np.asarray(opamp.gbw_hz, float)[..., None])
        y_mat, rhs, idx = nodal_system(net, vals, s, opamp)
        out = idx["vout"]
        y_out = y_mat.copy()
        y_out[..., :, out] = rhs
        scale = rho ** np.arange(size)
        polys = []
        for d in (np.linalg.det(y_out), np.linalg.det(y_mat)):
            c = np.real(np.fft.fft(d, axis=-1)) / size / scale      # ascending powers of s
            polys.append(c[..., ::-1])
        num, den = polys
        # the degree: terms that are rounding at |s| = wn across the whole batch go
        size_at = np.abs(den * (rho ** np.arange(size)[::-1]))
        keep = np.max(size_at / np.max(size_at, axis=-1, keepdims=True), axis=tuple(range(size_at.ndim - 1))) > 1e-10
        first = int(np.argmax(keep))
        num, den = num[..., first:], den[..., first:]
        num_size = np.abs(num * (rho ** np.arange(num.shape[-1])[::-1]))
        num = np.where(num_size < 1e-10 * np.max(size_at, axis=-1, keepdims=True), 0.0, num)
        d0 = den[..., -1:]
        return num / d0, den / d0

    # ---- the ideal pair (a hook, as opamp_model: the Sallen-Key low-pass overrides it) ------------
    def ideal_wn_zeta(self, values: dict, den=None) -> tuple:
        """(wn in rad/s, zeta) of the section's ideal denominator, vectorised: the one hook
        every ideal pair is computed by (:meth:`ideal_pair`, :meth:`figures`,
        :func:`designer.plant.circuit.sensitivities`, :func:`designer.plant.circuit.circuit_figures`).
        By default from :meth:`coefficients`, den = d2 s^2 + d1 s + d0: wn = sqrt(d0/d2),
        zeta = d1 / (2 sqrt(d0 d2)) (for real poles too: p1 p2 = d0/d2, p1 + p2 = d1/d2,
        :func:`designer.core.lti.dominant_pair`'s pair); a first-order section, den =
        d1 s + d0, has its pole wn = d0/d1 and zeta 1 (the critically damped pair at its
        pole, whose span covers its settling). A section with closed forms of its own
        overrides this (they must equal these to rounding: the conformance suite checks; the
        Sallen-Key low-pass gives its parts record's arithmetic, which the reference outputs hold).

        wn is returned in rad/s, undivided: a sensitivity is a ratio of two wn a relative 1e-6
        apart, and fn = wn / (2 pi) rounds each of them once more.

        Parameters
        ----------
        values : dict
            Designator -> value (ohm, farad), numbers or arrays (one batch shape).
        den : ndarray, optional
            The ideal denominator of ``values`` (:meth:`coefficients`' second), when the caller has
            it already (:meth:`figures`): the default then does not compute it again; a section's own
            arithmetic may ignore it.

        Returns
        -------
        tuple of ndarray
            (wn, zeta), each shaped as the batch (0-d for numbers).
        """
        if den is None:
            den = self.coefficients(values)[1]
        if self.order == 1:
            wn = den[-1] / den[0]
            return wn, np.ones_like(wn)
        return np.sqrt(den[-1] / den[0]), den[1] / (2 * np.sqrt(den[-1] * den[0]))

    def ideal_pair(self, values: dict) -> tuple:
        """(fn in Hz, zeta) of the section's ideal denominator, the pair a PID's plant is
        named and sized by (:attr:`designer.pid.plant.PlantCircuit.fn_hz`): the hook
        :meth:`ideal_wn_zeta`'s, fn = wn / (2 pi). Sections override the hook, not this.

        Parameters
        ----------
        values : dict
            Designator -> value (ohm, farad), numbers or arrays (one batch shape).

        Returns
        -------
        tuple
            (fn_hz, zeta): floats for numbers, arrays shaped as the batch for arrays.
        """
        wn, zeta = self.ideal_wn_zeta(values)
        return _plain(wn / (2 * math.pi)), _plain(zeta)

    # ---- a section's own figures of sampled builds (the Monte Carlo's analytic engine) -----------------
    def sample_figures(self, values: dict, opamp=None):
        """Every figure of :data:`designer.plant.circuit.FIGURES` for arrays of sampled part values by
        the section's own exact definitions, or None (the default): the generic ones
        (:func:`designer.plant.circuit.circuit_figures`, the dominant pair's second-order step figures).
        :func:`designer.plant.circuit.evaluate`, the Monte Carlo's and the worst case's chunk function,
        takes these where a section has them (the Sallen-Key low-pass: its third-order model's exact step).

        Parameters
        ----------
        values : dict
            Designator -> value, numbers or arrays (one batch shape).
        opamp : designer.core.opamps.OpAmp, optional
            The op-amp (None or the ideal one: the ideal model); its gain-bandwidth may be an array
            shaped as the batch.

        Returns
        -------
        dict or None
            Figure -> array shaped as the batch, or None.
        """
        return None

    # ---- the settled output of a step (the SPICE step engine's levels; a hook, as opamp_model) ----------
    def step_final(self, values: dict, opamp, amplitude_v: float = 1.0):
        """What the output settles to after an input step of ``amplitude_v``: amplitude_v G(0), G the
        op-amp-aware response at DC by nodal analysis of :meth:`netlist` (the op-amp's finite A0,
        the ideal one's too: the deck simulates it), negative for an inverting section. The SPICE
        step engine's 10/90 % and 2 % levels and overshoot are read against it
        (:mod:`designer.tolerance.spice_engine`). A section with a closed form overrides this (the
        Sallen-Key low-pass: amplitude K A0/(K + A0), the seed plant's engine's arithmetic to the
        bit); it must equal this to rounding (the conformance suite checks every section).

        Parameters
        ----------
        values : dict
            Designator -> value, numbers or arrays (one batch shape).
        opamp : designer.core.opamps.OpAmp
            The op-amp (its A0).
        amplitude_v : float
            The step (V).

        Returns
        -------
        ndarray
            The settled output (V), shaped as the batch.
        """
        vals = self.values_of(values)
        net = self.netlist({r: 1.0 for r in self.designators})
        return amplitude_v * np.real(nodal_response(net, vals, 0j, opamp))

    # ---- parameters besides the parts (a sensitivity table's extra rows) ------------------------
    def sensitivity_parameters(self) -> tuple:
        """Names of the section's parameters besides its declared parts and the op-amp that a
        sensitivity table lists (:func:`designer.plant.circuit.sensitivities`): none by default;
        a section whose gain K is set by a gain pair lists ``"K"`` (the seed's plant table's row).

        Returns
        -------
        tuple of str
            The names :meth:`with_parameter` takes.
        """
        return ()

    def with_parameter(self, values: dict, name: str, factor) -> dict:
        """``values`` moved so that parameter ``name`` (of :meth:`sensitivity_parameters`) is
        ``factor`` times its value and nothing else of the section changes (K: the feedback
        resistor of the gain pair moves, the RC network stays).

        Parameters
        ----------
        values : dict
            Designator -> value, numbers or arrays.
        name : str
            A name of :meth:`sensitivity_parameters`.
        factor : float or ndarray
            The relative change (1 + h).

        Returns
        -------
        dict
            Designator -> value.

        Raises
        ------
        DesignError
            ``name`` is not one of the section's parameters.
        """
        raise DesignError(f"parameter: {self.name} has no parameter {name!r}; it has "
                          f"{', '.join(self.sensitivity_parameters()) or 'none'}", param="parameter")

    def figures(self, values: dict) -> Figures:
        """fn, Q, zeta and the passband gain magnitude: fn, zeta and Q = 1/(2 zeta) from the ideal
        pair (:meth:`ideal_wn_zeta`, the section's hook), the gain from the ideal coefficients.

        Second order, den = d2 s^2 + d1 s + d0: wn = sqrt(d0/d2), zeta = d1 / (2 sqrt(d0 d2))
        (by default); gain num/den at DC (low-pass), at infinity (high-pass), at wn
        (band-pass, n1/d1). First order, den = d1 s + d0: wn = d0/d1, no Q.

        Parameters
        ----------
        values : dict
            Designator -> value, numbers or arrays.

        Returns
        -------
        Figures
            Numbers for numbers, arrays for arrays.
        """
        num, den = self.coefficients(values)
        wn, zeta = self.ideal_wn_zeta(values, den)
        zeta, q = (zeta, 1 / (2 * zeta)) if self.order == 2 else (None, None)
        if self.kind == "lowpass":
            gain = num[-1] / den[-1]
        elif self.kind == "highpass":
            gain = num[0] / den[0]
        else:
            gain = num[1] / den[1]
        return Figures(_plain(wn / (2 * math.pi)), _plain(q), _plain(np.abs(gain)), _plain(zeta))

    def check_realisable(self, target: SectionTarget, **choices) -> None:
        """Refuse a target or choices the topology cannot realise, in one line that
        names the limit and what to change.

        Parameters
        ----------
        target : SectionTarget
            The section target.
        **choices
            The free choices (:attr:`choices`).

        Raises
        ------
        DesignError
            The first limit broken.
        """
        unknown = [c for c in choices if c not in self.choices]
        if unknown:
            raise DesignError(f"{unknown[0]}: {self.name} has no choice {unknown[0]!r}; it takes "
                              f"{', '.join(self.choices) or 'none'}", param=unknown[0])
        if target.kind != self.kind:
            raise DesignError(f"kind: {self.name} is a {self.kind} section, the target asks for a {target.kind}; "
                              f"use a {target.kind} section", param="kind")
        if not (math.isfinite(target.fn_hz) and target.fn_hz > 0):
            raise DesignError(f"fn_hz must be a positive frequency, got {target.fn_hz!r}", param="fn_hz")
        if self.order == 2 and not (target.q is not None and math.isfinite(target.q) and target.q > 0):
            raise DesignError(f"q: {self.name} is second-order and needs a positive Q, got {target.q!r}",
                              param="q")
        if self.order == 1 and target.q is not None:
            raise DesignError(f"q: {self.name} is first-order and has no Q (got {target.q!r}); leave q unset "
                              "or use a second-order section", param="q")
        if not (math.isfinite(target.gain) and target.gain > 0):
            raise DesignError(f"gain must be a positive magnitude, got {target.gain!r}", param="gain")
        for name in ("impedance_ohm", "c_f"):
            v = getattr(target, name)
            if v is not None and not (math.isfinite(v) and v > 0):
                raise DesignError(f"{name} must be positive, got {v!r}", param=name)
        for name, v in choices.items():
            if not (isinstance(v, (int, float)) and math.isfinite(v) and v > 0):
                raise DesignError(f"{name} must be a positive number, got {v!r}", param=name)
        self._check_limits(target, choices)

    def _check_limits(self, target: SectionTarget, choices: dict) -> None:
        """The topology's own limits (none by default); subclasses raise DesignError."""

    def require_unity_gain(self, target: SectionTarget, instead: str) -> None:
        """Refuse a gain other than 1 for a follower section.

        Parameters
        ----------
        target : SectionTarget
            The target.
        instead : str
            What to do instead ("use sallen-key-lowpass-gain").

        Raises
        ------
        DesignError
            The gain is not 1 (one line).
        """
        if abs(target.gain - 1.0) > 1e-12:
            raise DesignError(f"gain: {self.name} is a follower (gain 1), the target asks for {target.gain:.4g}; "
                              f"{instead}", param="gain")

    def scale(self, target: SectionTarget, c_over_r: float = 1.0) -> float:
        """The reference capacitor (farad) of a synthesis: ``target.c_f``, or the one
        that puts the resistors near ``target.impedance_ohm`` (default
        :data:`DEFAULT_IMPEDANCE_OHM`) at wn: C = c_over_r / (wn R).

        Parameters
        ----------
        target : SectionTarget
            The section target.
        c_over_r : float
            The section's C wn R at its design point (1 for an RC pole).

        Returns
        -------
        float
            Farad.
        """
        if target.c_f is not None:
            return float(target.c_f)
        r = target.impedance_ohm or DEFAULT_IMPEDANCE_OHM
        return c_over_r / (target.wn * r)

    def __repr__(self) -> str:
        return f"<{type(self).__name__} {self.name!r}>"
