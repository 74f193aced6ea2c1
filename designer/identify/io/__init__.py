"""Reading the measurements identification starts from: step-response
captures and frequency-response (Bode) tables.

One module per family, as scikit-rf's ``io`` is: :mod:`.capture` (the one
reading path of every time capture: step, square wave or broadband
excitation), :mod:`.layout` (the generic table and the project's waveforms),
the vendors' layouts (:mod:`.tektronix`, :mod:`.rigol`, :mod:`.siglent`,
:mod:`.keysight`, :mod:`.picoscope`, :mod:`.digilent`), :mod:`.formats`
(which reader reads a file), :mod:`.writers` and :mod:`.freqtable`.

Step-response captures
----------------------
One entry point, :func:`read_capture`, recognises the layouts a student or CI
actually has and returns a :class:`Capture` (time, output and optional input):

- generic ``t,y`` or ``t,u,y`` tables, with or without a header line, comma,
  semicolon (decimal comma allowed) or tab separated;
- the waveforms this project writes: header ``time_s,<signal>,...``;
- Tektronix TDS/TBS exports (``Record Length,...`` header block carried in
  columns 1-3 of the first rows, time and value in columns 4 and 5);
- Tektronix MSO/DPO exports (``Model,...`` key/value lines, then a
  ``TIME,CH1,...`` header and the samples);
- Rigol DS/MSO exports (``X,CH1,Start,Increment,`` then
  ``Sequence,Volt,<start>,<increment>,`` then sample index and values; time is
  start + index * increment).

Which signal is the input and which the output: by name when the header names
them (``u``, ``vin``, ``in``... and ``y``, ``vout``, ``out``...), otherwise by
position (``t,u,y``: the first signal is the input, the last the output; one
signal is the output). ``input_column``/``output_column`` override both.
An input chosen by position only is kept and marked (``input_by_position``):
whether it is one is the analysis' decision
(:func:`designer.identify.broadband.positional_input`), not the reader's.

Plain signal columns without a time column (a data set as DaISy keeps it,
``u y``): ``sample_time_s`` gives the time (sample k at k * sample_time_s) and
``column_names`` names the columns (:func:`plain_columns`); such a file read
without it is refused naming them (its first column is no time).

Files are streamed, never read whole: the layout is recognised from the first
lines, then the samples are parsed a block at a time by numpy's C parser, and
only the (at most three) columns used are kept, so memory is about 8 bytes per
kept value however long the file is. Size, encoding and non-regular files
(a directory, ``/dev/zero``, a FIFO) are handled by :mod:`designer.core.fileio`; the
checks on the samples themselves (finite, increasing time, physical ranges)
are :func:`designer.identify.edges.check_samples`.

Frequency-response tables
-------------------------
:func:`read_freq_table` (:func:`parse_freq_table` for text) reads a table of
frequency, gain (dB or amplitude ratio) and optionally phase (degrees,
radians, or the time shift of the output behind the input, as seed 000
Table IV measures it: phase = -360 f dt degrees) into a :class:`FreqData`.
Every row's values are checked against their physical ranges
(``RANGES["freq_hz"]``, ``["gain_db"]`` or ``["gain_ratio"]``,
``["phase_deg"]``) before any arithmetic, so no overflow reaches the fits.
"""


from .capture import (
    BLOCK_LINES,
    HEAD_LINES,
    INPUT_NAMES,
    OUTPUT_NAMES,
    TIME_NAMES,
    Capture,
    CaptureInfo,
    looks_like_step_input,
    parse_capture_text,
    plain_columns,
    read_capture,
    text_lines,
)
from .formats import check_format
from .freqtable import (
    FREQ_UNITS,
    GAIN_UNITS,
    MAX_POINTS,
    MIN_POINTS,
    PHASE_UNITS,
    NUMBER,
    FreqData,
    freq_data,
    parse_freq_table,
    read_freq_table,
    unit_hint,
)
from .layout import FORMAT_NAMES, FORMATS
from .split import PARSED, FileBlocks
from .writers import format_generic

__all__ = ["BLOCK_LINES", "HEAD_LINES", "INPUT_NAMES", "OUTPUT_NAMES", "TIME_NAMES", "Capture", "CaptureInfo",
           "looks_like_step_input", "parse_capture_text", "plain_columns", "read_capture", "text_lines", "check_format", "FREQ_UNITS",
           "GAIN_UNITS", "MAX_POINTS", "MIN_POINTS", "PHASE_UNITS", "FreqData", "freq_data", "parse_freq_table",
           "read_freq_table", "FORMAT_NAMES", "FORMATS", "format_generic", "NUMBER", "unit_hint", "FileBlocks",
           "PARSED"]
