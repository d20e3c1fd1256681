"""``rmt plan`` and ``rmt check-path``: OMPL joint paths around singular windows, and dense checks
of a joint path given as CSV."""
from __future__ import annotations

import math
import sys
from pathlib import Path

import numpy as np

from kin.output import write_output
from studies.cli.common import (
    MAX_TIME_LIMIT,
    CliInputError,
    bounded,
    cell_args,
    joint_values,
    limits_from,
    output_file,
    positions,
    sampled_windows_note,
    seed,
    window_width_args,
    windows_from_args,
    windows_label,
    world_from_args,
)
from studies.cli.floor import floor_from_args, require_above_floor, sigma_floor_args
from studies.cli.frames import frame_arg, pose_frame, pose_from_args
from studies.cli.goal_text import goal_lines
from studies.jointpath import MAX_PATH_BYTES, PathFileError, path_csv_text, read_path_csv  # noqa: E402,F401  (where they live)
from studies.jsonio import dump, finite_or_none
from studies.taskrows import require_task_rows
from studies.units import joint_units


def write_path_csv(robot, path_si: np.ndarray, out: str | Path) -> Path:
    """A joint path as CSV (:func:`path_csv_text`), written with :func:`kin.output.write_output`."""
    return write_output(out, path_csv_text(robot, path_si))


