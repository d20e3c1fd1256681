"""``rmt validate-toolpath``: follow a Cartesian tool path (CSV or TOML) with a continuous IK
solution and say whether the robot can do it — reachability, joint limits, singular windows, σ_min,
joint speeds at the feed rate, branch continuity.  Exit 0 when the path is valid, 1 when not, 2 on
bad input."""
from __future__ import annotations

import json
import math
from pathlib import Path

import numpy as np

import kin
from studies.cli.common import (
    bounded,
    cell_args,
    numbers,
    output_file,
    seed,
    window_width_args,
    windows_from_args,
    windows_label,
    world_from_args,
)
from studies.cli.floor import FloorChoice, floor_from_args, sigma_floor_args
from studies.taskrows import require_task_rows
from studies.toolpaths import bundled_toolpaths, toolpath_file
from studies.units import joint_units


def _positive(x: float | None, what: str) -> float | None:
    if x is not None and not (math.isfinite(x) and x > 0):
        raise kin.RmtError(f"{what} {x} must be a positive number")
    return x


def _windows(robot: kin.Robot, args):
    """Windows from --margin (file units), --sigma-min (SI threshold) or --windows FILE.json; or None."""
    from planning.windows import WindowSet
    if args.windows:
        ws = WindowSet.load(args.windows)
        if ws.n != robot.n:
            raise kin.RmtError(f"{args.windows}: windows for a {ws.n}-joint robot ({ws.robot}); {robot.name} has "
                               f"{robot.n} joints")
        return ws
    if args.sigma_min is not None:
        _positive(args.sigma_min, "--sigma-min")
    return windows_from_args(robot, args.margin, args.sigma_min)


def _per_joint(robot: kin.Robot, values, what: str) -> np.ndarray | None:
    """One value for every joint, or one per joint, in file units → SI (n,)."""
    if values is None:
        return None
    v = numbers(values, what)
    if len(v) not in (1, robot.n):
        raise kin.RmtError(f"{what}: give one value or {robot.n} (one per joint); got {len(v)}")
    arr = np.broadcast_to(np.array(v), (robot.n,))
    if np.any(arr <= 0):
        raise kin.RmtError(f"{what}: values must be > 0")
    return arr * robot.chain.variable_scale


def report_text(report, robot: kin.Robot, floor: FloorChoice | None = None, windows: str | None = None) -> str:
    """The verdict line, then a short table (robot file units; σ_min SI); ``floor``: the σ_min floor
    applied, ``windows``: the windows in words (:func:`windows_label`)."""
    c = robot.chain
    L, Lu, A, Au = c.length_scale, c.length_unit, c.angle_scale, c.angle_unit
    var = c.variable_scale
    units = joint_units(c)
    d = report.summary()
    N = report.n_waypoints
    dur = "" if report.t is None else f", {report.t[-1]:.4g} s"
    rows = [("path", f"{Path(report.source).name}: {N} waypoints, {report.s[-1] / L:.6g} {Lu}{dur} ({report.mode} IK)"),
            ("reachable", f"{d['reachable']} / {N}")]
    if d["max_position_error"] is not None:
        err = f"{d['max_position_error'] / L:.3g} {Lu}"
        if report.mode == "pose":
            err += f", orientation {d['max_orientation_error'] / A:.3g} {Au}"
        rows.append(("max IK error", err))
    if d["min_sigma"] is not None:
        rows.append(("min σ_min", f"{d['min_sigma']:.4g} (SI) at waypoint {d['min_sigma_index']}"))
        rows.append(("min manipulability",
                     f"{d['min_manipulability']:.4g} (SI) at waypoint {d['min_manipulability_index']}"))
    if floor is not None:
        rows.append(("σ_min floor", floor.text))
    if windows is not None:
        rows.append(("windows", windows))
    reach = report.reachable
    if reach.any():
        m = (np.minimum(report.q - c.lower, c.upper - report.q) / var)[reach]
        j = int(np.argmin(m.min(axis=0)))
        rows.append(("min limit margin", f"{m[:, j].min():.4g} {units[j]} (joint {j + 1})"))
    if d["max_joint_speed"] is not None:
        v = np.array(d["max_joint_speed"]) / var
        rows.append(("max joint speeds", ", ".join(f"q{j + 1} {v[j]:.3g} {units[j]}/s" for j in range(c.n))))
        rows.append(("max speed ratio", "n/a (no joint speed limits)" if d["max_speed_ratio"] is None
                     else f"{d['max_speed_ratio']:.3g} of the joints' maximum speeds"))
    else:
        rows.append(("joint speeds", "n/a (the path has no feed or times)"))
    if report.window_names:
        inside = {report.window_names[k]: int((report.window == k).sum()) for k in range(len(report.window_names))}
        rows.append(("in windows", ", ".join(f"{k}: {v}" for k, v in inside.items())))
    if d["min_clearance"] is not None:
        rows.append(("min clearance", f"{d['min_clearance'] * 1e3:.4g} mm at waypoint {d['min_clearance_index']}; "
                                      f"joint motions between waypoints {d['collision_check']}"))
    counts = ", ".join(f"{k} {v}" for k, v in report.counts.items() if v) or "none"
    rows.append(("problems", counts))
    if report.segments_check is not None:
        segs = ", ".join(f"{k} {v}" for k, v in report.segment_counts.items() if v) or "none"
        rows.append(("between waypoints", f"{segs} (joint motions checked: windows and floor "
                                          f"{report.segments_check}, sign changes of the exact singular factors)"))
    st = report.stats
    rows.append(("IK", f"{report.elapsed_s:.3g} s; {st.get('fk_jacobian_calls', 0)} FK+J evaluations, "
                       f"{st.get('global_solves', 0)} global solves"))
    w = max(len(k) for k, _ in rows)
    return "\n".join([report.verdict()] + [f"  {k:<{w}}  {v}" for k, v in rows])


