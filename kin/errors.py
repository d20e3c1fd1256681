"""Exception hierarchy of rmtkit.

Every error raised on purpose by rmtkit derives from :class:`RmtError`.  Messages name the
file (when there is one), the field and the allowed values, so that the command line can print
them as one line and exit with code 2.
"""
from __future__ import annotations


class RmtError(Exception):
    """Root of every rmtkit error."""


class RobotFileError(RmtError):
    """A robot file (TOML) is missing, unreadable or invalid.

    ``path`` is the file, ``field`` the offending field (dotted, e.g. ``joints[2].limits``).
    """

    def __init__(self, message: str, path: str | None = None, field: str | None = None):
        self.path = path
        self.field = field
        where = ": ".join(x for x in (path, field) if x)
        super().__init__(f"{where}: {message}" if where else message)


class UnknownRobotError(RmtError):
    """A robot name is neither bundled nor an existing file."""


class ArgumentError(RmtError, ValueError):
    """An argument of a Python API call is outside its allowed values (an unknown method name, a
    bad option); the message names the argument and what is allowed."""


class ChainError(RmtError):
    """A chain is built or transformed inconsistently (programmatic API)."""


class DynamicsError(RmtError, ValueError):
    """The chain cannot answer a dynamics question: no body carries inertial data (a mass)."""


class ConfigurationError(RmtError, ValueError):
    """A joint configuration or batch has the wrong shape or non-finite values."""


class JointLimitError(ConfigurationError):
    """A configuration lies outside the joint limits."""


class ParameterError(RmtError, ValueError):
    """A design-parameter vector is wrong (unknown name, wrong length, out of bounds)."""


class CompileError(RmtError):
    """A native kernel could not be built — the compiler refused it or timed out, or the cache path
    is unusable (:func:`kin.native.build`); callers fall back to CasADi's VM or numpy."""


class OutBufferError(RmtError, ValueError):
    """An ``out=`` buffer handed to a batch call has the wrong type, dtype, shape or layout."""


class GeometryError(RmtError, ValueError):
    """Collision geometry or a clearance model's arguments are invalid: a negative or non-finite radius
    or size, a capsule or an ignored body the chain does not have, an obstacle pose that is not rigid,
    a sphere set that is not (K, 4)."""


class SettingError(RmtError, ValueError):
    """An environment setting (``RMTKIT_THREADS``, ``RMTKIT_ARCH``) holds a value outside its allowed range."""
