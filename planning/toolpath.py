"""Cartesian tool paths: a sequence of tool poses with arc length, timing and feed rate.

Two file formats, both read into a :class:`ToolPath` in SI units (conversion happens once, at load):

* **CSV** (``.csv``) — one waypoint per row under a header naming the columns: ``x, y, z``, the
  orientation as ``roll, pitch, yaw`` or ``qw, qx, qy, qz`` (or neither), and ``t`` or ``feed``
  (optional).  Read by :mod:`planning.toolpath_csv`, whose docstring gives the details.
* **TOML** (``.toml``) — parametric ``line`` and ``arc`` segments from a ``[start]`` pose.  Read by
  :mod:`planning.toolpath_segments`, whose docstring gives the format.

Values are in the *robot file's* units unless the TOML names its own ``length_unit`` /
``angle_unit``.  Every problem raises :class:`ToolPathError` naming the file, the line or field,
and the allowed values.

This module is the place to import from: :func:`load_toolpath` picks the reader by the file's
extension, and the value (:mod:`planning.toolpath_model`), the readers and the geometry helpers
(:mod:`planning.toolpath_geometry`) are re-exported here.
"""
from __future__ import annotations

from pathlib import Path

from .toolpath_csv import CSV_COLUMNS, parse_toolpath_csv, read_toolpath_csv  # noqa: F401  (re-exported)
from .toolpath_geometry import (  # noqa: F401  (re-exported)
    QUAT_NORM_TOL,
    chord_length,
    quaternions_to_matrices,
    rpy_to_matrices,
    slerp,
    times_from_feed,
)
from .toolpath_model import MAX_WAYPOINTS, ToolPath, ToolPathError
from .toolpath_segments import (  # noqa: F401  (re-exported)
    ARC_FIELDS,
    ARC_RADIUS_TOL,
    LINE_FIELDS,
    SEGMENT_TYPES,
    START_FIELDS,
    TOP_FIELDS,
    parse_toolpath_toml,
    read_toolpath_toml,
)

__all__ = ["ToolPath", "ToolPathError", "read_toolpath_csv", "read_toolpath_toml", "load_toolpath",
           "rpy_to_matrices", "quaternions_to_matrices", "slerp", "chord_length", "CSV_COLUMNS", "SEGMENT_TYPES",
           "MAX_WAYPOINTS"]

READERS = {".csv": read_toolpath_csv, ".toml": read_toolpath_toml}


def load_toolpath(path: str | Path, robot) -> ToolPath:
    """Read a tool path by its extension: ``.csv`` (waypoints) or ``.toml`` (parametric segments)."""
    p = Path(path)
    reader = READERS.get(p.suffix.lower())
    if reader is None:
        raise ToolPathError(f"unknown tool-path file type {p.suffix or '(none)'!r}; allowed: "
                            f"{', '.join(READERS)}", str(p))
    return reader(p, robot)
