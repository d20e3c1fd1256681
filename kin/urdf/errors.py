"""The error and the warning of URDF reading and writing: one line naming the file and the element."""
from __future__ import annotations

from kin.errors import RmtError


class UrdfError(RmtError):
    """A URDF file is missing, unreadable, not a tree, or holds a chain rmtkit cannot represent.

    ``path`` is the file, ``element`` the offending element (``joint 'elbow'``, ``link 'tool0'``).
    """

    def __init__(self, message: str, path: str | None = None, element: str | None = None):
        self.path = path
        self.element = element
        where = ": ".join(x for x in (path, element) if x)
        super().__init__(f"{where}: {message}" if where else message)


class UrdfWarning(UserWarning):
    """A URDF holds something rmtkit leaves out and says so (a placeholder <inertial>: mass 0 with a
    non-zero tensor); one line naming the file and the element."""
