"""Small numpy helpers for rigid transforms (4×4 homogeneous matrices, SI units)."""
from __future__ import annotations

import numpy as np


def rot_x(a: float) -> np.ndarray:
    c, s = np.cos(a), np.sin(a)
    return np.array([[1.0, 0, 0], [0, c, -s], [0, s, c]])


def rot_y(a: float) -> np.ndarray:
    c, s = np.cos(a), np.sin(a)
    return np.array([[c, 0, s], [0, 1.0, 0], [-s, 0, c]])


def rot_z(a: float) -> np.ndarray:
    c, s = np.cos(a), np.sin(a)
    return np.array([[c, -s, 0], [s, c, 0], [0, 0, 1.0]])


def rpy_to_matrix(rpy) -> np.ndarray:
    """Fixed-axis roll-pitch-yaw (rad) → rotation: R = Rz(yaw)·Ry(pitch)·Rx(roll)."""
    r, p, y = (float(v) for v in rpy)
    return rot_z(y) @ rot_y(p) @ rot_x(r)


def matrix_to_rpy(R: np.ndarray) -> np.ndarray:
    """Inverse of :func:`rpy_to_matrix` (rad); pitch in [-π/2, π/2], roll = 0 at gimbal lock."""
    R = np.asarray(R, dtype=float)
    sp = -R[2, 0]
    if abs(sp) > 1.0 - 1e-12:
        pitch = np.copysign(np.pi / 2, sp)
        roll = 0.0
        yaw = np.arctan2(-R[0, 1], R[1, 1])
    else:
        pitch = np.arcsin(np.clip(sp, -1.0, 1.0))
        roll = np.arctan2(R[2, 1], R[2, 2])
        yaw = np.arctan2(R[1, 0], R[0, 0])
    return np.array([roll, pitch, yaw])


def make_transform(R: np.ndarray | None = None, p=None) -> np.ndarray:
    """Homogeneous 4×4 transform from a rotation (3×3) and a position (3,)."""
    T = np.eye(4)
    if R is not None:
        T[:3, :3] = R
    if p is not None:
        T[:3, 3] = p
    return T


def rigidity_defect(T: np.ndarray) -> float:
    """How far a 4×4 matrix is from a proper rigid transform (0 for an exact one)."""
    T = np.asarray(T, dtype=float)
    R = T[:3, :3]
    orth = np.abs(R.T @ R - np.eye(3)).max()
    det = abs(np.linalg.det(R) - 1.0)
    bottom = np.abs(T[3] - np.array([0.0, 0.0, 0.0, 1.0])).max()
    return float(max(orth, det, bottom))


def rotation_error(R_target: np.ndarray, R: np.ndarray) -> np.ndarray:
    """Rotation vector (axis·angle, rad) that takes R to R_target, expressed in the base frame.

    Works on single (3, 3) matrices or batches (..., 3, 3); exact for angles up to π.
    """
    Re = np.einsum("...ij,...kj->...ik", R_target, R)  # R_target · Rᵀ
    return log_so3(Re)


def log_so3(R: np.ndarray) -> np.ndarray:
    """Matrix logarithm of rotations (..., 3, 3) → rotation vectors (..., 3)."""
    R = np.asarray(R, dtype=float)
    tr = np.trace(R, axis1=-2, axis2=-1)
    cos = np.clip((tr - 1.0) / 2.0, -1.0, 1.0)
    v = np.stack([R[..., 2, 1] - R[..., 1, 2], R[..., 0, 2] - R[..., 2, 0], R[..., 1, 0] - R[..., 0, 1]], -1)
    sin = 0.5 * np.linalg.norm(v, axis=-1)
    angle = np.arctan2(sin, cos)
    out = np.empty(v.shape)
    small = sin < 1e-7
    near_pi = small & (cos < 0)
    regular = ~small
    # regular case: axis from the skew part
    with np.errstate(invalid="ignore", divide="ignore"):
        scale = np.where(regular, angle / np.where(regular, 2.0 * sin, 1.0), 0.5)
    out[...] = v * scale[..., None]
    if np.any(near_pi):
        # angle ≈ π: axis from the symmetric part, R ≈ 2·a·aᵀ − I
        Rp = R[near_pi]
        B = (Rp + np.eye(3)) / 2.0
        d = np.diagonal(B, axis1=-2, axis2=-1)
        k = np.argmax(d, axis=-1)
        idx = np.arange(len(k))
        col = B[idx, :, k]
        axis = col / np.sqrt(np.maximum(d[idx, k], 1e-300))[:, None]
        axis /= np.linalg.norm(axis, axis=-1, keepdims=True)
        # choose the sign consistent with the (tiny) skew part
        sgn = np.sign(np.einsum("ij,ij->i", axis, v[near_pi]))
        sgn[sgn == 0] = 1.0
        out[near_pi] = axis * (angle[near_pi] * sgn)[:, None]
    return out
