"""Cartesian tool paths: a sequence of tool poses with arc length, timing and feed rate.

Two file formats, both read into a :class:`ToolPath` in SI units (conversion happens once, here):

* **CSV** (``.csv``) — one waypoint per row, a header naming the columns (case-insensitive, any
  order; comma, semicolon or whitespace separated; ``#`` starts a comment line):

  ``x, y, z`` (required, file length unit) and the orientation as either ``roll, pitch, yaw``
  (fixed-axis RPY, R = Rz(yaw)·Ry(pitch)·Rx(roll), file angle unit) or a unit quaternion
  ``qw, qx, qy, qz`` — or neither, for a position-only path; optionally ``t`` (s, strictly
  increasing) or ``feed`` (file length unit / s: the feed of the move *into* that row).

* **TOML** (``.toml``) — parametric segments from a start pose::

      length_unit = "m"          # optional: the units of this file; default: the robot file's
      angle_unit = "deg"
      feed = 0.02                # optional defaults for every segment: feed, step or points
      [start]
      xyz = [x, y, z]
      rpy = [r, p, y]            # or quat = [w, x, y, z]; neither: a position-only path
      [[segments]]
      type = "line"              # "line" | "arc"
      to = [x, y, z]
      feed = 0.0125              # length unit / s (or duration = 4.0 s for the whole segment)
      points = 1000              # waypoints the segment adds (its end included), or step = spacing
      [[segments]]
      type = "arc"
      center = [x, y, z]         # with normal = [nx, ny, nz]: the arc turns about the normal by the
      normal = [1, 0, 0]         # right-hand rule (counter-clockwise seen from its tip) from the
      to = [x, y, z]             # segment's start to ``to``; ``to`` = start makes a full circle.
      # or: through = [x, y, z]  (the circle through start, through and to, travelled in that order)
      rpy = [r, p, y]            # optional: orientation at the segment's end (slerp along it);
                                 # default: the orientation is held

Values are in the *robot file's* units unless the TOML names its own ``length_unit`` /
``angle_unit``.  Every problem raises :class:`ToolPathError` naming the file, the line or field,
and the allowed values.
"""
from __future__ import annotations

import csv
import io
import math
import tomllib
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any, Sequence

import numpy as np

from kin.chain import ANGLE_UNITS, LENGTH_UNITS
from kin.errors import RmtError
from kin.transforms import log_so3

__all__ = ["ToolPath", "ToolPathError", "read_toolpath_csv", "read_toolpath_toml", "load_toolpath",
           "rpy_to_matrices", "quaternions_to_matrices", "slerp", "chord_length", "CSV_COLUMNS", "SEGMENT_TYPES", "MAX_WAYPOINTS"]

CSV_COLUMNS = ("x", "y", "z", "roll", "pitch", "yaw", "qw", "qx", "qy", "qz", "t", "feed")
SEGMENT_TYPES = ("line", "arc")
TOP_FIELDS = ("name", "title", "description", "robot", "length_unit", "angle_unit", "feed", "step", "points",
              "start", "segments")
START_FIELDS = ("xyz", "rpy", "quat")
LINE_FIELDS = ("type", "to", "feed", "duration", "points", "step", "rpy", "quat")
ARC_FIELDS = LINE_FIELDS + ("center", "normal", "through")
#: a path longer than this is refused (a step of a micrometre over metres is a unit mistake)
MAX_WAYPOINTS = 5_000_000
#: an arc's ``to`` may miss the radius by this fraction of it (rounded coordinates); the arc spirals onto it
ARC_RADIUS_TOL = 1e-4
QUAT_NORM_TOL = 1e-3


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
        """A path through given poses (N, 4, 4), SI; arc length by chords; timing from ``t`` (N,) or a
        ``feed`` (m/s; a scalar or one per waypoint, the feed of the move into it)."""
        poses = np.asarray(poses, dtype=float)
        if poses.ndim == 2:
            poses = poses[None]
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


# ---- geometry helpers ----------------------------------------------------------------------------
def chord_length(P: np.ndarray) -> np.ndarray:
    """Cumulative chord length (N,) of points (N, 3), starting at 0."""
    d = np.linalg.norm(np.diff(P, axis=0), axis=1) if len(P) > 1 else np.zeros(0)
    return np.concatenate([[0.0], np.cumsum(d)])


