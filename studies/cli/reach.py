"""``rmt reach`` (the reach study of a task: per target the verdict, the score and the reason it is
missed, for a robot placed in a work cell; :func:`design.reach.reach_study`) and ``rmt reach-compare``
(two saved studies side by side; :func:`design.reach.compare_studies`).  Values on the command line
and in the printed summary are in the task file's length and angle units; ``--json``, ``reach.json``
and ``reach.csv`` are SI.  ``rmt reach`` exits 0 when every target is reached, 1 when some are not,
2 on bad input."""
from __future__ import annotations

import csv
import io
import math
import sys
import unicodedata
from pathlib import Path

from kin.output import check_output, write_output
from studies.cli.common import (
    EXIT_FAIL,
    EXIT_OK,
    CliInputError,
    bounded,
    cell_file,
    numbers,
    window_width_args,
    windows_from_args,
)
from studies.cli.tcp import with_task_cell_tcp
from studies.jsonio import dump

#: the score's dexterity measures (:data:`design.reach.MEASURES`; not imported: ``rmt --help`` stays light)
MEASURES = ("sigma_min", "manipulability")
#: a reach study JSON (rmt reach-compare's input) may have at most this many bytes
MAX_STUDY_BYTES = 200 * 2**20
#: unreached targets listed in the summary
LISTED = 20


def reach_csv(study, length_scale: float = 1.0) -> str:
    """One row per target of a reach study: position (÷ ``length_scale``), verdict, score and its terms
    (SI), reason, obstacle, support, the configuration q1 … qn (SI)."""
    rows = study.rows()
    n = len(rows[0]["q"]) if rows else 0
    keys = [k for k in (rows[0] if rows else {}) if k != "q"]
    buf = io.StringIO()
    w = csv.writer(buf, lineterminator="\n")
    w.writerow(keys + [f"q{i + 1}" for i in range(n)])
    for r in rows:
        vals = []
        for k in keys:
            v = r[k]
            if k in ("x", "y", "z"):
                v = v / length_scale
            vals.append("" if v is None else (repr(float(v)) if isinstance(v, float) else v))
        w.writerow(vals + [repr(float(v)) for v in r["q"]])
    return buf.getvalue()


def task_cell(args, task, ls: float):
    """The work cell and the required clearance (SI) of a task, ``--cell`` and ``--clearance`` (task
    length unit) over the task's own."""
    cell = task.cell
    if args.cell is not None:
        from planning.cell import load_cell
        cell = load_cell(cell_file(args.cell))
    clearance = task.clearance
    if args.clearance is not None:
        from planning.collision import MAX_MARGIN
        if cell is None:
            raise CliInputError("--clearance needs --cell (or a task file with a cell)")
        clearance = args.clearance * ls
        if clearance > MAX_MARGIN:
            raise CliInputError(f"--clearance {args.clearance:g} is outside the allowed range [0, "
                                f"{MAX_MARGIN / ls:g}] {task.length_unit}")
    return cell, clearance


def _fmt(v: float) -> str:
    return f"{v:.6g}" if abs(v) >= 1e-12 else "0"


