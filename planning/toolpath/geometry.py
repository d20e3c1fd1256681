"""Geometry of tool paths: chord length and feed timing, rotations from roll-pitch-yaw angles and
quaternions, slerp between rotations, and poses assembled from positions and rotations.

Shared by the :class:`~planning.toolpath.model.ToolPath` value and the two readers
(:mod:`planning.toolpath.csv_reader`, :mod:`planning.toolpath.segments`); SI units throughout.
"""
from __future__ import annotations

import numpy as np

from kin.transforms import log_so3

__all__ = ["chord_length", "times_from_feed", "rpy_to_matrices", "quaternions_to_matrices", "slerp",
           "assemble_poses", "QUAT_NORM_TOL"]

#: a file's quaternion may miss unit norm by this much (rounded values); it is then normalised
QUAT_NORM_TOL = 1e-3


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


def assemble_poses(P: np.ndarray, R: np.ndarray) -> np.ndarray:
    """Poses (N, 4, 4) from positions P (N, 3) and rotations R (N, 3, 3)."""
    T = np.zeros((len(P), 4, 4))
    T[:, :3, :3] = R
    T[:, :3, 3] = P
    T[:, 3, 3] = 1.0
    return T
