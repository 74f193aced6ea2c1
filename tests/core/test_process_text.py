"""Process models typed by hand (parse_tf): each form against its constructor,
engineering notation and list spellings, every refusal one line naming the key,
and printed models parsing back."""

import json

import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

from designer.core.errors import DesignError
from designer.core.process import ProcessModel
from designer.core.process_build import (
    MAX_DEAD_TIME_RATIO,
    fopdt,
    integrating,
    rational,
    sopdt,
    underdamped,
)
from designer.core.process_text import parse_tf
from designer.core.units import format_eng


def _same(a: ProcessModel, b: ProcessModel) -> bool:
    """The same model up to the last bit of a parsed number ("200u" is 200 * 1e-6, not 200e-6)."""
    near = lambda x, y: x == pytest.approx(y, rel=1e-15, abs=0)   # noqa: E731
    return (a.kind == b.kind and a.source == b.source and a.ci95 == b.ci95 and set(a.params) == set(b.params)
            and all(near(a.params[k], b.params[k]) for k in a.params)
            and near(a.num, b.num) and near(a.den, b.den) and near(a.theta_s, b.theta_s))


# --------------------------------------------------------------------------- typed models

EXAMPLES = [
    ("K=2 tau=1m theta=200u", fopdt(2, 1e-3, 200e-6)),
    ("K=1 tau1=2m tau2=500u theta=300u", sopdt(1, 2e-3, 500e-6, 300e-6)),
    ("K=1 fn=500 zeta=0.3 theta=0", underdamped(1, 500, 0.3, 0)),
    ("num=[1] den=[1m 1] theta=0", rational([1], [1e-3, 1], 0)),
    ("K=50 tau=10m integrator", integrating(50, 10e-3)),
    ("K=50 integrator theta=1m", integrating(50, 0, 1e-3)),
]


@pytest.mark.parametrize("text, model", EXAMPLES, ids=[e[0] for e in EXAMPLES])
def test_parse_tf_equals_the_constructor(text, model):
    assert _same(parse_tf(text), model)
    assert _same(parse_tf(text.upper().replace("M", "m").replace("U", "u")), model)   # keys in any case


def test_parse_tf_reads_engineering_notation_and_list_spellings():
    assert parse_tf("K=4k7 tau=1m theta=2u2").params == {"K": 4700.0, "tau_s": 1e-3, "theta_s": 2.2e-6}
    assert parse_tf("K=1 fn=3.5meg zeta=0.5").params["fn_hz"] == 3.5e6
    assert _same(parse_tf("k = 2  tau = 1.5 ms theta=200 us"), fopdt(2, 1.5e-3, 200e-6))
    assert parse_tf("K=1 fn=500Hz zeta=0.3") == underdamped(1, 500, 0.3)
    spelled = [parse_tf(t) for t in ("num=[2m, 1] den=[1u,2m,1]", "num=[2m 1] den=[ 1u 2m 1 ]",
                                     "NUM=[2m, 1]  DEN=[1u  2m, 1] theta=0")]
    assert spelled[0] == spelled[1] == spelled[2]
    assert _same(spelled[0], rational([2e-3, 1], [1e-6, 2e-3, 1]))
    assert _same(parse_tf("num=1 den=[1m 1]"), rational([1], [1e-3, 1]))
    assert _same(parse_tf("K=1 tau_s=1m theta_s=1u"), fopdt(1, 1e-3, 1e-6))
    # commas or semicolons between words, as MATLAB users type them
    assert _same(parse_tf("K=2, tau=1.5 ms; theta=200u"), fopdt(2, 1.5e-3, 200e-6))
    assert _same(parse_tf("K=2,tau=1m,"), fopdt(2, 1e-3, 0.0))


