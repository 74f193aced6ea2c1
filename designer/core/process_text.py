"""Process models typed by hand: :func:`parse_tf` reads ``key=value`` words
separated by spaces, commas or semicolons into a :class:`~designer.core.process.ProcessModel`.

Forms (:data:`FORMS`; keys case-insensitive, :data:`KEYS` for their spellings,
values in engineering notation, theta 0 when not given):

- ``K tau [theta]``               FOPDT, K e^(-theta s) / (tau s + 1)
- ``K tau1 tau2 [theta]``         SOPDT, K e^(-theta s) / ((tau1 s + 1)(tau2 s + 1))
  (overdamped; sorted, tau1 >= tau2)
- ``K fn zeta [theta]``           underdamped, K wn^2 e^(-theta s) / (s^2 + 2 zeta wn s + wn^2),
  wn = 2 pi fn, fn in Hz
- ``num den [theta]``             rational, N(s) e^(-theta s) / D(s), coefficients highest
  power first, commas or spaces inside the brackets (``num=[1] den=[1m 1]``)
- ``K [tau] integrator [theta]``  integrating, K e^(-theta s) / (s (tau s + 1)) (no tau: K/s)
- ``K [zeros] poles [theta]``     factored, as papers print a plant (e.g. Astrom and Hagglund,
  *Advanced PID Control*, 2006, the test batch of section 7.2):
  ``K=1 zeros=[-0.3s+1, 0.08s+1] poles=[2s+1, s+1, (0.05s+1)^3]``, K times the product of the
  zeros' factors over the product of the poles' (:func:`factor_list`; printed back by
  :func:`factored_text`), built as the rational form

Each form is built by the builder of :mod:`designer.core.process_build` that its
constructor uses, with the typed key names, so a typed model is checked
against the same ranges (:data:`~designer.core.process_build.TAU_RANGE`,
:data:`~designer.core.process_build.GAIN_RANGE`, :data:`~designer.core.process_build.FN_RANGE`,
0 < zeta < 1, :data:`~designer.core.process_build.MAX_DEAD_TIME_RATIO`, a proper
and stable rational part) and a refusal names the key as typed. What cannot
be read (an unknown key, with the closest one; a key given twice; a key
missing for its form; a mix of forms; a value that is not a number) is
refused here, each in one :class:`~designer.core.errors.DesignError` line.
"""

from __future__ import annotations

import difflib
import re

import numpy as np

from .errors import DesignError
# the builders behind the constructors: they take the names a refusal uses
from .process import ProcessModel
from .process_build import MAX_ORDER, build_fopdt, build_integrating, build_rational, build_sopdt, build_underdamped
from .units import parse_value

__all__ = ["KEYS", "INTEGRATOR", "FACTOR_KEYS", "FORMS", "FORMS_TEXT", "FACTORS_TEXT", "parse_tf",
           "factor_list", "factored_text"]

#: what a key of a typed model may be written as (lower case) -> the key
KEYS = {"k": "K", "tau": "tau", "tau_s": "tau", "tau1": "tau1", "tau1_s": "tau1", "tau2": "tau2",
        "tau2_s": "tau2", "fn": "fn", "fn_hz": "fn", "zeta": "zeta", "theta": "theta", "theta_s": "theta",
        "num": "num", "den": "den", "zeros": "zeros", "poles": "poles"}
#: the keys whose lists are factors (polynomials in s), not coefficients
FACTOR_KEYS = ("zeros", "poles")
#: the bare word of the integrating form
INTEGRATOR = "integrator"
#: form -> (required keys, optional keys) of :func:`parse_tf`
FORMS = {
    "fopdt": (("K", "tau"), ("theta",)),
    "sopdt": (("K", "tau1", "tau2"), ("theta",)),
    "underdamped": (("K", "fn", "zeta"), ("theta",)),
    "rational": (("num", "den"), ("theta",)),
    "integrating": (("K", INTEGRATOR), ("tau", "theta")),
    "factored": (("K", "poles"), ("zeros", "theta")),
}
_FORM_NAMES = {"fopdt": "FOPDT", "sopdt": "SOPDT", "underdamped": "underdamped", "rational": "rational",
               "integrating": "integrating", "factored": "factored"}
