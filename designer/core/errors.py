"""The exceptions the command-line layer turns into a single line on stderr.

- :class:`DesignError`: bad input or an impossible request (exit status 2).
  Library code raises it for anything the user can fix.
- :class:`SimulatorError`: ngspice missing, crashed, timed out or wrote nothing
  usable (exit status 3).
"""


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


class SimulatorError(DesignError):
    """The simulator could not produce a result (not the user's input)."""


#: exit statuses of every command
EXIT_OK, EXIT_CHECK_FAILED, EXIT_BAD_INPUT, EXIT_SIMULATOR, EXIT_INTERRUPTED = 0, 1, 2, 3, 130
