"""Reach benchmark: the reach study's throughput against pinocchio + coal, robot placement by IPOPT
against a brute-force grid, and the planar 2R whose best placement is known.

Run as ``python -m studies.benchmarks.bench_reach [--json] [--quick]`` (part of ``make bench``).
Everything runs on one thread: ``RMTKIT_THREADS=1`` for rmtkit's batch calls, and the BLAS / OpenMP
pools of the process (numpy's, pinocchio's, IPOPT's) limited to 1 by threadpoolctl; pinocchio is
only called through its serial functions.  Each section reports its CPU time over its wall time.

1. **Reach-study throughput** (targets/s, median of repeats): the UR5e in the cell
   ``studies/benchmarks/scenes/table_pick.toml`` (a table, cans, a cereal box, a crate, a bowl, a
   bottle), 200 targets on a 5 × 8 × 5 box grid in front of it (x 0.3–0.9, y −0.4–0.4, z 0.05–0.45
   m; ``--quick``: 3 × 4 × 3), the tool axis pointing down ("axis": free about itself).  rmtkit:
   :func:`design.reach.reach_study` with its default settings (8 starts × 8 spins per target, and
   the score, the reasons of the misses).  **Peer**: what a pinocchio user writes — a Python loop
   over the targets and, per target, over the *same* 8 × 8 (start, spin) pairs (the same Halton
   start configurations, the same goal frames; handed over ready, not timed): pinocchio's CLIK
   (the damped least-squares loop of pinocchio's ``examples/inverse-kinematics.py``:
   ``forwardKinematics``, ``log`` of the error, ``computeJointJacobian``, ``Jlog6``, ``integrate``,
   its step 0.1 and damping 1e-12; the goal carried from the tool to the last joint, the tolerance
   the targets' 1e-6 and at most 200 iterations per start, rmtkit's budget), the angles brought
   into (−π, π] and checked against the limits, then ``computeCollisions`` (stop at the first)
   between rmtkit's capsules as coal capsules and the cell's obstacles, with rmtkit's pairs
   (:func:`studies.benchmarks.collision_peers.capsule_scene`); the first clear solution ends a
   target.  So the peer answers less (no score, no reason) and stops early: the ratio flatters it.
   Agreement: targets both call reached, neither, rmtkit only, pinocchio only — the two IKs differ,
   disagreements are counted, not asserted.
2. **Placement**: the UR5e, 27 targets on a 3 × 3 × 3 box (x 0.9–1.3, y −0.3–0.3, z 0–0.3 m, tool
   axis (0, 0, −1)), no cell; the region x ∈ [0, 1.5], y ∈ [−1, 1], z = 0, yaw ∈ [−π, π].  IPOPT:
   :func:`design.place.place` (4 starts, no grid, no differential evolution; screening, IPOPT and
   its verification by the full reach study all timed).  Grid: 30 values per free coordinate
   (27,000 placements; ``--quick``: 12³ = 1,728, and the time ratio is then not the acceptance
   figure) scored by the light reach study :data:`design.place.SCREEN`
   (:func:`design.place.evaluate_placements`), its best verified by the full reach study; the set-up,
   evaluation and verification timed.  Targets: IPOPT's verified coverage ≥ the grid's, its mean
   score ≥ 0.99 × the grid's, its time ≤ the grid's / 20.
3. **Planar 2R** (a1 = 1, a2 = 0.8 m: it reaches the annulus 0.2–1.8 m): targets on rings of radii
   0.2 … 1.8 m (both boundary circles included) around (0.5, 0.3, 0); only a base at the centre
   reaches the boundary circles.  ``place`` with its default region; targets: its answer within
   1 mm of the centre, 100 % coverage.

A MISS does not change the exit status (0); an error does.  Figures taken while other processes
used more than 10 % of the CPUs are flagged unreliable (:class:`studies.benchmarks.load.ForeignLoad`).
"""
from __future__ import annotations

import argparse
import contextlib
import dataclasses
import math
import os
import platform
import statistics
import sys
import time

import numpy as np