def times_from_feed(s: np.ndarray, feed: np.ndarray) -> np.ndarray:
    """Times (N,) of waypoints at arc lengths s (N,), the move into waypoint i at feed[i] (m/s)."""
    dt = np.diff(s) / feed[1:]
    return np.concatenate([[0.0], np.cumsum(dt)])


def rpy_to_matrices(rpy: np.ndarray) -> np.ndarray:
    """Fixed-axis roll-pitch-yaw (N, 3) rad → rotations (N, 3, 3): R = Rz(yaw)·Ry(pitch)·Rx(roll)."""
    rpy = np.asarray(rpy, dtype=float).reshape(-1, 3)
    cr, sr = np.cos(rpy[:, 0]), np.sin(rpy[:, 0])
    cp, sp = np.cos(rpy[:, 1]), np.sin(rpy[:, 1])
    cy, sy = np.cos(rpy[:, 2]), np.sin(rpy[:, 2])
    R = np.empty((len(rpy), 3, 3))
    R[:, 0, 0] = cy * cp
    R[:, 0, 1] = cy * sp * sr - sy * cr
    R[:, 0, 2] = cy * sp * cr + sy * sr
    R[:, 1, 0] = sy * cp
    R[:, 1, 1] = sy * sp * sr + cy * cr
    R[:, 1, 2] = sy * sp * cr - cy * sr
    R[:, 2, 0] = -sp
    R[:, 2, 1] = cp * sr
    R[:, 2, 2] = cp * cr
    return R


def quaternions_to_matrices(quat: np.ndarray) -> np.ndarray:
    """Unit quaternions (N, 4) as (w, x, y, z) → rotations (N, 3, 3)."""
    w, x, y, z = np.asarray(quat, dtype=float).reshape(-1, 4).T
    R = np.empty((len(w), 3, 3))
    R[:, 0, 0] = 1 - 2 * (y * y + z * z)
    R[:, 0, 1] = 2 * (x * y - w * z)
    R[:, 0, 2] = 2 * (x * z + w * y)
    R[:, 1, 0] = 2 * (x * y + w * z)
    R[:, 1, 1] = 1 - 2 * (x * x + z * z)
    R[:, 1, 2] = 2 * (y * z - w * x)
    R[:, 2, 0] = 2 * (x * z - w * y)
    R[:, 2, 1] = 2 * (y * z + w * x)
    R[:, 2, 2] = 1 - 2 * (x * x + y * y)
    return R


def _exp_so3(w: np.ndarray) -> np.ndarray:
    """Rotation vectors (N, 3) → rotations (N, 3, 3) (Rodrigues)."""
    w = np.asarray(w, dtype=float).reshape(-1, 3)
    th = np.linalg.norm(w, axis=1)
    K = np.zeros((len(w), 3, 3))
    K[:, 0, 1], K[:, 0, 2], K[:, 1, 2] = -w[:, 2], w[:, 1], -w[:, 0]
    K[:, 1, 0], K[:, 2, 0], K[:, 2, 1] = w[:, 2], -w[:, 1], w[:, 0]
    small = th < 1e-8
    with np.errstate(invalid="ignore", divide="ignore"):
        a = np.where(small, 1.0 - th ** 2 / 6, np.sin(th) / np.where(small, 1.0, th))
        b = np.where(small, 0.5 - th ** 2 / 24, (1 - np.cos(th)) / np.where(small, 1.0, th ** 2))
    return np.eye(3) + a[:, None, None] * K + b[:, None, None] * (K @ K)


def slerp(R0: np.ndarray, R1: np.ndarray, u: np.ndarray) -> np.ndarray:
    """Rotations (M, 3, 3) from R0 (u = 0) to R1 (u = 1) along the shortest geodesic, at fractions u (M,)."""
    w = log_so3(R0.T @ R1)
    return R0[None] @ _exp_so3(np.outer(u, w))


def _poses(P: np.ndarray, R: np.ndarray) -> np.ndarray:
    T = np.zeros((len(P), 4, 4))
    T[:, :3, :3] = R
    T[:, :3, 3] = P
    T[:, 3, 3] = 1.0
    return T


# ---- units -------------------------------------------------------------------------------------
def _robot_units(robot) -> tuple[str, str]:
    """(length unit, angle unit) of a Robot or Chain."""
    chain = getattr(robot, "chain", robot)
    return chain.length_unit, chain.angle_unit


