"""The :class:`ToolPath` value — tool poses with arc length, timing and feed rate, SI units — and
:class:`ToolPathError`, raised for every problem with a tool-path file.

The readers (:mod:`planning.toolpath.csv_reader`, :mod:`planning.toolpath.segments`) build a ToolPath;
:func:`planning.toolpath.load_toolpath` picks one by the file's extension.
"""
from __future__ import annotations

from dataclasses import dataclass, field
from pathlib import Path
from typing import Sequence

import numpy as np

from kin.chain import ANGLE_UNITS, LENGTH_UNITS
from kin.errors import RmtError
from kin.files import FileReadError, read_text
from kin.validation import real_array
from planning.toolpath.geometry import chord_length, times_from_feed

__all__ = ["ToolPath", "ToolPathError", "MAX_WAYPOINTS", "FEED_RANGE", "MAX_COORDINATE", "robot_units"]

#: a path longer than this is refused (a step of a micrometre over metres is a unit mistake)
MAX_WAYPOINTS = 5_000_000
#: the largest tool-path file read (CSV or TOML; 5 million waypoints of a few numbers each)
MAX_TOOLPATH_BYTES = 500_000_000
#: feed rates a reader accepts, m/s (1 µm/s to 1 km/s)
FEED_RANGE = (1e-6, 1e3)
#: the largest coordinate a reader accepts, m (as a robot file's lengths)
MAX_COORDINATE = 1e4


class ToolPathError(RmtError, ValueError):
    """A tool-path file is missing, unreadable or invalid.

    ``path`` is the file, ``field`` where in it (``line 7, column 'x'``, ``segments[2].feed``).
    """

    def __init__(self, message: str, path: str | None = None, field: str | None = None):
        self.path = path
        self.field = field
        where = ": ".join(str(x) for x in (path, field) if x)
        super().__init__(f"{where}: {message}" if where else message)


