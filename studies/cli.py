"""The ``rmt`` command line.

Every command takes ROBOT as a bundled name (``rmt robots``) or a path to a robot file, reads and
prints values in the robot file's units, and with ``--json`` prints one JSON object.  Bad input
exits with code 2 and one line on stderr; ``rmt ik`` exits 1 when it finds no solution.
"""
from __future__ import annotations

import argparse
import re
import sys
from pathlib import Path
from typing import Sequence

import numpy as np

import kin
from kin.transforms import make_transform, rpy_to_matrix

from . import kinematics_study as ks
from .cli_common import dump, joint_values, numbers
from .commands_follow import add_commands as add_follow_commands
from .commands_plan import add_commands as add_plan_commands
from .commands_singular import add_commands
from .commands_toolpath import add_commands as add_toolpath_commands
from .study import run_study
from .study_report import study_report
from .units import joint_units, pose_to_file, unit_names

EXIT_OK, EXIT_FAIL, EXIT_USAGE = 0, 1, 2


class UsageError(Exception):
    """Bad command-line input (exit code 2)."""


class _Parser(argparse.ArgumentParser):
    def __init__(self, *args, **kwargs):
        super().__init__(*args, **kwargs)
        # argparse takes "-1e-5" for an option; joint values in exponent form are numbers too
        self._negative_number_matcher = re.compile(r"^-(\d+\.?\d*|\.\d+)([eE][-+]?\d+)?$")

    def error(self, message):  # one line, exit 2 (argparse prints usage + message by default)
        raise UsageError(f"{self.prog}: {message}")


def _robot(arg: str) -> kin.Robot:
    return kin.load_robot(arg)






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




# ---- commands ----------------------------------------------------------------------------------
def cmd_robots(args) -> int:
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


def cmd_show(args) -> int:
    robot = _robot(args.robot)
    c = robot.chain
    dh = ks.dh_rows(c)
    info = {"name": c.name, "title": c.title, "source": c.source, "convention": c.convention,
            "units": unit_names(c), "joints": dh,
            "base": pose_to_file(c, c.base.matrix).tolist(), "tool": pose_to_file(c, c.tool.matrix).tolist(),
            "parameters": {k: {"value": p.value / (c.length_scale if p.kind == "length" else c.angle_scale),
                               "bounds": [b / (c.length_scale if p.kind == "length" else c.angle_scale)
                                          for b in p.bounds], "kind": p.kind}
                           for k, p in c.parameters.items()},
            "task_rows": [["x", "y", "z", "rx", "ry", "rz"][r] for r in robot.task_rows]}
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
    return EXIT_OK


def cmd_fk(args) -> int:
    robot = _robot(args.robot)
    q = joint_values(robot, args.q)
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


def cmd_jacobian(args) -> int:
    robot = _robot(args.robot)
    q = joint_values(robot, args.q)
    _warn_limits(robot, q)
    r = ks.evaluate_configuration(robot, robot.chain.from_si(q))
    out = {"J": r["J"], "manipulability": r["manipulability"], "sigma_min": r["sigma_min"],
           "condition": r["condition"], "det": r["det"], "units": unit_names(robot.chain),
           "task_rows": [["x", "y", "z", "rx", "ry", "rz"][i] for i in robot.task_rows]}
    if args.json:
        print(dump(out))
        return EXIT_OK
    c = robot.chain
    print(f"J (rows vx vy vz [{c.length_unit}/s] wx wy wz [{c.angle_unit}/s] per joint rate):")
    print(_fmt_matrix(np.array(r["J"])))
    cond = "inf (singular)" if r["condition"] is None else f"{r['condition']:.6g}"
    det = "n/a (task Jacobian not square)" if r["det"] is None else f"{r['det']:.6g}"
    print(f"manipulability {r['manipulability']:.6g}  sigma_min {r['sigma_min']:.6g}  condition {cond}  det {det}")
    return EXIT_OK


