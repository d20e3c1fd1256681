"""The naive method the path follower (:func:`planning.follow.follow_path`) is compared with.

:func:`resolved_rate` is open-loop resolved-rate control q_{k+1} = q_k + J⁻¹·ẋ_des·Δt, with
``np.linalg.solve`` — and, where ``solve`` raises because J is exactly singular, the pseudo-inverse
(``np.linalg.pinv``), recorded per step together with the condition number of J.  It tracks the
same task as the follower in the same ``mode`` (pose, tool axis or position), so the two can be
compared on any path.
"""
from __future__ import annotations

import math
from collections.abc import Callable
from dataclasses import dataclass

import numpy as np

from planning.follow.inputs import _check_mode, _check_start, _path_arrays
from planning.follow.tracking import _log_rot, tracking_errors

__all__ = ["resolved_rate", "ResolvedRateResult"]


@dataclass
class ResolvedRateResult:
    """Result of :func:`resolved_rate` (SI units); arrays as in
    :class:`~planning.follow.result.FollowResult`.

    ``condition`` (N−1,): condition number of the task Jacobian at each step (inf when exactly
    singular); ``pinv_steps``: steps where ``np.linalg.solve`` raised (J exactly singular, or not
    square) and the pseudo-inverse was used; ``diverged_at``: first row whose configuration is not
    finite (None when all are); rows from there on are NaN.  ``axis_error`` (N,) rad: the angle
    between the achieved and target tool z axes; ``mode``: the task tracked.
    """

    t: np.ndarray
    q: np.ndarray
    position_error: np.ndarray
    orientation_error: np.ndarray
    joint_velocity: np.ndarray
    joint_speed: np.ndarray
    condition: np.ndarray
    pinv_steps: list[int]
    diverged_at: int | None
    method: str
    axis_error: np.ndarray | None = None
    mode: str = "pose"

    @property
    def peak_joint_speed(self) -> float:
        return float(np.nanmax(self.joint_speed)) if np.isfinite(self.joint_speed).any() else math.inf

    @property
    def max_tracking_error(self) -> float:
        return float(np.nanmax(self.position_error))

    @property
    def max_orientation_error(self) -> float:
        """Largest orientation error the mode tracks (rad): full angle (pose), tool-axis angle (axis),
        NaN for position mode (not tracked)."""
        if self.mode == "pose":
            return float(np.nanmax(self.orientation_error))
        if self.mode == "axis" and self.axis_error is not None:
            return float(np.nanmax(self.axis_error))
        return math.nan

    def summary(self) -> dict:
        finite = self.condition[np.isfinite(self.condition)]
        return {"method": self.method, "mode": self.mode, "waypoints": int(len(self.t)),
                "peak_joint_speed": self.peak_joint_speed, "max_position_error_m": self.max_tracking_error,
                "max_orientation_error_rad": float(np.nanmax(self.orientation_error)),
                "max_axis_error_rad": None if self.axis_error is None else float(np.nanmax(self.axis_error)),
                "pinv_steps": len(self.pinv_steps), "first_pinv_steps": self.pinv_steps[:5],
                "max_finite_condition": float(finite.max()) if finite.size else None,
                "singular_steps": int((~np.isfinite(self.condition)).sum()), "diverged_at": self.diverged_at}


def resolved_rate(robot, path, q0, dt: float | None = None,
                  jacobian: Callable[[np.ndarray], np.ndarray] | None = None, mode: str = "pose"
                  ) -> ResolvedRateResult:
    """Open-loop resolved-rate control: q_{k+1} = q_k + J(q_k)⁻¹·ẋ_des,k·Δt, no feedback, no limits.

    ẋ_des,k = [p*_{k+1} − p*_k; log(R*_{k+1}·R*_kᵀ)]/Δt (base frame).  ``mode`` picks the task rows
    as the follower's does: ``"pose"`` all six; ``"axis"`` the position rows and the two rotation
    rows perpendicular to the current tool z axis (E·Rᵀ: rotation about the tool axis is free);
    ``"position"`` the position rows.  J⁻¹·ẋ is computed with ``np.linalg.solve``; where it raises
    ``LinAlgError`` (J exactly singular in floating point) the pseudo-inverse ``np.linalg.pinv(J)·ẋ``
    (minimum-norm least squares) is used and the step is listed in ``pinv_steps``.  A task Jacobian
    that is not square (as many rows as joints) always uses the pseudo-inverse.  The condition
    number of the task Jacobian is recorded at every step.  ``jacobian(q) -> (6, n)`` replaces the
    robot's geometric Jacobian (to reproduce a method with a different one).  Joint limits are not
    enforced: this is the textbook method, with none of the follower's safeguards.
    """
    _check_mode(mode)
    poses, t = _path_arrays(path, dt, mode)
    q = _check_start(robot, q0)
    jac = jacobian or robot.jacobian
    E = np.eye(3)[:2]
    N, n = len(poses), robot.n
    Q = np.full((N, n), np.nan)
    Q[0] = q
    cond = np.full(N - 1, np.nan)
    pinv_steps: list[int] = []
    diverged = None
    for k in range(N - 1):
        dx = np.empty(6)
        dx[:3] = poses[k + 1, :3, 3] - poses[k, :3, 3]
        dx[3:] = _log_rot(poses[k + 1, :3, :3], poses[k, :3, :3])
        J = np.asarray(jac(q), dtype=float)
        if mode == "position":
            J, dx = J[:3], dx[:3]
        elif mode == "axis":
            S = E @ robot.fk(q)[:3, :3].T          # rotation rows perpendicular to the tool z axis
            J, dx = np.vstack([J[:3], S @ J[3:]]), np.r_[dx[:3], S @ dx[3:]]
        with np.errstate(all="ignore"):
            # inf when J is exactly singular (σ_min = 0)
            cond[k] = np.linalg.cond(J) if np.all(np.isfinite(J)) else np.nan
        try:
            if J.shape[1] != J.shape[0]:
                raise np.linalg.LinAlgError("not square")
            dq = np.linalg.solve(J, dx)
        except np.linalg.LinAlgError:
            dq = np.linalg.pinv(J) @ dx
            pinv_steps.append(k)
        q = q + dq
        if not np.all(np.isfinite(q)):
            diverged = k + 1
            break
        Q[k + 1] = q
    pe, oe, ae = tracking_errors(robot, Q, poses)
    vel = np.full_like(Q, np.nan)
    vel[0] = 0.0
    vel[1:] = np.diff(Q, axis=0) / np.diff(t)[:, None]
    return ResolvedRateResult(t=t, q=Q, position_error=pe, orientation_error=oe, joint_velocity=vel,
                              joint_speed=np.abs(vel), condition=cond, pinv_steps=pinv_steps, diverged_at=diverged,
                              method="q += solve(J, ẋ·Δt); pinv where solve raises (J exactly singular)",
                              axis_error=ae, mode=mode)
