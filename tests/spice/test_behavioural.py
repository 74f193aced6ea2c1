"""The behavioural plant (:mod:`designer.spice.behavioural`) against the exact
G(s) = N(s)/D(s) e^(-theta s): step responses (scipy's step of the rational
part, shifted by theta, on SPICE's time points), ``.ac`` magnitude and phase
(-w theta included), closed PI loops around it, and the decks' standalone form.
Every simulated deck runs under both backends."""

import math
import re
import subprocess
from dataclasses import dataclass
from functools import lru_cache

import numpy as np
import pytest
from scipy import linalg, signal

from designer.core.errors import DesignError
from designer.spice.behavioural import FORMS, HINT_WH, max_step_hint_s, normalise, plant_lines, poles
from designer.spice.deck import STEPS_PER_TIME_SCALE
from designer.spice.simulate import get_simulator

BACKENDS = ("pyspice", "ngspice-cli")
WN = 2 * math.pi * 500.0
#: the accuracy asked of every step response and closed loop: a fraction of the step size
STEP_TOL = 0.005


@dataclass(frozen=True)
class Case:
    num: tuple
    den: tuple
    theta_s: float
    t0_s: float      # the input step's time
    stop_s: float    # a finite window (the integrating plant's output ramps on)


CASES = {
    "fopdt": Case((2.0,), (1e-3, 1.0), 200e-6, 1e-3, 10e-3),
    "sopdt": Case((1.5,), tuple(np.polymul([1e-3, 1], [0.3e-3, 1])), 300e-6, 1e-3, 12e-3),
    "underdamped": Case((1.0,), (1 / WN**2, 2 * 0.3 / WN, 1.0), 300e-6, 1e-3, 15e-3),
    "zero": Case((0.5e-3, 1.0), (1e-6, 1.2e-3, 1.0), 100e-6, 1e-3, 15e-3),
    "integrating": Case((50.0,), (10e-3, 1.0, 0.0), 1e-3, 1e-3, 50e-3),
    "slow": Case((1.0,), (10.0, 1.0), 2.0, 1.0, 60.0),
    "fast": Case((1.0,), (2e-6, 1.0), 0.5e-6, 1e-6, 20e-6),
    "biproper": Case((1e-3, 1.0), (0.5e-3, 1.0), 200e-6, 1e-3, 10e-3),
}


def _num(x: float) -> str:
    return "%.12g" % x


def standalone(lines) -> str:
    """A deck from lines, refused unless it can run alone (``ngspice -b deck.cir``)."""
    text = "\n".join(lines) + "\n"
    assert not re.search(r"^\s*\.(control|endc)\b", text, re.I | re.M), "a .control block"
    assert not re.search(r"^\s*\.(include|inc|lib)\b", text, re.I | re.M), "an include"
    assert text.rstrip().lower().endswith(".end")
    return text


def step_deck(c: Case, form: str, max_step: float, extra=()) -> str:
    """A PULSE step (0 -> 1 V at t0, edges 1e-7 of the window) into the plant, and ``.tran``."""
    edge = c.stop_s * 1e-7
    return standalone(["behavioural plant step",
                       f"V1 in 0 PULSE(0 1 {_num(c.t0_s)} {_num(edge)} {_num(edge)} "
                       f"{_num(10 * c.stop_s)} {_num(20 * c.stop_s)})",
                       *plant_lines(c.num, c.den, c.theta_s, "in", "out", form=form),
                       f".tran {_num(max_step)} {_num(c.stop_s)} 0 {_num(max_step)}", *extra, ".end"])


@lru_cache(maxsize=None)
def _exact_step_grid(c: Case):
    # 50001 points: linear interpolation adds < 1e-7 of the step (h^2/8 |y''|) to every case
    grid = np.linspace(0.0, c.stop_s - c.t0_s - c.theta_s, 50001)
    _, ys = signal.step(signal.lti(c.num, c.den), T=grid)
    return grid, ys


def exact_step(c: Case, t) -> np.ndarray:
    """The exact unit step response at times ``t``: scipy's on a fine uniform grid, shifted, interpolated."""
    tau = np.asarray(t) - c.t0_s - c.theta_s
    grid, ys = _exact_step_grid(c)
    return np.where(tau > 0, np.interp(tau, grid, ys), 0.0)


def step_errors(c: Case, res):
    """Max and RMS error as fractions of the step size (the exact response's largest magnitude)."""
    t, y = res["time"], res["out"]
    ye = exact_step(c, t)
    err = y - ye
    size = np.abs(ye).max()
    return np.abs(err).max() / size, math.sqrt(np.mean(err**2)) / size


