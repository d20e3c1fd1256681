"""Sweep benchmark: designs per second of a SCARA coverage sweep on local worker processes and on
Dask, and the per-design overhead of the store and of Dask.

Run as ``python -m studies.benchmarks.bench_sweep [--json] [--quick]`` (part of ``make bench``).
The sweep is the SCARA arm lengths A1, A2 (``studies/tasks/robots/scara_design.toml``) on a
50 × 40 grid (2 000 designs; ``--quick``: 20 × 10) for a 2 × 2 box of targets with σ_min ≥ 0.04
m/rad, one IK seed per target and 200 sampled configurations for the seed index, so the work per
design is small and the executors' overheads show.  Every configuration writes its own database in
a temporary folder:

* ``local_1``, ``local_2``: :class:`design.sweep.LocalExecutor` with 1 and 2 spawned processes;
* ``dask_1``, ``dask_2``: :class:`design.sweep.DaskExecutor` on a LocalCluster of 1 and 2 worker
  processes (one thread each) started for the run;

each reports designs/s over the whole run (start-up of the pool or cluster included) and checks
that its rows equal ``local_1``'s.  Overheads: ``store_ms_per_design`` — inserting, marking running
and recording one design through :class:`design.sweep.Store` with its batched commits;
``noop_local_ms_per_design`` and ``noop_dask_ms_per_design`` — the wall time per design of a sweep
whose per-design function does nothing (:func:`evaluate_noop`) on 1 worker, start-up included;
``dask_overhead_ms_per_design`` their difference.
"""
from __future__ import annotations

import argparse
import os
import platform
import sys
import tempfile
import time
from pathlib import Path

from design.sweep import DaskExecutor, Design, LocalExecutor, Store, loads_sweep, read_sweep, run_sweep
from design.sweep.evaluate import Outcome
from design.task import load_task
from studies.jsonio import dump

ROBOT = Path(__file__).resolve().parents[1] / "tasks" / "robots" / "scara_design.toml"


def task_text(name: str, count: tuple[int, int], min_coverage: float, sigma_min: float = 0.04) -> str:
    """A SCARA task file (``scara_design`` robot): a count[0] × count[1] box of targets at
    z = −150 mm over x ∈ [150, 350], y ∈ [−150, 150] mm, σ_min ≥ ``sigma_min``, minimise length."""
    return f'''
name = "{name}"
robot = "{ROBOT}"
length_unit = "mm"
angle_unit = "deg"
objective = "length"
[target]
shape = "box"
min = [150, -150, -150]
max = [350, 150, -150]
count = [{count[0]}, {count[1]}, 1]
tolerance = 1e-3
[dexterity]
sigma_min = {sigma_min}
[constraints]
min_coverage = {min_coverage}
'''


TASK = task_text("bench_scara", (2, 2), 1.0)


def sweep_text(n1: int, n2: int) -> str:
    return f'''
name = "bench_sweep"
task = "task.toml"
[evaluation]
seeds = 1
samples = 200
[parameters.A1]
range = [100, 400]
count = {n1}
[parameters.A2]
range = [100, 400]
count = {n2}
'''


def evaluate_noop(job, robot, design) -> dict:
    """A per-design function that does no work (for the executors' overhead)."""
    return {"objective": 0.0, "score": 0.0, "feasible": True}


def _load(folder: Path, n1: int, n2: int):
    (folder / "task.toml").write_text(TASK)
    return loads_sweep(sweep_text(n1, n2), str(folder / "bench.toml"), folder, load_task(folder / "task.toml"))


def _rows(db) -> dict:
    return {r["key"]: (r["status"], r["metrics"]) for r in read_sweep(db)[1]}


def store_overhead(folder: Path, n: int = 2000) -> float:
    """ms per design of add + mark running + record through the store's batched commits."""
    ds = [Design.make("", {"A1": 0.1 + 1e-4 * i, "A2": 0.2}) for i in range(n)]
    t0 = time.perf_counter()
    with Store(folder / "store.sqlite", {"name": "bench", "fingerprint": "x"}) as s:
        s.add(ds, seed=0)
        for i in range(0, n, 10):
            chunk = ds[i:i + 10]
            s.mark_running(d.key for d in chunk)
            s.record(Outcome(d.key, True, {"objective": 0.0, "score": 0.0, "feasible": True}, None, 0.0, "w")
                     for d in chunk)
    return 1e3 * (time.perf_counter() - t0) / n


