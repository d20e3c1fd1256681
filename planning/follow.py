"""Singularity-robust path following: one OSQP quadratic program per step.

A tool path is a sequence of target poses T*_k (N, 4, 4) at times t_k.  From a start configuration
q_0 the follower chooses, at every step k → k+1 (Δt = t_{k+1} − t_k), a joint velocity q̇ (n,) held
over the step (q_{k+1} = q_k + q̇·Δt) by solving

    minimise    ‖S·(J·q̇ − ẋ_ref)‖² + q̇ᵀ·Λ·q̇
    subject to  max(lo − q_k, −v_max·Δt) ≤ q̇·Δt ≤ min(hi − q_k, v_max·Δt)       joint + speed limits
                ∇d_w(q_k)·q̇·Δt ≥ −γ·(d_w(q_k) − m_w)                for every window w (barrier)

* J (6, n) is the geometric Jacobian at q_k (rows vx vy vz ωx ωy ωz, base frame, tool point).
* ẋ_ref = ẋ_des + K·e_k/Δt: the feed-forward twist of the path, ẋ_des = [p*_{k+1} − p*_k;
  log(R*_{k+1}·R*_kᵀ)]/Δt, plus a feedback term on the tracking error e_k = [p*_k − p(q_k);
  log(R*_k·R(q_k)ᵀ)] (K = ``feedback``, the fraction of the error removed per step), so that errors do
  not drift as they would with the feed-forward term alone.
* S (m, 6) selects and weights the task (``mode``):
  ``"pose"``      S = diag(w_p·I₃, w_o·I₃): position and full orientation (6 DOF);
  ``"axis"``      position and the direction of the tool z axis (5 DOF): the orientation rows are
                  E·Rᵀ with E = the first two rows of I₃ — rotation about the tool's own z axis (a
                  pen's or a spindle's axis) is free, and the orientation error is the angle between
                  the tool z axis and its target;
  ``"position"``  S = w_p·I₃: the tool point only (3 DOF).
  ``weights = (w_p, w_o)`` put metres and radians on one scale (w_o is a length, m/rad).
* Λ is singular-value-filtered damping (Maciejewski–Klein / Chiaverini): with the SVD S·J = U·Σ·Vᵀ,
  Λ = λ_min·I + Σ_i λ_i·v_i·v_iᵀ with λ_i = λ_max·(1 − (σ_i/σ₀)²) for σ_i < σ₀ (and for the
  directions J cannot move at all), 0 otherwise.  Well-conditioned directions are tracked without
  lag; a direction whose singular value goes to zero gets a bounded gain σ/(σ² + λ) ≤ 1/(2√λ)
  instead of 1/σ — the joint speeds stay finite at and near a singularity.  ``damping`` = λ_max
  (m²/rad² with the default weights), ``singular_value_threshold`` = σ₀.
* The windows of :mod:`planning.windows` are kept with a discrete barrier on each window's signed
  margin d_w (> 0 outside; joint distance for an interval window, |g| − ε for a predicate window,
  linearised as sign(g)·∇g): d_w(q_{k+1}) − m_w ≥ (1 − γ)·(d_w(q_k) − m_w), γ = Δt/τ
  (``barrier_time`` = τ).  Outside a window this only bites when the configuration approaches it
  (it may approach at most at the rate (d − m)/τ and stops a buffer m_w short of the boundary);
  inside a window the same inequality asks the follower to climb out at that rate.
  m_w = ``window_buffer`` × the window's half-width (interval) or × ε (predicate).

Entering a window only when the path forces it.  Two tests decide when a barrier is dropped:

* inside a window (or its buffer), a probe QP over a joint displacement Δ (same P, same sparsity:
  minimise ‖S·(J·Δ − e_next)‖² + ΔᵀΛΔ within the joint limits, with d_w + ∇d_w·Δ ≥ m_w) asks
  whether some configuration outside the window still meets the next target within ``window_slack``
  × ``tolerance`` (linearised).  If not, the path forces the window and its barrier is dropped for
  this step — the follower does not push out, in vain, step after step; if so, the barrier pushes
  the configuration out;
* the step's QP is then solved with the remaining barriers (stage 1).  It is accepted when it is
  solved and its predicted tracking error after the step, e_k + ẋ_des·Δt − J·q̇·Δt, stays within
  ``window_slack`` × ``tolerance``, or when no barrier is active.  Otherwise keeping out of a window
  would cost more tracking than that, and the step is solved again without the active barriers
  (stage 2): the path forces the follower into the window.

Steps where a barrier was dropped are marked in ``FollowResult.forced``.

Everything is set up once: the sparsity of P (upper triangle, dense n×n) and of A (identity rows for
the joints, one row per window with its joints' entries) is fixed, and every step only ``update``s
P, q, A, l and u of the same OSQP object (warm started).  Polishing is off (OSQP prints a line on
stdout when there is nothing to polish); the solver runs to tight tolerances (1e-9) on joint
velocities (rad/s or m/s), and the solution is projected onto the joint box so that joint and speed
limits hold exactly.

Default joint-speed limit when the robot file gives none (``Joint.max_velocity`` is None):
:data:`DEFAULT_V_MAX_REVOLUTE` = π rad/s (180°/s, the speed of a UR arm's base joints) and
:data:`DEFAULT_V_MAX_PRISMATIC` = 0.5 m/s.

:func:`resolved_rate` is the naive method the follower is compared with: open-loop resolved-rate
control q_{k+1} = q_k + J⁻¹·ẋ_des·Δt, with ``np.linalg.solve`` — and, where ``solve`` raises because
J is exactly singular, the pseudo-inverse (``np.linalg.pinv``), recorded per step together with the
condition number of J.
"""
from __future__ import annotations

