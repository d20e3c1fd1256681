"""Cell planning benchmark: MotionBenchMaker-style scenes, OMPL RRTConnect with proofs of clearance
from every collision and every singular window.

Run as ``python -m studies.benchmarks.bench_cell_plan [--json] [--quick] [--profile]
[--geometry robot|urdf]`` (part of ``make bench``).  Four scenes after MotionBenchMaker's (cell files
in ``studies/benchmarks/scenes/``, reusable with ``rmt plan --cell``): ``table_pick`` (objects on
the table), ``bookshelf`` (a shelf with boards and books), ``cage`` (a cage of bars) and ``box``
(an open box), each for the Franka Panda and the UR5e standing on the table at the origin, with the
robot's own capsules (:attr:`kin.Robot.geometry`, whatever they are; ``--geometry urdf``: the Panda
imported from example-robot-data's URDF, see :func:`studies.benchmarks.bench_collision.load_robot`)
and windows of margin :data:`MARGIN` rad (:func:`planning.windows.build_windows`).

Queries (:data:`QUERIES` per scene and robot, fixed seeds), drawn as MotionBenchMaker draws its
problems, from grasp-like poses solved by IK (:func:`draw_queries`): starts are valid configurations
whose tool point lies in a "ready" region above the table (:data:`READY`, tool pointing down); goals
put the tool point in the scene's target region (between the cans, in a compartment, inside the cage
or the box) with the tool along the scene's approach direction (down, or into the shelf), solved by
IK warm-started at a random start (the branch nearest it, as a user picks the IK solution nearest
the current configuration).  Both are valid (inside the limits, outside every window, clear of the
cell and of the robot itself); pairs that a window separates (:func:`planning.certify.free_cells`:
no answer exists, ``plan`` refuses them at once; or in two gaps of an interval window, a slab across
the joint space, which ``free_cells`` misses when the window shares a group with a multi-joint one)
or that lie on two sides of a formula window's singular surface are dropped; the pairs whose
straight joint-space line collides come first (the share is reported, and the share crossing a
window).

Each query is planned with ``plan(robot, start, goal, windows, world=world, planner="RRTConnect",
time_limit=TIME_LIMIT)``; the benchmark records success, the wall time of the call (including its
own dense check and proofs), ``res.proven`` (every segment proven clear of the cell, the robot
itself and every window), and re-checks every returned path independently: ``check_path(...,
world=world)`` and a dense clearance sampling (every 0.02° of joint motion, the world's clearance
above its margin and outside every window, the ends at the query's start and goal).

Targets per robot and scene (PASS/MISS): median planning time ≤ 5 ms (with the proofs); 100 % of
the returned paths proven; every returned path valid on the re-checks; success ≥ 98 %.  Context,
not a measured peer: VAMP (Thomason, Kingston, Kavraki, ICRA 2024) publishes a 35 µs median
RRT-Connect on MotionBenchMaker's Panda scenes with SIMD sphere checks (no proofs between samples).
``--profile`` runs cProfile over the planning calls and reports where the time goes.  A MISS does
not change the exit status (0); an error does.
"""
from __future__ import annotations

import argparse
import cProfile
import io
import math
import os
import platform
import pstats
import statistics
import sys
import time
from dataclasses import dataclass

import numpy as np

from planning.certify import free_cells
from planning.ompl.planner import plan
from planning.ompl.validity import JointSpaceChecker
from planning.validate import check_path, densify
from planning.windows import build_windows
from studies.benchmarks.bench_collision import load_robot, world_for
from studies.benchmarks.driver import measure_and_print
from studies.benchmarks.load import ForeignLoad

ROBOTS = ("franka_panda", "ur5e")
QUERIES = 100
QUICK_QUERIES = 10
SEED = 20240621
MARGIN = 0.05               # rad, half-width of every window
PLANNER = "RRTConnect"
TIME_LIMIT = 2.0            # s
CANDIDATE_POSES = 3000      # grasp-like target poses drawn per region (IK, then validity)
DENSE_STEP = math.radians(0.02)   # rad: the re-check's clearance sampling
VAMP_MEDIAN_S = 35e-6       # published, Panda, MotionBenchMaker scenes, RRT-Connect (context only)

