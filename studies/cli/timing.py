"""``rmt time``: the minimum-time (on a grid), rest-to-rest timing of a joint path file under speed,
acceleration, optional torque and jerk limits (:func:`planning.timing.time_parameterize`).

Units: the path file (what ``rmt plan --out`` writes: one configuration per row, robot file units)
and ``--v-max``/``--a-max``/``--j-max`` are in the robot file's units (its angle or length unit per
s, s², s³); ``--tau-max`` in N·m (revolute) or N (prismatic); ``--blend`` and ``--ds`` are SI
joint-space distances (rad or m, the arc length the timing works in).  Output in the same units.

``--shape spline`` times the spline through every waypoint instead of the blended polyline; between
waypoints it leaves the straight segments (a path certified segment by segment is no longer covered
by that proof) and may leave the joint limits: the exact range of every joint along it is checked
(exit 1 when outside), and ``--path-out`` writes it as a dense path for ``rmt check-path`` (windows,
cell).

A ``.toml`` path argument is a cycle file: several moves with dwells, timed into one trajectory
(:mod:`studies.cli.timecycle`)."""
from __future__ import annotations

import math
import sys

import numpy as np

from kin.output import write_output
from studies.cli.common import (
    EXIT_FAIL,
    bounded,
    leaving_limits,
    limits_from,
    output_file,
    require_within_limits,
)
from studies.cli.timelimits import limits_or_defaults, per_joint
from studies.jsonio import dump, finite_or_none
from studies.units import joint_units

#: the path shapes of planning.timing.time_parameterize (``SHAPES``; not imported here: ``rmt --help``
#: must not load scipy or CasADi)
SHAPES = ("blend", "spline")
#: largest joint-space distance (rad or m) between the shaped path and the polyline ``--path-out`` writes
SHAPED_TOLERANCE = 1e-4


def _csv(robot, tr) -> str:
    """The sampled trajectory as a trajectory file (:mod:`studies.export.trajectory`): t, q, q̇, q̈ (robot
    file units), τ (N·m, N) when known."""
    from studies.export.trajectory import trajectory_csv_text
    return trajectory_csv_text(robot, tr.t, tr.q, tr.qd, tr.qdd, tr.tau)


def cmd_time(args, load_robot) -> int:
    from kin.dynamics.rnea import has_inertia
    from planning.timing import time_parameterize
    from studies.cli.plan import read_path_csv
    output_file(args.csv)
    output_file(args.plot)
    output_file(args.path_out)
    robot = load_robot(args.robot)
    c = robot.chain
    from studies.cli.timecycle import is_cycle_file, time_cycle
    cycle = is_cycle_file(args.path)
    P = None if cycle else read_path_csv(robot, args.path)
    vmax, amax = limits_or_defaults(robot, args.v_max, args.a_max)
    jmax = per_joint(robot, args.j_max, "--j-max", 1, None)
    taumax = per_joint(robot, args.tau_max, "--tau-max", 0, None)
    use_robot = taumax is not None or has_inertia(c)
    if P is not None:                     # after the options' one-line errors
        require_within_limits(robot, P, lambda i: f"{args.path}: data row {i + 1}")
    if cycle:
        return time_cycle(args, robot, vmax, amax, jmax, taumax, use_robot, _csv)
    tr = time_parameterize(P, vmax, amax, ds=args.ds, blend=args.blend, j_max=jmax,
                           robot=robot if use_robot else None, tau_max=taumax, shape=args.shape)
    if args.csv:
        write_output(args.csv, _csv(robot, tr))
    if args.path_out:
        from studies.cli.plan import write_path_csv
        write_path_csv(robot, tr.path.polyline(SHAPED_TOLERANCE), args.path_out)
    leaving = leaving_limits(robot, tr.path, args.shape)
    outside = [j for j, _ in leaving]
    names = c.joint_names()
    if args.plot:
        from studies.plots.timing import plot_timing
        plot_timing(tr, args.plot, names, f"{robot.name}: {tr.duration:.4g} s")
    peak_v = np.max(np.abs(tr.qd), axis=0) / tr.v_max
    peak_a = np.max(np.abs(tr.qdd), axis=0) / tr.a_max
    peak_tau = None if tr.tau is None else np.max(np.abs(tr.tau), axis=0)
    lim = tr.tau_max
    units = joint_units(c)
    joints = []
    for j in range(robot.n):
        tl = None if lim is None or not math.isfinite(lim[j]) else float(lim[j])
        joints.append({"name": names[j], "unit": units[j], "peak_velocity_ratio": float(peak_v[j]),
                       "peak_acceleration_ratio": float(peak_a[j]),
                       "peak_torque": None if peak_tau is None else float(peak_tau[j]),
                       "tau_max": tl,
                       "peak_torque_ratio": None if tl is None else float(peak_tau[j] / tl)})
    out = {"duration_s": tr.duration, "samples": len(tr.t), "grid_intervals": len(tr.grid) - 1 if tr.grid is not None
           else 0, "solver": tr.qp_status, "joints": joints,
           "dense_overshoot": tr.overshoot, "max_torque_ratio": finite_or_none(tr.max_torque_ratio),
           "torque_rounds": tr.torque_rounds, "max_jerk_ratio": finite_or_none(tr.max_jerk_ratio),
           "path_max_deviation": tr.path.max_deviation, "shape": args.shape,
           "joints_leaving_limits": [names[j] for j in outside],
           "v_max": c.from_si(tr.v_max).tolist(), "a_max": c.from_si(tr.a_max).tolist(),
           "limits_from": limits_from(args),
           "units": {"v_max": "robot file units/s", "a_max": "robot file units/s²", "torque": "N·m or N",
                     "path_max_deviation": "SI (rad/m joint-space)"}}
    if args.json:
        print(dump(out))
        return EXIT_FAIL if outside else 0
    print(f"duration {tr.duration:.6g} s ({len(tr.t)} samples, {out['grid_intervals']} grid intervals; {tr.qp_status})")
    print(f"limits: speeds from {out['limits_from']['v_max']}, accelerations from {out['limits_from']['a_max']}")
    hdr = f"  {'joint':>10} {'|q̇|/v':>8} {'|q̈|/a':>8}"
    if peak_tau is not None:
        hdr += f" {'|τ| peak':>10} {'τ_max':>8} {'|τ|/τ_max':>9}"
    print(hdr)
    for d in joints:
        line = f"  {d['name']:>10} {d['peak_velocity_ratio']:8.4f} {d['peak_acceleration_ratio']:8.4f}"
        if peak_tau is not None:
            tl = "-" if d["tau_max"] is None else f"{d['tau_max']:.4g}"
            tr_ = "-" if d["peak_torque_ratio"] is None else f"{d['peak_torque_ratio']:.4f}"
            line += f" {d['peak_torque']:10.4g} {tl:>8} {tr_:>9}"
        print(line)
    dense = f"dense re-check between samples: speed/acceleration overshoot {tr.overshoot:.2e}"
    if tr.max_torque_ratio is not None:
        dense += f", max |τ|/τ_max {tr.max_torque_ratio:.6f} after {tr.torque_rounds} tightening round(s)"
    print(dense)
    if tr.max_jerk_ratio is not None:
        print(f"jerk ratio between grid points {tr.max_jerk_ratio:.4f}")
    for f in (args.csv, args.plot, args.path_out):
        if f:
            print(f"wrote {f}")
    if leaving:
        print(leaving[0][1], file=sys.stderr)
        return EXIT_FAIL
    return 0


