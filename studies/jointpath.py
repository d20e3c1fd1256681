"""Joint paths as reports and files show them: resampled evenly along their joint-space length
(:func:`densify`, for plots and the 3-D view's slider) and written as CSV in the robot file's units
(:func:`path_csv_text`, what ``rmt plan --out`` and a study's ``plan.csv`` hold).

(:func:`planning.validate.densify` is another thing: the states a validator checks, spaced by a
step angle.)"""
from __future__ import annotations

import csv
import io
import math
from pathlib import Path

import numpy as np

import kin

__all__ = ["densify", "path_csv_text", "read_path_csv", "PathFileError", "MAX_PATH_BYTES", "outside_limits"]

#: the largest joint-path file read (about a million rows of six joints)
MAX_PATH_BYTES = 100_000_000


class PathFileError(kin.RmtError):
    """A joint-path CSV file is missing or invalid."""


def densify(Q: np.ndarray, m: int) -> np.ndarray:
    """``m`` configurations equally spaced in joint-space arc length along the polyline ``Q`` (M, n),
    its first and last waypoints included (a path of one waypoint is returned as it is).  Point k
    lies at the fraction k / (m − 1) of the path's length."""
    Q = np.asarray(Q, float)
    if len(Q) < 2:
        return Q.copy()
    s = np.r_[0.0, np.cumsum(np.linalg.norm(np.diff(Q, axis=0), axis=1))]
    if s[-1] == 0.0:
        return np.repeat(Q[:1], m, axis=0)
    t = np.linspace(0.0, s[-1], m)
    return np.stack([np.interp(t, s, Q[:, j]) for j in range(Q.shape[1])], axis=1)


def path_csv_text(robot, path_si: np.ndarray) -> str:
    """A joint path (M, n) in SI as CSV text in the robot file's units (header q1..qn; values exact
    to the bit)."""
    buf = io.StringIO()
    w = csv.writer(buf, lineterminator="\n")
    w.writerow([f"q{i + 1}" for i in range(robot.n)])
    for row in robot.chain.from_si(np.asarray(path_si, float)):
        w.writerow([repr(float(x)) for x in row])
    return buf.getvalue()


def read_path_csv(robot, path: str | Path) -> np.ndarray:
    """A joint path CSV (one configuration per row, robot file units; optional header) → (M, n) SI."""
    from kin.files import FileReadError, read_text
    path = Path(path)
    try:
        text = read_text(path, "joint-path file", MAX_PATH_BYTES)
    except FileReadError as e:
        raise PathFileError(str(e)) from None
    rows = []
    for lineno, row in enumerate(csv.reader(io.StringIO(text)), 1):
        if not row or all(not c.strip() for c in row) or row[0].lstrip().startswith("#"):
            continue
        try:
            vals = [float(c) for c in row]
        except ValueError:
            if not rows and lineno == 1:
                continue           # a header
            raise PathFileError(f"{path}: line {lineno}: non-numeric value in {row!r}") from None
        if len(vals) != robot.n:
            raise PathFileError(f"{path}: line {lineno}: {len(vals)} values; {robot.name} has {robot.n} joints")
        if not all(math.isfinite(v) for v in vals):
            raise PathFileError(f"{path}: line {lineno}: NaN or infinite value")
        rows.append(vals)
    if not rows:
        raise PathFileError(f"{path}: no configurations (one row of {robot.n} joint values per line)")
    return robot.chain.to_si(np.array(rows))


def outside_limits(robot, P: np.ndarray, where) -> str | None:
    """The first joint value of a path (M, n) SI outside the robot's limits (1e-12 SI of slack), in one
    line naming ``where(i)`` (i the 0-based row), the joint, its value and the range in robot file
    units; None when every value is inside."""
    c = robot.chain
    bad = (P < c.lower[None, :] - 1e-12) | (P > c.upper[None, :] + 1e-12)
    if not bad.any():
        return None
    i, j = (int(x) for x in np.argwhere(bad)[0])
    from studies.units import joint_units
    u = joint_units(c)[j]
    lo, hi, q = c.from_si(c.lower)[j], c.from_si(c.upper)[j], c.from_si(P[i])[j]
    return (f"{where(i)}: joint {c.joint_names()[j]} = {q:.10g} {u} is outside its limits "
            f"[{lo:.10g}, {hi:.10g}] {u} ({robot.name})")
