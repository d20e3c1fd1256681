"""A FANUC LR Mate 200iD welding a flanged pipe in its cell (`studies/cells/fanuc_weld_cell.toml`):
the robot on a welding table, the pipe on a fixture, a wire-feeder column beside it, a fence behind
it, the floor below it.  The cell's obstacles, the robot's collision capsules and its torch are what
every check below uses: how much of the joint space the robot spends inside itself; which points of
the pipe's fillet seam the torch reaches, and how many of them collisions take away; and a move from
a park pose behind the column to a weld pose at the seam, whose windows-only plan is proven clear
of the singular windows and drives the forearm through the column, while the plan that knows the
cell is proven clear of the cell, of the robot itself and of the windows.

Run it with ``rmt study fanuc_weld_cell`` (``--quick`` for the reduced version) or ``python
studies/bundled/fanuc_weld_cell.py --out DIR``.  Lengths are shown in mm, angles in degrees; the
results are SI (m, rad).  Copy this file to change the seam, the torch angle, the park pose or the
required clearance — or point ``CELL`` at your own cell file.
"""
from __future__ import annotations

import math
import sys
from collections import Counter
from pathlib import Path

import numpy as np
from matplotlib.figure import Figure
from matplotlib.lines import Line2D

import studies
from design.coverage import coverage
from design.task import load_task
from design.task.model import Targets
from kin.errors import RmtError
from kin.geometry import body_frames
from planning.cell import load_cell
from planning.collision import collision_world
from planning.ompl.planner import plan
from planning.validate import check_path, densify
from planning.windows import build_windows
from studies.jointpath import path_csv_text
from studies.plots.clearance import plot_clearance, plot_collision_map
from studies.report.cell_view import cell_view, closest_segments, contact_world
from studies.study import Study, main

NAME = "fanuc_weld_cell"
TITLE = "FANUC LR Mate 200iD in a weld cell: self-collision, seam coverage and a move proven clear"

CELL = Path(studies.__file__).parent / "cells" / "fanuc_weld_cell.toml"
#: the bundled design task of the same name, written for the FANUC M-16iB/20 (checked against this cell below)
TASK = Path(studies.__file__).parent / "tasks" / "fanuc_weld_cell.toml"
ROBOT = "fanuc_lrmate200id"

#: the fillet seam where the pipe (outer radius 50 mm) meets the flange's face, in the cell frame (mm):
#: the pipe's axis runs along y through x = 550, z = 950 (docs/cells.md), the flange's face is at y = 113
SEAM_CENTRE = (550.0, 113.0, 950.0)
SEAM_RADIUS = 50.0
#: the torch tip comes from the pipe's side (−y), half-way between the pipe's surface and the flange's face
WORK_ANGLE = 45.0
#: seam points around the pipe and rolls of the torch about its own axis tried at each (quick, full)
SEAM_POINTS, TORCH_ROLLS = (36, 72), (8, 12)
#: the margin of the singular windows (rad) around the LR Mate's three singular factors
WINDOW_MARGIN = 0.05
#: the clearance (m) the plans and the weld poses keep from the cell and between the robot's own bodies
CLEARANCE = 0.010
#: park poses behind the wire-feeder column (torch cleaning), J1, J2, J3 in degrees, tried in this order
#: (J4 = J6 = 0; J5 = ±90° with the weld pose's sign, so that no path has to cross the wrist window)
PARK_CANDIDATES = [(j1, j2, j3) for j2, j3 in ((20, 0), (40, 20), (50, 30), (60, 30), (40, 0), (60, 40))
                   for j1 in (-150, -140, -130, -160)]
#: the forearm: body 4 carries the 335 mm d4 offset from the elbow to the wrist
FOREARM = 4


# ---- the weld targets ----------------------------------------------------------------------------
def torch_tip(cell) -> np.ndarray:
    """The torch's tip and axis in the tool frame: the far end of the cell's last tool capsule and the
    direction it points (4×4: origin the tip, z the axis)."""
    neck = cell.tool[-1]
    a, b = np.array(neck.a), np.array(neck.b)
    z = (b - a) / np.linalg.norm(b - a)
    x = np.array([1.0, 0.0, 0.0]) - z[0] * z
    x /= np.linalg.norm(x)
    T = np.eye(4)
    T[:3, 0], T[:3, 1], T[:3, 2], T[:3, 3] = x, np.cross(z, x), z, b
    return T


def seam_points(n: int) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """The seam's n points in the cell frame (m), the torch axis at each (unit, pointing into the weld)
    and the angle φ of each around the pipe (rad; 0: away from the robot, π/2: the top)."""
    phi = 2 * np.pi * np.arange(n) / n
    c = np.array(SEAM_CENTRE) / 1000
    radial = np.column_stack([np.cos(phi), np.zeros(n), np.sin(phi)])
    along = np.array([0.0, 1.0, 0.0])                # from the pipe's side into the flange's face
    w = math.radians(WORK_ANGLE)
    axis = -math.sin(w) * radial + math.cos(w) * along
    return c + SEAM_RADIUS / 1000 * radial, axis / np.linalg.norm(axis, axis=1, keepdims=True), phi


