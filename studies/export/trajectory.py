"""The trajectory file rmtkit writes and reads: a timed joint trajectory as CSV.

``rmt time --out`` and ``rmt plan --time --trajectory-out`` write it; ``rmt export-trajectory``
reads it (:func:`read_trajectory`).  A few ``#`` lines state what the columns are, then a header row
and one row per sample::

    # rmtkit trajectory 1
    # robot: ur5e
    # joints: ["base", "shoulder", "elbow", "wrist1", "wrist2", "wrist3"]
    # angle_unit: deg
    # length_unit: m
    # columns: t s; q1..q6 positions in angle_unit (revolute) or length_unit (prismatic); qd per s; qdd per s²
    t,q1,...,q6,qd1,...,qd6,qdd1,...,qdd6
    0.0,0.0,-90.0,...

``joints`` is a JSON list (a name may hold any character); ``tau1..taun`` (N·m or N) may follow the
accelerations.  Times start at 0 and increase; the q̈ of a row is the acceleration from that row on
(the next row may start another): between two rows the trajectory is the quartic in t with the first
row's q, q̇, q̈ and the second's q, q̇ (:mod:`studies.export.interpolate`).  A file without the ``#``
lines (written by an older rmtkit) is read in the robot file's units.
"""
from __future__ import annotations

import csv
import io
import json
import math
from dataclasses import dataclass
from pathlib import Path

import numpy as np

import kin
from kin.states import is_number

__all__ = ["Trajectory", "TrajectoryFileError", "trajectory_csv_text", "read_trajectory", "MAX_TRAJECTORY_BYTES",
           "FORMAT_LINE"]

#: the largest trajectory file read (about 300 000 samples of six joints)
MAX_TRAJECTORY_BYTES = 100_000_000
#: the first line of every trajectory file
FORMAT_LINE = "# rmtkit trajectory 1"
ANGLE_UNITS = {"rad": 1.0, "deg": math.pi / 180.0}
LENGTH_UNITS = {"m": 1.0, "mm": 1e-3, "in": 0.0254}


class TrajectoryFileError(kin.RmtError):
    """A trajectory file is missing, too large or invalid (the CLI exits with code 2)."""


@dataclass
class Trajectory:
    """A timed joint trajectory in SI: ``t`` (K,) s from 0, increasing; ``q``, ``qd``, ``qdd`` (K, n)
    rad or m, per s, per s²; ``tau`` (K, n) N·m or N or None; ``names`` the joint names the file gives
    (None: none); ``source`` the file it came from (for messages)."""

    t: np.ndarray
    q: np.ndarray
    qd: np.ndarray
    qdd: np.ndarray
    tau: np.ndarray | None = None
    names: list[str] | None = None
    source: str = ""

    @property
    def n(self) -> int:
        return self.q.shape[1]

    @property
    def duration(self) -> float:
        return float(self.t[-1])


def columns(n: int, torques: bool = False) -> list[str]:
    """The header row: t, q1..qn, qd1..qdn, qdd1..qddn (and tau1..taun)."""
    out = ["t"] + [f"{k}{j}" for k in ("q", "qd", "qdd") for j in range(1, n + 1)]
    return out + ([f"tau{j}" for j in range(1, n + 1)] if torques else [])


def trajectory_csv_text(robot, t, q, qd, qdd, tau=None, si: bool = False, names=None) -> str:
    """The trajectory file's text of samples ``t`` (K,) s and ``q``, ``qd``, ``qdd`` (K, n) SI (``tau``
    (K, n) N·m or N, optional): in the robot file's units, or in SI (rad, m) with ``si``; ``names`` the
    joint names stated (default: the robot's).  Values exact to the bit (``repr``)."""
    c = robot.chain
    n = robot.n
    names = list(c.joint_names() if names is None else names)
    au, lu = ("rad", "m") if si else (c.angle_unit, c.length_unit)
    conv = (lambda x: np.asarray(x, float)) if si else c.from_si
    buf = io.StringIO()
    buf.write(f"{FORMAT_LINE}\n# robot: {robot.name}\n# joints: {json.dumps(names)}\n"
              f"# angle_unit: {au}\n# length_unit: {lu}\n"
              f"# columns: t s; q1..q{n} positions in angle_unit (revolute) or length_unit (prismatic), "
              f"in the order of joints; qd per s; qdd per s²{'; tau N·m or N' if tau is not None else ''}\n")
    w = csv.writer(buf, lineterminator="\n")
    w.writerow(columns(n, tau is not None))
    cols = [np.asarray(t, float)[:, None], conv(q), conv(qd), conv(qdd)] + ([np.asarray(tau, float)]
                                                                          if tau is not None else [])
    for row in np.hstack(cols):
        w.writerow([repr(float(x)) for x in row])
    return buf.getvalue()


def _meta(path: Path, lineno: int, line: str, meta: dict) -> None:
    """One ``# key: value`` line: the keys this format knows are checked; other comments are skipped."""
    key, sep, value = line[1:].partition(":")
    key, value = key.strip(), value.strip()
    if not sep or key not in ("robot", "joints", "angle_unit", "length_unit"):
        return
    if key in meta:
        raise TrajectoryFileError(f"{path}: line {lineno}: '{key}' is given twice")
    if key == "joints":
        try:
            names = json.loads(value)
        except ValueError:
            names = None
        if not (isinstance(names, list) and names and all(isinstance(x, str) for x in names)):
            raise TrajectoryFileError(f"{path}: line {lineno}: joints must be a JSON list of joint names, "
                                      f'e.g. ["j1", "j2"]')
        value = names
    elif key == "angle_unit" and value not in ANGLE_UNITS:
        raise TrajectoryFileError(f"{path}: line {lineno}: angle_unit {value[:40]!r} is not one of "
                                  f"{', '.join(ANGLE_UNITS)}")
    elif key == "length_unit" and value not in LENGTH_UNITS:
        raise TrajectoryFileError(f"{path}: line {lineno}: length_unit {value[:40]!r} is not one of "
                                  f"{', '.join(LENGTH_UNITS)}")
    meta[key] = value