def noop_sweep(folder: Path, make, n1: int, n2: int, name: str) -> float:
    """ms per design of a sweep whose per-design function does nothing, on ``make()`` (start-up of
    the pool or cluster included)."""
    from studies.benchmarks.bench_sweep import evaluate_noop as noop  # by its module name, not __main__
    rep = run_sweep(_load(folder, n1, n2), folder / f"{name}_noop.sqlite", make(), evaluate=noop)
    return 1e3 * rep.time_s / (n1 * n2)


def run(quick: bool, log=None) -> dict:
    n1, n2 = (20, 10) if quick else (50, 40)
    out = {"designs": n1 * n2, "grid": [n1, n2], "targets": 4, "ik_seeds": 1, "samples": 200,
           "python": platform.python_version(), "cpus": os.cpu_count(), "runs": {}}
    configs = [("local_1", lambda: LocalExecutor(1)), ("local_2", lambda: LocalExecutor(2)),
               ("dask_1", lambda: DaskExecutor(local_workers=1)), ("dask_2", lambda: DaskExecutor(local_workers=2))]
    with tempfile.TemporaryDirectory(prefix="bench_sweep_") as tmp:
        folder = Path(tmp)
        sweep = _load(folder, n1, n2)
        ref = None
        for name, make in configs:
            if name.startswith("dask"):
                try:
                    import distributed  # noqa: F401 - only probes that dask is installed
                except ImportError:
                    out["runs"][name] = {"skipped": "dask[distributed] not installed"}
                    continue
            rep = run_sweep(sweep, folder / f"{name}.sqlite", make())
            rows = _rows(folder / f"{name}.sqlite")
            ref = ref or rows
            out["runs"][name] = {"designs_per_s": rep.rate, "time_s": rep.time_s, "done": rep.counts["done"],
                                 "failed": rep.counts["failed"], "rows_equal_local_1": rows == ref}
            if log:
                log(f"{name}: {rep.rate:.1f} designs/s ({rep.time_s:.1f} s)")
        out["store_ms_per_design"] = store_overhead(folder)
        out["noop_local_ms_per_design"] = noop_sweep(folder, lambda: LocalExecutor(1), n1, n2, "local")
        if "skipped" not in out["runs"].get("dask_1", {"skipped": ""}):
            out["noop_dask_ms_per_design"] = noop_sweep(folder, lambda: DaskExecutor(local_workers=1), n1, n2, "dask")
            out["dask_overhead_ms_per_design"] = out["noop_dask_ms_per_design"] - out["noop_local_ms_per_design"]
    return out


def format_report(R: dict) -> str:
    lines = [f"SCARA coverage sweep: {R['designs']} designs ({R['grid'][0]} × {R['grid'][1]}), {R['targets']} targets, "
             f"{R['ik_seeds']} IK seed, {R['samples']} samples; {R['cpus']} CPUs",
             f"{'executor':<10} {'designs/s':>10} {'time s':>8}  rows = local_1"]
    for name, r in R["runs"].items():
        if "skipped" in r:
            lines.append(f"{name:<10} skipped: {r['skipped']}")
        else:
            lines.append(f"{name:<10} {r['designs_per_s']:>10.1f} {r['time_s']:>8.1f}  {r['rows_equal_local_1']}")
    lines.append(f"store overhead {R['store_ms_per_design']:.3f} ms/design; no-op sweep (start-up included): local "
                 f"{R['noop_local_ms_per_design']:.3f} ms/design" +
                 (f", Dask {R['noop_dask_ms_per_design']:.3f} ms/design (Dask overhead "
                  f"{R['dask_overhead_ms_per_design']:.3f} ms/design)" if "noop_dask_ms_per_design" in R else ""))
    return "\n".join(lines)


def main(argv=None) -> int:
    ap = argparse.ArgumentParser(prog="python -m studies.benchmarks.bench_sweep", description=__doc__.splitlines()[0])
    ap.add_argument("--json", action="store_true", help="print one JSON object with all figures instead of the table")
    ap.add_argument("--quick", action="store_true", help="200 designs instead of 2 000")
    args = ap.parse_args(argv)
    log = None if args.json else (lambda msg: print(msg, file=sys.stderr, flush=True))
    R = run(args.quick, log)
    print(dump(R) if args.json else format_report(R))
    return 0


if __name__ == "__main__":
    sys.exit(main())
