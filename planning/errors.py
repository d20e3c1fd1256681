"""Errors of the planning layer (all derive from :class:`kin.RmtError`)."""
from __future__ import annotations

from kin.errors import RmtError


class WindowError(RmtError, ValueError):
    """A singular window cannot be built or read (bad width, unreachable threshold, bad file)."""


class PlanningError(RmtError):
    """A planning request is invalid (start/goal out of limits or inside a window, bad planner)."""


class CellError(PlanningError):
    """A work-cell file (or a mesh or point cloud it names) is missing or invalid, or names a body
    the robot does not have (:mod:`planning.cell`)."""