import kin
from design.place import SCREEN, PlacementRegion, evaluate_placements, grid_placements, place, placement_transform
from design.reach import ReachSettings, ScoreWeights, reach_study
from design.reach.study import ReachProblem
from design.task.model import Targets
from planning.cell import load_cell
from planning.collision import collision_world
from studies.benchmarks.bench_collision import scene_path
from studies.benchmarks.driver import measure_and_print
from studies.benchmarks.load import ForeignLoad

ROBOT = "ur5e"
CELL = "table_pick.toml"
DOWN = (0.0, 0.0, -1.0)
#: the reach-study box (m): x, y, z ranges; the number of values per axis is in SIZES
REACH_BOX = ((0.3, 0.9), (-0.4, 0.4), (0.05, 0.45))
#: the placement task's box (m) and region
PLACE_BOX = ((0.9, 1.3), (-0.3, 0.3), (0.0, 0.3))
PLACE_REGION = PlacementRegion(x=(0.0, 1.5), y=(-1.0, 1.0), z=(0.0, 0.0), yaw=(-math.pi, math.pi))
PLACE_STARTS = 4
#: the planar 2R's ring centre (m) and radii (m)
RING_CENTRE = (0.5, 0.3, 0.0)
RING_RADII = (0.2, 1.8)
#: pinocchio's CLIK example: step and damping; the tolerance and the iteration budget are the study's
CLIK_DT, CLIK_DAMP = 1e-1, 1e-12

SIZES = {False: dict(reach_shape=(5, 8, 5), rm_repeats=5, peer_repeats=3, place_shape=(3, 3, 3), place_grid=30,
                     place_repeats=3, ring=(5, 12)),
         True: dict(reach_shape=(3, 4, 3), rm_repeats=3, peer_repeats=1, place_shape=(3, 3, 3), place_grid=12,
                    place_repeats=1, ring=(5, 12))}

TARGETS = {
    # key: (description, comparison, threshold, unit)
    "place_coverage": ("IPOPT verified coverage − grid's", ">=", 0.0, "%"),
    "place_score": ("IPOPT mean score / grid's", ">=", 0.99, ""),
    "place_speed": ("grid time / IPOPT time", ">=", 20.0, "x"),
    "planar_distance": ("2R placement − ring centre", "<=", 1.0, "mm"),
    "planar_coverage": ("2R verified coverage", ">=", 100.0, "%"),
}


# ---- helpers -----------------------------------------------------------------------------
@contextlib.contextmanager
def one_thread():
    """``RMTKIT_THREADS=1`` and every BLAS / OpenMP pool of the process at 1 thread, restored after."""
    from threadpoolctl import threadpool_limits
    old = os.environ.get("RMTKIT_THREADS")
    os.environ["RMTKIT_THREADS"] = "1"
    try:
        with threadpool_limits(limits=1):
            yield
    finally:
        if old is None:
            os.environ.pop("RMTKIT_THREADS", None)
        else:
            os.environ["RMTKIT_THREADS"] = old


class _Clock:
    """Wall and CPU time of a block (CPU / wall ≈ 1 on one thread)."""

    def __enter__(self):
        self.t0, self.c0 = time.perf_counter(), time.process_time()
        return self

    def __exit__(self, *exc):
        self.wall = time.perf_counter() - self.t0
        self.cpu = time.process_time() - self.c0


def _try_pinocchio():
    try:
        import coal  # noqa: F401 - the capsules' distances
        import pinocchio as pin
        return pin, None
    except Exception as e:  # ImportError, or a broken binary install
        return None, f"pinocchio / coal not importable ({type(e).__name__}: {e}); install the 'bench' extra"


def _version(dist: str) -> str:
    from importlib import metadata
    try:
        return metadata.version(dist)
    except metadata.PackageNotFoundError:
        return "?"


def box_targets(box, shape, axis=DOWN) -> Targets:
    """Targets on a grid of ``shape`` values over the box ((x0, x1), (y0, y1), (z0, z1)) (m), the tool
    axis along ``axis`` ("axis": free about it)."""
    axes = [np.linspace(lo, hi, k) for (lo, hi), k in zip(box, shape)]
    P = np.stack(np.meshgrid(*axes, indexing="ij"), axis=-1).reshape(-1, 3)
    return Targets(P, orientation="axis", axes=np.tile(np.asarray(axis, float), (len(P), 1)))


