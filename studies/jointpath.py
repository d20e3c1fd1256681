"""Joint paths as reports and files show them: resampled evenly along their joint-space length
(:func:`densify`, for plots and the 3-D view's slider) and written as CSV in the robot file's units
(:func:`path_csv_text`, what ``rmt plan --out`` and a study's ``plan.csv`` hold).

(:func:`planning.validate.densify` is another thing: the states a validator checks, spaced by a
step angle.)"""
from __future__ import annotations

import csv
import io

import numpy as np

__all__ = ["densify", "path_csv_text"]


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
