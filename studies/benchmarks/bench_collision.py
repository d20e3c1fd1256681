"""Collision benchmark: the clearance kernel's throughput in a cluttered cell, against pinocchio + coal,
and how well the robot's capsules enclose its real collision meshes.

Run as ``python -m studies.benchmarks.bench_collision [--json] [--quick] [--geometry robot|urdf]``
(part of ``make bench``).  For the Franka Panda (7R) and the FANUC LR Mate 200iD, each in the cell
``studies/benchmarks/scenes/clutter.toml`` (a table, a shelf, boxes, cylinders, a capsule, spheres:
12 obstacles), with the robot's own capsules (:attr:`kin.Robot.geometry`, whatever they are; with
``--geometry urdf`` the Panda is imported from example-robot-data's URDF instead and its capsules
are what the import gives) and the cell's allowed pairs (:func:`planning.collision.collision_world`):

1. rmtkit, configurations/s at N = 1e5 uniform random configurations (about half of them in
   collision), median of repeats: ``clearance`` (the minimum over obstacles and self pairs, the
   planner's call) and ``per_body`` (per body, obstacles and self apart), on 1 thread and on all the
   threads the process may use; the same with ``cap = inf`` (every pair's exact distance, no
   pruning: the like-for-like of ``computeDistances``); ``clear_one(q)`` latency (µs);
2. pinocchio + coal, (a) the way a pinocchio user would: the Panda URDF's collision meshes
   (``pin.buildGeomFromUrdf``, links 0–7: the bundled robot has no hand), the obstacles as coal
   primitives, a Python loop of ``pin.computeDistances`` (all pairs, then the nearest pair's
   distance) and of ``pin.computeCollisions`` (stop at the first collision), and pinocchio's own
   batch call ``computeCollisionsInParallel`` (GeometryPool) on 1 and all threads; (a') for scale, the
   set-up of the measurement in the issue that asked for this benchmark (the meshes against one box,
   no self pairs; it reported 7.6 µs per ``computeCollisions`` and 255 µs per ``computeDistances``);
   (b) like for like:
   rmtkit's capsules as ``coal.Capsule`` on the chain rebuilt from its DH table, the same calls.
   The pairs are exactly rmtkit's (:mod:`studies.benchmarks.collision_peers`).  Ratios compare 1
   thread with 1 thread; the peers' collision calls answer less (a yes/no) than a clearance;
3. agreement of rmtkit's clearance with coal's capsule distances (b), per configuration, obstacles and
   self pairs apart (coal's GJK/EPA tolerances tightened to 1e-10; a pair where coal fails to converge
   and reports −DBL_MAX is left out and counted);
4. enclosure (Panda): on uniform configurations and on near-contact ones (rmtkit's obstacle
   clearance in (0, 5 cm]), whenever rmtkit says clear (clearance > 0) coal's exact test between the
   URDF's collision meshes and the obstacles (and between the meshes of the checked self pairs) must
   say clear too — the count of violations must be 0, per body; and the over-estimate, coal's mesh
   distance minus rmtkit's clearance (how much room the capsules give away).  The LR Mate has no
   meshes to check against (``rmt export-urdf`` writes visuals only, and example-robot-data has no
   FANUC): its enclosure is "n/a".

Targets (PASS/MISS): clearance ≥ 1e6 configurations/s on 1 thread per robot; no enclosure violation
(obstacles and self); agreement with coal's capsule distances ≤ 1e-6 m.  A MISS does not change the
exit status (0); an error does.  Figures taken while other processes used more than 10 % of the CPUs
are flagged unreliable (:class:`studies.benchmarks.load.ForeignLoad`).
"""
from __future__ import annotations

import argparse
import math
import os
import platform
import statistics
import sys
import time
import timeit
from importlib.resources import files

import numpy as np