def cmd_plan(args, load_robot) -> int:
    from planning.collision.report import nearest_json
    from planning.ompl.planner import plan
    output_file(args.out)
    output_file(args.trajectory_out)
    robot = require_task_rows(load_robot(args.robot))
    c = robot.chain
    timing = _timing_limits(robot, args)
    start = joint_values(robot, args.start, "--start")
    goal = goal_pose = None
    if args.goal is not None:
        goal = joint_values(robot, args.goal, "--goal")
    else:
        goal_pose = pose_from_args(c, args.goal_pose[:3], args.goal_pose[3:], "--goal-pose")
    frame = pose_frame(args, "--goal-pose")
    boxes = _keep_out(c, args)
    world = world_from_args(robot, args, keep_out=boxes)
    ws = windows_from_args(robot, args.margin, args.sigma_min)
    floor = floor_from_args(robot, args)
    require_above_floor(robot, floor, start, "--start")
    if goal is not None:
        require_above_floor(robot, floor, goal, "--goal")
    if floor.active is None:
        note = sampled_windows_note(ws, "drop --no-singularity-check (or give --sigma-floor S) to plan with "
                                        "σ_min ≥ S proven along the path")
        if note:
            print(note, file=sys.stderr)
    res = plan(robot, start, goal, ws, goal_pose=goal_pose, goal_frame=frame, planner=args.planner,
               time_limit=args.time_limit,
               seed=args.seed, objective=args.objective, world=world, sigma_min=floor.active)
    if goal is None:
        goal = res.goal if res.goal is not None else start
    dense = res.check
    if res.success:
        # plan() returns its path checked by the proofs alone; the command reports what check-path reports:
        # the smallest σ_min and clearance of the dense states and the proof's lower bound along the path
        from planning.validate import check_path
        dense = check_path(robot, res.path, ws, floor.active, world=world)
    path_file = robot.chain.from_si(res.path) if res.success else np.zeros((0, robot.n))
    if args.out and res.success:
        write_path_csv(robot, res.path, args.out)
    timed = None
    if res.success and timing is not None:
        timed = _time_path(robot, res.path, timing, args.trajectory_out, limits_from(args))
    out = {"success": res.success, "path": path_file.tolist(), "planner": res.planner, "time_s": res.time_s,
           "length": finite_or_none(res.length),
           "min_sigma": finite_or_none(dense.min_sigma if res.success else res.min_sigma),
           "windows": [] if ws is None else [w.name for w in ws.windows],
           "straight_line_valid": res.straight_line_valid, "status": res.status,
           "proven": res.proven, "checks": None if res.check is None else
           {"windows": res.check.windows_check, "sigma_min": res.check.sigma_check,
            "collisions": res.check.collision_check},
           "min_clearance": None if dense is None else finite_or_none(dense.min_clearance),
           "clearance_bound": None if dense is None else finite_or_none(dense.clearance_bound),
           **nearest_json(dense.nearest if res.success and dense is not None else None),
           "cell": None if world is None else world.name or args.cell,
           "separation": None if res.separation is None else
           {"joints": list(res.separation.joints), "kind": res.separation.kind, "reason": res.separation.reason},
           "goal": None if res.goal is None else c.from_si(res.goal).tolist(),
           "goal_branch": None if res.goal_branch is None else
           {k: v for k, v in res.goal_branch.items() if k != "q"},
           "goal_frame": None if goal_pose is None else frame,
           "keep_out_boxes": len(boxes),
           "sigma_floor": floor.to_dict(), "margin": args.margin, "timing": timed,
           "units": {"path": "robot file units", "length": "joint-space length, SI (rad/m)", "min_sigma": "SI",
                     "min_clearance": "m"}}
    if args.json:
        print(dump(out))
    else:
        if res.goal_branch is not None:
            print(goal_lines(c, res))
        if res.success:
            print(f"path found by {res.planner} in {res.time_s:.3f} s: {len(res.path)} waypoints, joint-space "
                  f"length {res.length:.4g} (straight line {np.linalg.norm(goal - start):.4g}"
                  f"{', blocked' if not res.straight_line_valid else ''}), min σ_min {dense.min_sigma:.3g} (SI)")
            print("  " + " ".join(f"{f'q{i + 1} [{u}]':>10}" for i, u in enumerate(joint_units(c))))
            for row in path_file:
                print("  " + " ".join(f"{x:10.5g}" for x in row))
            label = windows_label(c, args.margin, args.sigma_min)
            if label is None:
                print("no singular windows (--margin X or --sigma-min S gives them)")
            else:
                print(f"{label} proven clear along every segment" if res.proof is not None and res.proof.proven
                      else f"{label} checked by samples on some segments (the proof could not settle them)")
            if floor.active is not None:
                print(f"σ_min ≥ {floor.value:g} (SI) {res.check.sigma_check} along every segment ({floor.text})")
            else:
                print(f"σ_min floor: {floor.text}")
            if world is not None:
                print(f"collisions with the cell and the robot itself: {res.check.collision_check}; min clearance "
                      f"{dense.min_clearance * 1e3:.4g} mm (proven ≥ {(dense.clearance_bound or 0.0) * 1e3:.4g} mm; "
                      f"{world.shapes_text})")
                print("  " + "; ".join(dense.nearest.lines()))      # the cell apart from the robot's own pairs
            if timed is not None:
                print(f"timed rest to rest, stopping at every waypoint: {timed['duration_s']:.6g} s "
                      f"({timed['samples']} samples; speeds from {timed['limits_from']['v_max']}, accelerations "
                      f"from {timed['limits_from']['a_max']})")
            for f in (args.out, args.trajectory_out):
                if f:
                    print(f"wrote {f}")
        elif res.separation is not None or res.goal is None:
            print(res.status + (f"; σ_min floor: {floor.text}" if res.separation is not None
                                and res.separation.kind == "sign" else ""))
        else:
            print(f"no path found by {res.planner} within {args.time_limit:g} s ({res.status}); σ_min floor: "
                  f"{floor.text}")
    return 0 if res.success else 1


def _timing_limits(robot, args):
    """(v_max, a_max) SI for ``--time``/``--trajectory-out`` (as ``rmt time``'s: the options, else the robot
    file's), checked before planning; None when the path is not to be timed."""
    if not (args.time or args.trajectory_out):
        for opt, val in (("--v-max", args.v_max), ("--a-max", args.a_max)):
            if val is not None:
                raise CliInputError(f"{opt} applies with --time or --trajectory-out only")
        return None
    from studies.cli.timelimits import limits_or_defaults
    return limits_or_defaults(robot, args.v_max, args.a_max)


def _time_path(robot, path_si: np.ndarray, limits, out: str | None, source: dict) -> dict:
    """Time the planned path rest to rest with no corner blends (``rmt time --blend 0``: the trajectory
    stops at every waypoint, so it is the path the planner checked) and write it as a trajectory file."""
    from kin.dynamics.rnea import has_inertia
    from planning.timing import time_parameterize
    from studies.export.trajectory import trajectory_csv_text
    tr = time_parameterize(path_si, limits[0], limits[1], blend=0.0,
                           robot=robot if has_inertia(robot.chain) else None)
    if out:
        write_output(out, trajectory_csv_text(robot, tr.t, tr.q, tr.qd, tr.qdd, tr.tau))
    return {"duration_s": tr.duration, "samples": len(tr.t), "blend": 0.0, "trajectory": out,
            "limits_from": source}


