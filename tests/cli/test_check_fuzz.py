"""check-design and analyze-pid driven with generated input (the property tests
of issue 7, for the commands issues 10 and 11 added).

check-design gets generated spec files: every key the format has, typos of
them, and values across 600 orders of magnitude, odd strings, lists and maps
where numbers belong, and bytes that are no YAML at all. Whatever it reads, it
ends with exit status 0, 1, 2 or 3 (ngspice is unreachable in these tests, so a
spec that needs a simulation is a simulator error); on 2 with exactly one line
on stderr naming the file; never a traceback, a printed warning or a numpy
repr. analyze-pid gets generated part values, with ``--no-sim``.
``CHECK_FUZZ_EXAMPLES`` raises the number of examples for a deeper run.
"""

import contextlib
import copy
import io
import os
import warnings

import yaml
from fuzzing import ODD, sci
from hypothesis import HealthCheck, given, settings
from hypothesis import strategies as st

from designer.check.sections import SUB
from designer.check.spec import TOP
from designer.cli.check import check_design_main
from designer.cli.pid import analyze_pid_main

SCALE = float(os.environ.get("CHECK_FUZZ_EXAMPLES", "1"))


def examples(n):
    return settings(max_examples=max(1, int(n * SCALE)), deadline=None,
                    suppress_health_check=[HealthCheck.function_scoped_fixture, HealthCheck.too_slow])


def run(main, prog, argv, allowed=(0, 1, 2, 3)):
    """Run a command in-process; returns (status, stderr) after checking the contract."""
    out, err = io.StringIO(), io.StringIO()
    with warnings.catch_warnings(record=True) as caught:
        warnings.simplefilter("always")
        with contextlib.redirect_stdout(out), contextlib.redirect_stderr(err):
            status = main(argv)   # an exception here is a traceback for the user
    out, err = out.getvalue(), err.getvalue()
    assert not caught, [f"{w.category.__name__}: {w.message}" for w in caught]
    assert status in allowed, (status, err)
    for stream in (out, err):
        assert "Traceback" not in stream and "np.float64(" not in stream and "Warning:" not in stream
    if status == 2:
        lines = err.splitlines()
        assert len(lines) == 1 and lines[0].startswith(f"{prog}: error: "), err
    return status, err


# ---- generated specs ------------------------------------------------------------

def number():
    return st.one_of(sci(), st.sampled_from(ODD), st.floats(allow_nan=True, allow_infinity=True),
                     st.integers(-10 ** 30, 10 ** 30), st.sampled_from(["3k5", "0.2", "10n", "-1%", "+5%", "1m"]))


def value(depth=0):
    leaves = st.one_of(number(), st.booleans(), st.none(), st.text(max_size=12))
    if depth >= 2:
        return leaves
    return st.one_of(leaves, st.lists(value(depth + 1), max_size=3),
                     st.dictionaries(key(), value(depth + 1), max_size=4))


def key():
    words = sorted({k for ks in (*TOP.values(), *SUB.values()) for k in ks})
    names = words + ["fc", "zeta", "gain", "R1", "R2", "C1", "C2", "R3", "min", "typ", "max", "fail", "nrms_max",
                     "against", "file", "reltol", "abstol", "fn_hz", "overshoot_pct", "slew_rate", "amplitude",
                     "frequency", "kp", "ti", "td"]
    typo = st.sampled_from(names).map(lambda k: k[:-1] + "x" if len(k) > 1 else k + "x")
    return st.one_of(st.sampled_from(names), typo, st.text(max_size=6))


#: valid specs of each kind (as the dogfood specs in specs/), the starting points of the mutations
BASES = [
    {"kind": "plant", "target": {"fc": "3.5k", "zeta": 0.2}, "series": {"r": "E24", "c": "E12"},
     "opamp": ["LM741", "TL072"], "stimulus": {"amplitude": 2},
     "checks": {"fn_hz": {"min": "3k", "max": "4.2k"}, "zeta": {"typ": 0.2, "min": "-2%", "max": "+2%"},
                "zeta_opamp": {"min": 0.199, "fail": False}},
     "design_checks": "all", "tolerance": ["fn_hz"]},
    {"kind": "plant", "parts": {"R1": 820, "R2": "1k", "C1": "10n", "C2": "220n"},
     "checks": {"q": {"min": 1}}, "design_checks": ["slew_rate"]},
    {"kind": "pid", "plant": {"fc": "3.5k", "zeta": 0.2}, "tuning": "zn", "opamp": "LM741",
     "checks": {"kp": {"typ": 3.31, "min": "-1%", "max": "+1%"}}, "design_checks": ["integrator_corner"]},
    {"kind": "netlist", "deck": "d.cir", "checks": {"vmax": {"min": 0.9, "max": 1.1}}},
]