def hint(c: Case, form: str) -> float:
    return min(max_step_hint_s(c.num, c.den, c.theta_s, form), c.stop_s / 200)


# ----------------------------------------------------------------------------------------- the lines


@pytest.mark.parametrize("form", FORMS)
@pytest.mark.parametrize("case", CASES)
def test_lines_are_prefixed_and_end_in_a_stiff_output(case, form):
    c = CASES[case]
    lines = plant_lines(c.num, c.den, c.theta_s, "u", "y", name="gp", form=form)
    for ln in lines:
        if ln.startswith(("*", ".model")):
            continue
        ref, *nodes = ln.split()
        assert re.fullmatch(r"gp_[a-z]+\d*", ref[1:].lower()), ln   # <kind><name>_<suffix without _>
        for node in nodes[:4 if ref[0] in "EGT" else 2]:
            assert node in ("0", "u", "y") or node.startswith("gp_"), ln
    out = [ln for ln in lines if ln.split()[0] == "Egp_o"]
    assert len(out) == 1 and out[0].split()[1:3] == ["y", "0"]   # the output: an E source to ground
    # the input only controls sources (no element has it as a terminal)
    for ln in lines:
        ref, *nodes = ln.split()
        if ref[0] in "RCT":
            assert "u" not in nodes, ln
        if ref[0] in "EG":
            assert "u" not in nodes[:2], ln


def test_dead_time_is_a_matched_line_and_zero_leaves_it_out():
    c = CASES["fopdt"]
    lines = plant_lines(c.num, c.den, c.theta_s, "u", "y")
    assert "Eplant_d plant_d 0 plant_y 0 2" in lines
    assert "Rplant_s plant_d plant_a 50" in lines
    assert "Tplant_dt plant_a 0 plant_b 0 Z0=50 TD=0.0002" in lines
    assert "Rplant_t plant_b 0 50" in lines
    no_delay = plant_lines(c.num, c.den, 0.0, "u", "y")
    assert not [ln for ln in no_delay if ln[0] == "T"] and "Eplant_o y 0 plant_y 0 1" in no_delay


@pytest.mark.parametrize("case", ["slow", "fast", "underdamped", "integrating"])
def test_coefficients_are_normalised_near_one(case):
    c = CASES[case]
    T, alpha, beta = normalise(c.num, c.den)
    assert alpha[-1] == 1.0
    nz = np.abs(alpha[alpha != 0])
    assert nz.max() / nz.min() < 10       # whether the plant is a 2 us or a 10 s one
    for form in FORMS:
        text = "\n".join(plant_lines(c.num, c.den, c.theta_s, "u", "y", form=form))
        values = [abs(float(v)) for v in re.findall(r"(?<![\w.])[-+]?\d[\d.]*(?:e[-+]?\d+)?(?=[\s\])]|$)", text)]
        skip = (0.0, 50.0, 1e12, T, 1 / T, c.theta_s)   # ground, the line, the leak, the time scale, the delay
        gains = [v for v in values if not any(math.isclose(v, k, rel_tol=1e-9) for k in skip)]
        assert all(1e-3 < v < 1e3 for v in gains), (form, gains)


def test_s_xfer_is_given_one_initial_condition_per_state_and_the_denormalisation():
    c = CASES["underdamped"]
    T, _, _ = normalise(c.num, c.den)
    model = next(ln for ln in plant_lines(c.num, c.den, 0.0, "u", "y", form="s_xfer") if ln.startswith(".model"))
    assert "int_ic=[0 0]" in model and f"denormalized_freq={_num(1 / T)}" in model
    assert "den_coeff=[1 " in model


def test_normalise_keeps_the_transfer_function():
    for c in CASES.values():
        T, alpha, beta = normalise(c.num, c.den)
        s = 1j * np.logspace(-2, 2, 7) / T
        exact = np.polyval(c.num, s) / np.polyval(c.den, s)
        assert np.allclose(np.polyval(beta[::-1], s * T) / np.polyval(alpha[::-1], s * T), exact, rtol=1e-12)