def flange_poses(cell, points: np.ndarray, axes: np.ndarray, rolls: int) -> np.ndarray:
    """Tool-frame poses (in the robot's base frame) that put the torch tip on each point with the
    torch along its axis, at ``rolls`` rolls about that axis: (N · rolls, 4, 4), point-major."""
    tip_inv = np.linalg.inv(torch_tip(cell))
    base_inv = np.linalg.inv(cell.base)
    out = []
    for p, d in zip(points, axes):
        e = np.cross(d, [0.0, 0.0, 1.0]) if abs(d[2]) < 0.9 else np.cross(d, [1.0, 0.0, 0.0])
        e /= np.linalg.norm(e)
        f = np.cross(d, e)
        for k in range(rolls):
            t = 2 * np.pi * k / rolls
            x = math.cos(t) * e + math.sin(t) * f
            T = np.eye(4)
            T[:3, 0], T[:3, 1], T[:3, 2], T[:3, 3] = x, np.cross(d, x), d, p
            out.append(base_inv @ T @ tip_inv)
    return np.array(out)


# ---- an independent check of the clearance kernel: signed distances in plain numpy ---------------
def signed_distance(shape, P: np.ndarray) -> np.ndarray:
    """Signed distance (m) of points P (K, 3) to a box, cylinder, sphere or capsule (kin.geometry.Shape)."""
    T = np.asarray(shape.pose)
    L = (P - T[:3, 3]) @ T[:3, :3]
    r, h, z = shape.size
    if shape.kind == "box":
        q = np.abs(L) - [r, h, z]
        return np.linalg.norm(np.maximum(q, 0), axis=1) + np.minimum(q.max(axis=1), 0)
    if shape.kind == "cylinder":
        q = np.column_stack([np.hypot(L[:, 0], L[:, 1]) - r, np.abs(L[:, 2]) - h])
        return np.linalg.norm(np.maximum(q, 0), axis=1) + np.minimum(q.max(axis=1), 0)
    if shape.kind == "capsule":
        return np.linalg.norm(L - np.outer(np.clip(L[:, 2], -h, h), [0, 0, 1]), axis=1) - r
    return np.linalg.norm(L, axis=1) - r


def numpy_clearance(world, q, body: int, obstacle: int, samples: int = 4001) -> float:
    """The clearance of ``body``'s capsules to obstacle ``obstacle`` at ``q``: each capsule's segment at
    ``samples`` points, its signed distance to every shape and sphere of the obstacle, minus its radius."""
    F = body_frames(world.chain, np.asarray(q, float)[None], world.base)[0, body]
    ob = world.obstacles[obstacle]
    best = math.inf
    for c in world.geometry.capsules:
        if c.body != body:
            continue
        t = np.linspace(0.0, 1.0, samples)[:, None]
        P = (np.array(c.a) + t * (np.subtract(c.b, c.a))) @ F[:3, :3].T + F[:3, 3]
        d = [signed_distance(s, P) for s in ob.shapes]
        if ob.spheres is not None:
            S = ob.spheres
            d += [(np.linalg.norm(P[k:k + 64, None, :] - S[None, :, :3], axis=2) - S[None, :, 3]).min(axis=1)
                  for k in range(0, len(P), 64)]
        best = min(best, min(float(np.min(x)) for x in d) - c.radius)
    return best


def deepest(world, path: np.ndarray, among: str = "cell") -> dict:
    """The state of ``path`` (M, n) with the smallest clearance ``among`` the cell or the robot's own
    pairs, over its states 0.1° apart, with its closest approach."""
    Q, seg, _ = densify(np.asarray(path, float), world.chain.revolute_mask)
    c = np.asarray(contact_world(world, among).clearance(Q), float)
    k = int(np.argmin(c))
    return {"q": Q[k], "segment": int(seg[k]), "fraction": k / max(1, len(Q) - 1),
            "states": len(Q), **closest_segments(world, Q[k:k + 1], among)[0]}


def into(text: str) -> str:
    """"link 4 (J4) against obstacle 'x': 12 mm deep" → "link 4 (J4) into obstacle 'x'"."""
    return text.split(":")[0].replace(" against ", " into ")


def deg(q) -> str:
    return "(" + ", ".join(f"{x:.4g}" for x in np.degrees(np.asarray(q, float))) + ")°"


def mm(x: float) -> str:
    return f"{1000 * x:.4g} mm".replace("-", "−")


