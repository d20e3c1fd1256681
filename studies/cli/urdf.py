"""``rmt import-urdf`` and ``rmt export-urdf``: a URDF's serial chain (and its collision geometry, as
capsules) as a robot file, and any robot (bundled, a file, a designed one) as a URDF with simple
cylinder visuals and its collision capsules."""
from __future__ import annotations

from pathlib import Path

from studies.cli.common import EXIT_OK, CliInputError, bounded
from studies.jsonio import dump


def _out_path(out: str, suffix: str) -> Path:
    """``--out``, checked before any work as every command's is (:func:`kin.output.check_output`:
    a regular file or nothing; missing parent directories are made when it is written)."""
    from kin.output import check_output
    path = Path(out)
    if path.suffix != suffix:
        raise CliInputError(f"--out {out!r} must end in {suffix}")
    return check_output(path)


def _save_checked(chain, out: Path, urdf: str) -> Path:
    """Write ``chain`` to ``out`` only as a file the robot-file reader loads: its text is read back
    (:func:`kin.robotfile.loads_robot`, within the reader's size cap) and must give the same chain
    before :func:`kin.output.write_output` writes it (parents made).  On a refusal nothing is written
    and one :class:`kin.urdf.UrdfError` names the URDF and the field."""
    from kin.errors import RobotFileError
    from kin.output import write_output
    from kin.robotfile import MAX_ROBOT_BYTES, dumps_robot, loads_robot
    from kin.urdf import UrdfError

    text = dumps_robot(chain, out.parent)          # [visual] mesh files named relative to the robot file
    try:
        size = len(text.encode("utf-8"))
        if size > MAX_ROBOT_BYTES:
            raise RobotFileError(f"{size} bytes; a robot file may have at most {MAX_ROBOT_BYTES // 2**20} MB",
                                 str(out))
        back = loads_robot(text, str(out))
    except RobotFileError as e:
        raise UrdfError(f"the robot file made of it is refused by the robot-file reader ({e.field or 'the file'}: "
                        f"{str(e).rsplit(': ', 1)[-1]}); nothing written; please report this URDF", urdf) from None
    if back != chain:
        raise UrdfError("the robot file made of it reads back as another robot; nothing written; please report "
                        "this URDF", urdf)
    return write_output(out, text)


def _packages(items) -> dict[str, str]:
    out = {}
    for item in items or ():
        name, sep, directory = item.partition("=")
        if not sep or not name or not directory:
            raise CliInputError(f"--package {item!r} must be NAME=DIR")
        if not Path(directory).is_dir():
            raise CliInputError(f"--package {item!r}: directory {directory!r} does not exist")
        out[name] = directory
    return out