def test_poles_and_step_hint():
    c = CASES["underdamped"]
    assert np.allclose(np.abs(poles(c.num, c.den)), WN)
    assert max_step_hint_s(c.num, c.den, c.theta_s) == pytest.approx(HINT_WH["integrators"] / WN)
    assert max_step_hint_s(c.num, c.den, c.theta_s, "s_xfer") < max_step_hint_s(c.num, c.den, c.theta_s) / 20
    # the delay does not enter; a pole at 0 is not a time scale; nothing to resolve: no limit
    assert max_step_hint_s(c.num, c.den, 1.0) == max_step_hint_s(c.num, c.den, 0.0)
    assert max_step_hint_s([50], [10e-3, 1, 0], 1e-3) == pytest.approx(HINT_WH["integrators"] / 100)
    assert max_step_hint_s([50], [1, 0], 1e-3) == math.inf and max_step_hint_s([3], [2], 0) == math.inf


def test_static_gain_and_pure_integrator():
    assert "Gplant_d 0 plant_y u 0 1.5" in plant_lines([3], [2], 0.0, "u", "y")
    T, alpha, beta = normalise([50], [1, 0])
    assert T == pytest.approx(0.02) and list(alpha) == [0, 1] and beta[0] == pytest.approx(1)


@pytest.mark.parametrize("kw, param", [
    (dict(num=[1, 2, 3], den=[1, 1]), "num"),
    (dict(den=[0, 0]), "den"),
    (dict(num=[float("nan")]), "num"),
    (dict(num=[]), "num"),
    (dict(theta_s=-1e-3), "theta_s"),
    (dict(theta_s=float("inf")), "theta_s"),
    (dict(inp="a b"), "inp"),
    (dict(out="0"), "out"),
    (dict(out="u"), "out"),
    (dict(out="plant_y"), "out"),
    (dict(name="1x"), "name"),
    (dict(form="laplace"), "form"),
])
def test_refusals_name_the_parameter(kw, param):
    args = dict(num=[2], den=[1e-3, 1], theta_s=1e-4, inp="u", out="y")
    args.update(kw)
    with pytest.raises(DesignError) as exc:
        plant_lines(**args)
    assert exc.value.param == param and str(exc.value).startswith(param)


# ----------------------------------------------------------------------------------------- step responses


@pytest.mark.spice
@pytest.mark.parametrize("backend", BACKENDS)
@pytest.mark.parametrize("form", FORMS)
@pytest.mark.parametrize("case", CASES)
def test_step_response_matches_the_exact_one(case, form, backend):
    c = CASES[case]
    res = get_simulator(backend).run(step_deck(c, form, hint(c, form)))
    worst, rms = step_errors(c, res)
    assert worst < STEP_TOL and rms < STEP_TOL, (worst, rms)
    # measured at the hint: within 0.1 %, the integrators within 0.03 %
    assert worst < (3e-4 if form == "integrators" else 1e-3)


@pytest.mark.spice
@pytest.mark.parametrize("backend", BACKENDS)
@pytest.mark.parametrize("case", ["fopdt", "underdamped", "zero", "slow", "fast"])
def test_integrators_are_accurate_at_the_projects_own_step(case, backend):
    # the project's decks step at 1/(50 wn): the default form is within 0.01 % there, s_xfer is not
    c = CASES[case]
    step = 1 / (STEPS_PER_TIME_SCALE * np.abs(poles(c.num, c.den)).max())
    worst, _ = step_errors(c, get_simulator(backend).run(step_deck(c, "integrators", step)))
    assert worst < 1e-4
    worst_sx, _ = step_errors(c, get_simulator(backend).run(step_deck(c, "s_xfer", step)))
    assert worst_sx > 10 * worst


@pytest.mark.spice
@pytest.mark.parametrize("backend", BACKENDS)
def test_the_line_does_not_limit_the_time_step(backend):
    # theta = tau/100 at steps of 5 theta: ngspice steps past the delay and the delayed step stays exact
    c = Case((2.0,), (1e-3, 1.0), 10e-6, 1e-3, 10e-3)
    res = get_simulator(backend).run(step_deck(c, "integrators", 5 * c.theta_s))
    assert np.median(np.diff(res["time"])) > 4 * c.theta_s
    worst, rms = step_errors(c, res)
    assert worst < 2e-4 and rms < 1e-4


# ----------------------------------------------------------------------------------------- .ac


def ac_deck(c: Case, form: str, f_lo: float, f_hi: float) -> str:
    return standalone(["behavioural plant ac", "V1 in 0 DC 0 AC 1",
                       *plant_lines(c.num, c.den, c.theta_s, "in", "out", form=form),
                       f".ac dec 40 {_num(f_lo)} {_num(f_hi)}", ".end"])