def run(s: Study) -> None:
    robot = s.robot(ROBOT)
    n = robot.n
    seed = s.input("seed", 0)
    s.input("cell", f"studies/cells/{CELL.name}")
    n_random = s.input("self-collision: random configurations", 20_000 if s.quick else 200_000)
    grid = (61, 106) if s.quick else (121, 211)
    s.input("self-collision: J2–J3 grid", list(grid))
    n_seam = s.input("seam: points", SEAM_POINTS[0] if s.quick else SEAM_POINTS[1])
    n_roll = s.input("seam: torch rolls per point", TORCH_ROLLS[0] if s.quick else TORCH_ROLLS[1])
    s.input("seam: work angle (deg)", WORK_ANGLE)
    ik_seeds = s.input("coverage: IK seeds per target", 4 if s.quick else 8)
    ik_samples = s.input("coverage: sampled configurations", 20_000)
    margin = s.input("windows: margin (rad)", WINDOW_MARGIN)
    plan_time = s.input("plan: time limit (s)", 1.0 if s.quick else 2.0)
    clearance = s.input("required clearance (m)", CLEARANCE)

    # ------------------------------------------------------------------------------------------
    with s.section("The cell"):
        cell = load_cell(CELL)
        world = collision_world(robot, cell, margin=clearance)     # clear: by the required clearance
        touching = collision_world(robot, cell)                    # in collision: touching
        names = world.body_names
        tip = torch_tip(cell)
        s.text(f"The cell file `studies/cells/{CELL.name}` places the robot's base on the welding table, 800 mm "
               "above the floor, and lists its obstacles. Every check in this study uses the same world "
               "(`planning.collision.collision_world`): the robot's collision capsules (its robot file's, or "
               "capsules along its DH offsets when the file has none), the torch's two capsules from the cell file, "
               "the obstacles, and the pairs that are never checked. The torch tip — the far end of the torch neck, "
               f"at ({', '.join(f'{1000 * x:.4g}' for x in tip[:3, 3])}) mm in the tool frame, "
               f"{math.degrees(math.acos(tip[2, 2])):.0f}° off the faceplate's axis — is what welds. A weld pose or a "
               f"plan counts as clear when it keeps {1000 * clearance:g} mm from the cell and between the robot's own "
               "bodies; a collision is anything less than touching.")
        s.code(CELL.read_text(encoding="utf-8"), f"The cell file `studies/cells/{CELL.name}`.", collapsed=True)
        rows = []
        for ob in world.obstacles:
            lo = np.full(3, np.inf)
            hi = -lo
            for sh in ob.shapes:
                lo = np.minimum(lo, sh.pose[:3, 3] - sh.bounding_radius)
                hi = np.maximum(hi, sh.pose[:3, 3] + sh.bounding_radius)
            if ob.spheres is not None:
                lo = np.minimum(lo, (ob.spheres[:, :3] - ob.spheres[:, 3:]).min(axis=0))
                hi = np.maximum(hi, (ob.spheres[:, :3] + ob.spheres[:, 3:]).max(axis=0))
            rows.append([ob.name, ob.kind, ob.n_primitives, 1000 * ob.over_estimate,
                         ", ".join(names[b] for b in sorted(ob.ignore)) or "—", cell.notes.get(ob.name, "")])
        s.table(["obstacle", "type", "primitives", "spheres stand out by ≤ (mm)", "may touch it", "note"], rows,
                "The cell's obstacles as the checks see them: a mesh becomes spheres that provably hold it "
                "(docs/cells.md); the 3-D views draw its original triangles.", fmt=".3g")
        caps = world.geometry.capsules
        s.table(["body", "capsules", "radius (mm)", "segment length (mm)", "source"],
                [[names[b], sum(c.body == b for c in caps),
                  ", ".join(sorted({f"{1000 * c.radius:.3g}" for c in caps if c.body == b})),
                  ", ".join(f"{1000 * c.length:.4g}" for c in caps if c.body == b), world.geometry.source]
                 for b in world.geometry.bodies()],
                "The robot's collision capsules, body by body (body k moves with joint k; the tool is the torch).")
        auto = ", ".join(f"{names[i]} – {names[j]}" for i, j in world.auto_allowed) or "none"
        s.text(f"Self-collision is checked for {len(world.pairs)} pairs of bodies. Besides neighbours and the "
               "pairs the cell allows (link 5 – tool), the pairs found touching in every sampled configuration are "
               f"not checked either (they would always be in collision): {auto}.")
        # the bundled design task of the same name: written for the M-16iB/20, in its base frame
        task = load_task(TASK, robot=robot)
        far = coverage(robot, task.targets, None, seeds=2, samples=5_000, seed=seed)
        reach = float(np.linalg.norm(task.targets.positions, axis=1).min())
        s.text(f"The bundled design task `studies/tasks/{TASK.name}` does not fit this cell: it sizes the FANUC "
               f"M-16iB/20's arm for {len(task.targets)} targets 0.9–1.5 m in front of its base (the nearest "
               f"{reach:.3g} m from the base's origin); the LR Mate reaches {int(far.reached.sum())} of them. This "
               "study takes its targets from the part instead: the fillet seam of the pipe.")
        s.results["cell"] = {"file": CELL.name, "name": cell.name, "obstacles": len(world.obstacles),
                             "primitives": cell.n_primitives, "over_estimate": cell.over_estimate,
                             "base": cell.base[:3, 3].tolist(), "geometry_source": world.geometry.source,
                             "capsules": len(caps), "self_pairs": len(world.pairs),
                             "auto_allowed": [list(p) for p in world.auto_allowed],
                             "torch_tip": tip[:3, 3].tolist(), "torch_axis": tip[:3, 2].tolist(),
                             "design_task": {"file": TASK.name, "targets": len(task.targets),
                                             "reached_by_lrmate": int(far.reached.sum())}}

    # ------------------------------------------------------------------------------------------
    with s.section("Self-collision"):
        lo, hi = robot.chain.lower, robot.chain.upper
        Qr = robot.random_configurations(n_random, seed=seed)
        obs, slf = world.per_body(Qr)
        own = np.asarray(slf).min(axis=1) <= 0
        hit = np.asarray(obs).min(axis=1) <= 0
        sw = contact_world(world, "self")
        ct = sw.nearest(Qr[own]) if own.any() else None
        pairs = Counter((int(b), int(-1 - o)) for b, o in zip(ct.body, ct.other)) if ct is not None else Counter()
        top = [[names[min(a, b)] + " – " + names[max(a, b)], k, 100 * k / max(1, own.sum())]
               for (a, b), k in pairs.most_common(5)]
        # the upper arm upright (J2 = 0), the wrist at 90°: how far can J3 fold before the robot hits itself?
        q_up = np.zeros(n)
        q_up[4] = math.radians(90)
        fold = {}
        for side, end in (("down", lo[2]), ("up", hi[2])):
            t = np.linspace(0.0, end, 1 + int(abs(end) / math.radians(0.1)))
            Qf = np.tile(q_up, (len(t), 1))
            Qf[:, 2] = t
            bad = np.asarray(sw.clearance(Qf)) <= 0
            if bad.any():
                k = int(np.argmax(bad))
                c0 = closest_segments(world, Qf[k:k + 1], "self")[0]
                fold[side] = {"q3": float(t[k]), "limit": float(end), "q": Qf[k].tolist(),
                              "pair": [c0["body"], -1 - c0["other"]], "text": c0["text"]}
        # an example: the upper arm upright, J3 half-way from where the robot starts to hit itself to its limit
        q_self = q_up.copy()
        q_self[2] = 0.5 * (fold["down"]["q3"] + lo[2]) if "down" in fold else lo[2]
        ex = closest_segments(world, q_self[None], "self")[0]
        fig, shares = plot_collision_map(touching, q_up, (1, 2), grid,
                                         marks=[("example", (q_self[1], q_self[2]))])
        s.figure(fig, "j2_j3_map", "Which (J2, J3) configurations are clear, in collision with the cell, with the "
                                   "robot itself, or both (J1 = 0: the arm faces the part; J5 = 90°; the other "
                                   "joints 0). The robot file's joint limits let the forearm fold into the robot's "
                                   "base column at both ends of J3's 420° range.")
        s.table(["pair in self-collision (nearest)", "random configurations", "share of those in self-collision (%)"],
                top, f"The nearest pair at each of the {int(own.sum()):,} self-colliding random configurations "
                     f"(of {n_random:,}, seed {seed}).", fmt=".3g")
        folds = "; ".join(f"folding J3 {side} past {math.degrees(f['q3']):.1f}° (its limit: "
                          f"{math.degrees(f['limit']):.0f}°) puts {f['text'].split(':')[0]}"
                          for side, f in fold.items())
        s.text(f"{100 * own.mean():.1f} % of the random configurations within the joint limits put the robot into "
               f"itself and {100 * hit.mean():.1f} % into the cell. With the upper arm upright, {folds}. The robot "
               "file says why: FANUC's controller limits J3 against J2 (the J2/J3 interaction limit), which the file "
               f"does not model. The example marked on the map, q = {deg(q_self)}, is {ex['text']}.")
        s.view3d(cell_view(world, q_self, meshes=cell.meshes, closest="self", title="Self-collision"),
                 "self_collision_3d", f"The example: the upper arm upright, J3 at {math.degrees(q_self[2]):.0f}°. "
                                      "The red line joins the deepest points of the two capsules that overlap.")
        s.results["self_collision"] = {"samples": n_random, "seed": seed, "self_fraction": float(own.mean()),
                                       "cell_fraction": float(hit.mean()),
                                       "pairs": [{"bodies": [min(a, b), max(a, b)], "count": k}
                                                 for (a, b), k in pairs.most_common()],
                                       "fold": fold, "map": shares,
                                       "example": {"q": q_self.tolist(), "clearance": ex["clearance"],
                                                   "bodies": [ex["body"], -1 - ex["other"]], "text": ex["text"]}}
        first = fold.get("down") or next(iter(fold.values()), None)
        s.finding(f"self-collision: {100 * own.mean():.1f} % of random configurations within the joint limits put "
                  "the robot into itself"
                  + (f"; with the upper arm upright J3 past {math.degrees(first['q3']):.0f}° (limit "
                     f"{math.degrees(first['limit']):.0f}°) puts {first['text'].split(':')[0]}" if first else "")
                  + " — the J2/J3 interaction limit the robot file leaves out", ok=True)

    # ------------------------------------------------------------------------------------------
    with s.section("The seam: coverage with and without the cell"):
        P, A, phi = seam_points(n_seam)
        poses = flange_poses(cell, P, A, n_roll)
        targets = Targets(poses[:, :3, 3], "pose", rotations=poses[:, :3, :3], tolerance=1e-4)
        free = coverage(robot, targets, None, seeds=ik_seeds, samples=ik_samples, seed=seed)
        incell = coverage(robot, targets, None, seeds=ik_seeds, samples=ik_samples, seed=seed, cell=cell,
                          clearance=clearance)
        R0 = free.reached.reshape(n_seam, n_roll)
        R1 = incell.reached.reshape(n_seam, n_roll)
        reach_pt, clear_pt = R0.any(axis=1), R1.any(axis=1)
        removed = reach_pt & ~clear_pt
        # what blocks them: the nearest collision of IK's collision-free-ignorant solution at each removed point
        blockers = Counter()
        Q0 = free.q.reshape(n_seam, n_roll, n)
        for i in np.flatnonzero(removed):
            k = int(np.argmax(R0[i]))
            c = closest_segments(world, Q0[i, k][None], "all")[0]
            blockers[f"{names[c['body']]} against {world.other_name(c['other'])}"] += 1
        arcs = [("top (45° … 135°)", (phi >= np.pi / 4) & (phi <= 3 * np.pi / 4)),
                ("robot's side (135° … 225°)", (phi > 3 * np.pi / 4) & (phi < 5 * np.pi / 4)),
                ("bottom (225° … 315°)", (phi >= 5 * np.pi / 4) & (phi <= 7 * np.pi / 4)),
                ("far side (315° … 45°)", (phi > 7 * np.pi / 4) | (phi < np.pi / 4))]
        s.text(f"The seam is the fillet where the pipe (outer radius {SEAM_RADIUS:g} mm) meets the flange's face: "
               f"{n_seam} points, {360 / n_seam:g}° apart around the pipe. At each the torch tip is on the "
               f"seam and the torch comes from the pipe's side at {WORK_ANGLE:g}° between the pipe and the flange, "
               f"rolled about its own axis in {n_roll} steps. A point counts as reached when inverse kinematics "
               "puts the torch there at any roll inside the joint limits (`design.coverage.coverage`), and as clear "
               "when that configuration also keeps the robot and torch clear of the cell and of themselves (the "
               "torch may touch the part it welds).")
        s.table(["arc of the seam (φ from the far side, up)", "points", "reached by IK", "reached clear of the cell",
                 "removed by collisions"],
                [[label, int(m.sum()), int(reach_pt[m].sum()), int(clear_pt[m].sum()), int(removed[m].sum())]
                 for label, m in arcs]
                + [["whole seam", n_seam, int(reach_pt.sum()), int(clear_pt.sum()), int(removed.sum())]],
                f"Seam points covered (any of the {n_roll} torch rolls): {int(free.reached.sum())} of "
                f"{len(targets)} torch poses reached by IK, {int(incell.reached.sum())} of them clear "
                f"({ik_seeds} IK seeds per pose from {ik_samples:,} sampled configurations, seed {seed}).")
        if blockers:
            s.table(["what the collision-blind solution hits", "seam points"],
                    [[k, v] for k, v in blockers.most_common()],
                    "At each removed point, the nearest collision of the configuration IK found without the cell.")
        fig = seam_figure(P, A, phi, reach_pt, clear_pt, cell)
        s.figure(fig, "seam", "The seam seen along the pipe's axis from the pipe's free end: its points by what "
                              "the torch can do there, with the torch's direction where it reaches clear.")
        s.results["seam"] = {"points": n_seam, "rolls": n_roll, "work_angle_deg": WORK_ANGLE,
                             "centre": (np.array(SEAM_CENTRE) / 1000).tolist(), "radius": SEAM_RADIUS / 1000,
                             "positions": P.tolist(), "axes": A.tolist(), "phi": phi.tolist(),
                             "reached": reach_pt.tolist(), "clear": clear_pt.tolist(), "removed": removed.tolist(),
                             "poses_reached": int(free.reached.sum()), "poses_clear": int(incell.reached.sum()),
                             "blocked_poses": int(incell.blocked.sum()), "blockers": dict(blockers),
                             "q_clear": incell.q.tolist(), "pose_clear": incell.reached.tolist(),
                             "ik": {"seeds": ik_seeds, "samples": ik_samples, "seed": seed}}
        s.finding(f"seam coverage: IK reaches {int(reach_pt.sum())} of the seam's {n_seam} points; collisions "
                  f"remove {int(removed.sum())} of them"
                  + (f" (mostly {blockers.most_common(1)[0][0]})" if blockers else "")
                  + f", leaving {int(clear_pt.sum())} the torch reaches clear", ok=bool(clear_pt.any()))

    # ------------------------------------------------------------------------------------------
    with s.section("A move to the seam"):
        windows = build_windows(robot, margin=margin)
        # the goal: the clear weld pose nearest the top of the seam, at the roll with the most clearance
        top_first = np.argsort(np.abs(np.angle(np.exp(1j * (phi - np.pi / 2)))), kind="stable")
        Qc = incell.q.reshape(n_seam, n_roll, n)
        goal_point = next((int(i) for i in top_first if clear_pt[i]), None)
        if goal_point is None:
            s.text("**No seam point is reachable clear of the cell**: there is no weld pose to move to.")
            s.finding("no move: no seam point is reachable clear of the cell", ok=False)
            return
        rolls = np.flatnonzero(R1[goal_point])
        goal = Qc[goal_point, rolls[int(np.argmax(world.clearance(Qc[goal_point, rolls])))]]
        start, why = choose_park(robot, world, windows, goal)
        s.text(f"From a park pose behind the wire-feeder column (where a torch-cleaning station would stand), "
               f"q = {deg(start)}, to the weld pose at the seam point {math.degrees(phi[goal_point]):.0f}° around "
               f"the pipe, q = {deg(goal)}. The park pose is chosen among the study's candidates: {why}. Both are "
               f"clear of the cell and of the robot itself ({mm(float(world.clearance(start)))} and "
               f"{mm(float(world.clearance(goal)))}) and outside the singular windows (the LR Mate's three singular "
               f"factors with a {margin:g} rad margin).")
        # 1. the plan that knows only the windows, checked against the cell afterwards
        blind = plan(robot, start, goal, windows, time_limit=plan_time, seed=seed)
        if not blind.success:
            s.text(f"**The windows-only plan found no path** ({blind.status}).")
            s.finding(f"the windows-only plan found no path ({blind.status})", ok=False)
            return
        c_blind = check_path(robot, blind.path, windows, world=world)
        d_blind = deepest(world, blind.path, "cell")
        kernel = d_blind["clearance"]
        plain = numpy_clearance(world, d_blind["q"], d_blind["body"], d_blind["other"]) \
            if d_blind["other"] >= 0 else math.nan
        # 2. the plan that knows the cell
        aware = plan(robot, start, goal, windows, time_limit=plan_time, seed=seed, world=world)
        if not aware.success:
            s.text(f"**The cell-aware plan found no path** ({aware.status}).")
            s.finding(f"the cell-aware plan found no path ({aware.status})", ok=False)
            return
        # plan() returned it proven; the table's re-check is the dense one, with the proven clearance bound
        c_aware = check_path(robot, aware.path, windows, world=world)
        d_aware = deepest(world, aware.path, "cell")
        d_aware_self = deepest(world, aware.path, "self")
        s.table(["path", "waypoints", "joint-space length (rad)", "windows", "collisions (with the cell)",
                 "min clearance (mm)", "proven clearance ≥ (mm)", "first problem"],
                [["windows-only plan", len(blind.path), blind.length, blind.check.windows_check,
                  c_blind.collision_check, 1000 * c_blind.min_clearance, None,
                  c_blind.first_violation.detail if c_blind.first_violation else "—"],
                 ["cell-aware plan", len(aware.path), aware.length, c_aware.windows_check, c_aware.collision_check,
                  1000 * c_aware.min_clearance,
                  None if c_aware.clearance_bound is None else 1000 * c_aware.clearance_bound,
                  c_aware.first_violation.detail if c_aware.first_violation else "—"]],
                "Both plans re-checked with `planning.validate.check_path` against the windows and the cell (every "
                f"state 0.1° apart, and every segment proven: `collisions` says so). OMPL {aware.planner}, seed "
                f"{seed}, {plan_time:g} s limit.", fmt=".4g")
        s.text(f"**The windows-only plan** is {'the straight joint-space line' if len(blind.path) == 2 else 'a path'} "
               f"from the park pose to the weld pose, proven clear of every window — and it drives "
               f"{into(d_blind['text'])}, {mm(-kernel)} deep at {100 * d_blind['fraction']:.0f} % of the way. "
               f"A plain numpy check of that state (the capsule's axis at 4001 points, placed by "
               f"`kin.geometry.body_frames`, against the obstacle's shape) gives {mm(plain)}, "
               f"{abs(plain - kernel) * 1e3:.2g} mm from the compiled kernel's {mm(kernel)}.\n\n"
               f"**The cell-aware plan** (`plan(..., world=world)`) goes around: {len(aware.path)} waypoints, every "
               f"segment proven clear of the cell, of the robot itself and of the windows; its closest approach to the "
               f"cell is {d_aware['text']} ({100 * d_aware['fraction']:.0f} % of the way), and within the robot "
               f"{d_aware_self['text']}.")
        s.figure(plot_clearance(world, [("windows-only plan", blind.path), ("cell-aware plan", aware.path)],
                                bounds={"cell-aware plan": c_aware.clearance_bound}),
                 "clearance", "Clearance along both plans (to the cell and within the robot, whichever is smaller) "
                              "against the fraction of each plan's joint-space length, the proven lower bound of the "
                              "cell-aware plan dashed; below, each body's clearance to the cell along the "
                              "windows-only plan.")
        s.file("windows_only_plan.csv", path_csv_text(robot, blind.path))
        s.file("cell_aware_plan.csv", path_csv_text(robot, aware.path))
        marks = [("seam: reached clear", P[clear_pt], "#2ca02c"),
                 ("seam: removed by collisions", P[removed], "#d62728"),
                 ("seam: out of reach", P[~reach_pt], "#7f7f7f")]
        s.view3d(cell_view(world, d_blind["q"], path=blind.path, meshes=cell.meshes, closest="cell",
                           tip=tip[:3, 3], points=marks, path_name="torch tip (windows-only plan)",
                           title="The windows-only plan"),
                 "windows_only_3d", "The robot at the windows-only plan's deepest collision; the red line joins the "
                                    "deepest points of the capsule and the obstacle. The slider moves the robot along "
                                    "the plan, with its closest approach to the cell.")
        s.view3d(cell_view(world, d_aware["q"], path=aware.path, meshes=cell.meshes, closest="cell",
                           tip=tip[:3, 3], points=marks, path_name="torch tip (cell-aware plan)",
                           title="The cell-aware plan"),
                 "cell_aware_3d", "The robot at the cell-aware plan's closest approach to the cell (green: clear, "
                                  "labelled with the clearance); the slider moves it along the plan.")

        def contact(d):
            return {"q": d["q"].tolist(), "clearance": d["clearance"], "body": d["body"], "other": d["other"],
                    "fraction": d["fraction"], "text": d["text"], "point_robot": d["point_robot"].tolist(),
                    "point_other": d["point_other"].tolist()}

        s.results["move"] = {
            "start": start.tolist(), "goal": goal.tolist(), "goal_seam_point": goal_point, "park_choice": why,
            "windows_margin": margin,
            "windows_only": {**blind.to_dict(), "cell_check": c_blind.to_dict(), "deepest": contact(d_blind),
                             "numpy_clearance": plain},
            "cell_aware": {**aware.to_dict(), "check": c_aware.to_dict(), "closest_cell": contact(d_aware),
                           "closest_self": contact(d_aware_self)}}
        collided = c_blind.first_violation is not None and c_blind.first_violation.kind == "collision" and kernel < 0
        s.finding(f"the windows-only plan is proven clear of the windows but drives {into(d_blind['text'])}, "
                  f"{mm(-kernel)} deep (a plain numpy check: {mm(-plain)})", ok=collided and abs(plain - kernel) < 1e-4)
        s.finding(f"the cell-aware plan: {len(aware.path)} waypoints, proven clear of the cell, the robot itself and "
                  f"the windows; clearance ≥ {mm(c_aware.min_clearance)} at every state checked (proven ≥ "
                  f"{mm(c_aware.clearance_bound or 0.0)}), closest: {d_aware['text'].split(':')[0]}",
                  ok=aware.proven)


