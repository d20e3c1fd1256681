"""Tool-path validation as offline-programming tools do it: continuous IK along the path, checked waypoint by
waypoint and segment by segment.

:func:`validate_toolpath` follows a Cartesian :class:`~planning.toolpath.ToolPath` with a continuous
inverse-kinematics solution and reports, per waypoint, whether the robot can do it:

* **continuous IK** (:mod:`planning.toolpath.ik`).  The first waypoint is solved from ``start_q``
  when given (the choice of start branch), otherwise by :meth:`kin.Robot.ik` — the solution nearest
  the home configuration.  Every next waypoint is solved by Newton / damped-least-squares
  (Levenberg–Marquardt) steps from the previous solution, with Cartesian sub-steps and the global
  solver as fall-backs.  Steps are not clipped to the joint limits: a path that needs a joint
  beyond its limit is reported as such.
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

* **between waypoints** (:mod:`planning.toolpath.between`): the joint motion from one reachable
  waypoint to the next — the windows and the σ_min floor along the joint-space segment, densely and
  by proof, and a sign change of an exact singular factor (a proven crossing of the singular set).
  A segment problem ranks after its first waypoint's problems and before its second's.

Problem kinds, in the order they rank at one waypoint: ``unreachable``, ``branch_jump``,
``limits``, ``window``, ``sigma_min``, ``speed``.  The verdict names the first problem along the
path, its kind and where it is (index, arc length, time).  Nothing here prints.

The report is a :class:`~planning.toolpath.report.ToolPathReport` (with :class:`Problem` and
:data:`KINDS`, in :mod:`planning.toolpath.report`).
"""
from __future__ import annotations

import math
import time

import numpy as np

from kin.errors import ConfigurationError, RmtError
from kin.transforms import rotation_error
from planning.certify.collision import certify_collision
from planning.certify.signs import floor_factors
from planning.toolpath.between import check_segments
from planning.toolpath.ik import continuous_ik
from planning.toolpath.model import ToolPath, ToolPathError
from planning.toolpath.report import KINDS, Problem, ToolPathReport
from planning.windows import WindowSet

__all__ = ["validate_toolpath", "DEFAULT_MAX_STEP_ANGLE",
           "DEFAULT_MAX_STEP_LENGTH"]

