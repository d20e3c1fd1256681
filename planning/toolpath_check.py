"""Tool-path validation: the singularity thesis's validation model, as offline-programming tools do it.

:func:`validate_toolpath` follows a Cartesian :class:`~planning.toolpath.ToolPath` with a continuous
inverse-kinematics solution and reports, per waypoint, whether the robot can do it:

* **continuous IK.**  The first waypoint is solved from ``start_q`` when given (the choice of
  start branch; a local solve, or :meth:`kin.Robot.ik` with ``q0 = start_q`` when that fails),
  otherwise by :meth:`kin.Robot.ik` — the solution nearest the home configuration.  Every next
  waypoint is solved by Newton / damped-least-squares (Levenberg–Marquardt) steps from the previous
  solution, whose FK and Jacobian are already known — on a smooth path one step and one new
  FK+Jacobian evaluation per waypoint:

      J_w·Δq = e   or   (J_wᵀJ_w + μ·I)·Δq = J_wᵀ·e,
      e = [p* − p(q); w·log(R*·R(q)ᵀ)],   J_w = diag(1, 1, 1, w, w, w)·J

  with w a length (half the robot's reach) that weighs radians against metres.  The undamped step
  is used while J_w is square and well conditioned; near a singularity, or when a step does not
  lower ‖e‖, the damping μ takes over and grows until a step does.  Steps are not clipped to the
  joint limits: a path that needs a joint beyond its limit is reported as such.  When the local
  solve fails the waypoint is retried from the previous solution in Cartesian sub-steps, then by
  the global solver (rarely: with doubling gaps along an unreachable stretch, a bounded number of
  times per path).
* **branch continuity.**  A solution whose largest joint change from the previous waypoint
  exceeds ``max_joint_step`` (rad for revolute, m for prismatic joints) is a ``branch_jump``: the
  continuous solution does not exist there (a singularity is crossed) or the solver had to switch
  branch.  After an unreachable stretch the path resumes from the last reachable solution; the
  gap across the stretch is reported as ``joint_step`` but not as a jump.
* **per waypoint:** reachable (position and orientation error of the final configuration, by a
  batch FK, within tolerance), the errors, the joint-limit margin (min over joints of the distance
  to the nearer limit, SI), σ_min and manipulability of the task Jacobian, the singular window the
  configuration is in, the joint speeds the feed needs — q̇_i = (q_i − q_{i−1}) / (t_i − t_{i−1}),
  q̇_0 = 0 — and their ratio to the joints' maximum speeds when known.

Problem kinds, in the order they rank at one waypoint: ``unreachable``, ``branch_jump``,
``limits``, ``window``, ``sigma_min``, ``speed``.  The verdict names the first problem along the
path, its kind and where it is (index, arc length, time).  Nothing here prints.
"""
from __future__ import annotations

import math
import time
from dataclasses import dataclass, field

import numpy as np
from scipy.linalg import lapack

from kin.errors import ConfigurationError, RmtError
from kin.transforms import log_so3, rotation_error

from .toolpath import ToolPath, ToolPathError, slerp
from .windows import WindowSet

__all__ = ["validate_toolpath", "ToolPathReport", "Problem", "KINDS", "DEFAULT_MAX_STEP_ANGLE",
           "DEFAULT_MAX_STEP_LENGTH"]

KINDS = ("unreachable", "branch_jump", "limits", "window", "sigma_min", "speed")
#: default largest joint change between consecutive waypoints before a branch jump is reported
DEFAULT_MAX_STEP_ANGLE = math.radians(30.0)   # rad, revolute joints
DEFAULT_MAX_STEP_LENGTH = 0.1                 # m, prismatic joints
#: the local solver aims this far inside the tolerances (the final check is a batch FK at the tolerances)
_AIM = 1e-1
#: at most this many waypoints per path go to the (slower) global solver
MAX_GLOBAL_SOLVES = 8


@dataclass(frozen=True)
class Problem:
    """A problem at waypoint ``index``: its ``kind`` (one of :data:`KINDS`), a text, and where it is
    on the path — arc length ``s`` (m) and time ``t`` (s, or None without timing)."""

    index: int
    kind: str
    detail: str
    s: float
    t: float | None
    origin: str = ""

    def to_dict(self) -> dict:
        return {"index": self.index, "kind": self.kind, "detail": self.detail, "s": self.s, "t": self.t,
                "origin": self.origin}

    def where(self, total: int | None = None) -> str:
        """``waypoint i [of N] (s = …, t = …, line/segment …)``."""
        parts = [f"s = {self.s:.6g} m"] + ([] if self.t is None else [f"t = {self.t:.6g} s"])
        parts += [self.origin] if self.origin else []
        of = "" if total is None else f" of {total}"
        return f"waypoint {self.index}{of} ({', '.join(parts)})"


