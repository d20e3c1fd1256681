"""Where to bolt a FANUC LR Mate 200iD to its welding table so that its torch reaches the whole fillet
seam of a flanged pipe, clear of the cell and away from its singularities.

The cell is the bundled weld cell (`studies/cells/fanuc_weld_cell.toml`): a welding table, a fixture
with the pipe on it, a wire-feeder column, a fence, the floor.  The task is the upper half of the pipe's
fillet seam — the circle where the pipe meets the flange's face — with the torch at 45° between the pipe and the
flange and free to turn about its own axis (`axis` orientation).  The study runs the reach study at
the cell's placement (before), searches the placement on the table top with IPOPT, cross-checked
by differential evolution and a grid of placements (every answer re-verified by the reach study),
and runs the reach study again at the answer (after): heat maps of the score on the seam before and
after, the reasons of the targets missed, the methods side by side, and a 3-D view of the robot at
its new place welding the seam.

Run it with ``rmt study fanuc_weld_placement`` (``--quick`` for the reduced version) or ``python
studies/bundled/fanuc_weld_placement.py --out DIR``.  Copy this file to weld another seam (change
``seam_targets``), to use another robot, or to stand the robot somewhere else (``REGION``).
"""
from __future__ import annotations

import dataclasses
import math
import sys
from pathlib import Path

import numpy as np
from matplotlib.figure import Figure
from matplotlib.patches import Rectangle

import studies
from design.place import PlacementRegion, place
from design.reach import ReachSettings, compare_studies
from design.task.model import Targets
from kin import Placement, Robot
from kin.transforms import matrix_to_rpy
from planning.cell import load_cell
from planning.collision import collision_world
from studies.report.cell_view import cell_view
from studies.study import Study, main

NAME = "fanuc_weld_placement"
TITLE = "FANUC LR Mate 200iD: placing the robot on its welding table for a fillet seam"

CELL = Path(studies.__file__).parent / "cells" / "fanuc_weld_cell.toml"
ROBOT = "fanuc_lrmate200id"
#: the fillet seam (cell frame, mm): the pipe's axis along y through x = 550, z = 950; the flange's face at y = 113
SEAM_CENTRE = (550.0, 113.0, 950.0)
SEAM_RADIUS = 50.0
WORK_ANGLE = 45.0
#: the arc welded in this set-up (deg about the pipe's axis; 0: away from the robot, 90: the top): the upper
#: half — the pipe lies on the fixture, whose top the torch would hit lower down; the lower half is welded
#: after turning the part (widen the arc to see the fixture collisions in the reasons)
ARC = (0.0, 180.0)
#: the table top the base may stand on (m): x, y; the base at the table's height, any yaw
REGION = {"x": (-0.25, 1.05), "y": (-0.40, 0.40), "z": (0.80, 0.80)}
#: the fixture's footprint (m) grown by the base's radius: the base may not stand there
KEEP_OUT = ((0.28, 0.82, -0.22, 0.22),)
#: the clearance (m) a weld pose keeps from the cell and between the robot's own bodies
CLEARANCE = 0.005


def seam_targets(n: int) -> Targets:
    """The seam's n points (cell frame, m) on the arc :data:`ARC` with the torch axis into the weld
    (free about itself)."""
    phi = np.radians(ARC[0] + (ARC[1] - ARC[0]) * np.arange(n) / (n - 1))
    radial = np.column_stack([np.cos(phi), np.zeros(n), np.sin(phi)])
    w = math.radians(WORK_ANGLE)
    axis = -math.sin(w) * radial + math.cos(w) * np.array([0.0, 1.0, 0.0])
    return Targets(np.array(SEAM_CENTRE) / 1000 + SEAM_RADIUS / 1000 * radial, "axis", axes=axis, tolerance=1e-4)


