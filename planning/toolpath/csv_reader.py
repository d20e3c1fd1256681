"""CSV tool paths (``.csv``): one waypoint per row, read into a :class:`~planning.toolpath.model.ToolPath`
in SI units (conversion happens once, here).

A header names the columns (case-insensitive, any order; comma, semicolon or whitespace
separated; ``#`` starts a comment line):

``x, y, z`` (required, file length unit) and the orientation as either ``roll, pitch, yaw``
(fixed-axis RPY, R = Rz(yaw)·Ry(pitch)·Rx(roll), file angle unit) or a unit quaternion
``qw, qx, qy, qz`` — or neither, for a position-only path; optionally ``t`` (s, strictly
increasing) or ``feed`` (file length unit / s: the feed of the move *into* that row).

Values are in the *robot file's* units.  Every problem raises
:class:`~planning.toolpath.model.ToolPathError` naming the file, the line or column, and the
allowed values.
"""
from __future__ import annotations

import csv
import io
import math
from pathlib import Path

import numpy as np

from kin.chain import ANGLE_UNITS, LENGTH_UNITS
from planning.toolpath.geometry import (
    QUAT_NORM_TOL,
    assemble_poses,
    chord_length,
    quaternions_to_matrices,
    rpy_to_matrices,
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

__all__ = ["read_toolpath_csv", "parse_toolpath_csv", "CSV_COLUMNS"]

CSV_COLUMNS = ("x", "y", "z", "roll", "pitch", "yaw", "qw", "qx", "qy", "qz", "t", "feed")


def _split(line: str, delim: str | None) -> list[str]:
    if delim is None:
        return line.split()
    return [c.strip() for c in next(csv.reader(io.StringIO(line), delimiter=delim))]


def read_toolpath_csv(path: str | Path, robot) -> ToolPath:
    """Read a CSV tool path (see the module docstring) in ``robot``'s file units → :class:`ToolPath` (SI).

    ``robot`` is a :class:`kin.Robot` or :class:`kin.Chain`; only its units are used.
    """
    text, src = read_toolpath_text(path)
    length_unit, angle_unit = robot_units(robot)
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
    for group, scale, top, what in ((("x", "y", "z"), length_scale, MAX_COORDINATE, "file length unit; 10 km"),
                                     (("roll", "pitch", "yaw"), angle_scale, 8 * math.pi, "file angle unit; ±8π rad")):
        for c in group:
            if c in cols and np.any(np.abs(cols[c]) * scale > top):
                i = int(np.argmax(np.abs(cols[c]) * scale > top))
                raise ToolPathError(f"{cols[c][i]:g} is outside the allowed range ±{top / scale:g} ({what})", src,
                                    f"line {lines[i]}, column {c!r}")
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
        bad = (feed < FEED_RANGE[0]) | (feed > FEED_RANGE[1])
        if np.any(bad):
            i = int(np.argmax(bad))
            raise ToolPathError(f"feed {cols['feed'][i]:.6g} is outside the allowed range "
                                f"[{FEED_RANGE[0] / length_scale:g}, "
                                f"{FEED_RANGE[1] / length_scale:g}] ({unit_names[0]}/s)", src,
                                f"line {lines[i]}, column 'feed'")
        t = times_from_feed(s, feed)
    return ToolPath(poses=assemble_poses(P, R), s=s, t=t, feed=feed, source=src,
                    has_orientation=has_orientation, line=lines)
