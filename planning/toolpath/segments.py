"""TOML tool paths (``.toml``): parametric line and arc segments from a start pose, read into a
:class:`~planning.toolpath.model.ToolPath` in SI units (conversion happens once, here)::

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
``angle_unit``.  Every problem raises :class:`~planning.toolpath.model.ToolPathError` naming the
file, the field, and the allowed values.
"""
from __future__ import annotations

import math
import tomllib
from pathlib import Path
from typing import Any

import numpy as np

from kin.chain import ANGLE_UNITS, LENGTH_UNITS
from kin.validation import Fields, type_name
from planning.toolpath.geometry import (
    QUAT_NORM_TOL,
    assemble_poses,
    quaternions_to_matrices,
    rpy_to_matrices,
    slerp,
    times_from_feed,
)
from planning.toolpath.model import (
    FEED_RANGE,
    MAX_COORDINATE,
    MAX_WAYPOINTS,
    ToolPath,
    ToolPathError,
    read_toolpath_text,
    robot_units,
)

__all__ = ["read_toolpath_toml", "parse_toolpath_toml", "SEGMENT_TYPES"]

SEGMENT_TYPES = ("line", "arc")
TOP_FIELDS = ("name", "title", "description", "robot", "length_unit", "angle_unit", "feed", "step", "points",
              "start", "segments")
START_FIELDS = ("xyz", "rpy", "quat")
LINE_FIELDS = ("type", "to", "feed", "duration", "points", "step", "rpy", "quat")
ARC_FIELDS = LINE_FIELDS + ("center", "normal", "through")
#: the largest roll, pitch or yaw accepted, rad (as a robot file's angles)
MAX_ANGLE = 8 * math.pi
#: an arc's ``to`` may miss the radius by this fraction of it (rounded coordinates); the arc spirals onto it
ARC_RADIUS_TOL = 1e-4


class _Toml(Fields):
    """Tool-path file fields (:class:`kin.validation.Fields`) with the tool-path error, positions,
    feeds and units."""

    def __init__(self, src: str):
        super().__init__(src)
        self.src = src

    def fail(self, field: str | None, msg: str) -> ToolPathError:
        return ToolPathError(msg, self.src, field)

    def vector(self, obj: Any, field: str, size: int) -> np.ndarray:
        return np.array(super().vector(obj, field, size))

    def position(self, obj: Any, field: str, scale: float) -> np.ndarray:
        """A point [x, y, z] in file units → m, every coordinate within ±:data:`MAX_COORDINATE`."""
        p = self.vector(obj, field, 3) * scale
        if np.any(np.abs(p) > MAX_COORDINATE):
            raise self.fail(field, f"coordinates must lie within ±{MAX_COORDINATE / scale:g} (file length unit; 10 km)")
        return p

    def feed(self, x: float, field: str, scale: float) -> float:
        """A feed in file units/s → m/s within :data:`FEED_RANGE`."""
        v = x * scale
        if not FEED_RANGE[0] <= v <= FEED_RANGE[1]:
            raise self.fail(field, f"feed {x:g} is outside the allowed range [{FEED_RANGE[0] / scale:g}, "
                            f"{FEED_RANGE[1] / scale:g}] (file length unit/s)")
        return v

    def unit(self, obj: Any, field: str, units: dict) -> float:
        if obj not in units:
            raise self.fail(field, f"unknown unit {obj!r}; allowed: {', '.join(units)}")
        return units[obj]


_tname = type_name


def read_toolpath_toml(path: str | Path, robot) -> ToolPath:
    """Read a TOML tool path of parametric segments (see the module docstring) → :class:`ToolPath` (SI).

    Values are in ``robot``'s file units unless the file sets ``length_unit`` / ``angle_unit``.
    """
    text, src = read_toolpath_text(path)
    return parse_toolpath_toml(text, robot, src)


