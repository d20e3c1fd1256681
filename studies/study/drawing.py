"""The drawing task of the robotics homework (docs/machines.md §6), as the bundled study ``ur3_drawing``
runs it: a UR3-like arm with a pen draws a closed "D" in the y–z plane, starting at a singular pose —
the naive resolved-rate method, with the homework's Jacobian and with the correct one, against the
OSQP path follower of :mod:`planning.follow`.  Any other tool path is followed the same way, without
the task's closed forms, by ``rmt follow`` (:mod:`studies.study.follow`); the bundled tool path
``ur3_drawing`` is this drawing.

The task.  Pen on joint 6 (d6 = 0.1218 m), start q = (0, 0, 90°, −90°, 0, 0): θ5 = 0, a wrist
singularity.  The pen tip draws counter-clockwise in the plane x = x_start (seen from +x: y to the
right, z up), 5 segments of 4 s with 1000 points each at constant speed: a quarter circle (R = 0.05 m,
centre start − (0, 0, R)) from the top to its left point, 5 cm straight down, 10 cm along +y, 5 cm up,
and the other quarter circle back to the start.  The orientation is held at the start orientation.
Waypoint 0 is the start; segment k contributes its 1000 points after its own start (so waypoints
1000·k are the corners, 5001 in all, Δt = 4 ms, 20 s).

What the study finds (and reports as numbers):

* The singular direction at the start is a rotation about the base y axis (the tool's −x axis): the
  pen axis tilting in the base x–z plane.  It is *not* the rotation about the pen's own axis (the
  pen points along −x; rotation about it is available four times over, by joints 2, 3, 4 and 6 —
  the Jacobian's null space is a self-motion of those joints).
* On the start branch every waypoint of the drawing is singular: sin θ5 = 0 ⇔ the tool z axis is
  parallel to the joint-2 axis, whose direction depends on θ1 alone; with the pen axis held along −x
  and the tip moving in a plane x = const, the wrist-centre condition keeps θ1 (hence θ5 = 0)
  constant.  So in pose mode and in pen-axis (5-DOF) mode the path itself forces the wrist window for
  all 5001 waypoints — the follower confirms it: at every step its probe finds no configuration
  outside the window that meets the next target within the allowed slack of the tolerance.
  :func:`wrist_branches` shows it from the path alone (closed form from the pen tip and axis): the
  start branch has θ5 = 0 at every waypoint; the other shoulder solution (θ1 ≈ 150°) is not singular
  but is not reachable while the pen stays on the drawing.  Only position mode (the pen may tilt)
  leaves the window, within the first second.  Every method's result therefore carries, besides
  "within tolerance", its waypoints inside a window, their share and whether the path forces them
  (``forced_by_path``, ``verdict``) — "completes" alone would hide that the arm drew the whole figure
  at a singularity.
* The naive method q += J⁻¹·ẋ·Δt with the homework's Jacobian (joint axes z1…z6 instead of z0…z5)
  blows up.  With the correct Jacobian it does not: J is exactly singular at the start
  (``np.linalg.solve`` raises, the pseudo-inverse is used), then has a condition number ~1e19–1e20
  at every step, yet the desired twist lies in the range of J and the lost direction is never
  excited, so the open-loop method completes the drawing (drifting by ~17 µm).  The QP follower
  completes it within the tolerance too, with feedback and bounded joint speeds by construction.
"""
from __future__ import annotations

import dataclasses
import math
from collections.abc import Sequence

import numpy as np

import kin
from planning.follow import MODES, follow_path, resolved_rate, window_ranges
from planning.windows import WindowSet, build_windows

__all__ = ["PEN_D6", "START_Q", "pen_robot", "drawing_path", "homework_jacobian", "run_drawing_study",
           "drawing_windows", "wrist_branches"]