@pytest.mark.spice
@pytest.mark.parametrize("backend", BACKENDS)
@pytest.mark.parametrize("form", FORMS)
@pytest.mark.parametrize("case", CASES)
def test_ac_matches_the_exact_frequency_response(case, form, backend):
    c = CASES[case]
    T, _, _ = normalise(c.num, c.den)
    fc = 1 / (2 * math.pi * T)    # the corner: two decades around it
    res = get_simulator(backend).run(ac_deck(c, form, fc / 10, fc * 10))
    f, h = np.real(res["frequency"]), res["out"]
    w = 2 * math.pi * f
    g = np.polyval(c.num, 1j * w) / np.polyval(c.den, 1j * w)
    mag_err = 20 * np.log10(np.abs(h)) - 20 * np.log10(np.abs(g))
    exact_phase = np.unwrap(np.angle(g)) - w * c.theta_s
    phase = np.unwrap(np.angle(h))
    phase += 2 * math.pi * round((exact_phase[0] - phase[0]) / (2 * math.pi))   # same branch at f_lo
    assert np.abs(mag_err).max() < 0.1
    assert np.degrees(np.abs(phase - exact_phase)).max() < 0.5
    assert np.degrees(np.abs(phase - exact_phase)).max() < 1e-3    # measured: exact to rounding


# ----------------------------------------------------------------------------------------- closed loops


def pi_loop_deck(c: Case, kp: float, ki: float, rise: float, max_step: float, form="integrators") -> str:
    """A behavioural PI (e = r - y, u = kp e + ki int e) around the plant; r ramps 0 -> 1 V at t0."""
    return standalone(["behavioural plant in a PI loop",
                       f"V1 r 0 PULSE(0 1 {_num(c.t0_s)} {_num(rise)} {_num(rise)} "
                       f"{_num(10 * c.stop_s)} {_num(20 * c.stop_s)})",
                       "Ee e 0 r y 1",
                       "Ci i 0 1", f"Gi 0 i e 0 {_num(ki)}", "Ri i 0 1e15",
                       f"Bu u 0 V={_num(kp)}*V(e)+V(i)",
                       *plant_lines(c.num, c.den, c.theta_s, "u", "y", form=form),
                       f".tran {_num(max_step)} {_num(c.stop_s)} 0 {_num(max_step)}", ".end"])


@lru_cache(maxsize=None)
def loop_reference(c: Case, kp: float, ki: float, rise: float, per_delay: int = 200):
    """The PI loop with dead time, sampled at theta/per_delay: the plant exact for a piecewise-linear
    input (first-order hold), the integral trapezoidal; the delay breaks the algebraic loop."""
    A, B, C, D = signal.tf2ss(c.num, c.den)
    n, h = A.shape[0], c.theta_s / per_delay
    M = np.zeros((n + 2, n + 2))
    M[:n, :n], M[:n, n], M[n, n + 1] = A, B[:, 0], 1 / h
    E = linalg.expm(M * h)
    phi, g0, g1 = E[:n, :n], E[:n, n], E[:n, n + 1]
    N = int(round(c.stop_s / h)) + 1
    t = np.arange(N) * h
    r = np.clip((t - c.t0_s) / rise, 0.0, 1.0)
    x, integral, e, u = np.zeros(n), 0.0, r[0], kp * r[0]
    y_plant, y = np.zeros(N), np.zeros(N)
    for k in range(N - 1):
        y_plant[k] = C[0] @ x + D[0, 0] * u
        y[k + 1] = y_plant[k + 1 - per_delay] if k + 1 >= per_delay else 0.0
        e1 = r[k + 1] - y[k + 1]
        integral += h / 2 * ki * (e + e1)
        u1 = kp * e1 + integral
        x = phi @ x + g0 * u + g1 * (u1 - u)
        e, u = e1, u1
    return t, y


LOOPS = {   # plant, kp, ki (SIMC-like PI: well damped)
    "fopdt": (CASES["fopdt"], 1.25, 1250.0),
    "integrating": (Case((50.0,), (10e-3, 1.0, 0.0), 1e-3, 5e-3, 150e-3), 0.3, 2.0),
}


@pytest.mark.spice
@pytest.mark.parametrize("backend", BACKENDS)
@pytest.mark.parametrize("loop", LOOPS)
def test_pi_loop_with_dead_time(loop, backend):
    c, kp, ki = LOOPS[loop]
    rise = c.theta_s / 10
    res = get_simulator(backend).run(pi_loop_deck(c, kp, ki, rise, hint(c, "integrators")))
    t_ref, y_ref = loop_reference(c, kp, ki, rise)
    err = res["y"] - np.interp(res["time"], t_ref, y_ref)
    assert np.abs(err).max() < STEP_TOL and math.sqrt(np.mean(err**2)) < STEP_TOL
    assert len(res["time"]) < 5 * c.stop_s / hint(c, "integrators")    # no collapse of the time step