TARGETS = {
    # key: (description, comparison, threshold, unit)
    "median_time_s": ("median planning time (with proofs)", "<=", 0.005, "s"),
    "proven_rate": ("returned paths proven (collisions, windows)", ">=", 1.0, ""),
    "recheck_rate": ("returned paths valid on the re-checks", ">=", 1.0, ""),
    "success_rate": (f"success ({PLANNER}, {TIME_LIMIT:g} s limit)", ">=", 0.98, ""),
}


@dataclass(frozen=True)
class Region:
    """Tool points uniformly in the box lo–hi (world, m), the tool's z axis along ``approach``, turned
    about it at random."""

    lo: tuple[float, float, float]
    hi: tuple[float, float, float]
    approach: tuple[float, float, float]


DOWN = (0.0, 0.0, -1.0)
READY = Region((0.15, -0.4, 0.45), (0.4, 0.4, 0.75), DOWN)
SCENES = {
    "table_pick": Region((0.4, -0.3, 0.12), (0.72, 0.3, 0.3), DOWN),
    "bookshelf": Region((0.52, -0.3, 0.1), (0.66, 0.3, 0.8), (1.0, 0.0, 0.0)),
    "cage": Region((0.45, -0.2, 0.1), (0.7, 0.2, 0.4), DOWN),
    "box": Region((0.5, -0.15, 0.06), (0.7, 0.15, 0.2), DOWN),
}


# ---- queries -----------------------------------------------------------------------------
def _frame(approach, angle: float) -> np.ndarray:
    z = np.asarray(approach, float)
    z = z / np.linalg.norm(z)
    helper = np.array([1.0, 0.0, 0.0]) if abs(z[0]) < 0.9 else np.array([0.0, 1.0, 0.0])
    x = np.cross(helper, z)
    x /= np.linalg.norm(x)
    y = np.cross(z, x)
    c, s = math.cos(angle), math.sin(angle)
    return np.column_stack([c * x + s * y, -s * x + c * y, z])


def region_configurations(robot, world, checker: JointSpaceChecker, region: Region, count: int,
                          seed: int) -> np.ndarray:
    """Valid configurations (limits, windows, clear of the cell) whose tool pose is one of ``count``
    poses drawn in ``region``: IK from random warm starts (so that the branches vary)."""
    rng = np.random.default_rng(seed)
    T = np.tile(np.eye(4), (count, 1, 1))
    T[:, :3, 3] = rng.uniform(region.lo, region.hi, (count, 3))
    for k, a in enumerate(rng.uniform(-math.pi, math.pi, count)):
        T[k, :3, :3] = _frame(region.approach, a)
    Tb = np.linalg.inv(world.base) @ T                      # the robot's base frame
    res = robot.ik(Tb, seed=seed, q0=robot.random_configurations(count, seed=seed + 1), restarts=2, rounds=2)
    Q = res.q[res.success]
    return Q[checker.batch_valid(Q)] if len(Q) else Q


def straight_line(robot, world, windows, a, b) -> tuple[bool, bool]:
    """(collides, crosses a window) along the straight joint-space line a → b, sampled at 0.1°."""
    Q, _, _ = densify(np.array([a, b]), robot.chain.revolute_mask)
    return bool((world.clearance(Q) <= world.margin).any()), bool(windows.contains(Q).any())


def aspect(windows, Q: np.ndarray) -> np.ndarray:
    """The sign of every formula window's factor g at configurations Q (N, n) → (N, k): configurations
    with different signs lie on different sides of a singular surface (sampled windows have no
    factor).  Interval windows: :func:`slab_cells`."""
    cols = [np.sign(w.g(Q)) for w in windows.windows if not w.is_interval and hasattr(w, "g")]
    return np.stack(cols, axis=1) if cols else np.zeros((len(Q), 0))


def slab_cells(windows, Q: np.ndarray) -> np.ndarray:
    """For every interval window, the free gap between its intervals that each configuration's joint
    lies in (N, k): an interval window is a slab across the whole joint space, so two configurations
    in different gaps are separated whatever the other joints do."""
    cols = [np.searchsorted(np.array([hi for _, hi in w.intervals]), Q[:, w.joint])
            for w in windows.windows if w.is_interval]
    return np.stack(cols, axis=1) if cols else np.zeros((len(Q), 0), int)


