"""The errors Caliper raises.

Every failure of a call into a Caliper process raises a subclass of :class:`Error` carrying the
server's own message (it names the Model, the id, the file and what is wrong). The classes
mirror the IDL's exceptions, so that a program can tell them apart::

    try:
        arm.set_command("elbow_flexor", 50.0)
    except caliper.InvalidParameter as e:
        print("refused:", e)

A process that cannot be reached (CORBA's TRANSIENT, COMM_FAILURE, TIMEOUT, OBJECT_NOT_EXIST)
raises :class:`ConnectionError`, which is also Python's built-in ``ConnectionError``. Wrong
Python types and shapes raise ``TypeError`` / ``ValueError`` naming the argument before anything
is sent.
"""

import builtins

__all__ = [
    "Error", "ConnectionError", "UnknownId", "InvalidParameter", "NotAvailable", "LoadFailed",
    "LimitExceeded", "RunFailed", "EditRefused", "SetupError", "FormatError", "RecordingError",
]


class Error(Exception):
    """Base of every error Caliper raises."""


class ConnectionError(Error, builtins.ConnectionError):
    """A process (the naming service, a Model, a renderer) cannot be reached or did not answer
    within the call's deadline. ``address`` names what was called."""

    address: str = ""


class UnknownId(Error, LookupError):
    """An id (actuator, channel, body, tendon, subscription) the Model does not have; ``id``
    names it."""

    id: str = ""

    def __str__(self) -> str:  # LookupError would quote the message like a key
        return str(self.args[0]) if self.args else ""


class InvalidParameter(Error, ValueError):
    """A value the Model refuses (NaN, a wrong shape, outside its range)."""


class NotAvailable(Error):
    """The Model cannot do it now (no scene loaded, faulted, replaying, running an experiment)."""


class LoadFailed(Error):
    """A scene that cannot be loaded; the message names the file, the element and the problem."""


class LimitExceeded(Error):
    """More than one call may ask for; ``limit`` is the bound."""

    limit: int = 0


class RunFailed(Error):
    """The physics faulted (NaN, an explosion); the message is the Model's report. ``steps``
    is how many steps ran before it, when known."""

    steps: int = 0


class EditRefused(Error):
    """A scene edit the Model refused; nothing changed."""


class SetupError(Error):
    """A run that cannot be set up on any Model (its scene does not load, an id it lacks)."""


class FormatError(Error, ValueError):
    """A file (experiments, calibration, measurements) that cannot be read; the message names the
    file, the entry and what is wrong."""


class RecordingError(Error):
    """A recording file that cannot be read; the message names the file."""
