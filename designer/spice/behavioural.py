"""A plant that is only a model, G(s) = N(s)/D(s) e^(-theta s), as ngspice deck
lines between an input node and an output node (an identified transfer
function with dead time, for simulating a controller circuit around it).

What each element does, and why (ngspice 39; the figures are measured, see
``tests/spice/test_behavioural.py`` and the notes at the end):

Rational part, ``form="integrators"`` (the default): a chain of n integrators
in controllable canonical form, built from native linear elements only.

- The polynomials are normalised to the plant's time scale ``T`` (the
  geometric mean of its time constants, see :func:`normalise`): with s' = sT,
  H(s') = B(s')/A(s') has A monic and coefficients near 1 whether the plant is
  a 1 us or a 1000 s one.
- Integrator k is node ``<name>_zk`` with ``C<name>_zk`` = T farads to ground,
  fed by G sources of transconductances equal to those coefficients:
  C dz/dt = i is dz/dt' = i, so every gain in the deck is near 1 and every
  state is of the order of the input voltage. ``G<name>_ck`` makes
  z_k' = z_(k+1); the last integrator takes the input (``G<name>_u``) minus
  the feedbacks alpha_i z_i (``G<name>_ai``).
- ``R<name>_zk`` (1e12 ohm, a 1e-12 leak against the unit transconductances)
  gives each integrator node a DC path to ground: an integrating plant (a
  pole at 0) has no DC solution otherwise. Its effect is a pole at -1e-12/T.
- The output y = sum beta_i z_i + d u is summed as currents into ``R<name>_y``
  (1 ohm, node ``<name>_y``); d, the direct feedthrough of a biproper H, is a
  G source from the input, so no element ever sees an improper H.
- Every element is linear and native: ngspice integrates the capacitors with
  its trapezoidal rule under its own truncation-error control, with an exact
  Jacobian, in ``.tran``, ``.ac`` and ``.op`` alike.

Rational part, ``form="s_xfer"``: the XSPICE ``s_xfer`` code model (measured:
it needs ``int_ic`` given, one value per state, and rejects an improper H, so
the feedthrough d is split off as above and s_xfer gets the strictly proper
rest). ``denormalized_freq`` = 1/T keeps the coefficients in the deck near 1:
s_xfer divides the coefficient of s^i by ``denormalized_freq``^i, and then by
the leading denominator coefficient, so it computes with the real-time
coefficients (the deck is readable; the arithmetic is unchanged). Its
``gain`` scales the internal states to at least the input's order (its error
control adds ``abstol``, 1e-12, to a state's tolerance). It accepts a zero
constant term (an integrating plant) and gives the exact H(jw) in ``.ac``,
but it is **not** the default:

- it is first-order accurate: it computes its integrators' input from the
  *previous* time point's states, so its step response is off in proportion
  to w h (h the time step, w the fastest pole's magnitude): 0.18 to 0.37 %
  at w h = 0.01, where the integrators are within 0.01 % at w h = 0.02 and
  0.05 % at w h = 0.05 (zeta = 0.1 the worst measured);
- in a closed loop its output's step-to-step jitter sets transmission-line
  breakpoints that come back one delay later, each adding more: a PI loop
  around FOPDT + line shrinks its step from 10 us to 5e-11 s within 4 ms;
  10 of 12 such loops (reference edges 1 ns or 20 us, two PI tunings) did
  not finish 20 ms in 15 s, where the integrators take 0.03 s each;
- its output partial derivative is wrong (it reports a state's value), so
  with theta = 0 in a PI loop ngspice's Newton iteration settles on wrong
  points: 0.7 to 37 % off even at h = 1 us (the integrators: 0.002 % at 10 us).

Operating point: s_xfer holds its states at ``int_ic`` = 0 (the plant is at
rest at t = 0 whatever its input); the integrators start at the equilibrium
y = G(0) u(0), which for an integrating plant needs u(0) = 0 (or a loop
around it that holds it there).

Dead time: a lossless transmission line ``T<name>_dt <name>_a 0 <name>_b 0
Z0=50 TD=theta``, matched at both ends. ``E<name>_d`` drives 2 y (stiff)
through ``R<name>_s`` = 50 ohm, and ``R<name>_t`` = 50 ohm terminates the far
end: the far end then sees half the drive, y(t - theta), and nothing is
reflected back from either end. The line has the exact phase -w theta in
``.ac`` and delays a step within 0.001 % at fine steps (the XSPICE ``delay``
block is 0.19 % off and zero in ``.ac``; a Pade approximation is not a
delay). With theta = 0 the line is left out.

Output: ``E<name>_o`` copies the far end (or y) onto the output node, a stiff
voltage source that can drive the controller's difference amplifier. The
input node only controls G sources (or the s_xfer input): it draws no
current.

Names: every internal node is ``<name>_<suffix>`` and every element
``<kind letter><name>_<suffix>``, the suffixes without ``_``: plants of
different names never share a node or an element name, so several share a deck.

Time step: the line does **not** limit ngspice's step (measured: steps of 10 x
TD once the waveform is smooth, the delayed step still within 0.05 %); only
the rational part's dynamics do. :func:`max_step_hint_s` is the largest step
that keeps the plant's own integration error near 0.05 % of a step. The line
sets a breakpoint one delay after its input's slope reverses (its defaults
REL=1 ABS=1), not after a mere corner: a biproper plant passes its input's
edges on, and in a loop with high-frequency gain they come back every theta;
resolve them with a step below their rise time (measured: a 20 us edge, 0.7 %
off at 2 us steps, 3 % at 10 us).
"""