def _summary(study, task, ls: float, as_: float) -> list[str]:
    import numpy as np

    from kin.transforms import matrix_to_rpy
    lu, au = task.length_unit, task.angle_unit
    P = study.placement
    lines = [f"{study.robot}: task {task.name}, {len(study)} targets ({study.orientation}), "
             f"{'cell ' + study.cell if study.cell else 'no cell'}; lengths in {lu}, angles in {au}",
             f"placement: xyz {' '.join(_fmt(v / ls) for v in P[:3, 3])} {lu}, rpy "
             f"{' '.join(_fmt(v / as_) for v in matrix_to_rpy(P[:3, :3]))} {au}",
             f"reached: {int(study.reached.sum())} of {len(study)} ({100 * study.coverage:.1f} %), mean score "
             f"{study.mean_score:.3f} (over the reached: "
             f"{float(study.score[study.reached].mean()) if study.reached.any() else 0.0:.3f})"]
    counts = study.reason_counts()
    counts.pop("reached", None)
    if counts:
        lines.append("missed: " + ", ".join(f"{k.replace('_', ' ')} {v}" for k, v in counts.items()))
    if study.obstacle_counts():
        lines.append("collisions by object: " + ", ".join(f"{k} {v}" for k, v in study.obstacle_counts().items()))
    if study.fragile.any():
        lines.append(f"fragile (reached from one start only): {int(study.fragile.sum())}")
    miss = np.flatnonzero(~study.reached)
    if len(miss):
        lines.append(f"unreached targets (first {min(LISTED, len(miss))} of {len(miss)}):")
        for i in miss[:LISTED]:
            p = " ".join(f"{v / ls:.5g}" for v in study.positions[i])
            lines.append(f"  {i:5d}  ({p}) {lu}  {study.reason[i]}: {study.detail[i]}")
    lines += [f"note: {n}" for n in study.notes]
    return lines


def cmd_reach(args, load_robot) -> int:
    from design.reach import ReachSettings, ScoreWeights, reach_study
    from design.task import TaskError, load_task
    from kin.chain import ANGLE_UNITS, LENGTH_UNITS
    from studies.cli.design import task_file
    robot = load_robot(args.robot)
    task = load_task(task_file(args.task), robot=robot)
    ls, as_ = LENGTH_UNITS[task.length_unit], ANGLE_UNITS[task.angle_unit]
    outputs = {}
    if args.out is not None:
        d = Path(args.out) / task.name
        outputs = {k: d / k for k in ("reach.json", "reach.csv", "reach_score.png", "reach_reason.png")}
    if args.csv is not None:
        outputs["csv"] = Path(args.csv)
    if args.plot is not None:
        outputs["plot"] = Path(args.plot)
    for p in outputs.values():
        check_output(p)
    cell, clearance = task_cell(args, task, ls)
    robot = with_task_cell_tcp(args, robot, cell)
    placement = None
    if args.placement is not None:
        import numpy as np

        from design.task.file import MAX_PLACEMENT
        u = np.array(numbers(args.placement, "--placement"))
        placement = np.concatenate([u[:3] * ls, u[3:] * as_])
        # the bounds of a task's [placement] region (design.task.file): ±10 km, angles within ±2π
        if np.abs(placement[:3]).max() > MAX_PLACEMENT * (1 + 1e-12) or \
                np.abs(placement[3:]).max() > 2 * np.pi * (1 + 1e-12):
            raise CliInputError(f"--placement: x y z must lie within ±{MAX_PLACEMENT / ls:g} {task.length_unit} "
                                f"(10 km) and roll pitch yaw within ±{2 * np.pi / as_:g} {task.angle_unit} (a full "
                                f"turn), as a task's [placement]; got {' '.join(args.placement)}")
    try:
        given = {} if args.weights is None else dict(zip(("dexterity", "clearance", "limits"), args.weights))
        if args.clearance_ref is not None:
            given["clearance_ref"] = args.clearance_ref * ls
        weights = ScoreWeights(measure=args.measure, **given)
    except TaskError as e:
        raise CliInputError(f"--weights / --clearance-ref: {e}") from None
    try:
        settings = ReachSettings(starts=args.starts, samples=args.samples, spins=args.spins)
    except TaskError as e:
        raise CliInputError(f"--starts / --samples / --spins: {e}") from None
    windows = windows_from_args(robot, args.margin, args.sigma_min)
    dex = task.dexterity if task.dexterity.kind in ("sigma_min", "manipulability") else None
    if task.dexterity.kind == "sigma_min_full":
        raise CliInputError(f"{task.source or task.name}: dexterity with a characteristic_length (σ_min of the "
                            "full Jacobian) is not a reach-study requirement; give sigma_min or manipulability")
    progress = None if args.quiet or not sys.stderr.isatty() else (
        lambda t: print(f"… {t}", file=sys.stderr, flush=True))
    study = reach_study(robot, task.targets, cell=cell, placement=placement, clearance=clearance, windows=windows,
                        weights=weights, settings=settings, dexterity=dex, progress=progress)
    out = {**study.to_dict(), "task": task.name, "units": "SI (m, rad)", "length_unit": task.length_unit,
           "angle_unit": task.angle_unit}
    written = []
    if "reach.json" in outputs:
        written.append(write_output(outputs["reach.json"], dump(out) + "\n"))
        written.append(write_output(outputs["reach.csv"], reach_csv(study, ls)))
    if "csv" in outputs:
        written.append(write_output(outputs["csv"], reach_csv(study, ls)))
    if "reach_score.png" in outputs or "plot" in outputs:
        from studies.plots.reach import plot_reach
        if "reach_score.png" in outputs:
            written.append(plot_reach(study, outputs["reach_score.png"], "score", ls, task.length_unit))
            written.append(plot_reach(study, outputs["reach_reason.png"], "reason", ls, task.length_unit))
        if "plot" in outputs:
            written.append(plot_reach(study, outputs["plot"], "score", ls, task.length_unit))
    if args.json:
        print(dump(out))
    elif not args.quiet:
        print("\n".join(_summary(study, task, ls, as_)))
        if written:
            print(f"wrote {', '.join(str(p) for p in written)}")
    return EXIT_OK if study.reached.all() else EXIT_FAIL