_ORDER = ("K", "tau", "tau1", "tau2", "fn", "zeta", "num", "den", "zeros", "poles", INTEGRATOR, "theta")
#: the typed key of each library parameter name
_TYPED_NAMES = {"K": "K", "tau_s": "tau", "tau1_s": "tau1", "tau2_s": "tau2", "fn_hz": "fn", "zeta": "zeta",
                "theta_s": "theta", "num": "num", "den": "den"}


def _form_text(form: str, label: bool = True) -> str:
    req, opt = FORMS[form]
    words = " ".join(k if k in req else f"[{k}]" for k in _ORDER if k in req or k in opt)
    return f"{words} ({_FORM_NAMES[form]})" if label else words


FORMS_TEXT = "; ".join(_form_text(f) for f in FORMS)
_KEYS_TEXT = "K, tau, tau1, tau2, fn, zeta, theta, num, den, zeros, poles and the word integrator"
#: the accepted syntax of a factor list, for messages
FACTORS_TEXT = "poles=[2s+1, s+1, (0.05s+1)^3] (factors: polynomials in s such as 0.4s+1 or s^2+0.2s+1, " \
               "a power on a bracketed factor, factors separated by commas)"

_NAME = re.compile(r"[A-Za-z_][A-Za-z0-9_]*", re.ASCII)
_VALUE = re.compile(r"[^\s\[\]=,;]+")
# words are separated by spaces, commas or semicolons ("K=2, tau=1m")
_SPACE = re.compile(r"[\s,;]*")
_DECIMAL_COMMA = re.compile(r"(\d),(\d)")
# a prefix or unit standing alone after a number ("1.5 ms", "200 u", "3.5 kHz"): format_eng's
# own output; an upper-case K alone is the gain key, never kilo, here
_UNIT_WORD = re.compile(r"(?:(?i:meg)|[fpnuµμmkMGT])?(?:s|(?i:hz)|(?i:ohms?))?")


def _show(text: str, limit: int = 40) -> str:
    r = repr(text)
    return r if len(r) <= limit else r[: limit - 4] + "...'"


def _tokens(text: str) -> list:
    """``[(word, value), ...]``: value is None for a bare word, a str for
    ``key=value`` and a list of str for ``key=[a b, c]``."""
    s, pos, out = text, 0, []
    m = _DECIMAL_COMMA.search(s)
    if m and "[" not in s[:m.start()][s[:m.start()].rfind("]") + 1:]:   # outside a list, where commas separate
        word = (s[:m.start()].split() or [""])[-1] if s[:m.start()][-1:].strip() else ""
        word += s[m.start():].split()[0]   # the whole word the comma is in
        point = _DECIMAL_COMMA.sub(r"\1.\2", word)
        raise DesignError(f"{_show(word)}: write the decimal point as a point ({point}); commas only "
                          "separate words and list items")

    def garbage(at: int):
        chunk = s[at:].split()[0] if s[at:].split() else s[at:]
        if chunk[:1] in ("]", ")"):
            return DesignError(f"unbalanced bracket: {_show(chunk)} closes a bracket never opened; write lists "
                               "as num=[1m 1] or " + FACTORS_TEXT)
        return DesignError(f"cannot read {_show(chunk)}: write the plant as key=value words, e.g. "
                           "K=2 tau=1m theta=200u")

    while True:
        pos = start = _SPACE.match(s, pos).end()
        if pos >= len(s):
            return out
        m = _NAME.match(s, pos)
        if not m:
            raise garbage(pos)
        word, pos = m.group(), m.end()
        j = _SPACE.match(s, pos).end()
        if j < len(s) and s[j] == "=":
            pos = _SPACE.match(s, j + 1).end()
            if pos < len(s) and s[pos] == "[":
                close = s.find("]", pos)
                factors = word.lower() in FACTOR_KEYS
                example = f"{word}=[2s+1, (0.05s+1)^3]" if factors else f"{word}=[1m 1]"
                if close < 0:
                    raise DesignError(f"unbalanced bracket: {word}=[ has no closing ]; write lists as {example}")
                inside = s[pos + 1:close]
                if "=" in inside or "[" in inside:
                    raise DesignError(f"unbalanced bracket: {word}=[ has no closing ] before the next key; "
                                      f"write lists as {example}")
                # a factor list is read whole (its factors hold brackets and spaces), a coefficient list by items
                out.append((word, _Factors(inside) if factors else [x for x in re.split(r"[,\s]+", inside) if x]))
                pos = close + 1
            else:
                v = _VALUE.match(s, pos)
                if not v:
                    raise DesignError(f"{word}= has no value: write it as {word}=1m")
                value, pos = v.group(), v.end()
                # a unit or prefix on its own after the number: "tau=1.5 ms"
                k = _SPACE.match(s, pos).end()
                u = _VALUE.match(s, k)
                if u and k > pos and _UNIT_WORD.fullmatch(u.group()) and u.group() and u.group() != "K":
                    after = _SPACE.match(s, u.end()).end()
                    if not (after < len(s) and s[after] == "="):
                        value, pos = value + u.group(), u.end()
                out.append((word, value))
        else:
            out.append((word, None))
        if pos < len(s) and not (s[pos].isspace() or s[pos] in ",;"):
            raise garbage(pos if s[pos] in "])" else start)


