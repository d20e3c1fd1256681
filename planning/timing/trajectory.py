"""The types the timing modules share: :class:`TimingError`, the geometric joint path being timed
(:class:`BlendedPath`, built by :func:`planning.timing.shaping.blend_path`) and the result
(:class:`TimedTrajectory`, built by :func:`planning.timing.parameterize.time_parameterize`).

SI units throughout: rad, rad/s, rad/s² for revolute joints, m, m/s, m/s² for prismatic ones.
"""
from __future__ import annotations

import math
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
        c0, c1, c2 = self._power
        x = np.clip(s - self.s0[p], 0.0, self.ell[p])[:, None]
        b, c = c1[p], c2[p]
        d2 = 2.0 * c
        d1 = b + d2 * x
        q = c0[p] + x * (b + c * x)
        return q, d1, d2

    def polyline(self, tolerance: float) -> np.ndarray:
        """Vertices (V, n) of a polyline through points of the path, in order, that stays within
        ``tolerance`` (rad or m, joint-space distance) of it: a quadratic piece with q″ = 2·c2 lies within
        |c2|·Δ²/4 of its chord over any parameter step Δ, so every piece is cut into equal steps with
        |c2|·Δ² ≤ 4·tolerance.  The form a path check (:func:`planning.validate.check_path`) takes."""
        if not (isinstance(tolerance, (int, float, np.floating)) and math.isfinite(tolerance) and tolerance > 0):
            raise TimingError(f"tolerance = {tolerance!r} must be a positive finite distance (rad or m)")
        if not len(self.ell):
            return self.waypoints[:1].copy()
        c2 = np.linalg.norm(self._power[2], axis=1)
        steps = np.maximum(1, np.ceil(self.ell * np.sqrt(c2 / (4.0 * tolerance)) - 1e-12)).astype(int)
        if int(steps.sum()) > 10_000_000:
            raise TimingError(f"tolerance = {tolerance:g} needs {int(steps.sum())} polyline vertices; at most 10000000")
        piece = np.repeat(np.arange(len(self.ell)), steps)
        k = np.arange(len(piece)) - np.repeat(np.cumsum(steps) - steps, steps)
        s = self.s0[piece] + self.ell[piece] * k / steps[piece]
        q = self.evaluate(s, piece)[0]
        return np.vstack([q, self.evaluate([self.length], [len(self.ell) - 1])[0]])

    @property
    def _power(self) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
        """Power-basis coefficients of every piece in x = s − s0: q = c0 + c1·x + c2·x² (cached)."""
        key = (id(self.ctrl), self.ctrl.shape)
        if getattr(self, "_power_key", None) != key:
            P0, P1, P2 = self.ctrl[:, 0], self.ctrl[:, 1], self.ctrl[:, 2]
            ell = self.ell[:, None]
            self._power_cache = (P0.copy(), 2 * (P1 - P0) / ell, (P0 - 2 * P1 + P2) / ell ** 2)
            self._power_key = key
        return self._power_cache

    def joint_range(self) -> tuple[np.ndarray, np.ndarray]:
        """Exact smallest and largest value (n,) each of every joint along the whole path (the ends of
        every piece and the vertex of every quadratic)."""
        if not len(self.ell):
            return self.waypoints[0].copy(), self.waypoints[0].copy()
        P0, P1, P2 = self.ctrl[:, 0], self.ctrl[:, 1], self.ctrl[:, 2]
        den = P0 - 2 * P1 + P2
        with np.errstate(divide="ignore", invalid="ignore"):
            u = np.where(np.abs(den) > 1e-300, (P0 - P1) / np.where(den == 0, 1.0, den), 0.0)
        u = np.clip(u, 0.0, 1.0)
        vert = (1 - u) ** 2 * P0 + 2 * u * (1 - u) * P1 + u ** 2 * P2
        allv = np.concatenate([P0, P2, vert])
        return allv.min(axis=0), allv.max(axis=0)

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