def _read_study(path: str):
    from design.reach import ReachStudy
    from kin.files import FileReadError, read_json
    try:
        data = read_json(path, "reach study (rmt reach --json)", MAX_STUDY_BYTES)
    except FileReadError as e:
        raise CliInputError(str(e)) from None
    return ReachStudy.from_dict(data, str(path)), data


def cmd_reach_compare(args, load_robot) -> int:
    from design.reach import compare_studies
    out_dir = Path(args.out) if args.out is not None else None
    if out_dir is not None:
        for name in ("reach_compare.html", "reach_compare.json"):
            check_output(out_dir / name)
    (a, da), (b, _) = _read_study(args.a), _read_study(args.b)
    labels = tuple(args.labels) if args.labels else (Path(args.a).stem, Path(args.b).stem)
    if labels[0] == labels[1]:
        labels = (labels[0] + " (a)", labels[1] + " (b)")
    for lab in labels:
        what = "--labels" if args.labels else "the label made of the file name (give --labels)"
        if not lab.strip() or len(lab) > 80:
            raise CliInputError(f"{what}: {lab!r} must be 1–80 characters")
        bad = next((c for c in lab if unicodedata.category(c) in ("Cc", "Cf", "Cs", "Co", "Cn", "Zl", "Zp")), None)
        if bad is not None:      # a newline would start a line of its own in the output (a forged 'rmt: error:')
            raise CliInputError(f"{what}: {lab!r} holds the control character U+{ord(bad):04X}; allowed: 1–80 "
                                "printable characters")
    cmp = compare_studies(a, b, labels)
    lu = da.get("length_unit", "m")
    from kin.chain import LENGTH_UNITS
    ls = LENGTH_UNITS.get(lu, 1.0) if isinstance(lu, str) else 1.0
    lu = lu if isinstance(lu, str) and lu in LENGTH_UNITS else "m"
    d = cmp.to_dict()
    written = []
    if out_dir is not None:
        from studies.report.html import render
        from studies.study.reach_compare import comparison_document
        doc = comparison_document(cmp, ls, lu, sources=(args.a, args.b))
        written.append(write_output(out_dir / "reach_compare.html", render(doc)))
        written.append(write_output(out_dir / "reach_compare.json", dump(d) + "\n"))
    if args.json:
        print(dump(d))
    else:
        la, lb = labels
        print(f"{len(cmp.gained)} targets: {la} {d['coverage_percent'][la]:.1f} % reached, mean score "
              f"{d['mean_score'][la]:.3f}; {lb} {d['coverage_percent'][lb]:.1f} %, {d['mean_score'][lb]:.3f}")
        print(f"gained by {lb}: {len(d['gained'])}; lost: {len(d['lost'])}; reached by both: {d['reached_by_both']} "
              f"(mean score change there {d['mean_score_change_both']:+.3f})")
        for r in d["reason_changes"]:
            print(f"  {r['from']} → {r['to']}: {r['targets']}")
        if written:
            print(f"wrote {', '.join(str(p) for p in written)}")
    return EXIT_OK


