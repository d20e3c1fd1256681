"""Cartesian tool paths: a sequence of tool poses with arc length, timing and feed rate.

Two file formats, both read into a :class:`ToolPath` in SI units (conversion happens once, at load):

* **CSV** (``.csv``) — one waypoint per row under a header naming the columns: ``x, y, z``, the
  orientation as ``roll, pitch, yaw`` or ``qw, qx, qy, qz`` (or neither), and ``t`` or ``feed``
  (optional).  Read by :mod:`planning.toolpath.csv_reader`, whose docstring gives the details.
* **TOML** (``.toml``) — parametric ``line`` and ``arc`` segments from a ``[start]`` pose.  Read by
  :mod:`planning.toolpath.segments`, whose docstring gives the format.

Values are in the *robot file's* units unless the TOML names its own ``length_unit`` /
``angle_unit``.  Every problem raises :class:`ToolPathError` naming the file, the line or field,
and the allowed values.

:func:`load_toolpath` picks the reader by the file's extension; import it, the value
(:mod:`planning.toolpath.model`), the readers and the geometry helpers (:mod:`planning.toolpath.geometry`)
from :mod:`planning.toolpath`.
"""
from __future__ import annotations

from pathlib import Path

from planning.toolpath.csv_reader import read_toolpath_csv
from planning.toolpath.model import ToolPath, ToolPathError, robot_units
from planning.toolpath.segments import read_toolpath_toml

__all__ = ["load_toolpath", "READERS"]

READERS = {".csv": read_toolpath_csv, ".toml": read_toolpath_toml}


def load_toolpath(path: str | Path, robot) -> ToolPath:
    """Read a tool path by its extension: ``.csv`` (waypoints) or ``.toml`` (parametric segments).

    ``robot`` (a :class:`kin.Robot` or :class:`kin.Chain`) is required: the file's numbers are in its
    robot file's units (:class:`ToolPathError` without one).
    """
    robot_units(robot)
    p = Path(path)
    reader = READERS.get(p.suffix.lower())
    if reader is None:
        raise ToolPathError(f"unknown tool-path file type {p.suffix or '(none)'!r}; allowed: "
                            f"{', '.join(READERS)}", str(p))
    return reader(p, robot)
