"""Digilent WaveForms exports: ``#`` comment lines, then ``Time (s),Channel 1 (V),...``.
"""

from __future__ import annotations

from .layout import _headed_table


#: Digilent WaveForms: ``#`` comment lines, then ``Time (s),Channel 1 (V),...``.
_read_digilent = _headed_table("digilent", lambda c: c.startswith("time"),
                               "Time (s),Channel 1 (V),...")
