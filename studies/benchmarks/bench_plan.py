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
import json
import math
import os
import platform
import statistics
import sys
import time
from dataclasses import dataclass

import numpy as np

import kin
from planning.ompl.planner import plan
from planning.validate import check_path, densify
from planning.windows import WindowSet, build_windows

ROBOTS = ("fanuc_m16ib20", "puma560", "ur3_homework")
MARGIN = 0.05            # rad, half-width of every window
PAIRS = 50
QUICK_PAIRS = 10
SEED = 20240612
PLANNER = "RRTConnect"
TIME_LIMIT = 2.0         # s
GRID_FRACTION = 0.25     # grid step ≤ this fraction of the narrowest full window width (2 × margin)
MAX_DRAWS = 600_000      # start/goal pairs drawn per robot before giving up

TARGETS = {
    # key: (description, comparison, threshold, unit)
    "success_rate": (f"success rate ({PLANNER}, {TIME_LIMIT:g} s limit)", ">=", 0.98, ""),
    "median_time_s": ("median planning time", "<=", 0.3, "s"),
    "dense_valid_rate": ("returned paths dense-valid", ">=", 1.0, ""),
}


# ---- connectivity, independent of the planner ------------------------------------------------
def joint_groups(ws: WindowSet) -> list[list[int]]:
    """0-based joints the windows depend on, grouped: joints sharing a window are in one group."""
    parent: dict[int, int] = {}

    def find(j: int) -> int:
        while parent[j] != j:
            parent[j] = parent[parent[j]]
            j = parent[j]
        return j

    for w in ws.windows:
        js = [j - 1 for j in w.joints]
        for j in js:
            parent.setdefault(j, j)
        for j in js[1:]:
            parent[find(j)] = find(js[0])
    groups: dict[int, list[int]] = {}
    for j in sorted(parent):
        groups.setdefault(find(j), []).append(j)
    return sorted(groups.values())


@dataclass
class GroupGrid:
    """Connected components of the free set of one joint group, on a regular grid."""

    joints: list[int]           # 0-based
    axes: list[np.ndarray]      # grid values per joint (SI), from the lower to the upper limit
    labels: np.ndarray          # int32 grid, 0 inside a window, 1..count per component
    count: int
    step: float                 # largest grid step (SI)
    free_fraction: float
    seconds: float

    def label_of(self, Q: np.ndarray) -> np.ndarray:
        """Component label (N,) of the grid point nearest to each configuration (0: in a window)."""
        idx = []
        for j, ax in zip(self.joints, self.axes):
            h = (ax[-1] - ax[0]) / (len(ax) - 1)
            idx.append(np.clip(np.rint((Q[:, j] - ax[0]) / h).astype(int), 0, len(ax) - 1))
        return self.labels[tuple(idx)]


def label_group(robot, ws: WindowSet, joints: list[int], step: float) -> GroupGrid:
    """Label the free set of ``joints`` (their windows only) on a grid of step ≤ ``step``."""
    from scipy import ndimage

    t0 = time.perf_counter()
    lo, hi = robot.chain.lower, robot.chain.upper
    mine = [w for w in ws.windows if {j - 1 for j in w.joints} <= set(joints)]
    axes = [np.linspace(lo[j], hi[j], int(math.ceil((hi[j] - lo[j]) / step)) + 1) for j in joints]
    shape = tuple(len(a) for a in axes)
    free = np.empty(shape, bool)
    # one slice of the first joint at a time; the other joints stay at 0 (the group's windows do
    # not depend on them)
    rest = np.meshgrid(*axes[1:], indexing="ij") if len(joints) > 1 else []
    Q = np.zeros((int(np.prod(shape[1:])), robot.n), order="F")   # column access is what the windows do
    for k, j in enumerate(joints[1:], 1):
        Q[:, j] = rest[k - 1].ravel()
    for i, x in enumerate(axes[0]):
        Q[:, joints[0]] = x
        inside = np.zeros(len(Q), bool)
        for w in mine:
            inside |= w.contains(Q)
        free[i] = ~inside.reshape(shape[1:])
    free = free.reshape(shape)
    structure = ndimage.generate_binary_structure(len(joints), 1)   # faces only: no diagonal leaks
    labels, count = ndimage.label(free, structure=structure)
    return GroupGrid(joints, axes, labels, int(count), float(max((a[-1] - a[0]) / (len(a) - 1) for a in axes)),
                     float(free.mean()), time.perf_counter() - t0)


class Connectivity:
    """Whether two valid configurations lie in one connected component of the free joint space."""

    def __init__(self, robot, ws: WindowSet, fraction: float = GRID_FRACTION):
        widths = [2 * w.width for w in ws.windows if w.width > 0]
        self.step = fraction * min(widths) if widths else math.inf
        self.groups = [label_group(robot, ws, g, self.step) for g in joint_groups(ws)]

    def labels(self, Q: np.ndarray) -> np.ndarray:
        """(N, groups) component labels; a 0 means the nearest grid point is inside a window."""
        Q = np.atleast_2d(Q)
        if not self.groups:
            return np.ones((len(Q), 0), int)
        return np.stack([g.label_of(Q) for g in self.groups], axis=1)


