"""What an ``identify`` user asks for about one capture, validated once, and the one library call that
identifies it (issue 26: capture-to-model is a library call).

An :class:`IdentifySpec` that exists is a valid one: the step time, the step amplitude, the window, the
sample interval and the Welch segment inside their ranges (:data:`designer.core.ranges.RANGES`), the
layout one that :func:`designer.identify.io.read_capture` reads, the broadband route one of
:data:`designer.identify.broadband.METHODS`. Numbers may be given as numbers or in engineering notation
(``"1.5m"``), so that a front end hands over what its user typed and a refusal quotes it.

:func:`identify_file` does what the ``identify`` command does with a file: a frequency-response table
(its header naming a frequency and a gain column) is analysed as ``identify-freq`` does
(:func:`designer.identify.frequency.identify_freq`, seeds 000 and 003), anything else read as a capture
and identified by every route (:func:`designer.identify.assess.identify_record`: the step methods of
seeds 000-003, the correlation and spectral estimates of seed 003 sections 2.4 and 3.2, the
output-error fits and their validation), compared with a design when one is given
(:func:`designer.identify.against.compare_with_design`).

Errors name the library's parameters (``step_time_s``, ``window``, ``fmt``); the command line shows its
options instead (:data:`designer.cli.common.FLAGS`), the web page its fields' labels
(:func:`designer.web.forms.page_message`): a message about one parameter starts with its name
(:attr:`DesignError.param`), a message about several writes them as ``{name}`` markers
(:class:`~designer.core.errors.ParamError`).
"""

from __future__ import annotations

import os
from dataclasses import dataclass, fields

from ..core.errors import DesignError, ParamError
from ..core.fileio import MAX_CAPTURE_BYTES, SNIFF_BYTES, decode, open_limited, shown
from ..core.ranges import RANGES, parse_in_range
from ..core.units import parse_value

__all__ = ["FREQUENCY_TABLE", "IdentifySpec", "STEP_EDGE_ONLY", "STEP_ONLY", "frequency_table_header",
           "header_text", "identify_dict", "identify_file", "identify_spec"]

#: what ``identify`` says (``format`` in its JSON) of a frequency-response table it was given
FREQUENCY_TABLE = "frequency-table"
#: the parameters only a step capture takes (a frequency table refuses them), in the order a refusal names them
STEP_ONLY = ("step_time_s", "step_amplitude", "window", "fmt", "input_column", "output_column", "sample_time_s",
             "column_names", "methods", "refine", "against", "method", "validate", "segment_length")
#: the parameters of a step's edge, which a broadband capture (PRBS or noise) refuses
STEP_EDGE_ONLY = ("step_time_s", "step_amplitude", "against")
#: each parameter's value when it is not given
_UNSET = {"fmt": "auto", "refine": True}


