"""``rmt place``: the robot's base placement in a work cell that reaches most targets of a task, best —
IPOPT from screened starts, cross-checked by differential evolution and a grid, every method's answer
verified by the reach study (:func:`design.place.place`).  Values on the command line and in the
printed summary are in the task file's length and angle units; ``--json`` and ``placement.json`` are
SI.  Exit 0 when the placement found reaches every target, 1 when some stay unreached, 2 on bad input."""
from __future__ import annotations

import argparse
import math
import sys
from pathlib import Path

from kin.output import check_output, write_output
from studies.cli.common import EXIT_FAIL, EXIT_OK, CliInputError, bounded, seed
from studies.cli.reach import reach_csv, task_cell
from studies.cli.tcp import with_task_cell_tcp
from studies.jsonio import dump

#: the score's dexterity measures (:data:`design.reach.MEASURES`; not imported: ``rmt --help`` stays light)
MEASURES = ("sigma_min", "manipulability")
#: the methods of :func:`design.place.place`, in the order the summary lists them
METHODS = ("current", "ipopt", "differential_evolution", "grid", "candidates")
#: how errors name the placement options (:func:`design.task.file.placement_region`)
FIELDS = {"x": "--region XMIN XMAX", "y": "--region YMIN YMAX", "z": "--region ZMIN ZMAX", "yaw": "--yaw",
          "tilt": "--tilt", "keep_out": "--keep-out", "": "placement region"}


def _number(text: str) -> float:
    """argparse type: a finite number (ranges are checked with the region)."""
    try:
        v = float(text)
    except ValueError:
        raise argparse.ArgumentTypeError(f"{text!r} is not a number") from None
    if not math.isfinite(v):
        raise argparse.ArgumentTypeError(f"{text!r} is not a finite number")
    return v


def _region(args, task, robot, cell):
    """The placement region (SI): the task's ``[placement]`` with the command line's options over it
    key by key; where neither gives a key, ``place``'s default: the targets' x–y box grown by the
    robot's reach, z at the cell's placement, yaw a full turn."""
    import numpy as np

    from design.place import PlacementRegion
    from design.task.file import placement_region
    values = {}
    if args.region is not None:
        if len(args.region) not in (4, 6):
            raise CliInputError(f"--region: give XMIN XMAX YMIN YMAX [ZMIN ZMAX] (4 or 6 numbers), got "
                                f"{len(args.region)}")
        values["x"], values["y"] = args.region[0:2], args.region[2:4]
        if len(args.region) == 6:
            values["z"] = args.region[4:6]
    if args.yaw is not None:
        values["yaw"] = args.yaw
    if args.tilt is not None:
        values["tilt"] = args.tilt
    if args.keep_out is not None:
        values["keep_out"] = args.keep_out
    z0 = float(np.asarray(cell.base)[2, 3]) if cell is not None else 0.0
    base = task.region
    if base is None and not {"x", "y"} <= set(values):
        base = PlacementRegion.default(robot, task.targets.positions, z=z0)        # as design.place.place
    if not values:
        return base
    return placement_region(values, task.length_unit, task.angle_unit, base=base, z=z0, fields=FIELDS)


def _fmt(v: float) -> str:
    return f"{v:.6g}" if abs(v) >= 1e-12 else "0"


def _interval(lo: float, hi: float, scale: float) -> str:
    return _fmt(lo / scale) if lo == hi else f"[{_fmt(lo / scale)}, {_fmt(hi / scale)}]"