PEN_D6 = 0.1218                                           # m, the homework's pen
START_Q = (0.0, 0.0, math.pi / 2, -math.pi / 2, 0.0, 0.0)  # rad, the singular start pose
SEGMENTS = ("quarter circle to the left", "5 cm down", "10 cm along +y", "5 cm up", "quarter circle back")


def pen_robot() -> kin.Robot:
    """The UR3-like arm with the pen: bundled ``ur3_homework_pen`` when available, else
    ``ur3_homework`` with joint 6's d set to :data:`PEN_D6`."""
    if "ur3_homework_pen" in kin.bundled_robots():
        return kin.load_robot("ur3_homework_pen")
    chain = kin.load_chain("ur3_homework")
    joints = list(chain.joints)
    joints[-1] = dataclasses.replace(joints[-1], d=PEN_D6)
    return kin.Robot(dataclasses.replace(chain, name="ur3_homework_pen", joints=tuple(joints)))


def drawing_path(robot: kin.Robot, q0=START_Q, radius: float = 0.05, segment_time: float = 4.0,
                 points: int = 1000) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """The drawing as (poses (N, 4, 4), times (N,), segment index (N,)), N = 5·points + 1 (SI)."""
    T0 = robot.fk(np.asarray(q0, dtype=float))
    x0, y0, z0 = T0[:3, 3]
    c = np.array([y0, z0 - radius])            # centre of both quarter circles, in (y, z)
    u = np.arange(1, points + 1) / points      # each segment's own points after its start
    half = math.pi / 2
    segs = [c + radius * np.c_[np.cos(half + u * half), np.sin(half + u * half)],        # top → left
            np.c_[np.full(points, y0 - radius), z0 - radius - u * radius],                # down
            np.c_[y0 - radius + u * 2 * radius, np.full(points, z0 - 2 * radius)],        # along +y
            np.c_[np.full(points, y0 + radius), z0 - 2 * radius + u * radius],            # up
            c + radius * np.c_[np.cos(u * half), np.sin(u * half)]]                       # right → top
    yz = np.vstack([[y0, z0]] + segs)
    N = len(yz)
    poses = np.tile(T0, (N, 1, 1))
    poses[:, 0, 3] = x0
    poses[:, 1, 3] = yz[:, 0]
    poses[:, 2, 3] = yz[:, 1]
    times = np.arange(N) * (segment_time / points)
    seg = np.r_[0, np.repeat(np.arange(5), points)]
    return poses, times, seg


def homework_jacobian(robot: kin.Robot):
    """The homework's (wrong) Jacobian as a function q → (6, n): column i built from the axis z_i and
    origin o_i of frame i (i = 1…n) instead of z_{i−1}, o_{i−1} — [z_i × (o_n − o_i); z_i].  Standard
    DH, identity base and tool (as in the homework)."""
    chain = robot.chain
    if chain.convention != "standard" or not (chain.base.is_identity and chain.tool.is_identity):
        raise kin.ChainError("homework_jacobian reproduces a standard-DH chain with identity base and tool only")
    dh = chain.dh_table()          # rows (a, alpha, d, theta offset), SI
    revolute = chain.revolute_mask

    def jac(q: np.ndarray) -> np.ndarray:
        T = np.eye(4)
        frames = []
        for i, (a, al, d, th) in enumerate(dh):
            th = th + (q[i] if revolute[i] else 0.0)
            d = d + (0.0 if revolute[i] else q[i])
            ct, st, ca, sa = math.cos(th), math.sin(th), math.cos(al), math.sin(al)
            T = T @ np.array([[ct, -st * ca, st * sa, a * ct], [st, ct * ca, -ct * sa, a * st],
                              [0.0, sa, ca, d], [0.0, 0.0, 0.0, 1.0]])
            frames.append(T)
        on = frames[-1][:3, 3]
        J = np.zeros((6, len(dh)))
        for i, F in enumerate(frames):   # frame i+1: the homework's z_i, o_i with i = 1…n
            z, o = F[:3, 2], F[:3, 3]
            if revolute[i]:
                J[:3, i] = np.cross(z, on - o)
                J[3:, i] = z
            else:
                J[:3, i] = z
        return J

    return jac