def choose_park(robot, world, windows, goal) -> tuple[np.ndarray, str]:
    """The park candidate (J1, J2, J3 in degrees; J4 = J6 = 0, J5 = ±90° with the goal's sign), clear of
    the cell by 20 mm and outside the windows, whose straight line to ``goal`` shows best what a plan
    blind to the cell risks, by the first rule some candidate meets: the line touches the cell first and
    goes deepest into it with the forearm; it goes deepest with the forearm; it touches first with the
    forearm; it runs a link (not the torch) into the cell; the candidate is clear.  Among the candidates
    of that rule, the one whose line goes deepest (the first of equals).  Returns it and the rule."""
    sign = 1.0 if goal[4] >= 0 else -1.0
    rules = ["its straight line to the weld pose touches the cell first and goes deepest with the forearm",
             "its straight line to the weld pose goes deepest into the cell with the forearm",
             "its straight line to the weld pose touches the cell first with the forearm",
             "its straight line to the weld pose runs a link into the cell (no candidate's runs the forearm)",
             "clear, but no candidate's straight line runs a link into the cell"]
    cell_only = contact_world(world, "cell")
    best = None
    for j1, j2, j3 in PARK_CANDIDATES:
        q = np.radians([j1, j2, j3, 0.0, 90.0 * sign, 0.0])
        if cell_only.clearance(q) < 0.02 or world.clearance(q) <= 0 or windows.contains(q[None])[0]:
            continue
        Q, _, _ = densify(np.array([q, goal]), robot.chain.revolute_mask)
        c = np.asarray(cell_only.clearance(Q))
        rank = 4
        if (c <= 0).any():
            k, m = int(np.argmax(c <= 0)), int(np.argmin(c))
            first, deep = (closest_segments(world, Q[i:i + 1], "cell")[0]["body"] for i in (k, m))
            rank = 0 if first == deep == FOREARM else 1 if deep == FOREARM else 2 if first == FOREARM \
                else 3 if deep <= robot.n else 4
        key = (rank, round(float(c.min()), 6))          # rounded: equals stay equal across machines
        if best is None or key < best[0]:
            best = (key, q)
    if best is None:
        raise RmtError("no park candidate is clear of the cell and outside the windows")
    return best[1], rules[best[0][0]] + f" ({len(PARK_CANDIDATES)} candidates; the deepest of those)"


