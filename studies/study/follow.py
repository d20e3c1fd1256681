"""Following a tool path as ``rmt follow`` does, for any robot and path: the OSQP follower
(:func:`planning.follow.follow_path`) and, for comparison, the naive resolved-rate method
(:func:`planning.follow.resolved_rate`) on the same task, each summed up the same way — peak joint
speed, largest position and orientation errors, within tolerance or not, and the waypoints spent
inside a singular window.

* :func:`default_mode` — the task a path asks of a robot: pose when the path gives orientations and
  the robot controls all six rows, position otherwise (as :func:`planning.toolpath.validate_toolpath`
  decides it); :func:`check_mode` refuses a mode the path or the robot cannot serve.
* :func:`start_configuration` — a start for the path: IK of its first waypoint.
* :func:`follow_toolpath` — run the methods and sum them up: a :class:`FollowComparison` of
  :class:`MethodRun` (SI), which :meth:`FollowComparison.to_json` gives in the robot file's units.
* :func:`solver_output_silenced` — keep a solver's C-level printing off standard output while it runs.

Everything is SI inside (m, rad, s); σ_min is that of the SI task Jacobian.

    import kin
    from planning.toolpath import load_toolpath
    from studies.toolpaths import toolpath_file
    from studies.study.follow import follow_toolpath, start_configuration

    robot = kin.load_robot("scara_rrp")
    path = load_toolpath(toolpath_file("scara_line"), robot)
    q0, start = start_configuration(robot, path.poses[0], "position")
    comparison = follow_toolpath(robot, path, q0, mode="position", tolerance=(5e-3, 0.01), naive=True, start=start)
    assert comparison.ok                                  # the follower within 5 mm at every waypoint
    comparison.to_json()["methods"]["naive"]["max_position_error"]      # ≈ 15.9 (mm, the file's unit)
"""
from __future__ import annotations

import ctypes
import math
import os
import sys
from contextlib import contextmanager
from dataclasses import dataclass, field
from pathlib import Path

import numpy as np

import kin
from studies.jsonio import finite_or_none, jsonable
from studies.units import joint_units, unit_names

__all__ = ["DEFAULT_TOLERANCE", "MODES", "MethodRun", "FollowComparison", "default_mode", "check_mode",
           "start_configuration", "follow_toolpath", "solver_output_silenced"]

#: the followers' task modes (:data:`planning.follow.MODES`; repeated here so that naming them does
#: not import OSQP — a test keeps the two equal)
MODES = ("pose", "axis", "position")
#: (position m, orientation rad) a method must stay within at every waypoint: the follower's default
DEFAULT_TOLERANCE = (1e-3, math.radians(1.0))


# ---- the task and the start ---------------------------------------------------------------------------
def _orientation_rows(robot: kin.Robot) -> bool:
    return any(r >= 3 for r in robot.task_rows)


def default_mode(robot: kin.Robot, has_orientation: bool) -> str:
    """``"pose"`` when the path gives orientations and the robot controls all six task rows,
    ``"position"`` otherwise."""
    return "pose" if has_orientation and len(robot.task_rows) == 6 else "position"


def check_mode(robot: kin.Robot, mode: str, has_orientation: bool, what: str = "mode") -> str:
    """``mode`` if the path and the robot can serve it, else :class:`kin.ChainError` naming ``what``:
    pose and axis mode need a path with orientations and a robot that controls its tool's orientation."""
    if mode not in MODES:
        raise kin.ChainError(f"{what} {mode!r} unknown; allowed: {', '.join(MODES)}")
    if mode != "position" and not has_orientation:
        raise kin.ChainError(f"{what} {mode}: the tool path gives positions only (no orientation to follow); "
                             "use position mode")
    if mode != "position" and not _orientation_rows(robot):
        rows = ", ".join(("x", "y", "z", "rx", "ry", "rz")[r] for r in robot.task_rows)
        raise kin.ChainError(f"{what} {mode}: {robot.name} controls no tool orientation (task rows {rows}); "
                             "use position mode")
    return mode


