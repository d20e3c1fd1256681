"""``rmt coverage`` and ``rmt optimise``: task coverage decided by IK, and link-parameter (and
joint-type) optimisation of a design task.  Heavy imports stay inside the command functions."""
from __future__ import annotations

import sys
from pathlib import Path

import kin
from kin.output import write_output
from studies.cli.common import EXIT_FAIL, EXIT_OK, MAX_SIGMA, CliInputError, bounded, bundled_file, seed
from studies.cli.tcp import with_task_cell_tcp
from studies.jsonio import dump, jsonable

#: bundled example task files: ``rmt optimise NAME`` finds ``NAME.toml`` here
TASK_DIR = Path(__file__).parent.parent / "tasks"


def bundled_tasks() -> list[str]:
    return sorted(p.stem for p in TASK_DIR.glob("*.toml"))


def task_file(arg: str) -> Path:
    """A task argument → an existing file: a path, or the name of a bundled example."""
    return bundled_file(arg, TASK_DIR, "task")


def _params(robot: kin.Robot, items: list[str] | None) -> dict[str, float]:
    """NAME=VALUE pairs in the robot file's units → SI mapping."""
    out = {}
    c = robot.chain
    for it in items or []:
        name, _, val = it.partition("=")
        if name not in c.parameters:
            raise CliInputError(f"--param {it!r}: unknown design parameter; {c.name} has "
                                f"{', '.join(c.parameters) or 'none'}")
        try:
            x = float(val)
        except ValueError:
            raise CliInputError(f"--param {it!r}: value must be a number") from None
        scale = c.length_scale if c.parameters[name].kind == "length" else c.angle_scale
        lo, hi = c.parameters[name].bounds
        if not (lo - 1e-12 <= x * scale <= hi + 1e-12):
            raise CliInputError(f"--param {it!r}: outside the bounds [{lo / scale:g}, {hi / scale:g}]")
        out[name] = x * scale
    return out


def _budget(args) -> None:
    if not 1 <= args.seeds <= 64:
        raise CliInputError(f"--seeds {args.seeds} must be in [1, 64]")
    if not 100 <= args.samples <= 5_000_000:
        raise CliInputError(f"--samples {args.samples} must be in [100, 5000000]")
    if args.seed < 0:
        raise CliInputError(f"--seed {args.seed} must be ≥ 0")


def cmd_coverage(args, load_robot) -> int:
    from design.coverage import coverage
    from design.task import Dexterity, load_task
    from design.task.model import Targets
    from design.task.targets import read_points_csv
    _budget(args)
    robot = load_robot(args.robot)
    c = robot.chain
    path = task_file(args.target) if not args.target.endswith(".csv") else Path(args.target)
    if path.suffix == ".csv":
        if not path.is_file():
            raise CliInputError(f"{path}: no such points file")
        P, axes = read_points_csv(path, c.length_scale)
        targets, dex = Targets(P, "axis" if axes is not None else "free", axes), Dexterity()
        task = None
    else:
        task = load_task(path, robot=robot)
        targets, dex = task.targets, task.dexterity
    cell, clearance = (None, 0.0) if task is None else (task.cell, task.clearance)
    if args.cell is not None:
        from planning.cell import load_cell
        from studies.cli.common import cell_file
        cell = load_cell(cell_file(args.cell))
    robot = with_task_cell_tcp(args, robot, cell)
    if args.clearance:
        if cell is None:
            raise CliInputError("--clearance needs --cell (or a task file with a cell)")
        clearance = args.clearance * c.length_scale
    if args.sigma_min is not None or args.manipulability is not None:
        if args.sigma_min is not None and args.manipulability is not None:
            raise CliInputError("give --sigma-min or --manipulability, not both")
        if args.manipulability is not None:
            dex = Dexterity("manipulability", args.manipulability)
        elif args.characteristic_length is not None:
            dex = Dexterity("sigma_min_full", args.sigma_min, args.characteristic_length * c.length_scale)
        else:
            dex = Dexterity("sigma_min", args.sigma_min)
    cov = coverage(robot, targets, dex, params=_params(robot, args.param), seeds=args.seeds,
                   samples=args.samples, seed=args.seed, cell=cell, clearance=clearance)
    if args.plot:
        from studies.plots.design import plot_coverage
        plot_coverage(targets.positions / c.length_scale, cov, args.plot, c.length_unit, robot.name)
    out = cov.to_dict()
    out["positions"] = targets.positions / c.length_scale
    out["units"] = {"length": c.length_unit, "positions": c.length_unit}
    cyc = None
    if task is not None and task.cycle is not None:        # the task's motion cycle (design.cycle)
        from design.cycle import evaluate_cycle
        cyc = evaluate_cycle(robot, task.cycle, targets, _params(robot, args.param), args.seed)
        out["cycle"] = cyc.to_dict()
        out["units"]["cycle"] = {"time": "s", "torque": "N·m (revolute), N (prismatic)"}
    if args.json:
        print(dump(out))
    else:
        print(f"{robot.name}: {len(targets)} targets, reached {100 * cov.reach_fraction:.1f} %, covered "
              f"{100 * cov.fraction:.1f} % ({cov.measure} ≥ {cov.threshold:g}), {cov.flips} flip across "
              f"{args.seeds} seeds, GCI {cov.gci:.3f}")
        if cov.blocked is not None:
            print(f"  in the cell: {int(cov.blocked.sum())} target(s) reached only through a collision "
                  f"(not counted)")
        if cyc is not None and not cyc.ok:
            print(f"  cycle: target(s) {', '.join(map(str, cyc.unreached))} not reached")
        elif cyc is not None:
            peaks = ", ".join(f"{nm} {t:.4g}" + ("" if m != m else f"/{m:g}")
                              for nm, t, m in zip(cyc.joint_names, cyc.peak_torque, cyc.tau_max))
            print(f"  cycle {cyc.cycle_time:.4g} s; peak torque (N·m, N; /limit) {peaks}: "
                  f"{'within' if cyc.within_torque else 'OVER'} the motor limits")
    return EXIT_OK if cov.covered.all() and (cyc is None or cyc.within_torque) else EXIT_FAIL


