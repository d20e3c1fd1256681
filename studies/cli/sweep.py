"""``rmt sweep``, ``rmt sweep-export`` and ``rmt sweep-plot``: parameter sweeps into an SQLite store,
on local processes or Dask, with Gaussian-process refinement; export and plots of a store."""
from __future__ import annotations

import sys
from pathlib import Path

from studies.cli.common import EXIT_FAIL, EXIT_OK, CliInputError, bundled_file
from studies.jsonio import dump

#: bundled example sweep files: ``rmt sweep NAME`` finds ``NAME.toml`` here
SWEEP_DIR = Path(__file__).parent.parent / "sweeps"


def sweep_file(arg: str) -> Path:
    """A sweep argument → an existing file: a path, or the name of a bundled example."""
    return bundled_file(arg, SWEEP_DIR, "sweep")


def _executor(args):
    from design.sweep import DaskExecutor, LocalExecutor
    chosen = [x for x in (args.workers is not None, args.scheduler is not None, args.dask_local is not None) if x]
    if len(chosen) > 1:
        raise CliInputError("give one of --workers, --scheduler, --dask-local")
    if args.scheduler is not None:
        if not args.scheduler.startswith(("tcp://", "tls://", "inproc://")):
            raise CliInputError(f"--scheduler {args.scheduler!r} must be an address like tcp://HOST:PORT")
        return DaskExecutor(scheduler=args.scheduler)
    if args.dask_local is not None:
        if not 1 <= args.dask_local <= 256:
            raise CliInputError(f"--dask-local {args.dask_local} must be in [1, 256]")
        return DaskExecutor(local_workers=args.dask_local)
    workers = 1 if args.workers is None else args.workers
    if not 1 <= workers <= 256:
        raise CliInputError(f"--workers {workers} must be in [1, 256]")
    return LocalExecutor(workers)


class _Bar:
    """tqdm progress bar (designs done, failed, rate, ETA) on a terminal; nothing otherwise."""

    def __init__(self, show: bool):
        self.show, self.bar, self.failed = show, None, 0

    def start(self, total: int, already: int) -> None:
        if self.show:
            import shutil

            from tqdm import tqdm
            self.bar = tqdm(total=total, unit="design", file=sys.stderr, ncols=shutil.get_terminal_size().columns,
                            desc="sweep" + (f" ({already} done before)" if already else ""))

    def update(self, n: int, failed: int) -> None:
        if self.bar is not None:
            self.failed += failed
            self.bar.set_postfix(failed=self.failed, refresh=False)
            self.bar.update(n)

    def close(self) -> None:
        if self.bar is not None:
            self.bar.close()


def cmd_sweep(args, load_robot) -> int:
    from design.sweep import load_sweep, run_sweep
    executor = _executor(args)
    if not 0 <= args.refine <= 10_000:
        raise CliInputError(f"--refine {args.refine} must be in [0, 10000]")
    if not 0 < args.max_time <= 30 * 86_400:
        raise CliInputError(f"--max-time {args.max_time} must be in (0, 2592000] s")
    sweep = load_sweep(sweep_file(args.sweep))
    db = Path(args.db) if args.db else Path(args.out) / sweep.name / "sweep.sqlite"
    bar = _Bar(sys.stderr.isatty() and not args.quiet and not args.json)
    try:
        rep = run_sweep(sweep, db, executor, resume=args.resume, retry_failed=args.retry_failed,
                        refine=args.refine, progress=bar.update, start=bar.start, max_time=args.max_time,
                        refine_seed=args.seed)
    finally:
        bar.close()
    out = rep.to_dict()
    if args.json:
        print(dump(out))
    elif not args.quiet:
        c = rep.counts
        print(f"{sweep.name}: {c['done']} done, {c['failed']} failed, {c['pending']} pending in {db} "
              f"({rep.evaluated} evaluated now on {rep.executor} in {rep.time_s:.1f} s, "
              f"{rep.rate:.1f} designs/s{'; stopped by --max-time' if rep.stopped_by_budget else ''})")
        if rep.best:
            print(f"  best: {_design_text(sweep, rep.best)}")
        if rep.refine:
            r = rep.refine
            print(f"  refinement: {r['proposed']} designs, best {sweep.task.objective} "
                  f"{_num(r['best_before'])} → {_num(r['best_after'])} (improvement {_num(r['improvement'])})")
    return EXIT_OK if rep.counts["failed"] == 0 and rep.counts["pending"] == 0 else EXIT_FAIL