def _values(tokens) -> dict:
    """Typed key -> value (float, list of floats, or True for the integrator)."""
    got, raw = {}, {}
    for word, value in tokens:
        low = word.lower()
        if low == INTEGRATOR:
            key = INTEGRATOR
            if value is not None:
                raise DesignError(f"{INTEGRATOR} is a bare word, without a value: write K=50 tau=10m {INTEGRATOR}")
        elif low in KEYS:
            key = KEYS[low]
            if value is None:
                raise DesignError(f"{key} needs a value: write it as {key}=" + ("[1m 1]" if key in ("num", "den")
                                                                               else "1m"))
        else:
            close = difflib.get_close_matches(low, list(KEYS) + [INTEGRATOR], n=1, cutoff=0.6)
            hint = f" (did you mean {KEYS.get(close[0], close[0])}?)" if close else ""
            raise DesignError(f"unknown key {_show(word)}{hint}; the keys are {_KEYS_TEXT}")
        if key in got:
            raise DesignError(f"{key} is given twice ({_pair(key, raw[key])} and {_pair(key, value)}); "
                              "give each key once")
        raw[key] = value
        if key == INTEGRATOR:
            got[key] = True
        elif key in FACTOR_KEYS:
            got[key] = factor_list(value, key)
        elif key in ("num", "den"):
            items = value if isinstance(value, list) else [value]
            got[key] = [parse_value(x, key) for x in items]
        else:
            if isinstance(value, list):
                raise DesignError(f"{key} takes one number, not a list: write it as {key}=1m")
            got[key] = parse_value(value, key)
    return got


def _pair(key, value) -> str:
    if value is None:
        return key
    return f"{key}=[{' '.join(value)}]" if isinstance(value, list) else f"{key}={value}"


def _form(given: set) -> str:
    """The one form the keys ``given`` make, or a refusal naming what is wrong."""
    cover = {f: set(req) | set(opt) for f, (req, opt) in FORMS.items()}
    candidates = [f for f in FORMS if given <= cover[f]]
    if not candidates:
        # a mix: the keys outside the form that covers most of them
        best = max(FORMS, key=lambda f: len(given & cover[f]))
        extra = [k for k in _ORDER if k in given - cover[best]][0]
        mine = [k for k in _ORDER if k in given & cover[best] and k not in ("K", "theta")]
        other = mine[0] if mine else next(k for k in _ORDER if k in given & cover[best])
        raise DesignError(f"{extra} and {other} belong to different forms; give one of: {FORMS_TEXT}")
    complete = [f for f in candidates if set(FORMS[f][0]) <= given]
    if complete:
        return complete[0]
    missing = {f: [k for k in FORMS[f][0] if k not in given] for f in candidates}
    fewest = min(len(v) for v in missing.values())
    near = [f for f in candidates if len(missing[f]) == fewest]
    if len(near) == 1:
        f = near[0]
        return _missing(missing[f], f)
    what = " ".join(k for k in _ORDER if k in given) or "nothing"
    raise DesignError(f"incomplete plant model ({what} given); give one of: {FORMS_TEXT}")


