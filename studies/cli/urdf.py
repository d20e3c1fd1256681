"""``rmt import-urdf`` and ``rmt export-urdf``: a URDF's serial chain as a robot file, and any robot
(bundled, a file, a designed one) as a URDF with simple cylinder visuals."""
from __future__ import annotations

from pathlib import Path

from studies.cli.common import EXIT_OK, CliInputError
from studies.jsonio import dump


def _out_path(out: str, suffix: str) -> Path:
    path = Path(out)
    if path.suffix != suffix:
        raise CliInputError(f"--out {out!r} must end in {suffix}")
    if not path.parent.is_dir():
        raise CliInputError(f"--out {out!r}: directory {str(path.parent)!r} does not exist")
    return path


def cmd_import_urdf(args, load_robot) -> int:
    import kin
    from kin.urdf import import_urdf

    out = _out_path(args.out, ".toml")
    chain = import_urdf(args.file, base=args.base, tip=args.tip, convention=args.convention, name=args.name)
    kin.save_robot(chain, out)
    if args.json:
        print(dump({"out": str(out), "name": chain.name, "joints": chain.n, "types": list(chain.joint_types),
                    "convention": chain.convention, "base_is_identity": chain.base.is_identity,
                    "tool_is_identity": chain.tool.is_identity}))
        return EXIT_OK
    types = "".join("R" if j.is_revolute else "P" for j in chain.joints)
    print(f"{args.file}: {chain.title}")
    print(f"{chain.n} joints ({types}), {chain.convention} DH, written to {out} (m, rad); "
          f"see it with: rmt show {out}")
    return EXIT_OK


def cmd_export_urdf(args, load_robot) -> int:
    from kin.urdf import save_urdf

    out = _out_path(args.out, ".urdf")
    robot = load_robot(args.robot)
    save_urdf(robot.chain, out)
    if args.json:
        print(dump({"out": str(out), "name": robot.chain.name, "joints": robot.n,
                    "links": ["base_link"] + [f"link_{i}" for i in range(1, robot.n + 1)] + ["tool"]}))
        return EXIT_OK
    print(f"{robot.chain.name}: {robot.n} joints written to {out} (links base_link, link_1 … link_{robot.n}, tool; "
          "metres, radians)")
    return EXIT_OK


def add_commands(add) -> None:
    sp = add("import-urdf", cmd_import_urdf, "convert a URDF's serial chain to a robot file (DH, same FK)")
    sp.add_argument("file", metavar="FILE.urdf", help="URDF file")
    sp.add_argument("--base", help="first link of the chain (default: the root link)")
    sp.add_argument("--tip", help="last link of the chain (default: the only leaf link)")
    sp.add_argument("--convention", choices=("standard", "modified"), default="standard",
                    help="DH convention of the robot file (default: standard)")
    sp.add_argument("--name", help="robot name, [a-z0-9_]+ (default: from the URDF's robot name)")
    sp.add_argument("--out", required=True, metavar="ROBOT.toml", help="robot file to write")
    sp = add("export-urdf", cmd_export_urdf, "write a robot as URDF with cylinder visuals (same FK)")
    sp.add_argument("robot", metavar="ROBOT", help="bundled name or robot file")
    sp.add_argument("--out", required=True, metavar="FILE.urdf", help="URDF file to write")