from __future__ import annotations

import math
import re

import numpy as np

from ..core.errors import DesignError
from ..core.lti import coefficients

__all__ = ["FORMS", "HINT_WH", "max_step_hint_s", "normalise", "plant_lines", "poles"]

#: the realisations of the rational part (see the module's notes)
FORMS = ("integrators", "s_xfer")
#: characteristic impedance of the dead-time line, and its two terminations (ohm)
LINE_Z0_OHM = 50.0
#: the leak from each integrator node to ground, relative to the unit transconductances
LEAK_S = 1e-12
#: w h (the fastest pole's magnitude times the step) for about 0.05 % error in a step response,
#: measured over FOPDT, SOPDT, zeta = 0.1 and 0.3, a zero, an integrating plant (worst: zeta = 0.1)
HINT_WH = {"integrators": 0.05, "s_xfer": 0.0015}

_NODE = re.compile(r"^[A-Za-z0-9_]+$")
_NAME = re.compile(r"^[A-Za-z][A-Za-z0-9_]*$")


def _num(x: float) -> str:
    """A number for the deck: plain float text with 12 significant digits."""
    return "%.12g" % x


def _theta(theta_s) -> float:
    try:
        th = float(theta_s)
    except (TypeError, ValueError):
        raise DesignError("theta_s: the dead time must be a number of seconds", param="theta_s") from None
    if not math.isfinite(th) or th < 0:
        raise DesignError(f"theta_s: the dead time must be finite and >= 0 s (got {theta_s!r})", param="theta_s")
    return th


def normalise(num, den):
    """The rational part in normalised frequency s' = s T.

    Parameters
    ----------
    num, den : sequence of float
        N(s) and D(s), highest power first; deg N <= deg D (proper).

    Returns
    -------
    T : float
        The time scale, seconds: (a_n/a_k)^(1/(n-k)) with a_k the lowest
        non-zero coefficient of D (the geometric mean of the time constants;
        for an integrating plant those of its non-zero poles). For D = a_n s^n
        (pure integrators) the numerator's lowest term sets it instead (the
        time in which the output moves by the input), and T = 1 s for a static gain.
    alpha : ndarray
        A(s') = D(s'/T)/(leading coefficient), ascending powers, alpha[n] = 1.
    beta : ndarray
        B(s') = N(s'/T)/(the same), ascending powers, length n + 1 (zero padded).

    Raises
    ------
    DesignError
        For non-finite or all-zero coefficients, or an improper H (deg N > deg D).
    """
    b = coefficients(num, "num")[::-1]
    a = coefficients(den, "den")[::-1]
    n = a.size - 1
    if b.size - 1 > n:
        raise DesignError(f"num: the plant is improper (numerator degree {b.size - 1} > denominator degree {n}); "
                          "a physical plant has deg N <= deg D", param="num")
    k = int(np.flatnonzero(a)[0])
    if k < n:
        T = abs(a[n] / a[k]) ** (1.0 / (n - k))
    else:
        # D = a_n s^n: no time constant in D; N's lowest term below s^n sets the scale (none: a static gain)
        j = [i for i in np.flatnonzero(b) if i < n]
        T = abs(a[n] / b[j[0]]) ** (1.0 / (n - j[0])) if j else 1.0
    p = T ** -np.arange(n + 1)
    alpha = a * p
    beta = np.zeros(n + 1)
    beta[:b.size] = b * p[:b.size]
    lead = alpha[n]
    return T, alpha / lead, beta / lead


