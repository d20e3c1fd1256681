"""Clearance benchmark: configurations per second of :class:`kin.geometry.ClearanceModel` (the compiled
kernel ``kin/geometry/clearance.c``) and the cost of one ``clear_one`` call.

Run as ``python -m studies.benchmarks.bench_clearance [--json] [--quick]``.

The cell (:func:`cell`): ten primitives around a robot at the origin — a table under it (ignoring the
base and body 1, which stand on it), a shelf of three boxes, two posts and a small part (cylinders),
two spheres and a pipe (capsule).  The robots: the Franka Panda (7 joints, 10 capsules) and the FANUC
LR Mate 200iD (6 joints, 8 capsules) with their default geometry; self pairs are the checked body
pairs apart at the zero configuration (the default geometries have pairs that always touch at a
joint: a planner allows those).  Configurations: uniform within the joint limits.

Figures per robot: configurations per second of wall time and per CPU-second of the process (all its
threads; on a shared machine the wall time counts waits for a CPU), best of :data:`REPEATS` batches of
:data:`N`, for
``clearance`` (mode a: the minimum) and ``per_body`` (mode b: per body, obstacles and self apart), with
obstacles only and with self pairs too, at 1 and 2 threads; ``clear_one`` as OMPL calls it (a list of
floats), in µs per call.  Target (issue: the compiled clearance kernel): ≥ 1 M configurations per
CPU-second on one thread for the Panda, mode a, obstacles only.  The report states the machine's load:
figures taken while other processes run are not reliable.
"""
from __future__ import annotations

import argparse
import json
import sys
import time

import numpy as np

import kin
from kin.geometry import ClearanceModel, Obstacle, Shape
from studies.benchmarks.load import ForeignLoad

ROBOTS = ("franka_panda", "fanuc_lrmate200id")
N = 200_000
QUICK_N = 20_000
REPEATS = 3
ONE_CALLS = 20_000
TARGET = 1.0e6          # configurations/s, Panda, mode a, one thread, obstacles only


def _at(x: float, y: float, z: float) -> np.ndarray:
    T = np.eye(4)
    T[:3, 3] = (x, y, z)
    return T


def cell() -> list[Obstacle]:
    """The benchmark's ten primitives (see the module docstring)."""
    return [
        Obstacle("table", (Shape("box", (0.9, 0.9, 0.02), _at(0.2, 0.0, -0.021)),), ignore={0, 1}),
        Obstacle("shelf", (Shape("box", (0.15, 0.45, 0.01), _at(0.65, 0.0, 0.3)),
                           Shape("box", (0.15, 0.45, 0.01), _at(0.65, 0.0, 0.65)),
                           Shape("box", (0.15, 0.01, 0.4), _at(0.65, 0.45, 0.4)))),
        Obstacle("posts", (Shape("cylinder", (0.04, 0.6, 0.0), _at(-0.45, 0.45, 0.6)),
                           Shape("cylinder", (0.04, 0.6, 0.0), _at(-0.45, -0.45, 0.6)))),
        Obstacle("parts", (Shape("sphere", (0.06, 0.0, 0.0), _at(0.4, -0.5, 0.25)),
                           Shape("sphere", (0.08, 0.0, 0.0), _at(0.35, 0.5, 0.3)),
                           Shape("cylinder", (0.05, 0.1, 0.0), _at(0.5, -0.2, 0.1)))),
        Obstacle("pipe", (Shape("capsule", (0.04, 0.5, 0.0), _at(0.0, 0.6, 1.1)),)),
    ]


def apart_pairs(robot) -> list[tuple[int, int]]:
    zero = np.zeros(robot.n)
    return [p for p in robot.geometry.checked_pairs(robot.n)
            if ClearanceModel(robot, self_pairs=[p], cap=10.0).clearance(zero) > 0]


