"""``rmt robots``, ``show``, ``fk``, ``jacobian``: a robot's description and its kinematics at one
configuration, in the robot file's units (``rmt ik``: :mod:`studies.cli.ik`)."""
from __future__ import annotations

import sys

import numpy as np

import kin
from kin.chain import MAX_PRISMATIC
from studies.cli.common import EXIT_OK, CliInputError, joint_values
from studies.jsonio import dump
from studies.taskrows import require_task_rows
from studies.units import joint_units, pose_to_file, unit_names


def configuration(robot: kin.Robot, values, what: str = "joint values") -> np.ndarray:
    """A configuration given in the robot file's units → SI: :func:`joint_values` (count, finiteness),
    and every prismatic joint within ±:data:`kin.chain.MAX_PRISMATIC` (the range the evaluators accept;
    far outside any limit), else one line naming the argument, the joint and that range in file units."""
    c = robot.chain
    q = joint_values(robot, values, what)
    for i, j in enumerate(c.joints):
        if not j.is_revolute and not abs(q[i]) <= MAX_PRISMATIC:
            s, u = c.length_scale, c.length_unit
            raise CliInputError(f"{what}: joint {i + 1} = {q[i] / s:.6g} {u} is beyond ±{MAX_PRISMATIC / s:g} {u}, "
                                f"the range a prismatic joint value may take (its limits: [{j.limits[0] / s:.6g}, "
                                f"{j.limits[1] / s:.6g}] {u})")
    return q


def _warn_limits(robot: kin.Robot, q: np.ndarray) -> None:
    chain = robot.chain
    for i, v, (lo, hi) in chain.limit_violations(q):
        s = chain.variable_scale[i - 1]
        u = joint_units(chain)[i - 1]
        print(f"rmt: warning: joint {i} = {v / s:.6g} {u} is outside its limits [{lo / s:.6g}, {hi / s:.6g}] {u}",
              file=sys.stderr)


def _fmt_matrix(M: np.ndarray, width: int = 11, prec: int = 6) -> str:
    # + 0.0 turns -0.0 into 0.0
    return "\n".join("  " + " ".join(f"{x + 0.0:{width}.{prec}g}" for x in row) for row in np.asarray(M))


def cmd_robots(args, load_robot) -> int:
    rows = []
    for name in kin.bundled_robots():
        c = kin.load_chain(name)
        rows.append({"name": name, "title": c.title, "joints": c.n,
                     "types": "".join("R" if j.is_revolute else "P" for j in c.joints),
                     "convention": c.convention, "units": unit_names(c), "source": c.source})
    if args.json:
        print(dump({"robots": rows}))
        return EXIT_OK
    w = max(len(r["name"]) for r in rows)
    for r in rows:
        print(f"{r['name']:<{w}}  {r['types']:<7} {r['units']['length']:>2}/"
              f"{r['units']['angle']:<3}  {r['title']}")
    return EXIT_OK


def cmd_show(args, load_robot) -> int:
    from studies.study import kinematics as ks
    robot = load_robot(args.robot)
    c = robot.chain
    dh = ks.dh_rows(c)
    info = {"name": c.name, "title": c.title, "source": c.source, "convention": c.convention,
            "units": unit_names(c), "joints": dh,
            "base": pose_to_file(c, c.base.matrix).tolist(), "tool": pose_to_file(c, c.tool.matrix).tolist(),
            "parameters": {k: {"value": p.value / (c.length_scale if p.kind == "length" else c.angle_scale),
                               "bounds": [b / (c.length_scale if p.kind == "length" else c.angle_scale)
                                          for b in p.bounds], "kind": p.kind}
                           for k, p in c.parameters.items()},
            "task_rows": [["x", "y", "z", "rx", "ry", "rz"][r] for r in robot.task_rows],
            "dynamics": _dynamics_info(c),
            "states": {k: c.from_si(v).tolist() for k, v in c.states.items()}}
    if args.json:
        print(dump(info))
        return EXIT_OK
    print(f"{c.name}: {c.title}")
    if c.source:
        print(f"source: {c.source}")
    print(f"{c.convention} DH, lengths in {c.length_unit}, angles in {c.angle_unit}; "
          f"task rows: {' '.join(info['task_rows'])}")
    print(f"{'i':>2} {'type':<9} {'a':>10} {'alpha':>10} {'d':>10} {'theta':>10}   limits")
    for r in dh:
        cells = [f"{r[f]:>10.6g}" if not isinstance(r[f], str) else f"{r[f]:>10}" for f in ("a", "alpha", "d", "theta")]
        print(f"{r['joint']:>2} {r['type']:<9} {' '.join(cells)}   [{r['limits'][0]:.6g}, {r['limits'][1]:.6g}]")
    for label, pl in (("base", c.base), ("tool", c.tool)):
        if not np.array_equal(pl.matrix, np.eye(4)):
            print(f"{label}:\n{_fmt_matrix(pose_to_file(c, pl.matrix))}")
    for k, p in info["parameters"].items():
        print(f"parameter {k} = {p['value']:.6g} in [{p['bounds'][0]:.6g}, {p['bounds'][1]:.6g}] ({p['kind']})")
    for k, v in info["states"].items():
        print(f"state {k} = " + " ".join(f"{x:.6g}" for x in v))
    d = info["dynamics"]
    if any(j["mass_kg"] is not None or j["max_torque"] is not None for j in d["joints"]):
        print("dynamics (SI): link mass, joint torque limit (N·m, N for prismatic joints)")
        for i, j in enumerate(d["joints"], 1):
            m = "—" if j["mass_kg"] is None else f"{j['mass_kg']:.6g} kg"
            t = "—" if j["max_torque"] is None else f"{j['max_torque']:.6g}"
            print(f"{i:>2} mass {m:>12}   max torque {t:>8}")
        if d["payload_kg"] is not None:
            print(f"payload {d['payload_kg']:.6g} kg")
    else:
        print("dynamics: no inertial data or torque limits in this robot file")
    return EXIT_OK