# ---- pairs ---------------------------------------------------------------------------------
def crosses_window(robot, ws: WindowSet, a: np.ndarray, b: np.ndarray) -> bool:
    """Whether the straight joint-space line a→b enters a window (states 0.1° apart, windows only)."""
    Q, _, _ = densify(np.array([a, b]), robot.chain.revolute_mask)
    return bool(ws.contains(Q).any())


def draw_pairs(robot, ws: WindowSet, conn: Connectivity, count: int, seed: int, batch: int = 20_000,
               max_draws: int = MAX_DRAWS) -> tuple[np.ndarray, dict]:
    """``count`` blocked, connectable start/goal pairs (count, 2, n) and the tallies of the draw.

    Configurations are drawn uniformly in the limits and paired in draw order.  A valid pair is
    rejected when its two ends lie in different components (unconnectable) or when its straight
    line stays outside every window (not a blocked case); the rest are kept, after a final dense
    :func:`check_path` of the straight line confirms it fails with kind ``window``.  Gives up after
    ``max_draws`` pairs (fewer pairs are returned: some machines have almost none, see the PUMA note
    in :func:`bench_robot`).
    """
    rng = np.random.default_rng(seed)
    lo, hi = robot.chain.lower, robot.chain.upper
    tally = {"drawn_pairs": 0, "invalid_pairs": 0, "grid_ambiguous_pairs": 0, "valid_pairs": 0,
             "unconnectable": 0, "connectable_straight_line_valid": 0, "kept": 0}
    pairs: list[np.ndarray] = []
    while len(pairs) < count:
        if tally["drawn_pairs"] >= max_draws:
            break
        A = rng.uniform(lo, hi, size=(batch, robot.n))
        B = rng.uniform(lo, hi, size=(batch, robot.n))
        valid = ~ws.contains(A) & ~ws.contains(B)
        LA, LB = conn.labels(A), conn.labels(B)
        resolved = (LA > 0).all(axis=1) & (LB > 0).all(axis=1)   # not within a grid step of a window
        same = (LA == LB).all(axis=1)
        for k in range(min(batch, max_draws - tally["drawn_pairs"])):
            tally["drawn_pairs"] += 1
            if not valid[k]:
                tally["invalid_pairs"] += 1
                continue
            if not resolved[k]:
                tally["grid_ambiguous_pairs"] += 1
                continue
            tally["valid_pairs"] += 1
            if not same[k]:
                tally["unconnectable"] += 1
                continue
            if not crosses_window(robot, ws, A[k], B[k]):
                tally["connectable_straight_line_valid"] += 1
                continue
            chk = check_path(robot, np.array([A[k], B[k]]), ws)
            if chk.valid or chk.first_violation.kind != "window":   # cannot happen: a second opinion
                raise RuntimeError(f"{robot.name}: straight-line checks disagree for pair {tally['drawn_pairs']}")
            tally["kept"] += 1
            pairs.append(np.array([A[k], B[k]]))
            if len(pairs) == count:
                break
    return np.array(pairs).reshape(-1, 2, robot.n), tally


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
        if res.success:
            chk = check_path(robot, res.path, ws)     # our own dense re-check
            ends = bool(np.allclose(res.path[0], a, atol=1e-12) and np.allclose(res.path[-1], b, atol=1e-12))
            row.update({"waypoints": int(len(res.path)), "length": float(res.length),
                        "length_ratio": float(res.length / row["straight_length"]),
                        "min_sigma": float(chk.min_sigma), "dense_valid": bool(chk.valid and ends),
                        "violation": None if chk.first_violation is None else chk.first_violation.kind})
        rows.append(row)
        if log and (k + 1) % 10 == 0:
            log(f"  {k + 1}/{len(pairs)} planned")
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
    log = None if args.json else (lambda msg: print(msg, file=sys.stderr, flush=True))
    try:
        R = run(args.quick, log)
    except Exception as e:  # a failed measurement is an error, not a MISS
        print(f"bench_plan: {type(e).__name__}: {e}", file=sys.stderr)
        return 1

    def clean(x):   # JSON without NaN
        if isinstance(x, float) and not math.isfinite(x):
            return None
        if isinstance(x, dict):
            return {k: clean(v) for k, v in x.items()}
        if isinstance(x, (list, tuple)):
            return [clean(v) for v in x]
        return x

    print(json.dumps(clean(R), default=float) if args.json else format_report(R))
    return 0


if __name__ == "__main__":
    sys.exit(main())