def wrist_branches(robot: kin.Robot, poses: np.ndarray, margin: float, theta1_start: float = START_Q[0]) -> dict:
    """Why the drawing forces the wrist window, in closed form from the path alone (no follower).

    For the homework's arm (joints 2, 3, 4 with parallel axes, α2 = α3 = 0; α1, α4, α5 = ±π/2;
    a1 = a5 = a6 = 0, identity base and tool) the pen tip p and the pen axis z (tool z) fix θ1 and
    |sin θ5|: the wrist point w = p − d6·z lies at the distance D = d2 + d3 + d4 from the base along
    joint 2's axis z1(θ1) = sin α1·(sin t, −cos t, 0), t = θ1 + θ1's offset — two solutions
    t = ψ + asin(sin α1·D/r) and t = ψ + π − asin(sin α1·D/r) (ψ = atan2(w_y, w_x), r = |w_xy|) — and the pen
    axis makes the angle θ5 with z1's plane: |z1 · z| = |cos θ5|.  So sin θ5 = 0 ⇔ the pen axis is
    parallel to joint 2's axis.  The start branch is followed continuously from ``theta1_start``.

    Returns per branch the θ1 range (rad), max |sin θ5|, and the waypoints with |sin θ5| ≤ sin(margin)
    (inside a ±margin window around θ5 = 0 or π); this holds in pose and in pen-axis mode alike (only p
    and z enter)."""
    c = robot.chain
    J = c.joints
    tab = c.dh_table()                   # rows (a, alpha, d, theta offset), SI
    ok = (c.n == 6 and c.convention == "standard" and c.base.is_identity and c.tool.is_identity
          and all(j.is_revolute for j in J) and abs(tab[1, 1]) < 1e-12 and abs(tab[2, 1]) < 1e-12
          and abs(tab[5, 1]) < 1e-12 and all(abs(abs(tab[i, 1]) - math.pi / 2) < 1e-12 for i in (0, 3, 4))
          and all(abs(tab[i, 0]) < 1e-12 for i in (0, 4, 5)))
    if not ok:
        raise kin.ChainError(f"wrist_branches: {c.name} is not the homework arm's structure (6R, α2 = α3 = α6 = 0, "
                             "α1, α4, α5 = ±π/2, a1 = a5 = a6 = 0, identity base and tool)")
    s1, off1, d6, D = math.sin(tab[0, 1]), tab[0, 3], tab[5, 2], tab[1, 2] + tab[2, 2] + tab[3, 2]
    z = poses[:, :3, 2]
    w = poses[:, :3, 3] - d6 * z
    psi, r = np.arctan2(w[:, 1], w[:, 0]), np.hypot(w[:, 0], w[:, 1])
    a = np.arcsin(np.clip(s1 * D / r, -1.0, 1.0))
    sols = np.stack([psi + a - off1, psi + math.pi - a - off1], axis=1)
    sols = np.angle(np.exp(1j * sols))   # wrap to (−π, π]
    # the start branch: the solution nearest the start's θ1, then nearest the previous waypoint's
    pick = np.empty(len(poses), int)
    prev = theta1_start
    for k in range(len(poses)):
        pick[k] = int(np.argmin(np.abs(np.angle(np.exp(1j * (sols[k] - prev))))))
        prev = sols[k, pick[k]]
    out: dict = {"margin_rad": float(margin), "waypoints": int(len(poses))}
    for key, col in (("start_branch", pick), ("other_branch", 1 - pick)):
        th1 = sols[np.arange(len(poses)), col]
        z1 = s1 * np.stack([np.sin(th1 + off1), -np.cos(th1 + off1), np.zeros_like(th1)], axis=1)
        sin5 = np.sqrt(np.clip(1.0 - np.einsum("ij,ij->i", z1, z) ** 2, 0.0, 1.0))
        inside = sin5 <= math.sin(margin)
        out[key] = {"theta1_rad": [float(th1.min()), float(th1.max())],
                    "abs_sin_theta5": [float(sin5.min()), float(sin5.max())],
                    "waypoints_in_window": int(inside.sum()), "share_in_window": float(inside.mean())}
    sb = out["start_branch"]
    out["forced"] = sb["share_in_window"] == 1.0
    out["reason"] = (
        f"sin θ5 = 0 exactly when the pen axis is parallel to joint 2's axis, and that axis turns with θ1 alone; "
        f"the pen tip moves in a plane with the pen held along its normal, so the wrist point w = p − d6·z moves in "
        f"a parallel plane and θ1 stays at {round(math.degrees(sb['theta1_rad'][0]), 6) + 0.0:g}° "
        "on the start branch, the pen axis "
        f"parallel to joint 2's axis: θ5 = 0 at all {len(poses)} waypoints — the path itself lies on the wrist "
        f"singular set" if out["forced"] and np.ptp(sb["theta1_rad"]) < 1e-9 else
        f"on the start branch {sb['share_in_window']:.1%} of the waypoints have "
        f"|sin θ5| ≤ sin {math.degrees(margin):g}°")
    return out