def _missing(keys, form):
    raise DesignError(f"missing {' and '.join(keys)} for the {_FORM_NAMES[form]} form: "
                      f"{_form_text(form, label=False)}")


def parse_tf(text: str) -> ProcessModel:
    """A process model typed by hand: space-separated ``key=value`` words.

    Forms (keys case-insensitive, values in engineering notation, theta 0 when
    not given; ``tau_s``, ``fn_hz``, ``theta_s``... are accepted for the keys):

    - ``K=2 tau=1m theta=200u``                  FOPDT
    - ``K=1 tau1=2m tau2=500u theta=300u``       SOPDT (overdamped; sorted)
    - ``K=1 fn=500 zeta=0.3 theta=0``            underdamped, fn in Hz
    - ``num=[1] den=[1m 1] theta=0``             rational, highest power first,
      commas or spaces inside the brackets
    - ``K=50 tau=10m integrator``, ``K=50 integrator theta=1m``  integrating
    - ``K=1 zeros=[-0.3s+1] poles=[2s+1, (0.05s+1)^3] theta=0.1``  factored:
      K times the zeros' factors over the poles' (:func:`factor_list`)

    A value may carry its unit or prefix after a space, as
    :func:`~designer.core.units.format_eng` prints it (``tau=1.5 ms``).

    Parameters
    ----------
    text : str

    Returns
    -------
    ProcessModel
        With ``source`` ``"typed"``.

    Raises
    ------
    DesignError
        One line naming the key at fault and what is allowed: an unknown key
        (with the closest one), a key given twice, a key missing for the form,
        a mix of forms, a value that is not a number, a factor list with an
        unbalanced bracket, an unknown word, a power that is not a positive
        whole number or no factor (:func:`factor_list`), or a value outside the
        ranges of :mod:`designer.core.process_build` (:data:`~designer.core.process_build.TAU_RANGE`,
        :data:`~designer.core.process_build.GAIN_RANGE`, :data:`~designer.core.process_build.FN_RANGE`,
        0 < zeta < 1, :data:`~designer.core.process_build.MAX_DEAD_TIME_RATIO`, a
        proper and stable rational part).
    """
    if not isinstance(text, str):
        raise DesignError(f"a plant model is text such as 'K=2 tau=1m theta=200u', got {type(text).__name__}")
    got = _values(_tokens(text))
    if not got:
        raise DesignError(f"empty plant model: give one of: {FORMS_TEXT}")
    form = _form(set(got))
    theta = got.get("theta", 0.0)
    n = _TYPED_NAMES
    if form == "fopdt":
        return build_fopdt(got["K"], got["tau"], theta, n, "typed", None)
    if form == "sopdt":
        return build_sopdt(got["K"], got["tau1"], got["tau2"], theta, n, "typed", None)
    if form == "underdamped":
        return build_underdamped(got["K"], got["fn"], got["zeta"], theta, n, "typed", None)
    if form == "rational":
        return build_rational(got["num"], got["den"], theta, n, "typed", None)
    if form == "factored":
        num = got["K"] * np.asarray(got.get("zeros", [1.0]), float)
        return build_rational(num, got["poles"], theta, {**n, "num": "zeros", "den": "poles"}, "typed", None)
    return build_integrating(got["K"], got.get("tau", 0.0), theta, n, "typed", None)


# --------------------------------------------------------------------------- factored forms

class _Factors(str):
    """The text inside a factor list's brackets, kept whole for :func:`factor_list`."""


# a coefficient: a decimal number, then an engineering prefix or none ("50ms+1" is 50m s + 1)
_COEF = re.compile(r"(?:\d+\.?\d*|\.\d+)(?:[eE][+-]?\d+)?(?:meg|MEG|[fpnuµmkMGT](?![a-rt-zA-Z]))?")