import math
from collections import Counter
from collections.abc import Callable, Sequence
from dataclasses import dataclass, field

import numpy as np
import osqp
import scipy.sparse as sps
import sympy as sp

from kin.errors import ConfigurationError
from kin.transforms import rotation_error

from .errors import PlanningError
from .windows import Window, WindowSet

__all__ = ["follow_path", "resolved_rate", "FollowResult", "ResolvedRateResult", "FollowError", "MODES",
           "DEFAULT_V_MAX_REVOLUTE", "DEFAULT_V_MAX_PRISMATIC", "joint_velocity_limits", "window_ranges",
           "tracking_errors"]

MODES = ("pose", "axis", "position")
DEFAULT_V_MAX_REVOLUTE = math.pi     # rad/s, used when a revolute joint has no max_velocity
DEFAULT_V_MAX_PRISMATIC = 0.5        # m/s, used when a prismatic joint has no max_velocity
LAMBDA_MIN = 1e-9                    # always-on regularisation: P stays positive definite
OSQP_SETTINGS = dict(verbose=False, eps_abs=1e-9, eps_rel=1e-9, eps_prim_inf=1e-7, eps_dual_inf=1e-7,
                     max_iter=20000, polishing=False, warm_starting=True, adaptive_rho=True)
_OK = ("solved", "solved inaccurate")


class FollowError(PlanningError, ValueError):
    """A path-following request is invalid (bad path, start, limits or settings)."""


