"""``rmt ik``: inverse kinematics of a tool pose (or position).

Where the chain has a closed form (a spherical wrist, or joints 2, 3, 4 parallel as on the UR family:
:func:`kin.ik.analytic.analytic_ik`) every branch inside the limits is listed, ranked by joint-space
distance from ``--near`` (default: the zero configuration) — the first is the nearest; ``--all-turns``
lists every whole-turn copy too.  Otherwise (or for a position alone) the numeric solver answers from
``--near`` as its warm start.  With ``--cell`` the pose is in the cell frame (``--frame`` says
otherwise) and each solution is marked clear or in collision in the cell."""
from __future__ import annotations

import numpy as np

from studies.cli.common import EXIT_FAIL, EXIT_OK, CliInputError, cell_args, seed, world_from_args
from studies.cli.frames import frame_arg, frame_name, pose_frame, pose_from_args
from studies.jsonio import dump
from studies.units import joint_units, unit_names

__all__ = ["add_commands", "cmd_ik"]


def _near(robot, args) -> np.ndarray | None:
    from studies.cli.kinematics import configuration
    if args.near is not None and args.q0 is not None:
        raise CliInputError("--near and --q0 say the same thing (the reference configuration): give one")
    raw = args.near if args.near is not None else args.q0
    if raw is None:
        return None
    what = "--near" if args.near is not None else "--q0"
    q = configuration(robot, raw, what)
    c = robot.chain
    for j in range(c.n):        # a reference far beyond the limits is a typo, not a branch: limits ± a turn
        pad = 2 * np.pi if c.revolute_mask[j] else c.upper[j] - c.lower[j]
        lo, hi = c.lower[j] - pad, c.upper[j] + pad
        if not lo <= q[j] <= hi:
            s, u = c.variable_scale[j], joint_units(c)[j]
            turn = "a turn" if c.revolute_mask[j] else "the joint's range"
            raise CliInputError(f"{what}: joint {j + 1} = {q[j] / s:.6g} {u} is outside [{lo / s:.6g}, {hi / s:.6g}] "
                                f"{u} (its limits ± {turn})")
    return q


def _why_none(robot, target, ref) -> str:
    """Why the closed form has no solution inside the limits: no branch reaches the pose at all, or
    every branch that does has a joint outside its limits (the nearest branch's first such joint)."""
    from kin.ik.analytic import analytic_branches
    c = robot.chain
    B = analytic_branches(robot, target, q_ref=ref)
    if not len(B):
        return "out of reach: no branch of the closed form reaches the pose (whatever the joint limits)"
    q = B[0]
    j = int(np.argmax((q < c.lower) | (q > c.upper)))
    s, u = c.variable_scale[j], joint_units(c)[j]
    return (f"{len(B)} branch(es) of the closed form reach the pose, each with a joint outside its limits (every "
            f"whole turn tried): the nearest has joint {j + 1} = {q[j] / s:.6g} {u} outside "
            f"[{c.lower[j] / s:.6g}, {c.upper[j] / s:.6g}] {u}")


def _collisions(world, Q) -> list[str | None]:
    """Per configuration: None when clear in the cell, else which bodies touch."""
    if world is None or not len(Q):
        return [None] * len(Q)
    out = []
    for q in Q:
        if world.state_clear([float(x) for x in q]):
            out.append(None)
        else:
            c = world.nearest(np.asarray(q, dtype=float)[None])
            out.append(world.describe(int(c.body[0]), int(c.other[0]), float(c.clearance[0])))
    return out


