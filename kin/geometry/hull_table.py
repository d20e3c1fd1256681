"""The ``[[geometry.hull]]`` tables of a robot file: read (validated, numbers only) and written back.

Each table: ``body`` (a body name, as capsules have), ``points`` (an array of [x, y, z] in the file's
length unit, the body's frame: the hull is their convex hull), optional ``radius`` (a dilation in the
file's length unit, ≥ 0: what rounding the points may have cut off) and ``name``.  Hulls need listed
capsules (``[[geometry.capsule]]`` or the other shapes): the robot is taken to lie inside both.
"""
from __future__ import annotations

import math

import numpy as np

from kin.geometry.shapes import LinkHull

__all__ = ["HULL_FIELDS", "MAX_HULL_POINTS", "MAX_TOTAL_HULL_POINTS", "read_hulls", "hull_lines"]

HULL_FIELDS = ("body", "points", "radius", "name")
#: points of one hull, and of all of a robot's hulls, at most
MAX_HULL_POINTS = 4096
MAX_TOTAL_HULL_POINTS = 65536
MAX_LENGTH = 1e4           # m, as every length of a robot file


def _is_number(x) -> bool:
    return isinstance(x, (int, float)) and not isinstance(x, bool)


def read_hulls(items, fail, body_of, name_of, ls: float) -> list[LinkHull]:
    """``items``: the raw [[geometry.hull]] list; ``fail(field, message)`` makes the error to raise;
    ``body_of(value, field)`` a body number; ``name_of(value, field)`` a checked string; ``ls`` the file's
    length unit in m."""
    if not isinstance(items, list) or not all(isinstance(t, dict) for t in items):
        raise fail("geometry.hull", "must be an array of tables: write [[geometry.hull]]")
    out, total = [], 0
    for i, t in enumerate(items):
        fld = f"geometry.hull[{i}]"
        unknown = sorted(set(t) - set(HULL_FIELDS))
        if unknown:
            raise fail(f"{fld}.{unknown[0]}", f"unknown field; a hull has {', '.join(HULL_FIELDS)}")
        for f in ("body", "points"):
            if f not in t:
                raise fail(f"{fld}.{f}", "missing required field; a hull has body, points (optional: radius, name)")
        body = body_of(t["body"], f"{fld}.body")
        pts = t["points"]
        if not isinstance(pts, list) or not 1 <= len(pts) <= MAX_HULL_POINTS:
            raise fail(f"{fld}.points", f"must be a list of 1 to {MAX_HULL_POINTS} points [x, y, z]")
        total += len(pts)
        if total > MAX_TOTAL_HULL_POINTS:
            raise fail(f"{fld}.points", f"the hulls hold more than {MAX_TOTAL_HULL_POINTS} points in all")
        for k, p in enumerate(pts):
            if not (isinstance(p, list) and len(p) == 3 and all(_is_number(x) for x in p)):
                raise fail(f"{fld}.points[{k}]", f"must be a point [x, y, z] of three numbers, got {p!r}"[:200])
        P = np.array(pts, dtype=float) * ls
        bad = ~np.isfinite(P).all(axis=1) | (np.abs(P) > MAX_LENGTH).any(axis=1)
        if bad.any():
            k = int(np.flatnonzero(bad)[0])
            raise fail(f"{fld}.points[{k}]", f"must be finite and within ±{MAX_LENGTH / ls:g} (file length unit; "
                       "10 km)")
        radius = 0.0
        if "radius" in t:
            x = t["radius"]
            if not _is_number(x) or not math.isfinite(x) or x < 0 or x * ls > MAX_LENGTH:
                raise fail(f"{fld}.radius", f"must be a length ≥ 0 (file length unit), got {x!r}")
            radius = float(x) * ls
        name = name_of(t["name"], f"{fld}.name") if "name" in t else f"hull {i + 1}"
        out.append(LinkHull(body, P, radius, name))
    return out


def hull_lines(hulls, label_of, vec, num, string, ls: float) -> list[str]:
    """The [[geometry.hull]] tables of ``hulls`` in the file's length unit (``vec``, ``num``, ``string``
    format a point, a number and a string as the robot file does)."""
    out = []
    for h in hulls:
        out += ["", "[[geometry.hull]]", f"body = {string(label_of(h.body))}"]
        if h.radius:
            out.append(f"radius = {num(h.radius / ls)}")
        if h.name:
            out.append(f"name = {string(h.name)}")
        out.append("points = [" + ", ".join(vec(p, ls) for p in h.points) + "]")
    return out
