"""Planning benchmark: OMPL joint paths around singular windows on three 6-joint arms.

Run as ``python -m studies.benchmarks.bench_plan [--json] [--quick]`` (part of ``make bench``).
For the FANUC M-16iB/20, the PUMA 560 and the UR3-like arm (``ur3_homework``), with windows of a
stated margin (:data:`MARGIN` rad around every singular factor), it draws start/goal pairs (fixed
seed) that are

* both valid (inside the joint limits, outside every window),
* blocked: their straight joint-space line crosses a window (a dense :func:`check_path` of the
  two-row path fails with kind ``window``), and
* connectable — decided independently of the planner (:class:`Connectivity`): the joints the windows
  depend on are grouped (joints that share a window are in one group); for every group the free set
  (inside the limits, outside the group's windows, membership by the windows' own ``contains``) is
  sampled on a grid over the group's joints and its connected components are labelled
  (``scipy.ndimage.label``, face connectivity, so no window can be jumped diagonally); a pair is kept
  when its two configurations lie in the same component in every group.  Joints in no window are
  free and never disconnect anything.

Single-joint windows are slabs across the whole joint space (e.g. the wrist window q5 ∈ [−w, w]),
so the kept pairs never cross one: every kept pair crosses a multi-joint window (the shoulder
factor) and goes around it.  Such pairs exist only where a free component is not convex in the
window joints.  On the FANUC (shoulder offset a1) and the UR3 (a 3-joint shoulder factor) the
shoulder windows are curved and there are many; on the PUMA 560 the shoulder factor
0.433 sin(q2+q3) + 0.432 cos q2 − 0.020 cos(q2+q3) vanishes on nearly straight lines
q3 ≈ 3π/2 − 2 q2 (exactly straight if a2 = d4 and a3 = 0), so every component of (q2, q3) is
(nearly) convex and a connectable pair (almost) always has a free straight line: the draw gives up
after :data:`MAX_DRAWS` pairs, the report says how many it found, and targets without pairs are "n/a".

Each pair is planned with ``plan(..., planner="RRTConnect", time_limit=2 s)``; the benchmark
records success, wall time of the ``plan`` call, joint-space path length against the straight
line, the smallest σ_min along the path, and re-runs :func:`check_path` on every returned path.

Targets (checked with PASS/MISS, per robot): success ≥ 98 %; median planning time ≤ 0.3 s; 100 %
of the returned paths dense-valid.  A MISS does not change the exit status (0); an error does.
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

import kin
from planning.certify import certify_path
from planning.ompl.goals import wrist_twins
from planning.ompl.planner import plan
from planning.validate import check_path
from planning.windows import build_windows
from studies.benchmarks.driver import measure_and_print
from studies.benchmarks.plan_pairs import MAX_DRAWS, Connectivity, crosses_window, draw_pairs, naive_plan

ROBOTS = ("fanuc_m16ib20", "puma560", "ur3_homework")
MARGIN = 0.05            # rad, half-width of every window
PAIRS = 50
QUICK_PAIRS = 10
SEED = 20240612
PLANNER = "RRTConnect"
TIME_LIMIT = 2.0         # s

TARGETS = {
    # key: (description, comparison, threshold, unit)
    "success_rate": (f"success rate ({PLANNER}, {TIME_LIMIT:g} s limit)", ">=", 0.98, ""),
    "median_time_s": ("median planning time", "<=", 0.3, "s"),
    "dense_valid_rate": ("returned paths dense-valid", ">=", 1.0, ""),
    "proven_rate": ("returned paths proven clear of every window", ">=", 1.0, ""),
    "verdict_time_median_s": ("separated queries: median time to the verdict", "<=", 0.05, "s"),
    "verdict_rate": ("separated queries answered before planning", ">=", 0.98, ""),
    "pose_goal_success_rate": ("pose goals across the wrist window: success", ">=", 0.98, ""),
}


# ---- one robot -----------------------------------------------------------------------------
def _pct(x: list[float], p: float) -> float:
    return float(np.percentile(x, p)) if x else math.nan


def bench_robot(name: str, n_pairs: int, seed: int, log=None, max_draws: int = MAX_DRAWS) -> dict:
    t0 = time.perf_counter()
    robot = kin.load_robot(name)
    ws = build_windows(robot, margin=MARGIN)
    t_windows = time.perf_counter() - t0
    conn = Connectivity(robot, ws)
    pairs, tally = draw_pairs(robot, ws, conn, n_pairs, seed, max_draws=max_draws)
    if log:
        log(f"{name}: {len(ws.windows)} windows, groups {[[j + 1 for j in g.joints] for g in conn.groups]}, "
            f"{len(pairs)} pairs")
    rows = []
    if len(pairs):   # warm-up (OMPL and evaluator first calls), not timed
        plan(robot, pairs[0, 0], pairs[0, 1], ws, planner=PLANNER, time_limit=TIME_LIMIT, seed=seed)
    for k, (a, b) in enumerate(pairs):
        t = time.perf_counter()
        res = plan(robot, a, b, ws, planner=PLANNER, time_limit=TIME_LIMIT, seed=seed + k)
        wall = time.perf_counter() - t
        row = {"success": bool(res.success), "time_s": wall, "status": res.status,
               "straight_line_valid": bool(res.straight_line_valid),
               "straight_length": float(np.linalg.norm(b - a))}
        naive = naive_plan(robot, ws, a, b, TIME_LIMIT, seed + k)
        row["naive_returned"] = naive is not None
        row["naive_through_window"] = naive is not None and certify_path(ws, naive).violation is not None
        if res.success:
            row["proven"] = bool(res.proven)
            chk = check_path(robot, res.path, ws)     # our own dense re-check
            ends = bool(np.allclose(res.path[0], a, atol=1e-12) and np.allclose(res.path[-1], b, atol=1e-12))
            row.update({"waypoints": int(len(res.path)), "length": float(res.length),
                        "length_ratio": float(res.length / row["straight_length"]),
                        "min_sigma": float(chk.min_sigma), "dense_valid": bool(chk.valid and ends),
                        "violation": None if chk.first_violation is None else chk.first_violation.kind})
        rows.append(row)
        if log and (k + 1) % 10 == 0:
            log(f"  {k + 1}/{len(pairs)} planned")
    separated = _separated_queries(robot, ws, conn, n_pairs, seed + 7, max_draws, log)
    pose = _pose_goal_queries(robot, ws, n_pairs, seed + 11)
    ok = [r for r in rows if r["success"]]
    times = [r["time_s"] for r in rows]
    ok_times = [r["time_s"] for r in ok]
    ratios = [r["length_ratio"] for r in ok]
    sig = [r["min_sigma"] for r in ok]
    summary = {
        "pairs": len(rows),
        "success_rate": len(ok) / len(rows) if rows else math.nan,
        "median_time_s": statistics.median(times) if times else math.nan,
        "p95_time_s": _pct(times, 95),
        "median_time_success_s": statistics.median(ok_times) if ok_times else math.nan,
        "p95_time_success_s": _pct(ok_times, 95),
        "length_ratio_median": statistics.median(ratios) if ratios else math.nan,
        "length_ratio_p95": _pct(ratios, 95),
        "length_ratio_max": max(ratios) if ratios else math.nan,
        "min_sigma_median": statistics.median(sig) if sig else math.nan,
        "min_sigma_min": min(sig) if sig else math.nan,
        # by construction all of them; recounted here, and as the planner saw it
        "straight_lines_crossing_window": sum(crosses_window(robot, ws, a, b) for a, b in pairs),
        "planner_saw_straight_line_blocked": sum(1 for r in rows if not r["straight_line_valid"]),
        "dense_valid_rate": (sum(r["dense_valid"] for r in ok) / len(ok)) if ok else math.nan,
        "dense_valid": sum(r["dense_valid"] for r in ok),
        "returned_paths": len(ok),
        "failures": [r["status"] for r in rows if not r["success"]],
        "proven_rate": (sum(r["proven"] for r in ok) / len(ok)) if ok else math.nan,
        "naive_returned": sum(r["naive_returned"] for r in rows),
        "naive_through_window": sum(r["naive_through_window"] for r in rows),
        **separated, **pose,
        "note": None,
    }
    if len(pairs) < n_pairs:
        summary["note"] = (
            f"only {len(pairs)} of {n_pairs} blocked connectable pairs in {tally['drawn_pairs']:,d} drawn pairs: of "
            f"{tally['valid_pairs']:,d} valid pairs, {tally['unconnectable']:,d} are unconnectable and "
            f"{tally['connectable_straight_line_valid']:,d} of the connectable ones have a free straight line — "
            "the free components are (nearly) convex in the window joints, so a connectable pair is "
            "(almost) never blocked")
    return {
        "robot": name,
        "windows": [{"name": w.name, "joints": list(w.joints), "margin": w.width,
                     **({"intervals": w.intervals} if w.is_interval else {"epsilon": w.epsilon})} for w in ws.windows],
        "windows_s": t_windows,
        "connectivity": {"grid_step_rad": conn.step,
                         "groups": [{"joints": [j + 1 for j in g.joints], "grid_shape": list(g.labels.shape),
                                     "components": g.count, "free_fraction": g.free_fraction,
                                     "seconds": g.seconds} for g in conn.groups]},
        "pair_draws": tally,
        "summary": summary,
        "runs": rows,
    }


def _separated_queries(robot, ws, conn, count: int, seed: int, max_draws: int, log=None) -> dict:
    """Valid pairs in different free components (no joint path exists, by the grid labelling):
    how many plan() answers before planning, and how fast."""
    pairs, _ = draw_pairs(robot, ws, conn, count, seed, max_draws=max_draws, kind="separated")
    times, answered, reasons = [], 0, {}
    for k, (a, b) in enumerate(pairs):
        t = time.perf_counter()
        res = plan(robot, a, b, ws, planner=PLANNER, time_limit=TIME_LIMIT, seed=seed + k)
        times.append(time.perf_counter() - t)
        if res.success:
            raise RuntimeError(f"{robot.name}: plan() joined a pair the grid labelling calls separated")
        if res.separation is not None:
            answered += 1
            reasons[res.separation.kind] = reasons.get(res.separation.kind, 0) + 1
    if log:
        log(f"  {len(pairs)} separated queries, {answered} answered before planning")
    return {"separated_pairs": len(pairs), "verdict_rate": answered / len(pairs) if len(pairs) else math.nan,
            "verdict_time_median_s": statistics.median(times) if times else math.nan,
            "verdict_time_max_s": max(times) if times else math.nan, "verdict_kinds": reasons}


def _pose_goal_queries(robot, ws, count: int, seed: int) -> dict:
    """Pose goals whose given configuration lies across the wrist window from the start (so the
    nearest IK branch is on the far side) while a branch on the start's side exists: the goal keeps
    the start's arm joints (q2, q3: the same free cell of the arm's windows) and draws a new q1 and
    wrist with the wrist joint on the other side, and its wrist twin (q4 ± π, −q5, q6 ± π) must be
    valid.  plan() must find and pick a branch on the start's side."""
    wrist = [w for w in ws.windows if w.kind == "wrist" and w.is_interval]
    if not wrist:
        return {"pose_goal_pairs": 0, "pose_goal_success_rate": math.nan, "pose_goal_proven": 0}
    j = wrist[0].joint
    rng = np.random.default_rng(seed)
    Q = robot.random_configurations(40 * count, seed=seed)
    starts = Q[(ws.which(Q) < 0) & (Q[:, j] < 0)]
    ok = proven = m = 0
    failures = []
    for a in starts:
        if m == count:
            break
        g = a.copy()
        free_joints = [0] + list(range(j - 1, robot.n))            # q1 and the wrist
        lo, hi = robot.chain.lower, robot.chain.upper
        g[free_joints] = rng.uniform(lo[free_joints], hi[free_joints])
        g[j] = rng.uniform(0.2, hi[j])
        if ws.contains(g) or not any(not ws.contains(f) for f in wrist_twins(robot, g, robot.fk(g))):
            continue                     # only queries with a valid branch on the start's side
        m += 1
        res = plan(robot, a, goal_pose=robot.fk(g), windows=ws, planner=PLANNER, time_limit=TIME_LIMIT, seed=seed + m)
        if res.success and np.abs(robot.fk(res.path[-1]) - robot.fk(g)).max() < 1e-8 \
                and check_path(robot, res.path, ws).valid:
            ok += 1
            proven += bool(res.proven)
        else:
            failures.append(res.status)
    return {"pose_goal_pairs": m, "pose_goal_success_rate": ok / m if m else math.nan, "pose_goal_proven": proven,
            "pose_goal_failures": failures}


