"""Where the project's own SPICE model library lives.

The models are in the top-level ``circuits/`` folder of the repository, which
setuptools ships as the package ``designer.spice.circuits`` (see
``pyproject.toml``), so an installed wheel builds decks from any folder.
"""

from __future__ import annotations

from functools import lru_cache
from importlib import resources

__all__ = []


@lru_cache(maxsize=None)
def library_text(name: str) -> str:
    """The text of one model file of the library (e.g. ``opamp_behavioural.lib``)."""
    return resources.files("designer.spice.circuits").joinpath(name).read_text()
