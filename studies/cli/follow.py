"""``rmt follow``: follow a Cartesian tool path (CSV or TOML, or a bundled one) with the OSQP path
follower and, with ``--naive``, with the naive resolved-rate method for comparison; per method the
peak joint speed, the largest position and orientation errors, whether it stayed within tolerance
and the waypoints it spent inside a singular window (:mod:`studies.study.follow`).  Exit 0 when the
follower stays within tolerance, 1 when not, 2 on bad input."""
from __future__ import annotations

import math

from studies.cli.common import (
    EXIT_FAIL,
    EXIT_OK,
    CliInputError,
    bounded,
    output_file,
    sampled_windows_note,
    window_width_args,
    windows_from_args,
)
from studies.jsonio import dump
from studies.taskrows import require_task_rows
from studies.toolpaths import bundled_toolpaths, toolpath_file
from studies.units import joint_units

#: the followers' task modes (planning.follow.MODES, listed here so that registering the command
#: does not import OSQP; a test keeps the two equal)
MODES = ("pose", "axis", "position")


def _fmt(x: float | None, unit: str = "") -> str:
    if x is None:
        return "—"
    if not math.isfinite(x):
        return "inf" if x > 0 else "nan"
    return f"{x:.3g}" + (f" {unit}" if unit else "")


def follow_text(comparison) -> str:
    """The verdict line, what was followed, then one column per method (robot file units)."""
    robot = comparison.robot
    c = robot.chain
    L, A, Lu, Au = c.length_scale, c.angle_scale, c.length_unit, c.angle_unit
    var, units = c.variable_scale, joint_units(c)
    qp = comparison.runs[0].summary
    tol = f"{comparison.tolerance[0] / L:g} {Lu}" + (
        "" if comparison.mode == "position" else f", {comparison.tolerance[1] / A:g} {Au}")
    verdict = ("the QP follower stays within tolerance" if qp["within_tolerance"] else
               f"the QP follower leaves the tolerance ({tol})")
    length = "" if comparison.length is None else f", {comparison.length / L:.4g} {Lu}"
    head = (f"{robot.name} following {comparison.source or 'the tool path'} ({len(comparison.poses)} waypoints"
            f"{length}, {comparison.times[-1] - comparison.times[0]:.4g} s), {comparison.mode} mode: {verdict}")
    st = comparison.start
    q0 = comparison.q0 / var
    q0 = (f"({', '.join(f'{v:.6g}' for v in q0)}) {units[0]}" if len(set(units)) == 1 else
          "(" + ", ".join(f"{v:.6g} {u}" for v, u in zip(q0, units)) + ")")
    how = st.get("from", "given")
    if "position_error" in st:
        how += f", error {st['position_error'] / L:.3g} {Lu}" + ("" if st.get("success", True) else ": no IK solution")
    ws = comparison.windows.windows if comparison.windows is not None else []
    info = [("start", f"q = {q0} ({how})"), ("tolerance", tol),
            ("windows", ", ".join(w.name for w in ws) if ws else "none (give --margin or --sigma-min)")]
    w = max(len(k) for k, _ in info)
    lines = [head] + [f"  {k:<{w}}  {v}" for k, v in info] + [""]

    cols = [r.label for r in comparison.runs]
    rows = []
    n = len(comparison.poses)
    for name, get in (
            ("within tolerance", lambda s: "yes" if s["within_tolerance"] else "no"),
            ("peak joint speed", lambda s: (f"{_fmt(s['peak_joint_speed'] / var[s['peak_joint'] - 1])} "
                                            f"{units[s['peak_joint'] - 1]}/s (q{s['peak_joint']})")
             if s["peak_joint"] else "0"),
            ("max speed / limit", lambda s: _fmt(s["max_speed_ratio"])),
            ("max position error", lambda s: _fmt(s["max_position_error"] / L, Lu)),
            ("max orientation error", lambda s: "(not tracked)" if s["max_orientation_error"] is None
             else _fmt(s["max_orientation_error"] / A, Au) + (" (tool axis)" if s["mode"] == "axis" else "")),
            ("in a singular window", lambda s: "—" if not ws else
             f"{s['waypoints_in_window']}/{n} waypoints ({100 * s['share_in_window']:.3g} %)"),
            ("min σ_min (SI)", lambda s: _fmt(s["min_sigma"]))):
        rows.append([name] + [get(r.summary) for r in comparison.runs])
    widths = [max(len(str(x)) for x in col) for col in zip(["", *cols], *rows)]
    lines.append("  " + "  ".join(f"{x:<{widths[i]}}" for i, x in enumerate(["", *cols])).rstrip())
    for row in rows:
        lines.append("  " + "  ".join(f"{x:<{widths[i]}}" for i, x in enumerate(row)).rstrip())
    lines.append("")
    for r in comparison.runs:
        s = r.summary
        notes = ["; ".join(f"{e['name']} at waypoints " + ", ".join(f"{a}–{b}" if b > a else f"{a}"
                                                                    for a, b in e["ranges"])
                           for e in s["windows_entered"])] if s["windows_entered"] else []
        if r.key == "qp":
            if s["forced_steps"]:
                notes.append(f"{s['forced_steps']} of {n - 1} steps forced into a window (no configuration "
                             "outside it met the next waypoint)")
        else:
            rows = {"pose": 6, "axis": 5, "position": 3}[s["mode"]]
            if rows != robot.n:
                notes.append(f"minimum-norm pseudo-inverse at every step (the {rows}×{robot.n} task Jacobian is not "
                             "square)")
            elif s["pinv_steps"]:
                notes.append(f"pseudo-inverse at {s['pinv_steps']} step(s) where J is exactly singular")
            if s["max_finite_condition"] is not None:
                notes.append(f"largest finite condition number of J {s['max_finite_condition']:.3g}")
            if s["diverged_at"] is not None:
                notes.append(f"diverged at waypoint {s['diverged_at']} (joint values no longer finite)")
        if notes:
            lines.append(f"  {r.label}: " + "; ".join(notes))
    return "\n".join(lines).rstrip()