def _rate(call, Q, threads: int) -> dict:
    """Configurations per second of wall time and per CPU-second of this process (all its threads), each
    the best of REPEATS batches: on a busy machine the wall time counts the waits for a CPU, the CPU
    time does not."""
    call(Q[:1000], threads=threads)
    wall = cpu = float("inf")
    for _ in range(REPEATS):
        t0, c0 = time.perf_counter(), time.process_time()
        call(Q, threads=threads)
        wall, cpu = min(wall, time.perf_counter() - t0), min(cpu, time.process_time() - c0)
    return {"wall": len(Q) / wall, "cpu": len(Q) / cpu}


def run(n: int) -> dict:
    out = {}
    for name in ROBOTS:
        robot = kin.load_robot(name)
        Q = robot.random_configurations(n, seed=1)
        pairs = apart_pairs(robot)
        rows = {}
        for label, self_pairs in (("obstacles", ()), ("obstacles+self", pairs)):
            m = ClearanceModel(robot, obstacles=cell(), self_pairs=self_pairs)
            if m.backend != "compiled":
                raise RuntimeError("the clearance kernel did not compile: nothing to measure")
            for mode in ("clearance", "per_body"):
                for threads in (1, 2):
                    rows[f"{mode} {label} threads={threads}"] = _rate(getattr(m, mode), Q, threads)
        m = ClearanceModel(robot, obstacles=cell(), self_pairs=pairs)
        qs = [list(map(float, q)) for q in Q[:1000]]
        one = m.clear_one
        wall = cpu = float("inf")
        for _ in range(REPEATS):
            t0, c0 = time.perf_counter(), time.process_time()
            for k in range(ONE_CALLS):
                one(qs[k % len(qs)])
            wall, cpu = min(wall, time.perf_counter() - t0), min(cpu, time.process_time() - c0)
        d = m.clearance(Q[:10_000])
        out[name] = {"joints": robot.n, "capsules": len(robot.geometry.capsules), "self_pairs": len(pairs),
                     "configurations_per_s": rows,
                     "clear_one_us": {"wall": wall / ONE_CALLS * 1e6, "cpu": cpu / ONE_CALLS * 1e6},
                     "colliding_share": float((d < 0).mean()), "median_clearance_m": float(np.median(d))}
    return out


def main(argv=None) -> int:
    ap = argparse.ArgumentParser(prog="bench_clearance", description=__doc__.splitlines()[0])
    ap.add_argument("--json", action="store_true", help="print one JSON object")
    ap.add_argument("--quick", action="store_true", help=f"{QUICK_N} configurations per batch instead of {N}")
    args = ap.parse_args(argv)
    with ForeignLoad() as load:
        res = run(QUICK_N if args.quick else N)
    rate = res["franka_panda"]["configurations_per_s"]["clearance obstacles threads=1"]["cpu"]
    verdict = "PASS" if rate >= TARGET else "MISS"
    if args.json:
        print(json.dumps({"results": res, "target_per_s": TARGET, "verdict": verdict, "load": load.as_dict()}))
        return 0
    for name, r in res.items():
        print(f"{name}: {r['joints']} joints, {r['capsules']} capsules, {r['self_pairs']} self pairs; "
              f"{100 * r['colliding_share']:.0f} % of configurations collide, median clearance "
              f"{r['median_clearance_m']:.3f} m")
        print(f"  {'M configurations/s':<40} {'wall':>6}  {'per CPU-s':>9}")
        for row, v in r["configurations_per_s"].items():
            print(f"  {row:<40} {v['wall'] / 1e6:6.2f}  {v['cpu'] / 1e6:9.2f}")
        one = r["clear_one_us"]
        print(f"  {'clear_one (a list of floats), µs':<40} {one['wall']:6.2f}  {one['cpu']:9.2f}")
    share = "n/a" if load.share is None else f"{100 * load.share:.0f} %"
    print(f"other processes' CPU share meanwhile: {share}{'' if load.reliable else ' (figures unreliable)'}")
    print(f"{verdict}: Panda, mode a, one thread {rate / 1e6:.2f} M configurations per CPU-second "
          f"(target ≥ {TARGET / 1e6:g} M)")
    return 0


if __name__ == "__main__":
    sys.exit(main())