def mutate(draw, doc):
    """One change somewhere in ``doc``: a value replaced, a key added or removed."""
    path, node = [], doc
    while isinstance(node, dict) and node and draw(st.booleans()):
        k = draw(st.sampled_from(sorted(node, key=str)))
        path.append(k)
        node = node[k]
    parent = doc
    for k in path[:-1]:
        parent = parent[k]
    what = draw(st.sampled_from(["replace", "add", "remove"]))
    if what == "replace" and path:
        parent[path[-1]] = draw(st.one_of(number(), value()))
    elif what == "remove" and path:
        del parent[path[-1]]
    elif isinstance(node, dict):
        node[draw(key())] = draw(st.one_of(number(), value()))


@st.composite
def spec_text(draw):
    doc = copy.deepcopy(draw(st.sampled_from(BASES)))
    for _ in range(draw(st.integers(0, 3))):
        mutate(draw, doc)
    if draw(st.integers(0, 14)) == 0:
        return draw(st.binary(max_size=60))
    text = yaml.safe_dump(doc, allow_unicode=True)
    if draw(st.integers(0, 9)) == 0:   # broken YAML
        cut = draw(st.integers(0, len(text)))
        text = text[:cut] + draw(st.sampled_from(["{", "]", ": :", "\t", "- [", "'"]))
    return text.encode("utf-8")


DECK = "rc\nV1 in 0 PULSE(0 1 0 1n 1n 1 2)\nR1 in out 1k\nC1 out 0 1u\n.tran 10u 5m\n.meas tran vmax MAX v(out)\n.end\n"


@examples(60)
@given(data=spec_text())
def test_any_spec_ends_in_a_verdict_or_one_line(data, tmp_path_factory):
    folder = tmp_path_factory.mktemp("spec")
    (folder / "d.cir").write_text(DECK)
    path = folder / "s.yaml"
    path.write_bytes(data)
    status, err = run(check_design_main, "check-design", [str(path), "--timeout", "20"])
    if status == 2:
        assert "s.yaml" in err or "--" in err, err


#: the seed's controller parts (seed 001, V.13), the starting point of analyze-pid's values
SEED = {"--r3": "12k", "--r4": "1.777k", "--r5": "22k", "--r6": "3.3k", "--r7": "14.356k", "--r8": "1.2k",
        "--r9": "10k", "--r10": "10k", "--r11": "10k", "--r12": "1.026k", "--r13": "26.048k", "--r14": "2.528k",
        "--r15": "10k", "--r16": "10k", "--r17": "10k", "--r18": "10k", "--c3": "4.7n", "--c4": "47n"}


@examples(40)
@given(changed=st.dictionaries(st.sampled_from(sorted(SEED)),
                               st.one_of(sci(), st.sampled_from(ODD), st.sampled_from(["10k", "4n7", "1k", "47n"])),
                               max_size=4),
       dropped=st.lists(st.sampled_from(sorted(SEED)), max_size=2))
def test_analyze_pid_with_any_parts_ends_in_a_result_or_one_line(changed, dropped, tmp_path_factory):
    out = tmp_path_factory.mktemp("out")
    argv = ["--plant-fc", "3500", "--plant-zeta", "0.2", "--no-sim", "--out", str(out)]
    for flag, v in {**SEED, **changed}.items():
        if flag not in dropped:
            argv += [f"{flag}={v}"]
    status, _ = run(analyze_pid_main, "analyze-pid", argv, allowed=(0, 1, 2))
    if status == 2:
        assert not any(out.rglob("*.json"))
