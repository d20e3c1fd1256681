"""The error of URDF reading and writing: one line naming the file and the element."""
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