@dataclass
class ToolPathReport:
    """Result of :func:`validate_toolpath`.  Arrays have one row per waypoint (N); SI units.

    q (N, n) joint solution; reachable (N,) bool; position_error (N,) m; orientation_error (N,) rad
    (0 in position mode); limit_margin (N,) min over joints of the distance to the nearer limit (rad
    or m; < 0 outside); sigma_min, manipulability (N,) of the task Jacobian; window (N,) index into
    ``window_names`` (−1: none); joint_speed (N, n) rad/s or m/s (NaN without timing or next to an
    unreachable waypoint); speed_ratio (N,) max over joints of |q̇|/max speed (NaN when no joint
    has one); joint_step (N,) largest |Δq| from the previous reachable waypoint; flags: kind →
    (N,) bool where that problem occurs.
    """

    robot: str
    source: str
    mode: str
    s: np.ndarray
    t: np.ndarray | None
    q: np.ndarray
    reachable: np.ndarray
    position_error: np.ndarray
    orientation_error: np.ndarray
    limit_margin: np.ndarray
    sigma_min: np.ndarray
    manipulability: np.ndarray
    window: np.ndarray
    window_names: list[str]
    joint_speed: np.ndarray
    speed_ratio: np.ndarray
    joint_step: np.ndarray
    flags: dict[str, np.ndarray]
    first_problem: Problem | None
    thresholds: dict
    elapsed_s: float
    stats: dict = field(default_factory=dict)
    windows: WindowSet | None = field(default=None, repr=False)
    toolpath: ToolPath | None = field(default=None, repr=False)

    # ---- summary ------------------------------------------------------------------------------
    @property
    def ok(self) -> bool:
        """True when no waypoint has a problem."""
        return self.first_problem is None

    @property
    def n_waypoints(self) -> int:
        return len(self.s)

    @property
    def counts(self) -> dict[str, int]:
        """Waypoints with each kind of problem."""
        return {k: int(self.flags[k].sum()) for k in KINDS}

    def window_name(self, i: int) -> str | None:
        """Name of the window waypoint ``i`` is in, or None."""
        w = int(self.window[i])
        return None if w < 0 else self.window_names[w]

    def problems(self, kind: str | None = None) -> np.ndarray:
        """Indices of the waypoints with a problem (of ``kind``, or of any kind)."""
        if kind is None:
            m = np.zeros(self.n_waypoints, bool)
            for k in KINDS:
                m |= self.flags[k]
            return np.nonzero(m)[0]
        if kind not in KINDS:
            raise ValueError(f"problem kind {kind!r} unknown; allowed: {', '.join(KINDS)}")
        return np.nonzero(self.flags[kind])[0]

    def _min(self, a: np.ndarray) -> tuple[float | None, int | None]:
        v = np.where(self.reachable & np.isfinite(a), a, np.inf)
        if not np.isfinite(v).any():
            return None, None
        i = int(np.argmin(v))
        return float(v[i]), i

    def verdict(self) -> str:
        """One line: VALID, or INVALID with the first problem, its kind and where it is."""
        N = self.n_waypoints
        if self.ok:
            sig, i = self._min(self.sigma_min)
            extra = "" if sig is None else f"; min σ_min {sig:.3g} at waypoint {i}"
            return f"VALID: all {N} waypoints reachable, no problem found{extra}"
        p = self.first_problem
        others = ", ".join(f"{k} {c}" for k, c in self.counts.items() if c)
        return (f"INVALID: first problem at {p.where(N)}: {p.kind} — {p.detail} "
                f"[waypoints with problems: {others}]")

    def summary(self) -> dict:
        """JSON-ready summary (SI units; non-finite numbers as None)."""
        sig, isig = self._min(self.sigma_min)
        man, iman = self._min(self.manipulability)
        lim, ilim = self._min(self.limit_margin)
        reach = self.reachable
        sr = self.speed_ratio[np.isfinite(self.speed_ratio)]
        qd = self.joint_speed[np.isfinite(self.joint_speed).all(axis=1)] if self.joint_speed.size else self.joint_speed
        return _clean({
            "valid": self.ok, "first_problem": None if self.first_problem is None else self.first_problem.to_dict(),
            "verdict": self.verdict(), "robot": self.robot, "source": self.source, "mode": self.mode,
            "waypoints": self.n_waypoints, "reachable": int(reach.sum()),
            "length": float(self.s[-1]), "duration": None if self.t is None else float(self.t[-1]),
            "counts": self.counts,
            "min_sigma": sig, "min_sigma_index": isig, "min_manipulability": man, "min_manipulability_index": iman,
            "min_limit_margin": lim, "min_limit_margin_index": ilim,
            "max_position_error": float(self.position_error[reach].max()) if reach.any() else None,
            "max_orientation_error": float(self.orientation_error[reach].max()) if reach.any() else None,
            "max_joint_step": float(np.nanmax(self.joint_step)) if np.isfinite(self.joint_step).any() else None,
            "max_joint_speed": np.abs(qd).max(axis=0).tolist() if len(qd) else None,
            "max_speed_ratio": float(sr.max()) if len(sr) else None,
            "windows": list(self.window_names),
            "waypoints_in_windows": int((self.window >= 0).sum()),
            "thresholds": self.thresholds, "elapsed_s": self.elapsed_s, "stats": self.stats,
            "units": "SI (m, rad, s)",
        })

    def to_dict(self, waypoints: bool = False) -> dict:
        """The :meth:`summary`, plus the per-waypoint arrays when ``waypoints`` is True (JSON-ready)."""
        d = self.summary()
        if waypoints:
            d["per_waypoint"] = _clean({
                "s": self.s, "t": self.t, "q": self.q, "reachable": self.reachable,
                "position_error": self.position_error, "orientation_error": self.orientation_error,
                "limit_margin": self.limit_margin, "sigma_min": self.sigma_min,
                "manipulability": self.manipulability, "window": self.window,
                "joint_speed": self.joint_speed, "speed_ratio": self.speed_ratio, "joint_step": self.joint_step,
                "flags": {k: v for k, v in self.flags.items()}})
        return d


