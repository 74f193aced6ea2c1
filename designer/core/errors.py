"""The exceptions the command-line layer turns into a single line on stderr.

- :class:`DesignError`: bad input or an impossible request (exit status 2).
  Library code raises it for anything the user can fix, naming the parameter.
- :class:`ParamError`: the same, for a message about several parameters.
- :class:`SimulatorError`: ngspice missing, crashed, timed out or wrote nothing
  usable (exit status 3).
- :class:`DeckError`: ngspice refused to load a deck (a user's own netlist
  that is not valid ngspice input): bad input, exit status 2.
"""

import re

__all__ = ["DeckError", "DesignError", "EXIT_BAD_INPUT", "EXIT_CHECK_FAILED", "EXIT_OK", "EXIT_SIMULATOR",
           "ParamError", "SimulatorError"]


class DesignError(ValueError):
    """Bad input or an impossible request, with a message that says what is
    wrong and what is allowed.

    ``param`` names the library parameter at fault (``fc_hz``, ``kp``,
    ``r_min``); the message then starts with it, and the command-line layer
    swaps it for the option the user typed (``--fc``) from one table
    (:data:`designer.cli.common.FLAGS`).
    """

    def __init__(self, message: str, param: str | None = None):
        super().__init__(message)
        self.param = param

    def naming(self, names: dict) -> str:
        """The message with the parameter it starts with read through ``names``
        (the command line's options, a spec file's keys); unchanged otherwise."""
        msg = str(self)
        if isinstance(self.param, str) and self.param in names and msg.startswith(self.param):
            return names[self.param] + msg[len(self.param):]
        return msg


_MARKER = re.compile(r"\{([a-z][a-z0-9_]*)\}")
#: how the library writes a marker that is not a parameter name (the CLI has an option for it)
SPELLING = {"no_sim": "simulate=False"}


class ParamError(DesignError):
    """A refusal whose message names several parameters, as ``{name}`` markers.

    ``str(error)`` reads them as the library's names (``r_min``, or
    :data:`SPELLING`); :meth:`naming` reads them through another table, e.g.
    the command line's options (``--r-min``). ``param`` is the first name.

    Parameters
    ----------
    marked : str
        The message, parameters written ``{name}``.
    params : collection of str, optional
        The only names that are markers (other ``{...}`` text, e.g. in a file
        name, stays as it is); default every ``{identifier}``.
    """

    def __init__(self, marked: str, params=None):
        self.marked = marked
        self.params = None if params is None else frozenset(params)
        first = next((m.group(1) for m in _MARKER.finditer(marked) if self._is_param(m.group(1))), None)
        super().__init__(self.naming({}), param=first)

    def _is_param(self, name: str) -> bool:
        return self.params is None or name in self.params

    def naming(self, names: dict) -> str:
        """The message with each marker read through ``names`` (a name it lacks
        reads as the library writes it)."""
        def name(m):
            key = m.group(1)
            return names.get(key, SPELLING.get(key, key)) if self._is_param(key) else m.group(0)
        return _MARKER.sub(name, self.marked)


class SimulatorError(DesignError):
    """The simulator could not produce a result (not the user's input)."""


class DeckError(DesignError):
    """ngspice refused the deck as it read it (a syntax error, an unknown
    element or subcircuit): the deck is bad input, not a simulator failure."""


#: exit statuses of every command
EXIT_OK, EXIT_CHECK_FAILED, EXIT_BAD_INPUT, EXIT_SIMULATOR, EXIT_INTERRUPTED = 0, 1, 2, 3, 130