import kin
from kin.compiled import default_threads
from kin.geometry import ClearanceModel, body_names
from planning.collision import collision_world
from studies.benchmarks import collision_peers as cp
from studies.benchmarks.driver import measure_and_print
from studies.benchmarks.load import ForeignLoad

ROBOTS = ("franka_panda", "fanuc_lrmate200id")
CELL = "clutter.toml"
SEED = 20240620
NEAR = 0.05                  # m: "near contact" for the enclosure check
AGREE_TOL = 1e-6             # m
ONE_BOX = "parcel"           # the obstacle of the one-box set-up (the measurement: meshes against one box)

SIZES = {False: dict(N=100_000, repeats=5, loop=5_000, mesh_dist=200, mesh_col=2_000, agree=2_000, enclose=500,
                     single=20_000),
         True: dict(N=20_000, repeats=3, loop=500, mesh_dist=20, mesh_col=200, agree=200, enclose=60, single=5_000)}

TARGETS = {
    # key: (description, comparison, threshold, unit)
    "clearance_1thread": ("clearance, 1 thread (with distances)", ">=", 1e6, "cfg/s"),
    "enclosure_violations": ("rmtkit clear where coal's meshes collide", "<=", 0, ""),
    "agreement_coal": ("|rmtkit − coal| on capsules (both clear)", "<=", AGREE_TOL, "m"),
}


def scene_path(name: str):
    """A bundled benchmark scene (cell file) by file name."""
    return files("studies.benchmarks") / "scenes" / name


# ---- helpers -----------------------------------------------------------------------------
def _try_import(name: str):
    try:
        return __import__(name), None
    except Exception as e:  # ImportError, or a broken binary install
        return None, f"{name} not importable ({type(e).__name__}: {e}); install the 'bench' extra"


def _time_repeat(fn, repeats: int) -> list[float]:
    out = []
    for _ in range(repeats):
        t0 = time.perf_counter()
        fn()
        out.append(time.perf_counter() - t0)
    return out


def _rate(times: list[float], count: int) -> dict:
    best, med = min(times), statistics.median(times)
    return {"best_cfg_per_s": count / best, "median_cfg_per_s": count / med, "median_us_per_cfg": 1e6 * med / count,
            "configs": count, "repeats": len(times)}


def load_robot(name: str, geometry: str = "robot"):
    """The robot whose capsules are benchmarked: the bundled one (its own geometry, whatever it is),
    or with ``geometry="urdf"`` the Panda imported from example-robot-data's URDF (its capsules are
    what :func:`kin.urdf.import_urdf` reads from the URDF's collision elements).  Other robots keep
    their bundled geometry (example-robot-data ships the UR5, UR3 and UR10 of the CB3 series, not
    the UR5e); ``geometry="capsules"``: the bundled robot's capsules without its hulls.  Raises
    RuntimeError when the import gives no collision geometry."""
    if geometry == "capsules":                # the bundled geometry without its hulls (the UR5e has some)
        from dataclasses import replace
        robot = kin.load_robot(name)
        g = robot.chain.geometry
        return robot if g is None or not g.hulls else kin.Robot(replace(robot.chain, geometry=replace(g, hulls=())))
    if geometry == "robot" or name != "franka_panda":
        return kin.load_robot(name)
    from kin.urdf import import_urdf
    share = cp.erd_share()
    if share is None:
        raise RuntimeError("--geometry urdf needs example-robot-data (pip install example-robot-data)")
    robot = kin.Robot(import_urdf(share / cp.PANDA_URDF, tip="panda_link8", convention="modified",
                                  name="franka_panda_urdf"))
    if getattr(robot.chain, "geometry", None) is None:
        raise RuntimeError("the URDF import gives no collision geometry yet (kin.urdf.import_urdf reads no "
                           "<collision> elements): --geometry urdf cannot be measured")
    return robot


def world_for(robot, cell: str = CELL):
    return collision_world(robot, scene_path(cell))