def _positive_or_default(value: float | None, scale: float, default: float) -> float:
    return default if value is None else value * scale


def cmd_follow(args, load_robot) -> int:
    import sys

    from planning.toolpath import load_toolpath
    from studies.cli.kinematics import configuration
    from studies.study.follow import (
        DEFAULT_TOLERANCE,
        check_mode,
        default_mode,
        follow_toolpath,
        start_configuration,
    )
    output_file(args.plot)
    robot = require_task_rows(load_robot(args.robot))
    c = robot.chain
    tp = load_toolpath(toolpath_file(args.toolpath), robot)
    if tp.t is None:
        raise CliInputError(f"{args.toolpath}: the tool path has no times; give it a feed, durations or a time "
                            "column (the followers move along it in time)")
    if len(tp.poses) < 2:
        raise CliInputError(f"{args.toolpath}: {len(tp.poses)} waypoint; a path to follow needs at least 2")
    mode = (check_mode(robot, args.mode, tp.has_orientation, "--mode") if args.mode
            else default_mode(robot, tp.has_orientation))
    start = None
    if args.start is not None:
        start = configuration(robot, args.start, "--start")
        robot.check_limits(start)
    tolerance = (_positive_or_default(args.tol_position, c.length_scale, DEFAULT_TOLERANCE[0]),
                 _positive_or_default(args.tol_orientation, c.angle_scale, DEFAULT_TOLERANCE[1]))
    ws = windows_from_args(robot, args.margin, args.sigma_min)
    note = sampled_windows_note(ws, "the waypoints inside them are counted as far as their samples show")
    if note:
        print(note, file=sys.stderr)
    if start is None:
        start, info = start_configuration(robot, tp.poses[0], mode)
        if not info["success"]:
            print(f"note: IK found no configuration for waypoint 0 (position error "
                  f"{info['position_error'] / c.length_scale:.3g} {c.length_unit}); the followers start from the "
                  "nearest one it found (give --start)", file=sys.stderr)
    else:
        info = {"from": "--start"}
    comparison = follow_toolpath(robot, tp, start, ws, mode=mode, tolerance=tolerance, naive=args.naive, start=info)
    if args.plot:
        from studies.plots.follow import plot_follow
        plot_follow(comparison, args.plot)
    if args.json:
        print(dump(comparison.to_json(waypoints=args.waypoints)))
    else:
        print(follow_text(comparison))
        if args.plot:
            print(f"wrote {args.plot}")
    return EXIT_OK if comparison.ok else EXIT_FAIL


def add_commands(add) -> None:
    """Register ``follow`` with the CLI's ``add(name, func, help)`` helper."""
    sp = add("follow", cmd_follow, "follow a Cartesian tool path with the OSQP follower (and the naive resolved-rate "
                                   "method): joint speeds, errors, singular windows; exit 0 within tolerance, 1 not")
    sp.add_argument("robot", metavar="ROBOT", help="bundled name or path to a robot .toml file")
    sp.add_argument("toolpath", metavar="TOOLPATH",
                    help="tool path with times or a feed: .csv (waypoints) or .toml (segments), in the robot file's "
                         "units; or the name of a bundled example (" + ", ".join(bundled_toolpaths()) + ")")
    sp.add_argument("--start", nargs="+", metavar="Q",
                    help="start configuration, file units (default: IK of the first waypoint)")
    sp.add_argument("--mode", choices=MODES,
                    help="task: pose (6 DOF), axis (position and tool z axis, 5 DOF) or position (3 DOF); default: "
                         "pose when the path gives orientations and the robot controls them, else position")
    window_width_args(sp)
    sp.add_argument("--naive", action="store_true",
                    help="also run the naive resolved-rate method q += J⁻¹·ẋ·Δt on the same task, for comparison")
    sp.add_argument("--tol-position", type=bounded(0, math.inf, "(file length unit)", open_low=True), metavar="E",
                    help="position tolerance, file length unit (default 1 mm)")
    sp.add_argument("--tol-orientation", type=bounded(0, math.inf, "(file angle unit)", open_low=True), metavar="E",
                    help="orientation tolerance, file angle unit (default 1°)")
    sp.add_argument("--waypoints", action="store_true", help="with --json: include the per-waypoint arrays")
    sp.add_argument("--plot", metavar="FILE.png", help="write joint speeds, position errors and σ_min against time")