def draw_queries(robot, world, windows, count: int, seed: int, region: Region,
                 poses: int = CANDIDATE_POSES) -> tuple[list[dict], dict]:
    """``count`` queries (start, goal, straight-line facts) and a tally of the draw.

    Starts: valid configurations for poses in :data:`READY`.  Goals: poses in ``region``, each solved
    by IK warm-started at a random start (the branch nearest it, as a user picks the IK solution
    nearest the current configuration) and kept when valid, not separated from its start by a window
    (:func:`planning.certify.free_cells`, and in the same gap of every interval window,
    :func:`slab_cells`) and on the same side of every formula window (:func:`aspect`).
    The pairs whose straight line collides come first (in random order), then the others."""
    checker = JointSpaceChecker(robot, windows, world=world)
    S = region_configurations(robot, world, checker, READY, poses, seed + 7)
    tally = {"start_candidates": int(len(S)), "goal_poses": poses, "ik_solved": 0, "valid_goals": 0,
             "separated": 0, "slab_separated_missed": 0, "other_aspect": 0, "pairs": 0, "pairs_colliding": 0}
    if not len(S):
        return [], tally
    rng = np.random.default_rng(seed)
    T = np.tile(np.eye(4), (poses, 1, 1))
    T[:, :3, 3] = rng.uniform(region.lo, region.hi, (poses, 3))
    for k, ang in enumerate(rng.uniform(-math.pi, math.pi, poses)):
        T[k, :3, :3] = _frame(region.approach, ang)
    idx = rng.integers(len(S), size=poses)
    res = robot.ik(np.linalg.inv(world.base) @ T, seed=seed, q0=S[idx], restarts=2, rounds=2)
    tally["ik_solved"] = int(res.success.sum())
    ok = res.success.copy()
    ok[ok] = checker.batch_valid(res.q[ok])
    tally["valid_goals"] = int(ok.sum())
    A, B = S[idx[ok]], res.q[ok]
    cells = free_cells(robot.chain.lower, robot.chain.upper, windows)
    sep = np.array([cells.separation(a, b) is not None for a, b in zip(A, B)], bool)
    slab = (slab_cells(windows, A) != slab_cells(windows, B)).any(axis=1)
    same = (aspect(windows, A) == aspect(windows, B)).all(axis=1)
    tally["separated"] = int(sep.sum())
    # separated by a slab window, yet free_cells did not say so (plan() then searches until its limit)
    tally["slab_separated_missed"] = int((~sep & slab).sum())
    tally["other_aspect"] = int((~sep & ~slab & ~same).sum())
    keep = ~sep & ~slab & same
    A, B = A[keep], B[keep]
    tally["pairs"] = len(A)
    facts = [straight_line(robot, world, windows, a, b) for a, b in zip(A, B)]
    colliding = np.array([f[0] for f in facts], bool)
    tally["pairs_colliding"] = int(colliding.sum())
    order = np.concatenate([rng.permutation(np.flatnonzero(colliding)), rng.permutation(np.flatnonzero(~colliding))])
    out = [{"start": A[i], "goal": B[i], "straight_collides": facts[i][0], "straight_crosses_window": facts[i][1]}
           for i in order[:count]]
    return out, tally


# ---- re-check ----------------------------------------------------------------------------
def recheck(robot, world, windows, path: np.ndarray, a, b) -> dict:
    """The returned path checked apart from the planner: check_path with the world, and the clearance
    sampled every :data:`DENSE_STEP` of joint motion (above the margin, outside every window)."""
    chk = check_path(robot, path, windows, world=world)
    Q, _, _ = densify(path, robot.chain.revolute_mask, DENSE_STEP, 1e-5)
    c = world.clearance(Q)
    ends = bool(np.allclose(path[0], a, atol=1e-12) and np.allclose(path[-1], b, atol=1e-12))
    dense_ok = bool((c > world.margin).all() and not windows.contains(Q).any())
    return {"check_path_valid": bool(chk.valid), "collision_check": chk.collision_check,
            "windows_check": chk.windows_check, "clearance_bound": chk.clearance_bound,
            "dense_states": int(len(Q)), "dense_min_clearance": float(c.min()), "dense_valid": dense_ok,
            "ends": ends, "valid": bool(chk.valid and dense_ok and ends),
            "violation": None if chk.first_violation is None else chk.first_violation.kind}


# ---- one robot in one scene --------------------------------------------------------------
def _pct(x: list[float], p: float) -> float:
    return float(np.percentile(x, p)) if x else math.nan