# ---- CSV ---------------------------------------------------------------------------------------
def _split(line: str, delim: str | None) -> list[str]:
    if delim is None:
        return line.split()
    return [c.strip() for c in next(csv.reader(io.StringIO(line), delimiter=delim))]


def read_toolpath_csv(path: str | Path, robot) -> ToolPath:
    """Read a CSV tool path (see the module docstring) in ``robot``'s file units → :class:`ToolPath` (SI).

    ``robot`` is a :class:`kin.Robot` or :class:`kin.Chain`; only its units are used.
    """
    path = Path(path)
    src = str(path)
    try:
        text = path.read_text(encoding="utf-8")
    except FileNotFoundError:
        raise ToolPathError("no such tool-path file", src) from None
    except (OSError, UnicodeDecodeError) as e:
        raise ToolPathError(f"cannot read file ({e})", src) from None
    length_unit, angle_unit = _robot_units(robot)
    return parse_toolpath_csv(text, LENGTH_UNITS[length_unit], ANGLE_UNITS[angle_unit], src,
                              (length_unit, angle_unit))


def parse_toolpath_csv(text: str, length_scale: float, angle_scale: float, src: str = "<csv>",
                       unit_names: tuple[str, str] = ("file length unit", "file angle unit")) -> ToolPath:
    """Parse CSV text; lengths × ``length_scale`` (m per unit), angles × ``angle_scale`` (rad per unit)."""
    rows: list[tuple[int, str]] = [(i, ln) for i, ln in enumerate(text.splitlines(), 1)
                                   if ln.strip() and not ln.lstrip().startswith("#")]
    if not rows:
        raise ToolPathError(f"empty file; a header is required naming the columns ({', '.join(CSV_COLUMNS)})", src)
    hline, header = rows[0]
    delim = "," if "," in header else (";" if ";" in header else None)
    names = [c.strip().lower() for c in _split(header, delim)]
    allowed = ", ".join(CSV_COLUMNS)
    for c in names:
        if c not in CSV_COLUMNS:
            try:
                float(c)
                msg = (f"the first row holds numbers, not a header; a header is required naming the columns "
                       f"(allowed: {allowed})")
            except ValueError:
                msg = f"unknown column {c!r}; allowed: {allowed}"
            raise ToolPathError(msg, src, f"line {hline} (header)")
    dup = sorted({c for c in names if names.count(c) > 1})
    if dup:
        raise ToolPathError(f"column {dup[0]!r} appears twice", src, f"line {hline} (header)")
    missing = [c for c in ("x", "y", "z") if c not in names]
    if missing:
        raise ToolPathError(f"missing column(s) {', '.join(missing)}; required: x, y, z; orientation: roll, "
                            f"pitch, yaw or qw, qx, qy, qz (optional); timing: t or feed (optional)", src,
                            f"line {hline} (header)")
    has_rpy = [c in names for c in ("roll", "pitch", "yaw")]
    has_q = [c in names for c in ("qw", "qx", "qy", "qz")]
    if any(has_rpy) and any(has_q):
        raise ToolPathError("give the orientation as roll, pitch, yaw or as qw, qx, qy, qz, not both", src,
                            f"line {hline} (header)")
    for group, have in ((("roll", "pitch", "yaw"), has_rpy), (("qw", "qx", "qy", "qz"), has_q)):
        if any(have) and not all(have):
            lacking = [g for g, h in zip(group, have) if not h]
            raise ToolPathError(f"missing column(s) {', '.join(lacking)}: the orientation needs all of "
                                f"{', '.join(group)}", src, f"line {hline} (header)")
    if "t" in names and "feed" in names:
        raise ToolPathError("give a t column (s) or a feed column (length unit/s), not both", src,
                            f"line {hline} (header)")
    body = rows[1:]
    if not body:
        raise ToolPathError("no waypoints after the header", src)
    if len(body) > MAX_WAYPOINTS:
        raise ToolPathError(f"{len(body)} waypoints; at most {MAX_WAYPOINTS}", src)
    cells = []
    for ln, line in body:
        r = _split(line, delim)
        if len(r) != len(names):
            raise ToolPathError(f"{len(r)} values; the header names {len(names)} columns ({', '.join(names)})",
                                src, f"line {ln}")
        cells.append(r)
    lines = np.array([ln for ln, _ in body])
    cols: dict[str, np.ndarray] = {}
    for k, c in enumerate(names):
        raw = [r[k] for r in cells]
        try:
            v = np.array(raw, dtype=float)
        except ValueError:
            v = None
        if v is None or not np.all(np.isfinite(v)):
            for i, x in enumerate(raw):   # find the culprit for the message
                try:
                    fx = float(x)
                except ValueError:
                    raise ToolPathError(f"{x!r} is not a number", src, f"line {lines[i]}, column {c!r}") from None
                if not math.isfinite(fx):
                    raise ToolPathError(f"{x!r} is not a finite number (NaN and infinity are not allowed)", src,
                                        f"line {lines[i]}, column {c!r}")
        cols[c] = v
    P = np.stack([cols["x"], cols["y"], cols["z"]], axis=1) * length_scale
    has_orientation = True
    if all(has_rpy):
        R = rpy_to_matrices(np.stack([cols["roll"], cols["pitch"], cols["yaw"]], axis=1) * angle_scale)
    elif all(has_q):
        Qn = np.stack([cols["qw"], cols["qx"], cols["qy"], cols["qz"]], axis=1)
        norm = np.linalg.norm(Qn, axis=1)
        bad = np.abs(norm - 1.0) > QUAT_NORM_TOL
        if bad.any():
            i = int(np.argmax(bad))
            raise ToolPathError(f"quaternion (qw, qx, qy, qz) has norm {norm[i]:.6g}; a unit quaternion is required "
                                f"(norm within {QUAT_NORM_TOL:g} of 1)", src, f"line {lines[i]}, columns qw..qz")
        R = quaternions_to_matrices(Qn / norm[:, None])
    else:
        R = np.broadcast_to(np.eye(3), (len(P), 3, 3))
        has_orientation = False
    s = chord_length(P)
    t = feed = None
    if "t" in cols:
        t = cols["t"]
        dt = np.diff(t)
        if np.any(dt <= 0):
            i = int(np.argmax(dt <= 0)) + 1
            raise ToolPathError(f"t = {t[i]:.6g} s does not increase (previous {t[i - 1]:.6g} s); t must be strictly "
                                f"increasing", src, f"line {lines[i]}, column 't'")
        t = t - t[0]
    elif "feed" in cols:
        feed = cols["feed"] * length_scale
        if np.any(feed <= 0):
            i = int(np.argmax(feed <= 0))
            raise ToolPathError(f"feed {cols['feed'][i]:.6g} must be > 0 ({unit_names[0]}/s)", src,
                                f"line {lines[i]}, column 'feed'")
        t = times_from_feed(s, feed)
    return ToolPath(poses=_poses(P, R), s=s, t=t, feed=feed, source=src, has_orientation=has_orientation,
                    line=lines)