def _targets(results: list[dict]) -> list[dict]:
    out = []
    for R in results:
        s = R["summary"]
        for key, (what, cmp, thr, unit) in TARGETS.items():
            v = s[key]
            ok = (v >= thr) if cmp == ">=" else (v <= thr)
            shown = f"{100 * thr:g} %" if unit == "" else f"{thr:g} {unit}"
            out.append({"robot": R["robot"], "key": key, "what": what, "value": v,
                        "target": f"{cmp} {shown}",
                        "status": "n/a" if math.isnan(v) else ("PASS" if ok else "MISS")})
    return out


def run(quick: bool = False, log=None) -> dict:
    t0 = time.perf_counter()
    n_pairs = QUICK_PAIRS if quick else PAIRS
    max_draws = MAX_DRAWS // 3 if quick else MAX_DRAWS
    results = [bench_robot(name, n_pairs, SEED + 1000 * i, log, max_draws) for i, name in enumerate(ROBOTS)]
    from importlib import metadata
    try:
        ompl_version = metadata.version("ompl")
    except metadata.PackageNotFoundError:
        ompl_version = "?"
    return {
        "benchmark": "bench_plan", "quick": quick, "planner": PLANNER, "time_limit_s": TIME_LIMIT,
        "margin_rad": MARGIN, "pairs_per_robot": n_pairs, "seed": SEED,
        "environment": {"python": platform.python_version(), "numpy": np.__version__,
                        "ompl": ompl_version, "machine": platform.machine(),
                        "cpu_count": os.cpu_count(), "loadavg_1min": os.getloadavg()[0]},
        "robots": results,
        "targets": _targets(results),
        "elapsed_s": time.perf_counter() - t0,
    }


