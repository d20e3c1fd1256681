"""``rmt export-trajectory``: a trajectory file (``rmt time --out``, ``rmt plan --time
--trajectory-out``) as something a robot reads — a ROS 2 ``trajectory_msgs/JointTrajectory`` (YAML or
JSON), a URScript program for a UR e-series arm (a ``servoj`` stream or ``movej`` through the stops),
or a plain timed CSV in SI — after checking it against the robot's limits (:mod:`studies.export`).

Exit 0 written, 1 the trajectory breaks a limit (one line naming the joint and the time, nothing
written), 2 bad input."""
from __future__ import annotations

import json
import sys

import numpy as np

from kin.output import write_output
from studies.cli.common import EXIT_FAIL, CliInputError, bounded, output_file
from studies.jsonio import dump

FORMATS = ("ros", "ros-json", "urscript", "csv")
MODES = ("servoj", "movej")
#: the fastest resampling rate, Hz (a ROS controller's 1 kHz)
MAX_RATE = 1000.0
#: UR's ranges of servoj's lookahead_time (s) and gain
LOOKAHEAD_RANGE = (0.03, 0.2)
GAIN_RANGE = (100.0, 2000.0)
MAX_NAME = 200


def _joint_names(robot, raw) -> list[str]:
    """``--joint-names`` (n distinct names of printable characters) or the robot file's joint names."""
    if raw is None:
        return robot.chain.joint_names()
    if len(raw) != robot.n:
        raise CliInputError(f"--joint-names: got {len(raw)} names; {robot.name} has {robot.n} joints")
    for s in raw:
        if not s or len(s) > MAX_NAME or not s.isprintable():
            raise CliInputError(f"--joint-names: {s[:40]!r} must be 1 to {MAX_NAME} printable characters")
    if len(set(raw)) != len(raw):
        raise CliInputError("--joint-names: a name is given twice; every joint needs its own")
    return list(raw)


def _check_options(args, robot) -> None:
    if args.format != "urscript":
        for opt, val in (("--urscript-mode", args.urscript_mode), ("--lookahead", args.lookahead),
                         ("--gain", args.gain)):
            if val is not None:
                raise CliInputError(f"{opt} applies to --format urscript only")
        return
    c = robot.chain
    if robot.n != 6 or not c.revolute_mask.all():
        raise CliInputError(f"--format urscript is for a UR arm's six revolute joints; {robot.name} has {robot.n} "
                            f"joints ({int((~c.revolute_mask).sum())} prismatic)")
    if args.urscript_mode == "movej" and (args.rate, args.lookahead, args.gain) != (None, None, None):
        raise CliInputError("--rate, --lookahead and --gain apply to --urscript-mode servoj only (movej goes "
                            "through the trajectory's stops at the planned times)")
    if args.rate is not None and args.rate > 500 and args.urscript_mode != "movej":
        raise CliInputError(f"--rate {args.rate:g}: a UR e-series controller takes servoj at 500 Hz at most")
    for opt, val, (lo, hi) in (("--lookahead", args.lookahead, LOOKAHEAD_RANGE), ("--gain", args.gain, GAIN_RANGE)):
        if val is not None and not lo <= val <= hi:
            raise CliInputError(f"{opt} {val:g} is outside UR's allowed range [{lo:g}, {hi:g}]")


def _notes(robot, traj, names, what: str, samples: str) -> list[str]:
    units = ", ".join(sorted({"rad" if r else "m" for r in robot.chain.revolute_mask}))
    return [f"{what}, written by rmtkit (rmt export-trajectory) from {json.dumps(traj.source)}",
            f"robot {robot.name}; joints in this order: {json.dumps(names)}",
            f"units: SI - positions {units}, velocities per s, accelerations per s^2, time s from the start",
            f"{samples}; duration {traj.duration:.9g} s"]


