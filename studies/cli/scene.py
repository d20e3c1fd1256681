"""``rmt import-scene``: a MoveIt planning scene — the ``.scene`` text of RViz's "Export scene", or a
``moveit_msgs/PlanningScene`` in YAML as MotionBenchMaker ships its problems — as a work-cell file
(docs/cells.md "MoveIt planning scenes"), read back by the cell reader before it is written."""
from __future__ import annotations

from studies.cli.common import EXIT_OK, CliInputError, bounded, output_file
from studies.jsonio import dump

#: the robot's placement options: ±10 km (a cell's span), ±360°
_XYZ = bounded(-1e4, 1e4, "m")
_RPY = bounded(-360, 360, "deg")
_PLURAL = {"box": "boxes", "mesh": "meshes"}


def _name(text: str | None) -> str | None:
    if text is not None and not (text.strip() and len(text) <= 100 and text.isprintable()):
        raise CliInputError(f"--name {text[:120]!r} must be 1 to 100 printable characters")
    return text


def _frame(text: str | None) -> str | None:
    if text is not None and not (text.strip() and len(text) <= 200 and text.isprintable() and " " not in text):
        raise CliInputError(f"--frame {text[:120]!r} must be a frame name (1 to 200 printable characters, no spaces)")
    return text


def cmd_import_scene(args, load_robot) -> int:
    from kin.output import write_output
    from planning.cell.moveit import load_scene, scene_cell

    if not args.out.endswith(".toml"):
        raise CliInputError(f"--out {args.out!r} must end in .toml (a cell file)")
    output_file(args.out)
    name, frame = _name(args.name), _frame(args.frame)
    robot = load_robot(args.robot) if args.robot else None
    scene = load_scene(args.scene, frame)
    text, cell = scene_cell(scene, args.out, name, args.robot_xyz or (0.0, 0.0, 0.0),
                            args.robot_rpy or (0.0, 0.0, 0.0))
    clashes: dict[str, str] = {}
    if robot is not None:
        from kin.geometry import body_names
        from planning.cell import body_lookup
        lookup, labels = body_lookup(robot.chain), body_names(robot.chain)
        for ob in cell.obstacles:
            k = lookup.get(" ".join(ob.name.split()).casefold())
            if k is not None:
                clashes[ob.name] = labels[k]
        cell.resolve(robot)                      # every name the cell gives checked against the robot
    else:
        from planning.cell.model import is_body_like
        clashes = {ob.name: ob.name for ob in cell.obstacles if is_body_like(ob.name)}
    write_output(args.out, text)
    kinds = scene.kinds
    compound = sum(1 for ob in scene.objects if len(ob.shapes) > 1)
    if args.json:
        print(dump({"out": args.out, "scene": args.scene, "format": scene.format, "name": cell.name,
                    "obstacles": len(cell.obstacles), "shapes": kinds, "compound": compound,
                    "over_estimate": cell.over_estimate, "body_names": sorted(clashes), "notes": list(scene.notes),
                    "robot": None if robot is None else robot.name, "units": {"length": "m", "angle": "deg"}}))
        return EXIT_OK
    what = ", ".join(f"{n} {k if n == 1 else _PLURAL.get(k, k + 's')}" for k, n in sorted(kinds.items()))
    print(f"{args.scene} ({scene.format}): {len(scene.objects)} objects → {args.out}: {len(cell.obstacles)} "
          f"obstacles ({what or 'none'}{f'; {compound} of several shapes, as compound obstacles' if compound else ''})"
          f", in m and degrees, in the scene's planning frame")
    if cell.over_estimate > 0:
        print(f"  cones and meshes are held by shapes that stand out of them by at most "
              f"{cell.over_estimate * 1000:.1f} mm")
    for ob_name, body in clashes.items():
        whose = f"{robot.name}'s body {body}" if robot is not None else "a robot body"
        print(f"  obstacle {ob_name!r} has the name of {whose}: the cell keeps it; in [allow] pairs write "
              f"'obstacle:{ob_name}' for the obstacle, 'body:{ob_name}' for the body")
    for note in scene.notes:
        print(f"  note: {note}")
    if robot is not None:
        print(f"  every name checked against {robot.name}; see the robot in it: rmt clearance {args.robot} Q... "
              f"--cell {args.out}")
    return EXIT_OK


def add_commands(add) -> None:
    sp = add("import-scene", cmd_import_scene, "convert a MoveIt planning scene (.scene text or PlanningScene YAML, "
                                               "e.g. MotionBenchMaker's) to a work-cell file")
    sp.add_argument("scene", metavar="SCENE", help="a .scene file (RViz's Export scene) or a moveit_msgs/PlanningScene "
                                                   "in YAML (.yaml, .yml)")
    sp.add_argument("--out", required=True, metavar="CELL.toml", help="the cell file to write")
    sp.add_argument("--robot", metavar="ROBOT", help="bundled name or robot file: check the cell's names against its "
                                                     "bodies")
    sp.add_argument("--robot-xyz", nargs=3, type=_XYZ, metavar=("X", "Y", "Z"),
                    help="where the robot's base placement stands in the scene's planning frame, m (default: its "
                         "origin — MoveIt scenes are in the robot's root frame)")
    sp.add_argument("--robot-rpy", nargs=3, type=_RPY, metavar=("R", "P", "Y"),
                    help="the robot's orientation there, roll pitch yaw in degrees (default 0 0 0)")
    sp.add_argument("--frame", metavar="NAME", help="YAML: the planning frame's name, for objects whose "
                                                    "header.frame_id names it and the scene's fixed frames do not")
    sp.add_argument("--name", help="the cell's name (default: the scene's, else the file's name)")


__all__ = ["add_commands", "cmd_import_scene"]
