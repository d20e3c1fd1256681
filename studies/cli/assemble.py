"""``rmt assemble`` and ``rmt modules``: a robot file made of catalogue modules (:mod:`kin.modules`),
and what a module catalogue holds.

``rmt assemble CATALOGUE --modules NAME[@TWIST] ... --out ROBOT.toml`` builds the robot of the
assembly (:func:`kin.modules.assemble`), checks that every joint holds the rest of the chain at rest
(:func:`kin.modules.holding`), and writes it — only as a file the robot-file reader reads back as the
same robot.  A joint that provably cannot hold the chain exits 1 and writes nothing, unless
``--no-holding-check``.  ``rmt modules [CATALOGUE]`` lists a catalogue's connector types and its
modules per kind with their key numbers (the bundled catalogues without one).
"""
from __future__ import annotations

import math
import re
import sys
from pathlib import Path

import numpy as np

from studies.cli.common import EXIT_FAIL, EXIT_OK, CliInputError
from studies.jsonio import dump

#: joint fields compared when the written text is read back (SI; relative to the robot's size)
READ_BACK_TOL = 1e-9


def _out_path(out: str) -> Path:
    from kin.output import check_output
    path = Path(out)
    if path.suffix != ".toml":
        raise CliInputError(f"--out {out!r} must end in .toml (a robot file)")
    return check_output(path)


def _robot_name(args, out: Path) -> str:
    """``--name``, else the output file's stem made a robot name ([a-z0-9_]+)."""
    from kin.chain import NAME_RE
    if args.name is not None:
        if not NAME_RE.match(args.name):
            raise CliInputError(f"--name {args.name!r} must match [a-z0-9_]+")
        return args.name
    stem = re.sub(r"[^a-z0-9_]+", "_", out.stem.lower()).strip("_")
    return stem if stem and NAME_RE.match(stem) else "assembly"


def _same_robot(a, b) -> bool:
    """Whether the chain read back from the written text is the assembled one (numbers to rounding)."""
    if (a.n, a.joint_types, a.length_unit, a.angle_unit) != (b.n, b.joint_types, b.length_unit, b.angle_unit):
        return False
    scale = max(1.0, float(np.abs(a.base.matrix[:3, 3]).max()), *(abs(j.a) + abs(j.d) for j in a.joints))

    def close(x, y) -> bool:
        return bool(np.allclose(np.asarray(x, float), np.asarray(y, float), rtol=READ_BACK_TOL,
                                atol=READ_BACK_TOL * scale))
    for ja, jb in zip(a.joints, b.joints):
        if not close([ja.a, ja.alpha, ja.d, ja.theta, *ja.limits], [jb.a, jb.alpha, jb.d, jb.theta, *jb.limits]):
            return False
        if (ja.inertia is None) != (jb.inertia is None) or (ja.inertia is not None and not close(
                [ja.inertia.mass, *ja.inertia.com, *ja.inertia.inertia],
                [jb.inertia.mass, *jb.inertia.com, *jb.inertia.inertia])):
            return False
    pa, pb = a.payload, b.payload
    if (pa is None) != (pb is None) or (pa is not None and not close([pa.mass, *pa.com], [pb.mass, *pb.com])):
        return False
    return close(a.base.matrix, b.base.matrix) and close(a.tool.matrix, b.tool.matrix)


def _write_checked(chain, out: Path) -> Path:
    """Write ``chain`` to ``out`` only as text the robot-file reader reads back as the same robot."""
    from kin.errors import RobotFileError
    from kin.modules import AssemblyError
    from kin.output import write_output
    from kin.robotfile import dumps_robot, loads_robot

    text = dumps_robot(chain, out.parent)
    try:
        back = loads_robot(text, str(out))
    except RobotFileError as e:
        raise AssemblyError(f"the robot file made of the assembly is refused by the robot-file reader ({e}); "
                            "nothing written; please report this assembly") from None
    if not _same_robot(chain, back):
        raise AssemblyError("the robot file made of the assembly reads back as another robot; nothing written; "
                            "please report this assembly")
    return write_output(out, text)


def _masses(cat, assembly, chain) -> dict:
    """kg: every part of every module, the moving bodies, the tool (payload), the rest (standing)."""
    total = float(sum(cat.modules[m].proximal.mass + cat.modules[m].distal.mass for m in assembly.modules))
    moving = float(sum(j.inertia.mass for j in chain.joints if j.inertia is not None))
    tool = 0.0 if chain.payload is None else float(chain.payload.mass)
    return {"total": total, "moving": moving, "tool": tool, "standing": max(total - moving - tool, 0.0)}