def _header(path: Path, lineno: int, row: list[str], robot) -> bool:
    """Check the header row against ``robot``; True when it has torque columns."""
    cells = [c.strip() for c in row]
    n = robot.n
    qs = [c for c in cells if c[:1] == "q" and c[1:].isdigit()]
    if qs and len(qs) != n:
        raise TrajectoryFileError(f"{path}: line {lineno}: the header has {len(qs)} joint position columns "
                                  f"(q1..q{len(qs)}); {robot.name} has {n} joints")
    for torques in (False, True):
        if cells == columns(n, torques):
            return torques
    raise TrajectoryFileError(f"{path}: line {lineno}: the header must be t,q1..q{n},qd1..qd{n},qdd1..qdd{n} "
                              f"(and optionally tau1..tau{n}) for {robot.name}; got {','.join(cells)[:80]!r}")


def read_trajectory(robot, path: str | Path, max_bytes: int = MAX_TRAJECTORY_BYTES) -> Trajectory:
    """Read and check a trajectory file for ``robot``: at most ``max_bytes``, a header matching the
    robot's joint count, at least two rows of finite numbers, times from 0 strictly increasing; units
    from its ``angle_unit``/``length_unit`` lines (default: the robot file's).  Every problem is one
    :class:`TrajectoryFileError` line naming the file and the line."""
    from kin.files import FileReadError, read_text
    path = Path(path)
    try:
        text = read_text(path, "trajectory file", max_bytes)
    except FileReadError as e:
        raise TrajectoryFileError(str(e)) from None
    meta: dict = {}
    torques = None
    rows: list[list[float]] = []
    linenos: list[int] = []
    for lineno, line in enumerate(text.split("\n"), 1):
        line = line.strip()
        if not line:
            continue
        if line.startswith("#"):
            if torques is None:
                _meta(path, lineno, line, meta)
            continue
        row = line.split(",")
        if torques is None:
            torques = _header(path, lineno, row, robot)
            width = 1 + (4 if torques else 3) * robot.n
            continue
        if len(row) != width:
            raise TrajectoryFileError(f"{path}: line {lineno}: {len(row)} values; the header has {width} columns")
        try:
            vals = [float(c) for c in row]
        except ValueError:
            bad = next(c for c in row if not is_number(c))
            raise TrajectoryFileError(f"{path}: line {lineno}: {bad.strip()[:40]!r} is not a number") from None
        if not all(math.isfinite(v) for v in vals):
            k = next(i for i, v in enumerate(vals) if not math.isfinite(v))
            raise TrajectoryFileError(f"{path}: line {lineno}: column {columns(robot.n, torques)[k]} is "
                                      f"{row[k].strip()[:20]}; every value must be a finite number")
        rows.append(vals)
        linenos.append(lineno)
    if torques is None:
        raise TrajectoryFileError(f"{path}: no header row (t,q1..q{robot.n},qd1..,qdd1..); is it a trajectory "
                                  f"file (rmt time --out)?")
    if len(rows) < 2:
        raise TrajectoryFileError(f"{path}: {len(rows)} sample(s); a trajectory needs at least two (its start "
                                  f"and its end)")
    _check_robot(path, meta, robot)
    X = np.array(rows)
    t = X[:, 0]
    if t[0] != 0.0:
        raise TrajectoryFileError(f"{path}: line {linenos[0]}: the first sample is at t = {t[0]:g} s; a "
                                  f"trajectory starts at t = 0")
    dt = np.diff(t)
    if not np.all(dt > 0):
        i = int(np.argmax(~(dt > 0)))
        raise TrajectoryFileError(f"{path}: line {linenos[i + 1]}: t = {float(t[i + 1])!r} s is not after the previous "
                                  f"sample's {float(t[i])!r} s; times must increase strictly")
    n = robot.n
    scale = np.where(robot.chain.revolute_mask, ANGLE_UNITS[meta.get("angle_unit", robot.chain.angle_unit)],
                     LENGTH_UNITS[meta.get("length_unit", robot.chain.length_unit)])
    q, qd, qdd = (X[:, 1 + k * n:1 + (k + 1) * n] * scale for k in range(3))
    if not (np.isfinite(q).all() and np.isfinite(qd).all() and np.isfinite(qdd).all()):
        raise TrajectoryFileError(f"{path}: a value overflows when converted to SI; every value must be a finite "
                                  f"number within the float range")
    tau = X[:, 1 + 3 * n:] if torques else None
    return Trajectory(t, q, qd, qdd, tau, meta.get("joints"), str(path))


def _check_robot(path: Path, meta: dict, robot) -> None:
    """The file's ``robot`` and ``joints`` lines, when given, must fit ``robot``."""
    names = meta.get("joints")
    if names is not None and len(names) != robot.n:
        raise TrajectoryFileError(f"{path}: names {len(names)} joints; {robot.name} has {robot.n}")
    if "robot" in meta and meta["robot"] != robot.name:
        raise TrajectoryFileError(f"{path}: is a trajectory of {meta['robot'][:40]!r}, not of {robot.name} "
                                  f"(its robot line); give the robot it was made for")
