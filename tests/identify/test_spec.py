"""The identify request (issue 26): an IdentifySpec is validated once, when built, its errors naming the
library's parameters (the command line shows its options for them from designer.cli.common.FLAGS), and
identify_file is what the ``identify`` command does with a file."""

from __future__ import annotations

import json
from pathlib import Path

import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

from designer.cli.common import FLAGS, flag_message
from designer.core.errors import DesignError, ParamError
from designer.core.jsonio import json_safe
from designer.core.ranges import RANGES
from designer.identify.frequency import identify_freq
from designer.identify.io import FORMATS, read_freq_table
from designer.identify.spec import (
    FREQUENCY_TABLE,
    STEP_ONLY,
    IdentifySpec,
    frequency_table_header,
    identify_dict,
    identify_file,
    identify_spec,
)

FIXTURES = Path(__file__).resolve().parents[1] / "fixtures"
CAPTURE = FIXTURES / "identify" / "tektronix_mso.csv"
TABLE = FIXTURES / "identify_freq" / "seed003_table31.csv"

def inside(key):
    """Finite numbers inside the range ``RANGES[key]``."""
    r = RANGES[key]
    return st.floats(r.lo, r.hi, allow_nan=False, allow_infinity=False)


@settings(max_examples=200, deadline=None)
@given(step_time=inside("capture_time_s"), amplitude=inside("step_amplitude"), negative=st.booleans(),
       window=st.lists(inside("capture_time_s"), min_size=2, max_size=2, unique=True),
       fmt=st.sampled_from(("auto",) + FORMATS), upper=st.booleans(), sample=inside("sample_time_s"),
       segment=st.integers(RANGES["segment_length"].lo, RANGES["segment_length"].hi), as_text=st.booleans(),
       method=st.sampled_from([None, "correlation", "spectral"]), refine=st.booleans())
def test_valid_plain_parameters_build_the_values_given(step_time, amplitude, negative, window, fmt, upper, sample,
                                                       segment, as_text, method, refine):
    amp = -amplitude if negative else amplitude
    t0, t1 = sorted(window)

    def typed(x):
        return repr(x) if as_text else x
    spec = identify_spec({"capture": "c.csv", "step_time_s": typed(step_time), "step_amplitude": typed(amp),
                          "window": [typed(t0), typed(t1)], "fmt": fmt.upper() if upper else fmt,
                          "sample_time_s": typed(sample), "segment_length": str(segment) if as_text else segment,
                          "method": method, "refine": refine, "input_column": None})
    assert (spec.step_time_s, spec.step_amplitude, spec.window) == (step_time, amp, (t0, t1))
    assert (spec.fmt, spec.sample_time_s, spec.segment_length, spec.method) == (fmt, sample, segment, method)
    assert spec.refine is refine and spec.input_column is None
    # what a front end set is what the spec says it was given (a table refuses those)
    assert spec.given() == [n for n in STEP_ONLY if n in ("step_time_s", "step_amplitude", "window",
                                                          "sample_time_s", "segment_length")
                            or (n == "fmt" and fmt != "auto") or (n == "method" and method is not None)
                            or (n == "refine" and not refine)]


#: a bad value of each parameter (outside its range, not a number, not one of the allowed)
BAD = st.one_of(
    st.tuples(st.just("step_time_s"), st.sampled_from(["1e11", -2e10, "4x", float("nan"), "inf"])),
    st.tuples(st.just("step_amplitude"), st.sampled_from([0, "0", "1e13", 1e-13, "x", -1e13])),
    st.tuples(st.just("window"), st.sampled_from([["1"], ["1", "2", "3"], ["2m", "1m"], ["0", "x"], ["1e11", "0"],
                                                  "1"])),
    st.tuples(st.just("fmt"), st.text(min_size=1, max_size=12).filter(
        lambda s: s.strip().lower() not in ("auto",) + FORMATS)),
    st.tuples(st.just("sample_time_s"), st.sampled_from([0, "0", "-1", "1e7", "y"])),
    st.tuples(st.just("segment_length"), st.sampled_from([0, 15, "3", 2 ** 21, "z"])),
    st.tuples(st.just("method"), st.sampled_from(["fourier", "", "step"])),
    st.tuples(st.just("refine"), st.sampled_from(["yes", 1, "true"])),
    st.tuples(st.just("methods"), st.sampled_from([[1, 2], [None]])),
    st.tuples(st.sampled_from(["capture", "validate", "against"]), st.sampled_from([3, 2.5, ["a.csv"]])),
)