# ---- 1. rmtkit ---------------------------------------------------------------------------
def bench_rmtkit(world, N: int, repeats: int, single: int, threads_all: int) -> dict:
    robot = world.robot
    Q = robot.random_configurations(N, seed=SEED)
    model = world.model
    exact = ClearanceModel(world.chain, world.geometry, world.obstacles, base=world.base, self_pairs=world.pairs,
                           cap=math.inf)
    c = model.clearance(Q)
    out: dict = {"configs": N, "clear_share": float((c > 0).mean()), "cap_m": model.cap, "threads": {}}
    for th in sorted({1, threads_all}):
        rec = {}
        with ForeignLoad() as load:
            for key, m, call in (("clearance", model, "clearance"), ("per_body", model, "per_body"),
                                 ("clearance_exact", exact, "clearance"), ("per_body_exact", exact, "per_body")):
                fn = getattr(m, call)
                fn(Q[:1000], threads=th)
                rec[key] = _rate(_time_repeat(lambda: fn(Q, threads=th), repeats), N)
                rec[key]["threads_ran"] = getattr(m, "last_threads", 1)
        rec["load"] = load.as_dict()
        out["threads"][str(th)] = rec
    q = [float(x) for x in Q[1]]
    with ForeignLoad() as load:
        model.clear_one(q)
        per = [t / single * 1e6 for t in timeit.Timer(lambda: model.clear_one(q)).repeat(repeat=5, number=single)]
    out["clear_one_us"] = {"best_us": min(per), "median_us": statistics.median(per), "load": load.as_dict()}
    out["backend"] = model.backend
    return out


# ---- 2. pinocchio + coal -----------------------------------------------------------------
def _pin_loops(scene, Q: np.ndarray, n_dist: int, n_col: int, threads_all: int) -> dict:
    import pinocchio as pin

    model, data, gm, gd = scene.model, scene.data, scene.gmodel, scene.gdata
    res = gd.distanceResults
    cd, cc = pin.computeDistances, pin.computeCollisions
    Qd = [scene.q(x) for x in Q[:n_dist]]
    Qc = [scene.q(x) for x in Q[:n_col]]

    def distances():
        out = np.empty(len(Qd))
        for k, q in enumerate(Qd):
            out[k] = res[cd(model, data, gm, gd, q)].min_distance      # all pairs, then the nearest one
        return out

    def collisions():
        out = np.empty(len(Qc), bool)
        for k, q in enumerate(Qc):
            out[k] = cc(model, data, gm, gd, q, True)
        return out

    rec: dict = {"geometries": scene.robot_geoms, "pairs": len(gm.collisionPairs),
                 "obstacle_pairs": int(scene.obstacle_pairs.sum()), "self_pairs": int((~scene.obstacle_pairs).sum()),
                 "notes": scene.notes}
    with ForeignLoad() as load:
        distances()
        rec["computeDistances_loop"] = _rate(_time_repeat(distances, 3), len(Qd))
        collisions()
        rec["computeCollisions_loop"] = _rate(_time_repeat(collisions, 3), len(Qc))
        Qb = scene.pad(Q[:n_col]).T.copy()        # (nq, N), pinocchio's batch layout
        rec["computeCollisionsInParallel"] = {}
        for th in sorted({1, threads_all}):
            pool = pin.GeometryPool(model, gm, th)
            call = lambda: pin.computeCollisionsInParallel(th, pool, Qb, True, False)
            call()
            rec["computeCollisionsInParallel"][str(th)] = _rate(_time_repeat(call, 3), len(Qc))
    rec["load"] = load.as_dict()
    return rec