def start_configuration(robot: kin.Robot, pose: np.ndarray, mode: str, seed: int = 0) -> tuple[np.ndarray, dict]:
    """A start for a path whose first target is ``pose`` (4, 4), SI: the IK solution (seeded random
    starts, :meth:`kin.Robot.ik`) in position mode for a position task, else in pose mode.  Returns
    ``(q0, info)`` with ``info``: ``from`` ("IK of waypoint 0"), ``success``, ``position_error`` (m),
    ``orientation_error`` (rad).  When IK finds no solution, q0 is the best configuration it found —
    the follower starts from there and its errors say how far off that is."""
    res = robot.ik(np.asarray(pose, dtype=float), seed=seed, mode="position" if mode == "position" else "pose")
    q0 = np.clip(np.asarray(res.q, dtype=float), robot.chain.lower, robot.chain.upper)
    return q0, {"from": "IK of waypoint 0", "success": bool(res.success),
                "position_error": float(res.position_error), "orientation_error": float(res.orientation_error)}


# ---- the runs -----------------------------------------------------------------------------------------
@dataclass
class MethodRun:
    """One method on the path: ``key`` ("qp" or "naive"), ``label``, its ``result``
    (:class:`~planning.follow.FollowResult` or :class:`~planning.follow.ResolvedRateResult`),
    per waypoint the window it is inside (``in_window``, −1 for none) and σ_min of the task
    Jacobian (NaN where the configuration is not finite), and its ``summary`` (SI):

    ``method``, ``mode``, ``within_tolerance``, ``peak_joint_speed`` (the largest joint speed, in its
    joint's unit/s) of ``peak_joint`` (1-based: the joint that comes nearest to, or furthest over,
    its speed limit), ``max_joint_speed`` (n,), ``max_speed_ratio`` (speed over the joint's limit),
    ``max_position_error`` (m; over the waypoints reached when the method diverged),
    ``max_orientation_error`` (rad: the full angle in pose mode, the tool-axis angle in axis mode, None
    in position mode), ``waypoints_in_window``,
    ``share_in_window``, ``windows_entered`` (``[{"window", "name", "ranges", "waypoints"}]``),
    ``min_sigma``; the follower also ``forced_steps`` (steps forced into a window: no configuration
    outside it met the next waypoint) and ``qp_status``; the naive method ``pinv_steps``,
    ``first_pinv_steps``, ``max_finite_condition`` and ``diverged_at``.
    """

    key: str
    label: str
    result: object
    in_window: np.ndarray
    sigma_min: np.ndarray
    summary: dict = field(default_factory=dict)