# ---- TOML --------------------------------------------------------------------------------------
class _Toml:
    """Field access with messages naming the file and the field."""

    def __init__(self, src: str):
        self.src = src

    def fail(self, field: str | None, msg: str) -> ToolPathError:
        return ToolPathError(msg, self.src, field)

    def table(self, obj: Any, field: str, allowed: Sequence[str]) -> dict:
        if not isinstance(obj, dict):
            raise self.fail(field, f"must be a table, got {_tname(obj)}")
        for k in obj:
            if k not in allowed:
                raise self.fail(f"{field}.{k}" if field else k, f"unknown field; allowed: {', '.join(allowed)}")
        return obj

    def number(self, obj: Any, field: str, positive: bool = False) -> float:
        if isinstance(obj, bool) or not isinstance(obj, (int, float)):
            raise self.fail(field, f"must be a number, got {_tname(obj)}")
        x = float(obj)
        if not math.isfinite(x):
            raise self.fail(field, "must be a finite number (NaN and infinity are not allowed)")
        if positive and x <= 0:
            raise self.fail(field, f"must be > 0, got {x:g}")
        return x

    def vector(self, obj: Any, field: str, size: int) -> np.ndarray:
        if not isinstance(obj, list) or len(obj) != size:
            raise self.fail(field, f"must be a list of {size} numbers, got {_tname(obj)}"
                            + (f" of length {len(obj)}" if isinstance(obj, list) else ""))
        return np.array([self.number(v, f"{field}[{i}]") for i, v in enumerate(obj)])

    def integer(self, obj: Any, field: str) -> int:
        if isinstance(obj, bool) or not isinstance(obj, int):
            raise self.fail(field, f"must be an integer ≥ 1, got {_tname(obj)}")
        if obj < 1:
            raise self.fail(field, f"must be an integer ≥ 1, got {obj}")
        return int(obj)

    def unit(self, obj: Any, field: str, units: dict) -> float:
        if obj not in units:
            raise self.fail(field, f"unknown unit {obj!r}; allowed: {', '.join(units)}")
        return units[obj]