def cmd_ik(args) -> int:
    robot = _robot(args.robot)
    c = robot.chain
    xyz = np.array(numbers(args.xyz, "--xyz")) * c.length_scale
    if args.rpy is not None:
        rpy = np.array(numbers(args.rpy, "--rpy")) * c.angle_scale
        target = make_transform(rpy_to_matrix(rpy), xyz)
        mode = "pose"
    else:
        target, mode = xyz, "position"
    q0 = None if args.q0 is None else joint_values(robot, args.q0, "--q0")
    res = robot.ik(target, seed=args.seed, q0=q0, mode=mode)
    out = {"success": bool(res.success), "q": c.from_si(res.q).tolist(),
           "position_error": res.position_error / c.length_scale,
           "orientation_error": res.orientation_error / c.angle_scale,
           "mode": mode, "units": unit_names(c)}
    if args.json:
        print(dump(out))
    else:
        status = "solution" if res.success else "NO solution (closest configuration found)"
        print(f"{status}: q = " + " ".join(f"{x:.6g}" for x in out["q"]))
        print(f"position error {out['position_error']:.3g} {c.length_unit}, "
              f"orientation error {out['orientation_error']:.3g} {c.angle_unit}")
    return EXIT_OK if res.success else EXIT_FAIL


def cmd_study(args) -> int:
    study = ks.load_study(args.study or ks.DEFAULT_STUDY)
    out_dir = Path(args.out) / study["name"]
    quiet = args.quiet or args.json
    progress = None if quiet or not sys.stderr.isatty() else (lambda t: print(f"… {t}", file=sys.stderr))
    results = run_study(study, out_dir, progress)
    if args.json:
        print(dump(results))
    elif not args.quiet:
        print(study_report(results, out_dir / "results.json"))
    return EXIT_OK


# ---- parser ------------------------------------------------------------------------------------
def build_parser() -> argparse.ArgumentParser:
    p = _Parser(prog="rmt", description="rmtkit: kinematics, singularities and motion planning of "
                                        "reconfigurable machine tools and robot arms")
    sub = p.add_subparsers(dest="command", metavar="COMMAND", parser_class=_Parser)
    sub.required = True

    def add(name, func, help_):
        sp = sub.add_parser(name, help=help_, description=help_)
        sp.set_defaults(func=func)
        sp.add_argument("--json", action="store_true", help="print one JSON object")
        return sp

    add("robots", cmd_robots, "list the bundled robots")
    sp = add("show", cmd_show, "show a robot's DH table, limits, base/tool and parameters")
    sp.add_argument("robot", metavar="ROBOT", help="bundled name or path to a robot .toml file")
    for name, func, text in (("fk", cmd_fk, "forward kinematics: the tool pose"),
                             ("jacobian", cmd_jacobian, "geometric Jacobian and dexterity measures")):
        sp = add(name, func, text)
        sp.add_argument("robot", metavar="ROBOT", help="bundled name or path to a robot .toml file")
        sp.add_argument("q", metavar="Q", nargs="+", help="joint values in the robot file's units")
    sp = add("ik", cmd_ik, "inverse kinematics of a tool position (and orientation); exit 1 if unsolved")
    sp.add_argument("robot", metavar="ROBOT", help="bundled name or path to a robot .toml file")
    sp.add_argument("--xyz", nargs=3, required=True, metavar=("X", "Y", "Z"), help="position, file length unit")
    sp.add_argument("--rpy", nargs=3, metavar=("R", "P", "Y"),
                    help="fixed-axis roll-pitch-yaw, file angle unit (omit for position-only IK)")
    sp.add_argument("--q0", nargs="+", metavar="Q", help="initial guess, file units")
    sp.add_argument("--seed", type=int, default=0, help="seed of the random starts (default 0)")
    for register in (add_commands, add_plan_commands, add_toolpath_commands, add_follow_commands):
        register(lambda name, func, text: add(name, lambda args, f=func: f(args, _robot), text))
    sp = add("study", cmd_study, "run a study (default: the bundled FANUC M-16iB/20 study)")
    sp.add_argument("study", metavar="STUDY", nargs="?", help="study .toml file (default: bundled)")
    sp.add_argument("--out", default="out", help="output directory (default: out)")
    sp.add_argument("--quiet", action="store_true", help="print nothing but errors")
    return p


def main(argv: Sequence[str] | None = None) -> int:
    parser = build_parser()
    try:
        args = parser.parse_args(argv)
        return args.func(args)
    except UsageError as e:
        print(f"rmt: error: {e}", file=sys.stderr)
    except kin.RmtError as e:
        print(f"rmt: error: {e}", file=sys.stderr)
    except BrokenPipeError:
        return EXIT_OK
    except KeyboardInterrupt:
        print("rmt: interrupted", file=sys.stderr)
        return 130
    return EXIT_USAGE


if __name__ == "__main__":
    sys.exit(main())