def _check_nodes(inp, out, name) -> None:
    for label, node in (("inp", inp), ("out", out)):
        if not isinstance(node, str) or not _NODE.match(node):
            raise DesignError(f"{label}: node name {node!r} must be letters, digits or _", param=label)
    if not isinstance(name, str) or not _NAME.match(name):
        raise DesignError(f"name: {name!r} must start with a letter and be letters, digits or _", param="name")
    if out == "0":
        raise DesignError("out: the plant's output cannot be ground (node 0)", param="out")
    if inp.lower() == out.lower():
        raise DesignError(f"out: the output node must differ from the input node ({inp!r})", param="out")
    own = re.compile(rf"^{re.escape(name)}_(?:[xydab]|z\d+)$", re.I)
    for label, node in (("inp", inp), ("out", out)):
        if own.match(node):
            raise DesignError(f"{label}: {node!r} is one of the plant's own nodes ({name}_...); "
                              "use another node or another name", param=label)


def plant_lines(num, den, theta_s, inp: str, out: str, name: str = "plant", form: str = "integrators") -> list:
    """Deck lines of the plant G(s) = N(s)/D(s) e^(-theta s) from node ``inp`` to node ``out``.

    Parameters
    ----------
    num, den : sequence of float
        N(s) and D(s), highest power first (``[2]``, ``[1e-3, 1]`` is 2/(1 ms s + 1));
        proper (deg N <= deg D); D may have a zero constant term (an integrating plant).
    theta_s : float
        Dead time, seconds (>= 0; 0 leaves the line out).
    inp, out : str
        The input node (it draws no current) and the output node (a stiff voltage
        source to ground).
    name : str
        Prefix of every internal node (``<name>_...``) and element name, unique in the deck.
    form : {"integrators", "s_xfer"}
        How the rational part is built (see the module's notes; ``s_xfer`` is
        first-order accurate and unfit for closed loops in ngspice 39).

    Returns
    -------
    list of str
        Element (and, for ``s_xfer``, ``.model``) lines: no analysis, no ``.control``, no include.

    Raises
    ------
    DesignError
        For a bad polynomial, an improper H, a negative or non-finite dead
        time, bad node names or an unknown ``form``.
    """
    if form not in FORMS:
        raise DesignError(f"form: unknown realisation {form!r}; allowed: {', '.join(FORMS)}", param="form")
    _check_nodes(inp, out, name)
    theta = _theta(theta_s)
    T, alpha, beta = normalise(num, den)
    n = alpha.size - 1
    d = beta[n]                   # direct feedthrough of a biproper H
    rest = beta[:n] - d * alpha[:n]   # B - d A: the strictly proper part's numerator
    y = f"{name}_y"
    lines = [f"* plant {name}: G(s) = N(s)/D(s) exp(-{_num(theta)} s), time scale T = {_num(T)} s, "
             f"realised as {form}",
             f"R{name}_y {y} 0 1"]   # the output sum: currents into 1 ohm
    dynamic = n > 0 and np.any(rest != 0)
    if dynamic and form == "integrators":
        lines += _integrator_lines(alpha, rest, T, inp, y, name)
    elif dynamic:
        lines += _s_xfer_lines(alpha, rest, T, inp, y, name)
    if d != 0:
        lines.append(f"G{name}_d 0 {y} {inp} 0 {_num(d)}")
    if theta > 0:
        z0 = _num(LINE_Z0_OHM)
        lines += [f"E{name}_d {name}_d 0 {y} 0 2",             # 2 y: the matched far end sees y
                  f"R{name}_s {name}_d {name}_a {z0}",          # source match: nothing comes back
                  f"T{name}_dt {name}_a 0 {name}_b 0 Z0={z0} TD={_num(theta)}",
                  f"R{name}_t {name}_b 0 {z0}",                 # load match: nothing is reflected
                  f"E{name}_o {out} 0 {name}_b 0 1"]
    else:
        lines.append(f"E{name}_o {out} 0 {y} 0 1")
    return lines