def cmd_import_urdf(args, load_robot) -> int:
    import sys
    import warnings

    from kin.urdf import UrdfWarning, chain_from_serial, read_serial_chain
    from studies.cli.progress import TerminalProgress

    out = _out_path(args.out, ".toml")
    packages = _packages(args.package)
    with warnings.catch_warnings(record=True) as caught, TerminalProgress() as progress:
        warnings.simplefilter("always", UrdfWarning)
        sc = read_serial_chain(args.file, args.base, args.tip)
        chain = chain_from_serial(sc, args.convention, args.name, collision=not args.no_collision,
                                  max_capsules=args.capsules_per_mesh, package_dirs=packages,
                                  search="exhaustive" if args.thorough else "fast", progress=progress,
                                  srdf=args.srdf, hulls=None if args.hulls is None else args.hulls / 1000)
    notes = [str(w.message) for w in caught if issubclass(w.category, UrdfWarning)]
    for note in notes:
        print(f"rmt: warning: {note}", file=sys.stderr)
    _save_checked(chain, out, args.file)
    g = chain.geometry
    if args.json:
        print(dump({"out": str(out), "name": chain.name, "joints": chain.n, "types": list(chain.joint_types),
                    "convention": chain.convention, "base_is_identity": chain.base.is_identity,
                    "tool_is_identity": chain.tool.is_identity, "capsules": 0 if g is None else len(g.capsules),
                    "hulls": 0 if g is None else len(g.hulls),
                    "over_estimate": None if g is None else g.over_estimate,
                    "geometry_source": None if g is None else g.source, "source": chain.source,
                    "states": {k: list(v) for k, v in chain.states.items()}, "warnings": notes}))
        return EXIT_OK
    types = "".join("R" if j.is_revolute else "P" for j in chain.joints)
    print(f"{args.file}: {chain.title}")
    if sc.tip_note:
        print(sc.tip_note)
    print(f"{chain.n} joints ({types}), {chain.convention} DH, written to {out} (m, rad); "
          f"see it with: rmt show {out}")
    if g is not None:
        hulls = f", {len(g.hulls)} hulls" if g.hulls else ""
        print(f"collision geometry: {len(g.capsules)} capsules{hulls}; {g.source}")
        if args.srdf:
            print(f"self-collision: {len(g.allowed)} body pair(s) the SRDF disables are not checked")
    elif not args.no_collision:
        print("collision geometry: none in the URDF; the robot gets the default capsules along its DH offsets")
    if chain.states:
        print(f"named states from the SRDF: {', '.join(chain.states)} (a configuration wherever one is taken: "
              f"rmt fk {out} {next(iter(chain.states))})")
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
          f"metres, radians; {len(robot.geometry.capsules)} collision capsules, each a cylinder and two spheres)")
    return EXIT_OK


def add_commands(add) -> None:
    sp = add("import-urdf", cmd_import_urdf, "convert a URDF's serial chain to a robot file (DH, same FK)")
    sp.add_argument("file", metavar="FILE.urdf", help="URDF file")
    sp.add_argument("--base", help="first link of the chain (default: the root link)")
    sp.add_argument("--tip", help="last link of the chain (default: the only leaf link)")
    sp.add_argument("--convention", choices=("standard", "modified"), default="standard",
                    help="DH convention of the robot file (default: standard)")
    sp.add_argument("--name", help="robot name, [a-z0-9_]+ (default: from the URDF's robot name)")
    sp.add_argument("--no-collision", action="store_true",
                    help="leave out the links' <collision> elements (and their mesh files): default capsules")
    sp.add_argument("--capsules-per-mesh", type=int, choices=(1, 2, 3), default=3,
                    help="capsules enclosing each collision mesh, at most (default: 3)")
    sp.add_argument("--thorough", action="store_true",
                    help="score every candidate cut of each mesh exactly (how the bundled arms were fitted; several "
                         "times slower)")
    sp.add_argument("--hulls", nargs="?", const=1.0, default=None, metavar="MM", type=bounded(0.01, 100, "mm"),
                    help="also keep each collision element as a hull (a mesh's convex hull thinned to within MM, "
                         "default 1 mm): where the capsules come too close, clearances are the hulls' "
                         "(tighter; checks slower there)")
    sp.add_argument("--package", action="append", metavar="NAME=DIR",
                    help="directory of the ROS package NAME for package:// mesh paths (repeatable; default: "
                         "the directory of that name above the URDF file)")
    sp.add_argument("--srdf", metavar="FILE.srdf",
                    help="a MoveIt SRDF: body pairs all of whose links' pairs it disables are not checked for "
                         "self-collision (the robot file's allow); its group states that set every joint of the "
                         "chain become named states (the robot file's [states], e.g. --start home)")
    sp.add_argument("--out", required=True, metavar="ROBOT.toml", help="robot file to write")
    sp = add("export-urdf", cmd_export_urdf, "write a robot as URDF with cylinder visuals and collision capsules")
    sp.add_argument("robot", metavar="ROBOT", help="bundled name or robot file")
    sp.add_argument("--out", required=True, metavar="FILE.urdf", help="URDF file to write")
