"""Numerical inverse kinematics: damped least squares (Levenberg–Marquardt), joint limits by
projection, many starts evaluated as one batch.

The error of a configuration q for a target (p*, R*) is e = [p* − p(q); w·log(R*·R(q)ᵀ)]
(base frame, the rows of the geometric Jacobian), with w a length that puts radians on the
scale of metres.  Each LM step solves (JᵀJ + λ·diag(JᵀJ) + μI)·Δq = Jᵀe, is projected onto the
joint limits, and is kept only when it lowers ‖e‖ (λ shrinks) — otherwise λ grows.

The success flag is honest: it is True only when the position error and the orientation error are
both within tolerance at a configuration inside the joint limits.  An unreachable target gives
success = False and the residual of the best attempt.
"""
from __future__ import annotations

import math
from typing import NamedTuple

import numpy as np

from kin.compiled import WANT_J, WANT_T
from kin.errors import ArgumentError, ConfigurationError
from kin.transforms import rotation_error

MODES = ("auto", "pose", "position")
#: largest defect of a target pose from a rigid transform (orthonormality, det, bottom row)
RIGID_TOL = 1e-6


class IKResult(NamedTuple):
    """Result of :func:`solve_ik`; fields are scalars for one target, arrays (N, …) for a batch."""

    success: bool | np.ndarray
    q: np.ndarray                               # (n,) or (N, n), SI
    position_error: float | np.ndarray          # m
    orientation_error: float | np.ndarray       # rad (0 in position mode)


def _targets(T, n_targets_hint: str) -> tuple[np.ndarray, np.ndarray | None, bool]:
    """Targets as positions (N, 3) and rotations (N, 3, 3) or None; plus whether one was given."""
    arr = np.asarray(T, dtype=float)
    if arr.shape == (4, 4):  # the common single pose: checked with plain floats (numpy's per-call cost dominates)
        return _one_pose(arr)
    if arr.shape == (3,) or (arr.ndim == 2 and arr.shape[1] == 3 and arr.shape != (3, 3)):
        single = arr.ndim == 1
        P = arr.reshape(-1, 3)
        R = None
    elif arr.shape[-2:] == (4, 4) and arr.ndim in (2, 3):
        single = arr.ndim == 2
        A = arr.reshape(-1, 4, 4)
        P, R = A[:, :3, 3].copy(), A[:, :3, :3].copy()
    else:
        raise ConfigurationError(f"IK target has shape {arr.shape}; expected a pose (4, 4) or (N, 4, 4), "
                                 f"or a position (3,) or (N, 3) {n_targets_hint}")
    if not np.all(np.isfinite(arr)):
        raise ConfigurationError("IK target holds NaN or infinite values")
    if R is not None and len(R):
        A = arr.reshape(-1, 4, 4)
        # huge entries overflow to inf or NaN, and NaN compares False: "not within tolerance" refuses both
        with np.errstate(over="ignore", invalid="ignore"):
            orth = np.abs(np.einsum("kji,kjl->kil", R, R) - np.eye(3)).max(axis=(1, 2))
            det = np.abs(np.linalg.det(R) - 1.0)
        bottom = np.abs(A[:, 3] - np.array([0.0, 0.0, 0.0, 1.0])).max(axis=1)
        bad = np.nonzero(~((orth <= RIGID_TOL) & (det <= RIGID_TOL) & (bottom <= RIGID_TOL)))[0]
        if len(bad):
            where = "" if single else f" (target {bad[0]})"
            raise ConfigurationError(f"IK target{where} is not a rigid transform: its rotation must be orthonormal "
                                     f"with det +1 (to {RIGID_TOL:g}) and its bottom row [0, 0, 0, 1]")
    return P, R, single


