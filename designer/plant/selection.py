"""The Sallen-Key plant's joint E-series search (the exact parallelogram
search, the section's fast path, and its brute-force reference), as the plant
wing has always imported it: it lives with the Sallen-Key low-pass section, in
:mod:`designer.filters.sallen_key_lowpass_search` (the one place that names
its parts, issue 26); this module keeps the old import path working."""

from ..filters.sallen_key_lowpass_search import Candidate, brute_force, joint_search

__all__ = ["Candidate", "brute_force", "joint_search"]