def ring_targets(radii: int, angles: int) -> Targets:
    """Position targets on ``radii`` rings from RING_RADII[0] to [1] (both included), ``angles`` per
    ring, around RING_CENTRE."""
    r = np.linspace(*RING_RADII, radii)
    a = np.linspace(0.0, 2 * math.pi, angles, endpoint=False)
    R, A = np.meshgrid(r, a, indexing="ij")
    c = np.asarray(RING_CENTRE)
    P = np.column_stack([c[0] + (R * np.cos(A)).ravel(), c[1] + (R * np.sin(A)).ravel(), np.full(R.size, c[2])])
    return Targets(P)


def _median_timed(fn, repeats: int):
    """``fn()`` ``repeats`` times: (its last result, the wall times, CPU / wall over all)."""
    times, cpu, out = [], 0.0, None
    for _ in range(repeats):
        with _Clock() as c:
            out = fn()
        times.append(c.wall)
        cpu += c.cpu
    return out, times, cpu / max(sum(times), 1e-12)


# ---- 1. reach-study throughput ----------------------------------------------------------
def clik_peer(world, goals: np.ndarray, starts: np.ndarray, nv: int, tolerance: float, max_iter: int):
    """The pinocchio user's reach loop (see the module text) on the capsule scene of ``world``:
    ``goals`` (N·nv, 4, 4) tool goal frames (robot frame), ``starts`` (N, k, n).  Returns a callable
    giving (reached (N,), CLIK runs, CLIK iterations, collision checks)."""
    import pinocchio as pin

    from studies.benchmarks import collision_peers as cp

    scene = cp.capsule_scene(world)
    model, data, gm, gd = scene.model, scene.data, scene.gmodel, scene.gdata
    fid = model.getFrameId("tool")
    jid = model.frames[fid].parentJoint
    tMj = model.frames[fid].placement.inverse()          # the goal of the tool → the goal of its joint
    lo, hi = model.lowerPositionLimit, model.upperPositionLimit
    N, k, n = starts.shape
    eye6 = np.eye(6)
    norm, solve = np.linalg.norm, np.linalg.solve
    fk, log, jac, jlog, integrate = pin.forwardKinematics, pin.log, pin.computeJointJacobian, pin.Jlog6, pin.integrate
    collide = pin.computeCollisions
    two_pi = 2 * math.pi

    def clik(oMdes, q):
        """pinocchio's CLIK example: (converged, q, iterations)."""
        for i in range(max_iter + 1):
            fk(model, data, q)
            iMd = data.oMi[jid].actInv(oMdes)
            err = log(iMd).vector
            if norm(err) < tolerance:
                return True, q, i
            if i >= max_iter:
                return False, q, i
            J = -jlog(iMd.inverse()) @ jac(model, data, q, jid)
            v = -J.T @ solve(J @ J.T + CLIK_DAMP * eye6, err)
            q = integrate(model, q, v * CLIK_DT)
        return False, q, max_iter

    def run():
        reached = np.zeros(N, bool)
        runs = iters = checks = 0
        for i in range(N):
            for j in range(k):
                for v in range(nv):
                    oMdes = pin.SE3(goals[i * nv + v]) * tMj
                    ok, q, it = clik(oMdes, starts[i, j].copy())
                    runs += 1
                    iters += it
                    if not ok:
                        continue
                    q = (q + math.pi) % two_pi - math.pi
                    if np.any(q < lo) or np.any(q > hi):
                        continue
                    checks += 1
                    if not collide(model, data, gm, gd, q, True):
                        reached[i] = True
                        break
                if reached[i]:
                    break
        return reached, runs, iters, checks

    return run, scene