def _dynamics_info(c) -> dict:
    """Per joint: the link's mass (kg) and the joint's torque limit (N·m or N), None where unknown;
    the payload's mass and gravity (m/s², base placement frame)."""
    joints = [{"mass_kg": None if j.inertia is None else float(j.inertia.mass),
               "max_torque": None if j.max_torque is None else float(j.max_torque)} for j in c.joints]
    return {"joints": joints, "payload_kg": None if c.payload is None else float(c.payload.mass),
            "gravity": [float(g) for g in c.gravity]}


def cmd_fk(args, load_robot) -> int:
    robot = load_robot(args.robot)
    q = configuration(robot, args.q)
    _warn_limits(robot, q)
    T = pose_to_file(robot.chain, robot.fk(q))
    out = {"T": T.tolist(), "position": T[:3, 3].tolist(), "units": unit_names(robot.chain),
           "within_limits": bool(robot.within_limits(q))}
    if args.json:
        print(dump(out))
    else:
        print(f"T ({robot.chain.length_unit}):\n{_fmt_matrix(T)}")
        print("position: " + " ".join(f"{x:.6g}" for x in T[:3, 3]))
    return EXIT_OK


def cmd_jacobian(args, load_robot) -> int:
    from studies.study import kinematics as ks
    robot = require_task_rows(load_robot(args.robot))
    q = configuration(robot, args.q)
    _warn_limits(robot, q)
    r = ks.evaluate_configuration(robot, robot.chain.from_si(q))
    # the dexterity measures in SI (J in m/s and rad/s per rad/s or m/s), as plan, check-path,
    # validate-toolpath and the σ_min floor give them; J itself is printed in the file's units
    si = r["si"]
    out = {"J": r["J"], "manipulability": si["manipulability"], "sigma_min": si["sigma_min"],
           "condition": si["condition"], "det": si["det"], "units": {**unit_names(robot.chain), "J": "robot file units",
                                                                "measures": "SI"},
           "task_rows": [["x", "y", "z", "rx", "ry", "rz"][i] for i in robot.task_rows]}
    if args.json:
        print(dump(out))
        return EXIT_OK
    c = robot.chain
    print(f"J (rows vx vy vz [{c.length_unit}/s] wx wy wz [{c.angle_unit}/s] per joint rate in "
          f"{'/'.join(sorted(set(joint_units(c))))}/s):")
    print(_fmt_matrix(np.array(r["J"])))
    cond = "inf (singular)" if out["condition"] is None else f"{out['condition']:.6g}"
    det = "n/a (task Jacobian not square)" if si["det"] is None else f"{si['det']:.6g}"
    print(f"manipulability {out['manipulability']:.6g}  sigma_min {out['sigma_min']:.6g}  condition {cond}  "
          f"det {det}  (SI: J in m/s and rad/s per rad/s or m/s)")
    return EXIT_OK


def add_commands(add) -> None:
    add("robots", cmd_robots, "list the bundled robots")
    sp = add("show", cmd_show, "show a robot's DH table, limits, base/tool and parameters")
    sp.add_argument("robot", metavar="ROBOT", help="bundled name or path to a robot .toml file")
    for name, func, text in (("fk", cmd_fk, "forward kinematics: the tool pose"),
                             ("jacobian", cmd_jacobian, "geometric Jacobian and dexterity measures")):
        sp = add(name, func, text)
        sp.add_argument("robot", metavar="ROBOT", help="bundled name or path to a robot .toml file")
        sp.add_argument("q", metavar="Q", nargs="+", help="joint values in the robot file's units, or the name "
                                                          "of one of its states (e.g. home; see rmt show)")