#: default largest joint change between consecutive waypoints before a branch jump is reported
DEFAULT_MAX_STEP_ANGLE = math.radians(30.0)   # rad, revolute joints
DEFAULT_MAX_STEP_LENGTH = 0.1                 # m, prismatic joints


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
                      limit_clearance: float = 0.0, mode: str = "auto", max_iter: int = 8,
                      world=None, factors=None) -> ToolPathReport:
    """Validate ``toolpath`` for ``robot`` (see the module docstring).

    Parameters
    ----------
    windows : singular windows to stay out of (``planning.windows.build_windows``), or None.
    start_q : (n,) SI configuration the first waypoint is solved from — the start branch; None: the
        IK solution of :meth:`kin.Robot.ik` (seeded by ``branch_seed``).
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
    world : a :class:`planning.collision.CollisionWorld` (the robot in its work cell): every reachable
        waypoint must be clear of it by its margin, and every joint motion between two reachable
        waypoints is proven clear (:func:`planning.certify.collision.certify_collision`).
    factors : exact singular factors whose sign change between two waypoints is a proven crossing of
        the singular set (:func:`planning.certify.signs.floor_factors`); None: looked up when
        ``sigma_min`` or ``windows`` is given; () : none.

    The joint motions between consecutive waypoints are checked too
    (:func:`planning.toolpath.between.check_segments`): the windows and the σ_min floor along them,
    densely and by proof, and sign changes of the exact singular factors.

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
    if windows is not None:
        windows.check_robot(robot)
    if world is not None and world.chain != chain:
        raise ConfigurationError(f"the collision world is for {world.chain.name}, not {chain.name}")
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
    s = toolpath.s
    ik = continuous_ik(robot, toolpath, Pt, Rt, mode, start_q, branch_seed, bound, tol_position, tol_orientation,
                       max_iter, t0)
    Q, jump, step, prev, stats = ik.q, ik.jump, ik.step, ik.prev, ik.stats
    lo, hi = chain.lower, chain.upper

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

    clearance, collision, collision_check, coll_text = None, np.zeros(N, bool), None, {}
    if world is not None:
        clearance, collision, collision_check, coll_text = _collisions(world, Q, reachable)
    flags = {
        "unreachable": ~reachable,
        "branch_jump": jump & reachable,
        "limits": reachable & (limit_margin < limit_clearance - 1e-12),
        "window": reachable & (win >= 0),
        "sigma_min": reachable & (sig < sigma_min) if sigma_min is not None else np.zeros(N, bool),
        "speed": reachable & (speed_ratio > 1.0),
        "collision": collision,
    }
    first = None
    for k in KINDS:
        idx = np.nonzero(flags[k])[0]
        if len(idx) and (first is None or idx[0] < first[0]):
            first = (int(idx[0]), k)
    # ---- between the waypoints: the joint motions (planning.toolpath.between) ----------------------
    if factors is None:
        factors = floor_factors(robot) if (sigma_min is not None or windows is not None) else ()
    checkable = reachable[:-1] & reachable[1:] & ~jump[1:]
    clear = reachable & ~flags["window"] & ~flags["sigma_min"]
    segments, segments_check = check_segments(robot, Q, checkable, clear, windows, sigma_min, factors)
    problem = None
    if segments and (first is None or segments[0].index < first[0]):
        sp = segments[0]
        t_seg = None if toolpath.t is None else float(toolpath.t[sp.index])
        problem = Problem(sp.index, sp.kind, sp.detail, float(s[sp.index]), t_seg, toolpath.origin(sp.index),
                          segment=True, s_end=float(s[sp.index + 1]))
        first = None
    if first is not None:
        i, k = first
        detail = coll_text[i] if k == "collision" else \
            _detail(k, i, int(prev[i]), robot, Q, position_error, orientation_error, limit_margin, margins, sig,
                    sigma_min, win, windows, qd, vmax, step, bound, tol_position, tol_orientation,
                    limit_clearance, pose)
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
                          stats=stats, windows=windows, toolpath=toolpath, clearance=clearance,
                          collision_check=collision_check, segment_problems=segments,
                          segments_check=segments_check if (sigma_min is not None or windows is not None
                                                            or factors) else None)


def _collisions(world, Q: np.ndarray, reachable: np.ndarray):
    """Clearance per waypoint (NaN where unreachable), collision flags, how the motions between
    waypoints were decided, and the text of each flagged waypoint.  A motion from waypoint i to i + 1
    that is not proven clear flags waypoint i + 1 (the robot collides on its way there)."""
    N = len(Q)
    clearance = np.full(N, np.nan)
    flags = np.zeros(N, bool)
    text: dict[int, str] = {}
    if reachable.any():
        idx = np.flatnonzero(reachable)
        near = world.nearest(Q[idx])                 # the minimum and who gives it, in one pass
        clearance[idx] = near.clearance
        for k, i in enumerate(idx):
            if clearance[i] <= world.margin:
                flags[i] = True
                text[i] = "in collision: " + world.describe(int(near.body[k]), int(near.other[k]),
                                                            float(near.clearance[k]))
    check = "proven"
    # runs of consecutive reachable waypoints: their joint motions are proven one run at a time
    edges = np.flatnonzero(np.diff(np.concatenate([[0], reachable.astype(int), [0]])))
    for a, b in zip(edges[::2], edges[1::2]):
        if b - a < 2:
            continue
        proof = certify_collision(world, Q[a:b])
        v = proof.violation
        if v is not None and v.t > 0:
            i = a + v.segment + 1
            if not flags[i]:
                flags[i] = True
                text[i] = (f"in collision on the way from waypoint {i - 1} (at {v.t:.3f} of the joint motion): "
                           f"{v.text} (proven)")
        if proof.unproven:
            check = "sampled"
            for k in proof.unproven:
                i = a + k + 1
                if not flags[i]:
                    flags[i] = True
                    text[i] = (f"the joint motion from waypoint {i - 1} grazes the cell: not proven clear "
                               f"(clearance bound not settled)")
    return clearance, flags, check, text


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
        return f"inside singular window '{w.name}' ({at}σ_min = {sig[i]:.3g} SI)"
    if kind == "sigma_min":
        return f"σ_min = {sig[i]:.3g} < {sigma_min:.3g} (SI): too close to a singularity"
    if kind == "speed":
        with np.errstate(invalid="ignore"):
            r = np.where(np.isnan(vmax), -np.inf, np.abs(qd[i]) / np.where(np.isnan(vmax), 1.0, vmax))
        j = int(np.argmax(r))
        return (f"joint {j + 1} needs {jv(j, abs(qd[i, j]))}/s at the feed rate, {r[j]:.3g} × its maximum "
                f"{jv(j, vmax[j])}/s")
    raise RmtError(f"unknown problem kind {kind!r}")   # pragma: no cover