@dataclass(frozen=True)
class IdentifySpec:
    """An identification request about one file (SI units), validated on construction.

    Parameters
    ----------
    capture : str or path-like
        The file: a capture (any layout :func:`~designer.identify.io.read_capture` reads) or a
        frequency-response table (as ``identify-freq`` reads it).
    step_time_s : float or str, optional
        When the input stepped (default: from the input's edges, else the output's).
    step_amplitude : float or str, optional
        The input step, non-zero, either sign (default: from the input, else 1).
    window : pair of float or str, optional
        Only the samples from ``window[0]`` to ``window[1]`` seconds.
    fmt : str
        The capture's layout, ``auto`` (recognised) or one of :data:`designer.identify.io.FORMATS`.
    input_column, output_column : str or int, optional
        The columns by name or number (``input_column="none"`` ignores an input).
    sample_time_s : float or str, optional
        A file without a time column: its sample interval.
    column_names : str, optional
        With ``sample_time_s``: every column's name in order (``"u,y"``).
    methods : sequence of str, optional
        Only these step methods.
    refine : bool
        The least-squares fits (with their 95 % intervals).
    method : str, optional
        A broadband capture's route alone: ``correlation`` or ``spectral``.
    validate : str or path-like, optional
        A second capture of the same plant (same layout and columns) to score every model on.
    segment_length : int or str, optional
        A noise input's Welch segment, samples.
    against : str or path-like, optional
        A ``design-plant`` result.json to compare the identified plant with.
    name : str, optional
        The capture's name in messages (default: the file's path as shown).

    Returns
    -------
    IdentifySpec
        The request, every value checked and typed.

    Raises
    ------
    DesignError
        One line naming the parameter at fault and what is allowed.
    """

    capture: str
    step_time_s: float | None = None
    step_amplitude: float | None = None
    window: tuple | None = None
    fmt: str = "auto"
    input_column: str | None = None
    output_column: str | None = None
    sample_time_s: float | None = None
    column_names: str | None = None
    methods: tuple | None = None
    refine: bool = True
    method: str | None = None
    validate: str | None = None
    segment_length: int | None = None
    against: str | None = None
    name: str | None = None

    def __post_init__(self):
        def put(key, value):
            object.__setattr__(self, key, value)   # frozen: the spec is normalised once, here

        for key in ("capture", "validate", "against"):
            value = getattr(self, key)
            if value is not None:   # a name the reader cannot open (an empty one too) is the reader's to refuse
                if not isinstance(value, (str, os.PathLike)):
                    raise DesignError(f"{key} needs a file name, got {str(value)[:40]!r}", param=key)
                put(key, os.fspath(value))
        if self.step_time_s is not None:
            put("step_time_s", parse_in_range(self.step_time_s, "step_time_s", "capture_time_s"))
        if self.step_amplitude is not None:
            put("step_amplitude", _amplitude(self.step_amplitude))
        if self.window is not None:
            put("window", _window(self.window))
        fmt = str(self.fmt).strip().lower()
        from .io import FORMATS
        if fmt not in ("auto",) + FORMATS:
            raise DesignError(f"fmt {fmt!r} unknown; allowed: auto, {', '.join(FORMATS)}", param="fmt")
        put("fmt", fmt)
        for key in ("input_column", "output_column", "column_names"):
            value = getattr(self, key)
            if value is not None:
                put(key, str(value))
        if self.sample_time_s is not None:
            put("sample_time_s", parse_in_range(self.sample_time_s, "sample_time_s", "sample_time_s"))
        if self.methods is not None:
            methods = (self.methods,) if isinstance(self.methods, str) else self.methods
            if not all(isinstance(m, str) for m in methods):
                raise DesignError(f"methods are names, such as smith or least-squares, got {methods!r:.60}",
                                  param="methods")
            put("methods", tuple(methods))
        if not isinstance(self.refine, bool):
            raise DesignError(f"refine is a switch: true or false, got {self.refine!r:.40}", param="refine")
        from .broadband import check_method
        try:
            put("method", check_method(self.method))
        except DesignError as exc:
            raise DesignError(str(exc), param="method") from None
        if self.segment_length is not None:
            put("segment_length", int(parse_in_range(self.segment_length, "segment_length", "segment_length")))

    def given(self, names=STEP_ONLY) -> list:
        """The parameters of ``names`` this request sets (not at their defaults), in that order.

        Parameters
        ----------
        names : sequence of str
            Parameter names (default :data:`STEP_ONLY`).

        Returns
        -------
        list of str
            Those given.
        """
        return [n for n in names if getattr(self, n) != _UNSET.get(n)]

    def read_options(self) -> dict:
        """:func:`~designer.identify.io.read_capture`'s keyword arguments of this request.

        Returns
        -------
        dict
            ``input_column``, ``output_column``, ``fmt``, ``sample_time_s``, ``column_names``.
        """
        return {"input_column": self.input_column, "output_column": self.output_column, "fmt": self.fmt,
                "sample_time_s": self.sample_time_s, "column_names": self.column_names}