REFUSALS = [
    ("K=2 tua=1m", ["tua", "tau"]),                       # unknown key, closest one
    ("K=2 tau=1m thetta=1u", ["thetta", "theta"]),
    ("K=2 tau=1m integrater", ["integrater", "integrator"]),
    ("K=2 tau=1m tau=2m", ["tau", "twice"]),
    ("K=2 tau=1m tau_s=2m", ["tau", "twice"]),
    ("K=1 tau1=1m", ["tau2", "missing"]),
    ("tau=1m", ["K", "missing"]),
    ("num=[1]", ["den", "missing"]),
    ("K=2", ["K", "tau"]),
    ("", ["K", "tau"]),
    ("K=x tau=1m", ["K", "not a number"]),
    ("K=2 tau=1q", ["tau", "not a number"]),
    ("num=[1 x] den=[1 1]", ["num", "not a number"]),
    ("K=2 tau=0", ["tau", "positive"]),
    ("K=2 tau=-1m", ["tau", "positive"]),
    ("K=1 tau1=1m tau2=0", ["tau2", "positive"]),
    ("K=50 tau=-1 integrator", ["tau", "positive"]),
    ("K=0 tau=1m", ["K", "non-zero"]),
    ("K=inf tau=1m", ["K", "number"]),
    ("K=1e300 tau=1m", ["K", "1e+09"]),
    ("K=1 fn=500 zeta=1.2", ["zeta", "below 1", "SOPDT", "tau1", "tau2"]),
    ("K=1 fn=500 zeta=1", ["zeta", "SOPDT"]),
    ("K=1 fn=500 zeta=0", ["zeta", "0.0001 or more", "below 1"]),
    ("K=1 fn=500 zeta=-0.1", ["zeta", "0.0001 or more", "below 1"]),
    ("K=1 fn=0 zeta=0.5", ["fn", "Hz"]),
    ("num=[1] den=[1 -1]", ["den", "s = +1", "stable"]),
    ("num=[1] den=[1 0 1]", ["den", "imaginary axis"]),
    ("num=[1] den=[1 -1 1]", ["den", "right half plane"]),
    ("num=[1] den=[1m 0]", ["den", "s = 0", "integrator"]),
    ("num=[1 2 3] den=[1m 1]", ["num", "degree 2", "den", "degree 1", "proper"]),
    ("num=[1] den=[5]", ["den", "pole"]),
    ("num=[1 0] den=[1 1]", ["num", "zero at s = 0"]),
    ("num=[0] den=[1 1]", ["num", "zeros"]),
    ("num=[] den=[1 1]", ["num", "empty"]),
    ("num=[1 den=[1 1]", ["num", "]"]),
    ("num=[1] den=[1 1 1 1 1 1 1 1 1 1 1 1]", ["den", "degree"]),
    ("K=2 tau=1m theta=1", ["theta", "100 times", "1 ms"]),
    ("K=1 fn=500 zeta=0.3 theta=1", ["theta", "100 times"]),
    ("num=[1] den=[1m 1] theta=1", ["theta", "100 times"]),
    ("K=2 tau=1m theta=-1u", ["theta", "0 to"]),
    ("K=1 tau=1m fn=500", ["fn", "tau", "different forms"]),
    ("K=1 tau=1m tau1=2m tau2=1m", ["tau", "different forms"]),
    ("K=1 tau=1m num=[1] den=[1 1]", ["different forms"]),
    ("K=1 fn=500 zeta=0.3 integrator", ["integrator", "different forms"]),
    ("K=2 tau=1m integrator=1", ["integrator", "bare word"]),
    ("K=2 tau", ["tau", "needs a value"]),
    ("K=2 tau=", ["tau", "no value"]),
    ("K=2 tau=[1m 2m]", ["tau", "one number"]),
    ("K=2 tau:1m", ["tau:1m", "key=value"]),
    ("K=2 %", ["%", "key=value"]),
    # a decimal comma (the seeds' Spanish notation) is refused with the number it meant, never read as two words
    ("K=1,25 tau=124,6m", ["K=1,25", "K=1.25", "decimal point"]),
    ("K=2 tau=1m theta=0,2m", ["theta=0,2m", "theta=0.2m"]),
]


@pytest.mark.parametrize("text, words", REFUSALS, ids=[r[0] or "empty" for r in REFUSALS])
def test_every_refusal_is_one_line_naming_the_key(text, words):
    with pytest.raises(DesignError) as e:
        parse_tf(text)
    msg = str(e.value)
    assert "\n" not in msg and "array(" not in msg and "Traceback" not in msg
    for w in words:
        assert w in msg, (w, msg)


def test_a_dead_time_is_zero_or_at_least_a_picosecond():
    """Bug fixed (the CLI fuzz): theta = 2e-144 s passed, and the rules that divide by it gave Kp = 1e143."""
    assert parse_tf("K=1 tau=1 theta=1p").theta_s == 1e-12
    with pytest.raises(DesignError, match="must be 0 or at least 1 ps"):
        parse_tf("K=1 tau=1 theta=2e-144")


def test_the_dead_time_limit_is_the_documented_ratio():
    parse_tf(f"K=1 tau=1m theta={MAX_DEAD_TIME_RATIO * 1e-3}")
    with pytest.raises(DesignError):
        parse_tf(f"K=1 tau=1m theta={MAX_DEAD_TIME_RATIO * 1e-3 * 1.001}")


_MAG = st.floats(-6, 6).map(lambda e: 10.0 ** e)
_TAU = st.floats(-9, 3).map(lambda e: 10.0 ** e)