def _holding_rows(rep, chain) -> list[dict]:
    rows = []
    for j, joint in enumerate(chain.joints):
        tm = rep.max_torque[j]
        rows.append({"joint": j + 1, "name": joint.name, "verdict": rep.verdict[j], "bound": float(rep.bound[j]),
                     "witness": float(rep.witness[j]), "witness_q": chain.from_si(rep.witness_q[j]).tolist(),
                     "max_torque": None if math.isnan(tm) else float(tm),
                     "unit": "N·m" if joint.is_revolute else "N"})
    return rows


def cmd_assemble(args, load_robot) -> int:
    from kin.modules import Assembly, assemble, holding, load_catalogue
    from studies.study.kinematics import dh_rows
    from studies.units import unit_names

    out = _out_path(args.out)
    name = _robot_name(args, out)
    cat = load_catalogue(args.catalogue)
    assembly = Assembly.parse(" ".join(args.modules), cat)
    chain = assemble(cat, assembly, name=name, check_holding=False)
    rep = holding(chain)
    text = assembly.text(cat)
    refused = None
    if rep.fails and not args.no_holding_check:
        refused = rep.failure_text(chain)
    else:
        _write_checked(chain, out)
    cost = assembly.cost(cat)
    masses = _masses(cat, assembly, chain)
    if args.json:
        print(dump({"out": str(out), "written": refused is None, "refused": refused, "name": chain.name,
                    "catalogue": cat.name, "assembly": text, "modules": list(assembly.modules),
                    "cost": cost, "currency": cat.currency, "joints": dh_rows(chain), "units": unit_names(chain),
                    "mass_kg": masses, "holding": _holding_rows(rep, chain)}))
    if refused is not None:
        print(f"rmt assemble: {refused}; nothing written (--no-holding-check writes it anyway)", file=sys.stderr)
        return EXIT_FAIL
    if args.json:
        return EXIT_OK
    _print_summary(cat, chain, text, cost, masses, rep, out)
    return EXIT_OK


def _print_summary(cat, chain, text, cost, masses, rep, out) -> None:
    from kin.transforms import matrix_to_rpy
    from studies.study.kinematics import dh_rows
    from studies.units import joint_units

    cur = f" {cat.currency}" if cat.currency else ""
    print(f"{chain.name}: {text} (catalogue {cat.name})")
    print(f"cost: {cost:g}{cur}")
    types = "".join("R" if j.is_revolute else "P" for j in chain.joints)
    print(f"{chain.n} joint{'s' if chain.n != 1 else ''} ({types}), standard DH, lengths in {chain.length_unit}, "
          f"angles in {chain.angle_unit}:")
    print(f"{'i':>2} {'type':<9} {'a':>10} {'alpha':>10} {'d':>10} {'theta':>10}   {'limits':<20} max torque")
    units = joint_units(chain)
    for r, j, u in zip(dh_rows(chain), chain.joints, units):
        cells = " ".join(f"{r[f] + 0.0:>10.6g}" for f in ("a", "alpha", "d", "theta"))
        lim = f"[{r['limits'][0]:.6g}, {r['limits'][1]:.6g}] {u}"
        tq = "—" if j.max_torque is None else f"{j.max_torque:.6g} {'N·m' if j.is_revolute else 'N'}"
        print(f"{r['joint']:>2} {r['type']:<9} {cells}   {lim:<20} {tq}")
    for label, pl in (("base", chain.base), ("tool", chain.tool)):
        T = pl.matrix
        if not np.array_equal(T, np.eye(4)):
            xyz = " ".join(f"{x / chain.length_scale + 0.0:.6g}" for x in T[:3, 3])
            rpy = " ".join(f"{x / chain.angle_scale + 0.0:.6g}" for x in matrix_to_rpy(T[:3, :3]))
            print(f"{label}: xyz {xyz} {chain.length_unit}, rpy {rpy} {chain.angle_unit}")
    print(f"mass: {masses['total']:.6g} kg in all — moving {masses['moving']:.6g} kg, tool (payload) "
          f"{masses['tool']:.6g} kg, standing {masses['standing']:.6g} kg")
    print("holding the rest of the chain at rest, over the joint limits:")
    for line in rep.lines(chain):
        print(f"  {line}")
    if rep.fails:
        print(f"rmt assemble: warning: {rep.failure_text(chain)} (written anyway: --no-holding-check)",
              file=sys.stderr)
    print(f"written to {out}; see it with: rmt show {out}")


# ---- rmt modules ----------------------------------------------------------------------------------
def _module_row(cat, m) -> dict:
    ls, as_ = cat.length_scale, cat.angle_scale
    T = m.axis @ m.out if m.is_joint else m.out
    row = {"name": m.name, "kind": m.kind, "title": m.title, "cost": m.cost,
           "mass_kg": m.proximal.mass + m.distal.mass, "input": m.input, "output": m.output,
           "length": float(np.linalg.norm(T[:3, 3])) / ls,
           "bend": float(math.acos(max(-1.0, min(1.0, T[2, 2])))) / as_}
    if m.is_joint:
        s = as_ if m.type == "revolute" else ls
        row.update(type=m.type, limits=[m.limits[0] / s, m.limits[1] / s], max_velocity=m.max_velocity / s,
                   max_acceleration=None if m.max_acceleration is None else m.max_acceleration / s,
                   max_torque=m.max_torque, torque_unit="N·m" if m.type == "revolute" else "N")
    return row


