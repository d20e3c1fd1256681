"""The default collision geometry of a chain: capsules along its DH offsets, of one stated radius.

A DH row is a path of straight pieces from one frame's origin to the next (standard: along z_{k-1}
by d, then along x_k by a; modified: along x_{k-1} by a, then along z_k by d).  Each piece becomes a
capsule on the body it is fixed to — a piece on a revolute joint's axis is fixed to both sides and
goes with the later body — so the capsules follow the robot's real links, whatever the DH
convention.  Pieces along a prismatic joint's axis change length with the joint: they become a rail
on the body before it (covering the joint's whole stroke) and a ball where the moving body rides on
it.  Bodies with no piece of their own (a spherical wrist's middle link) get a ball at their frame's
origin.  The base gets a ball of 1.5 radii at frame 0's origin; the tool a capsule of half the radius
from the last frame's origin to the tool point when the tool placement moves it.

The radius, unless given, is 5 % of the chain's length (the sum of its DH offsets), at least 1 cm:
``RobotGeometry.radius`` states it (and its ``source`` says "default").  Real machines deserve a
``[geometry]`` table of their own (see the robot-file documentation).
"""
from __future__ import annotations

import math

import numpy as np

from kin.geometry.frames import dh_rows
from kin.geometry.model import RobotGeometry
from kin.geometry.shapes import LinkCapsule

__all__ = ["default_geometry", "default_radius", "chain_length"]

TINY = 1e-9     # m: pieces shorter than this are not pieces


def chain_length(chain) -> float:
    """The sum of the DH offsets |a| + |d| of a chain (m), prismatic strokes at their largest extent,
    plus the tool's offset."""
    rows = dh_rows(chain)
    total = 0.0
    for (a, _, d, _, pris), (lo, hi) in zip(rows, chain.limits):
        total += abs(a) + (max(abs(d + lo), abs(d + hi)) if pris else abs(d))
    return total + float(np.linalg.norm(chain.tool.matrix[:3, 3]))


def default_radius(chain) -> float:
    """5 % of :func:`chain_length`, at least 0.01 m."""
    return max(0.01, 0.05 * chain_length(chain))


def _inv(T: np.ndarray) -> np.ndarray:
    R, p = T[:3, :3], T[:3, 3]
    out = np.eye(4)
    out[:3, :3] = R.T
    out[:3, 3] = -R.T @ p
    return out


def _rx(a):
    c, s = math.cos(a), math.sin(a)
    return np.array([[1, 0, 0, 0], [0, c, -s, 0], [0, s, c, 0], [0, 0, 0, 1.0]])


def _rz(a):
    c, s = math.cos(a), math.sin(a)
    return np.array([[c, -s, 0, 0], [s, c, 0, 0], [0, 0, 1, 0], [0, 0, 0, 1.0]])


def _t(x=0.0, y=0.0, z=0.0):
    T = np.eye(4)
    T[:3, 3] = (x, y, z)
    return T


def _pt(T: np.ndarray, p=(0.0, 0.0, 0.0)) -> tuple[float, float, float]:
    v = T @ np.array([*p, 1.0])
    return tuple(float(x) for x in v[:3])   # type: ignore[return-value]


def default_geometry(chain, radius: float | None = None) -> RobotGeometry:
    """Capsules along the DH offsets of ``chain`` (see the module docstring); ``radius`` in m
    (default :func:`default_radius`)."""
    r = default_radius(chain) if radius is None else float(radius)
    if not (math.isfinite(r) and r > 0):
        raise ValueError(f"geometry radius {radius!r} must be a positive finite number (m)")
    n = chain.n
    rows = dh_rows(chain)
    caps: list[LinkCapsule] = [LinkCapsule(0, (0, 0, 0), (0, 0, 0), 1.5 * r, "base")]
    has_own = [False] * (n + 2)

    def add(body: int, p, q, label: str, radius: float = r) -> None:
        if math.dist(p, q) > TINY:
            caps.append(LinkCapsule(body, p, q, radius, label))
            has_own[body] = True

    modified = chain.convention == "modified"
    for k in range(1, n + 1):
        a, alpha, d, theta, pris = rows[k - 1]
        lo, hi = chain.limits[k - 1]
        label = f"link {k}"
        if not modified:
            # frame k-1 → Rz(θ)·Tz(d) → M → Tx(a)·Rx(α) → frame k
            to_k = _inv(_t(x=a) @ _rx(alpha))                   # frame "after Rz·Tz" in frame k
            M_k = _pt(to_k)                                      # M in frame k
            if pris:
                add(k - 1, (0, 0, d + lo), (0, 0, d + hi), f"link {k} rail")
                caps.append(LinkCapsule(k, M_k, M_k, r, f"{label} carriage"))
                has_own[k] = True
            else:
                O_prev_k = _pt(to_k @ _t(z=-d))                  # frame k-1's origin (on the axis) in frame k
                add(k, O_prev_k, M_k, label)
            add(k, M_k, (0, 0, 0), label)
        else:
            # frame k-1 → Rx(α)·Tx(a) → P (on axis k) → Rz(θ)·Tz(d) → frame k
            add(k - 1, (0, 0, 0), (a, 0, 0), f"link {k - 1}" if k > 1 else "base")
            P_prev = _rx(alpha) @ _t(x=a)                        # the axis frame in frame k-1
            if pris:
                add(k - 1, _pt(P_prev @ _rz(theta), (0, 0, d + lo)), _pt(P_prev @ _rz(theta), (0, 0, d + hi)),
                    f"link {k} rail")
                caps.append(LinkCapsule(k, (0, 0, 0), (0, 0, 0), r, f"{label} carriage"))
                has_own[k] = True
            else:
                add(k, (0, 0, -d), (0, 0, 0), label)
    for k in range(1, n + 1):
        if not has_own[k]:
            caps.append(LinkCapsule(k, (0, 0, 0), (0, 0, 0), r, f"link {k}"))
    tool = chain.tool.matrix
    if float(np.linalg.norm(tool[:3, 3])) > TINY:
        add(n + 1, _pt(_inv(tool)), (0, 0, 0), "tool", 0.5 * r)
    return RobotGeometry(tuple(caps), source="default", radius=r)