def format_report(R: dict) -> str:
    L = [f"bench_plan — {R['planner']}, {R['time_limit_s']:g} s limit, windows of margin {R['margin_rad']:g} rad, "
         f"{R['pairs_per_robot']} blocked connectable pairs per robot (seed {R['seed']})"
         f"{' [quick]' if R['quick'] else ''}",
         f"OMPL {R['environment']['ompl']}, {R['environment']['cpu_count']} CPUs, load (1 min) "
         f"{R['environment']['loadavg_1min']:.2f}", ""]
    for r in R["robots"]:
        s, t, c = r["summary"], r["pair_draws"], r["connectivity"]
        L.append(f"{r['robot']}")
        L.append("   windows: " + "; ".join(f"{w['name']} (joints {w['joints']})" for w in r["windows"]))
        L.append(f"   connectivity grid step {c['grid_step_rad']:.4f} rad: " + "; ".join(
            f"joints {g['joints']} grid {'x'.join(map(str, g['grid_shape']))}, {g['components']} components, "
            f"{100 * g['free_fraction']:.1f} % free ({g['seconds']:.1f} s)" for g in c["groups"]))
        L.append(f"   pairs: {t['valid_pairs']} valid pairs drawn, {t['unconnectable'] + t['kept']} of them with a "
                 f"blocked straight line: {t['unconnectable']} rejected as unconnectable, "
                 f"{t['connectable_straight_line_valid']} connectable with a free straight line (not blocked), "
                 f"{t['kept']} blocked & connectable kept ({t['invalid_pairs']} invalid and "
                 f"{t['grid_ambiguous_pairs']} within a grid step of a window skipped)")
        L.append(f"   straight lines crossing a window: {s['straight_lines_crossing_window']}/{s['pairs']} "
                 f"(blocked as plan() saw it: {s['planner_saw_straight_line_blocked']})")
        if s["note"]:
            L.append(f"   NOTE: {s['note']}")
        if s["pairs"]:
            L.append(f"   success {100 * s['success_rate']:.0f} % ({s['returned_paths']}/{s['pairs']}); time median "
                     f"{s['median_time_s']:.3f} s, p95 {s['p95_time_s']:.3f} s (wall of plan(), incl. its own checks)")
        if s["returned_paths"]:
            L.append(f"   length / straight line: median {s['length_ratio_median']:.3f}, p95 "
                     f"{s['length_ratio_p95']:.3f}, max {s['length_ratio_max']:.3f}")
            L.append(f"   min σ_min along the path: smallest {s['min_sigma_min']:.4g}, median "
                     f"{s['min_sigma_median']:.4g}")
            L.append(f"   dense re-check (check_path, 0.1° step, ends at start/goal): "
                     f"{s['dense_valid']}/{s['returned_paths']} valid")
        if s["returned_paths"]:
            L.append(f"   proven clear of every window (interval proof per segment): "
                     f"{100 * s['proven_rate']:.0f} % of returned paths")
        L.append(f"   naive OMPL set-up (pointwise validity, default motion resolution): {s['naive_returned']} paths "
                 f"returned, {s['naive_through_window']} of them through a singular window")
        if s["separated_pairs"]:
            L.append(f"   separated queries: {s['verdict_rate'] * 100:.0f} % of {s['separated_pairs']} answered before "
                     f"planning {s['verdict_kinds']}, median {1e3 * s['verdict_time_median_s']:.1f} ms, max "
                     f"{1e3 * s['verdict_time_max_s']:.1f} ms (was the full {TIME_LIMIT:g} s limit)")
        if s["pose_goal_pairs"]:
            L.append(f"   pose goals across the wrist window: {100 * s['pose_goal_success_rate']:.0f} % of "
                     f"{s['pose_goal_pairs']} planned to a branch on the start's side ({s['pose_goal_proven']} proven)")
        if s["failures"]:
            L.append(f"   failures: {s['failures']}")
        L.append("")
    L.append("targets")
    for t in R["targets"]:
        v = t["value"]
        vs = "—" if v is None or (isinstance(v, float) and math.isnan(v)) else f"{v:.4g}"
        L.append(f"   {t['status']:4s}  {t['robot']:14s} {t['what']:42s} {vs:>8s}   target {t['target']}")
    L.append(f"\n(elapsed {R['elapsed_s']:.1f} s)")
    return "\n".join(L)


def main(argv=None) -> int:
    ap = argparse.ArgumentParser(prog="python -m studies.benchmarks.bench_plan", description=__doc__.splitlines()[0])
    ap.add_argument("--json", action="store_true", help="print one JSON object with all figures instead of the table")
    ap.add_argument("--quick", action="store_true",
                    help=f"{QUICK_PAIRS} pairs per robot, at most {MAX_DRAWS // 3:,d} draws (smoke test)")
    args = ap.parse_args(argv)
    return measure_and_print("bench_plan", args.json,
                             lambda log: run(args.quick, log), format_report)


if __name__ == "__main__":
    sys.exit(main())
