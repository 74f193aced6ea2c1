"""The exceptions the command-line layer turns into a single line on stderr.

- :class:`DesignError`: bad input or an impossible request (exit status 2).
  Library code raises it for anything the user can fix.
- :class:`SimulatorError`: ngspice missing, crashed, timed out or wrote nothing
  usable (exit status 3).
"""


class DesignError(ValueError):
    """Bad input or an impossible request, with a message that says what is
    wrong and what is allowed."""


class SimulatorError(DesignError):
    """The simulator could not produce a result (not the user's input)."""


#: exit statuses of every command
EXIT_OK, EXIT_CHECK_FAILED, EXIT_BAD_INPUT, EXIT_SIMULATOR, EXIT_INTERRUPTED = 0, 1, 2, 3, 130