def _summary(res, task, region, ls: float, as_: float) -> list[str]:
    import numpy as np

    from design.place.run import CURRENT_BEST
    lu, au = task.length_unit, task.angle_unit
    study, before = res.study, res.before
    lines = [f"{res.robot}: task {task.name}, {len(study)} targets, "
             f"{'cell ' + (study.cell or '(unnamed)') if study.cell else 'no cell'}; lengths in {lu}, angles in {au}"]
    keep = "; keep-out " + ", ".join("[" + ", ".join(_fmt(v / ls) for v in r) + "]" for r in region.keep_out) \
        if region.keep_out else ""
    lines.append(f"region: x {_interval(*region.x, ls)}, y {_interval(*region.y, ls)}, z {_interval(*region.z, ls)}, "
                 f"yaw {_interval(*region.yaw, as_)}, tilt ≤ {_fmt(region.tilt / as_)}{keep}; free: "
                 f"{', '.join(region.names())}")
    table = [["method", f"x [{lu}]", f"y [{lu}]", f"z [{lu}]", f"roll [{au}]", f"pitch [{au}]", f"yaw [{au}]",
              "coverage", "mean score", "time", ""]]
    for name in [m for m in METHODS if m in res.methods] + [m for m in res.methods if m not in METHODS]:
        m = res.methods[name]
        u = m["placement"]
        table.append([name, *(_fmt(v / ls) for v in u[:3]), *(_fmt(v / as_) for v in u[3:]),
                      f"{m['coverage_percent']:.1f} %", f"{m['mean_score']:.3f}", f"{m['time_s']:.2f} s",
                      "← answer" if name == res.method else ""])
    width = [max(len(row[i]) for row in table) for i in range(len(table[0]))]
    for row in table:
        cells = [row[0].ljust(width[0])] + [c.rjust(w) for c, w in zip(row[1:-1], width[1:-1])] + [row[-1]]
        lines.append(("  " + "  ".join(cells)).rstrip())
    u = res.u
    if res.current_is_best:
        lines.append(f"{CURRENT_BEST} (coverage {100 * study.coverage:.1f} %, "
                     f"mean score {study.mean_score:.3f}); keep the robot where it stands")
    lines.append(f"answer ({res.method}): xyz {' '.join(_fmt(v / ls) for v in u[:3])} {lu}, "
                 f"rpy {' '.join(_fmt(v / as_) for v in u[3:])} {au}")
    if before is not None:
        from kin.transforms import matrix_to_rpy
        P = before.placement
        gained = int(np.sum(study.reached & ~before.reached))
        lost = int(np.sum(before.reached & ~study.reached))
        lines.append(f"before (xyz {' '.join(_fmt(v / ls) for v in P[:3, 3])} {lu}, rpy "
                     f"{' '.join(_fmt(v / as_) for v in matrix_to_rpy(P[:3, :3]))} {au}): coverage "
                     f"{100 * before.coverage:.1f} %, mean score {before.mean_score:.3f}")
        lines.append(f"after: coverage {100 * study.coverage:.1f} %, mean score {study.mean_score:.3f}; "
                     f"{gained} target{'s' if gained != 1 else ''} gained, {lost} lost")
    missed = study.reason_counts()
    missed.pop("reached", None)
    if missed:
        lines.append("unreached at the answer: " + ", ".join(f"{k} {v}" for k, v in missed.items()))
    lines += [f"note: {n}" for n in (*res.notes, *study.notes) if not n.startswith(CURRENT_BEST)]
    return lines


def cmd_place(args, load_robot) -> int:
    from design.task import load_task
    from kin.chain import ANGLE_UNITS, LENGTH_UNITS
    from studies.cli.design import task_file
    robot = load_robot(args.robot)
    task = load_task(task_file(args.task), robot=robot)
    ls, as_ = LENGTH_UNITS[task.length_unit], ANGLE_UNITS[task.angle_unit]
    out_dir = None
    if args.out is not None:
        out_dir = Path(args.out) / task.name
        for name in ("placement.json", "reach.csv"):
            check_output(out_dir / name)
    cell, clearance = task_cell(args, task, ls)
    robot = with_task_cell_tcp(args, robot, cell)
    region = _region(args, task, robot, cell)
    from design.place import MAX_GRID, place
    k = int(region.free.sum())
    if args.grid and args.grid ** k > MAX_GRID:
        raise CliInputError(f"--grid {args.grid}: {args.grid} values on each of the {k} free coordinates "
                            f"({', '.join(region.names())}) make {args.grid ** k:.3g} placements; at most {MAX_GRID}")
    from design.reach import ScoreWeights
    from design.task import TaskError
    try:
        given = {} if args.weights is None else dict(zip(("dexterity", "clearance", "limits"), args.weights))
        weights = ScoreWeights(measure=args.measure, **given)
    except TaskError as e:
        raise CliInputError(f"--weights: {e}") from None
    progress = None if args.quiet or not sys.stderr.isatty() else (
        lambda t: print(f"… {t}", file=sys.stderr, flush=True))
    res = place(robot, task.targets, cell=cell, region=region, clearance=clearance, weights=weights,
                dexterity=task.dexterity, starts=args.starts, candidates=args.candidates, grid=args.grid,
                de_iterations=args.de_iterations, seed=task.seed if args.seed is None else args.seed,
                max_time=args.max_time, progress=progress)
    out = res.to_dict()
    if res.before is not None:
        out["targets_gained"] = int((res.study.reached & ~res.before.reached).sum())
        out["targets_lost"] = int((res.before.reached & ~res.study.reached).sum())
    out.update(task=task.name, units="SI (m, rad)", length_unit=task.length_unit, angle_unit=task.angle_unit)
    written = []
    if out_dir is not None:
        written.append(write_output(out_dir / "placement.json", dump(out) + "\n"))
        written.append(write_output(out_dir / "reach.csv", reach_csv(res.study)))
    if args.json:
        print(dump(out))
    elif not args.quiet:
        print("\n".join(_summary(res, task, res.region, ls, as_)))
        if written:
            print(f"wrote {', '.join(str(p) for p in written)}")
    return EXIT_OK if res.study.reached.all() else EXIT_FAIL