@dataclass
class FollowComparison:
    """The methods run on one path from one start (SI): ``robot``, the ``path`` followed (a
    :class:`~planning.toolpath.ToolPath` or ``(poses, times)``), ``mode``, ``q0`` with ``start``
    (where it came from), ``tolerance`` (m, rad), the ``windows`` (a WindowSet or None) and the
    ``runs`` — the follower first.  ``ok``: the follower stayed within tolerance.  ``source``: the
    tool path's file name, ``length``: its arc length (m), when known."""

    robot: kin.Robot
    poses: np.ndarray
    times: np.ndarray
    mode: str
    q0: np.ndarray
    start: dict
    tolerance: tuple[float, float]
    windows: object
    runs: list[MethodRun]
    source: str = ""
    length: float | None = None

    @property
    def ok(self) -> bool:
        return bool(self.runs[0].summary["within_tolerance"])

    def run(self, key: str) -> MethodRun | None:
        return next((r for r in self.runs if r.key == key), None)

    def to_json(self, waypoints: bool = False) -> dict:
        """The comparison as a JSON-ready dict in the robot file's units (σ_min stays SI; joint
        speeds per joint in file units/s); with ``waypoints`` each method's per-waypoint arrays
        (``t``, ``q``, ``position_error``, ``orientation_error``, ``axis_error``, ``in_window``)."""
        c = self.robot.chain
        L, A, var = c.length_scale, c.angle_scale, c.variable_scale
        methods = {}
        for r in self.runs:
            s = r.summary
            m = {"method": s["method"], "mode": s["mode"], "within_tolerance": s["within_tolerance"],
                 "peak_joint_speed": s["peak_joint_speed"] / var[s["peak_joint"] - 1] if s["peak_joint"] else None,
                 "peak_joint": s["peak_joint"],
                 "max_joint_speed": [finite_or_none(v) for v in np.asarray(s["max_joint_speed"]) / var],
                 "max_speed_ratio": s["max_speed_ratio"],
                 "max_position_error": s["max_position_error"] / L,
                 "max_orientation_error": (None if s["max_orientation_error"] is None
                                           else s["max_orientation_error"] / A),
                 "waypoints_in_window": s["waypoints_in_window"], "share_in_window": s["share_in_window"],
                 "windows_entered": s["windows_entered"], "min_sigma": s["min_sigma"]}
            for k in ("forced_steps", "qp_status", "pinv_steps", "first_pinv_steps", "max_finite_condition",
                      "diverged_at"):
                if k in s:
                    m[k] = s[k]
            if waypoints:
                res = r.result
                m["per_waypoint"] = {"t": res.t, "q": res.q / var, "position_error": res.position_error / L,
                                     "orientation_error": res.orientation_error / A,
                                     "axis_error": res.axis_error / A, "in_window": r.in_window}
            methods[r.key] = m
        ws = self.windows.windows if self.windows is not None else []
        start = {"q": self.q0 / var, **self.start}
        if "position_error" in start:
            start["position_error"] /= L
        if "orientation_error" in start:
            start["orientation_error"] /= A
        out = {"ok": self.ok, "robot": self.robot.name, "toolpath": self.source, "mode": self.mode,
               "waypoints": int(len(self.poses)), "duration": float(self.times[-1] - self.times[0]),
               "length": None if self.length is None else self.length / L, "start": start,
               "tolerance": {"position": self.tolerance[0] / L, "orientation": self.tolerance[1] / A},
               "windows": [w.name for w in ws],
               "methods": methods,
               "units": {**unit_names(c), "joints": joint_units(c), "time": "s", "sigma_min": "SI",
                         "max_joint_speed": "per joint, file units / s",
                         "peak_joint_speed": "the peak joint's unit / s",
                         "max_speed_ratio": "joint speed / the joint's speed limit"}}
        return jsonable(out)


def _summary(robot: kin.Robot, key: str, res, in_window: np.ndarray, sigma: np.ndarray, names: list[str],
             tolerance: tuple[float, float], v_max: np.ndarray) -> dict:
    from planning.follow import window_ranges
    finite = np.all(np.isfinite(res.q), axis=1)
    with np.errstate(invalid="ignore"):
        per_joint = np.array([np.nanmax(c) if np.isfinite(c).any() else math.inf for c in res.joint_speed.T])
    ratio = per_joint / v_max
    peak = int(np.argmax(np.where(np.isnan(ratio), -np.inf, ratio))) + 1 if per_joint.size else None
    orient = None if res.mode == "position" else res.max_orientation_error
    # a method that diverged (non-finite joints from some waypoint on) did not follow the path
    within = bool(finite.all() and res.max_tracking_error <= tolerance[0]
                  and (orient is None or orient <= tolerance[1]))
    inside = in_window >= 0
    out = {"method": "QP follower (OSQP)" if key == "qp" else "naive resolved rate", "mode": res.mode,
           "within_tolerance": within,
           "peak_joint_speed": float(per_joint[peak - 1]) if peak else 0.0, "peak_joint": peak,
           "max_joint_speed": per_joint.tolist(), "max_speed_ratio": float(np.max(ratio)) if ratio.size else 0.0,
           "max_position_error": res.max_tracking_error, "max_orientation_error": orient,
           "waypoints_in_window": int(inside.sum()), "share_in_window": float(inside.mean()),
           "windows_entered": window_ranges(in_window, names),
           "min_sigma": float(np.nanmin(sigma)) if np.isfinite(sigma).any() else None}
    if key == "qp":
        out.update(forced_steps=int(res.forced.sum()), qp_status=dict(res.qp_status))
    else:
        d = res.summary()
        out.update({k: d[k] for k in ("pinv_steps", "first_pinv_steps", "max_finite_condition", "diverged_at")})
    return out