def bench_scene(robot, windows, scene: str, count: int, seed: int, profiler=None, log=None) -> dict:
    world = world_for(robot, f"{scene}.toml")
    t0 = time.perf_counter()
    queries, tally = draw_queries(robot, world, windows, count, seed, SCENES[scene])
    tally["seconds"] = time.perf_counter() - t0
    if log:
        log(f"  {scene}: {len(queries)} queries (of {tally['pairs']} pairs, {tally['pairs_colliding']} with a "
            f"colliding straight line)")
    rows = []
    if queries:       # warm-up: OMPL's and the kernels' first calls, not timed
        plan(robot, queries[0]["start"], queries[0]["goal"], windows, world=world, planner=PLANNER,
             time_limit=TIME_LIMIT, seed=seed)
    with ForeignLoad() as load:
        for k, q in enumerate(queries):
            if profiler is not None:
                profiler.enable()
            t = time.perf_counter()
            res = plan(robot, q["start"], q["goal"], windows, world=world, planner=PLANNER, time_limit=TIME_LIMIT,
                       seed=seed + k)
            wall = time.perf_counter() - t
            if profiler is not None:
                profiler.disable()
            row = {"success": bool(res.success), "time_s": wall, "status": res.status,
                   "straight_collides": q["straight_collides"], "straight_crosses_window": q["straight_crosses_window"],
                   "planner_saw_straight_line_valid": bool(res.straight_line_valid)}
            if res.success:
                row.update({"proven": bool(res.proven), "waypoints": int(len(res.path)), "length": float(res.length),
                            "min_clearance": res.min_clearance,
                            "recheck": recheck(robot, world, windows, res.path, q["start"], q["goal"])})
            rows.append(row)
    ok = [r for r in rows if r["success"]]
    times = [r["time_s"] for r in rows]
    n = len(rows)
    summary = {
        "queries": n,
        "straight_collides_share": sum(r["straight_collides"] for r in rows) / n if n else math.nan,
        "straight_crosses_window_share": sum(r["straight_crosses_window"] for r in rows) / n if n else math.nan,
        "straight_free_share": (sum(r["planner_saw_straight_line_valid"] for r in rows) / n) if n else math.nan,
        "success_rate": len(ok) / n if n else math.nan,
        "median_time_s": statistics.median(times) if times else math.nan,
        "p95_time_s": _pct(times, 95),
        "median_time_success_s": statistics.median([r["time_s"] for r in ok]) if ok else math.nan,
        "p95_time_success_s": _pct([r["time_s"] for r in ok], 95),
        "returned_paths": len(ok),
        "proven_rate": sum(r["proven"] for r in ok) / len(ok) if ok else math.nan,
        "recheck_rate": sum(r["recheck"]["valid"] for r in ok) / len(ok) if ok else math.nan,
        "check_path_valid": sum(r["recheck"]["check_path_valid"] for r in ok),
        "dense_valid": sum(r["recheck"]["dense_valid"] for r in ok),
        "min_clearance_m": min((r["recheck"]["dense_min_clearance"] for r in ok), default=math.nan),
        "median_waypoints": statistics.median([r["waypoints"] for r in ok]) if ok else math.nan,
        "failures": [r["status"] for r in rows if not r["success"]],
        "unproven": [f"collisions {r['recheck']['collision_check']}, windows {r['recheck']['windows_check']}"
                     for r in ok if not r["proven"]],
    }
    return {"scene": scene, "cell": f"{scene}.toml", "world": repr(world), "obstacles": len(world.obstacles),
            "draw": tally, "load": load.as_dict(), "summary": summary, "runs": rows}


def bench_robot(name: str, count: int, seed: int, geometry: str, profiler=None, log=None, scenes=None) -> dict:
    robot = load_robot(name, geometry)
    t0 = time.perf_counter()
    windows = build_windows(robot, margin=MARGIN)
    t_windows = time.perf_counter() - t0
    if log:
        log(f"{name}: {len(windows.windows)} windows ({t_windows:.1f} s), geometry '{robot.geometry.source}'")
    scenes = [bench_scene(robot, windows, scene, count, seed + 100 * list(SCENES).index(scene), profiler, log)
              for scene in (SCENES if scenes is None else scenes)]
    return {"robot": name, "geometry_source": robot.geometry.source, "capsules": len(robot.geometry.capsules),
            "hulls": len(robot.geometry.hulls),
            "windows": [{"name": w.name, "joints": list(w.joints)} for w in windows.windows], "windows_s": t_windows,
            "scenes": scenes}