def cmd_validate_toolpath(args, load_robot) -> int:
    from planning.toolpath import load_toolpath
    from planning.toolpath.check import validate_toolpath
    output_file(args.plot)
    robot = require_task_rows(load_robot(args.robot))
    c = robot.chain
    tp = load_toolpath(toolpath_file(args.toolpath), robot)
    ws = _windows(robot, args)
    from studies.cli.kinematics import configuration
    start = None if args.start is None else configuration(robot, args.start, "--start")
    floor = floor_from_args(robot, args, sigma_min=args.sigma_min)
    tol_p = _positive(args.tol_position, "--tol-position")
    tol_o = _positive(args.tol_orientation, "--tol-orientation")
    max_step = _per_joint(robot, args.max_step, "--max-step")
    max_speed = _per_joint(robot, args.max_speed, "--max-speed")
    world = world_from_args(robot, args)
    report = validate_toolpath(robot, tp, windows=ws, start_q=start, branch_seed=args.seed, sigma_min=floor.active,
                               tol_position=1e-6 if tol_p is None else tol_p * c.length_scale,
                               tol_orientation=1e-6 if tol_o is None else tol_o * c.angle_scale,
                               max_joint_step=max_step, max_speed=max_speed, world=world)
    if args.plot:
        from studies.plots.toolpath import plot_toolpath_report
        plot_toolpath_report(report, robot, args.plot)
    if args.json:
        from studies.study.toolpath import toolpath_json
        out = toolpath_json(report, robot, args.waypoints)
        out["sigma_floor"] = floor.to_dict()
        out["margin"] = args.margin
        print(json.dumps(out, allow_nan=False))
    else:
        print(report_text(report, robot, floor, None if args.windows else windows_label(c, args.margin,
                                                                                          args.sigma_min)))
        if args.plot:
            print(f"wrote {args.plot}")
    return 0 if report.ok else 1


def add_commands(add) -> None:
    """Register ``validate-toolpath`` with the CLI's ``add(name, func, help)`` helper."""
    sp = add("validate-toolpath", cmd_validate_toolpath,
             "follow a Cartesian tool path (CSV or TOML) with continuous IK and check it; exit 0 valid, 1 invalid")
    sp.add_argument("robot", metavar="ROBOT", help="bundled name or path to a robot .toml file")
    sp.add_argument("toolpath", metavar="TOOLPATH",
                    help="tool path: .csv (waypoints) or .toml (segments), in the robot file's units; or the name "
                         "of a bundled example (" + ", ".join(bundled_toolpaths()) + ")")
    g = window_width_args(sp, sigma_help="singular windows from a σ_min threshold (SI), and S as a σ_min floor")
    g.add_argument("--windows", metavar="FILE.json", help="singular windows saved by `rmt windows --out`")
    sigma_floor_args(sp, "fail where σ_min (SI) drops below S")
    sp.add_argument("--start", nargs="+", metavar="Q",
                    help="configuration to solve the first waypoint from (the start branch), file units")
    sp.add_argument("--seed", type=seed, default=0,
                    help="seed of the global IK (default 0; the windows do not depend on it)")
    sp.add_argument("--tol-position", type=bounded(0, math.inf, "(file length unit)", open_low=True), metavar="E",
                    help="reach tolerance, file length unit (default 1e-6 m)")
    sp.add_argument("--tol-orientation", type=bounded(0, math.inf, "(file angle unit)", open_low=True), metavar="E",
                    help="orientation tolerance, file angle unit (default 1e-6 rad)")
    sp.add_argument("--max-step", nargs="+", metavar="D",
                    help="largest joint change between waypoints before a branch jump, file units; one value or "
                         "one per joint (default 30° / 0.1 m)")
    sp.add_argument("--max-speed", nargs="+", metavar="V",
                    help="joint speed limits, file units/s; one value or one per joint (default: the robot file's)")
    cell_args(sp)
    sp.add_argument("--waypoints", action="store_true", help="with --json: include the per-waypoint arrays")
    sp.add_argument("--plot", metavar="FILE.png", help="write joint trajectories (windows shaded) and σ_min")