def bench_pinocchio(world, sizes: dict, threads_all: int, mesh_scene) -> dict:
    pin, why = _try_import("pinocchio")
    if pin is None:
        return {"skipped": why}
    Q = world.robot.random_configurations(max(sizes["loop"], sizes["mesh_col"]), seed=SEED + 1)
    out = {"version": pin.__version__, "coal": _version("coal")}
    out["capsules"] = _pin_loops(cp.capsule_scene(world), Q, sizes["loop"], sizes["loop"], threads_all)
    if mesh_scene is not None:
        out["meshes"] = _pin_loops(mesh_scene, Q, sizes["mesh_dist"], sizes["mesh_col"], threads_all)
        share = cp.erd_share()
        box = cp.urdf_mesh_scene(cp.one_obstacle(world, ONE_BOX), share / cp.PANDA_URDF, share, cp.PANDA_LINKS)
        out["meshes_one_box"] = _pin_loops(box, Q, sizes["mesh_col"], sizes["mesh_col"], threads_all)
    return out


def _version(dist: str) -> str:
    from importlib import metadata
    try:
        return metadata.version(dist)
    except metadata.PackageNotFoundError:
        return "?"


# ---- 3. agreement on capsules ------------------------------------------------------------
def agreement(world, count: int) -> dict:
    """rmtkit's exact clearance (cap inf) against coal's distances between the same capsules and
    obstacles (GJK/EPA tolerances tightened to 1e-10, :func:`collision_peers.tighten`), per
    configuration: the obstacle minimum and the self minimum apart."""
    if _try_import("pinocchio")[0] is None:
        return {"skipped": "pinocchio not importable"}
    scene = cp.tighten(cp.capsule_scene(world))
    Q = world.robot.random_configurations(count, seed=SEED + 2)
    exact = ClearanceModel(world.chain, world.geometry, world.obstacles, base=world.base, self_pairs=world.pairs,
                           cap=math.inf)
    ob, se = exact.per_body(Q)
    D = np.array([scene.distances(x) for x in Q])
    frames = max(float(np.abs(cp.body_frames_pin(scene, world.chain, x)
                              - kin.geometry.body_frames(world.chain, x[None])[0, 1:world.chain.n + 1]).max())
                 for x in Q[:20])
    out = {"configs": count, "frames_max_diff": frames}
    for key, ours, mask in (("obstacles", ob.min(axis=1), scene.obstacle_pairs),
                            ("self", se.min(axis=1), ~scene.obstacle_pairs)):
        if not mask.any():
            out[key] = None
            continue
        coal_failed = np.isnan(D[:, mask]).any(axis=1)      # left out: coal gave no distance
        ours, theirs = ours[~coal_failed], D[~coal_failed][:, mask].min(axis=1)
        both = (ours > 0) & (theirs > 0)
        out[key] = {"both_clear": int(both.sum()), "coal_failed": int(coal_failed.sum()),
                    "max_abs_diff_m": float(np.abs(ours - theirs)[both].max()) if both.any() else math.nan,
                    "max_ours_minus_coal_m": float((ours - theirs)[both].max()) if both.any() else math.nan,
                    "sign_mismatches": int(((ours > 0) != (theirs > 0)).sum())}
    return out