def _one_pose(arr: np.ndarray) -> tuple[np.ndarray, np.ndarray, bool]:
    (a, b, c, px), (d, e, f, py), (g, h, i, pz), (w0, w1, w2, w3) = arr.tolist()
    zero = 0.0 * a + 0.0 * b + 0.0 * c + 0.0 * px + 0.0 * d + 0.0 * e + 0.0 * f + 0.0 * py \
        + 0.0 * g + 0.0 * h + 0.0 * i + 0.0 * pz + 0.0 * w0 + 0.0 * w1 + 0.0 * w2 + 0.0 * w3
    if zero != 0.0:                  # 0·x is NaN exactly when x is NaN or ±inf (and never overflows)
        raise ConfigurationError("IK target holds NaN or infinite values")
    # columns orthonormal (RᵀR = I), det R = 1, bottom row [0, 0, 0, 1]
    defect = max(abs(a * a + d * d + g * g - 1.0), abs(b * b + e * e + h * h - 1.0), abs(c * c + f * f + i * i - 1.0),
                 abs(a * b + d * e + g * h), abs(a * c + d * f + g * i), abs(b * c + e * f + h * i),
                 abs(a * (e * i - f * h) - b * (d * i - f * g) + c * (d * h - e * g) - 1.0),
                 abs(w0), abs(w1), abs(w2), abs(w3 - 1.0))
    if not defect <= RIGID_TOL:
        raise ConfigurationError(f"IK target is not a rigid transform: its rotation must be orthonormal with det +1 "
                                 f"(to {RIGID_TOL:g}) and its bottom row [0, 0, 0, 1]")
    return arr[None, :3, 3], arr[None, :3, :3], True


class Problem(NamedTuple):
    """A validated IK request (see :func:`prepare`)."""

    Pt: np.ndarray                 # (N, 3) target positions, m
    Rt: np.ndarray | None          # (N, 3, 3) target rotations; None in position mode
    single: bool                   # one target given (scalar results)
    Q0: np.ndarray | None          # (N, n) warm starts inside the limits, or None
    P: np.ndarray | None           # design parameters (n_p,) or (N, n_p); None: nominal


def prepare(robot, T, q0, mode: str, params, tol_position: float, tol_orientation: float) -> Problem:
    """Validate an IK request: target shapes and values, mode, q0, parameters, tolerances."""
    if mode not in MODES:
        raise ArgumentError(f"mode {mode!r} unknown; allowed: {', '.join(MODES)}")
    for name, tol in (("tol_position", tol_position), ("tol_orientation", tol_orientation)):
        if not (math.isfinite(tol) and tol > 0):
            raise ConfigurationError(f"IK {name} = {tol} must be a positive finite number")
    chain = robot.chain
    n = chain.n
    Pt, Rt, single = _targets(T, f"for {chain.name}")
    if mode == "auto":
        mode = "pose" if (Rt is not None and len(robot.task_rows) == 6) else "position"
    if mode == "pose" and Rt is None:
        raise ConfigurationError("IK mode 'pose' needs a 4×4 target, got a position")
    if mode == "position":
        Rt = None
    N = len(Pt)
    Q0 = None
    if q0 is not None:
        Q0, _ = chain.as_batch(q0, "q0")
        if len(Q0) not in (1, N):
            raise ConfigurationError(f"q0 has {len(Q0)} rows for {N} targets")
        Q0 = np.clip(np.broadcast_to(Q0, (N, n)), chain.lower, chain.upper)
    P = None if params is None else robot._params(params, N)
    if P is not None and P.ndim == 2 and P.shape[0] != N:
        raise ConfigurationError(f"parameter batch has {P.shape[0]} rows for {N} targets")
    return Problem(Pt, Rt, single, Q0, P)