def follow_toolpath(robot: kin.Robot, path, q0, windows=None, mode: str = "pose",
                    tolerance: tuple[float, float] = DEFAULT_TOLERANCE, naive: bool = False,
                    start: dict | None = None) -> FollowComparison:
    """Follow ``path`` (a :class:`~planning.toolpath.ToolPath` with times, or ``(poses, times)``, SI)
    from ``q0`` with the OSQP follower in ``mode``, keeping out of ``windows`` (a
    :class:`~planning.windows.WindowSet` or None) unless the path forces it in, and with ``naive``
    also with the naive resolved-rate method on the same task (no windows, no limits: it goes where
    J⁻¹ takes it).  Each method is summed up as :class:`MethodRun` describes; solver output stays
    off standard output.  ``start`` says where ``q0`` came from (kept in the comparison as is;
    default ``{"from": "given"}``)."""
    from planning.follow import FollowError, follow_path, joint_velocity_limits, resolved_rate
    poses = np.asarray(path.poses if hasattr(path, "poses") else path[0], dtype=float)
    times = path.t if hasattr(path, "poses") else path[1]
    if times is None:
        raise FollowError(f"{getattr(path, 'source', 'the tool path')}: the path has no times (give the file a "
                          "feed, durations or times)")
    times = np.asarray(times, dtype=float)
    q0 = np.asarray(q0, dtype=float)
    names = [w.name for w in windows.windows] if windows is not None else []
    v_max = joint_velocity_limits(robot)

    def which(Q):
        if not names:
            return np.full(len(Q), -1)
        return windows.which(np.nan_to_num(Q, nan=np.inf))

    def sigma(Q):
        s = np.full(len(Q), np.nan)
        ok = np.all(np.isfinite(Q), axis=1)
        if ok.any():
            s[ok] = robot.sigma_min(Q[ok])
        return s

    runs = []
    with solver_output_silenced():
        fr = follow_path(robot, (poses, times), q0, windows, mode=mode, tolerance=tolerance)
    runs.append(MethodRun("qp", "QP follower", fr, fr.in_window, np.asarray(fr.sigma_min, float)))
    if naive:
        with np.errstate(all="ignore"):
            nr = resolved_rate(robot, (poses, times), q0, mode=mode)
        runs.append(MethodRun("naive", "naive resolved rate", nr, which(nr.q), sigma(nr.q)))
    for r in runs:
        r.summary = _summary(robot, r.key, r.result, r.in_window, r.sigma_min, names, tolerance, v_max)
    length = float(path.s[-1]) if hasattr(path, "s") else None
    source = Path(path.source).name if getattr(path, "source", "") else ""
    return FollowComparison(robot=robot, poses=poses, times=times, mode=mode, q0=q0,
                            start=dict(start) if start is not None else {"from": "given"}, tolerance=tolerance,
                            windows=windows if names else None, runs=runs, source=source, length=length)


# ---- solver output ------------------------------------------------------------------------------------
@contextmanager
def solver_output_silenced():
    """Route file descriptor 1 to /dev/null while solvers run: OSQP's C library prints its own errors
    with printf, and they must never reach a command's standard output (its answer).  Nothing in
    the computation prints on purpose (only ``studies`` prints, after it)."""
    sys.stdout.flush()
    try:
        saved = os.dup(1)
        devnull = os.open(os.devnull, os.O_WRONLY)
    except OSError:
        yield
        return
    try:
        os.dup2(devnull, 1)
        yield
    finally:
        try:
            _libc_flush()
        finally:
            os.dup2(saved, 1)
            os.close(saved)
            os.close(devnull)


def _libc_flush() -> None:
    """Flush C's stdout buffer (what printf wrote but has not passed to the descriptor yet)."""
    try:
        ctypes.CDLL(None).fflush(None)
    except (OSError, AttributeError):
        pass