# ---- 4. enclosure against the URDF's meshes ---------------------------------------------
def enclosure(world, mesh_scene, count: int) -> dict:
    """Uniform and near-contact configurations: rmtkit's clearance (the world's model, capped) against
    coal's exact tests and distances between the URDF's collision meshes and the obstacles (and the
    meshes of the checked self pairs), per body."""
    robot = world.robot
    B = world.chain.n + 2
    uniform = robot.random_configurations(count, seed=SEED + 3)
    pool = robot.random_configurations(max(50 * count, 20_000), seed=SEED + 4)
    ob_pool, _ = world.per_body(pool)
    c = ob_pool.min(axis=1)
    near = pool[(c > 0) & (c <= NEAR)][:count]
    names = body_names(world.chain)
    out = {"near_contact_m": NEAR, "over_estimate_robot_geometry_m": float(world.geometry.over_estimate),
           "geometry_source": world.geometry.source, "sets": {}}
    cap = world.model.cap
    pb = mesh_scene.pair_body
    for label, Q in (("uniform", uniform), ("near_contact", near)):
        ob, se = world.per_body(Q)
        D = np.array([mesh_scene.distances(x) for x in Q])
        C = np.array([mesh_scene.collisions(x) for x in Q])
        rec = {"configs": len(Q)}
        obst = mesh_scene.obstacle_pairs
        for key, ours_b, mask in (("obstacles", ob, obst), ("self", se, ~obst)):
            per_body, viol_any = {}, np.zeros(len(Q), bool)
            for b in range(B):
                m = mask & (pb == b)
                if key == "self":        # a self pair counts for both of its bodies
                    m = mask & ((pb == b) | (mesh_scene.pair_other == -1 - b))
                if not m.any():
                    continue
                coal_col = C[:, m].any(axis=1)
                coal_d = np.fmin.reduce(D[:, m], axis=1)       # coal's failures (NaN) left out
                v = (ours_b[:, b] > 0) & coal_col
                viol_any |= v
                clear = (ours_b[:, b] > 0) & ~coal_col & np.isfinite(coal_d)
                short = (ours_b[:, b] - np.minimum(coal_d, cap))[clear]
                per_body[names[b]] = {"violations": int(v.sum()),
                                      "max_ours_minus_coal_m": float(short.max()) if len(short) else math.nan}
            ours = ours_b.min(axis=1)
            coal_d = np.minimum(np.fmin.reduce(D[:, mask], axis=1), cap)
            coal_col = C[:, mask].any(axis=1)
            clear = ours > 0
            over = (coal_d - ours)[clear & ~coal_col & np.isfinite(coal_d)]
            rec[key] = {"ours_clear": int(clear.sum()), "coal_collides": int(coal_col.sum()),
                        "violations": int(viol_any.sum()),
                        "violations_min_clearance": int((clear & coal_col).sum()),
                        "ours_above_coal": int((ours > coal_d + AGREE_TOL)[~coal_col].sum()),
                        "over_estimate_max_m": float(over.max()) if len(over) else math.nan,
                        "over_estimate_median_m": float(np.median(over)) if len(over) else math.nan,
                        "per_body": per_body}
        out["sets"][label] = rec
    out["violations"] = sum(s[k]["violations"] for s in out["sets"].values() for k in ("obstacles", "self"))
    return out


# ---- the whole run -----------------------------------------------------------------------
def bench_robot(name: str, quick: bool, geometry: str = "robot", log=None) -> dict:
    say = log or (lambda msg: None)
    sizes = SIZES[quick]
    threads_all = default_threads()
    robot = load_robot(name, geometry)
    world = world_for(robot)
    say(f"{name}: {world!r}, geometry '{world.geometry.source}'")
    mesh_scene, mesh_note, share = None, None, None
    if name == "franka_panda":
        share = cp.erd_share()
        if share is None:
            mesh_note = "example-robot-data not installed: no meshes to compare with"
        elif _try_import("pinocchio")[0] is None:
            mesh_note = "pinocchio not importable"
        else:
            mesh_scene = cp.urdf_mesh_scene(world, share / cp.PANDA_URDF, share, cp.PANDA_LINKS)
    else:
        mesh_note = ("no collision meshes: rmt export-urdf writes visuals only and example-robot-data has no "
                     "FANUC; pinocchio gets rmtkit's capsules (b) only")
    say("  rmtkit kernel ...")
    rm = bench_rmtkit(world, sizes["N"], sizes["repeats"], sizes["single"], threads_all)
    say("  pinocchio + coal ...")
    pe = bench_pinocchio(world, sizes, threads_all, mesh_scene)
    say("  agreement on capsules ...")
    ag = agreement(world, sizes["agree"])
    enc = None
    if mesh_scene is not None:
        say("  enclosure against the URDF's meshes ...")
        enc = enclosure(world, cp.tighten(cp.urdf_mesh_scene(world, share / cp.PANDA_URDF, share, cp.PANDA_LINKS)),
                        sizes["enclose"])
    return {"robot": name, "chain": robot.chain.name, "world": repr(world), "geometry_source": world.geometry.source,
            "capsules": len(world.geometry.capsules), "obstacles": len(world.obstacles),
            "self_pairs": len(world.pairs), "auto_allowed": [list(p) for p in world.auto_allowed],
            "rmtkit": rm, "pinocchio": pe, "agreement": ag, "enclosure": enc, "mesh_note": mesh_note,
            "ratios": ratios(rm, pe)}