def solve_ik(robot, T, seed: int = 0, q0=None, mode: str = "auto", restarts: int = 8, rounds: int = 12,
             max_iter: int = 150, tol_position: float = 1e-6, tol_orientation: float = 1e-6,
             params=None) -> IKResult:
    """Inverse kinematics of ``robot`` for one target or a batch, in numpy (the fallback of
    :func:`kin.ik.solve_ik` when no C compiler works).

    Parameters
    ----------
    T : target pose (4, 4) or batch (N, 4, 4), base frame, SI; or a position (3,) / (N, 3).
    seed : seed of the random starts (same seed, same answer).
    q0 : initial guess (n,) or (N, n), tried first (e.g. the previous waypoint of a path).
    mode : ``"pose"`` (position and orientation), ``"position"``, or ``"auto"`` — pose for a
        chain that controls all six rows, position otherwise or when only a position is given.
    restarts : random starts (uniform within the limits) per round, besides ``q0``.
    rounds : rounds of fresh random starts for the targets not yet solved.
    tol_position, tol_orientation : success tolerances (m, rad).

    Returns :class:`IKResult`; among successful starts the one nearest ``q0`` (or, without q0,
    nearest the home configuration: zero clipped to the limits) is returned, otherwise the one
    with the smallest residual.
    """
    chain = robot.chain
    n = chain.n
    Pt, Rt, single, Q0, P = prepare(robot, T, q0, mode, params, tol_position, tol_orientation)
    P = chain.parameter_values if P is None else P
    N = len(Pt)
    rng = np.random.default_rng(seed)
    lo, hi = chain.lower, chain.upper
    scale = _length_scale(chain)
    solver = _LM(robot, P, scale, tol_position, tol_orientation, max_iter)

    # successful starts are ranked by their distance to q0, or to the home configuration
    ref = Q0 if Q0 is not None else np.broadcast_to(np.clip(0.0, lo, hi), (N, n))
    # until a start has a finite residual the answer is the reference: a defined configuration inside
    # the limits even for a target so far away that every residual overflows
    best_q = np.array(ref, dtype=float)
    best_ok = np.zeros(N, bool)
    best_dist = np.full(N, np.inf)
    best_resid = np.full(N, np.inf)
    best_pe, best_oe = np.full(N, np.inf), np.full(N, np.inf)
    for rnd in range(max(rounds, 1)):
        todo = np.nonzero(~best_ok)[0] if rnd else np.arange(N)
        if len(todo) == 0:
            break
        starts = [rng.uniform(lo, hi, size=(len(todo), n)) for _ in range(max(restarts, 1))]
        if rnd == 0 and Q0 is not None:
            starts.insert(0, Q0)
        K = len(starts)
        tgt = np.tile(todo, K)
        Q, pe, oe = solver.run(np.concatenate(starts), Pt[tgt], None if Rt is None else Rt[tgt], tgt)
        ok = (pe <= tol_position) & (oe <= tol_orientation) & chain.within_limits(Q, 1e-12)
        dist = np.linalg.norm(Q - ref[tgt], axis=1)
        resid = pe + oe * scale
        for k in range(K):  # keep the best start per target: success nearest ref, else smallest residual
            sl = slice(k * len(todo), (k + 1) * len(todo))
            t = todo
            better = np.where(ok[sl], ~best_ok[t] | (dist[sl] < best_dist[t]),
                              ~best_ok[t] & (resid[sl] < best_resid[t]))
            u = t[better]
            best_q[u] = Q[sl][better]
            best_ok[u] = ok[sl][better]
            best_dist[u] = dist[sl][better]
            best_resid[u] = resid[sl][better]
            best_pe[u], best_oe[u] = pe[sl][better], oe[sl][better]
    if single:
        return IKResult(bool(best_ok[0]), best_q[0], float(best_pe[0]), float(best_oe[0]))
    return IKResult(best_ok, best_q, best_pe, best_oe)


