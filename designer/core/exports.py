"""A package's public API re-exported lazily: the names of its modules' ``__all__``
reachable from the package (``from designer.plant import design_plant``), each module
imported on first use, so that a command pays only for what it runs (PEP 562: a module's
``__getattr__`` and ``__dir__``, Python 3.7+). The rule it serves is checked by
``tests/test_layout.py``: every name in a public module's ``__all__`` is reachable from
its package, except names several modules share (a protocol, such as each Monte Carlo
engine's ``evaluate``) and names that are also a module's name; those are reached through
their module."""

import importlib
import sys

__all__ = ["lazy_exports"]


def lazy_exports(package: str, table: dict) -> tuple:
    """The ``__all__``, ``__getattr__`` and ``__dir__`` of a package that re-exports its
    modules' names lazily.

    Parameters
    ----------
    package : str
        The package's dotted name (its ``__name__``).
    table : dict
        Module name relative to the package -> the names of it the package re-exports.

    Returns
    -------
    names : list of str
        The package's ``__all__``: the names of ``table``, sorted.
    getattr_ : callable
        The package's ``__getattr__``: imports the module defining a name on first use
        and keeps the name in the package.
    dir_ : callable
        The package's ``__dir__``: its attributes and the names not yet imported.
    """
    where = {name: module for module, names in table.items() for name in names}

    def getattr_(name):
        if name not in where:
            raise AttributeError(f"module {package!r} has no attribute {name!r}")
        value = getattr(importlib.import_module(f"{package}.{where[name]}"), name)
        setattr(sys.modules[package], name, value)    # the next use finds it directly
        return value

    def dir_():
        return sorted(set(vars(sys.modules[package])) | set(where))

    return sorted(where), getattr_, dir_