def cmd_export(args, load_robot) -> int:
    from studies.export import interpolate, ros, urscript
    from studies.export.limits import first_breach
    from studies.export.trajectory import read_trajectory, trajectory_csv_text
    output_file(args.out)
    if args.json and not args.out:
        raise CliInputError("--json needs --out FILE: without it the export itself is printed")
    robot = load_robot(args.robot)
    _check_options(args, robot)
    names = _joint_names(robot, args.joint_names)
    frame_id = args.frame_id
    if not frame_id.isprintable() or len(frame_id) > MAX_NAME:
        raise CliInputError(f"--frame-id: must be at most {MAX_NAME} printable characters")
    traj = read_trajectory(robot, args.trajectory)
    mode = args.urscript_mode or "servoj"
    rate = args.rate if args.rate is not None else (urscript.SERVO_RATE if args.format == "urscript"
                                                     and mode == "servoj" else None)
    checks = [("position", traj.t, traj.q), ("velocity", traj.t, traj.qd), ("acceleration", traj.t, traj.qdd),
              ("mean velocity", traj.t[:-1], np.diff(traj.q, axis=0) / np.diff(traj.t)[:, None])]
    times, q, qd, qdd = traj.t, traj.q, traj.qd, traj.qdd
    if rate is not None:
        try:
            times = interpolate.resample_times(traj.duration, rate)
        except ValueError as e:
            raise CliInputError(f"--rate {rate:g}: {e}") from None
        q, qd, qdd = interpolate.evaluate(traj, times)
        checks += [("position", times, q), ("velocity", times, qd), ("acceleration", times, qdd)]
    breach = first_breach(robot, checks)
    if breach is not None:
        print(f"{traj.source}: {breach}", file=sys.stderr)
        return EXIT_FAIL
    sampled = f"{len(times)} samples" + (f" at {rate:g} Hz (quartic Hermite between the file's samples)"
                                         if rate is not None else " (the file's own)")
    if args.format in ("ros", "ros-json"):
        what = "ROS 2 trajectory_msgs/msg/JointTrajectory"
        msg = ros.message(names, frame_id, times, q, qd, qdd)
        notes = _notes(robot, traj, names, what, sampled)
        text = ros.yaml_text(msg, notes) if args.format == "ros" else ros.json_text(msg, notes)
    elif args.format == "csv":
        what = "timed CSV (SI)"
        text = trajectory_csv_text(robot, times, q, qd, qdd, si=True, names=names)
    elif mode == "servoj":
        what = f"URScript servoj stream, t = {1 / rate:g} s"
        notes = _notes(robot, traj, names, "URScript for a UR e-series arm: a servoj stream", sampled)
        notes[2] = "units: joint positions rad, times s"
        text = urscript.servoj_program(q, rate, args.lookahead or 0.1, args.gain or 300, notes)
    else:
        try:
            stops = urscript.movej_waypoints(traj)
        except urscript.MovejError as e:
            raise CliInputError(f"{traj.source}: --urscript-mode movej: {e}") from None
        what = "URScript movej through the stops"
        sampled = f"{len(stops)} stops, movej with the planned time between each two (r=0: it halts at each)"
        notes = _notes(robot, traj, names, "URScript for a UR e-series arm: movej through the stops", sampled)
        notes[2] = "units: joint positions rad, times s"
        text = urscript.movej_program(traj, notes)
        times = traj.t[stops]
    if not args.out:
        sys.stdout.write(text)
        return 0
    write_output(args.out, text)
    out = {"format": args.format, "mode": mode if args.format == "urscript" else None, "out": args.out,
           "samples": len(times), "rate_hz": rate, "duration_s": traj.duration, "joint_names": names,
           "robot": robot.name}
    if args.json:
        print(dump(out))
    else:
        print(f"wrote {args.out}: {what}, {robot.n} joints, {len(times)} "
              f"{'stops' if mode == 'movej' and args.format == 'urscript' else 'samples'}, {traj.duration:.6g} s")
    return 0


def add_commands(add) -> None:
    sp = add("export-trajectory", cmd_export, "write a trajectory file (rmt time --out) for a robot controller: "
                                              "ROS 2 JointTrajectory, URScript or a timed CSV; exit 1 if it "
                                              "breaks the robot's limits")
    sp.add_argument("robot", metavar="ROBOT", help="bundled name or path to a robot .toml file")
    sp.add_argument("trajectory", metavar="TRAJ.csv", help="a trajectory file (rmt time --out, rmt plan --time "
                                                           "--trajectory-out)")
    sp.add_argument("--format", required=True, choices=FORMATS,
                    help="ros: trajectory_msgs/JointTrajectory as YAML; ros-json: the same as JSON; urscript: a "
                         "UR e-series program; csv: the trajectory in SI units")
    sp.add_argument("--out", metavar="FILE", help="write here (default: print it)")
    sp.add_argument("--urscript-mode", choices=MODES, help="servoj: stream the whole trajectory at --rate (default); "
                                                           "movej: through the trajectory's stops, planned times")
    sp.add_argument("--rate", type=bounded(0, MAX_RATE, "Hz", open_low=True), metavar="HZ",
                    help="resample at this rate (servoj: default 500, at most 500; ros, csv: default the file's "
                         "own samples)")
    sp.add_argument("--lookahead", type=bounded(0, 1, "s", open_low=True), metavar="S",
                    help="servoj lookahead_time, s (default 0.1; UR allows 0.03 to 0.2)")
    sp.add_argument("--gain", type=bounded(0, 1e4, "", open_low=True), metavar="G",
                    help="servoj gain (default 300; UR allows 100 to 2000)")
    sp.add_argument("--frame-id", default="base_link", metavar="FRAME",
                    help="ROS header.frame_id (default base_link)")
    sp.add_argument("--joint-names", nargs="+", metavar="NAME",
                    help="joint names for the controller, in order (default: the robot file's)")