class _LM:
    """Batched Levenberg–Marquardt on many (start, target) pairs at once."""

    def __init__(self, robot, P, scale, tol_position, tol_orientation, max_iter):
        self.robot, self.P, self.scale, self.max_iter = robot, P, scale, max_iter
        # iterate well past the success tolerance: LM converges quadratically there, so it is cheap
        self.tol_cost = (min(tol_position, tol_orientation * scale) * 1e-4) ** 2

    def _eval(self, Q, tgt, want):
        P = self.P if self.P.ndim == 1 else self.P[tgt]
        return self.robot.evaluator.evaluate(Q, P, want)

    def _residual(self, Q, Pt, Rt, tgt):
        res = self._eval(Q, tgt, WANT_T | WANT_J)
        T, J = res["T"], res["J"]
        if Rt is None:
            return Pt - T[:, :3, 3], J[:, :3, :]
        e = np.concatenate([Pt - T[:, :3, 3], self.scale * rotation_error(Rt, T[:, :3, :3])], axis=1)
        J = J.copy()
        J[:, 3:, :] *= self.scale
        return e, J

    def run(self, Q, Pt, Rt, tgt):
        """Iterate from starts Q (M, n) towards targets; return (Q, position error, orientation error).

        A target so far away that its squared error overflows has an infinite cost: no step lowers
        it, so its start is returned unchanged, with its position error (finite below ~1.8e308 m).
        """
        with np.errstate(over="ignore", invalid="ignore", divide="ignore"):
            return self._run(Q, Pt, Rt, tgt)

    def _run(self, Q, Pt, Rt, tgt):
        chain = self.robot.chain
        lo, hi = chain.lower, chain.upper
        Q = Q.copy()
        e, J = self._residual(Q, Pt, Rt, tgt)
        cost = np.einsum("ij,ij->i", e, e)
        lam = np.full(len(Q), 1e-3)
        active = cost > self.tol_cost
        eye = np.eye(chain.n)
        for _ in range(self.max_iter):
            idx = np.nonzero(active)[0]
            if len(idx) == 0:
                break
            Ja, ea = J[idx], e[idx]
            JtJ = np.einsum("kri,krj->kij", Ja, Ja)
            g = np.einsum("kri,kr->ki", Ja, ea)
            diag = np.einsum("kii->ki", JtJ)
            A = JtJ + lam[idx, None, None] * (diag[:, :, None] * eye + 1e-6 * eye)
            dq = np.linalg.solve(A, g[..., None])[..., 0]
            Qn = np.clip(Q[idx] + dq, lo, hi)
            en, Jn = self._residual(Qn, Pt[idx], None if Rt is None else Rt[idx], tgt[idx])
            cn = np.einsum("ij,ij->i", en, en)
            better = cn < cost[idx]
            b, w = idx[better], idx[~better]
            Q[b], e[b], J[b], cost[b] = Qn[better], en[better], Jn[better], cn[better]
            lam[b] = np.maximum(lam[b] / 3.0, 1e-9)
            lam[w] *= 6.0
            active &= ~((lam > 1e8) | (cost < self.tol_cost))
        T = self._eval(Q, tgt, WANT_T)["T"]
        pe = _row_norms(Pt - T[:, :3, 3])
        oe = np.zeros(len(Q)) if Rt is None else np.linalg.norm(rotation_error(Rt, T[:, :3, :3]), axis=1)
        return Q, pe, oe


def _row_norms(E: np.ndarray) -> np.ndarray:
    """Euclidean norms of the rows of E (M, k), as ``np.linalg.norm(E, axis=1)``; rows whose squares
    overflow (entries beyond ~1e154) are scaled first, so that a finite row has its finite norm."""
    with np.errstate(over="ignore"):
        r = np.linalg.norm(E, axis=1)
        big = np.isinf(r) & np.isfinite(E).all(axis=1)
        if big.any():
            m = np.abs(E[big]).max(axis=1)
            r[big] = m * np.linalg.norm(E[big] / m[:, None], axis=1)
    return r


def _length_scale(chain) -> float:
    """A length (m) that weighs orientation errors against position errors: half the reach."""
    tab = chain.dh_table()
    reach = np.abs(tab[:, 0]).sum() + np.abs(tab[:, 2]).sum() + np.linalg.norm(chain.tool.matrix[:3, 3])
    return float(max(0.5 * reach, 0.05))


def local_ik(robot, T, q, mode: str = "auto", max_iter: int = 150, tol_position: float = 1e-6,
             tol_orientation: float = 1e-6, params=None) -> IKResult:
    """One Levenberg–Marquardt run per target from the warm start ``q`` (n,) or (N, n), no restarts
    (numpy; see :func:`kin.ik.local_ik`)."""
    Pt, Rt, single, Q0, P = prepare(robot, T, q, mode, params, tol_position, tol_orientation)
    if Q0 is None:
        raise ConfigurationError("local IK needs a warm start q")
    N = len(Pt)
    lm = _LM(robot, robot.chain.parameter_values if P is None else P, _length_scale(robot.chain), tol_position,
             tol_orientation, max_iter)
    Q, pe, oe = lm.run(Q0, Pt, Rt, np.arange(N))
    ok = (pe <= tol_position) & (oe <= tol_orientation)
    if single:
        return IKResult(bool(ok[0]), Q[0], float(pe[0]), float(oe[0]))
    return IKResult(ok, Q, pe, oe)
