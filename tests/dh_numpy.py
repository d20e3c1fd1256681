"""A plain numpy re-implementation of DH forward kinematics, for tests only.

Independent of rmtkit's kinematics code (it reads only the chain *description*: joints, base,
tool, convention), so that tests can compare the product against a second, simple implementation
and against the numbers of the reference document.

Conventions (SI units, per row i with joint variable q_i):

* standard (distal):   A_i = Rz(θ_i) · Tz(d_i) · Tx(a_i) · Rx(α_i); joint i acts about z_{i-1}
* modified (proximal): A_i = Rx(α_{i-1}) · Tx(a_{i-1}) · Rz(θ_i) · Tz(d_i), the row's a/alpha
  fields holding a_{i-1}, α_{i-1}; joint i acts about z_i

revolute: θ_i = q_i + theta, d_i = d;   prismatic: d_i = q_i + d, θ_i = theta.
FK = base · A_1 ⋯ A_n · tool.
"""
from __future__ import annotations

import numpy as np


def rot_x_h(a: float) -> np.ndarray:
    c, s = np.cos(a), np.sin(a)
    return np.array([[1.0, 0.0, 0.0, 0.0], [0.0, c, -s, 0.0], [0.0, s, c, 0.0], [0.0, 0.0, 0.0, 1.0]])


def rot_z_h(a: float) -> np.ndarray:
    c, s = np.cos(a), np.sin(a)
    return np.array([[c, -s, 0.0, 0.0], [s, c, 0.0, 0.0], [0.0, 0.0, 1.0, 0.0], [0.0, 0.0, 0.0, 1.0]])


def trans_h(x: float = 0.0, y: float = 0.0, z: float = 0.0) -> np.ndarray:
    T = np.eye(4)
    T[:3, 3] = (x, y, z)
    return T


def dh_standard(theta: float, d: float, a: float, alpha: float) -> np.ndarray:
    """A = Rz(θ)·Tz(d)·Tx(a)·Rx(α), written out entry by entry (textbook form)."""
    ct, st, ca, sa = np.cos(theta), np.sin(theta), np.cos(alpha), np.sin(alpha)
    return np.array([[ct, -st * ca, st * sa, a * ct],
                     [st, ct * ca, -ct * sa, a * st],
                     [0.0, sa, ca, d],
                     [0.0, 0.0, 0.0, 1.0]])


def dh_modified(theta: float, d: float, a_prev: float, alpha_prev: float) -> np.ndarray:
    """A = Rx(α_{i-1})·Tx(a_{i-1})·Rz(θ)·Tz(d), written out entry by entry (Craig's form)."""
    ct, st, ca, sa = np.cos(theta), np.sin(theta), np.cos(alpha_prev), np.sin(alpha_prev)
    return np.array([[ct, -st, 0.0, a_prev],
                     [st * ca, ct * ca, -sa, -sa * d],
                     [st * sa, ct * sa, ca, ca * d],
                     [0.0, 0.0, 0.0, 1.0]])


def _row(chain, joint, qi: float) -> tuple[float, float, float, float]:
    """(θ, d, a, α) of one joint at joint value qi (SI), parameters resolved."""
    a = chain.resolve(joint.a)
    alpha = chain.resolve(joint.alpha)
    d = chain.resolve(joint.d)
    theta = chain.resolve(joint.theta)
    if joint.type == "revolute":
        theta = qi + theta
    elif joint.type == "prismatic":
        d = qi + d
    else:  # pragma: no cover - the chain model rejects other types
        raise ValueError(f"unknown joint type {joint.type!r}")
    return theta, d, a, alpha


def _check_q(chain, q) -> np.ndarray:
    q = np.asarray(q, dtype=float)
    if q.shape != (len(chain.joints),):
        raise ValueError(f"q has shape {q.shape}; expected ({len(chain.joints)},)")
    return q


def frames_numpy(chain, q) -> list[np.ndarray]:
    """Frames base·A_1⋯A_i for i = 0..n (without the tool), each 4×4, SI."""
    q = _check_q(chain, q)
    T = np.array(chain.base.matrix, dtype=float)
    out = [T]
    for j, qi in zip(chain.joints, q):
        theta, d, a, alpha = _row(chain, j, float(qi))
        if chain.convention == "standard":
            A = dh_standard(theta, d, a, alpha)
        elif chain.convention == "modified":
            A = dh_modified(theta, d, a, alpha)
        else:  # pragma: no cover
            raise ValueError(f"unknown convention {chain.convention!r}")
        T = T @ A
        out.append(T)
    return out


def fk_numpy(chain, q) -> np.ndarray:
    """Forward kinematics base · A_1 ⋯ A_n · tool as a 4×4 array (SI units)."""
    return frames_numpy(chain, q)[-1] @ np.array(chain.tool.matrix, dtype=float)


def jacobian_numpy(chain, q) -> np.ndarray:
    """Geometric Jacobian (6×n; rows vx vy vz wx wy wz) of the tool frame origin, base frame."""
    q = _check_q(chain, q)
    frames = frames_numpy(chain, q)
    p = (frames[-1] @ np.array(chain.tool.matrix, dtype=float))[:3, 3]
    J = np.zeros((6, len(chain.joints)))
    for i, j in enumerate(chain.joints):
        if chain.convention == "standard":
            axis_frame = frames[i]  # joint i acts about z_{i-1}
        else:
            a = chain.resolve(j.a)
            alpha = chain.resolve(j.alpha)
            axis_frame = frames[i] @ rot_x_h(alpha) @ trans_h(x=a)  # joint i acts about z_i
        z = axis_frame[:3, 2]
        o = axis_frame[:3, 3]
        if j.type == "revolute":
            J[:3, i] = np.cross(z, p - o)
            J[3:, i] = z
        else:
            J[:3, i] = z
    return J


def pose_errors_numpy(chain, Q, poses) -> tuple[np.ndarray, np.ndarray]:
    """Position error (m) and rotation angle (rad) between :func:`fk_numpy` of each configuration of
    ``Q`` and the matching 4×4 pose of ``poses``."""
    pe, oe = [], []
    for q, T in zip(Q, poses):
        F = fk_numpy(chain, q)
        pe.append(np.linalg.norm(F[:3, 3] - T[:3, 3]))
        c = np.clip((np.trace(T[:3, :3].T @ F[:3, :3]) - 1) / 2, -1, 1)
        oe.append(float(np.arccos(c)))
    return np.array(pe), np.array(oe)