def _keep_out(chain, args) -> list:
    """Keep-out boxes from ``--keep-out FILE`` and ``--keep-out-box`` (robot file length unit)."""
    from planning.ompl import KeepOutBox
    from planning.ompl.keep_out import load_keep_out
    boxes = [] if args.keep_out is None else load_keep_out(args.keep_out, chain.length_unit)
    for raw in args.keep_out_box or []:
        v = positions(chain, raw, "--keep-out-box")
        if not np.all(v[:3] < v[3:]):
            raise CliInputError(f"--keep-out-box {' '.join(raw)}: needs X0 Y0 Z0 X1 Y1 Z1 with each lower corner "
                                "value below the upper one")
        boxes.append(KeepOutBox(tuple(v[:3]), tuple(v[3:])))
    return boxes


def cmd_check_path(args, load_robot) -> int:
    from planning.collision.report import nearest_json
    from planning.validate import (
        DEFAULT_STEP_ANGLE,
        DEFAULT_STEP_LENGTH,
        STEP_ANGLE_RANGE,
        STEP_LENGTH_RANGE,
        check_path,
    )
    robot = require_task_rows(load_robot(args.robot))
    P = read_path_csv(robot, args.path)
    ws = windows_from_args(robot, args.margin, args.sigma_min)
    c = robot.chain
    step_angle = DEFAULT_STEP_ANGLE if args.step is None else args.step * c.angle_scale
    step_length = DEFAULT_STEP_LENGTH if args.step is None else args.step * c.length_scale
    rev = c.revolute_mask
    for kind, used, step, (lo, hi), scale, unit in (
            ("revolute", rev.any(), step_angle, STEP_ANGLE_RANGE, c.angle_scale, c.angle_unit),
            ("prismatic", (~rev).any(), step_length, STEP_LENGTH_RANGE, c.length_scale, c.length_unit)):
        if used and not lo <= step <= hi:
            raise CliInputError(f"--step {args.step:g} is outside the allowed range [{lo / scale:.3g}, "
                                f"{hi / scale:.3g}] {unit} for the {kind} joints of {c.name}")
    floor = floor_from_args(robot, args)
    if floor.active is None:
        note = sampled_windows_note(ws, "drop --no-singularity-check (or give --sigma-floor S) to prove σ_min ≥ S "
                                        "along the path")
        if note:
            print(note, file=sys.stderr)
    world = world_from_args(robot, args)
    chk = check_path(robot, P, ws, sigma_min=floor.active, step_angle=step_angle, step_length=step_length,
                     world=world)
    fv = chk.first_violation
    out = {"valid": chk.valid,
           "first_violation": None if fv is None else {"index": fv.index, "kind": fv.kind, "detail": fv.detail},
           "min_sigma": finite_or_none(chk.min_sigma), "min_sigma_index": chk.min_sigma_index,
           "checked_states": chk.checked_states, "rows": int(len(P)),
           "windows_check": chk.windows_check, "sigma_check": chk.sigma_check,
           "collision_check": chk.collision_check, "min_clearance": finite_or_none(chk.min_clearance),
           "min_clearance_index": chk.min_clearance_index if world is not None else None,
           "clearance_bound": finite_or_none(chk.clearance_bound), **nearest_json(chk.nearest),
           "sigma_floor": floor.to_dict(),
           "margin": args.margin, "units": {"min_clearance": "m", "min_sigma": "SI", "margin": "robot file units"}}
    if args.json:
        print(dump(out))
    elif chk.valid:
        label = windows_label(c, args.margin, args.sigma_min)
        how = "" if chk.windows_check is None else f"; {label} {chk.windows_check}"
        how += f"; σ_min floor: {floor.text}" if floor.active is None else \
            f"; σ_min ≥ {floor.value:g} (SI) {chk.sigma_check}"
        if world is not None:
            how += (f"; collisions {chk.collision_check}, min clearance {chk.min_clearance * 1e3:.4g} mm "
                    f"(row {chk.min_clearance_index}; {world.shapes_text})")
        print(f"valid: {len(P)} rows, {chk.checked_states} states checked{how}; min σ_min {chk.min_sigma:.3g} (SI) "
              f"(row {chk.min_sigma_index})")
    else:
        print(f"INVALID at row {fv.index}: {fv.kind} — {fv.detail}")
        print(f"{len(P)} rows, {chk.checked_states} states checked; min σ_min {chk.min_sigma:.3g} (SI); σ_min floor: "
              f"{floor.text}")
    if not args.json and chk.nearest is not None:       # the cell apart from the robot's own pairs
        print("  " + "; ".join(chk.nearest.lines()))
    return 0 if chk.valid else 1