# ---- results ---------------------------------------------------------------------------------------
@dataclass
class FollowResult:
    """Result of :func:`follow_path` (SI units).

    Arrays have one row per waypoint: ``q`` (N, n); ``t`` (N,) s; ``position_error`` (N,) m;
    ``orientation_error`` (N,) rad — the full rotation angle between achieved and target orientation;
    ``axis_error`` (N,) rad — the angle between the achieved and target tool z axes;
    ``joint_velocity`` (N, n) — (q_k − q_{k−1})/Δt (row 0 is zero), ``joint_speed`` its magnitude;
    ``in_window`` (N,) — index of the first window q_k is inside, −1 for none; ``forced`` (N,) —
    True where the step that ended at row k had to drop a window barrier (stage 2); ``sigma_min``
    (N,) — smallest singular value of the robot's task Jacobian.
    """

    mode: str
    t: np.ndarray
    q: np.ndarray
    position_error: np.ndarray
    orientation_error: np.ndarray
    axis_error: np.ndarray
    joint_velocity: np.ndarray
    joint_speed: np.ndarray
    in_window: np.ndarray
    forced: np.ndarray
    sigma_min: np.ndarray
    v_max: np.ndarray
    tolerance: tuple[float, float]
    qp_status: dict[str, int] = field(default_factory=dict)
    window_names: list[str] = field(default_factory=list)

    @property
    def peak_joint_speed(self) -> float:
        """Largest joint speed over the path (rad/s or m/s)."""
        return float(self.joint_speed.max()) if self.joint_speed.size else 0.0

    @property
    def max_tracking_error(self) -> float:
        """Largest position error (m)."""
        return float(self.position_error.max())

    @property
    def max_orientation_error(self) -> float:
        """Largest orientation error the mode tracks (rad): full angle (pose), tool-axis angle (axis),
        NaN for position mode (not tracked)."""
        if self.mode == "pose":
            return float(self.orientation_error.max())
        if self.mode == "axis":
            return float(self.axis_error.max())
        return math.nan

    @property
    def within_tolerance(self) -> bool:
        """Position error ≤ tolerance[0] at every waypoint and, unless position mode, the tracked
        orientation error ≤ tolerance[1]."""
        ok = self.max_tracking_error <= self.tolerance[0]
        return bool(ok and (self.mode == "position" or self.max_orientation_error <= self.tolerance[1]))

    @property
    def speed_ratio(self) -> float:
        """max_k,j |q̇_kj| / v_max_j (≤ 1 when the speed limits hold)."""
        return float((self.joint_speed / self.v_max[None, :]).max()) if self.joint_speed.size else 0.0

    def window_ranges(self) -> list[dict]:
        """Waypoint ranges inside each window: [{"window", "name", "ranges": [[first, last], ...],
        "waypoints"}] for the windows that were entered."""
        return window_ranges(self.in_window, self.window_names)

    def summary(self) -> dict:
        """Scalars and window ranges (JSON-friendly; NaN stays NaN)."""
        return {"mode": self.mode, "waypoints": int(len(self.t)), "duration_s": float(self.t[-1] - self.t[0]),
                "peak_joint_speed": self.peak_joint_speed, "speed_ratio": self.speed_ratio,
                "max_position_error_m": self.max_tracking_error,
                "max_orientation_error_rad": float(self.orientation_error.max()),
                "max_axis_error_rad": float(self.axis_error.max()),
                "tolerance": {"position_m": self.tolerance[0], "orientation_rad": self.tolerance[1]},
                "within_tolerance": self.within_tolerance, "forced_steps": int(self.forced.sum()),
                "min_sigma": float(self.sigma_min.min()), "qp_status": dict(self.qp_status),
                "windows_entered": self.window_ranges()}