def _targets(results: list[dict]) -> list[dict]:
    out = []
    for R in results:
        for S in R["scenes"]:
            s = S["summary"]
            for key, (what, cmp, thr, unit) in TARGETS.items():
                v = s[key]
                ok = (v >= thr) if cmp == ">=" else (v <= thr)
                shown = f"{100 * thr:g} %" if unit == "" else f"{thr * 1e3:g} ms" if unit == "s" else f"{thr:g} {unit}"
                out.append({"robot": R["robot"], "scene": S["scene"], "key": key, "what": what, "value": v,
                            "target": f"{cmp} {shown}",
                            "status": "n/a" if math.isnan(v) else ("PASS" if ok else "MISS")})
    return out


def profile_table(profiler: cProfile.Profile, top: int = 25) -> dict:
    """The profile's top functions by own time and by cumulative time (text, as pstats prints them)."""
    out = {}
    for key in ("tottime", "cumulative"):
        buf = io.StringIO()
        pstats.Stats(profiler, stream=buf).strip_dirs().sort_stats(key).print_stats(top)
        out[key] = buf.getvalue()
    return out


def run(quick: bool = False, log=None, geometry: str = "robot", profile: bool = False, robots=None,
        scene: str | None = None) -> dict:
    t0 = time.perf_counter()
    robots = ROBOTS if robots is None else robots
    if scene is not None and scene not in SCENES:
        raise SystemExit(f"bench_cell_plan: scene {scene!r} unknown; allowed: {', '.join(SCENES)}")
    scenes = SCENES if scene is None else [scene]
    count = QUICK_QUERIES if quick else QUERIES
    profiler = cProfile.Profile() if profile else None
    with ForeignLoad() as load:
        results = [bench_robot(name, count, SEED + 1000 * i, geometry, profiler, log, scenes)
                   for i, name in enumerate(robots)]
    from importlib import metadata
    try:
        ompl_version = metadata.version("ompl")
    except metadata.PackageNotFoundError:
        ompl_version = "?"
    unreliable = [f"{R['robot']} {S['scene']}" for R in results for S in R["scenes"] if not S["load"]["reliable"]]
    R = {"benchmark": "bench_cell_plan", "quick": quick, "planner": PLANNER, "time_limit_s": TIME_LIMIT,
         "margin_rad": MARGIN, "queries_per_scene": count, "seed": SEED, "geometry": geometry,
         "context": {"vamp_median_s": VAMP_MEDIAN_S,
                     "vamp_note": "VAMP (Thomason, Kingston, Kavraki, ICRA 2024): published RRT-Connect median on "
                                  "MotionBenchMaker Panda scenes, SIMD sphere checks at sampled states; context, "
                                  "not measured here"},
         "environment": {"python": platform.python_version(), "numpy": np.__version__, "ompl": ompl_version,
                         "machine": platform.machine(), "cpu_count": os.cpu_count(), "load": load.as_dict(),
                         "unreliable_sections": unreliable},
         "robots": results, "targets": _targets(results), "elapsed_s": time.perf_counter() - t0}
    if profiler is not None:
        R["profile"] = profile_table(profiler)
    return R


def _ms(x) -> str:
    """Seconds as milliseconds, or n/a (no successful query to time)."""
    return "n/a" if x is None else f"{1e3 * x:.1f} ms"


