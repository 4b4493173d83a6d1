"""Errors that describe a user's mistake (bad input), as opposed to a bug.

The command line turns a :class:`UserError` into one line on stderr and exit status 2.
"""


class UserError(ValueError):
    """Bad input: an unknown name, a non-physical value, an unreachable pose, a malformed file."""


class PhysicalConsistencyWarning(UserWarning):
    """Positive definite inertia that no rigid body can have (triangle inequality violated)."""


class RunWarning(UserWarning):
    """Something a run did differently from what its user may expect, and still finished (a checkpoint file that
    failed verification, evaluated again)."""


class RenamedWarning(FutureWarning):
    """An old name still taken for one release (an index option, a hand): the command line says it in one
    ``warning:`` line, once, and the run goes on with the new name's meaning."""


class InputError(UserError):
    """Bad value of named inputs (``samples``, ``region``, ``q``): the message says the input in
    words and names no command-line flag; ``inputs`` lets a command line name the flags that carry
    them (the first input leads the message when the message begins with its name)."""

    def __init__(self, message: str, *inputs: str) -> None:
        super().__init__(message)
        self.inputs = inputs