@dataclass
class ResolvedRateResult:
    """Result of :func:`resolved_rate` (SI units); arrays as in :class:`FollowResult`.

    ``condition`` (N−1,): condition number of J at each step (inf when exactly singular);
    ``pinv_steps``: steps where ``np.linalg.solve`` raised (J exactly singular) and the
    pseudo-inverse was used; ``diverged_at``: first row whose configuration is not finite (None when
    all are); rows from there on are NaN.
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

    @property
    def peak_joint_speed(self) -> float:
        return float(np.nanmax(self.joint_speed)) if np.isfinite(self.joint_speed).any() else math.inf

    @property
    def max_tracking_error(self) -> float:
        return float(np.nanmax(self.position_error))

    @property
    def max_orientation_error(self) -> float:
        return float(np.nanmax(self.orientation_error))

    def summary(self) -> dict:
        finite = self.condition[np.isfinite(self.condition)]
        return {"method": self.method, "waypoints": int(len(self.t)),
                "peak_joint_speed": self.peak_joint_speed, "max_position_error_m": self.max_tracking_error,
                "max_orientation_error_rad": self.max_orientation_error,
                "pinv_steps": len(self.pinv_steps), "first_pinv_steps": self.pinv_steps[:5],
                "max_finite_condition": float(finite.max()) if finite.size else None,
                "singular_steps": int((~np.isfinite(self.condition)).sum()), "diverged_at": self.diverged_at}


# ---- helpers ---------------------------------------------------------------------------------------
def joint_velocity_limits(robot, v_max=None) -> np.ndarray:
    """Per-joint speed limits (n,), SI.  ``v_max``: None (the robot file's ``max_velocity``, or the
    defaults :data:`DEFAULT_V_MAX_REVOLUTE` / :data:`DEFAULT_V_MAX_PRISMATIC` where it gives none),
    a scalar for every joint, or an array (n,)."""
    n = robot.n
    if v_max is None:
        return np.array([j.max_velocity if j.max_velocity is not None else
                         (DEFAULT_V_MAX_REVOLUTE if j.is_revolute else DEFAULT_V_MAX_PRISMATIC)
                         for j in robot.chain.joints], dtype=float)
    v = np.broadcast_to(np.asarray(v_max, dtype=float), (n,)) if np.ndim(v_max) == 0 else np.asarray(v_max, float)
    if v.shape != (n,) or not np.all(np.isfinite(v)) or not np.all(v > 0):
        raise FollowError(f"v_max {v_max!r} must be a positive finite number or {n} of them (rad/s, m/s)")
    return v.astype(float).copy()


def window_ranges(in_window: np.ndarray, names: Sequence[str] = ()) -> list[dict]:
    """Contiguous waypoint ranges [first, last] (inclusive) of each window index in ``in_window``."""
    out = []
    for w in sorted(set(int(x) for x in np.unique(in_window)) - {-1}):
        idx = np.flatnonzero(in_window == w)
        breaks = np.flatnonzero(np.diff(idx) > 1)
        starts = np.r_[idx[0], idx[breaks + 1]]
        ends = np.r_[idx[breaks], idx[-1]]
        out.append({"window": w, "name": names[w] if w < len(names) else str(w),
                    "ranges": [[int(a), int(b)] for a, b in zip(starts, ends)], "waypoints": int(len(idx))})
    return out


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


def _path_arrays(path, dt: float | None, mode: str) -> tuple[np.ndarray, np.ndarray]:
    """(poses (N, 4, 4), times (N,)) from an array of poses (or positions in position mode), a
    ``(poses, times)`` pair, or an object with ``poses`` and ``times`` attributes."""
    times = None
    if hasattr(path, "poses"):
        poses = path.poses
        times = getattr(path, "times", None)
        if times is None:
            times = getattr(path, "t", None)
    elif isinstance(path, tuple) and len(path) == 2:
        poses, times = path
    else:
        poses = path
    P = np.asarray(poses, dtype=float)
    if P.ndim == 2 and P.shape[1] == 3:
        if mode != "position":
            raise FollowError(f"a path of positions (N, 3) can only be followed in mode 'position', not {mode!r}")
        T = np.tile(np.eye(4), (len(P), 1, 1))
        T[:, :3, 3] = P
        P = T
    if P.ndim != 3 or P.shape[1:] != (4, 4) or len(P) < 2:
        raise FollowError(f"path poses have shape {np.shape(poses)}; expected (N, 4, 4) with N ≥ 2 "
                          "(or positions (N, 3) in position mode)")
    if not np.all(np.isfinite(P)):
        raise FollowError("path poses hold NaN or infinite values")
    if times is None:
        if dt is None or not (math.isfinite(dt) and dt > 0):
            raise FollowError(f"dt = {dt!r}: a path without times needs a positive finite step dt (s)")
        t = np.arange(len(P)) * float(dt)
    else:
        t = np.asarray(times, dtype=float)
        if t.shape != (len(P),) or not np.all(np.isfinite(t)) or not np.all(np.diff(t) > 0):
            raise FollowError(f"path times have shape {t.shape} for {len(P)} poses; they must be finite and "
                              "strictly increasing (s)")
    return P, t


class _Barrier:
    """Signed margin d(q) of one window (> 0 outside) with its gradient, and the buffer m."""

    def __init__(self, w: Window, n: int, buffer: float):
        self.window = w
        self.empty = False
        if w.is_interval:
            self.joints = [w.joint]
            self.ivs = np.array(w.intervals, dtype=float).reshape(-1, 2)
            self.empty = len(self.ivs) == 0
            self.m = buffer * w.width
        else:
            self.joints = [j - 1 for j in w.joints]
            self.empty = w.epsilon is None or w.epsilon < 0
            self.m = buffer * max(w.epsilon or 0.0, 0.0)
            q = sp.symbols(f"q1:{n + 1}", real=True)
            expr = sp.sympify(w.expr, locals={f"q{i + 1}": q[i] for i in range(n)})
            self._g = sp.lambdify([q], expr, modules="math")
            grads = [sp.diff(expr, q[j]) for j in self.joints]
            self._dg = sp.lambdify([q], grads, modules="math")

    def __call__(self, q: np.ndarray) -> tuple[float, np.ndarray]:
        """(d, ∂d/∂q over ``self.joints``)."""
        if self.empty:
            return math.inf, np.zeros(len(self.joints))
        if self.window.is_interval:
            x = q[self.joints[0]]
            lo, hi = self.ivs[:, 0], self.ivs[:, 1]
            d_each = np.maximum(lo - x, x - hi)
            i = int(np.argmin(d_each))
            # the nearer edge of the interval decides the direction (outwards when inside)
            sgn = -1.0 if (lo[i] - x) > (x - hi[i]) else 1.0
            return float(d_each[i]), np.array([sgn])
        ql = [float(v) for v in q]
        g = float(self._g(ql))
        dg = np.asarray(self._dg(ql), dtype=float)
        s = 1.0 if g >= 0 else -1.0
        return abs(g) - float(self.window.epsilon), s * dg


def _check_start(robot, q0) -> np.ndarray:
    q = np.asarray(q0, dtype=float)
    if q.shape != (robot.n,) or not np.all(np.isfinite(q)):
        raise ConfigurationError(f"q0 has shape {q.shape} or non-finite values; expected ({robot.n},) finite "
                                 f"for {robot.name}")
    robot.check_limits(q)
    return q.copy()


# ---- the follower ----------------------------------------------------------------------------------
def follow_path(robot, path, q0, windows: WindowSet | Sequence[Window] | None = None, *, mode: str = "pose",
                weights: tuple[float, float] = (1.0, 0.1), damping: float = 1e-3,
                singular_value_threshold: float = 0.02, feedback: float = 0.5, dt: float | None = None,
                v_max=None, tolerance: tuple[float, float] = (1e-3, math.radians(1.0)),
                window_slack: float = 0.1, barrier_time: float = 0.2, window_buffer: float = 0.05
                ) -> FollowResult:
    """Follow a tool path with one OSQP QP per step (see the module docstring for the formulation).

    Parameters
    ----------
    robot : kin.Robot
    path : (N, 4, 4) target poses (base frame, SI), optionally with times: a ``(poses, times)`` pair or
        an object with ``poses`` and ``times`` attributes (a ToolPath).  In position mode positions
        (N, 3) are accepted too.
    q0 : (n,) start configuration, inside the joint limits.  The path is followed from wherever
        fk(q0) is: the initial error is removed by the feedback term.
    windows : a :class:`~planning.windows.WindowSet` (or list of windows) to keep out of; None: none.
    mode : ``"pose"`` (6 DOF), ``"axis"`` (position + tool z axis, 5 DOF) or ``"position"`` (3 DOF).
    weights : (w_p, w_o) task weights: 1/m and m/rad·(1/m) — w_o is the length that equates 1 rad to
        w_o metres of position error.
    damping : λ_max of the singular-value-filtered damping (same units as ‖S·J‖²).
    singular_value_threshold : σ₀ below which a singular direction of S·J is damped.
    feedback : K in (0, 1], the fraction of the tracking error corrected per step.
    dt : step (s) when the path has no times.
    v_max : joint speed limits (None: the robot file's, else the documented defaults).
    tolerance : (position m, orientation rad) — used to accept window-respecting steps (× window_slack)
        and for :attr:`FollowResult.within_tolerance`.
    window_slack : fraction of the tolerance a window-respecting step may cost before the window is
        treated as forced by the path.
    barrier_time : τ (s) of the discrete window barrier.
    window_buffer : buffer m_w as a fraction of each window's half-width (or of ε).
    """
    if mode not in MODES:
        raise FollowError(f"mode {mode!r} unknown; allowed: {', '.join(MODES)}")
    poses, t = _path_arrays(path, dt, mode)
    q = _check_start(robot, q0)
    n = robot.n
    wp, wo = (float(x) for x in weights)
    checks = {"weights[0] (position)": (wp, wp > 0), "weights[1] (orientation)": (wo, wo >= 0),
              "damping": (damping, damping >= 0), "singular_value_threshold": (singular_value_threshold,
                                                                                singular_value_threshold > 0),
              "feedback": (feedback, 0 < feedback <= 1), "window_slack": (window_slack, window_slack > 0),
              "barrier_time": (barrier_time, barrier_time > 0), "window_buffer": (window_buffer, window_buffer >= 0),
              "tolerance[0] (m)": (tolerance[0], tolerance[0] > 0), "tolerance[1] (rad)": (tolerance[1],
                                                                                         tolerance[1] > 0)}
    for name, (value, ok) in checks.items():
        if not (math.isfinite(float(value)) and ok):
            raise FollowError(f"{name} = {value!r} is out of range (weights > 0 / ≥ 0, damping ≥ 0, threshold > 0, "
                              "0 < feedback ≤ 1, window_slack > 0, barrier_time > 0, window_buffer ≥ 0, "
                              "tolerances > 0)")
    vmax = joint_velocity_limits(robot, v_max)
    lo, hi = robot.chain.lower, robot.chain.upper
    wlist = list(windows.windows if isinstance(windows, WindowSet) else (windows or []))
    for w in wlist:
        if w.n != n:
            raise FollowError(f"window {w.name!r} is for a {w.n}-joint robot; {robot.name} has {n} joints")
    barriers = [_Barrier(w, n, window_buffer) for w in wlist]
    nw = len(barriers)

    # ---- fixed sparsity: P dense upper triangle, A = [I_n; one row per window over its joints]
    iu = np.triu_indices(n)
    order = np.lexsort((iu[0], iu[1]))                 # CSC order: by column, then row
    p_rows, p_cols = iu[0][order], iu[1][order]
    P0 = sps.csc_matrix((np.ones(len(p_rows)), (p_rows, p_cols)), shape=(n, n))
    a_r = list(range(n))
    a_c = list(range(n))
    for i, b in enumerate(barriers):
        for j in b.joints:
            a_r.append(n + i)
            a_c.append(j)
    a_r, a_c = np.array(a_r), np.array(a_c)
    A0 = sps.csc_matrix((np.ones(len(a_r)), (a_r, a_c)), shape=(n + nw, n))
    A0.sort_indices()
    # positions of our entries in the CSC data array (csc sorts by column, then row)
    a_order = np.lexsort((a_r, a_c))
    a_rows_csc, a_cols_csc = a_r[a_order], a_c[a_order]
    Adense = np.zeros((n + nw, n))
    Adense[np.arange(n), np.arange(n)] = 1.0
    solver = osqp.OSQP()
    solver.setup(P0, np.zeros(n), A0, -np.ones(n + nw), np.ones(n + nw), **OSQP_SETTINGS)

    N = len(poses)
    Q = np.empty((N, n))
    Q[0] = q
    forced = np.zeros(N, bool)
    status: Counter = Counter()
    tol_p, tol_o = float(tolerance[0]) * window_slack, float(tolerance[1]) * window_slack
    gamma_scale = 1.0 / barrier_time
    E = np.eye(3)[:2]

    for k in range(N - 1):
        h = t[k + 1] - t[k]
        T, J = robot.fk_jacobian(q)
        R = T[:3, :3]
        # feed-forward twist and tracking error (base frame)
        ff = np.empty(6)
        ff[:3] = (poses[k + 1, :3, 3] - poses[k, :3, 3]) / h
        ff[3:] = _log_rot(poses[k + 1, :3, :3], poses[k, :3, :3]) / h
        e = np.empty(6)
        e[:3] = poses[k, :3, 3] - T[:3, 3]
        if mode == "axis":
            z, zt = R[:, 2], poses[k, :3, 2]
            ax = np.cross(z, zt)
            s = np.linalg.norm(ax)
            ang = math.atan2(s, float(np.clip(z @ zt, -1.0, 1.0)))
            e[3:] = ax * (ang / s) if s > 1e-15 else (np.zeros(3) if ang < 1.0 else _any_perpendicular(z) * ang)
        else:
            e[3:] = _log_rot(poses[k, :3, :3], R)
        if mode == "pose":
            S = np.zeros((6, 6))
            S[:3, :3] = wp * np.eye(3)
            S[3:, 3:] = wo * np.eye(3)
        elif mode == "axis":
            S = np.zeros((5, 6))
            S[:3, :3] = wp * np.eye(3)
            S[3:, 3:] = wo * (E @ R.T)
        else:
            S = np.zeros((3, 6))
            S[:, :3] = wp * np.eye(3)
        xref = ff + feedback * e / h
        SJ = S @ J
        # singular-value-filtered damping over all n right singular directions
        _, sig, Vt = np.linalg.svd(SJ, full_matrices=True)
        sig_full = np.zeros(n)
        sig_full[:min(len(sig), n)] = sig[:n]
        lam = np.where(sig_full < singular_value_threshold,
                       damping * (1.0 - (sig_full / singular_value_threshold) ** 2), 0.0)
        Pm = SJ.T @ SJ + (Vt.T * lam) @ Vt + LAMBDA_MIN * np.eye(n)
        qlin = -(SJ.T @ (S @ xref))
        # joint box (velocity units)
        lb = np.maximum((lo - q) / h, -vmax)
        ub = np.minimum((hi - q) / h, vmax)
        lb = np.minimum(lb, 0.0)   # q inside its limits: 0 is always feasible
        ub = np.maximum(ub, 0.0)
        l = np.empty(n + nw)
        u = np.full(n + nw, np.inf)
        l[:n], u[:n] = lb, ub
        dval = np.full(nw, np.inf)
        for i, b in enumerate(barriers):
            d, g = b(q)
            Adense[n + i, b.joints] = g
            dval[i] = d
            if not math.isfinite(d):
                l[n + i] = -np.inf
                continue
            need = -gamma_scale * (d - b.m)
            # never ask for more outward speed than the joint box allows (keeps stage 1 feasible)
            reach = float(np.sum(np.maximum(g * ub[b.joints], g * lb[b.joints])))
            l[n + i] = min(need, 0.5 * reach) if need > 0 else need
        solver.update(Px=Pm[p_rows, p_cols], Ax=Adense[a_rows_csc, a_cols_csc])
        # inside a window (or its buffer): is there a configuration outside it that still meets the
        # next target within the slack?  (one QP over a joint displacement Δ within the joint limits,
        # linearised: minimise ‖S·(J·Δ − e_next)‖² + ΔᵀΛΔ with d_w + ∇d_w·Δ ≥ m_w.)  If not, the path
        # forces the window: its barrier is dropped instead of pushing out at every step in vain.
        probe_forced = np.zeros(nw, bool)
        e_next = e + ff * h
        for i in np.flatnonzero(dval - np.array([b.m for b in barriers]) < 0):
            lp = np.full(n + nw, -np.inf)
            up_ = np.full(n + nw, np.inf)
            lp[:n], up_[:n] = np.minimum(lo - q, 0.0), np.maximum(hi - q, 0.0)
            lp[n + i] = barriers[i].m - dval[i]
            solver.update(q=-(SJ.T @ (S @ e_next)), l=lp, u=up_)
            res = solver.solve(raise_error=False)
            if res.info.status in _OK:
                rp, ro = _task_error_norms(e_next - J @ res.x, R, mode)
                probe_forced[i] = rp > tol_p or ro > tol_o
            else:
                probe_forced[i] = True
        l[n:][probe_forced] = -np.inf
        solver.update(q=qlin, l=l, u=u)
        res = solver.solve(raise_error=False)
        st = res.info.status
        qd = None
        if st in _OK:
            qd = np.clip(res.x, lb, ub)
            if nw:
                r = e + (ff - J @ qd) * h
                rp, ro = _task_error_norms(r, R, mode)
                if rp > tol_p or ro > tol_o:
                    # which barriers bind?  If none, the windows are not what limits the tracking
                    act = Adense[n:] @ res.x <= l[n:] + 1e-7 * np.maximum(1.0, np.abs(l[n:]))
                    act |= np.abs(res.y[n:]) > 1e-9
                    act &= np.isfinite(l[n:])
                    if act.any():
                        qd = None
            if qd is not None:
                status[st] += 1
        else:
            act = np.ones(nw, bool)
        forced[k + 1] = bool(probe_forced.any())
        if qd is None and nw:
            # stage 2: the path forces the follower into the windows whose barriers bound stage 1
            l2 = l.copy()
            l2[n:][act] = -np.inf
            solver.update(l=l2)
            res = solver.solve(raise_error=False)
            st = res.info.status
            forced[k + 1] = True
            if st in _OK:
                qd = np.clip(res.x, lb, ub)
                status[st] += 1
        if qd is None:
            # solver failure: damped least squares, projected onto the joint box
            qd = np.clip(np.linalg.solve(Pm, -qlin), lb, ub)
            status[f"fallback ({st})"] += 1
        q = q + qd * h
        q = np.clip(q, lo, hi)   # rounding only: qd·h ≤ hi − q by construction
        Q[k + 1] = q

    pe, oe, ae = tracking_errors(robot, Q, poses)
    vel = np.zeros_like(Q)
    vel[1:] = np.diff(Q, axis=0) / np.diff(t)[:, None]
    ws = WindowSet(robot=robot.name, n=n, windows=wlist)
    in_w = ws.which(Q) if wlist else np.full(N, -1)
    return FollowResult(mode=mode, t=t, q=Q, position_error=pe, orientation_error=oe, axis_error=ae,
                        joint_velocity=vel, joint_speed=np.abs(vel), in_window=in_w, forced=forced,
                        sigma_min=np.asarray(robot.sigma_min(Q), dtype=float), v_max=vmax,
                        tolerance=(float(tolerance[0]), float(tolerance[1])), qp_status=dict(status),
                        window_names=[w.name for w in wlist])


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


# ---- the naive method ------------------------------------------------------------------------------
def resolved_rate(robot, path, q0, dt: float | None = None,
                  jacobian: Callable[[np.ndarray], np.ndarray] | None = None) -> ResolvedRateResult:
    """Open-loop resolved-rate control: q_{k+1} = q_k + J(q_k)⁻¹·ẋ_des,k·Δt, no feedback, no limits.

    ẋ_des,k = [p*_{k+1} − p*_k; log(R*_{k+1}·R*_kᵀ)]/Δt (base frame).  J⁻¹·ẋ is computed with
    ``np.linalg.solve``; where it raises ``LinAlgError`` (J exactly singular in floating point) the
    pseudo-inverse ``np.linalg.pinv(J)·ẋ`` (minimum-norm least squares) is used and the step is
    listed in ``pinv_steps``.  A Jacobian with n ≠ 6 columns always uses the pseudo-inverse.  The
    condition number of J is recorded at every step.  ``jacobian(q) -> (6, n)`` replaces the robot's
    geometric Jacobian (to reproduce a method with a different one).  Joint limits are not enforced:
    this is the method as a homework would write it.
    """
    poses, t = _path_arrays(path, dt, "pose")
    q = _check_start(robot, q0)
    jac = jacobian or robot.jacobian
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
    pe, oe, _ = tracking_errors(robot, Q, poses)
    vel = np.full_like(Q, np.nan)
    vel[0] = 0.0
    vel[1:] = np.diff(Q, axis=0) / np.diff(t)[:, None]
    return ResolvedRateResult(t=t, q=Q, position_error=pe, orientation_error=oe, joint_velocity=vel,
                              joint_speed=np.abs(vel), condition=cond, pinv_steps=pinv_steps, diverged_at=diverged,
                              method="q += solve(J, ẋ·Δt); pinv where solve raises (J exactly singular)")
