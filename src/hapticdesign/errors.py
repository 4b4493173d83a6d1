"""Errors that describe a user's mistake (bad input), as opposed to a bug.

The command line turns a :class:`UserError` into one line on stderr and exit status 2.
"""


class UserError(ValueError):
    """Bad input: an unknown name, a non-physical value, an unreachable pose, a malformed file."""


class PhysicalConsistencyWarning(UserWarning):
    """Positive definite inertia that no rigid body can have (triangle inequality violated)."""