def torch_robot(robot: Robot, cell):
    """The robot with its tool frame moved to the torch tip (the far end of the cell's last tool
    capsule, z along the torch neck), and the cell with the torch capsules re-expressed in that frame."""
    neck = cell.tool[-1]
    a, b = np.array(neck.a), np.array(neck.b)
    z = (b - a) / np.linalg.norm(b - a)
    x = np.array([1.0, 0.0, 0.0]) - z[0] * z
    x /= np.linalg.norm(x)
    tip = np.eye(4)
    tip[:3, 0], tip[:3, 1], tip[:3, 2], tip[:3, 3] = x, np.cross(z, x), z, b
    inv = np.linalg.inv(tip)
    move = lambda p: tuple(float(v) for v in (inv @ np.array([*p, 1.0]))[:3])
    tool = tuple(dataclasses.replace(c, a=move(c.a), b=move(c.b)) for c in cell.tool)
    chain = dataclasses.replace(robot.chain, tool=Placement.from_matrix(robot.chain.tool.matrix @ tip),
                                geometry=robot.geometry)
    return Robot(chain), dataclasses.replace(cell, tool=tool), tip


def heat_map(targets: Targets, studies_: list, titles: list[str]) -> Figure:
    """The seam seen along the pipe's axis (x–z, mm), each target coloured by its score (grey ×: missed)."""
    fig = Figure(figsize=(5.2 * len(studies_), 4.6))
    P = 1000 * targets.positions
    for k, (st, title) in enumerate(zip(studies_, titles)):
        ax = fig.add_subplot(1, len(studies_), k + 1)
        ok = st.reached
        sc = ax.scatter(P[ok, 0], P[ok, 2], c=st.score[ok], cmap="viridis", vmin=0, vmax=1, s=60, edgecolor="k")
        ax.scatter(P[~ok, 0], P[~ok, 2], marker="x", color="0.5", s=50, label="missed")
        for i in np.flatnonzero(~ok):
            ax.annotate(st.reason[i].replace("_", " "), (P[i, 0], P[i, 2]), fontsize=6, color="0.35",
                        xytext=(4, 4), textcoords="offset points")
        ax.set_aspect("equal")
        ax.set_xlabel("x (mm)")
        ax.set_ylabel("z (mm)")
        ax.set_title(f"{title}: {100 * st.coverage:.0f} % reached, mean score {st.mean_score:.2f}", fontsize=9)
        if (~ok).any():
            ax.legend(loc="lower right", fontsize=7)
    fig.colorbar(sc, ax=fig.axes, label="score (0 … 1)", shrink=0.8)
    return fig


def placement_map(result, grid) -> Figure:
    """The grid's placements on the table (x, y), coloured by their value, with every method's answer."""
    fig = Figure(figsize=(7.2, 5.4))
    ax = fig.add_subplot(1, 1, 1)
    if grid is not None:
        best = grid.value.max()
        ok = np.isfinite(grid.value) & (grid.value >= 0)
        top = {}
        for u, v in zip(grid.U[ok], grid.value[ok]):       # the best yaw at each (x, y)
            key = (round(u[0], 6), round(u[1], 6))
            top[key] = max(top.get(key, -1.0), v)
        xy = np.array(list(top))
        sc = ax.scatter(1000 * xy[:, 0], 1000 * xy[:, 1], c=list(top.values()), cmap="magma", s=30,
                        vmin=0, vmax=best)
        fig.colorbar(sc, ax=ax, label="targets reached + mean score (best yaw)")
    for (x0, x1, y0, y1) in KEEP_OUT:
        ax.add_patch(Rectangle((1000 * x0, 1000 * y0), 1000 * (x1 - x0), 1000 * (y1 - y0), fill=False, hatch="//",
                               color="tab:red"))
    marks = {"ipopt": "*", "differential_evolution": "D", "grid": "s"}
    for name, m in result.methods.items():
        ax.scatter(1000 * m["placement"][0], 1000 * m["placement"][1], marker=marks.get(name, "o"), s=140,
                   edgecolor="white", color="tab:blue" if name == result.method else "tab:green",
                   label=f"{name}: {m['coverage_percent']:.0f} %, {m['mean_score']:.3f}")
    ax.scatter(0, 0, marker="P", s=120, color="tab:orange", label="the cell's placement")
    ax.set_aspect("equal")
    ax.set_xlabel("x (mm)")
    ax.set_ylabel("y (mm)")
    ax.legend(fontsize=7, loc="upper center", bbox_to_anchor=(0.5, -0.14), ncol=2)
    ax.set_title("Where the base may stand (hatched: the fixture's keep-out)", fontsize=9)
    fig.subplots_adjust(bottom=0.24)
    return fig