def _num(x) -> str:
    return "none" if x is None else f"{x:.6g}"


def _design_text(sweep, best: dict) -> str:
    chain = sweep.task.robot.chain
    pars = ", ".join(
        f"{k} = {v / (chain.length_scale if chain.parameters[k].kind == 'length' else chain.angle_scale):.6g}"
        f" {chain.length_unit if chain.parameters[k].kind == 'length' else chain.angle_unit}"
        for k, v in best["params"].items())
    arch = f"{best['architecture']} " if best["architecture"] else ""
    return (f"{arch}{pars}: {sweep.task.objective} {best['objective']:.6g}, "
            f"{'feasible' if best['feasible'] else 'NOT feasible'} ({best['origin']})")


def cmd_sweep_export(args, load_robot) -> int:
    from design.sweep import read_sweep, write_csv, write_parquet
    if not args.csv and not args.parquet:
        raise CliInputError("give --csv FILE and/or --parquet FILE")
    written = []
    if args.csv:
        written.append(write_csv(args.db, args.csv))
    if args.parquet:
        written.append(write_parquet(args.db, args.parquet))
    meta, rows = read_sweep(args.db)
    if args.json:
        print(dump({"rows": len(rows), "written": [str(p) for p in written]}))
    else:
        print(f"{meta['name']}: {len(rows)} rows → {', '.join(str(p) for p in written)}")
    return EXIT_OK


def cmd_sweep_plot(args, load_robot) -> int:
    from design.sweep import read_sweep
    from studies.plots.sweep import plot_cycle_pareto, plot_heatmap, plot_pareto
    meta, rows = read_sweep(args.db)
    out = Path(args.out) if args.out else Path(args.db).parent
    written = [plot_pareto(meta, rows, out / "pareto.png")]
    if len(meta["swept"]) == 2:
        written.append(plot_heatmap(meta, rows, out / "heatmap.png"))
    if {"cycle_time", "torque_ratio"} <= set(meta["metrics"]):
        written.append(plot_cycle_pareto(meta, rows, out / "cycle_pareto.png"))
    if args.json:
        print(dump({"written": [str(p) for p in written]}))
    else:
        print(f"wrote {', '.join(str(p) for p in written)}")
    return EXIT_OK


def add_commands(add) -> None:
    sp = add("sweep", cmd_sweep, "parameter sweep of a design task into an SQLite store (local processes or Dask; "
                                 "resumable after a crash), with optional Gaussian-process refinement")
    sp.add_argument("sweep", help="sweep file or bundled sweep name")
    sp.add_argument("--workers", type=int, help="local worker processes (default 1)")
    sp.add_argument("--scheduler", help="Dask scheduler address tcp://HOST:PORT of an existing cluster")
    sp.add_argument("--dask-local", type=int, metavar="N", help="start a Dask LocalCluster of N workers for the run")
    sp.add_argument("--db", help="database file (default OUT/NAME/sweep.sqlite)")
    sp.add_argument("--out", default="out", help="output folder for the default database (default out/)")
    sp.add_argument("--resume", action="store_true", help="continue an existing database (done rows are kept)")
    sp.add_argument("--retry-failed", action="store_true", help="with --resume: evaluate failed rows again")
    sp.add_argument("--refine", type=int, default=0, metavar="K",
                    help="K more designs proposed by a Gaussian-process surrogate (expected improvement)")
    sp.add_argument("--seed", type=int, default=0, help="seed of the refinement's candidate search")
    sp.add_argument("--max-time", type=float, default=86_400.0, help="budget in s; unfinished rows stay pending")
    sp.add_argument("--quiet", action="store_true", help="no progress bar and no summary")
    ex = add("sweep-export", cmd_sweep_export, "export a sweep database as CSV (and Parquet with pyarrow)")
    ex.add_argument("db", help="sweep database (sweep.sqlite)")
    ex.add_argument("--csv", help="CSV file to write")
    ex.add_argument("--parquet", help="Parquet file to write (needs pyarrow)")
    pl = add("sweep-plot", cmd_sweep_plot, "plot a sweep: coverage against structural length with the Pareto "
                                           "front; a heat map for a 2-parameter sweep")
    pl.add_argument("db", help="sweep database (sweep.sqlite)")
    pl.add_argument("--out", help="folder for the PNG files (default: the database's folder)")