def cmd_ik(args, load_robot) -> int:
    robot = load_robot(args.robot)
    c = robot.chain
    target = pose_from_args(c, args.xyz, args.rpy, "--xyz/--rpy")
    mode = "pose" if args.rpy is not None else "position"
    frame = pose_frame(args, "--xyz/--rpy")
    world = world_from_args(robot, args)
    if frame == "cell":
        base_inv = np.linalg.inv(world.base)
        target = base_inv @ target if mode == "pose" else base_inv[:3, :3] @ target + base_inv[:3, 3]
    ref = _near(robot, args)
    if args.all_turns and mode != "pose":
        raise CliInputError("--all-turns needs a pose (--rpy): a position alone has a continuum of solutions")
    sols, method = None, "numeric"
    if mode == "pose":
        from kin.ik.analytic import NoClosedFormError, analytic_ik  # casadi: not on `rmt --help`
        try:
            sols = analytic_ik(robot, target, q_ref=ref, all_turns=args.all_turns)
            method = "closed form"
        except NoClosedFormError:
            sols = None
    out = {"success": False, "q": None, "position_error": None, "orientation_error": None, "mode": mode,
           "frame": frame, "method": method, "near": None if ref is None else c.from_si(ref).tolist()}
    if sols is not None:
        r0 = np.zeros(c.n) if ref is None else ref
        hits = _collisions(world, sols)
        pe = oe = None
        if len(sols):                          # the first solution's residual, by the FK
            from kin.transforms import rotation_error
            F = robot.fk(sols[0])
            pe = float(np.linalg.norm(F[:3, 3] - target[:3, 3])) / c.length_scale
            oe = float(np.linalg.norm(rotation_error(target[:3, :3][None], F[:3, :3][None]))) / c.angle_scale
        out.update({"success": len(sols) > 0, "q": c.from_si(sols[0]).tolist() if len(sols) else None,
                    "position_error": pe, "orientation_error": oe,
                    "solutions": [{"q": c.from_si(q).tolist(), "distance": float(np.linalg.norm(q - r0)),
                                   "collision": h} for q, h in zip(sols, hits)]})
        ok = len(sols) > 0
        if not ok:
            out["reason"] = _why_none(robot, target, r0)
    else:
        from kin.ik.turns import nearest_turns
        res = robot.ik(target, seed=args.seed, q0=ref, mode=mode)
        ok = bool(res.success)
        # the same pose, each revolute angle the whole-turn copy nearest the reference inside the limits
        q = nearest_turns(c, res.q, np.zeros(c.n) if ref is None else ref)
        out.update({"success": ok, "q": c.from_si(q).tolist(),
                    "position_error": res.position_error / c.length_scale,
                    "orientation_error": res.orientation_error / c.angle_scale,
                    "solutions": [{"q": c.from_si(q).tolist(), "collision": _collisions(world, [q])[0]}]
                    if ok else []})
    out["units"] = unit_names(c)
    if args.json:
        print(dump(out))
    else:
        _print(c, out, frame_name(frame, world), ref is not None, world is not None)
    return EXIT_OK if ok else EXIT_FAIL


def _print(c, out: dict, frame: str, near_given: bool, cell: bool) -> None:
    fmt = lambda q: " ".join(f"{x + 0.0:.6g}" for x in q)      # noqa: E731 (+ 0.0: no -0)
    if out["method"] == "closed form":
        sols = out["solutions"]
        if not sols:
            print(f"NO solution ({frame}): {out['reason']}")
            return
        ref = "--near" if near_given else "the zero configuration (--near Q for another)"
        print(f"{len(sols)} solution(s) by the closed form ({frame}), nearest to {ref} first; "
              f"q in {c.angle_unit}:")
        for k, s in enumerate(sols):
            tag = "" if not cell else ("  clear" if s["collision"] is None else f"  in collision: {s['collision']}")
            print(f"  {k + 1:>2}: q = {fmt(s['q'])}   (distance {s['distance']:.4g}, SI){tag}")
        return
    status = "solution" if out["success"] else "NO solution (closest configuration found)"
    print(f"{status} ({frame}): q = {fmt(out['q'])}")
    print(f"position error {out['position_error']:.3g} {c.length_unit}, "
          f"orientation error {out['orientation_error']:.3g} {c.angle_unit}")
    if cell and out["solutions"] and out["solutions"][0]["collision"] is not None:
        print(f"in collision in the cell: {out['solutions'][0]['collision']}")


def add_commands(add) -> None:
    sp = add("ik", cmd_ik, "inverse kinematics of a tool pose (every closed-form branch, nearest first) or "
                           "position; exit 1 if unsolved")
    sp.add_argument("robot", metavar="ROBOT", help="bundled name or path to a robot .toml file")
    sp.add_argument("--xyz", nargs=3, required=True, metavar=("X", "Y", "Z"),
                    help="position, file length unit (cell frame with --cell, see --frame)")
    sp.add_argument("--rpy", nargs=3, metavar=("R", "P", "Y"),
                    help="fixed-axis roll-pitch-yaw, file angle unit (omit for position-only IK)")
    sp.add_argument("--near", nargs="+", metavar="Q",
                    help="reference configuration, file units: solutions ranked by distance from it (default: "
                         "the zero configuration); the numeric solver's warm start")
    sp.add_argument("--q0", nargs="+", metavar="Q", help="the same as --near (kept for old scripts)")
    sp.add_argument("--all-turns", action="store_true",
                    help="list every whole-turn copy of every branch inside the limits (closed form only)")
    sp.add_argument("--seed", type=seed, default=0, help="seed of the numeric solver's random starts (default 0)")
    cell_args(sp)
    frame_arg(sp)