@pytest.mark.spice
@pytest.mark.parametrize("backend", BACKENDS)
def test_pi_loop_keeps_its_time_step_with_a_sharp_reference(backend):
    # 1 ns edges into the loop: the line's breakpoints must not cascade (s_xfer's do: no end in minutes)
    c = Case(CASES["fopdt"].num, CASES["fopdt"].den, CASES["fopdt"].theta_s, 0.0, 20e-3)
    res = get_simulator(backend).run(pi_loop_deck(c, 0.5, 500.0, 1e-9, 10e-6))
    assert len(res["time"]) < 1.2 * c.stop_s / 10e-6
    assert res["y"][-1] == pytest.approx(1.0, abs=1e-4)


@lru_cache(maxsize=None)
def closed_loop_reference(c: Case, kp: float, ki: float, rise: float):
    """The PI loop without dead time: the exact closed loop (kp s + ki) G / (s + (kp s + ki) G), lsim of the ramp."""
    ln, ld = np.polymul([kp, ki], c.num), np.polymul([1, 0], c.den)
    grid = np.linspace(0, c.stop_s, 50001)   # the ramp's corners (1 ms, 1.02 ms) on the grid
    _, y, _ = signal.lsim(signal.lti(ln, np.polyadd(ld, ln)), np.clip((grid - c.t0_s) / rise, 0, 1), grid)
    return grid, y


@pytest.mark.spice
@pytest.mark.parametrize("backend", BACKENDS)
@pytest.mark.parametrize("case", ["biproper", "zero", "fopdt"])
def test_pi_loop_without_dead_time_matches_the_exact_closed_loop(case, backend):
    # no line: the loop is algebraic through the plant's feedthrough and its Jacobian (s_xfer's is wrong)
    c0 = CASES[case]
    c = Case(c0.num, c0.den, 0.0, 1e-3, 10e-3)
    kp, ki, rise = 0.5, 400.0, 20e-6
    res = get_simulator(backend).run(pi_loop_deck(c, kp, ki, rise, 10e-6))
    grid, y_ref = closed_loop_reference(c, kp, ki, rise)
    err = res["y"] - np.interp(res["time"], grid, y_ref)
    assert np.abs(err).max() < 1e-3


# ----------------------------------------------------------------------------------------- standalone


@pytest.mark.spice
def test_deck_runs_alone_with_ngspice_b(tmp_path):
    c = CASES["fopdt"]
    at = c.t0_s + c.theta_s + 1e-3     # one time constant after the delayed step
    deck = step_deck(c, "integrators", hint(c, "integrators"), extra=[f".meas tran yat FIND v(out) AT={_num(at)}"])
    path = tmp_path / "plant.cir"
    path.write_text(deck)
    out = subprocess.run(["ngspice", "-b", str(path)], capture_output=True, text=True, cwd=tmp_path, timeout=60)
    assert out.returncode == 0, out.stdout + out.stderr
    m = re.search(r"^\s*yat\s*=\s*([-+\d.eE]+)", out.stdout, re.M)
    assert m and float(m.group(1)) == pytest.approx(2 * (1 - math.exp(-1)), rel=1e-3)


@pytest.mark.spice
@pytest.mark.parametrize("backend", BACKENDS)
def test_two_plants_share_a_deck(backend):
    # names keep the plants apart, even "p" and "p_d" (p has a node p_d): two plants in series, theta added
    a, b = CASES["fopdt"], CASES["sopdt"]
    deck = standalone(["two plants", "V1 in 0 PULSE(0 1 1m 1n 1n 1 2)",
                       *plant_lines(a.num, a.den, a.theta_s, "in", "mid", name="p"),
                       *plant_lines(b.num, b.den, b.theta_s, "mid", "out", name="p_d"),
                       ".tran 5u 15m 0 5u", ".end"])
    res = get_simulator(backend).run(deck)
    both = Case(tuple(np.polymul(a.num, b.num)), tuple(np.polymul(a.den, b.den)), a.theta_s + b.theta_s, 1e-3, 15e-3)
    worst, _ = step_errors(both, res)
    assert worst < 1e-3
