"""A tool-centre-point offset on top of a robot file's ``[tool]``, without copying the file.

``with_tcp(robot, xyz, rpy)`` returns the robot whose tool frame is the file's tool frame times the
offset T = (xyz, R(rpy)) (SI; R = Rz(yaw)·Ry(pitch)·Rx(roll), as everywhere): FK, IK, Jacobians and
every pose a command reads or prints are then about the offset point.  The physical tool does not
move: capsules on the tool body (n + 1) and the payload, given in the old tool frame, are
re-expressed in the new one (T⁻¹ applied), and :attr:`kin.Robot.tcp` keeps T so that a work cell's
``[[tool]]`` shapes, written in the robot file's tool frame, are placed the same way
(:meth:`planning.cell.Cell.resolve`).  :func:`tcp_transform` reads and bounds the six values.
"""
from __future__ import annotations

import math
from dataclasses import replace

import numpy as np

from kin.chain import ANGLE_UNITS, LENGTH_UNITS, Placement
from kin.errors import ArgumentError
from kin.transforms import make_transform, rpy_to_matrix

__all__ = ["with_tcp", "tcp_transform", "MAX_TCP_LENGTH", "MAX_TCP_ANGLE"]

#: the largest |x|, |y|, |z| of an offset (m) and |roll|, |pitch|, |yaw| (rad)
MAX_TCP_LENGTH = 1e4
MAX_TCP_ANGLE = 2 * math.pi


def tcp_transform(values, length_unit: str = "m", angle_unit: str = "rad", what: str = "tcp") -> np.ndarray:
    """The 4×4 offset (SI) of ``values`` = [x, y, z] or [x, y, z, roll, pitch, yaw] in the given units;
    each finite, lengths within ±10 km, angles within ±360°; ``what`` names the input in errors."""
    try:
        v = [float(x) for x in values]
    except (TypeError, ValueError):
        items = list(values) if isinstance(values, (list, tuple)) else [values]
        plain = " ".join(str(x) for x in items)           # as typed, not a Python repr
        raise ArgumentError(f"{what}: expected 3 or 6 numbers (x y z [roll pitch yaw]), got {plain}") from None
    if len(v) not in (3, 6):
        raise ArgumentError(f"{what}: expected 3 or 6 numbers (x y z [roll pitch yaw]), got {len(v)}")
    ls, as_ = LENGTH_UNITS[length_unit], ANGLE_UNITS[angle_unit]
    for i, x in enumerate(v):
        name = ("x", "y", "z", "roll", "pitch", "yaw")[i]
        lim, unit, s = (MAX_TCP_LENGTH, length_unit, ls) if i < 3 else (MAX_TCP_ANGLE, angle_unit, as_)
        if not math.isfinite(x) or abs(x * s) > lim * (1 + 1e-12):
            raise ArgumentError(f"{what}: {name} = {x!r} must be a finite number within ±{lim / s:g} {unit}")
    v += [0.0] * (6 - len(v))
    return make_transform(rpy_to_matrix(np.array(v[3:]) * as_), np.array(v[:3]) * ls)


def with_tcp(robot, T):
    """``robot`` (a :class:`kin.Robot`) with its tool frame moved by T (4×4, SI, in the current tool
    frame); T = identity returns ``robot`` itself.  See the module text."""
    from kin.robot import Robot
    T = np.asarray(T, dtype=float)
    if T.shape != (4, 4) or not np.all(np.isfinite(T)):
        raise ArgumentError(f"tcp must be a finite 4×4 transform, got shape {T.shape}")
    if np.array_equal(T, np.eye(4)):
        return robot
    chain = robot.chain
    inv = np.linalg.inv(T)
    tool_body = chain.n + 1
    new = replace(chain, tool=Placement.from_matrix(chain.tool.matrix @ T))
    g = chain.geometry
    if g is not None and (any(c.body == tool_body for c in g.capsules) or any(h.body == tool_body for h in g.hulls)):
        def moved(p):
            return tuple(float(x) for x in (inv @ [*p, 1.0])[:3])
        caps = tuple(replace(c, a=moved(c.a), b=moved(c.b)) if c.body == tool_body else c for c in g.capsules)
        hulls = tuple(replace(h, points=h.array @ inv[:3, :3].T + inv[:3, 3]) if h.body == tool_body else h
                      for h in g.hulls)
        new = replace(new, geometry=replace(g, capsules=caps, hulls=hulls))
    if chain.payload is not None:
        new = replace(new, payload=chain.payload.transformed(inv))
    out = Robot(new, backend=robot.backend_request)
    out.tcp = getattr(robot, "tcp", np.eye(4)) @ T
    return out