@settings(max_examples=200)
@given(K=_MAG, negative=st.booleans(), tau1=_TAU, tau2=st.none() | _TAU, ratio=st.floats(0, 50))
def test_format_eng_printed_models_parse_back(K, negative, tau1, tau2, ratio):
    K = -K if negative else K
    theta = ratio * max(tau1, tau2 or 0.0)
    theta = 0.0 if theta < 1e-12 else theta     # a dead time is 0 or at least 1 ps
    if tau2 is None:
        model, text = fopdt(K, tau1, theta), f"K={format_eng(K)} tau={format_eng(tau1, 's')}"
    else:
        model, text = sopdt(K, tau1, tau2, theta), (f"K={format_eng(K)} tau1={format_eng(tau1, 's')} "
                                                     f"tau2={format_eng(tau2)}")
    got = parse_tf(f"{text} theta={format_eng(theta)}")
    assert got.kind == model.kind and set(got.params) == set(model.params)
    for k, v in model.params.items():
        assert got.params[k] == pytest.approx(v, rel=6e-4, abs=1e-300), k


_SOUP = st.lists(st.sampled_from(["K=", "k=", "tau=", "tau1=", "tau2=", "fn=", "zeta=", "theta=", "num=", "den=",
                                  "integrator", "[", "]", ",", " ", "=", "1", "0", "-", "1m", "4k7", "2u2", "3.5meg",
                                  "1e308", "1e-308", "5e-324", "nan", "inf", ".", "e", "x", "µ", "\t", "s", "Hz",
                                  "0.3", "1.2", "500", "K", "tau"]),
                 max_size=25).map("".join)


@settings(max_examples=400)
@given(text=st.text(max_size=60) | _SOUP)
def test_garbage_only_ever_raises_design_error(text):
    try:
        m = parse_tf(text)
    except DesignError as e:
        assert "\n" not in str(e)
        return
    assert isinstance(m, ProcessModel)
    m.text()
    json.dumps(m.to_dict(), allow_nan=False)


def test_parse_tf_refuses_what_is_not_text():
    with pytest.raises(DesignError, match="text"):
        parse_tf(None)


# --------------------------------------------------------------------------- factored forms (issue 28)

from designer.core.process_text import factor_list, factored_text  # noqa: E402


def _expanded(K, zeros, poles):
    """num, den of a factored model by numpy's own products (independent of the parser)."""
    import numpy as np
    num, den = np.array([float(K)]), np.array([1.0])
    for c, p in zeros:
        for _ in range(p):
            num = np.polymul(num, c)
    for c, p in poles:
        for _ in range(p):
            den = np.polymul(den, c)
    return num / den[-1], den / den[-1]


def test_the_issue_s_factored_plant_is_the_product_of_its_factors():
    import numpy as np
    m = parse_tf("K=1 zeros=[-0.3s+1, 0.08s+1] poles=[2s+1, s+1, 0.4s+1, 0.2s+1, (0.05s+1)^3] theta=0.1")
    num, den = _expanded(1.0, [([-0.3, 1], 1), ([0.08, 1], 1)],
                         [([2, 1], 1), ([1, 1], 1), ([0.4, 1], 1), ([0.2, 1], 1), ([0.05, 1], 3)])
    assert m.kind == "rational" and m.theta_s == 0.1 and m.gain == pytest.approx(1.0, rel=1e-15)
    assert np.allclose(m.num, num, rtol=1e-14) and np.allclose(m.den, den, rtol=1e-14)
    assert sorted(m.time_constants_s) == pytest.approx(sorted([2, 1, 0.4, 0.2, 0.05, 0.05, 0.05]), rel=1e-4)


@pytest.mark.parametrize("text, same_as", [
    ("K=2 poles=[2s+1, s+1]", "K=2 poles=[( 2s + 1 )(s+1)]"),
    ("K=2 poles=[2s+1, s+1]", "K=2 poles=[(2s+1) * (s+1)]"),
    ("K=2 poles=[2s+1, s+1]", "K=2 poles=[(2s+1) (s+1)]"),
    ("K=2 poles=[2s+1, s+1]", "K=2 poles=[2*s+1, 1s+1]"),
    ("K=2 poles=[2s+1, s+1]", "k=2 POLES=[2s +1, s + 1]"),
    ("K=2 poles=[0.05s+1, 0.05s+1, 0.05s+1]", "K=2 poles=[(50ms+1)^3]"),
    ("K=2 poles=[s^2+0.2s+1]", "K=2 poles=[s^2 + 200m*s + 1]"),
    ("K=2 poles=[0.4s+1]", "K=2 poles=0.4s+1"),
    ("K=2 poles=[0.4s+1]", "num=[2] den=[0.4 1]"),
    ("K=2 zeros=[-0.3s+1] poles=[2s+1, s+1] theta=1", "num=[-0.6 2] den=[2 3 1] theta=1"),
])
def test_factored_spellings_give_the_same_model(text, same_as):
    import numpy as np
    a, b = parse_tf(text), parse_tf(same_as)
    assert np.allclose(a.num, b.num, rtol=1e-14) and np.allclose(a.den, b.den, rtol=1e-14)
    assert a.theta_s == b.theta_s


