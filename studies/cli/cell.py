"""``rmt clearance``: how clear one configuration is of its work cell and of itself, body by body; the
nearest obstacle and the nearest self pair named apart (a self pair must not hide the obstacles)."""
from __future__ import annotations

from studies.cli.common import cell_args, world_from_args
from studies.jsonio import dump, finite_or_none


def cmd_clearance(args, load_robot) -> int:
    from planning.collision import ClearanceTally, nearest_obstacle_per_body
    from studies.cli.kinematics import configuration
    robot = load_robot(args.robot)
    q = configuration(robot, args.q, "q")
    args.self_collision = True           # the robot against itself, always
    world = world_from_args(robot, args)
    near = world.nearest(q[None])
    obs, slf = world.per_body(q[None])
    tally = ClearanceTally(world)
    tally.add(q[None])
    named = nearest_obstacle_per_body(world, q)
    c = float(near.clearance[0])
    body, other = int(near.body[0]), int(near.other[0])
    clear = c > world.margin
    names = world.body_names
    holds = set(world.geometry.bodies())
    per_body = [{"body": names[k], "obstacles": finite_or_none(obs[0, k]),
                 "nearest_obstacle": None if named[k] is None else named[k][0], "self": finite_or_none(slf[0, k])}
                for k in range(len(names)) if k in holds]
    if args.json:
        print(dump({"clear": clear, "clearance": c, "body": names[body], "other": world.other_name(other),
                    "point_robot": near.point_robot[0], "point_other": near.point_other[0],
                    **tally.to_dict(), "required": world.margin, "cell": world.name or args.cell,
                    "per_body": per_body, "capped_at": world.cap,
                    "units": "m (values at the cap mean 'at least this far')"}))
    else:
        both = "; ".join(tally.lines(row=""))
        if clear:       # the obstacles first: a self pair near in every pose must not hide them
            print(f"clear: {both}")
        else:
            print(f"IN COLLISION: {world.describe(body, other, c)}")
            print(f"  {both}")
        print(f"  {'body':<20} {'obstacles [mm]':>15} {'nearest obstacle':<20} {'self [mm]':>12}")
        for row in per_body:
            fmt = [f"{v * 1e3:.4g}" if v is not None and v < world.cap else f"≥ {world.cap * 1e3:.0f}"
                   for v in (row["obstacles"], row["self"])]
            print(f"  {row['body']:<20} {fmt[0]:>15} {row['nearest_obstacle'] or '-':<20} {fmt[1]:>12}")
    return 0 if clear else 1


def add_commands(add) -> None:
    sp = add("clearance", cmd_clearance, "how clear a configuration is of its work cell and of itself (self-collision "
                                         "always); exit 0 clear, 1 in collision")
    sp.add_argument("robot", metavar="ROBOT", help="bundled name or path to a robot .toml file")
    sp.add_argument("q", nargs="+", metavar="Q", help="the configuration, robot file units")
    cell_args(sp)


__all__ = ["add_commands", "cmd_clearance"]