def drawing_windows(robot: kin.Robot, margin: float = math.radians(5.0)) -> WindowSet:
    """Windows of half-width ``margin`` (rad) around every singular factor of the pen arm."""
    return build_windows(robot, margin=margin)


def _start_analysis(robot: kin.Robot, q0: np.ndarray) -> dict:
    T, J = robot.fk_jacobian(q0)
    U, S, Vt = np.linalg.svd(J)
    u = U[:, -1] * (1.0 if U[4, -1] >= 0 else -1.0)     # sign: make the ωy component positive
    z_tool = T[:3, 2]
    with np.errstate(divide="ignore"):
        cond = float(S[0] / S[-1]) if S[-1] > 0 else math.inf
    return {"q_deg": np.degrees(q0).tolist(), "position": T[:3, 3].tolist(), "pen_axis": z_tool.tolist(),
            "singular_values": S.tolist(), "sigma_min": float(S[-1]), "condition": cond,
            "lost_twist": u.tolist(),
            "lost_rotation_about_pen_axis": float(abs(u[3:] @ z_tool)),
            "lost_rotation_in_tool_frame": (T[:3, :3].T @ u[3:]).tolist(),
            "self_motion": (Vt[-1] * np.sign(Vt[-1][np.argmax(np.abs(Vt[-1]))])).tolist()}