def _amplitude(value) -> float:
    """``step_amplitude``: non-zero, its size inside ``RANGES["step_amplitude"]`` (negative: a falling step)."""
    number = parse_value(value, "step_amplitude")
    if number == 0:
        raise DesignError("step_amplitude must be non-zero (its size "
                          f"{RANGES['step_amplitude'].text()}, either sign)", param="step_amplitude")
    try:
        RANGES["step_amplitude"].check(abs(number), "the size of step_amplitude (either sign)",
                                       shown=repr(value) if isinstance(value, str) else None)
    except DesignError as exc:
        raise DesignError(str(exc), param="step_amplitude") from None
    return number


def _window(value) -> tuple:
    """``window``: two times, each inside ``RANGES["capture_time_s"]``, the first before the second."""
    from .preprocess import check_window
    values = [value] if isinstance(value, (str, int, float)) else list(value)
    if len(values) != 2:
        raise DesignError(f"window takes 2 values, got {len(values)}", param="window")
    times = []
    for v, which in zip(values, ("T0", "T1")):
        try:
            times.append(parse_in_range(v, f"window {which}", "capture_time_s"))
        except DesignError as exc:
            raise DesignError(str(exc), param="window") from None
    try:
        return check_window(times)
    except DesignError as exc:   # the message as check_window writes it, the parameter named for the front ends
        raise DesignError(str(exc), param="window") from None


def identify_spec(params: dict) -> IdentifySpec:
    """An :class:`IdentifySpec` from plain parameters, as every front end has them (the command line's
    options, the web page's fields): the one mapping from what a user types to the spec.

    Parameters
    ----------
    params : dict
        The spec's fields (:class:`IdentifySpec`; a value None is not given).

    Returns
    -------
    IdentifySpec
        Checked on construction.

    Raises
    ------
    DesignError
        One line naming the parameter at fault; a name that is no parameter is refused, the parameters
        listed.
    """
    known = {f.name for f in fields(IdentifySpec)}
    unknown = sorted(k for k in params if k not in known)
    if unknown:
        raise DesignError(f"{unknown[0]!r} is not a parameter of an identification; allowed: "
                          f"{', '.join(sorted(known))}")
    given = {k: v for k, v in params.items() if v is not None}
    if "capture" not in given:
        raise DesignError("capture is required: the file to identify", param="capture")
    return IdentifySpec(**given)


def frequency_table_header(path) -> list | None:
    """The header cells of ``path`` when it is a frequency-response table as ``identify-freq`` reads it,
    else None.

    Its first row that is not blank or a ``#`` comment must be a header whose first cell names a
    frequency (``f_hz``, ``f_khz``, ``w_rad_s``, ``Frequency (Hz)``...) and whose second names a gain
    (``gain_db``, ``gain_ratio``, ``Channel 1 Magnitude (dB)``...), split as identify-freq splits it.
    Only the head of the file is read; a file that cannot be read gives None, so the capture reader
    reports it in its own words.

    Parameters
    ----------
    path : str or Path
        The file given to ``identify``.

    Returns
    -------
    list of str or None
        The header's cells, or None for anything else (a step capture, a table without a header: those
        are read as captures).
    """
    from .io.freqtable import NUMBER, unit_hint   # identify-freq's own reading of a header
    try:
        with open_limited(path, "capture file", MAX_CAPTURE_BYTES) as fh:
            head = fh.read(SNIFF_BYTES) or b""
    except DesignError:
        return None
    line = next((ln.strip() for ln in decode(head).lstrip("\ufeff").splitlines()
                 if ln.strip() and not ln.strip().startswith("#")), "")
    sep = next((c for c in (";", ",", "\t") if c in line), None)
    cells = [c.strip().strip('"').strip("'") for c in (line.split(sep) if sep else line.split())]
    while cells and cells[-1] == "":
        cells.pop()
    if len(cells) < 2 or all(NUMBER.match(c) for c in cells):
        return None
    first, second = cells[0], cells[1].lower()
    is_freq = first.lower().startswith("freq") or unit_hint(first, "frequency") is not None
    is_gain = unit_hint(cells[1], "gain") is not None or "gain" in second or "magnitude" in second
    return cells if is_freq and is_gain else None


