"""The exception hierarchy: one root, flat subclasses, messages written for users.

The CLI turns any :class:`FluidymationError` into its message on stderr and exit code 2.
"""


class FluidymationError(Exception):
    """Root of every error caused by the user's input rather than by a bug."""


class SceneError(FluidymationError):
    """A scene file is missing, malformed, or holds an invalid value."""


class InputError(FluidymationError):
    """A file named by the scene (vector animation, exemplar, image) is unusable."""


class StageError(FluidymationError):
    """A stage cannot run with the inputs and parameters it was given."""


class ParameterError(StageError):
    """A stage or stylizer parameter has an invalid value; ``name`` says which, so callers can point at it."""

    def __init__(self, name: str, message: str):
        super().__init__(message)
        self.name = name