def _tname(obj: Any) -> str:
    return {dict: "a table", list: "a list", str: "a string", bool: "a boolean"}.get(type(obj), type(obj).__name__)


def read_toolpath_toml(path: str | Path, robot) -> ToolPath:
    """Read a TOML tool path of parametric segments (see the module docstring) → :class:`ToolPath` (SI).

    Values are in ``robot``'s file units unless the file sets ``length_unit`` / ``angle_unit``.
    """
    path = Path(path)
    src = str(path)
    try:
        text = path.read_text(encoding="utf-8")
    except FileNotFoundError:
        raise ToolPathError("no such tool-path file", src) from None
    except (OSError, UnicodeDecodeError) as e:
        raise ToolPathError(f"cannot read file ({e})", src) from None
    return parse_toolpath_toml(text, robot, src)


def parse_toolpath_toml(text: str, robot, src: str = "<toml>") -> ToolPath:
    """Parse TOML text of parametric segments; see :func:`read_toolpath_toml`."""
    rd = _Toml(src)
    try:
        doc = tomllib.loads(text)
    except tomllib.TOMLDecodeError as e:
        raise rd.fail(None, f"not valid TOML ({e})") from None
    rd.table(doc, "", TOP_FIELDS)
    length_unit, angle_unit = _robot_units(robot)
    ls = rd.unit(doc.get("length_unit", length_unit), "length_unit", LENGTH_UNITS)
    as_ = rd.unit(doc.get("angle_unit", angle_unit), "angle_unit", ANGLE_UNITS)
    if "start" not in doc:
        raise rd.fail("start", "missing table [start] (fields: xyz, and rpy or quat)")
    st = rd.table(doc["start"], "start", START_FIELDS)
    if "xyz" not in st:
        raise rd.fail("start.xyz", "missing field: the start position [x, y, z]")
    p0 = rd.vector(st["xyz"], "start.xyz", 3) * ls
    if "rpy" in st and "quat" in st:
        raise rd.fail("start", "give rpy or quat, not both")
    has_orientation = "rpy" in st or "quat" in st
    R0 = _orientation(rd, st, "start", as_) if has_orientation else np.eye(3)
    defaults = {k: doc[k] for k in ("feed", "step", "points") if k in doc}
    if "feed" in defaults:
        rd.number(defaults["feed"], "feed", positive=True)
    if "step" in defaults:
        rd.number(defaults["step"], "step", positive=True)
    if "points" in defaults:
        rd.integer(defaults["points"], "points")
    segs = doc.get("segments")
    if not isinstance(segs, list) or not segs:
        raise rd.fail("segments", "missing or empty: at least one [[segments]] table (type = "
                      + " | ".join(f'"{t}"' for t in SEGMENT_TYPES) + ")")
    Ps, Rs, ss, feeds, segidx, types = [p0[None]], [R0[None]], [np.zeros(1)], [], [np.array([-1])], []
    p_cur, R_cur, s_cur = p0, R0, 0.0
    total = 1
    for k, seg in enumerate(segs):
        f = f"segments[{k}]"
        if not isinstance(seg, dict):
            raise rd.fail(f, f"must be a table, got {_tname(seg)}")
        typ = seg.get("type")
        if typ not in SEGMENT_TYPES:
            raise rd.fail(f"{f}.type", ("missing field" if typ is None else f"unknown segment type {typ!r}")
                          + f"; allowed: {', '.join(SEGMENT_TYPES)}")
        rd.table(seg, f, LINE_FIELDS if typ == "line" else ARC_FIELDS)
        if "to" not in seg:
            raise rd.fail(f"{f}.to", "missing field: the segment's end point [x, y, z]")
        p1 = rd.vector(seg["to"], f"{f}.to", 3) * ls
        if typ == "line":
            geom = _line(rd, f, p_cur, p1)
        else:
            geom = _arc(rd, f, seg, p_cur, p1, ls)
        L = geom.length
        # count of points: `points`, or `step` spacing; segment fields first, then the file's defaults
        if "points" in seg and "step" in seg:
            raise rd.fail(f, "give points or step, not both")
        if "points" in seg:
            m = rd.integer(seg["points"], f"{f}.points")
        elif "step" in seg:
            m = max(1, math.ceil(L / (rd.number(seg["step"], f"{f}.step", positive=True) * ls) - 1e-9))
        elif "points" in defaults:
            m = int(defaults["points"])
        elif "step" in defaults:
            m = max(1, math.ceil(L / (float(defaults["step"]) * ls) - 1e-9))
        else:
            raise rd.fail(f, "missing points or step (here or at the top of the file)")
        total += m
        if total > MAX_WAYPOINTS:
            raise rd.fail(f, f"the path would have more than {MAX_WAYPOINTS} waypoints; use a coarser step")
        if "feed" in seg and "duration" in seg:
            raise rd.fail(f, "give feed or duration, not both")
        if "feed" in seg:
            fr = rd.number(seg["feed"], f"{f}.feed", positive=True) * ls
        elif "duration" in seg:
            fr = L / rd.number(seg["duration"], f"{f}.duration", positive=True)
        elif "feed" in defaults:
            fr = float(defaults["feed"]) * ls
        else:
            raise rd.fail(f"{f}.feed", "missing field: the feed rate (length unit/s), or duration (s), here or a "
                          "feed at the top of the file")
        u = np.arange(1, m + 1) / m
        P = geom.points(u)
        if "rpy" in seg or "quat" in seg:
            if not has_orientation:
                raise rd.fail(f, "an orientation (rpy/quat) needs one in [start] too")
            if "rpy" in seg and "quat" in seg:
                raise rd.fail(f, "give rpy or quat, not both")
            R1 = _orientation(rd, seg, f, as_)
            R = slerp(R_cur, R1, u)
        else:
            R = np.broadcast_to(R_cur, (m, 3, 3))
        Ps.append(P)
        Rs.append(R)
        ss.append(s_cur + geom.arc_length(u))
        feeds.append(np.full(m, fr))
        segidx.append(np.full(m, k))
        types.append(typ)
        p_cur, R_cur, s_cur = P[-1], R[-1], s_cur + L
    P = np.concatenate(Ps)
    R = np.concatenate(Rs)
    s = np.concatenate(ss)
    feed = np.concatenate([feeds[0][:1]] + feeds)
    return ToolPath(poses=_poses(P, R), s=s, t=times_from_feed(s, feed), feed=feed, source=src,
                    has_orientation=has_orientation, segment=np.concatenate(segidx), segment_types=types)