def header_text(header) -> str:
    """A table's header as a message quotes it (at most 100 characters).

    Parameters
    ----------
    header : list of str
        The header's cells (:func:`frequency_table_header`).

    Returns
    -------
    str
        The cells joined by commas.
    """
    text = ",".join(header)
    return text if len(text) <= 100 else text[:97] + "..."


def identify_file(spec: IdentifySpec, also_given=()):
    """Identify the file of ``spec`` as the ``identify`` command does (see the module docstring).

    Parameters
    ----------
    spec : IdentifySpec
        The request.
    also_given : sequence of str
        A front end's own step-only settings it was given (named in a frequency table's refusal after
        the request's, as ``{name}`` markers).

    Returns
    -------
    IdentifyResult, BroadbandResult or FreqIdentifyResult
        A step capture's :class:`~designer.identify.step.IdentifyResult` (with its ``comparison`` when
        ``against`` is given), a broadband capture's
        :class:`~designer.identify.broadband.BroadbandResult`, a frequency table's
        :class:`~designer.identify.frequency.FreqIdentifyResult` (:func:`identify_dict` writes either as
        ``identify --json`` prints it).

    Raises
    ------
    DesignError
        The file or a setting refused, in one line naming the parameter.
    """
    name = spec.name if spec.name is not None else shown(spec.capture)
    header = frequency_table_header(spec.capture)
    if header is not None:
        given = spec.given() + list(also_given)
        if given:
            one = len(given) == 1
            raise ParamError(f"{', '.join('{%s}' % g for g in given)} {'is' if one else 'are'} for a step "
                             f"capture; {name} is a frequency-response table (header {header_text(header)}), "
                             f"analysed as identify-freq does: drop {'it' if one else 'them'}", given)
        from .frequency import identify_freq
        from .io import read_freq_table
        return identify_freq(read_freq_table(spec.capture))
    from .broadband import positional_input
    from .io import read_capture
    cap = positional_input(read_capture(spec.capture, **spec.read_options()))
    validation = _validation(spec, cap, name)
    design = None
    if spec.against is not None:
        from .against import load_design
        design = load_design(spec.against)
    from .assess import identify_record
    result = identify_record(cap.t, cap.y, cap.u, step_time=spec.step_time_s, step_amplitude=spec.step_amplitude,
                             window=spec.window, methods=None if spec.methods is None else list(spec.methods),
                             refine=spec.refine, method=spec.method, capture=cap.info(), name=name,
                             validation=validation, segment_length=spec.segment_length,
                             step_only_given=spec.given(STEP_EDGE_ONLY))
    if design is not None and not hasattr(result, "excitation"):
        from .against import compare_with_design
        result.comparison = compare_with_design(result, design)
    return result


def _validation(spec: IdentifySpec, cap, name: str):
    """``validate``: the second capture (t, u, y), read as the first (its layout and columns), or None;
    both need an input channel."""
    if spec.validate is None:
        return None
    from .broadband import positional_input
    from .io import read_capture
    other = positional_input(read_capture(spec.validate, **spec.read_options()))
    if other.u is None or cap.u is None:
        which = shown(spec.validate) if other.u is None else name
        raise DesignError(f"validate: {which} has no input column; validation simulates each model under the "
                          "recorded input, so both captures need one (t,u,y)", param="validate")
    return other.t, other.u, other.y


def identify_dict(result) -> dict:
    """A result of :func:`identify_file` as ``identify --json`` prints it (before :func:`json_safe`): a
    frequency table's with ``"format": "frequency-table"`` first.

    Parameters
    ----------
    result : IdentifyResult, BroadbandResult or FreqIdentifyResult
        What :func:`identify_file` returned.

    Returns
    -------
    dict
        Its JSON object.
    """
    from .frequency import FreqIdentifyResult
    if isinstance(result, FreqIdentifyResult):
        return {"format": FREQUENCY_TABLE, **result.to_dict()}
    return result.to_dict()