def seam_figure(P, A, phi, reached, clear, cell) -> Figure:
    """The seam along the pipe's axis (x–z in the cell frame, mm): pipe and flange outlines, the fixture's
    top, the seam points coloured by reach, and the torch direction where it reaches clear."""
    fig = Figure(figsize=(7.5, 6.4), dpi=100, layout="constrained")
    ax = fig.subplots()
    c = np.array(SEAM_CENTRE)
    t = np.linspace(0, 2 * np.pi, 200)
    for r, style in ((SEAM_RADIUS, "-"), (90.0, "--"), (40.0, ":")):
        ax.plot(c[0] + r * np.cos(t), c[2] + r * np.sin(t), style, color="#555555", linewidth=1.0)
    try:
        fx = cell.obstacle("fixture").shapes[0]
        top = 1000 * (fx.pose[2, 3] + fx.size[2])
        half = 1000 * fx.size[0]
        ax.fill_between([1000 * fx.pose[0, 3] - half, 1000 * fx.pose[0, 3] + half], top - 60, top, color="#c9b3a5",
                        alpha=0.6, linewidth=0)
        ax.text(1000 * fx.pose[0, 3] - half + 5, top - 25, "fixture", fontsize=8, color="#5c4033")
    except Exception:       # a changed cell without a fixture box: leave it out
        pass
    X = 1000 * P
    colours = np.where(clear, "#2ca02c", np.where(reached, "#d62728", "#9e9e9e"))
    ax.scatter(X[:, 0], X[:, 2], c=list(colours), s=36, zorder=3)
    for x, a in zip(X[clear], A[clear]):
        ax.annotate("", xy=(x[0], x[2]), xytext=(x[0] - 60 * a[0], x[2] - 60 * a[2]),
                    arrowprops=dict(arrowstyle="->", color="#2ca02c", linewidth=0.9))
    dot = dict(marker="o", linestyle="")
    ax.legend(handles=[Line2D([], [], **dot, color="#2ca02c", label="reached clear (torch →)"),
                       Line2D([], [], **dot, color="#d62728", label="reached only through a collision"),
                       Line2D([], [], **dot, color="#9e9e9e", label="out of reach"),
                       Line2D([], [], color="#555555", label="pipe (r 50 mm); flange (r 90, dashed)")],
              loc="upper right", fontsize=8)
    ax.set_aspect("equal")
    ax.set_xlabel("x (mm, cell frame; the robot is at x = 0, to the left)")
    ax.set_ylabel("z (mm, cell frame)")
    ax.set_xlim(c[0] - 190, c[0] + 190)
    ax.set_ylim(c[2] - 150, c[2] + 170)
    ax.grid(True, linewidth=0.5, alpha=0.4)
    return fig


if __name__ == "__main__":
    raise SystemExit(main(sys.modules[__name__]))