def add_commands(add) -> None:
    sp = add("coverage", cmd_coverage, "task coverage decided by IK: reach %, per-target best σ_min, seed flips")
    sp.add_argument("robot", help="bundled robot name or robot file")
    sp.add_argument("target", help="task file (its target and dexterity), bundled task name, or points CSV "
                                   "(x, y, z[, ax, ay, az] in the robot's length unit)")
    sp.add_argument("--sigma-min", type=bounded(0, MAX_SIGMA, "(SI)", open_low=True),
                    help="σ_min ≥ S of the translational rows (SI, m/rad)")
    sp.add_argument("--characteristic-length", type=bounded(0, 1e6, "(robot length unit)", open_low=True),
                    help="with --sigma-min: of the full Jacobian scaled by this length (robot length unit)")
    sp.add_argument("--manipulability", type=bounded(0, 1e6, "", open_low=True),
                    help="manipulability ≥ M of the task rows")
    sp.add_argument("--param", nargs="+", metavar="NAME=VALUE", help="design parameters (robot file units)")
    sp.add_argument("--seeds", type=int, default=4, help="IK seeds per target (default 4)")
    sp.add_argument("--samples", type=int, default=20_000, help="sampled configurations for the seed index")
    sp.add_argument("--seed", type=seed, default=0, help="seed of the sampling and IK starts (default 0)")
    sp.add_argument("--plot", help="write the targets coloured by their best σ_min score (PNG)")
    sp.add_argument("--cell", metavar="CELL.toml",
                    help="work cell (docs/cells.md): a target counts only with a collision-free IK solution "
                         "(default: the task file's cell, if any)")
    sp.add_argument("--clearance", type=bounded(0, 1e6, "(robot length unit)"), default=0.0, metavar="D",
                    help="with a cell: the clearance a solution needs, robot length unit (default 0)")
    add_optimise(add)


def _write_outputs(res, out_dir: Path) -> list[Path]:
    """design.json (strict JSON), the optimised robot file, coverage / history plots."""
    written = [write_output(out_dir / "design.json", dump(res.to_dict()) + "\n")]
    written.append(kin.save_robot(res.chain, out_dir / f"{res.robot.name}_optimised.toml"))
    return written