def bench_study(sizes: dict, log) -> dict:
    robot = kin.load_robot(ROBOT)
    cell = load_cell(str(scene_path(CELL)))
    targets = box_targets(REACH_BOX, sizes["reach_shape"])
    settings = ReachSettings()
    N = len(targets)
    say = log or (lambda s: None)
    say(f"reach study: {N} targets, rmtkit reach_study × {sizes['rm_repeats']}")
    reach_study(robot, targets, cell)                    # warm-up: the compiled kernels' caches
    with ForeignLoad() as load:
        study, times, cpu = _median_timed(lambda: reach_study(robot, targets, cell), sizes["rm_repeats"])
    med = statistics.median(times)
    rm = {"median_s": med, "times_s": times, "targets_per_s": N / med, "cpu_per_wall": cpu,
          "coverage_percent": 100 * study.coverage, "reached": int(study.reached.sum()),
          "mean_score": study.mean_score, "reasons": study.reason_counts(),
          "collisions_by_object": study.obstacle_counts(), "ik_runs": N * study.settings.starts * settings.spins,
          "load": load.as_dict()}
    out = {"robot": ROBOT, "cell": CELL, "targets": N, "grid": list(sizes["reach_shape"]),
           "box_m": [list(b) for b in REACH_BOX], "orientation": "axis", "axis": list(DOWN),
           "settings": dataclasses.asdict(settings), "rmtkit": rm}
    pin, why = _try_pinocchio()
    if pin is None:
        out["pinocchio"] = {"skipped": why}
        return out
    pb = ReachProblem(robot, targets, cell, 0.0, None, ScoreWeights(), settings, None)
    goals, starts, mode = pb.goals(pb.default_base)
    assert mode == "pose" and np.allclose(pb.default_base, cell.base)
    peer, scene = clik_peer(collision_world(robot, cell), goals, starts, pb.nv, targets.tolerance, settings.max_iter)
    say(f"reach study: pinocchio CLIK + coal loop × {sizes['peer_repeats']} (tens of seconds each)")
    with ForeignLoad() as load:
        (reached, runs, iters, checks), ptimes, pcpu = _median_timed(peer, sizes["peer_repeats"])
    pmed = statistics.median(ptimes)
    out["pinocchio"] = {"median_s": pmed, "times_s": ptimes, "targets_per_s": N / pmed, "cpu_per_wall": pcpu,
                        "coverage_percent": 100 * float(reached.mean()), "reached": int(reached.sum()),
                        "clik_runs": runs, "clik_iterations": iters, "collision_checks": checks,
                        "clik": {"dt": CLIK_DT, "damping": CLIK_DAMP, "tolerance": targets.tolerance,
                                 "max_iter": settings.max_iter},
                        "pairs": len(scene.gmodel.collisionPairs), "version": _version("pin"),
                        "coal": _version("coal"), "load": load.as_dict()}
    ours = study.reached
    only_rm, only_pin = ours & ~reached, reached & ~ours
    out["agreement"] = {"both_reached": int((ours & reached).sum()), "neither": int((~ours & ~reached).sum()),
                        "rmtkit_only": int(only_rm.sum()), "pinocchio_only": int(only_pin.sum()),
                        "disagreements": int((ours != reached).sum()),
                        "pinocchio_only_rmtkit_reasons": {str(r): int(np.sum(study.reason[only_pin] == r))
                                                          for r in sorted(set(study.reason[only_pin]))}}
    out["ratio_targets_per_s"] = rm["targets_per_s"] / out["pinocchio"]["targets_per_s"]
    return out