def _clean(obj):
    """numpy → plain Python, NaN/inf → None (strict JSON)."""
    if isinstance(obj, dict):
        return {str(k): _clean(v) for k, v in obj.items()}
    if isinstance(obj, (list, tuple)):
        return [_clean(v) for v in obj]
    if isinstance(obj, np.ndarray):
        if obj.dtype == bool:
            return obj.tolist()
        if np.issubdtype(obj.dtype, np.integer):
            return obj.tolist()
        return _clean(obj.tolist())
    if isinstance(obj, (bool, np.bool_)):
        return bool(obj)
    if isinstance(obj, np.integer):
        return int(obj)
    if isinstance(obj, (float, np.floating)):
        x = float(obj)
        return x if math.isfinite(x) else None
    return obj


# ---- the local solver -----------------------------------------------------------------------------
def _length_scale(chain) -> float:
    """A length (m) that weighs orientation errors against position errors: half the reach."""
    tab = chain.dh_table()
    reach = np.abs(tab[:, 0]).sum() + np.abs(tab[:, 2]).sum() + np.linalg.norm(chain.tool.matrix[:3, 3])
    return float(max(0.5 * reach, 0.05))


class _Tracker:
    """Newton / Levenberg–Marquardt on one configuration, cheap per step.

    A step costs one compiled FK+Jacobian call (``robot.fk_jacobian``), the residual in plain
    Python floats and one LAPACK call: a Newton step J_w·Δq = e (LU, ``dgesv``) while the weighted
    Jacobian is square and the step stays moderate, otherwise the damped normal equations
    (J_wᵀJ_w + μ·I)·Δq = J_wᵀ·e (Cholesky, ``dposv``).  A step is kept only when it lowers ‖e‖;
    otherwise the damping grows (Newton falls back to LM).  Near a singularity — where the
    homework's naive q += J⁻¹·ẋ·Δt fails — the damping keeps the step bounded.
    """

    def __init__(self, robot, pose: bool, w: float, tol_p: float, tol_o: float, big_step: float):
        self.fkj = robot.fk_jacobian
        self.n = n = robot.n
        self.pose = pose
        self.w = w
        self.aim_p, self.aim_o = tol_p * _AIM, tol_o * _AIM
        self.tol_p, self.tol_o = tol_p, tol_o
        self.square = (6 if pose else 3) == n
        self.big = big_step
        self.eye = np.eye(n)
        self.scale = None          # μ = λ·scale, scale = mean diagonal of J_wᵀJ_w at the first evaluation
        self.evals = 0
        self.last = None           # (q, (T, J_w)) of the last solve's result
        self.improving = False     # the last solve ran out of iterations while converging fast

    def evaluate(self, q):
        """(T as nested lists, weighted Jacobian J_w) at q: one compiled call."""
        T, J = self.fkj(q)
        self.evals += 1
        if self.pose:
            J[3:] *= self.w
            return T.tolist(), J
        return T.tolist(), J[:3]

    def error(self, T, pt, Rt):
        """(e, pe, oe): weighted error (6,) or (3,), position and orientation error (m, rad) of the
        pose T (nested lists) against the target ``pt`` (3 floats) and ``Rt`` (nested 3×3 lists)."""
        (r00, r01, r02, px), (r10, r11, r12, py), (r20, r21, r22, pz), _ = T
        ex, ey, ez = pt[0] - px, pt[1] - py, pt[2] - pz
        pe = math.sqrt(ex * ex + ey * ey + ez * ez)
        if not self.pose:
            return np.array((ex, ey, ez)), pe, 0.0
        # rotation vector of Re = Rt·Rᵀ (the geometric Jacobian's angular rows act on it)
        (a0, a1, a2), (b0, b1, b2), (c0, c1, c2) = Rt
        e00 = a0 * r00 + a1 * r01 + a2 * r02
        e11 = b0 * r10 + b1 * r11 + b2 * r12
        e22 = c0 * r20 + c1 * r21 + c2 * r22
        vx = (c0 * r10 + c1 * r11 + c2 * r12) - (b0 * r20 + b1 * r21 + b2 * r22)   # Re21 − Re12
        vy = (a0 * r20 + a1 * r21 + a2 * r22) - (c0 * r00 + c1 * r01 + c2 * r02)   # Re02 − Re20
        vz = (b0 * r00 + b1 * r01 + b2 * r02) - (a0 * r10 + a1 * r11 + a2 * r12)   # Re10 − Re01
        s2 = vx * vx + vy * vy + vz * vz
        cos = 0.5 * (e00 + e11 + e22 - 1.0)
        if s2 > 1e-28:
            sin = 0.5 * math.sqrt(s2)
            sc = math.atan2(sin, cos) / (2.0 * sin)
            ox, oy, oz = vx * sc, vy * sc, vz * sc
        elif cos > 0:   # identity up to rounding
            ox, oy, oz = 0.5 * vx, 0.5 * vy, 0.5 * vz
        else:           # a half turn: the skew part vanishes; use the exact logarithm
            ox, oy, oz = log_so3(np.array(Rt) @ np.array(T)[:3, :3].T).tolist()
        oe = math.sqrt(ox * ox + oy * oy + oz * oz)
        w = self.w
        return np.array((ex, ey, ez, w * ox, w * oy, w * oz)), pe, oe

    def converged(self, pe: float, oe: float) -> bool:
        return pe <= self.tol_p and oe <= self.tol_o

    def solve(self, q, pt, Rt, max_iter: int, at=None):
        """Iterate from q (n,) towards the target; returns (q, pe, oe, iterations).

        ``at``: (T, J_w) already evaluated at q (the previous waypoint's solution), saving a call.
        The last accepted evaluation is kept in :attr:`last` for the next waypoint.
        """
        T, J = self.evaluate(q) if at is None else at
        e, pe, oe = self.error(T, pt, Rt)
        if self.scale is None:
            self.scale = max(float(np.dot(J.ravel(), J.ravel())) / self.n, 1e-12)
        cost = float(e.dot(e))
        it = 0
        newton = self.square
        lam = 1e-6
        ratio = 1.0      # cost ratio of the last accepted step
        while (pe > self.aim_p or oe > self.aim_o) and it < max_iter:
            it += 1
            if newton:
                lu, _, dq, info = lapack.dgesv(J, e)
                u = np.abs(lu.diagonal()).tolist()
                dl = dq.tolist()
                # (nearly) singular J: a Newton step could move along the null space at will — damp instead
                if info != 0 or min(u) < 1e-8 * max(u) or max(dl) > self.big or -min(dl) > self.big:
                    newton = False      # singular or a wild step: damp instead (no evaluation spent)
                    it -= 1
                    continue
            else:
                A = J.T.dot(J)
                A += self.eye * (lam * self.scale)
                g = J.T.dot(e)
                _, dq, info = lapack.dposv(A, g)
                if info != 0:           # not positive definite numerically: least squares
                    dq = np.linalg.lstsq(A, g, rcond=None)[0]
            qn = q + dq
            Tn, Jn = self.evaluate(qn)
            en, pen, oen = self.error(Tn, pt, Rt)
            cn = float(en.dot(en))
            if cn < cost:
                ratio = cn / cost if cost > 0 else 0.0
                q, T, J, e, pe, oe, cost = qn, Tn, Jn, en, pen, oen, cn
                lam = max(lam * 0.1, 1e-12)
            elif newton:
                newton = False
            else:
                lam *= 10.0
                if lam > 1e8:
                    break
        self.last = (q, (T, J))
        # still converging fast when the iterations ran out (a reachable target, far away): worth more
        self.improving = it >= max_iter and ratio < 0.5
        return q, pe, oe, it