def run_drawing_study(robot: kin.Robot | None = None, windows: WindowSet | None = None,
                      window_margin: float = math.radians(5.0),
                      tolerance: tuple[float, float] = (1e-3, math.radians(1.0)),
                      modes: Sequence[str] = MODES, series: bool = False) -> dict:
    """Run the drawing comparison and return its results (SI units; JSON-friendly except ``series``).

    ``robot``: the pen arm (default :func:`pen_robot`); ``windows``: singular windows (default: half-width
    ``window_margin`` around every factor); ``tolerance``: (position m, orientation rad) a method must
    stay within to complete the drawing; ``modes``: the QP follower's task modes to run; ``series``:
    also return the time series (numpy arrays, for plots) under ``"series"``.
    """
    robot = robot or pen_robot()
    for m in modes:
        if m not in MODES:
            raise kin.RmtError(f"mode {m!r} unknown; allowed: {', '.join(MODES)}")
    q0 = np.array(START_Q)
    poses, times, seg = drawing_path(robot, q0)
    dt = float(times[1] - times[0])
    ws = windows if windows is not None else drawing_windows(robot, window_margin)
    out: dict = {"robot": robot.name, "pen_d6_m": float(robot.chain.resolve(robot.chain.joints[-1].d)),
                 "path": {"waypoints": int(len(poses)), "segments": list(SEGMENTS), "points_per_segment": 1000,
                          "segment_time_s": 4.0, "dt_s": dt, "duration_s": float(times[-1]),
                          "radius_m": 0.05, "plane": f"x = {poses[0, 0, 3]:.6g} m (y–z plane)",
                          "corners": [int(i) for i in np.flatnonzero(np.diff(seg)) + 1]},
                 "start": _start_analysis(robot, q0),
                 "tolerance": {"position_m": tolerance[0], "orientation_rad": tolerance[1],
                               "orientation_deg": math.degrees(tolerance[1])},
                 "windows": [{"index": i, "name": w.name, "kind": w.kind, "joints": list(w.joints),
                              "half_width": w.width,
                              **({"intervals": [list(iv) for iv in w.intervals]} if w.is_interval
                                 else {"epsilon": w.epsilon})} for i, w in enumerate(ws.windows)]}
    wrist = next((w for w in ws.windows if w.kind == "wrist" and getattr(w, "is_interval", False)), None)
    try:
        out["forced_by_path"] = wrist_branches(robot, poses, wrist.width if wrist is not None else window_margin)
    except kin.ChainError:      # not the homework arm's structure: the closed form does not apply
        out["forced_by_path"] = None
    names = [w.name for w in ws.windows]
    # the naive method, as the homework wrote it, and with the correct Jacobian
    naive_hw = resolved_rate(robot, (poses, times), q0, jacobian=homework_jacobian(robot))
    naive = resolved_rate(robot, (poses, times), q0)
    sigma = {}
    for key, res, label in (("naive_homework", naive_hw, "homework Jacobian (axes z1…z6)"),
                            ("naive", naive, "correct Jacobian (axes z0…z5)")):
        d = res.summary()
        d["jacobian"] = label
        d["task"] = "pose"
        d["within_tolerance"] = bool(res.max_tracking_error <= tolerance[0]
                                     and res.max_orientation_error <= tolerance[1])
        d["max_abs_q5_rad"] = float(np.nanmax(np.abs(res.q[:, 4])))
        sigma[key] = np.full(len(res.q), np.nan)
        finite = np.all(np.isfinite(res.q), axis=1)
        sigma[key][finite] = robot.sigma_min(res.q[finite])
        d["min_sigma"] = float(np.nanmin(sigma[key]))
        in_w = ws.which(np.nan_to_num(res.q, nan=np.inf)) if ws.windows else np.full(len(res.q), -1)
        d["windows_entered"] = window_ranges(in_w, names)
        d.update(_window_share(in_w))
        out[key] = d
    qp = {}
    results = {}
    for m in modes:
        fr = follow_path(robot, (poses, times), q0, ws, mode=m, tolerance=tolerance)
        results[m] = fr
        d = fr.summary()
        d["task"] = m
        d["max_abs_q5_rad"] = float(np.abs(fr.q[:, 4]).max())
        d["max_abs_q1_rad"] = float(np.abs(fr.q[:, 0]).max())
        d["pen_tilt_max_rad"] = float(fr.axis_error.max())
        d.update(_window_share(fr.in_window))
        qp[m] = d
    out["qp"] = qp
    for d in (out["naive_homework"], out["naive"], *qp.values()):
        d["forced_by_path"], d["verdict"] = _verdict(d, out)
    ref = "pose" if "pose" in qp else (modes[0] if modes else None)
    if ref is not None:
        p = qp[ref]["peak_joint_speed"]
        out["comparison"] = {
            "reference_mode": ref,
            "naive_homework_peak_over_qp": naive_hw.peak_joint_speed / p if p > 0 else math.inf,
            "naive_peak_over_qp": naive.peak_joint_speed / p if p > 0 else math.inf,
            "naive_homework_error_over_qp": naive_hw.max_tracking_error / max(qp[ref]["max_position_error_m"], 1e-300),
        }
    out["explanation"] = _explanation(out)
    if series:
        out["series"] = {"t": times, "segment": seg,
                         "naive_homework": {"q": naive_hw.q, "joint_speed": naive_hw.joint_speed,
                                            "position_error": naive_hw.position_error,
                                            "sigma_min": sigma["naive_homework"]},
                         "naive": {"q": naive.q, "joint_speed": naive.joint_speed,
                                   "position_error": naive.position_error, "sigma_min": sigma["naive"]},
                         **{f"qp_{m}": {"q": r.q, "joint_speed": r.joint_speed, "position_error": r.position_error,
                                        "orientation_error": r.orientation_error, "axis_error": r.axis_error,
                                        "in_window": r.in_window, "sigma_min": r.sigma_min}
                            for m, r in results.items()}}
    return out