# ---- 2. placement: IPOPT against a grid -------------------------------------------------
def bench_placement(sizes: dict, log) -> dict:
    robot = kin.load_robot(ROBOT)
    targets = box_targets(PLACE_BOX, sizes["place_shape"])
    region = PLACE_REGION
    say = log or (lambda s: None)
    say(f"placement: place() with IPOPT × {sizes['place_repeats']}")
    with ForeignLoad() as load:
        res, times, cpu = _median_timed(lambda: place(robot, targets, None, region, starts=PLACE_STARTS, grid=0,
                                                      de_iterations=0), sizes["place_repeats"])
    m = res.methods.get("ipopt") or res.methods[res.method]
    ip = {"method": res.method if "ipopt" not in res.methods else "ipopt", "median_s": statistics.median(times),
          "times_s": times, "cpu_per_wall": cpu, "placement": m["placement"],
          "coverage_percent": m["coverage_percent"], "mean_score": m["mean_score"], "value": m["value"],
          "starts": PLACE_STARTS, "runs": [{"status": r.status, "iterations": r.iterations, "time_s": r.time_s}
                                           for r in res.ipopt], "load": load.as_dict()}
    n = sizes["place_grid"]
    U = grid_placements(region, n)
    say(f"placement: grid {n}^{int(region.free.sum())} = {len(U):,d} placements (light study)")
    with ForeignLoad() as load:
        with _Clock() as c_setup:      # the light problem as place() builds it
            weights, settings = ScoreWeights(), ReachSettings()
            full = ReachProblem(robot, targets, None, 0.0, None, weights, settings, None)
            light = ReachProblem(robot, targets, None, 0.0, None,
                                 dataclasses.replace(weights, dexterity_ref=full.dex_ref), SCREEN, None)
        with _Clock() as c_eval:
            ev = evaluate_placements(light, U, region)
        with _Clock() as c_ver:
            u = ev.U[ev.best()]
            s = reach_study(robot, targets, None, placement_transform(u), settings=settings)
    grid_time = c_setup.wall + c_eval.wall + c_ver.wall
    gr = {"per_axis": n, "placements": len(U), "time_s": grid_time, "setup_s": c_setup.wall,
          "evaluate_s": c_eval.wall, "verify_s": c_ver.wall,
          "cpu_per_wall": (c_setup.cpu + c_eval.cpu + c_ver.cpu) / max(grid_time, 1e-12),
          "placement": [float(v) for v in u], "screen_value": float(ev.value[ev.best()]),
          "coverage_percent": 100 * s.coverage, "mean_score": s.mean_score, "value": s.value, "load": load.as_dict()}
    return {"robot": ROBOT, "targets": len(targets), "box_m": [list(b) for b in PLACE_BOX], "axis": list(DOWN),
            "region": region.to_dict(), "ipopt": ip, "grid": gr, "acceptance": n >= 30,
            "coverage_gain_percent": ip["coverage_percent"] - gr["coverage_percent"],
            "score_ratio": ip["mean_score"] / gr["mean_score"] if gr["mean_score"] > 0 else math.inf,
            "time_ratio": grid_time / ip["median_s"]}


# ---- 3. the planar 2R -------------------------------------------------------------------
def bench_planar(sizes: dict, log) -> dict:
    robot = kin.load_robot("planar_2r")
    targets = ring_targets(*sizes["ring"])
    (log or (lambda s: None))("planar 2R: place() on the ring")
    with ForeignLoad() as load:
        with _Clock() as c:
            res = place(robot, targets)
    d = float(np.linalg.norm(res.u[:2] - np.asarray(RING_CENTRE[:2])))
    return {"robot": "planar_2r", "targets": len(targets), "rings": sizes["ring"][0], "per_ring": sizes["ring"][1],
            "radii_m": list(RING_RADII), "centre_m": list(RING_CENTRE), "placement": [float(v) for v in res.u],
            "distance_mm": 1e3 * d, "coverage_percent": 100 * res.study.coverage, "mean_score": res.study.mean_score,
            "method": res.method, "region": res.region.to_dict(), "time_s": c.wall, "load": load.as_dict()}


# ---- targets and the whole run ----------------------------------------------------------
def _check(key: str, value, note: str = "") -> dict:
    desc, op, thr, unit = TARGETS[key]
    if value is None or (isinstance(value, float) and math.isnan(value)):
        status = "n/a"
    else:
        status = "PASS" if (value >= thr if op == ">=" else value <= thr) else "MISS"
    return {"key": key, "what": desc, "value": value, "target": f"{op} {thr:g} {unit}".strip(), "status": status,
            "note": note}


def _targets(R: dict) -> list[dict]:
    p, q = R["placement"], R["planar_2r"]
    note = "" if p["acceptance"] else f"quick: {p['grid']['per_axis']}³ grid, not the acceptance figure"
    return [_check("place_coverage", p["coverage_gain_percent"]), _check("place_score", p["score_ratio"]),
            _check("place_speed", p["time_ratio"], note), _check("planar_distance", q["distance_mm"]),
            _check("planar_coverage", q["coverage_percent"])]