def run(s: Study) -> None:
    base_robot = s.robot(ROBOT)
    cell0 = load_cell(CELL)
    robot, cell, tip = torch_robot(base_robot, cell0)
    n_seam = s.input("seam: points", 18 if s.quick else 36)
    settings = ReachSettings(starts=4 if s.quick else 8, samples=2048 if s.quick else 4096, spins=8,
                             max_iter=200)
    s.input("reach study: starts, samples, spins", [settings.starts, settings.samples, settings.spins])
    grid_n = s.input("grid: placements per free coordinate (x, y, yaw)", 8 if s.quick else 14)
    de_iter = s.input("differential evolution: generations", 6 if s.quick else 20)
    starts = s.input("IPOPT starts", 3 if s.quick else 4)
    seed = s.input("seed (differential evolution)", 0)
    clearance = s.input("required clearance (m)", CLEARANCE)
    targets = seam_targets(n_seam)
    region = PlacementRegion(REGION["x"], REGION["y"], REGION["z"], keep_out=KEEP_OUT)

    with s.section("The task"):
        s.text(f"The torch tip — the end of the cell's torch neck, {1000 * np.linalg.norm(tip[:3, 3]):.0f} mm from "
               "the faceplate — becomes the robot's tool frame, so each target is a point and a torch axis: the "
               f"{n_seam} points of the fillet seam's upper half ({ARC[0]:g}° … {ARC[1]:g}° around the pipe, "
               f"radius {SEAM_RADIUS:g} mm, at the flange's face; lower down the torch would hit the fixture the pipe "
               "lies on, so the lower half is welded after turning the part), the torch at "
               f"{WORK_ANGLE:g}° between pipe and flange, free to turn about its own axis. "
               f"A weld pose counts when it keeps {1000 * clearance:g} mm from the cell and between the robot's "
               "own bodies. The base may stand anywhere on the table top "
               f"(x {1000 * REGION['x'][0]:g} … {1000 * REGION['x'][1]:g} mm, y {1000 * REGION['y'][0]:g} … "
               f"{1000 * REGION['y'][1]:g} mm, at the table's height, any yaw) but not under the fixture.")
        s.results["task"] = {"seam_points": n_seam, "work_angle_deg": WORK_ANGLE, "region": region.to_dict(),
                             "torch_tip_m": tip[:3, 3].tolist(), "clearance_m": clearance}

    with s.section("Placement"):
        result = place(robot, targets, cell, region, clearance, settings=settings, starts=starts, grid=grid_n,
                       de_iterations=de_iter, seed=seed, progress=s.say)
        before, after = result.before, result.study
        rows = []
        for name, m in result.methods.items():
            u = m["placement"]
            rows.append([name + (" ←" if name == result.method else ""), 1000 * u[0], 1000 * u[1],
                         math.degrees(u[5]), m["coverage_percent"], m["mean_score"], m["time_s"]])
        s.table(["method", "x (mm)", "y (mm)", "yaw (°)", "reached (%)", "mean score", "time (s)"], rows,
                "Each method's best placement, verified by the full reach study (← the answer).", fmt=".4g")
        ip, gr = result.methods.get("ipopt"), result.methods.get("grid")
        if ip and gr:
            gap = (gr["mean_score"] - ip["mean_score"]) / max(gr["mean_score"], 1e-12)
            s.finding(f"IPOPT reaches {ip['coverage_percent']:.0f} % (grid: {gr['coverage_percent']:.0f} %) with mean "
                      f"score {ip['mean_score']:.3f} (grid best: {gr['mean_score']:.3f}, "
                      f"{'above' if gap <= 0 else f'{100 * gap:.2g} % below'}) in {ip['time_s']:.1f} s against "
                      f"{gr['time_s']:.1f} s for the grid's {gr['placements']} placements.",
                      ok=ip["coverage_percent"] >= gr["coverage_percent"] and gap <= 0.01)
        s.figure(placement_map(result, result.grid), "placement_map",
                 "The table top seen from above: the value of a coarse grid of placements (best yaw at each point), "
                 "the keep-out under the fixture, and where each method put the base.")
        P = result.matrix
        s.text(f"The answer: the base at x = {1000 * result.u[0]:.0f} mm, y = {1000 * result.u[1]:.0f} mm, yaw "
               f"{math.degrees(matrix_to_rpy(P[:3, :3])[2]):.1f}°, found by {result.method}.")
        s.results["placement"] = {"answer": result.to_dict()}

    with s.section("Before and after"):
        s.figure(heat_map(targets, [before, after], ["before (the cell's placement)", "after"]), "seam_heat_map",
                 "The seam seen along the pipe's axis: each target coloured by its reach score; grey crosses are "
                 "missed, labelled with the reason.")
        cmp = compare_studies(before, after, ("before", "after"))
        d = cmp.to_dict()
        s.table(["", "before", "after"],
                [["reached (%)", 100 * before.coverage, 100 * after.coverage],
                 ["mean score", before.mean_score, after.mean_score],
                 ["missed: out of reach", *(st.reason_counts().get("out_of_reach", 0) for st in (before, after))],
                 ["missed: joint limits", *(st.reason_counts().get("joint_limits", 0) for st in (before, after))],
                 ["missed: collision", *(st.reason_counts().get("collision", 0) for st in (before, after))]],
                f"Targets gained: {len(d['gained'])}, lost: {len(d['lost'])}; collisions before, by object: "
                f"{before.obstacle_counts() or 'none'}.", fmt=".4g")
        s.finding(f"The placement takes the seam from {100 * before.coverage:.0f} % to {100 * after.coverage:.0f} % "
                  f"reached (mean score {before.mean_score:.3f} → {after.mean_score:.3f}).",
                  ok=after.value >= before.value)
        # an independent check of the answer: the torch tip on every reached seam point, along its axis
        Tq = robot.fk(after.q[after.reached])
        W = np.einsum("ij,njk->nik", P, Tq)
        err_p = np.abs(W[:, :3, 3] - targets.positions[after.reached]).max() if len(W) else 0.0
        err_a = np.degrees(np.arccos(np.clip(np.einsum("ni,ni->n", W[:, :3, 2], targets.axes[after.reached]),
                                             -1, 1))).max() if len(W) else 0.0
        s.finding(f"At every reached target the torch tip lies within {1000 * err_p:.2g} mm of the seam point and "
                  f"its axis within {err_a:.2g}° of the weld's (forward kinematics of the reported configurations).",
                  ok=err_p <= 1e-4 + 1e-9 and err_a <= 0.01)
        world = collision_world(robot, cell, clearance)
        world.move_base(P)
        clear = world.clearance(after.q[after.reached]) if after.reached.any() else np.array([np.inf])
        s.finding(f"The smallest clearance of a reached weld pose is {1000 * float(np.min(clear)):.3g} mm "
                  f"(required: {1000 * clearance:g} mm).", ok=bool(np.min(clear) > clearance))
        s.results["before"] = before.summary()
        s.results["after"] = {**after.summary(), "per_target": after.rows()}
        s.results["comparison"] = {k: d[k] for k in ("gained", "lost", "mean_score_change", "reason_changes")}
        path = after.q[after.reached]
        s.view3d(cell_view(world, path[0] if len(path) else None, path=path if len(path) > 1 else None,
                           meshes=cell.meshes, closest="cell", title="The LR Mate at its new place",
                           points=[("seam: reached", targets.positions[after.reached], "green"),
                                   ("seam: missed", targets.positions[~after.reached], "red")],
                           path_name="torch tip"),
                 "placement_3d", "The robot at its new place, the slider stepping through its weld poses along the "
                                 "seam; green: reached seam points, red: missed.")


if __name__ == "__main__":
    sys.exit(main(sys.modules[__name__]))
