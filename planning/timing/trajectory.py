"""The types the timing modules share: :class:`TimingError`, the geometric joint path being timed
(:class:`BlendedPath`, built by :func:`planning.timing.shaping.blend_path`) and the result
(:class:`TimedTrajectory`, built by :func:`planning.timing.parameterize.time_parameterize`).

SI units throughout: rad, rad/s, rad/s² for revolute joints, m, m/s, m/s² for prismatic ones.
"""
from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from kin.errors import RmtError

__all__ = ["TimingError", "BlendedPath", "TimedTrajectory"]


class TimingError(RmtError, ValueError):
    """A time-parameterisation request is invalid (bad path, limits or grid) or the QP failed."""


@dataclass
class BlendedPath:
    """A joint path made of quadratic Bézier pieces (straight pieces are Béziers with their midpoint
    as control point), parameterised by s ∈ [0, length].

    ``ctrl`` (m, 3, n): control points P0, P1, P2 of each piece; ``s0`` (m,), ``ell`` (m,): start and
    parameter length of each piece (q(s) = B((s − s0)/ℓ)); ``stops``: s values where q′ jumps (unblended
    corners, the trajectory stops there); ``max_deviation``: an upper bound of the joint-space distance
    between an input waypoint and the path; ``waypoints``: the waypoints kept (after thinning).
    """

    ctrl: np.ndarray
    s0: np.ndarray
    ell: np.ndarray
    stops: np.ndarray
    max_deviation: float
    waypoints: np.ndarray

    @property
    def length(self) -> float:
        return float(self.s0[-1] + self.ell[-1]) if len(self.ell) else 0.0

    @property
    def n(self) -> int:
        return self.waypoints.shape[1]

    def piece_of(self, s: np.ndarray, side: str = "right") -> np.ndarray:
        """Index of the piece holding each s (at a boundary: the piece to the right, or left)."""
        s = np.asarray(s, dtype=float)
        if side == "right":
            idx = np.searchsorted(self.s0, s, side="right") - 1
        else:
            idx = np.searchsorted(self.s0 + self.ell, s, side="left")
        return np.clip(idx, 0, len(self.ell) - 1)

    def evaluate(self, s, piece: np.ndarray | None = None) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
        """q (K, n), q′ (K, n), q″ (K, n) at parameters s (K,), on the given pieces (default: the piece
        to the right of each s)."""
        s = np.atleast_1d(np.asarray(s, dtype=float))
        p = self.piece_of(s) if piece is None else np.asarray(piece)
        ell = self.ell[p][:, None]
        u = np.clip((s - self.s0[p]) / self.ell[p], 0.0, 1.0)[:, None]
        P0, P1, P2 = self.ctrl[p, 0], self.ctrl[p, 1], self.ctrl[p, 2]
        q = (1 - u) ** 2 * P0 + 2 * u * (1 - u) * P1 + u ** 2 * P2
        d1 = 2 * ((1 - u) * (P1 - P0) + u * (P2 - P1)) / ell
        d2 = np.broadcast_to(2 * (P0 - 2 * P1 + P2) / ell ** 2, q.shape).copy()
        return q, d1, d2

# ---- the timed trajectory ----------------------------------------------------------------------------
@dataclass
class TimedTrajectory:
    """A time-parameterised joint path (SI).

    ``t`` (K,) s; ``q``, ``qd``, ``qdd`` (K, n) at the grid points (``qdd`` with the s̈ of the interval
    that starts there; the last row with the last interval's); ``s`` (K,), ``sd`` (K,) = ṡ, ``sdd``
    (K,) = s̈; ``duration`` s; ``max_velocity_ratio`` / ``max_acceleration_ratio``: max over samples
    and joints of |q̇_j|/v_j and |q̈_j|/A_j; ``path``: the geometric path (for :meth:`sample`);
    ``scale``: the feasibility factor c applied to the solver's b (1 − c ≈ rounding or the QP's
    tolerance); ``grid``: the grid in s; ``method``: the solver (``"reach"`` or ``"qp"``);
    ``overshoot``: the largest relative excess over the speed or acceleration limits found by the
    dense re-check between samples (0 when none; :func:`planning.timing.limits.dense_ratios`);
    ``j_max``: the jerk limits imposed (None: none) and ``max_jerk_ratio`` the largest
    |Δq̈_j|/(Δt·j_max_j) between consecutive grid points (see :mod:`planning.timing.jerk`).
    ``tau`` (K, n): the joint torques (N·m or N, inverse dynamics of q, q̇, q̈) at the samples when a
    robot was given (else None); ``tau_max`` the torque limits imposed (inf: that joint unlimited;
    None: none); ``max_torque_ratio`` the largest |τ_j|/τmax_j of the dense re-check between samples
    and ``torque_rounds`` the re-solves it took (see :mod:`planning.timing.torque`).
    """

    t: np.ndarray
    q: np.ndarray
    qd: np.ndarray
    qdd: np.ndarray
    s: np.ndarray
    sd: np.ndarray
    sdd: np.ndarray
    duration: float
    max_velocity_ratio: float
    max_acceleration_ratio: float
    path: BlendedPath
    v_max: np.ndarray
    a_max: np.ndarray
    qp_status: str = ""
    scale: float = 1.0
    grid: np.ndarray | None = None
    method: str = "reach"
    overshoot: float = 0.0
    j_max: np.ndarray | None = None
    max_jerk_ratio: float | None = None
    tau: np.ndarray | None = None
    tau_max: np.ndarray | None = None
    max_torque_ratio: float | None = None
    torque_rounds: int = 0

    def sample(self, times) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
        """q, q̇, q̈ (T, n) at arbitrary times (clipped to [0, duration]), from the exact s(t) of the
        piecewise-constant s̈."""
        tau = np.clip(np.atleast_1d(np.asarray(times, dtype=float)), self.t[0], self.t[-1])
        if len(self.t) == 1:
            z = np.zeros((len(tau), self.q.shape[1]))
            return np.repeat(self.q, len(tau), axis=0), z, z.copy()
        i = np.clip(np.searchsorted(self.t, tau, side="right") - 1, 0, len(self.t) - 2)
        h = tau - self.t[i]
        a = self.sdd[i]
        s = np.minimum(self.s[i] + self.sd[i] * h + 0.5 * a * h * h, self.s[i + 1])
        sd = np.maximum(self.sd[i] + a * h, 0.0)
        piece = self.path.piece_of(0.5 * (self.s[i] + self.s[i + 1]))   # the interval's own piece
        q, d1, d2 = self.path.evaluate(s, piece)
        return q, d1 * sd[:, None], d1 * a[:, None] + d2 * (sd ** 2)[:, None]