def run(quick: bool = False, log=None, sections=("study", "placement", "planar")) -> dict:
    t0 = time.perf_counter()
    sizes = SIZES[quick]
    _try_pinocchio()                 # load its libraries before the thread pools are limited
    import casadi  # noqa: F401 - likewise IPOPT's
    R: dict = {"benchmark": "bench_reach", "quick": quick}
    with one_thread(), ForeignLoad() as load:
        if "study" in sections:
            R["reach_study"] = bench_study(sizes, log)
        if "placement" in sections:
            R["placement"] = bench_placement(sizes, log)
        if "planar" in sections:
            R["planar_2r"] = bench_planar(sizes, log)
    unreliable = []
    for name, sec, keys in (("reach study", "reach_study", ("rmtkit", "pinocchio")),
                            ("placement", "placement", ("ipopt", "grid")), ("planar 2R", "planar_2r", (None,))):
        for k in keys:
            rec = R.get(sec, {}) if k is None else R.get(sec, {}).get(k, {})
            if "load" in rec and not rec["load"]["reliable"]:
                unreliable.append(f"{name}{'' if k is None else ' ' + k}")
    R["environment"] = {"python": platform.python_version(), "numpy": np.__version__, "pinocchio": _version("pin"),
                        "coal": _version("coal"), "casadi": _version("casadi"), "machine": platform.machine(),
                        "cpu_count": os.cpu_count(), "RMTKIT_THREADS": 1, "load": load.as_dict(),
                        "unreliable_sections": unreliable}
    R["targets"] = _targets(R) if {"placement", "planar"} <= set(sections) else []
    R["elapsed_s"] = time.perf_counter() - t0
    return R


# ---- report ------------------------------------------------------------------------------
def _u(u) -> str:
    return f"x {u[0]:.3f} m, y {u[1]:.3f} m, yaw {math.degrees(u[5]):.1f}°"


def _flag(rec: dict) -> str:
    return "" if rec["load"]["reliable"] else "  UNRELIABLE"