def ratios(rm: dict, pe: dict) -> dict:
    """rmtkit / peer throughput, 1 thread against 1 thread (and all threads against the peer's batch
    call on as many threads)."""
    out = {}
    one = rm["threads"]["1"]
    for kind in ("capsules", "meshes"):
        p = pe.get(kind)
        if not p:
            continue
        dist = p["computeDistances_loop"]["median_cfg_per_s"]
        col = p["computeCollisions_loop"]["median_cfg_per_s"]
        out[f"clearance_vs_{kind}_computeDistances"] = one["clearance"]["median_cfg_per_s"] / dist
        out[f"clearance_exact_vs_{kind}_computeDistances"] = one["clearance_exact"]["median_cfg_per_s"] / dist
        out[f"per_body_vs_{kind}_computeDistances"] = one["per_body"]["median_cfg_per_s"] / dist
        out[f"clearance_vs_{kind}_computeCollisions"] = one["clearance"]["median_cfg_per_s"] / col
        for th, rec in p["computeCollisionsInParallel"].items():
            if th in rm["threads"]:
                out[f"clearance_{th}threads_vs_{kind}_computeCollisionsInParallel_{th}threads"] = (
                    rm["threads"][th]["clearance"]["median_cfg_per_s"] / rec["median_cfg_per_s"])
    return out


def _check(robot: str, key: str, value) -> dict:
    desc, op, thr, unit = TARGETS[key]
    if value is None or (isinstance(value, float) and math.isnan(value)):
        status = "n/a"
    else:
        status = "PASS" if (value >= thr if op == ">=" else value <= thr) else "MISS"
    return {"robot": robot, "key": key, "what": desc, "value": value, "target": f"{op} {thr:g} {unit}".strip(),
            "status": status}


def _targets(results: list[dict]) -> list[dict]:
    out = []
    for R in results:
        ag = R["agreement"]
        diffs = [ag[k]["max_abs_diff_m"] for k in ("obstacles", "self") if isinstance(ag.get(k), dict)]
        out += [_check(R["robot"], "clearance_1thread", R["rmtkit"]["threads"]["1"]["clearance"]["median_cfg_per_s"]),
                _check(R["robot"], "enclosure_violations", None if R["enclosure"] is None
                       else R["enclosure"]["violations"]),
                _check(R["robot"], "agreement_coal", max(diffs) if diffs else None)]
    return out


def run(quick: bool = False, log=None, geometry: str = "robot", robots=None) -> dict:
    t0 = time.perf_counter()
    robots = ROBOTS if robots is None else robots
    with ForeignLoad() as load:
        results = [bench_robot(name, quick, geometry, log) for name in robots]
    unreliable = []
    for R in results:
        for th, rec in R["rmtkit"]["threads"].items():
            if not rec["load"]["reliable"]:
                unreliable.append(f"{R['robot']} rmtkit {th} thread(s)")
        for kind in ("capsules", "meshes", "meshes_one_box"):
            p = R["pinocchio"].get(kind)
            if p and not p["load"]["reliable"]:
                unreliable.append(f"{R['robot']} pinocchio {kind}")
    return {"benchmark": "bench_collision", "quick": quick, "cell": CELL, "geometry": geometry, "seed": SEED,
            "environment": {"python": platform.python_version(), "numpy": np.__version__,
                            "pinocchio": _version("pin"), "coal": _version("coal"),
                            "example_robot_data": _version("example-robot-data"),
                            "machine": platform.machine(), "cpu_count": os.cpu_count(),
                            "threads_all": default_threads(), "load": load.as_dict(),
                            "unreliable_sections": unreliable},
            "robots": results, "targets": _targets(results), "elapsed_s": time.perf_counter() - t0}