def add_commands(add) -> None:
    sp = add("time", cmd_time, "time a joint path (CSV) under speed, acceleration, torque and jerk limits "
                               "(minimum time on a grid, rest to rest)")
    sp.add_argument("robot", metavar="ROBOT", help="bundled name or path to a robot .toml file")
    sp.add_argument("path", metavar="PATH.csv|CYCLE.toml",
                    help="one configuration per row, robot file units (what `rmt plan --out` writes); or a cycle "
                         "file (.toml): moves (path CSVs or waypoints) with dwells, timed into one trajectory")
    sp.add_argument("--v-max", nargs="+", metavar="V", help="joint speed limits, file units/s: one for all joints "
                                                           "or one per joint (default: the joints' max_velocity)")
    sp.add_argument("--a-max", nargs="+", metavar="A", help="joint acceleration limits, file units/s² (default: "
                                                           "the joints' max_acceleration)")
    sp.add_argument("--tau-max", nargs="+", metavar="T", help="joint torque limits, N·m (revolute) or N "
                                                             "(prismatic); needs inertial data (default: the "
                                                             "joints' max_torque where known)")
    sp.add_argument("--j-max", nargs="+", metavar="J", help="joint jerk limits between grid points, file units/s³")
    sp.add_argument("--blend", type=bounded(0, 10, "rad or m (SI)"), default=0.05, metavar="R",
                    help="corner blend half-length, SI joint-space distance (default 0.05; 0: stop at corners)")
    sp.add_argument("--ds", type=bounded(0, math.inf, "rad or m (SI)", open_low=True), metavar="DS",
                    help="grid step in SI joint-space arc length (default: path length / 300)")
    sp.add_argument("--shape", choices=SHAPES, default="blend",
                    help="blend: straight segments, corners cut within --blend (default); spline: the C¹ spline "
                         "through every waypoint (faster through many close waypoints)")
    sp.add_argument("--path-out", metavar="FILE.csv", help="write the shaped path as a dense joint path CSV "
                    f"(within {SHAPED_TOLERANCE:g} rad or m of it) for `rmt check-path`")
    sp.add_argument("--csv", "--out", dest="csv", metavar="FILE.csv",
                    help="write the sampled trajectory (of the whole cycle for a cycle file): t, q, q̇, q̈ (file "
                         "units), τ")
    sp.add_argument("--plot", metavar="FILE.png", help="write speed, acceleration and torque over their limits "
                                                       "against time")
