"""Projecting configurations onto the singular set of any chain (the numeric analysis of
:mod:`kin.singular.numeric`).

With U, S, V the SVD of the task Jacobian J (m × n, r = min(m, n)), the residuals
h_ab = u_aᵀ J v_b over the near-null left vectors u_a (columns r…m of U) and right vectors v_b
(columns r…n of V) vanish exactly where rank J < r; their gradients ∂h_ab/∂q_k = u_aᵀ ∂_k J v_b
(∂_k J by central differences of the compiled Jacobian) span the normal space of the set.
Gauss–Newton on h moves a configuration onto the set: for a square J this is Newton on the signed
σ_min, for a redundant arm (n > m) the set is where J·Jᵀ is singular, of codimension n − m + 1.
"""
from __future__ import annotations

import time

import numpy as np

#: finite-difference step of ∂J/∂q (rad or m)
FD_STEP = 1e-6
#: a joint belongs to a component's support when its normal component exceeds this share
SUPPORT_TOL = 1e-5
#: longest Gauss–Newton step (rad or m)
MAX_STEP = 0.3


def _task_jacobian(robot, Q: np.ndarray) -> np.ndarray:
    return robot.jacobian(Q)[:, list(robot.task_rows), :]


def _jacobian_derivatives(robot, Q: np.ndarray) -> np.ndarray:
    """∂J/∂q_k of the task Jacobian by central differences: (N, n, m, n), index 1 = k."""
    N, n = Q.shape
    E = np.eye(n) * FD_STEP
    Qp = (Q[:, None, :] + E[None]).reshape(-1, n)
    Qm = (Q[:, None, :] - E[None]).reshape(-1, n)
    Jp = _task_jacobian(robot, Qp)
    Jm = _task_jacobian(robot, Qm)
    return ((Jp - Jm) / (2 * FD_STEP)).reshape(N, n, Jp.shape[1], n)


def residuals(robot, Q: np.ndarray):
    """(σ_min (N,), residuals h (N, c), normal rows G (N, c, n), left null u (N, m), second
    smallest singular value (N,)) at Q."""
    J = _task_jacobian(robot, Q)
    N, m, n = J.shape
    r = min(m, n)
    U, S, Vt = np.linalg.svd(J, full_matrices=True)
    Ul = U[:, :, r - 1:]                      # (N, m, a)
    Vr = np.transpose(Vt, (0, 2, 1))[:, :, r - 1:]   # (N, n, b)
    dJ = _jacobian_derivatives(robot, Q)      # (N, n, m, n)
    h = np.einsum("nia,nij,njb->nab", Ul, J, Vr).reshape(N, -1)
    G = np.einsum("nia,nkij,njb->nabk", Ul, dJ, Vr).reshape(N, -1, n)
    second = S[:, r - 2] if r >= 2 else np.full(N, np.inf)
    return S[:, r - 1], h, G, U[:, :, r - 1], second


def project(robot, Q0: np.ndarray, iterations: int = 40, tol: float = 1e-10,
            deadline: float | None = None, slack: float = 0.0) -> tuple[np.ndarray, np.ndarray]:
    """Gauss–Newton projection of configurations (N, n) onto the singular set, inside the joint
    limits widened by ``slack`` (rad or m) → (projected Q, converged mask).  ``tol``: σ_min
    accepted as zero (SI)."""
    lo, hi = robot.chain.lower - slack, robot.chain.upper + slack
    Q = np.clip(np.array(Q0, dtype=float), lo, hi)
    active = np.ones(len(Q), bool)
    sigma = np.full(len(Q), np.inf)
    for _ in range(iterations):
        idx = np.flatnonzero(active)
        if len(idx) == 0 or (deadline is not None and time.perf_counter() > deadline):
            break
        s, h, G, _, _ = residuals(robot, Q[idx])
        sigma[idx] = s
        done = s < tol
        active[idx[done]] = False
        idx, h, G = idx[~done], h[~done], G[~done]
        if len(idx) == 0:
            break
        step = -np.einsum("nkc,nc->nk", np.linalg.pinv(G, rcond=1e-10), h)
        norm = np.linalg.norm(step, axis=1, keepdims=True)
        step *= np.minimum(1.0, MAX_STEP / np.maximum(norm, 1e-300))
        Q[idx] = np.clip(Q[idx] + step, lo, hi)
    s = np.asarray(robot.sigma_min(Q)) if len(Q) else np.zeros(0)
    return Q, (s < 10 * tol) & np.isfinite(s)


# ---- describing the points ------------------------------------------------------------------------
def support(G: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """Per point: boolean support (N, n) of the normal space and a unit normal (N, n)."""
    col = np.linalg.norm(G, axis=1)                      # (N, n)
    scale = np.maximum(col.max(axis=1, keepdims=True), 1e-300)
    _, _, Vt = np.linalg.svd(G, full_matrices=False)
    return col > SUPPORT_TOL * scale, Vt[:, 0, :]