def _window_share(in_window: np.ndarray) -> dict:
    """Waypoints inside any window and their share of the path."""
    inside = np.asarray(in_window) >= 0
    return {"waypoints_in_window": int(inside.sum()), "share_in_window": float(inside.mean())}


def _ranges_text(d: dict) -> str:
    return "; ".join(", ".join(f"{a}–{b}" for a, b in w["ranges"]) for w in d["windows_entered"]) or "none"


def _verdict(d: dict, out: dict) -> tuple[bool | None, str]:
    """(forced by the path?, one plain line): tolerance met or not, and where the method was inside a
    window — with whether the path forces it.  The drawing forces the wrist window only where the task
    holds the pen axis (pose and pen-axis modes, and the naive method, which tracks the full pose) and
    the closed form (:func:`wrist_branches`) puts every waypoint of the start branch in the window."""
    tol = out["tolerance"]
    n = out["path"]["waypoints"]
    if not d["within_tolerance"]:
        return None, (f"fails: tracking error up to {d['max_position_error_m']:.3g} m (tolerance "
                      f"{tol['position_m'] * 1e3:g} mm); in a window at {d['waypoints_in_window']}/{n} waypoints")
    held = d["task"] in ("pose", "axis")
    fb = out["forced_by_path"]
    forced = None if fb is None and held else bool(held and fb["forced"])
    done = "drawing within tolerance" + ("" if held else " (pen axis free)")
    k = d["waypoints_in_window"]
    if k == 0:
        where = "never in a window"
    elif k == n:
        where = f"inside the wrist window at all {n} waypoints"
    else:
        where = f"in a window at {k}/{n} waypoints ({100 * k / n:.3g} %: {_ranges_text(d)})"
    why = (" — forced by the path (θ5 = 0 at every waypoint)" if forced else
           " — not forced (the pen may tilt)" if not held and k else
           " — whether the path forces it is not determined (not the homework arm)" if forced is None and k else "")
    return forced, f"{done}; {where}{why}"