@dataclass
class ToolPath:
    """A Cartesian tool path, SI units.

    poses   (N, 4, 4) tool poses in the robot's base frame (m).
    s       (N,) arc length of the tool point along the path (m), s[0] = 0.
    t       (N,) time (s), t[0] = 0, or None when the file gives neither times nor feeds.
    feed    (N,) feed rate of the move *into* each waypoint (m/s; feed[0] is that of the first
            move), or None.
    source  where the path comes from (file name).
    has_orientation  False for a position-only path (the orientations are then identity and
            are not to be tracked).
    segment (N,) index of the TOML segment a waypoint ends (−1 for the start), or None.
    line    (N,) 1-based line of a CSV file each waypoint comes from, or None.
    segment_types  type of each TOML segment.
    """

    poses: np.ndarray
    s: np.ndarray
    t: np.ndarray | None = None
    feed: np.ndarray | None = None
    source: str = ""
    has_orientation: bool = True
    segment: np.ndarray | None = None
    line: np.ndarray | None = None
    segment_types: list[str] = field(default_factory=list)

    def __post_init__(self):
        self.poses = np.asarray(self.poses, dtype=float)
        if self.poses.ndim != 3 or self.poses.shape[1:] != (4, 4) or len(self.poses) == 0:
            raise ToolPathError(f"poses have shape {self.poses.shape}; expected (N, 4, 4) with N ≥ 1", self.source)
        N = len(self.poses)
        self.s = np.asarray(self.s, dtype=float)
        for name in ("s", "t", "feed", "segment", "line"):
            v = getattr(self, name)
            if v is not None and np.shape(v) != (N,):
                raise ToolPathError(f"{name} has shape {np.shape(v)}; expected ({N},)", self.source)
        if not np.all(np.isfinite(self.poses)):
            raise ToolPathError("poses hold NaN or infinite values", self.source)

    def __len__(self) -> int:
        return len(self.poses)

    @property
    def positions(self) -> np.ndarray:
        """(N, 3) tool positions (m)."""
        return self.poses[:, :3, 3]

    @property
    def length(self) -> float:
        """Total arc length (m)."""
        return float(self.s[-1])

    @property
    def duration(self) -> float | None:
        """Total time (s), or None without timing."""
        return None if self.t is None else float(self.t[-1])

    def origin(self, i: int) -> str:
        """Where waypoint ``i`` comes from in its file: ``line 57`` (CSV), ``segment 2 (arc)`` or
        ``start`` (TOML), or "" for a path built in code."""
        if self.line is not None:
            return f"line {int(self.line[i])}"
        if self.segment is not None:
            k = int(self.segment[i])
            if k < 0:
                return "start"
            return f"segment {k}" + (f" ({self.segment_types[k]})" if k < len(self.segment_types) else "")
        return ""

    def where(self, i: int) -> str:
        """Where waypoint ``i`` is, in words: index, arc length, time and :meth:`origin`."""
        parts = [f"s = {self.s[i]:.6g} m"] + ([] if self.t is None else [f"t = {self.t[i]:.6g} s"])
        o = self.origin(i)
        return f"waypoint {i} ({', '.join(parts + ([o] if o else []))})"

    @classmethod
    def from_poses(cls, poses, feed: float | Sequence[float] | None = None, t=None, source: str = "poses",
                   has_orientation: bool = True) -> "ToolPath":
        """A path through given poses (N, 4, 4) or one pose (4, 4), SI, coordinates within
        ±:data:`MAX_COORDINATE`; arc length by chords; timing from ``t`` (N,) or a ``feed`` (m/s; a
        scalar or one per waypoint, the feed of the move into it).  :class:`ToolPathError` for
        anything else."""
        poses = real_array(poses, "poses", lambda msg: ToolPathError(msg, source)).astype(float)
        shape = poses.shape
        if poses.ndim == 2:
            poses = poses[None]
        if poses.ndim != 3 or poses.shape[1:] != (4, 4) or len(poses) == 0:
            raise ToolPathError(f"poses has shape {shape}; expected (N, 4, 4) with N ≥ 1, or one pose (4, 4)", source)
        if not np.all(np.isfinite(poses)):
            raise ToolPathError("poses hold NaN or infinite values", source)
        if np.any(np.abs(poses[:, :3, 3]) > MAX_COORDINATE):
            i = int(np.argmax(np.abs(poses[:, :3, 3]).max(axis=1) > MAX_COORDINATE))
            raise ToolPathError(f"poses[{i}] has a coordinate beyond ±{MAX_COORDINATE:g} m (10 km), the range a "
                                f"tool path may span", source)
        s = chord_length(poses[:, :3, 3])
        feeds = None
        if t is not None and feed is not None:
            raise ToolPathError("give t or feed, not both", source)
        if feed is not None:
            feeds = np.broadcast_to(np.asarray(feed, dtype=float), (len(poses),)).copy()
            if not np.all(np.isfinite(feeds)) or np.any(feeds <= 0):
                raise ToolPathError("feed must be a positive finite number (m/s)", source, "feed")
            t = times_from_feed(s, feeds)
        elif t is not None:
            t = np.asarray(t, dtype=float)
            if t.shape != (len(poses),) or not np.all(np.isfinite(t)) or np.any(np.diff(t) <= 0):
                raise ToolPathError(f"t must be {len(poses)} finite, strictly increasing times (s)", source, "t")
        return cls(poses=poses, s=s, t=t, feed=feeds, source=source, has_orientation=has_orientation)


def robot_units(robot) -> tuple[str, str]:
    """(length unit, angle unit) of a Robot or Chain (or anything with a ``chain`` or itself holding
    ``length_unit`` and ``angle_unit``): the units a tool-path file is read in.

    :class:`ToolPathError` for anything else (``None`` included): a tool-path file holds numbers in
    its robot file's units, so the robot is required.
    """
    chain = getattr(robot, "chain", robot)
    units = getattr(chain, "length_unit", None), getattr(chain, "angle_unit", None)
    if not (isinstance(units[0], str) and units[0] in LENGTH_UNITS and isinstance(units[1], str)
            and units[1] in ANGLE_UNITS):
        got = repr(robot)
        got = got if len(got) <= 40 else f"a {type(robot).__name__}"
        raise ToolPathError(f"robot is {got}; expected a kin.Robot or kin.Chain (a tool-path file is read in "
                            f"its robot file's units)")
    return units


def read_toolpath_text(path: str | Path) -> tuple[str, str]:
    """The text of a tool-path file and its name for messages; :class:`ToolPathError` if unreadable."""
    path = Path(path)
    src = str(path)
    try:
        return read_text(path, "tool-path file", MAX_TOOLPATH_BYTES), src
    except FileReadError as e:
        raise ToolPathError(e.reason, src) from None