def format_report(R: dict) -> str:
    env = R["environment"]
    L = [f"bench_reach — 1 thread (RMTKIT_THREADS=1, BLAS/OpenMP pools at 1){' [quick]' if R['quick'] else ''}",
         f"pinocchio {env['pinocchio']}, coal {env['coal']}, casadi {env['casadi']}; {env['cpu_count']} CPUs; load "
         f"average before / after {env['load']['loadavg_1min_before']:.2f} / {env['load']['loadavg_1min_after']:.2f}"]
    if env["unreliable_sections"]:
        L.append("UNRELIABLE figures (other processes took > 10 % of the CPUs meanwhile): "
                 + ", ".join(env["unreliable_sections"]))
    L.append("")
    S = R.get("reach_study")
    if S:
        st, rm = S["settings"], S["rmtkit"]
        shape = " × ".join(str(k) for k in S["grid"])
        L.append(f"1. reach study: {S['robot']} in {S['cell']}, {S['targets']} targets ({shape} box x "
                 f"{S['box_m'][0][0]:g}–{S['box_m'][0][1]:g}, y {S['box_m'][1][0]:g}–{S['box_m'][1][1]:g}, z "
                 f"{S['box_m'][2][0]:g}–{S['box_m'][2][1]:g} m, tool axis down), {st['starts']} starts × "
                 f"{st['spins']} spins per target")
        L.append(f"   rmtkit reach_study (default settings): {rm['targets_per_s']:9.1f} targets/s (median of "
                 f"{len(rm['times_s'])}: {rm['median_s']:.3f} s; CPU/wall {rm['cpu_per_wall']:.2f}); "
                 f"{rm['coverage_percent']:.1f} % reached, mean score {rm['mean_score']:.4f}; {rm['reasons']}"
                 + _flag(rm))
        pe = S["pinocchio"]
        if "skipped" in pe:
            L.append(f"   pinocchio: {pe['skipped']}")
        else:
            L.append(f"   pinocchio CLIK + coal loop:            {pe['targets_per_s']:9.1f} targets/s (median of "
                     f"{len(pe['times_s'])}: {pe['median_s']:.2f} s; CPU/wall {pe['cpu_per_wall']:.2f}); "
                     f"{pe['coverage_percent']:.1f} % reached; {pe['clik_runs']:,d} CLIK runs, "
                     f"{pe['clik_iterations']:,d} iterations, {pe['collision_checks']:,d} computeCollisions "
                     f"({pe['pairs']} pairs)" + _flag(pe))
            a = S["agreement"]
            L.append(f"   ratio rmtkit / pinocchio (targets/s, 1 thread each): {S['ratio_targets_per_s']:.1f}x")
            L.append(f"   agreement: both reached {a['both_reached']}, neither {a['neither']}, rmtkit only "
                     f"{a['rmtkit_only']}, pinocchio only {a['pinocchio_only']} (rmtkit's reasons there: "
                     f"{a['pinocchio_only_rmtkit_reasons'] or '—'}) → {a['disagreements']} disagreement(s) of "
                     f"{S['targets']}")
        L.append("")
    P = R.get("placement")
    if P:
        ip, gr = P["ipopt"], P["grid"]
        L.append(f"2. placement: {P['robot']}, {P['targets']} targets (x {P['box_m'][0][0]:g}–{P['box_m'][0][1]:g}, "
                 f"y {P['box_m'][1][0]:g}–{P['box_m'][1][1]:g}, z {P['box_m'][2][0]:g}–{P['box_m'][2][1]:g} m, "
                 f"tool axis down), region x {P['region']['x']}, y {P['region']['y']}, yaw ±180°, no cell")
        L.append(f"   IPOPT (place, {ip['starts']} starts, no grid, no DE): {ip['median_s']:.2f} s (median of "
                 f"{len(ip['times_s'])}; CPU/wall {ip['cpu_per_wall']:.2f}); verified {ip['coverage_percent']:.1f} %, "
                 f"mean score {ip['mean_score']:.4f} at {_u(ip['placement'])}" + _flag(ip))
        L.append(f"   grid {gr['per_axis']}³ = {gr['placements']:,d} placements (light study): {gr['time_s']:.1f} s "
                 f"(set-up {gr['setup_s']:.2f} + evaluate {gr['evaluate_s']:.1f} + verify {gr['verify_s']:.2f}; "
                 f"CPU/wall {gr['cpu_per_wall']:.2f}); verified {gr['coverage_percent']:.1f} %, mean score "
                 f"{gr['mean_score']:.4f} at {_u(gr['placement'])}" + _flag(gr))
        L.append(f"   IPOPT / grid: coverage {P['coverage_gain_percent']:+.1f} points, mean score ×"
                 f"{P['score_ratio']:.4f}, {P['time_ratio']:.1f}x sooner"
                 + ("" if P["acceptance"] else f" (quick: a {gr['per_axis']}³ grid, not the acceptance figure)"))
        L.append("")
    Q = R.get("planar_2r")
    if Q:
        L.append(f"3. planar 2R: {Q['targets']} targets on {Q['rings']} rings of radii {Q['radii_m'][0]:g}–"
                 f"{Q['radii_m'][1]:g} m around ({', '.join(f'{v:g}' for v in Q['centre_m'][:2])}): place → "
                 f"{_u(Q['placement'])}, {Q['distance_mm']:.2e} mm from the centre, {Q['coverage_percent']:.1f} % "
                 f"covered, {Q['time_s']:.2f} s" + _flag(Q))
        L.append("")
    if R["targets"]:
        L.append("targets")
        for t in R["targets"]:
            v = t["value"]
            vs = "—" if v is None or (isinstance(v, float) and math.isnan(v)) else f"{v:.4g}"
            L.append(f"   {t['status']:4s}  {t['what']:36s} {vs:>10s}   target {t['target']}"
                     + (f"   ({t['note']})" if t["note"] else ""))
    L.append(f"\n(elapsed {R['elapsed_s']:.1f} s)")
    return "\n".join(L)


def main(argv=None) -> int:
    ap = argparse.ArgumentParser(prog="python -m studies.benchmarks.bench_reach", description=__doc__.splitlines()[0])
    ap.add_argument("--json", action="store_true", help="print one JSON object with all figures instead of the table")
    ap.add_argument("--quick", action="store_true",
                    help="36 reach targets, fewer repeats, a 12³ placement grid (its time ratio is not the "
                         "acceptance figure)")
    args = ap.parse_args(argv)
    return measure_and_print("bench_reach", args.json, lambda log: run(args.quick, log), format_report)


if __name__ == "__main__":
    sys.exit(main())