def _integrator_lines(alpha, rest, T, inp, y, name) -> list:
    """The controllable canonical form as G-fed capacitors (see the module's notes)."""
    n = alpha.size - 1
    z = [f"{name}_z{k}" for k in range(n)]
    lines = []
    for k in range(n):
        lines += [f"C{name}_z{k} {z[k]} 0 {_num(T)}", f"R{name}_z{k} {z[k]} 0 {_num(1 / LEAK_S)}"]
    for k in range(n - 1):
        lines.append(f"G{name}_c{k} 0 {z[k]} {z[k + 1]} 0 1")      # z_k' = z_(k+1)
    lines.append(f"G{name}_u 0 {z[n - 1]} {inp} 0 1")             # z_(n-1)' = u - sum alpha_i z_i
    lines += [f"G{name}_a{k} {z[n - 1]} 0 {z[k]} 0 {_num(alpha[k])}" for k in range(n) if alpha[k] != 0]
    lines += [f"G{name}_b{k} 0 {y} {z[k]} 0 {_num(rest[k])}" for k in range(n) if rest[k] != 0]
    return lines


def _s_xfer_lines(alpha, rest, T, inp, y, name) -> list:
    """The strictly proper part as an XSPICE s_xfer (see the module's notes)."""
    n = alpha.size - 1
    # s_xfer's states: the deepest ~ gain x input, the others ~ gain x input x T^-i (i-th derivative);
    # for T > 1 s the gain keeps the smallest, ~ input T^(1-n), at the input's order
    gain = T ** (n - 1) if T > 1 else 1.0
    numc = rest[::-1] / gain
    numc = numc[np.flatnonzero(numc)[0]:]
    fmt = lambda c: " ".join(_num(v) for v in c)  # noqa: E731
    return [f"A{name}_x {inp} {name}_x {name}_xfer",
            f".model {name}_xfer s_xfer(in_offset=0 gain={_num(gain)} num_coeff=[{fmt(numc)}] "
            f"den_coeff=[{fmt(alpha[::-1])}] int_ic=[{' '.join(['0'] * n)}] denormalized_freq={_num(1 / T)})",
            f"G{name}_x 0 {y} {name}_x 0 1"]


def poles(num, den) -> np.ndarray:
    """The poles of N(s)/D(s), rad/s (roots found in normalised frequency, for conditioning).

    Parameters
    ----------
    num, den : array_like
        The numerator and denominator coefficients, highest power first.

    Returns
    -------
    numpy.ndarray
        The poles (complex, rad/s); empty for a constant denominator.
    """
    T, alpha, _ = normalise(num, den)
    if alpha.size < 2:
        return np.zeros(0, dtype=complex)
    return np.roots(alpha[::-1]) / T


def max_step_hint_s(num, den, theta_s, form: str = "integrators") -> float:
    """The largest ``.tran`` time step that keeps the plant's integration error near 0.05 % of a step.

    It is :data:`HINT_WH` / (the largest magnitude among the non-zero poles);
    ``inf`` when there is none (a static gain, pure integrators: nothing of the
    plant needs resolving). The dead time does not enter: in ngspice 39 the
    line neither limits the step nor loses accuracy at steps longer than it
    (``theta_s`` is checked and kept in the signature so that the whole model is passed).

    Parameters
    ----------
    num, den : sequence of float
        N(s) and D(s), highest power first.
    theta_s : float
        Dead time, seconds.
    form : {"integrators", "s_xfer"}
        The realisation: s_xfer, first-order accurate, needs a step about 30 times shorter.

    Returns
    -------
    float
        Seconds (the deck's own signals may need shorter steps still).
    """
    if form not in FORMS:
        raise DesignError(f"form: unknown realisation {form!r}; allowed: {', '.join(FORMS)}", param="form")
    _theta(theta_s)
    mags = np.abs(poles(num, den))
    mags = mags[mags > 1e-9 * max(mags.max(initial=0.0), 1e-300)]
    if mags.size == 0:
        return math.inf
    return HINT_WH[form] / float(mags.max())
