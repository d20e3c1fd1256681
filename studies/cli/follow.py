"""``rmt drawing``: the homework's drawing task (docs/machines.md §6) from a singular start — the naive
resolved-rate method against the OSQP path follower (:mod:`studies.drawing`)."""
from __future__ import annotations

import math

import kin

from studies.cli.common import bounded, output_file
from studies.jsonio import dump

#: the QP follower's task modes (planning.follow.MODES, listed here so that registering the command
#: does not import OSQP; a test keeps the two equal)
MODES = ("pose", "axis", "position")


def _ranges(d: dict) -> str:
    if not d["windows_entered"]:
        return "none"
    return "; ".join(f"{w['name']}: waypoints " + ", ".join(f"{a}–{b}" for a, b in w["ranges"])
                     for w in d["windows_entered"])


def cmd_drawing(args, load_robot) -> int:
    from studies.drawing import pen_robot, run_drawing_study, solver_output_silenced
    output_file(args.plot)
    robot = load_robot("ur3_homework_pen") if "ur3_homework_pen" in kin.bundled_robots() else pen_robot()
    margin = math.radians(5.0 if args.margin is None else args.margin)
    with solver_output_silenced():
        res = run_drawing_study(robot, window_margin=margin, modes=args.modes or MODES, series=bool(args.plot))
    if args.plot:
        from studies.plots.drawing import plot_drawing
        plot_drawing(res, args.plot)
    res.pop("series", None)
    if args.json:
        print(dump(res))
        return 0
    p, st, tol = res["path"], res["start"], res["tolerance"]
    print(f"Drawing task (docs/machines.md §6) on {res['robot']} (pen d6 = {res['pen_d6_m']:g} m): "
          f"{len(p['segments'])} segments × {p['segment_time_s']:g} s × {p['points_per_segment']} points "
          f"(Δt = {p['dt_s'] * 1e3:g} ms, {p['waypoints']} waypoints), plane {p['plane']}")
    cond = "inf" if not math.isfinite(st["condition"]) else f"{st['condition']:.3g}"
    print(f"start q = ({', '.join(f'{x:g}' for x in st['q_deg'])})°: σ_min(J) = {st['sigma_min']:.3g}, "
          f"condition {cond}; lost twist along rotation about base y (pen-axis component "
          f"{st['lost_rotation_about_pen_axis']:.3g})")
    print(f"tolerance: {tol['position_m'] * 1e3:g} mm, {tol['orientation_deg']:g}°; windows: "
          + ", ".join(f"{w['name']} (±{math.degrees(w['half_width']):g}°)" for w in res["windows"]))
    print()
    print(f"{'method':<34} {'peak speed':>12} {'max pos err':>12} {'max orient':>11}  result")
    rows = [("naive, homework J (z1…z6)", res["naive_homework"]), ("naive, correct J (z0…z5)", res["naive"])]
    for name, d in rows:
        print(f"{name:<34} {d['peak_joint_speed']:>8.3g} r/s {d['max_position_error_m']:>10.3g} m "
              f"{math.degrees(d['max_orientation_error_rad']):>9.3g}°  {d['verdict']}; pinv at {d['pinv_steps']} "
              "step(s)")
    for m, d in res["qp"].items():
        orient = {"pose": d["max_orientation_error_rad"], "axis": d["max_axis_error_rad"]}.get(m, math.nan)
        o = f"{math.degrees(orient):>9.3g}°" if math.isfinite(orient) else f"{'(free)':>10}"
        print(f"{'QP follower, ' + m + ' mode':<34} {d['peak_joint_speed']:>8.3g} r/s {d['max_position_error_m']:>10.3g} m "
              f"{o}  {d['verdict']}; forced steps {d['forced_steps']}; in windows: {_ranges(d)}")
        if m == "position":
            print(f"{'':<34} pen tilt up to {math.degrees(d['pen_tilt_max_rad']):.3g}° (orientation not tracked)")
    c = res.get("comparison")
    if c:
        print(f"\nnaive (homework) peak speed / QP ({c['reference_mode']}) peak speed = "
              f"{c['naive_homework_peak_over_qp']:.3g}; naive (correct J) / QP = {c['naive_peak_over_qp']:.3g}")
    print()
    for line in res["explanation"]:
        print(f"- {line}")
    if args.plot:
        print(f"\nwrote {args.plot}")
    return 0


def add_commands(add) -> None:
    """Register the commands with the CLI's ``add(name, func, help)`` helper."""
    sp = add("drawing", cmd_drawing, "the homework's drawing task from a singular start: naive resolved rate "
                                     "vs the OSQP path follower")
    sp.add_argument("--plot", metavar="FILE.png", help="write joint speeds and tracking errors against time")
    sp.add_argument("--margin", type=bounded(0, 45, "degrees"), metavar="DEG", help="half-width of the singular windows in degrees "
                                                                "(default 5)")
    sp.add_argument("--modes", nargs="+", choices=MODES, metavar="MODE",
                    help=f"QP follower task modes to run (default: all of {', '.join(MODES)})")