@settings(max_examples=200, deadline=None)
@given(bad=BAD)
def test_a_bad_plain_parameter_is_refused_naming_it(bad):
    name, value = bad
    params = {"capture": "c.csv", name: value}
    with pytest.raises(DesignError) as caught:
        identify_spec(params)
    exc = caught.value
    assert "\n" not in str(exc)
    if name == "method":   # the broadband route's own check writes its option (identify's choices)
        assert str(exc).startswith("--method ")
    assert exc.param == name, (exc.param, str(exc))
    # the command line shows its option for it (or the message's own words name it: "the window must start ...")
    assert (name in FLAGS and FLAGS[name] in flag_message(exc)) or name in str(exc), flag_message(exc)


def test_an_unknown_parameter_or_no_capture_is_refused():
    with pytest.raises(DesignError, match="'step_time' is not a parameter of an identification; allowed: .*"
                                          "step_time_s"):
        identify_spec({"capture": "c.csv", "step_time": "1"})
    with pytest.raises(DesignError, match="capture is required") as caught:
        identify_spec({"step_time_s": "1"})
    assert caught.value.param == "capture"


def test_the_clis_messages_are_the_ones_it_printed():
    """The library names parameters; through FLAGS the command line prints what it printed before."""
    cases = [({"step_amplitude": "0"}, "--step-amplitude must be non-zero (its size 1e-12 to 1e+12, either sign)"),
             ({"step_amplitude": "1e13"}, "the size of --step-amplitude (either sign) must be 1e-12 to 1e+12, "
                                          "got '1e13'"),
             ({"window": ["0", "x"]}, "--window T1: 'x' is not a number"),
             ({"fmt": "bogus"}, "--format 'bogus' unknown; allowed: auto, "),
             ({"segment_length": "3"}, "--segment-length must be 16 to 1.04858e+06, got '3'"),
             ({"sample_time_s": "0"}, "--sample-time must be 1 ps to 1e+06 s, got '0'")]
    for params, words in cases:
        with pytest.raises(DesignError) as caught:
            identify_spec({"capture": "c.csv", **params})
        assert flag_message(caught.value).startswith(words), flag_message(caught.value)


def test_a_frequency_table_is_identify_freqs_analysis_and_refuses_step_settings():
    assert frequency_table_header(TABLE) is not None and frequency_table_header(CAPTURE) is None
    result = identify_file(identify_spec({"capture": str(TABLE)}))
    want = identify_freq(read_freq_table(TABLE))
    got = json_safe(identify_dict(result))
    assert got == json_safe({"format": FREQUENCY_TABLE, **want.to_dict()})
    assert json.dumps(got, allow_nan=False)
    with pytest.raises(ParamError) as caught:
        identify_file(IdentifySpec(str(TABLE), step_time_s=0, refine=False), ("out_folder",))
    exc = caught.value
    assert str(exc).startswith("step_time_s, refine, out_folder are for a step capture; ")
    assert flag_message(exc).startswith("--step-time, --no-refine, --out are for a step capture; ")
    assert "(header f_hz,gain_db)" in str(exc) and exc.param == "step_time_s"


def test_a_step_capture_is_identified_with_its_settings():
    whole = identify_file(IdentifySpec(str(CAPTURE)))
    assert identify_dict(whole) == whole.to_dict() and whole.to_dict()["capture"]["format"] == "tektronix-mso"
    cut = identify_file(IdentifySpec(str(CAPTURE), window=("-0.1m", "1.5m"), refine=False))
    got = cut.to_dict()
    assert not any(m["name"] == "least-squares" for m in got["methods"])
    assert got["best"]["params"] != whole.to_dict()["best"]["params"]   # the window took effect