# ---- validation -----------------------------------------------------------------------------------
def _max_steps(chain, max_joint_step) -> np.ndarray:
    if max_joint_step is None:
        return np.where(chain.revolute_mask, DEFAULT_MAX_STEP_ANGLE, DEFAULT_MAX_STEP_LENGTH)
    b = np.broadcast_to(np.asarray(max_joint_step, dtype=float), (chain.n,)).copy()
    if not np.all(np.isfinite(b)) or np.any(b <= 0):
        raise ConfigurationError(f"max_joint_step must be positive and finite (rad or m), got {max_joint_step}")
    return b


def _max_speeds(chain, max_speed) -> np.ndarray:
    v = np.array([np.nan if j.max_velocity is None else float(j.max_velocity) for j in chain.joints])
    if max_speed is not None:
        m = np.broadcast_to(np.asarray(max_speed, dtype=float), (chain.n,))
        if np.any(~np.isnan(m) & ~(m > 0)):
            raise ConfigurationError(f"max_speed must be positive (rad/s or m/s; NaN for unknown), got {max_speed}")
        v = np.where(np.isnan(m), v, m)
    return v


def validate_toolpath(robot, toolpath: ToolPath, windows: WindowSet | None = None, start_q=None,
                      branch_seed: int = 0, sigma_min: float | None = None, tol_position: float = 1e-6,
                      tol_orientation: float = 1e-6, max_joint_step=None, max_speed=None,
                      limit_clearance: float = 0.0, mode: str = "auto", max_iter: int = 8) -> ToolPathReport:
    """Validate ``toolpath`` for ``robot`` (see the module docstring).

    Parameters
    ----------
    windows : singular windows to stay out of (``planning.windows.build_windows``), or None.
    start_q : (n,) SI configuration the first waypoint is solved from — the start branch; None: the
        IK solution nearest the home configuration.
    branch_seed : seed of the global IK's random starts (first waypoint, fall-backs).
    sigma_min : floor on σ_min of the task Jacobian (None: reported, not judged).
    tol_position, tol_orientation : reachability tolerances (m, rad).
    max_joint_step : largest joint change between consecutive waypoints (scalar or (n,), rad/m);
        default 30° for revolute, 0.1 m for prismatic joints.
    max_speed : joint speed limits (scalar or (n,), rad/s or m/s) overriding the robot file's
        ``max_velocity`` (NaN entries keep the file's value).
    limit_clearance : required distance to the joint limits (rad/m); 0: only outside is a problem.
    mode : ``"pose"``, ``"position"`` or ``"auto"`` (pose when the path has orientations and the
        robot's task has all six rows).
    max_iter : LM iterations per waypoint of the first attempt (more on retries).

    Returns a :class:`ToolPathReport`.
    """
    t0 = time.perf_counter()
    chain = robot.chain
    n = chain.n
    if not isinstance(toolpath, ToolPath):
        raise ToolPathError(f"expected a ToolPath, got {type(toolpath).__name__}")
    if mode not in ("auto", "pose", "position"):
        raise ConfigurationError(f"mode {mode!r} unknown; allowed: auto, pose, position")
    for name, v in (("tol_position", tol_position), ("tol_orientation", tol_orientation)):
        if not (v > 0 and math.isfinite(v)):
            raise ConfigurationError(f"{name} must be a positive number, got {v}")
    if sigma_min is not None and not (sigma_min >= 0 and math.isfinite(sigma_min)):
        raise ConfigurationError(f"sigma_min must be a finite number ≥ 0, got {sigma_min}")
    if not (limit_clearance >= 0 and math.isfinite(limit_clearance)):
        raise ConfigurationError(f"limit_clearance must be a finite number ≥ 0 (rad or m), got {limit_clearance}")
    if windows is not None and windows.n != n:
        raise ConfigurationError(f"windows are for a {windows.n}-joint robot ({windows.robot}); "
                                 f"{chain.name} has {n} joints")
    if mode == "auto":
        mode = "pose" if (toolpath.has_orientation and len(robot.task_rows) == 6) else "position"
    pose = mode == "pose"
    bound = _max_steps(chain, max_joint_step)
    vmax = _max_speeds(chain, max_speed)
    if start_q is not None:
        start_q, _ = chain.as_batch(start_q, "start_q")
        start_q = start_q[0]

    N = len(toolpath)
    Pt = np.ascontiguousarray(toolpath.poses[:, :3, 3])
    Rt = np.ascontiguousarray(toolpath.poses[:, :3, :3])
    # the per-waypoint loop works on plain Python floats: numpy's per-call overhead dominates at n = 6
    Ptl, Rtl = Pt.tolist(), Rt.tolist()
    s = toolpath.s
    tracker = _Tracker(robot, pose, _length_scale(chain), tol_position, tol_orientation, float(bound.max()))
    ik_opts = dict(mode=mode, tol_position=tol_position, tol_orientation=tol_orientation)
    bl = bound.tolist()
    b0 = bl[0] if all(b == bl[0] for b in bl) else None

    def jump_of(q, ref) -> tuple[float, bool]:
        """(largest |Δq|, whether every joint stays within its bound)."""
        d = (q - ref).tolist()
        m = max(max(d), -min(d))
        if b0 is not None:
            return m, m <= b0
        return m, all(abs(x) <= c for x, c in zip(d, bl))

    Q = np.zeros((N, n))
    jump = np.zeros(N, bool)
    step = np.zeros(N)
    prev = np.full(N, -1)      # index of the previous reachable waypoint (the one a jump is measured from)
    stats = {"global_solves": 0, "substep_retries": 0, "iterations": 0}
    conv = tracker.converged
    lo, hi = chain.lower, chain.upper

    def inside(q) -> bool:
        return bool(np.all((q >= lo) & (q <= hi)))

    # first waypoint: the start branch
    q_first = at_prev = outside = None      # at_prev: (T, J_w) at the last reachable solution, when known
    if start_q is not None:
        q, pe, oe, it = tracker.solve(start_q.copy(), Ptl[0], Rtl[0], 50)
        stats["iterations"] += it
        if conv(pe, oe):
            if inside(q):
                q_first, at_prev = q, tracker.last[1]
            else:
                outside = (q, tracker.last[1])   # reached, beyond a limit: kept if nothing better exists
    ok0 = True
    if q_first is None:
        res = robot.ik(toolpath.poses[0], seed=branch_seed, q0=start_q, **ik_opts)
        stats["global_solves"] += 1
        if res.success or outside is None:
            q_first, ok0 = np.asarray(res.q, dtype=float), bool(res.success)
        else:
            q_first, at_prev = outside
    Q[0] = q_first
    q_prev = q_first if ok0 else None        # the last reachable solution: the continuation's seed
    i_prev = 0 if ok0 else -1

    # global solves are slow (a batch of random starts): within an unreachable stretch they are tried
    # with doubling gaps (offsets 0, 1, 3, 7, … into the stretch), at most MAX_GLOBAL_SOLVES per path
    backoff = {"next": 0, "gap": 1}

    def global_solve(i: int, q0):
        if stats["global_solves"] >= MAX_GLOBAL_SOLVES or i < backoff["next"]:
            return None
        res = robot.ik(toolpath.poses[i], seed=branch_seed, q0=q0, restarts=4, rounds=2, max_iter=100, **ik_opts)
        stats["global_solves"] += 1
        if res.success:
            return np.asarray(res.q, dtype=float), res.position_error, res.orientation_error
        backoff["next"], backoff["gap"] = i + backoff["gap"], 2 * backoff["gap"]
        return None

    for i in range(1, N):
        pt, R = Ptl[i], Rtl[i]
        if q_prev is None:   # nothing reachable yet: local from the best try so far, then (rarely) global
            q, pe, oe, it = tracker.solve(np.clip(Q[i - 1], lo, hi), pt, R, max_iter)
            stats["iterations"] += it
            Q[i] = q
            if conv(pe, oe) and inside(q):   # no continuity to keep yet: take a solution within the limits
                q_prev, i_prev, at_prev = q, i, tracker.last[1]
            elif (g := global_solve(i, start_q)) is not None:
                Q[i] = g[0]
                q_prev, i_prev, at_prev = g[0], i, None
            if q_prev is not None:
                backoff["next"], backoff["gap"] = 0, 1
            continue
        stretch = i_prev < i - 1     # inside an unreachable stretch: cheaper attempts
        # Newton from the previous solution, whose FK and Jacobian are at hand: usually one new evaluation
        q, pe, oe, it = tracker.solve(q_prev, pt, R, max_iter if stretch else 4 * max_iter, at=at_prev)
        stats["iterations"] += it
        if stretch and tracker.improving and not conv(pe, oe):   # coming back into reach: keep going
            q, pe, oe, it = tracker.solve(q, pt, R, 4 * max_iter, at=tracker.last[1])
            stats["iterations"] += it
        ok = conv(pe, oe)
        stp, near = jump_of(q, q_prev) if ok else (math.inf, False)
        at = tracker.last[1]
        if not (ok and near) and not stretch:
            # Cartesian sub-steps from the previous waypoint keep the solution on its branch if it exists
            stats["substep_retries"] += 1
            q3, ok3 = _substeps(tracker, q_prev, toolpath.poses[i - 1], toolpath.poses[i], 8, 4 * max_iter, stats)
            if ok3:
                pe3, oe3 = _errors(robot, q3, Pt[i], Rt[i], pose)
                stp3, near3 = jump_of(q3, q_prev)
                if conv(pe3, oe3) and (near3 or not ok):
                    q, pe, oe, ok, stp, near, at = q3, pe3, oe3, True, stp3, near3, None
        if not ok and (g := global_solve(i, q_prev)) is not None:
            q, pe, oe, ok = *g, True
            stp, near, at = *jump_of(q, q_prev), None
        Q[i] = q
        if ok:
            prev[i] = i_prev
            step[i] = stp
            jump[i] = not near and not stretch   # across an unreachable stretch the gap is no branch problem
            q_prev, i_prev, at_prev = q, i, at
            backoff["next"], backoff["gap"] = 0, 1
    stats["fk_jacobian_calls"] = tracker.evals
    stats["solve_s"] = time.perf_counter() - t0

    # ---- everything else is a batch --------------------------------------------------------------
    T = robot.fk(Q)
    position_error = np.linalg.norm(Pt - T[:, :3, 3], axis=1)
    orientation_error = (np.linalg.norm(rotation_error(Rt, T[:, :3, :3]), axis=1) if pose else np.zeros(N))
    reachable = (position_error <= tol_position) & (orientation_error <= tol_orientation)
    meas = robot.measures(Q)
    sig = np.asarray(meas.sigma_min, dtype=float).reshape(N)
    man = np.asarray(meas.manipulability, dtype=float).reshape(N)
    margins = np.minimum(Q - lo, hi - Q)
    limit_margin = margins.min(axis=1)
    win = windows.which(Q) if (windows is not None and windows.windows) else np.full(N, -1)
    names = [w.name for w in windows.windows] if windows is not None else []
    # joint speeds the feed needs: backward differences over the time step
    qd = np.full((N, n), np.nan)
    if toolpath.t is not None:
        qd[0] = 0.0
        if N > 1:
            dq = np.diff(Q, axis=0)
            dt = np.diff(toolpath.t)
            with np.errstate(divide="ignore", invalid="ignore"):
                v = dq / dt[:, None]
            v = np.where((dt[:, None] <= 0) & (np.abs(dq) <= 1e-12), 0.0, v)
            v = np.where((dt[:, None] <= 0) & (np.abs(dq) > 1e-12), np.inf, v)
            both = reachable[1:] & reachable[:-1]
            qd[1:] = np.where(both[:, None], v, np.nan)
        qd[~reachable] = np.nan
    known = ~np.isnan(vmax)
    if known.any():
        with np.errstate(invalid="ignore"):
            ratio = np.abs(qd[:, known]) / vmax[known]
        speed_ratio = np.where(np.isnan(ratio).all(axis=1), np.nan, np.nanmax(np.where(np.isnan(ratio), -np.inf, ratio),
                                                                               axis=1))
    else:
        speed_ratio = np.full(N, np.nan)
    step = np.where(reachable, step, np.nan)

    flags = {
        "unreachable": ~reachable,
        "branch_jump": jump & reachable,
        "limits": reachable & (limit_margin < limit_clearance - 1e-12),
        "window": reachable & (win >= 0),
        "sigma_min": reachable & (sig < sigma_min) if sigma_min is not None else np.zeros(N, bool),
        "speed": reachable & (speed_ratio > 1.0),
    }
    first = None
    for k in KINDS:
        idx = np.nonzero(flags[k])[0]
        if len(idx) and (first is None or idx[0] < first[0]):
            first = (int(idx[0]), k)
    problem = None
    if first is not None:
        i, k = first
        detail = _detail(k, i, int(prev[i]), robot, Q, position_error, orientation_error, limit_margin, margins, sig, sigma_min,
                         win, windows, qd, vmax, step, bound, tol_position, tol_orientation, limit_clearance, pose)
        problem = Problem(i, k, detail, float(s[i]), None if toolpath.t is None else float(toolpath.t[i]),
                          toolpath.origin(i))
    thresholds = {"tol_position": tol_position, "tol_orientation": tol_orientation, "sigma_min": sigma_min,
                  "max_joint_step": bound.tolist(), "max_speed": [None if np.isnan(v) else float(v) for v in vmax],
                  "limit_clearance": limit_clearance,
                  "start_q": None if start_q is None else start_q.tolist(), "branch_seed": branch_seed}
    return ToolPathReport(robot=chain.name, source=toolpath.source, mode=mode, s=s.copy(),
                          t=None if toolpath.t is None else toolpath.t.copy(), q=Q, reachable=reachable,
                          position_error=position_error, orientation_error=orientation_error,
                          limit_margin=limit_margin, sigma_min=sig, manipulability=man, window=win,
                          window_names=names, joint_speed=qd, speed_ratio=speed_ratio, joint_step=step, flags=flags,
                          first_problem=problem, thresholds=thresholds, elapsed_s=time.perf_counter() - t0,
                          stats=stats, windows=windows, toolpath=toolpath)