def parse_toolpath_toml(text: str, robot, src: str = "<toml>") -> ToolPath:
    """Parse TOML text of parametric segments; see :func:`read_toolpath_toml`."""
    rd = _Toml(src)
    try:
        doc = tomllib.loads(text)
    except tomllib.TOMLDecodeError as e:
        raise rd.fail(None, f"not valid TOML ({e})") from None
    rd.table(doc, "", TOP_FIELDS)
    length_unit, angle_unit = robot_units(robot)
    ls = rd.unit(doc.get("length_unit", length_unit), "length_unit", LENGTH_UNITS)
    as_ = rd.unit(doc.get("angle_unit", angle_unit), "angle_unit", ANGLE_UNITS)
    if "start" not in doc:
        raise rd.fail("start", "missing table [start] (fields: xyz, and rpy or quat)")
    st = rd.table(doc["start"], "start", START_FIELDS)
    if "xyz" not in st:
        raise rd.fail("start.xyz", "missing field: the start position [x, y, z]")
    p0 = rd.position(st["xyz"], "start.xyz", ls)
    if "rpy" in st and "quat" in st:
        raise rd.fail("start", "give rpy or quat, not both")
    has_orientation = "rpy" in st or "quat" in st
    R0 = _orientation(rd, st, "start", as_) if has_orientation else np.eye(3)
    defaults = {k: doc[k] for k in ("feed", "step", "points") if k in doc}
    if "feed" in defaults:
        rd.feed(rd.number(defaults["feed"], "feed", positive=True), "feed", ls)
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
        p1 = rd.position(seg["to"], f"{f}.to", ls)
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
        elif "step" in seg or "step" in defaults:
            step = rd.number(seg["step"], f"{f}.step", positive=True) if "step" in seg else float(defaults["step"])
            m_f = L / (step * ls) - 1e-9                # a float first: a tiny step gives inf, not an OverflowError
            if not m_f <= MAX_WAYPOINTS:
                raise rd.fail(f, f"the path would have more than {MAX_WAYPOINTS} waypoints; use a coarser step")
            m = max(1, math.ceil(m_f))
        elif "points" in defaults:
            m = int(defaults["points"])
        else:
            raise rd.fail(f, "missing points or step (here or at the top of the file)")
        total += m
        if total > MAX_WAYPOINTS:
            raise rd.fail(f, f"the path would have more than {MAX_WAYPOINTS} waypoints; use a coarser step")
        if "feed" in seg and "duration" in seg:
            raise rd.fail(f, "give feed or duration, not both")
        if "feed" in seg:
            fr = rd.feed(rd.number(seg["feed"], f"{f}.feed", positive=True), f"{f}.feed", ls)
        elif "duration" in seg:
            fr = rd.feed(L / ls / rd.number(seg["duration"], f"{f}.duration", positive=True), f"{f}.duration", ls)
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
    return ToolPath(poses=assemble_poses(P, R), s=s, t=times_from_feed(s, feed), feed=feed, source=src,
                    has_orientation=has_orientation, segment=np.concatenate(segidx), segment_types=types)


def _orientation(rd: _Toml, tab: dict, f: str, angle_scale: float) -> np.ndarray:
    if "rpy" in tab:
        rpy = rd.vector(tab["rpy"], f"{f}.rpy", 3) * angle_scale
        if np.any(np.abs(rpy) > MAX_ANGLE):
            raise rd.fail(f"{f}.rpy", f"angles must lie within ±{MAX_ANGLE / angle_scale:g} (file angle unit; ±8π rad)")
        return rpy_to_matrices(rpy)[0]
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
        pm = rd.position(seg["through"], f"{f}.through", ls)
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
        c = rd.position(seg["center"], f"{f}.center", ls)
        normal = rd.vector(seg["normal"], f"{f}.normal", 3)
        big = float(np.abs(normal).max())
        normal = normal / big if big > 0 else normal     # scaled first: [1e308, 0, 0] must not overflow
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