def cmd_optimise(args, load_robot) -> int:
    from design.optimise import VerifySettings, optimise
    from design.task import load_task
    _budget(args)
    if not 1 <= args.starts <= 1000:
        raise CliInputError(f"--starts {args.starts} must be in [1, 1000]")
    if not 0 < args.max_time <= 86_400:
        raise CliInputError(f"--max-time {args.max_time} must be in (0, 86400] s")
    path = task_file(args.task)
    task = load_task(path)
    tty = sys.stderr.isatty() and not args.json
    progress = (lambda line: print(f"  {line}", file=sys.stderr)) if tty else None
    settings = VerifySettings(seeds=args.seeds, samples=args.samples, seed=args.seed)
    if task.architectures:
        from design.architecture import optimise_architectures
        ranking = optimise_architectures(task, method=args.method, starts=args.starts, seed=args.seed,
                                         settings=settings, max_time=args.max_time, progress=progress)
        out = ranking.to_dict()
        out_dir = Path(args.out) / task.name
        write_output(out_dir / "design.json", dump(out) + "\n")
        from studies.plots.design import plot_ranking
        plot_ranking(ranking.names, ranking.objectives, ranking.coverages, out_dir / "ranking.png",
                     task.objective)
        if args.json:
            print(dump(out))
        else:
            print(ranking.table())
            print(f"wrote {out_dir / 'design.json'}, {out_dir / 'ranking.png'}")
        return EXIT_OK if any(ranking.feasible) else EXIT_FAIL
    res = optimise(task, method=args.method, starts=args.starts, seed=args.seed, settings=settings,
                   max_time=args.max_time, progress=progress)
    from design.metrics import design_metrics
    res.metrics = design_metrics(res.robot, res.params, res.verification.gci, volume=args.volume,
                                           seed=args.seed)
    out_dir = Path(args.out) / task.name
    written = _write_outputs(res, out_dir)
    from studies.plots.design import plot_coverage, plot_history
    c = res.robot.chain
    written.append(plot_coverage(task.targets.positions / c.length_scale, res.verification,
                                 out_dir / "coverage.png", c.length_unit, f"{task.name} ({res.method})"))
    if any(res.history):
        written.append(plot_history(res.history, out_dir / "history.png", task.objective, task.name))
    out = jsonable(res.to_dict())
    if args.json:
        print(dump(out))
    else:
        pars = ", ".join(f"{k} = {v:.6g} {c.length_unit if c.parameters[k].kind == 'length' else c.angle_unit}"
                         for k, v in res.params_in_file_units().items())
        v = res.verification
        print(f"{task.name} ({res.method}): {pars}")
        print(f"  objective {task.objective} = {res.objective:.6g}; verified coverage {100 * v.fraction:.1f} % "
              f"({v.flips} flip across {v.verdicts.shape[1]} seeds), GCI {v.gci:.3f}; "
              f"{'feasible' if res.feasible else 'NOT feasible'}; {res.time_s:.2f} s")
        m = res.metrics
        if "workspace" in m:
            w = m["workspace"]
            print(f"  workspace {w['volume']:.4g} {w['unit']} (voxel {w['voxel_m']:.3g} m, {w['samples']} samples, "
                  f"{'converged' if w['converged'] else 'NOT converged'} to {100 * w['tolerance']:g} %), "
                  f"Q_L {m['length_index']:.4g}")
        print(f"  wrote {', '.join(str(p) for p in written)}")
    return EXIT_OK if res.feasible else EXIT_FAIL


def add_optimise(add) -> None:
    sp = add("optimise", cmd_optimise, "optimise a design task's link parameters (and joint types); "
                                       "the answer re-verified by IK coverage")
    sp.add_argument("task", help="task file or bundled task name")
    sp.add_argument("--method", choices=("ipopt", "de"), default="ipopt")
    sp.add_argument("--starts", type=int, default=4, help="IPOPT starts (default 4)")
    sp.add_argument("--seed", type=seed, default=0, help="seed of the starts, sampling and IK (default 0)")
    sp.add_argument("--seeds", type=int, default=4, help="IK seeds per target in the verification")
    sp.add_argument("--samples", type=int, default=20_000, help="sampled configurations for the seed index")
    sp.add_argument("--max-time", type=bounded(0, 86_400, "s", open_low=True), default=600.0,
                    help="solver time budget, s (default 600)")
    sp.add_argument("--out", default="out", help="output folder (default out/); writes OUT/NAME/")
    sp.add_argument("--volume", action="store_true",
                    help="also the converged workspace volume and the structural length index Q_L")
