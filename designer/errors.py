"""The one exception type that the command-line layer turns into a single line
and exit status 2. Library code raises it for anything the user can fix."""


class DesignError(ValueError):
    """Bad input or an impossible request, with a message that says what is
    wrong and what is allowed."""