def format_report(R: dict) -> str:
    env = R["environment"]
    L = [f"bench_cell_plan — {R['planner']}, {R['time_limit_s']:g} s limit, windows of margin {R['margin_rad']:g} rad, "
         f"{R['queries_per_scene']} queries per scene and robot (seed {R['seed']}), geometry '{R['geometry']}'"
         f"{' [quick]' if R['quick'] else ''}",
         f"OMPL {env['ompl']}, {env['cpu_count']} CPUs, load average before / after "
         f"{env['load']['loadavg_1min_before']:.2f} / {env['load']['loadavg_1min_after']:.2f}"]
    if env["unreliable_sections"]:
        L.append("UNRELIABLE times (other processes took > 10 % of the CPUs meanwhile): "
                 + ", ".join(env["unreliable_sections"]))
    L.append(f"context (not measured): VAMP publishes a {R['context']['vamp_median_s'] * 1e6:.0f} µs median "
             "RRT-Connect on MotionBenchMaker Panda scenes (SIMD sphere checks, no proofs)")
    L.append("")
    for r in R["robots"]:
        L.append(f"{r['robot']}: {r['capsules']} capsules (geometry '{r['geometry_source']}'); windows "
                 + "; ".join(f"{w['name']} (joints {w['joints']})" for w in r["windows"])
                 + f" ({r['windows_s']:.1f} s)")
        for S in r["scenes"]:
            s, d = S["summary"], S["draw"]
            L.append(f"   {S['scene']} ({S['obstacles']} obstacles): {s['queries']} queries; draw: {d['goal_poses']} "
                     f"goal poses, {d['ik_solved']} solved by IK, {d['valid_goals']} valid, {d['separated']} "
                     f"separated from their start by a window, {d['slab_separated_missed']} more across a slab "
                     f"window (free_cells did not see it), {d['other_aspect']} across a singular surface, "
                     f"{d['pairs']} pairs left, {d['pairs_colliding']} with a colliding straight line")
            L.append(f"      straight line: collides {100 * s['straight_collides_share']:.0f} %, crosses a window "
                     f"{100 * s['straight_crosses_window_share']:.0f} %, free (as plan() saw it) "
                     f"{100 * s['straight_free_share']:.0f} %")
            if not s["queries"]:
                continue
            L.append(f"      success {100 * s['success_rate']:.0f} % ({s['returned_paths']}/{s['queries']}); time "
                     f"median {1e3 * s['median_time_s']:.1f} ms, p95 {1e3 * s['p95_time_s']:.1f} ms (successes: median "
                     f"{_ms(s['median_time_success_s'])}, p95 {_ms(s['p95_time_success_s'])})"
                     f"{'' if S['load']['reliable'] else '  UNRELIABLE'}")
            if s["returned_paths"]:
                L.append(f"      proven {100 * s['proven_rate']:.0f} %; re-checks: check_path {s['check_path_valid']}/"
                         f"{s['returned_paths']}, dense clearance every {math.degrees(DENSE_STEP):g}° "
                         f"{s['dense_valid']}/{s['returned_paths']}; smallest clearance "
                         f"{1e3 * s['min_clearance_m']:.3g} mm; median {s['median_waypoints']:g} waypoints")
            if s["failures"]:
                kinds = {k: s["failures"].count(k) for k in sorted(set(s["failures"]))}
                L.append(f"      failures: {kinds}")
            if s["unproven"]:
                kinds = {k: s["unproven"].count(k) for k in sorted(set(s["unproven"]))}
                L.append(f"      returned but not proven: {kinds}")
        L.append("")
    L.append("targets")
    for t in R["targets"]:
        v = t["value"]
        vs = "—" if v is None or (isinstance(v, float) and math.isnan(v)) else (
            f"{v * 1e3:.2f} ms" if t["key"] == "median_time_s" else f"{100 * v:.0f} %")
        L.append(f"   {t['status']:4s}  {t['robot']:13s} {t['scene']:11s} {t['what']:45s} {vs:>9s}   "
                 f"target {t['target']}")
    if "profile" in R:
        L.append("\nprofile of the plan() calls (cProfile), by own time:")
        L.append(R["profile"]["tottime"])
        L.append("by cumulative time:")
        L.append(R["profile"]["cumulative"])
    L.append(f"\n(elapsed {R['elapsed_s']:.1f} s)")
    return "\n".join(L)


def main(argv=None) -> int:
    ap = argparse.ArgumentParser(prog="python -m studies.benchmarks.bench_cell_plan",
                                 description=__doc__.splitlines()[0])
    ap.add_argument("--json", action="store_true", help="print one JSON object with all figures instead of the table")
    ap.add_argument("--quick", action="store_true", help=f"{QUICK_QUERIES} queries per scene and robot (smoke test)")
    ap.add_argument("--profile", action="store_true", help="cProfile the planning calls and report the top costs")
    ap.add_argument("--geometry", choices=("robot", "urdf", "capsules"), default="robot",
                    help="the robots' geometry: the bundled robot's (default: the UR5e's capsules and hulls), "
                         "its capsules alone (capsules), or the Panda's from the import of example-robot-data's "
                         "panda.urdf (urdf)")
    ap.add_argument("--robot", choices=ROBOTS, help="only this robot (default: both)")
    ap.add_argument("--scene", help=f"only this scene (one of {', '.join(SCENES)}; default: all)")
    args = ap.parse_args(argv)
    return measure_and_print("bench_cell_plan", args.json,
                             lambda log: run(args.quick, log, args.geometry, args.profile,
                                             None if args.robot is None else (args.robot,), args.scene), format_report)


if __name__ == "__main__":
    sys.exit(main())