def add_commands(add) -> None:
    sp = add("reach", cmd_reach, "reach study: for every target of a task, whether the robot placed in a work cell "
                                 "reaches it (IK from fixed starts: the same verdicts on every run), its score and "
                                 "the reason it is missed; exit 1 if a target is unreached")
    sp.add_argument("robot", metavar="ROBOT", help="bundled robot name or robot file (overrides the task's robot)")
    sp.add_argument("task", metavar="TASK", help="task file or bundled task name: its targets (cell frame), "
                                                 "dexterity, cell and clearance")
    sp.add_argument("--cell", metavar="CELL", help="work cell (docs/cells.md) or a bundled cell's name; default the "
                                                   "task's (none: collisions not checked)")
    sp.add_argument("--clearance", type=bounded(0, math.inf, "(task length unit)"), metavar="D",
                    help="with a cell: the clearance a solution needs, task length unit (default the task's)")
    sp.add_argument("--placement", nargs=6, metavar=("X", "Y", "Z", "R", "P", "YAW"),
                    help="the robot's base placement in the cell: task length and angle units (default the cell's "
                         "[robot] placement, else the origin)")
    sp.add_argument("--weights", nargs=3, type=bounded(0, 1e6, ""), metavar=("WD", "WC", "WL"),
                    help="score weights of dexterity, clearance and joint-limit margin (default 0.5 0.25 0.25)")
    sp.add_argument("--measure", choices=MEASURES, default="sigma_min",
                    help="the score's dexterity measure (default sigma_min)")
    sp.add_argument("--clearance-ref", type=bounded(0, 1e6, "(task length unit)", open_low=True), metavar="D",
                    help="the clearance that scores full marks, task length unit (default 50 mm)")
    sp.add_argument("--starts", type=bounded(1, 64, "", integer=True), default=8, metavar="K",
                    help="IK starts per target and orientation (1–64, default 8)")
    sp.add_argument("--samples", type=bounded(16, 2_000_000, "", integer=True), default=4096, metavar="M",
                    help="Halton configurations the starts are chosen from (default 4096)")
    sp.add_argument("--spins", type=bounded(1, 72, "", integer=True), default=8, metavar="S",
                    help="rotations tried about a free tool axis (default 8)")
    window_width_args(sp, sigma_help="singular windows from a σ_min threshold (SI): a solution inside one "
                                     "does not count")
    sp.add_argument("--csv", metavar="FILE", help="write one row per target (CSV: position in the task's length "
                                                  "unit, the rest SI)")
    sp.add_argument("--plot", metavar="FILE", help="write the targets coloured by score (PNG)")
    sp.add_argument("--out", metavar="DIR", help="write DIR/TASK/reach.json, reach.csv, reach_score.png, "
                                                 "reach_reason.png")
    sp.add_argument("--quiet", action="store_true", help="no progress lines and no summary (errors only)")

    cp = add("reach-compare", cmd_reach_compare, "two reach studies of the same targets side by side (the JSON of "
                                                 "rmt reach --json or --out): targets gained and lost, score change, "
                                                 "reasons that changed; --out writes an HTML report")
    cp.add_argument("a", metavar="A.json", help="the first study (rmt reach --json output)")
    cp.add_argument("b", metavar="B.json", help="the second study, of the same targets")
    cp.add_argument("--labels", nargs=2, metavar=("LA", "LB"), help="names of the two set-ups (default the file names)")
    cp.add_argument("--out", metavar="DIR", help="write DIR/reach_compare.html (report) and DIR/reach_compare.json")


__all__ = ["add_commands", "cmd_reach", "cmd_reach_compare", "reach_csv", "MEASURES"]