@pytest.mark.parametrize("text, words", [
    ("K=1 poles=[2s+1", ("unbalanced bracket", "no closing ]", "poles=[")),
    ("K=1 poles=[(2s+1]", ("unbalanced bracket", "'(' with no ')'", "poles=[2s+1")),
    ("K=1 poles=[2s+1)]", ("unbalanced bracket", "')' with no '('")),
    ("K=1 poles=[2s+1]]", ("unbalanced bracket", "never opened")),
    ("K=1 poles=[]", ("no factor", "poles=[2s+1")),
    ("K=1 zeros=[ ] poles=[s+1]", ("zeros=[] has no factor", "leave zeros out")),
    ("K=1 poles=[2s+1,,s+1]", ("empty factor",)),
    ("K=1 poles=[2x+1]", ("unknown word 'x'", "'2x+1'", "polynomials in s")),
    ("K=1 poles=[(s+1)x]", ("'x' outside the brackets",)),
    ("K=1 poles=[(s+1)^0]", ("'^0'", "positive whole number")),
    ("K=1 poles=[(s+1)^1.5]", ("'^1.5'", "positive whole number")),
    ("K=1 poles=[(s+1)^-2]", ("'^-2'", "positive whole number")),
    ("K=1 poles=[(s+1)^99999999999]", ("positive whole number up to 10",)),
    ("K=1 poles=[s^x+1]", ("'s^x'", "positive whole number")),
    ("K=1 poles=[s+1^2]", ("bracketed factor",)),
    ("K=1 poles=[2s + s]", ("two terms in s^1",)),
    ("K=1 poles=[0.4 s+1]", ("only a space between",)),
    ("K=1 poles=[2s+1 s+1]", ("only a space between", "separate factors with commas")),
    ("K=1 poles=[s^2 + 200m s + 1]", ("only a space between",)),
    ("K=1 poles=[2, s+1]", ("constant factor",)),
    ("K=1 poles=[s+1] pole=2", ("unknown key 'pole'", "did you mean poles", "zeros, poles")),
    ("K=1 zeros=[s+1, s+2] poles=[s+1]", ("proper",)),
    ("K=1 poles=[-s+1]", ("right half plane",)),
    ("zeros=[s+1] poles=[s+1, s+2]", ("missing K", "K [zeros] poles [theta]")),
    ("K=1 tau=2 poles=[s+1]", ("different forms", "(factored)")),
    ("K=1 poles=[(s+1)^6, (s+1)^5]", ("degree 11", "at most 10")),
])
def test_every_factored_refusal_is_one_line(text, words):
    with pytest.raises(DesignError) as err:
        parse_tf(text)
    msg = str(err.value)
    assert "\n" not in msg and all(w in msg for w in words), msg


_TAUS = st.floats(1e-3, 1e3, allow_nan=False, allow_infinity=False)


@st.composite
def _factored(draw):
    """A random proper, stable factored model: first-order factors (zeros of either sign) and
    underdamped pairs, with powers."""
    poles = [([draw(_TAUS), 1.0], draw(st.integers(1, 3))) for _ in range(draw(st.integers(1, 2)))]
    if draw(st.booleans()):
        wn, zeta = 1.0 / draw(_TAUS), draw(st.floats(0.05, 0.95))
        poles.append(([1.0 / wn ** 2, 2 * zeta / wn, 1.0], 1))
    order = sum((len(c) - 1) * p for c, p in poles)
    zeros = []
    for _ in range(draw(st.integers(0, min(2, order)))):
        zeros.append(([draw(_TAUS) * draw(st.sampled_from([1.0, -1.0])), 1.0], 1))
    K = draw(st.floats(1e-3, 1e3)) * draw(st.sampled_from([1.0, -1.0]))
    theta = draw(st.sampled_from([0.0, 0.5, 1.25])) * poles[0][0][0]   # within the dead-time limit
    return K, zeros, poles, theta


@settings(max_examples=150, deadline=None)
@given(_factored())
def test_a_printed_factored_model_parses_back_to_the_same_num_and_den(model):
    import numpy as np
    K, zeros, poles, theta = model
    text = factored_text(K, poles, zeros, theta)
    parsed = parse_tf(text)
    num, den = _expanded(K, zeros, poles)
    assert np.allclose(parsed.num, num, rtol=1e-12, atol=0) and np.allclose(parsed.den, den, rtol=1e-12, atol=0), text
    assert parsed.theta_s == theta


@settings(max_examples=200, deadline=None)
@given(st.text(alphabet="s0123456789.+-*^() ,xK", max_size=30))
def test_factor_lists_only_ever_raise_design_error(text):
    try:
        c = factor_list(text)
    except DesignError as exc:
        assert "\n" not in str(exc)
    else:
        assert c.size >= 1