def _orientation(rd: _Toml, tab: dict, f: str, angle_scale: float) -> np.ndarray:
    if "rpy" in tab:
        return rpy_to_matrices(rd.vector(tab["rpy"], f"{f}.rpy", 3) * angle_scale)[0]
    q = rd.vector(tab["quat"], f"{f}.quat", 4)
    n = float(np.linalg.norm(q))
    if abs(n - 1.0) > QUAT_NORM_TOL:
        raise rd.fail(f"{f}.quat", f"has norm {n:.6g}; a unit quaternion [w, x, y, z] is required")
    return quaternions_to_matrices(q / n)[0]


class _Line:
    def __init__(self, p0, p1):
        self.p0, self.d = p0, p1 - p0
        self.length = float(np.linalg.norm(self.d))

    def points(self, u):
        return self.p0[None] + u[:, None] * self.d[None]

    def arc_length(self, u):
        return u * self.length


def _line(rd: _Toml, f: str, p0, p1) -> _Line:
    g = _Line(p0, p1)
    if g.length < 1e-12:
        raise rd.fail(f"{f}.to", "zero-length segment: `to` equals the segment's start point")
    return g


class _Arc:
    """Arc about ``center`` with unit ``normal`` from p0 through angle ``phi`` (rad, > 0); the radius
    goes linearly from r0 to r1 so that the arc ends exactly on ``to`` (rounded coordinates)."""

    def __init__(self, center, normal, p0, phi, r0, r1, e1):
        self.c, self.n, self.phi, self.r0, self.r1 = center, normal, phi, r0, r1
        self.e0 = (p0 - center) / np.linalg.norm(p0 - center)
        self.e1 = e1      # in-plane direction 90° ahead of e0
        self.length = float(0.5 * (r0 + r1) * phi)

    def points(self, u):
        a = u * self.phi
        r = self.r0 + (self.r1 - self.r0) * u
        return self.c[None] + r[:, None] * (np.cos(a)[:, None] * self.e0[None] + np.sin(a)[:, None] * self.e1[None])

    def arc_length(self, u):
        return self.phi * (self.r0 * u + 0.5 * (self.r1 - self.r0) * u * u)