def _factor_error(what: str, factor: str, key: str) -> DesignError:
    return DesignError(f"{key}: {what} in the factor {_show(factor)}; write {FACTORS_TEXT}")


def _poly(text: str, factor: str, key: str) -> np.ndarray:
    """The coefficients (highest power first) of a polynomial in s written without spaces."""
    terms, i, n = {}, 0, len(text)
    if n == 0:
        raise _factor_error("an empty bracket", factor, key)
    while i < n:
        sign = 1.0
        if text[i] in "+-":
            sign, i = (-1.0 if text[i] == "-" else 1.0), i + 1
        elif terms:
            raise _factor_error(f"{_show(text[i:])} follows a term with no + or - between", factor, key)
        start = i
        m = _COEF.match(text, i)
        coef = 1.0
        if m:
            coef, i = parse_value(m.group(), key), m.end()
            if i < n and text[i] == "*":
                i += 1
        deg = 0
        if i < n and text[i] == "s":
            deg, i = 1, i + 1
            if i < n and text[i] == "^":
                p = re.match(r"[^+\-*()]*", text[i + 1:]).group()
                deg, i = _power(p, f"s^{p}", factor, key), i + 1 + len(p)
        if i == start or (m is None and deg == 0):
            word = re.match(r"[^+\-*()]*", text[start:]).group() or text[start:start + 1]
            raise _factor_error(f"unknown word {_show(word)}", factor, key)
        if i < n and text[i] == "^":
            raise _factor_error("a power on a term that is not s (a power goes on a bracketed factor, "
                                "(0.05s+1)^3)", factor, key)
        if i < n and text[i] not in "+-":
            word = re.match(r"[^+\-*()]*", text[i:]).group() or text[i]
            raise _factor_error(f"unknown word {_show(word)}", factor, key)
        if deg in terms:
            raise _factor_error(f"two terms in s^{deg} (separate factors with commas)", factor, key)
        terms[deg] = sign * coef
    c = np.zeros(max(terms) + 1)
    for deg, v in terms.items():
        c[-1 - deg] = v
    c = np.trim_zeros(c, "f")
    if c.size == 0:
        raise _factor_error("a factor that is zero", factor, key)
    return c


def _power(text: str, shown: str, factor: str, key: str) -> int:
    """A power: a whole number 1 to :data:`MAX_ORDER` (the highest order a plant may have)."""
    if not (text.isascii() and text.isdigit()) or not 1 <= int(text) <= MAX_ORDER:
        raise _factor_error(f"the power {_show(shown)} is not a positive whole number up to {MAX_ORDER}",
                            factor, key)
    return int(text)


def _factor(text: str, key: str) -> np.ndarray:
    """One factor: a polynomial in s, or bracketed ones multiplied (``(s+1)(2s+1)``, ``*`` allowed), each
    with an optional power."""
    f = re.sub(r"\)\s+([(*])", r")\1", text.strip())   # (2s+1) (s+1): a product, as without the space
    if re.search(r"[\w.)]\s+[\w.(]", f):
        raise _factor_error("two terms with only a space between them (separate factors with commas; "
                            "write a term as 0.4s)", text, key)
    f = "".join(f.split())
    if "(" not in f and ")" not in f:
        return _poly(f, text, key)
    out, i = np.ones(1), 0
    while i < len(f):
        if f[i] == "*" and i > 0:
            i += 1
        if i >= len(f) or f[i] != "(":
            what = ("unbalanced bracket: a ')' with no '('" if ")" in f[i:] and "(" not in f[i:f.find(")", i)]
                    else f"{_show(f[i:])} outside the brackets (write a bracketed factor whole: (0.05s+1)^3)")
            raise _factor_error(what, text, key)
        close = f.find(")", i + 1)
        if close < 0 or "(" in f[i + 1:close]:
            raise _factor_error("unbalanced bracket: a '(' with no ')'", text, key)
        poly, i = _poly(f[i + 1:close], text, key), close + 1
        power = 1
        if i < len(f) and f[i] == "^":
            p = re.match(r"[^(*]*", f[i + 1:]).group()
            power, i = _power(p, "^" + p, text, key), i + 1 + len(p)
        for _ in range(power):
            out = np.polymul(out, poly)
        if out.size - 1 > MAX_ORDER:
            break   # refused, naming the list, by the rational form's own check of its degree
    return out