def _window_args(sp, seed_help: str) -> None:
    window_width_args(sp)
    sp.add_argument("--seed", type=seed, default=0, help=seed_help)


def add_commands(add) -> None:
    sp = add("plan", cmd_plan, "plan a joint path with OMPL that avoids the singular windows; exit 1 if none found")
    sp.add_argument("robot", metavar="ROBOT", help="bundled name or path to a robot .toml file")
    sp.add_argument("--start", nargs="+", required=True, metavar="Q",
                    help="start configuration, file units, or a named state (e.g. home)")
    goal = sp.add_mutually_exclusive_group(required=True)
    goal.add_argument("--goal", nargs="+", metavar="Q", help="goal configuration, file units, or a named state")
    goal.add_argument("--goal-pose", nargs=6, metavar=("X", "Y", "Z", "R", "P", "Y"),
                      help="goal tool pose, file units (fixed-axis roll-pitch-yaw), in the cell frame with --cell "
                           "(see --frame): every IK branch and its whole-turn copies are candidates; the valid one "
                           "on the start's side of every window nearest the start is the goal")
    frame_arg(sp)
    sp.add_argument("--keep-out", metavar="FILE.toml",
                    help="keep-out boxes of the work cell (TOML, see docs/cli.md, 'Keep-out files')")
    sp.add_argument("--keep-out-box", nargs=6, action="append", metavar=("X0", "Y0", "Z0", "X1", "Y1", "Z1"),
                    help="a keep-out box for the tool point, base frame, file length unit (repeatable)")
    _window_args(sp, "seed of the planner (default 0; the windows do not depend on it)")
    cell_args(sp)
    sp.add_argument("--planner", default="RRTConnect", help="OMPL planner (RRTConnect, RRT*, PRM*, BIT*, ...)")
    sp.add_argument("--time-limit", type=bounded(0, MAX_TIME_LIMIT, "s", open_low=True), default=2.0,
                    metavar="S", help=f"planning time limit, s (default 2, at most {MAX_TIME_LIMIT:g})")
    sp.add_argument("--objective", default="none", choices=("none", "length", "singularity"),
                    help="optimisation objective for optimising planners (default none)")
    sigma_floor_args(sp, "keep σ_min ≥ S (SI) along the path, proven segment by segment")
    sp.add_argument("--out", metavar="PATH.csv", help="write the path as CSV (robot file units)")
    sp.add_argument("--time", action="store_true", help="time the path found rest to rest, stopping at every "
                                                        "waypoint (rmt time --blend 0), and report its duration")
    sp.add_argument("--trajectory-out", metavar="TRAJ.csv", help="write that timed trajectory as a trajectory file "
                                                                 "(rmt export-trajectory reads it); implies --time")
    sp.add_argument("--v-max", nargs="+", metavar="V", help="with --time: joint speed limits, file units/s (default: "
                                                           "the joints' max_velocity)")
    sp.add_argument("--a-max", nargs="+", metavar="A", help="with --time: joint acceleration limits, file units/s² "
                                                           "(default: the joints' max_acceleration)")
    sp = add("check-path", cmd_check_path, "check a joint path (CSV) densely; exit 0 valid, 1 invalid")
    sp.add_argument("robot", metavar="ROBOT", help="bundled name or path to a robot .toml file")
    sp.add_argument("path", metavar="PATH.csv", help="one configuration per row, robot file units")
    _window_args(sp, "accepted for symmetry with plan and ignored: the check uses no random numbers")
    cell_args(sp)
    sigma_floor_args(sp, "fail where σ_min (SI) drops below S")
    sp.add_argument("--step", type=bounded(0, math.inf, "(robot file units)", open_low=True), metavar="D",
                    help="largest joint change between checked states, file units (default 0.1° / 0.1 mm)")