def _explanation(out: dict) -> list[str]:
    """Sentences for the report, each stating what the numbers above show."""
    st = out["start"]
    u = np.asarray(st["lost_twist"])
    names = ("vx", "vy", "vz", "ωx", "ωy", "ωz")
    what = (f"a pure {names[int(np.argmax(np.abs(u)))]}" if np.abs(u).max() > 0.99 else
            "the twist (" + ", ".join(f"{x:.3g}" for x in np.round(u, 3) + 0.0) + ")")
    lines = [
        (f"The start pose is singular: σ_min(J) = {st['sigma_min']:.3g} (θ5 = 0). The lost twist is {what} (base "
         f"frame; ({', '.join(f'{x:.3g}' for x in np.round(st['lost_rotation_in_tool_frame'], 6) + 0.0)}) in the tool "
         "frame): the pen axis tilting. "
         f"Its component along the pen axis is {st['lost_rotation_about_pen_axis']:.3g}: rotation about the pen's "
         "own axis is not the lost direction — it stays available (the Jacobian's null space is a self-motion of "
         f"joints {', '.join(str(j + 1) for j in np.flatnonzero(np.abs(st['self_motion']) > 1e-9))}), so freeing "
         "it (5-DOF 'axis' mode) does not remove the singularity."),
    ]
    n_steps = out["path"]["waypoints"] - 1
    forced = [m for m in ("pose", "axis") if m in out.get("qp", {}) and out["qp"][m]["forced_steps"] == n_steps]
    if forced:
        lines.append(
            f"{' and '.join(forced).capitalize()} mode: forced into the wrist window at all {n_steps} steps — with "
            "the pen axis held and the tip in a plane x = const, θ1 and θ5 = 0 stay constant on the start branch, "
            "so every waypoint is singular; at every step the follower's probe found no configuration outside the "
            "window that meets the next target within 10 % of the tolerance.")
    fb = out.get("forced_by_path")
    if fb:
        sb, ob = fb["start_branch"], fb["other_branch"]
        lines.append(
            f"The path alone says so, without any follower (closed form from the pen tip and the pen axis): "
            f"{fb['reason']}. The start branch has "
            + ("|sin θ5| < 1e-12" if sb["abs_sin_theta5"][1] < 1e-12 else f"|sin θ5| ≤ {sb['abs_sin_theta5'][1]:.2g}")
            + f" and lies in the "
            f"±{math.degrees(fb['margin_rad']):g}° wrist window at {sb['waypoints_in_window']}/{fb['waypoints']} "
            f"waypoints. The arm's other shoulder solution (θ1 = {math.degrees(ob['theta1_rad'][0]):.0f}°…"
            f"{math.degrees(ob['theta1_rad'][1]):.0f}°, |θ5| = {math.degrees(math.asin(ob['abs_sin_theta5'][0])):.0f}°…"
            f"{math.degrees(math.asin(ob['abs_sin_theta5'][1])):.0f}°) is not singular, but it is another inverse-"
            "kinematics solution with joint 1 turned that far: no motion that keeps the pen on the drawing reaches it.")
    if "position" in out.get("qp", {}):
        d = out["qp"]["position"]
        wr = d["windows_entered"]
        last = max((r[1] for w in wr for r in w["ranges"]), default=-1)
        stays = "and stays out" if sum(len(w["ranges"]) for w in wr) == 1 else "(and re-enters later)"
        lines.append(f"Position mode, where the pen may tilt, is not forced: it climbs out of the wrist window by "
                     f"waypoint {last + 1} ({(last + 1) * out['path']['dt_s']:.3g} s) {stays}, tilting the pen by "
                     f"up to {math.degrees(d['pen_tilt_max_rad']):.3g}° — more than the "
                     f"{out['tolerance']['orientation_deg']:g}° orientation tolerance, which is why pose (or pen-axis) "
                     "mode is the reference here.")
    nh, nv = out["naive_homework"], out["naive"]
    done = ("still fails the tolerance" if not nv["within_tolerance"] else
            "draws within tolerance" + (f" inside the wrist window at all {nv['waypoints_in_window']} waypoints, like "
                                       "the follower in pose mode" if nv.get("forced_by_path") else ""))
    lines.append(f"The homework's naive method (J⁻¹ with axes z1…z6) reaches {nh['peak_joint_speed']:.3g} rad/s and a "
                 f"{nh['max_position_error_m']:.3g} m error. With the correct Jacobian the same method needs the "
                 f"pseudo-inverse at {nv['pinv_steps']} step(s) (where J is exactly singular and has no inverse), "
                 "then runs at "
                 f"condition numbers up to {nv['max_finite_condition']:.3g} and {done} "
                 f"({nv['max_position_error_m']:.3g} m open-loop drift, peak {nv['peak_joint_speed']:.3g} rad/s): the "
                 "desired twist lies in the range of J and never asks for the lost direction.")
    return lines