def _list_bundled(args) -> int:
    from kin.modules import bundled_catalogues, load_catalogue
    rows = []
    for name in bundled_catalogues():
        c = load_catalogue(name)
        rows.append({"name": name, "title": c.title, "modules": len(c.modules),
                     "joints": len(c.of_kind("joint")), "source": c.source})
    if args.json:
        print(dump({"catalogues": rows}))
        return EXIT_OK
    if not rows:
        print("no bundled module catalogues")
    w = max((len(r["name"]) for r in rows), default=0)
    for r in rows:
        print(f"{r['name']:<{w}}  {r['modules']:>4} modules ({r['joints']} joint)  {r['title']}")
    return EXIT_OK


def cmd_modules(args, load_robot) -> int:
    from kin.modules import load_catalogue

    if args.catalogue is None:
        return _list_bundled(args)
    cat = load_catalogue(args.catalogue)
    lu, au = cat.length_unit, cat.angle_unit
    conns = [{"name": c.name, "root": c.root, "twists": [t / cat.angle_scale for t in c.twists]}
             for c in cat.connectors.values()]
    rows = [_module_row(cat, m) for m in cat.modules.values()]
    if args.json:
        print(dump({"name": cat.name, "title": cat.title, "source": cat.source, "path": cat.path,
                    "units": {"length": lu, "angle": au}, "currency": cat.currency, "connectors": conns,
                    "modules": rows}))
        return EXIT_OK
    print(f"{cat.name}: {cat.title}" if cat.title else cat.name)
    if cat.source:
        print(f"source: {cat.source}")
    cur = f"costs in {cat.currency}" if cat.currency else "costs"
    print(f"lengths in {lu}, angles in {au}, masses in kg, {cur}; "
          f"{len(cat.modules)} modules, {len(conns)} connector type{'s' if len(conns) != 1 else ''}")
    print("connectors (the twists at which two faces of a type meet):")
    w = max(len(c["name"]) for c in conns)
    for c in conns:
        like = "" if c["root"] == c["name"] else f"  (meets as {c['root']})"
        print(f"  {c['name']:<{w}}  twists {', '.join(f'{t:g}' for t in c['twists'])}{like}")
    w = max(len(r["name"]) for r in rows)
    for kind, title in (("base", "bases"), ("joint", "joints"), ("link", "links"), ("tool", "tools")):
        mine = [r for r in rows if r["kind"] == kind]
        if not mine:
            continue
        print(f"{title}:")
        for r in mine:
            faces = f"{r['input'] or '·'} → {r['output'] or '·'}"
            head = f"  {r['name']:<{w}}  {r['cost']:>9g}  {r['mass_kg']:>7.4g} kg  length {r['length']:.4g} {lu}"
            bend = f", bend {r['bend']:.4g} {au}" if r["bend"] > 1e-9 else ""
            if kind == "joint":
                u = au if r["type"] == "revolute" else lu
                print(f"{head}{bend}  {r['type']}, {r['max_torque']:.4g} {r['torque_unit']}, travel "
                      f"[{r['limits'][0]:g}, {r['limits'][1]:g}] {u}, {r['max_velocity']:.4g} {u}/s  {faces}")
            else:
                print(f"{head}{bend}  {faces}")
    return EXIT_OK


def add_commands(add) -> None:
    sp = add("assemble", cmd_assemble, "build a robot file from catalogue modules (NAME[@TWIST] ...), checked")
    sp.add_argument("catalogue", metavar="CATALOGUE", help="bundled module catalogue name or path to a .toml file")
    sp.add_argument("--modules", nargs="+", required=True, metavar="NAME[@TWIST]",
                    help="the modules, base first, each mounted on the one before at TWIST (catalogue angle unit, "
                         "default 0)")
    sp.add_argument("--name", help="robot name, [a-z0-9_]+ (default: from --out's file name)")
    sp.add_argument("--out", required=True, metavar="ROBOT.toml", help="robot file to write")
    sp.add_argument("--no-holding-check", action="store_true",
                    help="write the robot even when a joint provably cannot hold the rest of the chain at rest")
    sp = add("modules", cmd_modules, "list a module catalogue's connectors and modules (or the bundled catalogues)")
    sp.add_argument("catalogue", metavar="CATALOGUE", nargs="?",
                    help="bundled module catalogue name or path to a .toml file (default: list the bundled ones)")
