"""Tracking errors of the path followers: a joint path's position, rotation and tool-axis errors
against its target poses (:func:`tracking_errors`, batch), and the single-step helpers of
:func:`planning.follow.follow_path` — the rotation vector of one pair of rotations, a direction
perpendicular to the tool axis, and the norms of a predicted error in a mode's task space.
"""
from __future__ import annotations

import math

import numpy as np

from kin.transforms import rotation_error

__all__ = ["tracking_errors"]


def tracking_errors(robot, Q: np.ndarray, poses: np.ndarray) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """(position error (N,) m, rotation angle (N,) rad, tool-z-axis angle (N,) rad) of a joint path
    against target poses; rows with non-finite q give NaN."""
    Q = np.asarray(Q, dtype=float)
    ok = np.all(np.isfinite(Q), axis=1)
    pe = np.full(len(Q), np.nan)
    oe = np.full(len(Q), np.nan)
    ae = np.full(len(Q), np.nan)
    if ok.any():
        T = robot.fk(Q[ok])
        P = poses[ok]
        pe[ok] = np.linalg.norm(P[:, :3, 3] - T[:, :3, 3], axis=1)
        oe[ok] = np.linalg.norm(rotation_error(P[:, :3, :3], T[:, :3, :3]), axis=1)
        c = np.clip(np.einsum("ij,ij->i", P[:, :3, 2], T[:, :3, 2]), -1.0, 1.0)
        s = np.linalg.norm(np.cross(T[:, :3, 2], P[:, :3, 2]), axis=1)
        ae[ok] = np.arctan2(s, c)
    return pe, oe, ae


def _log_rot(Ra: np.ndarray, Rb: np.ndarray) -> np.ndarray:
    """Rotation vector (base frame) of Ra·Rbᵀ — :func:`kin.transforms.rotation_error` for one pair,
    without the batch machinery (it runs twice per step); angles near π go to the batch version."""
    M = Ra @ Rb.T
    c = 0.5 * (M[0, 0] + M[1, 1] + M[2, 2] - 1.0)
    v = np.array([M[2, 1] - M[1, 2], M[0, 2] - M[2, 0], M[1, 0] - M[0, 1]])
    s = 0.5 * math.sqrt(v[0] * v[0] + v[1] * v[1] + v[2] * v[2])
    if c < -0.9:
        return rotation_error(Ra, Rb)
    if s < 1e-7:
        return 0.5 * v            # angle ≈ sin(angle): first order is exact to 1e-21
    return v * (math.atan2(s, min(max(c, -1.0), 1.0)) / (2.0 * s))


def _any_perpendicular(z: np.ndarray) -> np.ndarray:
    a = np.eye(3)[int(np.argmin(np.abs(z)))]
    v = np.cross(z, a)
    return v / np.linalg.norm(v)


def _task_error_norms(r: np.ndarray, R: np.ndarray, mode: str) -> tuple[float, float]:
    """(position, orientation) norms of a predicted error in the mode's task space."""
    rp = float(np.linalg.norm(r[:3]))
    if mode == "pose":
        return rp, float(np.linalg.norm(r[3:]))
    if mode == "axis":
        return rp, float(np.linalg.norm((R.T @ r[3:])[:2]))
    return rp, 0.0