def _errors(robot, q, pt, R, pose: bool) -> tuple[float, float]:
    T = robot.fk(q)
    pe = float(np.linalg.norm(pt - T[:3, 3]))
    oe = float(np.linalg.norm(rotation_error(R, T[:3, :3]))) if pose else 0.0
    return pe, oe


def _substeps(tracker: _Tracker, q, T0: np.ndarray, T1: np.ndarray, k: int, max_iter: int, stats: dict):
    """Follow the straight Cartesian interpolation T0 → T1 in k sub-steps from q; (q, success)."""
    u = np.arange(1, k + 1) / k
    P = T0[:3, 3][None] + u[:, None] * (T1[:3, 3] - T0[:3, 3])[None]
    R = slerp(T0[:3, :3], T1[:3, :3], u)
    Pl, Rl = P.tolist(), R.tolist()
    for j in range(k):
        q, pe, oe, it = tracker.solve(q, Pl[j], Rl[j], max_iter)
        stats["iterations"] += it
        if not tracker.converged(pe, oe):
            return q, False
    return q, True


def _detail(kind, i, ip, robot, Q, pe, oe, limit_margin, margins, sig, sigma_min, win, windows, qd, vmax, step,
            bound, tol_p, tol_o, clearance, pose) -> str:
    """The problem in words, values in the robot file's units (σ_min in SI)."""
    chain = robot.chain
    sc = chain.variable_scale
    unit = [chain.angle_unit if r else chain.length_unit for r in chain.revolute_mask]
    L, Lu, A, Au = chain.length_scale, chain.length_unit, chain.angle_scale, chain.angle_unit

    def jv(j, v):   # a joint value (SI) in file units
        return f"{v / sc[j]:.6g} {unit[j]}"

    if kind == "unreachable":
        txt = f"no IK solution: position error {pe[i] / L:.3g} {Lu} (tolerance {tol_p / L:.3g} {Lu})"
        if pose:
            txt += f", orientation error {oe[i] / A:.3g} {Au} (tolerance {tol_o / A:.3g} {Au})"
        return txt
    if kind == "branch_jump":
        j = int(np.argmax(np.abs(Q[i] - Q[ip]) / bound))
        return (f"the continuous IK solution jumps: joint {j + 1} changes by {jv(j, abs(Q[i, j] - Q[ip, j]))} from "
                f"waypoint {ip} (allowed {jv(j, bound[j])}); a singularity is crossed or the branch changed")
    if kind == "limits":
        j = int(np.argmin(margins[i]))
        where = "outside" if margins[i, j] < 0 else f"within {jv(j, clearance)} of"
        return (f"joint {j + 1} = {jv(j, Q[i, j])} is {where} its limits "
                f"[{chain.lower[j] / sc[j]:.6g}, {chain.upper[j] / sc[j]:.6g}] {unit[j]}")
    if kind == "window":
        w = windows.windows[int(win[i])]
        at = f"q{w.joint + 1} = {jv(w.joint, Q[i, w.joint])}, " if w.is_interval else ""
        return f"inside singular window '{w.name}' ({at}σ_min = {sig[i]:.3g})"
    if kind == "sigma_min":
        return f"σ_min = {sig[i]:.3g} < {sigma_min:.3g}: too close to a singularity"
    if kind == "speed":
        with np.errstate(invalid="ignore"):
            r = np.where(np.isnan(vmax), -np.inf, np.abs(qd[i]) / np.where(np.isnan(vmax), 1.0, vmax))
        j = int(np.argmax(r))
        return (f"joint {j + 1} needs {jv(j, abs(qd[i, j]))}/s at the feed rate, {r[j]:.3g} × its maximum "
                f"{jv(j, vmax[j])}/s")
    raise RmtError(f"unknown problem kind {kind!r}")   # pragma: no cover