def factor_list(value, key: str = "poles") -> np.ndarray:
    """The product of a typed factor list, as polynomial coefficients (highest power of s first).

    Parameters
    ----------
    value : str
        The text inside the brackets of ``poles=[...]`` or ``zeros=[...]``:
        factors separated by commas, each a polynomial in s (``0.4s+1``,
        ``-0.3s+1``, ``s^2+0.2s+1``, ``50ms+1``: coefficients in engineering
        notation, an optional ``*``), a bracketed polynomial with a power
        (``(0.05s+1)^3``), or bracketed ones multiplied (``(s+1)(2s+1)``).
        Spaces may stand around signs and brackets; two terms with only a
        space between them (``[2s+1 s+1]``, ``0.4 s``) are refused, never
        guessed.
    key : str
        The list's key, for messages.

    Returns
    -------
    ndarray
        The coefficients of the product, highest power first.

    Raises
    ------
    DesignError
        One line naming the list and the factor: no factor, an unbalanced
        bracket, an unknown word, a power that is not a whole number 1 to
        :data:`~designer.core.process_build.MAX_ORDER`, two terms with no sign
        between them, a factor that is zero.
    """
    text = str(value)
    items = [x.strip() for x in text.split(",")]
    if not any(items):
        raise DesignError(f"{key}=[] has no factor: give at least one"
                          + (" (or leave zeros out)" if key == "zeros" else "") + f", e.g. {FACTORS_TEXT}")
    if not all(items):
        raise DesignError(f"{key}: an empty factor between two commas in {_show('[' + text + ']')}; "
                          f"write {FACTORS_TEXT}")
    out = np.ones(1)
    for item in items:
        f = _factor(item, key)
        if f.size == 1:
            raise _factor_error("a constant factor (the gain goes in K)", item, key)
        out = np.polymul(out, f)
        if out.size - 1 > MAX_ORDER:
            raise DesignError(f"{key} has degree {out.size - 1}; at most {MAX_ORDER} is allowed")
    return out


def _poly_text(c) -> str:
    """A polynomial in s as :func:`factor_list` reads it back exactly (repr of each coefficient)."""
    c = [float(x) for x in c]
    deg = len(c) - 1
    parts = []
    for k, v in enumerate(c):
        p = deg - k
        if v == 0 and p > 0:
            continue
        mag = repr(abs(v))
        s_part = "" if p == 0 else ("s" if p == 1 else f"s^{p}")
        body = mag + s_part if (p == 0 or abs(v) != 1.0) else s_part
        parts.append(("-" if v < 0 else ("+" if parts else "")) + body)
    return "".join(parts)


def factored_text(K: float, poles, zeros=(), theta_s: float = 0.0) -> str:
    """A factored model as :func:`parse_tf` reads it: ``K=.. zeros=[..] poles=[..] theta=..``.

    Parameters
    ----------
    K : float
        The gain multiplying the zeros' factors.
    poles, zeros : sequence of (coefficients, power)
        Each factor's polynomial (highest power of s first) and how many times it is repeated.
    theta_s : float
        Dead time, seconds (written when non-zero).

    Returns
    -------
    str
        The model's text; parsed back it gives the same numerator and denominator (every
        number written as Python's repr, exactly).
    """
    def items(factors):
        return ", ".join(f"({_poly_text(c)})^{p}" if p > 1 else _poly_text(c) for c, p in factors)
    words = [f"K={float(K)!r}"] + ([f"zeros=[{items(zeros)}]"] if len(zeros) else []) + [f"poles=[{items(poles)}]"]
    return " ".join(words + ([f"theta={float(theta_s)!r}"] if theta_s else []))