def _arc(rd: _Toml, f: str, seg: dict, p0, p1, ls: float) -> _Arc:
    has_c, has_n, has_t = "center" in seg, "normal" in seg, "through" in seg
    if has_t and (has_c or has_n):
        raise rd.fail(f, "an arc takes center and normal, or a through point, not both")
    if has_t:
        pm = rd.vector(seg["through"], f"{f}.through", 3) * ls
        a, b = pm - p0, p1 - p0
        nrm = np.cross(a, b)
        nn = float(np.linalg.norm(nrm))
        scale = max(float(np.linalg.norm(a)), float(np.linalg.norm(b)), 1e-12)
        if float(np.linalg.norm(b)) < 1e-12:
            raise rd.fail(f"{f}.to", "a full circle needs center and normal (through is ambiguous when to = start)")
        if nn < 1e-9 * scale * scale:
            raise rd.fail(f"{f}.through", "start, through and to are collinear: no circle passes through them")
        # circumcentre of the triangle p0, pm, p1
        c = p0 + (np.dot(a, a) * np.cross(b, nrm) + np.dot(b, b) * np.cross(nrm, a)) / (2 * nn * nn)
        normal = nrm / nn
    else:
        if not (has_c and has_n):
            missing = "center" if not has_c else "normal"
            raise rd.fail(f"{f}.{missing}", "missing field: an arc needs center and normal (the rotation axis, "
                          "right-hand rule), or a through point")
        c = rd.vector(seg["center"], f"{f}.center", 3) * ls
        normal = rd.vector(seg["normal"], f"{f}.normal", 3)
        nn = float(np.linalg.norm(normal))
        if nn < 1e-12:
            raise rd.fail(f"{f}.normal", "is the zero vector; give the arc's rotation axis")
        normal = normal / nn
    v0, v1 = p0 - c, p1 - c
    r0, r1 = float(np.linalg.norm(v0)), float(np.linalg.norm(v1))
    if r0 < 1e-12:
        raise rd.fail(f"{f}.center", "zero-length segment: the arc's center is its start point (radius 0)")
    tol = ARC_RADIUS_TOL * r0 + 1e-12
    for v, what in ((v0, "the segment's start point"), (v1, "`to`")):
        if abs(float(np.dot(v, normal))) > tol:
            raise rd.fail(f"{f}.normal", f"{what} is not in the arc's plane (offset {float(np.dot(v, normal)):.3g} m "
                          f"along the normal)")
    if abs(r1 - r0) > tol:
        raise rd.fail(f"{f}.to", f"is {r1:.6g} m from the center but the arc starts at radius {r0:.6g} m")
    e0 = v0 / r0
    e1 = np.cross(normal, e0)
    phi = math.atan2(float(np.dot(v1, e1)), float(np.dot(v1, e0)))
    if float(np.linalg.norm(p1 - p0)) < 1e-9 * max(r0, 1.0):
        phi = 2 * math.pi          # to = start: a full circle
    elif phi <= 0:
        phi += 2 * math.pi
    return _Arc(c, normal, p0, phi, r0, r1, e1)


# ---- dispatch ----------------------------------------------------------------------------------
READERS = {".csv": read_toolpath_csv, ".toml": read_toolpath_toml}


def load_toolpath(path: str | Path, robot) -> ToolPath:
    """Read a tool path by its extension: ``.csv`` (waypoints) or ``.toml`` (parametric segments)."""
    p = Path(path)
    reader = READERS.get(p.suffix.lower())
    if reader is None:
        raise ToolPathError(f"unknown tool-path file type {p.suffix or '(none)'!r}; allowed: "
                            f"{', '.join(READERS)}", str(p))
    return reader(p, robot)