# ---- report ------------------------------------------------------------------------------
def _m(x: float) -> str:
    return f"{x / 1e6:7.3f} M/s"


def _k(x: float) -> str:
    return f"{x / 1e3:9.2f} k/s"


def _mm(x) -> str:
    return "—" if x is None or (isinstance(x, float) and math.isnan(x)) else f"{x * 1e3:.3g} mm"


def format_report(R: dict) -> str:
    env = R["environment"]
    L = [f"bench_collision — cell {R['cell']}, geometry '{R['geometry']}'{' [quick]' if R['quick'] else ''}",
         f"pinocchio {env['pinocchio']}, coal {env['coal']}, example-robot-data {env['example_robot_data']}; "
         f"{env['cpu_count']} CPUs, {env['threads_all']} usable; load average before / after "
         f"{env['load']['loadavg_1min_before']:.2f} / {env['load']['loadavg_1min_after']:.2f}"]
    if env["unreliable_sections"]:
        L.append("UNRELIABLE figures (other processes took > 10 % of the CPUs meanwhile): "
                 + ", ".join(env["unreliable_sections"]))
    L.append("")
    for r in R["robots"]:
        rm = r["rmtkit"]
        L.append(f"{r['robot']}: {r['capsules']} capsules (geometry '{r['geometry_source']}'), {r['obstacles']} "
                 f"obstacles, {r['self_pairs']} self pairs (always touching, not checked: {r['auto_allowed']})")
        L.append(f"   rmtkit ({rm['backend']}), N = {rm['configs']:,d} random configurations, "
                 f"{100 * rm['clear_share']:.0f} % clear; configurations/s (median)")
        for th, rec in rm["threads"].items():
            L.append(f"     {th} thread(s): clearance {_m(rec['clearance']['median_cfg_per_s'])}   per_body "
                     f"{_m(rec['per_body']['median_cfg_per_s'])}   exact (cap inf): clearance "
                     f"{_m(rec['clearance_exact']['median_cfg_per_s'])}, per_body "
                     f"{_m(rec['per_body_exact']['median_cfg_per_s'])}"
                     f"{'' if rec['load']['reliable'] else '  UNRELIABLE'}")
        L.append(f"     clear_one(q): {rm['clear_one_us']['median_us']:.2f} µs (median)")
        pe = r["pinocchio"]
        if "skipped" in pe:
            L.append(f"   pinocchio: {pe['skipped']}")
        for kind, label in (("meshes", "(a) the URDF's collision meshes"),
                            ("meshes_one_box", f"(a') the meshes against one box ('{ONE_BOX}') only, no self pairs"),
                            ("capsules", "(b) rmtkit's capsules")):
            p = pe.get(kind)
            if not p:
                continue
            L.append(f"   pinocchio + coal {label}: {p['pairs']} pairs ({p['obstacle_pairs']} obstacle, "
                     f"{p['self_pairs']} self); {'; '.join(p['notes'])}")
            d, c = p["computeDistances_loop"], p["computeCollisions_loop"]
            L.append(f"     computeDistances loop {_k(d['median_cfg_per_s'])} ({d['median_us_per_cfg']:.1f} µs/config)"
                     f"   computeCollisions loop (stop at first) {_k(c['median_cfg_per_s'])} "
                     f"({c['median_us_per_cfg']:.1f} µs/config)")
            L.append("     computeCollisionsInParallel (batch): " + "   ".join(
                f"{th} thread(s) {_k(x['median_cfg_per_s'])}" for th, x in p["computeCollisionsInParallel"].items())
                + ("" if p["load"]["reliable"] else "  UNRELIABLE"))
        if r["ratios"]:
            L.append("   ratios rmtkit / pinocchio (throughput; 1 thread vs 1 thread unless named):")
            for k, v in r["ratios"].items():
                L.append(f"     {k:70s} {v:9.1f}x")
        ag = r["agreement"]
        if "skipped" not in ag:
            L.append(f"   agreement with coal on the capsules ({ag['configs']} configurations; rebuilt frames agree to "
                     f"{ag['frames_max_diff']:.1e} m):")
            for k in ("obstacles", "self"):
                a = ag.get(k)
                if a:
                    L.append(f"     {k:9s}: both clear {a['both_clear']} (coal failed on {a['coal_failed']}), "
                             f"max |rmtkit − coal| "
                             f"{a['max_abs_diff_m']:.2e} m, max (rmtkit − coal) {a['max_ours_minus_coal_m']:.2e} m, "
                             f"sign mismatches {a['sign_mismatches']}")
        enc = r["enclosure"]
        if enc is None:
            L.append(f"   enclosure: n/a — {r['mesh_note']}")
        else:
            L.append(f"   enclosure: rmtkit's capsules ('{enc['geometry_source']}') against the URDF's collision "
                     f"meshes, {enc['violations']} violation(s) in all")
            for label, s in enc["sets"].items():
                for k in ("obstacles", "self"):
                    e = s[k]
                    bad = {b: v["violations"] for b, v in e["per_body"].items() if v["violations"]}
                    L.append(f"     {label:12s} {k:9s} ({s['configs']} configs): rmtkit clear {e['ours_clear']}, coal "
                             f"collides {e['coal_collides']}; VIOLATIONS {e['violations']}"
                             f"{' ' + str(bad) if bad else ''}; over-estimate (coal − rmtkit where both clear) "
                             f"max {_mm(e['over_estimate_max_m'])}, median {_mm(e['over_estimate_median_m'])}; "
                             f"rmtkit above coal in {e['ours_above_coal']}")
            worst = {}
            for s in enc["sets"].values():
                for k in ("obstacles", "self"):
                    for b, v in s[k]["per_body"].items():
                        if v["max_ours_minus_coal_m"] == v["max_ours_minus_coal_m"]:
                            worst[b] = max(worst.get(b, -math.inf), v["max_ours_minus_coal_m"])
            short = {b: _mm(v) for b, v in worst.items() if v > AGREE_TOL}
            if short:
                L.append("     capsules short of the meshes, where coal says clear (rmtkit − coal, largest per body): "
                         f"{short}")
        L.append("")
    L.append("targets")
    for t in R["targets"]:
        v = t["value"]
        vs = "—" if v is None or (isinstance(v, float) and math.isnan(v)) else f"{v:.4g}"
        L.append(f"   {t['status']:4s}  {t['robot']:18s} {t['what']:44s} {vs:>10s}   target {t['target']}")
    L.append(f"\n(elapsed {R['elapsed_s']:.1f} s)")
    return "\n".join(L)


def main(argv=None) -> int:
    ap = argparse.ArgumentParser(prog="python -m studies.benchmarks.bench_collision",
                                 description=__doc__.splitlines()[0])
    ap.add_argument("--json", action="store_true", help="print one JSON object with all figures instead of the table")
    ap.add_argument("--quick", action="store_true", help="fewer configurations and repeats (smoke test)")
    ap.add_argument("--geometry", choices=("robot", "urdf"), default="robot",
                    help="the Panda's capsules: the bundled robot's (default) or those the import of "
                         "example-robot-data's panda.urdf gives")
    args = ap.parse_args(argv)
    return measure_and_print("bench_collision", args.json,
                             lambda log: run(args.quick, log, args.geometry), format_report)


if __name__ == "__main__":
    sys.exit(main())
