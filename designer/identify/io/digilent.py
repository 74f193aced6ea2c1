"""Digilent WaveForms exports: ``#`` comment lines, then ``Time (s),Channel 1 (V),...``.
"""

from __future__ import annotations

from .layout import headed_table

__all__ = []


#: Digilent WaveForms: ``#`` comment lines, then ``Time (s),Channel 1 (V),...``.
read_digilent = headed_table("digilent", lambda c: c.startswith("time"),
                               "Time (s),Channel 1 (V),...")