def add_commands(add) -> None:
    sp = add("place", cmd_place, "the robot's base placement that reaches most targets of a task, best: IPOPT "
                                 "from screened starts, cross-checked by differential evolution and a grid, each "
                                 "answer verified by the reach study; exit 1 if a target stays unreached")
    sp.add_argument("robot", metavar="ROBOT", help="bundled robot name or robot file (overrides the task's robot)")
    sp.add_argument("task", metavar="TASK", help="task file or bundled task name: its targets, dexterity, cell, "
                                                 "clearance and [placement] region")
    sp.add_argument("--cell", metavar="CELL",
                    help="work cell (docs/cells.md) or a bundled cell's name; default the task's; the search "
                         "starts from, and compares with, the cell's placement of the robot")
    sp.add_argument("--clearance", type=bounded(0, math.inf, "(task length unit)"), metavar="D",
                    help="with a cell: the clearance a solution needs, task length unit (default the task's)")
    sp.add_argument("--region", nargs="+", type=_number, metavar="V",
                    help="XMIN XMAX YMIN YMAX [ZMIN ZMAX]: where the base may stand, task length unit (equal "
                         "ends fix a coordinate; default the task's [placement], else around the targets)")
    sp.add_argument("--yaw", nargs=2, type=_number, metavar=("LO", "HI"),
                    help="the base's yaw range, task angle unit (default a full turn)")
    sp.add_argument("--tilt", type=_number, metavar="MAX",
                    help="largest |roll| and |pitch| of the base, task angle unit, at most 90° (default 0: level)")
    sp.add_argument("--keep-out", nargs=4, type=_number, action="append",
                    metavar=("XMIN", "XMAX", "YMIN", "YMAX"),
                    help="a floor rectangle the base's origin stays out of, task length unit (repeatable; "
                         "replaces the task's)")
    sp.add_argument("--starts", type=bounded(1, 64, "", integer=True), default=4, metavar="K",
                    help="IPOPT starts, the best screened candidates (1–64, default 4)")
    sp.add_argument("--candidates", type=bounded(1, 100_000, "", integer=True), default=32, metavar="M",
                    help="quasi-random candidate placements screened for the starts (default 32)")
    sp.add_argument("--grid", type=bounded(0, 1000, "", integer=True), default=0, metavar="G",
                    help="grid cross-check: G values per free coordinate (default 0: none)")
    sp.add_argument("--de-iterations", type=bounded(0, 100_000, "", integer=True), default=0, metavar="I",
                    help="differential-evolution cross-check: generations (default 0: none)")
    sp.add_argument("--seed", type=seed, metavar="S", help="seed of differential evolution (default the task's)")
    sp.add_argument("--max-time", type=bounded(0, 86_400, "s", open_low=True), default=600.0, metavar="SEC",
                    help="time budget of the searches, s (default 600)")
    sp.add_argument("--weights", nargs=3, type=bounded(0, 1e6, ""), metavar=("WD", "WC", "WL"),
                    help="score weights of dexterity, clearance and joint-limit margin (default 0.5 0.25 0.25)")
    sp.add_argument("--measure", choices=MEASURES, default="sigma_min",
                    help="the score's dexterity measure (default sigma_min)")
    sp.add_argument("--out", metavar="DIR", help="write DIR/TASK/placement.json and reach.csv (per target, SI)")
    sp.add_argument("--quiet", action="store_true", help="no progress lines and no summary (errors only)")


__all__ = ["add_commands", "cmd_place", "MEASURES"]
